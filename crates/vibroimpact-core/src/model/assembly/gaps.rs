//! The gaps of the interactions and their rates, and what the kernel asks
//! of one wall: when it lands, whether its mirror holds it, its scale, its
//! release from sticking.

use super::{Assembly, Interaction, InteractionLaw, Mode, SPARSE_FROM};
use crate::kernel::sized::by_size;
use crate::numerics::linalg;

impl Assembly {
    /// The interactions (each wall of each pair), in the order of the modes.
    pub fn interactions(&self) -> &[Interaction] {
        &self.interactions
    }

    /// The gap of interaction `i` and its rate at state `y`.
    #[inline(always)]
    pub fn gap(&self, i: usize, y: &[f64]) -> (f64, f64) {
        let it = &self.interactions[i];
        let d = self.dim;
        let (hx, hv) = it.dots(&y[..d], &y[d..2 * d]);
        (it.offset + hx, hv)
    }

    /// Every interaction's gap and its rate at state `y` into `out`, as
    /// [`Self::gap`] gives them (a damper's two walls share their products).
    pub fn gaps(&self, y: &[f64], out: &mut [(f64, f64)]) {
        by_size!(self, |n, k| self.gaps_in(n + k, y, out))
    }

    /// [`Self::gaps`] over `d` coordinates (a constant where inlined).
    #[inline(always)]
    pub(crate) fn gaps_in(&self, d: usize, y: &[f64], out: &mut [(f64, f64)]) {
        let (x, v) = (&y[..d], &y[d..2 * d]);
        let mut products = (0.0, 0.0);
        for ((it, mirror), out) in self
            .interactions
            .iter()
            .zip(&self.mirrors_previous)
            .zip(out.iter_mut())
        {
            products = if *mirror {
                (-products.0, -products.1)
            } else if d >= SPARSE_FROM {
                // (A branch the small sizes' constants fold away.)
                it.dots(x, v)
            } else {
                dots(&it.h[..d], x, v)
            };
            *out = (it.offset + products.0, products.1);
        }
    }

    /// When open interaction `i` at state `y`, its coordinates' accelerations
    /// `acc` (m/s^2), would reach its wall on its gap's parabola (s after
    /// now); None where the gap's acceleration does not close it.
    pub fn landing_time(&self, i: usize, y: &[f64], acc: &[f64]) -> Option<f64> {
        let (gap, rate) = self.gap(i, y);
        let closing = -self.interactions[i].dot(&acc[..self.dim]);
        (closing > 0.0)
            .then(|| (rate + (rate * rate + 2.0 * closing * gap.max(0.0)).sqrt()) / closing)
    }

    /// Whether interaction `i` is a wall whose other wall (of the same
    /// damper) is sticking: its gap is then held too, at the sum of the
    /// clearances (0 for a zero clearance, to round-off), and it has no
    /// event of its own. Sticking it as well would make the constraints
    /// dependent.
    pub fn held_by_mirror(&self, i: usize, modes: &[Mode]) -> bool {
        let before = self.mirrors_previous[i] && modes[i - 1] == Mode::Sticking;
        let after =
            self.mirrors_previous.get(i + 1) == Some(&true) && modes[i + 1] == Mode::Sticking;
        before || after
    }

    /// Whether interaction `i` is a wall of a damper with no clearance at
    /// all (its two walls' offsets sum to zero): stuck, the damper is locked
    /// to its point, its constraint force of either sign (the force passes
    /// from one wall to the other without a release, which round-off would
    /// otherwise turn into a release and a re-sticking, without end).
    pub fn locked(&self, i: usize) -> bool {
        let mirror = if self.mirrors_previous[i] {
            Some(i - 1)
        } else if self.mirrors_previous.get(i + 1) == Some(&true) {
            Some(i + 1)
        } else {
            None
        };
        mirror.is_some_and(|j| {
            let (a, b) = (self.interactions[i].offset, self.interactions[j].offset);
            (a + b).abs() <= 4.0 * f64::EPSILON * (a.abs() + b.abs())
        })
    }

    /// The most friction element `i` holds while stuck, N (0 for a wall).
    #[inline]
    pub fn static_force(&self, i: usize) -> f64 {
        match self.interactions[i].law {
            InteractionLaw::Friction { static_force, .. } => static_force,
            _ => 0.0,
        }
    }

    /// The round-off of interaction `i`'s rate at state `y`, m/s: a sliding
    /// speed this small is zero.
    pub fn rate_round_off(&self, i: usize, y: &[f64]) -> f64 {
        let d = self.dim;
        8.0 * f64::EPSILON * self.interactions[i].magnitudes(&y[d..2 * d])
    }

    /// The scale of interaction `i`'s gap at state `y`, m: its offset and
    /// the magnitudes of the terms `h . x` sums, whose round-off the gap
    /// carries; for a rigid pair, at least the system's floor
    /// (`gap_floor`).
    #[inline(always)]
    pub fn gap_scale(&self, i: usize, y: &[f64]) -> f64 {
        let it = &self.interactions[i];
        let scale = it.offset.abs() + it.magnitudes(&y[..self.dim]);
        if matches!(it.law, InteractionLaw::Rigid { .. }) {
            scale.max(self.gap_floor)
        } else {
            scale
        }
    }

    /// The gap (m) a pair `i` released at state `y` is put at: a few units of
    /// its round-off open ([`Self::release`]).
    pub fn released_gap(&self, i: usize, y: &[f64]) -> f64 {
        16.0 * f64::EPSILON * self.gap_scale(i, y)
    }

    /// A sticking pair `i` released: held on its wall only to round-off, it
    /// is put at rest relative to the wall (no approach left) with its gap
    /// a few units of that round-off open, along `M^-1 h^T` (the momentum
    /// and energy that moves are round-off too). Without it a gap a hair
    /// below zero, slowly opening, reads as a new contact at every step
    /// until the pair has moved away by more than the round-off.
    pub fn release(&self, i: usize, y: &mut [f64]) {
        let it = &self.interactions[i];
        let d = self.dim;
        let (gap, rate) = self.gap(i, y);
        let opening = (self.released_gap(i, y) - gap) / it.inverse_mass;
        let lift = -rate.min(0.0) / it.inverse_mass;
        for (k, p) in it.push.iter().enumerate() {
            y[k] += p * opening;
            y[d + k] += p * lift;
        }
    }
}

impl Interaction {
    /// `(h . x, h . v)`, each summed in order as [`linalg::dot`] sums it:
    /// over the support where the row has one (the zeros' terms left out
    /// change a sum only where it is zero, in its sign).
    #[inline(always)]
    pub fn dots(&self, x: &[f64], v: &[f64]) -> (f64, f64) {
        if self.support.is_empty() {
            return dots(&self.h, x, v);
        }
        let (mut hx, mut hv) = (-0.0, -0.0);
        for &c in &self.support {
            hx += self.h[c] * x[c];
            hv += self.h[c] * v[c];
        }
        (hx, hv)
    }

    /// `h . x` as [`linalg::dot`] sums it, over the support where the row
    /// has one.
    #[inline(always)]
    pub fn dot(&self, x: &[f64]) -> f64 {
        if self.support.is_empty() {
            return linalg::dot(&self.h, x);
        }
        self.support
            .iter()
            .fold(-0.0, |sum, &c| sum + self.h[c] * x[c])
    }

    /// `sum |h_k x_k|`: the magnitudes a product `h . x` sums (its
    /// round-off's scale), over the support where the row has one.
    #[inline(always)]
    pub fn magnitudes(&self, x: &[f64]) -> f64 {
        if self.support.is_empty() {
            return self.h.iter().zip(x).map(|(h, x)| (h * x).abs()).sum();
        }
        self.support
            .iter()
            .fold(-0.0, |sum, &c| sum + (self.h[c] * x[c]).abs())
    }

    /// `M^-1 h^T p`'s velocities added to `v` (an impulse `p`, N s).
    #[inline(always)]
    pub fn add_push(&self, p: f64, v: &mut [f64]) {
        if self.support.is_empty() {
            for (v, push) in v.iter_mut().zip(&self.push) {
                *v += push * p;
            }
        } else {
            for &c in &self.support {
                v[c] += self.push[c] * p;
            }
        }
    }
}

/// `(h . x, h . v)` in one pass, each summed in order as [`linalg::dot`]
/// sums it (the same bits): a wall's gap and rate as the events see them.
#[inline(always)]
fn dots(h: &[f64], x: &[f64], v: &[f64]) -> (f64, f64) {
    let n = h.len();
    let (x, v) = (&x[..n], &v[..n]);
    let (mut hx, mut hv) = (-0.0, -0.0);
    for i in 0..n {
        hx += h[i] * x[i];
        hv += h[i] * v[i];
    }
    (hx, hv)
}

/// A wall's `h` times a vector where the product leads to a force: a
/// compliant wall's indentation and rate, and a sticking wall's `h . a` for
/// its constraint. The even and the odd terms are summed apart, then
/// together: two chains of half the length on a step's critical path (a
/// stage's contact force waits on it). The gaps that the events watch are
/// summed in order ([`dots`]); the two differ in the last bits at most, and
/// every path sums each quantity the same way (the same bits).
/// Whether the rows `a` and `b` hold the same relative coordinate (either
/// sign, to 1e-12): a wall and a friction element on one damper's axis.
pub(crate) fn same_row(a: &[f64], b: &[f64]) -> bool {
    let along = linalg::dot(a, b);
    along * along >= (1.0 - 1e-12) * linalg::dot(a, a) * linalg::dot(b, b)
}

#[inline(always)]
pub(crate) fn h_dot(h: &[f64], x: &[f64]) -> f64 {
    let n = h.len();
    let x = &x[..n];
    let mut sum = [-0.0; 2];
    for i in 0..n {
        sum[i % 2] += h[i] * x[i];
    }
    sum[0] + sum[1]
}

#[cfg(test)]
mod tests {
    use crate::model::assembly::{Assembly, Damper, PairLaw, SystemSpec};
    use crate::model::structure::Structure;
    use crate::numerics::linalg;

    /// `count` loose masses in a row on an oscillator, neighbours colliding.
    fn row_of(count: usize) -> Assembly {
        let structure = Structure::oscillator(1.0, 8883.0, 9.42).unwrap();
        let masses: Vec<f64> = (0..count).map(|j| 0.01 * (1.0 + j as f64)).collect();
        let law = PairLaw::rigid(0.9).unwrap();
        Assembly::new(&SystemSpec::column(
            structure,
            0.0,
            &masses,
            [2e-3, 2e-3, 3e-2],
            law,
        ))
        .unwrap()
    }

    /// Five loose masses on a two-coordinate structure whose mass matrix
    /// couples its coordinates: a wall's push (`M^-1 h^T`) moves a structure
    /// coordinate its row does not touch.
    fn coupled_carrier() -> Assembly {
        let structure = Structure::matrices(
            &[vec![2.0, 0.5], vec![0.5, 1.0]],
            &[vec![900.0, -300.0], vec![-300.0, 600.0]],
            &[vec![0.0, 0.0], vec![0.0, 0.0]],
        )
        .unwrap();
        let dampers = (0..5)
            .map(|j| Damper {
                mass: 0.02,
                at: 0.0,
                lower_clearance: 1e-3 * (1.0 + j as f64),
                upper_clearance: 2e-3,
                law: PairLaw::rigid(0.5).unwrap(),
            })
            .collect();
        Assembly::new(&SystemSpec::of(structure, dampers)).unwrap()
    }

    /// A large system's rows keep the coordinates where `h` or `push` is not
    /// zero, and its products over them are the dense products: a support
    /// missing a coordinate (or a mirror's products shared wrongly) moves a
    /// gap, a rate, a landing or an impulse.
    #[test]
    fn products_over_the_support_are_the_dense_products() {
        crate::testing::timeout(10, || {
            // The coupled carrier: each wall's row touches coordinate 0 and
            // its mass, its push coordinate 1 as well (a support of the row
            // alone would leave the impulse's share there out).
            let system = coupled_carrier();
            let d = system.dim;
            let y: Vec<f64> = (0..2 * d).map(|k| 1e-3 * (k as f64 + 1.0)).collect();
            for it in &system.interactions {
                assert_eq!((it.h[1], it.support.len()), (0.0, 3));
                assert_ne!(it.push[1], 0.0);
                let mut pushed = y[d..].to_vec();
                it.add_push(0.3, &mut pushed);
                for (k, (after, before)) in pushed.iter().zip(&y[d..]).enumerate() {
                    assert_eq!(*after, before + it.push[k] * 0.3, "{k}");
                }
            }
            let system = row_of(10);
            let d = system.dim;
            assert_eq!(d, 11);
            let y: Vec<f64> = (0..2 * d)
                .map(|k| ((k as f64) * 0.7).sin() * 1e-2 + 1e-3)
                .collect();
            let mut gaps = vec![(0.0, 0.0); system.interactions.len()];
            system.gaps(&y, &mut gaps);
            for (i, it) in system.interactions.iter().enumerate() {
                // The floor and ceiling touch the structure and one mass, a
                // collision two masses.
                assert_eq!(it.support.len(), 2, "{i}");
                let dense = (
                    it.offset + linalg::dot(&it.h, &y[..d]),
                    linalg::dot(&it.h, &y[d..]),
                );
                assert_eq!(system.gap(i, &y), dense, "{i}");
                assert_eq!(gaps[i], dense, "{i}");
                let magnitudes: f64 = it.h.iter().zip(&y[..d]).map(|(h, x)| (h * x).abs()).sum();
                assert_eq!(it.magnitudes(&y[..d]), magnitudes);
                let mut pushed = y[d..].to_vec();
                it.add_push(0.3, &mut pushed);
                for (k, (after, before)) in pushed.iter().zip(&y[d..]).enumerate() {
                    assert_eq!(*after, before + it.push[k] * 0.3, "{i} {k}");
                }
            }
            // A small system keeps every entry (the fixed-size paths' sums).
            assert!(row_of(2)
                .interactions
                .iter()
                .all(|it| it.support.is_empty()));
        });
    }
}
