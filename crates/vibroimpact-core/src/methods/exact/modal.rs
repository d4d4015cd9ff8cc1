#![allow(clippy::needless_range_loop)]
//! A linear system under equality constraints, in its own normal modes: what
//! the exact flow needs for each set of sticking pairs.
//!
//! With the constraints `h_i . x + offset_i = 0` the coordinates are
//! `x = x_p + N y` (`N`: an orthonormal basis of the constraints' null
//! space, `x_p`: the least-norm point on them), and the reduced system
//! `N^T M N y'' + N^T C N y' + N^T K N y = N^T (f - K x_p)` is decoupled by
//! its mass-normalised modes `Phi`, when its damping is classical (`Phi^T C
//! Phi` diagonal): `x = x_p + B eta`, `eta = T (x - x_p)` with `B = N Phi`
//! and `T = Phi^T N^T M N N^T`, each modal coordinate an oscillator
//! `eta'' + c eta' + w2 eta = F0 + sum_k Re(P_k e^(i omega_k t))`.

use crate::error::{Error, Result};
use crate::model::assembly::{HarmonicLoad, LinearParts, SPARSE_FROM};
use crate::numerics::linalg;

/// One harmonic of the forcing, with each mode's steady (particular)
/// response `Re(Z e^(i omega t))` as `(Re Z, Im Z)`.
#[derive(Debug, Clone, PartialEq)]
pub struct ModalHarmonic {
    /// rad/s (> 0).
    pub omega: f64,
    pub response: Vec<(f64, f64)>,
    /// Each mode's force `Re(P e^(i omega t))` as `(Re P, Im P)`.
    pub force: Vec<(f64, f64)>,
    /// The modes it forces (a response or a force not zero), in order: the
    /// others' terms are zeros (a free mass's mode where the force acts on
    /// the structure).
    pub forced: Vec<usize>,
}

impl ModalHarmonic {
    fn find_forced(&mut self) {
        self.forced = (0..self.response.len())
            .filter(|&j| self.response[j] != (0.0, 0.0) || self.force[j] != (0.0, 0.0))
            .collect();
    }
}

/// A linear system in the normal modes of one set of constraints.
#[derive(Debug, Clone, PartialEq)]
pub struct Configuration {
    /// Modal coordinates (degrees of freedom left by the constraints).
    pub modes: usize,
    /// The least-norm point on the constraints, over all coordinates.
    pub origin: Vec<f64>,
    /// `B` (`dim x modes`, row-major): coordinates from modal coordinates.
    pub to_coordinates: Vec<f64>,
    /// `T` (`modes x dim`): modal coordinates from coordinates.
    pub to_modal: Vec<f64>,
    /// `B`'s and `T`'s non-zero entries by rows: the products the flow
    /// takes at every evaluation (free masses' modes are one coordinate
    /// each, and most of `B` zeros).
    pub coordinate_rows: linalg::SparseRows,
    pub modal_rows: linalg::SparseRows,
    /// Each mode's `w2` (1/s^2, >= 0) and `c` (1/s, >= 0).
    pub stiffness: Vec<f64>,
    pub damping: Vec<f64>,
    /// Each mode's constant force per unit modal mass, `F0`.
    pub constant: Vec<f64>,
    /// The part of `constant` excitations drive (0 Hz harmonics): its work
    /// is input, where gravity's and the stops' preloads are potential.
    pub driven: Vec<f64>,
    pub harmonics: Vec<ModalHarmonic>,
}

impl Configuration {
    /// No modes (a configuration integrated otherwise).
    pub fn empty() -> Self {
        Self {
            modes: 0,
            origin: Vec::new(),
            to_coordinates: Vec::new(),
            to_modal: Vec::new(),
            coordinate_rows: linalg::SparseRows::default(),
            modal_rows: linalg::SparseRows::default(),
            stiffness: Vec::new(),
            damping: Vec::new(),
            constant: Vec::new(),
            driven: Vec::new(),
            harmonics: Vec::new(),
        }
    }

    /// The modes of `parts` under `constraints` (`(h, offset)` pairs over all
    /// coordinates). `what` names the configuration in errors.
    pub fn new(parts: &LinearParts, constraints: &[(&[f64], f64)], what: &str) -> Result<Self> {
        Self::classical(parts, constraints, what)?.ok_or_else(|| {
            Error::Inconsistent(format!(
                "method \"exact\" needs classical damping (C diagonal in the normal modes), \
                 and {what} couples modes through damping; use \"dop853\""
            ))
        })
    }

    /// [`Configuration::new`], or None when the damping is not classical.
    pub fn classical(
        parts: &LinearParts,
        constraints: &[(&[f64], f64)],
        what: &str,
    ) -> Result<Option<Self>> {
        let dim = parts.constant.len();
        let reduced = Reduced::new(parts, constraints);
        let (r, null, origin) = (reduced.size, &reduced.null, &reduced.origin);
        let Some(NormalModes {
            values,
            phi,
            damping: cm,
        }) = normal_modes(&reduced, what)?
        else {
            return Ok(None);
        };
        let (to_coordinates, to_modal) = transforms(null, &phi, &reduced.mass, dim, r);
        // Modal loads: B^T f.
        let project = |f: &[f64]| -> Vec<f64> {
            (0..r)
                .map(|c| (0..dim).map(|i| to_coordinates[i * r + c] * f[i]).sum())
                .collect()
        };
        let mut static_load = parts.constant.clone();
        for i in 0..dim {
            static_load[i] -= linalg::dot(&parts.stiffness[i * dim..(i + 1) * dim], origin);
        }
        let mut constant = project(&static_load);
        // A rigid-body mode's damping at the round-off of the others' (a chain
        // of loose masses held by damped contacts, moving as one) is none: its
        // constant force's particular response `F t / c` would be huge, and
        // the start's correction cancelling it would lose every digit (the
        // exact flow had drifted 1e-2 of the input work off the ledger).
        let largest = cm
            .iter()
            .step_by(r + 1)
            .fold(reduced.damping_scale, |m, c| m.max(c.abs()));
        let damping: Vec<f64> = (0..r)
            .map(|i| {
                let c = cm[i * r + i].max(0.0);
                if values[i] == 0.0 && c <= 1e-9 * largest {
                    0.0
                } else {
                    c
                }
            })
            .collect();
        let mut harmonics: Vec<ModalHarmonic> = Vec::new();
        let mut driven = vec![0.0; r];
        for load in &parts.harmonics {
            let shape = project(&load.shape);
            if load.omega == 0.0 {
                for ((c, d), s) in constant.iter_mut().zip(&mut driven).zip(&shape) {
                    let force = load.amplitude * load.phase.cos() * s;
                    *c += force;
                    *d += force;
                }
                continue;
            }
            let harmonic = steady_response(load, &shape, &values, &damping, what)?;
            // Harmonics of one frequency add.
            match harmonics.iter_mut().find(|h| h.omega == load.omega) {
                Some(h) => {
                    for (a, b) in h.response.iter_mut().zip(&harmonic.response) {
                        a.0 += b.0;
                        a.1 += b.1;
                    }
                    for (a, b) in h.force.iter_mut().zip(&harmonic.force) {
                        a.0 += b.0;
                        a.1 += b.1;
                    }
                }
                None => harmonics.push(harmonic),
            }
        }
        harmonics.iter_mut().for_each(ModalHarmonic::find_forced);
        Ok(Some(Self {
            modes: r,
            origin: origin.clone(),
            coordinate_rows: sparse_rows(&to_coordinates, dim, r),
            modal_rows: sparse_rows(&to_modal, r, dim),
            to_coordinates,
            to_modal,
            stiffness: values,
            damping,
            constant,
            driven,
            harmonics,
        }))
    }
}

/// The error of a mass matrix `mass` (`r x r`) whose Cholesky factor
/// failed: where its diagonal spans more than the factor's resolution (a
/// damper of 1e-14 kg on a 1 kg structure), that, and what to do; else not
/// positive definite.
pub(super) fn mass_error(what: &str, mass: &[f64], r: usize) -> Error {
    let diagonal = (0..r).map(|i| mass[i * r + i]);
    let (least, most) = diagonal.fold((f64::INFINITY, 0.0_f64), |(lo, hi), m| {
        (lo.min(m), hi.max(m))
    });
    if least > 0.0 && least <= 1e-14 * most {
        return Error::Inconsistent(format!(
            "{what}: its masses span {least:.3e} kg to {most:.3e} kg, a ratio below the \
             exact flow's resolution (1e-14): make the smallest larger or the largest \
             smaller, or use another method (\"dop853\")"
        ));
    }
    Error::Inconsistent(format!("{what}: the mass matrix is not positive definite"))
}

/// A reduced system's mass-normalised modes.
struct NormalModes {
    /// Each mode's `w2` (1/s^2; rigid-body modes' round-off set to zero).
    values: Vec<f64>,
    /// `Phi`, row-major `size x size`.
    phi: Vec<f64>,
    /// `Phi^T C Phi`.
    damping: Vec<f64>,
}

/// The reduced system's mass-normalised modes; None when `Phi^T C Phi` is
/// not diagonal (the damping is not classical). `what` names the
/// configuration in errors.
fn normal_modes(reduced: &Reduced, what: &str) -> Result<Option<NormalModes>> {
    let r = reduced.size;
    let (mr, kr, cr) = (&reduced.mass, &reduced.stiffness, &reduced.damping);
    let l = linalg::cholesky(mr, r).ok_or_else(|| mass_error(what, mr, r))?;
    let linv = linalg::inverse_lower(&l, r);
    // A = L^-1 K L^-T; Phi = L^-T V.
    // As two products (`r^3` each, where the sum over both indices at
    // once took `r^4`: minutes for a thousand dampers).
    let similar = |a: &[f64]| {
        let left = product(&linv, a, r);
        let mut out = vec![0.0; r * r];
        for p in 0..r {
            for q in 0..r {
                out[p * r + q] = linalg::dot(&left[p * r..(p + 1) * r], &linv[q * r..(q + 1) * r]);
            }
        }
        out
    };
    let a = similar(kr);
    let (mut values, vectors) = linalg::symmetric_eigen(&a, r);
    // Columns of Phi = L^-T V.
    let mut phi = vec![0.0; r * r];
    for i in 0..r {
        for c in 0..r {
            phi[i * r + c] = (0..r).map(|k| linv[k * r + i] * vectors[k * r + c]).sum();
        }
    }
    let scale = values.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    align_repeated(&values, &mut phi, cr, r, scale);
    let cm = modal_damping(cr, &phi, r);
    let largest = (0..r).fold(reduced.damping_scale, |m, i| m.max(cm[i * r + i].abs()));
    for p in 0..r {
        for q in p + 1..r {
            if cm[p * r + q].abs() > 1e-9 * largest {
                return Ok(None);
            }
        }
    }
    // Rigid-body modes: round-off of zero, against the unconstrained
    // system's scale too (at least its modes' largest value, by Rayleigh's
    // quotient, so it changes only systems whose constraints took the stiff
    // directions: there a rigid mode's 1e-29 had been taken for a stiffness,
    // its constant load's static response `F / w2` for 1e27 m).
    let rigid = scale.max(reduced.stiffness_scale);
    for v in values.iter_mut() {
        if v.abs() <= 1e-12 * rigid {
            *v = 0.0;
        }
    }
    Ok(Some(NormalModes {
        values,
        phi,
        damping: cm,
    }))
}

/// `Phi^T C Phi` of the `r x r` damping `cr`, as two products (`r^3` each).
fn modal_damping(cr: &[f64], phi: &[f64], r: usize) -> Vec<f64> {
    let damped = product(cr, phi, r);
    let mut out = vec![0.0; r * r];
    for i in 0..r {
        for p in 0..r {
            let factor = phi[i * r + p];
            for q in 0..r {
                out[p * r + q] += factor * damped[i * r + q];
            }
        }
    }
    out
}

/// Within a repeated eigenvalue (free masses, symmetric structures) the
/// modes are any basis of the eigenspace: the columns of `phi` there are
/// turned to the one that diagonalises the damping `cr` there too (`scale`:
/// the largest eigenvalue's magnitude).
fn align_repeated(values: &[f64], phi: &mut [f64], cr: &[f64], r: usize, scale: f64) {
    let same = |a: f64, b: f64| (a - b).abs() <= 1e-9 * scale;
    let mut start = 0;
    while start < r {
        let mut end = start + 1;
        while end < r && same(values[start], values[end]) {
            end += 1;
        }
        if end - start > 1 {
            let cm = modal_damping(cr, phi, r);
            let g = end - start;
            let block: Vec<f64> = (0..g * g)
                .map(|p| cm[(start + p / g) * r + start + p % g])
                .collect();
            let (_, rotation) = linalg::symmetric_eigen(&block, g);
            for i in 0..r {
                let old: Vec<f64> = (0..g).map(|c| phi[i * r + start + c]).collect();
                for c in 0..g {
                    phi[i * r + start + c] = (0..g).map(|k| old[k] * rotation[k * g + c]).sum();
                }
            }
        }
        start = end;
    }
}

/// A transform's rows by their non-zero entries where the flow takes its
/// products so (a system of [`SPARSE_FROM`] coordinates or more); none for a
/// smaller one, whose products take every entry.
fn sparse_rows(dense: &[f64], rows: usize, columns: usize) -> linalg::SparseRows {
    if rows.max(columns) < SPARSE_FROM {
        return linalg::SparseRows::default();
    }
    linalg::SparseRows::new(dense, rows, columns)
}

/// `B = N Phi` (`dim x r`: coordinates from modal coordinates) and `T =
/// Phi^T Mr N^T` (`r x dim`: modal coordinates from coordinates), `null`
/// holding `N`'s columns and `mr` the reduced mass.
fn transforms(
    null: &[Vec<f64>],
    phi: &[f64],
    mr: &[f64],
    dim: usize,
    r: usize,
) -> (Vec<f64>, Vec<f64>) {
    let mut to_coordinates = vec![0.0; dim * r];
    for i in 0..dim {
        for c in 0..r {
            to_coordinates[i * r + c] = (0..r).map(|k| null[k][i] * phi[k * r + c]).sum();
        }
    }
    let mut phi_t_m = vec![0.0; r * r];
    for c in 0..r {
        for k in 0..r {
            phi_t_m[c * r + k] = (0..r).map(|j| phi[j * r + c] * mr[j * r + k]).sum();
        }
    }
    let mut to_modal = vec![0.0; r * dim];
    for c in 0..r {
        for i in 0..dim {
            to_modal[c * dim + i] = (0..r).map(|k| phi_t_m[c * r + k] * null[k][i]).sum();
        }
    }
    (to_coordinates, to_modal)
}

/// The harmonic `load` of modal shape `shape` with each mode's force `(Re
/// P, Im P)` and steady response `Z = P / (w2 - omega^2 + i c omega)`
/// (`values`: each mode's `w2`, `damping` its `c`); an error where an
/// undamped mode is forced at exactly its frequency.
fn steady_response(
    load: &HarmonicLoad,
    shape: &[f64],
    values: &[f64],
    damping: &[f64],
    what: &str,
) -> Result<ModalHarmonic> {
    let r = values.len();
    let (sin, cos) = load.phase.sin_cos();
    let mut response = Vec::with_capacity(r);
    let mut force = Vec::with_capacity(r);
    for j in 0..r {
        let (pr, pi) = (
            load.amplitude * cos * shape[j],
            load.amplitude * sin * shape[j],
        );
        force.push((pr, pi));
        let (dr, di) = (values[j] - load.omega * load.omega, damping[j] * load.omega);
        let norm = dr * dr + di * di;
        if norm == 0.0 {
            if pr == 0.0 && pi == 0.0 {
                response.push((0.0, 0.0));
                continue;
            }
            return Err(Error::Inconsistent(format!(
                "{what}: an undamped mode forced at exactly its frequency {} Hz grows \
                 as t between contacts, which the flow's phasors cannot hold; add \
                 damping, shift the frequency or use method \"dop853\"",
                load.omega / std::f64::consts::TAU
            )));
        }
        // Z = P / (w2 - omega^2 + i c omega).
        response.push(((pr * dr + pi * di) / norm, (pi * dr - pr * di) / norm));
    }
    Ok(ModalHarmonic {
        omega: load.omega,
        response,
        force,
        forced: Vec::new(),
    })
}

/// A linear system reduced to the null space of its constraints: `x = origin
/// + N y` with `N`'s columns (`null`, orthonormal) and the reduced matrices
/// `N^T A N` (row-major `size x size`).
#[derive(Debug, Clone, PartialEq)]
pub struct Reduced {
    pub size: usize,
    pub null: Vec<Vec<f64>>,
    pub origin: Vec<f64>,
    pub mass: Vec<f64>,
    pub stiffness: Vec<f64>,
    pub damping: Vec<f64>,
    /// The unconstrained system's largest `K_ii / M_ii` (1/s^2) and `C_ii /
    /// M_ii` (1/s): the scales of the reduced matrices' round-off. Where the
    /// constraints take every stiff direction (a spring between two masses
    /// stuck together) the reduced system's own values are all round-off, and
    /// no scale of their own tells it.
    pub stiffness_scale: f64,
    pub damping_scale: f64,
}

/// `A B` of two `r x r` row-major matrices, the zeros of `A` skipped (the
/// triangular `L^-1`, a sparse damping).
fn product(a: &[f64], b: &[f64], r: usize) -> Vec<f64> {
    let mut out = vec![0.0; r * r];
    for p in 0..r {
        for i in 0..r {
            let factor = a[p * r + i];
            if factor != 0.0 {
                for (o, b) in out[p * r..(p + 1) * r]
                    .iter_mut()
                    .zip(&b[i * r..(i + 1) * r])
                {
                    *o += factor * b;
                }
            }
        }
    }
    out
}

impl Reduced {
    pub fn new(parts: &LinearParts, constraints: &[(&[f64], f64)]) -> Self {
        let dim = parts.constant.len();
        let (rows, null) = split_space(constraints.iter().map(|c| c.0), dim);
        let r = null.len();
        // The least-norm point: x_p = U c with (H U) c = -offset over the
        // orthonormal row basis U.
        let mut origin = vec![0.0; dim];
        if !rows.is_empty() {
            let s = rows.len();
            let m = constraints.len();
            // Least squares (H U)^T (H U) c = -(H U)^T offset, consistent for
            // dependent constraints on the same point.
            let mut hu = vec![0.0; m * s];
            for (i, (h, _)) in constraints.iter().enumerate() {
                for (j, u) in rows.iter().enumerate() {
                    hu[i * s + j] = linalg::dot(h, u);
                }
            }
            let mut normal = vec![0.0; s * s];
            let mut rhs = vec![0.0; s];
            for a in 0..s {
                for b in 0..s {
                    normal[a * s + b] = (0..m).map(|i| hu[i * s + a] * hu[i * s + b]).sum();
                }
                rhs[a] = -(0..m)
                    .map(|i| hu[i * s + a] * constraints[i].1)
                    .sum::<f64>();
            }
            linalg::solve_in_place(&mut normal, &mut rhs, s);
            for (u, c) in rows.iter().zip(&rhs) {
                for (o, u) in origin.iter_mut().zip(u) {
                    *o += c * u;
                }
            }
        }
        // N^T A N, as two products (`dim^2 r` and `dim r^2`, where the sum
        // for each entry at once took `dim^2 r^2`: minutes for a thousand
        // dampers).
        let reduce = |a: &[f64]| {
            // A N, column q of N in row q of `an`.
            let an: Vec<Vec<f64>> = null
                .iter()
                .map(|n| {
                    (0..dim)
                        .map(|i| linalg::dot(&a[i * dim..(i + 1) * dim], n))
                        .collect()
                })
                .collect();
            let mut out = vec![0.0; r * r];
            for p in 0..r {
                for q in 0..r {
                    out[p * r + q] = linalg::dot(&null[p], &an[q]);
                }
            }
            out
        };
        let diagonal_scale = |a: &[f64]| {
            (0..dim).fold(0.0f64, |m, i| {
                m.max(a[i * dim + i].abs() / parts.mass[i * dim + i])
            })
        };
        Self {
            size: r,
            stiffness_scale: diagonal_scale(&parts.stiffness),
            damping_scale: diagonal_scale(&parts.damping),
            mass: reduce(&parts.mass),
            stiffness: reduce(&parts.stiffness),
            damping: reduce(&parts.damping),
            null,
            origin,
        }
    }

    /// `N^T f`.
    pub fn project(&self, f: &[f64]) -> Vec<f64> {
        self.null.iter().map(|n| linalg::dot(n, f)).collect()
    }
}

/// Orthonormal bases of the span of `rows` (dependent rows dropped) and of
/// its orthogonal complement in `R^dim`, by Gram-Schmidt twice over.
fn split_space<'a>(
    rows: impl Iterator<Item = &'a [f64]>,
    dim: usize,
) -> (Vec<Vec<f64>>, Vec<Vec<f64>>) {
    let mut basis: Vec<Vec<f64>> = Vec::new();
    let orthogonalise = |v: &mut Vec<f64>, basis: &[Vec<f64>]| {
        for _ in 0..2 {
            for b in basis {
                let p = linalg::dot(v, b);
                for (x, b) in v.iter_mut().zip(b) {
                    *x -= p * b;
                }
            }
        }
        linalg::dot(v, v).sqrt()
    };
    for row in rows {
        let size = linalg::dot(row, row).sqrt();
        let mut v = row.to_vec();
        let left = orthogonalise(&mut v, &basis);
        if left > 1e-10 * size {
            v.iter_mut().for_each(|x| *x /= left);
            basis.push(v);
        }
    }
    let count = basis.len();
    let mut all = basis;
    for e in 0..dim {
        if all.len() == dim {
            break;
        }
        let mut v = vec![0.0; dim];
        v[e] = 1.0;
        let left = orthogonalise(&mut v, &all);
        if left > 1e-6 {
            v.iter_mut().for_each(|x| *x /= left);
            all.push(v);
        }
    }
    let null = all.split_off(count);
    (all, null)
}
