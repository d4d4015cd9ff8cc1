//! Explicit Runge-Kutta steppers over any [`Assembly`]: the state is a slice
//! and every buffer is allocated once, when the stepper is made.
//!
//! One generic stepper over a Butcher tableau serves RK4 (fixed step),
//! Dormand-Prince 5(4) and DOP853 (error control, first same as last).

use crate::error::{Error, Result};
use crate::kernel::compact::Stretch;
use crate::kernel::sized::by_size;
use crate::methods::tableau::*;
use crate::methods::trapezoid::Trapezoid;
use crate::model::assembly::{Assembly, Mode, Scratch};
use crate::numerics::linalg;

/// A method the 0.2 kernel can drive: it advances the state within one set of
/// contact modes, where the right-hand side is smooth.
pub trait SystemStepper {
    fn name(&self) -> &'static str;
    /// Whether the step size is controlled by an error estimate.
    fn is_adaptive(&self) -> bool;
    /// Whether a step lands on the exact solution (then the run's time
    /// resolution is set by round-off, not by the step).
    fn is_exact(&self) -> bool {
        false
    }
    /// The longest step the method takes from `(time, y)` in `modes` (s): a
    /// method whose step is set by the system it integrates shortens it where
    /// that changes.
    fn step_limit(
        &mut self,
        _system: &Assembly,
        _time: f64,
        _y: &[f64],
        _modes: &[Mode],
        _scratch: &mut Scratch,
    ) -> Result<f64> {
        Ok(f64::INFINITY)
    }
    /// The state's rates at `(time, y)` where an adaptive method has them for
    /// nothing (its first stage, kept for the attempt that follows), else
    /// None: the kernel ends a step soon after an open gap's parabola lands.
    fn start_rates(
        &mut self,
        _system: &Assembly,
        _time: f64,
        _y: &[f64],
        _modes: &[Mode],
        _scratch: &mut Scratch,
    ) -> Option<&[f64]> {
        None
    }
    /// Forget data carried from the last step (the right-hand side jumped).
    fn reset(&mut self);
    /// Fixed stepping (steps not cut at contacts): the step just kept and
    /// accepted ended with a contact change found inside it, and the modes
    /// change from the next step on. By default the carried data go, as at
    /// any mode switch ([`Self::reset`]). The founding paper's Newmark keeps
    /// its accelerations (0.1's fixed-step kernel never restarted it), so
    /// that its fixed steps are 0.1's to the bit; the kernel must then not
    /// call [`Self::reset`] for that change, nor attempt other lengths from
    /// the step's start after the kept one.
    fn switched_within_step(&mut self) {
        self.reset();
    }
    /// Whether the method creates energy at a contact by construction (the
    /// founding paper's Newmark, whose contact force lags one step: its
    /// Table 1 collision rebounds at 1.0015 of the approach speed at its
    /// dt = 1e-4 s, 1.049 at 1e-3 s, where the model's is 0.99635).
    /// Its contacts are then bounded by `energy_tolerance` alone, as 0.1
    /// bounded them, not by the kernel's `CONTACT_CREATION_LIMIT`.
    fn creates_contact_energy(&self) -> bool {
        false
    }
    /// Whether the method takes stretches of plain fixed steps of `system`
    /// (see [`Self::stretch`]). No by default.
    fn takes_stretches(&self, _system: &Assembly) -> bool {
        false
    }
    /// Plain fixed steps taken at once (see [`Stretch`], a type of the
    /// kernel's, not for callers), where the method can: each the step the
    /// kernel would take, to the bit. None by default.
    #[doc(hidden)]
    fn stretch(
        &mut self,
        _system: &Assembly,
        _stretch: &mut Stretch<'_>,
        _modes: &[Mode],
        _scratch: &mut Scratch,
    ) {
    }
    /// Attempt a step `h` from `(time, y)` into `out`; the scaled error
    /// (accept when <= 1), 0 for a fixed-step method.
    #[allow(clippy::too_many_arguments)]
    fn attempt(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) -> Result<f64>;
    /// The accelerations and their rates (`dim` values each, into `accel`
    /// and `jerk`) at the end of the last attempt, where the method has them
    /// for little (the exact flow, from its modal state there): locating an
    /// event then solves the value's cubic Taylor polynomial about a trial
    /// instead of its tangent. False (the default) where it has not.
    fn end_derivatives(
        &mut self,
        _system: &Assembly,
        _accel: &mut [f64],
        _jerk: &mut [f64],
    ) -> bool {
        false
    }
    /// The last attempt is the new current point.
    fn accept(&mut self);
    /// Complete the step `h` from `(time, y)` the kernel keeps, `end`, with
    /// what only a kept step needs (a method that leaves its attempts'
    /// energy accumulators out fills them here). Unless `settle` (the kernel
    /// reads the accumulators at `end`: an event there, a balance check, the
    /// run's end), a method may leave them as they are in `y` and add this
    /// step's share at a later step's settlement (the kernel then passes on
    /// `end` unchanged as the next step's start).
    #[allow(clippy::too_many_arguments)]
    fn finish(
        &mut self,
        _system: &Assembly,
        _time: f64,
        _y: &[f64],
        _h: f64,
        _modes: &[Mode],
        _scratch: &mut Scratch,
        _end: &mut [f64],
        _settle: bool,
    ) -> Result<()> {
        Ok(())
    }
    /// The step-size factor's core for a scaled `error`.
    fn shrink(&self, error: f64) -> f64;
    /// Right-hand-side evaluations so far.
    fn evaluations(&self) -> u64;
}

/// How a tableau estimates its local error.
#[derive(Debug, Clone)]
enum Estimate {
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
    /// Whether RK4 takes the compact path where the system has one: its
    /// steps in fixed-size arrays, plain ones in stretches (see
    /// [`crate::kernel::compact`]; the same bits either way).
    pub compact: bool,
    /// Stage derivatives, plus one slot for `f` at the new point.
    k: Vec<Vec<f64>>,
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

fn flatten<const S: usize>(a: &[[f64; S]; S]) -> Vec<f64> {
    a.iter().flatten().copied().collect()
}

impl ExplicitRk {
    fn build(
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

    fn reset(&mut self) {
        self.start_valid = false;
        self.end_slot = None;
    }

    fn takes_stretches(&self, system: &Assembly) -> bool {
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
        if !self.start_valid {
            system.rates(time, y, modes, scratch, &mut self.k[0]);
            self.evaluations += 1;
            self.start_valid = true;
        }
        Some(&self.k[0])
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
                let mut sum = 0.0;
                for n in 0..coordinates {
                    let err: f64 = e.iter().zip(&self.k).map(|(w, k)| w * k[n]).sum();
                    let ratio = h * err / scale(n);
                    sum += ratio * ratio;
                }
                (sum / coordinates as f64).sqrt()
            }
            Estimate::Dop853 { e5, e3 } => {
                system.rates(time + h, out, modes, scratch, &mut self.k[s]);
                self.evaluations += 1;
                self.end_slot = Some(s);
                let (mut err5, mut err3) = (0.0, 0.0);
                for n in 0..coordinates {
                    let a: f64 = e5.iter().zip(&self.k).map(|(w, k)| w * k[n]).sum();
                    let b: f64 = e3.iter().zip(&self.k).map(|(w, k)| w * k[n]).sum();
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
        })
    }

    fn accept(&mut self) {
        match self.end_slot {
            Some(slot) => {
                self.k.swap(0, slot);
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

/// The Newmark family on any system, for the new accelerations `a1` by
/// Newton's method:
///
/// `(1 - am) a1 + am a0 = A(t + (1 - af) h, (1 - af) x1 + af x0, (1 - af) v1 + af v0)`
///
/// with Newmark's `x1 = x0 + h v0 + h^2 ((1/2 - beta) a0 + beta a1)`, `v1 = v0 +
/// h ((1 - gamma) a0 + gamma a1)` and `A` the accelerations of the system
/// (contact and constraint forces included). `am = af = 0` is Newmark-beta
/// (average acceleration for 1/4, 1/2: second order, no numerical damping);
/// Chung-Hulbert's generalised-alpha sets all four from the spectral radius.
/// The energy accumulators follow the trapezoidal rule, second order too.
#[derive(Debug, Clone)]
pub struct NewmarkFamily {
    name: &'static str,
    alpha_m: f64,
    alpha_f: f64,
    beta: f64,
    gamma: f64,
    /// Accelerations (algorithmic) at the current point, and the
    /// accumulators' rates there; valid after `reset` and `accept`.
    accel: Vec<f64>,
    powers: Trapezoid,
    valid: bool,
    pending_accel: Vec<f64>,
    point: Vec<f64>,
    rates: Vec<f64>,
    a1: Vec<f64>,
    step: Vec<f64>,
    dadx: Vec<f64>,
    dadv: Vec<f64>,
    jacobian: Vec<f64>,
    evaluations: u64,
}

/// Newton iterations allowed per step.
const NEWTON_ITERATIONS: usize = 40;

impl NewmarkFamily {
    fn build(
        name: &'static str,
        am: f64,
        af: f64,
        beta: f64,
        gamma: f64,
        dim: usize,
        len: usize,
    ) -> Self {
        Self {
            name,
            alpha_m: am,
            alpha_f: af,
            beta,
            gamma,
            accel: vec![0.0; dim],
            powers: Trapezoid::of(len - 2 * dim),
            valid: false,
            pending_accel: vec![0.0; dim],
            point: vec![0.0; len],
            rates: vec![0.0; len],
            a1: vec![0.0; dim],
            step: vec![0.0; dim],
            dadx: vec![0.0; dim * dim],
            dadv: vec![0.0; dim * dim],
            jacobian: vec![0.0; dim * dim],
            evaluations: 0,
        }
    }

    /// Newmark-beta (`beta`, `gamma`) solved implicitly, for `system`.
    pub fn newmark(system: &Assembly, beta: f64, gamma: f64) -> Self {
        Self::build(
            "newmark-implicit",
            0.0,
            0.0,
            beta,
            gamma,
            system.dim,
            system.state_len(),
        )
    }

    /// Chung-Hulbert generalised-alpha with spectral radius `rho` in [0, 1].
    pub fn generalized_alpha(system: &Assembly, rho: f64) -> Self {
        let am = (2.0 * rho - 1.0) / (rho + 1.0);
        let af = rho / (rho + 1.0);
        let gamma = 0.5 - am + af;
        let beta = 0.25 * (1.0 - am + af).powi(2);
        Self::build(
            "generalized-alpha",
            am,
            af,
            beta,
            gamma,
            system.dim,
            system.state_len(),
        )
    }
}

impl SystemStepper for NewmarkFamily {
    fn name(&self) -> &'static str {
        self.name
    }

    fn is_adaptive(&self) -> bool {
        false
    }

    fn reset(&mut self) {
        self.valid = false;
    }

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
        let d = system.dim;
        let (am, af, beta, gamma) = (self.alpha_m, self.alpha_f, self.beta, self.gamma);
        if !self.valid {
            // After a jump, the physical accelerations.
            system.rates(time, y, modes, scratch, &mut self.rates);
            self.evaluations += 1;
            self.accel.copy_from_slice(&self.rates[d..2 * d]);
            self.powers.restart(system, &self.rates);
            self.valid = true;
        }
        let (bx, gv) = (beta * h * h, gamma * h);
        let new_state = |a1: &[f64], point: &mut [f64], accel: &[f64]| {
            for i in 0..d {
                let x1 = y[i] + h * y[d + i] + h * h * (0.5 - beta) * accel[i] + bx * a1[i];
                let v1 = y[d + i] + h * (1.0 - gamma) * accel[i] + gv * a1[i];
                point[i] = x1;
                point[d + i] = v1;
            }
        };
        self.a1.copy_from_slice(&self.accel);
        self.point[2 * d..].copy_from_slice(&y[2 * d..]);
        let mut converged = false;
        for _ in 0..NEWTON_ITERATIONS {
            new_state(&self.a1, &mut self.point, &self.accel);
            // The generalised midpoint.
            for (p, y) in self.point[..2 * d].iter_mut().zip(y) {
                *p = (1.0 - af) * *p + af * y;
            }
            system.rates(
                time + (1.0 - af) * h,
                &self.point,
                modes,
                scratch,
                &mut self.rates,
            );
            system.acceleration_jacobian(
                &self.point,
                modes,
                scratch,
                &mut self.dadx,
                &mut self.dadv,
            );
            self.evaluations += 1;
            let mut size = 0.0f64;
            for i in 0..d {
                let accel = self.rates[d + i];
                self.step[i] = -((1.0 - am) * self.a1[i] + am * self.accel[i] - accel);
                // The scale of the equation's terms, whose round-off bounds
                // how far Newton can go: the new and old accelerations and
                // the stiffness and damping terms (the accelerations can be
                // exactly zero, a pair at rest on a resting wall).
                let mut terms = 0.0;
                for j in 0..d {
                    let identity = if i == j { 1.0 - am } else { 0.0 };
                    let (by_x, by_v) = (self.dadx[i * d + j], self.dadv[i * d + j]);
                    self.jacobian[i * d + j] = identity - (1.0 - af) * (bx * by_x + gv * by_v);
                    terms += (by_x * self.point[j]).abs() + (by_v * self.point[d + j]).abs();
                }
                size = size
                    .max(self.a1[i].abs())
                    .max(accel.abs())
                    .max(self.accel[i].abs())
                    .max(terms);
            }
            linalg::solve_in_place(&mut self.jacobian, &mut self.step, d);
            let mut largest = 0.0f64;
            for i in 0..d {
                self.a1[i] += self.step[i];
                largest = largest.max(self.step[i].abs());
            }
            if !largest.is_finite() {
                break;
            }
            if largest <= 1e-12 * size || largest == 0.0 {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(Error::NewtonFailed { time });
        }
        new_state(&self.a1, out, &self.accel);
        let rates = &mut self.rates;
        self.powers
            .step(system, time, y, h, modes, scratch, rates, out);
        self.evaluations += 1;
        self.pending_accel.copy_from_slice(&self.a1);
        Ok(0.0)
    }

    fn accept(&mut self) {
        std::mem::swap(&mut self.accel, &mut self.pending_accel);
        self.powers.accept();
    }

    fn shrink(&self, _error: f64) -> f64 {
        1.0
    }

    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::assembly::{
        initial_state, Damper, Excitation, Load, PairLaw, SystemSpec, CONTACT,
    };
    use crate::model::contact::{Contact, LawKind};
    use crate::model::signals::Signal;
    use crate::model::structure::Structure;

    /// A modal cantilever with two dampers (one compliant, one rigid), two
    /// forces, a base excitation and gravity: every term of the rates.
    fn beam() -> Assembly {
        let contact = Contact::new(LawKind::HertzDamped, 1e7, Some(0.6), 1.0).unwrap();
        let spec = SystemSpec {
            structure: Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.01).unwrap(),
            dampers: vec![
                Damper {
                    mass: 0.01,
                    at: 0.5,
                    lower_clearance: 2e-4,
                    upper_clearance: 2e-4,
                    law: PairLaw::Compliant(contact),
                },
                Damper {
                    mass: 0.02,
                    at: 0.25,
                    lower_clearance: 1e-4,
                    upper_clearance: 3e-4,
                    law: PairLaw::rigid(0.5).unwrap(),
                },
            ],
            stops: vec![],
            gravity: 9.81,
            excitations: vec![
                Excitation {
                    load: Load::Force { at: 0.5 },
                    signal: Signal::harmonic(0.5, 8.0, 0.0).unwrap(),
                },
                Excitation {
                    load: Load::Force { at: 0.3 },
                    signal: Signal::harmonic(0.2, 13.0, 0.4).unwrap(),
                },
                Excitation {
                    load: Load::Base,
                    signal: Signal::harmonic(1.5, 5.0, 0.1).unwrap(),
                },
            ],
            points: vec![],
            moments: vec![],
        };
        Assembly::new(&spec).unwrap()
    }

    /// A state whose coordinates and accumulators are all nonzero.
    fn state(system: &Assembly, seed: f64) -> Vec<f64> {
        let mut y = initial_state(system, &[], &[], &[], &[]).unwrap();
        for (i, v) in y.iter_mut().enumerate() {
            *v = 1e-4 * (seed + 0.37 * i as f64).sin();
        }
        y
    }

    /// Open, in compliant contact and sticking: each branch of the rates.
    fn mode_sets(system: &Assembly) -> Vec<Vec<Mode>> {
        let count = system.interactions.len();
        let mut sets = vec![vec![Mode::Open; count]];
        let mut compliant = vec![Mode::Open; count];
        compliant[1] = Mode::Compliant {
            approach_rate: 0.01,
        };
        sets.push(compliant.clone());
        compliant[2] = Mode::Sticking;
        sets.push(compliant);
        sets
    }

    #[test]
    fn bodies_for_constant_sizes_match_the_general_one_to_the_bit() {
        crate::testing::timeout(60, || {
            let system = beam();
            let len = system.state_len();
            // Sizes the compiler cannot see: the general body.
            let (n, k) = std::hint::black_box((system.n, system.k));
            let (mut s1, mut s2) = (Scratch::new(&system), Scratch::new(&system));
            let (mut a, mut b) = (vec![0.0; len], vec![0.0; len]);
            let count = system.interactions.len();
            let (mut g1, mut g2) = (vec![(0.0, 0.0); count], vec![(0.0, 0.0); count]);
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            for modes in &mode_sets(&system) {
                for step in 0..100 {
                    let (time, y) = (1e-5 * step as f64, state(&system, step as f64));
                    system.rates(time, &y, modes, &mut s1, &mut a);
                    system.rates_in(n, k, time, &y, modes, &mut s2, &mut b);
                    assert_eq!(bits(&a), bits(&b), "step {step}, {modes:?}");
                    assert_eq!(bits(&s1.forces), bits(&s2.forces));
                    system.gaps(&y, &mut g1);
                    system.gaps_in(n + k, &y, &mut g2);
                    let pairs = |g: &[(f64, f64)]| {
                        g.iter()
                            .map(|p| (p.0.to_bits(), p.1.to_bits()))
                            .collect::<Vec<_>>()
                    };
                    assert_eq!(pairs(&g1), pairs(&g2));
                }
            }
        });
    }

    #[test]
    fn rk4_own_loop_matches_its_tableau_to_the_bit() {
        crate::testing::timeout(60, || {
            let system = beam();
            let len = system.state_len();
            for modes in &mode_sets(&system) {
                let mut own = ExplicitRk::rk4(len);
                let mut tableau = ExplicitRk::build(
                    "rk4 by its tableau",
                    &RK4_C,
                    flatten(&RK4_A),
                    &RK4_B,
                    Estimate::None,
                    5.0,
                    len,
                );
                let (mut s1, mut s2) = (Scratch::new(&system), Scratch::new(&system));
                let (mut a, mut b) = (vec![0.0; len], vec![0.0; len]);
                let mut time = 0.0;
                for step in 0..200 {
                    let y = state(&system, step as f64);
                    // Repeated attempts from one point reuse its rates.
                    for h in [1e-5, 0.4e-5] {
                        own.attempt(&system, time, &y, h, modes, &mut s1, &mut a)
                            .unwrap();
                        tableau
                            .attempt(&system, time, &y, h, modes, &mut s2, &mut b)
                            .unwrap();
                        let same = a.iter().zip(&b).all(|(p, q)| p.to_bits() == q.to_bits());
                        assert!(same, "step {step}, h {h}: {a:?} != {b:?}");
                    }
                    own.accept();
                    tableau.accept();
                    time += 1e-5;
                }
                assert_eq!(own.evaluations(), tableau.evaluations());
                assert!(a[2 * system.dim + CONTACT..].iter().all(|l| l.is_finite()));
            }
        });
    }

    #[test]
    fn all_gaps_at_once_match_each_gap_to_the_bit() {
        crate::testing::timeout(60, || {
            let system = beam();
            let mut gaps = vec![(0.0, 0.0); system.interactions.len()];
            for seed in 0..50 {
                let y = state(&system, seed as f64);
                system.gaps(&y, &mut gaps);
                for (i, (g, r)) in gaps.iter().enumerate() {
                    let (g0, r0) = system.gap(i, &y);
                    assert_eq!((g.to_bits(), r.to_bits()), (g0.to_bits(), r0.to_bits()));
                }
            }
        });
    }
}
