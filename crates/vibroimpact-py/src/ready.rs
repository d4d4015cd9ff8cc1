//! A checked system with its method and its run limits, ready to run from
//! any state: what a prepared system, a simulation and the tangent runs
//! share (the GIL released around each run).

use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact_core as core;
use vibroimpact_core::kernel::events::{CarriedContact, RunOptions, Stepping};
use vibroimpact_core::kernel::reductions::ReduceOptions;
use vibroimpact_core::methods::registry::{
    check_scales, check_settings, AnyStepper, Options, RunPlan, RunScales, DEFAULT_MAX_ROWS,
    DEFAULT_MAX_STEPS, ENERGY_TOLERANCE, SYSTEM,
};
use vibroimpact_core::model::assembly::{resumed_state, Assembly};
use vibroimpact_core::model::structure::Structure;

use crate::convert::system::system_spec;
use crate::errors::{released, to_py, InvalidInputError};

/// The numbers a run takes beside its system and method.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    dt: Option<f64>,
    max_steps: u64,
    max_rows: u64,
    energy_tolerance: f64,
    /// Events, or fixed steps (see `core::kernel::fixed`).
    stepping: Stepping,
}

impl Limits {
    /// The limits as given, each left out (None) taking the core registry's
    /// default for a system, checked with the method's `options` against the
    /// registry's ranges.
    pub(crate) fn new(
        method: &str,
        t_end: f64,
        dt: Option<f64>,
        options: &Options,
        (max_steps, max_rows, energy_tolerance): (Option<u64>, Option<u64>, Option<f64>),
        (stepping, contact_timing): (Option<&str>, Option<&str>),
    ) -> PyResult<Self> {
        let energy_tolerance = energy_tolerance.unwrap_or(ENERGY_TOLERANCE.default_value());
        check_method(t_end, dt, options, energy_tolerance)?;
        Ok(Self {
            dt,
            max_steps: max_steps.unwrap_or(DEFAULT_MAX_STEPS),
            max_rows: max_rows.unwrap_or(DEFAULT_MAX_ROWS),
            energy_tolerance,
            stepping: stepping_of(
                match stepping {
                    Some(stepping) => stepping,
                    None => SYSTEM.stepping(method).map_err(to_py)?,
                },
                contact_timing.unwrap_or(SYSTEM.contact_timing),
            )?,
        })
    }
}

/// A checked system with its method, ready to run from any state.
pub(crate) struct Ready {
    pub(crate) system: Assembly,
    pub(crate) stepper: AnyStepper,
    limits: Limits,
    /// What the up-front limits read of a run (see [`Self::check_length`]).
    plan: Plan,
}

/// The method, its options and the system's scales, for the registry's
/// up-front limits of a run of any length.
struct Plan {
    method: String,
    options: Options,
    structure: Structure,
    coordinates: usize,
    forcing: Vec<(usize, f64)>,
}

impl Ready {
    pub(crate) fn new(
        spec: &Bound<'_, PyDict>,
        method: &str,
        t_end: f64,
        options: &Options,
        limits: Limits,
    ) -> PyResult<Self> {
        let system_spec = system_spec(spec, t_end)?;
        let system = Assembly::new(&system_spec).map_err(to_py)?;
        let stepper = AnyStepper::new(&system, method, options).map_err(to_py)?;
        stepper
            .check_stepping(&system, limits.stepping)
            .map_err(to_py)?;
        let scales = RunScales::of(&system_spec);
        let plan = Plan {
            method: method.to_owned(),
            options: *options,
            structure: system_spec.structure.clone(),
            coordinates: scales.coordinates,
            forcing: scales.forcing,
        };
        Ok(Self {
            system,
            stepper,
            limits,
            plan,
        })
    }

    /// Refuse a run of `length` s (asked for as `field`) that the system's
    /// limits cannot complete, before any step, as a simulation's run is
    /// refused (the registry's `check_run`: more steps than `max_steps`,
    /// a step that cannot resolve the fastest mode or the forcing): the
    /// tangent map's and the Lyapunov spectrum's runs had no bound but
    /// `max_steps` counted as they went (hours, at `t_end = 1e300`).
    pub(crate) fn check_length(&self, length: f64, field: &str) -> PyResult<()> {
        let plan = RunPlan {
            method: &self.plan.method,
            dt: self.limits.dt,
            t_end: length,
            max_steps: self.limits.max_steps,
            max_rows: self.limits.max_rows,
            every: 1,
            history: false,
            strobe_period: None,
            options: self.plan.options,
        };
        let scales = RunScales {
            structure: &self.plan.structure,
            coordinates: self.plan.coordinates,
            forcing: self.plan.forcing.clone(),
        };
        check_scales(&scales, &plan).map_err(|e| {
            let text = e.to_string().replace("[solver] t_end", field);
            InvalidInputError::new_err(text.replace("shorten t_end", &format!("shorten {field}")))
        })
    }

    /// Integrate from `y0` with the GIL released (see [`crate::released`]).
    pub(crate) fn run(
        &mut self,
        py: Python<'_>,
        start: (&[f64], &[Option<CarriedContact>]),
        t_end: f64,
        history: (bool, u64),
        record_from: Option<f64>,
        strobe_period: Option<f64>,
    ) -> PyResult<core::kernel::events::SystemSolution> {
        released(py, |interrupt| {
            self.integrate(start, t_end, history, record_from, strobe_period, interrupt)
        })
    }

    /// The options of a run to `t_end` (see [`Self::integrate`]).
    pub(crate) fn options(
        &self,
        t_end: f64,
        history: (bool, u64),
        record_from: Option<f64>,
        strobe_period: Option<f64>,
    ) -> RunOptions {
        let strobe_period = strobe_period.unwrap_or(f64::INFINITY);
        let limits = self.limits;
        let dt = self.stepper.step(limits.dt, t_end, strobe_period);
        RunOptions {
            dt,
            t_end,
            every: history.1,
            keep_history: history.0,
            max_steps: limits.max_steps,
            max_rows: limits.max_rows,
            energy_tolerance: limits.energy_tolerance,
            reduce: ReduceOptions {
                record_from: record_from.unwrap_or(f64::INFINITY),
                strobe_period,
                mean_square: true,
                contacts_from: f64::NEG_INFINITY,
            },
        }
    }

    /// Integrate from `y0`, continuing the contacts `carried` (the caller
    /// holds no GIL).
    pub(crate) fn integrate(
        &mut self,
        start: (&[f64], &[Option<CarriedContact>]),
        t_end: f64,
        history: (bool, u64),
        record_from: Option<f64>,
        strobe_period: Option<f64>,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> core::Result<core::kernel::events::SystemSolution> {
        let options = self.options(t_end, history, record_from, strobe_period);
        let (system, stepping) = (&self.system, self.limits.stepping);
        // The registry's run, which gives an energy error its method's advice.
        self.stepper
            .integrate_continued(system, start, &options, stepping, interrupt)
    }

    /// The full state of the flat state `z` (x then v).
    pub(crate) fn full_state(&self, z: &[f64]) -> core::Result<Vec<f64>> {
        full_state(&self.system, z)
    }

    /// The stroboscopic map over `t_end` from the flat state `z` with its
    /// Jacobian from the tangent flow (row-major).
    /// Its grazings into `grazed` (the last map's: the orbit's, once Newton's
    /// method has converged, as `shoot` returns it).
    pub(crate) fn map_tangent(
        &mut self,
        z: &[f64],
        t_end: f64,
        interrupt: &mut dyn FnMut() -> bool,
        grazed: &mut Vec<core::analysis::tangent::Grazing>,
    ) -> core::Result<(Vec<f64>, Vec<f64>)> {
        let y0 = self.full_state(z)?;
        let options = self.options(t_end, (false, 1), None, None);
        let Self {
            system, stepper, ..
        } = self;
        let mut flow = core::analysis::tangent::Tangent::product(system)?;
        let end = stepper.integrate_observed(system, &y0, &options, interrupt, &mut flow)?;
        let size = 2 * system.dim;
        grazed.clear();
        grazed.extend_from_slice(flow.grazings());
        Ok((end.final_state[..size].to_vec(), flow.matrix().to_vec()))
    }

    /// The stroboscopic map over `t_end` from the flat state `z` (x then v).
    pub(crate) fn map(
        &mut self,
        z: &[f64],
        t_end: f64,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> core::Result<Vec<f64>> {
        let y0 = self.full_state(z)?;
        Ok(self
            .integrate((&y0, &[]), t_end, (false, 1), None, None, interrupt)?
            .final_state)
    }
}

/// The full state (with the energy accumulators) of `system`'s flat state `z`
/// (x then v).
pub(crate) fn full_state(system: &Assembly, z: &[f64]) -> core::Result<Vec<f64>> {
    let (n, d) = (system.n, system.dim);
    resumed_state(system, [&z[..n], &z[d..d + n], &z[n..d], &z[d + n..]])
}

/// The settings a run takes, each finite and in its range: the core
/// registry's check.
pub(crate) fn check_method(
    t_end: f64,
    dt: Option<f64>,
    options: &Options,
    energy_tolerance: f64,
) -> PyResult<()> {
    check_settings(t_end, dt, *options, energy_tolerance)
        .map(|_| ())
        .map_err(to_py)
}

/// The kernel's stepping from `[solver] stepping` and `contact_timing`.
pub(crate) fn stepping_of(stepping: &str, contact_timing: &str) -> PyResult<Stepping> {
    Stepping::parse(stepping, contact_timing).map_err(to_py)
}
