//! Explicit Runge-Kutta steppers over any [`Assembly`]: the state is a slice
//! and every buffer is allocated once, when the stepper is made.
//!
//! One generic stepper over a Butcher tableau serves RK4 (fixed step),
//! Dormand-Prince 5(4) and DOP853 (error control, first same as last).

use crate::error::Result;
use crate::kernel::compact::Stretch;
use crate::model::assembly::{Assembly, Mode, Scratch};

/// A method the 0.2 kernel can drive: it advances the state within one set of
/// contact modes, where the right-hand side is smooth.
pub trait SystemStepper {
    fn name(&self) -> &'static str;
    /// Whether the step size is controlled by an error estimate.
    fn is_adaptive(&self) -> bool;
    /// Whether a step lands on the exact solution (then the run's time
    /// resolution is set by round-off, not by the step).
    fn is_exact(&self) -> bool {
        false
    }
    /// The longest step the method takes from `(time, y)` in `modes` (s): a
    /// method whose step is set by the system it integrates shortens it where
    /// that changes.
    fn step_limit(
        &mut self,
        _system: &Assembly,
        _time: f64,
        _y: &[f64],
        _modes: &[Mode],
        _scratch: &mut Scratch,
    ) -> Result<f64> {
        Ok(f64::INFINITY)
    }
    /// The state's rates at `(time, y)` where an adaptive method has them for
    /// nothing (its first stage, kept for the attempt that follows), else
    /// None: the kernel ends a step soon after an open gap's parabola lands.
    fn start_rates(
        &mut self,
        _system: &Assembly,
        _time: f64,
        _y: &[f64],
        _modes: &[Mode],
        _scratch: &mut Scratch,
    ) -> Option<&[f64]> {
        None
    }
    /// An adaptive method's `(rtol, atol)`; None for a fixed-step one.
    fn tolerances(&self) -> Option<(f64, f64)> {
        None
    }
    /// Forget data carried from the last step (the right-hand side jumped).
    fn reset(&mut self);
    /// Fixed stepping (steps not cut at contacts): the step just kept and
    /// accepted ended with a contact change found inside it, and the modes
    /// change from the next step on. By default the carried data go, as at
    /// any mode switch ([`Self::reset`]). The founding paper's Newmark keeps
    /// its accelerations (0.1's fixed-step kernel never restarted it), so
    /// that its fixed steps are 0.1's to the bit; the kernel must then not
    /// call [`Self::reset`] for that change, nor attempt other lengths from
    /// the step's start after the kept one.
    fn switched_within_step(&mut self) {
        self.reset();
    }
    /// Whether the data carried from one step to the next are part of the
    /// method's solution, so that [`Self::reset`] between two steps changes
    /// it (generalised-alpha's algorithmic accelerations, which are not the
    /// physical ones). The kernel then takes a kept step again after probing
    /// inside it (the deepest indentation, a reduction's extremum) instead of
    /// restarting the method: what is recorded never changes the run.
    fn carries_solution(&self) -> bool {
        false
    }
    /// Whether the method creates energy at a contact by construction (the
    /// founding paper's Newmark, whose contact force lags one step: its
    /// Table 1 collision rebounds at 1.0015 of the approach speed at its
    /// dt = 1e-4 s, 1.049 at 1e-3 s, where the model's is 0.99635).
    /// Its contacts are then bounded by `energy_tolerance` alone, as 0.1
    /// bounded them, not by the kernel's `CONTACT_CREATION_LIMIT`.
    fn creates_contact_energy(&self) -> bool {
        false
    }
    /// Whether the method takes stretches of plain steps of `system` (see
    /// [`Self::stretch`]) when stepping fixed (`fixed`) or by events. No by
    /// default.
    fn takes_stretches(&self, _system: &Assembly, _fixed: bool) -> bool {
        false
    }
    /// Forget the last `evaluations` counted: an attempt taken back, which
    /// the kernel makes again ([`crate::kernel::plain_fixed`]).
    fn uncount(&mut self, _evaluations: u64) {}
    /// Plain fixed steps taken at once (see [`Stretch`], a type of the
    /// kernel's, not for callers), where the method can: each the step the
    /// kernel would take, to the bit. None by default.
    #[doc(hidden)]
    fn stretch(
        &mut self,
        _system: &Assembly,
        _stretch: &mut Stretch<'_>,
        _modes: &[Mode],
        _scratch: &mut Scratch,
    ) {
    }
    /// Attempt a step `h` from `(time, y)` into `out`; the scaled error
    /// (accept when <= 1), 0 for a fixed-step method.
    #[allow(clippy::too_many_arguments)]
    fn attempt(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) -> Result<f64>;
    /// The accelerations and their rates (`dim` values each, into `accel`
    /// and `jerk`) at the end of the last attempt, where the method has them
    /// for little (the exact flow, from its modal state there): locating an
    /// event then solves the value's cubic Taylor polynomial about a trial
    /// instead of its tangent. False (the default) where it has not.
    fn end_derivatives(
        &mut self,
        _system: &Assembly,
        _accel: &mut [f64],
        _jerk: &mut [f64],
    ) -> bool {
        false
    }
    /// The state's rates at the start of the last attempt where the method
    /// made them there (RK4's first stage, with the force's value at the
    /// step's start as the stages took it), else None. A fixed step's
    /// reductions take them (the same bits, one evaluation fewer).
    fn first_stage(&self) -> Option<&[f64]> {
        None
    }
    /// The last attempt is the new current point.
    fn accept(&mut self);
    /// Complete the step `h` from `(time, y)` the kernel keeps, `end`, with
    /// what only a kept step needs (a method that leaves its attempts'
    /// energy accumulators out fills them here). Unless `settle` (the kernel
    /// reads the accumulators at `end`: an event there, a balance check, the
    /// run's end), a method may leave them as they are in `y` and add this
    /// step's share at a later step's settlement (the kernel then passes on
    /// `end` unchanged as the next step's start).
    #[allow(clippy::too_many_arguments)]
    fn finish(
        &mut self,
        _system: &Assembly,
        _time: f64,
        _y: &[f64],
        _h: f64,
        _modes: &[Mode],
        _scratch: &mut Scratch,
        _end: &mut [f64],
        _settle: bool,
    ) -> Result<()> {
        Ok(())
    }
    /// The step-size factor's core for a scaled `error`.
    fn shrink(&self, error: f64) -> f64;
    /// Right-hand-side evaluations so far.
    fn evaluations(&self) -> u64;
}

mod newmark;
mod rk;
#[cfg(test)]
mod tests;

pub use newmark::NewmarkFamily;
pub use rk::ExplicitRk;
