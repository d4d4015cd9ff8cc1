//! Fixed-step studies of small modal systems: the runs in compact lockstep
//! lanes ([`crate::analysis::lanes`]), each the single fixed-step RK4 run of
//! its system bit for bit, reduced to the metrics an event-driven study's
//! run is reduced to ([`metrics_of`]).

use super::metrics::{metrics_of, RunMetrics};
use super::parameters::{row_system, Parameter};
use super::run::{failed_run, run_options};
use super::settings::StudySettings;

use crate::analysis::lanes::run_lanes;
use crate::error::{Error, Result};
use crate::kernel::reductions::ReduceOptions;
use crate::model::assembly::{initial_state, Assembly, SystemSpec};

/// A row's system and start, or why it has none.
type Member = std::result::Result<(Assembly, Vec<f64>), String>;

/// Why `stepping = "fixed"` cannot take the system `spec` in lockstep
/// lanes, if it cannot: one line naming `stepping` and what it takes.
pub(super) fn unfit_for_lanes(spec: &SystemSpec) -> Option<Error> {
    let why = match Assembly::new(spec) {
        Err(e) => return Some(e),
        Ok(system) => {
            if let Err(e) = crate::kernel::fixed::check_laws(&system) {
                // Friction or a rigid pair: the single fixed-step run's refusal.
                return Some(e);
            }
            if system.compact.is_none() {
                "it is not a small modal system (at most 4 modes, 2 dampers, 6 walls, one \
                 force, no base excitation)"
                    .to_string()
            } else {
                return None;
            }
        }
    };
    Some(Error::Inconsistent(format!(
        "stepping = \"fixed\" (lockstep RK4 runs) takes small modal systems with compliant \
         contact laws (at most 4 modes, 2 dampers, 6 walls, one force, gravity) or the \
         two-mass damper: {why}; or use stepping = \"events\""
    )))
}

/// The study's `rows` runs of `spec` in lockstep lanes, fixed steps of `dt`
/// to `t_end`, recorded from `record_from` (s).
#[allow(clippy::too_many_arguments)]
pub(super) fn run_compact_lanes(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    parameters: &[Parameter],
    values: &[f64],
    rows: usize,
    settings: &StudySettings,
    (dt, t_end, record_from): (f64, f64, f64),
    threads: usize,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<RunMetrics>> {
    let width = parameters.len().max(1);
    // Each row's system and start, or why it has none.
    let members: Vec<Member> = (0..rows)
        .map(|row| {
            let row_values = &values[(row * width).min(values.len())..][..parameters.len()];
            let (spec, initial) = row_system(spec, initial, parameters, row_values, settings)
                .map_err(|e| e.to_string())?;
            if let Some(unfit) = unfit_for_lanes(&spec) {
                return Err(unfit.to_string());
            }
            let system = Assembly::new(&spec).map_err(|e| e.to_string())?;
            let [x, v, y, u] = &initial;
            let y0 = initial_state(&system, x, v, y, u).map_err(|e| e.to_string())?;
            Ok((system, y0))
        })
        .collect();
    let (systems, starts): (Vec<Assembly>, Vec<Vec<f64>>) = members
        .iter()
        .filter_map(|m| m.as_ref().ok())
        .cloned()
        .unzip();
    let reduce = ReduceOptions {
        record_from,
        strobe_period: f64::INFINITY,
        mean_square: settings.mean_square,
        contacts_from: record_from,
    };
    let options = run_options(settings, Some(dt), t_end, reduce);
    let mut runs = run_lanes(&systems, &starts, &options, threads, interrupt)?.into_iter();
    Ok(members
        .iter()
        .map(|member| match member {
            Ok((system, _)) => match runs.next().expect("one run a member") {
                Ok(sol) => metrics_of(system, &sol, (record_from, f64::INFINITY), settings),
                Err(e) => failed_run(spec, e.to_string()),
            },
            // A row's values change no size: the base's NaN rows fit it.
            Err(reason) => failed_run(spec, reason.clone()),
        })
        .collect())
}
