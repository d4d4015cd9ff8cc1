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
/// over the step. Bisection on the slope (a quadratic).
pub(crate) fn argmax(g0: f64, g1: f64, m0: f64, m1: f64) -> f64 {
    let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
    for _ in 0..60 {
        let mid = 0.5 * (lo + hi);
        if eval(g0, g1, m0, m1, mid).1 > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reproduces_a_cubic_exactly_and_finds_its_root() {
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
    }

    #[test]
    fn finds_the_maximum_of_a_parabola() {
        // q(t) = -(t - 0.7)^2 + 1 has its maximum at 0.7.
        let q = |t: f64| 1.0 - (t - 0.7) * (t - 0.7);
        let dq = |t: f64| -2.0 * (t - 0.7);
        let a = argmax(q(0.0), q(1.0), dq(0.0), dq(1.0));
        assert!((a - 0.7).abs() < 1e-12, "{a}");
    }
}
