//! Where an event lies in a step: every interaction's event value (a gap,
//! an indentation or a sticking pair's constraint force), the earliest
//! crossing a step shows ([`find_crossing`], from the ends and the cubic
//! Hermite interpolant of [`crate::numerics::hermite`]), and its location on
//! the method's own solution ([`locate`]: the step length that ends on it).

use crate::error::Result;
use crate::kernel::held::{held_value, Held, Probe};
use crate::methods::step_control::rejects;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, Mode, Scratch};
use crate::numerics::hermite;

/// The value whose sign change is interaction `i`'s event: positive on the
/// side it is on now (open: the gap; compliant contact: the indentation;
/// sticking: the constraint force; sliding: the sliding speed; stuck: the
/// static force left before it slips).
#[allow(clippy::too_many_arguments)]
pub(super) fn event_value(
    system: &Assembly,
    i: usize,
    mode: Mode,
    time: f64,
    y: &[f64],
    modes: &[Mode],
    scratch: &mut Scratch,
    work: &mut [f64],
) -> f64 {
    // A held element's value is a force: its gap is not needed.
    let gap = match mode {
        Mode::Sticking | Mode::Stuck { .. } => (f64::NAN, f64::NAN),
        _ => system.gap(i, y),
    };
    event_value_from(system, i, mode, gap, time, y, modes, scratch, work)
}

/// [`event_value`] where interaction `i`'s gap and rate at `y` are known,
/// as [`Assembly::gaps`] gives them (the same bits as [`Assembly::gap`]): a
/// gap's, an indentation's or a sliding speed's value without the products
/// again.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn event_value_from(
    system: &Assembly,
    i: usize,
    mode: Mode,
    (gap, rate): (f64, f64),
    time: f64,
    y: &[f64],
    modes: &[Mode],
    scratch: &mut Scratch,
    work: &mut [f64],
) -> f64 {
    match mode {
        Mode::Open => gap,
        Mode::Compliant { .. } => -gap,
        Mode::Sliding { direction } => direction * rate,
        Mode::Sticking | Mode::Stuck { .. } => {
            let force = constraint_force(system, i, (time, y, modes), scratch, work);
            held_value(system, i, mode, force)
        }
    }
}

/// The force that holds interaction `i` (a sticking pair or a stuck friction
/// element, along its row) at `time` and state `y` in `modes`, N; 0 where
/// it is not held.
pub(super) fn constraint_force(
    system: &Assembly,
    i: usize,
    (time, y, modes): (f64, &[f64], &[Mode]),
    scratch: &mut Scratch,
    work: &mut [f64],
) -> f64 {
    system.rates(time, y, modes, scratch, work);
    scratch.force_of(i).unwrap_or(0.0)
}

/// Whether interaction `i`, whose event value at state `y` is `v`, is at its
/// event: past its wall, or on it to round-off and arriving. Pairs that
/// reach their walls together (two dampers touching one point at rest) are
/// all switched at the instant one of them is located; and a value a hair
/// past its wall but leaving it (a contact started at a gap of round-off,
/// its indentation growing) has not crossed back.
pub(super) fn crossed(system: &Assembly, i: usize, mode: Mode, v: f64, y: &[f64]) -> bool {
    match mode {
        // Stopped (or reversed): a sliding speed within round-off is zero.
        Mode::Sliding { .. } => return v <= 0.0,
        Mode::Stuck { .. } => return v < 0.0,
        _ => {}
    }
    if mode == Mode::Sticking {
        // No force holding it (exactly zero, a system at rest on its
        // walls) is released too: it was found as an event, and kept
        // sticking it would be found again at once, without end.
        return v <= 0.0 && !system.locked(i);
    }
    if v.abs() <= wall_round_off(system, i, y) {
        // Arriving.
        side(mode) * system.gap(i, y).1 <= 0.0
    } else {
        v < 0.0
    }
}

/// The sign that turns interaction `i`'s gap into its event value in `mode`
/// (NaN for a sticking pair, whose value is a force).
pub(super) fn side(mode: Mode) -> f64 {
    match mode {
        Mode::Open => 1.0,
        Mode::Compliant { .. } => -1.0,
        Mode::Sticking | Mode::Sliding { .. } | Mode::Stuck { .. } => f64::NAN,
    }
}

/// The round-off of interaction `i`'s gap at state `y`, m: a value this
/// close to zero is on its wall.
pub(super) fn wall_round_off(system: &Assembly, i: usize, y: &[f64]) -> f64 {
    8.0 * f64::EPSILON * system.gap_scale(i, y)
}

/// Whether interaction `i`, whose event value at state `y` is `v`, is past
/// its wall by more than round-off (a sticking pair: its force below zero).
pub(super) fn past(system: &Assembly, i: usize, mode: Mode, v: f64, y: &[f64]) -> bool {
    match mode {
        Mode::Sticking => v < 0.0 && !system.locked(i),
        Mode::Sliding { .. } | Mode::Stuck { .. } => v < 0.0,
        // (The round-off's products only for a value below the wall.)
        _ => v < 0.0 && v < -wall_round_off(system, i, y),
    }
}

/// An event found in a step: interaction `i`, first guessed at the fraction
/// `guess` of the step; `interior` when both ends are on the old side.
#[derive(Debug, Clone, Copy)]
pub(super) struct Crossing {
    pub(super) i: usize,
    pub(super) guess: f64,
    pub(super) interior: bool,
    /// A fraction of the step on the old side (0: the start), for a value
    /// that starts on the wall (just after an event) and moves away first.
    pub(super) before: f64,
    /// The interpolant's root (a fraction of the step): the first guess of
    /// the crossing (for an interior dip, once the dip is confirmed).
    pub(super) root: f64,
}

/// Every interaction's gap and rate (see [`Assembly::gaps`]) at a step's
/// start and at its end: a kept step's end is the next one's start.
pub(super) struct Gaps {
    pub(super) start: Vec<(f64, f64)>,
    pub(super) end: Vec<(f64, f64)>,
}

/// The earliest event in the step `y -> end` of length `h` (`gaps` at both),
/// from the end values and, for gaps, the cubic Hermite interpolant (an
/// interior touch or separation deeper than `graze` m counts; a shallower one
/// is a graze).
#[allow(clippy::too_many_arguments)]
pub(super) fn find_crossing(
    system: &Assembly,
    time: f64,
    gaps: &Gaps,
    (start, end): (&[f64], &[f64]),
    h: f64,
    modes: &[Mode],
    graze: f64,
    grazes: &mut u64,
    scratch: &mut Scratch,
    (work, probe): (&mut [f64], Probe<'_>),
    skip: &[bool],
) -> Option<Crossing> {
    let mut held = Held {
        probe,
        end: false,
        start: false,
    };
    let mut best: Option<Crossing> = None;
    let mut consider = |c: Crossing| {
        if best.is_none_or(|b| c.guess < b.guess) {
            best = Some(c);
        }
    };
    for (i, &mode) in modes.iter().enumerate() {
        if skip[i] || (mode == Mode::Open && system.held_by_mirror(i, modes)) {
            continue;
        }
        let sign = match mode {
            Mode::Open => 1.0,
            Mode::Compliant { .. } => -1.0,
            Mode::Sticking if system.locked(i) => continue,
            Mode::Sliding { direction } => {
                if let Some(c) = sliding_crossing(i, direction, gaps.start[i], gaps.end[i], h) {
                    consider(c);
                }
                continue;
            }
            Mode::Sticking | Mode::Stuck { .. } => {
                let v1 = event_value(system, i, mode, time + h, end, modes, scratch, work);
                if v1 < 0.0 {
                    consider(Crossing {
                        i,
                        guess: 1.0,
                        interior: false,
                        before: 0.0,
                        root: f64::NAN,
                    });
                    continue;
                }
                // `event_value` left the run's rates at the end in `work`.
                let at = ((time, h), (start, end));
                let run = (&*scratch, &*work);
                if let Some((guess, root)) = held.dip((system, modes), (i, mode, v1), at, run) {
                    consider(Crossing {
                        i,
                        guess,
                        interior: true,
                        before: 0.0,
                        root,
                    });
                }
                continue;
            }
        };
        let ((g0, r0), (g1, r1)) = (gaps.start[i], gaps.end[i]);
        let (v0, v1, m0, m1) = (sign * g0, sign * g1, sign * r0 * h, sign * r1 * h);
        if v1 < 0.0 {
            // On the wall at the start (to round-off, just after an event)
            // and moving away: the crossing is the later one, after the
            // interpolant's maximum.
            let before = if v0 <= graze && m0 > 0.0 && m1 < 0.0 {
                hermite::peak(v0, v1, m0, m1)
            } else if v0 <= graze && m0 > 0.0 {
                // Rising again at the end (the wall's own motion turned
                // within the step): the first maximum, where it turned back,
                // if the interpolant rises there above a graze (a step far
                // longer than the flight says nothing of it).
                let top = hermite::first_maximum(v0, v1, m0, m1);
                if hermite::eval(v0, v1, m0, m1, top).0 > graze {
                    top
                } else {
                    0.0
                }
            } else {
                0.0
            };
            let top = hermite::eval(v0, v1, m0, m1, before).0;
            // The interpolant's root: a guess within its error of the event.
            let guess = if top > 0.0 {
                hermite::root_within(v0, v1, m0, m1, before, 1.0)
            } else {
                before
            };
            consider(Crossing {
                i,
                guess,
                interior: false,
                before,
                root: guess,
            });
        } else if m0 < 0.0 && m1 > 0.0 {
            // The value falls then rises within the step: a dip below zero?
            // The interpolant errs by its fourth-order term (5e-5 of the
            // swing at the exact flow's eighth of a period): a dip that it
            // takes down to half of the ends' lower value is checked on the
            // method's own solution (`locate` finds its lowest point there).
            let theta = hermite::peak(-v0, -v1, -m0, -m1);
            let low = hermite::eval(v0, v1, m0, m1, theta).0;
            if low < -graze || low < 0.5 * v0.min(v1) {
                consider(Crossing {
                    i,
                    guess: theta,
                    interior: true,
                    before: 0.0,
                    root: hermite::root_within(v0, v1, m0, m1, 0.0, theta),
                });
            } else if low < 0.0 {
                *grazes += 1;
            }
        }
    }
    best
}

/// A sliding friction element's stop in a step of length `h` whose ends
/// have the row's displacement and rate `start` and `end`: the rate (the
/// sliding velocity) is the derivative of the displacement's cubic Hermite
/// interpolant, a quadratic, whose first root after the start is the guess
/// (a crossing the ends show), or whose dip below zero and back (a stop
/// and a slide on, within the step) is checked on the method's solution.
fn sliding_crossing(
    i: usize,
    direction: f64,
    (g0, r0): (f64, f64),
    (g1, r1): (f64, f64),
    h: f64,
) -> Option<Crossing> {
    // h v(theta) = a theta^2 + b theta + c, v(0) = r0, v(1) = r1 (times direction).
    let (d0, d1, fall) = (
        direction * r0 * h,
        direction * r1 * h,
        direction * (g0 - g1),
    );
    let (a, b, c) = (
        6.0 * fall + 3.0 * d0 + 3.0 * d1,
        -6.0 * fall - 4.0 * d0 - 2.0 * d1,
        d0,
    );
    // The first root after the start (a start at zero speed, just set
    // sliding, is not one).
    let first_root = || {
        let roots = if a == 0.0 {
            [-c / b, f64::NAN]
        } else {
            let disc = (b * b - 4.0 * a * c).max(0.0).sqrt();
            let q = -0.5 * (b + b.signum() * disc);
            [q / a, c / q]
        };
        roots
            .into_iter()
            .filter(|t| *t > 1e-9 && *t <= 1.0)
            .fold(f64::NAN, f64::min)
    };
    if d1 < 0.0 {
        let root = first_root();
        let guess = if root.is_nan() { 1.0 } else { root };
        return Some(Crossing {
            i,
            guess,
            interior: false,
            before: 0.0,
            root: guess,
        });
    }
    // A dip that the quadratic takes below zero, or down to half of the
    // ends' lower speed (it errs by far more than a shallow stop's depth
    // over a long step), is checked on the method's solution.
    let lowest = -b / (2.0 * a);
    let low = a * lowest * lowest + b * lowest + c;
    if a > 0.0 && lowest > 0.0 && lowest < 1.0 && (low < 0.0 || low < 0.5 * d0.min(d1)) {
        return Some(Crossing {
            i,
            guess: lowest,
            interior: true,
            before: 0.0,
            root: first_root(),
        });
    }
    None
}

/// Whether any interaction is in a compliant contact.
pub(super) fn any_compliant(modes: &[Mode]) -> bool {
    modes.iter().any(|m| matches!(m, Mode::Compliant { .. }))
}

/// Whether [`find_crossing`] may find anything in the step whose `gaps` are
/// given: a cheap test of every interaction that passes all those it could
/// report (and some it will not), so that most steps skip it. A value ending
/// on its wall's far side, or one whose rate turns from towards the wall to
/// away (the dip test's `m0 < 0 < m1`: the rates' signs, which the step's
/// length multiplies), or a sticking pair.
#[inline(always)]
pub(super) fn may_cross(gaps: &Gaps, modes: &[Mode]) -> bool {
    let mut any = false;
    for ((start, end), mode) in gaps.start.iter().zip(&gaps.end).zip(modes) {
        any |= mode.may_cross(*start, *end);
    }
    any
}

/// The root `dt` near `-v / slope` of `v + slope dt + second dt^2 / 2 +
/// third dt^3 / 6` (a value's Taylor polynomial about a trial): Newton's
/// method on the polynomial from the tangent's root. Its error is that of the
/// polynomial, fourth order in the distance to the event, against second
/// order for the tangent's root alone (which it falls back to where the
/// polynomial turns away).
pub(super) fn taylor_root(v: f64, slope: f64, second: f64, third: f64) -> f64 {
    let tangent = -v / slope;
    let mut dt = tangent;
    for _ in 0..4 {
        let p = v + dt * (slope + dt * (0.5 * second + dt * (third / 6.0)));
        let dp = slope + dt * (second + dt * (0.5 * third));
        if dp == 0.0 || (dp > 0.0) != (slope > 0.0) {
            return tangent;
        }
        let step = p / dp;
        dt -= step;
        if step.abs() <= 1e-3 * f64::EPSILON * dt.abs() {
            break;
        }
    }
    // Within twice the tangent's step: the polynomial's root near the trial.
    if dt.is_finite() && (dt - tangent).abs() <= tangent.abs() {
        dt
    } else {
        tangent
    }
}

/// What locating an event found.
pub(super) enum Location {
    /// The step length ending on the event and its scaled error; the
    /// attempt is in `best`.
    Cut(f64, f64),
    /// The interpolant's dip was not there.
    Unconfirmed,
    /// An open pair's dip reaches past its wall by less than the graze
    /// tolerance: a graze, no contact.
    Graze,
    /// The step up to (about) the event fails the error control.
    Reject(f64),
}

/// Buffers of the location.
pub(super) struct Buffers {
    pub(super) probe: Vec<f64>,
    /// Rates at a step's start (reductions).
    pub(super) start: Vec<f64>,
    pub(super) best: Vec<f64>,
    pub(super) work: Vec<f64>,
    /// Accelerations and their rates at a trial's end (`dim` each), where
    /// the stepper gives them.
    pub(super) accel: Vec<f64>,
    pub(super) jerk: Vec<f64>,
    /// A state a little along its rates, the rates, a work space of their
    /// own and the holding forces (a held force's rate: see [`Probe`]).
    pub(super) shifted: Vec<f64>,
    pub(super) rates: Vec<f64>,
    pub(super) held: Scratch,
    pub(super) forces: Vec<f64>,
}

/// Locates interaction `c.i`'s event in the step of length `h` whose end is
/// `full`: Illinois on the step length, to round-off in time or in value (an
/// open pair's interior dip shallower than `graze` m is a graze).
#[allow(clippy::too_many_arguments)]
pub(super) fn locate<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    time: f64,
    y: &[f64],
    h: f64,
    full: &[f64],
    full_error: f64,
    modes: &[Mode],
    (c, graze): (Crossing, f64),
    scratch: &mut Scratch,
    buffers: &mut Buffers,
) -> Result<Location> {
    let mode = modes[c.i];
    let round_off = wall_round_off(system, c.i, y);
    let value = |end: &[f64], at: f64, scratch: &mut Scratch, work: &mut [f64]| {
        event_value(system, c.i, mode, at, end, modes, scratch, work)
    };
    let (mut lo, mut v_lo) = (0.0, value(y, time, scratch, &mut buffers.work));
    let sign = side(mode);
    // On the wall to round-off (or as far off it as a release puts a pair,
    // twice that: `Assembly::release`) and moving away (a rebound): the
    // event is where it comes back, after a stretch on the old side to
    // start from.
    let leaving = match mode {
        // Just set sliding from rest (a stuck pair slipping, or one that
        // stopped sliding back): the speed starts at zero and grows, and the
        // event is where it comes back to zero, after a stretch sliding.
        Mode::Sliding { .. } => v_lo <= system.rate_round_off(c.i, y),
        _ => v_lo.abs() <= 4.0 * round_off && sign * system.gap(c.i, y).1 > 0.0,
    };
    if c.before > 0.0 || leaving {
        let mut length = if c.before > 0.0 {
            c.before * h
        } else {
            0.5 * h
        };
        // A flight far shorter than the step, which the interpolant cannot
        // see (another pair's event cut the step later): shorter probes,
        // down to the round-off of the time, find it.
        while length > 4.0 * f64::EPSILON * (time.abs() + h) {
            stepper.attempt(system, time, y, length, modes, scratch, &mut buffers.probe)?;
            let v = value(&buffers.probe, time + length, scratch, &mut buffers.work);
            if v > 0.0 {
                (lo, v_lo) = (length, v);
                break;
            }
            // Where the interpolant was wrong about the old side, start
            // from 0.
            if !leaving {
                break;
            }
            length *= 0.125;
        }
    }
    let (mut hi, mut v_hi, mut best_error);
    if c.interior {
        let step = (time, y, h, full);
        match dip_bottom(system, stepper, step, modes, c, scratch, buffers)? {
            // Touching the wall by less than the tolerance, confirmed on the
            // method's solution: a graze (as the 0.1 kernel counted it).
            Ok((_, v, _)) if mode == Mode::Open && v >= -graze => return Ok(Location::Graze),
            Ok(bottom) => (hi, v_hi, best_error) = bottom,
            Err(end) => return Ok(end),
        }
    } else {
        hi = h;
        best_error = full_error;
        buffers.best.copy_from_slice(full);
        v_hi = value(full, time + h, scratch, &mut buffers.work);
    }
    if v_lo < 0.0 {
        // Starting on the wall to round-off: the event is the start.
        v_lo = 0.0;
    }
    // The interpolant's root first (within its error of the event), then
    // Newton's steps on the step length from the value's rate at each
    // trial's end (a gap's rate is in the state), kept inside the bracket;
    // regula falsi (Illinois) where Newton's step leaves it.
    let mut guess = c.root * h;
    let mut kept = 0i8;
    let mut first = true;
    for _ in 0..200 {
        let width = hi - lo;
        if width <= 4.0 * f64::EPSILON * (time.abs() + hi) || v_hi.abs() <= round_off {
            break;
        }
        let mut trial = if guess > lo && guess < hi {
            guess
        } else {
            hi - v_hi * width / (v_hi - v_lo)
        };
        if !(trial > lo && trial < hi) {
            trial = 0.5 * (lo + hi);
        }
        guess = f64::NAN;
        let error = stepper.attempt(system, time, y, trial, modes, scratch, &mut buffers.probe)?;
        if stepper.is_adaptive() && first && rejects(error) {
            return Ok(Location::Reject(trial));
        }
        first = false;
        let v = value(&buffers.probe, time + trial, scratch, &mut buffers.work);
        let slope = sign * system.gap(c.i, &buffers.probe).1;
        let mut converged = false;
        if slope != 0.0 && slope.is_finite() {
            let correction = v / slope;
            // Newton's correction within the round-off of the time itself:
            // the trial is the event (to a unit in the last place of the
            // time, as a bracket that narrow would say).
            converged = correction.abs() <= f64::EPSILON * (time.abs() + trial);
            guess = trial - correction;
            if !converged && stepper.end_derivatives(system, &mut buffers.accel, &mut buffers.jerk)
            {
                let h_i = &system.interactions[c.i].h;
                let second = sign * crate::numerics::linalg::dot(h_i, &buffers.accel);
                let third = sign * crate::numerics::linalg::dot(h_i, &buffers.jerk);
                guess = trial + taylor_root(v, slope, second, third);
            }
        }
        // The event is where the value reaches its wall moving towards it: a
        // value within round-off of zero while moving away is the start's own
        // touch (a pair just off its wall, or a dip's way back), the old side.
        let arriving = slope.is_nan() || slope <= 0.0;
        let at_event = (v.abs() <= round_off || converged) && arriving;
        if v < 0.0 || at_event {
            hi = trial;
            v_hi = v;
            best_error = error;
            std::mem::swap(&mut buffers.best, &mut buffers.probe);
            if kept == 1 {
                v_lo *= 0.5;
            }
            kept = 1;
        } else {
            lo = trial;
            v_lo = v;
            if kept == -1 {
                v_hi *= 0.5;
            }
            kept = -1;
        }
        if at_event {
            break;
        }
    }
    Ok(Location::Cut(hi, best_error))
}

/// The lowest point of interaction `c.i`'s interior dip (from the
/// interpolant's guess) in the step of length `h` from `(time, y)`, on the
/// method's own solution: the step length there, its value (below zero:
/// the dip crosses) and scaled error; or the location's end where the step
/// fails the error control or the dip stays above its wall.
#[allow(clippy::too_many_arguments)]
fn dip_bottom<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    (time, y, h, full): (f64, &[f64], f64, &[f64]),
    modes: &[Mode],
    c: Crossing,
    scratch: &mut Scratch,
    buffers: &mut Buffers,
) -> Result<std::result::Result<(f64, f64, f64), Location>> {
    let mode = modes[c.i];
    if let Mode::Sliding { direction } = mode {
        let (step, sliding) = ((time, y, h, full), (modes, c.i, direction));
        return sliding_bottom(system, stepper, step, sliding, scratch, buffers);
    }
    let sign = side(mode);
    let value = |end: &[f64], at: f64, scratch: &mut Scratch, work: &mut [f64]| {
        event_value(system, c.i, mode, at, end, modes, scratch, work)
    };
    let (mut hi, mut v_hi, mut best_error);
    hi = c.guess * h;
    best_error = stepper.attempt(system, time, y, hi, modes, scratch, &mut buffers.best)?;
    if stepper.is_adaptive() && rejects(best_error) {
        return Ok(Err(Location::Reject(hi)));
    }
    v_hi = value(&buffers.best, time + hi, scratch, &mut buffers.work);
    // The dip's lowest point on the method's solution: Newton's steps on
    // the value's rate from the interpolant's (each squares the error of
    // the time, so a graze the interpolant hides is found or ruled out).
    for _ in 0..4 {
        if v_hi < 0.0 {
            break;
        }
        let rate = sign * system.gap(c.i, &buffers.best).1;
        let curvature = sign
            * system.gap_acceleration(
                c.i,
                time + hi,
                &buffers.best,
                modes,
                scratch,
                &mut buffers.work,
            );
        let lowest = hi - rate / curvature;
        if !(curvature > 0.0 && lowest > 0.0 && lowest < h) || lowest == hi {
            break;
        }
        hi = lowest;
        best_error = stepper.attempt(system, time, y, hi, modes, scratch, &mut buffers.best)?;
        v_hi = value(&buffers.best, time + hi, scratch, &mut buffers.work);
    }
    if v_hi >= 0.0 {
        return Ok(Err(Location::Unconfirmed));
    }
    Ok(Ok((hi, v_hi, best_error)))
}

/// [`dip_bottom`] of a sliding friction element `i`: the lowest sliding
/// speed of a dip inside the step, where its rate (the row's relative
/// acceleration, in `direction`) turns from falling to rising, bracketed
/// from the step's ends (`y` and `full`) and narrowed by the secant on the
/// method's solution, stopping at the first trial whose speed has passed
/// zero. A speed has no curvature in the state (the gaps' Newton steps
/// take the acceleration for it): a dip of 1e-5 m/s on a speed of 1 m/s,
/// and the stick it begins, had gone unseen inside a step.
fn sliding_bottom<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    (time, y, h, full): (f64, &[f64], f64, &[f64]),
    (modes, i, direction): (&[Mode], usize, f64),
    scratch: &mut Scratch,
    buffers: &mut Buffers,
) -> Result<std::result::Result<(f64, f64, f64), Location>> {
    let rate = |state: &[f64], at: f64, scratch: &mut Scratch, work: &mut [f64]| {
        direction * system.gap_acceleration(i, at, state, modes, scratch, work)
    };
    let (mut lo, mut rate_lo) = (0.0, rate(y, time, scratch, &mut buffers.work));
    let (mut hi, mut rate_hi) = (h, rate(full, time + h, scratch, &mut buffers.work));
    if !(rate_lo < 0.0 && rate_hi > 0.0) {
        return Ok(Err(Location::Unconfirmed));
    }
    for _ in 0..16 {
        let width = hi - lo;
        let secant = lo - rate_lo * width / (rate_hi - rate_lo);
        // Inside the bracket by a tenth of it, so that it narrows.
        let trial = secant.clamp(lo + 0.1 * width, hi - 0.1 * width);
        let error = stepper.attempt(system, time, y, trial, modes, scratch, &mut buffers.best)?;
        if stepper.is_adaptive() && rejects(error) {
            return Ok(Err(Location::Reject(trial)));
        }
        let speed = direction * system.gap(i, &buffers.best).1;
        if speed <= 0.0 {
            return Ok(Ok((trial, speed, error)));
        }
        let r = rate(&buffers.best, time + trial, scratch, &mut buffers.work);
        if r < 0.0 {
            (lo, rate_lo) = (trial, r);
        } else {
            (hi, rate_hi) = (trial, r);
        }
        if hi - lo <= 4.0 * f64::EPSILON * (time.abs() + h) {
            break;
        }
    }
    Ok(Err(Location::Unconfirmed))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_taylor_polynomial_s_root_is_fourth_order() {
        crate::testing::timeout(30, || {
            // A cubic about a trial: its root exactly, where the tangent is off.
            let p = |t: f64| (t - 0.3) * (t + 2.0) * (t - 4.0);
            let dp = |t: f64| 3.0 * t * t - 4.6 * t - 7.4;
            let d2p = |t: f64| 6.0 * t - 4.6;
            let trial = 0.36;
            let dt = taylor_root(p(trial), dp(trial), d2p(trial), 6.0);
            assert!((trial + dt - 0.3).abs() < 1e-15, "{}", trial + dt);
            let tangent = -p(trial) / dp(trial);
            assert!((trial + tangent - 0.3).abs() > 1e-5);
            // sin t = 1/2 from 0.5: error ~ (pi/6 - 0.5)^4 / 24 against the
            // tangent's ~ (pi/6 - 0.5)^2 / 2.
            let t = 0.5f64;
            let dt = taylor_root(t.sin() - 0.5, t.cos(), -t.sin(), -t.cos());
            let root = std::f64::consts::FRAC_PI_6;
            assert!((t + dt - root).abs() < 2e-8, "{}", t + dt - root);
            let tangent = -(t.sin() - 0.5) / t.cos();
            assert!((t + tangent - root).abs() > 1e-4);
            // A polynomial that turns away before reaching zero: the tangent.
            let dt = taylor_root(1.0, -1.0, 4.0, 0.0);
            assert_eq!(dt, 1.0);
        });
    }
}
