//! The exact flow as a [`SystemStepper`] of the event kernel.

use super::energies::{Span, NODES, WEIGHTS};
use super::flow::ExactFlow;
use crate::error::Result;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{Assembly, Mode, Scratch, INPUT, VISCOUS};

/// The shortest step the limit of closing gaps asks for, in steps of the
/// configuration.
const APEX_STEPS: f64 = 64.0;

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
