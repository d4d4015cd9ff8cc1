//! The two-mass impact damper's run: the preset ([`ImpactDamper::assembly`])
//! on the one kernel, with the method and stepping its settings name. What
//! the binding's two-mass `simulate` and the paper's tables run.

mod settings;

pub use settings::*;

use crate::error::Result;
use crate::kernel::events::SystemSolution;
use crate::methods::registry::{check_steps_resolve, AnyStepper, Options};
use crate::model::contact::Contact;
use crate::model::impact_damper::{ImpactDamper, State};

/// The registry options `method` carries (the others at their defaults).
pub fn options_of(method: &Method) -> Options {
    let mut options = Options::default();
    match *method {
        Method::Newmark { beta, gamma } | Method::NewmarkImplicit { beta, gamma } => {
            (options.beta, options.gamma) = (beta, gamma);
        }
        Method::GeneralizedAlpha { spectral_radius } => options.spectral_radius = spectral_radius,
        Method::Dopri5(t) | Method::Dop853(t) => (options.rtol, options.atol) = (t.rtol, t.atol),
        Method::Rk4 => {}
    }
    options
}

/// Integrates `system` with `contact` from `start` as `settings` say, on
/// the general kernel: the state is `[w, y, w', y']` (main then impact
/// mass), the one pair the damper. A start with the impact mass inside a
/// wall is refused naming both displacements. `interrupt` is polled.
pub fn simulate(
    system: &ImpactDamper,
    contact: &Contact,
    start: &State,
    settings: &Settings,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<SystemSolution> {
    // Literals (the fields are public) through their constructors' checks,
    // named as the two-mass model names them.
    let system = &ImpactDamper::new(
        system.main_mass,
        system.stiffness,
        system.damping,
        system.impact_mass,
        system.clearance,
    )?;
    let start = &State::new(
        start.main_displacement,
        start.main_velocity,
        start.impact_displacement,
        start.impact_velocity,
    )?;
    let settings = &settings.checked()?;
    start.check_apart(system.clearance)?;
    // The system's own limits: an explicit step over the main mass's period
    // (it had blown up, a NumericalBlowUp, where the same structure as a
    // system was refused up front).
    let run = settings.run_options();
    let options = options_of(&settings.method);
    check_steps_resolve(
        &system.spec(contact)?,
        settings.method.name(),
        run.dt,
        options,
    )?;
    let assembly = system.assembly(contact)?;
    let y0 = start.vector(&assembly)?;
    let mut stepper = AnyStepper::new(&assembly, settings.method.name(), &options)?;
    stepper.integrate_stepped(&assembly, &y0, &run, settings.kernel_stepping(), interrupt)
}
