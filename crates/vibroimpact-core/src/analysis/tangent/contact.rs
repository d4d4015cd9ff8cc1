//! The tangent flow over one step of a run while a compliant contact is on:
//! the variational equations `Phi' = J(t, y) Phi` with the state's own
//! `y' = f(t, y)` from the step's start, `J` the flow's exact Jacobian (the
//! structure's matrices and each law's slopes in the indentation and its
//! rate, [`Assembly::acceleration_jacobian`]), by classical Runge-Kutta in
//! substeps of at most `SUBSTEP` radians of the flow's fastest rate. The
//! method's own step may be long for this: its trajectory is accurate to its
//! tolerance, not its interpolant (a cubic of the step's ends had left a
//! Hertz contact's tangent 1e-4 off, its slope growing as the square root of
//! the indentation from the onset).

use crate::model::assembly::{Assembly, Mode, Scratch};
use crate::numerics::linalg;

/// The longest substep, in radians of the flow's fastest rate (RK4's error
/// per substep is about its fifth power over 120), and the most substeps a
/// stretch of a step is cut into.
const SUBSTEP: f64 = 0.01;
const MOST_SUBSTEPS: usize = 1 << 16;
/// A step that starts at a contact's onset or ends at its separation is
/// graded towards that end in stretches halving `LEVELS` times: a Hertz
/// law's slope grows as the square root of the indentation, which uniform
/// substeps integrate to a few per cent over the first one (its velocities'
/// derivatives had been 3e-4 off after one contact); halving, the first
/// stretch's share falls as its length to the power 1.5. Each graded
/// stretch takes at least `GRADED` substeps (Simpson's rule, RK4's, errs by
/// 7e-5 on a square root over a doubling; its error falls as the fourth
/// power of the substeps).
const LEVELS: i32 = 20;
const GRADED: usize = 8;
/// An end of a step whose indentation is below this fraction of the other
/// end's is graded towards as an onset or a separation are (at 0.01, the
/// step before a separation, its indentation falling 60-fold, had left the
/// velocities' derivatives 1.5e-4 off).
const EDGE: f64 = 0.1;

/// Buffers for [`ContactSteps::factor`], made once per flow.
pub(super) struct ContactSteps {
    scratch: Scratch,
    /// A full state (the kernel's length) for the system's rates.
    full: Vec<f64>,
    rates: Vec<f64>,
    dadx: Vec<f64>,
    dadv: Vec<f64>,
    jacobian: Vec<f64>,
    state: Vec<f64>,
    stage_y: Vec<f64>,
    sum_y: Vec<f64>,
    k_y: Vec<f64>,
    stage_phi: Vec<f64>,
    sum_phi: Vec<f64>,
    k_phi: Vec<f64>,
    /// The step's stretches, as fractions of it (graded at its edges).
    marks: Vec<f64>,
    /// The extra columns' stage, sum and rate buffers ([`Extra`]).
    stage_g: Vec<f64>,
    sum_g: Vec<f64>,
    k_g: Vec<f64>,
}

/// Columns carried beside the map over a step, `X' = J X + B(t, y)`: the
/// gain by the latched approach rates ([`super::latched`]) and the
/// derivatives by parameters ([`super::parameters`]).
pub(super) struct Extra<'a> {
    /// `X`, row-major `2 dim x columns`, carried from its value in place.
    pub(super) values: &'a mut [f64],
    pub(super) columns: usize,
    pub(super) source: &'a mut dyn Source,
}

/// The inhomogeneous term `B` of [`Extra`]'s columns.
pub(super) trait Source {
    /// `B` at `time`, state `y` (`x` then `v`) and `modes`, added into
    /// `out` (row-major `2 dim x columns`).
    fn add(&mut self, system: &Assembly, time: f64, y: &[f64], modes: &[Mode], out: &mut [f64]);
}

impl ContactSteps {
    pub(super) fn new(system: &Assembly) -> Self {
        let (len, d) = (system.state_len(), system.dim);
        let size = 2 * d;
        Self {
            scratch: Scratch::new(system),
            full: vec![0.0; len],
            rates: vec![0.0; len],
            dadx: vec![0.0; d * d],
            dadv: vec![0.0; d * d],
            jacobian: vec![0.0; size * size],
            state: vec![0.0; size],
            stage_y: vec![0.0; size],
            sum_y: vec![0.0; size],
            k_y: vec![0.0; size],
            stage_phi: vec![0.0; size * size],
            sum_phi: vec![0.0; size * size],
            k_phi: vec![0.0; size * size],
            marks: Vec::with_capacity(2 * LEVELS as usize + 3),
            stage_g: Vec::new(),
            sum_g: Vec::new(),
            k_g: Vec::new(),
        }
    }

    /// The deepest indentation (m) of the compliant contacts on in `modes`
    /// at state `y`.
    fn indentation(system: &Assembly, y: &[f64], modes: &[Mode]) -> f64 {
        modes
            .iter()
            .enumerate()
            .filter(|(_, m)| matches!(m, Mode::Compliant { .. }))
            .map(|(i, _)| -system.gap(i, y).0)
            .fold(0.0, f64::max)
    }

    /// The step's stretches into `self.marks`: the whole, graded towards an
    /// end that is an onset or a separation (towards both from the middle).
    fn grade(&mut self, system: &Assembly, y0: &[f64], y1: &[f64], modes: &[Mode]) {
        if !super::in_contact(modes) {
            self.marks.clear();
            self.marks.extend([0.0, 1.0]);
            return;
        }
        let (start, end) = (
            Self::indentation(system, y0, modes),
            Self::indentation(system, y1, modes),
        );
        let (at_start, at_end) = (start < EDGE * end, end < EDGE * start);
        let both = at_start == at_end && start.max(end) <= 0.0;
        let (at_start, at_end) = if both {
            (true, true)
        } else {
            (at_start, at_end)
        };
        let reach = if at_start && at_end { 0.5 } else { 1.0 };
        self.marks.clear();
        self.marks.push(0.0);
        if at_start {
            self.marks
                .extend((1..=LEVELS).rev().map(|k| reach * 0.5f64.powi(k)));
        }
        if at_start && at_end {
            self.marks.push(0.5);
        }
        if at_end {
            self.marks
                .extend((1..=LEVELS).map(|k| 1.0 - reach * 0.5f64.powi(k)));
        }
        self.marks.push(1.0);
    }

    /// The flow's Jacobian at the state `y` (`x` then `v`) in `modes`, into
    /// `self.jacobian` (row-major `2 dim x 2 dim`), each contact's slopes
    /// from inside it.
    fn jacobian_at(&mut self, system: &Assembly, y: &[f64], modes: &[Mode]) {
        let size = 2 * system.dim;
        self.full[..size].copy_from_slice(y);
        system.flow_jacobian(
            (&self.full, modes, true),
            &mut self.scratch,
            (&mut self.dadx, &mut self.dadv),
            &mut self.jacobian,
        );
    }

    /// The fastest rate of the flow at the Jacobian in `self.jacobian`
    /// (1/s): the square root of the largest stiffness per mass, or the
    /// largest damping rate.
    fn fastest(&self, d: usize) -> f64 {
        let size = 2 * d;
        let j = &self.jacobian;
        let row = |r: usize, cols: std::ops::Range<usize>| -> f64 {
            cols.map(|c| j[r * size + c].abs()).sum::<f64>()
        };
        let stiffest = (d..size).map(|r| row(r, 0..d)).fold(0.0, f64::max);
        let damping = (d..size).map(|r| row(r, d..size)).fold(0.0, f64::max);
        stiffest.sqrt().max(damping)
    }

    /// The tangent factor of the step from `(t0, y0)` to `(t1, y1)` in
    /// `modes` into `out` (row-major `2 dim x 2 dim`; None: not asked, a
    /// step whose map is linear and carried whole at the events), and the
    /// extra columns carried over it where asked.
    pub(super) fn factor(
        &mut self,
        system: &Assembly,
        (t0, y0): (f64, &[f64]),
        (t1, y1): (f64, &[f64]),
        modes: &[Mode],
        mut out: Option<&mut [f64]>,
        mut extra: Option<Extra<'_>>,
    ) {
        let d = system.dim;
        let size = 2 * d;
        let h = t1 - t0;
        // The forcing's rate too: a step between contacts may span a period.
        let mut fastest = std::f64::consts::TAU / (10.0 * system.sticking_step);
        for y in [y0, y1] {
            self.jacobian_at(system, y, modes);
            fastest = fastest.max(self.fastest(d));
        }
        self.grade(system, y0, y1, modes);
        self.state.copy_from_slice(y0);
        if let Some(out) = out.as_deref_mut() {
            out.iter_mut().for_each(|v| *v = 0.0);
            for i in 0..size {
                out[i * size + i] = 1.0;
            }
        }
        if let Some(x) = extra.as_ref() {
            for buffer in [&mut self.stage_g, &mut self.sum_g, &mut self.k_g] {
                buffer.resize(x.values.len(), 0.0);
            }
        }
        for stretch in 1..self.marks.len() {
            let (from, to) = (self.marks[stretch - 1], self.marks[stretch]);
            let length = (to - from) * h;
            let substeps =
                ((length * fastest / SUBSTEP).ceil() as usize).clamp(GRADED, MOST_SUBSTEPS);
            let dt = length / substeps as f64;
            for n in 0..substeps {
                let t = t0 + from * h + n as f64 * dt;
                self.substep(system, (t, dt), modes, out.as_deref_mut(), extra.as_mut());
            }
        }
    }

    /// One classical Runge-Kutta substep of `dt` s from `t` of the state in
    /// `self.state`, the tangent `out` and the extra columns, in `modes`.
    fn substep(
        &mut self,
        system: &Assembly,
        (t, dt): (f64, f64),
        modes: &[Mode],
        out: Option<&mut [f64]>,
        mut extra: Option<&mut Extra<'_>>,
    ) {
        let size = 2 * system.dim;
        self.sum_y.iter_mut().for_each(|v| *v = 0.0);
        self.sum_phi.iter_mut().for_each(|v| *v = 0.0);
        self.sum_g.iter_mut().for_each(|v| *v = 0.0);
        for (stage, (offset, weight)) in [(0.0, 1.0), (0.5, 2.0), (0.5, 2.0), (1.0, 1.0)]
            .into_iter()
            .enumerate()
        {
            let step = if stage == 0 { 0.0 } else { offset * dt };
            if let Some(x) = extra.as_deref() {
                for ((value, start), k) in self.stage_g.iter_mut().zip(&*x.values).zip(&self.k_g) {
                    *value = start + step * k;
                }
            }
            for i in 0..size {
                self.stage_y[i] = self.state[i] + step * self.k_y[i];
            }
            if let Some(out) = out.as_deref() {
                for ((value, start), k) in self.stage_phi.iter_mut().zip(out).zip(&self.k_phi) {
                    *value = start + step * k;
                }
            }
            self.full[..size].copy_from_slice(&self.stage_y);
            let time = t + offset * dt;
            system.rates(time, &self.full, modes, &mut self.scratch, &mut self.rates);
            self.k_y.copy_from_slice(&self.rates[..size]);
            let stage_y = std::mem::take(&mut self.stage_y);
            self.jacobian_at(system, &stage_y, modes);
            if out.is_some() {
                linalg::matmul(&self.jacobian, &self.stage_phi, &mut self.k_phi, size);
            }
            if let Some(x) = extra.as_deref_mut() {
                let columns = x.columns;
                linalg::matmul_rect(&self.jacobian, &self.stage_g, &mut self.k_g, size, columns);
                x.source.add(system, time, &stage_y, modes, &mut self.k_g);
            }
            self.stage_y = stage_y;
            for i in 0..size {
                self.sum_y[i] += weight * self.k_y[i];
            }
            for (sum, k) in self.sum_phi.iter_mut().zip(&self.k_phi) {
                *sum += weight * k;
            }
            for (sum, k) in self.sum_g.iter_mut().zip(&self.k_g) {
                *sum += weight * k;
            }
        }
        for i in 0..size {
            self.state[i] += dt / 6.0 * self.sum_y[i];
        }
        if let Some(out) = out {
            for (value, sum) in out.iter_mut().zip(&self.sum_phi) {
                *value += dt / 6.0 * sum;
            }
        }
        if let Some(x) = extra {
            for (value, sum) in x.values.iter_mut().zip(&self.sum_g) {
                *value += dt / 6.0 * sum;
            }
        }
    }
}
