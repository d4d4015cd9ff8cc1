//! A compliant contact's own energy balance in the event-driven kernel of the
//! systems: the run's balance residual (stored energy + dissipated work -
//! input work - the energy at the start) taken at the contact's onset and at
//! its separation. A contact can only lose energy: what the residual gains
//! across it is energy the method created there, and beyond
//! [`CONTACT_CREATION_LIMIT`] of the energy in play (or `energy_tolerance`
//! where that is smaller) it is an error whatever `energy_tolerance` says, as
//! in the two-mass kernels. Evaluated at contact ends only, never per step.

use crate::error::{EnergyAdvice, Error, Result};
use crate::kernel::balance::balance;
use crate::kernel::events::PairContact;
use crate::model::assembly::{Assembly, Mode};

/// The most energy one contact may create, relative to the energy in play,
/// whatever `energy_tolerance` says. A contact can only lose energy; what
/// it gains is the method's error, which at the coarsest steps that resolve
/// a contact (ten steps across it) stays below 1e-2 for every method but the
/// founding paper's lagged Newmark (generalized-alpha 6e-3, the others
/// below 1e-3; dop853 and dopri5 1e-8), where a two-body rebound ratio is
/// within 0.5 % of 1. The paper's Newmark creates energy at every contact by
/// construction (it rebounds at 1.0016 of the approach speed at its own
/// dt = 1e-4 s, 1.05 at 1e-3 s): that is the error `vibroimpact paper`
/// reproduces and documents, so its runs are bounded by `energy_tolerance`
/// alone.
pub const CONTACT_CREATION_LIMIT: f64 = 1e-2;

/// The balance at a compliant contact's onset: the stored energy and the
/// run's residual there, J.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub(crate) struct OnsetBalance {
    stored: f64,
    residual: f64,
}

/// The stored energy, the residual and the energy in play (the magnitudes of
/// the stored energy's terms and of the work so far) at state `y`, J.
fn sample(
    system: &Assembly,
    y: &[f64],
    modes: &[Mode],
    stored_start: f64,
    impact: f64,
) -> (f64, f64, f64) {
    let (stored, magnitude) = system.energy_terms(y, modes);
    let b = balance(system, y, stored, stored_start, impact);
    (
        stored,
        b.residual,
        magnitude + b.input_work.abs() + b.dissipated.abs(),
    )
}

impl OnsetBalance {
    /// At a compliant onset, state `y` (the energy accumulators settled, as
    /// at every event). Out of line, as [`Self::check_separation`]: inlined,
    /// their stored-energy evaluations grew the kernel's loop enough to slow
    /// runs without compliant contacts (rigid impacts: +2 to 5 %).
    #[cold]
    #[inline(never)]
    pub(crate) fn at(
        system: &Assembly,
        y: &[f64],
        modes: &[Mode],
        stored_start: f64,
        impact: f64,
    ) -> Self {
        let (stored, residual, _) = sample(system, y, modes, stored_start, impact);
        Self { stored, residual }
    }

    /// The contact `record` just closed at state `y`: an error if the residual
    /// grew across it by more than the creation limit (`CONTACT_CREATION_LIMIT`,
    /// or `energy_tolerance` where smaller; `energy_tolerance` alone for a
    /// method that `creates` energy at contacts by construction, see
    /// [`crate::methods::steppers::SystemStepper::creates_contact_energy`])
    /// of the energy in play (the run's largest so far, `energy_scale`, or
    /// now's). Else the stored energy's change across the contact, J.
    #[allow(clippy::too_many_arguments)]
    #[cold]
    #[inline(never)]
    pub(crate) fn check_separation(
        &self,
        system: &Assembly,
        y: &[f64],
        modes: &[Mode],
        (stored_start, impact): (f64, f64),
        energy_scale: f64,
        (energy_tolerance, creates): (f64, bool),
        record: &PairContact,
    ) -> Result<f64> {
        let (stored, residual, in_play) = sample(system, y, modes, stored_start, impact);
        let created = residual - self.residual;
        let scale = energy_scale.max(in_play);
        let limit = if creates {
            energy_tolerance
        } else {
            energy_tolerance.min(CONTACT_CREATION_LIMIT)
        };
        let change = stored - self.stored;
        if created > limit * scale {
            return Err(Error::ContactEnergy {
                onset: record.onset,
                separation: record.separation,
                change,
                dissipated: record.energy_dissipated,
                // The rest of what the residual moved: the other dampers'
                // and contacts' losses less the input work over the contact.
                work: created - change - record.energy_dissipated,
                scale,
                restitution: record.restitution,
                tolerance: limit,
                created: limit < energy_tolerance,
                advice: EnergyAdvice::Any,
            });
        }
        Ok(change)
    }
}
