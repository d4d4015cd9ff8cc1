//! A system run's energy balance: where the energy went, and the check
//! that it closes, made every [`ENERGY_INTERVAL`] steps by the event kernel
//! and by the compact path's stretches alike.

use crate::error::{EnergyAdvice, Error, Result};
use crate::model::assembly::{Assembly, Mode, CONTACT, INPUT, VISCOUS};

/// How often (accepted steps) the energy balance is checked.
pub(crate) const ENERGY_INTERVAL: u64 = 32;

/// Where the energy went, J: `stored_end - stored_start = input_work -
/// dissipated + residual`, the residual being numerical error.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct EnergyBalance {
    pub input_work: f64,
    /// Viscous, contact and impact losses together.
    pub dissipated: f64,
    pub viscous: f64,
    pub contact: f64,
    /// Dry friction's loss (sliding), J.
    pub friction: f64,
    pub impact: f64,
    pub stored_start: f64,
    pub stored_end: f64,
    pub residual: f64,
}

pub(crate) fn balance(
    system: &Assembly,
    y: &[f64],
    stored_end: f64,
    stored_start: f64,
    impact: f64,
) -> EnergyBalance {
    let at = 2 * system.dim;
    let (viscous, input_work) = (y[at + VISCOUS], y[at + INPUT]);
    let (mut contact, mut friction) = (0.0, 0.0);
    for (loss, it) in y[at + CONTACT..].iter().zip(&system.interactions) {
        if it.law.is_friction() {
            friction += loss;
        } else {
            contact += loss;
        }
    }
    let dissipated = viscous + contact + friction + impact;
    EnergyBalance {
        input_work,
        dissipated,
        viscous,
        contact,
        friction,
        impact,
        stored_start,
        stored_end,
        residual: stored_end - stored_start - input_work + dissipated,
    }
}

/// Samples of the energy in play per the system's shortest period (see
/// [`EnergySampler`]).
const SAMPLES_PER_PERIOD: f64 = 2.0;

/// When the energy in play is next sampled between the balance checks: at
/// least every [`SAMPLES_PER_PERIOD`]-th of the system's shortest period (the
/// run's length if shorter), by the clock of the motion rather than by steps,
/// so that every method judges its residual on the same scale. A check every
/// [`ENERGY_INTERVAL`] steps alone saw the energy where the steps fell: the
/// exact flow's long steps (an eighth of a period) checked a resonant
/// oscillator against a stop only at its end, where it had handed the 0.78 J
/// it had moved back to the force, and judged round-off against 1.6e-7 J.
#[derive(Debug, Clone, Copy)]
pub struct EnergySampler {
    next: f64,
    spacing: f64,
}

impl EnergySampler {
    pub(crate) fn new(system: &Assembly, t_end: f64) -> Self {
        Self {
            next: 0.0,
            spacing: system.time_scale().min(t_end) / SAMPLES_PER_PERIOD,
        }
    }

    /// Whether the energy in play is due at `time` (s); if so, the next
    /// sample is set a spacing on.
    #[inline(always)]
    pub(crate) fn due(&mut self, time: f64) -> bool {
        if time < self.next {
            return false;
        }
        self.next = time + self.spacing;
        true
    }
}

/// Energy cannot be created: a residual beyond the tolerance, relative to the
/// largest energy in play so far (the magnitudes of the stored energy's terms
/// and of the work in and out, see [`EnergySampler`]), is a numerical
/// failure, not a result. With `check` false the energy in play is only
/// sampled (between checks a stepper may leave its accumulators to later).
#[allow(clippy::too_many_arguments)]
#[cold]
#[inline(never)]
pub(crate) fn check_balance(
    system: &Assembly,
    y: &[f64],
    modes: &[Mode],
    stored_start: f64,
    scale: &mut f64,
    impact: f64,
    (tolerance, check): (f64, bool),
    t_end: f64,
    time: f64,
    extremes: &mut Extremes,
) -> Result<()> {
    // One evaluation of the stored energy gives both its value and its scale.
    let (stored, magnitude) = system.energy_terms(y, modes);
    let b = balance(system, y, stored, stored_start, impact);
    extremes.stored = extremes.stored.max(stored);
    // The largest seen so far: a system without losses can pass through
    // states where every term is near zero.
    *scale = scale.max(magnitude + b.input_work.abs() + b.dissipated.abs());
    if !check {
        return Ok(());
    }
    *scale = scale.max(system.energy_floor(t_end)).max(f64::MIN_POSITIVE);
    extremes.residual = extremes.residual.max(b.residual.abs() / *scale);
    if !b.residual.is_finite() {
        return Err(Error::NumericalBlowUp {
            time,
            reason: "the energies are no longer finite: a blow-up, or inputs (amplitudes, scale \
                     factors) too large for floating point",
        });
    }
    if b.residual.abs() > tolerance * *scale {
        return Err(Error::EnergyBalance {
            time,
            residual: b.residual,
            scale: *scale,
            tolerance,
            advice: EnergyAdvice::Any,
        });
    }
    Ok(())
}

/// What the balance checks saw: the largest stored energy (J, at the checks
/// and samples) and the largest residual relative to the energy in play (at
/// the checks; NaN before the first).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Extremes {
    pub(crate) stored: f64,
    pub(crate) residual: f64,
}

impl Default for Extremes {
    fn default() -> Self {
        Self {
            stored: f64::NEG_INFINITY,
            residual: f64::NAN,
        }
    }
}

impl Extremes {
    /// `max(E) / E(0) - 1` over the start, the checks and the end `stored_end`
    /// of an unforced system (NaN when forced or starting with no energy).
    pub(crate) fn growth(&self, system: &Assembly, stored_start: f64, stored_end: f64) -> f64 {
        if system.is_free() && stored_start > 0.0 {
            self.stored.max(stored_start).max(stored_end) / stored_start - 1.0
        } else {
            f64::NAN
        }
    }
}

/// The run's energy balance as the kernel and its fast path check it:
/// every [`ENERGY_INTERVAL`] accepted steps and at the end, and the energy
/// in play sampled between (see [`EnergySampler`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct EnergyWatch {
    /// The energy stored at the start, J.
    pub(crate) stored_start: f64,
    /// The largest energy in play so far, J (see [`check_balance`]).
    pub(crate) scale: f64,
    pub(crate) sampler: EnergySampler,
    /// The energy the rigid impacts took so far, J.
    pub(crate) impact_loss: f64,
    pub(crate) tolerance: f64,
    pub(crate) t_end: f64,
    pub(crate) extremes: Extremes,
}

impl EnergyWatch {
    /// The balance after the `accepted`-th step, at `time` and state `y`
    /// (`done`: the run's last).
    #[inline(always)]
    pub(crate) fn after_step(
        &mut self,
        system: &Assembly,
        (y, modes): (&[f64], &[Mode]),
        accepted: u64,
        done: bool,
        time: f64,
    ) -> Result<()> {
        match self.due(accepted, done, time) {
            Some(check) => self.balance(system, (y, modes), check, time),
            None => Ok(()),
        }
    }

    /// [`Self::after_step`] on a fixed-size state of `len` values, copied
    /// where the balance is due: the fast paths keep their state in
    /// registers, which a reference taken on every step would not allow.
    #[inline(always)]
    pub(crate) fn after_step_of<const N: usize>(
        &mut self,
        system: &Assembly,
        (y, len, modes): (&[f64; N], usize, &[Mode]),
        accepted: u64,
        time: f64,
    ) -> Result<()> {
        match self.due(accepted, false, time) {
            Some(check) => {
                let copy = *y;
                self.balance(system, (&copy[..len.min(N)], modes), check, time)
            }
            None => Ok(()),
        }
    }

    /// Whether the `accepted`-th step, ending at `time`, needs the balance
    /// (`Some(check)`; with `check` false only the energy in play is
    /// sampled): the lockstep lanes ask this of every lane and gather a
    /// lane's state only where it does.
    #[inline(always)]
    pub(crate) fn due(&mut self, accepted: u64, done: bool, time: f64) -> Option<bool> {
        let check = accepted % ENERGY_INTERVAL == 0 || done;
        (check || self.sampler.due(time)).then_some(check)
    }

    /// The balance at `time` and state `y` (see [`Self::due`]).
    #[inline(always)]
    pub(crate) fn balance(
        &mut self,
        system: &Assembly,
        (y, modes): (&[f64], &[Mode]),
        check: bool,
        time: f64,
    ) -> Result<()> {
        check_balance(
            system,
            y,
            modes,
            self.stored_start,
            &mut self.scale,
            self.impact_loss,
            (self.tolerance, check),
            self.t_end,
            time,
            &mut self.extremes,
        )
    }
}
