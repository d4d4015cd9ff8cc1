//! A run's start: the kernel's state built from the system, the options and
//! the initial state (buffers, limits, tolerances, resumed contacts, the
//! first history row and step).

use crate::error::{Error, Result};
use crate::kernel::balance::{EnergySampler, EnergyWatch, ENERGY_INTERVAL};
use crate::kernel::clock::{Clock, Schedule};
use crate::kernel::contact_balance::OnsetBalance;
use crate::kernel::events::{CarriedContact, ContactKind, Open, RunOptions, Stepping};
use crate::kernel::fixed;
use crate::kernel::impacts::Impacts;
use crate::kernel::locate::{any_compliant, wall_round_off, Buffers, Gaps};
use crate::kernel::memory::FIRST_ROWS;
use crate::kernel::reductions::Reductions;
use crate::kernel::run::{loss_slot, Run};
use crate::methods::step_control::StepControl;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, InteractionLaw, Mode, Scratch};

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

/// Refuses a fixed step `dt` (s) longer than the finest interval over which
/// an excitation's signal changes: a recorded pulse shorter than a step fell
/// between two steps' stages and was lost whole (input work 0, without a
/// word), where a harmonic that fast is refused up front
/// ([`crate::methods::registry::check_run`]).
fn check_signal_steps(system: &Assembly, dt: f64) -> Result<()> {
    match system.finest_signal_interval() {
        Some((interval, name)) if dt > interval * (1.0 + 1e-9) => {
            Err(Error::Inconsistent(format!(
                "a \"{name}\" excitation changes every {interval:.3e} s (its samples, or a sweep's \
                 half period at its highest frequency), less than the fixed step dt = {dt:e} s, \
                 which would pass over it: reduce dt to at most {interval:.3e} s, or choose an \
                 adaptive method (\"dop853\")"
            )))
        }
        _ => Ok(()),
    }
}

/// Every compliant interaction in contact (see [`Run::all_compliant`]).
fn all_compliant(system: &Assembly) -> Vec<Mode> {
    let mode = |it: &crate::model::assembly::Interaction| match it.law {
        InteractionLaw::Compliant { .. } => Mode::Compliant {
            approach_rate: 0.0,
            indented_only: false,
        },
        InteractionLaw::Rigid { .. } | InteractionLaw::Friction { .. } => Mode::Open,
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
    /// A run of `system` from `initial`, the compliant contacts `carried`
    /// from the run it continues (per interaction, or empty), its first
    /// history row kept.
    pub(super) fn new<S: SystemStepper>(
        system: &'a Assembly,
        stepper: &mut S,
        (initial, carried): (&[f64], &[Option<CarriedContact>]),
        options: &'a RunOptions,
        stepping: Stepping,
        record_limit: u64,
    ) -> Result<Self> {
        let (len, d, count) = (system.state_len(), system.dim, system.interactions.len());
        if initial.len() != len {
            return Err(Error::Inconsistent(format!(
                "the initial state must have {len} values (x, v and the energy \
                 accumulators), got {}",
                initial.len()
            )));
        }
        options.check()?;
        CarriedContact::check_all(carried, count)?;
        if let Some(at) = initial.iter().position(|v| !v.is_finite()) {
            return Err(Error::Inconsistent(format!(
                "the initial state must be finite: value {at} (of x, v and the energy \
                 accumulators) is {}",
                initial[at]
            )));
        }
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
        if !adaptive && !stepper.is_exact() {
            check_signal_steps(system, dt)?;
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
                shifted: vec![0.0; len],
                rates: vec![0.0; len],
                held: Scratch::new(system),
                forces: vec![0.0; 4 * count],
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
            squeeze: Default::default(),
            stalled: 0,
            unconfirmed: vec![false; count],
            any_unconfirmed: false,
            just_switched: vec![false; count],
            on_wall_at_start,
            impacts: Impacts::new(system),
            compliant: false,
            friction: system.has_friction(),
            kinked: system.has_breakpoints(),
            stretches: !adaptive && stepper.takes_stretches(system, timing.is_some()),
            timing,
            creates_contact_energy: stepper.creates_contact_energy(),
            contact_step: (!adaptive && !stepper.is_exact()).then_some(dt),
            changes: vec![None; count],
            closing: vec![None; count],
            all_compliant: all_compliant(system),
            force_pairs: force_pairs(system),
            contact_forces: Vec::new(),
            first_rows: first_rows(&schedule),
            poll_every: interrupt_interval(system.dim),
            timed_polls: system.dim > TIMED_POLLS_BEYOND,
            last_poll: std::time::Instant::now(),
            watch: None,
        };
        run.start(stepper, carried)?;
        Ok(run)
    }

    /// The state at t = 0: contacts resumed, gaps and stored energy taken,
    /// the first history row kept and the first step chosen.
    fn start<S: SystemStepper>(
        &mut self,
        stepper: &mut S,
        carried: &[Option<CarriedContact>],
    ) -> Result<()> {
        let system = self.system;
        self.resume_contacts(carried);
        if self.friction {
            self.settle_friction(0.0, 0.0);
            self.rest_at_start();
        }
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
    /// another's end) resumes it: as `carried` (its latched approach rate,
    /// onset and approach), or else its approach rate taken as the
    /// indentation rate now (a damped law's at least the pressing's, as at
    /// any onset) and its onset now.
    fn resume_contacts(&mut self, carried: &[Option<CarriedContact>]) {
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
                let (mut approach_rate, mut resting) =
                    self.compliant_onset(i, 0.0, approach.max(f64::MIN_POSITIVE), scales);
                // In progress at the start: -0.0, an onset at or before it that
                // the run did not see begin (counted as no contact begun in it).
                let (mut onset, mut approach_speed, mut deepest) = (-0.0, approach, -gap);
                if let Some(Some(c)) = carried.get(i) {
                    approach_rate = c.approach_rate;
                    (onset, approach_speed) = (c.onset, c.approach_speed);
                    deepest = deepest.max(c.max_indentation);
                    // A resting contact was carried with no approach.
                    resting = false;
                }
                self.modes[i] = Mode::Compliant {
                    approach_rate,
                    indented_only: self.timing.is_some(),
                };
                self.open[i] = Some(Open {
                    kind: ContactKind::Compliant,
                    onset,
                    approach_speed,
                    max_indentation: deepest,
                    dissipated: self.y[loss_slot(system, i)],
                    resting,
                    balance: OnsetBalance::default(),
                    energy: f64::NAN,
                    power: 0.0,
                });
            }
        }
    }
}
