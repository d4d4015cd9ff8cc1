//! The event-driven kernel: no step straddles a contact onset or separation.
//!
//! Within a contact mode the right-hand side is smooth. After each step the
//! gap function `g = side (y - w) - d` is checked at the step's ends and, on
//! its cubic Hermite interpolant, inside the step (two crossings in one step,
//! a graze). An event is then located on the method's own solution: the step
//! length `h*` for which the method's step ends exactly on `g = 0` is found by
//! the Illinois method, started from the interpolant's root, to round-off in
//! time. The step is cut there, the mode switched and the method restarted
//! (its carried data is invalid after the jump in the contact force).

use crate::error::{Error, Result};
use crate::legacy::equations::{Excitation, Mode, Model};
use crate::legacy::records::{
    check_start, external_work, open_record, speed_squared_integral, ContactRecord, EnergyLedger,
    Records, Solution,
};
use crate::legacy::steppers::{to_state, to_vector, Attempt, Stepper, Vector};
use crate::methods::registry::two_mass::Settings;
use crate::methods::step_control::{rejects, StepControl};
use crate::model::contact::ContactLaw;
use crate::model::impact_damper::State;
use crate::numerics::hermite::{self, Quintic};

/// Gap of wall `side` and its rate.
#[inline(always)]
fn gap<L: ContactLaw, X: Excitation>(model: &Model<L, X>, y: &Vector, side: f64) -> (f64, f64) {
    (side * (y[2] - y[0]) - model.clearance, side * (y[3] - y[1]))
}

/// The sixth-order interpolant of the gap of `side` over the step
/// `y -> end` of length `h` taken in `mode` (accelerations at both ends).
#[allow(clippy::too_many_arguments)]
fn gap_quintic<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    time: f64,
    y: &Vector,
    end: &Vector,
    h: f64,
    mode: Mode,
    side: f64,
) -> Quintic {
    let (g0, r0) = gap(model, y, side);
    let (g1, r1) = gap(model, end, side);
    let (aw0, ay0) = model.accelerations_in(time, &to_state(y), mode);
    let (aw1, ay1) = model.accelerations_in(time + h, &to_state(end), mode);
    Quintic {
        g0,
        g1,
        m0: r0 * h,
        m1: r1 * h,
        c0: side * (ay0 - aw0) * h * h,
        c1: side * (ay1 - aw1) * h * h,
    }
}

/// What the check of one step found.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    /// The wall.
    side: f64,
    /// A step length (fraction of the step) on the old side of the event.
    before: f64,
    /// A step length (fraction) on the new side, or None if the interior
    /// extremum must be stepped to first to confirm it.
    after: Option<f64>,
    /// The interpolant's estimate of the event (fraction of the step).
    guess: f64,
}

/// Both ends of a free step outside contact, the gap's rate falling through
/// zero: touching and leaving within the step shows as a positive interior
/// maximum. The sixth-order interpolant finds it; where it and the cubic
/// disagree by more than its margin below the wall, the maximum is probed
/// with the method itself (by `locate`). Rare, so kept out of the hot loop.
#[cold]
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn interior_touch<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    time: f64,
    y: &Vector,
    end: &Vector,
    h: f64,
    mode: Mode,
    side: f64,
    graze_tolerance: f64,
    grazes: &mut u64,
) -> Option<Crossing> {
    let q = gap_quintic(model, time, y, end, h, mode, side);
    let theta = q.argmax();
    let peak = q.eval(theta).0;
    let cubic = hermite::eval(
        q.g0,
        q.g1,
        q.m0,
        q.m1,
        hermite::argmax(q.g0, q.g1, q.m0, q.m1),
    )
    .0;
    if peak > graze_tolerance || peak + (peak - cubic).abs() > 0.0 {
        Some(Crossing {
            side,
            before: 0.0,
            after: None,
            guess: theta,
        })
    } else {
        if peak > 0.0 {
            *grazes += 1;
        }
        None
    }
}

/// Looks for a mode change in the step `y -> end` of length `h`.
/// `graze_tolerance` (m): an interior touch shallower than that is a graze.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn find_crossing<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    time: f64,
    y: &Vector,
    end: &Vector,
    h: f64,
    mode: Mode,
    graze_tolerance: f64,
    grazes: &mut u64,
) -> Option<Crossing> {
    match mode {
        Mode::Free => {
            let mut best: Option<Crossing> = None;
            for side in [1.0, -1.0] {
                let (g0, r0) = gap(model, y, side);
                let (g1, r1) = gap(model, end, side);
                let (m0, m1) = (r0 * h, r1 * h);
                let found = if g1 > 0.0 {
                    // On the wall at the start (just after a separation, to
                    // round-off) and leaving it: the onset is the later
                    // crossing, after the interpolant's lowest point, not
                    // the start (that would be a contact that never was).
                    let leaving = g0 >= -graze_tolerance && m0 < 0.0 && m1 > 0.0;
                    let before = if leaving {
                        hermite::argmax(-g0, -g1, -m0, -m1)
                    } else {
                        0.0
                    };
                    let (low, _) = hermite::eval(g0, g1, m0, m1, before);
                    let guess = if leaving && low < 0.0 {
                        before + (1.0 - before) * -low / (g1 - low)
                    } else if g0 < 0.0 {
                        hermite::root(g0, g1, m0, m1)
                    } else {
                        0.0
                    };
                    Some(Crossing {
                        side,
                        before,
                        after: Some(1.0),
                        guess,
                    })
                } else if m0 > 0.0 && m1 < 0.0 {
                    interior_touch(model, time, y, end, h, mode, side, graze_tolerance, grazes)
                } else {
                    None
                };
                if let Some(c) = found {
                    if best.is_none_or(|b| c.guess < b.guess) {
                        best = Some(c);
                    }
                }
            }
            best
        }
        Mode::Contact { side, .. } => {
            let (g0, r0) = gap(model, y, side);
            let (g1, r1) = gap(model, end, side);
            let (m0, m1) = (r0 * h, r1 * h);
            if g1 < 0.0 {
                // Just after an onset g0 is zero to round-off and rising: the
                // old side is then the interior maximum, not the step start.
                let before = if g0 <= 0.0 && m0 > 0.0 && m1 < 0.0 {
                    hermite::argmax(g0, g1, m0, m1)
                } else {
                    0.0
                };
                let (gb, _) = hermite::eval(g0, g1, m0, m1, before);
                let guess = if gb > 0.0 {
                    before + (1.0 - before) * gb / (gb - g1)
                } else {
                    before
                };
                Some(Crossing {
                    side,
                    before,
                    after: Some(1.0),
                    guess: guess.max(before),
                })
            } else if m0 < 0.0 && m1 > 0.0 {
                let theta = hermite::argmax(-g0, -g1, -m0, -m1);
                let low = hermite::eval(g0, g1, m0, m1, theta).0;
                (low < -graze_tolerance).then_some(Crossing {
                    side,
                    before: 0.0,
                    after: None,
                    guess: theta,
                })
            } else {
                None
            }
        }
    }
}

/// What locating an event found.
enum Location {
    /// The step length on the new side of the event, and that step.
    Cut(f64, Attempt),
    /// The interpolant's crossing was not there.
    Unconfirmed,
    /// An interior touch shallower than the graze tolerance.
    Graze,
    /// The step up to the event would fail the error control: retry shorter.
    Reject(f64),
}

/// Locates an event inside the step `full` (of length `h`) on the method's
/// own solution: the step length at which the gap of `side` changes sign,
/// to round-off in the gap or in time.
#[allow(clippy::too_many_arguments)]
fn locate<L: ContactLaw, X: Excitation, S: Stepper>(
    model: &Model<L, X>,
    stepper: &mut S,
    time: f64,
    y: &Vector,
    h: f64,
    full: &Attempt,
    mode: Mode,
    crossing: Crossing,
    graze_tolerance: f64,
) -> Result<Location> {
    let side = crossing.side;
    let onset = matches!(mode, Mode::Free);
    // "New side": g > 0 for an onset, g < 0 for a separation.
    let new_side = |g: f64| if onset { g > 0.0 } else { g < 0.0 };
    let round_off = 4.0 * f64::EPSILON * (y[0].abs() + y[2].abs() + model.clearance);
    let (mut lo, mut g_lo) = (0.0, gap(model, y, side).0);
    if crossing.before > 0.0 {
        let length = crossing.before * h;
        let attempt = stepper.attempt(model, time, y, length, mode)?;
        let g = gap(model, &attempt.end, side).0;
        // Where the interpolant was wrong about the old side, start from 0.
        if !new_side(g) {
            (lo, g_lo) = (length, g);
        }
    }
    // The new side: the step's end, or for an interior crossing the
    // interpolant's extremum, which must be confirmed by stepping there.
    let (mut hi, mut best) = match crossing.after {
        Some(_) => (h, *full),
        None => {
            let length = crossing.guess * h;
            (length, stepper.attempt(model, time, y, length, mode)?)
        }
    };
    let mut g_hi = gap(model, &best.end, side).0;
    if !new_side(g_hi) {
        return Ok(Location::Unconfirmed);
    }
    if crossing.after.is_none() && onset && g_hi <= graze_tolerance {
        return Ok(Location::Graze);
    }
    // Whether the stepper's last attempt is the one at `hi`.
    let mut holds_hi = crossing.before == 0.0 || crossing.after.is_none();
    // Illinois: regula falsi that halves the retained end's value when the
    // same end is kept twice, so that both ends converge.
    let mut kept = 0i8;
    // The first guess from the sixth-order interpolant of the whole step.
    let mut guess = match crossing.after {
        Some(_) => {
            let quintic = gap_quintic(model, time, y, &full.end, h, mode, side);
            h * quintic.root(lo / h, 1.0)
        }
        None => crossing.guess * h,
    };
    let mut first = true;
    for _ in 0..100 {
        let width = hi - lo;
        if width <= 4.0 * f64::EPSILON * (time.abs() + hi) || g_hi.abs() <= round_off {
            break;
        }
        let mut trial = if guess > lo && guess < hi {
            guess
        } else {
            hi - g_hi * width / (g_hi - g_lo)
        };
        if !(trial > lo && trial < hi) {
            trial = 0.5 * (lo + hi);
        }
        guess = f64::NAN;
        let attempt = stepper.attempt(model, time, y, trial, mode)?;
        if S::ADAPTIVE && first && rejects(attempt.error) {
            // The step up to (about) the event is itself too long.
            return Ok(Location::Reject(trial));
        }
        first = false;
        let g = gap(model, &attempt.end, side).0;
        // On the wall to round-off is the event itself: the new mode starts
        // there (its force is continuous in the gap, so either side will do).
        if new_side(g) || g.abs() <= round_off {
            hi = trial;
            g_hi = g;
            best = attempt;
            holds_hi = true;
            if kept == 1 {
                g_lo *= 0.5;
            }
            kept = 1;
        } else {
            lo = trial;
            g_lo = g;
            holds_hi = false;
            if kept == -1 {
                g_hi *= 0.5;
            }
            kept = -1;
        }
        if g.abs() <= round_off {
            break;
        }
    }
    // The stepper's pending data must belong to the step that is kept.
    if !holds_hi && S::CARRIES_DATA {
        best = stepper.attempt(model, time, y, hi, mode)?;
    }
    Ok(Location::Cut(hi, best))
}

/// The largest indentation within the step `y -> end` (length `taken`) of a
/// contact on `side` whose indentation rate changes sign in it: located on
/// the step's sixth-order interpolant, then taken from the method's own step
/// to that instant (the maximum is flat, so that is accurate to the method).
/// Leaves the stepper holding the full step again.
#[allow(clippy::too_many_arguments)]
fn peak_indentation<L: ContactLaw, X: Excitation, S: Stepper>(
    model: &Model<L, X>,
    stepper: &mut S,
    time: f64,
    y: &Vector,
    end: &Vector,
    taken: f64,
    mode: Mode,
    side: f64,
) -> Result<f64> {
    let quintic = gap_quintic(model, time, y, end, taken, mode, side);
    let theta = quintic.argmax();
    let probe = stepper.attempt(model, time, y, theta * taken, mode)?;
    // The stepper's pending data must belong to the step that is kept.
    if S::CARRIES_DATA {
        stepper.attempt(model, time, y, taken, mode)?;
    }
    Ok(gap(model, &probe.end, side).0)
}

/// The time a contact at approach speed `speed` takes to store the relative
/// kinetic energy elastically, `delta* / speed` (s): a fraction of the
/// contact duration, used to start an adaptive method's steps after onset,
/// where `F ~ delta^1.5` makes the solution rough.
fn contact_time_scale<L: ContactLaw, X: Excitation>(model: &Model<L, X>, speed: f64) -> f64 {
    if speed <= 0.0 || !speed.is_finite() {
        return f64::INFINITY;
    }
    let m_eff = model.main_mass * model.impact_mass / (model.main_mass + model.impact_mass);
    let energy = 0.5 * m_eff * speed * speed;
    let mut hi = model.clearance.max(1e-6);
    for _ in 0..200 {
        if model.law.potential(hi) >= energy {
            break;
        }
        hi *= 2.0;
    }
    let mut lo = 0.0;
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if model.law.potential(mid) < energy {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    hi / speed
}

/// First adaptive step after onset, as a fraction of the contact time scale.
const ONSET_STEP_FRACTION: f64 = 1e-3;

/// A contact being followed.
#[derive(Debug, Clone, Copy)]
struct Open {
    side: f64,
    onset: f64,
    approach_speed: f64,
    max_indentation: f64,
    /// The non-conservative work at onset, J.
    losses_at_onset: f64,
    /// Mechanical energy at onset, J.
    energy: f64,
    /// `work_in_contact` at onset, J.
    work: f64,
}

/// How often (in accepted steps) the kernel asks whether to stop; a power of
/// two, a multiple of the energy check's interval.
const INTERRUPT_INTERVAL: u64 = 1 << 14;
/// Mode changes in a row closer than this many units of round-off of the time make chattering.
const CHATTER_ULPS: f64 = 1e3;
const CHATTER_EVENTS: u64 = 16;

/// Rebound over approach speed; NaN for a contact that did not start by an
/// approach (one open at t = 0 with the bodies at rest or separating).
pub(crate) fn restitution(rebound: f64, approach: f64) -> f64 {
    if approach > 0.0 {
        rebound / approach
    } else {
        f64::NAN
    }
}

/// The mode of the initial state: in contact when indented, or exactly at a
/// wall and moving into it.
fn initial_mode<L: ContactLaw, X: Excitation>(model: &Model<L, X>, y: &Vector) -> Mode {
    let s = to_state(y);
    let side = model.side(&s);
    let (g, rate) = gap(model, y, side);
    if g > 0.0 || (g == 0.0 && rate > 0.0) {
        Mode::Contact {
            side,
            approach_rate: rate,
        }
    } else {
        Mode::Free
    }
}

/// Integrates with located, cut and restarted contact events.
pub fn integrate_events<L: ContactLaw, X: Excitation, S: Stepper>(
    model: &Model<L, X>,
    stepper: &mut S,
    initial: &State,
    settings: &Settings,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<Solution> {
    settings.check_steps()?;
    check_start(model, initial)?;
    let fixed = !S::ADAPTIVE;
    let t0 = 0.0;
    let grid_steps = settings.steps();
    let dt = settings.dt.unwrap_or(f64::NAN);
    let t_end = if fixed {
        t0 + grid_steps as f64 * dt
    } else {
        settings.t_end
    };
    let every = settings.every;
    let graze_tolerance = 1e-12 * model.clearance.max(1e-9);
    // Events closer than a thousand units of round-off of the time itself
    // cannot be told apart (the main mass's period, or the run without a
    // spring, sets the scale near t = 0).
    let period = std::f64::consts::TAU * (model.main_mass / model.stiffness).sqrt();
    let time_scale = t_end.min(period);
    let chatter_interval = |time: f64| CHATTER_ULPS * f64::EPSILON * time.abs().max(time_scale);

    let mut y = to_vector(initial, 0.0);
    let mut time = t0;
    let mut mode = initial_mode(model, &y);
    let energy = model.energy(initial);
    let mut ledger = EnergyLedger::new(energy, X::IS_FREE, settings);
    // The method integrates the non-conservative work (y[4]): the main
    // damper's less the external force's apart, the contact's in contact.
    // The damper's and the external force's work in contact are summed here
    // (J), so that y[4] gains exactly each contact's dissipation.
    let mut work_in_contact = 0.0;
    let mut open = match mode {
        Mode::Contact {
            side,
            approach_rate,
        } => Some(Open {
            side,
            onset: t0,
            approach_speed: approach_rate,
            max_indentation: gap(model, &y, model.side(initial)).0,
            losses_at_onset: 0.0,
            energy,
            work: 0.0,
        }),
        Mode::Free => None,
    };
    stepper.reset(model, time, &y, mode);

    let rows = if fixed { grid_steps / every + 2 } else { 64 };
    if fixed {
        settings.check_rows(rows)?;
    }
    let mut records = Records::new(settings, rows)?;
    let force = |y: &Vector, mode: Mode| match mode {
        Mode::Free => 0.0,
        Mode::Contact {
            side,
            approach_rate,
        } => {
            model
                .contact_at(&to_state(y), side, approach_rate)
                .total_force
        }
    };
    records.keep(time, initial, force(&y, mode))?;

    let mut control = StepControl::new(match settings.dt {
        Some(dt) => dt,
        None => {
            let first =
                initial_step::<L, X, S>(model, &y, mode, settings.t_end, stepper.tolerance());
            match mode {
                Mode::Contact { approach_rate, .. } => {
                    first.min(ONSET_STEP_FRACTION * contact_time_scale(model, approach_rate))
                }
                Mode::Free => first,
            }
        }
    });
    let mut grid_index: u64 = 0;
    let (mut accepted, mut grazes) = (0u64, 0u64);
    let mut until_kept = every;
    let (mut last_event, mut close_events) = (f64::NEG_INFINITY, 0u64);

    while time < t_end {
        let mut length = if fixed {
            t0 + (grid_index + 1) as f64 * dt - time
        } else {
            control.h.min(t_end - time)
        };
        if fixed && length <= 0.0 {
            grid_index += 1;
            continue;
        }
        if !fixed && (t_end - time - length) < 1e-3 * length {
            // Do not leave a sliver of a step before the end.
            length = t_end - time;
        }
        let mut attempt = stepper.attempt(model, time, &y, length, mode)?;
        let mut taken = length;
        let mut switch_to: Option<Mode> = None;
        // Events first: a step that straddles an event is cut there, so that
        // the error control only ever judges steps within one smooth mode.
        if let Some(crossing) = find_crossing(
            model,
            time,
            &y,
            &attempt.end,
            length,
            mode,
            graze_tolerance,
            &mut grazes,
        ) {
            match locate(
                model,
                stepper,
                time,
                &y,
                length,
                &attempt,
                mode,
                crossing,
                graze_tolerance,
            )? {
                Location::Cut(cut, cut_attempt) => {
                    taken = cut;
                    attempt = cut_attempt;
                    switch_to = Some(match mode {
                        Mode::Free => Mode::Contact {
                            side: crossing.side,
                            approach_rate: gap(model, &attempt.end, crossing.side).1,
                        },
                        Mode::Contact { .. } => Mode::Free,
                    });
                }
                Location::Reject(shorter) => {
                    control.retry(0.9 * shorter);
                    continue;
                }
                // Not confirmed: the stepper must hold the full step again.
                Location::Unconfirmed => {
                    if S::CARRIES_DATA {
                        attempt = stepper.attempt(model, time, &y, length, mode)?
                    }
                }
                Location::Graze => {
                    grazes += 1;
                    if S::CARRIES_DATA {
                        attempt = stepper.attempt(model, time, &y, length, mode)?
                    }
                }
            }
        }
        // After a rejection the next step may not grow (Hairer's rule), which
        // stops the controller from oscillating where the solution is rough,
        // as it is near contact onset (F ~ delta^1.5).
        if S::ADAPTIVE
            && !control.judge(
                attempt.error,
                taken,
                S::shrink,
                switch_to.is_none(),
                time,
                t_end,
                accepted,
                settings.max_steps,
            )?
        {
            continue;
        }
        let end = attempt.end;
        let switched = switch_to.is_some();
        let step_mode = mode;
        if let Some(next) = switch_to {
            mode = next;
        }
        if !to_state(&end).is_finite() {
            return Err(Error::NumericalBlowUp {
                time: time + taken,
                reason: "the state is no longer finite",
            });
        }
        // Maximum indentation: where the indentation rate falls through zero
        // inside a step taken in contact, found on the method's own solution.
        if let (Some(oc), Mode::Contact { side, .. }) = (open.as_mut(), step_mode) {
            let (_, r0) = gap(model, &y, side);
            let (g1, r1) = gap(model, &end, side);
            if r0 > 0.0 && r1 <= 0.0 {
                let peak =
                    peak_indentation(model, stepper, time, &y, &end, taken, step_mode, side)?;
                oc.max_indentation = oc.max_indentation.max(peak);
            }
            oc.max_indentation = oc.max_indentation.max(g1);
        }
        stepper.accept();
        let (start, stop) = (to_state(&y), to_state(&end));
        if let Mode::Contact { .. } = step_mode {
            work_in_contact += model.damping * speed_squared_integral(taken, &start, &stop)
                - external_work(model, time, taken, &start, &stop);
        }
        ledger.external_step(model, time, taken, &start, &stop);
        time += taken;
        if fixed && !switched {
            grid_index += 1;
        }
        if fixed && switched && (t0 + (grid_index + 1) as f64 * dt - time) <= 0.0 {
            grid_index += 1;
        }
        y = end;
        accepted += 1;
        if switched {
            match mode {
                Mode::Contact {
                    side,
                    approach_rate,
                } => {
                    open = Some(Open {
                        side,
                        onset: time,
                        approach_speed: approach_rate,
                        max_indentation: gap(model, &y, side).0.max(0.0),
                        losses_at_onset: y[4],
                        energy: model.energy(&stop),
                        work: work_in_contact,
                    });
                }
                Mode::Free => {
                    if let Some(oc) = open.take() {
                        let rebound = -(oc.side * (y[3] - y[1]));
                        let work = work_in_contact - oc.work;
                        let record = ContactRecord {
                            onset: oc.onset,
                            separation: time,
                            duration: time - oc.onset,
                            max_indentation: oc.max_indentation,
                            approach_speed: oc.approach_speed,
                            rebound_speed: rebound,
                            restitution: restitution(rebound, oc.approach_speed),
                            energy_dissipated: y[4] - oc.losses_at_onset,
                            energy_change: model.energy(&stop) - oc.energy,
                        };
                        ledger.check_contact(&record, oc.energy, work)?;
                        records.contact(record, time)?;
                    }
                }
            }
            stepper.reset(model, time, &y, mode);
            if let (true, Mode::Contact { approach_rate, .. }) = (S::ADAPTIVE, mode) {
                control.h = control
                    .h
                    .min(ONSET_STEP_FRACTION * contact_time_scale(model, approach_rate));
            }
            if time - last_event < chatter_interval(time) {
                close_events += 1;
                if close_events >= CHATTER_EVENTS {
                    return Err(Error::Chattering {
                        time,
                        events: close_events,
                        interval: chatter_interval(time),
                    });
                }
            } else {
                close_events = 0;
            }
            last_event = time;
        }
        until_kept -= 1;
        let done = time >= t_end;
        // The rare work, behind one test: a history row, the energy check,
        // the question whether to stop (its interval a multiple of the
        // energy check's).
        if until_kept == 0 || ledger.due(accepted, done) {
            if until_kept == 0 || done {
                until_kept = every;
                if records.keeps_history() {
                    records.keep(time, &stop, force(&y, mode))?;
                }
            }
            if ledger.due(accepted, done) {
                ledger.check(model.energy(&stop), y[4] + work_in_contact, time)?;
                if accepted % INTERRUPT_INTERVAL == 0 && interrupt() {
                    return Err(Error::Interrupted { time });
                }
            }
        }
        if !done && accepted + control.rejected >= settings.max_steps {
            return Err(Error::TooManySteps {
                time,
                max_steps: settings.max_steps,
            });
        }
    }

    if let Some(oc) = open {
        let dissipated = y[4] - oc.losses_at_onset;
        let record = open_record(oc.onset, oc.approach_speed, oc.max_indentation, dissipated);
        records.contact(record, time)?;
    }
    Ok(Solution {
        history: records.history,
        contacts: records.contacts,
        steps: accepted,
        rejected_steps: control.rejected,
        grazing_contacts: grazes,
        rhs_evaluations: stepper.evaluations(),
        final_time: time,
        final_state: to_state(&y),
        energy_growth: ledger.growth(),
        energy_residual: ledger.residual(),
    })
}

/// A first step for the adaptive methods, after Hairer's: the size at which
/// an Euler step's change of the derivative meets the tolerance.
fn initial_step<L: ContactLaw, X: Excitation, S: Stepper>(
    model: &Model<L, X>,
    y: &Vector,
    mode: Mode,
    t_end: f64,
    tolerance: f64,
) -> f64 {
    let rates = |y: &Vector| {
        let (aw, ay) = model.accelerations_in(0.0, &to_state(y), mode);
        [y[1], aw, y[3], ay]
    };
    let norm = |v: &[f64], y: &Vector| {
        let sum: f64 = (0..4)
            .map(|n| {
                let scale = tolerance * (1.0 + y[n].abs());
                (v[n] / scale).powi(2)
            })
            .sum();
        (sum / 4.0).sqrt()
    };
    let f0 = rates(y);
    let (d0, d1) = (norm(&y[..4], y), norm(&f0, y));
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6 * t_end
    } else {
        0.01 * d0 / d1
    }
    .min(t_end);
    let mut y1 = *y;
    for n in 0..4 {
        y1[n] += h0 * f0[n];
    }
    let f1 = rates(&y1);
    let change: Vec4 = [f1[0] - f0[0], f1[1] - f0[1], f1[2] - f0[2], f1[3] - f0[3]];
    let d2 = norm(&change, y) / h0;
    let h1 = if d1.max(d2) <= 1e-15 {
        (1e-6 * h0).max(1e-3 * h0)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / S::CONTROL_EXPONENT)
    };
    (100.0 * h0).min(h1).min(0.1 * t_end).max(1e-12 * t_end)
}

type Vec4 = [f64; 4];
