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

use crate::model::assembly::{Assembly, InteractionLaw, Mode, Scratch, CONTACT};

/// Contacts held before those a run does not keep are dropped (see
/// [`ReduceOptions::contacts_from`]): a few, so that dropping them costs as
/// little as holding them.
const COMPACTED_CONTACTS: usize = 64;

/// The contact-loss accumulator of interaction `i` in a state vector.
#[inline(always)]
fn loss_slot(system: &Assembly, i: usize) -> usize {
    2 * system.dim + CONTACT + i
}
use crate::error::{Error, Result};
pub use crate::kernel::balance::EnergyBalance;
use crate::kernel::balance::{balance, check_balance, EnergySampler, ENERGY_INTERVAL};
use crate::kernel::compact::Stretch;
use crate::kernel::contact_balance::OnsetBalance;
use crate::kernel::impacts::{self, Impacts};
use crate::kernel::memory::{self, MAX_RECORD_BYTES};
use crate::kernel::reductions::{self, ReduceOptions, Reductions};
use crate::methods::step_control::{rejects, StepControl};
use crate::methods::steppers::SystemStepper;
use crate::numerics::hermite;

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
    pub steps: u64,
    pub rejected_steps: u64,
    pub rhs_evaluations: u64,
    pub grazing_contacts: u64,
    pub reductions: Reductions,
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
            // A sticking pair does not rebound.
            ContactKind::Sticking if separation.is_finite() => 0.0,
            // A contact that started at rest was never an impact: its
            // rebound over a round-off approach would be any number (1e58).
            _ if self.resting => f64::NAN,
            _ if self.approach_speed > 0.0 => rebound / self.approach_speed,
            _ => f64::NAN,
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
        }
    }
}

/// The value whose sign change is interaction `i`'s event: positive on the
/// side it is on now (open: the gap; compliant contact: the indentation;
/// sticking: the constraint force).
#[allow(clippy::too_many_arguments)]
fn event_value(
    system: &Assembly,
    i: usize,
    mode: Mode,
    time: f64,
    y: &[f64],
    modes: &[Mode],
    scratch: &mut Scratch,
    work: &mut [f64],
) -> f64 {
    match mode {
        Mode::Open => system.gap(i, y).0,
        Mode::Compliant { .. } => -system.gap(i, y).0,
        Mode::Sticking => {
            system.rates(time, y, modes, scratch, work);
            scratch.force_of(i).unwrap_or(0.0)
        }
    }
}

/// Whether interaction `i`, whose event value at state `y` is `v`, is at its
/// event: past its wall, or on it to round-off and arriving. Pairs that
/// reach their walls together (two dampers touching one point at rest) are
/// all switched at the instant one of them is located; and a value a hair
/// past its wall but leaving it (a contact started at a gap of round-off,
/// its indentation growing) has not crossed back.
fn crossed(system: &Assembly, i: usize, mode: Mode, v: f64, y: &[f64]) -> bool {
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
fn side(mode: Mode) -> f64 {
    match mode {
        Mode::Open => 1.0,
        Mode::Compliant { .. } => -1.0,
        Mode::Sticking => f64::NAN,
    }
}

/// The round-off of interaction `i`'s gap at state `y`, m: a value this
/// close to zero is on its wall.
fn wall_round_off(system: &Assembly, i: usize, y: &[f64]) -> f64 {
    8.0 * f64::EPSILON * system.gap_scale(i, y)
}

/// Whether interaction `i`, whose event value at state `y` is `v`, is past
/// its wall by more than round-off (a sticking pair: its force below zero).
fn past(system: &Assembly, i: usize, mode: Mode, v: f64, y: &[f64]) -> bool {
    match mode {
        Mode::Sticking => v < 0.0 && !system.locked(i),
        _ => v < -wall_round_off(system, i, y),
    }
}

/// An event found in a step: interaction `i`, first guessed at the fraction
/// `guess` of the step; `interior` when both ends are on the old side.
#[derive(Debug, Clone, Copy)]
struct Crossing {
    i: usize,
    guess: f64,
    interior: bool,
    /// A fraction of the step on the old side (0: the start), for a value
    /// that starts on the wall (just after an event) and moves away first.
    before: f64,
    /// The interpolant's root (a fraction of the step): the first guess of
    /// the crossing (for an interior dip, once the dip is confirmed).
    root: f64,
}

/// Every interaction's gap and rate (see [`Assembly::gaps`]) at a step's
/// start and at its end: a kept step's end is the next one's start.
struct Gaps {
    start: Vec<(f64, f64)>,
    end: Vec<(f64, f64)>,
}

/// Where the slope of the cubic Hermite interpolant (see [`hermite::eval`])
/// falls from `m0 > 0` to `m1 <= 0`: its maximum over the step, in closed
/// form (the slope is a quadratic in theta with one root in [0, 1]).
fn cubic_argmax(g0: f64, g1: f64, m0: f64, m1: f64) -> f64 {
    // slope(theta) = a theta^2 + b theta + m0.
    let a = 6.0 * (g0 - g1) + 3.0 * (m0 + m1);
    let b = 6.0 * (g1 - g0) - 4.0 * m0 - 2.0 * m1;
    if m1 >= 0.0 {
        return 1.0;
    }
    let root = if a == 0.0 {
        -m0 / b
    } else {
        // The two roots without cancellation: q / a and m0 / q.
        let q = -0.5 * (b + b.signum() * (b * b - 4.0 * a * m0).max(0.0).sqrt());
        let (r1, r2) = (q / a, if q != 0.0 { m0 / q } else { f64::NAN });
        // The one in [0, 1] (slope(0) > 0 >= slope(1): exactly one).
        if (0.0..=1.0).contains(&r1) && !(0.0..=1.0).contains(&r2) {
            r1
        } else if (0.0..=1.0).contains(&r2) && !(0.0..=1.0).contains(&r1) {
            r2
        } else {
            // Both (or neither) by round-off: the one whose slope is closer to 0.
            let slope = |t: f64| hermite::eval(g0, g1, m0, m1, t.clamp(0.0, 1.0)).1.abs();
            if slope(r1) <= slope(r2) || r2.is_nan() {
                r1
            } else {
                r2
            }
        }
    };
    if root.is_nan() {
        0.5
    } else {
        root.clamp(0.0, 1.0)
    }
}

/// The first local maximum of the cubic Hermite interpolant whose slope
/// starts at `m0 > 0` and ends at `m1 >= 0`: the smaller root of its slope
/// in [0, 1] when it falls below zero between them, else 0 (no maximum
/// inside: it rises throughout).
fn first_maximum(g0: f64, g1: f64, m0: f64, m1: f64) -> f64 {
    // slope(theta) = a theta^2 + b theta + m0, as in [`cubic_argmax`].
    let a = 6.0 * (g0 - g1) + 3.0 * (m0 + m1);
    let b = 6.0 * (g1 - g0) - 4.0 * m0 - 2.0 * m1;
    let discriminant = b * b - 4.0 * a * m0;
    if a <= 0.0 || discriminant <= 0.0 {
        // A slope that opens downwards and ends >= 0 stays >= 0; one with
        // no real roots never falls below zero.
        return 0.0;
    }
    // Both roots positive (their product m0 / a > 0): the smaller one.
    let q = -0.5 * (b - discriminant.sqrt());
    let root = m0 / q;
    if root > 0.0 && root < 1.0 {
        root
    } else {
        0.0
    }
}

/// A root of the cubic Hermite interpolant (see [`hermite::eval`]) between
/// `lo` and `hi` in theta, where it has opposite signs (else `hi`): Newton's
/// method on its power form, safeguarded by bisection, to 1e-10 in theta
/// (the interpolant itself is off by ~ theta^4 of the value's swing). The
/// first guess of an event's location.
fn cubic_root(g0: f64, g1: f64, m0: f64, m1: f64, mut lo: f64, mut hi: f64) -> f64 {
    // g0 + m0 t + c2 t^2 + c3 t^3.
    let c2 = 3.0 * (g1 - g0) - 2.0 * m0 - m1;
    let c3 = 2.0 * (g0 - g1) + m0 + m1;
    let value = |t: f64| g0 + t * (m0 + t * (c2 + t * c3));
    let (v_lo, v_hi) = (value(lo), value(hi));
    if v_lo == 0.0 {
        return lo;
    }
    if v_hi == 0.0 || (v_lo > 0.0) == (v_hi > 0.0) {
        return hi;
    }
    let positive_below = v_lo > 0.0;
    let mut theta = lo + (hi - lo) * v_lo / (v_lo - v_hi);
    for _ in 0..64 {
        let v = value(theta);
        if v == 0.0 {
            return theta;
        }
        if (v > 0.0) == positive_below {
            lo = theta;
        } else {
            hi = theta;
        }
        let slope = m0 + theta * (2.0 * c2 + 3.0 * theta * c3);
        let newton = theta - v / slope;
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - theta).abs() <= 1e-10 || hi - lo <= 1e-10 {
            return next;
        }
        theta = next;
    }
    theta
}

/// The earliest event in the step `y -> end` of length `h` (`gaps` at both),
/// from the end values and, for gaps, the cubic Hermite interpolant (an
/// interior touch or separation deeper than `graze` m counts; a shallower one
/// is a graze).
#[allow(clippy::too_many_arguments)]
fn find_crossing(
    system: &Assembly,
    time: f64,
    gaps: &Gaps,
    end: &[f64],
    h: f64,
    modes: &[Mode],
    graze: f64,
    grazes: &mut u64,
    scratch: &mut Scratch,
    work: &mut [f64],
    skip: &[bool],
) -> Option<Crossing> {
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
            Mode::Sticking => {
                let value = event_value(system, i, mode, time + h, end, modes, scratch, work);
                if value < 0.0 {
                    consider(Crossing {
                        i,
                        guess: 1.0,
                        interior: false,
                        before: 0.0,
                        root: f64::NAN,
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
                cubic_argmax(v0, v1, m0, m1)
            } else if v0 <= graze && m0 > 0.0 {
                // Rising again at the end (the wall's own motion turned
                // within the step): the first maximum, where it turned back,
                // if the interpolant rises there above a graze (a step far
                // longer than the flight says nothing of it).
                let top = first_maximum(v0, v1, m0, m1);
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
                cubic_root(v0, v1, m0, m1, before, 1.0)
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
            let theta = cubic_argmax(-v0, -v1, -m0, -m1);
            let low = hermite::eval(v0, v1, m0, m1, theta).0;
            if low < -graze || low < 0.5 * v0.min(v1) {
                consider(Crossing {
                    i,
                    guess: theta,
                    interior: true,
                    before: 0.0,
                    root: cubic_root(v0, v1, m0, m1, 0.0, theta),
                });
            } else if low < 0.0 {
                *grazes += 1;
            }
        }
    }
    best
}

/// Whether any interaction is in a compliant contact.
fn any_compliant(modes: &[Mode]) -> bool {
    modes.iter().any(|m| matches!(m, Mode::Compliant { .. }))
}

/// Whether [`find_crossing`] may find anything in the step whose `gaps` are
/// given: a cheap test of every interaction that passes all those it could
/// report (and some it will not), so that most steps skip it. A value ending
/// on its wall's far side, or one whose rate turns from towards the wall to
/// away (the dip test's `m0 < 0 < m1`: the rates' signs, which the step's
/// length multiplies), or a sticking pair.
#[inline(always)]
fn may_cross(gaps: &Gaps, modes: &[Mode]) -> bool {
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
fn taylor_root(v: f64, slope: f64, second: f64, third: f64) -> f64 {
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
enum Location {
    /// The step length ending on the event and its scaled error; the
    /// attempt is in `best`.
    Cut(f64, f64),
    /// The interpolant's dip was not there.
    Unconfirmed,
    /// The step up to (about) the event fails the error control.
    Reject(f64),
}

/// Buffers of the location.
struct Buffers {
    probe: Vec<f64>,
    /// Rates at a step's start (reductions).
    start: Vec<f64>,
    best: Vec<f64>,
    work: Vec<f64>,
    /// Accelerations and their rates at a trial's end (`dim` each), where
    /// the stepper gives them.
    accel: Vec<f64>,
    jerk: Vec<f64>,
}

/// Locates interaction `c.i`'s event in the step of length `h` whose end is
/// `full`: Illinois on the step length, to round-off in time or in value.
#[allow(clippy::too_many_arguments)]
fn locate<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    time: f64,
    y: &[f64],
    h: f64,
    full: &[f64],
    full_error: f64,
    modes: &[Mode],
    c: Crossing,
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
    let leaving = v_lo.abs() <= 4.0 * round_off && sign * system.gap(c.i, y).1 > 0.0;
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
        hi = c.guess * h;
        best_error = stepper.attempt(system, time, y, hi, modes, scratch, &mut buffers.best)?;
        if stepper.is_adaptive() && rejects(best_error) {
            return Ok(Location::Reject(hi));
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
            return Ok(Location::Unconfirmed);
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

/// Chattering of compliant contacts: this many mode changes in a row, each
/// closer than the time's round-off can resolve, stop it.
const CHATTER_EVENTS: u64 = 16;
const CHATTER_ULPS: f64 = 1e3;
/// Steps in a row at the round-off of time that stop a run.
const STALLED_STEPS: u64 = 64;
/// Systems of more coordinates than this also ask whether to stop by the
/// clock (their steps cost far more than reading it).
const TIMED_POLLS_BEYOND: usize = 16;
/// The longest such a system goes without asking whether to stop, s.
const POLL_SECONDS: f64 = 0.2;
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
/// [`Error::MemoryLimit`].
pub fn integrate_system_within<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    initial: &[f64],
    options: &RunOptions,
    interrupt: &mut dyn FnMut() -> bool,
    record_limit: u64,
) -> Result<SystemSolution> {
    let len = system.state_len();
    let d = system.dim;
    let count = system.interactions.len();
    let adaptive = stepper.is_adaptive();
    let t_end = options.t_end;
    let dt = options.dt.unwrap_or(f64::NAN);
    if !adaptive && (dt.is_nan() || dt <= 0.0) {
        return Err(Error::Inconsistent(format!(
            "dt is required for method {:?} (a step in s > 0)",
            stepper.name()
        )));
    }
    let graze = 1e-12
        * system
            .interactions
            .iter()
            .map(|it| it.offset.abs())
            .fold(1e-9, f64::max);
    // The time below which a chattering sequence is summed: the step, or a
    // millionth of the structure's longest period; without one (a body on
    // no spring), of the system's time scale (its forcing period or fall
    // time), not of the run: a cut-off growing with t_end had counted one
    // orbit's impacts differently in runs of different lengths.
    let resolution = if adaptive || stepper.is_exact() {
        let longest = if system.longest_period.is_finite() {
            system.longest_period
        } else {
            system.time_scale()
        };
        1e-6 * t_end.min(longest)
    } else {
        dt
    };
    // Events closer than a thousand units of round-off of the time itself
    // cannot be told apart.
    let time_scale = t_end.min(system.longest_period);
    let chatter_interval = |time: f64| CHATTER_ULPS * f64::EPSILON * time.abs().max(time_scale);

    // A stepper may be reused across runs: nothing carries over from the last.
    stepper.reset();
    let mut y = initial.to_vec();
    let mut end = vec![0.0; len];
    let mut full = vec![0.0; len];
    let mut buffers = Buffers {
        probe: vec![0.0; len],
        best: vec![0.0; len],
        work: vec![0.0; len],
        start: vec![0.0; len],
        accel: vec![0.0; d],
        jerk: vec![0.0; d],
    };
    let mut scratch = Scratch::new(system);
    // The reductions evaluate with their own: the signals' values the steps
    // cache (a harmonic's rotated phasor) are then the same bits whatever is
    // reduced (a peak differed in its last bit with the RMS kept or not).
    let mut reduce_scratch = Scratch::new(system);
    let mut modes = vec![Mode::Open; count];
    let mut open: Vec<Option<Open>> = vec![None; count];
    // A compliant pair that starts in contact (a run continued from another's
    // end) resumes it, its approach rate taken as the indentation rate now
    // (a damped law's at least the pressing's, as at any onset).
    for i in 0..count {
        let (gap, rate) = system.gap(i, &y);
        if gap < 0.0 && matches!(system.interactions[i].law, InteractionLaw::Compliant { .. }) {
            let approach = rate.abs().max(f64::MIN_POSITIVE);
            let (approach_rate, resting) = compliant_onset(
                system,
                i,
                0.0,
                &y,
                approach,
                &modes,
                &mut scratch,
                &mut buffers.work,
                (chatter_interval(0.0), time_scale),
            );
            modes[i] = Mode::Compliant { approach_rate };
            open[i] = Some(Open {
                kind: ContactKind::Compliant,
                onset: 0.0,
                approach_speed: approach,
                max_indentation: -gap,
                dissipated: y[loss_slot(system, i)],
                resting,
                balance: OnsetBalance::default(),
            });
        }
    }
    let mut gaps = Gaps {
        start: vec![(0.0, 0.0); count],
        end: vec![(0.0, 0.0); count],
    };
    system.gaps(&y, &mut gaps.start);
    let (stored_start, mut energy_scale) = system.energy_terms(&y, &modes);
    for record in open.iter_mut().flatten() {
        record.balance = OnsetBalance::at(system, &y, &modes, stored_start, 0.0);
    }
    let mut energy_sampler = EnergySampler::new(system, t_end);
    let mut impact_loss = 0.0;
    let mut contacts: Vec<PairContact> = Vec::new();
    let row = 2 * d;
    let mut time_rows: Vec<f64> = Vec::new();
    let mut states: Vec<f64> = Vec::new();
    // Bytes held by the records other than the history (strobes, contacts).
    let others = |reductions: &Reductions, contacts: &Vec<PairContact>| {
        memory::held(&reductions.strobe)
            + memory::held(&reductions.strobe_time)
            + memory::held(contacts)
    };
    // The error of a run whose records find no room, with what they hold.
    let no_room = |cause: memory::NoRoom,
                   time: f64,
                   time_rows: &Vec<f64>,
                   states: &Vec<f64>,
                   reductions: &Reductions,
                   contacts: &Vec<PairContact>| {
        let held = others(reductions, contacts) + memory::held(time_rows) + memory::held(states);
        cause.error(
            time,
            (time_rows.len() as u64, reductions.strobe_time.len() as u64),
            row as u64 + 1,
            contacts.len() as u64,
            held,
        )
    };
    let mut time = 0.0;
    let mut control = StepControl::new(options.dt.unwrap_or(1e-6 * t_end));
    let mut grid: u64 = 0;
    let (mut accepted, mut grazes) = (0u64, 0u64);
    let mut until_kept = options.every;
    let (mut last_event, mut close_events) = (f64::NEG_INFINITY, 0u64);
    let mut stalled = 0u64;
    // Interactions whose dip in this step was checked and stays open.
    let mut unconfirmed = vec![false; count];
    // Interactions switched at the event being handled.
    let mut just_switched = vec![false; count];
    // Open pairs on their walls at the start and not leaving them: their
    // first events within the resolution are at t = 0.
    let on_wall_at_start: Vec<bool> = (0..count)
        .map(|i| {
            let (gap, rate) = system.gap(i, &y);
            modes[i] == Mode::Open && gap.abs() <= wall_round_off(system, i, &y) && rate <= 0.0
        })
        .collect();
    let mut impacts = Impacts::new(system);
    let mut any_unconfirmed = false;
    // Whether a compliant contact is on (modes change only at events).
    let mut compliant = any_compliant(&modes);
    let mut reductions = Reductions {
        peaks: vec![0.0; system.observed()],
        square_integrals: vec![0.0; system.observed()],
        ..Reductions::default()
    };
    let mut next_strobe = options.reduce.strobe_period;
    let kinked = system.has_breakpoints();
    if options.keep_history {
        memory::push_row(
            &mut time_rows,
            &mut states,
            0.0,
            &y[..row],
            || 0,
            record_limit,
        )
        .map_err(|cause| no_room(cause, 0.0, &time_rows, &states, &reductions, &contacts))?;
    }

    // Each compliant contact's deepest indentation, lent to stretches.
    let stretches = !adaptive && stepper.takes_stretches(system);
    let poll_every = interrupt_interval(system.dim);
    let timed_polls = system.dim > TIMED_POLLS_BEYOND;
    let mut last_poll = std::time::Instant::now();
    let mut deepest = vec![f64::NAN; count];
    while time < t_end {
        // Plain steps in a row, where the stepper can take them at once (each
        // as this loop would, to the bit); the step after them is this
        // loop's. Not before this loop's first step, after which the memory
        // and row limits it checks stay as they were through a stretch (no
        // contact or row is added there).
        if stretches && accepted > 0 {
            for (deep, record) in deepest.iter_mut().zip(&open) {
                *deep = record.as_ref().map_or(f64::NAN, |o| o.max_indentation);
            }
            let mut stretch = Stretch {
                time,
                grid,
                accepted,
                until_kept,
                y: &mut y[..],
                gaps: &mut gaps.start[..],
                deepest: &mut deepest[..],
                peaks: &mut reductions.peaks[..],
                recorded_time: &mut reductions.recorded_time,
                evaluations: 0,
                steps: 0,
                // Up to the next interrupt poll, made here after it.
                max_accepted: ((accepted / poll_every + 1) * poll_every)
                    .min(options.max_steps.saturating_sub(control.rejected + 1)),
                limited: false,
                dt,
                t_end,
                record_from: options.reduce.record_from,
                mean_square: options.reduce.mean_square,
                next_strobe,
                strobe_period: options.reduce.strobe_period,
                keep_history: options.keep_history,
                chatter_factor: CHATTER_ULPS * f64::EPSILON,
                time_scale,
                stored_start,
                energy_scale,
                energy_sampler,
                impact_loss,
                energy_tolerance: options.energy_tolerance,
                unbalanced: None,
            };
            stepper.stretch(system, &mut stretch, &modes, &mut scratch);
            let (steps, limited) = (stretch.steps, stretch.limited);
            (energy_scale, energy_sampler) = (stretch.energy_scale, stretch.energy_sampler);
            if let Some(failure) = stretch.unbalanced {
                return Err(failure);
            }
            if steps > 0 {
                (time, grid, accepted, until_kept) = (
                    stretch.time,
                    stretch.grid,
                    stretch.accepted,
                    stretch.until_kept,
                );
                stalled = 0;
                for (deep, record) in deepest.iter().zip(&mut open) {
                    if let Some(o) = record {
                        o.max_indentation = *deep;
                    }
                }
                // What the loop does after a plain step that it may have
                // been, beyond the energy check the stretch made: an
                // interrupt poll.
                if accepted % poll_every == 0 && interrupt() {
                    return Err(Error::Interrupted { time });
                }
                if limited {
                    continue;
                }
            }
        }
        if !adaptive && t_end - time <= 1e-9 * dt {
            // On t_end to the round-off of the grid's times.
            break;
        }
        let mut length = if adaptive {
            control.h.min(t_end - time)
        } else {
            ((grid + 1) as f64 * dt - time)
                .min(t_end - time)
                .min(stepper.step_limit(system, time, &y, &modes, &mut scratch)?)
        };
        if !adaptive && length <= 0.0 {
            grid += 1;
            continue;
        }
        if adaptive && (t_end - time - length) < 1e-3 * length {
            length = t_end - time;
        }
        if adaptive && modes.contains(&Mode::Open) {
            // A step that passes over a short flight (a rebound that lands and
            // leaves again within it) shows the gap open at both ends, and a
            // smooth flight gives the error control no reason to shorten it:
            // end it a little after each open gap's parabola lands, no sooner
            // than the resolution (shorter flights are a chattering sequence).
            if let Some(rates) = stepper.start_rates(system, time, &y, &modes, &mut scratch) {
                for (i, mode) in modes.iter().enumerate() {
                    if *mode != Mode::Open || system.held_by_mirror(i, &modes) {
                        continue;
                    }
                    if let Some(hit) = system.landing_time(i, &y, &rates[d..2 * d]) {
                        length = length.min((1.5 * hit).max(resolution));
                    }
                }
            }
        }
        if adaptive && modes.contains(&Mode::Sticking) {
            // A sticking pair's release shows only as its constraint force
            // at a step's end: steps short enough not to pass over it.
            length = length.min(system.sticking_step);
        }
        if adaptive && kinked {
            // Land on the signals' next kink (their samples).
            length = length.min(system.next_breakpoint(time) - time);
        }
        let from = options.reduce.record_from;
        if from - time < length && from - time > 1e-9 * length {
            // Land on the start of the recorded window: a step across it
            // would be left out of the peak and RMS, or counted whole.
            length = from - time;
        }
        if next_strobe - time < length && next_strobe - time > 1e-9 * options.reduce.strobe_period {
            // Land on the stroboscopic instant.
            length = next_strobe - time;
        }
        let error = stepper.attempt(system, time, &y, length, &modes, &mut scratch, &mut end)?;
        system.gaps(&end, &mut gaps.end);
        let mut full_error = error;
        let mut taken = length;
        let mut switched: Option<usize> = None;
        let mut last_attempt_kept = true;
        if any_unconfirmed {
            unconfirmed.iter_mut().for_each(|u| *u = false);
            any_unconfirmed = false;
        }
        let mut crossing = if may_cross(&gaps, &modes) {
            find_crossing(
                system,
                time,
                &gaps,
                &end,
                length,
                &modes,
                graze,
                &mut grazes,
                &mut scratch,
                &mut buffers.work,
                &unconfirmed,
            )
        } else {
            None
        };
        // An event inside the step: locate it; another interaction that
        // turns out to have crossed before it is located in its turn.
        let mut rounds = 0;
        while let Some(c) = crossing {
            rounds += 1;
            full.copy_from_slice(&end);
            match locate(
                system,
                stepper,
                time,
                &y,
                taken,
                &full,
                full_error,
                &modes,
                c,
                &mut scratch,
                &mut buffers,
            )? {
                // A step that straddled an event may have been accepted for
                // an error measured across it; the cut step must pass too.
                Location::Cut(cut, cut_error) if adaptive && rejects(cut_error) => {
                    control.retry(0.5 * cut);
                    switched = None;
                    crossing = None;
                    taken = f64::NAN;
                    continue;
                }
                Location::Cut(cut, cut_error) => {
                    taken = cut;
                    full_error = cut_error;
                    switched = Some(c.i);
                    last_attempt_kept = false;
                    end.copy_from_slice(&buffers.best);
                    system.gaps(&end, &mut gaps.end);
                }
                Location::Unconfirmed => {
                    last_attempt_kept = false;
                    if switched.is_none() {
                        // That dip stays above its wall: another pair may
                        // still cross within the step.
                        unconfirmed[c.i] = true;
                        any_unconfirmed = true;
                        let mut counted = 0;
                        crossing = find_crossing(
                            system,
                            time,
                            &gaps,
                            &end,
                            taken,
                            &modes,
                            graze,
                            &mut counted,
                            &mut scratch,
                            &mut buffers.work,
                            &unconfirmed,
                        );
                        continue;
                    }
                }
                Location::Reject(shorter) => {
                    control.retry(0.9 * shorter);
                    switched = None;
                    crossing = None;
                    taken = f64::NAN;
                    continue;
                }
            }
            crossing = None;
            if rounds > count {
                break;
            }
            // Another interaction on its new side at the cut came first.
            for (j, &mode) in modes.iter().enumerate() {
                if Some(j) == switched || system.held_by_mirror(j, &modes) {
                    continue;
                }
                let v = event_value(
                    system,
                    j,
                    mode,
                    time + taken,
                    &end,
                    &modes,
                    &mut scratch,
                    &mut buffers.work,
                );
                // Past its wall beyond round-off: one on it to round-off (the
                // located pair's simultaneous partner, or a pair at rest on
                // its wall) switches with it, and must not hide one that
                // crossed earlier behind it.
                if past(system, j, mode, v, &end) {
                    crossing = Some(Crossing {
                        i: j,
                        guess: 1.0,
                        interior: false,
                        before: 0.0,
                        root: f64::NAN,
                    });
                    break;
                }
            }
        }
        if taken.is_nan() {
            continue;
        }
        if adaptive
            && switched.is_none()
            && !control.judge(
                error,
                taken,
                |e| stepper.shrink(e),
                true,
                time,
                t_end,
                accepted,
                options.max_steps,
            )?
        {
            continue;
        }
        // v * 0 is 0 for a finite v, NaN otherwise: one sum tells (and
        // does not branch on every value).
        if end[..row].iter().fold(0.0, |sum, v| sum + v * 0.0) != 0.0 {
            return Err(Error::NumericalBlowUp {
                time: time + taken,
                reason: "the state is no longer finite",
            });
        }
        // Deepest indentation of each compliant contact within the step:
        // where the indentation rate changes sign, the method's own state
        // at the interpolant's turning point (the interpolant alone errs by
        // its third-order term, 1e-4 of the indentation at dop853's steps).
        if compliant {
            for (i, record) in open.iter_mut().enumerate() {
                if let (Some(oc), Mode::Compliant { .. }) = (record.as_mut(), modes[i]) {
                    let ((g0, r0), (g1, r1)) = (gaps.start[i], gaps.end[i]);
                    let (m0, m1) = (r0 * taken, r1 * taken);
                    let mut deepest = -g1;
                    if m0 < 0.0 && m1 > 0.0 {
                        // Then one Newton step on the gap's rate from there
                        // (the error of the turning point squared).
                        let mut at = cubic_argmax(-g0, -g1, -m0, -m1) * taken;
                        for newton in [true, false] {
                            stepper.attempt(
                                system,
                                time,
                                &y,
                                at,
                                &modes,
                                &mut scratch,
                                &mut buffers.probe,
                            )?;
                            let (gap, rate) = system.gap(i, &buffers.probe);
                            deepest = deepest.max(-gap);
                            if !newton {
                                break;
                            }
                            let curvature = system.gap_acceleration(
                                i,
                                time + at,
                                &buffers.probe,
                                &modes,
                                &mut scratch,
                                &mut buffers.work,
                            );
                            at -= rate / curvature;
                            if !(at > 0.0 && at < taken) {
                                break;
                            }
                        }
                        last_attempt_kept = false;
                    }
                    oc.max_indentation = oc.max_indentation.max(deepest);
                }
            }
        }
        // A step that starts within round-off of the window's start, which
        // it was not cut to land on, is in the window.
        if time + 1e-9 * taken >= options.reduce.record_from {
            let located = reduce_step(
                system,
                stepper,
                time,
                &y,
                &end,
                taken,
                &modes,
                &mut reduce_scratch,
                &mut buffers,
                &mut reductions,
                options.reduce.mean_square,
            )?;
            if located {
                last_attempt_kept = false;
            }
        }
        if last_attempt_kept {
            stepper.accept();
        } else {
            stepper.reset();
        }
        // The energy accumulators are read at an event, at a balance check
        // and at the end; in between a stepper may leave them to a later step.
        let next = time + taken;
        let settle = switched.is_some()
            || (accepted + 1) % ENERGY_INTERVAL == 0
            || next >= t_end
            || (!adaptive && t_end - next <= 1e-9 * dt);
        stepper.finish(
            system,
            time,
            &y,
            taken,
            &modes,
            &mut scratch,
            &mut end,
            settle,
        )?;
        time += taken;
        if !adaptive && (switched.is_none() || (grid + 1) as f64 * dt - time <= 0.0) {
            grid += 1;
        }
        // The attempt is overwritten by the next one: the buffers trade places.
        std::mem::swap(&mut y, &mut end);
        std::mem::swap(&mut gaps.start, &mut gaps.end);
        accepted += 1;

        if switched.is_some() {
            // An event located within the round-off of the run's start (a
            // pair on its wall at t = 0: the value's round-off put the root
            // at 1e-66 s), or one of a pair on its wall from the start
            // located within the run's resolution (not pressed at first, the
            // gap reached its round-off only after 1e-8 s), is at the start.
            let from_start = switched.is_some_and(|i| on_wall_at_start[i]) && time <= resolution;
            let event_time = if time <= f64::EPSILON * time_scale || from_start {
                0.0
            } else {
                time
            };
            // Every interaction on its wall at this instant switches; the
            // open rigid ones are resolved together with the sticking ones.
            let mut any = false;
            let mut rigid = false;
            just_switched.iter_mut().for_each(|s| *s = false);
            for i in 0..count {
                let v = event_value(
                    system,
                    i,
                    modes[i],
                    time,
                    &y,
                    &modes,
                    &mut scratch,
                    &mut buffers.work,
                );
                let located = Some(i) == switched;
                if !(located || crossed(system, i, modes[i], v, &y))
                    || (modes[i] == Mode::Open && system.held_by_mirror(i, &modes))
                {
                    continue;
                }
                if impacts.mark(system, i, modes[i]) {
                    rigid = true;
                    continue;
                }
                let (was, onset) = (modes[i], open[i].map(|o| o.balance));
                just_switched[i] = switch(
                    system,
                    i,
                    event_time,
                    &mut y,
                    &mut modes,
                    &mut open,
                    &mut contacts,
                    (
                        &mut scratch,
                        &mut buffers.work,
                        (chatter_interval(time), time_scale),
                    ),
                );
                // A compliant contact's own balance, from its onset to its
                // separation: it must not create energy.
                match (was, modes[i], open[i].as_mut(), onset, contacts.last()) {
                    (Mode::Open, Mode::Compliant { .. }, Some(record), ..) => {
                        record.balance =
                            OnsetBalance::at(system, &y, &modes, stored_start, impact_loss);
                    }
                    (Mode::Compliant { .. }, Mode::Open, None, Some(onset), Some(record)) => {
                        onset.check_separation(
                            system,
                            &y,
                            &modes,
                            (stored_start, impact_loss),
                            energy_scale,
                            options.energy_tolerance,
                            record,
                        )?;
                    }
                    _ => {}
                }
                any |= just_switched[i];
            }
            if rigid {
                any |= impacts.resolve(
                    system,
                    event_time,
                    &mut y,
                    &mut modes,
                    &mut open,
                    &mut contacts,
                    &mut impact_loss,
                    &mut grazes,
                    (resolution, chatter_interval(time), time_scale),
                    &mut scratch,
                    &mut buffers.work,
                    &mut just_switched,
                );
            }
            if any {
                stepper.reset();
                if adaptive {
                    control.h = control.h.min(1e-3 * t_end);
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
            // Impacts change the velocities.
            system.gaps(&y, &mut gaps.start);
            compliant = any_compliant(&modes);
            if contacts.len() >= COMPACTED_CONTACTS && time < options.reduce.contacts_from {
                // Before the contacts kept begin: what closed is dropped (a
                // contact across their start may stay; it is dropped below).
                contacts.retain(|c| c.onset >= options.reduce.contacts_from);
            }
        }

        if time >= next_strobe - 1e-9 * options.reduce.strobe_period {
            memory::push_row(
                &mut reductions.strobe_time,
                &mut reductions.strobe,
                time,
                &y[..row],
                || memory::held(&time_rows) + memory::held(&states) + memory::held(&contacts),
                record_limit,
            )
            .map_err(|cause| no_room(cause, time, &time_rows, &states, &reductions, &contacts))?;
            next_strobe = (reductions.strobe_time.len() + 1) as f64 * options.reduce.strobe_period;
        }
        let done = time >= t_end || (!adaptive && t_end - time <= 1e-9 * dt);
        // Counts down only while it matters (no history: it stays at 0).
        until_kept = until_kept.saturating_sub(1);
        if options.keep_history && (until_kept == 0 || done) {
            until_kept = options.every;
            memory::push_row(
                &mut time_rows,
                &mut states,
                time,
                &y[..row],
                || others(&reductions, &contacts),
                record_limit,
            )
            .map_err(|cause| no_room(cause, time, &time_rows, &states, &reductions, &contacts))?;
        }
        // Room for the contacts the next step may close (a Vec's own
        // doubling could pass the limit, or abort where memory is refused).
        memory::make_room(
            &mut contacts,
            2 * count + 2,
            8,
            || {
                memory::held(&reductions.strobe)
                    + memory::held(&reductions.strobe_time)
                    + memory::held(&time_rows)
                    + memory::held(&states)
            },
            record_limit,
        )
        .map_err(|cause| no_room(cause, time, &time_rows, &states, &reductions, &contacts))?;
        if (time_rows.len() + contacts.len() + reductions.strobe_time.len()) as u64
            > options.max_rows
        {
            return Err(Error::RowLimit {
                time,
                max_rows: options.max_rows,
                rows: time_rows.len() as u64,
                contacts: contacts.len() as u64,
                advice: "raise every, set history = false, shorten t_end or raise max_rows",
            });
        }
        // Steps within a thousand units of round-off of the time make no
        // progress: an event that recurs at once (a zero clearance, say)
        // would otherwise loop.
        // (An adaptive method's own short steps, from a tiny first step, grow.)
        if taken <= chatter_interval(time) && (switched.is_some() || !adaptive) {
            stalled += 1;
            if stalled >= STALLED_STEPS {
                return Err(Error::Chattering {
                    time,
                    events: stalled,
                    interval: taken,
                });
            }
        } else {
            stalled = 0;
        }
        // The balance is checked every few steps and at the end; the energy
        // in play is sampled between, by the clock (see EnergySampler).
        let check = accepted % ENERGY_INTERVAL == 0 || done;
        if check || energy_sampler.due(time) {
            check_balance(
                system,
                &y,
                &modes,
                stored_start,
                &mut energy_scale,
                impact_loss,
                (options.energy_tolerance, check),
                t_end,
                time,
            )?;
        }
        if !done && accepted + control.rejected >= options.max_steps {
            return Err(Error::TooManySteps {
                time,
                max_steps: options.max_steps,
            });
        }
        // Large systems poll by the clock too: a step of hundreds of sticking
        // pairs (a constraint solve in each stage) takes a tenth of a second.
        let due = accepted % poll_every == 0
            || (timed_polls && last_poll.elapsed().as_secs_f64() >= POLL_SECONDS);
        if due {
            last_poll = std::time::Instant::now();
            if interrupt() {
                return Err(Error::Interrupted { time });
            }
        }
    }

    for (i, record) in open.iter().enumerate() {
        if let Some(oc) = record {
            let dissipated = match oc.kind {
                ContactKind::Compliant => y[loss_slot(system, i)] - oc.dissipated,
                _ => oc.dissipated,
            };
            contacts.push(oc.close(system.interactions[i].pair, f64::NAN, f64::NAN, dissipated));
        }
    }
    if options.reduce.contacts_from > f64::NEG_INFINITY {
        contacts.retain(|c| c.onset >= options.reduce.contacts_from);
    }
    contacts.sort_by(|a, b| a.onset.total_cmp(&b.onset));
    let energy = balance(
        system,
        &y,
        system.energy(&y, &modes),
        stored_start,
        impact_loss,
    );
    Ok(SystemSolution {
        time: time_rows,
        states,
        contacts,
        final_state: y[..row].to_vec(),
        final_time: time,
        energy,
        steps: accepted,
        rejected_steps: control.rejected,
        rhs_evaluations: stepper.evaluations(),
        grazing_contacts: grazes,
        reductions,
    })
}

/// The energy balance at state `y`, whose stored energy is `stored_end`.
/// Add the kept step `(time, y) -> end` of length `h` to the reductions.
/// Returns whether the stepper was used (its last attempt is then not the
/// kept step).
#[allow(clippy::too_many_arguments)]
fn reduce_step<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    time: f64,
    y: &[f64],
    end: &[f64],
    h: f64,
    modes: &[Mode],
    scratch: &mut Scratch,
    buffers: &mut Buffers,
    out: &mut Reductions,
    mean_square: bool,
) -> Result<bool> {
    let (n, d) = (system.n, system.dim);
    let observed = system.observed();
    // Each observed quantity (a coordinate or a point) of a block of the
    // structure's displacements, velocities or accelerations.
    let of = |j: usize, block: &[f64]| system.observe(j, block);
    // The exact flow's mean square from the flow itself at the quadrature's
    // nodes (its steps are long, the interpolant's error 1e-6 there).
    let on_flow = mean_square && stepper.is_exact();
    let interpolated = mean_square && !on_flow;
    let mut used = false;
    if on_flow {
        for (x, w) in reductions::NODES.iter().zip(reductions::WEIGHTS) {
            stepper.attempt(system, time, y, x * h, modes, scratch, &mut buffers.probe)?;
            for j in 0..observed {
                let value = of(j, &buffers.probe[..n]);
                out.square_integrals[j] += h * w * value * value;
            }
        }
        used = true;
    }
    let (v0, v1) = (&y[d..d + n], &end[d..d + n]);
    // The accelerations at both ends only where the interpolant is needed:
    // for the mean square, or where a velocity changes sign (a peak inside).
    let turning = (0..observed).any(|j| of(j, v0) * of(j, v1) < 0.0);
    if interpolated || turning {
        system.rates(time, y, modes, scratch, &mut buffers.start);
        system.rates(time + h, end, modes, scratch, &mut buffers.work);
    }
    for j in 0..observed {
        let (p0, p1) = (of(j, &y[..n]), of(j, &end[..n]));
        let (s0, s1) = (of(j, v0), of(j, v1));
        let mut peak = p0.abs().max(p1.abs());
        let inside = s0 * s1 < 0.0;
        if interpolated || inside {
            let a = reductions::quintic(
                p0,
                p1,
                h * s0,
                h * s1,
                h * h * of(j, &buffers.start[d..d + n]),
                h * h * of(j, &buffers.work[d..d + n]),
            );
            if interpolated {
                out.square_integrals[j] += h * reductions::square_integral(&a);
            }
            if inside {
                let theta = reductions::derivative_root(&a);
                stepper.attempt(
                    system,
                    time,
                    y,
                    theta * h,
                    modes,
                    scratch,
                    &mut buffers.probe,
                )?;
                used = true;
                peak = peak.max(of(j, &buffers.probe[..n]).abs());
            }
        }
        out.peaks[j] = out.peaks[j].max(peak);
    }
    out.recorded_time += h;
    Ok(used)
}

/// The start of compliant interaction `i` (open in `modes`) at `time` and
/// state `y`, approaching at `approach` (m/s): the rate its law latches (see
/// [`crate::model::contact::AnyLaw::latched_approach_rate`]: a damped Hertz law's damping is taken
/// from the pressing where the approach is slower) and whether it starts at
/// rest (an approach the pressing gives within round-off, see
/// [`impacts::resting`]: no impact, so no rebound ratio). `scales` are the
/// time's round-off and the system's time scale, s. Once per onset.
#[allow(clippy::too_many_arguments)]
#[cold]
#[inline(never)]
fn compliant_onset(
    system: &Assembly,
    i: usize,
    time: f64,
    y: &[f64],
    approach: f64,
    modes: &[Mode],
    scratch: &mut Scratch,
    work: &mut [f64],
    (instant, time_scale): (f64, f64),
) -> (f64, bool) {
    let it = &system.interactions[i];
    let InteractionLaw::Compliant { law, .. } = it.law else {
        return (approach, false);
    };
    // < 0 presses the pair shut.
    let pressing = system.gap_acceleration(i, time, y, modes, scratch, work);
    let mass = 1.0 / it.inverse_mass;
    // A flight rising less than the round-off of the gap, or of the
    // indentation the pressing holds (a stop at the origin has a gap scale
    // of 0), is round-off: the ringing of a body set down on the contact.
    let round_off =
        impacts::flight_round_off(system, i, y).max(1e-9 * law.static_indentation(mass, -pressing));
    let (landing, at_rest) = impacts::resting(approach, pressing, round_off, instant, time_scale);
    let latched = law.latched_approach_rate(approach, mass, -pressing);
    (latched, landing || at_rest)
}

/// Switch interaction `i` at `time`: start or end a compliant contact, or
/// release a sticking pair whose constraint force turned (the open rigid
/// pairs are [`Impacts::resolve`]'s).
#[allow(clippy::too_many_arguments)]
fn switch(
    system: &Assembly,
    i: usize,
    time: f64,
    y: &mut [f64],
    modes: &mut [Mode],
    open: &mut [Option<Open>],
    contacts: &mut Vec<PairContact>,
    (scratch, work, scales): (&mut Scratch, &mut [f64], (f64, f64)),
) -> bool {
    let it = &system.interactions[i];
    let (_, rate) = system.gap(i, y);
    match modes[i] {
        Mode::Open => {
            let approach = -rate;
            let (approach_rate, resting) =
                compliant_onset(system, i, time, y, approach, modes, scratch, work, scales);
            modes[i] = Mode::Compliant { approach_rate };
            open[i] = Some(Open {
                kind: ContactKind::Compliant,
                onset: time,
                approach_speed: approach,
                max_indentation: 0.0,
                dissipated: y[loss_slot(system, i)],
                resting,
                balance: OnsetBalance::default(),
            });
        }
        Mode::Compliant { .. } => {
            modes[i] = Mode::Open;
            if let Some(oc) = open[i].take() {
                let dissipated = y[loss_slot(system, i)] - oc.dissipated;
                contacts.push(oc.close(it.pair, time, rate, dissipated));
            }
        }
        Mode::Sticking => {
            system.release(i, y);
            modes[i] = Mode::Open;
            if let Some(oc) = open[i].take() {
                contacts.push(oc.close(it.pair, time, 0.0, oc.dissipated));
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hermite data `(g0, g1, m0, m1)` over [0, 1] of `p` with derivative `dp`.
    fn data(p: impl Fn(f64) -> f64, dp: impl Fn(f64) -> f64) -> (f64, f64, f64, f64) {
        (p(0.0), p(1.0), dp(0.0), dp(1.0))
    }

    #[test]
    fn the_interpolant_s_root_is_a_cubic_s_root() {
        crate::testing::timeout(30, || {
            // A cubic is its own Hermite interpolant: its root, to round-off.
            let p = |t: f64| (t - 0.3) * (t + 2.0) * (t - 4.0);
            let dp = |t: f64| (t + 2.0) * (t - 4.0) + (t - 0.3) * (t - 4.0) + (t - 0.3) * (t + 2.0);
            let (g0, g1, m0, m1) = data(p, dp);
            for (lo, hi) in [(0.0, 1.0), (0.25, 0.9), (0.1, 0.3000001)] {
                let r = cubic_root(g0, g1, m0, m1, lo, hi);
                assert!((r - 0.3).abs() < 1e-14, "[{lo}, {hi}]: {r}");
            }
            // Falling through zero (the sign of the old side is positive).
            let r = cubic_root(-g0, -g1, -m0, -m1, 0.0, 1.0);
            assert!((r - 0.3).abs() < 1e-14, "{r}");
            // No sign change in the bracket: its end.
            assert_eq!(cubic_root(g0, g1, m0, m1, 0.5, 1.0), 1.0);
        });
    }

    #[test]
    fn the_first_maximum_of_a_cubic_that_rises_again() {
        crate::testing::timeout(30, || {
            // p = 0.3 t - t^2 + t^3: p' = 0.3 - 2 t + 3 t^2 vanishes at
            // (2 -+ sqrt(0.4)) / 6; the first, 0.2279, is its maximum.
            let p = |t: f64| 0.3 * t - t * t + t * t * t;
            let dp = |t: f64| 0.3 - 2.0 * t + 3.0 * t * t;
            let (g0, g1, m0, m1) = data(p, dp);
            let exact = (2.0 - 0.4f64.sqrt()) / 6.0;
            assert!((first_maximum(g0, g1, m0, m1) - exact).abs() < 1e-15);
            // One that rises throughout has none inside.
            let (g0, g1, m0, m1) = data(|t| t + t * t * t, |t| 1.0 + 3.0 * t * t);
            assert_eq!(first_maximum(g0, g1, m0, m1), 0.0);
        });
    }

    #[test]
    fn the_interpolant_s_maximum_in_closed_form() {
        crate::testing::timeout(30, || {
            // -(t^3 - t^2 / 2 - 3 t / 2): slope 1.5 at 0, -0.5 at 1, zero at
            // (1 + sqrt(19)) / 6.
            let p = |t: f64| -(t * t * t - 0.5 * t * t - 1.5 * t);
            let dp = |t: f64| -(3.0 * t * t - t - 1.5);
            let (g0, g1, m0, m1) = data(p, dp);
            let expected = (1.0 + 19f64.sqrt()) / 6.0;
            let a = cubic_argmax(g0, g1, m0, m1);
            assert!((a - expected).abs() < 1e-15, "{a} {expected}");
            // A parabola (the slope is linear): its vertex.
            let q = |t: f64| 1.0 - (t - 0.7) * (t - 0.7);
            let dq = |t: f64| -2.0 * (t - 0.7);
            let (g0, g1, m0, m1) = data(q, dq);
            assert!((cubic_argmax(g0, g1, m0, m1) - 0.7).abs() < 1e-15);
            // Hermite's own argmax agrees.
            let reference = hermite::argmax(g0, g1, m0, m1);
            assert!((cubic_argmax(g0, g1, m0, m1) - reference).abs() < 1e-12);
            // Still rising at the end: the end.
            assert_eq!(cubic_argmax(0.0, 1.0, 1.0, 0.5), 1.0);
        });
    }

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
