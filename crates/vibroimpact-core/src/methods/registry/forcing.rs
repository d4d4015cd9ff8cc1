//! The forcing periods an analysis can run (SI units), checked when the
//! analysis is set up. An adaptive or exact run steps at least once in each
//! period of the structure's fastest mode, so a forcing period of more than
//! `max_steps` of those is beyond it (a sweep from 1e-300 Hz had failed each
//! point as a numerical blow-up advising a smaller dt); a fixed-step run
//! takes `period / dt` steps whatever the modes (an implicit method is stable
//! on a mode far faster than its step; its two steps a period are checked
//! with the run's own settings, by [`super::check_run`]). An adaptive or
//! exact run judges positions to `atol`: a forcing that moves the structure
//! by less than `atol` a period is not resolved (a 5 Hz oscillator forced at
//! 1e9 Hz had failed its energy balance), and a body on no spring is
//! resolved only while the round-off of the run's times stays below the time
//! its largest acceleration takes to move it by `atol` (a ball on a table at
//! 1e-20 Hz had failed as "step size too small", at 1e-300 Hz as a blow-up).
//! Each refusal names the frequency and the range a run can take.

use super::limits::{highest_frequency, python_g, python_repr};
use super::table::{method, ATOL, DT};
use crate::error::{positive, Error, Result};
use crate::model::assembly::{Assembly, SystemSpec};
use crate::numerics::linalg;

/// What the check reads of an analysis's runs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ForcingPlan<'a> {
    pub method: &'a str,
    /// Step, s (required by the fixed-step methods).
    pub dt: Option<f64>,
    /// The absolute tolerance (m) an adaptive or exact run resolves.
    pub atol: f64,
    pub max_steps: u64,
}

/// Refuse a forcing `period` (s) of `system` no run of `plan` can step
/// through: for a fixed-step method, more than `max_steps` steps of `dt`;
/// for an adaptive or exact one, more than `max_steps` periods of the
/// system's fastest mode, a forcing moving the structure less than `atol` a
/// period, or (a body on no spring) a period whose times' round-off exceeds
/// the time its largest acceleration takes to move it by `atol`.
pub fn check_forcing_period(system: &SystemSpec, plan: &ForcingPlan, period: f64) -> Result<()> {
    positive("forcing_period", period)?;
    let spec = method(plan.method)?;
    if let Some(dt) = plan.dt {
        DT.check(dt)?;
    }
    ATOL.check(plan.atol)?;
    let max_steps = plan.max_steps as f64;
    if let Some(dt) = plan.dt.filter(|_| spec.kind.is_fixed_step()) {
        if period / dt > max_steps {
            return Err(refuse(
                period,
                &format!(
                    "its period, {} s, takes {} steps of dt = {} s, more than a run's max_steps \
                     ({})",
                    python_g(period, 6),
                    python_g(period / dt, 3),
                    python_repr(dt),
                    plan.max_steps
                ),
                &format!(
                    "set the [[excitation]] frequency to at least {} Hz",
                    python_g(1.0 / (max_steps * dt), 3)
                ),
            ));
        }
        return Ok(());
    }
    let highest = highest_frequency(&system.structure);
    let (forcing, weight) = accelerations(&Assembly::new(system)?)?;
    let (atol, largest) = (plan.atol, forcing.max(weight));
    // The relative round-off of a run's times (f64).
    let round_off = f64::EPSILON;
    // A free body: no mode sets its time scale, so the one the run must
    // resolve is the time its largest acceleration takes to move it by atol.
    let resolved = if highest == 0.0 && largest > 0.0 {
        (2.0 * atol / largest).sqrt()
    } else {
        f64::INFINITY
    };
    let lowest = (highest / max_steps).max(round_off / resolved);
    let mut works = format!(
        "set the [[excitation]] frequency to at least {} Hz",
        python_g(lowest, 3)
    );
    // Only a method that takes atol resolves the motion to it: the exact flow's
    // response of a structure on springs to a fast forcing is its closed form however
    // small (a MEMS sweep was refused for an atol it does not use). A free body's
    // scale is atol for every method (its events are found to it).
    let resolves_to_atol =
        highest == 0.0 || spec.options.iter().any(|option| option.name == ATOL.name);
    if forcing > 0.0 && resolves_to_atol {
        let top = (forcing / atol).sqrt() / std::f64::consts::TAU;
        works += &format!(" and at most {} Hz", python_g(top, 3));
    }
    if highest > 0.0 && period * highest > max_steps {
        return Err(refuse(
            period,
            &format!(
                "its period, {} s, spans {} periods of the system's fastest mode ({} Hz), more \
                 than a run's max_steps ({}) steps through",
                python_g(period, 6),
                python_g(period * highest, 3),
                python_g(highest, 6),
                plan.max_steps
            ),
            &works,
        ));
    }
    if round_off * period > resolved {
        return Err(refuse(
            period,
            &format!(
                "a body on no spring: the round-off of the run's times, {} of the period {} s, \
                 exceeds the {} s its largest acceleration ({} m/s^2) takes to move it by atol \
                 ({} m)",
                python_g(round_off, 3),
                python_g(period, 3),
                python_g(resolved, 3),
                python_g(largest, 3),
                python_repr(atol)
            ),
            &works,
        ));
    }
    let omega = std::f64::consts::TAU / period;
    // Divided twice: omega^2 overflows beyond 1e154 Hz.
    let moved = forcing / omega / omega;
    if forcing > 0.0 && resolves_to_atol && moved < atol {
        return Err(refuse(
            period,
            &format!(
                "the forcing ({} m/s^2) moves the structure by {} m a period, below the atol \
                 ({} m) a run resolves",
                python_g(forcing, 3),
                python_g(moved, 3),
                python_repr(atol)
            ),
            &works,
        ));
    }
    Ok(())
}

fn refuse(period: f64, reason: &str, advice: &str) -> Error {
    Error::Inconsistent(format!(
        "forcing frequency {} Hz: {reason}; {advice}",
        python_repr(1.0 / period)
    ))
}

/// The largest acceleration amplitude (m/s^2) the harmonic loads give a
/// coordinate (`M^-1` times the load) and the largest the constant load
/// (gravity) gives.
fn accelerations(system: &Assembly) -> Result<(f64, f64)> {
    let parts = system.linear_parts("linear_parts")?;
    let d = system.dim;
    // M is positive definite (the assembly checked it).
    let Some(lower) = linalg::cholesky(&parts.mass, d) else {
        return Ok((0.0, 0.0));
    };
    let inverse = linalg::inverse_from_cholesky(&lower, d);
    let largest = |load: &[f64]| -> f64 {
        let mut out = vec![0.0; d];
        linalg::multiply(&inverse, load, &mut out);
        out.iter().fold(0.0f64, |m, v| m.max(v.abs()))
    };
    let forcing = parts
        .harmonics
        .iter()
        .filter(|h| h.omega > 0.0)
        .map(|h| h.amplitude.abs() * largest(&h.shape))
        .fold(0.0f64, f64::max);
    let weight = if parts.constant.is_empty() {
        0.0
    } else {
        largest(&parts.constant)
    };
    Ok((forcing, weight))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::assembly::{Excitation, Load};
    use crate::model::signals::Signal;
    use crate::model::structure::Structure;

    /// A mass of 1 kg on a spring of (2 pi f)^2 N/m (0: none), forced by
    /// `amplitude` N at 1 Hz, under `gravity`.
    fn oscillator(frequency: f64, amplitude: f64, gravity: f64) -> SystemSpec {
        let stiffness = (std::f64::consts::TAU * frequency).powi(2);
        SystemSpec {
            structure: Structure::oscillator(1.0, stiffness, 0.0).unwrap(),
            dampers: vec![],
            collisions: vec![],
            frictions: vec![],
            stops: vec![],
            gravity,
            excitations: vec![Excitation {
                load: Load::Force { at: 0.0 },
                signal: Signal::harmonic(amplitude, 1.0, 0.0).unwrap(),
            }],
            points: vec![],
            moments: vec![],
        }
    }

    fn plan(method: &str, dt: Option<f64>) -> ForcingPlan<'_> {
        ForcingPlan {
            method,
            dt,
            atol: 1e-12,
            max_steps: 1000,
        }
    }

    fn message(system: &SystemSpec, plan: &ForcingPlan, period: f64) -> String {
        check_forcing_period(system, plan, period)
            .unwrap_err()
            .to_string()
    }

    #[test]
    fn a_fixed_step_takes_at_most_max_steps_a_forcing_period() {
        crate::testing::timeout(10, || {
            let system = oscillator(5.0, 1.0, 0.0);
            // 1000 steps of 1e-3 s: a period up to 1 s (1 Hz).
            let rk4 = plan("rk4", Some(1e-3));
            assert!(check_forcing_period(&system, &rk4, 0.999).is_ok());
            assert_eq!(
                message(&system, &rk4, 2.0),
                "forcing frequency 0.5 Hz: its period, 2 s, takes 2e+03 steps of dt = 0.001 s, \
                 more than a run's max_steps (1000); set the [[excitation]] frequency to at \
                 least 1 Hz"
            );
        });
    }

    #[test]
    fn an_adaptive_run_steps_through_at_most_max_steps_periods_of_the_fastest_mode() {
        crate::testing::timeout(10, || {
            // A 5 Hz mode: 1000 of its periods last 200 s.
            let system = oscillator(5.0, 1.0, 0.0);
            let dop853 = plan("dop853", None);
            assert!(check_forcing_period(&system, &dop853, 199.0).is_ok());
            let text = message(&system, &dop853, 400.0);
            assert!(
                text.starts_with(
                    "forcing frequency 0.0025 Hz: its period, 400 s, spans 2e+03 periods of the \
                     system's fastest mode (5 Hz)"
                ),
                "{text}"
            );
            // At most sqrt(a / atol) / 2 pi Hz: a 1 m/s^2 forcing moves the mass by
            // a / omega^2 a period, below atol = 1e-12 m beyond 1.59e5 Hz.
            assert!(
                text.ends_with("at least 0.005 Hz and at most 1.59e+05 Hz"),
                "{text}"
            );
            assert!(check_forcing_period(&system, &dop853, 1.0 / 1.5e5).is_ok());
            let text = message(&system, &dop853, 1.0 / 1.7e5);
            assert!(
                text.contains("moves the structure by 8.76e-13 m a period"),
                "{text}"
            );
            // The exact flow takes no atol: its response to that forcing is its closed
            // form, however small (a MEMS sweep was refused for it).
            let exact = plan("exact", None);
            assert!(check_forcing_period(&system, &exact, 1.0 / 1.7e5).is_ok());
            assert!(message(&system, &exact, 400.0).ends_with("at least 0.005 Hz"));
        });
    }

    #[test]
    fn a_free_body_is_forced_within_what_its_times_round_off_resolves() {
        crate::testing::timeout(10, || {
            // No spring, gravity 2 m/s^2 (above the forcing's 1): 2 atol / 2 = 1e-12 s^2,
            // resolved = 1e-6 s; the times' round-off 2.22e-16 of the period reaches it
            // at 4.5e9 s (2.22e-10 Hz).
            let system = oscillator(0.0, 1.0, 2.0);
            let exact = plan("exact", None);
            assert!(check_forcing_period(&system, &exact, 4.4e9).is_ok());
            let text = message(&system, &exact, 4.6e9);
            assert!(text.contains("a body on no spring"), "{text}");
            assert!(text.contains("at least 2.22e-10 Hz"), "{text}");
            // A period that is not finite and > 0 is named.
            assert!(message(&system, &exact, f64::NAN).starts_with("forcing_period must be"));
        });
    }
}
