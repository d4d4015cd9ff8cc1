#![allow(clippy::needless_range_loop)]
//! The exact flow of a linear system with rigid pairs (`method = "exact"`):
//! between impacts each normal mode is an oscillator under constant and
//! harmonic forcing, integrated in closed form, so a step of any length
//! lands on the solution to round-off and the event kernel's location of an
//! impact is limited by round-off alone.
//!
//! It is a [`SystemStepper`] for [`crate::kernel::events::integrate_system`]:
//! the kernel watches the gaps, locates impacts on this flow, applies the
//! impact map, sums chattering sequences and holds sticking pairs, whose
//! constrained system has its own modes (computed when first needed). Steps
//! are an eighth of the fastest period present, so that the kernel's cubic
//! check between step ends sees a gap dipping through zero and back within
//! one step (grazing). The energy accumulators (viscous loss, input work) are
//! integrated by 5-point Gauss-Legendre over each step, on the exact flow.

use crate::error::{Error, Result};
use crate::methods::matrix_flow::MatrixFlow;
use crate::methods::modal::Configuration;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{
    Assembly, InteractionLaw, LinearParts, Mode, Scratch, INPUT, VISCOUS,
};
use crate::model::contact::AnyLaw;
use crate::numerics::series::{exp, sin_cos};

mod from_rest;

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
    /// `constant / w2` (w2 > 0): the static response.
    offset: f64,
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
            offset: if w2 > 0.0 { constant / w2 } else { 0.0 },
        }
    }

    /// `e^(-sigma t) C(t)` and `e^(-sigma t) S(t)`, where `C' = disc S`,
    /// `S' = C`, `C(0) = 1`, `S(0) = 0`: the free response is
    /// `e^(-sigma t) (d0 C + (d0' + sigma d0) S)`.
    #[inline(always)]
    fn factors(&self, t: f64) -> (f64, f64) {
        if self.disc == 0.0 && self.sigma == 0.0 {
            // A free mass: the series below, exactly.
            return (1.0, t);
        }
        let z = self.disc * t * t;
        if z.abs() < 1e-3 {
            // Near critical damping (and for free masses): the series.
            let e = if self.sigma == 0.0 {
                1.0
            } else {
                exp(-self.sigma * t)
            };
            let c = 1.0 + z * (0.5 + z * (1.0 / 24.0 + z / 720.0));
            let s = t * (1.0 + z * (1.0 / 6.0 + z * (1.0 / 120.0 + z / 5040.0)));
            (e * c, e * s)
        } else if self.disc < 0.0 {
            let e = exp(-self.sigma * t);
            let (s, c) = sin_cos(self.root * t);
            (e * c, e * s / self.root)
        } else {
            // root <= sigma: neither exponential overflows.
            let a = ((self.root - self.sigma) * t).exp();
            let b = (-(self.root + self.sigma) * t).exp();
            (0.5 * (a + b), 0.5 * (a - b) / self.root)
        }
    }

    /// The factors at `a + b` from those at `a` and at `b` (the addition
    /// theorem of `C` and `S`; the exponentials multiply).
    #[inline(always)]
    fn sum(&self, a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
        (a.0 * b.0 + self.disc * a.1 * b.1, a.1 * b.0 + a.0 * b.1)
    }

    /// The factors at `a - b` from those at `a` and at `b`: those at `-b`
    /// are `(C, -S) / e^(-2 sigma b)`, and `C^2 - disc S^2 = 1`.
    #[inline(always)]
    fn difference(&self, a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
        let det = b.0 * b.0 - self.disc * b.1 * b.1;
        (
            (a.0 * b.0 - self.disc * a.1 * b.1) / det,
            (a.1 * b.0 - a.0 * b.1) / det,
        )
    }

    /// The constant force's particular response and its rate, `t` after the
    /// start of the flow.
    #[inline(always)]
    fn steady(&self, t: f64) -> (f64, f64) {
        if self.w2 > 0.0 {
            (self.offset, 0.0)
        } else if self.c > 0.0 {
            (self.constant * t / self.c, self.constant / self.c)
        } else {
            (0.5 * self.constant * t * t, self.constant * t)
        }
    }
}

/// Mode `j`'s coordinate and rate in the state `y` (`x` then `v`, `dim`
/// each).
#[inline(always)]
fn modal_state(cfg: &Configuration, dim: usize, j: usize, y: &[f64]) -> (f64, f64) {
    let row = &cfg.to_modal[j * dim..(j + 1) * dim];
    let (x, v) = (&y[..dim], &y[dim..2 * dim]);
    let (mut eta, mut rate) = (0.0, 0.0);
    for i in 0..dim {
        eta += row[i] * (x[i] - cfg.origin[i]);
        rate += row[i] * v[i];
    }
    (eta, rate)
}

/// What each interaction does in a configuration.
const OPEN: u8 = 0;
const STICKING: u8 = 1;
const TOUCHING: u8 = 2;

/// Whether `key` is the configuration of `modes`.
#[inline(always)]
fn fits(key: &[u8], modes: &[Mode]) -> bool {
    key.iter().zip(modes).all(|(s, mode)| *s == state_of(mode))
}

#[inline(always)]
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
    /// Whether the energies may come from the closed form over a stretch of
    /// steps ([`ExactFlow::step_energies`]): one harmonic at most, no mode
    /// near an undamped resonance.
    closed_form: bool,
    /// See [`near_resonance`].
    from_rest: Vec<bool>,
    /// An eighth of the configuration's fastest period (s).
    step: f64,
}

/// The largest `(w2 + omega^2) / |w2 - omega^2 + i c omega|` of a forced mode
/// for which its energies come from the closed form: that form divides the
/// ends' terms, of the size of the particular response `Z`, by the
/// denominator of `Z` again, so its round-off is `eps` of `(w2 + omega^2)
/// |Z|^2`, the square of this ratio times the forcing's own energy scale
/// `|P|^2 / (w2 + omega^2)`. Near an undamped resonance `Z` dwarfs the motion
/// (which grows from rest, or stays small against a stop), and the closed
/// form's input work drowned it (1 Hz, 1e-5 off, undamped: 7e-4 J where
/// the truth was 8e-9 J): the Gauss-Legendre powers on the flow take its
/// place, and the motion the response from rest ([`from_rest`]).
const CLOSED_FORM_AMPLIFICATION: f64 = 100.0;

/// Which harmonic `k` forces which mode `j` near its undamped resonance, at
/// `k * modes + j` (empty where none does): a forced mode whose amplification
/// passes [`CLOSED_FORM_AMPLIFICATION`] (an underdamped one: `c omega` is then
/// small against `w2 + omega^2`). Their energies come from the powers on the
/// flow, not the closed form, and their motion from the response from rest
/// ([`from_rest`]), not the particular response.
fn near_resonance(configuration: &Configuration, oscillators: &[Oscillator]) -> Vec<bool> {
    let r = configuration.modes;
    let mut near = vec![false; configuration.harmonics.len() * r];
    for (k, harmonic) in configuration.harmonics.iter().enumerate() {
        let w2 = harmonic.omega * harmonic.omega;
        for (j, (o, &(pr, pi))) in oscillators.iter().zip(&harmonic.force).enumerate() {
            let (dr, di) = (o.w2 - w2, o.c * harmonic.omega);
            near[k * r + j] = (pr != 0.0 || pi != 0.0)
                && o.disc < 0.0
                && o.w2 + w2 > CLOSED_FORM_AMPLIFICATION * dr.hypot(di);
        }
    }
    if !near.contains(&true) {
        near.clear();
    }
    near
}

/// `Re(P u0 G(t))` and its rate: mode `o`'s response from rest at `t` after
/// the start to the harmonic `Re(P e^(i omega t))` whose phasor there is
/// `(sin, cos)`, from the mode's factors at `t`.
#[inline(always)]
fn from_rest_part(
    o: &Oscillator,
    omega: f64,
    (pr, pi): (f64, f64),
    (s0, c0): (f64, f64),
    t: f64,
    factors: (f64, f64),
) -> (f64, f64) {
    let (g, rate) = from_rest::response(o.sigma, o.root, omega, t, factors);
    // P u0.
    let (ar, ai) = (pr * c0 - pi * s0, pr * s0 + pi * c0);
    (ar * g.0 - ai * g.1, ar * rate.0 - ai * rate.1)
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

/// The nodes as the midpoint less and plus these fractions of the step
/// (`0.5 - NODES[0]`, `0.5 - NODES[1]`).
const OFFSETS: [f64; 2] = [0.453_089_922_969_332, 0.269_234_655_052_841_55];

/// `(sin, cos)` of the sum and of the difference of two angles given theirs.
#[inline(always)]
fn turn_sum(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0 * b.1 + a.1 * b.0, a.1 * b.1 - a.0 * b.0)
}

#[inline(always)]
fn turn_difference(a: (f64, f64), b: (f64, f64)) -> (f64, f64) {
    (a.0 * b.1 - a.1 * b.0, a.1 * b.1 + a.0 * b.0)
}

/// Kept steps whose energy accumulators wait for one closed form over all of
/// them (they are one flow: no event between them): the modes, the time at
/// the first one's start and the first harmonic's phasor there, and the time
/// (bits) at the last one's end.
#[derive(Debug, Clone, Copy)]
struct Span {
    index: usize,
    time: f64,
    phasor: (f64, f64),
    end: u64,
}

/// The exact flow as a stepper.
#[derive(Debug, Clone)]
pub struct ExactFlow {
    parts: LinearParts,
    modes: Vec<Modes>,
    /// The index of the modes last selected.
    selected: usize,
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
    /// Per mode then node, the factors at the Gauss nodes of the step
    /// `finish` integrates; per harmonic then node, its turns there.
    node_modes: Vec<(f64, f64)>,
    node_turns: Vec<(f64, f64)>,
    /// The start last set: its time's bits and modes, and its state.
    begun: Option<(u64, usize)>,
    /// The modes and the time after the start of the last evaluation by
    /// the modes (`eta` and `rate` hold its increments), if it was the last.
    last: Option<(usize, f64)>,
    /// The steps whose energies are still to be added, and the modal state
    /// at their start.
    span: Option<Span>,
    span_modal: Vec<(f64, f64)>,
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
        let parts = Self::takes(system)?;
        let free = Self::modes_of(&parts, system, &vec![OPEN; system.interactions.len()])?;
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
                let from_rest = near_resonance(&configuration, &oscillators);
                Ok(Modes {
                    key: key.to_vec(),
                    closed_form: configuration.harmonics.len() <= 1 && from_rest.is_empty(),
                    from_rest,
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
                    closed_form: false,
                    from_rest: Vec::new(),
                })
            }
        }
    }

    /// The modes for the sticking interactions of `modes`, made when first met.
    #[inline(always)]
    fn select(&mut self, system: &Assembly, modes: &[Mode]) -> Result<usize> {
        // The modes of the last call, most often.
        if fits(&self.modes[self.selected].key, modes) {
            return Ok(self.selected);
        }
        self.select_other(system, modes)
    }

    #[cold]
    #[inline(never)]
    fn select_other(&mut self, system: &Assembly, modes: &[Mode]) -> Result<usize> {
        self.selected = match self.modes.iter().position(|m| fits(&m.key, modes)) {
            Some(index) => index,
            None => {
                let key: Vec<u8> = modes.iter().map(state_of).collect();
                let made = Self::modes_of(&self.parts, system, &key)?;
                self.modes.push(made);
                self.modes.len() - 1
            }
        };
        Ok(self.selected)
    }

    /// Set the flow's start at `time`, state `y`, in the modes `index`.
    #[inline(always)]
    fn begin(&mut self, index: usize, dim: usize, time: f64, y: &[f64]) {
        // Locating an event restarts from the same point many times.
        if self.begun != Some((time.to_bits(), index))
            || self.begun_state.iter().zip(y).any(|(b, v)| b != v)
        {
            self.begin_at(index, dim, time, y);
        }
    }

    #[inline(never)]
    fn begin_at(&mut self, index: usize, dim: usize, time: f64, y: &[f64]) {
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
    fn accelerations(&mut self, index: usize, dim: usize, out: &mut [f64]) {
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
        for (i, a) in out[..dim].iter_mut().enumerate() {
            let row = &cfg.to_coordinates[i * r..(i + 1) * r];
            *a = row.iter().zip(&self.eta[..r]).map(|(b, e)| b * e).sum();
        }
    }

    /// The accelerations and their rates at the last evaluation by the modes
    /// (see [`Self::at`]), into `accel` and `jerk`: each mode's `eta'' = F0 +
    /// f - w2 eta - c eta'` and `eta''' = f' - w2 eta' - c eta''`, taken to
    /// coordinates. False when the last evaluation was not by the modes.
    fn last_derivatives(&mut self, dim: usize, accel: &mut [f64], jerk: &mut [f64]) -> bool {
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
            let row = &cfg.to_coordinates[i * r..(i + 1) * r];
            let (mut x, mut y) = (0.0, 0.0);
            for k in 0..r {
                x += row[k] * a[k];
                y += row[k] * j[k];
            }
            accel[i] = x;
            jerk[i] = y;
        }
        true
    }

    /// The coordinates and velocities `t` after the start, into `out`.
    fn at(&mut self, index: usize, dim: usize, t: f64, out: &mut [f64]) {
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
    }

    /// The modal coordinates and rates `t` after the start, into `eta` and
    /// `rate`.
    fn modal_at(&mut self, index: usize, t: f64) {
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
            for ((e, v), &(zr, zi)) in eta.iter_mut().zip(rate.iter_mut()).zip(&h.response) {
                *e += zr * c - zi * s;
                *v -= h.omega * (zr * s + zi * c);
            }
        }
    }

    /// The harmonics' part of [`Self::modal_at`] where some force a mode near
    /// its resonance: those pairs by their response from rest (the start
    /// kept their particular response in, see [`Self::begin_at`]).
    #[cold]
    #[inline(never)]
    fn near_resonance_at(&mut self, index: usize, t: f64) {
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

    /// The viscous loss and the input work (J) over the step `h` from the
    /// start, in closed form from the modal states at its ends (one forcing
    /// harmonic at most). Each mode obeys `eta'' + c eta' + w2 eta = F0 +
    /// f(t)`, `f = Re(P u)`, `u = e^(i omega t)`, whose particular response
    /// is `Re(Z u)`; the rest `v` obeys `v'' + c v' + w2 v = F0`, so that
    /// integrating by parts twice gives `int u v' = (mu [u v'] + w2 [u v] -
    /// F0 [u]) / (mu^2 - c mu + w2)` (`mu = i omega`, `[.]` the change over
    /// the step), and `int f Re(Z u)'` is elementary. The viscous loss `c int
    /// eta'^2` is then the mode's input `int f eta'` plus `F0` times its
    /// displacement less the change of its energy `eta'^2 / 2 + w2 eta^2 / 2`.
    ///
    /// The start is `span_modal` with the first harmonic's phasor `phasor`
    /// there, `h` before `end`: any stretch of one flow.
    fn step_energies(
        &mut self,
        index: usize,
        dim: usize,
        h: f64,
        phasor: (f64, f64),
        end: &[f64],
    ) -> (f64, f64) {
        self.last = None;
        let m = &self.modes[index];
        let cfg = &m.configuration;
        // The modal state at the end, from the step's end.
        for j in 0..cfg.modes {
            (self.eta[j], self.rate[j]) = modal_state(cfg, dim, j, end);
        }
        let forcing = cfg.harmonics.first().map(|harmonic| {
            let (s0, c0) = phasor;
            let (st, ct) = sin_cos(harmonic.omega * h);
            // u at both ends as (Re, Im), and sin(omega h).
            let end = (c0 * ct - s0 * st, s0 * ct + c0 * st);
            (harmonic, (c0, s0), end, st)
        });
        let (mut viscous, mut input) = (0.0, 0.0);
        for (j, o) in m.oscillators.iter().enumerate() {
            let (eta0, rate0) = self.span_modal[j];
            let (eta1, rate1) = (self.eta[j], self.rate[j]);
            let mut work = 0.0;
            if let Some((harmonic, u0, u1, sin_turn)) = forcing {
                let w = harmonic.omega;
                let (zr, zi) = harmonic.response[j];
                let (pr, pi) = harmonic.force[j];
                // v and v' at an end: the particular response taken off.
                let rest = |(c, s): (f64, f64), eta: f64, rate: f64| {
                    (eta - (zr * c - zi * s), rate + w * (zr * s + zi * c))
                };
                let (v0, dv0) = rest(u0, eta0, rate0);
                let (v1, dv1) = rest(u1, eta1, rate1);
                // [u v'], [u v], [u].
                let (ar, ai) = (u1.0 * dv1 - u0.0 * dv0, u1.1 * dv1 - u0.1 * dv0);
                let (br, bi) = (u1.0 * v1 - u0.0 * v0, u1.1 * v1 - u0.1 * v0);
                let (gr, gi) = (u1.0 - u0.0, u1.1 - u0.1);
                let nr = -w * ai + o.w2 * br - o.constant * gr;
                let ni = w * ar + o.w2 * bi - o.constant * gi;
                let (dr, di) = (o.w2 - w * w, -o.c * w);
                let norm = dr * dr + di * di;
                let (jr, ji) = ((nr * dr + ni * di) / norm, (ni * dr - nr * di) / norm);
                work += pr * jr - pi * ji;
                // int Re(P u) Re(B u), B = i omega Z: half of Re(P conj(B)) h
                // plus half of Re(P B int u^2), int u^2 = u0 u1 sin(omega h) / omega.
                let (qr, qi) = (-w * zi, w * zr);
                let (er, ei) = (u0.0 * u1.0 - u0.1 * u1.1, u0.0 * u1.1 + u0.1 * u1.0);
                let (pqr, pqi) = (pr * qr - pi * qi, pr * qi + pi * qr);
                work += 0.5 * h * (pr * qr + pi * qi) + 0.5 * (pqr * er - pqi * ei) * sin_turn / w;
            }
            // A constant the excitations drive works on the mode too.
            input += work + cfg.driven[j] * (eta1 - eta0);
            if o.c > 0.0 {
                let (de, dr) = (eta1 - eta0, rate1 - rate0);
                let stored = 0.5 * dr * (rate1 + rate0) + 0.5 * o.w2 * de * (eta1 + eta0);
                viscous += o.constant * de + work - stored;
            }
        }
        (viscous, input)
    }

    /// The factors of the modes `index` at the Gauss nodes of a step `h`
    /// from a start, into `node_modes` and `node_turns`: three evaluations
    /// (the midpoint and the two offsets), the other two nodes by the
    /// addition theorems.
    fn node_factors(&mut self, index: usize, h: f64) {
        let m = &self.modes[index];
        let (mid, far, near) = (0.5 * h, OFFSETS[0] * h, OFFSETS[1] * h);
        let nodes = NODES.len();
        for (o, out) in m
            .oscillators
            .iter()
            .zip(self.node_modes.chunks_exact_mut(nodes))
        {
            let (at_mid, at_far, at_near) = (o.factors(mid), o.factors(far), o.factors(near));
            out[0] = o.difference(at_mid, at_far);
            out[1] = o.difference(at_mid, at_near);
            out[2] = at_mid;
            out[3] = o.sum(at_mid, at_near);
            out[4] = o.sum(at_mid, at_far);
        }
        for (h, out) in m
            .configuration
            .harmonics
            .iter()
            .zip(self.node_turns.chunks_exact_mut(nodes))
        {
            let at_mid = sin_cos(h.omega * mid);
            let (at_far, at_near) = (sin_cos(h.omega * far), sin_cos(h.omega * near));
            out[0] = turn_difference(at_mid, at_far);
            out[1] = turn_difference(at_mid, at_near);
            out[2] = at_mid;
            out[3] = turn_sum(at_mid, at_near);
            out[4] = turn_sum(at_mid, at_far);
        }
    }

    /// The viscous and the input power (W) at Gauss node `k` (`t` after the
    /// start; [`Self::node_factors`] made its factors): the modal rates
    /// only, without the coordinates (what the energy quadrature needs).
    fn powers_at(&mut self, index: usize, k: usize, t: f64) -> (f64, f64) {
        self.last = None;
        let m = &self.modes[index];
        let cfg = &m.configuration;
        let r = cfg.modes;
        let nodes = NODES.len();
        for (j, o) in m.oscillators.iter().enumerate() {
            let (d0, r0) = self.start[j];
            let (ec, es) = self.node_modes[nodes * j + k];
            self.rate[j] = ec * r0 - es * (o.sigma * r0 + o.w2 * d0) + o.steady(t).1;
        }
        // The rates take every harmonic's particular part before any
        // harmonic's power is taken from them.
        let turned = |n: usize, (s0, c0): (f64, f64)| {
            let (st, ct) = self.node_turns[nodes * n + k];
            (s0 * ct + c0 * st, c0 * ct - s0 * st)
        };
        for (n, (h, phasor)) in cfg.harmonics.iter().zip(&self.phasors).enumerate() {
            let (s, c) = turned(n, *phasor);
            for j in 0..r {
                if m.from_rest.get(n * r + j) == Some(&true) {
                    let o = &m.oscillators[j];
                    let factors = self.node_modes[nodes * j + k];
                    self.rate[j] += from_rest_part(o, h.omega, h.force[j], *phasor, t, factors).1;
                    continue;
                }
                let (zr, zi) = h.response[j];
                self.rate[j] -= h.omega * (zr * s + zi * c);
            }
        }
        let mut input = 0.0;
        for (n, (h, phasor)) in cfg.harmonics.iter().zip(&self.phasors).enumerate() {
            let (s, c) = turned(n, *phasor);
            for j in 0..r {
                let (pr, pi) = h.force[j];
                input += (pr * c - pi * s) * self.rate[j];
            }
        }
        for j in 0..r {
            input += cfg.driven[j] * self.rate[j];
        }
        // Mass-normalised modes with classical damping: the viscous power is
        // the sum of each mode's.
        let viscous: f64 = (0..r)
            .map(|j| m.oscillators[j].c * self.rate[j] * self.rate[j])
            .sum();
        (viscous, input)
    }
}

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
                if self.modes[index].matrix.is_some() {
                    system.rates(time, y, modes, scratch, &mut rates);
                } else {
                    self.begin(index, d, time, y);
                    self.accelerations(index, d, &mut rates[d..2 * d]);
                }
                evaluated = true;
            }
            if let Some(hit) = system.landing_time(i, y, &rates[d..2 * d]) {
                // The gap's parabola reaches the wall at `hit`: end the step a
                // little after it, so that the step's end sees the gap shut
                // even if the wall would draw away again later in the step.
                // Rebounds that come back sooner than the floor come back
                // within the next few steps, where their ends see them.
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
        for (o, v) in out[at..].iter_mut().zip(&y[at..]) {
            *o = *v;
        }
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
        settle: bool,
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
        if self.modes[index].closed_form {
            // The closed form holds over any stretch of one flow: the steps
            // between settlements share one (their accumulators stay those
            // at its start, in `y`, meanwhile).
            let continued = matches!(self.span, Some(span)
                if span.index == index && span.end == time.to_bits());
            if !continued {
                let r = self.modes[index].configuration.modes;
                self.span_modal[..r].copy_from_slice(&self.origin_modal[..r]);
                self.span = Some(Span {
                    index,
                    time,
                    phasor: self.phasors.first().copied().unwrap_or((0.0, 1.0)),
                    end: 0,
                });
            }
            let Some(span) = self.span.as_mut() else {
                unreachable!("a span was just begun")
            };
            if !settle {
                span.end = (time + h).to_bits();
                return Ok(());
            }
            let span = *span;
            self.span = None;
            let length = if continued { time + h - span.time } else { h };
            let (viscous, input) = self.step_energies(index, dim, length, span.phasor, end);
            end[at + VISCOUS] = y[at + VISCOUS] + viscous;
            end[at + INPUT] = y[at + INPUT] + input;
            return Ok(());
        }
        self.node_factors(index, h);
        let (mut viscous, mut input) = (0.0, 0.0);
        for (k, (x, w)) in NODES.iter().zip(WEIGHTS).enumerate() {
            let (v, i) = self.powers_at(index, k, x * h);
            viscous += w * v;
            input += w * i;
        }
        end[at + VISCOUS] = y[at + VISCOUS] + h * viscous;
        end[at + INPUT] = y[at + INPUT] + h * input;
        Ok(())
    }

    fn end_derivatives(&mut self, system: &Assembly, accel: &mut [f64], jerk: &mut [f64]) -> bool {
        self.last_derivatives(system.dim, accel, jerk)
    }

    fn accept(&mut self) {}

    fn shrink(&self, _error: f64) -> f64 {
        1.0
    }

    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::assembly::{initial_state, Damper, Excitation, Load, PairLaw, SystemSpec};
    use crate::model::signals::Signal;
    use crate::model::structure::Structure;

    #[test]
    fn nodes_by_the_addition_theorems_are_the_factors_there() {
        crate::testing::timeout(30, || {
            let h = 0.01;
            // Underdamped, near critical, overdamped, free, free and damped.
            for (w2, c) in [
                (4e3, 3.0),
                (400.0, 40.0),
                (100.0, 60.0),
                (0.0, 0.0),
                (0.0, 5.0),
            ] {
                let o = Oscillator::new(w2, c, 0.0);
                let (mid, far, near) = (
                    o.factors(0.5 * h),
                    o.factors(OFFSETS[0] * h),
                    o.factors(OFFSETS[1] * h),
                );
                let derived = [
                    o.difference(mid, far),
                    o.difference(mid, near),
                    mid,
                    o.sum(mid, near),
                    o.sum(mid, far),
                ];
                for (x, d) in NODES.iter().zip(derived) {
                    let direct = o.factors(x * h);
                    assert!(
                        (d.0 - direct.0).abs() <= 1e-15,
                        "{w2} {c}: {d:?} {direct:?}"
                    );
                    assert!(
                        (d.1 - direct.1).abs() <= 1e-15 * h,
                        "{w2} {c}: {d:?} {direct:?}"
                    );
                }
            }
        });
    }

    /// The forced damper (a structure and a loose mass, gravity), its flow
    /// started at a state in motion.
    fn forced_flow(damping: f64) -> (Assembly, ExactFlow, Vec<f64>) {
        let spec = SystemSpec {
            structure: Structure::oscillator(1.0, 3000.0, damping).unwrap(),
            dampers: vec![Damper {
                mass: 0.05,
                at: 0.0,
                lower_clearance: 0.01,
                upper_clearance: 0.01,
                law: PairLaw::rigid(0.6).unwrap(),
            }],
            stops: vec![],
            gravity: 9.81,
            excitations: vec![Excitation {
                load: Load::Force { at: 0.0 },
                signal: Signal::harmonic(20.0, 7.0, 0.3).unwrap(),
            }],
            points: vec![],
            moments: vec![],
        };
        let system = Assembly::new(&spec).unwrap();
        let y = initial_state(&system, &[0.004], &[-0.2], &[0.002], &[0.3]).unwrap();
        let flow = ExactFlow::new(&system).unwrap();
        (system, flow, y)
    }

    #[test]
    fn end_derivatives_are_the_system_s_accelerations_and_their_rates() {
        crate::testing::timeout(30, || {
            for damping in [3.0, 200.0] {
                let (system, mut flow, y) = forced_flow(damping);
                let (dim, len) = (system.dim, system.state_len());
                let modes = vec![Mode::Open; system.interactions.len()];
                let mut scratch = Scratch::new(&system);
                let (mut end, mut rates) = (vec![0.0; len], vec![0.0; len]);
                let (mut accel, mut jerk) = (vec![0.0; dim], vec![0.0; dim]);
                let (time, h) = (0.37, 0.6 * flow.step());
                // The accelerations at `t` after the start, by the system.
                let mut accelerations = |flow: &mut ExactFlow, t: f64| {
                    flow.attempt(&system, time, &y, t, &modes, &mut scratch, &mut end)
                        .unwrap();
                    system.rates(time + t, &end, &modes, &mut scratch, &mut rates);
                    rates[dim..2 * dim].to_vec()
                };
                let expected = accelerations(&mut flow, h);
                assert!(flow.end_derivatives(&system, &mut accel, &mut jerk));
                let delta = 1e-5 * h;
                let (ahead, behind) = (
                    accelerations(&mut flow, h + delta),
                    accelerations(&mut flow, h - delta),
                );
                for i in 0..dim {
                    let scale = expected.iter().fold(0.0f64, |m, a| m.max(a.abs()));
                    assert!(
                        (accel[i] - expected[i]).abs() <= 1e-12 * scale,
                        "{damping}: {accel:?} {expected:?}"
                    );
                    let difference = (ahead[i] - behind[i]) / (2.0 * delta);
                    let jerk_scale = jerk.iter().fold(0.0f64, |m, a| m.max(a.abs()));
                    assert!(
                        (jerk[i] - difference).abs() <= 1e-6 * jerk_scale,
                        "{damping}: {jerk:?} {difference}"
                    );
                }
                // Only for the last evaluation, once.
                assert!(flow.end_derivatives(&system, &mut accel, &mut jerk));
                assert!(!flow.end_derivatives(&system, &mut accel, &mut jerk));
            }
        });
    }

    #[test]
    fn energies_left_to_a_later_step_are_the_steps_own_sum() {
        crate::testing::timeout(30, || {
            for damping in [3.0, 200.0] {
                let (system, mut flow, y0) = forced_flow(damping);
                let (at, len) = (2 * system.dim, system.state_len());
                let modes = vec![Mode::Open; system.interactions.len()];
                let mut scratch = Scratch::new(&system);
                let h = 0.7 * flow.step();
                // Seven steps, settled every step or at the third and the last.
                let mut run = |settle_at: &dyn Fn(usize) -> bool| {
                    let (mut y, mut end) = (y0.clone(), vec![0.0; len]);
                    let mut time = 0.25;
                    for k in 0..7 {
                        flow.attempt(&system, time, &y, h, &modes, &mut scratch, &mut end)
                            .unwrap();
                        flow.finish(
                            &system,
                            time,
                            &y,
                            h,
                            &modes,
                            &mut scratch,
                            &mut end,
                            settle_at(k),
                        )
                        .unwrap();
                        if !settle_at(k) {
                            assert_eq!(end[at..], y[at..], "left as they were");
                        }
                        std::mem::swap(&mut y, &mut end);
                        time += h;
                    }
                    y
                };
                let each = run(&|_| true);
                let later = run(&|k| k == 2 || k == 6);
                assert_eq!(each[..at], later[..at]);
                for k in at..len {
                    let scale = each[k].abs().max(1e-300);
                    assert!(
                        (each[k] - later[k]).abs() <= 1e-12 * scale,
                        "{damping}: {each:?} {later:?}"
                    );
                }
                assert!(each[at..].iter().any(|e| e.abs() > 0.0));
            }
        });
    }

    #[test]
    fn near_an_undamped_resonance_the_state_and_its_input_work_keep_their_digits() {
        crate::testing::timeout(30, || {
            // 1 Hz forcing 1e-5 below an undamped mode (issue 23): the
            // particular response is 1.2e4 m, the motion from rest 0.4 m/s
            // a second. Without losses the work put in is the energy stored.
            let spec = SystemSpec {
                structure: Structure::oscillator(1.0, 39.478, 0.0).unwrap(),
                dampers: vec![],
                stops: vec![],
                gravity: 0.0,
                excitations: vec![Excitation {
                    load: Load::Force { at: 0.0 },
                    signal: Signal::harmonic(5.0, 1.0, 0.0).unwrap(),
                }],
                points: vec![],
                moments: vec![],
            };
            let system = Assembly::new(&spec).unwrap();
            let mut flow = ExactFlow::new(&system).unwrap();
            let (at, len) = (2 * system.dim, system.state_len());
            let modes = vec![Mode::Open; system.interactions.len()];
            let mut scratch = Scratch::new(&system);
            let (mut y, mut end) = (vec![0.0; len], vec![0.0; len]);
            let (h, mut time) = (1e-3, 0.0);
            for k in 0..2000 {
                flow.attempt(&system, time, &y, h, &modes, &mut scratch, &mut end)
                    .unwrap();
                let settle = k % 32 == 31;
                flow.finish(&system, time, &y, h, &modes, &mut scratch, &mut end, settle)
                    .unwrap();
                std::mem::swap(&mut y, &mut end);
                time += h;
            }
            // Undamped from rest: x = Z (cos W t - cos w t), Z = P / (w^2 - W^2),
            // as a product that divides nothing small.
            let (w, forcing) = (39.478f64.sqrt(), std::f64::consts::TAU);
            let (sum, difference) = (0.5 * (w + forcing), 0.5 * (w - forcing));
            let x = 5.0 / (2.0 * sum * difference) * (sum * time).sin() * (difference * time).sin();
            // The motion is 0.8 m at most and the particular response 1.2e4 m:
            // its round-off (eps of it a step) had been 1e-10 m after these
            // 2000 steps.
            assert!((y[0] - x).abs() <= 2e-12, "{} {x}", y[0]);
            let stored = system.energy(&y, &modes);
            assert!(stored > 0.1, "{stored}");
            // Round-off of the flow's states (eps of the particular response
            // a step) bounds the miss, not the closed form's 1e-5 J a stretch.
            assert!(
                (y[at + INPUT] - stored).abs() <= 1e-9 * stored,
                "{} {stored}",
                y[at + INPUT]
            );
        });
    }

    #[test]
    fn closed_form_step_energies_are_the_gauss_legendre_quadrature_s() {
        crate::testing::timeout(30, || {
            for damping in [3.0, 200.0] {
                let (system, mut flow, y) = forced_flow(damping);
                let dim = system.dim;
                let modes = vec![Mode::Open; system.interactions.len()];
                let index = flow.select(&system, &modes).unwrap();
                let mut end = vec![0.0; system.state_len()];
                for (time, h) in [(0.0, flow.step()), (1.37, 0.3 * flow.step()), (2.0, 1e-6)] {
                    flow.begin(index, dim, time, &y);
                    flow.at(index, dim, h, &mut end);
                    let r = flow.modes[index].configuration.modes;
                    flow.span_modal[..r].copy_from_slice(&flow.origin_modal[..r]);
                    let phasor = flow.phasors[0];
                    let (viscous, input) = flow.step_energies(index, dim, h, phasor, &end);
                    flow.node_factors(index, h);
                    let (mut v, mut i) = (0.0, 0.0);
                    for (k, (x, w)) in NODES.iter().zip(WEIGHTS).enumerate() {
                        let (pv, pi) = flow.powers_at(index, k, x * h);
                        v += w * h * pv;
                        i += w * h * pi;
                    }
                    let scale = v.abs().max(i.abs());
                    assert!(
                        (viscous - v).abs() <= 1e-10 * scale,
                        "{damping} {h}: {viscous} {v}"
                    );
                    assert!(
                        (input - i).abs() <= 1e-10 * scale,
                        "{damping} {h}: {input} {i}"
                    );
                }
            }
        });
    }
}
