//! The event kernel's state and its step: [`Run::step`] takes one step
//! (cut at the earliest event it shows, located on the method's own
//! solution) and says why it ended ([`Stop`]); the driver
//! ([`crate::kernel::events::integrate_system_within`]) loops on it.

use crate::error::{Error, Result};
use crate::kernel::balance::{EnergySampler, EnergyWatch, ENERGY_INTERVAL};
use crate::kernel::clock::{Clock, Schedule, Stop};
use crate::kernel::compact::Stretch;
use crate::kernel::contact_balance::OnsetBalance;
use crate::kernel::events::{ContactKind, ContactTiming, Open, PairContact, RunOptions, Stepping};
use crate::kernel::fixed::{self, Change};
use crate::kernel::impacts::Impacts;
use crate::kernel::locate::{
    any_compliant, event_value, find_crossing, locate, may_cross, past, wall_round_off, Buffers,
    Crossing, Gaps, Location,
};
use crate::kernel::memory::FIRST_ROWS;
use crate::kernel::reductions::{reduce_step, Reductions};
use crate::methods::step_control::{rejects, StepControl};
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, InteractionLaw, Mode, Scratch, CONTACT};

/// Systems of more coordinates than this also ask whether to stop by the
/// clock (their steps cost far more than reading it).
const TIMED_POLLS_BEYOND: usize = 16;
/// How often (steps) the caller is asked whether to stop (a multiple of
/// [`ENERGY_INTERVAL`]).
const INTERRUPT_INTERVAL: u64 = 1 << 14;

/// [`INTERRUPT_INTERVAL`] for a system of `dim` coordinates: shorter for
/// large systems, whose steps cost as the square of their size (the exact
/// flow's with 200 modes, a millisecond), so that a poll comes within a
/// fraction of a second; a multiple of [`ENERGY_INTERVAL`].
fn interrupt_interval(dim: usize) -> u64 {
    let scale = (dim / TIMED_POLLS_BEYOND).max(1) as u64;
    (INTERRUPT_INTERVAL / (scale * scale) / ENERGY_INTERVAL).max(1) * ENERGY_INTERVAL
}

/// Whether the caller is asked whether to stop after `accepted` steps, every
/// `poll_every` (a mask where that is a power of two, as for every system of
/// up to [`TIMED_POLLS_BEYOND`] coordinates: a division each kernel step
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
    /// kept or not).
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
    /// Whether the signals have kinks (samples) to land on.
    pub(super) kinked: bool,
    /// Whether plain fixed steps go to the stepper's fast path.
    pub(super) stretches: bool,
    pub(super) poll_every: u64,
    pub(super) timed_polls: bool,
    pub(super) last_poll: std::time::Instant,
    /// Fixed stepping's timing of contacts (None: stepping by events).
    pub(super) timing: Option<ContactTiming>,
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
    /// History rows the first growth makes room for (see [`first_rows`]).
    pub(super) first_rows: usize,
}

/// History rows the first growth of a run's history makes room for:
/// [`FIRST_ROWS`], or fewer where a fixed-step run keeps fewer (its steps
/// to `t_end`, each `every`-th kept, with the first and last rows).
fn first_rows(schedule: &Schedule) -> usize {
    let steps = (schedule.t_end / schedule.dt).ceil();
    // NaN (no dt) or as many steps as the rows: the first growth's.
    if schedule.adaptive || steps.is_nan() || steps >= FIRST_ROWS as f64 {
        return FIRST_ROWS;
    }
    (steps as usize / schedule.every.max(1) as usize + 2).min(FIRST_ROWS)
}

/// Every compliant interaction in contact (see [`Run::all_compliant`]).
fn all_compliant(system: &Assembly) -> Vec<Mode> {
    let mode = |it: &crate::model::assembly::Interaction| match it.law {
        InteractionLaw::Compliant { .. } => Mode::Compliant {
            approach_rate: 0.0,
            indented_only: false,
        },
        InteractionLaw::Rigid { .. } => Mode::Open,
    };
    system.interactions.iter().map(mode).collect()
}

/// The distance (m) within which a gap counts as grazed: 1e-12 of the
/// largest wall offset, at least 1e-21 m.
fn graze_tolerance(system: &Assembly) -> f64 {
    1e-12
        * system
            .interactions
            .iter()
            .map(|it| it.offset.abs())
            .fold(1e-9, f64::max)
}

/// The time (s) below which an adaptive or exact run sums a chattering
/// sequence: a millionth of the structure's longest period; without one (a
/// body on no spring), of the system's time scale (its forcing period or
/// fall time), not of the run: a cut-off growing with t_end had counted one
/// orbit's impacts differently in runs of different lengths.
fn chatter_resolution(system: &Assembly, t_end: f64) -> f64 {
    let longest = if system.longest_period.is_finite() {
        system.longest_period
    } else {
        system.time_scale()
    };
    1e-6 * t_end.min(longest)
}

/// The pairs with a compliant wall, in order (the contact-force columns).
fn force_pairs(system: &Assembly) -> Vec<usize> {
    let mut pairs: Vec<usize> = Vec::new();
    for it in &system.interactions {
        if matches!(it.law, InteractionLaw::Compliant { .. }) && !pairs.contains(&it.pair) {
            pairs.push(it.pair);
        }
    }
    pairs
}

impl<'a> Run<'a> {
    /// A run of `system` from `initial`, its first history row kept.
    pub(super) fn new<S: SystemStepper>(
        system: &'a Assembly,
        stepper: &mut S,
        initial: &[f64],
        options: &'a RunOptions,
        stepping: Stepping,
        record_limit: u64,
    ) -> Result<Self> {
        let (len, d, count) = (system.state_len(), system.dim, system.interactions.len());
        let adaptive = stepper.is_adaptive();
        let timing = Self::timing(stepping);
        if timing.is_some() {
            fixed::check(system, stepper)?;
        }
        let t_end = options.t_end;
        let schedule = Schedule::new(options, adaptive, system.longest_period, timing);
        let dt = schedule.dt;
        if !adaptive && (dt.is_nan() || dt <= 0.0) {
            return Err(Error::Inconsistent(format!(
                "dt is required for method {:?} (a step in s > 0)",
                stepper.name()
            )));
        }
        let graze = graze_tolerance(system);
        let resolution = if adaptive || stepper.is_exact() {
            chatter_resolution(system, t_end)
        } else {
            dt
        };
        // A stepper may be reused across runs: nothing carries over from the last.
        stepper.reset();
        let y = initial.to_vec();
        let on_wall_at_start = (0..count)
            .map(|i| {
                let (gap, rate) = system.gap(i, &y);
                gap.abs() <= wall_round_off(system, i, &y) && rate <= 0.0
            })
            .collect();
        let mut run = Run {
            system,
            options,
            record_limit,
            schedule,
            clock: Clock {
                time: 0.0,
                grid: 0,
                accepted: 0,
                until_kept: options.every,
                next_strobe: options.reduce.strobe_period,
            },
            graze,
            resolution,
            y,
            end: vec![0.0; len],
            full: vec![0.0; len],
            buffers: Buffers {
                probe: vec![0.0; len],
                best: vec![0.0; len],
                work: vec![0.0; len],
                start: vec![0.0; len],
                accel: vec![0.0; d],
                jerk: vec![0.0; d],
            },
            scratch: Scratch::new(system),
            reduce_scratch: Scratch::new(system),
            modes: vec![Mode::Open; count],
            open: vec![None; count],
            gaps: Gaps {
                start: vec![(0.0, 0.0); count],
                end: vec![(0.0, 0.0); count],
            },
            energy: EnergyWatch {
                stored_start: 0.0,
                scale: 0.0,
                sampler: EnergySampler::new(system, t_end),
                impact_loss: 0.0,
                tolerance: options.energy_tolerance,
                t_end,
                extremes: Default::default(),
            },
            contacts: Vec::new(),
            time_rows: Vec::new(),
            states: Vec::new(),
            reductions: Reductions {
                peaks: vec![0.0; system.observed()],
                square_integrals: vec![0.0; system.observed()],
                ..Reductions::default()
            },
            control: StepControl::new(options.dt.unwrap_or(1e-6 * t_end)),
            grazes: 0,
            taken: 0.0,
            last_event: f64::NEG_INFINITY,
            close_events: 0,
            stalled: 0,
            unconfirmed: vec![false; count],
            any_unconfirmed: false,
            just_switched: vec![false; count],
            on_wall_at_start,
            impacts: Impacts::new(system),
            compliant: false,
            kinked: system.has_breakpoints(),
            stretches: !adaptive && stepper.takes_stretches(system, timing.is_some()),
            timing,
            creates_contact_energy: stepper.creates_contact_energy(),
            changes: vec![None; count],
            closing: vec![None; count],
            all_compliant: all_compliant(system),
            force_pairs: force_pairs(system),
            contact_forces: Vec::new(),
            first_rows: first_rows(&schedule),
            poll_every: interrupt_interval(system.dim),
            timed_polls: system.dim > TIMED_POLLS_BEYOND,
            last_poll: std::time::Instant::now(),
        };
        run.start(stepper)?;
        Ok(run)
    }

    /// The state at t = 0: contacts resumed, gaps and stored energy taken,
    /// the first history row kept and the first step chosen.
    fn start<S: SystemStepper>(&mut self, stepper: &mut S) -> Result<()> {
        let system = self.system;
        self.resume_contacts();
        if self.timing.is_some() {
            self.resume_fixed();
        }
        // Open pairs only (a resumed contact is not on its wall).
        for (i, on_wall) in self.on_wall_at_start.iter_mut().enumerate() {
            *on_wall &= self.modes[i] == Mode::Open;
        }
        system.gaps(&self.y, &mut self.gaps.start);
        let (stored_start, energy_scale) = system.energy_terms(&self.y, &self.modes);
        (self.energy.stored_start, self.energy.scale) = (stored_start, energy_scale);
        for record in self.open.iter_mut().flatten() {
            record.balance = OnsetBalance::at(system, &self.y, &self.modes, stored_start, 0.0);
        }
        self.compliant = any_compliant(&self.modes);
        if self.options.keep_history {
            self.push_history_row(0.0)?;
        }
        self.first_step(stepper);
        Ok(())
    }

    /// A compliant pair that starts in contact (a run continued from
    /// another's end) resumes it, its approach rate taken as the indentation
    /// rate now (a damped law's at least the pressing's, as at any onset).
    fn resume_contacts(&mut self) {
        let system = self.system;
        let scales = (
            self.schedule.chatter_interval(0.0),
            self.schedule.time_scale,
        );
        for i in 0..self.modes.len() {
            let (gap, rate) = system.gap(i, &self.y);
            let compliant = matches!(system.interactions[i].law, InteractionLaw::Compliant { .. });
            if gap < 0.0 && compliant {
                // The law's rate > 0 (a damped law divides by it); the record
                // keeps the approach there was: none for bodies at rest.
                let approach = rate.abs();
                let (approach_rate, resting) =
                    self.compliant_onset(i, 0.0, approach.max(f64::MIN_POSITIVE), scales);
                self.modes[i] = Mode::Compliant {
                    approach_rate,
                    indented_only: self.timing.is_some(),
                };
                self.open[i] = Some(Open {
                    kind: ContactKind::Compliant,
                    onset: 0.0,
                    approach_speed: approach,
                    max_indentation: -gap,
                    dissipated: self.y[loss_slot(system, i)],
                    resting,
                    balance: OnsetBalance::default(),
                    energy: f64::NAN,
                    power: 0.0,
                });
            }
        }
    }

    /// The next step's length and the landing that bounds it
    /// ([`Stop::Step`] where none does), or why no step is taken.
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
        if modes.contains(&Mode::Sticking) {
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
    /// reduced and kept; why it ended.
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
        probed |= self.reduce(stepper, taken)?;
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
            &self.end,
            h,
            &self.modes,
            self.graze,
            grazes,
            &mut self.scratch,
            &mut self.buffers.work,
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
            let v = event_value(
                system,
                j,
                mode,
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
    /// was used (its last attempt is then not the step).
    #[inline(always)]
    pub(super) fn reduce<S: SystemStepper>(&mut self, stepper: &mut S, taken: f64) -> Result<bool> {
        if !self.schedule.in_window(self.clock.time, taken) {
            return Ok(false);
        }
        self.reduce_in_window(stepper, taken)
    }

    /// [`Self::reduce`] for a step in the recorded window: the window's test
    /// is inlined in the step, the reductions (a loop over the observed
    /// quantities, a peak's location) stay a call of their own.
    #[inline(never)]
    fn reduce_in_window<S: SystemStepper>(&mut self, stepper: &mut S, taken: f64) -> Result<bool> {
        let time = self.clock.time;
        reduce_step(
            self.system,
            stepper,
            (time, &self.y, &self.end, taken),
            &self.modes,
            &mut self.reduce_scratch,
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
