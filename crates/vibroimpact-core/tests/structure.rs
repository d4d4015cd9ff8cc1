//! Structures of 0.2: the matrices are checked as the model requires, and
//! points, influence and energy are what the definitions give.

mod common;

use vibroimpact_core::structure::Structure;

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
