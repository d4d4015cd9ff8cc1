//! Fixed stepping ([`Stepping::Fixed`]): steps of `dt` not cut at contacts,
//! as 0.1's two-mass kernel and the founding paper took them, over any
//! [`Assembly`] whose pairs are all compliant. A contact's force (its law's
//! and its contact damper's) acts where its pair is indented, nothing apart:
//! 0.1's force, a function of the state (its modes are marked
//! `indented_only`, see [`Mode::Compliant`]). The contact state at a step's
//! start holds through the step (the modes change from the next step on,
//! see [`SystemStepper::switched_within_step`]), except that a method whose
//! force is not lagged (RK4, the implicit Newmark family) feels a contact
//! entered within the step in the stages past the wall, with 0.1's
//! provisional approach rate (the indentation rate at the step's start).
//!
//! Onsets and separations are where the cubic Hermite interpolant of the
//! indentation crosses zero within the step (`ContactTiming::Located`), or
//! counted in whole steps (`ContactTiming::StepCount`: the onset is the
//! step's start when its sample is already touching, else its end; the
//! separation the end of the step that ends apart). Records as 0.1 kept
//! them: the approach rate at the located onset (which the contact then
//! latches), the deepest indentation (with `Located`, the interpolant's peak
//! inside a step), the contact's dissipation as the trapezoidal sum of its
//! power over the steps (the onset's and separation's steps in part), and
//! the energy change over the contact from the stored energies at the steps'
//! ends, interpolated to the onset and separation.

use crate::error::{Error, Result};
use crate::kernel::clock::Stop;
use crate::kernel::contact_balance::OnsetBalance;
use crate::kernel::contacts::check_resolved;
use crate::kernel::events::{ContactKind, ContactTiming, Open, Stepping};
use crate::kernel::run::Run;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, InteractionLaw, Mode};
use crate::model::contact::ContactLaw;
use crate::numerics::hermite;

/// Whether `stepper` may step `system` fixed: a fixed-step method, every
/// pair compliant.
pub(crate) fn check<S: SystemStepper>(system: &Assembly, stepper: &S) -> Result<()> {
    if stepper.is_adaptive() || stepper.is_exact() {
        return Err(Error::Inconsistent(format!(
            "stepping = \"fixed\" takes a fixed-step method (rk4, newmark, newmark-implicit, \
             generalized-alpha), not {:?}; use stepping = \"events\"",
            stepper.name()
        )));
    }
    check_laws(system)
}

/// Whether fixed steps may take `system`'s laws: every pair compliant, no
/// friction (the single run's check, and a lockstep study's).
pub(crate) fn check_laws(system: &Assembly) -> Result<()> {
    if let Some(it) = system.interactions.iter().find(|it| it.law.is_friction()) {
        return Err(Error::Inconsistent(format!(
            "stepping = \"fixed\" cannot locate stick-slip ({} has friction): use stepping = \
             \"events\"",
            system.pairs[it.pair]
        )));
    }
    if let Some(it) = system
        .interactions
        .iter()
        .find(|it| matches!(it.law, InteractionLaw::Rigid { .. }))
    {
        return Err(Error::Inconsistent(format!(
            "stepping = \"fixed\" takes compliant contact laws only (pair {} is rigid): give it a \
             compliant law (hertz, hyster-hertz, hertz-damped, linear) or use stepping = \"events\"",
            it.pair
        )));
    }
    Ok(())
}

/// The power of compliant interaction `i`'s dissipative forces at state `y`
/// with the approach rate `approach` latched (W; 0 apart): 0.1's
/// `contact_dissipation`.
#[inline(always)]
fn dissipation(system: &Assembly, i: usize, y: &[f64], approach: f64) -> f64 {
    let InteractionLaw::Compliant { law, damping } = system.interactions[i].law else {
        return 0.0;
    };
    let (gap, rate) = system.gap(i, y);
    let (indentation, rate) = (-gap, -rate);
    if indentation > 0.0 {
        // Both forces from one evaluation (one square root for the Hertz
        // laws), the same bits as `force` and `elastic_force` apart.
        let (force, elastic) = law.force_and_elastic(indentation, rate, approach);
        (force + damping * rate - elastic) * rate
    } else {
        0.0
    }
}

/// The force of compliant interaction `i` at state `y` in `mode` (N, > 0
/// pushing the pair apart; 0 apart): its law's and its contact damper's.
/// Apart, a law that reads the approach rate is given the indentation rate.
pub(super) fn contact_force(system: &Assembly, i: usize, y: &[f64], mode: Mode) -> f64 {
    let InteractionLaw::Compliant { law, damping } = system.interactions[i].law else {
        return 0.0;
    };
    let (gap, rate) = system.gap(i, y);
    let (indentation, rate) = (-gap, -rate);
    let approach = match mode {
        Mode::Compliant { approach_rate, .. } => approach_rate,
        _ => rate,
    };
    if indentation > 0.0 {
        law.force(indentation, rate, approach) + damping * rate
    } else {
        0.0
    }
}

/// A step's indentation data `(i0, i1, m0, m1)` from a pair's gap and rate
/// `(gap, rate)` at its start and end, `dt` long: the indentation (m) at
/// its ends and its rate times the step (0.1's data).
#[inline(always)]
pub(crate) fn indentation_data(
    (g0, r0): (f64, f64),
    (g1, r1): (f64, f64),
    dt: f64,
) -> (f64, f64, f64, f64) {
    (-g0, -g1, -r0 * dt, -r1 * dt)
}

/// A contact's deepest indentation with the step's indentation data `(i0,
/// i1, m0, m1)` ([`indentation_data`]): its end, and where located, the
/// interpolant's peak when the step passes one.
#[inline(always)]
pub(crate) fn deepest(oc: &mut Open, (i0, i1, m0, m1): (f64, f64, f64, f64), located: bool) {
    if located && m0 > 0.0 && m1 <= 0.0 {
        let peak = hermite::argmax(i0, i1, m0, m1);
        let deepest = hermite::eval(i0, i1, m0, m1, peak).0;
        oc.max_indentation = oc.max_indentation.max(deepest);
    }
    oc.max_indentation = oc.max_indentation.max(i1);
}

/// A step of `dt` of compliant interaction `i`'s contact `oc` (in `mode`)
/// that ends still in contact at `end`: the trapezoidal sum of its
/// dissipated power.
#[inline(always)]
pub(crate) fn press(system: &Assembly, i: usize, oc: &mut Open, end: &[f64], mode: Mode, dt: f64) {
    let latched = match mode {
        Mode::Compliant { approach_rate, .. } => approach_rate,
        _ => 0.0,
    };
    pressed(oc, dissipation(system, i, end, latched), dt);
}

/// A step of `dt` of contact `oc` that ends still in contact with the
/// dissipated `power` (W) at its end: the trapezoidal sum (see [`press`]).
#[inline(always)]
pub(crate) fn pressed(oc: &mut Open, power: f64, dt: f64) {
    let p0 = oc.power;
    oc.power = power;
    oc.dissipated += 0.5 * dt * (p0 + power);
}

/// A quantity at fraction `theta` of a step, between its values at the
/// step's ends.
fn within_step(start: f64, end: f64, theta: f64) -> f64 {
    start + theta * (end - start)
}

/// A contact change found in a fixed step.
#[derive(Debug, Clone, Copy)]
pub(super) enum Change {
    /// Onset, at fraction `theta` of the step, approaching at `rate` m/s.
    Onset { theta: f64, rate: f64 },
    /// Separation at fraction `theta`, receding at `-rate` m/s.
    Separation { theta: f64, rate: f64 },
}

impl Run<'_> {
    /// The timing of contacts of a fixed-step run (None: events).
    pub(super) fn timing(stepping: Stepping) -> Option<ContactTiming> {
        match stepping {
            Stepping::Events => None,
            Stepping::Fixed { contact_timing } => Some(contact_timing),
        }
    }

    /// One fixed step of `dt` from the grid point `grid dt`, its contacts
    /// recorded; why it ended (an event where a contact began or ended).
    pub(super) fn fixed_step<S: SystemStepper>(&mut self, stepper: &mut S) -> Result<Stop> {
        let (system, schedule) = (self.system, self.schedule);
        let time = self.clock.time;
        if schedule.at_end(time) {
            return Ok(Stop::End);
        }
        let dt = schedule.dt;
        // Again where a pair entered contact within the step (its force
        // then acts past the wall), for a method whose force is not lagged.
        let mut entered = false;
        loop {
            stepper.attempt(
                system,
                time,
                &self.y,
                dt,
                &self.modes,
                &mut self.scratch,
                &mut self.end,
            )?;
            system.gaps(&self.end, &mut self.gaps.end);
            if entered || stepper.creates_contact_energy() || !self.entered_within() {
                break;
            }
            entered = true;
        }
        if entered {
            self.left_within(time)?;
        }
        let row = 2 * system.dim;
        if self.end[..row].iter().fold(0.0, |sum, v| sum + v * 0.0) != 0.0 {
            return Err(Error::NumericalBlowUp {
                time: time + dt,
                reason: "the state is no longer finite",
            });
        }
        let kept_attempt = !self.reduce(stepper, dt, true)?;
        let first = self.fixed_changes(dt);
        if kept_attempt {
            stepper.accept();
        } else {
            stepper.reset();
        }
        let next = (self.clock.grid + 1) as f64 * dt;
        let settle = first.is_some()
            || (self.clock.accepted + 1) % crate::kernel::balance::ENERGY_INTERVAL == 0
            || schedule.done(next);
        stepper.finish(
            system,
            time,
            &self.y,
            dt,
            &self.modes,
            &mut self.scratch,
            &mut self.end,
            settle,
        )?;
        if first.is_some() {
            self.record_changes(time, dt)?;
            stepper.switched_within_step();
        }
        self.clock.time = next;
        self.clock.grid += 1;
        std::mem::swap(&mut self.y, &mut self.end);
        std::mem::swap(&mut self.gaps.start, &mut self.gaps.end);
        self.clock.accepted += 1;
        self.taken = dt;
        if first.is_some() {
            self.balance_changes()?;
        }
        Ok(match first {
            Some(interaction) => Stop::Event { interaction },
            None => Stop::Step,
        })
    }

    /// Whether a compliant pair apart at the step's start ends it indented:
    /// it then enters contact within the step, and is given its force there
    /// with 0.1's provisional approach rate (the indentation rate at the
    /// step's start), for the step to be taken again. An open pair feels no
    /// force; in contact mode, only where indented: the step taken again
    /// is 0.1's, whose force is the state's with that latch (except where
    /// a pair's stages indent in a step whose ends are apart: 0.1 pushed
    /// it there, this kernel does not look).
    fn entered_within(&mut self) -> bool {
        let mut any = false;
        for i in 0..self.modes.len() {
            if self.open[i].is_none() && self.gaps.end[i].0 < 0.0 {
                self.modes[i] = Mode::Compliant {
                    approach_rate: -self.gaps.start[i].1,
                    indented_only: true,
                };
                any = true;
            }
        }
        any
    }

    /// A pair given its force for a step taken again that ends it apart
    /// (the force pushed it back): still open, no force from the next step
    /// on (it had kept the provisional latch). Its contact began and ended
    /// within the step from `time`: refused where its law's duration at the
    /// closing speed the step began with is under two steps (a hertz-damped
    /// 1 g damper of 1e12 N/m^1.5 arriving at 0.23 m/s had been thrown back at
    /// 76 m/s, a contact never recorded, the energy created caught only at the
    /// next one).
    fn left_within(&mut self, time: f64) -> Result<()> {
        for i in 0..self.modes.len() {
            if self.open[i].is_none() && self.gaps.end[i].0 >= 0.0 {
                if let Mode::Compliant { approach_rate, .. } = self.modes[i] {
                    check_resolved(self.contact_step, self.system, i, (time, approach_rate))?;
                }
                self.modes[i] = Mode::Open;
            }
        }
        Ok(())
    }

    /// Each compliant pair's contact change in the step `y -> end` of `dt`
    /// (into `self.changes`), the deepest indentation and the dissipation
    /// of the contacts that go on; the first pair that changed.
    fn fixed_changes(&mut self, dt: f64) -> Option<usize> {
        let system = self.system;
        let located = self.timing == Some(ContactTiming::Located);
        let mut first = None;
        for i in 0..self.modes.len() {
            let ends = (self.gaps.start[i], self.gaps.end[i]);
            let (i0, i1, m0, m1) = indentation_data(ends.0, ends.1, dt);
            self.changes[i] = None;
            match self.open[i].as_mut() {
                None if i1 > 0.0 => {
                    let theta = if i0 <= 0.0 {
                        hermite::root(i0, i1, m0, m1)
                    } else {
                        0.0
                    };
                    let rate = hermite::eval(i0, i1, m0, m1, theta).1 / dt;
                    self.changes[i] = Some(Change::Onset { theta, rate });
                }
                None => continue,
                Some(oc) => {
                    deepest(oc, (i0, i1, m0, m1), located);
                    if i1 > 0.0 {
                        press(system, i, oc, &self.end, self.modes[i], dt);
                        continue;
                    }
                    let theta = if i0 > 0.0 {
                        hermite::root(i0, i1, m0, m1)
                    } else {
                        0.0
                    };
                    let rate = hermite::eval(i0, i1, m0, m1, theta).1 / dt;
                    self.changes[i] = Some(Change::Separation { theta, rate });
                }
            }
            first = first.or(Some(i));
        }
        first
    }

    /// The contacts begun and ended in the step from `time` of `dt`: their
    /// records, and the modes from the next step on.
    fn record_changes(&mut self, time: f64, dt: f64) -> Result<()> {
        let system = self.system;
        let located = self.timing == Some(ContactTiming::Located);
        let t1 = (self.clock.grid + 1) as f64 * dt;
        let energies = (
            system.energy(&self.y, &self.all_compliant),
            system.energy(&self.end, &self.all_compliant),
        );
        // A contact's own balance is taken from the start of the step that
        // enters it: an implicit method's step across the onset can create
        // energy too (generalized-alpha at four steps a contact: a lossless
        // contact left at 1.019 of its speed, unseen from the onset step's end).
        let onset_balance = self
            .changes
            .iter()
            .any(|c| matches!(c, Some(Change::Onset { .. })))
            .then(|| {
                let energy = self.energy;
                OnsetBalance::at(
                    system,
                    &self.y,
                    &self.modes,
                    energy.stored_start,
                    energy.impact_loss,
                )
            });
        for i in 0..self.modes.len() {
            let Some(change) = self.changes[i] else {
                continue;
            };
            let InteractionLaw::Compliant { damping, .. } = system.interactions[i].law else {
                continue;
            };
            match change {
                Change::Onset { theta, rate } => {
                    let i0 = -self.gaps.start[i].0;
                    let onset = if located {
                        time + theta * dt
                    } else if i0 >= 0.0 {
                        time
                    } else {
                        t1
                    };
                    // Checked at the closing speed the step began with: the
                    // interpolant's rate at the crossing of a step far too long
                    // for the contact is the overshoot's, not the approach's.
                    let closing = -self.gaps.start[i].1;
                    let approach = if closing > 0.0 { closing } else { rate };
                    check_resolved(self.contact_step, system, i, (onset, approach))?;
                    let power = dissipation(system, i, &self.end, rate);
                    let p_onset = damping * rate * rate;
                    self.modes[i] = Mode::Compliant {
                        approach_rate: rate,
                        indented_only: true,
                    };
                    self.open[i] = Some(Open {
                        kind: ContactKind::Compliant,
                        onset,
                        approach_speed: rate,
                        max_indentation: -self.gaps.end[i].0,
                        dissipated: 0.5 * (1.0 - theta) * dt * (p_onset + power),
                        resting: false,
                        balance: onset_balance.unwrap_or_default(),
                        energy: within_step(energies.0, energies.1, theta),
                        power,
                    });
                }
                Change::Separation { theta, rate } => {
                    let separation = if located { time + theta * dt } else { t1 };
                    self.modes[i] = Mode::Open;
                    let Some(oc) = self.open[i].take() else {
                        continue;
                    };
                    let p_separation = damping * rate * rate;
                    let dissipated = oc.dissipated + 0.5 * theta * dt * (oc.power + p_separation);
                    let mut record =
                        oc.close(system.interactions[i].pair, separation, -rate, dissipated);
                    record.energy_change = within_step(energies.0, energies.1, theta) - oc.energy;
                    self.closing[i] = Some(oc.balance);
                    self.contacts.push(record);
                }
            }
        }
        Ok(())
    }

    /// Each contact ended in the last step: its own balance (it must not
    /// create energy) from the start of the step that began it to this
    /// step's end.
    fn balance_changes(&mut self) -> Result<()> {
        let system = self.system;
        let energy = self.energy;
        let closed = self
            .changes
            .iter()
            .filter(|c| matches!(c, Some(Change::Separation { .. })))
            .count();
        // The records just pushed, in the order of their pairs.
        let first = self.contacts.len() - closed;
        let mut k = first;
        for i in 0..self.modes.len() {
            let Some(onset) = self.closing[i].take() else {
                continue;
            };
            let record = self.contacts[k];
            k += 1;
            onset.check_separation(
                system,
                &self.y,
                &self.modes,
                (energy.stored_start, energy.impact_loss),
                energy.scale,
                (energy.tolerance, self.creates_contact_energy),
                &record,
            )?;
        }
        Ok(())
    }

    /// A resumed compliant contact's sums for fixed stepping: its power now
    /// and the stored energy at the start.
    pub(super) fn resume_fixed(&mut self) {
        let system = self.system;
        let stored = system.energy(&self.y, &self.all_compliant);
        for (i, record) in self.open.iter_mut().enumerate() {
            if let Some(oc) = record {
                // 0.1's latch: the indentation rate at the start.
                let approach = -system.gap(i, &self.y).1;
                self.modes[i] = Mode::Compliant {
                    approach_rate: approach,
                    indented_only: true,
                };
                oc.approach_speed = approach;
                oc.power = dissipation(system, i, &self.y, approach);
                oc.energy = stored;
                oc.dissipated = 0.0;
            }
        }
    }
}

#[cfg(test)]
#[path = "fixed_tests.rs"]
mod tests;
