//! `vibroimpact._core`: the Python face of vibroimpact-core. It only converts
//! arguments and results, releases the GIL around integration and maps each
//! core error to its own Python exception.

use std::sync::{Mutex, OnceLock};

use numpy::{IntoPyArray, PyArray1};
use pyo3::create_exception;
use pyo3::exceptions::{
    PyArithmeticError, PyKeyboardInterrupt, PyRuntimeError, PyUserWarning, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use vibroimpact_core as core;
use vibroimpact_core::{beam, closed_forms, materials};

mod system;

// The module path makes the exceptions picklable (e.g. from worker processes).
create_exception!(
    vibroimpact._core,
    InvalidInputError,
    PyValueError,
    "An input is outside what the model allows; the message names the field."
);
create_exception!(
    vibroimpact._core,
    NumericalBlowUpError,
    PyArithmeticError,
    "The integration blew up (non-finite state or energy created from nothing)."
);

create_exception!(
    vibroimpact._core,
    EnergyBalanceError,
    NumericalBlowUpError,
    "The result would be physically impossible: its energy balance does not close, or a contact \
     created energy (beyond energy_tolerance)."
);

create_exception!(
    vibroimpact._core,
    SimulationError,
    PyRuntimeError,
    "The run could not go on: chattering, Newton failure, step size at round-off, or too many steps."
);
create_exception!(
    vibroimpact._core,
    RestitutionWarning,
    PyUserWarning,
    "The contact law will not rebound at the restitution it was given."
);

fn to_py(err: core::Error) -> PyErr {
    use core::Error as E;
    let message = err.to_string();
    match err {
        E::NumericalBlowUp { .. } => NumericalBlowUpError::new_err(message),
        E::EnergyBalance { .. } | E::ContactEnergy { .. } => EnergyBalanceError::new_err(message),
        E::Interrupted { .. } => PyKeyboardInterrupt::new_err(message),
        E::NewtonFailed { .. }
        | E::Chattering { .. }
        | E::StepSizeTooSmall { .. }
        | E::TooManySteps { .. }
        | E::RowLimit { .. } => SimulationError::new_err(message),
        E::InvalidParameter { .. } | E::UnknownChoice { .. } | E::Inconsistent(_) => {
            InvalidInputError::new_err(message)
        }
    }
}

/// Runs `work` with the GIL released, giving it a question to ask now and
/// then: has Ctrl-C been pressed? An interruption becomes the Python
/// exception (KeyboardInterrupt) that caused it; other errors map by kind.
fn released<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&mut dyn FnMut() -> bool) -> core::Result<T> + Send,
{
    let mut signal: Option<PyErr> = None;
    let result = py.detach(|| {
        work(&mut || match Python::attach(|py| py.check_signals()) {
            Ok(()) => false,
            Err(e) => {
                signal = Some(e);
                true
            }
        })
    });
    match result {
        Ok(value) => Ok(value),
        Err(core::Error::Interrupted { .. }) if signal.is_some() => {
            Err(signal.take().expect("checked"))
        }
        Err(e) => Err(to_py(e)),
    }
}

/// A whole number >= 1 from a Python int; one too large or too small for the
/// core is an InvalidInputError naming the field, not an OverflowError.
fn whole(field: &str, value: &Bound<'_, PyAny>) -> PyResult<u64> {
    let invalid = || {
        InvalidInputError::new_err(format!(
            "{field} must be a whole number in [1, {}], got {value}",
            i64::MAX
        ))
    };
    match value.extract::<i64>() {
        Ok(v) if v >= 1 => Ok(v as u64),
        Ok(_) => Err(invalid()),
        Err(err) if err.is_instance_of::<pyo3::exceptions::PyOverflowError>(value.py()) => {
            Err(invalid())
        }
        Err(err) => Err(err),
    }
}

/// A float argument (the `from_py_with` of every float parameter). A Python
/// int beyond the range of a float (`10**400`) becomes an infinity of its
/// sign, as a float computation beyond the range would, instead of an
/// OverflowError: the core then refuses it like any non-finite value, in an
/// InvalidInputError that names the field.
fn real(value: &Bound<'_, PyAny>) -> PyResult<f64> {
    match value.extract::<f64>() {
        Ok(v) => Ok(v),
        Err(err) if err.is_instance_of::<pyo3::exceptions::PyOverflowError>(value.py()) => {
            Ok(if value.lt(0)? {
                f64::NEG_INFINITY
            } else {
                f64::INFINITY
            })
        }
        Err(err) => Err(err),
    }
}

/// [`real`] for a parameter that may be None.
fn real_or_none(value: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    if value.is_none() {
        Ok(None)
    } else {
        real(value).map(Some)
    }
}

fn every_arg(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole("every", value)
}

fn max_steps_arg(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole("max_steps", value)
}

fn max_rows_arg(value: &Bound<'_, PyAny>) -> PyResult<Option<u64>> {
    if value.is_none() {
        Ok(None)
    } else {
        whole("max_rows", value).map(Some)
    }
}

fn mode_arg(value: &Bound<'_, PyAny>) -> PyResult<u32> {
    let mode = whole("mode", value)?;
    u32::try_from(mode).map_err(|_| {
        InvalidInputError::new_err(format!("mode must be at most {}, got {mode}", u32::MAX))
    })
}

/// The two-mass impact damper (SI units).
///
/// A main mass ``main_mass`` (M, kg) on a spring ``stiffness`` (K, N/m) and
/// damper ``damping`` (C, N s/m) carries an enclosure in which the impact mass
/// ``impact_mass`` (m, kg) moves freely with ``clearance`` (d, m) on each side.
#[pyclass(frozen, eq, module = "vibroimpact._core")]
#[derive(Clone, PartialEq)]
struct ImpactDamper(core::ImpactDamper);

#[pymethods]
impl ImpactDamper {
    #[new]
    #[pyo3(signature = (main_mass, stiffness, impact_mass, clearance, damping = 0.0))]
    fn new(
        #[pyo3(from_py_with = real)] main_mass: f64,
        #[pyo3(from_py_with = real)] stiffness: f64,
        #[pyo3(from_py_with = real)] impact_mass: f64,
        #[pyo3(from_py_with = real)] clearance: f64,
        #[pyo3(from_py_with = real)] damping: f64,
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
    fn __getnewargs__(&self) -> (f64, f64, f64, f64, f64) {
        let s = &self.0;
        (
            s.main_mass,
            s.stiffness,
            s.impact_mass,
            s.clearance,
            s.damping,
        )
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
const WARN_BELOW: f64 = 0.7;

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
struct Contact(core::Contact);

#[pymethods]
impl Contact {
    #[new]
    #[pyo3(signature = (law, stiffness, damping = 0.0, restitution = None))]
    fn new(
        py: Python<'_>,
        law: &str,
        #[pyo3(from_py_with = real)] stiffness: f64,
        #[pyo3(from_py_with = real)] damping: f64,
        #[pyo3(from_py_with = real_or_none)] restitution: Option<f64>,
    ) -> PyResult<Self> {
        let kind = core::LawKind::parse(law).map_err(to_py)?;
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
        #[pyo3(from_py_with = real)] indentation: f64,
        #[pyo3(from_py_with = real)] rate: f64,
        #[pyo3(from_py_with = real)] approach_rate: f64,
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
struct InitialState(core::State);

#[pymethods]
impl InitialState {
    #[new]
    #[pyo3(signature = (main_displacement = 0.0, main_velocity = 0.0, impact_displacement = 0.0, impact_velocity = 0.0))]
    fn new(
        #[pyo3(from_py_with = real)] main_displacement: f64,
        #[pyo3(from_py_with = real)] main_velocity: f64,
        #[pyo3(from_py_with = real)] impact_displacement: f64,
        #[pyo3(from_py_with = real)] impact_velocity: f64,
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
    fn __repr__(&self) -> String {
        let s = &self.0;
        format!(
            "InitialState(main_displacement={:?}, main_velocity={:?}, impact_displacement={:?}, impact_velocity={:?})",
            s.main_displacement, s.main_velocity, s.impact_displacement, s.impact_velocity
        )
    }
}

/// A column of results that becomes a NumPy array on first access (without
/// a copy): a call pays only for the arrays it reads.
struct Column {
    data: Mutex<Option<Vec<f64>>>,
    array: OnceLock<Py<PyArray1<f64>>>,
}

impl Column {
    fn new(data: Vec<f64>) -> Self {
        Self {
            data: Mutex::new(Some(data)),
            array: OnceLock::new(),
        }
    }

    fn get(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.array
            .get_or_init(|| {
                let data = self
                    .data
                    .lock()
                    .map(|mut d| d.take().unwrap_or_default())
                    .unwrap_or_default();
                data.into_pyarray(py).unbind()
            })
            .clone_ref(py)
    }
}

const CONTACT_COLUMNS: [&str; 9] = [
    "onset",
    "separation",
    "duration",
    "max_indentation",
    "approach_speed",
    "rebound_speed",
    "restitution",
    "energy_dissipated",
    "energy_change",
];

fn record_values(r: &core::ContactRecord) -> [f64; 9] {
    [
        r.onset,
        r.separation,
        r.duration,
        r.max_indentation,
        r.approach_speed,
        r.rebound_speed,
        r.restitution,
        r.energy_dissipated,
        r.energy_change,
    ]
}

/// The contacts of a run, one entry per contact, as NumPy arrays in SI units.
/// A contact still open at the end of the run has NaN ``separation``,
/// ``duration``, ``rebound_speed``, ``restitution`` and ``energy_change``.
#[pyclass(frozen, module = "vibroimpact._core")]
struct ContactTable {
    records: Vec<core::ContactRecord>,
    columns: [OnceLock<Py<PyArray1<f64>>>; 9],
}

impl ContactTable {
    fn new(records: Vec<core::ContactRecord>) -> Self {
        Self {
            records,
            columns: Default::default(),
        }
    }

    fn column(&self, py: Python<'_>, index: usize) -> Py<PyArray1<f64>> {
        self.columns[index]
            .get_or_init(|| {
                let values: Vec<f64> = self
                    .records
                    .iter()
                    .map(|r| record_values(r)[index])
                    .collect();
                values.into_pyarray(py).unbind()
            })
            .clone_ref(py)
    }
}

#[pymethods]
impl ContactTable {
    /// Column names, in order.
    #[classattr]
    fn columns() -> [&'static str; 9] {
        CONTACT_COLUMNS
    }
    /// Onset, s.
    #[getter]
    fn onset(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.column(py, 0)
    }
    /// Separation, s.
    #[getter]
    fn separation(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.column(py, 1)
    }
    /// Duration, s.
    #[getter]
    fn duration(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.column(py, 2)
    }
    /// Maximum indentation, m.
    #[getter]
    fn max_indentation(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.column(py, 3)
    }
    /// Relative normal speed at onset, m/s.
    #[getter]
    fn approach_speed(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.column(py, 4)
    }
    /// Relative normal speed at separation, m/s.
    #[getter]
    fn rebound_speed(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.column(py, 5)
    }
    /// Effective restitution: rebound_speed / approach_speed.
    #[getter]
    fn restitution(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.column(py, 6)
    }
    /// Work done during the contact by the contact's dissipative forces (the
    /// law's hysteresis and the contact damper c1), J, >= 0: the integral of
    /// ``(F - F_elastic) * delta'`` over the contact. The main damper C is not
    /// in it.
    #[getter]
    fn energy_dissipated(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.column(py, 7)
    }
    /// Net change of the whole system's mechanical energy over the contact
    /// (kinetic energy of both masses, main spring and contact elastic energy;
    /// at separation minus at onset), J. With no main damper it is
    /// ``-energy_dissipated``; with one, the damper's work during the contact
    /// is in it too. NaN for a contact still open at the end.
    #[getter]
    fn energy_change(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.column(py, 8)
    }
    fn __len__(&self) -> usize {
        self.records.len()
    }
    /// One dict per contact, keyed by the column names.
    fn to_dicts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for r in &self.records {
            let d = PyDict::new(py);
            for (name, value) in CONTACT_COLUMNS.iter().zip(record_values(r)) {
                d.set_item(name, value)?;
            }
            list.append(d)?;
        }
        Ok(list)
    }
    fn __repr__(&self) -> String {
        format!("ContactTable({} contacts)", self.records.len())
    }
}

/// What ``simulate`` returns: the time history (NumPy arrays, SI units), the
/// table of contacts and the run's statistics.
#[pyclass(frozen, module = "vibroimpact._core")]
struct Solution {
    history: [Column; 6],
    rows: usize,
    /// The contacts.
    #[pyo3(get)]
    contacts: Py<ContactTable>,
    /// Steps taken (accepted).
    #[pyo3(get)]
    steps: u64,
    /// Steps rejected by the error control (adaptive methods).
    #[pyo3(get)]
    rejected_steps: u64,
    /// Force (right-hand-side) evaluations, Newton iterations included.
    #[pyo3(get)]
    rhs_evaluations: u64,
    /// Touches shallower than round-off, not counted as contacts.
    #[pyo3(get)]
    grazing_contacts: u64,
    /// Time reached, s (t_end rounded up to a whole number of steps by the
    /// fixed-step methods).
    #[pyo3(get)]
    final_time: f64,
    /// Method name.
    #[pyo3(get)]
    method: &'static str,
    /// "fixed" or "events".
    #[pyo3(get)]
    stepping: &'static str,
    /// Largest relative growth of the mechanical energy of the unforced system,
    /// ``max(E)/E(0) - 1`` (NaN if it starts at rest). Physically <= 0: a
    /// positive value is numerical error (above 0.5 the run is refused).
    #[pyo3(get)]
    energy_growth: f64,
    /// Largest residual of the energy balance found by the run's checks
    /// (stored energy + dissipated work - external work - energy at the
    /// start), relative to the energy in play; NaN for a system at rest. The
    /// run is refused when it exceeds ``energy_tolerance``.
    #[pyo3(get)]
    energy_residual: f64,
    /// The state at ``final_time``.
    #[pyo3(get)]
    final_state: InitialState,
}

#[pymethods]
impl Solution {
    /// Time of each kept step, s.
    #[getter]
    fn t(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.history[0].get(py)
    }
    /// w, m.
    #[getter]
    fn main_displacement(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.history[1].get(py)
    }
    /// w', m/s.
    #[getter]
    fn main_velocity(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.history[2].get(py)
    }
    /// y, m.
    #[getter]
    fn impact_displacement(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.history[3].get(py)
    }
    /// y', m/s.
    #[getter]
    fn impact_velocity(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.history[4].get(py)
    }
    /// Force between the bodies (law + contact damper), N; > 0 pushes apart.
    #[getter]
    fn contact_force(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.history[5].get(py)
    }
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "Solution(method={:?}, stepping={:?}, steps={}, rows={}, contacts={})",
            self.method,
            self.stepping,
            self.steps,
            self.rows,
            self.contacts.bind(py).get().records.len()
        )
    }
}

#[allow(clippy::too_many_arguments)]
fn settings(
    dt: Option<f64>,
    t_end: f64,
    method: &str,
    every: u64,
    contact_timing: &str,
    stepping: Option<&str>,
    beta: f64,
    gamma: f64,
    spectral_radius: f64,
    rtol: f64,
    atol: f64,
    max_steps: u64,
    max_rows: Option<u64>,
    energy_tolerance: Option<f64>,
    history: bool,
) -> PyResult<core::Settings> {
    let options = core::MethodOptions {
        beta,
        gamma,
        spectral_radius,
        rtol,
        atol,
    };
    let parsed = core::Method::parse(method, &options).map_err(to_py)?;
    let timing = core::ContactTiming::parse(contact_timing).map_err(to_py)?;
    let stepping = stepping
        .map(core::Stepping::parse)
        .transpose()
        .map_err(to_py)?;
    core::Settings::new(parsed, dt, t_end, every, timing, stepping, max_steps)
        .and_then(|s| s.with_limits(history, max_rows, energy_tolerance))
        .map_err(to_py)
}

/// Check solver settings as ``simulate`` would, without running; raises
/// ``InvalidInputError`` naming the offending field.
#[pyfunction]
#[pyo3(signature = (*, t_end, dt = None, method = "newmark", every = 1, contact_timing = "located", stepping = None, beta = 0.25, gamma = 0.5, spectral_radius = 0.9, rtol = 1e-8, atol = 1e-12, max_steps = 1_000_000_000, max_rows = None, energy_tolerance = None, history = true))]
#[allow(clippy::too_many_arguments)]
fn check_solver(
    #[pyo3(from_py_with = real)] t_end: f64,
    #[pyo3(from_py_with = real_or_none)] dt: Option<f64>,
    method: &str,
    #[pyo3(from_py_with = every_arg)] every: u64,
    contact_timing: &str,
    stepping: Option<&str>,
    #[pyo3(from_py_with = real)] beta: f64,
    #[pyo3(from_py_with = real)] gamma: f64,
    #[pyo3(from_py_with = real)] spectral_radius: f64,
    #[pyo3(from_py_with = real)] rtol: f64,
    #[pyo3(from_py_with = real)] atol: f64,
    #[pyo3(from_py_with = max_steps_arg)] max_steps: u64,
    #[pyo3(from_py_with = max_rows_arg)] max_rows: Option<u64>,
    #[pyo3(from_py_with = real_or_none)] energy_tolerance: Option<f64>,
    history: bool,
) -> PyResult<()> {
    settings(
        dt,
        t_end,
        method,
        every,
        contact_timing,
        stepping,
        beta,
        gamma,
        spectral_radius,
        rtol,
        atol,
        max_steps,
        max_rows,
        energy_tolerance,
        history,
    )
    .map(|_| ())
}

/// Integrate the impact damper from ``initial`` to ``t_end`` (s).
///
/// ``method``: ``"newmark"`` (the founding paper's Newmark-beta, contact force
/// lagged one step), ``"newmark-implicit"`` (Newton on the contact force;
/// ``beta``, ``gamma`` default 1/4, 1/2), ``"generalized-alpha"``
/// (Chung-Hulbert, ``spectral_radius`` in [0, 1]), ``"rk4"`` (classical
/// Runge-Kutta): fixed step ``dt`` (s); ``"dopri5"``, ``"dop853"``: adaptive
/// with ``rtol``, ``atol`` (``dt`` is then the first step, optional).
///
/// ``stepping``: ``"events"`` locates every contact onset and separation to
/// round-off, cuts the step there and restarts; ``"fixed"`` is the founding
/// paper's stepping, for ``"newmark"`` and ``"rk4"`` only (their default),
/// whose contact instants are ``contact_timing`` ``"located"`` (interpolated
/// inside the step) or ``"step-count"`` (whole steps). ``every`` keeps every
/// N-th step in the history; ``max_steps`` bounds the work.
///
/// Limits: ``max_rows`` bounds the history rows plus contacts a run keeps
/// (None: ``DEFAULT_MAX_ROWS``, 2e7; a row is 48 bytes, a contact 72): a
/// fixed-step history beyond it is refused before the run, any other run
/// stops at it with a ``SimulationError``; ``history=False`` keeps no history at all
/// (empty arrays; ``final_state`` holds the end). A start with the bodies
/// interpenetrating is refused. ``energy_tolerance`` (relative, None:
/// ``DEFAULT_ENERGY_TOLERANCE``, 0.05): a result whose energy balance (stored
/// energy + dissipated work - external work = energy at the start) misses by
/// more than that fraction of the energy in play, or one of whose contacts
/// creates energy beyond it, raises ``EnergyBalanceError``.
/// The GIL is released while integrating; Ctrl-C interrupts.
#[pyfunction]
#[pyo3(signature = (system, contact, initial, *, t_end, dt = None, method = "newmark", every = 1, contact_timing = "located", stepping = None, beta = 0.25, gamma = 0.5, spectral_radius = 0.9, rtol = 1e-8, atol = 1e-12, max_steps = 1_000_000_000, max_rows = None, energy_tolerance = None, history = true))]
#[allow(clippy::too_many_arguments)]
fn simulate(
    py: Python<'_>,
    system: &ImpactDamper,
    contact: &Contact,
    initial: &InitialState,
    #[pyo3(from_py_with = real)] t_end: f64,
    #[pyo3(from_py_with = real_or_none)] dt: Option<f64>,
    method: &str,
    #[pyo3(from_py_with = every_arg)] every: u64,
    contact_timing: &str,
    stepping: Option<&str>,
    #[pyo3(from_py_with = real)] beta: f64,
    #[pyo3(from_py_with = real)] gamma: f64,
    #[pyo3(from_py_with = real)] spectral_radius: f64,
    #[pyo3(from_py_with = real)] rtol: f64,
    #[pyo3(from_py_with = real)] atol: f64,
    #[pyo3(from_py_with = max_steps_arg)] max_steps: u64,
    #[pyo3(from_py_with = max_rows_arg)] max_rows: Option<u64>,
    #[pyo3(from_py_with = real_or_none)] energy_tolerance: Option<f64>,
    history: bool,
) -> PyResult<Solution> {
    let settings = settings(
        dt,
        t_end,
        method,
        every,
        contact_timing,
        stepping,
        beta,
        gamma,
        spectral_radius,
        rtol,
        atol,
        max_steps,
        max_rows,
        energy_tolerance,
        history,
    )?;
    let parsed = settings.method;
    let (sys, con, init) = (system.0, contact.0, initial.0);
    let sol = released(py, |interrupt| {
        core::simulate(&sys, &con, &init, &settings, interrupt)
    })?;
    let h = sol.history;
    Ok(Solution {
        rows: h.time.len(),
        history: [
            Column::new(h.time),
            Column::new(h.main_displacement),
            Column::new(h.main_velocity),
            Column::new(h.impact_displacement),
            Column::new(h.impact_velocity),
            Column::new(h.contact_force),
        ],
        contacts: Py::new(py, ContactTable::new(sol.contacts))?,
        steps: sol.steps,
        rejected_steps: sol.rejected_steps,
        rhs_evaluations: sol.rhs_evaluations,
        grazing_contacts: sol.grazing_contacts,
        final_time: sol.final_time,
        energy_growth: sol.energy_growth,
        energy_residual: sol.energy_residual,
        final_state: InitialState(sol.final_state),
        method: parsed.name(),
        stepping: match settings.stepping {
            core::Stepping::Fixed => "fixed",
            core::Stepping::Events => "events",
        },
    })
}

/// Hertz stiffness K_hz (N/m^1.5) of a sphere (``radius`` m, ``youngs_modulus``
/// Pa, ``poisson_ratio``) on a flat, or on a second sphere of ``other_radius``
/// (m), made of (``other_youngs_modulus`` Pa, ``other_poisson_ratio``):
/// ``K_hz = (4/3) E* sqrt(R)``, ``1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2``,
/// ``R = r1 r2 / (r1 + r2)``.
#[pyfunction]
#[pyo3(signature = (radius, youngs_modulus, poisson_ratio, other_youngs_modulus, other_poisson_ratio, other_radius = None))]
fn hertz_stiffness(
    #[pyo3(from_py_with = real)] radius: f64,
    #[pyo3(from_py_with = real)] youngs_modulus: f64,
    #[pyo3(from_py_with = real)] poisson_ratio: f64,
    #[pyo3(from_py_with = real)] other_youngs_modulus: f64,
    #[pyo3(from_py_with = real)] other_poisson_ratio: f64,
    #[pyo3(from_py_with = real_or_none)] other_radius: Option<f64>,
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

/// One cantilever mode reduced to a single degree of freedom (see
/// ``cantilever_mode``). Stiffnesses in N/m, masses in kg, frequency in rad/s.
#[pyclass(frozen, get_all, module = "vibroimpact._core")]
struct BeamMode {
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
fn cantilever_mode(
    #[pyo3(from_py_with = real)] length: f64,
    #[pyo3(from_py_with = real)] youngs_modulus: f64,
    #[pyo3(from_py_with = real)] second_moment: f64,
    #[pyo3(from_py_with = real)] density: f64,
    #[pyo3(from_py_with = real)] area: f64,
    #[pyo3(from_py_with = mode_arg)] mode: u32,
    #[pyo3(from_py_with = real_or_none)] position: Option<f64>,
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
fn cantilever_root(#[pyo3(from_py_with = mode_arg)] mode: u32) -> PyResult<f64> {
    beam::cantilever_root(mode).map_err(to_py)
}

/// Which derivative of a mode shape: 0, 1, 2 or 3 (a huge int is invalid
/// input, not an OverflowError).
fn derivative_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    match value.extract::<i64>() {
        Ok(k @ 0..=3) => Ok(k as usize),
        Ok(_) => Err(InvalidInputError::new_err(format!(
            "derivative must be 0, 1, 2 or 3, got {value}"
        ))),
        Err(err) if err.is_instance_of::<pyo3::exceptions::PyOverflowError>(value.py()) => Err(
            InvalidInputError::new_err(format!("derivative must be 0, 1, 2 or 3, got {value}")),
        ),
        Err(err) => Err(err),
    }
}

/// Normalised mode shape ``phi(x)`` (``int_0^L phi^2 dx = L``, ``|phi(L)| =
/// 2``) of mode ``mode`` (any, exact to round-off) of a cantilever of
/// ``length`` (m), at ``x`` (m from the clamp, in [0, length]); with
/// ``derivative`` k = 1, 2 or 3 its k-th derivative in x (1/m^k).
#[pyfunction]
#[pyo3(signature = (length, mode, x, derivative = 0))]
fn cantilever_mode_shape(
    #[pyo3(from_py_with = real)] length: f64,
    #[pyo3(from_py_with = mode_arg)] mode: u32,
    #[pyo3(from_py_with = real)] x: f64,
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
fn goldsmith_contact_duration(
    #[pyo3(from_py_with = real)] impact_mass: f64,
    #[pyo3(from_py_with = real)] main_mass: f64,
    #[pyo3(from_py_with = real)] hertz_stiffness: f64,
    #[pyo3(from_py_with = real)] approach_speed: f64,
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
fn goldsmith_max_indentation(
    #[pyo3(from_py_with = real)] impact_mass: f64,
    #[pyo3(from_py_with = real)] main_mass: f64,
    #[pyo3(from_py_with = real)] hertz_stiffness: f64,
    #[pyo3(from_py_with = real)] approach_speed: f64,
) -> PyResult<f64> {
    closed_forms::goldsmith_max_indentation(impact_mass, main_mass, hertz_stiffness, approach_speed)
        .map_err(to_py)
}

/// Contact duration (s) of a linear spring ``stiffness`` (N/m) with a damper
/// ``damping`` (N s/m) between two free bodies: half a damped period.
#[pyfunction]
#[pyo3(signature = (impact_mass, main_mass, stiffness, damping = 0.0))]
fn linear_contact_duration(
    #[pyo3(from_py_with = real)] impact_mass: f64,
    #[pyo3(from_py_with = real)] main_mass: f64,
    #[pyo3(from_py_with = real)] stiffness: f64,
    #[pyo3(from_py_with = real)] damping: f64,
) -> PyResult<f64> {
    closed_forms::linear_contact_duration(impact_mass, main_mass, stiffness, damping).map_err(to_py)
}

/// The founding paper's adequacy factor (Eq. 15), percent:
/// ``((1 - error/max_error) wf1 + (1 - cpu_time/max_cpu_time)(1 - wf1)) * 100``
/// with ``wf1 = error_weight``.
#[pyfunction]
fn adequacy(
    #[pyo3(from_py_with = real)] error: f64,
    #[pyo3(from_py_with = real)] max_error: f64,
    #[pyo3(from_py_with = real)] cpu_time: f64,
    #[pyo3(from_py_with = real)] max_cpu_time: f64,
    #[pyo3(from_py_with = real)] error_weight: f64,
) -> PyResult<f64> {
    closed_forms::adequacy(error, max_error, cpu_time, max_cpu_time, error_weight).map_err(to_py)
}

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
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
    m.add_class::<BeamMode>()?;
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(system::simulate_system, m)?)?;
    m.add_function(wrap_pyfunction!(check_solver, m)?)?;
    m.add_function(wrap_pyfunction!(hertz_stiffness, m)?)?;
    m.add_function(wrap_pyfunction!(cantilever_mode, m)?)?;
    m.add_function(wrap_pyfunction!(cantilever_root, m)?)?;
    m.add_function(wrap_pyfunction!(cantilever_mode_shape, m)?)?;
    m.add_function(wrap_pyfunction!(goldsmith_contact_duration, m)?)?;
    m.add_function(wrap_pyfunction!(goldsmith_max_indentation, m)?)?;
    m.add_function(wrap_pyfunction!(linear_contact_duration, m)?)?;
    m.add_function(wrap_pyfunction!(adequacy, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add("DEFAULT_MAX_ROWS", core::DEFAULT_MAX_ROWS)?;
    m.add("DEFAULT_ENERGY_TOLERANCE", core::DEFAULT_ENERGY_TOLERANCE)?;
    Ok(())
}
