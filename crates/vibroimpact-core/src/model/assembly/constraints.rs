//! Sticking pairs' constraint forces, and the accelerations' Jacobians for
//! Newton's method (compliant slopes, constraints projected out).

use super::gaps::h_dot;
use super::{apart_damping, Assembly, InteractionLaw, Mode, Scratch};
use crate::model::contact::ContactLaw;
use crate::numerics::linalg;

impl Assembly {
    /// The constraint forces of the `sticking` interactions listed in
    /// `scratch` into it and onto the accelerations (out of line: rare).
    #[inline(never)]
    pub(crate) fn add_constraint_forces(
        &self,
        sticking: usize,
        acc: &mut [f64],
        scratch: &mut Scratch,
    ) {
        if sticking == 1 {
            // One constraint: W lambda = -h . a with W = h M^-1 h^T, what
            // the elimination below gives for one row.
            let it = &self.interactions[scratch.sticking[0]];
            let lambda = -h_dot(&it.h, acc) / it.inverse_mass;
            scratch.forces[0] = lambda;
            for (a, p) in acc.iter_mut().zip(&it.push) {
                *a += p * lambda;
            }
        } else {
            self.constraint_forces(
                &scratch.sticking[..sticking],
                acc,
                &mut scratch.matrix,
                &mut scratch.forces,
            );
            for (s, &i) in scratch.sticking[..sticking].iter().enumerate() {
                let lambda = scratch.forces[s];
                for (a, p) in acc.iter_mut().zip(&self.interactions[i].push) {
                    *a += p * lambda;
                }
            }
        }
    }

    /// The largest part of coordinate `i`'s acceleration that the pairs held
    /// in `scratch` (as the last rates solved them) contribute, m/s^2 (0 for
    /// none): a held pair's force cancels the others there, so it is the
    /// scale of their round-off, which bounds how far Newton's method can
    /// go where the acceleration itself is round-off.
    pub(crate) fn held_acceleration(&self, scratch: &Scratch, i: usize) -> f64 {
        let mut most = 0.0f64;
        for s in 0..scratch.count {
            let push = &self.interactions[scratch.sticking[s]].push;
            most = most.max((scratch.forces[s] * push[i]).abs());
        }
        most
    }

    /// The Jacobians of the accelerations (the middle `dim` rates) with
    /// respect to the coordinates `x` and the velocities `v` at state `y`, as
    /// row-major `dim x dim` matrices, for Newton's method: the structure's
    /// `-M^-1 K` and `-M^-1 C`, the compliant contacts' slopes along
    /// `M^-1 h^T h`, and sticking pairs' constraints projected out.
    pub fn acceleration_jacobian(
        &self,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        dadx: &mut [f64],
        dadv: &mut [f64],
    ) {
        self.jacobian_of_accelerations(y, modes, scratch, (dadx, dadv), false);
    }

    /// The Jacobian of the whole first-order flow `y' = (v, a)` at state `y`
    /// in `modes` into `out` (row-major `2 dim x 2 dim`: `[[0, I], [da/dx,
    /// da/dv]]`), `dadx` and `dadv` its work space: the tangent flow's. With
    /// `inside`, each compliant contact's slopes are taken from inside it (at
    /// an indentation of at least zero): the tangent flow's steps start and
    /// end on a contact's onset and separation, where a round-off gap of
    /// either sign would otherwise switch a linear law's stiffness on or off
    /// for a whole stage.
    pub fn flow_jacobian(
        &self,
        (y, modes, inside): (&[f64], &[Mode], bool),
        scratch: &mut Scratch,
        (dadx, dadv): (&mut [f64], &mut [f64]),
        out: &mut [f64],
    ) {
        self.jacobian_of_accelerations(y, modes, scratch, (&mut *dadx, &mut *dadv), inside);
        let d = self.dim;
        let size = 2 * d;
        out.iter_mut().for_each(|v| *v = 0.0);
        for i in 0..d {
            out[i * size + d + i] = 1.0;
            for c in 0..d {
                out[(d + i) * size + c] = dadx[i * d + c];
                out[(d + i) * size + d + c] = dadv[i * d + c];
            }
        }
    }

    fn jacobian_of_accelerations(
        &self,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        (dadx, dadv): (&mut [f64], &mut [f64]),
        inside: bool,
    ) {
        let (n, d) = (self.n, self.dim);
        let (x, v) = (&y[..d], &y[d..2 * d]);
        dadx.iter_mut().for_each(|a| *a = 0.0);
        dadv.iter_mut().for_each(|a| *a = 0.0);
        for i in 0..n {
            for j in 0..n {
                dadx[i * d + j] = -self.minv_k[i * n + j];
                dadv[i * d + j] = -self.minv_c[i * n + j];
            }
        }
        let mut sticking = 0;
        for (i, (it, mode)) in self.interactions.iter().zip(modes).enumerate() {
            match (*mode, it.law) {
                (
                    Mode::Compliant {
                        approach_rate,
                        indented_only,
                    },
                    InteractionLaw::Compliant { law, damping },
                ) => {
                    let mut indentation = -(it.offset + h_dot(&it.h, x));
                    if inside {
                        indentation = indentation.max(0.0);
                    }
                    let rate = -h_dot(&it.h, v);
                    let (_, by_indentation, by_rate, damping) =
                        if law.acts(indentation, indented_only) || (inside && indentation == 0.0) {
                            let (force, by_indentation, by_rate) =
                                law.force_derivatives(indentation, rate, approach_rate);
                            (force, by_indentation, by_rate, damping)
                        } else {
                            (0.0, 0.0, 0.0, apart_damping(damping, indented_only))
                        };
                    // lambda(delta, delta'), delta = -(b + h.x): d/dx = -lambda_delta h.
                    for (r, p) in it.push.iter().enumerate() {
                        for (c, h) in it.h.iter().enumerate() {
                            dadx[r * d + c] -= p * by_indentation * h;
                            dadv[r * d + c] -= p * (by_rate + damping) * h;
                        }
                    }
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
                _ => {}
            }
        }
        if sticking == 0 {
            return;
        }
        // The constraint force -W^-1 H a makes the accelerations P a with
        // P = I - Push W^-1 H: project each column of both Jacobians.
        let active = &scratch.sticking[..sticking];
        for matrix in [&mut *dadx, &mut *dadv] {
            for c in 0..d {
                for (r, &i) in active.iter().enumerate() {
                    for (q, &j) in active.iter().enumerate() {
                        scratch.matrix[r * sticking + q] =
                            linalg::dot(&self.interactions[i].h, &self.interactions[j].push);
                    }
                    scratch.forces[r] = (0..d)
                        .map(|k| self.interactions[i].h[k] * matrix[k * d + c])
                        .sum();
                }
                linalg::solve_in_place(
                    &mut scratch.matrix[..sticking * sticking],
                    &mut scratch.forces[..sticking],
                    sticking,
                );
                for (r, &i) in active.iter().enumerate() {
                    for k in 0..d {
                        matrix[k * d + c] -= self.interactions[i].push[k] * scratch.forces[r];
                    }
                }
            }
        }
    }

    /// The forces `lambda` of the sticking interactions `active` that keep
    /// their gaps' accelerations at zero: `W lambda = -H a`, `W = H M^-1
    /// H^T`, by Gaussian elimination with partial pivoting (a few rows).
    fn constraint_forces(
        &self,
        active: &[usize],
        acc: &[f64],
        matrix: &mut [f64],
        forces: &mut [f64],
    ) {
        let m = active.len();
        for (r, &i) in active.iter().enumerate() {
            for (c, &j) in active.iter().enumerate() {
                matrix[r * m + c] =
                    linalg::dot(&self.interactions[i].h, &self.interactions[j].push);
            }
            forces[r] = -h_dot(&self.interactions[i].h, acc);
        }
        linalg::solve_in_place(&mut matrix[..m * m], &mut forces[..m], m);
    }
}
