//! What makes a step of a stretch more than plain for the event kernel:
//! a wall's event it would search for, or a compliant contact at its
//! deepest (the RK4 stretches' rule and the paper's Newmark's), and for
//! fixed steps a contact begun or ended.

use super::stretch_reductions::peak_inside;
use super::{Compact, MAX_LEN, MAX_WALLS};
use crate::kernel::events::Open;
use crate::model::assembly::{Assembly, Mode};

/// Per wall, whether the event search passes over it and whether it is
/// locked; whether a sticking pair may release.
type PassedOver = ([bool; MAX_WALLS], [bool; MAX_WALLS], bool);

/// Each wall's gap and rate.
pub(crate) type WallGaps = [(f64, f64); MAX_WALLS];

/// The walls the event search passes over in `modes` (the open wall of a
/// sticking damper), the sticking walls of a damper without clearance
/// (locked), and whether a sticking pair may release.
#[inline(always)]
pub(crate) fn passed_over(system: &Assembly, modes: &[Mode]) -> PassedOver {
    let mut held = [false; MAX_WALLS];
    let mut locked = [false; MAX_WALLS];
    let mut releasable = false;
    for w in 0..modes.len().min(MAX_WALLS) {
        held[w] = modes[w] == Mode::Open && system.held_by_mirror(w, modes);
        locked[w] = system.locked(w);
        releasable |= modes[w] == Mode::Sticking && !locked[w];
    }
    (held, locked, releasable)
}

/// Whether the step of `length` whose walls' gaps and rates are `gaps` at
/// its start and end shows no event the kernel would search for, and no
/// compliant contact at its deepest.
#[inline(always)]
pub(crate) fn shows_no_event(
    modes: &[Mode],
    held: &[bool; MAX_WALLS],
    (start, end): (&WallGaps, &WallGaps),
    length: f64,
) -> bool {
    let mut plain = true;
    for w in 0..modes.len().min(MAX_WALLS) {
        match modes[w] {
            // The event search passes over these (see `find_crossing`).
            Mode::Sticking => {}
            Mode::Open if held[w] => {}
            mode => {
                plain &= !mode.may_cross(start[w], end[w]);
                if let Mode::Compliant { .. } = mode {
                    let (m0, m1) = (start[w].1 * length, end[w].1 * length);
                    plain &= !(m0 < 0.0 && m1 > 0.0);
                }
            }
        }
    }
    plain
}

impl Compact {
    /// Whether the fixed step from `y` to `end` is plain (the kernel's
    /// fixed step would only count it): a finite end, indented at the end
    /// exactly where in contact (no onset or separation; the walls' gaps at
    /// the end into `end_gaps`, in contact only), and `in_window` no peak
    /// inside.
    #[inline(always)]
    pub(super) fn fixed_plain<const FREE: bool>(
        &self,
        system: &Assembly,
        (n, k): (usize, usize),
        (y, end): (&[f64; MAX_LEN], &[f64; MAX_LEN]),
        end_gaps: &mut WallGaps,
        open: &[Option<Open>],
        in_window: bool,
    ) -> bool {
        let d = n + k;
        let mut plain = end[..2 * d].iter().fold(0.0, |sum, v| sum + v * 0.0) == 0.0;
        if FREE {
            // No contact: none may begin (the gaps themselves are needed
            // only where the stretch ends).
            plain &= !self.indented(d, end);
        } else {
            self.gaps(d, end, end_gaps);
            for w in 0..self.count.min(MAX_WALLS) {
                plain &= (end_gaps[w].0 < 0.0) == open[w].is_some();
            }
        }
        plain && !(in_window && peak_inside(system, system.observed(), (&y[..], &end[..]), d, n))
    }
}
