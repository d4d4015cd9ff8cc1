//! What each run of a study is reduced to: peaks, RMS, impacts, energy
//! dissipated, settling and (orbit studies) the Floquet multipliers.

use super::run::{run_options, stepper_of};
use super::section::{clear_section, full_state};
use super::settings::{Analysis, StudySettings};

use crate::analysis::settling::{self, MAX_PERIOD};
use crate::analysis::tangent::Tangent;
use crate::error::{Error, Result};
use crate::kernel::events::{ContactKind, RunOptions, SystemSolution};
use crate::kernel::reductions::ReduceOptions;
use crate::methods::registry::AnyStepper;
use crate::model::assembly::{Assembly, SystemSpec};
use crate::{analysis::shooting, numerics::linalg};

/// Newton's tolerance and iterations for an orbit study's shooting (as
/// `vibroimpact.analysis.orbit`'s defaults).
pub(super) const ORBIT_TOLERANCE: f64 = 1e-10;
pub(super) const ORBIT_ITERATIONS: usize = 40;

/// The metrics of one run. NaN where a run failed (see `status`).
#[derive(Debug, Clone, PartialEq)]
pub struct RunMetrics {
    /// 0 when the run completed, else 1 (the reason in `reason`).
    pub status: u8,
    pub reason: String,
    /// Per observed quantity (each structure coordinate, then each of the
    /// spec's points), m.
    pub peak: Vec<f64>,
    pub rms: Vec<f64>,
    /// Impacts and compliant contacts recorded (a sticking period is not
    /// an impact: it is left out).
    pub impacts: f64,
    /// Per pair, J, over the recorded time.
    pub energy_dissipated: Vec<f64>,
    /// Steady state only: impacts per forcing period, and 1 / 0 for settled.
    pub impacts_per_period: f64,
    pub settled: f64,
    /// Orbit only: 1 when Newton converged and every Floquet multiplier is
    /// inside the unit circle, else 0; the largest multiplier's modulus.
    pub stable: f64,
    pub largest_multiplier: f64,
    /// The largest Lyapunov exponent, 1/s: over the recorded time (runs and
    /// steady states, where asked), or `ln |largest multiplier| / T` of an
    /// orbit of `T` s.
    pub largest_lyapunov: f64,
}

/// An orbit study's run of `system` (made of `spec`): settle, shoot, then
/// one more orbit recorded. A settled state inside a contact whose law
/// latches is shot from on a section clear of it ([`clear_section`]).
pub(super) fn orbit_metrics(
    (spec, system): (&SystemSpec, &Assembly),
    stepper: &mut AnyStepper,
    y0: &[f64],
    settings: &StudySettings,
    (period, settle, periods): (f64, u64, u64),
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<RunMetrics> {
    let span = periods as f64 * period;
    let options = |t_end: f64, record: bool| {
        let from = if record { 0.0 } else { f64::INFINITY };
        let reduce = ReduceOptions {
            record_from: from,
            strobe_period: f64::INFINITY,
            mean_square: false,
            // Settling and shooting count no contact.
            contacts_from: from,
        };
        run_options(
            settings,
            stepper.step(settings.dt, t_end, period),
            t_end,
            reduce,
        )
    };
    let d = system.dim;
    let settle_options = options(settle.max(1) as f64 * period, false);
    let span_options = options(span, false);
    let record_options = options(span, true);
    let mut z = if settle > 0 {
        let settled = stepper.integrate(system, y0, &settle_options, &mut || interrupt())?;
        let cleared = clear_section(
            (spec, system),
            stepper,
            &settled,
            (settings, period),
            interrupt,
        )?;
        if let Some((spec, system, state)) = cleared {
            let mut stepper = stepper_of(&system, settings)?;
            let sizes = (period, 0, periods);
            let metrics = (&spec, &system);
            return orbit_metrics(metrics, &mut stepper, &state, settings, sizes, interrupt);
        }
        settled.final_state
    } else {
        y0[..2 * d].to_vec()
    };
    // A run from the flat state `z`, the tangent flow told of its events
    // where one is given.
    let mut run_from = |z: &[f64],
                        options: &RunOptions,
                        flow: Option<&mut Tangent<'_>>|
     -> Result<SystemSolution> {
        let y = full_state(system, z)?;
        let run = match flow {
            Some(flow) => {
                stepper.integrate_observed(system, &y, options, &mut || interrupt(), flow)
            }
            None => stepper.integrate(system, &y, options, &mut || interrupt()),
        };
        if run.is_err() {
            // A run stopped part way may leave work in the method (the exact
            // flow's pending energies): the next starts with a fresh one.
            *stepper = stepper_of(system, settings)?;
        }
        run
    };
    // The monodromy from the tangent flow through the impacts and contacts.
    let shot = shooting::shoot_by_tangent(
        &mut |z| {
            let mut flow = Tangent::product(system)?;
            let end = run_from(z, &span_options, Some(&mut flow))?.final_state;
            Ok((end, flow.matrix().to_vec()))
        },
        &z,
        period,
        ORBIT_TOLERANCE,
        ORBIT_ITERATIONS,
    )?;
    if !shot.converged {
        let refused = shot
            .refusal
            .map(|r| format!("; its last step was refused: {r}"))
            .unwrap_or_default();
        return Err(Error::Inconsistent(format!(
            "no orbit of {periods} forcing period(s) found near the settled state: Newton's \
             method stopped after {} iterations at residual {:.1e}{refused} (settle longer, or \
             look for an orbit of more periods)",
            shot.iterations, shot.residual
        )));
    }
    z.clone_from(&shot.state);
    let multipliers = linalg::eigenvalues(&shot.monodromy, 2 * d).ok_or_else(|| {
        Error::Inconsistent("the orbit's Floquet multipliers did not converge".into())
    })?;
    let largest = multipliers
        .iter()
        .map(|(re, im)| re.hypot(*im))
        .fold(0.0f64, f64::max);
    let orbit = run_from(&z, &record_options, None)?;
    let impacts = orbit
        .contacts
        .iter()
        .filter(|c| c.kind != ContactKind::Sticking && c.begun_from(0.0))
        .count() as f64;
    let nan = f64::NAN;
    Ok(RunMetrics {
        status: 0,
        reason: String::new(),
        peak: orbit.reductions.peaks.clone(),
        rms: vec![nan; system.observed()],
        impacts,
        energy_dissipated: vec![nan; system.pairs.len()],
        impacts_per_period: impacts / periods as f64,
        settled: nan,
        stable: f64::from(u8::from(shot.converged && largest < 1.0)),
        largest_multiplier: largest,
        largest_lyapunov: largest.ln() / span,
    })
}

/// The forcing periods a steady-state run records for `record` asked: at
/// least MAX_PERIOD, so that one whole orbit of any period it may find fits
/// (impacts per period counted over part of an orbit depend on where the
/// window ends: a period-8 orbit had given 1, 2, 3 or 14 over one period).
pub(super) fn recorded_periods(record: u64) -> u64 {
    record.max(MAX_PERIOD as u64)
}

/// The metrics of `sol`, recorded from `record_from` (s); `period` is the
/// forcing period (s) of a steady-state study.
pub(super) fn metrics_of(
    system: &Assembly,
    sol: &SystemSolution,
    (record_from, period): (f64, f64),
    settings: &StudySettings,
) -> RunMetrics {
    let r = &sol.reductions;
    let rms = r
        .square_integrals
        .iter()
        .map(|s| {
            if r.recorded_time > 0.0 {
                (s / r.recorded_time).sqrt()
            } else {
                f64::NAN
            }
        })
        .collect();
    let recorded: Vec<_> = sol
        .contacts
        .iter()
        .filter(|c| c.begun_from(record_from))
        .collect();
    let impacts = recorded
        .iter()
        .filter(|c| c.kind != ContactKind::Sticking)
        .count() as f64;
    let mut energy = vec![0.0; system.pairs.len()];
    for c in &recorded {
        if c.energy_dissipated.is_finite() {
            energy[c.pair] += c.energy_dissipated;
        }
    }
    add_friction_losses(system, sol, &mut energy);
    let (impacts_per_period, settled) = match settings.analysis {
        Analysis::SteadyState {
            settle,
            record,
            tolerance,
        } => {
            // Judged at the end of settling, as the analysis does.
            let width = 2 * system.dim;
            let rows = (settle as usize).min(r.strobe.len() / width);
            let strobe = &r.strobe[..rows * width];
            let repeats = settling::strobe_period(strobe, width, period, tolerance, MAX_PERIOD);
            // Impacts counted over whole periods of the orbit (a window of
            // 20 periods of a period-8 orbit counts part of one).
            let orbit = repeats.map_or(1, |p| p as u64);
            let whole = recorded_periods(record) / orbit * orbit;
            let end = record_from + whole as f64 * period;
            let counted = recorded
                .iter()
                .filter(|c| c.kind != ContactKind::Sticking && c.onset < end)
                .count() as f64;
            (
                counted / whole as f64,
                f64::from(u8::from(repeats.is_some())),
            )
        }
        Analysis::Run { .. } | Analysis::Orbit { .. } => (f64::NAN, f64::NAN),
    };
    RunMetrics {
        status: 0,
        reason: String::new(),
        peak: r.peaks.clone(),
        rms,
        impacts,
        energy_dissipated: energy,
        impacts_per_period,
        settled,
        stable: f64::NAN,
        largest_multiplier: f64::NAN,
        largest_lyapunov: f64::NAN,
    }
}

/// Each friction element's sliding loss over the recorded window (J) added to
/// its pair's (a stuck interval, its contact record, loses nothing; the
/// slides between are in no record). NaN where the window's start was not
/// seen.
fn add_friction_losses(system: &Assembly, sol: &SystemSolution, energy: &mut [f64]) {
    let losses = &sol.reductions.window_losses;
    for (i, it) in system.interactions.iter().enumerate() {
        if it.law.is_friction() {
            energy[it.pair] += losses.get(i).copied().unwrap_or(f64::NAN);
        }
    }
}
