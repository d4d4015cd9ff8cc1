//! The right-hand side: the state's rates (velocities, accelerations and
//! the accumulators' powers) in each interaction's mode. Per-step code: the
//! `#[inline]` attributes and the order of every sum are part of the bits.

use super::gaps::h_dot;
use super::{Assembly, InteractionLaw, Mode, RatesParts, Scratch, CONTACT, INPUT, VISCOUS};
use crate::kernel::sized::by_size;
use crate::model::contact::ContactLaw;
use crate::model::signals::Signal;
use crate::numerics::linalg;

impl Assembly {
    /// The derivative of the state `y` at `time` in `modes` into `out`; the
    /// constraint forces of sticking interactions are solved for on the way
    /// (`scratch` holds them). Allocates nothing.
    pub fn rates(
        &self,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) {
        by_size!(self, |n, k| self
            .rates_in(n, k, time, y, modes, scratch, out))
    }

    /// The second derivative of interaction `i`'s gap at `time` and state `y`
    /// in `modes` (m/s^2, < 0 pressing it shut): `h . a` from [`Self::rates`],
    /// which `work` (the state's length) receives.
    #[inline(always)]
    pub fn gap_acceleration(
        &self,
        i: usize,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        work: &mut [f64],
    ) -> f64 {
        self.rates(time, y, modes, scratch, work);
        self.interactions[i].dot(&work[self.dim..2 * self.dim])
    }

    /// [`Self::rates`] for `n` structure coordinates and `k` dampers: inlined
    /// where they are constants, every slice then has a length known at
    /// compile time (loops unrolled, no bounds checks).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn rates_in(
        &self,
        n: usize,
        k: usize,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) {
        self.rates_with(&self.rates_parts(n, k), time, y, modes, scratch, out)
    }

    /// The parts of the system [`Self::rates_with`] reads, cut to their
    /// sizes: a method that evaluates the rates several times a step (RK4)
    /// makes them once, and the lengths are checked once.
    #[inline(always)]
    pub(crate) fn rates_parts(&self, n: usize, k: usize) -> RatesParts<'_> {
        let (diagonals, first) = match (self.diagonal, self.forces.first()) {
            (true, Some(f)) => (
                Some(&self.diagonals[..n]),
                Some((&f.signal, &f.push[..n], &f.row[..n])),
            ),
            (true, None) => (Some(&self.diagonals[..n]), None),
            (false, _) => (None, None),
        };
        let fused = usize::from(first.is_some());
        RatesParts {
            n,
            k,
            diagonals,
            fused,
            unfused: self.forces.len() > fused,
            base: !self.base.is_empty(),
            first,
            interactions: &self.interactions[..],
            gravity: self.gravity,
        }
    }

    /// [`Self::rates`] from its parts (see [`Self::rates_parts`]).
    #[inline(always)]
    pub(crate) fn rates_with(
        &self,
        parts: &RatesParts<'_>,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) {
        let (n, k) = (parts.n, parts.k);
        let d = n + k;
        let count = parts.interactions.len();
        let (x, v) = (&y[..d], &y[d..2 * d]);
        let (velocity, rest) = out[..2 * d + CONTACT + count].split_at_mut(d);
        let (acc, rest) = rest.split_at_mut(d);
        let (head, losses) = rest.split_at_mut(CONTACT);
        // What few systems have is out of line (its fields are then not
        // loaded, nor kept, by a method's loop over the evaluations).
        let base = if parts.base {
            self.base_value(time, scratch)
        } else {
            0.0
        };
        let inertial = base + parts.gravity;
        // The velocities are copied inside the loops over the coordinates
        // (a lone copy of a handful of values becomes a call to memmove).
        let mut input = 0.0;
        let fused = parts.fused;
        let viscous = if let Some(diagonals) = parts.diagonals {
            // Modal coordinates: the matrices are diagonal. The first force
            // is added in the same pass (each sum in the same order).
            let (x, v) = (&x[..n], &v[..n]);
            let (acc, velocity) = (&mut acc[..n], &mut velocity[..n]);
            let mut viscous = 0.0;
            if let (Some((signal, push, row)), Some(cache)) =
                (parts.first, scratch.force_values.first_mut())
            {
                let value = cache.value(signal, time);
                let mut power = -0.0;
                for i in 0..n {
                    let [k, c, damping, r] = diagonals[i];
                    velocity[i] = v[i];
                    acc[i] = elastic(k, c, r, inertial, x[i], v[i]) + push[i] * value;
                    viscous += damping * v[i] * v[i];
                    power += row[i] * v[i];
                }
                input += value * power;
            } else {
                for i in 0..n {
                    let [k, c, damping, r] = diagonals[i];
                    velocity[i] = v[i];
                    acc[i] = elastic(k, c, r, inertial, x[i], v[i]);
                    viscous += damping * v[i] * v[i];
                }
            }
            viscous
        } else {
            self.coupled_rates(n, x, v, inertial, acc, velocity)
        };
        for ((a, o), v) in acc[n..d].iter_mut().zip(&mut velocity[n..d]).zip(&v[n..d]) {
            *o = *v;
            *a = -inertial;
        }
        if parts.unfused {
            input = self.unfused_forces(n, fused, time, v, input, acc, scratch);
        }
        if base != 0.0 {
            input -= base * self.base_momentum(n, k, v);
        }
        let mut sticking = 0;
        // `h . x`, `h . v` of the last interaction whose products were taken:
        // a damper's second wall has the first's row negated (see `gaps`).
        let mut products: Option<(f64, f64)> = None;
        for (i, (((it, mode), loss), mirror)) in parts
            .interactions
            .iter()
            .zip(&modes[..count])
            .zip(losses.iter_mut())
            .zip(&self.mirrors_previous)
            .enumerate()
        {
            *loss = 0.0;
            // Only the interaction just before may lend its products.
            let previous = products.take();
            match (mode, &it.law) {
                (
                    Mode::Compliant {
                        approach_rate,
                        indented_only,
                    },
                    InteractionLaw::Compliant { law, damping },
                ) => {
                    let (approach_rate, damping) = (*approach_rate, *damping);
                    let (hx, hv) = match previous {
                        Some((hx, hv)) if *mirror => (-hx, -hv),
                        _ => (h_dot(&it.h[..d], x), h_dot(&it.h[..d], v)),
                    };
                    products = Some((hx, hv));
                    let (indentation, rate) = (-(it.offset + hx), -hv);
                    let (force, elastic, damping) = if law.acts(indentation, *indented_only) {
                        let (force, elastic) =
                            law.force_and_elastic(indentation, rate, approach_rate);
                        (force, elastic, damping)
                    } else {
                        (0.0, 0.0, apart_damping(damping, *indented_only))
                    };
                    let total = force + damping * rate;
                    // Apart with no contact damper there is no force to add.
                    if total != 0.0 {
                        for (a, p) in acc.iter_mut().zip(&it.push[..d]) {
                            *a += p * total;
                        }
                    }
                    *loss = (total - elastic) * rate;
                }
                (
                    Mode::Sticking
                    | Mode::Stuck {
                        shadowed: false, ..
                    },
                    _,
                ) => {
                    scratch.sticking[sticking] = i;
                    sticking += 1;
                }
                (Mode::Sliding { direction }, InteractionLaw::Friction { kinetic_force, .. }) => {
                    // The kinetic force against the sliding, and its loss.
                    let hv = h_dot(&it.h[..d], v);
                    let force = -direction * kinetic_force;
                    for (a, p) in acc.iter_mut().zip(&it.push[..d]) {
                        *a += p * force;
                    }
                    *loss = -force * hv;
                }
                _ => {}
            }
        }
        if sticking > 0 {
            self.add_constraint_forces(sticking, acc, scratch);
        }
        scratch.count = sticking;
        head[VISCOUS] = viscous;
        head[INPUT] = input;
    }

    fn signals(&self) -> impl Iterator<Item = &Signal> {
        self.forces.iter().map(|f| &f.signal).chain(&self.base)
    }

    /// Whether any excitation's signal has kinks.
    pub fn has_breakpoints(&self) -> bool {
        self.signals().any(Signal::has_breakpoints)
    }

    /// The finest time over which an excitation that is not a sum of
    /// harmonics changes (s), with its signal's name: a record's or a random
    /// signal's shortest sample interval, a sweep's half period at its
    /// highest frequency ([`Signal::extent`]); None without one. A fixed
    /// step longer than this passes over what the signal does in between.
    pub fn finest_signal_interval(&self) -> Option<(f64, &'static str)> {
        self.finest_signal
    }

    /// The first kink of any excitation's signal after `time` (s; see
    /// [`Signal::next_breakpoint`]), or infinity.
    pub fn next_breakpoint(&self, time: f64) -> f64 {
        self.signals()
            .map(|signal| signal.next_breakpoint(time))
            .fold(f64::INFINITY, f64::min)
    }

    /// The sum of the base signals at `time`.
    #[inline(never)]
    fn base_value(&self, time: f64, scratch: &mut Scratch) -> f64 {
        let mut base = 0.0;
        for (signal, cache) in self.base.iter().zip(&mut scratch.base_values) {
            base += cache.value(signal, time);
        }
        base
    }

    /// The momentum `v . M r` whose rate the base signals' inertial load
    /// `-M r a` works on.
    #[inline(never)]
    fn base_momentum(&self, n: usize, k: usize, v: &[f64]) -> f64 {
        linalg::dot(&self.mass_influence[..n], &v[..n])
            + self.damper_mass[..k]
                .iter()
                .zip(&v[n..n + k])
                .map(|(m, v)| m * v)
                .sum::<f64>()
    }

    /// The structure's accelerations (and velocities) where its matrices
    /// couple the coordinates; returns the viscous power.
    #[inline(never)]
    fn coupled_rates(
        &self,
        n: usize,
        x: &[f64],
        v: &[f64],
        inertial: f64,
        acc: &mut [f64],
        velocity: &mut [f64],
    ) -> f64 {
        for (i, a) in acc[..n].iter_mut().enumerate() {
            let row = i * n..(i + 1) * n;
            velocity[i] = v[i];
            *a = -linalg::dot(&self.minv_k[row.clone()], &x[..n])
                - linalg::dot(&self.minv_c[row], &v[..n])
                - self.influence[i] * inertial;
        }
        linalg::quadratic_form(&self.damping[..n * n], &v[..n])
    }

    /// The forces after the first `fused` onto the accelerations; returns
    /// the input power with their work added to `input`.
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    fn unfused_forces(
        &self,
        n: usize,
        fused: usize,
        time: f64,
        v: &[f64],
        mut input: f64,
        acc: &mut [f64],
        scratch: &mut Scratch,
    ) -> f64 {
        for (f, cache) in self.forces[fused..]
            .iter()
            .zip(&mut scratch.force_values[fused..])
        {
            let value = cache.value(&f.signal, time);
            for (a, p) in acc[..n].iter_mut().zip(&f.push[..n]) {
                *a += p * value;
            }
            input += value * linalg::dot(&f.row[..n], &v[..n]);
        }
        input
    }
}

/// A compliant pair's contact damping (N s/m) where it is apart: none
/// where its forces act only where it is indented (fixed stepping, see
/// [`Mode::Compliant`]), its own where the mode is the contact (events).
/// Every path (general, compact, lanes, Jacobian) gates it here.
#[inline(always)]
pub(crate) fn apart_damping(damping: f64, indented_only: bool) -> f64 {
    if indented_only {
        0.0
    } else {
        damping
    }
}

/// A modal coordinate's acceleration from its spring, its damper and the
/// inertial load (m/s^2): `-(k x + c v) - r a` for `k`, `c` per unit mass,
/// influence `r` and inertial acceleration `a`. Written `(-c) v - k x` (the
/// same value: rounding is symmetric in sign; at most an exact zero's sign
/// differs) and the inertial term left out where `a` is zero, so that a
/// stage's dependency chain through the velocity is one multiply and one
/// subtraction: a small system's fixed steps wait on that chain. Every path
/// (general, compact, lanes) computes it here: the same bits.
#[inline(always)]
pub(crate) fn elastic(k: f64, c: f64, r: f64, inertial: f64, x: f64, v: f64) -> f64 {
    let free = (-c) * v - k * x;
    if inertial == 0.0 {
        free
    } else {
        free - r * inertial
    }
}
