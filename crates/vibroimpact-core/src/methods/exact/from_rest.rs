//! The response from rest of an underdamped mode to `e^(i omega t)`, for the
//! harmonics that force a mode near its undamped resonance.
//!
//! The flow otherwise writes a mode's motion as its particular response
//! `Re(Z u)`, `Z = P / (w2 - omega^2 + i c omega)`, plus a free response that
//! starts from the state less that particular one: near resonance both are of
//! the size of `Z` (1.2e4 m for a 1 Hz mode forced 1e-5 off its frequency)
//! and cancel to the motion, keeping the round-off of `Z` (eps |Z|, 3e-12 m a
//! step, which a low-speed impact turns into 1e-7 s of timing). Taken
//! together, the particular response less its free evolution is `Re(P u0
//! G(t))`, where `G'' + c G' + w2 G = e^(i omega t)`, `G(0) = G'(0) = 0`:
//! the second divided difference of `e^(s t)` over `i omega`, `lambda+` and
//! `lambda-` (`-sigma +- i w_d`), written with `phi1(z) = (e^z - 1) / z` so
//! that the close pair `i omega`, `lambda+` divides nothing small.

/// A complex number as `(re, im)`.
pub(super) type Complex = (f64, f64);

#[inline(always)]
fn mul(a: Complex, b: Complex) -> Complex {
    (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0)
}

#[inline(always)]
fn div(a: Complex, b: Complex) -> Complex {
    let norm = b.0 * b.0 + b.1 * b.1;
    (
        (a.0 * b.0 + a.1 * b.1) / norm,
        (a.1 * b.0 - a.0 * b.1) / norm,
    )
}

/// `(e^z - 1) / z`: by its series for small `|z|` (to 1e-17), else directly.
fn phi1(z: Complex) -> Complex {
    let size = z.0.hypot(z.1);
    if size < 0.5 {
        // 1 + z/2 (1 + z/3 (1 + ... (1 + z/18))): to z^17 / 18! (< 1e-21).
        let mut sum = (1.0, 0.0);
        for k in (2..=18).rev() {
            let term = mul(sum, z);
            sum = (1.0 + term.0 / k as f64, term.1 / k as f64);
        }
        sum
    } else {
        let scale = z.0.exp();
        let (s, c) = z.1.sin_cos();
        div((scale * c - 1.0, scale * s), z)
    }
}

/// `G(t)` and `G'(t)` of an underdamped mode (`sigma = c / 2`, `w_d =
/// sqrt(w2 - sigma^2) > 0`) under `e^(i omega t)`, from its factors at `t`
/// (`ec = e^(-sigma t) cos(w_d t)`, `es = e^(-sigma t) sin(w_d t) / w_d`).
pub(super) fn response(
    sigma: f64,
    damped: f64,
    omega: f64,
    t: f64,
    (ec, es): (f64, f64),
) -> (Complex, Complex) {
    // e^(lambda+ t), and A = (e^(i omega t) - e^(lambda+ t)) / (i omega -
    // lambda+) = e^(lambda+ t) t phi1((i omega - lambda+) t).
    let rising = (ec, damped * es);
    let close = (sigma, omega - damped);
    let p = phi1((close.0 * t, close.1 * t));
    let a = mul(rising, (p.0 * t, p.1 * t));
    let far = (sigma, omega + damped);
    let g = div((a.0 - es, a.1), far);
    // A' = i omega A + e^(lambda+ t); es' = ec - sigma es.
    let rate = (
        -omega * a.1 + rising.0 - (ec - sigma * es),
        omega * a.0 + rising.1,
    );
    (g, div(rate, far))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_response_from_rest_obeys_its_equation_and_starts_at_rest() {
        crate::testing::timeout(30, || {
            // Near resonance, lightly damped; and well apart, well damped.
            for (w2, c, omega) in [
                (39.478f64, 0.0f64, std::f64::consts::TAU),
                (100.0, 3.0, 4.0),
            ] {
                let sigma = 0.5 * c;
                let damped = (w2 - sigma * sigma).sqrt();
                let at = |t: f64| {
                    let e = (-sigma * t).exp();
                    let factors = (e * (damped * t).cos(), e * (damped * t).sin() / damped);
                    response(sigma, damped, omega, t, factors)
                };
                let (g0, r0) = at(0.0);
                assert!(g0.0.abs() + g0.1.abs() + r0.0.abs() + r0.1.abs() <= 1e-300);
                // Against the closed form far from resonance (Z form:
                // (e^(i w t) - free evolution of its start) / D).
                for t in [1e-4, 0.05, 0.3, 1.7] {
                    let (g, rate) = at(t);
                    let h = 1e-6 * t.max(1e-3);
                    let (ga, _) = at(t + h);
                    let (gb, _) = at(t - h);
                    let slope = ((ga.0 - gb.0) / (2.0 * h), (ga.1 - gb.1) / (2.0 * h));
                    let size = rate.0.hypot(rate.1).max(t);
                    assert!(
                        (slope.0 - rate.0).abs() <= 1e-6 * size,
                        "{t}: {slope:?} {rate:?}"
                    );
                    assert!(
                        (slope.1 - rate.1).abs() <= 1e-6 * size,
                        "{t}: {slope:?} {rate:?}"
                    );
                    if c > 0.0 {
                        let d = (w2 - omega * omega, c * omega);
                        let e = (-sigma * t).exp();
                        let (ec, es) = (e * (damped * t).cos(), e * (damped * t).sin() / damped);
                        let (s, co) = (omega * t).sin_cos();
                        // e^(i w t) - ec - (i w + sigma) es, over D.
                        let g_direct = div((co - ec - sigma * es, s - omega * es), d);
                        assert!((g.0 - g_direct.0).abs() <= 1e-12, "{t}: {g:?} {g_direct:?}");
                        assert!((g.1 - g_direct.1).abs() <= 1e-12, "{t}: {g:?} {g_direct:?}");
                    }
                }
            }
        });
    }
}
