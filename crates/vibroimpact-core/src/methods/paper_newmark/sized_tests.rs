//! The fixed-size path of the paper's Newmark against its general steps:
//! whole fixed-step runs, to the bit.

use super::*;
use crate::kernel::events::{
    integrate_system_stepped, ContactTiming, RunOptions, Stepping, SystemSolution,
};
use crate::kernel::reductions::ReduceOptions;
use crate::model::assembly::{
    initial_state, Damper, Excitation, Load, PairLaw, Side, Stop, SystemSpec,
};
use crate::model::contact::{Contact, LawKind};
use crate::model::signals::Signal;
use crate::model::structure::Structure;

/// A 3-mode cantilever with two compliant dampers (contact damping on
/// one), a compliant stop, a tip force and gravity.
fn beam() -> SystemSpec {
    let damped = Contact::new(LawKind::HertzDamped, 1e7, Some(0.6), 0.5).unwrap();
    let hyster = Contact::new(LawKind::HysterHertz, 1e7, Some(0.8), 0.0).unwrap();
    let damper = |at, clearance, contact| Damper {
        mass: 0.01,
        at,
        lower_clearance: clearance,
        upper_clearance: clearance,
        law: PairLaw::Compliant(contact),
    };
    let stop = Contact::new(LawKind::Linear, 2e5, None, 3.0).unwrap();
    SystemSpec {
        structure: Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.01).unwrap(),
        dampers: vec![damper(0.5, 2e-4, damped), damper(0.25, 1e-4, hyster)],
        collisions: vec![],
        frictions: vec![],
        stops: vec![Stop {
            at: 0.4,
            side: Side::Lower,
            gap: 3e-3,
            law: PairLaw::Compliant(stop),
            against: None,
        }],
        gravity: 9.81,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.5 },
            signal: Signal::harmonic(0.5, 8.0, 0.3).unwrap(),
        }],
        points: vec![0.1],
        moments: vec![],
    }
}

/// The fixed-step run of `spec` with and without the fixed-size path.
fn both(spec: &SystemSpec, options: &RunOptions, timing: ContactTiming) -> [String; 2] {
    let fixed = Stepping::Fixed {
        contact_timing: timing,
    };
    let system = Assembly::new(spec).unwrap();
    let y = initial_state(&system, &[], &[], &[], &[]).unwrap();
    both_from(&system, &y, options, fixed)
}

/// The run of `system` from `y` stepping as `stepping` says, with and
/// without the fixed-size path: its Debug text (every bit of every number,
/// and -0 told from 0) and the method's evaluations.
fn both_from(
    system: &Assembly,
    y: &[f64],
    options: &RunOptions,
    stepping: Stepping,
) -> [String; 2] {
    [true, false].map(|sized| {
        let mut stepper = PaperNewmark::new(system, 0.25, 0.5).unwrap();
        assert!(stepper.sized.is_some(), "the system has a fixed-size form");
        if !sized {
            stepper = stepper.general();
        }
        let run: crate::error::Result<SystemSolution> = integrate_system_stepped(
            system,
            &mut stepper,
            y,
            options,
            stepping,
            &mut || false,
            crate::MAX_RECORD_BYTES,
        );
        format!("{run:?} {}", stepper.evaluations())
    })
}

/// The beam's runs: 0.12 s of 1e-5 s steps, a history row every 7th, a
/// recorded window from 0.02 s and strobes.
fn beam_options() -> RunOptions {
    RunOptions {
        dt: Some(1e-5),
        t_end: 0.12,
        every: 7,
        keep_history: true,
        max_steps: u64::MAX,
        max_rows: u64::MAX,
        energy_tolerance: 0.05,
        reduce: ReduceOptions {
            record_from: 0.02,
            strobe_period: 0.0133,
            mean_square: false,
            ..ReduceOptions::default()
        },
    }
}

#[test]
fn fixed_runs_are_those_of_the_general_steps_to_the_bit() {
    crate::testing::timeout(120, || {
        let mut options = beam_options();
        for timing in [ContactTiming::Located, ContactTiming::StepCount] {
            let [sized, general] = both(&beam(), &options, timing);
            assert!(sized.matches("onset").count() > 10, "{sized:.3000}");
            assert!(
                sized == general,
                "sized:\n{sized:.3000}\ngeneral:\n{general:.3000}"
            );
        }
        // Unforced, no history: the free flights' stretches; a step limit
        // reached inside one.
        let mut spec = beam();
        (spec.excitations, spec.gravity) = (vec![], 0.0);
        let system = Assembly::new(&spec).unwrap();
        options.keep_history = false;
        options.max_steps = 7000;
        // (The lagged contact force creates energy at a contact.)
        options.energy_tolerance = 1.0;
        let y0 = initial_state(&system, &[0.0, 0.0, 0.0], &[1.0, 0.0, 0.0], &[], &[]).unwrap();
        let runs = [true, false].map(|sized| {
            let mut stepper = PaperNewmark::new(&system, 0.25, 0.5).unwrap();
            if !sized {
                stepper = stepper.general();
            }
            let fixed = Stepping::Fixed {
                contact_timing: ContactTiming::Located,
            };
            let run = integrate_system_stepped(
                &system,
                &mut stepper,
                &y0,
                &options,
                fixed,
                &mut || false,
                crate::MAX_RECORD_BYTES,
            );
            format!("{run:?}")
        });
        assert!(runs[0].contains("TooManySteps"), "{:.300}", runs[0]);
        assert!(
            runs[0] == runs[1],
            "sized:\n{:.3000}\ngeneral:\n{:.3000}",
            runs[0],
            runs[1]
        );
    });
}

/// Asserts the runs' texts are the same (to the bit).
fn same(sized: &str, general: &str) {
    assert!(
        sized == general,
        "sized:\n{sized:.3000}\ngeneral:\n{general:.3000}"
    );
}

#[test]
fn event_runs_are_those_of_the_general_steps_to_the_bit() {
    crate::testing::timeout(120, || {
        let mut options = beam_options();
        let system = Assembly::new(&beam()).unwrap();
        let y = initial_state(&system, &[], &[], &[], &[]).unwrap();
        let [sized, general] = both_from(&system, &y, &options, Stepping::Events);
        assert!(sized.matches("onset").count() > 10, "{sized:.3000}");
        same(&sized, &general);
        // The founding paper's two-mass damper (Table 1, Hyster-Hertz), no
        // history: contacts of many steps.
        let damper = crate::ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.01).unwrap();
        let contact = Contact::new(LawKind::HysterHertz, 3000.0, Some(0.9), 0.01).unwrap();
        let system = damper.assembly(&contact).unwrap();
        let start = crate::State::new(0.0, 0.0, 0.01, 0.1).unwrap();
        let y = start.vector(&system).unwrap();
        (options.dt, options.t_end, options.keep_history) = (Some(1e-4), 30.0, false);
        options.energy_tolerance = 1.0;
        let [sized, general] = both_from(&system, &y, &options, Stepping::Events);
        assert!(sized.matches("onset").count() > 20, "{sized:.3000}");
        same(&sized, &general);
        // A step limit reached inside a stretch, unforced and in free flight
        // (the beam from a push, no gravity).
        let mut spec = beam();
        (spec.excitations, spec.gravity) = (vec![], 0.0);
        let system = Assembly::new(&spec).unwrap();
        let y0 = initial_state(&system, &[0.0, 0.0, 0.0], &[1.0, 0.0, 0.0], &[], &[]).unwrap();
        (options.dt, options.t_end, options.max_steps) = (Some(1e-5), 0.12, 7000);
        let [sized, general] = both_from(&system, &y0, &options, Stepping::Events);
        assert!(sized.contains("TooManySteps"), "{sized:.300}");
        same(&sized, &general);
    });
}
