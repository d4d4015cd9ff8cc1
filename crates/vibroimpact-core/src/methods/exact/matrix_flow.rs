//! The exact flow of a linear system whose damping is not classical (modes
//! coupled through damping: a damper stuck to a multi-mode structure, a
//! contact damper, non-proportional matrices), by the matrix exponential.
//!
//! The reduced coordinates `y` (see [`Reduced`]), their rates and the forcing
//! make one linear system `w' = A w` with `w = (y, y', 1, cos(W_k t),
//! sin(W_k t), ...)`: the constant load rides on the constant 1 and each
//! harmonic on its own rotating pair, so `w(t + h) = e^(A h) w(t)` holds for
//! any step, free and forced alike. `e^(A h)` comes from scaling and squaring
//! with a Pade approximant (to a few ulps), kept for the lengths that repeat
//! (a fixed step and its Gauss nodes).

use super::modal::Reduced;
use crate::error::Result;
use crate::model::assembly::LinearParts;
use crate::numerics::linalg;

/// Exponentials kept per configuration.
const SLOTS: usize = 8;

/// The flow of one configuration by the matrix exponential.
#[derive(Debug, Clone)]
pub struct MatrixFlow {
    dim: usize,
    size: usize,
    /// `N`, row-major `dim x size`.
    null: Vec<f64>,
    origin: Vec<f64>,
    omegas: Vec<f64>,
    /// `A`, row-major `order x order`.
    generator: Vec<f64>,
    order: usize,
    cache: Vec<(Option<u64>, Vec<f64>)>,
    next: usize,
    start: Vec<f64>,
    end: Vec<f64>,
    /// The largest rate in the system (1/s): natural frequencies, damping
    /// rates and forcing frequencies.
    pub fastest: f64,
}

impl MatrixFlow {
    /// The flow of `parts` under `constraints`; `what` names it in errors.
    pub fn new(parts: &LinearParts, constraints: &[(&[f64], f64)], what: &str) -> Result<Self> {
        let dim = parts.constant.len();
        let reduced = Reduced::new(parts, constraints);
        let r = reduced.size;
        let l = linalg::cholesky(&reduced.mass, r)
            .ok_or_else(|| super::modal::mass_error(what, &reduced.mass, r))?;
        let minv = linalg::inverse_from_cholesky(&l, r);
        let times = |a: &[f64]| {
            let mut out = vec![0.0; r * r];
            linalg::matmul(&minv, a, &mut out, r);
            out
        };
        let (minv_k, minv_c) = (times(&reduced.stiffness), times(&reduced.damping));
        let apply = |f: &[f64]| -> Vec<f64> {
            let g = reduced.project(f);
            (0..r)
                .map(|i| linalg::dot(&minv[i * r..(i + 1) * r], &g))
                .collect()
        };
        let mut static_load = parts.constant.clone();
        for (i, load) in static_load.iter_mut().enumerate() {
            *load -= linalg::dot(&parts.stiffness[i * dim..(i + 1) * dim], &reduced.origin);
        }
        let mut constant = apply(&static_load);
        // Harmonics by frequency: a cos(W t + p) = a cos p cos W t - a sin p sin W t.
        let mut omegas: Vec<f64> = Vec::new();
        let mut cosines: Vec<Vec<f64>> = Vec::new();
        let mut sines: Vec<Vec<f64>> = Vec::new();
        for load in &parts.harmonics {
            let shape = apply(&load.shape);
            let (sin, cos) = load.phase.sin_cos();
            if load.omega == 0.0 {
                for (c, s) in constant.iter_mut().zip(&shape) {
                    *c += load.amplitude * cos * s;
                }
                continue;
            }
            let k = match omegas.iter().position(|w| *w == load.omega) {
                Some(k) => k,
                None => {
                    omegas.push(load.omega);
                    cosines.push(vec![0.0; r]);
                    sines.push(vec![0.0; r]);
                    omegas.len() - 1
                }
            };
            for i in 0..r {
                cosines[k][i] += load.amplitude * cos * shape[i];
                sines[k][i] -= load.amplitude * sin * shape[i];
            }
        }
        let order = 2 * r + 1 + 2 * omegas.len();
        let mut a = vec![0.0; order * order];
        for i in 0..r {
            a[i * order + r + i] = 1.0;
            for j in 0..r {
                a[(r + i) * order + j] = -minv_k[i * r + j];
                a[(r + i) * order + r + j] = -minv_c[i * r + j];
            }
            a[(r + i) * order + 2 * r] = constant[i];
            for k in 0..omegas.len() {
                a[(r + i) * order + 2 * r + 1 + 2 * k] = cosines[k][i];
                a[(r + i) * order + 2 * r + 2 + 2 * k] = sines[k][i];
            }
        }
        for (k, w) in omegas.iter().enumerate() {
            let (c, s) = (2 * r + 1 + 2 * k, 2 * r + 2 + 2 * k);
            a[c * order + s] = -w;
            a[s * order + c] = *w;
        }
        // The natural frequencies and the damping rates bound how fast the
        // state turns.
        let linv = linalg::inverse_lower(&l, r);
        let similar = |m: &[f64]| {
            let mut out = vec![0.0; r * r];
            for p in 0..r {
                for q in 0..r {
                    let mut sum = 0.0;
                    for i in 0..r {
                        for j in 0..r {
                            sum += linv[p * r + i] * m[i * r + j] * linv[q * r + j];
                        }
                    }
                    out[p * r + q] = sum;
                }
            }
            out
        };
        let largest = |m: &[f64]| {
            linalg::symmetric_eigenvalues(&similar(m), r)
                .last()
                .copied()
                .unwrap_or(0.0)
                .max(0.0)
        };
        let fastest = largest(&reduced.stiffness)
            .sqrt()
            .max(largest(&reduced.damping))
            .max(omegas.iter().fold(0.0, |m, w| m.max(*w)));
        let mut null = vec![0.0; dim * r];
        for (c, column) in reduced.null.iter().enumerate() {
            for i in 0..dim {
                null[i * r + c] = column[i];
            }
        }
        Ok(Self {
            dim,
            size: r,
            null,
            origin: reduced.origin,
            omegas,
            generator: a,
            order,
            cache: vec![(None, Vec::new()); SLOTS],
            next: 0,
            start: vec![0.0; order],
            end: vec![0.0; order],
            fastest,
        })
    }

    /// Set the flow's start at `time` from the state `y` (`x` then `v`).
    pub fn begin(&mut self, time: f64, y: &[f64]) {
        let (dim, r) = (self.dim, self.size);
        for c in 0..r {
            let (mut q, mut rate) = (0.0, 0.0);
            for i in 0..dim {
                q += self.null[i * r + c] * (y[i] - self.origin[i]);
                rate += self.null[i * r + c] * y[dim + i];
            }
            self.start[c] = q;
            self.start[r + c] = rate;
        }
        self.start[2 * r] = 1.0;
        for (k, w) in self.omegas.iter().enumerate() {
            let (s, c) = (w * time).sin_cos();
            self.start[2 * r + 1 + 2 * k] = c;
            self.start[2 * r + 2 + 2 * k] = s;
        }
    }

    /// The coordinates and velocities `t` after the start into `out`, as the
    /// start `y` plus the increments (continuous at the start to the bit).
    pub fn at(&mut self, y: &[f64], t: f64, out: &mut [f64]) {
        let key = Some(t.to_bits());
        let slot = match self.cache.iter().position(|(k, _)| *k == key) {
            Some(slot) => slot,
            None => {
                let slot = self.next;
                self.next = (self.next + 1) % SLOTS;
                let scaled: Vec<f64> = self.generator.iter().map(|a| a * t).collect();
                self.cache[slot] = (key, linalg::expm(&scaled, self.order));
                slot
            }
        };
        let n = self.order;
        let e = &self.cache[slot].1;
        for i in 0..2 * self.size {
            self.end[i] = linalg::dot(&e[i * n..(i + 1) * n], &self.start);
        }
        let (dim, r) = (self.dim, self.size);
        for i in 0..dim {
            let (mut dx, mut dv) = (0.0, 0.0);
            for c in 0..r {
                let n = self.null[i * r + c];
                dx += n * (self.end[c] - self.start[c]);
                dv += n * (self.end[r + c] - self.start[r + c]);
            }
            out[i] = y[i] + dx;
            out[dim + i] = y[dim + i] + dv;
        }
    }
}
