//! The exact flow alone (no Python): the forced damper of
//! benchmarks/bench_analyses.py part 1 over 1000 forcing periods and the ball
//! dropped 1 m (part 4); medians of repeated runs, with the flow evaluations
//! per impact, and the column of ten rigid particles of
//! benchmarks/bench_collisions.py (events per second). `exact_damper once`
//! runs the damper once (for callgrind), `exact_damper balls` the ball 300
//! times (callgrind of a run's set-up and a few events), `exact_damper
//! column` the column 50 times (for perf; `column-0.6` at restitution 0.6).
//!
//!     cargo run --release -p vibroimpact-core --example exact_damper

use std::time::Instant;
use vibroimpact_core::kernel::events::{RunOptions, SystemSolution};
use vibroimpact_core::kernel::reductions::ReduceOptions;
use vibroimpact_core::methods::registry::{AnyStepper, Options};
use vibroimpact_core::model::assembly::{
    initial_state, Assembly, Damper, Excitation, Load, PairLaw, Side, Stop, SystemSpec,
};
use vibroimpact_core::model::signals::Signal;
use vibroimpact_core::model::structure::Structure;

fn run(spec: &SystemSpec, t_end: f64) -> SystemSolution {
    let system = Assembly::new(spec).unwrap();
    let y = initial_state(&system, &[], &[], &[], &[]).unwrap();
    let mut stepper = AnyStepper::new(&system, "exact", &Options::default()).unwrap();
    let options = RunOptions {
        dt: stepper.step(None, t_end, f64::INFINITY),
        t_end,
        every: 1,
        keep_history: false,
        max_steps: 1_000_000_000,
        max_rows: u64::MAX,
        energy_tolerance: 1e-6,
        reduce: ReduceOptions::default(),
    };
    stepper
        .integrate(&system, &y, &options, &mut || false)
        .unwrap()
}

/// Ten 10 g particles stacked 2 mm apart in a 1 kg, 15 Hz, 5 % damped
/// cavity forced with 30 N at 10 Hz under gravity, every pair rigid at
/// `restitution` (tests/test_collisions.py's `forced_column`).
fn column(restitution: f64) -> SystemSpec {
    let structure = Structure::oscillator(1.0, 8883.0, 9.42).unwrap();
    let law = PairLaw::rigid(restitution).unwrap();
    SystemSpec {
        excitations: vec![Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(30.0, 10.0, 0.0).unwrap(),
        }],
        ..SystemSpec::column(structure, 0.0, &[0.01; 10], [0.002, 0.002, 0.03], law)
    }
}

/// `run` made `times` times (every one: a profile's runs), the last kept.
fn repeated(times: usize, run: impl Fn() -> SystemSolution) -> Option<SystemSolution> {
    let mut last = None;
    for _ in 0..times {
        last = Some(run());
    }
    last
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn main() {
    let wn = 2.0 * std::f64::consts::PI * 10.0;
    let k = wn * wn;
    let damper = SystemSpec {
        structure: Structure::oscillator(1.0, k, 2.0 * 0.01 * wn).unwrap(),
        dampers: vec![Damper {
            mass: 0.05,
            at: 0.0,
            lower_clearance: 0.01,
            upper_clearance: 0.01,
            law: PairLaw::rigid(0.6).unwrap(),
        }],
        collisions: vec![],
        frictions: vec![],
        stops: vec![],
        gravity: 0.0,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(0.3 * k * 0.01 * 3.0, 8.0, 0.0).unwrap(),
        }],
        points: vec![],
        moments: vec![],
    };
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
    // One run, for callgrind: the damper ("once") or the ball ("ball").
    let one = match std::env::args().nth(1).as_deref() {
        Some("once") => Some(run(&damper, 125.0)),
        Some("ball") => Some(run(&ball, 6.0)),
        Some("balls") => repeated(300, || run(&ball, 6.0)),
        Some("column") => repeated(50, || run(&column(0.9), 20.0)),
        Some("column-0.6") => repeated(50, || run(&column(0.6), 20.0)),
        _ => None,
    };
    if let Some(sol) = one {
        println!(
            "{} steps, {} evaluations, {} contacts; energy {:?}",
            sol.steps,
            sol.rhs_evaluations,
            sol.contacts.len(),
            sol.energy
        );
        return;
    }
    // Each system made just before its runs (the heap the runs meet is then
    // the same whatever follows: the ball's short runs are sensitive to it).
    type Make<'a> = Box<dyn Fn() -> SystemSpec + 'a>;
    let runs: [(&str, Make, f64, usize); 4] = [
        (
            "damper, 1000 periods",
            Box::new(|| damper.clone()),
            125.0,
            41,
        ),
        ("ball", Box::new(|| ball.clone()), 6.0, 2001),
        ("column, e 0.9", Box::new(|| column(0.9)), 20.0, 21),
        ("column, e 0.6", Box::new(|| column(0.6)), 20.0, 21),
    ];
    for (name, make, t_end, repeats) in runs {
        let spec = &make();
        let mut last = None;
        let times = (0..repeats)
            .map(|_| {
                let start = Instant::now();
                let sol = run(spec, t_end);
                let elapsed = start.elapsed().as_secs_f64();
                last = Some(sol);
                elapsed
            })
            .collect();
        let sol = last.unwrap();
        let t = median(times);
        println!(
            "{name}: {:.1} us per run ({:.3e} contacts/s); {} steps, {} evaluations, {} \
             contacts, final {:?}",
            t * 1e6,
            sol.contacts.len() as f64 / t,
            sol.steps,
            sol.rhs_evaluations,
            sol.contacts.len(),
            &sol.final_state
        );
    }
}
