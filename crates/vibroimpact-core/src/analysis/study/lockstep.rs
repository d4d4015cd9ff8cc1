//! Fixed-step studies: the runs as a lockstep ensemble of RK4 steps.

use super::metrics::RunMetrics;
use super::parameters::{row_system, Parameter};
use super::settings::{Analysis, StudySettings};

use crate::analysis::ensemble::{run_ensemble, EnsembleOptions, Member};
use crate::error::{Error, Result};
use crate::methods::registry::two_mass::{ContactTiming, Method, Settings, Stepping};
use crate::model::assembly::{PairLaw, SystemSpec};
use crate::model::impact_damper::{ImpactDamper, State};

use super::compact_lanes::{run_compact_lanes, unfit_for_lanes};

/// The study's `rows` runs as a lockstep ensemble of fixed RK4 steps.
#[allow(clippy::too_many_arguments)]
pub(super) fn run_lockstep(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    parameters: &[Parameter],
    values: &[f64],
    rows: usize,
    settings: &StudySettings,
    threads: usize,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<RunMetrics>> {
    let Analysis::Run { t_end, record_from } = settings.analysis else {
        return Err(Error::Inconsistent(
            "stepping = \"fixed\" runs each member to t_end: use analysis = \"run\"".into(),
        ));
    };
    if settings.method != "rk4" {
        return Err(Error::Inconsistent(format!(
            "stepping = \"fixed\" advances RK4 runs in lockstep: use method = \"rk4\" (got {:?})",
            settings.method
        )));
    }
    let run = Settings::new(
        Method::Rk4,
        settings.dt,
        t_end,
        1,
        ContactTiming::Located,
        Some(Stepping::Fixed),
        settings.max_steps,
    )?;
    run.check_steps()?;
    let dt = run.dt.expect("a fixed step was required");
    // The two-mass damper runs in its own lanes (the compact fixed RK4
    // specialised to the preset, the same bits as its single run, ten times
    // the compact lanes' speed on it); any other small modal system runs in
    // compact lanes, or is refused as its single fixed-step run is (a damper
    // with friction is no two-mass member: its lanes had run it without it).
    if member_of(spec, initial).is_err() {
        if let Some(unfit) = unfit_for_lanes(spec) {
            return Err(unfit);
        }
        return run_compact_lanes(
            spec,
            initial,
            parameters,
            values,
            rows,
            settings,
            (dt, t_end, record_from),
            threads,
            interrupt,
        );
    }
    let width = parameters.len().max(1);
    let members: Vec<std::result::Result<Member, String>> = (0..rows)
        .map(|row| {
            let row_values = &values[(row * width).min(values.len())..][..parameters.len()];
            let (spec, initial) = row_system(spec, initial, parameters, row_values, settings)
                .map_err(|e| e.to_string())?;
            member_of(&spec, &initial).map_err(|e| e.to_string())
        })
        .collect();
    let runnable: Vec<Member> = members.iter().filter_map(|m| m.clone().ok()).collect();
    let options = EnsembleOptions {
        dt,
        steps: run.steps(),
        record_from,
        energy_tolerance: settings.energy_tolerance,
    };
    let mut results = run_ensemble(&runnable, &options, threads, interrupt)?.into_iter();
    let nan = f64::NAN;
    Ok(members
        .into_iter()
        .map(|member| {
            let (status, reason, result) = match member {
                Ok(_) => {
                    let r = results.next().expect("one result a member");
                    (
                        u8::from(r.reason.is_some()),
                        r.reason.clone().unwrap_or_default(),
                        Some(r),
                    )
                }
                Err(reason) => (1, reason, None),
            };
            let ok = result.filter(|r| r.reason.is_none());
            RunMetrics {
                status,
                reason,
                peak: vec![ok.as_ref().map_or(nan, |r| r.peak)],
                rms: vec![ok.as_ref().map_or(nan, |r| r.rms)],
                impacts: ok.as_ref().map_or(nan, |r| r.contacts as f64),
                energy_dissipated: vec![nan],
                impacts_per_period: nan,
                settled: nan,
                stable: nan,
                largest_multiplier: nan,
                largest_lyapunov: nan,
            }
        })
        .collect())
}

/// The two-mass impact damper a 0.2 system is, if it is one: one mass on a
/// spring and damper (its point the coordinate itself), one damper with equal
/// clearances and a compliant law, no stops, gravity or excitation.
pub(super) fn member_of(spec: &SystemSpec, initial: &[Vec<f64>; 4]) -> Result<Member> {
    let unfit = |what: &str| {
        Error::Inconsistent(format!(
            "stepping = \"fixed\" (lockstep RK4 runs) takes one mass on a spring with one \
             [[damper]] of equal clearances and a compliant law, unforced, without stops or \
             gravity: {what}"
        ))
    };
    let structure = &spec.structure;
    if structure.dofs() != 1 {
        return Err(unfit("the structure has more than one coordinate"));
    }
    let [damper] = spec.dampers.as_slice() else {
        return Err(unfit("it needs exactly one [[damper]]"));
    };
    if !spec.stops.is_empty() || spec.gravity != 0.0 || !spec.excitations.is_empty() {
        return Err(unfit("the scenario has stops, gravity or an excitation"));
    }
    if !spec.frictions.is_empty() {
        // (A row's own: an axis may give a damper friction.)
        return Err(unfit(
            "stick-slip is located by event-driven runs only (friction)",
        ));
    }
    if !spec.points.is_empty() || !spec.moments.is_empty() {
        // Its one coordinate is its one point: its peak and rms are already kept.
        return Err(unfit(
            "[output] points and moments are followed by event-driven runs only",
        ));
    }
    if structure.point("damper.0.at", damper.at)? != [1.0] {
        return Err(unfit("the damper's point is not the coordinate itself"));
    }
    if damper.lower_clearance != damper.upper_clearance {
        return Err(unfit("the damper's lower and upper clearances differ"));
    }
    let PairLaw::Compliant(contact) = damper.law else {
        return Err(unfit("the damper's law is rigid"));
    };
    let first = |k: usize| initial[k].first().copied().unwrap_or(0.0);
    Ok(Member {
        system: ImpactDamper::new(
            structure.mass()[0],
            structure.stiffness()[0],
            structure.damping()[0],
            damper.mass,
            damper.lower_clearance,
        )?,
        contact,
        initial: State::new(first(0), first(1), first(2), first(3))?,
    })
}
