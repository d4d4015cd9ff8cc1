//! The founding paper's method (`method = "newmark"`) over any [`Assembly`]:
//! Newmark-beta on the system's linear part, `M`, `C` and `K`, with each
//! compliant contact's law force taken at the start of the step (lagged one
//! step: the paper's "piecewise linearisation") and its contact damper
//! implicit. The new accelerations then solve a linear system whose matrix,
//!
//! `A = M + gamma h (C + sum c1 h_c^T h_c) + beta h^2 K`
//!
//! (the sum over the contacts in compliant mode), changes only with the
//! step and the contacts: its inverse is kept, for the bodies apart and for
//! the last set of contacts, and a step is a few products. No Newton loop.
//!
//! On the two-mass impact damper ([`crate::model::impact_damper`]) it takes
//! the operations of 0.1's `PaperNewmark` in their order (the same bits):
//! the 2x2 inverse by its adjugate, the right-hand side
//! `f + h^T F_law - C v* - K x* + h^T c1 rate(v*)`, and after a restart the
//! accelerations as 0.1 wrote them, `(-C/M) v - (K/M) x + force / M` per
//! coordinate of a diagonal system.

use crate::error::{Error, Result};
use crate::kernel::compact::Stretch;
use crate::kernel::plain_fixed::plain_fixed_steps;
use crate::kernel::sized::by_size;
use crate::methods::steppers::SystemStepper;
use crate::methods::trapezoid::Trapezoid;
use crate::model::assembly::{
    h_dot, Assembly, HarmonicLoad, InteractionLaw, Mode, Scratch, CONTACT, INPUT, VISCOUS,
};
use crate::model::contact::{AnyLaw, ContactLaw};
use crate::numerics::linalg;
use sized::Sized;

/// A compliant interaction: its index, law and contact damper (N s/m).
#[derive(Debug, Clone, Copy)]
struct Compliant {
    index: usize,
    law: AnyLaw,
    damping: f64,
}

/// An inverse of the effective matrix, for the step and contacts it was made
/// for (`step` NaN: none yet).
#[derive(Debug, Clone)]
struct Effective {
    step: f64,
    /// Which entries of [`PaperNewmark::compliant`] are in contact.
    contacts: Vec<bool>,
    inverse: Vec<f64>,
}

impl Effective {
    fn new(dim: usize, compliant: usize) -> Self {
        Self {
            step: f64::NAN,
            contacts: vec![false; compliant],
            inverse: vec![0.0; dim * dim],
        }
    }
}

/// The founding paper's Newmark-beta with the contact force lagged one step.
#[derive(Debug, Clone)]
pub struct PaperNewmark {
    beta: f64,
    gamma: f64,
    n: usize,
    dim: usize,
    /// `M`, `C`, `K` over all coordinates (row-major `dim x dim`).
    mass: Vec<f64>,
    damping: Vec<f64>,
    stiffness: Vec<f64>,
    /// The loads between contacts (N): gravity's, then harmonic ones.
    constant: Vec<f64>,
    harmonics: Vec<HarmonicLoad>,
    /// Whether any load acts (else none is added, as 0.1 added none).
    forced: bool,
    /// `[C/M, K/M, 1/M]` of each coordinate where `M`, `C` and `K` are
    /// diagonal (0.1's accelerations after a restart), else None.
    per_mass: Option<Vec<[f64; 3]>>,
    compliant: Vec<Compliant>,
    /// The inverses apart and with the last set of contacts.
    apart: Effective,
    touching: Effective,
    /// The contacts of the step being taken.
    contacts: Vec<bool>,
    /// Accelerations (algorithmic) and the accumulators' rates at the
    /// current point, and at the end of the last attempt.
    accel: Vec<f64>,
    pending_accel: Vec<f64>,
    powers: Trapezoid,
    /// Whether `accel` and `powers` hold the current point's.
    valid: bool,
    powers_valid: bool,
    /// Work space: the predictor `(x*, v*)`, the right-hand side and the
    /// rates, and a matrix for the inverse.
    predictor: Vec<f64>,
    residual: Vec<f64>,
    rates: Vec<f64>,
    matrix: Vec<f64>,
    /// One a step, as 0.1 counted the method (the accelerations made again
    /// at a restart are not counted).
    evaluations: u64,
    /// The data in fixed-size arrays where the compact path takes the
    /// system: its plain steps, fixed or between events, are taken there
    /// ([`sized`]).
    sized: Option<Box<Sized>>,
}

impl PaperNewmark {
    /// The method with `beta` in [0, 0.5] and `gamma` in [0.5, 1] (the
    /// paper's average acceleration: 1/4, 1/2) for `system`, whose pairs
    /// must all be compliant and whose loads sums of harmonics.
    pub fn new(system: &Assembly, beta: f64, gamma: f64) -> Result<Self> {
        let parts = system.linear_parts("newmark")?;
        let mut compliant = Vec::new();
        for (index, it) in system.interactions.iter().enumerate() {
            match it.law {
                InteractionLaw::Compliant { law, damping } => compliant.push(Compliant {
                    index,
                    law,
                    damping,
                }),
                InteractionLaw::Friction { .. } => {
                    return Err(Error::Inconsistent(format!(
                        "method \"newmark\" (the founding paper's) takes compliant contact laws \
                         only, and {} is dry friction: use \"newmark-implicit\", \"exact\" or \
                         \"dop853\"",
                        system.pairs[it.pair]
                    )))
                }
                InteractionLaw::Rigid { .. } => {
                    return Err(Error::Inconsistent(format!(
                        "method \"newmark\" (the founding paper's, its contact force lagged one \
                         step) takes compliant contact laws only, and {} is rigid: give it a \
                         compliant law or use \"newmark-implicit\"",
                        system.pairs[it.pair]
                    )))
                }
            }
        }
        let (n, dim) = (system.n, system.dim);
        let diagonal = |a: &[f64]| (0..dim * dim).all(|p| p % (dim + 1) == 0 || a[p] == 0.0);
        let per_mass = [&parts.mass, &parts.damping, &parts.stiffness]
            .iter()
            .all(|a| diagonal(a))
            .then(|| {
                (0..dim)
                    .map(|i| {
                        let p = i * dim + i;
                        let m = parts.mass[p];
                        [parts.damping[p] / m, parts.stiffness[p] / m, 1.0 / m]
                    })
                    .collect()
            });
        let forced = !parts.harmonics.is_empty() || parts.constant.iter().any(|f| *f != 0.0);
        let count = compliant.len();
        let len = system.state_len();
        let mut method = Self {
            beta,
            gamma,
            n,
            dim,
            mass: parts.mass,
            damping: parts.damping,
            stiffness: parts.stiffness,
            constant: parts.constant,
            harmonics: parts.harmonics,
            forced,
            per_mass,
            compliant,
            apart: Effective::new(dim, count),
            touching: Effective::new(dim, count),
            contacts: vec![false; count],
            accel: vec![0.0; dim],
            powers: Trapezoid::new(system),
            pending_accel: vec![0.0; dim],
            valid: false,
            powers_valid: false,
            predictor: vec![0.0; 2 * dim],
            residual: vec![0.0; dim],
            rates: vec![0.0; len],
            matrix: vec![0.0; dim * dim],
            evaluations: 0,
            sized: None,
        };
        method.sized = Sized::of(&method, system).map(Box::new);
        Ok(method)
    }

    /// Without the fixed-size path (its steps then through the attempt).
    #[cfg(test)]
    pub(crate) fn general(mut self) -> Self {
        self.sized = None;
        self
    }

    /// What an attempt from `(time, y)` in `modes` needs before its step:
    /// the accelerations after a restart, the accumulators' rates in new
    /// modes. (Inlined: the tests in each attempt, as they were written there.)
    #[inline(always)]
    fn prepare(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        s: &mut Scratch,
    ) {
        if !self.valid {
            self.start(system, time, y, modes, s);
        } else if !self.powers_valid {
            system.rates(time, y, modes, s, &mut self.rates);
            self.powers.restart(system, &self.rates);
            self.powers_valid = true;
        }
    }

    /// The loads at `time` (N) added to `out`.
    fn add_loads(&self, time: f64, out: &mut [f64]) {
        for (o, f) in out.iter_mut().zip(&self.constant) {
            *o += f;
        }
        for load in &self.harmonics {
            let value = load.amplitude * (load.omega * time + load.phase).cos();
            for (o, s) in out.iter_mut().zip(&load.shape) {
                *o += value * s;
            }
        }
    }

    /// Interaction `c`'s indentation (m) and its rate (m/s) at `x`, `v`.
    #[inline(always)]
    fn indentation(system: &Assembly, c: &Compliant, x: &[f64], v: &[f64]) -> (f64, f64) {
        let it = &system.interactions[c.index];
        let h = &it.h[..x.len()];
        (-(it.offset + h_dot(h, x)), -h_dot(h, v))
    }

    /// The accelerations at `(time, y)` in `modes` after a restart (the
    /// right-hand side jumped), and the accumulators' rates there.
    fn start(&mut self, system: &Assembly, time: f64, y: &[f64], modes: &[Mode], s: &mut Scratch) {
        let d = self.dim;
        system.rates(time, y, modes, s, &mut self.rates);
        self.powers.restart(system, &self.rates);
        self.powers_valid = true;
        self.valid = true;
        let Some(per_mass) = &self.per_mass else {
            // Coupled coordinates: the system's own accelerations.
            self.accel.copy_from_slice(&self.rates[d..2 * d]);
            return;
        };
        // As 0.1 wrote them: each term over its own mass.
        let (x, v) = (&y[..d], &y[d..2 * d]);
        for (i, a) in self.accel.iter_mut().enumerate() {
            let [c, k, _] = per_mass[i];
            *a = if i < self.n {
                (-c) * v[i] - k * x[i]
            } else {
                0.0
            };
        }
        if self.forced {
            self.residual.iter_mut().for_each(|r| *r = 0.0);
            let mut loads = std::mem::take(&mut self.residual);
            self.add_loads(time, &mut loads);
            for ((a, f), p) in self.accel.iter_mut().zip(&loads).zip(per_mass) {
                *a += f * p[2];
            }
            self.residual = loads;
        }
        for c in &self.compliant {
            let Mode::Compliant { approach_rate, .. } = modes[c.index] else {
                continue;
            };
            let (indentation, rate) = Self::indentation(system, c, x, v);
            let law = if indentation > 0.0 {
                c.law.force(indentation, rate, approach_rate)
            } else {
                0.0
            };
            let total = law + c.damping * rate;
            let h = &system.interactions[c.index].h;
            for ((a, h), p) in self.accel.iter_mut().zip(h).zip(per_mass) {
                if *h != 0.0 {
                    *a += h * total * p[2];
                }
            }
        }
    }

    /// The step `h` from `(time, y)` into `out` after [`Self::start`], for
    /// `n` structure coordinates of `d` (constants where [`by_size`] makes
    /// them: the loops unrolled, the same operations).
    #[inline(always)]
    fn step_sized(
        &mut self,
        system: &Assembly,
        (n, d): (usize, usize),
        (time, h): (f64, f64),
        y: &[f64],
        modes: &[Mode],
        out: &mut [f64],
    ) {
        let (beta, gamma) = (self.beta, self.gamma);
        // The predictor: the parts of x1, v1 that do not depend on a1.
        let (db, dg) = ((0.5 - beta) * h * h, (1.0 - gamma) * h);
        let (x, v) = (&y[..d], &y[d..2 * d]);
        let (accel, predictor) = (&self.accel[..d], &mut self.predictor[..2 * d]);
        for i in 0..d {
            let a = accel[i];
            predictor[i] = x[i] + h * v[i] + db * a;
            predictor[d + i] = v[i] + dg * a;
        }
        // The right-hand side: the loads at the step's end, the contact
        // laws' forces at its start (the lag), the structure's spring and
        // damper on the predictor, then the contact dampers on it.
        self.residual[..d].iter_mut().for_each(|r| *r = 0.0);
        if self.forced {
            let mut loads = std::mem::take(&mut self.residual);
            self.add_loads(time + h, &mut loads);
            self.residual = loads;
        }
        for c in &self.compliant {
            let Mode::Compliant { approach_rate, .. } = modes[c.index] else {
                continue;
            };
            let (indentation, rate) = Self::indentation(system, c, x, v);
            if indentation > 0.0 {
                let law = c.law.force(indentation, rate, approach_rate);
                let row = &system.interactions[c.index].h[..d];
                for (r, hi) in self.residual[..d].iter_mut().zip(row) {
                    if *hi != 0.0 {
                        *r += hi * law;
                    }
                }
            }
        }
        let (xp, vp) = self.predictor[..2 * d].split_at(d);
        for (i, r) in self.residual[..n].iter_mut().enumerate() {
            let row = i * d..i * d + n;
            for (c, v) in self.damping[row.clone()].iter().zip(&vp[..n]) {
                *r -= c * v;
            }
            for (k, x) in self.stiffness[row].iter().zip(&xp[..n]) {
                *r -= k * x;
            }
        }
        for c in &self.compliant {
            if !matches!(modes[c.index], Mode::Compliant { .. }) {
                continue;
            }
            let (_, rate) = Self::indentation(system, c, xp, vp);
            let force = c.damping * rate;
            let row = &system.interactions[c.index].h[..d];
            for (r, hi) in self.residual[..d].iter_mut().zip(row) {
                if *hi != 0.0 {
                    *r += hi * force;
                }
            }
        }
        let any = self.contacts_of(modes);
        self.effective(system, h, any);
        let inverse = if any {
            &self.touching.inverse
        } else {
            &self.apart.inverse
        };
        let residual = &self.residual[..d];
        let solved = &mut self.pending_accel[..d];
        for (i, a1) in solved.iter_mut().enumerate() {
            // Summed in order from the first product (0.1's `a r + b s`).
            let row = &inverse[i * d..(i + 1) * d];
            let mut sum = row[0] * residual[0];
            for (a, r) in row[1..].iter().zip(&residual[1..]) {
                sum += a * r;
            }
            *a1 = sum;
        }
        let (bb, gg) = (beta * h * h, gamma * h);
        let predictor = &self.predictor[..2 * d];
        for i in 0..d {
            out[i] = predictor[i] + bb * solved[i];
            out[d + i] = predictor[d + i] + gg * solved[i];
        }
        // The accumulators by the trapezoidal rule on their rates.
        let mut powers = std::mem::take(&mut self.powers);
        let (xv, accumulators) = out.split_at_mut(2 * d);
        powers.integrate(h, &y[2 * d..], accumulators, |end| {
            self.end_powers(system, (n, d), time + h, xv, modes, end)
        });
        self.powers = powers;
    }

    /// The accumulators' rates at `(time, xv)` in `modes` (W) into `out`, as
    /// [`Assembly::rates`] gives them but without its accelerations (which
    /// cost as much as the rest of a step): the structure's dampers' power
    /// `v^T C v`, the loads' `f . v` (gravity's is its potential's) and each
    /// compliant contact's `(F - F_elastic) rate`.
    #[inline(always)]
    fn end_powers(
        &self,
        system: &Assembly,
        (n, d): (usize, usize),
        time: f64,
        xv: &[f64],
        modes: &[Mode],
        out: &mut [f64],
    ) {
        let (x, v) = xv.split_at(d);
        out.iter_mut().for_each(|p| *p = 0.0);
        out[VISCOUS] = if self.per_mass.is_some() {
            (0..n).map(|i| self.damping[i * d + i] * v[i] * v[i]).sum()
        } else {
            (0..n)
                .map(|i| v[i] * linalg::dot(&self.damping[i * d..i * d + n], &v[..n]))
                .sum()
        };
        for load in &self.harmonics {
            let value = load.amplitude * (load.omega * time + load.phase).cos();
            out[INPUT] += value * linalg::dot(&load.shape, v);
        }
        for c in &self.compliant {
            let Mode::Compliant { approach_rate, .. } = modes[c.index] else {
                continue;
            };
            let (indentation, rate) = Self::indentation(system, c, &x[..d], &v[..d]);
            let (force, elastic) = if indentation > 0.0 {
                c.law.force_and_elastic(indentation, rate, approach_rate)
            } else {
                (0.0, 0.0)
            };
            out[CONTACT + c.index] = (force + c.damping * rate - elastic) * rate;
        }
    }

    /// Which compliant interactions are in contact in `modes` (into
    /// `self.contacts`); whether any is.
    fn contacts_of(&mut self, modes: &[Mode]) -> bool {
        let mut any = false;
        for (c, touching) in self.compliant.iter().zip(&mut self.contacts) {
            *touching = matches!(modes[c.index], Mode::Compliant { .. });
            any |= *touching;
        }
        any
    }

    /// The inverse effective matrix for a step `h` with `self.contacts`,
    /// made again only where the step or the contacts changed.
    #[inline(always)]
    fn effective(&mut self, system: &Assembly, h: f64, any: bool) {
        let kept = if any { &self.touching } else { &self.apart };
        if kept.step.to_bits() != h.to_bits() || (any && kept.contacts != self.contacts) {
            self.rebuild(system, h, any);
        }
    }

    /// [`Self::effective`]'s inverse made for `h` and `self.contacts`.
    #[inline(never)]
    fn rebuild(&mut self, system: &Assembly, h: f64, any: bool) {
        let d = self.dim;
        // A = M + (gamma h) C + (beta h^2) K, as 0.1 summed it.
        let (g, b) = (self.gamma * h, self.beta * h * h);
        for p in 0..d * d {
            self.matrix[p] = self.mass[p] + g * self.damping[p] + b * self.stiffness[p];
        }
        // Each contact damper's implicit part, (gamma h c1) h^T h.
        for (c, touching) in self.compliant.iter().zip(&self.contacts) {
            if !touching {
                continue;
            }
            let coefficient = g * c.damping;
            let row = &system.interactions[c.index].h;
            for (i, hi) in row.iter().enumerate() {
                for (j, hj) in row.iter().enumerate() {
                    if *hi != 0.0 && *hj != 0.0 {
                        self.matrix[i * d + j] += coefficient * hi * hj;
                    }
                }
            }
        }
        let target = if any {
            &mut self.touching
        } else {
            &mut self.apart
        };
        invert(&mut self.matrix, &mut target.inverse, d);
        target.step = h;
        target.contacts.copy_from_slice(&self.contacts);
    }
}

/// The inverse of the row-major `d x d` matrix `a` into `inverse` (`a` is
/// overwritten): for two coordinates by the adjugate, `[d -b; -c a] / (a d -
/// b c)`, 0.1's arithmetic; otherwise by Gaussian elimination.
fn invert(a: &mut [f64], inverse: &mut [f64], d: usize) {
    match d {
        1 => inverse[0] = 1.0 / a[0],
        2 => {
            let det = a[0] * a[3] - a[1] * a[2];
            inverse.copy_from_slice(&[a[3] / det, -a[1] / det, -a[2] / det, a[0] / det]);
        }
        _ => {
            for (p, value) in inverse.iter_mut().enumerate() {
                *value = if p % (d + 1) == 0 { 1.0 } else { 0.0 };
            }
            linalg::solve_matrix_in_place(a, inverse, d);
        }
    }
}

impl SystemStepper for PaperNewmark {
    fn name(&self) -> &'static str {
        "newmark"
    }

    fn is_adaptive(&self) -> bool {
        false
    }

    fn reset(&mut self) {
        self.valid = false;
    }

    /// The accelerations carry through (0.1's fixed-step kernel); only the
    /// accumulators' rates are taken again, in the new modes.
    fn switched_within_step(&mut self) {
        self.powers_valid = false;
    }

    fn creates_contact_energy(&self) -> bool {
        true
    }

    fn takes_stretches(&self, _system: &Assembly, fixed: bool) -> bool {
        // Stepping by events, in the fixed-size arrays alone.
        fixed || self.sized.is_some()
    }

    fn stretch(
        &mut self,
        system: &Assembly,
        stretch: &mut Stretch<'_>,
        modes: &[Mode],
        scratch: &mut Scratch,
    ) {
        let Some(sized) = self.sized.take() else {
            return plain_fixed_steps(self, system, stretch, modes, scratch);
        };
        // Free flight (every wall open, none in contact) without the walls'
        // terms.
        let free =
            modes.iter().all(|m| *m == Mode::Open) && stretch.open.iter().all(Option::is_none);
        match (stretch.schedule.fixed.is_some(), free) {
            (true, true) => self.sized_stretch::<true>(system, &sized, stretch, modes, scratch),
            (true, false) => self.sized_stretch::<false>(system, &sized, stretch, modes, scratch),
            (false, true) => self.sized_event_stretch::<true>(system, &sized, stretch, modes),
            (false, false) => self.sized_event_stretch::<false>(system, &sized, stretch, modes),
        }
        self.sized = Some(sized);
    }

    fn uncount(&mut self, evaluations: u64) {
        self.evaluations -= evaluations;
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
        self.prepare(system, time, y, modes, scratch);
        by_size!(system, |n, k| self.step_sized(
            system,
            (n, n + k),
            (time, h),
            y,
            modes,
            out
        ));
        self.evaluations += 1;
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

mod sized;
#[cfg(test)]
mod sized_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod two_mass_tests;
