//! The implicit Newmark family's fixed-size step against its general
//! attempts: whole event-stepped runs, to the bit.

use super::*;
use crate::kernel::events::{integrate_system_stepped, RunOptions, Stepping};
use crate::kernel::reductions::ReduceOptions;
use crate::model::assembly::{initial_state, Damper, Excitation, Load, PairLaw, SystemSpec};
use crate::model::contact::{Contact, LawKind};
use crate::model::impact_damper::{ImpactDamper, State};
use crate::model::signals::Signal;
use crate::model::structure::Structure;

/// A 3-mode cantilever with a compliant damper (hysteretic Hertz), a rigid
/// one, a tip force and gravity.
fn beam() -> Assembly {
    let hyster = Contact::new(LawKind::HysterHertz, 1e7, Some(0.8), 0.0).unwrap();
    let damper = |at, clearance, law| Damper {
        mass: 0.01,
        at,
        lower_clearance: clearance,
        upper_clearance: clearance,
        law,
    };
    let spec = SystemSpec {
        structure: Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.01).unwrap(),
        dampers: vec![
            damper(0.5, 2e-4, PairLaw::Compliant(hyster)),
            damper(0.25, 1e-4, PairLaw::rigid(0.5).unwrap()),
        ],
        collisions: vec![],
        frictions: vec![],
        stops: vec![],
        gravity: 9.81,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.5 },
            signal: Signal::harmonic(0.5, 8.0, 0.3).unwrap(),
        }],
        points: vec![0.1],
        moments: vec![],
    };
    Assembly::new(&spec).unwrap()
}

/// The event-stepped runs of `system` from `y` by both methods of the
/// family, through the fixed-size path and through the general attempts:
/// each run's text (every bit of every number) and evaluations, the steps
/// the fixed-size path took and those of the run.
fn runs(system: &Assembly, y: &[f64], options: &RunOptions) -> Vec<([String; 2], u64, u64)> {
    let methods = [
        NewmarkFamily::newmark(system, 0.25, 0.5),
        NewmarkFamily::generalized_alpha(system, 0.9),
    ];
    methods
        .into_iter()
        .map(|method| {
            let (mut stretched, mut steps) = (0, 0);
            let texts = [true, false].map(|sized| {
                let mut stepper = method.clone();
                if !sized {
                    stepper = stepper.general();
                }
                let run = integrate_system_stepped(
                    system,
                    &mut stepper,
                    y,
                    options,
                    Stepping::Events,
                    &mut || false,
                    crate::MAX_RECORD_BYTES,
                );
                stretched += stepper.stretched;
                steps = run.as_ref().map_or(0, |solution| solution.steps);
                format!("{run:?} {}", stepper.evaluations())
            });
            (texts, stretched, steps)
        })
        .collect()
}

fn options(dt: f64, t_end: f64) -> RunOptions {
    RunOptions {
        dt: Some(dt),
        t_end,
        every: 7,
        keep_history: true,
        max_steps: u64::MAX,
        max_rows: u64::MAX,
        energy_tolerance: 0.05,
        reduce: ReduceOptions {
            record_from: 0.3 * t_end,
            strobe_period: 0.0133,
            mean_square: false,
            ..ReduceOptions::default()
        },
    }
}

/// Both runs of each method the same to the bit, with at least `contacts`
/// contacts, the fixed-size path having taken a good share of the steps
/// (the damper's free flights: 85 %; the beam's, between a rigid pair's
/// many impacts and its sticking, which the path leaves to the kernel:
/// 23 %).
fn same(runs: &[([String; 2], u64, u64)], contacts: usize) {
    for ([sized, general], stretched, steps) in runs {
        let onsets = sized.matches("onset").count();
        assert!(onsets >= contacts, "{onsets} contacts");
        assert!(*stretched > steps / 10, "{stretched} of {steps} steps");
        assert!(
            sized == general,
            "sized:\n{sized:.3000}\ngeneral:\n{general:.3000}"
        );
    }
}

#[test]
fn event_runs_are_those_of_the_general_attempts_to_the_bit() {
    crate::testing::timeout(120, || {
        // The two-mass impact damper of the founding paper (Table 1), with
        // hysteretic Hertz contact: free flights and contacts.
        let damper = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.01).unwrap();
        let contact = Contact::new(LawKind::HysterHertz, 3000.0, Some(0.9), 0.01).unwrap();
        let system = damper.assembly(&contact).unwrap();
        let y = State::new(0.0, 0.0, 0.01, 0.1)
            .unwrap()
            .vector(&system)
            .unwrap();
        same(&runs(&system, &y, &options(1e-4, 8.0)), 15);
        // A cantilever with gravity, a force, a compliant and a rigid damper.
        let system = beam();
        let y = initial_state(&system, &[], &[], &[], &[]).unwrap();
        same(&runs(&system, &y, &options(1e-5, 0.1)), 1);
    });
}
