//! An orbit study's stroboscopic section moved out of a contact whose law
//! latches its approach rate (as `vibroimpact.analysis.orbit` moves its own):
//! the map of a state (x, v) inside such a contact begins the contact afresh,
//! its rate latched at the indentation rate there, and Newton would find that
//! map's orbit (a hertz-damped damper's: 3 impacts a period for 2, the
//! largest multiplier 0.852 for 0.894). The multipliers, the amplitudes and
//! the impacts of a period do not depend on the section.

use std::f64::consts::TAU;

use super::run::run_options;
use super::settings::StudySettings;
use crate::error::Result;
use crate::kernel::events::{CarriedContact, Stepping, SystemSolution};
use crate::kernel::reductions::ReduceOptions;
use crate::methods::registry::AnyStepper;
use crate::model::assembly::{resumed_state, Assembly, SystemSpec};
use crate::model::signals::{Harmonic, Signal};

/// The fractions of the forcing period tried, `k / SECTION_STEPS` in order
/// (those of `vibroimpact.analysis.orbit`).
const SECTION_STEPS: u32 = 20;

/// Whether a contact whose law latches is open among `contacts` (one per
/// interaction of `system`).
fn latching_open(system: &Assembly, contacts: &[Option<CarriedContact>]) -> bool {
    let interactions = system.interactions();
    interactions
        .iter()
        .zip(contacts)
        .any(|(it, c)| c.is_some() && it.law.latches())
}

/// `spec` with its harmonic forcing started `delay` s later (its t = 0 that
/// instant of `spec`'s forcing); None where a signal is not harmonic.
fn delayed(spec: &SystemSpec, delay: f64) -> Option<SystemSpec> {
    let mut out = spec.clone();
    let shift = |h: &mut Harmonic| h.phase += TAU * h.frequency * delay;
    for e in &mut out.excitations {
        match &mut e.signal {
            Signal::Harmonic(h) => shift(h),
            Signal::Harmonics(all) => all.iter_mut().for_each(shift),
            _ => return None,
        }
    }
    Some(out)
}

/// The full state of `system` at the flat state `z` (displacements, then
/// velocities).
pub(super) fn full_state(system: &Assembly, z: &[f64]) -> Result<Vec<f64>> {
    let (n, d) = (system.n, system.dim);
    resumed_state(system, [&z[..n], &z[d..d + n], &z[n..d], &z[d + n..2 * d]])
}

/// Where `settled` (a run of `system`, made of `spec`, by `stepper`) ends
/// inside a contact whose law latches: the first fraction `k / 20` of the
/// forcing `period` after it at which the run on from it has none open, as
/// the spec and system whose forcing starts there and the full state there.
/// None where none is open at the end of `settled`, the forcing is not
/// harmonic, or no fraction is clear.
pub(super) fn clear_section(
    (spec, system): (&SystemSpec, &Assembly),
    stepper: &mut AnyStepper,
    settled: &SystemSolution,
    (settings, period): (&StudySettings, f64),
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Option<(SystemSpec, Assembly, Vec<f64>)>> {
    let carried = settled.carried();
    if !latching_open(system, &carried) {
        return Ok(None);
    }
    let start = full_state(system, &settled.final_state)?;
    let unrecorded = ReduceOptions {
        record_from: f64::INFINITY,
        strobe_period: f64::INFINITY,
        mean_square: false,
        contacts_from: f64::INFINITY,
    };
    for k in 1..SECTION_STEPS {
        // From the settled state each time: its forcing's time runs from 0.
        let delay = f64::from(k) / f64::from(SECTION_STEPS) * period;
        let step = stepper.step(settings.dt, delay, period);
        let options = run_options(settings, step, delay, unrecorded);
        let run = stepper.integrate_continued(
            system,
            (&start, &carried),
            &options,
            Stepping::Events,
            &mut || interrupt(),
        )?;
        if latching_open(system, &run.carried()) {
            continue;
        }
        let Some(moved) = delayed(spec, delay) else {
            return Ok(None);
        };
        let moved_system = Assembly::new(&moved)?;
        let state = full_state(&moved_system, &run.final_state)?;
        return Ok(Some((moved, moved_system, state)));
    }
    Ok(None)
}
