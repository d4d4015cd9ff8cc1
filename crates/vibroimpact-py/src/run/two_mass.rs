//! A two-mass run as the rows the binding's `Solution` shows, on the general
//! kernel (the preset [`core::ImpactDamper::spec`]) for every method with
//! events but the paper's lagged Newmark, and on the 0.1 kernel for those
//! and the paper's fixed stepping until the general kernel has them.

use vibroimpact_core as core;

use core::kernel::events::{PairContact, SystemSolution};
use core::methods::registry::AnyStepper;
use core::model::assembly::{Assembly, Mode};

/// A contact of either kernel as a row of the table (`CONTACT_COLUMNS`),
/// with its energy change.
macro_rules! contact_row {
    ($c:expr, $energy_change:expr) => {
        [
            $c.onset,
            $c.separation,
            $c.duration,
            $c.max_indentation,
            $c.approach_speed,
            $c.rebound_speed,
            $c.restitution,
            $c.energy_dissipated,
            $energy_change,
        ]
    };
}

/// A two-mass run's results, whichever kernel made them.
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

/// Whether a run with `settings` takes the general kernel: the fixed
/// stepping is the 0.1 kernel's alone, and so is the paper's lagged Newmark
/// until the general kernel bounds the energy its contacts create by
/// `energy_tolerance` alone (the 0.1 kernel's `contact_creation_limit`).
pub(crate) fn on_general_kernel(settings: &core::Settings) -> bool {
    settings.stepping == core::Stepping::Events
        && !matches!(settings.method, core::Method::Newmark { .. })
}

/// The run by the 0.1 kernel.
pub(crate) fn legacy(
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
        contacts: sol
            .contacts
            .iter()
            .map(|r| contact_row!(r, r.energy_change))
            .collect(),
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
/// of the same system takes (so that both give the same bits).
pub(crate) fn general(
    system: &core::ImpactDamper,
    contact: &core::Contact,
    initial: &core::State,
    settings: &core::Settings,
    options: &core::MethodOptions,
    interrupt: &mut dyn FnMut() -> bool,
) -> core::Result<TwoMassRun> {
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
    let sol = stepper.integrate(&assembly, &y0, &settings.run_options(), interrupt)?;
    let rows = Rows::of(&sol);
    let in_play = |y: &[f64]| assembly.energy(y, &[Mode::Compliant { approach_rate: 0.0 }; 2]);
    Ok(TwoMassRun {
        history: rows.columns(system, contact, &sol.contacts)?,
        contacts: sol
            .contacts
            .iter()
            .map(|c| contact_row!(c, rows.energy_change(c, &in_play)))
            .collect(),
        steps: sol.steps,
        rejected_steps: sol.rejected_steps,
        rhs_evaluations: sol.rhs_evaluations,
        grazing_contacts: sol.grazing_contacts,
        final_time: sol.final_time,
        final_state: core::State::of_vector(&sol.final_state),
        energy_growth: rows.energy_growth(&assembly, &y0, &sol.final_state),
        energy_residual: relative_residual(&sol),
    })
}

/// The kept rows of a general run of the preset: `[w, y, w', y']` each.
struct Rows<'a> {
    time: &'a [f64],
    states: &'a [f64],
}

impl<'a> Rows<'a> {
    fn of(sol: &'a SystemSolution) -> Self {
        Self {
            time: &sol.time,
            states: &sol.states,
        }
    }

    fn state(&self, row: usize) -> &'a [f64] {
        &self.states[4 * row..4 * row + 4]
    }

    /// The two-mass history's columns; the contact force from each row's
    /// state while a contact is open there (from its onset to before its
    /// separation, with its approach rate latched), zero elsewhere.
    // Interim: the general kernel keeps no contact-force column yet.
    fn columns(
        &self,
        system: &core::ImpactDamper,
        contact: &core::Contact,
        contacts: &[PairContact],
    ) -> core::Result<[Vec<f64>; 6]> {
        let n = self.time.len();
        let column = |k: usize| (0..n).map(|r| self.states[4 * r + k]).collect();
        let mut force = vec![0.0; n];
        let mut open = contacts.iter().peekable();
        for (row, (&t, value)) in self.time.iter().zip(force.iter_mut()).enumerate() {
            while open.next_if(|c| c.separation <= t).is_some() {}
            let Some(c) = open.peek().filter(|c| c.onset <= t) else {
                continue;
            };
            let s = core::State::of_vector(self.state(row));
            *value = system.contact_force(contact, &s, c.approach_speed)?;
        }
        Ok([
            self.time.to_vec(),
            column(0),
            column(2),
            column(1),
            column(3),
            force,
        ])
    }

    /// The row kept at `time` exactly (events are step ends), if any.
    fn at(&self, time: f64) -> Option<usize> {
        let row = self.time.partition_point(|t| *t < time);
        (self.time.get(row) == Some(&time)).then_some(row)
    }

    /// The mechanical energy at separation minus at onset (J), from the rows
    /// kept there; NaN for a contact still open or rows not kept.
    // Interim: the general kernel reports no energy change per contact yet.
    fn energy_change(&self, c: &PairContact, energy: &dyn Fn(&[f64]) -> f64) -> f64 {
        match (self.at(c.onset), self.at(c.separation)) {
            (Some(onset), Some(separation)) => {
                energy(self.state(separation)) - energy(self.state(onset))
            }
            _ => f64::NAN,
        }
    }

    /// `max(E) / E(0) - 1` over the kept rows and the end (NaN from rest).
    // Interim: the general kernel does not follow the growth itself.
    fn energy_growth(&self, system: &Assembly, start: &[f64], end: &[f64]) -> f64 {
        let modes = [Mode::Compliant { approach_rate: 0.0 }; 2];
        let initial = system.energy(start, &modes);
        if initial <= 0.0 {
            return f64::NAN;
        }
        let largest = (0..self.time.len())
            .map(|row| system.energy(self.state(row), &modes))
            .fold(system.energy(end, &modes), f64::max);
        largest / initial - 1.0
    }
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
