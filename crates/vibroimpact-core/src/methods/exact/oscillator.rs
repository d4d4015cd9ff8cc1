//! One modal oscillator in closed form, and a mode's share of a state.

use super::from_rest;
use super::modal::Configuration;
use crate::model::assembly::SPARSE_FROM;
use crate::numerics::series::{exp, sin_cos};

/// One modal oscillator `eta'' + c eta' + w2 eta = F0 + forcing`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Oscillator {
    pub(super) w2: f64,
    pub(super) c: f64,
    pub(super) sigma: f64,
    /// `sigma^2 - w2`: < 0 underdamped, > 0 overdamped.
    pub(super) disc: f64,
    /// `sqrt(|disc|)`.
    pub(super) root: f64,
    pub(super) constant: f64,
    /// `constant / w2` (w2 > 0): the static response.
    pub(super) offset: f64,
}

impl Oscillator {
    pub(super) fn new(w2: f64, c: f64, constant: f64) -> Self {
        let sigma = 0.5 * c;
        let disc = sigma * sigma - w2;
        Self {
            w2,
            c,
            sigma,
            disc,
            root: disc.abs().sqrt(),
            constant,
            offset: if w2 > 0.0 { constant / w2 } else { 0.0 },
        }
    }

    /// `e^(-sigma t) C(t)` and `e^(-sigma t) S(t)`, where `C' = disc S`,
    /// `S' = C`, `C(0) = 1`, `S(0) = 0`: the free response is
    /// `e^(-sigma t) (d0 C + (d0' + sigma d0) S)`.
    #[inline(always)]
    pub(super) fn factors(&self, t: f64) -> (f64, f64) {
        if self.disc == 0.0 && self.sigma == 0.0 {
            // A free mass: the series below, exactly.
            return (1.0, t);
        }
        let z = self.disc * t * t;
        if z.abs() < 1e-3 {
            // Near critical damping (and for free masses): the series.
            let e = if self.sigma == 0.0 {
                1.0
            } else {
                exp(-self.sigma * t)
            };
            let c = 1.0 + z * (0.5 + z * (1.0 / 24.0 + z / 720.0));
            let s = t * (1.0 + z * (1.0 / 6.0 + z * (1.0 / 120.0 + z / 5040.0)));
            (e * c, e * s)
        } else if self.disc < 0.0 {
            let e = exp(-self.sigma * t);
            let (s, c) = sin_cos(self.root * t);
            (e * c, e * s / self.root)
        } else {
            // root <= sigma: neither exponential overflows.
            let a = ((self.root - self.sigma) * t).exp();
            let b = (-(self.root + self.sigma) * t).exp();
            (0.5 * (a + b), 0.5 * (a - b) / self.root)
        }
    }

    /// The factors at `a + b` from those at `a` and at `b` (the addition
    /// theorem of `C` and `S`; the exponentials multiply).
    #[inline(always)]
    pub(super) fn sum(&self, a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
        (a.0 * b.0 + self.disc * a.1 * b.1, a.1 * b.0 + a.0 * b.1)
    }

    /// The factors at `a - b` from those at `a` and at `b`: those at `-b`
    /// are `(C, -S) / e^(-2 sigma b)`, and `C^2 - disc S^2 = 1`.
    #[inline(always)]
    pub(super) fn difference(&self, a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
        let det = b.0 * b.0 - self.disc * b.1 * b.1;
        (
            (a.0 * b.0 - self.disc * a.1 * b.1) / det,
            (a.1 * b.0 - a.0 * b.1) / det,
        )
    }

    /// The constant force's particular response and its rate, `t` after the
    /// start of the flow.
    #[inline(always)]
    pub(super) fn steady(&self, t: f64) -> (f64, f64) {
        if self.w2 > 0.0 {
            (self.offset, 0.0)
        } else if self.c > 0.0 {
            (self.constant * t / self.c, self.constant / self.c)
        } else {
            (0.5 * self.constant * t * t, self.constant * t)
        }
    }
}

/// Mode `j`'s coordinate and rate in the state `y` (`x` then `v`, `dim`
/// each).
#[inline(always)]
pub(super) fn modal_state(cfg: &Configuration, dim: usize, j: usize, y: &[f64]) -> (f64, f64) {
    let (x, v, origin) = (&y[..dim], &y[dim..2 * dim], &cfg.origin[..dim]);
    let (mut eta, mut rate) = (0.0, 0.0);
    if dim < SPARSE_FROM {
        let row = &cfg.to_modal[j * dim..(j + 1) * dim];
        for i in 0..dim {
            eta += row[i] * (x[i] - origin[i]);
            rate += row[i] * v[i];
        }
        return (eta, rate);
    }
    // `T`'s non-zero entries of row `j` (the sums from +0 take no sign
    // from the zeros' terms left out: the dense products' bits).
    let (columns, row) = cfg.modal_rows.row(j);
    for (&i, b) in columns.iter().zip(row) {
        eta += b * (x[i] - origin[i]);
        rate += b * v[i];
    }
    (eta, rate)
}

/// `Re(P u0 G(t))` and its rate: mode `o`'s response from rest at `t` after
/// the start to the harmonic `Re(P e^(i omega t))` whose phasor there is
/// `(sin, cos)`, from the mode's factors at `t`.
#[inline(always)]
pub(super) fn from_rest_part(
    o: &Oscillator,
    omega: f64,
    (pr, pi): (f64, f64),
    (s0, c0): (f64, f64),
    t: f64,
    factors: (f64, f64),
) -> (f64, f64) {
    let (g, rate) = from_rest::response(o.sigma, o.root, omega, t, factors);
    // P u0.
    let (ar, ai) = (pr * c0 - pi * s0, pr * s0 + pi * c0);
    (ar * g.0 - ai * g.1, ar * rate.0 - ai * rate.1)
}
