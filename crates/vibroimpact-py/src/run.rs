//! The two-mass run: its settings, `simulate`, and the results (history
//! columns and the contact table, as NumPy arrays made on first access).

use std::sync::{Mutex, OnceLock};

use numpy::{IntoPyArray, PyArray1};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyTuple};
use vibroimpact_core as core;
use vibroimpact_core::kernel::events::{PairContact, SystemSolution};
use vibroimpact_core::methods::registry as core_registry;

use crate::convert::*;
use crate::errors::*;
use crate::inputs::{Contact, ImpactDamper, InitialState};
/// A column of results that becomes a NumPy array on first access (without
/// a copy): a call pays only for the arrays it reads.
pub(crate) struct Column {
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

pub(crate) const CONTACT_COLUMNS: [&str; 9] = [
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

pub(crate) fn record_values(r: &PairContact) -> [f64; 9] {
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
pub(crate) struct ContactTable {
    /// Each contact's values, in the order of [`CONTACT_COLUMNS`].
    rows: Vec<[f64; 9]>,
    columns: [OnceLock<Py<PyArray1<f64>>>; 9],
}

impl ContactTable {
    fn new(records: &[PairContact]) -> Self {
        Self::of_rows(records.iter().map(record_values).collect())
    }

    fn of_rows(rows: Vec<[f64; 9]>) -> Self {
        Self {
            rows,
            columns: Default::default(),
        }
    }

    fn column(&self, py: Python<'_>, index: usize) -> Py<PyArray1<f64>> {
        self.columns[index]
            .get_or_init(|| {
                let values: Vec<f64> = self.rows.iter().map(|r| r[index]).collect();
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
        self.rows.len()
    }
    /// Pickled as its rows (a table made again by `_contact_table`).
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let rebuild = py.import("vibroimpact._core")?.getattr("_contact_table")?;
        Ok((rebuild, (self.rows.clone(),).into_pyobject(py)?))
    }
    /// One dict per contact, keyed by the column names.
    fn to_dicts<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let list = PyList::empty(py);
        for r in &self.rows {
            let d = PyDict::new(py);
            for (name, value) in CONTACT_COLUMNS.iter().zip(*r) {
                d.set_item(name, value)?;
            }
            list.append(d)?;
        }
        Ok(list)
    }
    fn __repr__(&self) -> String {
        format!("ContactTable({} contacts)", self.rows.len())
    }
}

/// A contact table from its rows (each in the order of `ContactTable.columns`):
/// how a pickled table is made again.
#[pyfunction]
pub(crate) fn _contact_table(rows: Vec<[f64; 9]>) -> ContactTable {
    ContactTable::of_rows(rows)
}

/// What ``simulate`` returns: the time history (NumPy arrays, SI units), the
/// table of contacts and the run's statistics.
#[pyclass(frozen, module = "vibroimpact._core")]
pub(crate) struct Solution {
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
    method: String,
    /// "fixed" or "events".
    #[pyo3(get)]
    stepping: String,
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
    /// Pickled as its columns, contacts and statistics (a solution made again
    /// by `_two_mass_solution`), so a pool of processes can return it.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let rebuild = py
            .import("vibroimpact._core")?
            .getattr("_two_mass_solution")?;
        let history: Vec<Py<PyArray1<f64>>> = self.history.iter().map(|c| c.get(py)).collect();
        let counts = (
            self.steps,
            self.rejected_steps,
            self.rhs_evaluations,
            self.grazing_contacts,
        );
        let arguments = (
            history,
            self.contacts.clone_ref(py),
            counts,
            (self.method.clone(), self.stepping.clone()),
            (self.final_time, self.energy_growth, self.energy_residual),
            self.final_state.clone(),
        );
        Ok((rebuild, arguments.into_pyobject(py)?))
    }
    /// One line: the run (method, stepping, time reached, steps), the contacts and
    /// rows kept, and the fields (never the arrays themselves).
    fn __repr__(&self, py: Python<'_>) -> String {
        format!(
            "Solution(two-body run, method={:?}, stepping={:?}, t_end={:?} s, steps={}, \
             contacts={}, rows={}; fields: t, main_displacement, main_velocity, \
             impact_displacement, impact_velocity, contact_force, contacts, steps, \
             rejected_steps, rhs_evaluations, grazing_contacts, final_time, final_state, \
             energy_growth, energy_residual)",
            self.method,
            self.stepping,
            // Six significant digits: a fixed-step run's time is t_end rounded up to
            // whole steps, with round-off digits not worth a line.
            format!("{:.5e}", self.final_time)
                .parse::<f64>()
                .unwrap_or(self.final_time),
            self.steps,
            self.contacts.bind(py).get().rows.len(),
            self.rows,
        )
    }
}

fn columns_rows(history: &[numpy::PyReadonlyArray1<'_, f64>]) -> usize {
    history.first().map_or(0, |a| a.as_array().len())
}

/// A two-mass solution from what its `__reduce__` gives: how a pickled one is
/// made again.
#[pyfunction]
pub(crate) fn _two_mass_solution(
    history: Vec<numpy::PyReadonlyArray1<'_, f64>>,
    contacts: Py<ContactTable>,
    counts: (u64, u64, u64, u64),
    names: (String, String),
    figures: (f64, f64, f64),
    final_state: PyRef<'_, InitialState>,
) -> PyResult<Solution> {
    let ((method, stepping), (final_time, energy_growth, energy_residual)) = (names, figures);
    let columns: Vec<Column> = history
        .iter()
        .map(|a| Column::new(a.as_array().to_vec()))
        .collect();
    let rows = columns_rows(&history);
    let history: [Column; 6] = columns
        .try_into()
        .map_err(|_| InvalidInputError::new_err("a two-mass solution has six history columns"))?;
    let (steps, rejected_steps, rhs_evaluations, grazing_contacts) = counts;
    Ok(Solution {
        history,
        rows,
        contacts,
        steps,
        rejected_steps,
        rhs_evaluations,
        grazing_contacts,
        final_time,
        method,
        stepping,
        energy_growth,
        energy_residual,
        final_state: final_state.clone(),
    })
}

/// The two-mass run's settings from its arguments, each left out (None)
/// taking the core registry's default for the two-mass damper (method,
/// stepping, contact timing, method options, `max_steps`).
#[allow(clippy::too_many_arguments)]
pub(crate) fn settings(
    dt: Option<f64>,
    t_end: f64,
    method: Option<&str>,
    every: u64,
    contact_timing: Option<&str>,
    stepping: Option<&str>,
    beta: Option<f64>,
    gamma: Option<f64>,
    spectral_radius: Option<f64>,
    rtol: Option<f64>,
    atol: Option<f64>,
    max_steps: Option<u64>,
    max_rows: Option<u64>,
    energy_tolerance: Option<f64>,
    history: bool,
) -> PyResult<core::Settings> {
    let defaults = core_registry::TWO_MASS;
    let options = core_registry::Options::or_defaults(rtol, atol, beta, gamma, spectral_radius);
    let parsed = core::Method::parse(method.unwrap_or(defaults.method), &options).map_err(to_py)?;
    let timing = core::ContactTiming::parse(contact_timing.unwrap_or(defaults.contact_timing))
        .map_err(to_py)?;
    let stepping = stepping
        .map(core::Stepping::parse)
        .transpose()
        .map_err(to_py)?;
    let max_steps = max_steps.unwrap_or(core_registry::DEFAULT_MAX_STEPS);
    core::Settings::new(parsed, dt, t_end, every, timing, stepping, max_steps)
        .and_then(|s| s.with_limits(history, max_rows, energy_tolerance))
        .map_err(to_py)
}

/// Check solver settings as ``simulate`` would, without running; raises
/// ``InvalidInputError`` naming the offending field.
#[pyfunction]
#[pyo3(signature = (*, t_end, dt = None, method = None, every = 1, contact_timing = None, stepping = None, beta = None, gamma = None, spectral_radius = None, rtol = None, atol = None, max_steps = None, max_rows = None, energy_tolerance = None, history = true))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn check_solver(
    #[pyo3(from_py_with = arg::t_end)] t_end: f64,
    #[pyo3(from_py_with = optional::dt)] dt: Option<f64>,
    method: Option<&str>,
    #[pyo3(from_py_with = every_arg)] every: u64,
    contact_timing: Option<&str>,
    stepping: Option<&str>,
    #[pyo3(from_py_with = optional::beta)] beta: Option<f64>,
    #[pyo3(from_py_with = optional::gamma)] gamma: Option<f64>,
    #[pyo3(from_py_with = optional::spectral_radius)] spectral_radius: Option<f64>,
    #[pyo3(from_py_with = optional::rtol)] rtol: Option<f64>,
    #[pyo3(from_py_with = optional::atol)] atol: Option<f64>,
    #[pyo3(from_py_with = optional_max_steps)] max_steps: Option<u64>,
    #[pyo3(from_py_with = max_rows_arg)] max_rows: Option<u64>,
    #[pyo3(from_py_with = optional::energy_tolerance)] energy_tolerance: Option<f64>,
    #[pyo3(from_py_with = history_arg)] history: bool,
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
/// interpenetrating is refused. ``energy_tolerance`` (relative, in (0, 1],
/// None: ``DEFAULT_ENERGY_TOLERANCE``, 0.05): a result whose energy balance
/// (stored energy + dissipated work - external work = energy at the start)
/// misses by more than that fraction of the energy in play, or one of whose
/// contacts creates energy beyond it, raises ``EnergyBalanceError``; so does a
/// contact that creates more than 1e-2 of it whatever ``energy_tolerance``
/// says, by every method but the paper's ``"newmark"`` (whose creation is its
/// documented error).
/// The GIL is released while integrating; Ctrl-C interrupts.
#[pyfunction]
#[pyo3(signature = (system, contact, initial, *, t_end, dt = None, method = None, every = 1, contact_timing = None, stepping = None, beta = None, gamma = None, spectral_radius = None, rtol = None, atol = None, max_steps = None, max_rows = None, energy_tolerance = None, history = true))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn simulate(
    py: Python<'_>,
    system: &ImpactDamper,
    contact: &Contact,
    initial: &InitialState,
    #[pyo3(from_py_with = arg::t_end)] t_end: f64,
    #[pyo3(from_py_with = optional::dt)] dt: Option<f64>,
    method: Option<&str>,
    #[pyo3(from_py_with = every_arg)] every: u64,
    contact_timing: Option<&str>,
    stepping: Option<&str>,
    #[pyo3(from_py_with = optional::beta)] beta: Option<f64>,
    #[pyo3(from_py_with = optional::gamma)] gamma: Option<f64>,
    #[pyo3(from_py_with = optional::spectral_radius)] spectral_radius: Option<f64>,
    #[pyo3(from_py_with = optional::rtol)] rtol: Option<f64>,
    #[pyo3(from_py_with = optional::atol)] atol: Option<f64>,
    #[pyo3(from_py_with = optional_max_steps)] max_steps: Option<u64>,
    #[pyo3(from_py_with = max_rows_arg)] max_rows: Option<u64>,
    #[pyo3(from_py_with = optional::energy_tolerance)] energy_tolerance: Option<f64>,
    #[pyo3(from_py_with = history_arg)] history: bool,
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
    // The one kernel runs the preset (`ImpactDamper::assembly`): the state is
    // `[w, y, w', y']`, the one pair the damper.
    let sol = released(py, |interrupt| {
        core_registry::two_mass::simulate(&sys, &con, &init, &settings, interrupt)
    })?;
    let SystemSolution {
        time,
        states,
        contacts,
        final_state,
        contact_forces,
        ..
    } = sol;
    // The columns are copies of the rows: memory the machine may refuse (under
    // `ulimit -v`), said as Python's MemoryError, never an abort.
    let rows = time.len();
    let column = |values: &mut dyn Iterator<Item = f64>| -> PyResult<Vec<f64>> {
        let mut out = Vec::new();
        out.try_reserve_exact(rows).map_err(|_| {
            pyo3::exceptions::PyMemoryError::new_err(format!(
                "the run's history of {rows} rows could not be copied into arrays (the \
                 machine refused {:.0} MB more): set history = false, raise every or shorten \
                 t_end",
                (rows * 8) as f64 / 1e6
            ))
        })?;
        out.extend(values);
        Ok(out)
    };
    let of = |k: usize| states.iter().skip(k).step_by(4).copied();
    let (w, wv) = (column(&mut of(0))?, column(&mut of(2))?);
    let (y, yv) = (column(&mut of(1))?, column(&mut of(3))?);
    let forces = if contact_forces.len() == rows {
        contact_forces
    } else {
        column(&mut std::iter::repeat_n(0.0, rows))?
    };
    Ok(Solution {
        rows: time.len(),
        history: [
            Column::new(time),
            Column::new(w),
            Column::new(wv),
            Column::new(y),
            Column::new(yv),
            Column::new(forces),
        ],
        contacts: Py::new(py, ContactTable::new(&contacts))?,
        steps: sol.steps,
        rejected_steps: sol.rejected_steps,
        rhs_evaluations: sol.rhs_evaluations,
        grazing_contacts: sol.grazing_contacts,
        final_time: sol.final_time,
        energy_growth: sol.energy_growth,
        energy_residual: sol.energy_residual,
        final_state: InitialState(core::State::of_vector(&final_state)),
        method: parsed.name().to_string(),
        stepping: match settings.stepping {
            core::Stepping::Fixed => "fixed",
            core::Stepping::Events => "events",
        }
        .to_string(),
    })
}
