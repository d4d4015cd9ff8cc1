//! Explicit Runge-Kutta steppers over any [`Assembly`]: the state is a slice
//! and every buffer is allocated once, when the stepper is made.
//!
//! One generic stepper over a Butcher tableau serves RK4 (fixed step),
//! Dormand-Prince 5(4) and DOP853 (error control, first same as last).

use crate::assembly::{Assembly, Mode, Scratch};
use crate::tableau::*;

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
    /// Stage derivatives, plus one slot for `f` at the new point.
    k: Vec<Vec<f64>>,
    point: Vec<f64>,
    /// `f` at the current point is in `k[0]` (after `reset` or `accept`).
    start_valid: bool,
    /// Index of the slot holding `f` at the end of the last attempt.
    end_slot: Option<usize>,
    evaluations: u64,
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

    pub fn name(&self) -> &'static str {
        self.name
    }

    pub fn is_adaptive(&self) -> bool {
        !matches!(self.estimate, Estimate::None)
    }

    /// Forget data carried from the last step (the right-hand side jumped).
    pub fn reset(&mut self) {
        self.start_valid = false;
        self.end_slot = None;
    }

    /// Attempt a step `h` from `(time, y)` into `out`; returns the scaled
    /// error (accept when <= 1), 0 for a fixed-step method. `coordinates`
    /// is the number of leading state values the error control weighs.
    #[allow(clippy::too_many_arguments)]
    pub fn attempt(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) -> f64 {
        let s = self.stages;
        if !self.start_valid {
            system.rates(time, y, modes, scratch, &mut self.k[0]);
            self.evaluations += 1;
            self.start_valid = true;
        }
        for i in 1..s {
            self.point.copy_from_slice(y);
            for j in 0..i {
                let weight = self.a[i * s + j];
                if weight != 0.0 {
                    for (p, k) in self.point.iter_mut().zip(&self.k[j]) {
                        *p += h * weight * k;
                    }
                }
            }
            system.rates(
                time + self.c[i] * h,
                &self.point,
                modes,
                scratch,
                &mut self.k[i],
            );
            self.evaluations += 1;
        }
        out.copy_from_slice(y);
        for (j, bj) in self.b.iter().enumerate() {
            if *bj != 0.0 {
                for (o, k) in out.iter_mut().zip(&self.k[j]) {
                    *o += h * bj * k;
                }
            }
        }
        let coordinates = 2 * system.dim;
        let scale = |n: usize| self.atol + self.rtol * y[n].abs().max(out[n].abs());
        match &self.estimate {
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
        }
    }

    /// The last attempt is the new current point.
    pub fn accept(&mut self) {
        match self.end_slot {
            Some(slot) => {
                self.k.swap(0, slot);
                self.start_valid = true;
            }
            None => self.start_valid = false,
        }
    }

    /// `error^(-1 / control_exponent)`.
    pub fn shrink(&self, error: f64) -> f64 {
        error.powf(-1.0 / self.control_exponent)
    }

    pub fn evaluations(&self) -> u64 {
        self.evaluations
    }
}
