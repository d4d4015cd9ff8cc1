//! The core's registry of methods as Python data, and its up-front run
//! limits: converted here, defined and checked in the core
//! (`vibroimpact_core::methods::registry`).

use pyo3::prelude::*;
use pyo3::types::PyDict;
use vibroimpact_core::methods::registry::{
    self, check_scales, OptionSpec, RunPlan, RunScales, METHOD_OPTIONS, METHOD_SPECS,
};

use crate::convert::system::{entries, get, structure, system_spec};
use crate::errors::to_py;

/// `{name: {default, low, high, low_open, allowed}}` of `options`.
fn options_dict<'py>(py: Python<'py>, options: &[OptionSpec]) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    for option in options {
        let entry = PyDict::new(py);
        // max_steps is a whole number in Python.
        if option.name == registry::MAX_STEPS.name {
            entry.set_item("default", registry::DEFAULT_MAX_STEPS)?;
        } else {
            entry.set_item("default", option.default)?;
        }
        entry.set_item("low", option.low)?;
        entry.set_item("high", option.high)?;
        entry.set_item("low_open", option.low_open)?;
        entry.set_item("allowed", option.allowed)?;
        out.set_item(option.name, entry)?;
    }
    Ok(out)
}

/// `METHODS`: method -> {kind, steppings, options: {name: {default, low,
/// high, low_open, allowed}}}, in the registry's order; `METHOD_OPTIONS`:
/// the options every run is given and checked, whatever its method; and
/// `RUN_DEFAULTS`: model kind ("two-mass", "system") -> {method,
/// fixed_by_default, contact_timing}.
pub(crate) fn add_registry(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    let methods = PyDict::new(py);
    for spec in &METHOD_SPECS {
        let entry = PyDict::new(py);
        entry.set_item("kind", spec.kind.name())?;
        entry.set_item("steppings", spec.steppings.to_vec())?;
        entry.set_item("options", options_dict(py, spec.options)?)?;
        methods.set_item(spec.name, entry)?;
    }
    m.add("METHODS", methods)?;
    let mut all = METHOD_OPTIONS.to_vec();
    all.push(registry::MAX_STEPS);
    m.add("METHOD_OPTIONS", options_dict(py, &all)?)?;
    let defaults = PyDict::new(py);
    for kind in &registry::RUN_DEFAULTS {
        let entry = PyDict::new(py);
        entry.set_item("method", kind.method)?;
        entry.set_item("fixed_by_default", kind.fixed_by_default.to_vec())?;
        entry.set_item("contact_timing", kind.contact_timing)?;
        defaults.set_item(kind.name, entry)?;
    }
    m.add("RUN_DEFAULTS", defaults)?;
    m.add("MAX_PERIODS", registry::MAX_PERIODS)?;
    // Internal (not in __all__): vibroimpact.system's checks call them.
    m.setattr("_check_run", wrap_pyfunction!(check_run, m)?)?;
    m.setattr("_check_settings", wrap_pyfunction!(check_settings, m)?)?;
    m.setattr(
        "_check_forcing_period",
        wrap_pyfunction!(check_forcing_period, m)?,
    )?;
    Ok(())
}

/// The harmonic frequencies (Hz) of a checked spec's `excitation` tables,
/// each with its index.
fn forcing(spec: &Bound<'_, PyDict>) -> PyResult<Vec<(usize, f64)>> {
    let mut found = Vec::new();
    for (index, table) in entries(spec, "excitation")?.iter().enumerate() {
        let place = format!("excitation {index}");
        match get::<String>(table, &place, "signal")?.as_str() {
            "harmonic" => found.push((index, get(table, &place, "frequency")?)),
            "harmonics" => found.extend(
                get::<Vec<f64>>(table, &place, "frequencies")?
                    .into_iter()
                    .map(|f| (index, f)),
            ),
            _ => {}
        }
    }
    Ok(found)
}

/// Refuse a run of the checked 0.2 `spec` that its settings cannot complete
/// within its limits (the core's `registry::check_run`): too many steps, a
/// step or a method that cannot resolve the fastest mode or a harmonic
/// forcing, a history or strobe record beyond `max_rows` or the records'
/// memory. `beta` and `gamma` (None: the registry's defaults): a Newmark
/// step's. Raises ``InvalidInputError`` naming the key and what is allowed.
#[pyfunction]
#[pyo3(signature = (spec, *, method, dt, t_end, max_steps, max_rows, every, history, strobe_period, beta=None, gamma=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn check_run(
    spec: &Bound<'_, PyDict>,
    method: &str,
    #[pyo3(from_py_with = crate::convert::optional::dt)] dt: Option<f64>,
    #[pyo3(from_py_with = crate::convert::arg::t_end)] t_end: f64,
    #[pyo3(from_py_with = crate::convert::max_steps_arg)] max_steps: u64,
    #[pyo3(from_py_with = crate::convert::max_rows_arg)] max_rows: Option<u64>,
    #[pyo3(from_py_with = crate::convert::every_arg)] every: u64,
    history: bool,
    #[pyo3(from_py_with = crate::convert::optional::strobe_period)] strobe_period: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::beta)] beta: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::gamma)] gamma: Option<f64>,
) -> PyResult<()> {
    let structure_dict = spec
        .get_item("structure")?
        .and_then(|d| d.cast_into::<PyDict>().ok());
    let Some(structure_dict) = structure_dict else {
        return Err(crate::errors::InvalidInputError::new_err(
            "[structure] is required",
        ));
    };
    let built = structure(&structure_dict)?;
    let scales = RunScales {
        structure: &built,
        coordinates: built.dofs() + entries(spec, "damper")?.len(),
        forcing: forcing(spec)?,
    };
    let plan = RunPlan {
        method,
        dt,
        t_end,
        max_steps,
        max_rows: max_rows.unwrap_or(u64::MAX),
        every,
        history,
        strobe_period,
        options: registry::Options::or_defaults(None, None, beta, gamma, None),
    };
    check_scales(&scales, &plan).map_err(to_py)
}

/// Check a run's settings against the registry's ranges (the core's
/// `check_settings`: `t_end`, `dt` where given, the method options every run
/// is given whatever its method, `energy_tolerance`), each left out (None)
/// the registry's default; raises ``InvalidInputError`` naming the first
/// outside and what is allowed.
#[pyfunction]
#[pyo3(signature = (*, t_end, dt=None, rtol=None, atol=None, beta=None, gamma=None, spectral_radius=None, energy_tolerance=None))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn check_settings(
    #[pyo3(from_py_with = crate::convert::arg::t_end)] t_end: f64,
    #[pyo3(from_py_with = crate::convert::optional::dt)] dt: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::rtol)] rtol: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::atol)] atol: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::beta)] beta: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::gamma)] gamma: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::spectral_radius)] spectral_radius: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::energy_tolerance)] energy_tolerance: Option<
        f64,
    >,
) -> PyResult<()> {
    let options = registry::Options::or_defaults(rtol, atol, beta, gamma, spectral_radius);
    let energy_tolerance = energy_tolerance.unwrap_or(registry::ENERGY_TOLERANCE.default_value());
    registry::check_settings(t_end, dt, options, energy_tolerance)
        .map(|_| ())
        .map_err(to_py)
}

/// Refuse an analysis's `forcing_period` (s) of the checked 0.2 `spec` that
/// no run of its settings can step through (the core's
/// `registry::check_forcing_period`); raises ``InvalidInputError`` naming the
/// frequency and the range a run can take.
#[pyfunction]
#[pyo3(signature = (spec, *, forcing_period, method, dt, atol, max_steps))]
pub(crate) fn check_forcing_period(
    spec: &Bound<'_, PyDict>,
    #[pyo3(from_py_with = crate::convert::arg::forcing_period)] forcing_period: f64,
    method: &str,
    #[pyo3(from_py_with = crate::convert::optional::dt)] dt: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::atol)] atol: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional_max_steps)] max_steps: Option<u64>,
) -> PyResult<()> {
    // Harmonic loads only (the check reads no other): no signal needs the
    // run's length.
    let system = system_spec(spec, 1.0)?;
    let plan = registry::ForcingPlan {
        method,
        dt,
        atol: atol.unwrap_or(registry::ATOL.default_value()),
        max_steps: max_steps.unwrap_or(registry::DEFAULT_MAX_STEPS),
    };
    registry::check_forcing_period(&system, &plan, forcing_period).map_err(to_py)
}
