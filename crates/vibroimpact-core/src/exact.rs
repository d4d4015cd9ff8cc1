#![allow(clippy::needless_range_loop)]
//! The exact flow of a linear system with rigid pairs (`method = "exact"`):
//! between impacts each normal mode is an oscillator under constant and
//! harmonic forcing, integrated in closed form, so a step of any length
//! lands on the solution to round-off and the event kernel's location of an
//! impact is limited by round-off alone.
//!
//! It is a [`SystemStepper`] for [`crate::system_events::integrate_system`]:
//! the kernel watches the gaps, locates impacts on this flow, applies the
//! impact map, sums chattering sequences and holds sticking pairs, whose
//! constrained system has its own modes (computed when first needed). Steps
//! are an eighth of the fastest period present, so that the kernel's cubic
//! check between step ends sees a gap dipping through zero and back within
//! one step (grazing). The energy accumulators (viscous loss, input work) are
//! integrated by 5-point Gauss-Legendre over each step, on the exact flow.

use crate::assembly::{Assembly, InteractionLaw, LinearParts, Mode, Scratch, INPUT, VISCOUS};
use crate::contact::AnyLaw;
use crate::error::{Error, Result};
use crate::matrix_flow::MatrixFlow;
use crate::modal::Configuration;
use crate::system_steppers::SystemStepper;

/// Steps per fastest period: the event kernel's cubic check of a gap between
/// step ends is then within a few 1e-3 of the gap's swing.
const STEPS_PER_PERIOD: f64 = 8.0;

/// The shortest step the limit of closing gaps asks for, in steps of the
/// configuration.
const APEX_STEPS: f64 = 64.0;

/// One modal oscillator `eta'' + c eta' + w2 eta = F0 + forcing`.
#[derive(Debug, Clone, Copy)]
struct Oscillator {
    w2: f64,
    c: f64,
    sigma: f64,
    /// `sigma^2 - w2`: < 0 underdamped, > 0 overdamped.
    disc: f64,
    /// `sqrt(|disc|)`.
    root: f64,
    constant: f64,
}

impl Oscillator {
    fn new(w2: f64, c: f64, constant: f64) -> Self {
        let sigma = 0.5 * c;
        let disc = sigma * sigma - w2;
        Self {
            w2,
            c,
            sigma,
            disc,
            root: disc.abs().sqrt(),
            constant,
        }
    }

    /// `e^(-sigma t) C(t)` and `e^(-sigma t) S(t)`, where `C' = disc S`,
    /// `S' = C`, `C(0) = 1`, `S(0) = 0`: the free response is
    /// `e^(-sigma t) (d0 C + (d0' + sigma d0) S)`.
    #[inline(always)]
    fn factors(&self, t: f64) -> (f64, f64) {
        let z = self.disc * t * t;
        if z.abs() < 1e-3 {
            // Near critical damping (and for free masses): the series.
            let e = if self.sigma == 0.0 {
                1.0
            } else {
                (-self.sigma * t).exp()
            };
            let c = 1.0 + z * (0.5 + z * (1.0 / 24.0 + z / 720.0));
            let s = t * (1.0 + z * (1.0 / 6.0 + z * (1.0 / 120.0 + z / 5040.0)));
            (e * c, e * s)
        } else if self.disc < 0.0 {
            let e = (-self.sigma * t).exp();
            let (s, c) = (self.root * t).sin_cos();
            (e * c, e * s / self.root)
        } else {
            // root <= sigma: neither exponential overflows.
            let a = ((self.root - self.sigma) * t).exp();
            let b = (-(self.root + self.sigma) * t).exp();
            (0.5 * (a + b), 0.5 * (a - b) / self.root)
        }
    }

    /// The constant force's particular response and its rate, `t` after the
    /// start of the flow.
    #[inline(always)]
    fn steady(&self, t: f64) -> (f64, f64) {
        if self.w2 > 0.0 {
            (self.constant / self.w2, 0.0)
        } else if self.c > 0.0 {
            (self.constant * t / self.c, self.constant / self.c)
        } else {
            (0.5 * self.constant * t * t, self.constant * t)
        }
    }
}

/// What each interaction does in a configuration.
const OPEN: u8 = 0;
const STICKING: u8 = 1;
const TOUCHING: u8 = 2;

fn state_of(mode: &Mode) -> u8 {
    match mode {
        Mode::Open => OPEN,
        Mode::Sticking => STICKING,
        Mode::Compliant { .. } => TOUCHING,
    }
}

/// The flow of one configuration (which pairs stick, which linear contacts
/// touch): its normal modes when its damping is classical, else the matrix
/// exponential (`matrix`, and no modes).
#[derive(Debug, Clone)]
struct Modes {
    key: Vec<u8>,
    configuration: Configuration,
    oscillators: Vec<Oscillator>,
    matrix: Option<MatrixFlow>,
    /// Whether a contact touches (its losses are the contact's, not viscous).
    touching: bool,
    /// An eighth of the configuration's fastest period (s).
    step: f64,
}

/// Gauss-Legendre nodes on [0, 1] and weights (5 points, exact to degree 9).
const NODES: [f64; 5] = [
    0.046_910_077_030_668_004,
    0.230_765_344_947_158_45,
    0.5,
    0.769_234_655_052_841_6,
    0.953_089_922_969_332,
];
const WEIGHTS: [f64; 5] = [
    0.118_463_442_528_094_54,
    0.239_314_335_249_683_23,
    0.284_444_444_444_444_45,
    0.239_314_335_249_683_23,
    0.118_463_442_528_094_54,
];

/// The exact flow as a stepper.
#[derive(Debug, Clone)]
pub struct ExactFlow {
    parts: LinearParts,
    modes: Vec<Modes>,
    /// The free system's step: an eighth of its fastest period (s).
    step: f64,
    /// Per mode, the free part's start `(d0, d0')`.
    start: Vec<(f64, f64)>,
    /// Per mode, the modal coordinate and its rate at the start.
    origin_modal: Vec<(f64, f64)>,
    /// Per harmonic, `(sin, cos)` of its angle at the flow's start.
    phasors: Vec<(f64, f64)>,
    eta: Vec<f64>,
    rate: Vec<f64>,
    factors: Vec<Factors>,
    next_slot: usize,
    /// The start last set: its time's bits and modes, and its state.
    begun: Option<(u64, usize)>,
    begun_state: Vec<f64>,
    /// A state and its rates at a Gauss node (the energy of contacts).
    node: Vec<f64>,
    rates: Vec<f64>,
    evaluations: u64,
}

impl ExactFlow {
    /// The flow of `system`, or an error saying what it cannot take
    /// (compliant laws, signals other than harmonics, non-classical damping).
    pub fn new(system: &Assembly) -> Result<Self> {
        if let Some(it) = system.interactions.iter().find(|it| {
            !matches!(
                it.law,
                InteractionLaw::Rigid { .. }
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
        let parts = system.linear_parts("exact")?;
        let free = Self::modes_of(&parts, system, &vec![OPEN; system.interactions.len()])?;
        let step = free.step;
        let dim = system.dim;
        Ok(Self {
            start: vec![(0.0, 0.0); dim],
            origin_modal: vec![(0.0, 0.0); dim],
            phasors: vec![(0.0, 1.0); parts.harmonics.len()],
            eta: vec![0.0; dim],
            rate: vec![0.0; dim],
            factors: vec![
                Factors {
                    key: None,
                    modes: vec![(0.0, 0.0); dim],
                    turns: vec![(0.0, 1.0); parts.harmonics.len()],
                };
                FACTOR_SLOTS
            ],
            next_slot: 0,
            begun: None,
            begun_state: vec![0.0; 2 * dim],
            node: vec![0.0; system.state_len()],
            rates: vec![0.0; system.state_len()],
            parts,
            modes: vec![free],
            step,
            evaluations: 0,
        })
    }

    /// The step the kernel should take (s; infinite when nothing in the
    /// system oscillates or decays: free flights are parabolas, which the
    /// kernel's cubic check holds exactly).
    pub fn step(&self) -> f64 {
        self.step
    }

    fn modes_of(parts: &LinearParts, system: &Assembly, key: &[u8]) -> Result<Modes> {
        let chosen = |state: u8| {
            system
                .interactions
                .iter()
                .zip(key)
                .filter(move |(_, s)| **s == state)
                .map(|(it, _)| it)
        };
        let constraints: Vec<(&[f64], f64)> = chosen(STICKING)
            .map(|it| (it.h.as_slice(), it.offset))
            .collect();
        // A touching linear contact pushes with k delta + c delta', delta =
        // -(h.x + offset): stiffness k h h^T and damping c h h^T on top, and
        // the load -k offset h.
        let mut parts = parts.clone();
        let dim = system.dim;
        for it in chosen(TOUCHING) {
            if let InteractionLaw::Compliant {
                law: AnyLaw::Linear(law),
                damping,
            } = it.law
            {
                for i in 0..dim {
                    parts.constant[i] -= law.stiffness * it.offset * it.h[i];
                    for j in 0..dim {
                        parts.stiffness[i * dim + j] += law.stiffness * it.h[i] * it.h[j];
                        parts.damping[i * dim + j] += damping * it.h[i] * it.h[j];
                    }
                }
            }
        }
        let mut names: Vec<String> = chosen(STICKING)
            .map(|it| format!("{} sticking", system.pairs[it.pair]))
            .collect();
        names.extend(chosen(TOUCHING).map(|it| format!("{} in contact", system.pairs[it.pair])));
        let what = if names.is_empty() {
            "the system".to_string()
        } else {
            format!("the system with {}", names.join(" and "))
        };
        let touching = key.contains(&TOUCHING);
        let step = |fastest: f64| std::f64::consts::TAU / (STEPS_PER_PERIOD * fastest);
        match Configuration::classical(&parts, &constraints, &what)? {
            Some(configuration) => {
                let oscillators: Vec<Oscillator> = (0..configuration.modes)
                    .map(|j| {
                        Oscillator::new(
                            configuration.stiffness[j],
                            configuration.damping[j],
                            configuration.constant[j],
                        )
                    })
                    .collect();
                let fastest = oscillators
                    .iter()
                    .map(|o| o.w2.sqrt().max(o.c))
                    .chain(configuration.harmonics.iter().map(|h| h.omega))
                    .fold(0.0f64, f64::max);
                Ok(Modes {
                    key: key.to_vec(),
                    configuration,
                    oscillators,
                    matrix: None,
                    touching,
                    step: step(fastest),
                })
            }
            None => {
                let flow = MatrixFlow::new(&parts, &constraints, &what)?;
                Ok(Modes {
                    key: key.to_vec(),
                    configuration: Configuration::empty(),
                    oscillators: Vec::new(),
                    step: step(flow.fastest),
                    matrix: Some(flow),
                    touching,
                })
            }
        }
    }

    /// The modes for the sticking interactions of `modes`, made when first met.
    fn select(&mut self, system: &Assembly, modes: &[Mode]) -> Result<usize> {
        let found = self.modes.iter().position(|m| {
            m.key
                .iter()
                .zip(modes)
                .all(|(s, mode)| *s == state_of(mode))
        });
        match found {
            Some(index) => Ok(index),
            None => {
                let key: Vec<u8> = modes.iter().map(state_of).collect();
                let made = Self::modes_of(&self.parts, system, &key)?;
                self.modes.push(made);
                Ok(self.modes.len() - 1)
            }
        }
    }

    /// Set the flow's start at `time`, state `y`, in the modes `index`.
    fn begin(&mut self, index: usize, dim: usize, time: f64, y: &[f64]) {
        // Locating an event restarts from the same point many times.
        if self.begun == Some((time.to_bits(), index)) && self.begun_state[..] == y[..2 * dim] {
            return;
        }
        self.begun = Some((time.to_bits(), index));
        self.begun_state.copy_from_slice(&y[..2 * dim]);
        if let Some(flow) = self.modes[index].matrix.as_mut() {
            flow.begin(time, y);
            return;
        }
        let m = &self.modes[index];
        let cfg = &m.configuration;
        for (h, p) in cfg.harmonics.iter().zip(self.phasors.iter_mut()) {
            *p = (h.omega * time).sin_cos();
        }
        for j in 0..cfg.modes {
            let row = &cfg.to_modal[j * dim..(j + 1) * dim];
            let mut eta = 0.0;
            let mut rate = 0.0;
            for i in 0..dim {
                eta += row[i] * (y[i] - cfg.origin[i]);
                rate += row[i] * y[dim + i];
            }
            let (mut p, mut dp) = m.oscillators[j].steady(0.0);
            for (h, (s, c)) in cfg.harmonics.iter().zip(&self.phasors) {
                let (zr, zi) = h.response[j];
                p += zr * c - zi * s;
                dp -= h.omega * (zr * s + zi * c);
            }
            self.start[j] = (eta - p, rate - dp);
            self.origin_modal[j] = (eta, rate);
        }
    }

    /// The coordinates and velocities `t` after the start, into `out`.
    fn at(&mut self, index: usize, dim: usize, t: f64, out: &mut [f64]) {
        if let Some(flow) = self.modes[index].matrix.as_mut() {
            flow.at(&self.begun_state, t, out);
            self.evaluations += 1;
            return;
        }
        let slot = self.factors_at(index, t);
        let m = &self.modes[index];
        let cfg = &m.configuration;
        let r = cfg.modes;
        let factors = &self.factors[slot];
        for j in 0..r {
            let o = &m.oscillators[j];
            let (d0, r0) = self.start[j];
            let (ec, es) = factors.modes[j];
            let (p, dp) = o.steady(t);
            self.eta[j] = ec * d0 + es * (r0 + o.sigma * d0) + p;
            self.rate[j] = ec * r0 - es * (o.sigma * r0 + o.w2 * d0) + dp;
        }
        for ((h, (s0, c0)), (st, ct)) in cfg.harmonics.iter().zip(&self.phasors).zip(&factors.turns)
        {
            // The angle at the start turned by omega t.
            let (s, c) = (s0 * ct + c0 * st, c0 * ct - s0 * st);
            for j in 0..r {
                let (zr, zi) = h.response[j];
                self.eta[j] += zr * c - zi * s;
                self.rate[j] -= h.omega * (zr * s + zi * c);
            }
        }
        // The start plus the modes' increments: the flow is continuous at its
        // start to the last bit (a state on a wall stays on it), and a start
        // off the constraints of sticking pairs by round-off stays as close.
        for j in 0..r {
            self.eta[j] -= self.origin_modal[j].0;
            self.rate[j] -= self.origin_modal[j].1;
        }
        for i in 0..dim {
            let row = &cfg.to_coordinates[i * r..(i + 1) * r];
            let mut x = self.begun_state[i];
            let mut v = self.begun_state[dim + i];
            for j in 0..r {
                x += row[j] * self.eta[j];
                v += row[j] * self.rate[j];
            }
            out[i] = x;
            out[dim + i] = v;
        }
        self.evaluations += 1;
    }

    /// The viscous and the input power (W) `t` after the start: the modal
    /// rates only, without the coordinates (what the energy quadrature needs).
    fn powers_at(&mut self, index: usize, t: f64) -> (f64, f64) {
        let slot = self.factors_at(index, t);
        let m = &self.modes[index];
        let cfg = &m.configuration;
        let r = cfg.modes;
        let factors = &self.factors[slot];
        for (j, o) in m.oscillators.iter().enumerate() {
            let (d0, r0) = self.start[j];
            let (ec, es) = factors.modes[j];
            self.rate[j] = ec * r0 - es * (o.sigma * r0 + o.w2 * d0) + o.steady(t).1;
        }
        let mut input = 0.0;
        for ((h, (s0, c0)), (st, ct)) in cfg.harmonics.iter().zip(&self.phasors).zip(&factors.turns)
        {
            let (s, c) = (s0 * ct + c0 * st, c0 * ct - s0 * st);
            for j in 0..r {
                let (zr, zi) = h.response[j];
                self.rate[j] -= h.omega * (zr * s + zi * c);
            }
            for j in 0..r {
                let (pr, pi) = h.force[j];
                input += (pr * c - pi * s) * self.rate[j];
            }
        }
        // Mass-normalised modes with classical damping: the viscous power is
        // the sum of each mode's.
        let viscous: f64 = (0..r)
            .map(|j| m.oscillators[j].c * self.rate[j] * self.rate[j])
            .sum();
        (viscous, input)
    }

    /// The slot of the factors of the modes `index` at `t` after a start:
    /// fixed steps and their Gauss nodes repeat a few lengths, whose
    /// exponentials, sines and cosines are kept.
    fn factors_at(&mut self, index: usize, t: f64) -> usize {
        let key = Some((t.to_bits(), index));
        if let Some(slot) = self.factors.iter().position(|f| f.key == key) {
            return slot;
        }
        let slot = self.next_slot;
        self.next_slot = (self.next_slot + 1) % self.factors.len();
        let m = &self.modes[index];
        let f = &mut self.factors[slot];
        f.key = key;
        for (out, o) in f.modes.iter_mut().zip(&m.oscillators) {
            *out = o.factors(t);
        }
        for (out, h) in f.turns.iter_mut().zip(&m.configuration.harmonics) {
            *out = (h.omega * t).sin_cos();
        }
        slot
    }
}

/// The factors of every mode and the turn of every harmonic at one time
/// after a start.
#[derive(Debug, Clone)]
struct Factors {
    key: Option<(u64, usize)>,
    modes: Vec<(f64, f64)>,
    turns: Vec<(f64, f64)>,
}

/// Lengths whose factors are kept: a step, its five Gauss nodes and two more.
const FACTOR_SLOTS: usize = 8;

impl SystemStepper for ExactFlow {
    fn name(&self) -> &'static str {
        "exact"
    }

    fn is_adaptive(&self) -> bool {
        false
    }

    fn is_exact(&self) -> bool {
        true
    }

    fn reset(&mut self) {}

    /// A configuration's own step (a touching contact is stiffer than the
    /// free system, so its steps are shorter), and not much longer than the
    /// time in which any open gap under a closing acceleration would reach its
    /// wall: a small rebound that comes back within one step could rise, dip
    /// through the wall and rise again between the step's ends, where the
    /// kernel's check of the ends and their slopes cannot see it.
    fn step_limit(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
    ) -> Result<f64> {
        let index = self.select(system, modes)?;
        let step = self.modes[index].step;
        let mut limit = step;
        let d = system.dim;
        let mut rates = std::mem::take(&mut self.rates);
        let mut evaluated = false;
        for (i, mode) in modes.iter().enumerate() {
            if *mode != Mode::Open {
                continue;
            }
            if !evaluated {
                system.rates(time, y, modes, scratch, &mut rates);
                evaluated = true;
            }
            let (gap, rate) = system.gap(i, y);
            let closing = -crate::linalg::dot(&system.interactions[i].h, &rates[d..2 * d]);
            if closing > 0.0 {
                // The gap's parabola reaches the wall at `hit`: end the step a
                // little after it, so that the step's end sees the gap shut
                // even if the wall would draw away again later in the step.
                // Rebounds that come back sooner than the floor come back
                // within the next few steps, where their ends see them.
                let hit = (rate + (rate * rate + 2.0 * closing * gap.max(0.0)).sqrt()) / closing;
                limit = limit.min((1.5 * hit).max(step / APEX_STEPS));
            }
        }
        self.rates = rates;
        Ok(limit)
    }

    fn attempt(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        _scratch: &mut Scratch,
        out: &mut [f64],
    ) -> Result<f64> {
        let dim = system.dim;
        let index = self.select(system, modes)?;
        self.begin(index, dim, time, y);
        // The accumulators are filled for the kept step only (`finish`).
        let at = 2 * dim;
        out[at..].copy_from_slice(&y[at..]);
        self.at(index, dim, h, out);
        Ok(0.0)
    }

    /// The energy accumulators of the kept step: the powers at the Gauss
    /// nodes on the exact flow.
    fn finish(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        end: &mut [f64],
    ) -> Result<()> {
        let dim = system.dim;
        let at = 2 * dim;
        let index = self.select(system, modes)?;
        if self.modes[index].matrix.is_some() || self.modes[index].touching {
            // Every accumulator, the contacts' losses too, from the system's
            // own rates at the Gauss nodes of the exact flow.
            self.begin(index, dim, time, y);
            let mut node = std::mem::take(&mut self.node);
            let mut rates = std::mem::take(&mut self.rates);
            for (x, w) in NODES.iter().zip(WEIGHTS) {
                self.at(index, dim, x * h, &mut node);
                system.rates(time + x * h, &node, modes, scratch, &mut rates);
                for k in at..end.len() {
                    end[k] += w * h * rates[k];
                }
            }
            self.node = node;
            self.rates = rates;
            return Ok(());
        }
        if !system.has_powers() {
            return Ok(());
        }
        self.begin(index, dim, time, y);
        let (mut viscous, mut input) = (0.0, 0.0);
        for (x, w) in NODES.iter().zip(WEIGHTS) {
            let (v, i) = self.powers_at(index, x * h);
            viscous += w * v;
            input += w * i;
        }
        end[at + VISCOUS] = y[at + VISCOUS] + h * viscous;
        end[at + INPUT] = y[at + INPUT] + h * input;
        Ok(())
    }

    fn accept(&mut self) {}

    fn shrink(&self, _error: f64) -> f64 {
        1.0
    }

    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}
