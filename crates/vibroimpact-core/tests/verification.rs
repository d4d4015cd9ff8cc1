//! Verification of the two-mass runs (the preset on the general kernel)
//! against closed forms, conservation laws and the high-accuracy reference
//! values of the founding-paper page.

mod common;

use vibroimpact_core::model::closed_forms::{
    goldsmith_contact_duration, goldsmith_max_indentation,
};
use vibroimpact_core::{
    simulate, Contact, ContactTiming, ImpactDamper, LawKind, Method, Settings, State,
    SystemSolution,
};

const NEWMARK: Method = Method::Newmark {
    beta: 0.25,
    gamma: 0.5,
};

/// The Table 1 system, starting at contact onset with 0.1 m/s approach.
fn table1(
    stiffness: f64,
    damping: f64,
    c1: f64,
    law: LawKind,
    e: Option<f64>,
) -> (ImpactDamper, Contact, State) {
    (
        ImpactDamper::new(1.0, stiffness, damping, 0.25, 0.01).unwrap(),
        Contact::new(law, 3000.0, e, c1).unwrap(),
        State::new(0.0, 0.0, 0.01, 0.1).unwrap(),
    )
}

fn run(
    sys: (ImpactDamper, Contact, State),
    method: Method,
    dt: f64,
    t_end: f64,
    timing: ContactTiming,
) -> SystemSolution {
    // The paper's lagged Newmark creates energy at every contact, which is refused by
    // default (issue 7); these tests are about other properties.
    let loose = matches!(method, Method::Newmark { .. }).then_some(0.5);
    let settings = Settings::new(method, Some(dt), t_end, 1, timing, None, u64::MAX)
        .and_then(|s| s.with_limits(true, None, loose))
        .unwrap();
    simulate(&sys.0, &sys.1, &sys.2, &settings, &mut || false).unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn pure_hertz_matches_goldsmith() {
    common::timeout(60, || {
        let sys = table1(0.0, 0.0, 0.0, LawKind::Hertz, None);
        let sol = run(sys, Method::Rk4, 1e-5, 0.15, ContactTiming::Located);
        let c = sol.contacts[0];
        let tc = goldsmith_contact_duration(0.25, 1.0, 3000.0, 0.1, true).unwrap();
        let dmax = goldsmith_max_indentation(0.25, 1.0, 3000.0, 0.1).unwrap();
        assert!(rel(c.duration, tc) < 1e-9, "{} vs {tc}", c.duration);
        assert!(
            rel(c.max_indentation, dmax) < 1e-9,
            "{} vs {dmax}",
            c.max_indentation
        );
        assert!(rel(c.rebound_speed, 0.1) < 1e-9);
    });
}

#[test]
fn table1_collision_matches_the_reference_values() {
    common::timeout(60, || {
        // Reference page: Tc = 0.1089819 s, delta_max = 3.69668e-3 m, ratio 0.99635.
        for method in [Method::Rk4, NEWMARK] {
            let dt = if method == Method::Rk4 { 1e-4 } else { 2e-6 };
            let c = run(
                table1(1.0, 0.01, 0.01, LawKind::Hertz, None),
                method,
                dt,
                0.15,
                ContactTiming::Located,
            )
            .contacts[0];
            let tol = if method == Method::Rk4 { 1e-6 } else { 2e-4 };
            assert!(
                rel(c.duration, 0.1089819) < tol,
                "{method:?} {}",
                c.duration
            );
            assert!(
                rel(c.max_indentation, 3.69668e-3) < tol.max(2e-6),
                "{method:?} {}",
                c.max_indentation
            );
            assert!(
                (c.rebound_speed / c.approach_speed - 0.99635).abs() < 2e-5 + tol,
                "{method:?}"
            );
        }
        let c = run(
            table1(1.0, 0.01, 0.01, LawKind::HysterHertz, Some(0.9)),
            Method::Rk4,
            1e-4,
            0.15,
            ContactTiming::Located,
        )
        .contacts[0];
        assert!(rel(c.duration, 0.1100637) < 1e-6, "{}", c.duration);
        assert!(
            rel(c.max_indentation, 3.56654e-3) < 2e-6,
            "{}",
            c.max_indentation
        );
        assert!((c.rebound_speed / c.approach_speed - 0.90985).abs() < 1e-5);
    });
}

#[test]
fn newmark_converges_at_first_order_and_step_counting_quantises() {
    common::timeout(60, || {
        let mut errors = vec![];
        for dt in [1e-3, 1e-4, 1e-5] {
            let c = run(
                table1(1.0, 0.01, 0.01, LawKind::Hertz, None),
                NEWMARK,
                dt,
                0.15,
                ContactTiming::Located,
            )
            .contacts[0];
            errors.push(rel(c.duration, 0.1089819));
            let counted = run(
                table1(1.0, 0.01, 0.01, LawKind::Hertz, None),
                NEWMARK,
                dt,
                0.15,
                ContactTiming::StepCount,
            )
            .contacts[0];
            let steps = counted.duration / dt;
            assert!(
                (steps - steps.round()).abs() < 1e-6,
                "counted duration is a whole number of steps"
            );
        }
        // About 0.47 % at 1e-3 (reference page), then ten times less per decade.
        assert!((errors[0] - 4.7e-3).abs() < 0.3e-3, "{errors:?}");
        for pair in errors.windows(2) {
            let order = (pair[0] / pair[1]).log10();
            assert!((order - 1.0).abs() < 0.15, "{errors:?}");
        }
    });
}

#[test]
fn momentum_is_conserved_through_a_contact() {
    common::timeout(60, || {
        for law in [LawKind::Hertz, LawKind::HysterHertz, LawKind::Linear] {
            let e = (law == LawKind::HysterHertz).then_some(0.6);
            let sys = (
                ImpactDamper::new(1.0, 0.0, 0.0, 0.25, 0.01).unwrap(),
                Contact::new(law, 3000.0, e, 0.05).unwrap(),
                State::new(0.0, -0.02, 0.0, 0.1).unwrap(),
            );
            for method in [Method::Rk4, NEWMARK] {
                let sol = run(sys, method, 1e-4, 0.5, ContactTiming::Located);
                assert!(!sol.contacts.is_empty());
                let p0 = 1.0 * -0.02 + 0.25 * 0.1;
                // Rows [w, y, w', y'].
                for row in sol.states.chunks(4) {
                    let p = row[2] + 0.25 * row[3];
                    assert!((p - p0).abs() < 1e-15, "{law:?} {method:?}: {p} vs {p0}");
                }
            }
        }
    });
}

#[test]
fn energy_is_conserved_without_losses() {
    common::timeout(60, || {
        let sys = table1(1.0, 0.0, 0.0, LawKind::Hertz, None);
        // Kinetic, main spring and Hertz contact energy of a row [w, y, w', y'].
        let energy = |sol: &SystemSolution, i: usize| {
            let row = &sol.states[4 * i..4 * i + 4];
            let indentation = (row[1] - row[0]).abs() - 0.01;
            let contact = if indentation > 0.0 {
                0.4 * 3000.0 * indentation.powf(2.5)
            } else {
                0.0
            };
            0.5 * (row[2] * row[2] + 0.25 * row[3] * row[3] + row[0] * row[0]) + contact
        };
        let e0 = 0.5 * 0.25 * 0.1 * 0.1;
        let drift = |method, dt| {
            let sol = run(sys, method, dt, 3.0, ContactTiming::Located);
            assert!(sol.contacts.len() >= 3);
            (0..sol.time.len())
                .map(|i| (energy(&sol, i) / e0 - 1.0).abs())
                .fold(0.0, f64::max)
        };
        // RK4: fourth order, tiny drift; the paper's lagged Newmark: first order.
        let rk = [drift(Method::Rk4, 1e-4), drift(Method::Rk4, 1e-5)];
        // Second order only: a fixed step straddles each contact onset, where the
        // force is not smooth (event location is issue 3's work).
        assert!(
            rk[0] < 1e-7 && rk[1] < 1e-9 && rk[1] < rk[0] / 50.0,
            "{rk:?}"
        );
        let coarse = drift(NEWMARK, 1e-4);
        let fine = drift(NEWMARK, 1e-5);
        assert!(fine < 0.12 * coarse, "{coarse} {fine}");
        for c in run(sys, Method::Rk4, 1e-4, 3.0, ContactTiming::Located).contacts {
            assert!(c.energy_dissipated.abs() < 1e-15);
        }
    });
}

/// Solve `alpha (1 + e*) = ln((1 + alpha) / (1 - alpha e*))` for e* by bisection.
fn exact_rebound_ratio(alpha: f64) -> f64 {
    let f = |r: f64| alpha * (1.0 + r) - ((1.0 + alpha) / (1.0 - alpha * r)).ln();
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if f(mid) > 0.0 {
            lo = mid
        } else {
            hi = mid
        }
    }
    0.5 * (lo + hi)
}

#[test]
fn hyster_hertz_rebound_ratio_follows_the_exact_relation() {
    common::timeout(60, || {
        for e in [0.9, 0.5, 0.1] {
            let alpha: f64 = 0.75 * (1.0 - e * e);
            let sys = table1(0.0, 0.0, 0.0, LawKind::HysterHertz, Some(e));
            let c = run(sys, Method::Rk4, 1e-5, 0.3, ContactTiming::Located).contacts[0];
            let ratio = c.rebound_speed / c.approach_speed;
            let exact = exact_rebound_ratio(alpha);
            // Measured: 3e-12 at dt = 1e-5 s (the onset at t = 0, the
            // separation located on the step's Hermite cubic).
            assert!((ratio - exact).abs() < 1e-10, "e = {e}: {ratio} vs {exact}");
            // The energy the contact reports dissipating is the kinetic energy lost.
            let m_eff = 0.2;
            let lost = 0.5 * m_eff * (c.approach_speed.powi(2) - c.rebound_speed.powi(2));
            assert!(
                rel(c.energy_dissipated, lost) < 1e-9,
                "{} vs {lost}",
                c.energy_dissipated
            );
        }
        assert!((exact_rebound_ratio(0.75 * (1.0 - 0.81)) - 0.9132).abs() < 1e-4);
    });
}
