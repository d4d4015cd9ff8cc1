//! The tangent flow through stick-slip: against the central differences of
//! whole runs (stops, reversals, sticking, slips, and impacts with friction
//! on the impacting row), and against the free decay's closed form of its
//! phase volume.

use super::parameter_tests::run as with_parameters;
use super::tests::{determinant, options, run_with, worst_difference_from};
use super::*;
use crate::kernel::events::{ContactKind, SystemSolution};
use crate::methods::registry::{AnyStepper, Options};
use crate::model::assembly::{
    initial_state, Damper, Excitation, Friction, FrictionSite, Load, PairLaw, SystemSpec,
};
use crate::model::signals::Signal;
use crate::model::structure::Structure;

const MASS: f64 = 1.0;
const STIFFNESS: f64 = 100.0;
/// N: the kinetic friction force of the oscillator's element.
const KINETIC: f64 = 1.0;

/// An oscillator (1 kg, `stiffness` N/m, `damping` N s/m) rubbing on the
/// ground through a friction element (`kinetic` and static `held` forces,
/// N), driven by a harmonic force of `amplitude` N at `frequency` Hz.
fn rubbing(
    damping: f64,
    [kinetic, held, amplitude, stiffness]: [f64; 4],
    frequency: f64,
) -> Assembly {
    let signal = Signal::harmonic(amplitude, frequency, 0.3).unwrap();
    driven(damping, [kinetic, held, stiffness], signal)
}

/// [`rubbing`] driven by the force `signal` (N).
fn driven(damping: f64, [kinetic, held, stiffness]: [f64; 3], signal: Signal) -> Assembly {
    let spec = SystemSpec {
        structure: Structure::oscillator(MASS, stiffness, damping).unwrap(),
        dampers: vec![],
        collisions: vec![],
        frictions: vec![Friction {
            site: FrictionSite::Points {
                at: 0.0,
                against: None,
            },
            coefficient: kinetic,
            static_coefficient: held,
            normal_force: 1.0,
        }],
        stops: vec![],
        gravity: 0.0,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.0 },
            signal,
        }],
        points: vec![],
        moments: vec![],
    };
    Assembly::new(&spec).unwrap()
}

/// The forced stick-slip oscillator (0.5 N s/m; at 0.8 Hz) with its kinetic
/// and static forces (N), forcing amplitude (N) and stiffness (N/m) from
/// `values`: it stops, sticks and slips again, once a cycle.
fn stick_slip(values: [f64; 4]) -> Assembly {
    rubbing(0.5, values, 0.8)
}

/// A forced oscillator (1 kg, 3000 N/m; 10 N at 6 Hz) carrying a horizontal
/// damper of 50 g between rigid walls 4 mm away (restitution 0.7) that
/// slides on its floor (kinetic force 0.2 N, static 0.3 N).
fn horizontal_damper() -> Assembly {
    horizontal_damper_with(0.7, 6.0)
}

/// [`horizontal_damper`] with its walls' `restitution`, forced at
/// `frequency` Hz.
fn horizontal_damper_with(restitution: f64, frequency: f64) -> Assembly {
    let spec = SystemSpec {
        structure: Structure::oscillator(MASS, 3000.0, 2.0).unwrap(),
        dampers: vec![Damper {
            mass: 0.05,
            at: 0.0,
            lower_clearance: 0.004,
            upper_clearance: 0.004,
            law: PairLaw::rigid(restitution).unwrap(),
        }],
        collisions: vec![],
        frictions: vec![Friction {
            site: FrictionSite::Damper(0),
            coefficient: 0.4,
            static_coefficient: 0.6,
            normal_force: 0.5,
        }],
        stops: vec![],
        gravity: 0.0,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(10.0, frequency, 0.0).unwrap(),
        }],
        points: vec![],
        moments: vec![],
    };
    Assembly::new(&spec).unwrap()
}

/// A run's end state and tangent map.
fn run(system: &Assembly, y0: &[f64], t_end: f64, method: &str) -> (Vec<f64>, Vec<f64>) {
    let (end, tangent, _) = run_with(system, y0, t_end, method);
    (end, tangent)
}

/// The run's solution (for its stick-slip record).
fn solution(system: &Assembly, y0: &[f64], t_end: f64) -> SystemSolution {
    let mut stepper = AnyStepper::new(system, "exact", &Options::default()).unwrap();
    let dt = stepper.step(None, t_end, f64::INFINITY);
    stepper
        .integrate_observed(
            system,
            y0,
            &options(t_end, dt),
            &mut || false,
            &mut Tangent::product(system).unwrap(),
        )
        .unwrap()
}

/// Static force 1.6 N against a kinetic 1 N, 4 N of forcing.
const STICK_SLIP: [f64; 4] = [KINETIC, 1.6, 4.0, STIFFNESS];

/// [`stick_slip`] of `values`, its start and a run's end (s) over which it
/// stops, sticks and slips again at least twice (checked).
fn sticking_run(values: [f64; 4]) -> (Assembly, Vec<f64>, f64) {
    let system = stick_slip(values);
    let y0 = initial_state(&system, &[0.02], &[0.1], &[], &[]).unwrap();
    let t_end = 2.5;
    let (stuck, slips) = sticks_and_slips(&solution(&system, &y0, t_end), t_end);
    assert!(
        stuck >= 2 && slips >= 2,
        "{stuck} stuck intervals, {slips} slips"
    );
    (system, y0, t_end)
}

/// Stuck intervals of the run, and slips from them before its end.
fn sticks_and_slips(solution: &SystemSolution, t_end: f64) -> (usize, usize) {
    let stuck = solution
        .contacts
        .iter()
        .filter(|c| c.kind == ContactKind::Sticking);
    let slips = stuck.clone().filter(|c| c.separation < t_end).count();
    (stuck.count(), slips)
}

#[test]
fn through_reversals_the_free_decays_phase_volume_is_its_closed_form() {
    crate::testing::timeout(60, || {
        // Undamped and unforced: the flow keeps phase volume between events,
        // and a reversal of amplitude R about the sliding offset F / k
        // multiplies it by (a+ . h) / (a- . h) = 1 - 2 F / (k R); the next
        // amplitude is R - 2 F / k, so after N reversals the volume is
        // R_N / R_0.
        let system = rubbing(0.0, [KINETIC, KINETIC, 0.0, STIFFNESS], 1.0);
        let (x0, v0) = (0.3, 0.5);
        let y0 = initial_state(&system, &[x0], &[v0], &[], &[]).unwrap();
        let omega = (STIFFNESS / MASS).sqrt();
        let offset = -KINETIC / STIFFNESS; // moving up: the force pulls down
        let r0 = ((x0 - offset).powi(2) + (v0 / omega).powi(2)).sqrt();
        for t_end in [0.5, 1.2, 2.0] {
            for method in ["exact", "dop853"] {
                let (_, tangent) = run(&system, &y0, t_end, method);
                // The reversals before t_end: the first at the phase where the
                // speed first vanishes, then every half period.
                let first = (v0 / omega).atan2(x0 - offset);
                let reversals = ((t_end * omega - first) / std::f64::consts::PI).floor() + 1.0;
                let expected = 1.0 - 2.0 * reversals * KINETIC / (STIFFNESS * r0);
                let got = determinant(&tangent, 2);
                // Measured: within 2e-14.
                assert!(
                    (got - expected).abs() < 1e-10,
                    "{method} to {t_end} s ({reversals} reversals): det {got} against {expected}"
                );
            }
        }
    });
}

#[test]
fn through_stops_sticking_and_slips_the_tangent_map_is_the_runs_central_differences() {
    crate::testing::timeout(120, || {
        let (system, y0, t_end) = sticking_run(STICK_SLIP);
        for method in ["exact", "dop853"] {
            // Measured: 6e-9 (exact), 6e-8 (dop853).
            let worst = worst_difference_from(&system, (&y0, &[0.01, 0.1]), t_end, method, 1e-7);
            assert!(worst < 1e-6, "{method}: worst scaled difference {worst:e}");
        }
    });
}

#[test]
fn through_impacts_with_friction_the_tangent_map_is_the_runs_central_differences() {
    crate::testing::timeout(120, || {
        let system = horizontal_damper();
        let y0 = initial_state(&system, &[0.002], &[-0.1], &[0.001], &[0.3]).unwrap();
        let t_end = 0.6;
        let run_solution = solution(&system, &y0, t_end);
        let impacts = run_solution
            .contacts
            .iter()
            .filter(|c| c.kind == ContactKind::Impact)
            .count();
        let (stuck, _) = sticks_and_slips(&run_solution, t_end);
        assert!(
            impacts >= 4 && stuck >= 1,
            "{impacts} impacts, {stuck} stuck intervals"
        );
        let scales = [1e-3, 1e-3, 0.1, 0.1];
        for method in ["exact", "dop853"] {
            // Measured: 1.1e-7 (exact), 2.8e-7 (dop853).
            let worst = worst_difference_from(&system, (&y0, &scales), t_end, method, 1e-7);
            assert!(worst < 2e-6, "{method}: worst scaled difference {worst:e}");
        }
    });
}

#[test]
fn through_landings_held_by_wall_and_friction_the_tangent_map_is_the_runs_central_differences() {
    crate::testing::timeout(120, || {
        // Plastic walls: the damper lands at rest on a wall, held there by
        // the wall and its friction together, and leaves where the wall
        // would pull by more than the static friction (a release at a
        // force, not at zero: its time moves with the state).
        let system = horizontal_damper_with(0.0, 5.0);
        let y0 = initial_state(&system, &[0.002], &[-0.1], &[0.001], &[0.3]).unwrap();
        let t_end = 1.0;
        let run_solution = solution(&system, &y0, t_end);
        let released = run_solution
            .contacts
            .iter()
            .filter(|c| c.pair == 0 && c.kind == ContactKind::Sticking && c.separation < t_end)
            .count();
        assert!(released >= 3, "{released} releases from a wall");
        let scales = [1e-3, 1e-3, 0.1, 0.1];
        for method in ["exact", "dop853"] {
            // Measured: 2.5e-7 (exact), 1.6e-6 (dop853, which lands by its
            // located events' accuracy).
            let worst = worst_difference_from(&system, (&y0, &scales), t_end, method, 1e-7);
            assert!(worst < 1e-5, "{method}: worst scaled difference {worst:e}");
        }
    });
}

#[test]
fn a_slip_just_after_a_recorded_sample_takes_the_load_s_rate_on_its_stretch() {
    crate::testing::timeout(60, || {
        // Stuck at rest, pushed by a recorded force whose slope falls from
        // 1.6 N/s to 1.4 N/s at 1 s, 1e-6 N short of the static force: the
        // slip comes 7e-7 s after that sample. A start moved by dx slips
        // k dx / (1.4 N/s) later; a rate taken across the kink would not.
        let ramp = Signal::recorded(vec![0.0, 1.0, 2.0], vec![0.0, 1.6 - 1e-6, 3.0], 1.0).unwrap();
        let system = driven(0.5, [KINETIC, 1.6, STIFFNESS], ramp);
        let y0 = initial_state(&system, &[0.0], &[0.0], &[], &[]).unwrap();
        let t_end = 1.5;
        let (_, tangent) = run(&system, &y0, t_end, "dop853");
        let step = 1e-9;
        let moved = |by: f64| {
            let mut start = y0.clone();
            start[0] += by;
            run(&system, &start, t_end, "dop853").0
        };
        let (up, down) = (moved(step), moved(-step));
        for r in 0..2 {
            let difference = (up[r] - down[r]) / (2.0 * step);
            let exact = tangent[r * 2];
            assert!(
                (difference - exact).abs() < 1e-4 * (1.0 + exact.abs()),
                "row {r}: {exact:e} against differences {difference:e}"
            );
        }
    });
}

#[test]
fn through_stick_slip_the_derivatives_by_parameters_are_the_runs_central_differences() {
    crate::testing::timeout(120, || {
        // Each parameter moves the stops, the stuck places and the slips:
        // the kinetic and static forces, the forcing and the stiffness.
        let values = STICK_SLIP;
        let (system, y0, t_end) = sticking_run(values);
        let shifted_by = |j: usize, delta: f64| {
            let (mut up, mut down) = (values, values);
            up[j] += delta;
            down[j] -= delta;
            Shifted {
                plus: stick_slip(up),
                minus: stick_slip(down),
                delta,
            }
        };
        let deltas: Vec<f64> = values.iter().map(|v| 1e-6 * v).collect();
        for method in ["exact", "dop853"] {
            let shifted = (0..4).map(|j| shifted_by(j, deltas[j])).collect();
            let (_, columns, _) = with_parameters(&system, &y0, t_end, method, shifted);
            let scales = [0.01, 0.1];
            let mut worst = 0.0f64;
            for (j, delta) in deltas.iter().enumerate() {
                let shifted = shifted_by(j, *delta);
                let (up, _) = run(&shifted.plus, &y0, t_end, method);
                let (down, _) = run(&shifted.minus, &y0, t_end, method);
                for r in 0..2 {
                    let difference = (up[r] - down[r]) / (2.0 * delta);
                    let exact = columns[r * 4 + j];
                    // Per relative change of the parameter, in the state's scale.
                    let error = (difference - exact).abs() * values[j] / scales[r];
                    worst = worst.max(error / (1.0 + exact.abs() * values[j] / scales[r]));
                }
            }
            // Measured: 7e-10 (exact), 1.2e-8 (dop853); without the slips'
            // margins moved by the parameters, 0.65.
            assert!(worst < 1e-6, "{method}: worst scaled difference {worst:e}");
        }
    });
}
