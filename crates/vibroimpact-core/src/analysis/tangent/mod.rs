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
//! The flow is told of events by the one kernel
//! ([`crate::kernel::observe`]); by concern: this product, the saltation
//! ([`saltation`]), the Lyapunov exponents ([`lyapunov`]).

mod contact;
mod latched;
mod lyapunov;
mod saltation;
#[cfg(test)]
mod tests;

pub use lyapunov::{lyapunov_blocks, LyapunovSpectrum};

use crate::error::Result;
use crate::kernel::observe::{EventObserver, EventView};
use crate::model::assembly::{Assembly, InteractionLaw, Mode, Scratch};
use crate::numerics::linalg;
use contact::{ContactSteps, Gain};
use latched::Latched;
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

/// Whether `system`'s tangent flow can be made: every pair's law has one
/// (rigid, and every compliant law, the hysteretic ones' latched approach
/// rates carried as rows, [`latched`]). An error would name the first pair
/// whose law has none, and what to do instead.
pub fn check(_system: &Assembly) -> Result<()> {
    Ok(())
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
    /// The linear flow's matrix `A` of each set of modes met.
    flows: Vec<(Vec<u8>, Vec<f64>)>,
    saltation: Saltation,
    /// The steps while a compliant contact is on (None: every pair rigid).
    contact: Option<ContactSteps>,
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

/// The key of a set of modes: the flow's matrix depends on which pairs
/// stick, nothing else (every pair is rigid).
fn key(modes: &[Mode]) -> impl Iterator<Item = u8> + '_ {
    modes.iter().map(|m| u8::from(*m == Mode::Sticking))
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
        check(system)?;
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
            expm: linalg::Expm::new(size),
            factor: vec![0.0; size * size],
            stretch: vec![0.0; size * size],
            product: vec![0.0; size * size],
            grazings: Vec::new(),
            impacts: 0,
            from: f64::NEG_INFINITY,
        })
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
            .position(|(k, _)| k.iter().copied().eq(key(modes)))
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
        self.flows.push((key(modes).collect(), a));
        self.flows.len() - 1
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
    /// rate is not its closing speed has no derivative: counted with the
    /// grazings.
    fn latch(&mut self, view: &EventView<'_>, stretch: bool) {
        let Some(latched) = self.latched.as_mut() else {
            return;
        };
        let size = self.size;
        for i in 0..view.modes_after.len() {
            if !latched.which[i] {
                continue;
            }
            match (view.modes_before[i], view.modes_after[i]) {
                (Mode::Open, Mode::Compliant { approach_rate, .. }) => {
                    let event = (view.time, view.before, view.modes_before);
                    let flow = stretch.then_some(&self.stretch[..]);
                    if !latched.onset(self.system, event, i, approach_rate, flow, &self.matrix) {
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
                (Mode::Compliant { .. }, Mode::Open) => latched.separation(i, size),
                _ => {}
            }
        }
    }
}

impl EventObserver for Tangent<'_> {
    fn start(&mut self, time: f64, y: &[f64], modes: &[Mode]) -> Result<()> {
        self.since = time.max(self.from);
        self.modes.copy_from_slice(modes);
        if let Some(latched) = self.latched.as_mut() {
            // Carried from the start: a resumed contact's rate is the
            // state's; from later, the state there does not set it.
            latched.resume(self.system, y, modes);
            if self.from > time {
                latched.rows.iter_mut().for_each(|v| *v = 0.0);
            }
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
            self.smooth(view.time);
            std::mem::swap(&mut self.factor, &mut self.stretch);
        }
        let outcome = self.saltation.matrix(self.system, view, &mut self.factor);

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
        self.impacts += u64::from(!view.jumps.is_empty() || onset);
        self.latch(view, stretch);
        self.apply(false);
        self.since = view.time;
        self.modes.copy_from_slice(view.modes_after);
        Ok(())
    }

    fn wants_steps(&self) -> bool {
        self.contact.is_some()
    }

    /// A step while a compliant contact is on: its factor from the
    /// variational equations ([`ContactSteps`]). Other steps are linear,
    /// carried whole at the events.
    fn step(&mut self, t0: f64, y0: &[f64], t1: f64, y1: &[f64], modes: &[Mode]) -> Result<()> {
        if !in_contact(modes) || t1 <= t0 {
            return Ok(());
        }
        if t0 < self.from {
            // Before the flow is carried (a study's settling): a step across
            // its start starts it at the step's end.
            self.since = self.since.max(t1);
            return Ok(());
        }
        if let Some(contact) = self.contact.as_mut() {
            let gain = self.latched.as_mut().map(|l| Gain {
                which: &l.which,
                gain: &mut l.gain,
            });
            let with_gain = gain.is_some();
            contact.factor(
                self.system,
                (t0, y0),
                (t1, y1),
                modes,
                &mut self.factor,
                gain,
            );
            self.apply(with_gain);
            self.since = t1;
        }
        Ok(())
    }

    fn finish(&mut self, time: f64, _y: &[f64], modes: &[Mode]) -> Result<()> {
        if time > self.since && !in_contact(&self.modes) {
            self.smooth(time);
            self.apply(false);
        }
        self.since = time;
        self.modes.copy_from_slice(modes);
        Ok(())
    }
}
