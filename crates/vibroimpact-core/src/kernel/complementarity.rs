//! The linear complementarity problem of the impulses at an event instant
//! (see [`crate::kernel::impacts`]): a small dense solver.

use crate::model::assembly::Assembly;
use crate::numerics::linalg;

/// A small linear complementarity problem `w = W z + q`, `w, z >= 0`, `w . z
/// = 0` with `W` symmetric positive semi-definite: Murty's least-index
/// principal pivoting (finite for a positive definite `W`), projected
/// Gauss-Seidel where a singular `W` (two walls of one zero clearance)
/// defeats it.
#[derive(Debug, Clone)]
pub(super) struct Complementarity {
    pub(super) m: usize,
    pub(super) matrix: Vec<f64>,
    pub(super) q: Vec<f64>,
    pub(super) z: Vec<f64>,
    /// Rows held as equalities (`w = 0`, `z` of either sign).
    pub(super) bilateral: Vec<bool>,
    active: Vec<bool>,
    index: Vec<usize>,
    sub: Vec<f64>,
    rhs: Vec<f64>,
}

impl Complementarity {
    pub(super) fn new(capacity: usize) -> Self {
        Self {
            m: 0,
            matrix: Vec::with_capacity(capacity * capacity),
            q: Vec::with_capacity(capacity),
            z: Vec::with_capacity(capacity),
            bilateral: Vec::with_capacity(capacity),
            active: Vec::with_capacity(capacity),
            index: Vec::with_capacity(capacity),
            sub: Vec::with_capacity(capacity * capacity),
            rhs: Vec::with_capacity(capacity),
        }
    }

    /// `W` of the interactions `members`: `h_a . M^-1 h_b^T`, 1/kg.
    pub(super) fn set_matrix(&mut self, system: &Assembly, members: &[usize]) {
        let m = members.len();
        self.m = m;
        self.matrix.clear();
        for &a in members {
            for &b in members {
                self.matrix
                    .push(system.interactions[a].dot(&system.interactions[b].push));
            }
        }
        self.q.clear();
        self.q.resize(m, 0.0);
        self.z.clear();
        self.z.resize(m, 0.0);
        self.bilateral.clear();
        self.bilateral.resize(m, false);
    }

    /// `(W z)_s`: the change of member `s`'s rate, m/s.
    pub(super) fn w_minus_q(&self, s: usize) -> f64 {
        let m = self.m;
        (0..m).map(|k| self.matrix[s * m + k] * self.z[k]).sum()
    }

    /// Whether `z` (the impulses, N s) solves the problem to `tolerance`
    /// (m/s); else the least index that violates it.
    fn violation(&self, tolerance: f64) -> Option<usize> {
        (0..self.m).find(|&s| {
            let w = self.w_minus_q(s) + self.q[s];
            if self.bilateral[s] {
                false
            } else if self.active[s] {
                self.z[s] * self.matrix[s * self.m + s] < -tolerance
            } else {
                w < -tolerance
            }
        })
    }

    pub(super) fn solve(&mut self) {
        let m = self.m;
        let scale = self.q.iter().fold(0.0f64, |a, q| a.max(q.abs()));
        self.z.iter_mut().for_each(|z| *z = 0.0);
        if scale == 0.0 {
            return;
        }
        if m == 1 {
            // One pair: Newton's impulse (the pivoting's answer, directly).
            let z = -self.q[0] / self.matrix[0];
            self.z[0] = if self.bilateral[0] { z } else { z.max(0.0) };
            return;
        }
        let tolerance = 1e-13 * scale;
        self.active.clear();
        self.active.extend_from_slice(&self.bilateral);
        // With equalities, their solve comes first.
        let mut solve_first = self.bilateral.contains(&true);
        for _ in 0..(20 * m + 20) {
            if !std::mem::take(&mut solve_first) {
                let Some(s) = self.violation(tolerance) else {
                    for (z, &b) in self.z.iter_mut().zip(&self.bilateral) {
                        if !b {
                            *z = z.max(0.0);
                        }
                    }
                    return;
                };
                self.active[s] = !self.active[s];
            }
            // z_A = -W_AA^-1 q_A, zero elsewhere.
            self.index.clear();
            self.index.extend((0..m).filter(|&s| self.active[s]));
            let n = self.index.len();
            self.sub.clear();
            self.rhs.clear();
            for &a in &self.index {
                for &b in &self.index {
                    self.sub.push(self.matrix[a * m + b]);
                }
                self.rhs.push(-self.q[a]);
            }
            linalg::solve_in_place(&mut self.sub, &mut self.rhs, n);
            self.z.iter_mut().for_each(|z| *z = 0.0);
            for (k, &a) in self.index.iter().enumerate() {
                self.z[a] = self.rhs[k];
            }
        }
        // Projected Gauss-Seidel from the last pivot's answer.
        for (z, &b) in self.z.iter_mut().zip(&self.bilateral) {
            if !b {
                *z = z.max(0.0);
            }
        }
        for _ in 0..10_000 {
            let mut change = 0.0f64;
            for s in 0..m {
                let diagonal = self.matrix[s * m + s];
                if diagonal <= 0.0 {
                    continue;
                }
                let w = self.w_minus_q(s) + self.q[s];
                let z = self.z[s] - w / diagonal;
                let z = if self.bilateral[s] { z } else { z.max(0.0) };
                change = change.max(((z - self.z[s]) * diagonal).abs());
                self.z[s] = z;
            }
            if change <= tolerance {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn problem(matrix: &[f64], q: &[f64]) -> Complementarity {
        let m = q.len();
        let mut lcp = Complementarity::new(m);
        lcp.m = m;
        lcp.matrix.extend_from_slice(matrix);
        lcp.q.extend_from_slice(q);
        lcp.z.resize(m, 0.0);
        lcp.bilateral.resize(m, false);
        lcp
    }

    /// Every sign pattern's candidate, the one that is feasible: the
    /// solution by enumeration, for a positive definite `W`.
    fn by_enumeration(matrix: &[f64], q: &[f64]) -> Vec<f64> {
        let m = q.len();
        for pattern in 0..1u32 << m {
            let index: Vec<usize> = (0..m).filter(|&s| pattern >> s & 1 == 1).collect();
            let n = index.len();
            let mut sub: Vec<f64> = index
                .iter()
                .flat_map(|&a| index.iter().map(move |&b| matrix[a * m + b]))
                .collect();
            let mut rhs: Vec<f64> = index.iter().map(|&a| -q[a]).collect();
            linalg::solve_in_place(&mut sub, &mut rhs, n);
            let mut z = vec![0.0; m];
            for (k, &a) in index.iter().enumerate() {
                z[a] = rhs[k];
            }
            let feasible = (0..m).all(|s| {
                let w: f64 = q[s] + (0..m).map(|k| matrix[s * m + k] * z[k]).sum::<f64>();
                z[s] >= -1e-12 && w >= -1e-12
            });
            if feasible {
                return z;
            }
        }
        panic!("no solution");
    }

    #[test]
    fn principal_pivoting_matches_enumeration_on_random_problems() {
        crate::testing::timeout(60, || {
            let mut seed = 7u64;
            let mut next = || {
                seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1);
                (seed >> 11) as f64 / (1u64 << 53) as f64 - 0.5
            };
            for m in 1..=6 {
                for _ in 0..200 {
                    // W = A A^T + a little: positive definite, coupled.
                    let a: Vec<f64> = (0..m * m).map(|_| next()).collect();
                    let mut w = vec![0.0; m * m];
                    for r in 0..m {
                        for c in 0..m {
                            w[r * m + c] = (0..m).map(|k| a[r * m + k] * a[c * m + k]).sum::<f64>()
                                + if r == c { 0.05 } else { 0.0 };
                        }
                    }
                    let q: Vec<f64> = (0..m).map(|_| next()).collect();
                    let mut lcp = problem(&w, &q);
                    lcp.solve();
                    let expected = by_enumeration(&w, &q);
                    for (z, e) in lcp.z.iter().zip(&expected) {
                        assert!((z - e).abs() <= 1e-9 * (1.0 + e.abs()), "{z} vs {e}");
                    }
                }
            }
        });
    }

    #[test]
    fn a_singular_matrix_still_gets_a_complementary_answer() {
        crate::testing::timeout(60, || {
            // Two walls of one zero clearance: rows h and -h.
            let w = [2.0, -2.0, -2.0, 2.0];
            for q in [[-1.0, 1.0], [0.3, -0.3], [0.5, 0.5]] {
                let mut lcp = problem(&w, &q);
                lcp.solve();
                for s in 0..2 {
                    let ws = q[s] + lcp.w_minus_q(s);
                    assert!(lcp.z[s] >= 0.0 && ws >= -1e-12, "{q:?}: {:?}", lcp.z);
                    assert!((lcp.z[s] * ws).abs() <= 1e-12, "{q:?}: {:?}", lcp.z);
                }
            }
        });
    }
}
