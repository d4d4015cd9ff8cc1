//! The tangent flow's columns by parameters against central differences of
//! whole runs of the systems made at `p +- h`.

use super::tests::{damper_on_oscillator, options};
use super::*;
use crate::methods::registry::{AnyStepper, Options};
use crate::model::assembly::{initial_state, PairLaw};
use crate::model::contact::{Contact, LawKind};
use crate::model::signals::Signal;

/// The forced oscillator with its impact damper, every value a parameter:
/// `[force amplitude (N), forcing frequency (Hz), clearance (m), structure
/// stiffness (N/m), damper mass (kg), the law's value]`, the law's value
/// its restitution (rigid) or its stiffness (compliant), then gravity
/// (m/s^2). A value of 0 is not varied.
type Values = [f64; 7];

const BASE: Values = [8.0, 9.0, 0.01, 3000.0, 0.05, 0.6, 0.0];
const NAMES: [&str; 7] = [
    "amplitude",
    "frequency",
    "clearance",
    "stiffness",
    "damper mass",
    "law",
    "gravity",
];

fn system(values: &Values, law: Option<LawKind>) -> Assembly {
    let [amplitude, frequency, clearance, stiffness, damper_mass, value, gravity] = *values;
    let law = match law {
        None => PairLaw::rigid(value).unwrap(),
        Some(kind) => {
            let restitution = kind.uses_restitution().then_some(0.7);
            let damping = if kind == LawKind::Linear { 40.0 } else { 0.0 };
            PairLaw::Compliant(Contact::new(kind, value, restitution, damping).unwrap())
        }
    };
    let signal = Signal::harmonic(amplitude, frequency, 0.3).unwrap();
    damper_on_oscillator((stiffness, damper_mass, clearance), law, gravity, signal)
}

/// The end state, the columns by `shifted` and the impacts of a run by
/// `method` to `t_end`.
pub(super) fn run(
    system: &Assembly,
    y0: &[f64],
    t_end: f64,
    method: &str,
    shifted: Vec<Shifted>,
) -> (Vec<f64>, Vec<f64>, u64) {
    let tight = Options {
        rtol: 1e-12,
        atol: 1e-15,
        ..Options::default()
    };
    let mut stepper = AnyStepper::new(system, method, &tight).unwrap();
    let dt = stepper.step(None, t_end, f64::INFINITY);
    let mut flow = Tangent::with_parameters(system, shifted).unwrap();
    let solution = stepper
        .integrate_observed(system, y0, &options(t_end, dt), &mut || false, &mut flow)
        .unwrap();
    assert!(flow.grazings().is_empty());
    let size = 2 * system.dim;
    (
        solution.final_state[..size].to_vec(),
        flow.parameter_columns().to_vec(),
        flow.impacts(),
    )
}

/// The worst difference, scaled as the state's coordinates are, between
/// each parameter's column and the central difference of the end states of
/// runs at `p +- step p`; and the fewest impacts of a run.
fn worst(values: Values, law: Option<LawKind>, method: &str, t_end: f64, step: f64) -> (f64, u64) {
    let base = system(&values, law);
    let y0 = initial_state(&base, &[0.004], &[-0.2], &[0.002], &[0.3]).unwrap();
    let moved = |j: usize, by: f64| {
        let mut moved = values;
        moved[j] += by;
        system(&moved, law)
    };
    // The flow's own quotient at a step of 1e-6 (exact where a value enters
    // linearly; the rest err by its square).
    let varied: Vec<usize> = (0..values.len()).filter(|&j| values[j] != 0.0).collect();
    let shifted = varied
        .iter()
        .map(|&j| {
            let delta = 1e-6 * values[j];
            Shifted {
                plus: moved(j, delta),
                minus: moved(j, -delta),
                delta,
            }
        })
        .collect();
    let (_, columns, impacts) = run(&base, &y0, t_end, method, shifted);
    let m = varied.len();
    let scales = [1e-3, 1e-3, 0.1, 0.1];
    let mut worst = 0.0f64;
    for (column, &j) in varied.iter().enumerate() {
        let h = step * values[j];
        let (up, _, _) = run(&moved(j, h), &y0, t_end, method, vec![]);
        let (down, _, _) = run(&moved(j, -h), &y0, t_end, method, vec![]);
        for r in 0..4 {
            let difference = (up[r] - down[r]) / (2.0 * h) * values[j] / scales[r];
            let exact = columns[r * m + column] * values[j] / scales[r];
            let error = (difference - exact).abs() / (1.0 + exact.abs());
            assert!(
                error < 2e-6,
                "{law:?} {method} {}: row {r}: {exact:e} against differences {difference:e}",
                NAMES[j]
            );
            worst = worst.max(error);
        }
    }
    (worst, impacts)
}

#[test]
fn through_rigid_impacts_the_parameter_columns_are_the_runs_central_differences() {
    crate::testing::timeout(120, || {
        for method in ["exact", "dop853"] {
            let (worst, impacts) = worst(BASE, None, method, 0.4, 1e-7);
            assert!(impacts >= 6, "{method}: {impacts} impacts");
            assert!(worst < 1e-6, "{method}: worst scaled difference {worst:e}");
        }
    });
}

#[test]
fn through_compliant_contacts_the_parameter_columns_are_the_runs_central_differences() {
    crate::testing::timeout(120, || {
        for (kind, stiffness) in [
            (LawKind::Hertz, 1e9),
            (LawKind::Linear, 2e6),
            (LawKind::HysterHertz, 1e9),
            (LawKind::HertzDamped, 1e9),
        ] {
            let mut values = BASE;
            values[5] = stiffness;
            let (worst, impacts) = worst(values, Some(kind), "dop853", 0.15, 1e-5);
            assert!(impacts >= 2, "{kind:?}: {impacts} contacts");
            assert!(worst < 1e-5, "{kind:?}: worst scaled difference {worst:e}");
        }
    });
}

#[test]
fn through_sticking_and_release_the_parameter_columns_are_the_runs_central_differences() {
    crate::testing::timeout(120, || {
        // Plastic impacts under gravity: the damper lands, sticks to its
        // carrier's wall, and is released as the carrier falls away faster
        // than gravity.
        let mut values = BASE;
        values[5] = 0.0;
        values[6] = 9.81;
        for method in ["exact", "dop853"] {
            let (worst, impacts) = worst(values, None, method, 0.4, 1e-7);
            assert!(impacts >= 4, "{method}: {impacts} impacts");
            assert!(worst < 2e-6, "{method}: worst scaled difference {worst:e}");
        }
    });
}
