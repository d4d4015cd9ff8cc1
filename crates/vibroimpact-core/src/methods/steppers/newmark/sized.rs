//! The implicit Newmark family's step in the compact form's fixed-size
//! arrays ([`crate::kernel::compact`]), which the event kernel's stretches
//! take in a row ([`Compact::stretch`]: the kernel's own stop rules and
//! records). A declared specialisation of [`NewmarkFamily::attempt`], not a
//! method of its own: the same operations in the same order, the right-hand
//! side by the compact form's [`Compact::rates`] (the general one's bits),
//! the Jacobians by [`Assembly::acceleration_jacobian`] itself and the
//! update by [`crate::numerics::linalg::solve_in_place`]'s own elimination
//! (inlined for the system's size): the same bits, which a test holds them
//! to. Every pair open, the equations are linear and the Jacobians the
//! structure's alone: made once for the stretch.

// Indexed loops over the fixed-size arrays, and copies written as loops,
// as in the compact path (tight code, no call to memcpy).
#![allow(clippy::needless_range_loop, clippy::manual_memcpy)]

use super::{NewmarkFamily, NEWTON_ITERATIONS};
use crate::kernel::compact::{ArraySteps, Compact, Factors, Stretch, MAX_DIM, MAX_LEN, MAX_WALLS};
use crate::model::assembly::{Assembly, Mode, Scratch, CONTACT};
use crate::numerics::linalg;

/// The accumulators' count at most: the powers and each wall's.
const MAX_RATES: usize = CONTACT + MAX_WALLS;

/// [`NewmarkFamily`]'s step data in fixed-size arrays for a stretch of steps
/// in one set of modes: its coefficients, the current point's (algorithmic)
/// accelerations and accumulator rates, the last attempt's.
struct Steps {
    alpha_m: f64,
    alpha_f: f64,
    beta: f64,
    gamma: f64,
    accel: [f64; MAX_DIM],
    rates: [f64; MAX_RATES],
    pending_accel: [f64; MAX_DIM],
    pending_rates: [f64; MAX_RATES],
    /// Every pair open: one Newton update with the Jacobians `dadx`, `dadv`
    /// (row-major `dim x dim`), which are then the structure's alone.
    linear: bool,
    dadx: [f64; MAX_DIM * MAX_DIM],
    dadv: [f64; MAX_DIM * MAX_DIM],
    /// Working rooms, kept across the steps (not zeroed each step): a
    /// contact's Jacobians, the generalised midpoint and the rates.
    contact_dadx: [f64; MAX_DIM * MAX_DIM],
    contact_dadv: [f64; MAX_DIM * MAX_DIM],
    point: [f64; MAX_LEN],
    work: [f64; MAX_LEN],
    /// Room for the rates at a step's end (no pair sticks in a stretch of
    /// this method: unused).
    end_rates: [f64; MAX_LEN],
}

impl ArraySteps for Steps {
    /// [`NewmarkFamily::attempt`] from a valid current point.
    #[inline(always)]
    fn step<const STICKING: bool, const FREE: bool>(
        &mut self,
        compact: &Compact,
        system: &Assembly,
        (n, k): (usize, usize),
        (time, h): (f64, f64),
        y: &[f64; MAX_LEN],
        at: (&[Mode], &Factors),
        scratch: &mut Scratch,
        end: &mut [f64; MAX_LEN],
    ) -> Option<u64> {
        let d = n + k;
        let (am, af, beta, gamma) = (self.alpha_m, self.alpha_f, self.beta, self.gamma);
        let (bx, gv) = (beta * h * h, gamma * h);
        // The new state's parts that do not depend on the new accelerations:
        // the general step's sums up to their last term (the same bits).
        let (mut x0, mut v0) = ([0.0; MAX_DIM], [0.0; MAX_DIM]);
        for i in 0..d {
            x0[i] = y[i] + h * y[d + i] + h * h * (0.5 - beta) * self.accel[i];
            v0[i] = y[d + i] + h * (1.0 - gamma) * self.accel[i];
        }
        let mut a1 = [0.0; MAX_DIM];
        for i in 0..d {
            a1[i] = self.accel[i];
        }
        let (point, rates) = (&mut self.point, &mut self.work);
        // The Jacobians: open, the structure's (made once); else each
        // iteration's, by the general path.
        let (dadx, dadv) = (&mut self.contact_dadx, &mut self.contact_dadv);
        let linear = self.linear;
        let mut evaluations = 0;
        let mut converged = false;
        for _ in 0..NEWTON_ITERATIONS {
            // The generalised midpoint.
            for i in 0..d {
                point[i] = (1.0 - af) * (x0[i] + bx * a1[i]) + af * y[i];
                point[d + i] = (1.0 - af) * (v0[i] + gv * a1[i]) + af * y[d + i];
            }
            let midpoint = time + (1.0 - af) * h;
            compact.rates::<STICKING, FREE>(system, n, k, midpoint, point, at, scratch, rates);
            let (by_x, by_v) = if linear {
                (&self.dadx, &self.dadv)
            } else {
                let (x, v) = (&mut dadx[..d * d], &mut dadv[..d * d]);
                system.acceleration_jacobian(&point[..], at.0, scratch, x, v);
                (&*dadx, &*dadv)
            };
            evaluations += 1;
            let mut size = 0.0f64;
            let mut jacobian = [0.0; MAX_DIM * MAX_DIM];
            let mut step = [0.0; MAX_DIM];
            for i in 0..d {
                let accel = rates[d + i];
                step[i] = -((1.0 - am) * a1[i] + am * self.accel[i] - accel);
                for j in 0..d {
                    let identity = if i == j { 1.0 - am } else { 0.0 };
                    let (dx, dv) = (by_x[i * d + j], by_v[i * d + j]);
                    jacobian[i * d + j] = identity - (1.0 - af) * (bx * dx + gv * dv);
                }
                if linear {
                    continue;
                }
                let mut terms = 0.0;
                for j in 0..d {
                    let (dx, dv) = (by_x[i * d + j], by_v[i * d + j]);
                    terms += (dx * point[j]).abs() + (dv * point[d + j]).abs();
                }
                size = size
                    .max(a1[i].abs())
                    .max(accel.abs())
                    .max(self.accel[i].abs())
                    .max(terms)
                    .max(system.held_acceleration(scratch, i));
            }
            linalg::solve_pivoted::<MAX_DIM>(&mut jacobian[..d * d], &mut step[..d], d);
            let mut largest = 0.0f64;
            for i in 0..d {
                a1[i] += step[i];
                largest = largest.max(step[i].abs());
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
            return None;
        }
        for i in 0..d {
            end[i] = x0[i] + bx * a1[i];
            end[d + i] = v0[i] + gv * a1[i];
        }
        // The accumulators by the trapezoidal rule (`Trapezoid::step`), over
        // every wall's room (those past the system's walls stay zeros).
        let rooms = (2 * d + MAX_RATES).min(MAX_LEN);
        for e in 2 * d..rooms {
            end[e] = y[e];
        }
        compact.rates::<STICKING, FREE>(system, n, k, time + h, end, at, scratch, rates);
        for e in 2 * d..rooms {
            let r = e - 2 * d;
            end[e] += 0.5 * h * (self.rates[r] + rates[e]);
            self.pending_rates[r] = rates[e];
        }
        for i in 0..d {
            self.pending_accel[i] = a1[i];
        }
        Some(evaluations + 1)
    }

    #[inline(always)]
    fn end_rates(&mut self) -> &mut [f64; MAX_LEN] {
        &mut self.end_rates
    }

    #[inline(always)]
    fn keep(&mut self, _end_rates: bool) {
        for i in 0..MAX_DIM {
            self.accel[i] = self.pending_accel[i];
        }
        for r in 0..MAX_RATES {
            self.rates[r] = self.pending_rates[r];
        }
    }
}

impl NewmarkFamily {
    /// Plain steps in a row from the kernel's state lent in `f`, each
    /// [`Self::attempt`]'s to the bit (see the module's text), where the
    /// current point is valid and no pair sticks; else none (the kernel
    /// takes the step).
    pub(super) fn sized_stretch(
        &mut self,
        compact: &Compact,
        system: &Assembly,
        f: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        let d = system.dim;
        let count = self.powers.start_rates().len();
        if !self.valid || modes.contains(&Mode::Sticking) || d > MAX_DIM || count > MAX_RATES {
            return;
        }
        let mut steps = Steps {
            alpha_m: self.alpha_m,
            alpha_f: self.alpha_f,
            beta: self.beta,
            gamma: self.gamma,
            accel: [0.0; MAX_DIM],
            rates: [0.0; MAX_RATES],
            pending_accel: [0.0; MAX_DIM],
            pending_rates: [0.0; MAX_RATES],
            linear: modes.iter().all(|mode| *mode == Mode::Open),
            dadx: [0.0; MAX_DIM * MAX_DIM],
            dadv: [0.0; MAX_DIM * MAX_DIM],
            contact_dadx: [0.0; MAX_DIM * MAX_DIM],
            contact_dadv: [0.0; MAX_DIM * MAX_DIM],
            point: [0.0; MAX_LEN],
            work: [0.0; MAX_LEN],
            end_rates: [0.0; MAX_LEN],
        };
        steps.accel[..d].copy_from_slice(&self.accel[..d]);
        steps.rates[..count].copy_from_slice(self.powers.start_rates());
        if steps.linear {
            // Open, the Jacobians are the structure's (the state's values
            // are not read): what every step's would be.
            let (x, v) = (&mut steps.dadx[..d * d], &mut steps.dadv[..d * d]);
            system.acceleration_jacobian(&f.y[..], modes, scratch, x, v);
        }
        compact.method_stretch(&mut steps, system, f, modes, scratch);
        self.evaluations += f.evaluations;
        #[cfg(test)]
        {
            self.stretched += f.steps;
        }
        self.accel[..d].copy_from_slice(&steps.accel[..d]);
        self.powers.start_rates()[..count].copy_from_slice(&steps.rates[..count]);
    }
}
