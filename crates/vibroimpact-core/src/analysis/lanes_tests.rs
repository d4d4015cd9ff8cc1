//! Each lane is the single fixed-step run of its system, bit for bit.

use super::*;
use crate::kernel::events::{integrate_system_stepped, ContactTiming, Stepping};
use crate::kernel::memory::MAX_RECORD_BYTES;
use crate::kernel::reductions::ReduceOptions;
use crate::methods::steppers::ExplicitRk;
use crate::model::assembly::{
    initial_state, Damper, Excitation, Load, PairLaw, Side, Stop, SystemSpec,
};
use crate::model::contact::{Contact, LawKind};
use crate::model::signals::Signal;
use crate::model::structure::Structure;

/// The acceptance system: a 2-mode cantilever, two hertz-damped dampers, a
/// harmonic tip force; member `m` varies the force and the clearances.
fn cantilever(m: usize, stiffness: f64) -> SystemSpec {
    let contact = Contact::new(LawKind::HertzDamped, stiffness, Some(0.6), 0.0).unwrap();
    let f = m as f64;
    let damper = |at, clearance| Damper {
        mass: 0.01,
        at,
        lower_clearance: clearance,
        upper_clearance: clearance,
        law: PairLaw::Compliant(contact),
    };
    SystemSpec {
        structure: Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 2, 0.01).unwrap(),
        dampers: vec![damper(0.5, 2e-4 + 1e-5 * f), damper(0.25, 1e-4)],
        collisions: vec![],
        frictions: vec![],
        stops: vec![],
        gravity: 0.0,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.5 },
            signal: Signal::harmonic(0.5 + 0.05 * f, 8.0 + 0.3 * f, 0.3).unwrap(),
        }],
        points: vec![0.3],
        moments: vec![],
    }
}

fn options(record_from: f64) -> RunOptions {
    RunOptions {
        dt: Some(1e-5),
        t_end: 0.08,
        every: 1,
        keep_history: false,
        max_steps: u64::MAX,
        max_rows: u64::MAX,
        energy_tolerance: 1e-2,
        reduce: ReduceOptions {
            record_from,
            strobe_period: f64::INFINITY,
            mean_square: true,
            contacts_from: record_from,
        },
    }
}

/// The single fixed-step RK4 run of `system` by the general kernel (not
/// its compact fast path, which is held to it elsewhere).
fn single(system: &Assembly, y0: &[f64], options: &RunOptions) -> Result<SystemSolution> {
    let mut stepper = ExplicitRk::rk4(system.state_len());
    stepper.compact = false;
    let stepping = Stepping::Fixed {
        contact_timing: ContactTiming::Located,
    };
    integrate_system_stepped(
        system,
        &mut stepper,
        y0,
        options,
        stepping,
        &mut || false,
        MAX_RECORD_BYTES,
    )
}

fn check(specs: &[SystemSpec], options: &RunOptions) -> Vec<Result<SystemSolution>> {
    let systems: Vec<Assembly> = specs.iter().map(|s| Assembly::new(s).unwrap()).collect();
    let starts: Vec<Vec<f64>> = systems
        .iter()
        .map(|s| initial_state(s, &[], &[], &[], &[]).unwrap())
        .collect();
    let lanes = run_lanes(&systems, &starts, options, 1, &|| false).unwrap();
    for (m, lane) in lanes.iter().enumerate() {
        // Debug text tells every bit of every number apart (and -0 from 0).
        let alone = format!("{:?}", single(&systems[m], &starts[m], options));
        assert!(
            format!("{lane:?}") == alone,
            "member {m}:\n{lane:?}\n{alone}"
        );
    }
    // Another grouping (from the third member on) on two threads.
    let again = run_lanes(&systems[2..], &starts[2..], options, 2, &|| false).unwrap();
    assert_eq!(format!("{:?}", &lanes[2..]), format!("{again:?}"));
    lanes
}

#[test]
fn lanes_are_single_fixed_runs_to_the_bit() {
    crate::testing::timeout(120, || {
        let specs: Vec<_> = (0..19).map(|m| cantilever(m, 1e7)).collect();
        let lanes = check(&specs, &options(0.02));
        let contacts: usize = lanes
            .iter()
            .map(|r| r.as_ref().unwrap().contacts.len())
            .sum();
        assert!(contacts > 100, "{contacts} contacts");
        // Without the mean squares (the lanes' steps sum none).
        let mut o = options(0.02);
        o.reduce.mean_square = false;
        check(&specs[..5], &o);
        // History rows every 37 steps and strobes every 12.3 ms: the runs'
        // rows of plain steps end where the schedule's rule says, found once
        // a row and counted down (the lockstep's `plain_window`).
        let mut o = options(0.02);
        (o.keep_history, o.every) = (true, 37);
        o.reduce.strobe_period = 0.0123;
        let lanes = check(&specs[..5], &o);
        let first = lanes[0].as_ref().unwrap();
        let (rows, strobes) = (first.time.len(), first.reductions.strobe_time.len());
        assert!(rows > 100 && strobes >= 4, "{rows} rows, {strobes} strobes");
        // A stop under the tip (the dampers' law) and gravity: the beam
        // rests on it in every lane (the lanes' contact force in vector
        // form) while the dampers rattle in a few (lane by lane).
        let stop = Contact::new(LawKind::HertzDamped, 1e7, Some(0.6), 0.0).unwrap();
        let specs: Vec<_> = (0..18)
            .map(|m| {
                let mut spec = cantilever(m, 1e7);
                spec.gravity = 9.81;
                spec.stops = vec![Stop {
                    at: 0.5,
                    side: Side::Lower,
                    gap: 2e-4,
                    law: PairLaw::Compliant(stop),
                    against: None,
                }];
                spec
            })
            .collect();
        let lanes = check(&specs, &options(0.0));
        assert!(lanes
            .iter()
            .all(|r| r.as_ref().unwrap().contacts.iter().any(|c| c.pair == 2)));
    });
}

#[test]
fn a_lane_that_blows_up_fails_alone() {
    crate::testing::timeout(60, || {
        // A contact of 1e16 N/m^1.5 on a 10 g damper at dt = 1e-5 s: RK4 is
        // unstable across it.
        let specs: Vec<_> = (0..6)
            .map(|m| cantilever(m, if m == 3 { 1e16 } else { 1e7 }))
            .collect();
        let lanes = check(&specs, &options(0.0));
        let failed: Vec<usize> = (0..6).filter(|&m| lanes[m].is_err()).collect();
        assert_eq!(failed, [3], "{:?}", lanes[3]);
    });
}
