//! A two-mass run as the rows the binding's `Solution` shows. Every method
//! runs on the 0.1 kernel until the general one keeps the earlier issues'
//! bars for this system: the two-mass preset ([`core::ImpactDamper::spec`])
//! on the general kernel missed issue 3's (DOP853 within 1e-10 of the exact
//! collision in 22 us against a 20 us goal; 86 times scipy's speed at 1e-8
//! against 100) and bench_steps' (the paper's Newmark 2.1e7 against 9.4e7
//! steps/s, a one-step call 5.7 us against 5 us). `vi.simulate` of the same
//! system as a `vibroimpact.System` (a 0.2 file, or `vi.load` of a 0.1 file)
//! runs it on the general kernel: the same bits for the paper's fixed-step
//! Newmark, round-off for the other methods.

use vibroimpact_core as core;

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
pub(crate) fn run(
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
