//! Contacts at events: every interaction on its wall at an event's instant
//! switches (a compliant contact starts or ends, a sticking pair is
//! released; the rigid ones are resolved together by
//! [`crate::kernel::impacts`]), and each contact's record is kept: onset,
//! approach, deepest indentation, separation, rebound and the energy its
//! forces took.

use crate::error::{Error, Result};
use crate::kernel::clock::CHATTER_EVENTS;
use crate::kernel::contact_balance::OnsetBalance;
use crate::kernel::events::{CarriedContact, ContactKind, Open};
use crate::kernel::impacts;
use crate::kernel::locate::{any_compliant, crossed, event_value_from};
use crate::kernel::observe::EventView;
use crate::kernel::run::{loss_slot, Run};
use crate::methods::step_control::initial_step;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, Interaction, InteractionLaw, Mode};
use crate::model::contact::{AnyLaw, Hertz, HysterHertz, Linear};
use crate::numerics::hermite;

/// Contacts held before those a run does not keep are dropped (see
/// [`crate::kernel::reductions::ReduceOptions::contacts_from`]): a few, so
/// that dropping them costs as little as holding them.
const COMPACTED_CONTACTS: usize = 64;

impl Run<'_> {
    /// The start of compliant interaction `i` (open) at `time` and the
    /// state now, approaching at `approach` (m/s): the rate its law latches
    /// (see [`crate::model::contact::AnyLaw::latched_approach_rate`]: a
    /// damped Hertz law's damping is taken from the pressing where the
    /// approach is slower) and whether it starts at rest (an approach the
    /// pressing gives within round-off, see [`impacts::resting`]: no impact,
    /// so no rebound ratio). `scales` are the time's round-off and the
    /// system's time scale, s. Once per onset.
    #[cold]
    #[inline(never)]
    pub(super) fn compliant_onset(
        &mut self,
        i: usize,
        time: f64,
        approach: f64,
        (instant, time_scale): (f64, f64),
    ) -> (f64, bool) {
        let system = self.system;
        let it = &system.interactions[i];
        let InteractionLaw::Compliant { law, .. } = it.law else {
            return (approach, false);
        };
        let y = &self.y;
        // < 0 presses the pair shut.
        let pressing = system.gap_acceleration(
            i,
            time,
            y,
            &self.modes,
            &mut self.scratch,
            &mut self.buffers.work,
        );
        let mass = 1.0 / it.inverse_mass;
        // A flight rising less than the round-off of the gap, or of the
        // indentation the pressing holds (a stop at the origin has a gap
        // scale of 0), is round-off: the ringing of a body set down on the
        // contact.
        let round_off = impacts::flight_round_off(system, i, y)
            .max(1e-9 * law.static_indentation(mass, -pressing));
        let (landing, at_rest) =
            impacts::resting(approach, pressing, round_off, instant, time_scale);
        let latched = law.latched_approach_rate(approach, mass, -pressing);
        (latched, landing || at_rest)
    }

    /// Switch interaction `i` at `time`: start or end a compliant contact,
    /// or release a sticking pair whose constraint force turned (the open
    /// rigid pairs are [`impacts::Impacts::resolve`]'s).
    fn switch(&mut self, i: usize, time: f64, scales: (f64, f64)) {
        let system = self.system;
        let it = &system.interactions[i];
        let (_, rate) = system.gap(i, &self.y);
        match self.modes[i] {
            Mode::Open => {
                let approach = -rate;
                let (approach_rate, resting) = self.compliant_onset(i, time, approach, scales);
                self.modes[i] = Mode::Compliant {
                    approach_rate,
                    indented_only: false,
                };
                self.open[i] = Some(Open {
                    kind: ContactKind::Compliant,
                    onset: time,
                    approach_speed: approach,
                    max_indentation: 0.0,
                    dissipated: self.y[loss_slot(system, i)],
                    resting,
                    balance: OnsetBalance::default(),
                    energy: f64::NAN,
                    power: 0.0,
                });
            }
            Mode::Compliant { .. } => {
                self.modes[i] = Mode::Open;
                if let Some(oc) = self.open[i].take() {
                    let dissipated = self.y[loss_slot(system, i)] - oc.dissipated;
                    self.contacts
                        .push(oc.close(it.pair, time, rate, dissipated));
                }
            }
            Mode::Sliding { .. } | Mode::Stuck { .. } => self.friction_switch(i, time),
            Mode::Sticking => {
                system.release(i, &mut self.y);
                self.modes[i] = Mode::Open;
                if let Some(oc) = self.open[i].take() {
                    self.contacts
                        .push(oc.close(it.pair, time, 0.0, oc.dissipated));
                }
            }
        }
    }

    /// The event of interaction `located` that ended the last step: every
    /// interaction on its wall at this instant switches; the open rigid
    /// ones are resolved together with the sticking ones.
    pub(super) fn at_event<S: SystemStepper>(
        &mut self,
        stepper: &mut S,
        located: usize,
    ) -> Result<()> {
        let (system, time) = (self.system, self.clock.time);
        let (resolution, time_scale) = (self.resolution, self.schedule.time_scale);
        let instant = self.schedule.chatter_interval(time);
        // An event located within the round-off of the run's start (a pair
        // on its wall at t = 0: the value's round-off put the root at 1e-66
        // s), or one of a pair on its wall from the start located within the
        // run's resolution (not pressed at first, the gap reached its
        // round-off only after 1e-8 s), is at the start.
        let from_start = self.on_wall_at_start[located] && time <= resolution;
        let event_time = if time <= f64::EPSILON * time_scale || from_start {
            0.0
        } else {
            time
        };
        let mut any = false;
        let mut rigid = false;
        if self.watch.is_some() {
            self.watch_before();
        }
        self.just_switched.iter_mut().for_each(|s| *s = false);
        // Whether an open pair the event did not cross touches (see
        // `mark_touching`).
        let touch = self.touch_band(instant);
        let mut near = false;
        // The step's end, kept: its gaps are those the step found there.
        debug_assert!({
            let mut here = self.gaps.end.clone();
            system.gaps(&self.y, &mut here);
            here == self.gaps.start
        });
        for i in 0..self.modes.len() {
            let mode = self.modes[i];
            let v = event_value_from(
                system,
                i,
                mode,
                self.gaps.start[i],
                time,
                &self.y,
                &self.modes,
                &mut self.scratch,
                &mut self.buffers.work,
            );
            if !(i == located || crossed(system, i, mode, v, &self.y))
                || (mode == Mode::Open && system.held_by_mirror(i, &self.modes))
            {
                near |= mode == Mode::Open && v <= touch.of(&system.interactions[i]);
                continue;
            }
            if self.impacts.mark(system, i, mode) {
                rigid = true;
                continue;
            }
            let onset = self.open[i].map(|o| o.balance);
            self.switch(i, event_time, (instant, time_scale));
            if matches!(
                mode,
                Mode::Sticking | Mode::Sliding { .. } | Mode::Stuck { .. }
            ) {
                // A release or a slip moved the state: the later pairs'
                // values are taken at the state moved.
                system.gaps(&self.y, &mut self.gaps.start);
            }
            self.just_switched[i] = true;
            self.check_contact(i, mode, onset)?;
            any = true;
        }
        let collapse = rigid && self.squeeze.armed();
        if collapse {
            // Every open pair the speeds close within the resolution.
            self.mark_touching(self.touch_band(resolution));
            self.squeeze.resolved();
        } else if rigid && near {
            self.mark_touching(touch);
        }
        if rigid {
            any |= self.resolve_marked(event_time, (resolution, instant, time_scale), collapse);
            if self.watch.is_some() {
                self.watch_jumps();
            }
        }
        if any {
            self.count_close_events(stepper, rigid)?;
        }
        if self.friction {
            // Impacts change the velocities, and sticking pairs shadow
            // friction elements on their rows.
            let impulses = if rigid {
                self.impacts.speed_scale()
            } else {
                0.0
            };
            self.settle_friction(event_time, impulses);
        }
        // Impacts change the velocities.
        system.gaps(&self.y, &mut self.gaps.start);
        self.compliant = any_compliant(&self.modes);
        let from = self.options.reduce.contacts_from;
        if self.contacts.len() >= COMPACTED_CONTACTS && time < from {
            // Before the contacts kept begin: what closed is dropped (a
            // contact across their start may stay; it is dropped at the end).
            self.contacts.retain(|c| c.onset >= from);
        }
        if self.watch.is_some() {
            self.watch_event(time, located)?;
        }
        Ok(())
    }

    /// The gaps that touch at an event whose time's round-off is `instant`
    /// (s): what the state's speeds close within it, or the round-off of
    /// the gap's scale that a touch's release leaves between two pairs.
    /// The marked rigid pairs and the sticking ones resolved at `time` on
    /// the run's state ([`impacts::Impacts::resolve`]; `scales`: the resolution, the
    /// time's round-off and the system's time scale, s): whether any changed
    /// or any impulse acted.
    pub(super) fn resolve_marked(
        &mut self,
        time: f64,
        scales: (f64, f64, f64),
        collapse: bool,
    ) -> bool {
        self.impacts.resolve(
            self.system,
            time,
            &mut self.y,
            &mut self.modes,
            &mut self.open,
            &mut self.contacts,
            &mut self.energy.impact_loss,
            &mut self.grazes,
            scales,
            collapse,
            &mut self.scratch,
            &mut self.buffers.work,
            &mut self.just_switched,
        )
    }

    fn touch_band(&self, instant: f64) -> TouchBand {
        let d = self.system.dim;
        let largest = |v: &[f64]| v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        TouchBand {
            closed: instant * largest(&self.y[d..2 * d]),
            reach: largest(&self.y[..d]),
        }
    }

    /// At a rigid event, the open rigid pairs whose gap is within `touch`
    /// join it: they touch at this instant. (Loose masses touching in a
    /// column are a few units of round-off apart; resolved one after the
    /// other, a landing ran up and down the column as impacts 1e-14 s apart,
    /// without end.)
    fn mark_touching(&mut self, touch: TouchBand) {
        let system = self.system;
        for i in 0..self.modes.len() {
            // (`gaps.start` follows the state through the switches.)
            let gap = self.gaps.start[i].0;
            if gap <= touch.of(&system.interactions[i]) && !system.held_by_mirror(i, &self.modes) {
                self.impacts.mark(system, i, self.modes[i]);
            }
        }
    }

    /// An observed run (see [`crate::kernel::observe`]): the state and modes
    /// before the event being handled. Out of line, so that a plain run's
    /// event handling is the code it was.
    #[cold]
    #[inline(never)]
    fn watch_before(&mut self) {
        if let Some(watch) = self.watch.as_mut() {
            watch.before.copy_from_slice(&self.y[..2 * self.system.dim]);
            watch.modes_before.copy_from_slice(&self.modes);
            watch.jumps.clear();
        }
    }

    /// An observed run whose observer wants steps: the step's start.
    #[cold]
    #[inline(never)]
    pub(super) fn watch_step_start(&mut self) {
        if let Some(watch) = self.watch.as_mut() {
            watch.step_time = self.clock.time;
            watch
                .step_start
                .copy_from_slice(&self.y[..2 * self.system.dim]);
        }
    }

    /// An observed run whose observer wants steps: the step kept, shown.
    #[cold]
    #[inline(never)]
    pub(super) fn watch_step(&mut self) -> Result<()> {
        if let Some(watch) = self.watch.as_mut() {
            let size = 2 * self.system.dim;
            watch.observer.step(
                watch.step_time,
                &watch.step_start,
                self.clock.time,
                &self.y[..size],
                &self.modes,
            )?;
        }
        Ok(())
    }

    /// An observed run: the rigid pairs the event's impulses acted on.
    #[cold]
    #[inline(never)]
    fn watch_jumps(&mut self) {
        if let Some(watch) = self.watch.as_mut() {
            self.impacts.jumps(&mut watch.jumps);
        }
    }

    /// An observed run: the event shown to the observer.
    #[cold]
    #[inline(never)]
    fn watch_event(&mut self, time: f64, located: usize) -> Result<()> {
        let dim = self.system.dim;
        if let Some(watch) = self.watch.as_mut() {
            watch.observer.event(&EventView {
                time,
                located,
                before: &watch.before,
                after: &self.y[..2 * dim],
                modes_before: &watch.modes_before,
                modes_after: &self.modes,
                jumps: &watch.jumps,
            })?;
        }
        Ok(())
    }

    /// A compliant contact's own balance, from its onset to its separation:
    /// it must not create energy. Interaction `i` was in mode `was`, its
    /// contact's balance at onset `onset`.
    fn check_contact(&mut self, i: usize, was: Mode, onset: Option<OnsetBalance>) -> Result<()> {
        let system = self.system;
        let energy = &self.energy;
        match (
            was,
            self.modes[i],
            self.open[i].as_mut(),
            onset,
            self.contacts.last(),
        ) {
            (Mode::Open, Mode::Compliant { .. }, Some(record), ..) => {
                check_resolved(
                    self.contact_step,
                    system,
                    i,
                    (record.onset, record.approach_speed),
                )?;
                record.balance = OnsetBalance::at(
                    system,
                    &self.y,
                    &self.modes,
                    energy.stored_start,
                    energy.impact_loss,
                );
            }
            (Mode::Compliant { .. }, Mode::Open, None, Some(onset), Some(record)) => {
                let change = onset.check_separation(
                    system,
                    &self.y,
                    &self.modes,
                    (energy.stored_start, energy.impact_loss),
                    // At least the round-off the run's own balance allows: a
                    // pair set touching at rest has nothing in play (gravity
                    // pressing a zero clearance: 7e-40 J had been refused).
                    energy.scale.max(system.energy_floor(self.schedule.t_end)),
                    (energy.tolerance, self.creates_contact_energy),
                    record,
                )?;
                if let Some(record) = self.contacts.last_mut() {
                    record.energy_change = change;
                }
            }
            _ => {}
        }
        Ok(())
    }

    /// After an event that switched a pair: the method restarts, and events
    /// closer than the time's round-off, too many in a row, are chattering.
    /// An adaptive method's step restarts below the onset cap of each
    /// contact just begun (0.1's rule); after a rigid impact (the velocities
    /// jumped) at most 1e-3 of the run.
    fn count_close_events<S: SystemStepper>(&mut self, stepper: &mut S, rigid: bool) -> Result<()> {
        let time = self.clock.time;
        stepper.reset();
        if self.schedule.adaptive {
            if rigid {
                self.control.h = self.control.h.min(1e-3 * self.schedule.t_end);
            }
            for i in 0..self.modes.len() {
                if let (true, Mode::Compliant { approach_rate, .. }) =
                    (self.just_switched[i], self.modes[i])
                {
                    let cap =
                        ONSET_STEP_FRACTION * contact_time_scale(self.system, i, approach_rate);
                    self.control.h = self.control.h.min(cap);
                }
            }
        }
        self.squeeze
            .after(rigid, (time, time - self.last_event), self.resolution);
        let interval = self.schedule.chatter_interval(time);
        if time - self.last_event < interval {
            self.close_events += 1;
            if self.close_events >= CHATTER_EVENTS {
                return Err(Error::Chattering {
                    time,
                    events: self.close_events,
                    interval,
                });
            }
        } else {
            self.close_events = 0;
        }
        self.last_event = time;
        Ok(())
    }

    /// Deepest indentation of each compliant contact within the step of
    /// `taken` s to `end`: where the indentation rate changes sign, the
    /// method's own state at the interpolant's turning point (the
    /// interpolant alone errs by its third-order term, 1e-4 of the
    /// indentation at dop853's steps). Whether the stepper was used (its
    /// last attempt is then not the step).
    pub(super) fn deepest_indentation<S: SystemStepper>(
        &mut self,
        stepper: &mut S,
        taken: f64,
    ) -> Result<bool> {
        let (system, time) = (self.system, self.clock.time);
        let mut used = false;
        for (i, record) in self.open.iter_mut().enumerate() {
            let (Some(oc), Mode::Compliant { .. }) = (record.as_mut(), self.modes[i]) else {
                continue;
            };
            let ((g0, r0), (g1, r1)) = (self.gaps.start[i], self.gaps.end[i]);
            let (m0, m1) = (r0 * taken, r1 * taken);
            let mut deepest = -g1;
            if m0 < 0.0 && m1 > 0.0 {
                // Then one Newton step on the gap's rate from there (the
                // error of the turning point squared).
                let mut at = hermite::peak(-g0, -g1, -m0, -m1) * taken;
                let probe = &mut self.buffers.probe;
                for newton in [true, false] {
                    stepper.attempt(
                        system,
                        time,
                        &self.y,
                        at,
                        &self.modes,
                        &mut self.scratch,
                        probe,
                    )?;
                    let (gap, rate) = system.gap(i, probe);
                    deepest = deepest.max(-gap);
                    if !newton {
                        break;
                    }
                    let curvature = system.gap_acceleration(
                        i,
                        time + at,
                        probe,
                        &self.modes,
                        &mut self.scratch,
                        &mut self.buffers.work,
                    );
                    at -= rate / curvature;
                    if !(at > 0.0 && at < taken) {
                        break;
                    }
                }
                used = true;
            }
            oc.max_indentation = oc.max_indentation.max(deepest);
        }
        Ok(used)
    }

    /// The compliant contacts open now, for a run continued from here
    /// ([`crate::kernel::events::SystemSolution::open_contacts`]).
    pub(super) fn open_contacts(&self) -> Vec<Option<CarriedContact>> {
        let carried = |(record, mode): (&Option<Open>, &Mode)| match (record, mode) {
            (Some(oc), Mode::Compliant { approach_rate, .. })
                if oc.kind == ContactKind::Compliant =>
            {
                Some(CarriedContact {
                    approach_rate: *approach_rate,
                    onset: oc.onset,
                    // A contact begun at rest had no approach to rebound from.
                    approach_speed: if oc.resting { 0.0 } else { oc.approach_speed },
                    max_indentation: oc.max_indentation,
                })
            }
            _ => None,
        };
        self.open.iter().zip(&self.modes).map(carried).collect()
    }

    /// The records of the contacts still open at the end (NaN separation).
    pub(super) fn close_open(&mut self) {
        let system = self.system;
        for (i, record) in self.open.iter().enumerate() {
            if let Some(oc) = record {
                // With events a compliant record holds its loss slot's value
                // at the onset; fixed steps sum its dissipation themselves
                // (`fixed::pressed`), as they do at a separation.
                let dissipated = match oc.kind {
                    ContactKind::Compliant if self.timing.is_none() => {
                        self.y[loss_slot(system, i)] - oc.dissipated
                    }
                    _ => oc.dissipated,
                };
                let pair = system.interactions[i].pair;
                self.contacts
                    .push(oc.close(pair, f64::NAN, f64::NAN, dissipated));
            }
        }
    }
}

/// The first adaptive step after a compliant contact's onset, as a fraction
/// of its time scale ([`contact_time_scale`]; 0.1's rule).
const ONSET_STEP_FRACTION: f64 = 1e-3;

/// The time compliant interaction `i`, approaching at `speed` (m/s), takes
/// to store the pair's relative kinetic energy elastically, `delta* /
/// speed` (s): a fraction of the contact's duration, where `F ~ delta^1.5`
/// makes the solution rough. Infinite for a rigid pair or no approach.
fn contact_time_scale(system: &Assembly, i: usize, speed: f64) -> f64 {
    let it = &system.interactions[i];
    let (InteractionLaw::Compliant { law, .. }, true) =
        (it.law, speed.abs() > 0.0 && speed.is_finite())
    else {
        return f64::INFINITY;
    };
    let speed = speed.abs();
    let energy = 0.5 * speed * speed / it.inverse_mass;
    let stiffness = match law {
        AnyLaw::Hertz(Hertz { stiffness })
        | AnyLaw::HysterHertz(HysterHertz { stiffness, .. })
        | AnyLaw::Linear(Linear { stiffness }) => stiffness,
    };
    let linear = matches!(law, AnyLaw::Linear(_));
    if energy < f64::MIN_POSITIVE {
        // The square underflowed (a pair set touching at rest, 3e-162 m/s: the
        // scale had been 0 and the steps after the onset 0 s long, forever):
        // the same in powers of the speed alone.
        let compliance = 0.5 / (it.inverse_mass * stiffness);
        return if linear {
            (2.0 * compliance).sqrt()
        } else {
            (compliance / 0.4).powf(0.4) * speed.powf(-0.2)
        };
    }
    // The law's potential inverted: `0.4 k delta^2.5` (Hertz), `0.5 k delta^2`.
    let indentation = if linear {
        (2.0 * energy / stiffness).sqrt()
    } else {
        (energy / (0.4 * stiffness)).powf(0.4)
    };
    indentation / speed
}

impl Run<'_> {
    /// An adaptive method's first step where the run sets none: Hairer's
    /// ([`initial_step`]) from the rates at the start, at most a tenth of
    /// the run and at least 1e-12 of it, and below the onset cap of a
    /// contact the run starts in or on the wall of (0.1's rules).
    pub(super) fn first_step<S: SystemStepper>(&mut self, stepper: &mut S) {
        let (system, t_end) = (self.system, self.schedule.t_end);
        let (Some(tolerances), None) = (stepper.tolerances(), self.options.dt) else {
            return;
        };
        let y = &self.y;
        let Some(f0) = stepper.start_rates(system, 0.0, y, &self.modes, &mut self.scratch) else {
            return;
        };
        self.buffers.start.copy_from_slice(f0);
        let (modes, scratch) = (&self.modes, &mut self.scratch);
        let buffers = (&mut self.buffers.probe[..], &mut self.buffers.work[..]);
        let mut h = initial_step(
            y,
            &self.buffers.start,
            2 * system.dim,
            tolerances,
            |e| stepper.shrink(e),
            0.1 * t_end,
            buffers,
            |time, y1, f1| system.rates(time, y1, modes, scratch, f1),
        )
        // At least 1e-12 of the run, as 0.1 (and a NaN one, of rates beyond
        // floating point, so: the first step finds the blow-up, not a crawl).
        .max(1e-12 * t_end);
        for (i, mode) in self.modes.iter().enumerate() {
            let speed = match mode {
                Mode::Compliant { approach_rate, .. } => *approach_rate,
                Mode::Open if self.on_wall_at_start[i] => system.gap(i, y).1,
                _ => continue,
            };
            h = h.min(ONSET_STEP_FRACTION * contact_time_scale(system, i, speed));
        }
        self.control.h = h;
    }
}

/// See [`Run::touch_band`].
#[derive(Debug, Clone, Copy)]
struct TouchBand {
    /// m: what the state's speeds close within the time's round-off.
    closed: f64,
    /// m: the largest coordinate.
    reach: f64,
}

impl TouchBand {
    /// Interaction `it`'s band, m: at least 64 units of round-off of (a
    /// bound on) its gap's scale, four times what a touch's release leaves.
    #[inline(always)]
    fn of(&self, it: &Interaction) -> f64 {
        self.closed
            .max(64.0 * f64::EPSILON * (it.offset.abs() + it.h_norm * self.reach))
    }
}

/// A compliant contact of pair `i` begun at `onset` (s) approaching at
/// `approach` (m/s), refused where the fixed step `step` (None: an adaptive
/// method or the exact flow) cannot resolve it: the law's elastic duration
/// for the pair's effective mass under two steps. Its rebound and losses
/// would be the step's, not the law's (a `hertz-damped` contact of 1e12 N/m^1.5
/// on a 1 g damper, 4e-6 s long, rebounded at 1.0 for e = 0.6 by rk4 at dt =
/// 1e-4 s, the ledger's contact loss 7 times the true one).
pub(super) fn check_resolved(
    step: Option<f64>,
    system: &Assembly,
    i: usize,
    (onset, approach): (f64, f64),
) -> Result<()> {
    let Some(dt) = step else {
        return Ok(());
    };
    let it = &system.interactions[i];
    let InteractionLaw::Compliant { law, .. } = it.law else {
        return Ok(());
    };
    let duration = law.impact_duration(1.0 / it.inverse_mass, approach);
    if duration.is_nan() || duration >= 2.0 * dt {
        return Ok(());
    }
    Err(Error::UnresolvedContact {
        time: onset,
        approach,
        duration,
        dt,
    })
}
