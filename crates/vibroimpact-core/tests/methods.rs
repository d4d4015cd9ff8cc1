//! Orders of the general kernel's steppers on a smooth problem with a
//! closed form, and every method's event-driven run of the Table 1 collision
//! (the two-mass preset on the general kernel).

mod common;

use vibroimpact_core::methods::registry::{two_mass, AnyStepper};
use vibroimpact_core::methods::steppers::SystemStepper;
use vibroimpact_core::model::assembly::{Assembly, Mode, Scratch};
use vibroimpact_core::model::closed_forms::{
    goldsmith_contact_duration, goldsmith_max_indentation,
};
use vibroimpact_core::{
    simulate, Contact, ContactTiming, ImpactDamper, LawKind, Method, Settings, State, Stepping,
    Tolerances,
};

/// A damped main oscillator whose impact mass never touches (huge
/// clearance), and its start `w(0) = 1`.
fn oscillator() -> (Assembly, Vec<f64>) {
    let system = ImpactDamper::new(1.0, 4.0, 0.1, 0.25, 10.0).unwrap();
    let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.0).unwrap();
    let assembly = system.assembly(&contact).unwrap();
    let y0 = State::new(1.0, 0.0, 0.0, 0.0)
        .unwrap()
        .vector(&assembly)
        .unwrap();
    (assembly, y0)
}

/// w(t) of `w'' + c w' + k w = 0`, `w(0) = 1`, `w'(0) = 0` (M = 1).
fn exact_w(t: f64) -> f64 {
    let (k, c) = (4.0_f64, 0.1_f64);
    let sigma = c / 2.0;
    let omega = (k - sigma * sigma).sqrt();
    (-sigma * t).exp() * ((omega * t).cos() + sigma / omega * (omega * t).sin())
}

/// Error at t = 2 s of fixed steps `h` (the adaptive methods' error
/// estimates ignored) with any stepper.
fn error_with<S: SystemStepper>(stepper: &mut S, h: f64) -> f64 {
    let (system, mut y) = oscillator();
    let modes = vec![Mode::Open; system.interaction_count()];
    let mut scratch = Scratch::new(&system);
    let mut end = y.clone();
    let n = (2.0 / h).round() as usize;
    stepper.reset();
    for i in 0..n {
        stepper
            .attempt(&system, i as f64 * h, &y, h, &modes, &mut scratch, &mut end)
            .unwrap();
        stepper.accept();
        y.copy_from_slice(&end);
    }
    (y[0] - exact_w(n as f64 * h)).abs()
}

fn error(method: &Method, h: f64) -> f64 {
    let (system, _) = oscillator();
    let options = two_mass::options_of(method);
    match AnyStepper::new(&system, method.name(), &options).unwrap() {
        AnyStepper::Rk(mut s) => error_with(&mut s, h),
        AnyStepper::Newmark(mut s) => error_with(&mut s, h),
        AnyStepper::Paper(mut s) => error_with(&mut s, h),
        AnyStepper::Exact(mut s) => error_with(&mut s, h),
    }
}

fn order(method: Method, steps: &[f64]) -> f64 {
    let errors: Vec<f64> = steps.iter().map(|&h| error(&method, h)).collect();
    let (first, last) = (errors[0], errors[errors.len() - 1]);
    (first / last).ln() / (steps[0] / steps[steps.len() - 1]).ln()
}

#[test]
fn each_method_converges_at_its_order_on_a_smooth_problem() {
    common::timeout(60, || {
        let loose = Tolerances {
            rtol: 1e-3,
            atol: 1e-6,
        };
        let cases: [(&str, f64, f64); 6] = [
            ("rk4", order(Method::Rk4, &[0.1, 0.05, 0.025]), 4.0),
            (
                "newmark-implicit",
                order(
                    Method::NewmarkImplicit {
                        beta: 0.25,
                        gamma: 0.5,
                    },
                    &[0.1, 0.05, 0.025],
                ),
                2.0,
            ),
            (
                "generalized-alpha",
                order(
                    Method::GeneralizedAlpha {
                        spectral_radius: 0.8,
                    },
                    &[0.1, 0.05, 0.025],
                ),
                2.0,
            ),
            (
                "newmark (lagged, free flight)",
                order(
                    Method::Newmark {
                        beta: 0.25,
                        gamma: 0.5,
                    },
                    &[0.1, 0.05, 0.025],
                ),
                2.0,
            ),
            (
                "dopri5",
                order(Method::Dopri5(loose), &[0.1, 0.05, 0.025]),
                5.0,
            ),
            (
                "dop853",
                order(Method::Dop853(loose), &[0.4, 0.2, 0.1]),
                8.0,
            ),
        ];
        for (name, measured, theory) in cases {
            assert!(
                (measured - theory).abs() < 0.2,
                "{name}: order {measured:.3}, expected {theory}"
            );
        }
    });
}

#[test]
fn every_method_with_events_converges_to_the_exact_collision() {
    common::timeout(60, || {
        // Two free bodies (K = C = c1 = 0) and a Hertz contact: the duration,
        // the deepest indentation and the rebound (equal to the approach for
        // an elastic law) are known in closed form (Goldsmith, with the exact
        // constant), independently of any integrator.
        let (impact_mass, main_mass, hertz, speed) = (0.25, 1.0, 3000.0, 0.1);
        let system = ImpactDamper::new(main_mass, 0.0, 0.0, impact_mass, 0.01).unwrap();
        let contact = Contact::new(LawKind::Hertz, hertz, None, 0.0).unwrap();
        let start = State::new(0.0, 0.0, 0.01, speed).unwrap();
        let duration =
            goldsmith_contact_duration(impact_mass, main_mass, hertz, speed, true).unwrap();
        let deepest = goldsmith_max_indentation(impact_mass, main_mass, hertz, speed).unwrap();
        let run = |method: Method, dt: Option<f64>| {
            let settings = Settings::new(
                method,
                dt,
                0.15,
                1_000_000,
                ContactTiming::Located,
                Some(Stepping::Events),
                // Far more than any of these runs takes (at most ~2000
                // steps): a method whose steps collapse fails at once.
                100_000,
            )
            .unwrap();
            simulate(&system, &contact, &start, &settings, &mut || false).unwrap()
        };
        let newmark = Method::NewmarkImplicit {
            beta: 0.25,
            gamma: 0.5,
        };
        let alpha = Method::GeneralizedAlpha {
            spectral_radius: 0.8,
        };
        let adaptive = Tolerances {
            rtol: 1e-10,
            atol: 1e-13,
        };
        let cases = [
            (Method::Rk4, Some(1e-3), 1e-6),
            (Method::Rk4, Some(1e-4), 1e-9),
            (newmark, Some(1e-4), 2e-6),
            (alpha, Some(1e-4), 2e-6),
            (Method::Dopri5(adaptive), None, 1e-9),
            (Method::Dop853(adaptive), None, 1e-10),
        ];
        for (method, dt, tolerance) in cases {
            let sol = run(method, dt);
            assert_eq!(sol.contacts.len(), 1, "{method:?} dt {dt:?}");
            let c = sol.contacts[0];
            let error = (c.duration / duration - 1.0).abs();
            assert!(error < tolerance, "{method:?} dt {dt:?}: error {error:.2e}");
            let peak = (c.max_indentation / deepest - 1.0).abs();
            assert!(
                peak < 10.0 * tolerance,
                "{method:?} dt {dt:?}: peak error {peak:.2e}"
            );
            let rebound = (c.restitution - 1.0).abs();
            assert!(
                rebound < 10.0 * tolerance,
                "{method:?} dt {dt:?}: restitution {}",
                c.restitution
            );
        }
        // Second order: ten times smaller step, a hundred times smaller error.
        let error = |dt| (run(newmark, Some(dt)).contacts[0].duration / duration - 1.0).abs();
        let slope = (error(1e-3) / error(1e-4)).log10();
        assert!((slope - 2.0).abs() < 0.2, "newmark-implicit slope {slope}");
    });
}
