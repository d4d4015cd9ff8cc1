//! What a two-mass run keeps and checks as it goes, shared by the fixed-step
//! and the event-driven kernels: contact records, the history within its
//! cap, the solution, the start check and the energy ledger.

use crate::error::{Error, Result};
use crate::kernel::memory::{self, NoRoom, MAX_RECORD_BYTES};
use crate::legacy::equations::{Excitation, Model};
use crate::methods::registry::two_mass::Settings;
use crate::model::contact::ContactLaw;
use crate::model::impact_damper::State;
use std::collections::TryReserveError;

/// One contact, from onset to separation. Speeds are relative normal speeds
/// (m/s, positive); a contact still open at the end has NaN separation,
/// duration, rebound speed, restitution and energy change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactRecord {
    /// s.
    pub onset: f64,
    /// s.
    pub separation: f64,
    /// s.
    pub duration: f64,
    /// m.
    pub max_indentation: f64,
    /// Indentation rate at onset, m/s.
    pub approach_speed: f64,
    /// Separation speed at the end of the contact, m/s.
    pub rebound_speed: f64,
    /// Effective restitution: `rebound_speed / approach_speed`.
    pub restitution: f64,
    /// Work done during the contact by the contact's dissipative forces (the
    /// law's hysteresis and the contact damper `c1`), J, >= 0: the integral
    /// of `(F - F_elastic) * delta'` over the contact, as the run integrates
    /// it. The main damper `C` and any external force are not in it.
    pub energy_dissipated: f64,
    /// Net change of the whole system's mechanical energy over the contact
    /// (kinetic energy of both masses, main spring and contact elastic energy,
    /// at separation minus at onset), J. Without a main damper or external
    /// force it is `-energy_dissipated` (to the method's accuracy: the
    /// contact's energy balance); with them it also holds their work during
    /// the contact, which may make it positive.
    pub energy_change: f64,
}

/// Time history columns (SI units), one row per kept step.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct History {
    pub time: Vec<f64>,
    pub main_displacement: Vec<f64>,
    pub main_velocity: Vec<f64>,
    pub impact_displacement: Vec<f64>,
    pub impact_velocity: Vec<f64>,
    /// Force between the bodies (law + contact damper), N; > 0 pushes apart.
    pub contact_force: Vec<f64>,
}

impl History {
    /// Room for `rows` more rows; Err when the machine refuses the memory.
    fn try_reserve_exact(&mut self, rows: usize) -> std::result::Result<(), TryReserveError> {
        self.time.try_reserve_exact(rows)?;
        self.main_displacement.try_reserve_exact(rows)?;
        self.main_velocity.try_reserve_exact(rows)?;
        self.impact_displacement.try_reserve_exact(rows)?;
        self.impact_velocity.try_reserve_exact(rows)?;
        self.contact_force.try_reserve_exact(rows)
    }

    /// Bytes held.
    fn held(&self) -> u64 {
        6 * memory::held(&self.time)
    }

    #[inline(always)]
    fn push(&mut self, time: f64, s: &State, force: f64) {
        self.time.push(time);
        self.main_displacement.push(s.main_displacement);
        self.main_velocity.push(s.main_velocity);
        self.impact_displacement.push(s.impact_displacement);
        self.impact_velocity.push(s.impact_velocity);
        self.contact_force.push(force);
    }
}

/// What a run keeps, within `max_rows` and [`MAX_RECORD_BYTES`]: the history
/// (if kept) and the contacts. Storage grows only as far as both allow, and
/// fallibly, so the rows allocated never exceed them; a row or a contact
/// beyond them stops the run with [`Error::RowLimit`] or
/// [`Error::MemoryLimit`].
pub(crate) struct Records {
    pub(crate) history: History,
    pub(crate) contacts: Vec<ContactRecord>,
    keep_history: bool,
    max_rows: u64,
    /// Bytes all the records may hold: [`MAX_RECORD_BYTES`] (less in tests).
    limit: u64,
}

/// Bytes of a history row (six f64 columns).
const ROW_BYTES: u64 = 48;

impl Records {
    /// Room for `rows` history rows from the start (as far as `max_rows`
    /// and the memory limit allow; an up-front check has refused a
    /// fixed-step history beyond them).
    pub(crate) fn new(settings: &Settings, rows: u64) -> Result<Self> {
        let mut records = Self::within(settings.history, settings.max_rows, MAX_RECORD_BYTES);
        if settings.history {
            let rows = rows
                .min(settings.max_rows)
                .min(MAX_RECORD_BYTES / ROW_BYTES / 2);
            records
                .history
                .try_reserve_exact(rows as usize)
                .map_err(|_| records.no_room(NoRoom::Refused, 0.0))?;
        }
        Ok(records)
    }

    /// Empty records within `max_rows` and `limit` bytes.
    fn within(keep_history: bool, max_rows: u64, limit: u64) -> Self {
        Self {
            history: History::default(),
            contacts: Vec::new(),
            keep_history,
            max_rows,
            limit,
        }
    }

    /// Whether the history is kept at all.
    #[inline(always)]
    pub(crate) fn keeps_history(&self) -> bool {
        self.keep_history
    }

    fn full(&self, time: f64) -> Error {
        Error::RowLimit {
            time,
            max_rows: self.max_rows,
            rows: self.history.time.len() as u64,
            contacts: self.contacts.len() as u64,
            advice: if self.keep_history {
                "raise every, set history = false, shorten t_end or raise max_rows"
            } else {
                "the contacts alone fill it: shorten t_end or raise max_rows"
            },
        }
    }

    fn no_room(&self, cause: NoRoom, time: f64) -> Error {
        cause.error(
            time,
            (self.history.time.len() as u64, 0),
            6,
            self.contacts.len() as u64,
            self.history.held() + memory::held(&self.contacts),
        )
    }

    /// History rows plus contacts allocated.
    fn allocated(&self) -> u64 {
        (self.history.time.capacity() + self.contacts.capacity()) as u64
    }

    /// How many more rows (of `row_bytes` each) may be allocated: as many as
    /// the `current` length (at least `least`), as far as `max_rows` allows
    /// and at most half the memory left, so that the other record can still
    /// grow (the history taking all of it left no room for the contacts).
    fn growth(&self, current: usize, least: usize, row_bytes: u64) -> usize {
        let room = self.max_rows.saturating_sub(self.allocated());
        let held = self.history.held() + memory::held(&self.contacts);
        let fits = self.limit.saturating_sub(held) / row_bytes;
        (current.max(least) as u64)
            .min(room)
            .min((fits / 2).max(fits.min(1))) as usize
    }

    /// The error of a run that found no room: the row limit, or the memory's.
    fn limit(&self, time: f64) -> Error {
        if self.allocated() >= self.max_rows {
            self.full(time)
        } else {
            self.no_room(NoRoom::Limit(self.limit), time)
        }
    }

    /// Keeps one history row (when the history is kept).
    #[inline(always)]
    pub(crate) fn keep(&mut self, time: f64, s: &State, force: f64) -> Result<()> {
        if !self.keep_history {
            return Ok(());
        }
        if self.history.time.len() == self.history.time.capacity() {
            self.grow_history(time)?;
        }
        self.history.push(time, s, force);
        Ok(())
    }

    #[cold]
    #[inline(never)]
    fn grow_history(&mut self, time: f64) -> Result<()> {
        let more = self.growth(self.history.time.len(), 64, ROW_BYTES);
        if more == 0 {
            return Err(self.limit(time));
        }
        self.history
            .try_reserve_exact(more)
            .map_err(|_| self.no_room(NoRoom::Refused, time))
    }

    /// Keeps one contact record; `time` is the run's time, for the message.
    pub(crate) fn contact(&mut self, record: ContactRecord, time: f64) -> Result<()> {
        if self.contacts.len() == self.contacts.capacity() {
            // Eight at first: a small allocation, as most runs have few contacts.
            let bytes = std::mem::size_of::<ContactRecord>() as u64;
            let more = self.growth(self.contacts.len(), 8, bytes);
            if more == 0 {
                return Err(self.limit(time));
            }
            self.contacts
                .try_reserve_exact(more)
                .map_err(|_| self.no_room(NoRoom::Refused, time))?;
        }
        self.contacts.push(record);
        Ok(())
    }
}

/// What a run returns.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Empty when the run kept no history.
    pub history: History,
    pub contacts: Vec<ContactRecord>,
    /// Steps taken (accepted).
    pub steps: u64,
    /// Steps rejected by the error control of the adaptive methods.
    pub rejected_steps: u64,
    /// Touches shallower than round-off that were not treated as contacts.
    pub grazing_contacts: u64,
    /// Right-hand-side (force) evaluations.
    pub rhs_evaluations: u64,
    pub final_time: f64,
    pub final_state: State,
    /// Largest relative growth of the mechanical energy of an unforced system
    /// over the run, `max(E) / E(0) - 1` (checked every few steps); NaN when
    /// forced or starting at rest. Physically it can only be <= 0.
    pub energy_growth: f64,
    /// Largest residual of the energy balance found by the checks, relative
    /// to the energy in play (see [`simulate`]); NaN when nothing was in play
    /// (a system at rest). The run is refused when it exceeds the tolerance.
    pub energy_residual: f64,
}

/// How often (in steps) the energy balance is checked; a power of two.
const ENERGY_INTERVAL: u64 = 32;
/// An unforced system whose energy grows by more than this factor has blown up.
const ENERGY_GROWTH_LIMIT: f64 = 1.5;

/// Refuses a start with the bodies interpenetrating (indentation beyond
/// round-off): no contact law gives that state a meaning (its onset, approach
/// speed and restitution would be invented). At the wall is fine.
pub(crate) fn check_start<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    initial: &State,
) -> Result<()> {
    initial.check_apart(model.clearance)
}

/// The work of the main damper `C` over the fixed-step kernel's equal steps
/// `dt`: the trapezoidal sum of `C w'^2`, from the kernel's sum of the squares
/// of `w'` at the step ends (`squares += w1'^2`, one multiply and one add a
/// step in the hot loop), with Euler-Maclaurin's end correction at each
/// check, so that it is fourth order wherever the motion is smooth.
pub(crate) struct DamperWork {
    damping: f64,
    dt: f64,
    /// `w'^2` at the start.
    start: f64,
    /// `w' w''` at the start, for the end correction.
    start_slope: f64,
}

impl DamperWork {
    /// From the start's main velocity and acceleration.
    pub(crate) fn new(damping: f64, dt: f64, velocity: f64, acceleration: f64) -> Self {
        Self {
            damping,
            dt,
            start: velocity * velocity,
            start_slope: velocity * acceleration,
        }
    }

    /// The work so far without the end correction, J, from the sum of
    /// squares and the main velocity now (for differences over a contact,
    /// where the correction is of the order of the contact's own quadrature
    /// error).
    #[inline(always)]
    pub(crate) fn so_far(&self, squares: f64, velocity: f64) -> f64 {
        // The trapezoidal sum: every square twice, less half of each end's.
        0.5 * self.damping * self.dt * (2.0 * squares - velocity * velocity + self.start)
    }

    /// The work so far, J, with the end correction, from the sum of squares
    /// and the main velocity and acceleration now.
    pub(crate) fn corrected(&self, squares: f64, velocity: f64, acceleration: f64) -> f64 {
        let correction = self.dt * self.dt / 6.0 * (velocity * acceleration - self.start_slope);
        self.so_far(squares, velocity) - self.damping * correction
    }
}

/// The integral of `w'^2` over the step `s0 -> s1` of length `h`, m^2/s:
/// exact for the step's cubic Hermite interpolant of `w`, whose velocity is
/// the quadratic through `w0'`, `(3/2)(w1 - w0)/h - (w0' + w1')/4` at
/// mid-step, and `w1'` (fourth order, from the step's end values alone).
#[inline(always)]
pub(crate) fn speed_squared_integral(h: f64, s0: &State, s1: &State) -> f64 {
    let (a, b) = (h * s0.main_velocity, h * s1.main_velocity);
    let m = 1.5 * (s1.main_displacement - s0.main_displacement) - 0.25 * (a + b);
    // h^2 times the integral of the quadratic's square over [0, 1].
    let squares = 2.0 * (a * a + b * b) + 8.0 * m * m + 2.0 * m * (a + b) - a * b;
    squares / (15.0 * h)
}

/// The external force's work over the step `s0 -> s1` of length `h` from
/// `time`, J: Simpson's rule on `F(t) w'(t)`, `w'` the velocity of the
/// step's cubic Hermite interpolant.
#[inline(always)]
pub(crate) fn external_work<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    time: f64,
    h: f64,
    s0: &State,
    s1: &State,
) -> f64 {
    if X::IS_FREE {
        return 0.0;
    }
    // Velocities times h at 0, 1/2 and 1.
    let (a, b) = (h * s0.main_velocity, h * s1.main_velocity);
    let m = 1.5 * (s1.main_displacement - s0.main_displacement) - 0.25 * (a + b);
    let f0 = model.external_force(time);
    let fm = model.external_force(time + 0.5 * h);
    let f1 = model.external_force(time + h);
    (f0 * a + 4.0 * fm * m + f1 * b) / 6.0
}

/// The energy bookkeeping of a run, shared by both kernels.
///
/// Checked every few steps: the mechanical energy now, plus the work of the
/// dissipative forces so far (the contact's, summed by the kernel, and the
/// main damper's, see [`DamperWork`]), minus the work of the external force,
/// must equal the energy at the start to within `tolerance` times the energy
/// in play (the energy at the start plus all the work done since). At each
/// separation the same balance must close over the contact alone: the
/// contact forces' net work (the energy change less the damper's and external
/// work) must be minus what they dissipate, never positive (a contact cannot
/// create energy; for two free bodies that is a restitution <= 1, but a main
/// spring can rightly give a larger rebound ratio, so the ratio itself is not
/// the test). An unforced system whose energy grows by half is a numerical
/// blow-up, as before.
pub(crate) struct EnergyLedger {
    /// Mechanical energy at the start, J.
    pub(crate) initial: f64,
    largest: f64,
    free: bool,
    tolerance: f64,
    /// The most a contact may create, relative (see
    /// [`Settings::contact_creation_limit`]).
    creation_limit: f64,
    /// Work of the external force so far, J.
    external: f64,
    /// Largest relative residual found.
    worst: f64,
}

impl EnergyLedger {
    pub(crate) fn new(initial: f64, free: bool, settings: &Settings) -> Self {
        Self {
            initial,
            largest: initial,
            free,
            tolerance: settings.energy_tolerance,
            creation_limit: settings.contact_creation_limit(),
            external: 0.0,
            worst: f64::NAN,
        }
    }

    /// Adds the external force's work over the step `s0 -> s1` of length `h`
    /// from `time`: Simpson's rule on `F(t) w'(t)`, `w'` the velocity of the
    /// step's cubic Hermite interpolant (nothing for an unforced system).
    #[inline(always)]
    pub(crate) fn external_step<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        time: f64,
        h: f64,
        s0: &State,
        s1: &State,
    ) {
        if !X::IS_FREE {
            self.external += external_work(model, time, h, s0, s1);
        }
    }

    /// The external force's work so far, J.
    #[inline(always)]
    pub(crate) fn external(&self) -> f64 {
        self.external
    }

    /// The first step count after `steps` at which a check is due (short of
    /// the last step's).
    #[inline(always)]
    pub(crate) fn next_due(&self, steps: u64) -> u64 {
        (steps / ENERGY_INTERVAL + 1) * ENERGY_INTERVAL
    }

    /// Whether to check at this many steps (every few steps, and at the end).
    #[inline(always)]
    pub(crate) fn due(&self, steps: u64, last: bool) -> bool {
        steps % ENERGY_INTERVAL == 0 || last
    }

    /// The balance with mechanical energy `energy` and the non-conservative
    /// work `losses` so far (J): the work of the dissipative forces (the
    /// contact's and the main damper's) less the external force's.
    pub(crate) fn check(&mut self, energy: f64, losses: f64, time: f64) -> Result<()> {
        if self.free {
            self.largest = self.largest.max(energy);
            if energy > ENERGY_GROWTH_LIMIT * self.initial {
                return Err(Error::NumericalBlowUp {
                    time,
                    reason: "the energy of the unforced system grew by more than 50 %",
                });
            }
        }
        let residual = energy + losses - self.initial;
        // The energy at the start, the dissipated work and the external work.
        let scale = self.initial + (losses + self.external) + self.external.abs();
        if scale > 0.0 {
            let ratio = residual.abs() / scale;
            // NaN (nothing found yet) gives way to any ratio.
            self.worst = self.worst.max(ratio);
            if ratio > self.tolerance || ratio.is_nan() {
                return Err(Error::EnergyBalance {
                    time,
                    residual,
                    scale,
                    tolerance: self.tolerance,
                });
            }
        }
        Ok(())
    }

    /// A closed contact's own balance: its energy change, plus the work of
    /// its dissipative forces, plus `work` (the main damper's minus the
    /// external force's work over the contact), is zero to within the
    /// tolerance of the energy in play (`energy` at onset and all that
    /// work). Positive, the contact created energy, which no raised
    /// tolerance admits beyond the creation limit (a rebound ratio above 1
    /// of two bodies alone is such a creation). Once per contact.
    pub(crate) fn check_contact(
        &self,
        record: &ContactRecord,
        energy: f64,
        work: f64,
    ) -> Result<()> {
        let residual = record.energy_change + record.energy_dissipated + work;
        let scale = energy + record.energy_dissipated + work.abs();
        let created = residual > self.creation_limit * scale;
        if created || residual.abs() > self.tolerance * scale || residual.is_nan() {
            return Err(Error::ContactEnergy {
                onset: record.onset,
                separation: record.separation,
                change: record.energy_change,
                dissipated: record.energy_dissipated,
                work,
                scale,
                restitution: record.restitution,
                tolerance: if created {
                    self.creation_limit
                } else {
                    self.tolerance
                },
                created: created && self.creation_limit < self.tolerance,
            });
        }
        Ok(())
    }

    /// `max(E) / E(0) - 1`; NaN when forced or starting at rest.
    pub(crate) fn growth(&self) -> f64 {
        if self.free && self.initial > 0.0 {
            self.largest / self.initial - 1.0
        } else {
            f64::NAN
        }
    }

    /// The largest relative residual found (NaN if nothing was in play).
    pub(crate) fn residual(&self) -> f64 {
        self.worst
    }
}

/// The record of a contact still open at the end of a run: no separation,
/// so no duration, rebound, restitution or energy change.
pub(crate) fn open_record(
    onset: f64,
    approach_speed: f64,
    max_indentation: f64,
    energy_dissipated: f64,
) -> ContactRecord {
    ContactRecord {
        onset,
        separation: f64::NAN,
        duration: f64::NAN,
        max_indentation,
        approach_speed,
        rebound_speed: f64::NAN,
        restitution: f64::NAN,
        energy_dissipated,
        energy_change: f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn contact() -> ContactRecord {
        ContactRecord {
            onset: 0.0,
            separation: 0.0,
            duration: 0.0,
            max_indentation: 0.0,
            approach_speed: 0.0,
            rebound_speed: 0.0,
            restitution: 0.0,
            energy_dissipated: 0.0,
            energy_change: 0.0,
        }
    }

    #[test]
    fn history_and_contacts_share_the_memory_limit() {
        crate::testing::timeout(60, || {
            // 1000 history rows' worth; a run that needs 60 % of it: 520
            // rows, then 50 contacts (72 bytes each). The history's growth
            // past 512 rows took all the room left, and the contacts, at
            // their first growth, found none.
            let limit = 1000 * ROW_BYTES;
            let mut records = Records::within(true, u64::MAX, limit);
            for step in 0..520 {
                records.keep(step as f64, &State::default(), 0.0).unwrap();
            }
            for _ in 0..50 {
                records.contact(contact(), 520.0).unwrap();
            }
            let held = records.history.held() + memory::held(&records.contacts);
            assert!(held <= limit, "{held} > {limit}");
            // Then it runs into the limit, and stops with the memory's error,
            // never holding more.
            let error = (600..100_000)
                .find_map(|step| records.keep(step as f64, &State::default(), 0.0).err())
                .unwrap();
            assert!(matches!(error, Error::MemoryLimit { .. }), "{error:?}");
            let held = records.history.held() + memory::held(&records.contacts);
            assert!(held <= limit && 2 * held >= limit, "{held} of {limit}");
        });
    }
}
