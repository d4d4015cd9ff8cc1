//! What a run can keep instead of (or beside) its history: each structure
//! coordinate's (and each followed point's) peak |displacement| and mean
//! square over a recording window,
//! and the state at every multiple of a period (the stroboscopic map).
//!
//! Peaks are located, not read off step ends: where a coordinate's velocity
//! changes sign within a step, the quintic Hermite interpolant through both
//! ends' displacements, velocities and accelerations places the extremum,
//! and the method's own solution is evaluated there (the displacement at an
//! extremum is insensitive to the error of its time). Velocity jumps happen
//! at impacts, which end steps, so peaks at impacts are step ends. Mean
//! squares integrate the same interpolant (Gauss-Legendre, exact for it), or
//! for the exact flow, whose steps are long (an eighth of a period: the
//! interpolant errs by 1e-6 there), the flow itself at the same nodes.

use crate::error::Result;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, Mode, Scratch};

/// What to reduce: from `record_from` (s) on, and a stroboscopic state every
/// `strobe_period` (s; infinite for none).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReduceOptions {
    pub record_from: f64,
    pub strobe_period: f64,
    /// Whether to integrate the mean squares (the peaks cost less without).
    pub mean_square: bool,
    /// Contacts whose onset is before this (s) are not kept: a run reduced
    /// to metrics (a study's) counts only those from its recording window,
    /// and its settling may be millions of periods. Minus infinity keeps
    /// all (the default).
    pub contacts_from: f64,
}

impl Default for ReduceOptions {
    fn default() -> Self {
        Self {
            record_from: f64::INFINITY,
            strobe_period: f64::INFINITY,
            mean_square: true,
            contacts_from: f64::NEG_INFINITY,
        }
    }
}

/// The reductions of a run.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Reductions {
    /// Per observed quantity (each structure coordinate, then each point of
    /// the spec's `points`), the largest |displacement| (m) recorded.
    pub peaks: Vec<f64>,
    /// Per observed quantity, the integral of the displacement squared over
    /// the recorded time (m^2 s).
    pub square_integrals: Vec<f64>,
    /// s.
    pub recorded_time: f64,
    /// Rows of `x` then `v` at each multiple of the strobe period.
    pub strobe: Vec<f64>,
    /// Times of the strobe rows (s).
    pub strobe_time: Vec<f64>,
    /// Where the system has friction elements: each interaction's loss over
    /// the recorded window (J, its contact-loss accumulator at the run's end
    /// less that at the window's start, which a run holds here until its
    /// end): a friction element's sliding loss, which no contact record
    /// holds. Empty otherwise, or where the window did not start.
    pub window_losses: Vec<f64>,
}

/// Monomial coefficients (in `theta` in [0, 1]) of the quintic Hermite
/// interpolant with values `p`, slopes `m` (per unit theta) and second
/// derivatives `c` (per unit theta squared) at both ends.
#[inline(always)]
pub fn quintic(p0: f64, p1: f64, m0: f64, m1: f64, c0: f64, c1: f64) -> [f64; 6] {
    let d = p1 - p0;
    [
        p0,
        m0,
        0.5 * c0,
        10.0 * d - 6.0 * m0 - 4.0 * m1 - 1.5 * c0 + 0.5 * c1,
        -15.0 * d + 8.0 * m0 + 7.0 * m1 + 1.5 * c0 - c1,
        6.0 * d - 3.0 * m0 - 3.0 * m1 - 0.5 * c0 + 0.5 * c1,
    ]
}

/// The polynomial `a` and its derivative at `t`.
#[inline(always)]
pub fn evaluate(a: &[f64; 6], t: f64) -> (f64, f64) {
    let mut value = a[5];
    let mut slope = 0.0;
    for k in (0..5).rev() {
        slope = slope * t + value;
        value = value * t + a[k];
    }
    (value, slope)
}

/// Where the derivative of `a` changes sign in (0, 1), given it does
/// (bisection on the derivative's sign, 50 halvings: to round-off).
pub fn derivative_root(a: &[f64; 6]) -> f64 {
    let slope = |t: f64| evaluate(a, t).1;
    let (mut lo, mut hi) = (0.0, 1.0);
    let low_sign = slope(0.0) < 0.0;
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if (slope(mid) < 0.0) == low_sign {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Gauss-Legendre on [0, 1], 6 points: exact for the square of a quintic
/// up to degree 11.
pub(crate) const NODES: [f64; 6] = [
    0.033_765_242_898_423_98,
    0.169_395_306_766_867_74,
    0.380_690_406_958_401_5,
    0.619_309_593_041_598_5,
    0.830_604_693_233_132_3,
    0.966_234_757_101_576,
];
pub(crate) const WEIGHTS: [f64; 6] = [
    0.085_662_246_189_585_17,
    0.180_380_786_524_069_3,
    0.233_956_967_286_345_5,
    0.233_956_967_286_345_5,
    0.180_380_786_524_069_3,
    0.085_662_246_189_585_17,
];

/// The integral over [0, 1] of the square of the quintic `a`.
#[inline(always)]
pub fn square_integral(a: &[f64; 6]) -> f64 {
    NODES
        .iter()
        .zip(WEIGHTS)
        .map(|(t, w)| {
            let v = evaluate(a, *t).0;
            w * v * v
        })
        .sum()
}

/// Add the kept step `(time, y) -> end` of length `h` to the reductions.
/// Returns whether the stepper was used (its last attempt is then not the
/// kept step). `stages`: a fixed step's work space, through whose signal
/// caches the step's stages went. The rates at the step's start are then
/// the method's first stage where it has one ([`SystemStepper::first_stage`];
/// else made with the reductions' own caches), and those at its end take
/// the force's values the stages took there: with RK4, a step's end rates
/// are the next step's first stage, to the bit.
#[allow(clippy::too_many_arguments)]
pub(crate) fn reduce_step<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    (time, y, end, h): (f64, &[f64], &[f64], f64),
    modes: &[Mode],
    (scratch, stages): (&mut Scratch, Option<&Scratch>),
    (probe, start, work): (&mut [f64], &mut [f64], &mut [f64]),
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
        for (x, w) in NODES.iter().zip(WEIGHTS) {
            stepper.attempt(system, time, y, x * h, modes, scratch, probe)?;
            for j in 0..observed {
                let value = of(j, &probe[..n]);
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
        match (stages, stepper.first_stage()) {
            (Some(_), Some(first)) => start[..first.len()].copy_from_slice(first),
            _ => system.rates(time, y, modes, scratch, start),
        }
        if let Some(stages) = stages {
            scratch.signals_from(stages);
        }
        system.rates(time + h, end, modes, scratch, work);
    }
    for j in 0..observed {
        let (p0, p1) = (of(j, &y[..n]), of(j, &end[..n]));
        let (s0, s1) = (of(j, v0), of(j, v1));
        let mut peak = p0.abs().max(p1.abs());
        let inside = s0 * s1 < 0.0;
        if interpolated || inside {
            let a = quintic(
                p0,
                p1,
                h * s0,
                h * s1,
                h * h * of(j, &start[d..d + n]),
                h * h * of(j, &work[d..d + n]),
            );
            if interpolated {
                out.square_integrals[j] += h * square_integral(&a);
            }
            if inside {
                let theta = derivative_root(&a);
                stepper.attempt(system, time, y, theta * h, modes, scratch, probe)?;
                used = true;
                peak = peak.max(of(j, &probe[..n]).abs());
            }
        }
        out.peaks[j] = out.peaks[j].max(peak);
    }
    out.recorded_time += h;
    Ok(used)
}
