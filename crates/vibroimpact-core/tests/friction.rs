//! Dry friction's stick-slip against closed forms: the free decay of an
//! oscillator with Coulomb friction to the ground (each half cycle loses
//! `2 F / k` of amplitude, the motion stops within `|x| <= F_s / k`), on the
//! exact flow and dop853, and a loose mass sliding to rest on its carrier.

mod common;

use std::f64::consts::PI;
use vibroimpact_core::kernel::events::{integrate_system, RunOptions, SystemSolution};
use vibroimpact_core::kernel::reductions::ReduceOptions;
use vibroimpact_core::methods::exact::ExactFlow;
use vibroimpact_core::methods::steppers::{ExplicitRk, SystemStepper};
use vibroimpact_core::model::assembly::{
    initial_state, Assembly, Damper, Friction, FrictionSite, PairLaw, SystemSpec,
};
use vibroimpact_core::model::structure::Structure;

const MASS: f64 = 2.0;
const STIFFNESS: f64 = 800.0;
const NORMAL: f64 = 10.0;
const KINETIC: f64 = 0.3;
const STATIC: f64 = 0.4;

fn oscillator_with_friction() -> SystemSpec {
    SystemSpec {
        structure: Structure::oscillator(MASS, STIFFNESS, 0.0).unwrap(),
        dampers: vec![],
        collisions: vec![],
        frictions: vec![Friction {
            site: FrictionSite::Points {
                at: 0.0,
                against: None,
            },
            coefficient: KINETIC,
            static_coefficient: STATIC,
            normal_force: NORMAL,
        }],
        stops: vec![],
        gravity: 0.0,
        excitations: vec![],
        points: vec![],
        moments: vec![],
    }
}

fn run<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    y: &[f64],
    dt: Option<f64>,
    t_end: f64,
) -> SystemSolution {
    let options = RunOptions {
        dt,
        t_end,
        every: 1,
        keep_history: true,
        max_steps: 10_000_000,
        max_rows: 10_000_000,
        energy_tolerance: 1e-9,
        reduce: ReduceOptions::default(),
    };
    integrate_system(system, stepper, y, &options, &mut || false).unwrap()
}

/// The free decay's turning points from `x0` at rest: each half cycle
/// about the kinetic force's offset `a = F / k` ends at `-(x - 2a)` (with
/// the sign), until the spring no longer passes the static force.
fn turning_points(x0: f64) -> Vec<f64> {
    let (a, held) = (KINETIC * NORMAL / STIFFNESS, STATIC * NORMAL / STIFFNESS);
    let mut points = vec![x0];
    let mut x = x0;
    while x.abs() > held {
        let next = -(x - 2.0 * a * x.signum());
        points.push(next);
        x = next;
    }
    points
}

fn check_decay(solution: &SystemSolution, x0: f64, tolerance: f64) {
    let expected = turning_points(x0);
    // Turning points: where the velocity changes sign or the motion stops.
    let d = 1;
    let (x, v): (Vec<f64>, Vec<f64>) = solution
        .states
        .chunks(2 * d)
        .map(|row| (row[0], row[1]))
        .unzip();
    let mut found = vec![x[0]];
    for i in 1..v.len() {
        if v[i] == 0.0 || v[i] * v[i - 1] < 0.0 {
            let last = *found.last().unwrap();
            if (x[i] - last).abs() > 1e-9 {
                found.push(x[i]);
            }
        }
    }
    assert!(
        found.len() >= expected.len(),
        "turning points {found:?}, expected {expected:?}"
    );
    for (f, e) in found.iter().zip(&expected) {
        assert!((f - e).abs() <= tolerance, "turning point {f} against {e}");
    }
    // At rest at the last one, within the static band.
    let last = *expected.last().unwrap();
    let end = &solution.final_state;
    assert!(
        (end[0] - last).abs() <= tolerance,
        "{} against {last}",
        end[0]
    );
    assert!(end[1].abs() <= 1e-9, "still moving: {}", end[1]);
    // The ledger: the friction loss is the energy that left the spring.
    let e = &solution.energy;
    let lost = 0.5 * STIFFNESS * (x0 * x0 - last * last);
    assert!(
        (e.friction - lost).abs() <= 1e-6 * lost,
        "friction loss {} against {lost}",
        e.friction
    );
    assert_eq!(e.contact, 0.0);
}

#[test]
fn free_decay_with_coulomb_friction_matches_the_closed_form_exact() {
    common::timeout(30, || {
        let system = Assembly::new(&oscillator_with_friction()).unwrap();
        let x0 = 0.0513;
        let y = initial_state(&system, &[x0], &[0.0], &[], &[]).unwrap();
        let period = 2.0 * PI * (MASS / STIFFNESS).sqrt();
        let mut flow = ExactFlow::new(&system).unwrap();
        let dt = flow.step();
        let solution = run(&system, &mut flow, &y, Some(dt), 12.0 * period);
        check_decay(&solution, x0, 1e-12);
    });
}

#[test]
fn free_decay_with_coulomb_friction_matches_the_closed_form_dop853() {
    common::timeout(30, || {
        let system = Assembly::new(&oscillator_with_friction()).unwrap();
        let x0 = 0.0513;
        let y = initial_state(&system, &[x0], &[0.0], &[], &[]).unwrap();
        let period = 2.0 * PI * (MASS / STIFFNESS).sqrt();
        let mut dop853 = ExplicitRk::dop853(system.state_len(), 1e-12, 1e-15);
        let solution = run(&system, &mut dop853, &y, None, 12.0 * period);
        check_decay(&solution, x0, 1e-9);
    });
}

/// A loose mass launched at `v0` on a carrier held by a stiff heavy
/// structure slides `v0^2 / (2 mu g)` (the carrier's own motion is of
/// order `m / M` smaller) and stays there.
#[test]
fn a_block_slides_to_rest_in_the_closed_form_distance() {
    common::timeout(30, || {
        let (m, mu, g, v0) = (0.5, 0.25, 9.81, 1.2);
        let spec = SystemSpec {
            structure: Structure::oscillator(1e6, 1e12, 0.0).unwrap(),
            dampers: vec![Damper {
                mass: m,
                at: 0.0,
                lower_clearance: f64::INFINITY,
                upper_clearance: f64::INFINITY,
                law: PairLaw::rigid(0.5).unwrap(),
            }],
            collisions: vec![],
            frictions: vec![Friction {
                site: FrictionSite::Damper(0),
                coefficient: mu,
                static_coefficient: mu,
                normal_force: m * g,
            }],
            stops: vec![],
            gravity: 0.0,
            excitations: vec![],
            points: vec![],
            moments: vec![],
        };
        let system = Assembly::new(&spec).unwrap();
        let y = initial_state(&system, &[0.0], &[0.0], &[0.0], &[v0]).unwrap();
        let mut flow = ExactFlow::new(&system).unwrap();
        let t_stop = v0 / (mu * g);
        let dt = flow.step().min(t_stop / 8.0);
        let solution = run(&system, &mut flow, &y, Some(dt), 2.0 * t_stop);
        let distance = v0 * v0 / (2.0 * mu * g);
        let end = &solution.final_state;
        // Relative to the carrier (which the reaction moves by 1e-10 m).
        let (slid, sliding) = (end[1] - end[0], end[3] - end[2]);
        assert!(
            (slid - distance).abs() <= 1e-9 * distance,
            "slid {slid} against {distance}"
        );
        assert!(sliding.abs() <= 1e-12, "still sliding at {sliding}");
        // One stuck interval, from the stop on.
        let stuck: Vec<_> = solution.contacts.iter().collect();
        assert_eq!(stuck.len(), 1, "{stuck:?}");
        assert!((stuck[0].onset - t_stop).abs() <= 1e-9 * t_stop);
        let lost = 0.5 * m * v0 * v0;
        assert!((solution.energy.friction - lost).abs() <= 1e-8 * lost);
    });
}

/// A horizontal impact damper with friction on a forced structure (impacts,
/// chattering onto a wall, stick-slip, a stop that slides back within a step):
/// the exact flow and dop853 at tight tolerances end 20 periods on the same state,
/// with the ledger closed.
#[test]
fn a_horizontal_damper_with_friction_agrees_on_exact_and_dop853() {
    common::timeout(60, || {
        use vibroimpact_core::model::assembly::{Excitation, Load};
        use vibroimpact_core::model::signals::{Harmonic, Signal};
        let spec = SystemSpec {
            structure: Structure::oscillator(1.0, 4000.0, 2.0).unwrap(),
            dampers: vec![Damper {
                mass: 0.1,
                at: 0.0,
                lower_clearance: 0.01,
                upper_clearance: 0.01,
                law: PairLaw::rigid(0.6).unwrap(),
            }],
            collisions: vec![],
            frictions: vec![Friction {
                site: FrictionSite::Damper(0),
                coefficient: 0.2,
                static_coefficient: 0.3,
                normal_force: 0.981,
            }],
            stops: vec![],
            gravity: 0.0,
            excitations: vec![Excitation {
                load: Load::Force { at: 0.0 },
                signal: Signal::Harmonic(Harmonic::new(30.0, 10.0, 0.0).unwrap()),
            }],
            points: vec![],
            moments: vec![],
        };
        let system = Assembly::new(&spec).unwrap();
        let y = initial_state(&system, &[0.0], &[0.0], &[0.0], &[0.0]).unwrap();
        let mut flow = ExactFlow::new(&system).unwrap();
        let dt = flow.step();
        let exact = run(&system, &mut flow, &y, Some(dt), 2.0);
        let mut dop853 = ExplicitRk::dop853(system.state_len(), 1e-12, 1e-15);
        let adaptive = run(&system, &mut dop853, &y, None, 2.0);
        for (a, b) in exact.final_state.iter().zip(&adaptive.final_state).take(4) {
            assert!((a - b).abs() <= 1e-6, "{a} against {b}");
        }
        for solution in [&exact, &adaptive] {
            let e = &solution.energy;
            assert!(e.friction > 0.0 && e.impact > 0.0);
            assert!(e.residual.abs() <= 1e-8 * e.input_work, "{e:?}");
        }
    });
}
