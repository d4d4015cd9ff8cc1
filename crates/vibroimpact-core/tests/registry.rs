//! The registry's up-front run limits, called from Rust alone: a run past
//! them is refused before any step, naming the field and what is allowed.

mod common;

use vibroimpact_core::methods::registry::{check_run, RunPlan, DEFAULT_MAX_STEPS};
use vibroimpact_core::model::assembly::{Excitation, Load, SystemSpec};
use vibroimpact_core::model::signals::Signal;
use vibroimpact_core::{Contact, ImpactDamper, LawKind, MAX_RECORD_BYTES};

/// The founding paper's two masses (M = 1 kg on K = 1 N/m: 0.159 Hz).
fn table_1() -> SystemSpec {
    let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.01).unwrap();
    ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.005)
        .unwrap()
        .spec(&contact)
        .unwrap()
}

fn plan(method: &str, dt: Option<f64>, t_end: f64) -> RunPlan<'_> {
    RunPlan {
        method,
        dt,
        t_end,
        max_steps: DEFAULT_MAX_STEPS,
        max_rows: 20_000_000,
        every: 1,
        history: true,
        strobe_period: None,
        options: Default::default(),
    }
}

fn refused(system: &SystemSpec, plan: &RunPlan, words: &[&str]) -> String {
    let text = check_run(system, plan).unwrap_err().to_string();
    for word in words {
        assert!(text.contains(word), "{word:?} not in {text}");
    }
    assert!(!text.contains('\n'), "{text}");
    text
}

#[test]
fn a_run_within_its_limits_passes() {
    common::timeout(10, || {
        let system = table_1();
        for method in [
            "rk4",
            "newmark",
            "newmark-implicit",
            "generalized-alpha",
            "exact",
        ] {
            assert_eq!(check_run(&system, &plan(method, Some(1e-3), 10.0)), Ok(()));
        }
        for method in ["dopri5", "dop853", "exact"] {
            assert_eq!(check_run(&system, &plan(method, None, 10.0)), Ok(()));
        }
    });
}

#[test]
fn too_many_fixed_steps_are_refused() {
    common::timeout(10, || {
        let system = table_1();
        let mut run = plan("rk4", Some(1e-3), 10.0);
        run.max_steps = 9_999;
        let text = refused(
            &system,
            &run,
            &["t_end / dt = 1.000e+04 steps", "max_steps (9999)"],
        );
        assert!(text.starts_with("[solver] "), "{text}");
        run.max_steps = 10_000;
        assert_eq!(check_run(&system, &run), Ok(()));
        // The exact flow steps at most dt: as many steps.
        run.method = "exact";
        run.max_steps = 9_999;
        refused(&system, &run, &["t_end / dt"]);
        // An adaptive method's dt is its first step only.
        run.method = "dop853";
        assert_eq!(check_run(&system, &run), Ok(()));
        refused(
            &system,
            &plan("rk4", None, 1.0),
            &["dt", "is required", "rk4"],
        );
    });
}

#[test]
fn an_explicit_step_over_the_fastest_period_is_refused() {
    common::timeout(10, || {
        // 1e12 N/m on 1 kg: 1.59e5 Hz, a period of 6.28e-6 s.
        let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.01).unwrap();
        let stiff = ImpactDamper::new(1.0, 1e12, 0.0, 0.25, 0.005)
            .unwrap()
            .spec(&contact)
            .unwrap();
        refused(
            &stiff,
            &plan("rk4", Some(1e-5), 1e-3),
            &["[solver] dt: the fastest mode's period, 6.28e-06 s (1.59e+05 Hz), is below 2.22 steps of dt = 1e-05 s"],
        );
        // RK4 is stable while omega dt <= 2 sqrt(2): a period of pi / sqrt(2) steps.
        let period = std::f64::consts::TAU / 1e6;
        let limit = period * std::f64::consts::SQRT_2 / std::f64::consts::PI;
        refused(
            &stiff,
            &plan("rk4", Some(1.01 * limit), 1e-3),
            &["is below 2.22 steps"],
        );
        assert_eq!(
            check_run(&stiff, &plan("rk4", Some(0.99 * limit), 1e-3)),
            Ok(())
        );
        // Implicit methods are stable on it.
        assert_eq!(
            check_run(&stiff, &plan("generalized-alpha", Some(1e-5), 1e-3)),
            Ok(())
        );
        // An adaptive method steps once in each period at least: 1.59e5 Hz
        // over 1e4 s is more than max_steps.
        let mut run = plan("dop853", None, 1e4);
        run.max_steps = 1_000_000;
        refused(
            &stiff,
            &run,
            &[
                "t_end = 10000.0 s spans 1.59e+09 periods",
                "max_steps (1000000)",
            ],
        );
    });
}

#[test]
fn a_conditionally_stable_newmark_step_over_its_limit_is_refused() {
    common::timeout(10, || {
        // Table 1's structure: w = 1 rad/s. Newmark with 2 beta < gamma is stable
        // where w dt <= 1 / sqrt(gamma / 2 - beta): 2 s for central differences
        // (beta 0, gamma 1/2; it had run to 2.7e56 m), sqrt(5) s for (0.1, 0.6).
        let system = table_1();
        for method in ["newmark", "newmark-implicit"] {
            for (beta, gamma, limit) in [(0.0, 0.5, 2.0), (0.1, 0.6, 5.0_f64.sqrt())] {
                let mut run = plan(method, Some(1.01 * limit), 1000.0);
                (run.options.beta, run.options.gamma) = (beta, gamma);
                refused(
                    &system,
                    &run,
                    &[
                        "[solver] dt: ",
                        method,
                        "beta >= gamma / 2",
                        "reduce dt below",
                    ],
                );
                run.dt = Some(0.99 * limit);
                assert_eq!(check_run(&system, &run), Ok(()), "{method} {beta}");
                // At beta >= gamma / 2 any step is stable.
                (run.options.beta, run.dt) = (0.5 * gamma, Some(100.0 * limit));
                assert_eq!(check_run(&system, &run), Ok(()), "{method} {beta}");
            }
        }
        // generalized-alpha's beta is its own (stable): the option is not read.
        let mut run = plan("generalized-alpha", Some(100.0), 1000.0);
        run.options.beta = 0.0;
        assert_eq!(check_run(&system, &run), Ok(()));
    });
}

#[test]
fn a_forcing_the_steps_cannot_follow_is_refused() {
    common::timeout(10, || {
        let mut system = table_1();
        system.excitations.push(Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(1.0, 1e9, 0.0).unwrap(),
        });
        refused(
            &system,
            &plan("rk4", Some(1e-3), 1.0),
            &["[[excitation]] 0: frequency 1000000000.0 Hz is sampled below two steps"],
        );
        refused(
            &system,
            &plan("exact", None, 2.0),
            &["[[excitation]] 0: frequency 1000000000.0 Hz: t_end = 2.0 s spans 2e+09"],
        );
    });
}

#[test]
fn a_history_beyond_the_rows_or_the_memory_is_refused() {
    common::timeout(10, || {
        let system = table_1();
        let mut run = plan("rk4", Some(1e-6), 100.0);
        run.max_rows = 1_000;
        run.max_steps = u64::MAX;
        refused(
            &system,
            &run,
            &["max_rows = 1000", "raise every", "history = false"],
        );
        // 1e8 rows of 5 values: 3815 MiB, beyond the records' memory.
        run.max_rows = u64::MAX;
        let text = refused(
            &system,
            &run,
            &["[output] history", "of 5 values", "3815 MiB"],
        );
        assert!(
            text.contains(&format!("{} MiB", MAX_RECORD_BYTES >> 20)),
            "{text}"
        );
        run.history = false;
        assert_eq!(check_run(&system, &run), Ok(()));
        run.strobe_period = Some(1e-7);
        refused(&system, &run, &["[output] strobe_period", "1.000e+09 rows"]);
    });
}
