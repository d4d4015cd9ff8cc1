//! What a 0.2 run keeps stays within its memory: rows of a wide system
//! count by their bytes, not only their number, and a run whose records
//! would pass the limit stops with a clear error, having never held more.

mod common;

use vibroimpact_core::error::Error;
use vibroimpact_core::kernel::events::{integrate_system_within, RunOptions, SystemSolution};
use vibroimpact_core::kernel::reductions::ReduceOptions;
use vibroimpact_core::methods::steppers::ExplicitRk;
use vibroimpact_core::model::assembly::{
    initial_state, Assembly, Damper, Excitation, Load, PairLaw, SystemSpec,
};
use vibroimpact_core::model::contact::{Contact, LawKind};
use vibroimpact_core::model::signals::Signal;
use vibroimpact_core::model::structure::Structure;
use vibroimpact_core::MAX_RECORD_BYTES;

/// A 40-mode cantilever with a damper at its tip, struck: rows of
/// 1 + 2 (40 + 1) = 83 values.
fn beam() -> (Assembly, Vec<f64>) {
    let spec = SystemSpec {
        dampers: vec![Damper {
            mass: 0.01,
            at: 1.0,
            lower_clearance: 1e-3,
            upper_clearance: 1e-3,
            law: PairLaw::Compliant(Contact::new(LawKind::Hertz, 1e5, None, 0.0).unwrap()),
        }],
        ..SystemSpec::of(
            Structure::cantilever(1.0, 2.0e5, 1e-8, 1.0, 40, 0.01).unwrap(),
            vec![],
        )
    };
    let system = Assembly::new(&spec).unwrap();
    let mut v = vec![0.0; 40];
    v[0] = 0.1;
    let y = initial_state(&system, &[], &v, &[], &[]).unwrap();
    (system, y)
}

fn options(keep_history: bool, strobe_period: f64) -> RunOptions {
    RunOptions {
        dt: None,
        t_end: 2.0,
        every: 1,
        keep_history,
        max_steps: 100_000_000,
        max_rows: 100_000_000,
        energy_tolerance: 1e-3,
        reduce: ReduceOptions {
            strobe_period,
            ..Default::default()
        },
    }
}

fn run(o: &RunOptions, limit: u64) -> vibroimpact_core::Result<SystemSolution> {
    let (system, y) = beam();
    let mut stepper = ExplicitRk::dopri5(system.state_len(), 1e-8, 1e-12);
    integrate_system_within(&system, &mut stepper, &y, o, &mut || false, limit)
}

#[test]
fn an_adaptive_history_stops_at_the_memory_limit_not_past_it() {
    common::timeout(60, || {
        // The whole run keeps thousands of rows of 83 values (> 1 MiB)...
        let whole = run(&options(true, f64::INFINITY), MAX_RECORD_BYTES).unwrap();
        let bytes = 8 * (whole.time.len() + whole.states.len());
        assert!(bytes > 1 << 20, "{bytes}");
        assert_eq!(whole.states.len(), 82 * whole.time.len());
        // ...so under a 1 MiB limit it stops, with what it kept under it.
        match run(&options(true, f64::INFINITY), 1 << 20) {
            Err(Error::MemoryLimit {
                rows,
                columns,
                held_mib,
                time,
                ref cause,
                ..
            }) => {
                assert_eq!(columns, 83);
                assert!(rows * columns * 8 <= 1 << 20, "{rows} rows");
                // At least half the limit was used before stopping.
                assert!(rows * columns * 8 >= 1 << 19, "{rows} rows");
                assert!(held_mib <= 1.0);
                assert!(time > 0.0 && time < 2.0);
                assert_eq!(cause, "would pass the limit of 1 MiB");
            }
            other => panic!("expected MemoryLimit, got {other:?}"),
        }
        // Without a history it runs to the end under the same limit.
        let bare = run(&options(false, f64::INFINITY), 1 << 20).unwrap();
        assert_eq!(bare.final_time, 2.0);
        assert_eq!(bare.final_state, whole.final_state);
    });
}

#[test]
fn stroboscopic_rows_count_against_the_memory_limit() {
    common::timeout(60, || {
        // 2 s / 1e-4 s = 20000 rows of 83 values: 13 MiB, past a 1 MiB limit.
        let message = match run(&options(false, 1e-4), 1 << 20) {
            Err(e @ Error::MemoryLimit { .. }) => e.to_string(),
            other => panic!("expected MemoryLimit, got {other:?}"),
        };
        for words in ["stroboscopic rows of 83 values", "strobe_period", "t_end"] {
            assert!(message.contains(words), "{message}");
        }
        // No history was kept: the advice is about what filled the memory.
        assert!(!message.contains("history = false"), "{message}");
        // Under the real limit the same run keeps them all.
        let kept = run(&options(false, 1e-4), MAX_RECORD_BYTES).unwrap();
        assert_eq!(kept.reductions.strobe_time.len(), 20_000);
    });
}

#[test]
fn a_limit_the_records_fit_within_changes_nothing() {
    common::timeout(60, || {
        // History and contacts grow in turn under a limit 25 % above what
        // they need: the run completes with the same result as without one
        // (the sharing of the room itself is memory.rs's unit test).
        let o = RunOptions {
            dt: Some(1e-4),
            ..options(true, f64::INFINITY)
        };
        let (system, y) = beam();
        let rk4 = || ExplicitRk::rk4(system.state_len());
        let whole =
            integrate_system_within(&system, &mut rk4(), &y, &o, &mut || false, u64::MAX).unwrap();
        assert!(whole.contacts.len() > 10, "{}", whole.contacts.len());
        let needed = 8 * (whole.time.len() + whole.states.len())
            + whole.contacts.len() * std::mem::size_of_val(&whole.contacts[0]);
        let limit = needed as u64 * 5 / 4;
        let fitted =
            integrate_system_within(&system, &mut rk4(), &y, &o, &mut || false, limit).unwrap();
        assert_eq!(fitted.final_state, whole.final_state);
    });
}

/// A harmonically forced oscillator with a rigid loose mass: 5,700 impacts
/// in 200 s (1000 forcing periods).
fn forced_damper() -> (Assembly, Vec<f64>) {
    let spec = SystemSpec {
        structure: Structure::oscillator(1.0, 1000.0, 0.0).unwrap(),
        dampers: vec![Damper {
            mass: 0.05,
            at: 0.0,
            lower_clearance: 0.005,
            upper_clearance: 0.005,
            law: PairLaw::rigid(0.6).unwrap(),
        }],
        collisions: vec![],
        frictions: vec![],
        stops: vec![],
        gravity: 0.0,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(1.0, 5.0, 0.0).unwrap(),
        }],
        points: vec![],
        moments: vec![],
    };
    let system = Assembly::new(&spec).unwrap();
    let y = initial_state(&system, &[], &[], &[], &[]).unwrap();
    (system, y)
}

#[test]
fn a_run_that_keeps_only_its_window_s_contacts_holds_no_others() {
    common::timeout(60, || {
        let (system, y) = forced_damper();
        let run = |contacts_from: f64, limit: u64| {
            let options = RunOptions {
                dt: Some(1e-3),
                t_end: 200.0,
                every: 1,
                keep_history: false,
                max_steps: 100_000_000,
                max_rows: 100_000_000,
                energy_tolerance: 1e-2,
                reduce: ReduceOptions {
                    contacts_from,
                    ..Default::default()
                },
            };
            let mut stepper = ExplicitRk::rk4(system.state_len());
            integrate_system_within(&system, &mut stepper, &y, &options, &mut || false, limit)
        };
        let all = run(f64::NEG_INFINITY, MAX_RECORD_BYTES).unwrap();
        assert!(all.contacts.len() > 5000, "{}", all.contacts.len());
        let from = 190.0;
        let window: Vec<_> = all.contacts.iter().filter(|c| c.onset >= from).collect();
        assert!(!window.is_empty() && window.len() < all.contacts.len() / 10);
        // 100 kB: the window's contacts fit, the run's do not.
        let limit = 100_000;
        let size = std::mem::size_of_val(&all.contacts[0]) as u64;
        assert!(
            window.len() as u64 * size * 2 < limit && all.contacts.len() as u64 * size > limit,
            "{} of {} contacts, {size} bytes each",
            window.len(),
            all.contacts.len()
        );
        assert!(matches!(
            run(f64::NEG_INFINITY, limit),
            Err(Error::MemoryLimit { .. })
        ));
        let kept = run(from, limit).unwrap();
        // The same run (dropping records changes no step), the same window.
        assert_eq!(kept.final_state, all.final_state);
        assert_eq!(kept.contacts.len(), window.len());
        for (a, b) in kept.contacts.iter().zip(&window) {
            assert_eq!(a, *b);
        }
        let none = run(f64::INFINITY, limit).unwrap();
        assert!(none.contacts.is_empty());
        assert_eq!(none.final_state, all.final_state);
    });
}
