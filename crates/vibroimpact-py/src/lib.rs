//! `vibroimpact._core`: the Python face of vibroimpact-core. It only converts
//! arguments and results, releases the GIL around integration and maps each
//! core error to its own Python exception.

use pyo3::prelude::*;
use vibroimpact_core as core;
use vibroimpact_core::methods::registry as core_registry;

mod convert;
mod errors;
mod helpers;
mod inputs;
mod ready;
mod registry;
mod run;
mod system;
mod tangent;

use errors::*;
use helpers::*;
use inputs::*;
use run::*;

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    // NumPy's C API is looked up (a Python import) on the first array made.
    // Made here, not after a run: a Ctrl-C pending at the end of a run made
    // that import fail, and the numpy crate panics where it fails.
    numpy::PyArray1::<f64>::zeros(py, 0, false);
    m.add("InvalidInputError", py.get_type::<InvalidInputError>())?;
    m.add(
        "NumericalBlowUpError",
        py.get_type::<NumericalBlowUpError>(),
    )?;
    m.add("EnergyBalanceError", py.get_type::<EnergyBalanceError>())?;
    m.add("SimulationError", py.get_type::<SimulationError>())?;
    m.add("RestitutionWarning", py.get_type::<RestitutionWarning>())?;
    m.add_class::<ImpactDamper>()?;
    m.add_class::<Contact>()?;
    m.add_class::<InitialState>()?;
    m.add_class::<Solution>()?;
    m.add_class::<ContactTable>()?;
    // How a pickled two-mass result is made again (not in `__all__`).
    m.setattr("_contact_table", wrap_pyfunction!(run::_contact_table, m)?)?;
    m.setattr(
        "_two_mass_solution",
        wrap_pyfunction!(run::_two_mass_solution, m)?,
    )?;
    m.add_class::<BeamMode>()?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(system::simulate_system, m)?)?;
    m.add_function(wrap_pyfunction!(system::linear_parts, m)?)?;
    m.add_class::<system::PreparedSystem>()?;
    m.add_function(wrap_pyfunction!(system::run_study, m)?)?;
    m.add_function(wrap_pyfunction!(tangent::tangent_map, m)?)?;
    m.add_function(wrap_pyfunction!(tangent::lyapunov_spectrum, m)?)?;
    m.add_function(wrap_pyfunction!(tangent::interactions, m)?)?;
    m.add_function(wrap_pyfunction!(check_solver, m)?)?;
    m.add_function(wrap_pyfunction!(hertz_stiffness, m)?)?;
    // Internal (not in __all__): vibroimpact.analysis.forcing_period wraps it.
    m.setattr("_forcing_period", wrap_pyfunction!(forcing_period, m)?)?;
    // Internal: vibroimpact.analysis.steady_state's criterion, the studies' own.
    m.setattr("_strobe_period", wrap_pyfunction!(strobe_period, m)?)?;
    m.add_function(wrap_pyfunction!(cantilever_mode, m)?)?;
    m.add_function(wrap_pyfunction!(cantilever_root, m)?)?;
    m.add_function(wrap_pyfunction!(cantilever_mode_shape, m)?)?;
    m.add_function(wrap_pyfunction!(goldsmith_contact_duration, m)?)?;
    m.add_function(wrap_pyfunction!(goldsmith_max_indentation, m)?)?;
    m.add_function(wrap_pyfunction!(linear_contact_duration, m)?)?;
    m.add_function(wrap_pyfunction!(adequacy, m)?)?;
    registry::add_registry(m)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    // The run limits' defaults and ranges: the core registry's.
    m.add("DEFAULT_MAX_ROWS", core_registry::DEFAULT_MAX_ROWS)?;
    m.add("MAX_RECORD_BYTES", core::MAX_RECORD_BYTES)?;
    m.add(
        "MAX_SIGNAL_SAMPLES",
        core::model::signals::MAX_SIGNAL_SAMPLES,
    )?;
    m.add(
        "DEFAULT_ENERGY_TOLERANCE",
        core_registry::ENERGY_TOLERANCE.default_value(),
    )?;
    m.add(
        "RTOL_RANGE",
        (core_registry::RTOL.low, core_registry::RTOL.high),
    )?;
    m.add("ATOL_MAX", core_registry::ATOL.high)?;
    m.add("MAX_ENERGY_TOLERANCE", core_registry::ENERGY_TOLERANCE.high)?;
    m.add("MAX_POINTS", core::model::assembly::MAX_POINTS)?;
    m.add("MAX_PAIRS", core::model::assembly::MAX_PAIRS)?;
    Ok(())
}
