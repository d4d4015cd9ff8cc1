//! A forced linear response against its closed form: each step-based method
//! must take the external force at the right instants of its step, which
//! shows as the method's order on a harmonically forced oscillator (a force
//! taken at the wrong end of a Newmark step is a first-order error).

mod common;

use std::f64::consts::TAU;
use vibroimpact_core::kernel::events::RunOptions;
use vibroimpact_core::methods::registry::{two_mass, AnyStepper};
use vibroimpact_core::model::assembly::{initial_state, Assembly, Excitation, Load, SystemSpec};
use vibroimpact_core::model::signals::Signal;
use vibroimpact_core::model::structure::Structure;
use vibroimpact_core::Method;

/// `F0 cos(omega t)` on the oscillator: amplitude N, angular frequency rad/s.
struct Harmonic {
    amplitude: f64,
    frequency: f64,
}

const MAIN_MASS: f64 = 1.0;
const STIFFNESS: f64 = 4.0;
const DAMPING: f64 = 0.1;
const FORCE: Harmonic = Harmonic {
    amplitude: 1.0,
    frequency: 3.0,
};

/// The steady response `w(t) = Re(Q exp(i omega t))` with
/// `Q = F0 / (K - omega^2 M + i omega C)` (forced-oracles.md, "Forced linear
/// baselines"): returns `(Re Q, Im Q)`. Started on it, the run has no
/// transient, so the exact solution is this for all t.
fn steady_amplitude() -> (f64, f64) {
    let omega = FORCE.frequency;
    let (re, im) = (STIFFNESS - omega * omega * MAIN_MASS, omega * DAMPING);
    let norm = re * re + im * im;
    (FORCE.amplitude * re / norm, -FORCE.amplitude * im / norm)
}

fn exact_w(t: f64) -> f64 {
    let (q_re, q_im) = steady_amplitude();
    let omega = FORCE.frequency;
    q_re * (omega * t).cos() - q_im * (omega * t).sin()
}

/// Largest error in `w` over 2 s of steps `dt` of the general kernel
/// (steps cut at events: there are none), every step recorded.
fn max_error(method: Method, dt: f64) -> f64 {
    let structure = Structure::oscillator(MAIN_MASS, STIFFNESS, DAMPING).unwrap();
    let spec = SystemSpec {
        excitations: vec![Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(FORCE.amplitude, FORCE.frequency / TAU, 0.0).unwrap(),
        }],
        ..SystemSpec::of(structure, vec![])
    };
    let system = Assembly::new(&spec).unwrap();
    let (q_re, q_im) = steady_amplitude();
    let y = initial_state(&system, &[q_re], &[-FORCE.frequency * q_im], &[], &[]).unwrap();
    let options = RunOptions {
        dt: Some(dt),
        t_end: 2.0,
        every: 1,
        keep_history: true,
        max_steps: 100_000_000,
        max_rows: 100_000_000,
        // Trapezoidal work against the Newmark family's own energy: an
        // O(dt^2) residual, not what this test is about.
        energy_tolerance: 1e-2,
        reduce: Default::default(),
    };
    let mut stepper =
        AnyStepper::new(&system, method.name(), &two_mass::options_of(&method)).unwrap();
    let sol = stepper
        .integrate(&system, &y, &options, &mut || false)
        .unwrap();
    assert!(sol.contacts.is_empty());
    assert_eq!(sol.time.len() as u64, sol.steps + 1);
    // Rows [w, w'].
    sol.time
        .iter()
        .zip(sol.states.chunks(2))
        .map(|(&t, row)| (row[0] - exact_w(t)).abs())
        .fold(0.0, f64::max)
}

/// Measured order over the steps `dts` (halving), and the error at the finest.
fn order(method: Method, dts: &[f64]) -> (f64, f64) {
    let errors: Vec<f64> = dts.iter().map(|&dt| max_error(method, dt)).collect();
    let n = errors.len() - 1;
    let slope = (errors[0] / errors[n]).ln() / (dts[0] / dts[n]).ln();
    // Every halving, not just the ends, shows the order.
    for pair in errors.windows(2) {
        let local = (pair[0] / pair[1]).log2();
        assert!(
            (local - slope).abs() < 0.02,
            "{method:?}: errors {errors:?} do not fall at one rate"
        );
    }
    (slope, errors[n])
}

#[test]
fn newmark_family_converges_at_second_order_on_a_forced_response() {
    common::timeout(60, || {
        let newmark = Method::NewmarkImplicit {
            beta: 0.25,
            gamma: 0.5,
        };
        let lagged = Method::Newmark {
            beta: 0.25,
            gamma: 0.5,
        };
        let alpha = Method::GeneralizedAlpha {
            spectral_radius: 0.8,
        };
        let dts = [0.02, 0.01, 0.005, 0.0025];
        let cases = [
            (newmark, order(newmark, &dts)),
            (lagged, order(lagged, &dts)),
            (alpha, order(alpha, &dts)),
        ];
        // The amplitude |Q| is about 0.2 m; average-acceleration Newmark's
        // leading error is its period error, (omega dt)^2 / 12 of the phase
        // per radian, about 1e-4 m at dt = 2.5 ms over 2 s: second order
        // to 0.05 in the slope, and no more than that in size.
        let amplitude = {
            let (re, im) = steady_amplitude();
            (re * re + im * im).sqrt()
        };
        let bound = amplitude * (FORCE.frequency * dts[3]).powi(2) / 12.0 * FORCE.frequency * 2.0;
        for (method, (slope, finest)) in cases {
            assert!(
                (slope - 2.0).abs() < 0.05,
                "{method:?}: order {slope:.3} on the forced response, expected 2"
            );
            assert!(
                finest < 2.0 * bound,
                "{method:?}: error {finest:.3e} m at dt = {} s, bound {bound:.3e} m",
                dts[3]
            );
        }
    });
}

#[test]
fn rk4_converges_at_fourth_order_on_a_forced_response() {
    common::timeout(60, || {
        let (slope, _) = order(Method::Rk4, &[0.04, 0.02, 0.01]);
        assert!(
            (slope - 4.0).abs() < 0.1,
            "rk4: order {slope:.3} on the forced response"
        );
    });
}
