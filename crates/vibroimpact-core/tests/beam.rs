//! Cantilever modes against independent values: published roots, the
//! characteristic equation, orthonormality by a Gauss-Legendre quadrature
//! written here, the boundary conditions, the beam equation itself, and
//! `|phi(L)| = 2` for every mode up to 1000.

mod common;

use vibroimpact_core::model::beam::{
    cantilever_mode, cantilever_mode_shape, cantilever_mode_shape_derivatives, cantilever_root,
    CantileverShape,
};
use vibroimpact_core::Error;

const EPS: f64 = f64::EPSILON;
const PI: f64 = std::f64::consts::PI;

/// `cos x + 1 / cosh x`: the characteristic equation `cos x cosh x + 1 = 0`
/// divided by `cosh x`, written here from `e^-x` so that it never overflows.
fn characteristic(x: f64) -> f64 {
    let e = (-x).exp();
    x.cos() + 2.0 * e / (1.0 + e * e)
}

/// Nodes and weights of the `n`-point Gauss-Legendre rule on [-1, 1]
/// (Newton on the Legendre polynomial from Tricomi's first guess).
fn gauss_legendre(n: usize) -> Vec<(f64, f64)> {
    (1..=n)
        .map(|k| {
            let mut x = (PI * (k as f64 - 0.25) / (n as f64 + 0.5)).cos();
            let mut slope = 0.0;
            for _ in 0..100 {
                // P_n(x) and P_n'(x) by the three-term recurrence.
                let (mut p0, mut p1) = (1.0, x);
                for j in 2..=n {
                    let p2 = ((2 * j - 1) as f64 * x * p1 - (j - 1) as f64 * p0) / j as f64;
                    p0 = p1;
                    p1 = p2;
                }
                slope = n as f64 * (x * p1 - p0) / (x * x - 1.0);
                let step = p1 / slope;
                x -= step;
                if step.abs() < 1e-16 {
                    break;
                }
            }
            (x, 2.0 / ((1.0 - x * x) * slope * slope))
        })
        .collect()
}

/// Points and weights of a composite 20-point Gauss-Legendre rule on [0, 1]
/// with `panels` panels: exact for polynomials of degree 39 on each panel.
fn quadrature(panels: usize) -> Vec<(f64, f64)> {
    let rule = gauss_legendre(20);
    let h = 1.0 / panels as f64;
    (0..panels)
        .flat_map(|p| {
            let mid = (p as f64 + 0.5) * h;
            rule.iter()
                .map(move |&(x, w)| (mid + 0.5 * h * x, 0.5 * h * w))
        })
        .collect()
}

#[test]
fn the_quadrature_is_exact_on_known_integrals() {
    common::timeout(60, || {
        // int_0^1 x^38 dx = 1/39 on one panel, and int_0^1 sin(200 x)^2 dx.
        let one = quadrature(1);
        let sum: f64 = one.iter().map(|&(x, w)| w * x.powi(38)).sum();
        assert!((sum - 1.0 / 39.0).abs() < 1e-15, "{sum}");
        let many = quadrature(64);
        let sum: f64 = many
            .iter()
            .map(|&(x, w)| w * (200.0 * x).sin().powi(2))
            .sum();
        let exact = 0.5 - (400.0_f64).sin() / 800.0;
        assert!((sum - exact).abs() < 1e-14, "{sum} vs {exact}");
    });
}

#[test]
fn first_roots_match_the_published_values() {
    common::timeout(60, || {
        // b_i L of a cantilever to 16 digits (e.g. Blevins, Formulas for Natural
        // Frequency and Mode Shape, table 8-1).
        let published = [
            1.875104068711961,
            4.694091132974175,
            7.854757438237613,
            10.99554073487547,
            14.13716839104647,
        ];
        for (i, &expected) in published.iter().enumerate() {
            let root = cantilever_root(i as u32 + 1).unwrap();
            assert!(
                (root - expected).abs() <= 2e-15 * expected,
                "mode {}: {root:.17} vs {expected}",
                i + 1
            );
        }
    });
}

#[test]
fn roots_solve_the_characteristic_equation_to_round_off() {
    common::timeout(60, || {
        for mode in (1..=2000).chain([10_000, 1_000_000, u32::MAX]) {
            let root = cantilever_root(mode).unwrap();
            // In (2i - 1) pi / 2 +- pi / 2: the i-th root, not a neighbour.
            let centre = (2.0 * f64::from(mode) - 1.0) * PI / 2.0;
            assert!((root - centre).abs() < PI / 2.0, "mode {mode}: {root}");
            // The residual is that of a round-off change of the root (slope ~ 1).
            assert!(
                characteristic(root).abs() <= 4.0 * EPS * root,
                "mode {mode}: residual {:e}",
                characteristic(root)
            );
            // A sign change within a few units in the last place on either side
            // (the function's own round-off is far below that slope * ulp).
            if mode <= 2000 {
                let ulp = EPS * root;
                let (below, above) = (
                    characteristic(root - 4.0 * ulp),
                    characteristic(root + 4.0 * ulp),
                );
                assert!(below * above < 0.0, "mode {mode}: {below:e} {above:e}");
            }
        }
    });
}

#[test]
fn roots_follow_the_asymptote_and_their_spacing_tends_to_pi() {
    common::timeout(60, || {
        // cos x = -1/cosh x near x_i = (2i - 1) pi / 2 gives
        // b_i L = x_i + (-1)^(i+1) / cosh x_i + O(1/cosh^2 x_i).
        for mode in 3..=12_u32 {
            let x = (2.0 * f64::from(mode) - 1.0) * PI / 2.0;
            let offset = cantilever_root(mode).unwrap() - x;
            let first_order = if mode % 2 == 1 { 1.0 } else { -1.0 } / x.cosh();
            let err = (offset - first_order).abs();
            assert!(
                err <= 4.0 * first_order * first_order + 4.0 * EPS * x,
                "mode {mode}: offset {offset:e}, first order {first_order:e}"
            );
        }
        let mut previous = cantilever_root(1).unwrap();
        for mode in 2..=1000_u32 {
            let root = cantilever_root(mode).unwrap();
            let x = (2.0 * f64::from(mode) - 3.0) * PI / 2.0;
            let spacing_error = (root - previous - PI).abs();
            assert!(
                spacing_error <= 2.5 / x.cosh() + 8.0 * EPS * root,
                "modes {} and {mode}: spacing {}",
                mode - 1,
                root - previous
            );
            previous = root;
        }
    });
}

#[test]
fn tip_value_is_two_for_every_mode_up_to_1000() {
    common::timeout(60, || {
        for mode in 1..=1000_u32 {
            let tip = cantilever_mode_shape(1.0, mode, 1.0).unwrap();
            let expected = if mode % 2 == 1 { 2.0 } else { -2.0 };
            assert!(
                (tip - expected).abs() <= 1e-14 + 16.0 * EPS * f64::from(mode),
                "mode {mode}: tip {tip}"
            );
        }
    });
}

/// `phi_i` at the quadrature points.
fn samples(mode: u32, points: &[(f64, f64)]) -> Vec<f64> {
    let shape = CantileverShape::new(mode).unwrap();
    points
        .iter()
        .map(|&(x, _)| shape.value(x).unwrap())
        .collect()
}

#[test]
fn modes_up_to_40_are_orthonormal() {
    common::timeout(60, || {
        // Mode 40 has 40 half-waves; 64 panels of 20 points resolve it to round-off.
        let points = quadrature(64);
        let shapes: Vec<Vec<f64>> = (1..=40).map(|mode| samples(mode, &points)).collect();
        for (i, a) in shapes.iter().enumerate() {
            for (j, b) in shapes.iter().enumerate().skip(i) {
                let integral: f64 = points
                    .iter()
                    .zip(a.iter().zip(b))
                    .map(|(&(_, w), (p, q))| w * p * q)
                    .sum();
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!(
                    (integral - expected).abs() < 1e-13,
                    "modes {} and {}: {integral:e}",
                    i + 1,
                    j + 1
                );
            }
        }
    });
}

#[test]
fn modes_227_and_1000_are_finite_and_orthonormal() {
    common::timeout(60, || {
        // 1024 panels: at least 2 panels per half-wave of mode 1000.
        let points = quadrature(1024);
        for (i, j) in [
            (227, 227),
            (226, 227),
            (227, 228),
            (1000, 1000),
            (999, 1000),
            (1, 1000),
        ] {
            let (a, b) = (samples(i, &points), samples(j, &points));
            assert!(a.iter().chain(&b).all(|v| v.is_finite()));
            let integral: f64 = points
                .iter()
                .zip(a.iter().zip(&b))
                .map(|(&(_, w), (p, q))| w * p * q)
                .sum();
            let expected = if i == j { 1.0 } else { 0.0 };
            assert!(
                (integral - expected).abs() < 1e-12,
                "modes {i} and {j}: {integral:e}"
            );
        }
    });
}

#[test]
fn boundary_conditions_hold_for_modes_up_to_1000() {
    common::timeout(60, || {
        // phi(0) = phi'(0) = 0 at the clamp, phi''(L) = phi'''(L) = 0 at the free
        // end; the k-th derivative is of order (b L / L)^k, the scale of its error.
        let length = 1.7;
        for mode in 1..=1000_u32 {
            let b = cantilever_root(mode).unwrap() / length;
            let clamp = cantilever_mode_shape_derivatives(length, mode, 0.0).unwrap();
            let tip = cantilever_mode_shape_derivatives(length, mode, length).unwrap();
            let tolerance = 32.0 * EPS * f64::from(mode);
            assert!(
                clamp[0].abs() <= tolerance,
                "mode {mode}: phi(0) {}",
                clamp[0]
            );
            assert!(
                clamp[1].abs() / b <= tolerance,
                "mode {mode}: phi'(0) {}",
                clamp[1]
            );
            assert!(
                tip[2].abs() / b.powi(2) <= tolerance,
                "mode {mode}: phi''(L) {}",
                tip[2]
            );
            assert!(
                tip[3].abs() / b.powi(3) <= tolerance,
                "mode {mode}: phi'''(L) {}",
                tip[3]
            );
            // Not vacuous: the same derivatives are of order one (scaled) elsewhere.
            assert!(clamp[2].abs() / b.powi(2) > 1.0 && tip[1].abs() / b > 1.0);
        }
    });
}

/// Central difference of `f` at `x` with step `h`, fourth order.
fn derivative(f: impl Fn(f64) -> f64, x: f64, h: f64) -> f64 {
    (8.0 * (f(x + h) - f(x - h)) - (f(x + 2.0 * h) - f(x - 2.0 * h))) / (12.0 * h)
}

#[test]
fn derivatives_are_those_of_the_shape_and_it_solves_the_beam_equation() {
    common::timeout(60, || {
        // Each analytic derivative against a finite difference of the one below,
        // and the Euler-Bernoulli equation phi'''' = b^4 phi from the third.
        let length = 0.8;
        for mode in [1, 2, 5, 13, 30, 227] {
            let b = cantilever_root(mode).unwrap() / length;
            let h = 1e-3 / b;
            let d = |x: f64| cantilever_mode_shape_derivatives(length, mode, x).unwrap();
            for k in 1..=19 {
                let x = length * k as f64 / 20.0;
                let here = d(x);
                for order in 0..3 {
                    let fd = derivative(|y| d(y)[order], x, h);
                    let scale = b.powi(order as i32 + 1);
                    assert!(
                        (fd - here[order + 1]).abs() <= 1e-8 * scale,
                        "mode {mode}, x {x}, derivative {}: {fd} vs {}",
                        order + 1,
                        here[order + 1]
                    );
                }
                let fourth = derivative(|y| d(y)[3], x, h);
                assert!(
                    (fourth - b.powi(4) * here[0]).abs() <= 1e-8 * b.powi(4),
                    "mode {mode}, x {x}: phi'''' {fourth} vs b^4 phi {}",
                    b.powi(4) * here[0]
                );
            }
        }
    });
}

#[test]
fn a_mode_referred_to_its_tip_is_a_quarter_of_its_modal_values() {
    common::timeout(60, || {
        let (length, e, i, rho, area) = (0.7, 2.1e11, 3.0e-10, 7800.0, 1.2e-4);
        for mode in 1..=30 {
            let beam = cantilever_mode(length, e, i, rho, area, mode, None).unwrap();
            let b = cantilever_root(mode).unwrap();
            let k = b.powi(4) * e * i / length.powi(3);
            assert!((beam.modal_stiffness / k - 1.0).abs() < 1e-14);
            assert!((beam.modal_mass / (rho * area * length) - 1.0).abs() < 1e-15);
            // omega_i = (b_i L)^2 sqrt(E I / (rho A L^4)).
            let omega = b * b * (e * i / (rho * area * length.powi(4))).sqrt();
            assert!((beam.angular_frequency / omega - 1.0).abs() < 1e-14);
            assert!(
                (beam.shape_at_position.abs() - 2.0).abs() < 1e-13,
                "mode {mode}"
            );
            assert!((beam.stiffness_at_position / (k / 4.0) - 1.0).abs() < 1e-13);
            assert!((beam.mass_at_position / (rho * area * length / 4.0) - 1.0).abs() < 1e-13);
        }
    });
}

#[test]
fn a_mode_at_an_inner_position_uses_the_shape_there() {
    common::timeout(60, || {
        let beam = cantilever_mode(2.0, 1.0, 1.0, 1.0, 1.0, 7, Some(0.3)).unwrap();
        let phi = cantilever_mode_shape(2.0, 7, 0.3).unwrap();
        assert_eq!(beam.shape_at_position, phi);
        assert!(
            (beam.stiffness_at_position * phi * phi / beam.modal_stiffness - 1.0).abs() < 1e-15
        );
        assert!((beam.mass_at_position * phi * phi / beam.modal_mass - 1.0).abs() < 1e-15);
    });
}

#[test]
fn the_first_modes_tip_stiffness_is_near_the_static_one() {
    common::timeout(60, || {
        // K_tip = (b_1 L)^4 / 4 EI/L^3 = 3.0906 EI/L^3, 3 % above the static 3 EI/L^3.
        let beam = cantilever_mode(1.0, 1.0, 1.0, 1.0, 1.0, 1, None).unwrap();
        assert!((beam.stiffness_at_position - 3.0906).abs() < 5e-5);
        assert!((beam.mass_at_position - 0.25).abs() < 1e-15);
    });
}

fn field(err: Error) -> String {
    match err {
        Error::InvalidParameter { field, .. } => field.to_string(),
        other => panic!("expected an invalid parameter, got {other}"),
    }
}

#[test]
fn bad_inputs_name_their_field() {
    common::timeout(60, || {
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, 0.0, -1.0] {
            let ok = 1.0;
            let mode = |l, e, i, r, a| cantilever_mode(l, e, i, r, a, 1, None).unwrap_err();
            assert_eq!(field(mode(bad, ok, ok, ok, ok)), "length");
            assert_eq!(field(mode(ok, bad, ok, ok, ok)), "youngs_modulus");
            assert_eq!(field(mode(ok, ok, bad, ok, ok)), "second_moment");
            assert_eq!(field(mode(ok, ok, ok, bad, ok)), "density");
            assert_eq!(field(mode(ok, ok, ok, ok, bad)), "area");
            let at = cantilever_mode(ok, ok, ok, ok, ok, 1, Some(bad)).unwrap_err();
            assert_eq!(field(at), "position");
            assert_eq!(
                field(cantilever_mode_shape(bad, 1, 0.5).unwrap_err()),
                "length"
            );
        }
        // 0 is the clamp, a valid point.
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -1e-12, 1.5] {
            assert_eq!(field(cantilever_mode_shape(1.0, 1, bad).unwrap_err()), "x");
            let shape = CantileverShape::new(1).unwrap();
            assert_eq!(field(shape.value(bad).unwrap_err()), "xi");
        }
        assert_eq!(
            field(cantilever_mode_shape(1.0, 1, 1.0 + 1e-12).unwrap_err()),
            "x"
        );
        assert_eq!(field(cantilever_root(0).unwrap_err()), "mode");
        assert_eq!(field(CantileverShape::new(0).unwrap_err()), "mode");
    });
}

#[test]
fn results_out_of_floating_point_range_are_errors() {
    common::timeout(60, || {
        // (b L)^4 E I / L^3 overflows; a unit-length beam 1e-200 m long has
        // derivatives of 1e600 1/m^3.
        let err = cantilever_mode(1.0, 1e300, 1e300, 1.0, 1.0, 1, None).unwrap_err();
        assert!(err.to_string().contains("modal stiffness"), "{err}");
        let err = cantilever_mode(1.0, 1.0, 1.0, 1e-200, 1e-200, 1, None).unwrap_err();
        assert!(err.to_string().contains("modal mass"), "{err}");
        let err = cantilever_mode_shape_derivatives(1e-200, 1, 0.5e-200).unwrap_err();
        assert!(err.to_string().contains("length"), "{err}");
    });
}
