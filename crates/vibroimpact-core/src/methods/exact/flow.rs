//! The exact flow from a start: the state and the accelerations (and their
//! rates) any time after it, by the modes or the matrix exponential.

use super::configurations::{Modes, OPEN};
use super::energies::{Span, NODES};
use super::oscillator::{from_rest_part, modal_state};
use crate::error::{Error, Result};
use crate::model::assembly::{Assembly, InteractionLaw, LinearParts, SPARSE_FROM};
use crate::model::contact::AnyLaw;
use crate::numerics::series::sin_cos;

/// The exact flow as a stepper.
#[derive(Debug, Clone)]
pub struct ExactFlow {
    pub(super) parts: LinearParts,
    pub(super) modes: Vec<Modes>,
    /// The index of the modes last selected.
    pub(super) selected: usize,
    /// The free system's step: an eighth of its fastest period (s).
    pub(super) step: f64,
    /// Per mode, the free part's start `(d0, d0')`.
    pub(super) start: Vec<(f64, f64)>,
    /// Per mode, the modal coordinate and its rate at the start.
    pub(super) origin_modal: Vec<(f64, f64)>,
    /// Per harmonic, `(sin, cos)` of its angle at the flow's start.
    pub(super) phasors: Vec<(f64, f64)>,
    pub(super) eta: Vec<f64>,
    pub(super) rate: Vec<f64>,
    /// Per mode then node, the factors at the Gauss nodes of the step
    /// `finish` integrates; per harmonic then node, its turns there.
    pub(super) node_modes: Vec<(f64, f64)>,
    pub(super) node_turns: Vec<(f64, f64)>,
    /// The start last set: its time's bits and modes, and its state.
    pub(super) begun: Option<(u64, usize)>,
    /// The modes and the time after the start of the last evaluation by
    /// the modes (`eta` and `rate` hold its increments), if it was the last.
    pub(super) last: Option<(usize, f64)>,
    /// The steps whose energies are still to be added, and the modal state
    /// at their start.
    pub(super) span: Option<Span>,
    pub(super) span_modal: Vec<(f64, f64)>,
    pub(super) begun_state: Vec<f64>,
    /// A state and its rates at a Gauss node (the energy of contacts).
    pub(super) node: Vec<f64>,
    pub(super) rates: Vec<f64>,
    pub(super) evaluations: u64,
}

impl ExactFlow {
    /// The flow of `system`, or an error saying what it cannot take
    /// (compliant laws, signals other than harmonics, non-classical damping).
    pub fn new(system: &Assembly) -> Result<Self> {
        let parts = Self::takes(system)?;
        let free = Self::modes_of(&parts, system, &vec![OPEN; system.interactions.len()], &[])?;
        let step = free.step;
        let dim = system.dim;
        Ok(Self {
            start: vec![(0.0, 0.0); dim],
            origin_modal: vec![(0.0, 0.0); dim],
            phasors: vec![(0.0, 1.0); parts.harmonics.len()],
            eta: vec![0.0; dim],
            rate: vec![0.0; dim],
            node_modes: vec![(0.0, 0.0); NODES.len() * dim],
            node_turns: vec![(0.0, 1.0); NODES.len() * parts.harmonics.len()],
            begun: None,
            last: None,
            span: None,
            span_modal: vec![(0.0, 0.0); dim],
            begun_state: vec![0.0; 2 * dim],
            node: vec![0.0; system.state_len()],
            rates: vec![0.0; system.state_len()],
            parts,
            modes: vec![free],
            selected: 0,
            step,
            evaluations: 0,
        })
    }

    /// The system's linear parts where the flow takes its kinds of laws and
    /// signals (rigid and linear laws, harmonics), else why not: what no
    /// value of theirs changes (a study refuses it before its runs).
    pub fn takes(system: &Assembly) -> Result<LinearParts> {
        if let Some(it) = system.interactions.iter().find(|it| {
            !matches!(
                it.law,
                InteractionLaw::Rigid { .. }
                    | InteractionLaw::Friction { .. }
                    | InteractionLaw::Compliant {
                        law: AnyLaw::Linear(_),
                        ..
                    }
            )
        }) {
            return Err(Error::Inconsistent(format!(
                "method \"exact\" takes rigid and linear laws only (a piecewise-linear system), \
                 and {} is not linear; use law = \"rigid\" or \"linear\", or method \"dop853\"",
                system.pairs[it.pair]
            )));
        }
        system.linear_parts("exact")
    }

    /// The step the kernel should take (s; infinite when nothing in the
    /// system oscillates or decays: free flights are parabolas, which the
    /// kernel's cubic check holds exactly).
    pub fn step(&self) -> f64 {
        self.step
    }

    /// Set the flow's start at `time`, state `y`, in the modes `index`.
    #[inline(always)]
    pub(super) fn begin(&mut self, index: usize, dim: usize, time: f64, y: &[f64]) {
        // Locating an event restarts from the same point many times.
        if self.begun != Some((time.to_bits(), index))
            || self.begun_state.iter().zip(y).any(|(b, v)| b != v)
        {
            self.begin_at(index, dim, time, y);
        }
    }

    #[inline(never)]
    pub(super) fn begin_at(&mut self, index: usize, dim: usize, time: f64, y: &[f64]) {
        self.begun = Some((time.to_bits(), index));
        // A loop: for a handful of values a call to memcpy costs more.
        for (b, v) in self.begun_state.iter_mut().zip(y) {
            *b = *v;
        }
        if let Some(flow) = self.modes[index].matrix.as_mut() {
            flow.begin(time, y);
            return;
        }
        let m = &self.modes[index];
        let cfg = &m.configuration;
        for (h, p) in cfg.harmonics.iter().zip(self.phasors.iter_mut()) {
            *p = (h.omega * time).sin_cos();
        }
        let r = cfg.modes;
        for j in 0..r {
            let (eta, rate) = modal_state(cfg, dim, j, y);
            let (mut p, mut dp) = m.oscillators[j].steady(0.0);
            for (k, (h, (s, c))) in cfg.harmonics.iter().zip(&self.phasors).enumerate() {
                if m.from_rest.get(k * r + j) == Some(&true) {
                    // Taken from rest in `modal_at`, not from its particular response.
                    continue;
                }
                let (zr, zi) = h.response[j];
                p += zr * c - zi * s;
                dp -= h.omega * (zr * s + zi * c);
            }
            self.start[j] = (eta - p, rate - dp);
            self.origin_modal[j] = (eta, rate);
        }
    }

    /// The accelerations at the start (of modes without a matrix flow), into
    /// `out`: each mode's `F0 + f - w2 eta - c eta'` taken to coordinates.
    pub(super) fn accelerations(&mut self, index: usize, dim: usize, out: &mut [f64]) {
        self.last = None;
        let m = &self.modes[index];
        let cfg = &m.configuration;
        let r = cfg.modes;
        for (j, o) in m.oscillators.iter().enumerate() {
            let (eta, rate) = self.origin_modal[j];
            self.eta[j] = o.constant - o.w2 * eta - o.c * rate;
        }
        for (h, (s, c)) in cfg.harmonics.iter().zip(&self.phasors) {
            for (a, (pr, pi)) in self.eta[..r].iter_mut().zip(&h.force) {
                *a += pr * c - pi * s;
            }
        }
        if dim < SPARSE_FROM {
            for (i, a) in out[..dim].iter_mut().enumerate() {
                let row = &cfg.to_coordinates[i * r..(i + 1) * r];
                *a = row.iter().zip(&self.eta[..r]).map(|(b, e)| b * e).sum();
            }
            return;
        }
        let eta = &self.eta[..r];
        for (i, a) in out[..dim].iter_mut().enumerate() {
            let (columns, row) = cfg.coordinate_rows.row(i);
            *a = columns.iter().zip(row).map(|(&c, b)| b * eta[c]).sum();
        }
    }

    /// The accelerations and their rates at the last evaluation by the modes
    /// (see [`Self::at`]), into `accel` and `jerk`: each mode's `eta'' = F0 +
    /// f - w2 eta - c eta'` and `eta''' = f' - w2 eta' - c eta''`, taken to
    /// coordinates. False when the last evaluation was not by the modes.
    pub(super) fn last_derivatives(
        &mut self,
        dim: usize,
        accel: &mut [f64],
        jerk: &mut [f64],
    ) -> bool {
        let Some((index, t)) = self.last.take() else {
            return false;
        };
        let m = &self.modes[index];
        let cfg = &m.configuration;
        let r = cfg.modes;
        // In place of the increments (`eta`: accelerations, `rate`: jerks).
        let (a, j) = (&mut self.eta[..r], &mut self.rate[..r]);
        for (k, o) in m.oscillators.iter().enumerate() {
            let eta = a[k] + self.origin_modal[k].0;
            let rate = j[k] + self.origin_modal[k].1;
            a[k] = o.constant - o.w2 * eta - o.c * rate;
            j[k] = -o.w2 * rate;
        }
        for (h, &(s0, c0)) in cfg.harmonics.iter().zip(&self.phasors) {
            let (st, ct) = sin_cos(h.omega * t);
            let (s, c) = (s0 * ct + c0 * st, c0 * ct - s0 * st);
            for ((a, j), &(pr, pi)) in a.iter_mut().zip(j.iter_mut()).zip(&h.force) {
                *a += pr * c - pi * s;
                *j -= h.omega * (pr * s + pi * c);
            }
        }
        for ((j, a), o) in j.iter_mut().zip(a.iter()).zip(&m.oscillators) {
            *j -= o.c * a;
        }
        for i in 0..dim {
            let (mut x, mut y) = (0.0, 0.0);
            if dim < SPARSE_FROM {
                let row = &cfg.to_coordinates[i * r..(i + 1) * r];
                for k in 0..r {
                    x += row[k] * a[k];
                    y += row[k] * j[k];
                }
            } else {
                let (columns, row) = cfg.coordinate_rows.row(i);
                for (&k, b) in columns.iter().zip(row) {
                    x += b * a[k];
                    y += b * j[k];
                }
            }
            accel[i] = x;
            jerk[i] = y;
        }
        true
    }

    /// The coordinates and velocities `t` after the start, into `out`.
    pub(super) fn at(&mut self, index: usize, dim: usize, t: f64, out: &mut [f64]) {
        if let Some(flow) = self.modes[index].matrix.as_mut() {
            flow.at(&self.begun_state, t, out);
            self.evaluations += 1;
            self.last = None;
            return;
        }
        self.modal_at(index, t);
        self.last = Some((index, t));
        let cfg = &self.modes[index].configuration;
        let r = cfg.modes;
        // The start plus the modes' increments: the flow is continuous at its
        // start to the last bit (a state on a wall stays on it), and a start
        // off the constraints of sticking pairs by round-off stays as close.
        // Slices of one length each (no bounds checks in the loops: for a
        // few modes those cost as much as the arithmetic).
        let (eta, rate) = (&mut self.eta[..r], &mut self.rate[..r]);
        for ((e, v), o) in eta
            .iter_mut()
            .zip(rate.iter_mut())
            .zip(&self.origin_modal[..r])
        {
            *e -= o.0;
            *v -= o.1;
        }
        if r == 0 {
            // Every coordinate held (all pairs sticking): the start.
            out[..2 * dim].copy_from_slice(&self.begun_state[..2 * dim]);
            self.evaluations += 1;
            return;
        }
        let (x0, v0) = self.begun_state[..2 * dim].split_at(dim);
        let (xs, vs) = out[..2 * dim].split_at_mut(dim);
        if dim < SPARSE_FROM {
            // A small system: every entry of `B`, in rows of one length (no
            // index to load; the same sums where the zeros' terms change
            // nothing).
            let rows = cfg.to_coordinates[..dim * r].chunks_exact(r);
            for ((((row, x1), v1), x0), v0) in rows.zip(xs).zip(vs).zip(x0).zip(v0) {
                let (mut x, mut v) = (*x0, *v0);
                for ((b, e), w) in row.iter().zip(eta.iter()).zip(rate.iter()) {
                    x += b * e;
                    v += b * w;
                }
                *x1 = x;
                *v1 = v;
            }
            self.evaluations += 1;
            return;
        }
        // `B`'s non-zero entries only (a free mass's mode moves its own
        // coordinate alone).
        for (i, (((x1, v1), x0), v0)) in xs.iter_mut().zip(vs).zip(x0).zip(v0).enumerate() {
            let (columns, row) = cfg.coordinate_rows.row(i);
            let (mut x, mut v) = (*x0, *v0);
            for (&c, b) in columns.iter().zip(row) {
                x += b * eta[c];
                v += b * rate[c];
            }
            *x1 = x;
            *v1 = v;
        }
        self.evaluations += 1;
    }

    /// The modal coordinates and rates `t` after the start, into `eta` and
    /// `rate`.
    pub(super) fn modal_at(&mut self, index: usize, t: f64) {
        let m = &self.modes[index];
        let cfg = &m.configuration;
        let r = cfg.modes;
        let (eta, rate) = (&mut self.eta[..r], &mut self.rate[..r]);
        for (((o, &(d0, r0)), e), v) in m
            .oscillators
            .iter()
            .zip(&self.start)
            .zip(eta.iter_mut())
            .zip(rate.iter_mut())
        {
            let (ec, es) = o.factors(t);
            let (p, dp) = o.steady(t);
            *e = ec * d0 + es * (r0 + o.sigma * d0) + p;
            *v = ec * r0 - es * (o.sigma * r0 + o.w2 * d0) + dp;
        }
        if !m.from_rest.is_empty() {
            return self.near_resonance_at(index, t);
        }
        for (h, &(s0, c0)) in cfg.harmonics.iter().zip(&self.phasors) {
            // The angle at the start turned by omega t.
            let (st, ct) = sin_cos(h.omega * t);
            let (s, c) = (s0 * ct + c0 * st, c0 * ct - s0 * st);
            // The modes it forces (the others' terms are zeros).
            for &j in &h.forced {
                let (zr, zi) = h.response[j];
                eta[j] += zr * c - zi * s;
                rate[j] -= h.omega * (zr * s + zi * c);
            }
        }
    }

    /// The harmonics' part of [`Self::modal_at`] where some force a mode near
    /// its resonance: those pairs by their response from rest (the start
    /// kept their particular response in, see [`Self::begin_at`]).
    #[cold]
    #[inline(never)]
    pub(super) fn near_resonance_at(&mut self, index: usize, t: f64) {
        let m = &self.modes[index];
        let cfg = &m.configuration;
        let r = cfg.modes;
        for (k, (h, &(s0, c0))) in cfg.harmonics.iter().zip(&self.phasors).enumerate() {
            let (st, ct) = sin_cos(h.omega * t);
            let (s, c) = (s0 * ct + c0 * st, c0 * ct - s0 * st);
            for j in 0..r {
                let (de, dv) = if m.from_rest[k * r + j] {
                    let o = &m.oscillators[j];
                    from_rest_part(o, h.omega, h.force[j], (s0, c0), t, o.factors(t))
                } else {
                    let (zr, zi) = h.response[j];
                    (zr * c - zi * s, -h.omega * (zr * s + zi * c))
                };
                self.eta[j] += de;
                self.rate[j] += dv;
            }
        }
    }
}
