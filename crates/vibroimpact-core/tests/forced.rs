//! A forced linear response against its closed form: each step-based method
//! must take the external force at the right instants of its step, which
//! shows as the method's order on a harmonically forced oscillator (a force
//! taken at the wrong end of a Newmark step is a first-order error).

mod common;

use vibroimpact_core::legacy::equations::{Excitation, Model};
use vibroimpact_core::legacy::events::integrate_events;
use vibroimpact_core::legacy::steppers::{NewmarkFamily, Rk4Stepper, Stepper};
use vibroimpact_core::model::contact::Hertz;
use vibroimpact_core::{ContactTiming, ImpactDamper, Method, Settings, State, Stepping};

/// `F0 cos(omega t)` on the main mass, N.
#[derive(Debug, Clone, Copy)]
struct Harmonic {
    amplitude: f64,
    frequency: f64,
}

impl Excitation for Harmonic {
    const IS_FREE: bool = false;
    fn main_force(&self, time: f64) -> f64 {
        self.amplitude * (self.frequency * time).cos()
    }
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

/// Largest error in `w` over 2 s of steps `dt`; the impact mass rests in the
/// middle of a 10 m clearance and is never reached (|w| < 0.3 m).
fn max_error<S: Stepper>(stepper: &mut S, method: Method, dt: f64) -> f64 {
    let system = ImpactDamper::new(MAIN_MASS, STIFFNESS, DAMPING, 0.25, 10.0).unwrap();
    let model = Model::new(&system, Hertz { stiffness: 3000.0 }, 0.0, FORCE);
    let (q_re, q_im) = steady_amplitude();
    let start = State::new(q_re, -FORCE.frequency * q_im, 0.0, 0.0).unwrap();
    let settings = Settings::new(
        method,
        Some(dt),
        2.0,
        1,
        ContactTiming::Located,
        Some(Stepping::Events),
        u64::MAX,
    )
    .unwrap();
    let sol = integrate_events(&model, stepper, &start, &settings, &mut || false).unwrap();
    assert!(sol.contacts.is_empty());
    let h = &sol.history;
    assert_eq!(h.time.len() as u64, sol.steps + 1);
    h.time
        .iter()
        .zip(&h.main_displacement)
        .map(|(&t, &w)| (w - exact_w(t)).abs())
        .fold(0.0, f64::max)
}

/// Measured order over the steps `dts` (halving), and the error at the finest.
fn order<S: Stepper>(mut make: impl FnMut() -> S, method: Method, dts: &[f64]) -> (f64, f64) {
    let errors: Vec<f64> = dts
        .iter()
        .map(|&dt| max_error(&mut make(), method, dt))
        .collect();
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
            (
                newmark,
                order(|| NewmarkFamily::newmark(0.25, 0.5, false), newmark, &dts),
            ),
            (
                lagged,
                order(|| NewmarkFamily::newmark(0.25, 0.5, true), lagged, &dts),
            ),
            (
                alpha,
                order(|| NewmarkFamily::generalized_alpha(0.8), alpha, &dts),
            ),
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
        let (slope, _) = order(Rk4Stepper::default, Method::Rk4, &[0.04, 0.02, 0.01]);
        assert!(
            (slope - 4.0).abs() < 0.1,
            "rk4: order {slope:.3} on the forced response"
        );
    });
}
