//! The tangent flow of a prepared system (see `core::analysis::tangent`):
//! its map over a run and its Lyapunov spectrum, each computed with the GIL
//! released.

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use vibroimpact_core as core;
use vibroimpact_core::analysis::tangent::{self, Grazing, Shifted, Tangent};
use vibroimpact_core::methods::registry::T_END;
use vibroimpact_core::model::assembly::Scratch;

use crate::errors::{released, to_py, InvalidInputError};
use crate::ready::{full_state, Ready};
use crate::system::PreparedSystem;

/// The prepared system's run state, locked, with `state` checked to be `2 dim`
/// values.
fn ready_for<'a>(
    py: Python<'_>,
    prepared: &'a PreparedSystem,
    state: &[f64],
) -> PyResult<std::sync::MutexGuard<'a, Ready>> {
    prepared.locked(py, Some(state))
}

/// Each parameter's two systems, made at `p + delta` and `p - delta`: each
/// copied with its lock held alone (one system given as both, or as the run's
/// own, had been locked twice at once: a hang).
fn shifted_systems(
    py: Python<'_>,
    parameters: Vec<(PyRef<'_, PreparedSystem>, PyRef<'_, PreparedSystem>, f64)>,
) -> PyResult<Vec<Shifted>> {
    parameters
        .into_iter()
        .map(|(plus, minus, delta)| {
            let plus = plus.locked(py, None)?.system.clone();
            let minus = minus.locked(py, None)?.system.clone();
            Ok(Shifted { plus, minus, delta })
        })
        .collect()
}

/// The grazings as a list of `(time s, pair name, closing speed m/s)`.
pub(crate) fn grazings<'py>(
    py: Python<'py>,
    system: &core::model::assembly::Assembly,
    found: &[Grazing],
) -> PyResult<Bound<'py, PyList>> {
    let rows: Vec<(f64, String, f64)> = found
        .iter()
        .map(|g| (g.time, system.pairs[g.pair].clone(), g.speed))
        .collect();
    PyList::new(py, rows)
}

/// The tangent map of a run of `t_end` s from the flat state `state` (x then
/// v): `state` (the end's), `rate` (its derivative in time there), `matrix` (the derivative of the end state by the
/// start state, row-major), `impacts` (events whose impulses acted, or where a
/// compliant contact began),
/// `grazings` (list of `(time, pair, speed)`, where the flow has no
/// derivative) and `parameters` (the derivatives of the end state by each of
/// `parameters`, row-major `2 dim x m`, at fixed `t_end`: each given as the
/// system made at `p + delta`, the one at `p - delta`, and `delta`).
#[pyfunction]
#[pyo3(signature = (prepared, state, t_end, parameters = Vec::new()))]
pub fn tangent_map<'py>(
    py: Python<'py>,
    prepared: &PreparedSystem,
    #[pyo3(from_py_with = crate::convert::state_arg)] state: Vec<f64>,
    #[pyo3(from_py_with = crate::convert::arg::t_end)] t_end: f64,
    parameters: Vec<(PyRef<'py, PreparedSystem>, PyRef<'py, PreparedSystem>, f64)>,
) -> PyResult<Bound<'py, PyDict>> {
    T_END.check(t_end).map_err(to_py)?;
    let shifted = shifted_systems(py, parameters)?;
    let mut guard = ready_for(py, prepared, &state)?;
    let ready: &mut Ready = &mut guard;
    ready.check_length(t_end, "t_end")?;
    let (end, rate, matrix, impacts, found, columns) = released(py, |interrupt| {
        let y0 = ready.full_state(&state)?;
        let mut options = ready.options(t_end, (false, 1), None, None);
        // The map reads no contact: none kept (a long run's table had grown
        // toward the records' limit for nothing).
        options.reduce.contacts_from = f64::INFINITY;
        let Ready {
            system, stepper, ..
        } = ready;
        let mut flow = Tangent::with_parameters(system, shifted)?;
        let end = stepper.integrate_observed(system, &y0, &options, interrupt, &mut flow)?;
        let size = 2 * system.dim;
        // The state's rate at the end, in the end's modes: a gap's second
        // derivative there (a grazing's location, `vibroimpact.analysis.grazing`).
        let full = full_state(system, &end.final_state[..size])?;
        let mut rate = vec![0.0; full.len()];
        let mut scratch = Scratch::new(system);
        system.rates(end.final_time, &full, flow.modes(), &mut scratch, &mut rate);
        rate.truncate(size);
        Ok((
            end.final_state[..size].to_vec(),
            rate,
            flow.matrix().to_vec(),
            flow.impacts(),
            flow.grazings().to_vec(),
            flow.parameter_columns().to_vec(),
        ))
    })?;
    let out = PyDict::new(py);
    out.set_item("state", end.into_pyarray(py))?;
    out.set_item("rate", rate.into_pyarray(py))?;
    out.set_item("matrix", matrix.into_pyarray(py))?;
    out.set_item("impacts", impacts)?;
    out.set_item("grazings", grazings(py, &ready.system, &found)?)?;
    out.set_item("parameters", columns.into_pyarray(py))?;
    Ok(out)
}

/// The Lyapunov spectrum from the flat state `state` over `blocks` runs of
/// `block_time` s each, each from the last one's end (see
/// `core::analysis::tangent::lyapunov_blocks`), each continuing the
/// compliant contacts the last left open, the first those `carried` (as
/// `PreparedSystem.run`'s): `exponents` (1/s, descending), `standard_error`
/// (over the blocks), `time` (s), `impacts`, `grazings`.
#[pyfunction]
#[pyo3(signature = (prepared, state, block_time, blocks, *, carried=None))]
pub fn lyapunov_spectrum<'py>(
    py: Python<'py>,
    prepared: &PreparedSystem,
    #[pyo3(from_py_with = crate::convert::state_arg)] state: Vec<f64>,
    #[pyo3(from_py_with = crate::convert::arg::block_time)] block_time: f64,
    #[pyo3(from_py_with = crate::convert::blocks_arg)] blocks: u64,
    carried: Option<Vec<Option<[f64; 4]>>>,
) -> PyResult<Bound<'py, PyDict>> {
    if !(block_time.is_finite() && block_time > 0.0) {
        return Err(InvalidInputError::new_err(format!(
            "block_time must be a finite number of seconds > 0, got {block_time}"
        )));
    }
    if !(1..=1_000_000).contains(&blocks) {
        return Err(InvalidInputError::new_err(format!(
            "blocks must be a whole number in [1, 1000000], got {blocks}"
        )));
    }
    let mut guard = ready_for(py, prepared, &state)?;
    let ready: &mut Ready = &mut guard;
    let total = block_time * blocks as f64;
    ready.check_length(total, "block_time x blocks")?;
    let blocks = blocks as usize;
    let spectrum = released(py, |interrupt| {
        let y0 = ready.full_state(&state)?;
        let mut options = ready.options(block_time, (false, 1), None, None);
        // The spectrum reads no contact: none kept.
        options.reduce.contacts_from = f64::INFINITY;
        let Ready {
            system, stepper, ..
        } = ready;
        let system: &core::model::assembly::Assembly = system;
        let mut carried = crate::convert::carried_contacts(carried);
        tangent::lyapunov_blocks(system, &y0, block_time, blocks, &mut |y, flow| {
            let start = (y, &carried[..]);
            let end =
                stepper.integrate_observed_continued(system, start, &options, interrupt, flow)?;
            carried = end.carried();
            full_state(system, &end.final_state[..2 * system.dim])
        })
    })?;
    let out = PyDict::new(py);
    out.set_item("exponents", spectrum.exponents.into_pyarray(py))?;
    out.set_item("standard_error", spectrum.standard_error.into_pyarray(py))?;
    out.set_item("running", spectrum.running.into_pyarray(py))?;
    out.set_item("time", spectrum.time)?;
    out.set_item("impacts", spectrum.impacts)?;
    out.set_item("grazings", grazings(py, &ready.system, &spectrum.grazings)?)?;
    Ok(out)
}

/// Each interaction (a wall of a pair) of the prepared system: `pair` (its
/// pair's name, as the contact table gives it), `h` (over all coordinates,
/// dense) and `offset` (m), its gap being `offset + h . x`; `latches`,
/// whether its law's force depends on the approach rate latched at the
/// contact's onset (which a state inside the contact does not hold).
#[pyfunction]
pub fn interactions<'py>(
    py: Python<'py>,
    prepared: &PreparedSystem,
) -> PyResult<Bound<'py, PyList>> {
    let ready = prepared.locked(py, None)?;
    let system = &ready.system;
    let out = PyList::empty(py);
    for it in system.interactions() {
        let row = PyDict::new(py);
        row.set_item("pair", system.pairs[it.pair].clone())?;
        row.set_item("h", it.h.clone().into_pyarray(py))?;
        row.set_item("offset", it.offset)?;
        row.set_item("latches", it.law.latches())?;
        out.append(row)?;
    }
    Ok(out)
}
