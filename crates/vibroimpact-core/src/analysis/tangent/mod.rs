//! The tangent (variational) flow along a run: the derivative of the state
//! at the run's end with respect to the state at its start, carried through
//! every event by its saltation matrix.
//!
//! Between two events the modes are fixed and a linear structure with rigid
//! pairs is a linear system, `y' = A y + b(t)` (`A` from
//! [`Assembly::acceleration_jacobian`], with sticking pairs' constraints
//! projected out), so the flow's derivative over `tau` s is `e^(A tau)`,
//! exact. At an event with reset map `R` (the impulses of the rigid pairs
//! the event's complementarity problem made active, each resolved to its own
//! restitution) the derivative jumps by the saltation matrix
//!
//! `S = R + (f+ - R f-) grad(g)^T / (grad(g) . f-)`
//!
//! (`g` the located pair's gap, `f-` and `f+` the rates just before and
//! after). An impact with restitution `e` multiplies phase-space volume by
//! `e^2`; a pair that starts to stick collapses it (its gap and rate are
//! lost); a release is smooth (the constraint force is zero there: `S = I`).
//! A pair arriving at a speed of round-off and leaving again is a grazing,
//! where the flow has no derivative: it is counted and reported
//! ([`Tangent::grazings`]), never differentiated through silently.
//!
//! While a compliant contact is on, the flow is not linear: each of the
//! method's steps is carried by the variational equations with the laws'
//! exact slopes ([`contact`]); its onset and separation are events whose
//! saltation holds the jump of the rates (none for Hertz, whose force is
//! zero at zero indentation; a contact damper's `c g'` for the others).
//!
//! Where asked, the flow also carries the state's derivatives by
//! parameters ([`parameters`]): `W' = J W + df/dp` over every step, and
//! `W+ = S W- + s` at each event, `s` the saltation's moved terms.
//!
//! The flow is told of events by the one kernel
//! ([`crate::kernel::observe`]); by concern: this product, the saltation
//! ([`saltation`]), the Lyapunov exponents ([`lyapunov`]).

mod contact;
#[cfg(test)]
mod friction_tests;
mod latched;
mod lyapunov;
#[cfg(test)]
mod parameter_tests;
mod parameters;
mod saltation;
#[cfg(test)]
mod tests;

pub use lyapunov::{lyapunov_blocks, LyapunovSpectrum};
pub use parameters::Shifted;

use crate::error::Result;
use crate::kernel::observe::{EventObserver, EventView};
use crate::model::assembly::{Assembly, InteractionLaw, Mode, Scratch};
use crate::numerics::linalg;
use contact::{ContactSteps, Extra, Source};
use latched::{Latched, OnsetRow};
use parameters::Parameters;
use saltation::Saltation;

/// A grazing met along the run: a pair that touched its wall at a speed of
/// round-off and left it again.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grazing {
    /// s.
    pub time: f64,
    pub interaction: usize,
    /// Its pair (index into [`Assembly::pairs`]).
    pub pair: usize,
    /// The closing speed, m/s (of round-off).
    pub speed: f64,
}

/// Whether a compliant contact is on: the flow is then not linear, and is
/// carried step by step ([`ContactSteps`]).
fn in_contact(modes: &[Mode]) -> bool {
    modes.iter().any(|m| matches!(m, Mode::Compliant { .. }))
}

/// What the flow does with each factor of the tangent map.
#[derive(Debug, Clone, PartialEq)]
enum Keep {
    /// The product: the derivative of the end state by the start state.
    Product,
    /// Re-orthonormalised after each event (Benettin's QR): the sum of the
    /// logarithms of the stretches of each direction. (Every 16 events
    /// instead, the saltations' shears had made the columns parallel to
    /// round-off between two QRs: a forced damper's sum of exponents was 12
    /// times too small.)
    Orthonormal { logs: Vec<f64> },
}

/// The tangent flow along a run: an [`EventObserver`] for
/// [`crate::kernel::events::integrate_system_observed`].
pub struct Tangent<'s> {
    system: &'s Assembly,
    /// `2 dim`.
    size: usize,
    /// The product so far (row-major `size x size`), or its orthonormal
    /// factor.
    matrix: Vec<f64>,
    keep: Keep,
    /// The start of the current smooth stretch (s) and its modes.
    since: f64,
    modes: Vec<Mode>,
    /// The linear flow's matrix `A` of each set of modes met, and the
    /// factors a second of it needs where orthonormalised ([`qr_rate`]).
    flows: Vec<(Vec<u8>, Vec<f64>, f64)>,
    saltation: Saltation,
    /// The steps while a compliant contact is on, or every step where the
    /// parameters' columns are carried (None: neither).
    contact: Option<ContactSteps>,
    /// The derivatives by parameters, where asked.
    parameters: Option<Parameters>,
    /// A step's extra columns (the latched gain, then the parameters'), or
    /// an event's saltation terms by the parameters; and the event's new
    /// parameter columns, kept aside until its latched rates are read.
    extra: Vec<f64>,
    moved: Vec<f64>,
    /// The hysteretic laws' latched rates (None: no law latches).
    latched: Option<Latched>,
    expm: linalg::Expm,
    factor: Vec<f64>,
    /// The stretch's flow before an event's saltation.
    stretch: Vec<f64>,
    product: Vec<f64>,
    grazings: Vec<Grazing>,
    /// Events whose impulses acted, or where a compliant contact began.
    impacts: u64,
    /// The time from which the flow is carried (s): events before it only
    /// set the modes.
    from: f64,
}

/// The most the directions' growths may differ by within one factor of an
/// orthonormalised flow, as a power of e: the slowest direction then keeps
/// all but about `QR_SPREAD / ln 10` (3.5) of its digits.
const QR_SPREAD: f64 = 8.0;

/// The most any direction may grow or shrink within one factor, as a power
/// of e: its column's squared norm stays far inside the doubles' range
/// (`e^-400`, 100 s of a -4/s decay, squared to zero).
const QR_GROWTH: f64 = 64.0;

/// How many factors a second of the flow of `a` (row-major `size x size`)
/// needs for [`QR_SPREAD`] and [`QR_GROWTH`] (1/s), from its eigenvalues'
/// real parts; where they are not found, from a bound of every `|lambda|`
/// (the largest row sum of `|a|`).
fn qr_rate(a: &[f64], size: usize) -> f64 {
    let (low, high) = match linalg::eigenvalues(a, size) {
        Some(values) => values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &(re, _)| {
                (l.min(re), h.max(re))
            }),
        None => {
            let bound = a
                .chunks(size)
                .map(|row| row.iter().map(|v| v.abs()).sum::<f64>())
                .fold(0.0, f64::max);
            (-bound, bound)
        }
    };
    ((high - low) / QR_SPREAD).max(low.abs().max(high.abs()) / QR_GROWTH)
}

/// The key of a set of modes: the flow's matrix depends on which
/// constraints hold (pairs sticking, friction elements stuck on rows no
/// pair holds), nothing else (every pair is rigid; a sliding element's
/// force is a constant load).
fn key(modes: &[Mode]) -> impl Iterator<Item = u8> + '_ {
    modes.iter().map(|m| {
        u8::from(matches!(
            m,
            Mode::Sticking
                | Mode::Stuck {
                    shadowed: false,
                    ..
                }
        ))
    })
}

impl<'s> Tangent<'s> {
    /// The product of the tangent map (the derivative of the end state by
    /// the start state), from the identity.
    pub fn product(system: &'s Assembly) -> Result<Self> {
        Self::new(system, Keep::Product)
    }

    /// The tangent map re-orthonormalised at each event, for Lyapunov
    /// exponents ([`Self::logs`]).
    pub fn orthonormal(system: &'s Assembly) -> Result<Self> {
        let logs = vec![0.0; 2 * system.dim];
        Self::new(system, Keep::Orthonormal { logs })
    }

    fn new(system: &'s Assembly, keep: Keep) -> Result<Self> {
        let size = 2 * system.dim;
        let mut matrix = vec![0.0; size * size];
        for i in 0..size {
            matrix[i * size + i] = 1.0;
        }
        Ok(Self {
            system,
            size,
            matrix,
            keep,
            since: 0.0,
            modes: vec![Mode::Open; system.interactions.len()],
            flows: Vec::new(),
            saltation: Saltation::new(system),
            contact: system
                .interactions
                .iter()
                .any(|it| matches!(it.law, InteractionLaw::Compliant { .. }))
                .then(|| ContactSteps::new(system)),
            latched: Latched::new(system),
            parameters: None,
            extra: Vec::new(),
            moved: Vec::new(),
            expm: linalg::Expm::new(size),
            factor: vec![0.0; size * size],
            stretch: vec![0.0; size * size],
            product: vec![0.0; size * size],
            grazings: Vec::new(),
            impacts: 0,
            from: f64::NEG_INFINITY,
        })
    }

    /// The product carrying, beside the map, the derivatives of the state
    /// by each parameter of `shifted` (its system made at `p +- delta`):
    /// see [`Self::parameter_columns`]. Refused where a shifted system
    /// differs in shape from `system`.
    pub fn with_parameters(system: &'s Assembly, shifted: Vec<Shifted>) -> Result<Self> {
        let mut flow = Self::product(system)?;
        if !shifted.is_empty() {
            flow.parameters = Some(Parameters::new(system, shifted)?);
            flow.contact
                .get_or_insert_with(|| ContactSteps::new(system));
        }
        Ok(flow)
    }

    /// The derivatives of the end state by the parameters (row-major `2 dim
    /// x m`, `x` then `v`; empty where none was asked), at a fixed time:
    /// a parameter that also moves the run's end (a forcing frequency, its
    /// period) adds the end's rate times that move.
    pub fn parameter_columns(&self) -> &[f64] {
        self.parameters.as_ref().map_or(&[], |p| &p.columns)
    }

    /// The flow carried from `time` (s) on, not from the run's start: the
    /// derivative of the end state by the state at `time` (a study's
    /// recorded window, after its settling).
    pub fn from_time(mut self, time: f64) -> Self {
        self.from = time;
        self
    }

    /// The derivative of the end state by the start state (row-major `2 dim
    /// x 2 dim`, `x` then `v`); for an orthonormalised flow, its orthonormal
    /// factor.
    pub fn matrix(&self) -> &[f64] {
        &self.matrix
    }

    /// The sums of the logarithms of each direction's stretches so far (an
    /// orthonormalised flow; empty for a product).
    pub fn logs(&self) -> &[f64] {
        match &self.keep {
            Keep::Orthonormal { logs } => logs,
            Keep::Product => &[],
        }
    }

    /// The grazings met (where the flow has no derivative).
    pub fn grazings(&self) -> &[Grazing] {
        &self.grazings
    }

    /// The modes of the stretch the flow is in (at a run's end, its last).
    pub fn modes(&self) -> &[Mode] {
        &self.modes
    }

    /// Events whose impulses acted, or where a compliant contact began.
    pub fn impacts(&self) -> u64 {
        self.impacts
    }

    /// The linear flow's matrix in `modes` (made once per set of modes).
    fn flow_matrix(&mut self, modes: &[Mode]) -> usize {
        if let Some(found) = self
            .flows
            .iter()
            .position(|(k, _, _)| k.iter().copied().eq(key(modes)))
        {
            return found;
        }
        let (d, size) = (self.system.dim, self.size);
        let mut scratch = Scratch::new(self.system);
        let y = vec![0.0; self.system.state_len()];
        let (mut dadx, mut dadv) = (vec![0.0; d * d], vec![0.0; d * d]);
        let mut a = vec![0.0; size * size];
        self.system.flow_jacobian(
            (&y, modes, false),
            &mut scratch,
            (&mut dadx, &mut dadv),
            &mut a,
        );
        let rate = qr_rate(&a, size);
        self.flows.push((key(modes).collect(), a, rate));
        self.flows.len() - 1
    }

    /// For the orthonormalised flow, the smooth stretch from `self.since` to
    /// `time` carried but for its last piece, in pieces short enough that
    /// the directions' growths differ by at most `e^QR_SPREAD` within one,
    /// and none grows or shrinks by more than `e^QR_GROWTH` (each piece
    /// re-orthonormalised): over a long stretch one factor `e^(A tau)` maps
    /// every direction onto the fastest-growing one, to round-off, and the
    /// slower ones' exponents are lost (a two-mode structure without an
    /// impact for 100 s gave -2.4/s for its -13.1/s), or underflows (a
    /// linear oscillator's -4/s gave minus infinity).
    /// `self.since` moves to the last piece's start.
    fn carry_long(&mut self, time: f64) {
        if !matches!(self.keep, Keep::Orthonormal { .. }) {
            return;
        }
        let tau = time - self.since;
        let modes = std::mem::take(&mut self.modes);
        let slot = self.flow_matrix(&modes);
        self.modes = modes;
        let pieces = (self.flows[slot].2 * tau).ceil();
        // (NaN, a rate not found, is one piece.)
        if pieces.is_nan() || pieces <= 1.0 {
            return;
        }
        // At most the stretch's time over the fastest decay's, which the
        // run's steps are already shorter than; bounded all the same (each
        // piece is a product and a QR, with no poll for an interrupt here).
        let pieces = pieces.min(1e6);
        let piece = tau / pieces;
        self.expm
            .compute(&self.flows[slot].1, piece, &mut self.factor);
        for _ in 1..pieces as u64 {
            self.apply(false);
        }
        self.since = time - piece;
    }

    /// The smooth flow from `self.since` to `time` in the current modes,
    /// into `self.factor`.
    fn smooth(&mut self, time: f64) {
        let tau = time - self.since;
        let modes = std::mem::take(&mut self.modes);
        let slot = self.flow_matrix(&modes);
        self.modes = modes;
        self.expm
            .compute(&self.flows[slot].1, tau, &mut self.factor);
    }

    /// `matrix <- factor matrix` (plus the step's gain by the latched rates,
    /// `with_gain`), then re-orthonormalised where asked.
    fn apply(&mut self, with_gain: bool) {
        linalg::matmul(&self.factor, &self.matrix, &mut self.product, self.size);
        if let (true, Some(latched)) = (with_gain, self.latched.as_ref()) {
            latched.add_gain(&mut self.product, self.size);
        }
        std::mem::swap(&mut self.matrix, &mut self.product);
        if let Keep::Orthonormal { logs } = &mut self.keep {
            let extra = match self.latched.as_mut() {
                Some(latched) => &mut latched.rows[..],
                None => &mut [][..],
            };
            lyapunov::orthonormalise(&mut self.matrix, self.size, logs, extra);
        }
    }

    /// The latched rates' rows at an event: set at a latching contact's
    /// onset (from the state's derivative just before it: the stretch's
    /// flow times the matrix), cleared at its separation. An onset whose
    /// rate is neither its closing speed nor its law's floor has no
    /// derivative: counted with the grazings.
    fn latch(&mut self, view: &EventView<'_>, stretch: bool) {
        let Some(latched) = self.latched.as_mut() else {
            return;
        };
        let size = self.size;
        let mut parameters = self.parameters.as_mut();
        for i in 0..view.modes_after.len() {
            if !latched.which[i] {
                continue;
            }
            match (view.modes_before[i], view.modes_after[i]) {
                (Mode::Open, Mode::Compliant { approach_rate, .. }) => {
                    let event = (view.time, view.before, view.modes_before);
                    let flow = stretch.then_some(&self.stretch[..]);
                    let found =
                        latched.onset(self.system, event, i, approach_rate, flow, &self.matrix);
                    if let Some(p) = parameters.as_deref_mut() {
                        let defined = found != OnsetRow::Undefined;
                        p.onset(i, event, defined.then_some((&*latched, found)));
                    }
                    if found == OnsetRow::Undefined {
                        self.grazings.push(Grazing {
                            time: view.time,
                            interaction: i,
                            pair: self.system.interactions[i].pair,
                            speed: -linalg::dot(
                                &self.system.interactions[i].h,
                                &view.before[size / 2..size],
                            ),
                        });
                    }
                }
                (Mode::Compliant { .. }, Mode::Open) => {
                    latched.separation(i, size);
                    if let Some(p) = parameters.as_deref_mut() {
                        p.onset(i, (view.time, view.before, view.modes_before), None);
                    }
                }
                _ => {}
            }
        }
    }
}

impl EventObserver for Tangent<'_> {
    fn start(&mut self, time: f64, y: &[f64], modes: &[Mode]) -> Result<()> {
        self.since = time.max(self.from);
        self.modes.copy_from_slice(modes);
        if time >= self.from {
            self.saltation
                .start_in(self.system, modes, &mut self.matrix);
        }
        if let Some(latched) = self.latched.as_mut() {
            // Carried from the start: a resumed contact's rate is the
            // state's; from later, the state there does not set it.
            latched.resume(self.system, y, modes);
            if self.from > time {
                latched.rows.iter_mut().for_each(|v| *v = 0.0);
            }
        }
        if let Some(p) = self.parameters.as_mut() {
            p.latched.iter_mut().for_each(|v| *v = 0.0);
        }
        Ok(())
    }

    fn event(&mut self, view: &EventView<'_>) -> Result<()> {
        if view.time <= self.from {
            self.modes.copy_from_slice(view.modes_after);
            return Ok(());
        }
        // The modes before the event are the stretch's (the kernel switches
        // modes only at events).
        self.modes.copy_from_slice(view.modes_before);
        // The stretch's flow, then the event's saltation: one factor (one QR).
        // (In contact, the steps carried the stretch.)
        let stretch = view.time > self.since && !in_contact(&self.modes);
        if stretch {
            self.carry_long(view.time);
            self.smooth(view.time);
            std::mem::swap(&mut self.factor, &mut self.stretch);
        }
        let outcome = self.saltation.matrix(self.system, view, &mut self.factor);
        if let Some(p) = self.parameters.as_ref() {
            // W+ = S W- + s, kept aside: an onset's latched rate reads W-.
            let (size, m) = (self.size, p.count());
            self.moved.resize(size * m, 0.0);
            self.extra.resize(size * m, 0.0);
            self.saltation
                .parameter_columns(self.system, p, view, &mut self.extra);
            linalg::matmul_rect(&self.factor, &p.columns, &mut self.moved, size, m);
            for (value, s) in self.moved.iter_mut().zip(&self.extra) {
                *value += s;
            }
        }

        if stretch {
            linalg::matmul(&self.factor, &self.stretch, &mut self.product, self.size);
            std::mem::swap(&mut self.factor, &mut self.product);
        }
        if let Some(speed) = outcome.grazing {
            self.grazings.push(Grazing {
                time: view.time,
                interaction: view.located,
                pair: self.system.interactions[view.located].pair,
                speed,
            });
        }
        let onset = view
            .modes_before
            .iter()
            .zip(view.modes_after)
            .any(|(b, a)| *b == Mode::Open && matches!(a, Mode::Compliant { .. }));
        // Impacts as the run records them: a pair that lands at rest (a
        // stick carried across a block's cut, found again at its start) or
        // is held by the others' impulses did not strike.
        let struck = view.jumps.iter().any(|j| j.struck);
        self.impacts += u64::from(struck || onset);
        self.latch(view, stretch);
        if let Some(p) = self.parameters.as_mut() {
            std::mem::swap(&mut p.columns, &mut self.moved);
        }
        self.apply(false);
        self.since = view.time;
        self.modes.copy_from_slice(view.modes_after);
        Ok(())
    }

    fn wants_steps(&self) -> bool {
        self.contact.is_some()
    }

    /// A step while a compliant contact is on: its factor from the
    /// variational equations ([`ContactSteps`]); other steps are linear,
    /// carried whole at the events. Every step carries the parameters'
    /// columns, where asked.
    fn step(&mut self, t0: f64, y0: &[f64], t1: f64, y1: &[f64], modes: &[Mode]) -> Result<()> {
        let on = in_contact(modes);
        if t1 <= t0 || !(on || self.parameters.is_some()) {
            return Ok(());
        }
        if t0 < self.from {
            // Before the flow is carried (a study's settling): a step across
            // its start starts it at the step's end.
            if on {
                self.since = self.since.max(t1);
            }
            return Ok(());
        }
        let Some(contact) = self.contact.as_mut() else {
            return Ok(());
        };
        let size = self.size;
        let gains = match (on, self.latched.as_ref()) {
            (true, Some(latched)) => latched.which.len(),
            _ => 0,
        };
        let m = self.parameters.as_ref().map_or(0, |p| p.count());
        let columns = gains + m;
        self.extra.resize(size * columns, 0.0);
        if let Some(p) = self.parameters.as_ref() {
            for r in 0..size {
                let row = &mut self.extra[r * columns..(r + 1) * columns];
                row[..gains].iter_mut().for_each(|v| *v = 0.0);
                row[gains..].copy_from_slice(&p.columns[r * m..(r + 1) * m]);
            }
        } else {
            self.extra.iter_mut().for_each(|v| *v = 0.0);
        }
        let mut sources = Sources {
            which: self
                .latched
                .as_ref()
                .filter(|_| gains > 0)
                .map(|l| &l.which[..]),
            parameters: self.parameters.as_mut(),
            columns,
        };
        let extra = (columns > 0).then(|| Extra {
            values: &mut self.extra,
            columns,
            source: &mut sources,
        });
        let out = on.then_some(&mut self.factor[..]);
        contact.factor(self.system, (t0, y0), (t1, y1), modes, out, extra);
        for r in 0..size {
            let row = &self.extra[r * columns..(r + 1) * columns];
            if let Some(latched) = self.latched.as_mut().filter(|_| gains > 0) {
                latched.gain[r * gains..(r + 1) * gains].copy_from_slice(&row[..gains]);
            }
            if let Some(p) = self.parameters.as_mut() {
                p.columns[r * m..(r + 1) * m].copy_from_slice(&row[gains..]);
            }
        }
        if on {
            self.apply(gains > 0);
            self.since = t1;
        }
        Ok(())
    }

    fn finish(&mut self, time: f64, _y: &[f64], modes: &[Mode]) -> Result<()> {
        if time > self.since && !in_contact(&self.modes) {
            self.carry_long(time);
            self.smooth(time);
            self.apply(false);
        }
        self.since = time;
        self.modes.copy_from_slice(modes);
        Ok(())
    }
}

/// The extra columns' `B` over a step: the latched rates' gain (a column
/// per interaction, `M^-1 h^T dF/dv0` where it latches), then each
/// parameter's `df/dp` plus the gain times its latched rates' derivatives.
struct Sources<'a> {
    which: Option<&'a [bool]>,
    parameters: Option<&'a mut Parameters>,
    columns: usize,
}

impl Source for Sources<'_> {
    fn add(&mut self, system: &Assembly, time: f64, y: &[f64], modes: &[Mode], out: &mut [f64]) {
        let (d, columns) = (system.dim, self.columns);
        let gains = self.which.map_or(0, <[bool]>::len);
        if let Some(which) = self.which {
            for (i, (&latches, &mode)) in which.iter().zip(modes).enumerate() {
                let by_rate = if latches {
                    Latched::force_by_rate(system, i, y, mode)
                } else {
                    0.0
                };
                if by_rate == 0.0 {
                    continue;
                }
                let m = columns - gains;
                for (r, p) in system.interactions()[i].push.iter().enumerate() {
                    let row = &mut out[(d + r) * columns..(d + r + 1) * columns];
                    row[i] += p * by_rate;
                    if let Some(parameters) = self.parameters.as_deref() {
                        let rates = &parameters.latched[i * m..(i + 1) * m];
                        for (value, l) in row[gains..].iter_mut().zip(rates) {
                            *value += p * by_rate * l;
                        }
                    }
                }
            }
        }
        if let Some(parameters) = self.parameters.as_deref_mut() {
            parameters.add_field(system, time, y, modes, out, (gains, columns));
        }
    }
}
