//! A two-mass run on the general kernel (the preset
//! [`core::ImpactDamper::spec`]), every method with event stepping, as the
//! rows the binding's `Solution` shows. Fixed stepping (the paper's Newmark,
//! the default, and RK4) stays on the 0.1 kernel until the general one is as
//! fast: RK4 2.4e7 against 7.9e7 steps/s, where it must keep numba's pace
//! (`benchmarks/bench_numba.py`, 7.1e7); Newmark 2.1e7 against 9.4e7, and a
//! one-step call 5.7 us against 0.8 us where `benchmarks/bench_steps.py`
//! asks for 5 us. The general kernel's fixed Newmark gives 0.1's bits (the
//! kernel's fixed-step tests), so a 0.1 file and its 0.2 form still agree.

use vibroimpact_core as core;

use core::kernel::events::SystemSolution;
use core::methods::registry::AnyStepper;
use core::model::assembly::{Assembly, Mode};

/// A contact of either kernel as a row of the table (`CONTACT_COLUMNS`).
macro_rules! contact_row {
    ($c:expr) => {
        [
            $c.onset,
            $c.separation,
            $c.duration,
            $c.max_indentation,
            $c.approach_speed,
            $c.rebound_speed,
            $c.restitution,
            $c.energy_dissipated,
            $c.energy_change,
        ]
    };
}

/// A two-mass run's results.
pub(crate) struct TwoMassRun {
    /// Time, w, w', y, y' and the contact force, one row a kept step.
    pub(crate) history: [Vec<f64>; 6],
    /// One row a contact, the values of `CONTACT_COLUMNS`.
    pub(crate) contacts: Vec<[f64; 9]>,
    pub(crate) steps: u64,
    pub(crate) rejected_steps: u64,
    pub(crate) rhs_evaluations: u64,
    pub(crate) grazing_contacts: u64,
    pub(crate) final_time: f64,
    pub(crate) final_state: core::State,
    pub(crate) energy_growth: f64,
    pub(crate) energy_residual: f64,
}

/// The run by the 0.1 kernel.
fn legacy(
    system: &core::ImpactDamper,
    contact: &core::Contact,
    initial: &core::State,
    settings: &core::Settings,
    interrupt: &mut dyn FnMut() -> bool,
) -> core::Result<TwoMassRun> {
    let sol = core::simulate(system, contact, initial, settings, interrupt)?;
    let h = sol.history;
    Ok(TwoMassRun {
        history: [
            h.time,
            h.main_displacement,
            h.main_velocity,
            h.impact_displacement,
            h.impact_velocity,
            h.contact_force,
        ],
        contacts: sol.contacts.iter().map(|c| contact_row!(c)).collect(),
        steps: sol.steps,
        rejected_steps: sol.rejected_steps,
        rhs_evaluations: sol.rhs_evaluations,
        grazing_contacts: sol.grazing_contacts,
        final_time: sol.final_time,
        final_state: sol.final_state,
        energy_growth: sol.energy_growth,
        energy_residual: sol.energy_residual,
    })
}

/// The run of the preset by the general kernel, with the options a 0.2 run
/// of the same system takes (so that both give the same bits); fixed
/// stepping by the 0.1 kernel.
pub(crate) fn run(
    system: &core::ImpactDamper,
    contact: &core::Contact,
    initial: &core::State,
    settings: &core::Settings,
    options: &core::MethodOptions,
    interrupt: &mut dyn FnMut() -> bool,
) -> core::Result<TwoMassRun> {
    if settings.stepping == core::Stepping::Fixed {
        return legacy(system, contact, initial, settings, interrupt);
    }
    // The two-mass message first: it names the two masses' displacements.
    initial.check_apart(system.clearance)?;
    let assembly = system.assembly(contact)?;
    let y0 = initial.vector(&assembly)?;
    let mut stepper = AnyStepper::new(
        &assembly,
        settings.method.name(),
        options.rtol,
        options.atol,
        options.beta,
        options.gamma,
        options.spectral_radius,
    )?;
    let sol = stepper.integrate_stepped(
        &assembly,
        &y0,
        &settings.run_options(),
        settings.kernel_stepping(),
        interrupt,
    )?;
    Ok(TwoMassRun {
        history: columns(system, contact, &sol)?,
        contacts: sol.contacts.iter().map(|c| contact_row!(c)).collect(),
        steps: sol.steps,
        rejected_steps: sol.rejected_steps,
        rhs_evaluations: sol.rhs_evaluations,
        grazing_contacts: sol.grazing_contacts,
        final_time: sol.final_time,
        final_state: core::State::of_vector(&sol.final_state),
        energy_growth: energy_growth(&assembly, &y0, &sol),
        energy_residual: relative_residual(&sol),
    })
}

/// The two-mass history's columns from the kept rows (`[w, y, w', y']`
/// each), and the contact force from each row's state while a contact is
/// open there (from its onset to before its separation, its approach rate
/// latched), zero elsewhere: as the 0.1 kernel reported it, after the
/// switch at an onset row and before it at a separation row.
// Not the kernel's contact_forces: at an onset row it holds the force before
// the switch (0) in some runs and after it (c1 times the approach) in others.
fn columns(
    system: &core::ImpactDamper,
    contact: &core::Contact,
    sol: &SystemSolution,
) -> core::Result<[Vec<f64>; 6]> {
    let rows = sol.time.len();
    let column = |k: usize| (0..rows).map(|r| sol.states[4 * r + k]).collect();
    let mut force = vec![0.0; rows];
    let mut open = sol.contacts.iter().peekable();
    for (row, (&t, value)) in sol.time.iter().zip(force.iter_mut()).enumerate() {
        while open.next_if(|c| c.separation <= t).is_some() {}
        let Some(c) = open.peek().filter(|c| c.onset <= t) else {
            continue;
        };
        let s = core::State::of_vector(&sol.states[4 * row..4 * row + 4]);
        *value = system.contact_force(contact, &s, c.approach_speed)?;
    }
    Ok([
        sol.time.clone(),
        column(0),
        column(2),
        column(1),
        column(3),
        force,
    ])
}

/// `max(E) / E(0) - 1` over the kept rows and the end (NaN from rest).
// The general kernel does not follow the growth itself: taken from the rows.
fn energy_growth(system: &Assembly, start: &[f64], sol: &SystemSolution) -> f64 {
    let modes = [Mode::Compliant { approach_rate: 0.0 }; 2];
    let initial = system.energy(start, &modes);
    if initial <= 0.0 {
        return f64::NAN;
    }
    let largest = sol
        .states
        .chunks_exact(4)
        .map(|row| system.energy(row, &modes))
        .fold(system.energy(&sol.final_state, &modes), f64::max);
    largest / initial - 1.0
}

/// The balance's residual at the end relative to the energy in play (the
/// larger stored energy, the work in and the losses); NaN with none.
fn relative_residual(sol: &SystemSolution) -> f64 {
    let e = sol.energy;
    let scale =
        e.stored_start.abs().max(e.stored_end.abs()) + e.input_work.abs() + e.dissipated.abs();
    if scale > 0.0 {
        e.residual.abs() / scale
    } else {
        f64::NAN
    }
}
