//! Lockstep lanes of compact systems against the same runs one by one (fixed
//! steps, and stepping by events), on one thread: the issue-24 acceptance
//! system (a 2-mode cantilever, two hertz-damped dampers, a harmonic force).
//!
//!     cargo run --release --example lanes_throughput [runs] [t_end] [lanes|fixed|events]
//!
//! With `two-mass` as the fourth argument, the lanes run the two-mass impact
//! damper instead (the ensemble's system of bench_study: an oscillator with
//! one damper of equal clearances, Hertz contact, dt = 1e-4 s, peaks only,
//! the damper's initial velocity varied), for the ensemble's bar.

use std::time::Instant;

use vibroimpact_core::analysis::lanes::run_lanes;
use vibroimpact_core::kernel::events::{
    integrate_system, integrate_system_stepped, ContactTiming, RunOptions, Stepping,
};
use vibroimpact_core::kernel::memory::MAX_RECORD_BYTES;
use vibroimpact_core::kernel::reductions::ReduceOptions;
use vibroimpact_core::methods::steppers::ExplicitRk;
use vibroimpact_core::model::assembly::{
    initial_state, Assembly, Damper, Excitation, Load, PairLaw, SystemSpec,
};
use vibroimpact_core::model::contact::{Contact, LawKind};
use vibroimpact_core::model::impact_damper::ImpactDamper;
use vibroimpact_core::model::signals::Signal;
use vibroimpact_core::model::structure::Structure;

fn spec(m: usize) -> SystemSpec {
    let contact = Contact::new(LawKind::HertzDamped, 1e7, Some(0.6), 0.0).unwrap();
    let damper = |at, clearance| Damper {
        mass: 0.01,
        at,
        lower_clearance: clearance,
        upper_clearance: clearance,
        law: PairLaw::Compliant(contact),
    };
    let (i, j) = ((m / 25) as f64, (m % 25) as f64);
    SystemSpec {
        structure: Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 2, 0.01).unwrap(),
        dampers: vec![damper(0.5, 1e-4 + 1.6e-5 * j), damper(0.25, 1e-4)],
        collisions: vec![],
        frictions: vec![],
        stops: vec![],
        gravity: 0.0,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.5 },
            signal: Signal::harmonic(0.5, 4.0 + 0.9 * i, 0.0).unwrap(),
        }],
        points: vec![],
        moments: vec![],
    }
}

/// The lanes' throughput on the two-mass impact damper (see the module's doc).
fn two_mass(runs: usize, t_end: f64) {
    let damper = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.01).unwrap();
    let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.0).unwrap();
    let system = damper.assembly(&contact).unwrap();
    let systems: Vec<Assembly> = (0..runs).map(|_| system.clone()).collect();
    let starts: Vec<Vec<f64>> = (0..runs)
        .map(|m| {
            let v = 0.05 + 0.1 * m as f64 / runs.max(2) as f64;
            initial_state(&system, &[], &[], &[0.0], &[v]).unwrap()
        })
        .collect();
    let dt = 1e-4;
    let options = RunOptions {
        dt: Some(dt),
        t_end,
        every: 1,
        keep_history: false,
        max_steps: u64::MAX,
        max_rows: u64::MAX,
        energy_tolerance: 1e-2,
        reduce: ReduceOptions {
            record_from: 0.0,
            strobe_period: f64::INFINITY,
            mean_square: false,
            contacts_from: 0.0,
        },
    };
    let steps = runs as f64 * (t_end / dt).round();
    let start = Instant::now();
    let lanes = run_lanes(&systems, &starts, &options, 1, &|| false).unwrap();
    let s = start.elapsed().as_secs_f64();
    let failed = lanes.iter().filter(|r| r.is_err()).count();
    println!(
        "two-mass lanes: {s:.3} s, {:.3e} trajectory-steps/s ({failed} failed; the ensemble's bar 1.2e8)",
        steps / s
    );
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if args.get(4).is_some_and(|a| a == "two-mass") {
        let runs: usize = args.get(1).map_or(160, |a| a.parse().unwrap());
        let t_end: f64 = args.get(2).map_or(2.0, |a| a.parse().unwrap());
        return two_mass(runs, t_end);
    }
    let runs: usize = args.get(1).map_or(160, |a| a.parse().unwrap());
    let t_end: f64 = args.get(2).map_or(0.05, |a| a.parse().unwrap());
    let dt = 1e-5;
    let systems: Vec<Assembly> = (0..runs)
        .map(|m| Assembly::new(&spec(m)).unwrap())
        .collect();
    let starts: Vec<Vec<f64>> = systems
        .iter()
        .map(|s| initial_state(s, &[], &[], &[], &[]).unwrap())
        .collect();
    let options = RunOptions {
        dt: Some(dt),
        t_end,
        every: 1,
        keep_history: false,
        max_steps: u64::MAX,
        max_rows: u64::MAX,
        energy_tolerance: 1e-2,
        reduce: ReduceOptions {
            record_from: 0.0,
            strobe_period: f64::INFINITY,
            mean_square: true,
            contacts_from: 0.0,
        },
    };
    let steps = runs as f64 * (t_end / dt).round();
    let only = args.get(3).cloned().unwrap_or_default();
    if only.is_empty() || only == "lanes" {
        let start = Instant::now();
        let lanes = run_lanes(&systems, &starts, &options, 1, &|| false).unwrap();
        let s = start.elapsed().as_secs_f64();
        let failed = lanes.iter().filter(|r| r.is_err()).count();
        println!(
            "lanes:  {s:.3} s, {:.3e} trajectory-steps/s ({failed} failed)",
            steps / s
        );
    }
    if only.is_empty() || only == "fixed" {
        let start = Instant::now();
        for (system, y0) in systems.iter().zip(&starts) {
            let mut rk4 = ExplicitRk::rk4(system.state_len());
            let stepping = Stepping::Fixed {
                contact_timing: ContactTiming::Located,
            };
            let _ = integrate_system_stepped(
                system,
                &mut rk4,
                y0,
                &options,
                stepping,
                &mut || false,
                MAX_RECORD_BYTES,
            );
        }
        let s = start.elapsed().as_secs_f64();
        println!("fixed one by one: {s:.3} s, {:.3e} steps/s", steps / s);
    }
    if only.is_empty() || only == "events" {
        let start = Instant::now();
        for (system, y0) in systems.iter().zip(&starts) {
            let mut rk4 = ExplicitRk::rk4(system.state_len());
            let _ = integrate_system(system, &mut rk4, y0, &options, &mut || false);
        }
        let s = start.elapsed().as_secs_f64();
        println!(
            "events one by one: {s:.3} s, {:.3e} grid steps/s",
            steps / s
        );
    }
}
