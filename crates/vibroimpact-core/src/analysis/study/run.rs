//! The study's runs on every core (rayon): each row's parameters applied
//! to a copy of the system, or only the start changed on one system.

use rayon::prelude::*;

use super::lockstep::run_lockstep;
use super::metrics::{metrics_of, orbit_metrics, recorded_periods, RunMetrics};
use super::parameters::{row_system, Parameter, Target};
use super::settings::{Analysis, StudySettings};
use crate::analysis::tangent::Tangent;
use crate::error::{Error, Result};
use crate::kernel::events::RunOptions;
use crate::kernel::reductions::ReduceOptions;
use crate::methods::exact::ExactFlow;
use crate::methods::registry::AnyStepper;
use crate::model::assembly::{initial_state, Assembly, SystemSpec};

/// Run the study: for each row of `values` (one value per parameter), set
/// the parameters in a copy of `spec` and `initial` and run; on `threads`
/// threads (0: all cores). Results in the order of the rows.
pub fn run_study(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    parameters: &[Parameter],
    values: &[f64],
    settings: &StudySettings,
    threads: usize,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<RunMetrics>> {
    settings.check()?;
    let width = parameters.len().max(1);
    if !parameters.is_empty() && values.len() % width != 0 {
        return Err(Error::Inconsistent(format!(
            "a study of {width} parameters takes {width} values a row, got {} values in all",
            values.len()
        )));
    }
    if !matches!(settings.analysis, Analysis::Run { .. }) {
        // Refused up front on the base scenario; an axis may still make a
        // point aperiodic, which then fails alone.
        forcing_period(spec)?;
    }
    if settings.method == "exact" {
        // Every run alike would fail on a law's or a signal's kind, which no
        // axis changes: refused up front (a base whose values an axis
        // replaces may be unfit to assemble; its runs then say so).
        if let Ok(system) = Assembly::new(spec) {
            ExactFlow::takes(&system)?;
        }
    }
    let rows = if parameters.is_empty() {
        1
    } else {
        values.len() / width
    };
    if settings.lockstep {
        return run_lockstep(
            spec, initial, parameters, values, rows, settings, threads, interrupt,
        );
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Inconsistent(format!("cannot start the study's threads: {e}")))?;
    let starts_only = !parameters.is_empty()
        && parameters
            .iter()
            .all(|p| matches!(p.target, Target::Initial(..)));
    if starts_only {
        return run_starts(
            spec, initial, parameters, values, rows, settings, &pool, interrupt,
        );
    }
    let results = pool.install(|| {
        (0..rows)
            .into_par_iter()
            .map(|row| {
                if interrupt() {
                    return Err(Error::Interrupted { time: 0.0 });
                }
                let row_values = if parameters.is_empty() {
                    &[][..]
                } else {
                    &values[row * width..(row + 1) * width]
                };
                one_run(spec, initial, parameters, row_values, settings, interrupt)
            })
            .collect::<Vec<Result<RunMetrics>>>()
    });
    results.into_iter().collect()
}

/// The forcing period of a steady-state or orbit study, s (see
/// [`crate::model::signals::common_period`]).
pub(super) fn forcing_period(spec: &SystemSpec) -> Result<f64> {
    let parts: Vec<_> = spec
        .excitations
        .iter()
        .map(|e| e.signal.harmonic_frequencies())
        .collect();
    crate::model::signals::common_period(&parts)
}

/// The metrics of a run of `spec` that failed for `reason`: NaN.
pub(super) fn failed_run(spec: &SystemSpec, reason: String) -> RunMetrics {
    // Each structure coordinate, then each followed point and moment.
    let n = spec.structure.dofs() + spec.points.len() + spec.moments.len();
    // As the system names its pairs (a friction element is one whatever its force).
    let pairs =
        spec.dampers.len() + spec.stops.len() + spec.collisions.len() + spec.frictions.len();
    RunMetrics {
        status: 1,
        reason,
        peak: vec![f64::NAN; n],
        rms: vec![f64::NAN; n],
        impacts: f64::NAN,
        energy_dissipated: vec![f64::NAN; pairs],
        impacts_per_period: f64::NAN,
        settled: f64::NAN,
        stable: f64::NAN,
        largest_multiplier: f64::NAN,
        largest_lyapunov: f64::NAN,
    }
}

/// Runs that vary only the start: one system for all, one method a thread.
#[allow(clippy::too_many_arguments)]
pub(super) fn run_starts(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    parameters: &[Parameter],
    values: &[f64],
    rows: usize,
    settings: &StudySettings,
    pool: &rayon::ThreadPool,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<RunMetrics>> {
    let system = Assembly::new(spec)?;
    let width = parameters.len();
    let results = pool.install(|| {
        (0..rows)
            .into_par_iter()
            .map_init(
                || stepper_of(&system, settings),
                |stepper, row| {
                    if interrupt() {
                        return Err(Error::Interrupted { time: 0.0 });
                    }
                    // Only the start changes: no copy of the system.
                    let mut start = initial.clone();
                    for (p, v) in parameters
                        .iter()
                        .zip(&values[row * width..(row + 1) * width])
                    {
                        p.apply_start(spec, &mut start, *v);
                    }
                    let run = match stepper {
                        Ok(method) => {
                            measured_on(spec, &system, method, &start, settings, interrupt)
                        }
                        Err(e) => Err(e.clone()),
                    };
                    if let Err(e @ Error::Interrupted { .. }) = run {
                        return Err(e);
                    }
                    if run.is_err() {
                        // A run stopped part way may leave work in the method
                        // (the exact flow's pending energies): a fresh one next.
                        *stepper = stepper_of(&system, settings);
                    }
                    Ok(run.unwrap_or_else(|e| failed_run(spec, e.to_string())))
                },
            )
            .collect::<Vec<Result<RunMetrics>>>()
    });
    results.into_iter().collect()
}

/// One run of the study at `values`: its metrics, or those of a failed run
/// with its reason; an interrupt (which stops the run part way) is an error.
pub(super) fn one_run(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    parameters: &[Parameter],
    values: &[f64],
    settings: &StudySettings,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<RunMetrics> {
    let (spec, initial) = match row_system(spec, initial, parameters, values, settings) {
        Ok(row) => row,
        Err(e) => return Ok(failed_run(spec, e.to_string())),
    };
    match measured(&spec, &initial, settings, interrupt) {
        Ok(metrics) => Ok(metrics),
        Err(e @ Error::Interrupted { .. }) => Err(e),
        Err(e) => Ok(failed_run(&spec, e.to_string())),
    }
}

pub(super) fn measured(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    settings: &StudySettings,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<RunMetrics> {
    let system = Assembly::new(spec)?;
    let mut stepper = stepper_of(&system, settings)?;
    measured_on(spec, &system, &mut stepper, initial, settings, interrupt)
}

/// A run of `system` (made of `spec`) from `initial`, by `stepper` (which
/// starts afresh in every run, so that it may serve many).
pub(super) fn measured_on(
    spec: &SystemSpec,
    system: &Assembly,
    stepper: &mut AnyStepper,
    initial: &[Vec<f64>; 4],
    settings: &StudySettings,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<RunMetrics> {
    let y0 = initial_state(system, &initial[0], &initial[1], &initial[2], &initial[3])?;
    let period = || forcing_period(spec);
    let (t_end, record_from, strobe_period) = match settings.analysis {
        Analysis::Run { t_end, record_from } => (t_end, record_from, f64::INFINITY),
        Analysis::SteadyState { settle, record, .. } => {
            let t = period()?;
            let record = recorded_periods(record);
            ((settle + record) as f64 * t, settle as f64 * t, t)
        }
        Analysis::Orbit { settle, periods } => {
            return orbit_metrics(
                (spec, system),
                stepper,
                &y0,
                settings,
                (period()?, settle, periods),
                interrupt,
            );
        }
    };
    let options = run_options(
        settings,
        stepper.step(settings.dt, t_end, strobe_period),
        t_end,
        ReduceOptions {
            record_from,
            strobe_period,
            mean_square: settings.mean_square,
            // Only the recorded contacts are counted.
            contacts_from: record_from,
        },
    );
    if settings.lyapunov {
        return with_lyapunov(
            system,
            stepper,
            &y0,
            &options,
            (record_from, strobe_period),
            settings,
            interrupt,
        );
    }
    let sol = stepper.integrate(system, &y0, &options, &mut || interrupt())?;
    Ok(metrics_of(
        system,
        &sol,
        (record_from, strobe_period),
        settings,
    ))
}

/// [`measured_on`]'s run with the tangent flow over the recorded time (from
/// `record_from`, s), re-orthonormalised at each event: its largest stretch
/// rate is the largest Lyapunov exponent. Out of line, so that a plain run's
/// code is what it was.
#[inline(never)]
fn with_lyapunov(
    system: &Assembly,
    stepper: &mut AnyStepper,
    y0: &[f64],
    options: &RunOptions,
    (record_from, strobe_period): (f64, f64),
    settings: &StudySettings,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<RunMetrics> {
    let mut flow = Tangent::orthonormal(system)?.from_time(record_from);
    let sol = stepper.integrate_observed(system, y0, options, &mut || interrupt(), &mut flow)?;
    let mut metrics = metrics_of(system, &sol, (record_from, strobe_period), settings);
    let largest = flow.logs().iter().fold(f64::NEG_INFINITY, |m, l| m.max(*l));
    metrics.largest_lyapunov = largest / (options.t_end - record_from);
    Ok(metrics)
}

/// A study run's options: no history, the study's limits.
pub(super) fn run_options(
    settings: &StudySettings,
    dt: Option<f64>,
    t_end: f64,
    reduce: ReduceOptions,
) -> RunOptions {
    RunOptions {
        dt,
        t_end,
        every: 1,
        keep_history: false,
        max_steps: settings.max_steps,
        max_rows: u64::MAX,
        energy_tolerance: settings.energy_tolerance,
        reduce,
    }
}

/// The study's method for `system`.
pub(super) fn stepper_of(system: &Assembly, settings: &StudySettings) -> Result<AnyStepper> {
    AnyStepper::new(system, &settings.method, &settings.options)
}
