//! The 0.2 kernel alone (no Python): steps per second of a 3-mode cantilever
//! with two dampers (RK4 with events: both hertz-damped, or the mid-span one
//! rigid as in `examples/beam_two_dampers.toml`; and of its peer without
//! contact, the clearances 1 m, every event test still made), the time per run of a ball dropped 1 m
//! (e = 0.8, to 6 s), and of a harmonically forced damper with rigid impacts
//! over 1000 forcing periods. Medians of repeated runs. First issue 24's
//! acceptance case: both hertz-damped dampers rattling over 50 s against the
//! peer without contact, timed alternately, and the ratio of their rates.
//! `system_throughput contacts` (or `peer`) runs that case once (for perf).
//!
//!     cargo run --release -p vibroimpact-core --example system_throughput

use std::time::Instant;
use vibroimpact_core::kernel::events::{integrate_system, RunOptions, SystemSolution};
use vibroimpact_core::methods::steppers::ExplicitRk;
use vibroimpact_core::model::assembly::{
    initial_state, Assembly, Damper, Excitation, Load, PairLaw, Side, Stop, SystemSpec,
};
use vibroimpact_core::model::contact::{Contact, LawKind};
use vibroimpact_core::model::signals::Signal;
use vibroimpact_core::model::structure::Structure;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn options(dt: Option<f64>, t_end: f64) -> RunOptions {
    RunOptions {
        dt,
        t_end,
        every: 1,
        keep_history: false,
        max_steps: u64::MAX,
        max_rows: u64::MAX,
        energy_tolerance: 1e-2,
        reduce: Default::default(),
    }
}

fn time_runs(
    repeats: usize,
    spec: &SystemSpec,
    make: &dyn Fn(usize) -> ExplicitRk,
    run: &RunOptions,
) -> (f64, SystemSolution) {
    let system = Assembly::new(spec).unwrap();
    let y = initial_state(&system, &[], &[], &[], &[]).unwrap();
    let mut last = None;
    let times = (0..repeats)
        .map(|_| {
            let mut stepper = make(system.state_len());
            let start = Instant::now();
            let sol = integrate_system(&system, &mut stepper, &y, run, &mut || false).unwrap();
            let elapsed = start.elapsed().as_secs_f64();
            last = Some(sol);
            elapsed
        })
        .collect();
    (median(times), last.unwrap())
}

/// The 3-mode aluminium cantilever with dampers at the tip and mid-span and a
/// tip force at 8 Hz: both dampers hertz-damped, the peer with clearances no
/// motion closes, and the example file's laws (the mid-span damper rigid).
fn cantilevers() -> (SystemSpec, SystemSpec, SystemSpec) {
    let mut beam = SystemSpec {
        structure: Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.01).unwrap(),
        dampers: vec![],
        collisions: vec![],
        frictions: vec![],
        stops: vec![],
        gravity: 0.0,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.5 },
            signal: Signal::harmonic(0.5, 8.0, 0.0).unwrap(),
        }],
        points: vec![],
        moments: vec![],
    };
    let contact = Contact::new(LawKind::HertzDamped, 1e7, Some(0.6), 0.0).unwrap();
    for at in [0.5, 0.25] {
        beam.dampers.push(Damper {
            mass: 0.01,
            at,
            lower_clearance: 2e-4,
            upper_clearance: 2e-4,
            law: PairLaw::Compliant(contact),
        });
    }
    let mut peer = beam.clone();
    for damper in &mut peer.dampers {
        (damper.lower_clearance, damper.upper_clearance) = (1.0, 1.0);
    }
    // The example file's laws: the mid-span damper rigid, chattering and
    // sticking at times.
    let mut file = beam.clone();
    file.dampers[1] = Damper {
        lower_clearance: 1e-4,
        upper_clearance: 3e-4,
        law: PairLaw::rigid(0.5).unwrap(),
        ..file.dampers[1].clone()
    };
    (beam, peer, file)
}

fn main() {
    let (beam, peer, file) = cantilevers();
    // One run of a case, for perf: "contacts" (both hertz-damped) or "peer",
    // over the acceptance case's 50 s.
    if let Some(case) = std::env::args().nth(1) {
        let spec = if case == "peer" { &peer } else { &beam };
        let (t, sol) = time_runs(1, spec, &ExplicitRk::rk4, &options(Some(1e-5), 50.0));
        println!(
            "{case}: {} steps, {} contacts, {t:.3} s",
            sol.steps,
            sol.contacts.len()
        );
        return;
    }
    // Issue 24's acceptance case: steady rattling of both hertz-damped
    // dampers over 50 s (thousands of contacts) at least 0.8x the steps per
    // second of the peer without contact; the two timed alternately, the
    // ratio of their medians.
    let (mut rattling, mut free) = (Vec::new(), Vec::new());
    let (mut with, mut without) = (None, None);
    for _ in 0..5 {
        let (t, sol) = time_runs(1, &beam, &ExplicitRk::rk4, &options(Some(1e-5), 50.0));
        rattling.push(sol.steps as f64 / t);
        with = Some(sol);
        let (t, sol) = time_runs(1, &peer, &ExplicitRk::rk4, &options(Some(1e-5), 50.0));
        free.push(sol.steps as f64 / t);
        without = Some(sol);
    }
    let (with, without) = (with.unwrap(), without.unwrap());
    let (rattling, free) = (median(rattling), median(free));
    println!(
        "acceptance: cantilever, 3 modes, 2 hertz-damped dampers rattling, rk4 with events, 50 s: {rattling:.3e} steps/s ({} steps, {} contacts); peer without contact {free:.3e} steps/s ({} steps): {:.3}x the peer (goal 0.8x)",
        with.steps,
        with.contacts.len(),
        without.steps,
        rattling / free
    );
    for (name, spec) in [
        ("", &beam),
        (", the example file's laws (one damper rigid)", &file),
        (", peer without contact", &peer),
    ] {
        let (t, sol) = time_runs(5, spec, &ExplicitRk::rk4, &options(Some(1e-5), 10.0));
        println!(
            "cantilever, 3 modes, 2 dampers, rk4 with events{name}: {:.3e} steps/s ({} steps, {} contacts, median {:.3} s)",
            sol.steps as f64 / t,
            sol.steps,
            sol.contacts.len(),
            t
        );
    }
    ball();
    forced_damper();
}

/// A ball dropped 1 m on a rigid floor (e = 0.8), by RK4 and by DOP853.
fn ball() {
    let ball = SystemSpec {
        structure: Structure::oscillator(0.2, 0.0, 0.0).unwrap(),
        dampers: vec![],
        collisions: vec![],
        frictions: vec![],
        stops: vec![Stop {
            at: 0.0,
            side: Side::Lower,
            gap: 1.0,
            law: PairLaw::rigid(0.8).unwrap(),
            against: None,
        }],
        gravity: 9.81,
        excitations: vec![],
        points: vec![],
        moments: vec![],
    };
    for (name, dt) in [("rk4 dt 1e-2", Some(1e-2)), ("dop853", None)] {
        let make: &dyn Fn(usize) -> ExplicitRk = match dt {
            Some(_) => &ExplicitRk::rk4,
            None => &|len| ExplicitRk::dop853(len, 1e-10, 1e-12),
        };
        let (t, sol) = time_runs(51, &ball, make, &options(dt, 6.0));
        println!(
            "ball dropped 1 m, e = 0.8, to 6 s, {name}: {:.1} us per run ({} impacts)",
            t * 1e6,
            sol.contacts.len()
        );
    }
}

/// The forced damper with rigid impacts, by RK4 and by DOP853.
fn forced_damper() {
    // Masri-Caughey-like: primary 1 kg on 1000 N/m (5.03 Hz) forced at 5 Hz,
    // a 0.05 kg loose mass with 10 mm total clearance, e = 0.6.
    let forced = SystemSpec {
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
    for (name, dt) in [("rk4 dt 1e-3", Some(1e-3)), ("dop853 rtol 1e-8", None)] {
        let make: &dyn Fn(usize) -> ExplicitRk = match dt {
            Some(_) => &ExplicitRk::rk4,
            None => &|len| ExplicitRk::dop853(len, 1e-8, 1e-12),
        };
        let (t, sol) = time_runs(11, &forced, make, &options(dt, 200.0));
        println!(
            "forced damper with rigid impacts, 1000 periods, {name}: {:.2} ms per run ({} impacts, {} steps, {} evaluations)",
            t * 1e3,
            sol.contacts.len(),
            sol.steps,
            sol.rhs_evaluations
        );
    }
}
