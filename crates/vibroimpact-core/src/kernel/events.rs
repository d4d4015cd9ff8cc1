//! The event-driven kernel for any [`Assembly`]: every interaction's gap is
//! watched at once, the earliest event in a step is located on the method's
//! own solution (the step length that ends on it, by the Illinois method),
//! the step is cut there and the method restarted.
//!
//! Events: a gap closing (a compliant contact starts, or a rigid impact
//! applies Newton's law with momentum conserved), a compliant contact
//! opening, and a sticking pair's constraint force reaching zero (release).
//! Every pair past its wall or arriving on it at the instant switches; the
//! rigid ones are resolved together, impacts, chattering sums and sticking,
//! by [`crate::kernel::impacts`].
//!
//! The kernel by concern: this driver and the run's types; the run's state
//! and its step ([`crate::kernel::run`]), which says why it ended
//! ([`crate::kernel::clock::Stop`], by the stop rules the fast path
//! [`crate::kernel::compact`] shares); where an event lies
//! ([`crate::kernel::locate`]); contacts at events
//! ([`crate::kernel::contacts`]); records and checks after each step
//! ([`crate::kernel::records`]).

use crate::error::{at_least_one, Error, Result};
pub use crate::kernel::balance::EnergyBalance;
use crate::kernel::clock::Stop;
use crate::kernel::contact_balance::OnsetBalance;
use crate::kernel::memory::MAX_RECORD_BYTES;
use crate::kernel::observe::{EventObserver, Watch};
use crate::kernel::reductions::{ReduceOptions, Reductions};
use crate::kernel::run::Run;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::Assembly;

/// How to run and what to keep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunOptions {
    /// Step (s): fixed for RK4, the first step of the adaptive methods.
    pub dt: Option<f64>,
    /// End time, s.
    pub t_end: f64,
    /// Keep every `every`-th step (and the last).
    pub every: u64,
    /// Keep no history at all when false (constant memory but the contacts).
    pub keep_history: bool,
    /// Most steps (accepted and rejected).
    pub max_steps: u64,
    /// Most history rows plus contacts a run may keep.
    pub max_rows: u64,
    /// Largest energy-balance residual, relative to the energies in play.
    pub energy_tolerance: f64,
    /// Peaks, mean squares and stroboscopic states to keep.
    pub reduce: ReduceOptions,
}

impl RunOptions {
    /// Refuses options no run can take, naming the field (the registry's
    /// ranges: [`crate::methods::registry`]): `t_end` finite and > 0, `dt`
    /// (where given) finite and > 0, `every` and `max_steps` at least 1,
    /// `energy_tolerance` in (0, 1]; `record_from` >= 0 and `strobe_period`
    /// > 0 (each infinite: none), `contacts_from` not NaN.
    pub fn check(&self) -> Result<()> {
        use crate::methods::registry::{DT, ENERGY_TOLERANCE, RECORD_FROM, STROBE_PERIOD, T_END};
        T_END.check(self.t_end)?;
        if let Some(dt) = self.dt {
            DT.check(dt)?;
        }
        ENERGY_TOLERANCE.check(self.energy_tolerance)?;
        at_least_one("every", self.every)?;
        at_least_one("max_steps", self.max_steps)?;
        // Infinite: no record window, no strobe; any other value in the registry's range.
        let reduce = &self.reduce;
        if reduce.record_from != f64::INFINITY {
            RECORD_FROM.check(reduce.record_from)?;
        }
        if reduce.strobe_period != f64::INFINITY {
            STROBE_PERIOD.check(reduce.strobe_period)?;
        }
        if reduce.contacts_from.is_nan() {
            return Err(Error::InvalidParameter {
                field: "contacts_from",
                allowed: "a time in s, not NaN",
                value: reduce.contacts_from,
            });
        }
        Ok(())
    }
}

/// How a run steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Stepping {
    /// Steps cut at every event, located on the method's own solution.
    #[default]
    Events,
    /// Steps of `dt` not cut at contacts (0.1's and the founding paper's),
    /// for fixed-step methods and compliant laws only: see
    /// [`crate::kernel::fixed`].
    Fixed { contact_timing: ContactTiming },
}

/// How a fixed-step run times a contact's onset and separation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ContactTiming {
    /// Where the cubic Hermite interpolant of the indentation crosses zero
    /// within the step.
    #[default]
    Located,
    /// In whole steps, as the founding paper counted them.
    StepCount,
}

impl Stepping {
    pub const NAMES: &'static str = "\"events\", \"fixed\"";

    /// The stepping named by `[solver] stepping` and `contact_timing`.
    pub fn parse(stepping: &str, contact_timing: &str) -> Result<Self> {
        let contact_timing = ContactTiming::parse(contact_timing)?;
        match stepping {
            "events" if contact_timing == ContactTiming::Located => Ok(Self::Events),
            "events" => Err(Error::Inconsistent(
                "contact_timing \"step-count\" needs stepping \"fixed\": with events the \
                 contact instants are located"
                    .into(),
            )),
            "fixed" => Ok(Self::Fixed { contact_timing }),
            other => Err(Error::UnknownChoice {
                field: "stepping",
                allowed: Self::NAMES,
                value: other.to_string(),
            }),
        }
    }
}

impl ContactTiming {
    pub const NAMES: &'static str = "\"located\", \"step-count\"";

    /// The timing named by `[solver] contact_timing`.
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "located" => Ok(Self::Located),
            "step-count" => Ok(Self::StepCount),
            _ => Err(Error::UnknownChoice {
                field: "contact_timing",
                allowed: Self::NAMES,
                value: name.to_string(),
            }),
        }
    }
}

/// What kind of contact a record is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactKind {
    /// A compliant contact, from onset to separation.
    Compliant,
    /// A rigid impact: zero duration.
    Impact,
    /// A rigid pair moving together, from the accumulation instant of its
    /// chattering sequence to its release.
    Sticking,
}

impl ContactKind {
    pub fn name(self) -> &'static str {
        match self {
            Self::Compliant => "compliant",
            Self::Impact => "impact",
            Self::Sticking => "sticking",
        }
    }
}

/// One contact of one pair. Speeds are relative normal speeds (m/s, > 0);
/// NaN separation, duration and rebound for a contact still open at the end.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PairContact {
    /// Index into [`Assembly::pairs`].
    pub pair: usize,
    pub kind: ContactKind,
    /// s.
    pub onset: f64,
    /// s.
    pub separation: f64,
    /// s.
    pub duration: f64,
    /// m (0 for rigid pairs).
    pub max_indentation: f64,
    pub approach_speed: f64,
    pub rebound_speed: f64,
    /// rebound over approach speed.
    pub restitution: f64,
    /// Energy taken by the contact's dissipative forces or by the impacts, J.
    pub energy_dissipated: f64,
    /// Net change of the whole system's stored mechanical energy (kinetic,
    /// elastic, gravity's and the contacts' elastic energy) over the contact,
    /// at separation minus at onset, J: `-energy_dissipated` for a contact
    /// with no other damper or force acting (to the method's accuracy); with
    /// them it also holds their work during the contact. An impact's is its
    /// kinetic energy lost, negated; NaN for a contact still open at the end
    /// and for a sticking pair's record.
    pub energy_change: f64,
}

impl PairContact {
    /// Whether the contact began in the run at or after `from` (s, >= 0):
    /// not one carried from the run before (its onset < 0) nor one in
    /// progress at the run's start whose onset no run gave (-0.0).
    pub fn begun_from(&self, from: f64) -> bool {
        self.onset >= from && self.onset.is_sign_positive()
    }
}

/// A compliant contact open at a run's end, carried into a run continued
/// from its final state: what the state `(x, v)` alone does not hold (a
/// damped law's latched approach rate, the contact's onset), without which
/// the continued run would begin the contact afresh (counted twice, a
/// Hunt-Crossley force latched at the indentation rate of mid-contact).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CarriedContact {
    /// The law's latched approach rate, m/s (> 0).
    pub approach_rate: f64,
    /// The onset, s, in the continued run's time (<= 0).
    pub onset: f64,
    /// The approach speed at the onset, m/s.
    pub approach_speed: f64,
    /// The deepest indentation so far, m.
    pub max_indentation: f64,
}

impl CarriedContact {
    /// Refuses carried contacts no run of `count` interactions could have
    /// left: one per interaction (or none), each as [`Self::check`].
    pub fn check_all(carried: &[Option<Self>], count: usize) -> Result<()> {
        if !carried.is_empty() && carried.len() != count {
            return Err(Error::Inconsistent(format!(
                "the carried contacts must be one per interaction ({count}), got {}",
                carried.len()
            )));
        }
        for (i, contact) in carried.iter().enumerate() {
            contact.map(|c| c.check(i)).transpose()?;
        }
        Ok(())
    }

    /// Refuses a carried contact no run could have left, naming its
    /// interaction `i`.
    pub fn check(&self, i: usize) -> Result<()> {
        let fine = self.approach_rate.is_finite()
            && self.approach_rate > 0.0
            && self.onset.is_finite()
            && self.onset <= 0.0
            && self.approach_speed.is_finite()
            && self.approach_speed >= 0.0
            && self.max_indentation.is_finite()
            && self.max_indentation >= 0.0;
        if fine {
            return Ok(());
        }
        Err(Error::Inconsistent(format!(
            "carried contact {i}: approach_rate must be finite and > 0, onset finite and <= 0 s, \
             approach_speed and max_indentation finite and >= 0, got {self:?}"
        )))
    }
}

/// What a run returns.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemSolution {
    /// Times of the kept rows, s.
    pub time: Vec<f64>,
    /// Kept rows of `x` then `v` (`2 dim` values each).
    pub states: Vec<f64>,
    pub contacts: Vec<PairContact>,
    /// `x` then `v` at the end.
    pub final_state: Vec<f64>,
    pub final_time: f64,
    pub energy: EnergyBalance,
    /// Largest relative growth of an unforced system's stored energy,
    /// `max(E) / E(0) - 1` over the start, the balance checks (every 32
    /// steps, and sampled between) and the end; NaN when forced or starting
    /// with no energy. Physically it is 0: more is numerical error.
    pub energy_growth: f64,
    /// Largest residual of the energy balance the checks found, relative to
    /// the energy in play; NaN when none was checked.
    pub energy_residual: f64,
    pub steps: u64,
    pub rejected_steps: u64,
    pub rhs_evaluations: u64,
    pub grazing_contacts: u64,
    pub reductions: Reductions,
    /// Indices into [`Assembly::pairs`] of the pairs with a compliant wall,
    /// in order: the columns of `contact_forces`.
    pub contact_force_pairs: Vec<usize>,
    /// At each kept row, the force of each pair of `contact_force_pairs`
    /// (its law's and its contact damper's, N, > 0 pushing it apart; 0
    /// apart), row after row.
    pub contact_forces: Vec<f64>,
    /// Per interaction, its compliant contact still open at the end, onset
    /// in this run's time (shift it by `-final_time` to continue a run from
    /// `final_state`: [`integrate_system_continued`]); None where open.
    pub open_contacts: Vec<Option<CarriedContact>>,
}

impl SystemSolution {
    /// [`Self::open_contacts`], their onsets in the time of a run continued
    /// from [`Self::final_state`] (shifted by `-final_time`).
    pub fn carried(&self) -> Vec<Option<CarriedContact>> {
        let shift = |c: CarriedContact| CarriedContact {
            onset: c.onset - self.final_time,
            ..c
        };
        self.open_contacts.iter().map(|c| c.map(shift)).collect()
    }
}

/// A contact being followed.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Open {
    pub(crate) kind: ContactKind,
    pub(crate) onset: f64,
    pub(crate) approach_speed: f64,
    pub(crate) max_indentation: f64,
    /// The contact-loss accumulator at onset (compliant), or the loss so far.
    pub(crate) dissipated: f64,
    /// Started at rest (an approach at round-off): no rebound ratio.
    pub(crate) resting: bool,
    /// The run's balance at a compliant onset (see [`OnsetBalance`]).
    pub(crate) balance: OnsetBalance,
    /// Fixed stepping: the stored energy at the onset (J) and the power of
    /// the contact's dissipative forces at the last step's end (W).
    pub(crate) energy: f64,
    pub(crate) power: f64,
}

impl Open {
    /// The record of this contact ending at `separation` (NaN: still open)
    /// with relative `rebound` speed (m/s) and `dissipated` energy (J).
    pub(crate) fn close(
        &self,
        pair: usize,
        separation: f64,
        rebound: f64,
        dissipated: f64,
    ) -> PairContact {
        let restitution = match self.kind {
            // A contact that started at rest was never an impact: its
            // rebound over a round-off approach would be any number (1e58),
            // and a friction stick (its approach 0, the slip ended) none.
            _ if self.resting || self.approach_speed <= 0.0 => f64::NAN,
            // A sticking pair that arrived does not rebound.
            ContactKind::Sticking if separation.is_finite() => 0.0,
            _ => rebound / self.approach_speed,
        };
        // A summed sequence's accumulation instant lies up to the resolution
        // after the impact where it was summed: a release before it ends
        // the sticking there, with no duration.
        let onset = if separation < self.onset {
            separation
        } else {
            self.onset
        };
        PairContact {
            pair,
            kind: self.kind,
            onset,
            separation,
            // Still open: NaN (f64::max would turn it into 0).
            duration: if separation.is_nan() {
                f64::NAN
            } else {
                separation - onset
            },
            max_indentation: self.max_indentation,
            approach_speed: self.approach_speed,
            rebound_speed: rebound,
            restitution,
            energy_dissipated: dissipated,
            energy_change: f64::NAN,
        }
    }
}

/// The run's steps, each cut at the earliest event it shows, to `t_end`:
/// one loop for the plain and the observed run, written in place in each (a
/// function, called out of line or inlined from there, had made the plain
/// runs' event handling slower: the events study of bench_lockstep.py
/// 0.40 -> 0.44-0.48 s).
macro_rules! by_events {
    ($run:ident, $stepper:ident, $interrupt:ident, $t_end:expr) => {
        by_events!($run, $stepper, $interrupt, $t_end, false)
    };
    // `$steps`: whether an observer is shown each step (`false` in a plain
    // run, where the check is compiled out).
    ($run:ident, $stepper:ident, $interrupt:ident, $t_end:expr, $steps:expr) => {
        while $run.clock.time < $t_end {
            // Plain steps in a row, where the stepper takes them at once (each
            // as the kernel's step would, to the bit); the step after them is
            // the kernel's.
            if $run.stretches && $run.clock.accepted > 0 && $run.fast_steps($stepper, $interrupt)? {
                continue;
            }
            if $steps {
                $run.watch_step_start();
            }
            let stop = $run.step($stepper)?;
            if $steps && !matches!(stop, Stop::End | Stop::Retry) {
                $run.watch_step()?;
            }
            match stop {
                Stop::End => break,
                Stop::Retry => continue,
                Stop::Event { interaction } => $run.at_event($stepper, interaction)?,
                Stop::Step | Stop::RecordWindow | Stop::Strobe => {}
            }
            $run.after_step(stop, $interrupt)?;
        }
    };
}

/// Integrates `system` from `initial` (see [`crate::model::assembly::initial_state`]).
pub fn integrate_system<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    initial: &[f64],
    options: &RunOptions,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<SystemSolution> {
    integrate_system_within(
        system,
        stepper,
        initial,
        options,
        interrupt,
        MAX_RECORD_BYTES,
    )
}

/// [`integrate_system`] with its records (history, stroboscopic states,
/// contacts) kept within `record_limit` bytes instead of
/// [`MAX_RECORD_BYTES`]: a run that would pass it stops with
/// [`crate::Error::MemoryLimit`].
pub fn integrate_system_within<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    initial: &[f64],
    options: &RunOptions,
    interrupt: &mut dyn FnMut() -> bool,
    record_limit: u64,
) -> Result<SystemSolution> {
    let stepping = Stepping::Events;
    integrate_system_stepped(
        system,
        stepper,
        initial,
        options,
        stepping,
        interrupt,
        record_limit,
    )
}

/// [`integrate_system_within`] stepping as `stepping` says: cut at events,
/// or in fixed steps (see [`crate::kernel::fixed`]; a rigid pair or an
/// adaptive or exact method is then refused, naming `stepping`).
pub fn integrate_system_stepped<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    initial: &[f64],
    options: &RunOptions,
    stepping: Stepping,
    interrupt: &mut dyn FnMut() -> bool,
    record_limit: u64,
) -> Result<SystemSolution> {
    let carried = &[];
    integrate_system_continued(
        system,
        stepper,
        (initial, carried),
        options,
        stepping,
        interrupt,
        record_limit,
    )
}

/// [`integrate_system_stepped`] continuing another run from its final
/// state, the compliant contacts it left open `carried` (per interaction,
/// or empty for none: see [`SystemSolution::open_contacts`]).
pub fn integrate_system_continued<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    (initial, carried): (&[f64], &[Option<CarriedContact>]),
    options: &RunOptions,
    stepping: Stepping,
    interrupt: &mut dyn FnMut() -> bool,
    record_limit: u64,
) -> Result<SystemSolution> {
    let start = (initial, carried);
    let mut run = Run::new(system, stepper, start, options, stepping, record_limit)?;
    if run.timing.is_some() {
        while run.clock.time < options.t_end {
            if run.stretches && run.clock.accepted > 0 && run.fast_steps(stepper, interrupt)? {
                continue;
            }
            let stop = run.fixed_step(stepper)?;
            if stop == Stop::End {
                break;
            }
            run.after_step(stop, interrupt)?;
        }
        return Ok(run.finish(stepper));
    }
    by_events!(run, stepper, interrupt, options.t_end);
    Ok(run.finish(stepper))
}

/// [`integrate_system_within`] from `start` (the initial state and the
/// contacts carried, as [`integrate_system_continued`]'s) with `observer`
/// told of the run's start, of each event (the states and modes either side, the rigid pairs' jumps)
/// and of its end: what the tangent flow is made of
/// ([`crate::kernel::observe`]). Steps are cut at events.
pub fn integrate_system_observed<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    start: (&[f64], &[Option<CarriedContact>]),
    options: &RunOptions,
    interrupt: &mut dyn FnMut() -> bool,
    record_limit: u64,
    observer: &mut dyn EventObserver,
) -> Result<SystemSolution> {
    let stepping = Stepping::Events;
    let mut run = Run::new(system, stepper, start, options, stepping, record_limit)?;
    let (dim, count) = (system.dim, system.interactions.len());
    observer.start(run.clock.time, &run.y[..2 * dim], &run.modes)?;
    let steps = observer.wants_steps();
    // Each step the kernel's own, for the observer to be shown.
    run.stretches &= !steps;
    run.watch = Some(Watch::new(observer, dim, count));
    // The loop written for each (a literal: an observer without steps pays
    // no check per step).
    if steps {
        by_events!(run, stepper, interrupt, options.t_end, true);
    } else {
        by_events!(run, stepper, interrupt, options.t_end, false);
    }
    if let Some(watch) = run.watch.take() {
        watch
            .observer
            .finish(run.clock.time, &run.y[..2 * dim], &run.modes)?;
    }
    Ok(run.finish(stepper))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stepping_names_parse_to_the_kernel_stepping_and_wrong_ones_are_refused() {
        crate::testing::timeout(10, || {
            assert_eq!(Stepping::parse("events", "located"), Ok(Stepping::Events));
            assert_eq!(
                Stepping::parse("fixed", "step-count"),
                Ok(Stepping::Fixed {
                    contact_timing: ContactTiming::StepCount
                })
            );
            // Events locate every instant: counting whole steps contradicts them.
            assert!(matches!(
                Stepping::parse("events", "step-count"),
                Err(Error::Inconsistent(_))
            ));
            let wrong = Stepping::parse("fixd", "located").unwrap_err().to_string();
            assert_eq!(
                wrong,
                "stepping must be one of \"events\", \"fixed\", got \"fixd\""
            );
            let wrong = ContactTiming::parse("counted").unwrap_err().to_string();
            assert!(
                wrong.starts_with("contact_timing must be one of"),
                "{wrong}"
            );
        });
    }
}
