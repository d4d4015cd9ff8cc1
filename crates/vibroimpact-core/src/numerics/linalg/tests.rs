use super::*;

#[test]
fn a_dependent_row_first_keeps_the_independent_one() {
    crate::testing::timeout(60, || {
        // Both walls of a zero-clearance damper (rows h and -h) and a
        // second damper sticking: the forces must hold all three gaps.
        // Partial pivoting swapped the third row into the dependent
        // second's place and dropped it: forces [2.73, 0, 0].
        let w = [11.0, -11.0, 1.0, -11.0, 11.0, -1.0, 1.0, -1.0, 21.0];
        let x = [0.3, 0.0, -0.2];
        let rhs: Vec<f64> = (0..3)
            .map(|r| (0..3).map(|c| w[r * 3 + c] * x[c]).sum())
            .collect();
        let (mut a, mut b) = (w, rhs.clone());
        solve_in_place(&mut a, &mut b, 3);
        for r in 0..3 {
            let got: f64 = (0..3).map(|c| w[r * 3 + c] * b[c]).sum();
            assert!((got - rhs[r]).abs() < 1e-12, "row {r}: {got} vs {}", rhs[r]);
        }
        // A regular system: the solution itself.
        let w = [4.0, 1.0, 0.5, 1.0, 3.0, -1.0, 0.5, -1.0, 2.0];
        let rhs: Vec<f64> = (0..3)
            .map(|r| (0..3).map(|c| w[r * 3 + c] * x[c]).sum())
            .collect();
        let (mut a, mut b) = (w, rhs);
        solve_in_place(&mut a, &mut b, 3);
        for (got, want) in b.iter().zip(x) {
            assert!((got - want).abs() < 1e-14, "{got} vs {want}");
        }
    });
}

#[test]
fn eigenvalues_of_a_known_matrix() {
    crate::testing::timeout(60, || {
        // The second-difference matrix tridiag(-1, 2, -1) of size n has
        // eigenvalues 2 - 2 cos(k pi / (n + 1)), k = 1..n.
        let n = 7;
        let mut a = vec![0.0; n * n];
        for i in 0..n {
            a[i * n + i] = 2.0;
            if i + 1 < n {
                a[i * n + i + 1] = -1.0;
                a[(i + 1) * n + i] = -1.0;
            }
        }
        let (values, vectors) = symmetric_eigen(&a, n);
        for (k, v) in values.iter().enumerate() {
            // A v = lambda v for each column.
            for r in 0..n {
                let av: f64 = (0..n).map(|c| a[r * n + c] * vectors[c * n + k]).sum();
                assert!((av - v * vectors[r * n + k]).abs() < 1e-13);
            }
            let exact = 2.0 - 2.0 * ((k + 1) as f64 * std::f64::consts::PI / (n + 1) as f64).cos();
            assert!((v - exact).abs() < 1e-14, "{v} vs {exact}");
        }
        let l = cholesky(&a, n).expect("positive definite");
        let inverse = inverse_from_cholesky(&l, n);
        // A A^-1 = I.
        for i in 0..n {
            for j in 0..n {
                let p: f64 = (0..n).map(|k| a[i * n + k] * inverse[k * n + j]).sum();
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!((p - expected).abs() < 1e-13);
            }
        }
        // e^A of a rotation generator and of a Jordan block, in closed form.
        let (w, t) = (3.0, 2.5);
        let e = expm(&[0.0, w * t, -w * t, 0.0], 2);
        let (s, c) = (w * t).sin_cos();
        for (got, want) in e.iter().zip([c, s, -s, c]) {
            assert!((got - want).abs() < 1e-14, "{e:?}");
        }
        let e = expm(&[-2.0 * t, t, 0.0, -2.0 * t], 2);
        let d = (-2.0 * t).exp();
        for (got, want) in e.iter().zip([d, t * d, 0.0, d]) {
            assert!((got - want).abs() < 1e-15, "{e:?}");
        }
        // Singular (a free-free chain) and indefinite matrices have no factor.
        assert!(cholesky(&[1.0, -1.0, -1.0, 1.0], 2).is_none());
        assert!(cholesky(&[1.0, 2.0, 2.0, 1.0], 2).is_none());
    });
}
#[test]
fn eigenvalues_of_general_matrices() {
    crate::testing::timeout(60, || {
        let sorted = |mut v: Vec<(f64, f64)>| {
            v.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
            v
        };
        let close = |got: &[(f64, f64)], want: &[(f64, f64)], tol: f64| {
            assert_eq!(got.len(), want.len());
            for (g, w) in got.iter().zip(want) {
                assert!(
                    (g.0 - w.0).abs() < tol && (g.1 - w.1).abs() < tol,
                    "{got:?} vs {want:?}"
                );
            }
        };
        // A rotation scaled by r: r e^(+-i phi).
        let (r, phi) = (0.9f64, 0.7f64);
        let (c, s) = (r * phi.cos(), r * phi.sin());
        close(
            &sorted(eigenvalues(&[c, -s, s, c], 2).unwrap()),
            &[(c, -s), (c, s)],
            1e-15,
        );
        // The companion matrix of (x - 0.5)(x + 0.3)(x - 1.1)(x^2 - 0.4 x + 0.53):
        // roots 0.5, -0.3, 1.1 and 0.2 +- 0.7 i.
        let roots = [(0.5, 0.0), (-0.3, 0.0), (1.1, 0.0), (0.2, 0.7), (0.2, -0.7)];
        // Coefficients of the monic polynomial, highest first, by expansion.
        let mut poly: Vec<(f64, f64)> = vec![(1.0, 0.0)];
        for &(rr, ri) in &roots {
            let mut next = vec![(0.0, 0.0); poly.len() + 1];
            for (i, &(pr, pi)) in poly.iter().enumerate() {
                next[i].0 += pr;
                next[i].1 += pi;
                next[i + 1].0 -= pr * rr - pi * ri;
                next[i + 1].1 -= pr * ri + pi * rr;
            }
            poly = next;
        }
        let n = 5;
        let mut companion = vec![0.0; n * n];
        for j in 0..n {
            companion[j] = -poly[j + 1].0;
        }
        for i in 1..n {
            companion[i * n + i - 1] = 1.0;
        }
        close(
            &sorted(eigenvalues(&companion, n).unwrap()),
            &sorted(roots.to_vec()),
            1e-12,
        );
        // Any matrix: the eigenvalues sum to the trace, and (n = 3) their
        // product is the determinant.
        let m = [0.3, -1.2, 2.5, 0.7, 0.1, -0.4, -2.0, 1.5, 0.9];
        let e = eigenvalues(&m, 3).unwrap();
        let trace: f64 = e.iter().map(|v| v.0).sum();
        assert!((trace - (0.3 + 0.1 + 0.9)).abs() < 1e-13);
        assert!(e.iter().map(|v| v.1).sum::<f64>().abs() < 1e-13);
        let det = m[0] * (m[4] * m[8] - m[5] * m[7]) - m[1] * (m[3] * m[8] - m[5] * m[6])
            + m[2] * (m[3] * m[7] - m[4] * m[6]);
        let (mut pr, mut pi) = (1.0, 0.0);
        for (a, b) in &e {
            (pr, pi) = (pr * a - pi * b, pr * b + pi * a);
        }
        assert!(
            (pr - det).abs() < 1e-12 && pi.abs() < 1e-12,
            "{pr} {pi} vs {det}"
        );
        // Triangular: its diagonal. One by one: itself.
        close(
            &sorted(eigenvalues(&[2.0, 5.0, 7.0, 0.0, -1.0, 3.0, 0.0, 0.0, 0.5], 3).unwrap()),
            &[(-1.0, 0.0), (0.5, 0.0), (2.0, 0.0)],
            1e-14,
        );
        close(&eigenvalues(&[4.2], 1).unwrap(), &[(4.2, 0.0)], 1e-15);
    });
}
