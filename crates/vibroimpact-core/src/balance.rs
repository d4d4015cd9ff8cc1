//! A system run's energy balance: where the energy went, and the check
//! that it closes, made every [`ENERGY_INTERVAL`] steps by the event kernel
//! and by the compact path's stretches alike.

use crate::assembly::{Assembly, Mode, CONTACT, INPUT, VISCOUS};
use crate::error::{Error, Result};

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
    let contact: f64 = y[at + CONTACT..].iter().sum();
    let dissipated = viscous + contact + impact;
    EnergyBalance {
        input_work,
        dissipated,
        viscous,
        contact,
        impact,
        stored_start,
        stored_end,
        residual: stored_end - stored_start - input_work + dissipated,
    }
}

/// Energy cannot be created: a residual beyond the tolerance, relative to the
/// energies in play, is a numerical failure, not a result.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
pub(crate) fn check_balance(
    system: &Assembly,
    y: &[f64],
    modes: &[Mode],
    stored_start: f64,
    scale: &mut f64,
    impact: f64,
    tolerance: f64,
    t_end: f64,
    time: f64,
) -> Result<()> {
    // One evaluation of the stored energy gives both its value and its scale.
    let (stored, magnitude) = system.energy_terms(y, modes);
    let b = balance(system, y, stored, stored_start, impact);
    // The energy in play: the largest seen so far, since a system without
    // losses can pass through states where every term is near zero.
    *scale = scale
        .max(magnitude + b.input_work.abs() + b.dissipated.abs())
        .max(system.energy_floor(t_end))
        .max(f64::MIN_POSITIVE);
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
        });
    }
    Ok(())
}
