//! Structures of 0.2: the matrices are checked as the model requires, and
//! points, influence and energy are what the definitions give.

mod common;

use vibroimpact_core::model::structure::Structure;

fn rows(flat: &[f64], n: usize) -> Vec<Vec<f64>> {
    flat.chunks(n).map(<[f64]>::to_vec).collect()
}

#[test]
fn two_mass_chain_is_accepted_and_its_energy_is_the_quadratic_forms() {
    common::timeout(10, || {
        // m1 = 2, m2 = 1; springs k1 = 3 (to ground), k2 = 1 between them.
        let m = rows(&[2.0, 0.0, 0.0, 1.0], 2);
        let k = rows(&[4.0, -1.0, -1.0, 1.0], 2);
        let c = rows(&[0.0; 4], 2);
        let s = Structure::matrices(&m, &k, &c).unwrap();
        assert_eq!(s.dofs(), 2);
        assert_eq!(s.influence(), &[1.0, 1.0]);
        // E = 1/2 (2 v1^2 + v2^2) + 1/2 (3 q1^2 + (q2 - q1)^2).
        let (q, v) = ([0.1, -0.2], [0.5, 0.25]);
        let exact = 0.5 * (2.0 * 0.25 + 0.0625) + 0.5 * (3.0 * 0.01 + 0.09);
        assert!((s.energy(&q, &v) - exact).abs() < 1e-15);
        assert_eq!(s.point("at", 1.0).unwrap(), vec![0.0, 1.0]);
    });
}

#[test]
fn bad_matrices_are_refused_naming_the_key() {
    common::timeout(10, || {
        let error = |m: &[f64], k: &[f64], c: &[f64], n: usize| {
            Structure::matrices(&rows(m, n), &rows(k, n), &rows(c, n))
                .unwrap_err()
                .to_string()
        };
        let eye = [1.0, 0.0, 0.0, 1.0];
        let zero = [0.0; 4];
        let e = error(&[1.0, 0.5, 0.4, 1.0], &eye, &zero, 2);
        assert!(
            e.contains("structure.mass must be symmetric") && e.contains("[0][1]"),
            "{e}"
        );
        // Symmetric but indefinite (eigenvalues 3 and -1), and singular.
        let e = error(&[1.0, 2.0, 2.0, 1.0], &eye, &zero, 2);
        assert!(
            e.contains("structure.mass must be positive definite"),
            "{e}"
        );
        assert!(error(&[1.0, 1.0, 1.0, 1.0], &eye, &zero, 2).contains("positive definite"));
        // A stiffness with eigenvalue -1 gains energy.
        let e = error(&eye, &[0.0, 1.0, 1.0, 0.0], &zero, 2);
        assert!(
            e.contains("structure.stiffness must be positive semi-definite"),
            "{e}"
        );
        assert!(e.contains("-1.0"), "{e}");
        let e = error(&eye, &zero, &[1.0, 0.0, 0.0, -1e-3], 2);
        assert!(
            e.contains("structure.damping must be positive semi-definite"),
            "{e}"
        );
        // A free-free chain's stiffness is singular but semi-definite: fine.
        Structure::matrices(
            &rows(&eye, 2),
            &rows(&[1.0, -1.0, -1.0, 1.0], 2),
            &rows(&zero, 2),
        )
        .unwrap();
        let e = error(&[1.0, 0.0, 0.0, f64::NAN], &eye, &zero, 2);
        assert!(
            e.contains("structure.mass must be finite") && e.contains("[1][1]"),
            "{e}"
        );
        let ragged = vec![vec![1.0, 0.0], vec![0.0]];
        let e = Structure::matrices(&rows(&eye, 2), &ragged, &rows(&zero, 2)).unwrap_err();
        assert!(
            e.to_string().contains("structure.stiffness must be 2 x 2"),
            "{e}"
        );
        assert!(Structure::matrices(&[], &[], &[]).is_err());
    });
}

#[test]
fn points_outside_the_structure_are_refused() {
    common::timeout(10, || {
        let s = Structure::oscillator(1.0, 10.0, 0.1).unwrap();
        assert_eq!(s.point("damper 0 at", 0.0).unwrap(), vec![1.0]);
        for at in [1.0, -1.0, 0.5, f64::NAN] {
            let e = s.point("damper 0 at", at).unwrap_err().to_string();
            assert!(
                e.starts_with("damper 0 at must be a coordinate index"),
                "{e}"
            );
        }
        assert!(Structure::oscillator(0.0, 1.0, 0.0).is_err());
        assert!(Structure::oscillator(1.0, -1.0, 0.0).is_err());
    });
}

#[test]
fn matrices_frequencies_are_the_generalised_eigenvalues() {
    common::timeout(10, || {
        // m1 = 2, m2 = 1, k1 = 3, k2 = 1: det(K - w^2 M) = 0 gives
        // 2 w^4 - 6 w^2 + 3 = 0, w^2 = (3 -+ sqrt 3) / 2.
        let m = rows(&[2.0, 0.0, 0.0, 1.0], 2);
        let k = rows(&[4.0, -1.0, -1.0, 1.0], 2);
        let s = Structure::matrices(&m, &k, &rows(&[0.0; 4], 2)).unwrap();
        let w = s.natural_frequencies();
        let exact = [
            ((3.0 - 3f64.sqrt()) / 2.0).sqrt(),
            ((3.0 + 3f64.sqrt()) / 2.0).sqrt(),
        ];
        for (a, b) in w.iter().zip(exact) {
            assert!((a - b).abs() < 1e-14, "{a} vs {b}");
        }
    });
}

/// A steel strip 0.3 m long, 20 mm x 2 mm: E 200 GPa, I = b h^3 / 12, rho A.
const BEAM: (f64, f64, f64, f64) = (0.3, 2.0e11, 0.02 * 8e-9 / 12.0, 7850.0 * 0.02 * 0.002);

#[test]
fn cantilever_frequencies_match_the_roots_of_its_frequency_equation() {
    common::timeout(20, || {
        let (length, e, i, rho_a) = BEAM;
        let s = Structure::cantilever(length, e, i, rho_a, 30, 0.0).unwrap();
        let w = s.natural_frequencies();
        // omega_i = (b_i L)^2 sqrt(E I / (rho A L^4)) with b_i L the roots of
        // cos x cosh x + 1 = 0, found here independently by bisection on
        // cos x + 1 / cosh x in [(i - 1/2) pi - 1, (i - 1/2) pi + 1].
        let scale = (e * i / (rho_a * length.powi(4))).sqrt();
        for (mode, omega) in w.iter().enumerate() {
            let f = |x: f64| x.cos() + 1.0 / x.cosh();
            let centre = (mode as f64 + 0.5) * std::f64::consts::PI;
            let (mut lo, mut hi) = ((centre - 1.0).max(0.5), centre + 1.0);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if (f(mid) > 0.0) == (f(lo) > 0.0) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let exact = (0.5 * (lo + hi)).powi(2) * scale;
            assert!(
                (omega / exact - 1.0).abs() < 1e-10,
                "mode {}: {omega} vs {exact}",
                mode + 1
            );
        }
        // The first root: 1.875104068711961 (Blevins, Formulas for natural
        // frequency and mode shape, table 8-1).
        assert!((w[0] / scale - 1.875104068711961f64.powi(2)).abs() < 1e-12 * w[0] / scale);
    });
}

#[test]
fn cantilever_static_tip_deflection_converges_to_p_l3_over_3_e_i() {
    common::timeout(20, || {
        // K q = h^T P with h the shapes at the tip: tip = sum h_i^2 P / K_ii.
        let (length, e, i, rho_a) = BEAM;
        let exact = length.powi(3) / (3.0 * e * i);
        let mut last_error = f64::INFINITY;
        for modes in [1, 2, 5, 10, 30] {
            let s = Structure::cantilever(length, e, i, rho_a, modes, 0.02).unwrap();
            let h = s.point("force at", length).unwrap();
            let n = s.dofs();
            let tip: f64 = (0..n).map(|k| h[k] * h[k] / s.stiffness()[k * n + k]).sum();
            let error = (tip / exact - 1.0).abs();
            assert!(error < last_error, "{modes} modes: {error}");
            last_error = error;
        }
        // The tail of sum 4 / (b_i L)^4 = 1/3 beyond 30 modes is about 1.6e-6.
        assert!(last_error < 3e-6, "{last_error}");
    });
}

#[test]
fn cantilever_influence_is_the_mean_of_each_shape() {
    common::timeout(20, || {
        // r_i = (1/L) int_0^L phi_i dx by composite Simpson on 20000
        // panels (independent of the closed form 2 sigma / bL).
        let (length, e, i, rho_a) = BEAM;
        let s = Structure::cantilever(length, e, i, rho_a, 12, 0.0).unwrap();
        let panels = 20_000;
        let h = length / panels as f64;
        let mut integral = vec![0.0; s.dofs()];
        for k in 0..=panels {
            let w = if k == 0 || k == panels {
                1.0
            } else if k % 2 == 1 {
                4.0
            } else {
                2.0
            };
            let row = s.point("x", (k as f64 * h).min(length)).unwrap();
            for (acc, v) in integral.iter_mut().zip(row) {
                *acc += w * v * h / 3.0;
            }
        }
        for (r, int) in s.influence().iter().zip(integral) {
            assert!((r - int / length).abs() < 1e-10, "{r} vs {}", int / length);
        }
        // Modal damping: C_ii = 2 zeta omega_i M_ii.
        let damped = Structure::cantilever(length, e, i, rho_a, 3, 0.05).unwrap();
        let w = damped.natural_frequencies();
        for (k, omega) in w.iter().enumerate() {
            let c = damped.damping()[k * 3 + k];
            assert!((c - 2.0 * 0.05 * omega * rho_a * length).abs() < 1e-12 * c);
        }
        let outside = damped.point("damper 0 at", 0.31).unwrap_err().to_string();
        assert!(
            outside.contains("position along the beam in [0, 0.3]"),
            "{outside}"
        );
        assert!(Structure::cantilever(length, e, i, rho_a, 0, 0.0).is_err());
    });
}
