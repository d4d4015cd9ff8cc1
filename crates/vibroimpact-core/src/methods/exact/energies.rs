//! The energy accumulators (viscous loss, input work) over a step of the
//! flow: in closed form over a stretch of one flow, or by Gauss-Legendre on
//! the modal rates.

use super::flow::ExactFlow;
use super::oscillator::{from_rest_part, modal_state};
use crate::numerics::series::sin_cos;

/// Gauss-Legendre nodes on [0, 1] and weights (5 points, exact to degree 9).
pub(super) const NODES: [f64; 5] = [
    0.046_910_077_030_668_004,
    0.230_765_344_947_158_45,
    0.5,
    0.769_234_655_052_841_6,
    0.953_089_922_969_332,
];
pub(super) const WEIGHTS: [f64; 5] = [
    0.118_463_442_528_094_54,
    0.239_314_335_249_683_23,
    0.284_444_444_444_444_45,
    0.239_314_335_249_683_23,
    0.118_463_442_528_094_54,
];

/// The nodes as the midpoint less and plus these fractions of the step
/// (`0.5 - NODES[0]`, `0.5 - NODES[1]`).
pub(super) const OFFSETS: [f64; 2] = [0.453_089_922_969_332, 0.269_234_655_052_841_55];

/// `(sin, cos)` of the sum and of the difference of two angles given theirs.
#[inline(always)]
pub(super) fn turn_sum(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0 * b.1 + a.1 * b.0, a.1 * b.1 - a.0 * b.0)
}

#[inline(always)]
pub(super) fn turn_difference(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0 * b.1 - a.1 * b.0, a.1 * b.1 + a.0 * b.0)
}

/// Kept steps whose energy accumulators wait for one closed form over all of
/// them (they are one flow: no event between them): the modes, the time at
/// the first one's start and the first harmonic's phasor there, and the time
/// (bits) at the last one's end.
#[derive(Debug, Clone, Copy)]
pub(super) struct Span {
    pub(super) index: usize,
    pub(super) time: f64,
    pub(super) phasor: (f64, f64),
    pub(super) end: u64,
}

impl ExactFlow {
    /// The viscous loss and the input work (J) over the step `h` from the
    /// start, in closed form from the modal states at its ends (one forcing
    /// harmonic at most). Each mode obeys `eta'' + c eta' + w2 eta = F0 +
    /// f(t)`, `f = Re(P u)`, `u = e^(i omega t)`, whose particular response
    /// is `Re(Z u)`; the rest `v` obeys `v'' + c v' + w2 v = F0`, so that
    /// integrating by parts twice gives `int u v' = (mu [u v'] + w2 [u v] -
    /// F0 [u]) / (mu^2 - c mu + w2)` (`mu = i omega`, `[.]` the change over
    /// the step), and `int f Re(Z u)'` is elementary. The viscous loss `c int
    /// eta'^2` is then the mode's input `int f eta'` plus `F0` times its
    /// displacement less the change of its energy `eta'^2 / 2 + w2 eta^2 / 2`.
    ///
    /// The start is `span_modal` with the first harmonic's phasor `phasor`
    /// there, `h` before `end`: any stretch of one flow.
    pub(super) fn step_energies(
        &mut self,
        index: usize,
        dim: usize,
        h: f64,
        phasor: (f64, f64),
        end: &[f64],
    ) -> (f64, f64) {
        self.last = None;
        let m = &self.modes[index];
        let cfg = &m.configuration;
        // The modal state at the end, from the step's end.
        for j in 0..cfg.modes {
            (self.eta[j], self.rate[j]) = modal_state(cfg, dim, j, end);
        }
        let forcing = cfg.harmonics.first().map(|harmonic| {
            let (s0, c0) = phasor;
            let (st, ct) = sin_cos(harmonic.omega * h);
            // u at both ends as (Re, Im), and sin(omega h).
            let end = (c0 * ct - s0 * st, s0 * ct + c0 * st);
            (harmonic, (c0, s0), end, st)
        });
        let (mut viscous, mut input) = (0.0, 0.0);
        for (j, o) in m.oscillators.iter().enumerate() {
            let (eta0, rate0) = self.span_modal[j];
            let (eta1, rate1) = (self.eta[j], self.rate[j]);
            let mut work = 0.0;
            // A mode the harmonic does not force (a free mass's) does no work:
            // its terms below are zeros, and `work` stays +0 (the same bits).
            let forced = forcing.filter(|(harmonic, ..)| harmonic.forced.contains(&j));
            if let Some((harmonic, u0, u1, sin_turn)) = forced {
                let w = harmonic.omega;
                let (zr, zi) = harmonic.response[j];
                let (pr, pi) = harmonic.force[j];
                // v and v' at an end: the particular response taken off.
                let rest = |(c, s): (f64, f64), eta: f64, rate: f64| {
                    (eta - (zr * c - zi * s), rate + w * (zr * s + zi * c))
                };
                let (v0, dv0) = rest(u0, eta0, rate0);
                let (v1, dv1) = rest(u1, eta1, rate1);
                // [u v'], [u v], [u].
                let (ar, ai) = (u1.0 * dv1 - u0.0 * dv0, u1.1 * dv1 - u0.1 * dv0);
                let (br, bi) = (u1.0 * v1 - u0.0 * v0, u1.1 * v1 - u0.1 * v0);
                let (gr, gi) = (u1.0 - u0.0, u1.1 - u0.1);
                let nr = -w * ai + o.w2 * br - o.constant * gr;
                let ni = w * ar + o.w2 * bi - o.constant * gi;
                let (dr, di) = (o.w2 - w * w, -o.c * w);
                let norm = dr * dr + di * di;
                let (jr, ji) = ((nr * dr + ni * di) / norm, (ni * dr - nr * di) / norm);
                work += pr * jr - pi * ji;
                // int Re(P u) Re(B u), B = i omega Z: half of Re(P conj(B)) h
                // plus half of Re(P B int u^2), int u^2 = u0 u1 sin(omega h) / omega.
                let (qr, qi) = (-w * zi, w * zr);
                let (er, ei) = (u0.0 * u1.0 - u0.1 * u1.1, u0.0 * u1.1 + u0.1 * u1.0);
                let (pqr, pqi) = (pr * qr - pi * qi, pr * qi + pi * qr);
                work += 0.5 * h * (pr * qr + pi * qi) + 0.5 * (pqr * er - pqi * ei) * sin_turn / w;
            }
            // A constant the excitations drive works on the mode too.
            input += work + cfg.driven[j] * (eta1 - eta0);
            if o.c > 0.0 {
                let (de, dr) = (eta1 - eta0, rate1 - rate0);
                let stored = 0.5 * dr * (rate1 + rate0) + 0.5 * o.w2 * de * (eta1 + eta0);
                viscous += o.constant * de + work - stored;
            }
        }
        (viscous, input)
    }

    /// The factors of the modes `index` at the Gauss nodes of a step `h`
    /// from a start, into `node_modes` and `node_turns`: three evaluations
    /// (the midpoint and the two offsets), the other two nodes by the
    /// addition theorems.
    pub(super) fn node_factors(&mut self, index: usize, h: f64) {
        let m = &self.modes[index];
        let (mid, far, near) = (0.5 * h, OFFSETS[0] * h, OFFSETS[1] * h);
        let nodes = NODES.len();
        for (o, out) in m
            .oscillators
            .iter()
            .zip(self.node_modes.chunks_exact_mut(nodes))
        {
            let (at_mid, at_far, at_near) = (o.factors(mid), o.factors(far), o.factors(near));
            out[0] = o.difference(at_mid, at_far);
            out[1] = o.difference(at_mid, at_near);
            out[2] = at_mid;
            out[3] = o.sum(at_mid, at_near);
            out[4] = o.sum(at_mid, at_far);
        }
        for (h, out) in m
            .configuration
            .harmonics
            .iter()
            .zip(self.node_turns.chunks_exact_mut(nodes))
        {
            let at_mid = sin_cos(h.omega * mid);
            let (at_far, at_near) = (sin_cos(h.omega * far), sin_cos(h.omega * near));
            out[0] = turn_difference(at_mid, at_far);
            out[1] = turn_difference(at_mid, at_near);
            out[2] = at_mid;
            out[3] = turn_sum(at_mid, at_near);
            out[4] = turn_sum(at_mid, at_far);
        }
    }

    /// The viscous and the input power (W) at Gauss node `k` (`t` after the
    /// start; [`Self::node_factors`] made its factors): the modal rates
    /// only, without the coordinates (what the energy quadrature needs).
    pub(super) fn powers_at(&mut self, index: usize, k: usize, t: f64) -> (f64, f64) {
        self.last = None;
        let m = &self.modes[index];
        let cfg = &m.configuration;
        let r = cfg.modes;
        let nodes = NODES.len();
        for (j, o) in m.oscillators.iter().enumerate() {
            let (d0, r0) = self.start[j];
            let (ec, es) = self.node_modes[nodes * j + k];
            self.rate[j] = ec * r0 - es * (o.sigma * r0 + o.w2 * d0) + o.steady(t).1;
        }
        // The rates take every harmonic's particular part before any
        // harmonic's power is taken from them.
        let turned = |n: usize, (s0, c0): (f64, f64)| {
            let (st, ct) = self.node_turns[nodes * n + k];
            (s0 * ct + c0 * st, c0 * ct - s0 * st)
        };
        for (n, (h, phasor)) in cfg.harmonics.iter().zip(&self.phasors).enumerate() {
            let (s, c) = turned(n, *phasor);
            for j in 0..r {
                if m.from_rest.get(n * r + j) == Some(&true) {
                    let o = &m.oscillators[j];
                    let factors = self.node_modes[nodes * j + k];
                    self.rate[j] += from_rest_part(o, h.omega, h.force[j], *phasor, t, factors).1;
                    continue;
                }
                let (zr, zi) = h.response[j];
                self.rate[j] -= h.omega * (zr * s + zi * c);
            }
        }
        let mut input = 0.0;
        for (n, (h, phasor)) in cfg.harmonics.iter().zip(&self.phasors).enumerate() {
            let (s, c) = turned(n, *phasor);
            for j in 0..r {
                let (pr, pi) = h.force[j];
                input += (pr * c - pi * s) * self.rate[j];
            }
        }
        for j in 0..r {
            input += cfg.driven[j] * self.rate[j];
        }
        // Mass-normalised modes with classical damping: the viscous power is
        // the sum of each mode's.
        let viscous: f64 = (0..r)
            .map(|j| m.oscillators[j].c * self.rate[j] * self.rate[j])
            .sum();
        (viscous, input)
    }
}
