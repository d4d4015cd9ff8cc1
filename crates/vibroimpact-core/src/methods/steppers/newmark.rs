//! The Newmark family (Newmark-beta, Chung-Hulbert's generalised-alpha) on
//! any system, Newton on the new accelerations.

use super::SystemStepper;
use crate::error::{Error, Result};
use crate::kernel::compact::Stretch;
use crate::methods::trapezoid::Trapezoid;
use crate::model::assembly::{Assembly, Mode, Scratch};
use crate::numerics::linalg;

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
    /// Whether plain steps on a system with a compact form are taken in
    /// the stretches of its fixed-size path ([`sized`]; the same bits).
    compact: bool,
    /// Steps taken in those stretches (its test asks that they ran).
    #[cfg(test)]
    stretched: u64,
}

mod sized;
#[cfg(test)]
mod sized_tests;

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
            compact: true,
            #[cfg(test)]
            stretched: 0,
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

    /// Every step by [`SystemStepper::attempt`], none in the fixed-size
    /// path's stretches (its test's reference).
    #[cfg(test)]
    pub(crate) fn general(mut self) -> Self {
        self.compact = false;
        self
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

    fn takes_stretches(&self, system: &Assembly, fixed: bool) -> bool {
        // The event kernel's stretches (fixed stepping has none of its own).
        !fixed && self.compact && system.compact.is_some()
    }

    fn stretch(
        &mut self,
        system: &Assembly,
        stretch: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        if let (Some(compact), true) = (&system.compact, self.compact) {
            self.sized_stretch(compact, system, stretch, modes, scratch);
        }
    }

    fn carries_solution(&self) -> bool {
        // Newmark-beta's converged accelerations are the physical ones at
        // the step's end (to Newton's tolerance); generalised-alpha's are not.
        self.alpha_m != 0.0 || self.alpha_f != 0.0
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
        // Every pair open: the equations are linear in the new accelerations
        // (the structure is), so one Newton update with the exact Jacobian
        // solves them, as 0.1 took it; no second evaluation to confirm it.
        let linear = modes.iter().all(|mode| *mode == Mode::Open);
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
                for j in 0..d {
                    let identity = if i == j { 1.0 - am } else { 0.0 };
                    let (by_x, by_v) = (self.dadx[i * d + j], self.dadv[i * d + j]);
                    self.jacobian[i * d + j] = identity - (1.0 - af) * (bx * by_x + gv * by_v);
                }
                if linear {
                    // One update solves it: no convergence test to scale.
                    continue;
                }
                // The scale of the equation's terms, whose round-off bounds
                // how far Newton can go: the new and old accelerations and
                // the stiffness and damping terms (the accelerations can be
                // exactly zero, a pair at rest on a resting wall).
                let mut terms = 0.0;
                for j in 0..d {
                    let (by_x, by_v) = (self.dadx[i * d + j], self.dadv[i * d + j]);
                    terms += (by_x * self.point[j]).abs() + (by_v * self.point[d + j]).abs();
                }
                // A pair held on its wall: the accelerations and the Jacobian's
                // terms there are round-off, of the forces its constraint cancels.
                size = size
                    .max(self.a1[i].abs())
                    .max(accel.abs())
                    .max(self.accel[i].abs())
                    .max(terms)
                    .max(system.held_acceleration(scratch, i));
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
            if linear || largest <= 1e-12 * size || largest == 0.0 {
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
