//! The two-mass system, its contact law and its initial state as Python classes.

use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict, PyTuple};
use vibroimpact_core as core;

use crate::convert::*;
use crate::errors::*;
/// The two-mass impact damper (SI units).
///
/// A main mass ``main_mass`` (M, kg) on a spring ``stiffness`` (K, N/m) and
/// damper ``damping`` (C, N s/m) carries an enclosure in which the impact mass
/// ``impact_mass`` (m, kg) moves freely with ``clearance`` (d, m) on each side.
#[pyclass(frozen, eq, module = "vibroimpact._core")]
#[derive(Clone, PartialEq)]
pub(crate) struct ImpactDamper(pub(crate) core::ImpactDamper);

#[pymethods]
impl ImpactDamper {
    #[new]
    // Keywords only: the order of the values is not the README's or the scenario's (a
    // positional call put 0.01 into impact_mass and 0.25 into clearance unnoticed).
    #[pyo3(signature = (*, main_mass, stiffness, impact_mass, clearance, damping = 0.0))]
    fn new(
        #[pyo3(from_py_with = arg::main_mass)] main_mass: f64,
        #[pyo3(from_py_with = arg::stiffness)] stiffness: f64,
        #[pyo3(from_py_with = arg::impact_mass)] impact_mass: f64,
        #[pyo3(from_py_with = arg::clearance)] clearance: f64,
        #[pyo3(from_py_with = arg::damping)] damping: f64,
    ) -> PyResult<Self> {
        core::ImpactDamper::new(main_mass, stiffness, damping, impact_mass, clearance)
            .map(Self)
            .map_err(to_py)
    }
    /// M, kg.
    #[getter]
    fn main_mass(&self) -> f64 {
        self.0.main_mass
    }
    /// K, N/m.
    #[getter]
    fn stiffness(&self) -> f64 {
        self.0.stiffness
    }
    /// m, kg.
    #[getter]
    fn impact_mass(&self) -> f64 {
        self.0.impact_mass
    }
    /// d, m (on each side).
    #[getter]
    fn clearance(&self) -> f64 {
        self.0.clearance
    }
    /// C, N s/m.
    #[getter]
    fn damping(&self) -> f64 {
        self.0.damping
    }
    /// ``m M / (m + M)``, kg.
    #[getter]
    fn effective_mass(&self) -> f64 {
        self.0.effective_mass()
    }
    /// Pickled by name, as it is made (keywords only).
    fn __getnewargs_ex__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyTuple>, Bound<'py, PyDict>)> {
        let s = &self.0;
        let keywords = [
            ("main_mass", s.main_mass),
            ("stiffness", s.stiffness),
            ("impact_mass", s.impact_mass),
            ("clearance", s.clearance),
            ("damping", s.damping),
        ]
        .into_py_dict(py)?;
        Ok((PyTuple::empty(py), keywords))
    }
    /// Hashed as the tuple of its values (equal objects hash equal, as
    /// `0.0 == -0.0` do), so it can key a dict or sit in a set.
    fn __hash__(&self, py: Python<'_>) -> PyResult<isize> {
        let s = &self.0;
        let values = (
            s.main_mass,
            s.stiffness,
            s.impact_mass,
            s.clearance,
            s.damping,
        );
        values.into_pyobject(py)?.hash()
    }
    fn __repr__(&self) -> String {
        let s = &self.0;
        format!(
            "ImpactDamper(main_mass={:?}, stiffness={:?}, impact_mass={:?}, clearance={:?}, damping={:?})",
            s.main_mass, s.stiffness, s.impact_mass, s.clearance, s.damping
        )
    }
}

/// "hyster-hertz" warns below this restitution: its rebound is then far from e.
pub(crate) const WARN_BELOW: f64 = 0.7;

/// A compliant contact law and the contact damper.
///
/// ``law`` is ``"hertz"`` (F = k delta^1.5), ``"hyster-hertz"``
/// (Lankarani-Nikravesh, F = k delta^1.5 (1 + 3/4 (1 - e^2) delta'/delta'_minus),
/// needs ``restitution`` e in (0, 1]; it rebounds faster than e and warns with
/// ``RestitutionWarning`` below 0.7), ``"hertz-damped"`` (the same form with
/// the damping solved so that two bodies alone rebound at exactly e) or
/// ``"linear"`` (F = k delta). ``stiffness``
/// is in N/m^1.5 for the Hertz laws and N/m for ``"linear"``. ``damping`` (c1,
/// N s/m) is a linear damper on the relative velocity acting only in contact.
/// The law's force never pulls the bodies together: it is clamped at zero.
#[pyclass(frozen, eq, module = "vibroimpact._core")]
#[derive(Clone, PartialEq)]
pub(crate) struct Contact(pub(crate) core::Contact);

#[pymethods]
impl Contact {
    #[new]
    #[pyo3(signature = (law, stiffness, damping = 0.0, restitution = None))]
    fn new(
        py: Python<'_>,
        #[pyo3(from_py_with = named_text::law)] law: String,
        #[pyo3(from_py_with = arg::stiffness)] stiffness: f64,
        #[pyo3(from_py_with = arg::damping)] damping: f64,
        #[pyo3(from_py_with = optional::restitution)] restitution: Option<f64>,
    ) -> PyResult<Self> {
        let kind = core::LawKind::parse(&law).map_err(to_py)?;
        let contact = core::Contact::new(kind, stiffness, restitution, damping).map_err(to_py)?;
        if kind == core::LawKind::HysterHertz && contact.restitution < WARN_BELOW {
            let message = std::ffi::CString::new(format!(
                "law \"hyster-hertz\" with restitution {} rebounds at {:.4} of the approach speed, \
                 not {}; use law \"hertz-damped\" for a rebound of exactly e",
                contact.restitution,
                contact.effective_restitution(),
                contact.restitution
            ))
            .expect("no NUL in the message");
            PyErr::warn(py, &py.get_type::<RestitutionWarning>(), &message, 1)?;
        }
        Ok(Self(contact))
    }
    /// The rebound/approach speed ratio two bodies alone get from the law
    /// (without the contact damper): e for "hertz-damped", more than e for
    /// "hyster-hertz" (never below 0.66296), 1 for "hertz" and "linear".
    #[getter]
    fn effective_restitution(&self) -> f64 {
        self.0.effective_restitution()
    }
    /// The law's name.
    #[getter]
    fn law(&self) -> &'static str {
        self.0.law.name()
    }
    /// K_hz (N/m^1.5) or k1 (N/m).
    #[getter]
    fn stiffness(&self) -> f64 {
        self.0.stiffness
    }
    /// c1, N s/m.
    #[getter]
    fn damping(&self) -> f64 {
        self.0.damping
    }
    /// e for "hyster-hertz" and "hertz-damped", None otherwise.
    #[getter]
    fn restitution(&self) -> Option<f64> {
        self.0.law.uses_restitution().then_some(self.0.restitution)
    }
    /// The law's force (N, clamped at zero; without the contact damper) at
    /// ``indentation`` (m; none at or below 0), indentation ``rate`` (m/s, > 0
    /// while approaching) and the rate at the onset of the contact
    /// ``approach_rate`` (m/s), all finite.
    #[pyo3(signature = (indentation, rate = 0.0, approach_rate = 1.0))]
    fn law_force(
        &self,
        #[pyo3(from_py_with = arg::indentation)] indentation: f64,
        #[pyo3(from_py_with = arg::rate)] rate: f64,
        #[pyo3(from_py_with = arg::approach_rate)] approach_rate: f64,
    ) -> PyResult<f64> {
        self.0
            .law_force(indentation, rate, approach_rate)
            .map_err(to_py)
    }
    fn __getnewargs__(&self) -> (&'static str, f64, f64, Option<f64>) {
        (
            self.law(),
            self.0.stiffness,
            self.0.damping,
            self.restitution(),
        )
    }
    /// Hashed as the values it is made from (see [`ImpactDamper::__hash__`]).
    fn __hash__(&self, py: Python<'_>) -> PyResult<isize> {
        self.__getnewargs__().into_pyobject(py)?.hash()
    }
    fn __repr__(&self) -> String {
        let restitution = match self.restitution() {
            Some(e) => format!(", restitution={e:?}"),
            None => String::new(),
        };
        format!(
            "Contact(law={:?}, stiffness={:?}, damping={:?}{restitution})",
            self.law(),
            self.0.stiffness,
            self.0.damping
        )
    }
}

/// Initial displacements (m) and velocities (m/s) of the main mass (w) and
/// the impact mass (y).
#[pyclass(frozen, eq, module = "vibroimpact._core")]
#[derive(Clone, PartialEq)]
pub(crate) struct InitialState(pub(crate) core::State);

#[pymethods]
impl InitialState {
    #[new]
    #[pyo3(signature = (main_displacement = 0.0, main_velocity = 0.0, impact_displacement = 0.0, impact_velocity = 0.0))]
    fn new(
        #[pyo3(from_py_with = arg::main_displacement)] main_displacement: f64,
        #[pyo3(from_py_with = arg::main_velocity)] main_velocity: f64,
        #[pyo3(from_py_with = arg::impact_displacement)] impact_displacement: f64,
        #[pyo3(from_py_with = arg::impact_velocity)] impact_velocity: f64,
    ) -> PyResult<Self> {
        core::State::new(
            main_displacement,
            main_velocity,
            impact_displacement,
            impact_velocity,
        )
        .map(Self)
        .map_err(to_py)
    }
    /// w, m.
    #[getter]
    fn main_displacement(&self) -> f64 {
        self.0.main_displacement
    }
    /// w', m/s.
    #[getter]
    fn main_velocity(&self) -> f64 {
        self.0.main_velocity
    }
    /// y, m.
    #[getter]
    fn impact_displacement(&self) -> f64 {
        self.0.impact_displacement
    }
    /// y', m/s.
    #[getter]
    fn impact_velocity(&self) -> f64 {
        self.0.impact_velocity
    }
    fn __getnewargs__(&self) -> (f64, f64, f64, f64) {
        let s = &self.0;
        (
            s.main_displacement,
            s.main_velocity,
            s.impact_displacement,
            s.impact_velocity,
        )
    }
    /// Hashed as the values it is made from (see [`ImpactDamper::__hash__`]).
    fn __hash__(&self, py: Python<'_>) -> PyResult<isize> {
        self.__getnewargs__().into_pyobject(py)?.hash()
    }
    fn __repr__(&self) -> String {
        let s = &self.0;
        format!(
            "InitialState(main_displacement={:?}, main_velocity={:?}, impact_displacement={:?}, impact_velocity={:?})",
            s.main_displacement, s.main_velocity, s.impact_displacement, s.impact_velocity
        )
    }
}
