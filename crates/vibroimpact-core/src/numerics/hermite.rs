//! Cubic Hermite interpolation of a scalar over one step, used to locate
//! contact onset, separation and maximum indentation inside the step.
//!
//! The step is mapped to `theta` in [0, 1]; `m0`, `m1` are the end slopes
//! already multiplied by the step size.

/// Value and slope (per unit theta) of the cubic at `theta`.
#[inline]
pub(crate) fn eval(g0: f64, g1: f64, m0: f64, m1: f64, theta: f64) -> (f64, f64) {
    let t = theta;
    let t2 = t * t;
    let t3 = t2 * t;
    let value = (2.0 * t3 - 3.0 * t2 + 1.0) * g0
        + (t3 - 2.0 * t2 + t) * m0
        + (-2.0 * t3 + 3.0 * t2) * g1
        + (t3 - t2) * m1;
    let slope = (6.0 * t2 - 6.0 * t) * g0
        + (3.0 * t2 - 4.0 * t + 1.0) * m0
        + (-6.0 * t2 + 6.0 * t) * g1
        + (3.0 * t2 - 2.0 * t) * m1;
    (value, slope)
}

/// A root in [0, 1] of the cubic, given that `g0` and `g1` bracket zero
/// (`g0 <= 0 < g1` or `g0 >= 0 > g1`). Newton's method safeguarded by
/// bisection, so it always converges to round-off.
pub(crate) fn root(g0: f64, g1: f64, m0: f64, m1: f64) -> f64 {
    if g0 == 0.0 {
        return 0.0;
    }
    let rising = g1 > g0;
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    let mut theta = g0 / (g0 - g1);
    for _ in 0..64 {
        let (value, slope) = eval(g0, g1, m0, m1, theta);
        if value == 0.0 {
            return theta;
        }
        // Keep the bracket: below the root the cubic has the sign of g0.
        if (value < 0.0) == rising {
            lo = theta;
        } else {
            hi = theta;
        }
        let newton = theta - value / slope;
        let next = if slope != 0.0 && newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - theta).abs() <= 1e-15 {
            return next;
        }
        theta = next;
    }
    theta
}

/// Where the cubic's slope falls from `m0 > 0` to `m1 <= 0`: its maximum
/// over the step. The slope is a quadratic in theta, with one root in [0, 1]
/// where it changes sign; found by the Illinois method (a few evaluations,
/// where bisection to round-off would take sixty).
pub(crate) fn argmax(g0: f64, g1: f64, m0: f64, m1: f64) -> f64 {
    falling_root(|t| eval(g0, g1, m0, m1, t).1, 4.0 * f64::EPSILON)
}

/// The root in [0, 1] of `slope`, positive at 0 and not positive at 1:
/// regula falsi with the Illinois modification, to `tolerance` in theta.
pub(crate) fn falling_root(slope: impl Fn(f64) -> f64, tolerance: f64) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    let (mut s_lo, mut s_hi) = (slope(lo), slope(hi));
    if s_hi >= 0.0 {
        return hi;
    }
    let (mut best, mut best_s) = (hi, s_hi.abs());
    let mut kept = 0i8;
    for _ in 0..200 {
        let mut t = hi - s_hi * (hi - lo) / (s_hi - s_lo);
        if !(t > lo && t < hi) {
            t = 0.5 * (lo + hi);
        }
        let s = slope(t);
        if s.abs() < best_s {
            (best, best_s) = (t, s.abs());
        }
        if s > 0.0 {
            lo = t;
            s_lo = s;
            if kept == -1 {
                s_hi *= 0.5;
            }
            kept = -1;
        } else {
            hi = t;
            s_hi = s;
            if kept == 1 {
                s_lo *= 0.5;
            }
            kept = 1;
        }
        if s == 0.0 || hi - lo <= tolerance {
            break;
        }
    }
    best
}

/// Where the slope of the cubic Hermite interpolant falls from `m0 > 0`
/// to `m1 <= 0`: its maximum over the step, in closed form (the slope is a
/// quadratic in theta with one root in [0, 1]). The event kernel's;
/// [`argmax`] finds the same point by regula falsi, to other bits.
pub(crate) fn peak(g0: f64, g1: f64, m0: f64, m1: f64) -> f64 {
    // slope(theta) = a theta^2 + b theta + m0.
    let a = 6.0 * (g0 - g1) + 3.0 * (m0 + m1);
    let b = 6.0 * (g1 - g0) - 4.0 * m0 - 2.0 * m1;
    if m1 >= 0.0 {
        return 1.0;
    }
    let root = if a == 0.0 {
        -m0 / b
    } else {
        // The two roots without cancellation: q / a and m0 / q.
        let q = -0.5 * (b + b.signum() * (b * b - 4.0 * a * m0).max(0.0).sqrt());
        let (r1, r2) = (q / a, if q != 0.0 { m0 / q } else { f64::NAN });
        // The one in [0, 1] (slope(0) > 0 >= slope(1): exactly one).
        if (0.0..=1.0).contains(&r1) && !(0.0..=1.0).contains(&r2) {
            r1
        } else if (0.0..=1.0).contains(&r2) && !(0.0..=1.0).contains(&r1) {
            r2
        } else {
            // Both (or neither) by round-off: the one whose slope is closer to 0.
            let slope = |t: f64| eval(g0, g1, m0, m1, t.clamp(0.0, 1.0)).1.abs();
            if slope(r1) <= slope(r2) || r2.is_nan() {
                r1
            } else {
                r2
            }
        }
    };
    if root.is_nan() {
        0.5
    } else {
        root.clamp(0.0, 1.0)
    }
}

/// The first local maximum of the cubic Hermite interpolant whose slope
/// starts at `m0 > 0` and ends at `m1 >= 0`: the smaller root of its slope
/// in [0, 1] when it falls below zero between them, else 0 (no maximum
/// inside: it rises throughout).
pub(crate) fn first_maximum(g0: f64, g1: f64, m0: f64, m1: f64) -> f64 {
    // slope(theta) = a theta^2 + b theta + m0, as in [`peak`].
    let a = 6.0 * (g0 - g1) + 3.0 * (m0 + m1);
    let b = 6.0 * (g1 - g0) - 4.0 * m0 - 2.0 * m1;
    let discriminant = b * b - 4.0 * a * m0;
    if a <= 0.0 || discriminant <= 0.0 {
        // A slope that opens downwards and ends >= 0 stays >= 0; one with
        // no real roots never falls below zero.
        return 0.0;
    }
    // Both roots positive (their product m0 / a > 0): the smaller one.
    let q = -0.5 * (b - discriminant.sqrt());
    let root = m0 / q;
    if root > 0.0 && root < 1.0 {
        root
    } else {
        0.0
    }
}

/// A root of the cubic Hermite interpolant (see [`eval`]) between
/// `lo` and `hi` in theta, where it has opposite signs (else `hi`): Newton's
/// method on its power form, safeguarded by bisection, to 1e-10 in theta
/// (the interpolant itself is off by ~ theta^4 of the value's swing). The
/// first guess of an event's location.
pub(crate) fn root_within(g0: f64, g1: f64, m0: f64, m1: f64, mut lo: f64, mut hi: f64) -> f64 {
    // g0 + m0 t + c2 t^2 + c3 t^3.
    let c2 = 3.0 * (g1 - g0) - 2.0 * m0 - m1;
    let c3 = 2.0 * (g0 - g1) + m0 + m1;
    let value = |t: f64| g0 + t * (m0 + t * (c2 + t * c3));
    let (v_lo, v_hi) = (value(lo), value(hi));
    if v_lo == 0.0 {
        return lo;
    }
    if v_hi == 0.0 || (v_lo > 0.0) == (v_hi > 0.0) {
        return hi;
    }
    let positive_below = v_lo > 0.0;
    let mut theta = lo + (hi - lo) * v_lo / (v_lo - v_hi);
    for _ in 0..64 {
        let v = value(theta);
        if v == 0.0 {
            return theta;
        }
        if (v > 0.0) == positive_below {
            lo = theta;
        } else {
            hi = theta;
        }
        let slope = m0 + theta * (2.0 * c2 + 3.0 * theta * c3);
        let newton = theta - v / slope;
        let next = if newton > lo && newton < hi {
            newton
        } else {
            0.5 * (lo + hi)
        };
        if (next - theta).abs() <= 1e-10 || hi - lo <= 1e-10 {
            return next;
        }
        theta = next;
    }
    theta
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Hermite data `(g0, g1, m0, m1)` over [0, 1] of `p` with derivative `dp`.
    fn data(p: impl Fn(f64) -> f64, dp: impl Fn(f64) -> f64) -> (f64, f64, f64, f64) {
        (p(0.0), p(1.0), dp(0.0), dp(1.0))
    }

    #[test]
    fn the_interpolant_s_root_is_a_cubic_s_root() {
        crate::testing::timeout(30, || {
            // A cubic is its own Hermite interpolant: its root, to round-off.
            let p = |t: f64| (t - 0.3) * (t + 2.0) * (t - 4.0);
            let dp = |t: f64| (t + 2.0) * (t - 4.0) + (t - 0.3) * (t - 4.0) + (t - 0.3) * (t + 2.0);
            let (g0, g1, m0, m1) = data(p, dp);
            for (lo, hi) in [(0.0, 1.0), (0.25, 0.9), (0.1, 0.3000001)] {
                let r = root_within(g0, g1, m0, m1, lo, hi);
                assert!((r - 0.3).abs() < 1e-14, "[{lo}, {hi}]: {r}");
            }
            // Falling through zero (the sign of the old side is positive).
            let r = root_within(-g0, -g1, -m0, -m1, 0.0, 1.0);
            assert!((r - 0.3).abs() < 1e-14, "{r}");
            // No sign change in the bracket: its end.
            assert_eq!(root_within(g0, g1, m0, m1, 0.5, 1.0), 1.0);
        });
    }

    #[test]
    fn the_first_maximum_of_a_cubic_that_rises_again() {
        crate::testing::timeout(30, || {
            // p = 0.3 t - t^2 + t^3: p' = 0.3 - 2 t + 3 t^2 vanishes at
            // (2 -+ sqrt(0.4)) / 6; the first, 0.2279, is its maximum.
            let p = |t: f64| 0.3 * t - t * t + t * t * t;
            let dp = |t: f64| 0.3 - 2.0 * t + 3.0 * t * t;
            let (g0, g1, m0, m1) = data(p, dp);
            let exact = (2.0 - 0.4f64.sqrt()) / 6.0;
            assert!((first_maximum(g0, g1, m0, m1) - exact).abs() < 1e-15);
            // One that rises throughout has none inside.
            let (g0, g1, m0, m1) = data(|t| t + t * t * t, |t| 1.0 + 3.0 * t * t);
            assert_eq!(first_maximum(g0, g1, m0, m1), 0.0);
        });
    }

    #[test]
    fn the_interpolant_s_maximum_in_closed_form() {
        crate::testing::timeout(30, || {
            // -(t^3 - t^2 / 2 - 3 t / 2): slope 1.5 at 0, -0.5 at 1, zero at
            // (1 + sqrt(19)) / 6.
            let p = |t: f64| -(t * t * t - 0.5 * t * t - 1.5 * t);
            let dp = |t: f64| -(3.0 * t * t - t - 1.5);
            let (g0, g1, m0, m1) = data(p, dp);
            let expected = (1.0 + 19f64.sqrt()) / 6.0;
            let a = peak(g0, g1, m0, m1);
            assert!((a - expected).abs() < 1e-15, "{a} {expected}");
            // A parabola (the slope is linear): its vertex.
            let q = |t: f64| 1.0 - (t - 0.7) * (t - 0.7);
            let dq = |t: f64| -2.0 * (t - 0.7);
            let (g0, g1, m0, m1) = data(q, dq);
            assert!((peak(g0, g1, m0, m1) - 0.7).abs() < 1e-15);
            // The regula falsi argmax agrees.
            assert!((peak(g0, g1, m0, m1) - argmax(g0, g1, m0, m1)).abs() < 1e-12);
            // Still rising at the end: the end.
            assert_eq!(peak(0.0, 1.0, 1.0, 0.5), 1.0);
        });
    }

    #[test]
    fn reproduces_a_cubic_exactly_and_finds_its_root() {
        crate::testing::timeout(60, || {
            // p(t) = (t - 0.3)(t + 2)(t - 4) on [0, 1] is a cubic: Hermite data from it
            // must reproduce it, so the located root is 0.3 to round-off.
            let p = |t: f64| (t - 0.3) * (t + 2.0) * (t - 4.0);
            let dp = |t: f64| (t + 2.0) * (t - 4.0) + (t - 0.3) * (t - 4.0) + (t - 0.3) * (t + 2.0);
            let r = root(p(0.0), p(1.0), dp(0.0), dp(1.0));
            assert!((r - 0.3).abs() < 1e-14, "{r}");
            for k in 0..=10 {
                let t = k as f64 / 10.0;
                let (v, s) = eval(p(0.0), p(1.0), dp(0.0), dp(1.0), t);
                assert!((v - p(t)).abs() < 1e-12 && (s - dp(t)).abs() < 1e-12);
            }
        });
    }

    #[test]
    fn finds_the_maximum_of_a_parabola() {
        crate::testing::timeout(60, || {
            // q(t) = -(t - 0.7)^2 + 1 has its maximum at 0.7.
            let q = |t: f64| 1.0 - (t - 0.7) * (t - 0.7);
            let dq = |t: f64| -2.0 * (t - 0.7);
            let a = argmax(q(0.0), q(1.0), dq(0.0), dq(1.0));
            assert!((a - 0.7).abs() < 1e-12, "{a}");
        });
    }
}
