//! What a run records never changes the run: the kernel's probes inside a
//! kept step (the deepest indentation of a compliant contact) leave the
//! method's own solution as it is.

mod common;

use vibroimpact_core::methods::registry::{AnyStepper, Options};
use vibroimpact_core::{
    Contact, ContactTiming, ImpactDamper, LawKind, Method, Settings, State, Stepping,
};

/// Table 1 (M = 1 kg, K = 1 N/m, C = 0.01 N s/m, m = 0.25 kg, d = 0.01 m,
/// Hertz 3000 N/m^1.5, c1 = 0.01 N s/m), starting at contact onset.
const MAIN: (f64, f64, f64) = (1.0, 1.0, 0.01);
const IMPACT_MASS: f64 = 0.25;
const CLEARANCE: f64 = 0.01;
const HERTZ: f64 = 3000.0;
const C1: f64 = 0.01;

/// Accelerations `[w'', y'']` of the Table 1 system in contact at
/// `x = [w, y]`, `v = [w', y']`, and their slopes: `(a, da/dx, da/dv)`.
fn accelerations(x: [f64; 2], v: [f64; 2]) -> ([f64; 2], [[f64; 2]; 2], [[f64; 2]; 2]) {
    let (m_main, k, c) = MAIN;
    let indentation = x[1] - x[0] - CLEARANCE;
    let rate = v[1] - v[0];
    let (force, by_indentation) = if indentation > 0.0 {
        let root = indentation.sqrt();
        (HERTZ * indentation * root + C1 * rate, 1.5 * HERTZ * root)
    } else {
        (C1 * rate, 0.0)
    };
    let a = [
        (-k * x[0] - c * v[0] + force) / m_main,
        -force / IMPACT_MASS,
    ];
    // d(force)/dx = by_indentation * [-1, 1]; d(force)/dv = C1 * [-1, 1].
    let dadx = [
        [(-k - by_indentation) / m_main, by_indentation / m_main],
        [by_indentation / IMPACT_MASS, -by_indentation / IMPACT_MASS],
    ];
    let dadv = [
        [(-c - C1) / m_main, C1 / m_main],
        [C1 / IMPACT_MASS, -C1 / IMPACT_MASS],
    ];
    (a, dadx, dadv)
}

/// Chung-Hulbert generalised-alpha with spectral radius `rho`, written out
/// for this system alone: `(1 - am) a1 + am a0 = A((1 - af) x1 + af x0,
/// (1 - af) v1 + af v0)`, Newton to round-off; the accelerations carried
/// from step to step, physical only at the start. The states `[w, y, w',
/// y']` after each of `steps` steps of `h`.
fn generalized_alpha(rho: f64, h: f64, start: [f64; 4], steps: usize) -> Vec<[f64; 4]> {
    let am = (2.0 * rho - 1.0) / (rho + 1.0);
    let af = rho / (rho + 1.0);
    let gamma = 0.5 - am + af;
    let beta = 0.25 * (1.0 - am + af).powi(2);
    let (mut x, mut v) = ([start[0], start[1]], [start[2], start[3]]);
    let mut a0 = accelerations(x, v).0;
    let mut rows = Vec::with_capacity(steps);
    for _ in 0..steps {
        let new = |a1: [f64; 2]| {
            let x1: [f64; 2] = std::array::from_fn(|i| {
                x[i] + h * v[i] + h * h * ((0.5 - beta) * a0[i] + beta * a1[i])
            });
            let v1: [f64; 2] =
                std::array::from_fn(|i| v[i] + h * ((1.0 - gamma) * a0[i] + gamma * a1[i]));
            (x1, v1)
        };
        let mut a1 = a0;
        for _ in 0..50 {
            let (x1, v1) = new(a1);
            let xm = std::array::from_fn(|i| (1.0 - af) * x1[i] + af * x[i]);
            let vm = std::array::from_fn(|i| (1.0 - af) * v1[i] + af * v[i]);
            let (a, dadx, dadv) = accelerations(xm, vm);
            let r: [f64; 2] = std::array::from_fn(|i| (1.0 - am) * a1[i] + am * a0[i] - a[i]);
            let j: [[f64; 2]; 2] = std::array::from_fn(|i| {
                std::array::from_fn(|k| {
                    let identity = if i == k { 1.0 - am } else { 0.0 };
                    identity - (1.0 - af) * (beta * h * h * dadx[i][k] + gamma * h * dadv[i][k])
                })
            });
            let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
            let d0 = -(j[1][1] * r[0] - j[0][1] * r[1]) / det;
            let d1 = -(-j[1][0] * r[0] + j[0][0] * r[1]) / det;
            a1 = [a1[0] + d0, a1[1] + d1];
            if d0.abs().max(d1.abs()) <= 1e-15 * a1[0].abs().max(a1[1].abs()) {
                break;
            }
        }
        let (x1, v1) = new(a1);
        (x, v, a0) = (x1, v1, a1);
        rows.push([x[0], x[1], v[0], v[1]]);
    }
    rows
}

#[test]
fn generalized_alpha_keeps_its_accelerations_through_the_deepest_indentation() {
    common::timeout(60, || {
        // The kernel locates each contact's deepest indentation by probing
        // inside the step that passes it. Generalised-alpha carries
        // algorithmic accelerations from step to step: restarting it from
        // the physical ones after the probe moved the run by 2.2e-7 m at
        // the next step (dt = 4e-3 s) and its contact's duration by 4.4e-7
        // relative (`vibroimpact paper`'s Table 2).
        let (h, rho) = (4e-3, 0.9);
        let system = ImpactDamper::new(MAIN.0, MAIN.1, MAIN.2, IMPACT_MASS, CLEARANCE).unwrap();
        let contact = Contact::new(LawKind::Hertz, HERTZ, None, C1).unwrap();
        let start = State::new(0.0, 0.0, CLEARANCE, 0.1).unwrap();
        let settings = Settings::new(
            Method::GeneralizedAlpha {
                spectral_radius: rho,
            },
            Some(h),
            0.1,
            1,
            ContactTiming::Located,
            Some(Stepping::Events),
            100_000,
        )
        .unwrap();
        // The two-mass preset on the general kernel.
        let assembly = system.assembly(&contact).unwrap();
        let y0 = start.vector(&assembly).unwrap();
        let options = Options {
            spectral_radius: rho,
            ..Options::default()
        };
        let mut stepper = AnyStepper::new(&assembly, "generalized-alpha", &options).unwrap();
        let sol = stepper
            .integrate_stepped(
                &assembly,
                &y0,
                &settings.run_options(),
                settings.kernel_stepping(),
                &mut || false,
            )
            .unwrap();
        let expected = generalized_alpha(rho, h, [0.0, CLEARANCE, 0.0, 0.1], 24);
        // The rows on the grid (the run starts at the wall: an onset at
        // t = 0 to round-off is kept as a row of its own).
        let on_grid: Vec<(f64, &[f64])> = sol
            .time
            .iter()
            .zip(sol.states.chunks(4))
            .filter(|(t, _)| **t > 1e-12)
            .map(|(t, s)| (*t, s))
            .collect();
        assert!(on_grid.len() >= expected.len(), "{} rows", on_grid.len());
        let mut passed_the_turn = false;
        for (k, ((t, row), want)) in on_grid.iter().zip(&expected).enumerate() {
            assert!((t - (k + 1) as f64 * h).abs() < 1e-15, "row {k} at t = {t}");
            passed_the_turn |= want[3] - want[2] < 0.0;
            let off = row.iter().zip(want).map(|(a, b)| (a - b).abs());
            assert!(
                off.fold(0.0, f64::max) < 1e-14,
                "t = {t}: {row:?} against generalised-alpha's own {want:?}"
            );
        }
        assert!(passed_the_turn);
    });
}
