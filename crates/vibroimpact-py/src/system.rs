//! The binding of the 0.2 engine: a system described by plain Python data
//! (the sections of a TOML scenario, already checked for unknown keys and
//! types by `vibroimpact.system`), integrated with the GIL released, and the
//! results returned as flat NumPy arrays for the Python side to shape.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::RecvTimeoutError;
use std::time::Duration;

use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{IntoPyDict, PyDict, PyList};
use vibroimpact_core as core;
use vibroimpact_core::kernel::events::Stepping;
use vibroimpact_core::methods::registry::{
    Options, DEFAULT_MAX_STEPS, ENERGY_TOLERANCE, FORCING_PERIOD, RECORD_FROM, STROBE_PERIOD,
    SYSTEM, TOLERANCE, T_END,
};
use vibroimpact_core::model::assembly::{initial_state, resumed_state, Assembly};

use crate::convert::system::system_spec;
use crate::errors::{released, to_py, InvalidInputError};
use crate::ready::{check_method, Limits, Ready};

/// A 0.2 system checked once, with its method, to run many times from any
/// state (the analyses' stroboscopic maps): see `vibroimpact.analysis`.
#[pyclass(frozen, module = "vibroimpact._core")]
pub struct PreparedSystem {
    /// A run at a time: the method's buffers are the system's.
    pub(crate) ready: std::sync::Mutex<Ready>,
}

impl PreparedSystem {
    /// The run state, locked (a run at a time), with `state`, where given,
    /// checked to be the system's `2 dim` values. Where another thread's run
    /// holds it, waited for with the GIL released (that run needs the GIL to
    /// return: two threads on one system had hung, Ctrl-C unheard), and the
    /// wait ended by an interrupt.
    pub(crate) fn locked(
        &self,
        py: Python<'_>,
        state: Option<&[f64]>,
    ) -> PyResult<std::sync::MutexGuard<'_, Ready>> {
        let ready = loop {
            match self.ready.try_lock() {
                Ok(ready) => break ready,
                Err(std::sync::TryLockError::WouldBlock) => {
                    py.detach(|| std::thread::sleep(std::time::Duration::from_micros(200)));
                    py.check_signals()?;
                }
                Err(std::sync::TryLockError::Poisoned(_)) => {
                    return Err(InvalidInputError::new_err(
                        "a run of this system failed; make it again",
                    ))
                }
            }
        };
        let size = 2 * ready.system.dim;
        match state {
            Some(state) if state.len() != size => Err(InvalidInputError::new_err(format!(
                "state must have {size} values (x then v), got {}",
                state.len()
            ))),
            _ => Ok(ready),
        }
    }
}

#[pymethods]
impl PreparedSystem {
    /// Check `spec` (the sections, as `simulate_system` takes them) and make
    /// its method; the settings as for `simulate_system` (`t_end`, s, sets the
    /// default duration of swept signals); `initial`, where given, the four
    /// arrays of `[initial]`, checked as a run from them checks them.
    #[new]
    #[pyo3(signature = (spec, *, t_end, method=None, dt=None, rtol=None, atol=None, beta=None, gamma=None, spectral_radius=None, max_steps=None, max_rows=None, energy_tolerance=None, stepping=None, contact_timing=None, initial=None))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        spec: &Bound<'_, PyDict>,
        #[pyo3(from_py_with = crate::convert::arg::t_end)] t_end: f64,
        method: Option<&str>,
        #[pyo3(from_py_with = crate::convert::optional::dt)] dt: Option<f64>,
        #[pyo3(from_py_with = crate::convert::optional::rtol)] rtol: Option<f64>,
        #[pyo3(from_py_with = crate::convert::optional::atol)] atol: Option<f64>,
        #[pyo3(from_py_with = crate::convert::optional::beta)] beta: Option<f64>,
        #[pyo3(from_py_with = crate::convert::optional::gamma)] gamma: Option<f64>,
        #[pyo3(from_py_with = crate::convert::optional::spectral_radius)] spectral_radius: Option<
            f64,
        >,
        #[pyo3(from_py_with = crate::convert::optional_max_steps)] max_steps: Option<u64>,
        #[pyo3(from_py_with = crate::convert::max_rows_arg)] max_rows: Option<u64>,
        #[pyo3(from_py_with = crate::convert::optional::energy_tolerance)] energy_tolerance: Option<
            f64,
        >,
        stepping: Option<&str>,
        contact_timing: Option<&str>,
        initial: Option<[Vec<f64>; 4]>,
    ) -> PyResult<Self> {
        let options = Options::or_defaults(rtol, atol, beta, gamma, spectral_radius);
        let method = method.unwrap_or(SYSTEM.method);
        let limits = Limits::new(
            method,
            t_end,
            dt,
            &options,
            (max_steps, max_rows, energy_tolerance),
            (stepping, contact_timing),
        )?;
        let ready = Ready::new(spec, method, t_end, &options, limits)?;
        if let Some(initial) = initial {
            // `[initial]` as a run takes it: every pair apart or touching.
            start_of(&ready.system, &initial)?;
        }
        Ok(Self {
            ready: std::sync::Mutex::new(ready),
        })
    }

    /// Run from the flat state `x` then `v` (the structure's coordinates, then
    /// the dampers') for `t_end` s, keeping no history: a dict as
    /// `simulate_system` returns, with `open_contacts` (per interaction, None
    /// or the compliant contact open at the end: `[approach_rate (m/s),
    /// onset (s, before the run's end: < 0), approach_speed (m/s),
    /// max_indentation (m)]`). `carried`: the `open_contacts` of the run
    /// this one continues from its final state (None: contacts in progress
    /// at the start begin there).
    #[pyo3(signature = (state, t_end, *, record_from=None, strobe_period=None, carried=None))]
    fn run<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = crate::convert::state_arg)] state: Vec<f64>,
        #[pyo3(from_py_with = crate::convert::arg::t_end)] t_end: f64,
        #[pyo3(from_py_with = crate::convert::optional::record_from)] record_from: Option<f64>,
        #[pyo3(from_py_with = crate::convert::optional::strobe_period)] strobe_period: Option<f64>,
        carried: Option<Vec<Option<[f64; 4]>>>,
    ) -> PyResult<Bound<'py, PyDict>> {
        let mut ready = self.locked(py, Some(&state))?;
        T_END.check(t_end).map_err(to_py)?;
        let system = &ready.system;
        let (n, d) = (system.n, system.dim);
        record_from
            .map(|v| RECORD_FROM.check(v))
            .transpose()
            .map_err(to_py)?;
        strobe_period
            .map(|v| STROBE_PERIOD.check(v))
            .transpose()
            .map_err(to_py)?;
        let y0 = resumed_state(
            system,
            [&state[..n], &state[d..d + n], &state[n..d], &state[d + n..]],
        )
        .map_err(to_py)?;
        let carried = crate::convert::carried_contacts(carried);
        let start = (&y0[..], &carried[..]);
        let sol = ready.run(py, start, t_end, (false, 1), record_from, strobe_period)?;
        solution_dict(py, &ready.system, sol)
    }

    /// Shoot for a periodic orbit over `t_end` s (whole forcing periods) from
    /// the flat state `state` (see `vibroimpact.analysis.orbit`): Newton's
    /// method with a central-difference Jacobian, all in the core with the GIL
    /// released. `forcing_period` (s, default `t_end`) sets the scale of the
    /// motion (see `core::analysis::shooting::shoot`). Returns `state`, `monodromy`
    /// (flat, row-major), `converged`, `iterations`, `residual`, `maps`, and by
    /// the tangent flow `grazings` (the last map's: the orbit's when converged).
    #[pyo3(signature = (state, t_end, *, tolerance, max_iterations, forcing_period = None, jacobian = "differences"))]
    #[allow(clippy::too_many_arguments)]
    fn shoot<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = crate::convert::state_arg)] state: Vec<f64>,
        #[pyo3(from_py_with = crate::convert::arg::t_end)] t_end: f64,
        #[pyo3(from_py_with = crate::convert::arg::tolerance)] tolerance: f64,
        #[pyo3(from_py_with = crate::convert::max_iterations_arg)] max_iterations: usize,
        #[pyo3(from_py_with = crate::convert::optional::forcing_period)] forcing_period: Option<
            f64,
        >,
        jacobian: &str,
    ) -> PyResult<Bound<'py, PyDict>> {
        T_END.check(t_end).map_err(to_py)?;
        TOLERANCE.check(tolerance).map_err(to_py)?;
        let tangent = match jacobian {
            "tangent" => true,
            "differences" => false,
            other => {
                return Err(InvalidInputError::new_err(format!(
                    "jacobian must be \"tangent\" or \"differences\", got {other:?}"
                )))
            }
        };
        let forcing_period = FORCING_PERIOD
            .check(forcing_period.unwrap_or(t_end))
            .map_err(to_py)?;
        let mut ready = self.locked(py, Some(&state))?;
        let ready: &mut Ready = &mut ready;
        let mut grazed = Vec::new();
        let shot = released(py, |interrupt| {
            if tangent {
                core::analysis::shooting::shoot_by_tangent(
                    &mut |z| ready.map_tangent(z, t_end, interrupt, &mut grazed),
                    &state,
                    forcing_period,
                    tolerance,
                    max_iterations,
                )
            } else {
                core::analysis::shooting::shoot(
                    &mut |z| ready.map(z, t_end, interrupt),
                    &state,
                    forcing_period,
                    tolerance,
                    max_iterations,
                )
            }
        })?;
        let out = PyDict::new(py);
        out.set_item("state", shot.state.into_pyarray(py))?;
        out.set_item("monodromy", shot.monodromy.into_pyarray(py))?;
        out.set_item("converged", shot.converged)?;
        out.set_item("iterations", shot.iterations)?;
        out.set_item("residual", shot.residual)?;
        out.set_item("maps", shot.maps)?;
        if tangent {
            out.set_item(
                "grazings",
                crate::tangent::grazings(py, &ready.system, &grazed)?,
            )?;
        }
        Ok(out)
    }
}

/// Integrate a 0.2 system (see `vibroimpact.simulate_system`). Returns a
/// dict of flat arrays that the Python side shapes.
#[pyfunction]
#[pyo3(signature = (spec, initial, *, t_end, method=None, dt=None, rtol=None, atol=None, beta=None, gamma=None, spectral_radius=None, every=1, history=true, max_steps=None, max_rows=None, energy_tolerance=None, record_from=None, strobe_period=None, stepping=None, contact_timing=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_system<'py>(
    py: Python<'py>,
    spec: &Bound<'py, PyDict>,
    initial: [Vec<f64>; 4],
    #[pyo3(from_py_with = crate::convert::arg::t_end)] t_end: f64,
    method: Option<&str>,
    #[pyo3(from_py_with = crate::convert::optional::dt)] dt: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::rtol)] rtol: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::atol)] atol: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::beta)] beta: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::gamma)] gamma: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::spectral_radius)] spectral_radius: Option<f64>,
    #[pyo3(from_py_with = crate::convert::every_arg)] every: u64,
    #[pyo3(from_py_with = crate::convert::history_arg)] history: bool,
    #[pyo3(from_py_with = crate::convert::optional_max_steps)] max_steps: Option<u64>,
    #[pyo3(from_py_with = crate::convert::max_rows_arg)] max_rows: Option<u64>,
    #[pyo3(from_py_with = crate::convert::optional::energy_tolerance)] energy_tolerance: Option<
        f64,
    >,
    #[pyo3(from_py_with = crate::convert::optional::record_from)] record_from: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::strobe_period)] strobe_period: Option<f64>,
    stepping: Option<&str>,
    contact_timing: Option<&str>,
) -> PyResult<Bound<'py, PyDict>> {
    let options = Options::or_defaults(rtol, atol, beta, gamma, spectral_radius);
    let method = method.unwrap_or(SYSTEM.method);
    let limits = Limits::new(
        method,
        t_end,
        dt,
        &options,
        (max_steps, max_rows, energy_tolerance),
        (stepping, contact_timing),
    )?;
    let mut ready = Ready::new(spec, method, t_end, &options, limits)?;
    let y0 = start_of(&ready.system, &initial)?;
    let start = (&y0[..], &[][..]);
    let sol = ready.run(
        py,
        start,
        t_end,
        (history, every),
        record_from,
        strobe_period,
    )?;
    solution_dict(py, &ready.system, sol)
}

/// The state of `[initial]`'s four arrays (the structure's displacements
/// and velocities, the dampers'), checked as a run from it checks it.
fn start_of(system: &Assembly, initial: &[Vec<f64>; 4]) -> PyResult<Vec<f64>> {
    let [x, v, z, w] = initial;
    initial_state(system, x, v, z, w).map_err(to_py)
}

/// A run's results as a dict of flat arrays.
fn solution_dict<'py>(
    py: Python<'py>,
    system: &Assembly,
    sol: core::kernel::events::SystemSolution,
) -> PyResult<Bound<'py, PyDict>> {
    // Onsets relative to the run's end: what a run continued from its final
    // state takes as `carried` (made before the solution is taken apart).
    let open: Vec<Option<[f64; 4]>> = sol
        .carried()
        .into_iter()
        .map(|c| c.map(crate::convert::carried_values))
        .collect();
    let out = PyDict::new(py);
    out.set_item("n", system.n)?;
    out.set_item("k", system.k)?;
    out.set_item("pairs", system.pairs.clone())?;
    out.set_item("time", sol.time.into_pyarray(py))?;
    out.set_item("states", sol.states.into_pyarray(py))?;
    out.set_item("final_state", sol.final_state.into_pyarray(py))?;
    out.set_item("final_time", sol.final_time)?;
    let columns = PyDict::new(py);
    let c = &sol.contacts;
    let column = |f: fn(&core::kernel::events::PairContact) -> f64| {
        c.iter().map(f).collect::<Vec<f64>>().into_pyarray(py)
    };
    columns.set_item("pair", c.iter().map(|r| r.pair).collect::<Vec<usize>>())?;
    columns.set_item("kind", c.iter().map(|r| r.kind.name()).collect::<Vec<_>>())?;
    columns.set_item("onset", column(|r| r.onset))?;
    columns.set_item("separation", column(|r| r.separation))?;
    columns.set_item("duration", column(|r| r.duration))?;
    columns.set_item("max_indentation", column(|r| r.max_indentation))?;
    columns.set_item("approach_speed", column(|r| r.approach_speed))?;
    columns.set_item("rebound_speed", column(|r| r.rebound_speed))?;
    columns.set_item("restitution", column(|r| r.restitution))?;
    columns.set_item("energy_dissipated", column(|r| r.energy_dissipated))?;
    columns.set_item("energy_change", column(|r| r.energy_change))?;
    out.set_item("contacts", columns)?;
    out.set_item("contact_force_pairs", sol.contact_force_pairs)?;
    out.set_item("contact_forces", sol.contact_forces.into_pyarray(py))?;
    let e = sol.energy;
    let energy = [
        ("input_work", e.input_work),
        ("dissipated", e.dissipated),
        ("viscous", e.viscous),
        ("contact", e.contact),
        ("friction", e.friction),
        ("impact", e.impact),
        ("stored_start", e.stored_start),
        ("stored_end", e.stored_end),
        ("residual", e.residual),
    ]
    .into_py_dict(py)?;
    out.set_item("energy", energy)?;
    out.set_item("steps", sol.steps)?;
    out.set_item("rejected_steps", sol.rejected_steps)?;
    out.set_item("rhs_evaluations", sol.rhs_evaluations)?;
    out.set_item("grazing_contacts", sol.grazing_contacts)?;
    let r = sol.reductions;
    out.set_item("peaks", r.peaks.into_pyarray(py))?;
    out.set_item("square_integrals", r.square_integrals.into_pyarray(py))?;
    out.set_item("recorded_time", r.recorded_time)?;
    out.set_item("strobe", r.strobe.into_pyarray(py))?;
    out.set_item("strobe_time", r.strobe_time.into_pyarray(py))?;
    out.set_item("open_contacts", open)?;
    Ok(out)
}

/// The linear parts of a 0.2 system over all its coordinates (structure, then
/// dampers): `mass`, `stiffness`, `damping` (row-major `dim x dim`), the constant
/// load (gravity, N) and each harmonic load (`amplitude`, `omega` in rad/s,
/// `phase`, `shape`), for closed-form linear responses.
#[pyfunction]
#[pyo3(signature = (spec))]
pub fn linear_parts<'py>(
    py: Python<'py>,
    spec: &Bound<'py, PyDict>,
) -> PyResult<Bound<'py, PyDict>> {
    // Harmonic loads only: no signal needs the run's length.
    let system_spec = system_spec(spec, 1.0)?;
    let system = Assembly::new(&system_spec).map_err(to_py)?;
    let parts = system.linear_parts("linear_parts").map_err(to_py)?;
    let out = PyDict::new(py);
    out.set_item("n", system.n)?;
    out.set_item("k", system.k)?;
    out.set_item("mass", parts.mass.into_pyarray(py))?;
    out.set_item("stiffness", parts.stiffness.into_pyarray(py))?;
    out.set_item("damping", parts.damping.into_pyarray(py))?;
    out.set_item("constant", parts.constant.into_pyarray(py))?;
    let harmonics = PyList::empty(py);
    for h in parts.harmonics {
        let d = PyDict::new(py);
        d.set_item("amplitude", h.amplitude)?;
        d.set_item("omega", h.omega)?;
        d.set_item("phase", h.phase)?;
        d.set_item("shape", h.shape.into_pyarray(py))?;
        harmonics.append(d)?;
    }
    out.set_item("harmonics", harmonics)?;
    Ok(out)
}

/// Run a chunk of a study (see `vibroimpact.study`): each row of `values`
/// (`len(paths)` values a row, flat) sets the parameters at `paths` in a
/// copy of the system and runs it, on `threads` threads (0: all cores), with
/// the GIL released. Returns the metrics as flat arrays, one row a run.
/// `analysis = "orbit"` settles, then shoots for an orbit of `orbit_periods`
/// forcing periods (its multipliers, amplitude and impacts). `lyapunov`
/// carries the tangent flow for the largest Lyapunov exponent (1/s).
/// `stepping = "fixed"` runs them as a lockstep ensemble of fixed RK4 steps
/// (any system the compact path takes: a small modal structure, a few dampers
/// and stops, compliant laws, one harmonic force; each run as its single
/// fixed-step run, bit for bit).
#[pyfunction]
#[pyo3(signature = (spec, initial, *, paths, values, analysis, t_end, record_from, settle_periods, record_periods, tolerance, threads, method=None, dt=None, rtol=None, atol=None, beta=None, gamma=None, spectral_radius=None, max_steps=None, energy_tolerance=None, mean_square=true, stepping=None, orbit_periods=1, lyapunov=false))]
#[allow(clippy::too_many_arguments)]
pub fn run_study<'py>(
    py: Python<'py>,
    spec: &Bound<'py, PyDict>,
    initial: [Vec<f64>; 4],
    paths: Vec<String>,
    values: numpy::PyReadonlyArray1<'py, f64>,
    analysis: &str,
    #[pyo3(from_py_with = crate::convert::arg::t_end)] t_end: f64,
    #[pyo3(from_py_with = crate::convert::arg::record_from)] record_from: f64,
    settle_periods: u64,
    record_periods: u64,
    #[pyo3(from_py_with = crate::convert::arg::tolerance)] tolerance: f64,
    threads: usize,
    method: Option<String>,
    #[pyo3(from_py_with = crate::convert::optional::dt)] dt: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::rtol)] rtol: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::atol)] atol: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::beta)] beta: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::gamma)] gamma: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional::spectral_radius)] spectral_radius: Option<f64>,
    #[pyo3(from_py_with = crate::convert::optional_max_steps)] max_steps: Option<u64>,
    #[pyo3(from_py_with = crate::convert::optional::energy_tolerance)] energy_tolerance: Option<
        f64,
    >,
    mean_square: bool,
    stepping: Option<&str>,
    orbit_periods: u64,
    lyapunov: bool,
) -> PyResult<Bound<'py, PyDict>> {
    use core::analysis::study::{run_study as study, Parameter, StudySettings};
    let options = Options::or_defaults(rtol, atol, beta, gamma, spectral_radius);
    let method = method.unwrap_or_else(|| SYSTEM.method.to_string());
    let energy_tolerance = energy_tolerance.unwrap_or(ENERGY_TOLERANCE.default_value());
    check_method(t_end, dt, &options, energy_tolerance)?;
    let stepping = match stepping {
        Some(stepping) => stepping,
        None => SYSTEM.stepping(&method).map_err(to_py)?,
    };
    RECORD_FROM.check(record_from).map_err(to_py)?;
    TOLERANCE.check(tolerance).map_err(to_py)?;
    let system_spec = system_spec(spec, t_end)?;
    // The base system and start must be valid on their own.
    let base = Assembly::new(&system_spec).map_err(to_py)?;
    start_of(&base, &initial)?;
    let parameters = paths
        .iter()
        .map(|p| Parameter::parse(p, &system_spec))
        .collect::<core::Result<Vec<_>>>()
        .map_err(to_py)?;
    let values = values.as_slice()?.to_vec();
    if !parameters.is_empty() && values.len() % parameters.len() != 0 {
        return Err(InvalidInputError::new_err(format!(
            "values must hold {} values a run, got {} in all",
            parameters.len(),
            values.len()
        )));
    }
    let analysis = study_analysis(
        analysis,
        t_end,
        record_from,
        settle_periods,
        record_periods,
        tolerance,
        orbit_periods,
    )?;
    let settings = StudySettings {
        method,
        dt,
        options,
        max_steps: max_steps.unwrap_or(DEFAULT_MAX_STEPS),
        energy_tolerance,
        analysis,
        mean_square,
        lockstep: lockstep_of(stepping)?,
        lyapunov,
    };
    let results = released(py, |interrupt| {
        // The runs go on the study's threads, where Python's signals cannot be
        // seen: this thread watches them and raises a flag every run checks
        // (between its steps), so Ctrl-C stops the chunk within moments.
        // The worker's end closes a channel, so that a short chunk is not held
        // for the rest of the watcher's 20 ms.
        let stop = AtomicBool::new(false);
        let (ended, end) = std::sync::mpsc::channel::<()>();
        std::thread::scope(|scope| {
            let worker = scope.spawn(|| {
                // Moved in and dropped when the study returns (or panics), which
                // ends the watcher's wait.
                let _ended = ended;
                study(
                    &system_spec,
                    &initial,
                    &parameters,
                    &values,
                    &settings,
                    threads,
                    &|| stop.load(Ordering::Relaxed),
                )
            });
            while let Err(RecvTimeoutError::Timeout) = end.recv_timeout(Duration::from_millis(20)) {
                if !stop.load(Ordering::Relaxed) && interrupt() {
                    stop.store(true, Ordering::Relaxed);
                }
            }
            worker.join().unwrap_or_else(|_| {
                Err(core::Error::Inconsistent(
                    "the study's threads failed (an internal error); please report it".into(),
                ))
            })
        })
    })?;
    study_dict(py, &base, &results)
}

/// The analysis a study's runs make, by its name.
#[allow(clippy::too_many_arguments)]
fn study_analysis(
    analysis: &str,
    t_end: f64,
    record_from: f64,
    settle_periods: u64,
    record_periods: u64,
    tolerance: f64,
    orbit_periods: u64,
) -> PyResult<core::analysis::study::Analysis> {
    use core::analysis::study::Analysis;
    Ok(match analysis {
        "run" => Analysis::Run { t_end, record_from },
        "steady-state" => Analysis::SteadyState {
            settle: settle_periods,
            record: record_periods.max(1),
            tolerance,
        },
        "orbit" => Analysis::Orbit {
            settle: settle_periods,
            periods: orbit_periods.max(1),
        },
        other => {
            return Err(InvalidInputError::new_err(format!(
                "analysis must be \"run\", \"steady-state\" or \"orbit\", got {other:?}"
            )))
        }
    })
}

/// Whether a study's `stepping` asks for lockstep fixed steps.
fn lockstep_of(stepping: &str) -> PyResult<bool> {
    let stepping = Stepping::parse(stepping, "located").map_err(to_py)?;
    Ok(matches!(stepping, Stepping::Fixed { .. }))
}

/// A study's metrics as flat arrays, one row a run.
fn study_dict<'py>(
    py: Python<'py>,
    base: &Assembly,
    results: &[core::analysis::study::RunMetrics],
) -> PyResult<Bound<'py, PyDict>> {
    let out = PyDict::new(py);
    out.set_item("n", base.n)?;
    out.set_item("pairs", base.pairs.clone())?;
    out.set_item(
        "status",
        results
            .iter()
            .map(|r| r.status)
            .collect::<Vec<u8>>()
            .into_pyarray(py),
    )?;
    out.set_item(
        "reason",
        results.iter().map(|r| r.reason.clone()).collect::<Vec<_>>(),
    )?;
    let flat = |f: &dyn Fn(&core::analysis::study::RunMetrics) -> Vec<f64>| {
        results
            .iter()
            .flat_map(f)
            .collect::<Vec<f64>>()
            .into_pyarray(py)
    };
    out.set_item("peak", flat(&|r| r.peak.clone()))?;
    out.set_item("rms", flat(&|r| r.rms.clone()))?;
    out.set_item("impacts", flat(&|r| vec![r.impacts]))?;
    out.set_item("energy_dissipated", flat(&|r| r.energy_dissipated.clone()))?;
    out.set_item("impacts_per_period", flat(&|r| vec![r.impacts_per_period]))?;
    out.set_item("settled", flat(&|r| vec![r.settled]))?;
    out.set_item("stable", flat(&|r| vec![r.stable]))?;
    out.set_item("largest_multiplier", flat(&|r| vec![r.largest_multiplier]))?;
    out.set_item("largest_lyapunov", flat(&|r| vec![r.largest_lyapunov]))?;
    Ok(out)
}
