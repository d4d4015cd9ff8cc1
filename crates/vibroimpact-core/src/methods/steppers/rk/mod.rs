//! Explicit Runge-Kutta methods on slices: one generic stepper over a Butcher
//! tableau (RK4 fixed step; Dormand-Prince 5(4) and DOP853 with error control).

use super::SystemStepper;
use crate::error::Result;
use crate::kernel::compact::Stretch;
use crate::kernel::sized::by_size;
use crate::methods::tableau::*;
use crate::model::assembly::{Assembly, Mode, Scratch};

mod compact;
use compact::Stages;

/// The adaptive tableaus the compact path takes (see [`compact`]).
#[derive(Debug, Clone, Copy, PartialEq)]
enum Fixed {
    Dopri5,
    Dop853,
}

/// How a tableau estimates its local error.
#[derive(Debug, Clone)]
pub(super) enum Estimate {
    /// A fixed-step method.
    None,
    /// Weights over the stages (the last stage is the new point's `f`).
    Embedded(Vec<f64>),
    /// DOP853's fifth- and third-order weights over the 12 stages and `f` at
    /// the new point, combined as Hairer's `err5^2 / sqrt(err5^2 + 0.01 err3^2)`.
    Dop853 { e5: Vec<f64>, e3: Vec<f64> },
}

/// An explicit Runge-Kutta method on slices.
#[derive(Debug, Clone)]
pub struct ExplicitRk {
    name: &'static str,
    c: Vec<f64>,
    /// Row-major `stages x stages`.
    a: Vec<f64>,
    b: Vec<f64>,
    estimate: Estimate,
    /// Order of the error estimate plus one.
    pub control_exponent: f64,
    pub rtol: f64,
    pub atol: f64,
    stages: usize,
    /// Classical RK4 (a fixed step taken by a loop of its own).
    rk4: bool,
    /// Whether RK4, Dormand-Prince 5(4) and DOP853 take the compact path
    /// where the system has one: their steps in fixed-size arrays, RK4's
    /// plain ones in stretches (see [`crate::kernel::compact`]; the same bits
    /// either way).
    pub compact: bool,
    /// Stage derivatives, plus one slot for `f` at the new point.
    k: Vec<Vec<f64>>,
    /// The adaptive tableau of the compact path, and its stages (a state
    /// that fits its arrays only).
    fixed: Option<(Fixed, Box<Stages>)>,
    /// The last attempt's stages are in `fixed`.
    fixed_used: bool,
    point: Vec<f64>,
    /// `f` at the current point is in `k[0]` (after `reset` or `accept`).
    start_valid: bool,
    /// Index of the slot holding `f` at the end of the last attempt.
    end_slot: Option<usize>,
    evaluations: u64,
}

/// `out = y + h sum_j weights_j k_j`, skipping zero weights.
#[inline(always)]
fn combine(out: &mut [f64], y: &[f64], h: f64, weights: &[f64], k: &[Vec<f64>]) {
    let mut first = true;
    let (len, y) = (out.len(), &y[..out.len()]);
    for (weight, kj) in weights.iter().zip(k) {
        if *weight == 0.0 {
            continue;
        }
        // Slices of the one length: a constant one unrolls.
        let kj = &kj[..len];
        let hw = h * weight;
        if first {
            for ((o, y), k) in out.iter_mut().zip(y).zip(kj) {
                *o = y + hw * k;
            }
            first = false;
        } else {
            for (o, k) in out.iter_mut().zip(kj) {
                *o += hw * k;
            }
        }
    }
    if first {
        out.copy_from_slice(y);
    }
}

/// The embedded estimate's scaled error of a step `h`: the RMS over the
/// `coordinates` of `h sum_j e_j k_j` over each one's `scale`.
#[inline(always)]
fn embedded_error<K: AsRef<[f64]>>(
    e: &[f64],
    k: &[K],
    h: f64,
    coordinates: usize,
    scale: impl Fn(usize) -> f64,
) -> f64 {
    let mut sum = 0.0;
    for n in 0..coordinates {
        let err: f64 = e.iter().zip(k).map(|(w, k)| w * k.as_ref()[n]).sum();
        let ratio = h * err / scale(n);
        sum += ratio * ratio;
    }
    (sum / coordinates as f64).sqrt()
}

/// DOP853's scaled error of a step `h` from its fifth- and third-order
/// estimates (Hairer's `err5^2 / sqrt(err5^2 + 0.01 err3^2)`).
#[inline(always)]
fn dop853_error<K: AsRef<[f64]>>(
    e5: &[f64],
    e3: &[f64],
    k: &[K],
    h: f64,
    coordinates: usize,
    scale: impl Fn(usize) -> f64,
) -> f64 {
    let (mut err5, mut err3) = (0.0, 0.0);
    for n in 0..coordinates {
        let a: f64 = e5.iter().zip(k).map(|(w, k)| w * k.as_ref()[n]).sum();
        let b: f64 = e3.iter().zip(k).map(|(w, k)| w * k.as_ref()[n]).sum();
        let sc = scale(n);
        err5 += (a / sc) * (a / sc);
        err3 += (b / sc) * (b / sc);
    }
    let denominator = err5 + 0.01 * err3;
    if denominator > 0.0 {
        h.abs() * err5 / (denominator * coordinates as f64).sqrt()
    } else {
        0.0
    }
}

pub(super) fn flatten<const S: usize>(a: &[[f64; S]; S]) -> Vec<f64> {
    a.iter().flatten().copied().collect()
}

impl ExplicitRk {
    pub(super) fn build(
        name: &'static str,
        c: &[f64],
        a: Vec<f64>,
        b: &[f64],
        estimate: Estimate,
        control_exponent: f64,
        len: usize,
    ) -> Self {
        let stages = c.len();
        Self {
            name,
            c: c.to_vec(),
            a,
            b: b.to_vec(),
            estimate,
            control_exponent,
            rtol: 0.0,
            atol: 0.0,
            stages,
            rk4: name == "rk4",
            compact: true,
            k: vec![vec![0.0; len]; stages + 1],
            fixed: None,
            fixed_used: false,
            point: vec![0.0; len],
            start_valid: false,
            end_slot: None,
            evaluations: 0,
        }
    }

    /// Classical RK4 for a state of `len` values.
    pub fn rk4(len: usize) -> Self {
        Self::build(
            "rk4",
            &RK4_C,
            flatten(&RK4_A),
            &RK4_B,
            Estimate::None,
            5.0,
            len,
        )
    }

    /// Dormand-Prince 5(4) with tolerances `rtol`, `atol` (m and m/s).
    pub fn dopri5(len: usize, rtol: f64, atol: f64) -> Self {
        let mut s = Self::build(
            "dopri5",
            &DOPRI5_C,
            flatten(&DOPRI5_A),
            &DOPRI5_B,
            Estimate::Embedded(DOPRI5_E.to_vec()),
            5.0,
            len,
        );
        (s.rtol, s.atol) = (rtol, atol);
        s.fixed = compact::stages(len).map(|k| (Fixed::Dopri5, k));
        s
    }

    /// DOP853 with tolerances `rtol`, `atol`.
    pub fn dop853(len: usize, rtol: f64, atol: f64) -> Self {
        let mut s = Self::build(
            "dop853",
            &DOP853_C,
            flatten(&DOP853_A),
            &DOP853_B,
            Estimate::Dop853 {
                e5: DOP853_E5.to_vec(),
                e3: DOP853_E3.to_vec(),
            },
            8.0,
            len,
        );
        (s.rtol, s.atol) = (rtol, atol);
        s.fixed = compact::stages(len).map(|k| (Fixed::Dop853, k));
        s
    }
}

impl ExplicitRk {
    /// RK4's stages after the first (in `k[0]`) and its new point, in the
    /// tableau's arithmetic: each stage point from the one nonzero weight of
    /// its row, the new point `y + h b_0 k_0 + ... + h b_3 k_3` summed in
    /// order, in one pass.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn rk4_stages(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) {
        by_size!(system, |n, k| match &system.compact {
            // The fast path, the same bits (see `compact`).
            Some(compact) if self.compact => {
                let len = system.state_len();
                compact.rk4(
                    system,
                    n,
                    k,
                    time,
                    &y[..len],
                    h,
                    modes,
                    scratch,
                    &mut self.k[0],
                    self.start_valid,
                    &mut out[..len],
                );
                self.evaluations += if self.start_valid { 3 } else { 4 };
                self.start_valid = true;
            }
            _ => self.rk4_in(system, n, k, time, y, h, modes, scratch, out),
        })
    }

    /// [`Self::rk4_stages`] for `n` structure coordinates and `k` dampers,
    /// the right-hand side inlined: where they are constants, the whole
    /// step has sizes known at compile time.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn rk4_in(
        &mut self,
        system: &Assembly,
        n: usize,
        k: usize,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) {
        let coordinates = 2 * (n + k);
        let len = system.state_len();
        // The tableau's own constants (what `c`, `a` and `b` hold for RK4):
        // the compiler folds them.
        let times = [0, 1, 2, 3].map(|i| if i == 0 { time } else { time + RK4_C[i] * h });
        // Each stage's one nonzero weight, on the stage before.
        let hw = [1, 2, 3].map(|i| h * RK4_A[i][i - 1]);
        let w = [0, 1, 2, 3].map(|i| h * RK4_B[i]);
        let [k0, k1, k2, k3, ..] = &mut self.k[..] else {
            unreachable!("RK4 has four stages")
        };
        let mut stages = [
            &mut k0[..len],
            &mut k1[..len],
            &mut k2[..len],
            &mut k3[..len],
        ];
        let (point, y) = (&mut self.point[..coordinates], &y[..len]);
        let parts = system.rates_parts(n, k);
        // One call of the right-hand side in the loop: it is inlined once.
        let first = if self.start_valid { 1 } else { 0 };
        for i in first..4 {
            let (done, next) = stages.split_at_mut(i);
            let at: &[f64] = if i == 0 {
                y
            } else {
                // The stage points need the coordinates and velocities only.
                let (from, y) = (&done[i - 1][..coordinates], &y[..coordinates]);
                for e in 0..coordinates {
                    point[e] = y[e] + hw[i - 1] * from[e];
                }
                point
            };
            system.rates_with(&parts, times[i], at, modes, scratch, next[0]);
        }
        self.evaluations += 4 - first as u64;
        self.start_valid = true;
        let [k0, k1, k2, k3] = stages;
        // Indexed over slices of one length: a loop the compiler vectorises.
        let out = &mut out[..len];
        for e in 0..len {
            out[e] = y[e] + w[0] * k0[e] + w[1] * k1[e] + w[2] * k2[e] + w[3] * k3[e];
        }
    }

    /// The stages of a step `h` from `(time, y)` by the tableau, for `n`
    /// structure coordinates and `k` dampers (constants where `by_size`
    /// fixes them), the right-hand side inlined once in the loop.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn tableau_stages(
        &mut self,
        system: &Assembly,
        n: usize,
        k: usize,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        let s = self.stages;
        // The stages' points need the coordinates and velocities only: the
        // rates do not depend on the energy accumulators.
        let coordinates = 2 * (n + k);
        let parts = system.rates_parts(n, k);
        let first = if self.start_valid { 1 } else { 0 };
        for i in first..s {
            let at = if i == 0 {
                y
            } else {
                // y + h sum_j a_ij k_j over the nonzero weights only, the
                // first term written over y (no copy), each pass a straight
                // vector loop.
                let row = &self.a[i * s..i * s + i];
                let point = &mut self.point[..coordinates];
                combine(point, &y[..coordinates], h, row, &self.k);
                point
            };
            let time = if i == 0 { time } else { time + self.c[i] * h };
            system.rates_with(&parts, time, at, modes, scratch, &mut self.k[i]);
        }
        self.evaluations += (s - first) as u64;
        self.start_valid = true;
    }
}

impl SystemStepper for ExplicitRk {
    fn name(&self) -> &'static str {
        self.name
    }

    fn is_adaptive(&self) -> bool {
        !matches!(self.estimate, Estimate::None)
    }

    fn tolerances(&self) -> Option<(f64, f64)> {
        self.is_adaptive().then_some((self.rtol, self.atol))
    }

    fn reset(&mut self) {
        self.start_valid = false;
        self.end_slot = None;
    }

    fn takes_stretches(&self, system: &Assembly, _fixed: bool) -> bool {
        self.rk4 && self.compact && system.compact.is_some()
    }

    fn stretch(
        &mut self,
        system: &Assembly,
        stretch: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        let Some(compact) = &system.compact else {
            return;
        };
        if !(self.rk4 && self.compact && !self.start_valid) {
            return;
        }
        compact.run_stretch(system, stretch, modes, scratch);
        self.evaluations += stretch.evaluations;
    }

    /// The first stage, `f(y)`: what the next attempt from `y` starts from
    /// (computed now, and kept, where the last step's end did not give it).
    fn start_rates(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
    ) -> Option<&[f64]> {
        if !self.is_adaptive() {
            return None;
        }
        let len = self.point.len();
        let fixed = match &mut self.fixed {
            Some((_, stages)) if self.compact && system.compact.is_some() => Some(stages),
            _ => None,
        };
        let first = match fixed {
            Some(stages) => &mut stages[0][..len],
            None => &mut self.k[0][..],
        };
        if !self.start_valid {
            system.rates(time, y, modes, scratch, first);
            self.evaluations += 1;
            self.start_valid = true;
        }
        Some(first)
    }

    /// The error control weighs the coordinates and velocities, not the
    /// energy accumulators.
    fn attempt(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) -> Result<f64> {
        let s = self.stages;
        if self.rk4 {
            self.rk4_stages(system, time, y, h, modes, scratch, out);
            self.end_slot = None;
            return Ok(0.0);
        }
        if let (Some(compact), true, true) = (&system.compact, self.compact, self.fixed.is_some()) {
            self.fixed_used = true;
            return Ok(self.compact_attempt(compact, system, time, y, h, modes, scratch, out));
        }
        self.fixed_used = false;
        by_size!(system, |n, k| self
            .tableau_stages(system, n, k, time, y, h, modes, scratch));
        let coordinates = 2 * system.dim;
        combine(out, y, h, &self.b, &self.k);
        let scale = |n: usize| self.atol + self.rtol * y[n].abs().max(out[n].abs());
        Ok(match &self.estimate {
            Estimate::None => {
                self.end_slot = None;
                0.0
            }
            Estimate::Embedded(e) => {
                // The last stage is evaluated at the new point (c = 1, a = b).
                self.end_slot = Some(s - 1);
                embedded_error(e, &self.k, h, coordinates, scale)
            }
            Estimate::Dop853 { e5, e3 } => {
                system.rates(time + h, out, modes, scratch, &mut self.k[s]);
                self.evaluations += 1;
                self.end_slot = Some(s);
                dop853_error(e5, e3, &self.k, h, coordinates, scale)
            }
        })
    }

    fn first_stage(&self) -> Option<&[f64]> {
        // RK4's first stage is `k[0]` on either path (the compact one too).
        self.rk4.then_some(&self.k[0][..])
    }

    fn accept(&mut self) {
        match self.end_slot {
            Some(slot) => {
                match &mut self.fixed {
                    Some((_, stages)) if self.fixed_used => stages[0] = stages[slot],
                    _ => self.k.swap(0, slot),
                }
                self.start_valid = true;
            }
            None => self.start_valid = false,
        }
    }

    fn shrink(&self, error: f64) -> f64 {
        error.powf(-1.0 / self.control_exponent)
    }

    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}
