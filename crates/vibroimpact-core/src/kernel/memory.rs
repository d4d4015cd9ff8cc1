//! The memory a run's records may take, and growth within it that fails with
//! an error instead of aborting the process.
//!
//! `max_rows` counts rows, but a row of a 200-mode beam is 400 values where
//! the two-mass damper's is 6: rows alone do not bound memory. Every run
//! also keeps its records (history, stroboscopic states, contacts) within
//! [`MAX_RECORD_BYTES`], and grows them with `try_reserve`, so that neither
//! a wide system nor a refusing allocator can take the process down.

use crate::error::Error;

/// Most bytes the records of one run may hold: 2 GiB. The default
/// `max_rows` of the two-mass damper (2e7 rows of 48 bytes, under 1 GB)
/// fits within it; a history that would pass it is refused before a fixed-step
/// run starts and stops any other run with [`crate::Error::MemoryLimit`].
pub const MAX_RECORD_BYTES: u64 = 1 << 31;

/// Rows a record's first growth makes room for, where the run does not
/// know how many it keeps (fewer for a fixed-step run keeping fewer: a
/// short run's set-up allocates what it keeps).
pub(crate) const FIRST_ROWS: usize = 64;

/// Bytes held by `v`'s allocation.
#[inline(always)]
pub(crate) fn held<T>(v: &Vec<T>) -> u64 {
    (v.capacity() * std::mem::size_of::<T>()) as u64
}

/// Why room could not be made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum NoRoom {
    /// The records would pass this limit (bytes).
    Limit(u64),
    /// The allocator refused the memory.
    Refused,
}

impl NoRoom {
    /// The run's error: it held `held` bytes at `time` (s) in `rows` history
    /// rows and `strobes` stroboscopic rows of `columns` values and
    /// `contacts` contacts.
    pub(crate) fn error(
        self,
        time: f64,
        (rows, strobes): (u64, u64),
        columns: u64,
        contacts: u64,
        held: u64,
    ) -> Error {
        // Advice for what holds the most: a contact is about 11 values.
        let (history, strobed) = (rows * columns, strobes * columns);
        let advice = if history >= strobed && history >= 11 * contacts {
            "raise every, set history = false or shorten t_end"
        } else if strobed >= 11 * contacts {
            "lengthen strobe_period or shorten t_end"
        } else {
            "the contacts fill it: shorten t_end"
        };
        Error::MemoryLimit {
            advice,
            time,
            rows,
            strobes,
            columns,
            contacts,
            held_mib: held as f64 / (1u64 << 20) as f64,
            cause: match self {
                Self::Limit(limit) => format!("would pass the limit of {} MiB", limit >> 20),
                Self::Refused => "the machine refused more memory".to_string(),
            },
        }
    }
}

/// Makes room in `v` for `more` elements: as many again as it holds (at
/// least `least`), but at most half the room left under `limit` bytes for
/// all the run's records, `v`'s and the `others` bytes held elsewhere
/// (asked only when `v` must grow): records that grow in turn share it.
#[inline(always)]
pub(crate) fn make_room<T>(
    v: &mut Vec<T>,
    more: usize,
    least: usize,
    others: impl FnOnce() -> u64,
    limit: u64,
) -> Result<(), NoRoom> {
    if v.capacity() - v.len() >= more {
        return Ok(());
    }
    grow(v, more, least, others(), limit)
}

#[cold]
#[inline(never)]
fn grow<T>(
    v: &mut Vec<T>,
    more: usize,
    least: usize,
    others: u64,
    limit: u64,
) -> Result<(), NoRoom> {
    let size = std::mem::size_of::<T>().max(1) as u64;
    // Elements that still fit, beyond those allocated.
    let fits = limit.saturating_sub(others + held(v)) / size;
    let spare = (v.capacity() - v.len()) as u64;
    if fits + spare < more as u64 {
        return Err(NoRoom::Limit(limit));
    }
    // At most half the room left, so that the other records can still grow.
    let wanted = (v.len().max(least) as u64).max(more as u64);
    let reserve = wanted.min(((fits + spare) / 2).max(more as u64)) as usize;
    v.try_reserve_exact(reserve).map_err(|_| NoRoom::Refused)
}

/// Appends a row, `time` to `times` and `values` to `rows`, growing both
/// together (as many rows again as they hold, at least `least`, at most
/// half the room left) within `limit` bytes of all the run's records, of
/// which `others` are held elsewhere (asked only when they must grow).
#[inline(always)]
pub(crate) fn push_row(
    times: &mut Vec<f64>,
    rows: &mut Vec<f64>,
    (time, values): (f64, &[f64]),
    least: usize,
    others: impl FnOnce() -> u64,
    limit: u64,
) -> Result<(), NoRoom> {
    if times.len() == times.capacity() || rows.capacity() - rows.len() < values.len() {
        grow_rows(times, rows, (values.len(), least), others(), limit)?;
    }
    times.push(time);
    rows.extend_from_slice(values);
    Ok(())
}

#[cold]
#[inline(never)]
fn grow_rows(
    times: &mut Vec<f64>,
    rows: &mut Vec<f64>,
    (width, least): (usize, usize),
    others: u64,
    limit: u64,
) -> Result<(), NoRoom> {
    let row_bytes = 8 * (width as u64 + 1);
    let fits = limit.saturating_sub(others + held(times) + held(rows)) / row_bytes;
    if fits == 0 {
        return Err(NoRoom::Limit(limit));
    }
    // At most half the room left, so that the other records can still grow.
    let more = (times.len().max(least) as u64).min((fits / 2).max(1)) as usize;
    times.try_reserve_exact(more).map_err(|_| NoRoom::Refused)?;
    rows.try_reserve_exact(more * width)
        .map_err(|_| NoRoom::Refused)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn growth_doubles_and_stops_at_the_limit() {
        crate::testing::timeout(60, || {
            let mut v: Vec<f64> = Vec::new();
            make_room(&mut v, 1, 4, || 0, 1 << 20).unwrap();
            assert_eq!(v.capacity(), 4);
            v.extend_from_slice(&[1.0; 4]);
            make_room(&mut v, 1, 4, || 0, 1 << 20).unwrap();
            assert_eq!(v.capacity(), 8, "as many again as it holds");
            // With 40 bytes left (5 f64), it takes half of what fits, then
            // half of the rest, up to the limit and no further.
            v.extend_from_slice(&[1.0; 4]);
            let others = (1 << 20) - held(&v) - 40;
            make_room(&mut v, 1, 4, || others, 1 << 20).unwrap();
            assert_eq!(v.capacity(), 8 + 2);
            while v.len() < 13 {
                make_room(&mut v, 1, 4, || others, 1 << 20).unwrap();
                v.push(0.0);
                assert!(held(&v) + others <= 1 << 20);
            }
            assert_eq!(v.capacity(), 13);
            assert_eq!(
                make_room(&mut v, 1, 4, || others, 1 << 20),
                Err(NoRoom::Limit(1 << 20))
            );
            assert_eq!(v.len(), 13, "nothing lost");
        });
    }

    #[test]
    fn rows_grow_together_within_the_limit() {
        crate::testing::timeout(60, || {
            let (mut times, mut rows) = (Vec::new(), Vec::new());
            // Rows of 1 + 3 values (32 bytes): 50 at first (half the room
            // of a 3200-byte limit), then half the rest each time, 100 in
            // all, then no more.
            let limit = 3200;
            for i in 0..100 {
                push_row(
                    &mut times,
                    &mut rows,
                    (i as f64, &[1.0, 2.0, 3.0]),
                    64,
                    || 0,
                    limit,
                )
                .unwrap();
                assert!(held(&times) + held(&rows) <= limit);
            }
            assert_eq!(times.capacity(), 100);
            assert_eq!(rows.capacity(), 300);
            assert_eq!(
                push_row(
                    &mut times,
                    &mut rows,
                    (100.0, &[1.0, 2.0, 3.0]),
                    64,
                    || 0,
                    limit
                ),
                Err(NoRoom::Limit(limit))
            );
            assert_eq!((times.len(), rows.len()), (100, 300), "nothing half kept");
            assert_eq!(rows[297..], [1.0, 2.0, 3.0]);
        });
    }

    #[test]
    fn a_growing_history_leaves_room_for_the_other_records() {
        crate::testing::timeout(60, || {
            // 200 rows of 32 bytes and 37 contacts of 8 need 6696 bytes, 89 %
            // of a 7500-byte limit. A history that took all the room its
            // doubling wanted would leave 12 bytes and stop the contacts.
            let limit = 7500;
            let (mut times, mut rows) = (Vec::new(), Vec::new());
            let mut contacts: Vec<f64> = Vec::new();
            for i in 0..200 {
                let others = held(&contacts);
                push_row(
                    &mut times,
                    &mut rows,
                    (i as f64, &[0.0; 3]),
                    64,
                    || others,
                    limit,
                )
                .unwrap();
            }
            let others = held(&times) + held(&rows);
            make_room(&mut contacts, 37, 8, || others, limit).unwrap();
            assert!(held(&times) + held(&rows) + held(&contacts) <= limit);
        });
    }

    #[test]
    fn an_impossible_reservation_is_refused_not_aborted() {
        crate::testing::timeout(60, || {
            let mut v: Vec<f64> = vec![0.0];
            // Within the limit but more than the address space:
            // try_reserve refuses it.
            assert_eq!(
                make_room(&mut v, usize::MAX / 16, 1, || 0, u64::MAX),
                Err(NoRoom::Refused)
            );
        });
    }
}
