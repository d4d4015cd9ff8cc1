//! The energy accumulators of the Newmark family's steps (the paper's
//! lagged Newmark, the implicit one, generalised-alpha) by the trapezoidal
//! rule on their rates.

use crate::model::assembly::{Assembly, Mode, Scratch};

/// The energy accumulators (the state after its `2 dim` coordinates and
/// velocities) of the Newmark family's steps by the trapezoidal rule on
/// their rates, second order like the methods: the rates at the current
/// point and at the end of the last attempt.
#[derive(Debug, Clone, Default)]
pub(crate) struct Trapezoid {
    start: Vec<f64>,
    pending: Vec<f64>,
}

impl Trapezoid {
    /// For `system`'s accumulators.
    pub(crate) fn new(system: &Assembly) -> Self {
        Self::of(system.state_len() - 2 * system.dim)
    }

    /// For `count` accumulators.
    pub(crate) fn of(count: usize) -> Self {
        Self {
            start: vec![0.0; count],
            pending: vec![0.0; count],
        }
    }

    /// The current point's accumulator rates, from all its `rates`.
    pub(crate) fn restart(&mut self, system: &Assembly, rates: &[f64]) {
        self.start.copy_from_slice(&rates[2 * system.dim..]);
    }

    /// The accumulators at the end `out` of a step `h` from `(time, y)`
    /// whose coordinates and velocities `out` holds; the rates at the end
    /// are evaluated into `rates` (the state's length).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn step(
        &mut self,
        system: &Assembly,
        time: f64,
        y: &[f64],
        h: f64,
        modes: &[Mode],
        scratch: &mut Scratch,
        rates: &mut [f64],
        out: &mut [f64],
    ) {
        let d = system.dim;
        out[2 * d..].copy_from_slice(&y[2 * d..]);
        system.rates(time + h, out, modes, scratch, rates);
        self.add(h, &rates[2 * d..], &mut out[2 * d..]);
    }

    /// The step `h`'s share onto the accumulators `out` (the step's start's
    /// values), from their rates `end` at the step's end.
    pub(crate) fn add(&mut self, h: f64, end: &[f64], out: &mut [f64]) {
        for (k, slot) in out.iter_mut().enumerate() {
            *slot += 0.5 * h * (self.start[k] + end[k]);
        }
        self.pending.copy_from_slice(end);
    }

    /// The accumulators `out` at the end of a step `h` from their values
    /// `start` (the step's start's), with their rates at the end written by
    /// `end_rates` (into the pending slot, with no copy): [`Self::add`]'s
    /// arithmetic.
    #[inline(always)]
    pub(crate) fn integrate(
        &mut self,
        h: f64,
        start: &[f64],
        out: &mut [f64],
        end_rates: impl FnOnce(&mut [f64]),
    ) {
        end_rates(&mut self.pending);
        let count = out
            .len()
            .min(start.len())
            .min(self.start.len())
            .min(self.pending.len());
        for k in 0..count {
            out[k] = start[k] + 0.5 * h * (self.start[k] + self.pending[k]);
        }
    }

    /// The current point's accumulator rates (a fixed-size path carries
    /// them through its steps and writes them back).
    pub(crate) fn start_rates(&mut self) -> &mut [f64] {
        &mut self.start
    }

    /// The last attempt's end is the new current point.
    pub(crate) fn accept(&mut self) {
        std::mem::swap(&mut self.start, &mut self.pending);
    }
}
