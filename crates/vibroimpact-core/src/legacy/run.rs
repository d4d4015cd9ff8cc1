//! The integration kernel: steps any integrator over any contact law, keeps a
//! thinned time history and builds the table of contacts, with contact
//! instants located inside the step.

use crate::error::{Error, Result};
use crate::legacy::equations::{Excitation, Free, Model, Onset};
use crate::legacy::events::integrate_events;
use crate::legacy::integrators::{Integrator, Newmark, Rk4};
use crate::legacy::records::*;
use crate::legacy::steppers::{Dop853Stepper, Dopri5Stepper, NewmarkFamily, Rk4Stepper};
use crate::methods::registry::two_mass::*;
use crate::model::contact::{Contact, ContactLaw, LawVisitor};
use crate::model::impact_damper::{ImpactDamper, State};
use crate::numerics::hermite;

/// A contact being followed.
#[derive(Debug, Clone, Copy)]
struct OpenContact {
    side: f64,
    onset: f64,
    approach_speed: f64,
    max_indentation: f64,
    dissipated: f64,
    /// Mechanical energy at onset, J.
    energy: f64,
    /// The ledger's non-conservative work at onset, J.
    work: f64,
    /// The power of the contact's dissipative forces now (at the step's
    /// start), W: the last step's end value, not evaluated again.
    power: f64,
}

impl OpenContact {
    /// The gap function against this contact's wall and its slopes (times
    /// the step `dt`) at the ends of the step `s0 -> s1`: `(g0, g1, m0, m1)`.
    #[inline(always)]
    fn gaps<L: ContactLaw, X: Excitation>(
        &self,
        model: &Model<L, X>,
        s0: &State,
        s1: &State,
        dt: f64,
    ) -> (f64, f64, f64, f64) {
        let (side, d) = (self.side, model.clearance);
        (
            side * s0.relative_displacement() - d,
            side * s1.relative_displacement() - d,
            side * s0.relative_velocity() * dt,
            side * s1.relative_velocity() * dt,
        )
    }

    /// The deepest indentation with the step's gaps: its end, and where
    /// located, the peak of its interpolant when the step passes one.
    #[inline(always)]
    fn deepest(&mut self, located: bool, (g0, g1, m0, m1): (f64, f64, f64, f64)) {
        if located && m0 > 0.0 && m1 <= 0.0 {
            let theta = hermite::argmax(g0, g1, m0, m1);
            let peak = hermite::eval(g0, g1, m0, m1, theta).0;
            self.max_indentation = self.max_indentation.max(peak);
        }
        self.max_indentation = self.max_indentation.max(g1);
    }

    /// A step of length `dt` that ends still in contact at `s1`: the
    /// trapezoidal sum of the contact's dissipation.
    #[inline(always)]
    fn pressed<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        s1: &State,
        dt: f64,
        approach: f64,
    ) {
        let p0 = self.power;
        let c = model.contact(s1, approach);
        self.power = model.contact_dissipation(&c);
        self.dissipated += 0.5 * dt * (p0 + self.power);
    }
}

/// How often (in steps) the kernel asks whether to stop; a power of two, a
/// multiple of `ENERGY_INTERVAL`.
const INTERRUPT_INTERVAL: u64 = 1 << 16;

/// The generic kernel. `interrupt` is called every few tens of thousands of
/// steps; returning true stops the run with `Error::Interrupted`.
pub fn integrate<L: ContactLaw, X: Excitation, I: Integrator>(
    model: &Model<L, X>,
    integrator: &mut I,
    initial: &State,
    settings: &Settings,
    rhs_per_step: u64,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<Solution> {
    settings.check_steps()?;
    check_start(model, initial)?;
    let dt = settings.dt.expect("fixed stepping has a step");
    let n_steps = settings.steps();
    let every = settings.every;
    let rows = n_steps / every + 2;
    settings.check_rows(rows)?;
    let located = settings.timing == ContactTiming::Located;
    let t0 = 0.0;
    let d = model.clearance;
    let c1 = model.contact_damping;

    let mut records = Records::new(settings, rows)?;
    let keep = records.keeps_history();

    let mut s = *initial;
    let side0 = model.side(&s);
    let mut approach = side0 * s.relative_velocity();
    let start = model.contact(&s, approach);
    records.keep(t0, &s, start.total_force)?;
    let mut ledger = EnergyLedger::new(model.energy(&s), X::IS_FREE, settings);
    let mut open: Option<OpenContact> = if start.indentation > 0.0 {
        Some(OpenContact {
            side: start.side,
            onset: t0,
            approach_speed: start.rate,
            max_indentation: start.indentation,
            dissipated: 0.0,
            energy: ledger.initial,
            work: 0.0,
            power: model.contact_dissipation(&start),
        })
    } else {
        None
    };
    // Work of the contact's dissipative forces in the contacts closed so far.
    let mut closed_dissipation = 0.0;
    let start_acceleration = model.accelerations(t0, &s, approach).0;
    let damper = DamperWork::new(model.damping, dt, s.main_velocity, start_acceleration);
    // Sum of w'^2 at the step ends, for the damper's work (see DamperWork).
    let mut squares = 0.0;
    integrator.start(model, &s, t0, dt, approach);
    // A countdown, not `step % every`: an integer division per step would
    // cost more than a Newmark step.
    let mut until_kept = every;

    // A step the free flight below took and handed over (it left |y - w| <= d).
    let mut pending: Option<State> = None;
    let mut n: u64 = 0;
    while n < n_steps {
        let t = t0 + n as f64 * dt;
        let t1 = t0 + (n + 1) as f64 * dt;
        let s1 = match pending.take() {
            Some(s1) => s1,
            None => {
                if open.is_none() {
                    // Provisional latch for stages that enter contact within this
                    // step; replaced by the located onset rate once it is found.
                    approach = model.side(&s) * s.relative_velocity();
                }
                integrator.step(model, &s, t, dt, approach)
            }
        };
        finite(&s1, t1)?;
        squares += s1.main_velocity * s1.main_velocity;
        ledger.external_step(model, t, dt, &s, &s1);

        match open.as_mut() {
            // Apart while |y - w| <= d: one subtraction and a comparison in
            // the hot loop; the side only when the bodies may touch.
            None if s1.relative_displacement().abs() <= d => {}
            None => {
                let side = model.side(&s1);
                let g1 = side * s1.relative_displacement() - d;
                if g1 > 0.0 {
                    let Onset {
                        theta,
                        rate,
                        gap_at_start,
                    } = model.onset_in_step(&s, &s1, side, dt);
                    // Counting steps, a sample exactly at the wall (|y - w| = d) is
                    // already touching, as in the paper's |y - w| >= d.
                    let onset = if located {
                        t + theta * dt
                    } else if gap_at_start >= 0.0 {
                        t
                    } else {
                        t1
                    };
                    let c = model.contact(&s1, rate);
                    let p_onset = c1 * rate * rate;
                    let p1 = model.contact_dissipation(&c);
                    let (before, after) =
                        step_work(model, &damper, squares, &ledger, t, dt, &s, &s1);
                    open = Some(OpenContact {
                        side,
                        onset,
                        approach_speed: rate,
                        max_indentation: g1,
                        dissipated: 0.5 * (1.0 - theta) * dt * (p_onset + p1),
                        energy: within_step(model.energy(&s), model.energy(&s1), theta),
                        work: within_step(before, after, theta),
                        power: p1,
                    });
                    approach = rate;
                }
            }
            Some(oc) => {
                let gaps = oc.gaps(model, &s, &s1, dt);
                let (g0, g1, m0, m1) = gaps;
                oc.deepest(located, gaps);
                let p0 = oc.power;
                if g1 > 0.0 {
                    oc.pressed(model, &s1, dt, approach);
                } else {
                    let theta = if g0 > 0.0 {
                        hermite::root(g0, g1, m0, m1)
                    } else {
                        0.0
                    };
                    let rate = hermite::eval(g0, g1, m0, m1, theta).1 / dt;
                    let p_sep = c1 * rate * rate;
                    let separation = if located { t + theta * dt } else { t1 };
                    let energy = within_step(model.energy(&s), model.energy(&s1), theta);
                    let (before, after) =
                        step_work(model, &damper, squares, &ledger, t, dt, &s, &s1);
                    let work = within_step(before, after, theta);
                    let record = ContactRecord {
                        onset: oc.onset,
                        separation,
                        duration: separation - oc.onset,
                        max_indentation: oc.max_indentation,
                        approach_speed: oc.approach_speed,
                        rebound_speed: -rate,
                        restitution: crate::legacy::events::restitution(-rate, oc.approach_speed),
                        energy_dissipated: oc.dissipated + 0.5 * theta * dt * (p0 + p_sep),
                        energy_change: energy - oc.energy,
                    };
                    ledger.check_contact(&record, oc.energy, work - oc.work)?;
                    closed_dissipation += record.energy_dissipated;
                    records.contact(record, t1)?;
                    open = None;
                }
            }
        }

        s = s1;
        n += 1;
        let step = n;
        until_kept -= 1;
        // The rare work, behind one test in the hot loop: a history row, the
        // energy check, the question whether to stop (its interval a
        // multiple of the energy check's).
        let last = step == n_steps;
        if until_kept == 0 || ledger.due(step, last) {
            if until_kept == 0 || last {
                until_kept = every;
                if keep {
                    let force = model.contact(&s, approach).total_force;
                    records.keep(t1, &s, force)?;
                }
            }
            if ledger.due(step, last) {
                let open_dissipation = open.map_or(0.0, |oc| oc.dissipated);
                let mut check = Check {
                    damper: &damper,
                    closed: closed_dissipation,
                    interrupt: &mut *interrupt,
                };
                let sums = (squares, open_dissipation);
                check.run(model, &mut ledger, &s, sums, approach, step, t1)?;
            }
        }
        // No step count check: n_steps <= max_steps was checked up front.

        // The steps that need none of the above but the energy checks
        // (made there): apart ([`free_flight`]) or in contact
        // ([`contact_flight`]), until a step changes that or the next step
        // with other bookkeeping: a history row or the last step.
        let mut bound = n_steps;
        if keep {
            bound = bound.min(n + until_kept);
        }
        let start = n;
        let flight = Flight {
            state: s,
            steps: n,
            squares,
            pending: None,
            approach,
        };
        let check = Check {
            damper: &damper,
            closed: closed_dissipation,
            interrupt: &mut *interrupt,
        };
        let flight = match open.as_mut() {
            None => free_flight(model, integrator, &mut ledger, check, flight, bound, t0, dt)?,
            Some(oc) => {
                let ends = (bound, t0, dt, located);
                contact_flight(model, integrator, &mut ledger, check, oc, flight, ends)?
            }
        };
        (s, n, squares, pending, approach) = (
            flight.state,
            flight.steps,
            flight.squares,
            flight.pending,
            flight.approach,
        );
        if keep {
            until_kept -= n - start;
        }
    }

    let final_time = t0 + n_steps as f64 * dt;
    if let Some(oc) = open {
        let record = open_record(
            oc.onset,
            oc.approach_speed,
            oc.max_indentation,
            oc.dissipated,
        );
        records.contact(record, final_time)?;
    }

    Ok(Solution {
        history: records.history,
        contacts: records.contacts,
        steps: n_steps,
        rejected_steps: 0,
        grazing_contacts: 0,
        rhs_evaluations: n_steps * rhs_per_step,
        final_time,
        final_state: s,
        energy_growth: ledger.growth(),
        energy_residual: ledger.residual(),
    })
}

/// Where a free flight stands: the state after `steps` steps, the sum of
/// `w'^2` at the step ends, and, when it ended with the bodies closer than
/// the clearance, that step's end (`pending`) with the latch from its start.
struct Flight {
    state: State,
    steps: u64,
    squares: f64,
    pending: Option<State>,
    approach: f64,
}

/// The energy balance due at a step, and every `INTERRUPT_INTERVAL` steps
/// the question whether to stop: what the kernel checks every
/// `ENERGY_INTERVAL` steps, in free flight too.
struct Check<'a> {
    damper: &'a DamperWork,
    /// The work of the contact's dissipative forces in the contacts closed
    /// so far, J.
    closed: f64,
    interrupt: &'a mut dyn FnMut() -> bool,
}

impl Check<'_> {
    /// The check after `step` steps, at `t1`, in state `s` with the sum of
    /// squares and the open contact's dissipation so far (`sums`) and the
    /// latch `approach`. Out of line: in a flight a call in a branch taken
    /// every few tens of steps, leaving the loop's registers to the step.
    #[inline(never)]
    #[allow(clippy::too_many_arguments)]
    fn run<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        ledger: &mut EnergyLedger,
        s: &State,
        (squares, open_dissipation): (f64, f64),
        approach: f64,
        step: u64,
        t1: f64,
    ) -> Result<()> {
        finite(s, t1)?;
        let acceleration = model.accelerations(t1, s, approach).0;
        let damper = self
            .damper
            .corrected(squares, s.main_velocity, acceleration);
        let losses = self.closed + open_dissipation + damper - ledger.external();
        ledger.check(model.energy(s), losses, t1)?;
        if step % INTERRUPT_INTERVAL == 0 && (self.interrupt)() {
            return Err(Error::Interrupted { time: t1 });
        }
        Ok(())
    }
}

/// A state no longer finite at `time` ends the run.
#[inline(always)]
fn finite(s: &State, time: f64) -> Result<()> {
    if s.is_finite() {
        Ok(())
    } else {
        Err(Error::NumericalBlowUp {
            time,
            reason: "the state is no longer finite",
        })
    }
}

/// Free flight: the bodies apart, no history row due before step `bound`:
/// the step alone, with the trapezoidal sum of the damper's work and the
/// energy checks due (`check`, out of line), until a step ends with
/// |y - w| > d (or not finite: the comparison fails for NaN), which is
/// handed back to the full bookkeeping. A function of its own so that the
/// state stays in registers (in the kernel it lives in memory, its address
/// taken by the bookkeeping).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn free_flight<L: ContactLaw, X: Excitation, I: Integrator>(
    model: &Model<L, X>,
    integrator: &mut I,
    ledger: &mut EnergyLedger,
    mut check: Check,
    mut flight: Flight,
    bound: u64,
    t0: f64,
    dt: f64,
) -> Result<Flight> {
    let d = model.clearance;
    let (mut s, mut n, mut squares) = (flight.state, flight.steps, flight.squares);
    'flight: while n + 1 < bound {
        // The steps to the next check (or to the step before the bound).
        let until = ledger.next_due(n).min(bound - 1);
        while n < until {
            let t = t0 + n as f64 * dt;
            // The provisional latch (not computed where the law ignores it).
            let latch = model.side(&s) * s.relative_velocity();
            let s1 = integrator.step(model, &s, t, dt, latch);
            // Fails for NaN too: a state no longer finite goes to the checks.
            let apart = s1.relative_displacement().abs() <= d;
            if !apart {
                flight.pending = Some(s1);
                flight.approach = latch;
                break 'flight;
            }
            squares += s1.main_velocity * s1.main_velocity;
            ledger.external_step(model, t, dt, &s, &s1);
            s = s1;
            n += 1;
        }
        if ledger.due(n, false) {
            // Not the last step (n < bound): as the kernel checks it. The
            // bodies are apart, so the accelerations do not read the latch.
            let t1 = t0 + n as f64 * dt;
            let at = s;
            let latch = model.side(&at) * at.relative_velocity();
            check.run(model, ledger, &at, (squares, 0.0), latch, n, t1)?;
        }
    }
    (flight.state, flight.steps, flight.squares) = (s, n, squares);
    Ok(flight)
}

/// Contact flight: the bodies in contact `oc`, no history row due before
/// step `bound` (`ends` is `(bound, t0, dt, located)`): the step with the
/// contact's sums ([`OpenContact`]) and the energy checks due, until a
/// step ends the contact (or is not finite), which is handed back to the
/// full bookkeeping. A function of its own for the reasons of
/// [`free_flight`].
#[inline(never)]
fn contact_flight<L: ContactLaw, X: Excitation, I: Integrator>(
    model: &Model<L, X>,
    integrator: &mut I,
    ledger: &mut EnergyLedger,
    mut check: Check,
    oc: &mut OpenContact,
    mut flight: Flight,
    (bound, t0, dt, located): (u64, f64, f64, bool),
) -> Result<Flight> {
    let approach = flight.approach;
    let (mut s, mut n, mut squares) = (flight.state, flight.steps, flight.squares);
    let mut contact = *oc;
    'flight: while n + 1 < bound {
        let until = ledger.next_due(n).min(bound - 1);
        while n < until {
            let t = t0 + n as f64 * dt;
            let s1 = integrator.step(model, &s, t, dt, approach);
            let gaps = contact.gaps(model, &s, &s1, dt);
            // Fails for NaN too.
            if !(gaps.1 > 0.0 && s1.is_finite()) {
                flight.pending = Some(s1);
                break 'flight;
            }
            squares += s1.main_velocity * s1.main_velocity;
            ledger.external_step(model, t, dt, &s, &s1);
            contact.deepest(located, gaps);
            contact.pressed(model, &s1, dt, approach);
            s = s1;
            n += 1;
        }
        if ledger.due(n, false) {
            // Not the last step (n < bound): as the kernel checks it.
            let t1 = t0 + n as f64 * dt;
            let at = s;
            let sums = (squares, contact.dissipated);
            check.run(model, ledger, &at, sums, approach, n, t1)?;
        }
    }
    *oc = contact;
    (flight.state, flight.steps, flight.squares) = (s, n, squares);
    Ok(flight)
}

/// The non-conservative work outside the contact (main damper minus external
/// force, J) at the start and at the end of the fixed step `s0 -> s1` just
/// summed: for a contact event inside it.
#[allow(clippy::too_many_arguments)]
fn step_work<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    damper: &DamperWork,
    squares: f64,
    ledger: &EnergyLedger,
    time: f64,
    dt: f64,
    s0: &State,
    s1: &State,
) -> (f64, f64) {
    let after = damper.so_far(squares, s1.main_velocity) - ledger.external();
    let (v0, v1) = (s0.main_velocity, s1.main_velocity);
    let step =
        0.5 * model.damping * dt * (v0 * v0 + v1 * v1) - external_work(model, time, dt, s0, s1);
    (after - step, after)
}

/// A quantity at fraction `theta` of a step, between its values at the
/// step's ends (second order, like the fixed-step kernel's other sums).
#[inline]
fn within_step(start: f64, end: f64, theta: f64) -> f64 {
    start + theta * (end - start)
}

fn with_method<L: ContactLaw>(
    model: &Model<L, Free>,
    initial: &State,
    settings: &Settings,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<Solution> {
    let events = settings.stepping == Stepping::Events;
    match settings.method {
        Method::Newmark { beta, gamma } if !events => integrate(
            model,
            &mut Newmark::new(beta, gamma),
            initial,
            settings,
            1,
            interrupt,
        ),
        Method::Rk4 if !events => integrate(model, &mut Rk4, initial, settings, 4, interrupt),
        Method::Newmark { beta, gamma } => {
            let mut stepper = NewmarkFamily::newmark(beta, gamma, true);
            integrate_events(model, &mut stepper, initial, settings, interrupt)
        }
        Method::NewmarkImplicit { beta, gamma } => {
            let mut stepper = NewmarkFamily::newmark(beta, gamma, false);
            integrate_events(model, &mut stepper, initial, settings, interrupt)
        }
        Method::GeneralizedAlpha { spectral_radius } => {
            let mut stepper = NewmarkFamily::generalized_alpha(spectral_radius);
            integrate_events(model, &mut stepper, initial, settings, interrupt)
        }
        Method::Rk4 => integrate_events(
            model,
            &mut Rk4Stepper::default(),
            initial,
            settings,
            interrupt,
        ),
        Method::Dopri5(tolerances) => {
            let mut stepper = Dopri5Stepper::new(tolerances);
            integrate_events(model, &mut stepper, initial, settings, interrupt)
        }
        Method::Dop853(tolerances) => {
            let mut stepper = Dop853Stepper::new(tolerances);
            integrate_events(model, &mut stepper, initial, settings, interrupt)
        }
    }
}

/// Integrate the unforced impact damper: dispatches once on the contact law
/// and the method, then runs the monomorphised kernel.
///
/// Every run has limits, each refused up front where it is known and stopped
/// with a clear error where it is not: steps (`max_steps`; a fixed-step
/// count `t_end / dt` beyond it is refused before the first step), memory
/// (`max_rows` history rows plus contacts; a fixed-step
/// history beyond it is refused, any other stops at it; `history = false`
/// keeps none), and physics: a start with the bodies interpenetrating is
/// refused, and a result whose energy balance misses by more than
/// `energy_tolerance` of the energy in play, or one of whose contacts creates
/// energy beyond it, is an error, never output (see `EnergyLedger`).
pub fn simulate(
    system: &ImpactDamper,
    contact: &Contact,
    initial: &State,
    settings: &Settings,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<Solution> {
    struct Run<'a> {
        system: &'a ImpactDamper,
        contact_damping: f64,
        initial: &'a State,
        settings: &'a Settings,
        interrupt: &'a mut dyn FnMut() -> bool,
    }
    impl LawVisitor for Run<'_> {
        type Output = Result<Solution>;
        fn visit<L: ContactLaw>(self, law: L) -> Result<Solution> {
            let model = Model::new(self.system, law, self.contact_damping, Free);
            with_method(&model, self.initial, self.settings, self.interrupt)
        }
    }
    contact.visit(Run {
        system,
        contact_damping: contact.damping,
        initial,
        settings,
        interrupt,
    })
}
