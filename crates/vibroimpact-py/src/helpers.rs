//! Closed forms, materials and beam modes: plain functions of their arguments.

use pyo3::prelude::*;
use vibroimpact_core::{
    analysis::settling, model::beam, model::closed_forms, model::materials, model::signals,
};

use crate::convert::*;
use crate::errors::*;
/// Hertz stiffness K_hz (N/m^1.5) of a sphere (``radius`` m, ``youngs_modulus``
/// Pa, ``poisson_ratio``) on a flat, or on a second sphere of ``other_radius``
/// (m), made of (``other_youngs_modulus`` Pa, ``other_poisson_ratio``):
/// ``K_hz = (4/3) E* sqrt(R)``, ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2``,
/// ``R = r1 r2 / (r1 + r2)``.
#[pyfunction]
#[pyo3(signature = (radius, youngs_modulus, poisson_ratio, other_youngs_modulus, other_poisson_ratio, other_radius = None))]
pub(crate) fn hertz_stiffness(
    #[pyo3(from_py_with = arg::radius)] radius: f64,
    #[pyo3(from_py_with = arg::youngs_modulus)] youngs_modulus: f64,
    #[pyo3(from_py_with = arg::poisson_ratio)] poisson_ratio: f64,
    #[pyo3(from_py_with = arg::other_youngs_modulus)] other_youngs_modulus: f64,
    #[pyo3(from_py_with = arg::other_poisson_ratio)] other_poisson_ratio: f64,
    #[pyo3(from_py_with = optional::other_radius)] other_radius: Option<f64>,
) -> PyResult<f64> {
    // Checked by the core, which names the second body's fields other_....
    let a = materials::Material {
        youngs_modulus,
        poisson_ratio,
    };
    let b = materials::Material {
        youngs_modulus: other_youngs_modulus,
        poisson_ratio: other_poisson_ratio,
    };
    materials::hertz_stiffness(radius, &a, &b, other_radius).map_err(to_py)
}

/// The forcing period (s) of excitations given as (signal name, harmonic
/// frequencies in Hz or ``None``): the periodic analyses' rule (see the core's
/// ``signals::common_period``); raises ``InvalidInputError`` naming the
/// excitation that has no period.
#[pyfunction]
pub(crate) fn forcing_period(excitations: Vec<(String, Option<Vec<f64>>)>) -> PyResult<f64> {
    let parts: Vec<(&str, Option<Vec<f64>>)> = excitations
        .iter()
        .map(|(name, frequencies)| (name.as_str(), frequencies.clone()))
        .collect();
    signals::common_period(&parts).map_err(to_py)
}

/// The fewest forcing periods p <= ``max_period`` after which the last row of
/// ``strobe`` (stroboscopic states: n displacements, m, then n velocities, m/s)
/// repeats within ``tolerance`` of the size of the motion, or ``None``: the
/// steady-state criterion of the analyses and the studies (see the core's
/// ``settling::strobe_period``). ``forcing_period`` in s.
#[pyfunction]
pub(crate) fn strobe_period(
    strobe: numpy::PyReadonlyArray2<'_, f64>,
    #[pyo3(from_py_with = arg::forcing_period)] forcing_period: f64,
    #[pyo3(from_py_with = arg::tolerance)] tolerance: f64,
    max_period: usize,
) -> PyResult<Option<usize>> {
    let rows = strobe.as_array();
    let width = rows.ncols();
    let flat: Vec<f64> = rows.iter().copied().collect();
    settling::checked_strobe_period(&flat, width, forcing_period, tolerance, max_period)
        .map_err(to_py)
}

/// One cantilever mode reduced to a single degree of freedom (see
/// ``cantilever_mode``). Stiffnesses in N/m, masses in kg, frequency in rad/s.
#[pyclass(frozen, get_all, module = "vibroimpact._core")]
pub(crate) struct BeamMode {
    mode: u32,
    beta_l: f64,
    angular_frequency: f64,
    modal_stiffness: f64,
    modal_mass: f64,
    position: f64,
    shape_at_position: f64,
    stiffness_at_position: f64,
    mass_at_position: f64,
}

#[pymethods]
impl BeamMode {
    fn __repr__(&self) -> String {
        format!(
            "BeamMode(mode={}, beta_l={:.6}, modal_stiffness={:.6e}, modal_mass={:.6e}, position={:?}, stiffness_at_position={:.6e}, mass_at_position={:.6e})",
            self.mode, self.beta_l, self.modal_stiffness, self.modal_mass, self.position,
            self.stiffness_at_position, self.mass_at_position
        )
    }
}

/// Reduce mode ``mode`` of a cantilever (``length`` m, ``youngs_modulus`` Pa,
/// ``second_moment`` m^4, ``density`` kg/m^3, ``area`` m^2) to one degree of
/// freedom by the Ritz method on its mode shape, normalised so that
/// ``int_0^L phi^2 dx = L``. Gives the paper's modal values
/// (``(b L)^4 E I / L^3``, ``rho A L``) and the values referred to
/// ``position`` (m from the clamp; the tip by default), where the enclosure sits.
/// Exact to round-off for any mode; a position at a node of the mode is refused.
#[pyfunction]
#[pyo3(signature = (length, youngs_modulus, second_moment, density, area, mode = 1, position = None))]
pub(crate) fn cantilever_mode(
    #[pyo3(from_py_with = arg::length)] length: f64,
    #[pyo3(from_py_with = arg::youngs_modulus)] youngs_modulus: f64,
    #[pyo3(from_py_with = arg::second_moment)] second_moment: f64,
    #[pyo3(from_py_with = arg::density)] density: f64,
    #[pyo3(from_py_with = arg::area)] area: f64,
    #[pyo3(from_py_with = mode_arg)] mode: u32,
    #[pyo3(from_py_with = optional::position)] position: Option<f64>,
) -> PyResult<BeamMode> {
    let b = beam::cantilever_mode(
        length,
        youngs_modulus,
        second_moment,
        density,
        area,
        mode,
        position,
    )
    .map_err(to_py)?;
    Ok(BeamMode {
        mode: b.mode,
        beta_l: b.beta_l,
        angular_frequency: b.angular_frequency,
        modal_stiffness: b.modal_stiffness,
        modal_mass: b.modal_mass,
        position: b.position,
        shape_at_position: b.shape_at_position,
        stiffness_at_position: b.stiffness_at_position,
        mass_at_position: b.mass_at_position,
    })
}

/// The root ``b_i L`` of ``cos(x) cosh(x) + 1 = 0`` for mode ``mode`` >= 1
/// (any mode, to round-off); ``omega_i = (b_i L)^2 sqrt(E I / (rho A L^4))``.
#[pyfunction]
pub(crate) fn cantilever_root(#[pyo3(from_py_with = mode_arg)] mode: u32) -> PyResult<f64> {
    beam::cantilever_root(mode).map_err(to_py)
}

/// Normalised mode shape ``phi(x)`` (``int_0^L phi^2 dx = L``, ``|phi(L)| =
/// 2``) of mode ``mode`` (any, exact to round-off) of a cantilever of
/// ``length`` (m), at ``x`` (m from the clamp, in [0, length]); with
/// ``derivative`` k = 1, 2 or 3 its k-th derivative in x (1/m^k).
#[pyfunction]
#[pyo3(signature = (length, mode, x, derivative = 0))]
pub(crate) fn cantilever_mode_shape(
    #[pyo3(from_py_with = arg::length)] length: f64,
    #[pyo3(from_py_with = mode_arg)] mode: u32,
    #[pyo3(from_py_with = arg::x)] x: f64,
    #[pyo3(from_py_with = derivative_arg)] derivative: usize,
) -> PyResult<f64> {
    let values = beam::cantilever_mode_shape_derivatives(length, mode, x).map_err(to_py)?;
    Ok(values[derivative])
}

/// Goldsmith's Hertz contact duration (s) of two free bodies meeting at
/// ``approach_speed`` (m/s): ``2.9432 / v^0.2 (5 / (4 K* K_hz))^(2/5)`` with
/// ``K* = (m + M)/(m M)``. ``exact_constant`` uses 2.943275... instead of 2.9432.
#[pyfunction]
#[pyo3(signature = (impact_mass, main_mass, hertz_stiffness, approach_speed, exact_constant = false))]
pub(crate) fn goldsmith_contact_duration(
    #[pyo3(from_py_with = arg::impact_mass)] impact_mass: f64,
    #[pyo3(from_py_with = arg::main_mass)] main_mass: f64,
    #[pyo3(from_py_with = arg::hertz_stiffness)] hertz_stiffness: f64,
    #[pyo3(from_py_with = arg::approach_speed)] approach_speed: f64,
    exact_constant: bool,
) -> PyResult<f64> {
    closed_forms::goldsmith_contact_duration(
        impact_mass,
        main_mass,
        hertz_stiffness,
        approach_speed,
        exact_constant,
    )
    .map_err(to_py)
}

/// Goldsmith's maximum Hertz indentation (m): ``(5 v^2 / (4 K* K_hz))^(2/5)``.
#[pyfunction]
pub(crate) fn goldsmith_max_indentation(
    #[pyo3(from_py_with = arg::impact_mass)] impact_mass: f64,
    #[pyo3(from_py_with = arg::main_mass)] main_mass: f64,
    #[pyo3(from_py_with = arg::hertz_stiffness)] hertz_stiffness: f64,
    #[pyo3(from_py_with = arg::approach_speed)] approach_speed: f64,
) -> PyResult<f64> {
    closed_forms::goldsmith_max_indentation(impact_mass, main_mass, hertz_stiffness, approach_speed)
        .map_err(to_py)
}

/// Contact duration (s) of a linear spring ``stiffness`` (N/m) with a damper
/// ``damping`` (N s/m) between two free bodies: half a damped period.
#[pyfunction]
#[pyo3(signature = (impact_mass, main_mass, stiffness, damping = 0.0))]
pub(crate) fn linear_contact_duration(
    #[pyo3(from_py_with = arg::impact_mass)] impact_mass: f64,
    #[pyo3(from_py_with = arg::main_mass)] main_mass: f64,
    #[pyo3(from_py_with = arg::stiffness)] stiffness: f64,
    #[pyo3(from_py_with = arg::damping)] damping: f64,
) -> PyResult<f64> {
    closed_forms::linear_contact_duration(impact_mass, main_mass, stiffness, damping).map_err(to_py)
}

/// The founding paper's adequacy factor (Eq. 15), percent:
/// ``((1 - error/max_error) wf1 + (1 - cpu_time/max_cpu_time)(1 - wf1)) * 100``
/// with ``wf1 = error_weight``.
#[pyfunction]
pub(crate) fn adequacy(
    #[pyo3(from_py_with = arg::error)] error: f64,
    #[pyo3(from_py_with = arg::max_error)] max_error: f64,
    #[pyo3(from_py_with = arg::cpu_time)] cpu_time: f64,
    #[pyo3(from_py_with = arg::max_cpu_time)] max_cpu_time: f64,
    #[pyo3(from_py_with = arg::error_weight)] error_weight: f64,
) -> PyResult<f64> {
    closed_forms::adequacy(error, max_error, cpu_time, max_cpu_time, error_weight).map_err(to_py)
}
