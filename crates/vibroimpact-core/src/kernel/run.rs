//! The event kernel's state and its step: [`Run::step`] takes one step
//! (cut at the earliest event it shows, located on the method's own
//! solution) and says why it ended ([`Stop`]); the driver
//! ([`crate::kernel::events::integrate_system_within`]) loops on it.

use crate::error::{Error, Result};
use crate::kernel::balance::{EnergyWatch, ENERGY_INTERVAL};
use crate::kernel::clock::{Clock, Schedule, Stop};
use crate::kernel::compact::Stretch;
use crate::kernel::contact_balance::OnsetBalance;
use crate::kernel::events::{ContactTiming, Open, PairContact, RunOptions};
use crate::kernel::fixed::Change;
use crate::kernel::held::Probe;
use crate::kernel::impacts::{Impacts, Squeeze};
use crate::kernel::locate::{
    event_value_from, find_crossing, locate, may_cross, past, Buffers, Crossing, Gaps, Location,
};
use crate::kernel::observe::Watch;
use crate::kernel::reductions::{reduce_step, Reductions};
use crate::methods::step_control::{rejects, StepControl};
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, Mode, Scratch, CONTACT};

/// Whether the caller is asked whether to stop after `accepted` steps, every
/// `poll_every` (a mask where that is a power of two, as for every system of
/// up to `TIMED_POLLS_BEYOND` (kernel::start) coordinates: a division each kernel step
/// cost more than the rest of the checks).
#[inline(always)]
pub(super) fn poll_due(accepted: u64, poll_every: u64) -> bool {
    if poll_every.is_power_of_two() {
        accepted & (poll_every - 1) == 0
    } else {
        accepted % poll_every == 0
    }
}

/// The contact-loss accumulator of interaction `i` in a state vector.
#[inline(always)]
pub(super) fn loss_slot(system: &Assembly, i: usize) -> usize {
    2 * system.dim + CONTACT + i
}

/// A run in progress.
pub(super) struct Run<'a> {
    pub(super) system: &'a Assembly,
    pub(super) options: &'a RunOptions,
    /// Bytes the records may hold.
    pub(super) record_limit: u64,
    pub(super) schedule: Schedule,
    pub(super) clock: Clock,
    /// An interior touch shallower than this is a graze, m.
    pub(super) graze: f64,
    /// The time below which a chattering sequence is summed, s.
    pub(super) resolution: f64,
    /// The state, an attempt's end and the full step's end.
    pub(super) y: Vec<f64>,
    pub(super) end: Vec<f64>,
    pub(super) full: Vec<f64>,
    pub(super) buffers: Buffers,
    pub(super) scratch: Scratch,
    /// The reductions evaluate with their own: the signals' values the
    /// steps cache (a harmonic's rotated phasor) are then the same bits
    /// whatever is reduced (a peak differed in its last bit with the RMS
    /// kept or not). A fixed step's reductions copy the steps' caches into
    /// it ([`Scratch::signals_from`]), which leaves those as they were.
    pub(super) reduce_scratch: Scratch,
    pub(super) modes: Vec<Mode>,
    /// The contact each interaction is in, if any.
    pub(super) open: Vec<Option<Open>>,
    pub(super) gaps: Gaps,
    pub(super) energy: EnergyWatch,
    pub(super) contacts: Vec<PairContact>,
    /// The history: times and rows of `x` then `v`.
    pub(super) time_rows: Vec<f64>,
    pub(super) states: Vec<f64>,
    pub(super) reductions: Reductions,
    pub(super) control: StepControl,
    pub(super) grazes: u64,
    /// The last kept step's length, s.
    pub(super) taken: f64,
    pub(super) last_event: f64,
    pub(super) close_events: u64,
    /// The rigid events watched for an inelastic collapse.
    pub(super) squeeze: Squeeze,
    pub(super) stalled: u64,
    /// Interactions whose dip in this step was checked and stays open.
    pub(super) unconfirmed: Vec<bool>,
    pub(super) any_unconfirmed: bool,
    /// Interactions switched at the event being handled.
    pub(super) just_switched: Vec<bool>,
    /// Open pairs on their walls at the start and not leaving them: their
    /// first events within the resolution are at t = 0.
    pub(super) on_wall_at_start: Vec<bool>,
    pub(super) impacts: Impacts,
    /// Whether a compliant contact is on (modes change only at events).
    pub(super) compliant: bool,
    /// Whether any friction element acts (its modes settle after events).
    pub(super) friction: bool,
    /// Whether the signals have kinks (samples) to land on.
    pub(super) kinked: bool,
    /// Whether plain fixed steps go to the stepper's fast path.
    pub(super) stretches: bool,
    pub(super) poll_every: u64,
    pub(super) timed_polls: bool,
    pub(super) last_poll: std::time::Instant,
    /// Fixed stepping's timing of contacts (None: stepping by events).
    pub(super) timing: Option<ContactTiming>,
    /// The fixed step that must resolve each compliant contact (None for an
    /// adaptive method or the exact flow), s.
    pub(super) contact_step: Option<f64>,
    /// Whether the method creates energy at contacts by construction (see
    /// [`SystemStepper::creates_contact_energy`]).
    pub(super) creates_contact_energy: bool,
    /// Fixed stepping: each interaction's contact change in the last step,
    /// and the onset balance of each contact it ended.
    pub(super) changes: Vec<Option<Change>>,
    pub(super) closing: Vec<Option<OnsetBalance>>,
    /// Every compliant interaction in contact: the modes whose stored
    /// energy counts each indented pair's elastic energy.
    pub(super) all_compliant: Vec<Mode>,
    /// The pairs with a compliant wall, and their forces at each kept row.
    pub(super) force_pairs: Vec<usize>,
    pub(super) contact_forces: Vec<f64>,
    /// History rows the first growth makes room for (see `first_rows` in kernel::start).
    pub(super) first_rows: usize,
    /// The observer told of each event, with what it is shown (see
    /// [`crate::kernel::observe`]); None for a plain run.
    pub(super) watch: Option<Watch<'a>>,
}

impl<'a> Run<'a> {
    /// The next step's length and the landing that bounds it
    /// ([`Stop::Step`] where none does), or why no step is taken.
    #[inline(always)]
    fn next_length<S: SystemStepper>(
        &mut self,
        stepper: &mut S,
    ) -> Result<std::result::Result<(f64, Stop), Stop>> {
        let (system, schedule) = (self.system, self.schedule);
        let (adaptive, time, t_end) = (schedule.adaptive, self.clock.time, schedule.t_end);
        if schedule.at_end(time) {
            return Ok(Err(Stop::End));
        }
        let mut length = if adaptive {
            self.control.h.min(t_end - time)
        } else {
            schedule.grid_length(&self.clock).min(stepper.step_limit(
                system,
                time,
                &self.y,
                &self.modes,
                &mut self.scratch,
            )?)
        };
        if !adaptive && length <= 0.0 {
            self.clock.grid += 1;
            return Ok(Err(Stop::Retry));
        }
        if adaptive {
            length = self.adaptive_length(stepper, length);
        }
        let mut bound = Stop::Step;
        if schedule.lands_on_window(time, length) {
            length = schedule.record_from - time;
            bound = Stop::RecordWindow;
        }
        if schedule.lands_on_strobe(&self.clock, time, length) {
            length = self.clock.next_strobe - time;
            bound = Stop::Strobe;
        }
        Ok(Ok((length, bound)))
    }

    /// An adaptive method's `length` shortened where the system asks it.
    fn adaptive_length<S: SystemStepper>(&mut self, stepper: &mut S, mut length: f64) -> f64 {
        let (system, time, t_end) = (self.system, self.clock.time, self.schedule.t_end);
        let d = system.dim;
        if (t_end - time - length) < 1e-3 * length {
            length = t_end - time;
        }
        let modes = &self.modes;
        if modes.contains(&Mode::Open) {
            // A step that passes over a short flight (a rebound that lands and
            // leaves again within it) shows the gap open at both ends, and a
            // smooth flight gives the error control no reason to shorten it:
            // end it a little after each open gap's parabola lands, no sooner
            // than the resolution (shorter flights are a chattering sequence).
            if let Some(rates) =
                stepper.start_rates(system, time, &self.y, modes, &mut self.scratch)
            {
                for (i, mode) in modes.iter().enumerate() {
                    if *mode != Mode::Open || system.held_by_mirror(i, modes) {
                        continue;
                    }
                    if let Some(hit) = system.landing_time(i, &self.y, &rates[d..2 * d]) {
                        length = length.min((1.5 * hit).max(self.resolution));
                    }
                }
            }
        }
        if modes.iter().any(Mode::is_held) {
            // A sticking pair's release shows only as its constraint force
            // at a step's end: steps short enough not to pass over it.
            length = length.min(system.sticking_step);
        }
        if self.kinked {
            // Land on the signals' next kink (their samples).
            length = length.min(system.next_breakpoint(time) - time);
        }
        length
    }

    /// One step: attempted, cut at the earliest event it shows, judged,
    /// reduced and kept; why it ended. Inlined where the run loops (the plain
    /// run and the observed one): out of line it had made the events study
    /// of bench_lockstep.py 10 % slower.
    #[inline(always)]
    pub(super) fn step<S: SystemStepper>(&mut self, stepper: &mut S) -> Result<Stop> {
        let (length, bound) = match self.next_length(stepper)? {
            Ok(next) => next,
            Err(stop) => return Ok(stop),
        };
        let (system, time) = (self.system, self.clock.time);
        let error = stepper.attempt(
            system,
            time,
            &self.y,
            length,
            &self.modes,
            &mut self.scratch,
            &mut self.end,
        )?;
        system.gaps(&self.end, &mut self.gaps.end);
        let Some((taken, switched, mut kept_attempt)) =
            self.cut_at_event(stepper, length, error)?
        else {
            return Ok(Stop::Retry);
        };
        let (adaptive, t_end) = (self.schedule.adaptive, self.schedule.t_end);
        if adaptive
            && switched.is_none()
            && !self.control.judge(
                error,
                taken,
                |e| stepper.shrink(e),
                true,
                time,
                t_end,
                self.clock.accepted,
                self.options.max_steps,
            )?
        {
            return Ok(Stop::Retry);
        }
        let row = 2 * system.dim;
        // v * 0 is 0 for a finite v, NaN otherwise: one sum tells (and
        // does not branch on every value).
        if self.end[..row].iter().fold(0.0, |sum, v| sum + v * 0.0) != 0.0 {
            return Err(Error::NumericalBlowUp {
                time: time + taken,
                reason: "the state is no longer finite",
            });
        }
        let mut probed = self.compliant && self.deepest_indentation(stepper, taken)?;
        probed |= self.reduce(stepper, taken, false)?;
        if probed && kept_attempt {
            if stepper.carries_solution() {
                // The probes replaced the stepper's pending data: the kept
                // step again, the same arithmetic, restores them.
                let again = &mut self.buffers.probe;
                stepper.attempt(
                    system,
                    time,
                    &self.y,
                    taken,
                    &self.modes,
                    &mut self.scratch,
                    again,
                )?;
                debug_assert!(again[..row] == self.end[..row]);
            } else {
                kept_attempt = false;
            }
        }
        self.keep(stepper, taken, switched.is_some(), kept_attempt)?;
        Ok(match switched {
            Some(interaction) => Stop::Event { interaction },
            None => bound,
        })
    }

    /// The attempt `y -> end` of `length` (its scaled `error`), cut at the
    /// earliest event it shows: the step taken, the interaction whose event
    /// ends it and whether the stepper's last attempt is that step; None
    /// where it is to be tried again (shorter).
    fn cut_at_event<S: SystemStepper>(
        &mut self,
        stepper: &mut S,
        length: f64,
        error: f64,
    ) -> Result<Option<(f64, Option<usize>, bool)>> {
        let (system, time, adaptive) = (self.system, self.clock.time, self.schedule.adaptive);
        let count = self.modes.len();
        let mut full_error = error;
        let mut taken = length;
        let mut switched: Option<usize> = None;
        let mut kept_attempt = true;
        if self.any_unconfirmed {
            self.unconfirmed.iter_mut().for_each(|u| *u = false);
            self.any_unconfirmed = false;
        }
        let mut crossing = if may_cross(&self.gaps, &self.modes) {
            self.find_crossing(taken, &mut 0, true)
        } else {
            None
        };
        // An event inside the step: locate it; another interaction that
        // turns out to have crossed before it is located in its turn.
        let mut rounds = 0;
        while let Some(c) = crossing {
            rounds += 1;
            self.full.copy_from_slice(&self.end);
            let location = locate(
                system,
                stepper,
                time,
                &self.y,
                taken,
                &self.full,
                full_error,
                &self.modes,
                (c, self.graze),
                &mut self.scratch,
                &mut self.buffers,
            )?;
            match location {
                // A step that straddled an event may have been accepted for
                // an error measured across it; the cut step must pass too.
                Location::Cut(cut, cut_error) if adaptive && rejects(cut_error) => {
                    self.control.retry(0.5 * cut);
                    return Ok(None);
                }
                Location::Cut(cut, cut_error) => {
                    taken = cut;
                    full_error = cut_error;
                    switched = Some(c.i);
                    kept_attempt = false;
                    self.end.copy_from_slice(&self.buffers.best);
                    system.gaps(&self.end, &mut self.gaps.end);
                }
                Location::Unconfirmed | Location::Graze => {
                    if matches!(location, Location::Graze) {
                        self.grazes += 1;
                    }
                    kept_attempt = false;
                    if switched.is_none() {
                        // That dip stays above its wall (or grazes it): another pair may
                        // still cross within the step.
                        self.unconfirmed[c.i] = true;
                        self.any_unconfirmed = true;
                        crossing = self.find_crossing(taken, &mut 0, false);
                        continue;
                    }
                }
                Location::Reject(shorter) => {
                    self.control.retry(0.9 * shorter);
                    return Ok(None);
                }
            }
            if rounds > count {
                break;
            }
            crossing = self.crossed_before(switched, time + taken);
        }
        Ok(Some((taken, switched, kept_attempt)))
    }

    /// [`find_crossing`] in the attempt `y -> end` of length `h`, its grazes
    /// counted where `count_grazes` (else into `uncounted`).
    fn find_crossing(
        &mut self,
        h: f64,
        uncounted: &mut u64,
        count_grazes: bool,
    ) -> Option<Crossing> {
        let grazes = if count_grazes {
            &mut self.grazes
        } else {
            uncounted
        };
        find_crossing(
            self.system,
            self.clock.time,
            &self.gaps,
            (&self.y, &self.end),
            h,
            &self.modes,
            self.graze,
            grazes,
            &mut self.scratch,
            (
                &mut self.buffers.work,
                Probe {
                    shifted: &mut self.buffers.shifted,
                    rates: &mut self.buffers.rates,
                    scratch: &mut self.buffers.held,
                    forces: &mut self.buffers.forces,
                },
            ),
            &self.unconfirmed,
        )
    }

    /// Another interaction than `switched` on its new side at the cut `end`
    /// (at `at`): it came first. One on its wall to round-off (the located
    /// pair's simultaneous partner, or a pair at rest on its wall) switches
    /// with it, and must not hide one that crossed earlier behind it.
    fn crossed_before(&mut self, switched: Option<usize>, at: f64) -> Option<Crossing> {
        let system = self.system;
        for (j, &mode) in self.modes.iter().enumerate() {
            if Some(j) == switched || system.held_by_mirror(j, &self.modes) {
                continue;
            }
            // `gaps.end` holds the cut end's gaps.
            let v = event_value_from(
                system,
                j,
                mode,
                self.gaps.end[j],
                at,
                &self.end,
                &self.modes,
                &mut self.scratch,
                &mut self.buffers.work,
            );
            if past(system, j, mode, v, &self.end) {
                return Some(Crossing {
                    i: j,
                    guess: 1.0,
                    interior: false,
                    before: 0.0,
                    root: f64::NAN,
                });
            }
        }
        None
    }

    /// Keep the step of `taken` s whose end is in `end` (an event's where
    /// `event`; the stepper's last attempt where `kept_attempt`).
    fn keep<S: SystemStepper>(
        &mut self,
        stepper: &mut S,
        taken: f64,
        event: bool,
        kept_attempt: bool,
    ) -> Result<()> {
        let (system, schedule, time) = (self.system, self.schedule, self.clock.time);
        if kept_attempt {
            stepper.accept();
        } else {
            stepper.reset();
        }
        // The energy accumulators are read at an event, at a balance check
        // and at the end; in between a stepper may leave them to a later step.
        let next = time + taken;
        let settle = event
            || (self.clock.accepted + 1) % ENERGY_INTERVAL == 0
            || next >= schedule.t_end
            || schedule.at_end(next);
        stepper.finish(
            system,
            time,
            &self.y,
            taken,
            &self.modes,
            &mut self.scratch,
            &mut self.end,
            settle,
        )?;
        self.clock.time += taken;
        if schedule.at_end(self.clock.time) {
            // On t_end to the grid's round-off: the run ends there, at t_end itself
            // (the exact flow's last step had ended 2e-15 s short of it, the time a
            // run and its history reported).
            self.clock.time = schedule.t_end;
        }
        if !schedule.adaptive
            && (!event || (self.clock.grid + 1) as f64 * schedule.dt - self.clock.time <= 0.0)
        {
            self.clock.grid += 1;
        }
        // The attempt is overwritten by the next one: the buffers trade places.
        std::mem::swap(&mut self.y, &mut self.end);
        std::mem::swap(&mut self.gaps.start, &mut self.gaps.end);
        self.clock.accepted += 1;
        self.taken = taken;
        Ok(())
    }

    /// The step of `taken` s from the state now to `end` added to the
    /// reductions where it is in the recorded window; whether the stepper
    /// was used (its last attempt is then not the step). `fixed`: a fixed
    /// step's (see [`reduce_step`]'s `stages`).
    #[inline(always)]
    pub(super) fn reduce<S: SystemStepper>(
        &mut self,
        stepper: &mut S,
        taken: f64,
        fixed: bool,
    ) -> Result<bool> {
        if !self.schedule.in_window(self.clock.time, taken) {
            return Ok(false);
        }
        self.reduce_in_window(stepper, taken, fixed)
    }

    /// [`Self::reduce`] for a step in the recorded window: the window's test
    /// is inlined in the step, the reductions (a loop over the observed
    /// quantities, a peak's location) stay a call of their own.
    #[inline(never)]
    fn reduce_in_window<S: SystemStepper>(
        &mut self,
        stepper: &mut S,
        taken: f64,
        fixed: bool,
    ) -> Result<bool> {
        let time = self.clock.time;
        if self.reductions.recorded_time == 0.0
            && self.reductions.window_losses.is_empty()
            && self.system.has_friction()
        {
            // The window's first step: the friction elements' losses so far
            // (sliding loses energy outside any contact's record).
            let at = loss_slot(self.system, 0);
            let count = self.modes.len();
            self.reductions.window_losses = self.y[at..at + count].to_vec();
        }
        reduce_step(
            self.system,
            stepper,
            (time, &self.y, &self.end, taken),
            &self.modes,
            (&mut self.reduce_scratch, fixed.then_some(&self.scratch)),
            (
                &mut self.buffers.probe,
                &mut self.buffers.start,
                &mut self.buffers.work,
            ),
            &mut self.reductions,
            self.schedule.mean_square,
        )
    }

    /// Plain fixed steps in a row through the stepper's fast path, each as
    /// [`Self::step`] would take it, to the bit, up to the next stop reason
    /// ([`Schedule::plain_step`]) or the next interrupt poll; whether it
    /// stopped at that poll's step limit (the driver then asks for another).
    /// Not before the kernel's first step, after which the memory and row
    /// limits it checks stay as they were through the fast path (no contact
    /// or row is added there).
    pub(super) fn fast_steps<S: SystemStepper>(
        &mut self,
        stepper: &mut S,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<bool> {
        let accepted = self.clock.accepted;
        let poll_every = self.poll_every;
        let mut stretch = Stretch {
            clock: &mut self.clock,
            schedule: &self.schedule,
            y: &mut self.y[..],
            gaps: &mut self.gaps.start[..],
            end: &mut self.end[..],
            end_gaps: &mut self.gaps.end[..],
            open: &mut self.open[..],
            peaks: &mut self.reductions.peaks[..],
            squares: &mut self.reductions.square_integrals[..],
            reduce_scratch: &mut self.reduce_scratch,
            recorded_time: &mut self.reductions.recorded_time,
            energy: &mut self.energy,
            // Up to the next interrupt poll, made here after it.
            max_accepted: ((accepted / poll_every + 1) * poll_every).min(
                self.options
                    .max_steps
                    .saturating_sub(self.control.rejected + 1),
            ),
            evaluations: 0,
            steps: 0,
            limited: false,
            unbalanced: None,
        };
        stepper.stretch(self.system, &mut stretch, &self.modes, &mut self.scratch);
        let (steps, limited) = (stretch.steps, stretch.limited);
        if let Some(failure) = stretch.unbalanced {
            return Err(failure);
        }
        if steps == 0 {
            return Ok(false);
        }
        self.stalled = 0;
        // What the kernel does after a plain step that it may have been,
        // beyond the energy check the fast path made: an interrupt poll.
        if poll_due(self.clock.accepted, poll_every) && interrupt() {
            return Err(Error::Interrupted {
                time: self.clock.time,
            });
        }
        Ok(limited)
    }
}
