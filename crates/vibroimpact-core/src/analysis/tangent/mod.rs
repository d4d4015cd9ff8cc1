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
//! The flow is told of events by the one kernel
//! ([`crate::kernel::observe`]); by concern: this product, the saltation
//! ([`saltation`]), the Lyapunov exponents ([`lyapunov`]).

mod lyapunov;
mod saltation;
#[cfg(test)]
mod tests;

pub use lyapunov::{lyapunov_blocks, LyapunovSpectrum};

use crate::error::{Error, Result};
use crate::kernel::observe::{EventObserver, EventView};
use crate::model::assembly::{Assembly, InteractionLaw, Mode, Scratch};
use crate::numerics::linalg;
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

/// Whether `system`'s tangent flow can be made exactly: every pair rigid
/// (its structure is linear). Else an error naming the first pair that is
/// not, and what to do instead.
pub fn check(system: &Assembly) -> Result<()> {
    for it in &system.interactions {
        if let InteractionLaw::Compliant { .. } = it.law {
            return Err(Error::Inconsistent(format!(
                "the tangent flow (exact Floquet multipliers, Lyapunov exponents, located \
                 bifurcations, sensitivities) takes rigid pairs only for now; {} has a \
                 compliant law: use restitution for a rigid wall, or finite differences \
                 (orbit jacobian = \"differences\")",
                system.pairs[it.pair]
            )));
        }
    }
    Ok(())
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
    expm: linalg::Expm,
    factor: Vec<f64>,
    /// The stretch's flow before an event's saltation.
    stretch: Vec<f64>,
    product: Vec<f64>,
    grazings: Vec<Grazing>,
    /// Events whose impulses acted.
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

    /// Events whose impulses acted.
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
        self.system
            .acceleration_jacobian(&y, modes, &mut scratch, &mut dadx, &mut dadv);
        let mut a = vec![0.0; size * size];
        for i in 0..d {
            a[i * size + d + i] = 1.0;
            for j in 0..d {
                a[(d + i) * size + j] = dadx[i * d + j];
                a[(d + i) * size + d + j] = dadv[i * d + j];
            }
        }
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

    /// `matrix <- factor matrix`, then re-orthonormalised where asked.
    fn apply(&mut self) {
        linalg::matmul(&self.factor, &self.matrix, &mut self.product, self.size);
        std::mem::swap(&mut self.matrix, &mut self.product);
        if let Keep::Orthonormal { logs } = &mut self.keep {
            lyapunov::orthonormalise(&mut self.matrix, self.size, logs);
        }
    }
}

impl EventObserver for Tangent<'_> {
    fn start(&mut self, time: f64, _y: &[f64], modes: &[Mode]) -> Result<()> {
        self.since = time.max(self.from);
        self.modes.copy_from_slice(modes);
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
        let stretch = view.time > self.since;
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
        self.impacts += u64::from(!view.jumps.is_empty());
        self.apply();
        self.since = view.time;
        self.modes.copy_from_slice(view.modes_after);
        Ok(())
    }

    fn finish(&mut self, time: f64, _y: &[f64], modes: &[Mode]) -> Result<()> {
        if time > self.since {
            self.smooth(time);
            self.apply();
        }
        self.since = time;
        self.modes.copy_from_slice(modes);
        Ok(())
    }
}
