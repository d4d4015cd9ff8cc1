//! Sine, cosine and exponential of small arguments by short power series:
//! a third of the library's cost, within an ulp of it (a test holds them to
//! it). The exact flow turns every mode by at most an eighth of a turn per
//! step, and a harmonic signal's phasor turns by a step's small angle.

/// The largest angle (rad) [`sin_cos`] takes its series at: the steps turn
/// every mode and harmonic by at most an eighth of a turn.
pub(crate) const SERIES_ANGLE: f64 = std::f64::consts::FRAC_PI_4 * (1.0 + 1e-9);

/// `(sin x, cos x)`: for `|x| <= pi/4` by their Taylor series to `x^17` and
/// `x^16` (truncated below 1e-17 relative; a third of the library's cost),
/// else the library's.
#[inline(always)]
pub(crate) fn sin_cos(x: f64) -> (f64, f64) {
    if x.abs() <= SERIES_ANGLE {
        sin_cos_series(x)
    } else {
        x.sin_cos()
    }
}

/// The largest angle (rad) [`sin_cos_by_quadrant`] reduces itself: the
/// multiples of pi/2 are then below 2^17, and `k` times each part of pi/2
/// is exact.
const REDUCED_ANGLE: f64 = 1e5;

/// `(sin x, cos x)` for any `x`: up to [`REDUCED_ANGLE`], `x - k pi/2` in
/// three parts of pi/2 of 33 bits each (Cody and Waite's reduction, as
/// fdlibm's) and the series there, the quadrant from `k`; beyond, the
/// library's. Within two ulps of the library's (a test holds it to it).
pub(crate) fn sin_cos_by_quadrant(x: f64) -> (f64, f64) {
    // NaN and infinities too.
    if !reduces(x) {
        return x.sin_cos();
    }
    let (k, r) = quadrant_reduce(x);
    let (s, c) = sin_cos_series(r);
    match (k as i64) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// Whether [`sin_cos_by_quadrant`] reduces `x` itself (not a number: no).
#[inline(always)]
pub(crate) fn reduces(x: f64) -> bool {
    x.abs() <= REDUCED_ANGLE
}

/// `x` as `k pi/2 + r`: `(k, r)` (see [`sin_cos_by_quadrant`]).
#[inline(always)]
pub(crate) fn quadrant_reduce(x: f64) -> (f64, f64) {
    // pi/2 in parts of 33 significant bits (fdlibm's pio2_1, pio2_2, pio2_3).
    const PIO2_1: f64 = f64::from_bits(0x3FF9_21FB_5440_0000);
    const PIO2_2: f64 = f64::from_bits(0x3DD0_B461_1A60_0000);
    const PIO2_3: f64 = f64::from_bits(0x3BA3_198A_2E00_0000);
    // Rounded to the nearest whole number by adding and taking away 1.5
    // 2^52 (a call to the library's `round` where the processor's is not
    // assumed).
    const SHIFTER: f64 = 6_755_399_441_055_744.0;
    let k = (x * std::f64::consts::FRAC_2_PI + SHIFTER) - SHIFTER;
    let r = ((x - k * PIO2_1) - k * PIO2_2) - k * PIO2_3;
    (k, r)
}

/// `(sin, cos)` of `k pi/2 + r` from `(s, c)`, those of `r`: the signs and
/// swap of [`sin_cos_by_quadrant`]'s quadrant (no rounding: the same bits)
/// without a branch, what vectorises over the lockstep lanes (the single
/// run keeps its `match`, which measured faster there).
#[inline(always)]
pub(crate) fn in_quadrant(k: f64, s: f64, c: f64) -> (f64, f64) {
    // `k` is whole and below 2^17 in magnitude.
    let q = (k as i32) & 3;
    let (s, c) = if q & 1 != 0 { (c, s) } else { (s, c) };
    let sin = if q & 2 != 0 { -s } else { s };
    let cos = if (q ^ (q >> 1)) & 1 != 0 { -c } else { c };
    (sin, cos)
}

#[inline(always)]
pub(crate) fn sin_cos_series(x: f64) -> (f64, f64) {
    let z = x * x;
    let z2 = z * z;
    let z4 = z2 * z2;
    // Estrin's scheme: shorter chains of dependent operations than Horner's.
    let s = (-1.0 / 6.0 + z * (1.0 / 120.0))
        + z2 * (-1.0 / 5040.0 + z * (1.0 / 362_880.0))
        + z4 * ((-1.0 / 39_916_800.0 + z * (1.0 / 6_227_020_800.0))
            + z2 * (-1.0 / 1_307_674_368_000.0 + z * (1.0 / 355_687_428_096_000.0)));
    let c = (-0.5 + z * (1.0 / 24.0))
        + z2 * (-1.0 / 720.0 + z * (1.0 / 40_320.0))
        + z4 * ((-1.0 / 3_628_800.0 + z * (1.0 / 479_001_600.0))
            + z2 * (-1.0 / 87_178_291_200.0 + z * (1.0 / 20_922_789_888_000.0)));
    (x + x * z * s, 1.0 + z * c)
}

/// `e^x`: for `|x| <= 1/16` (light damping over a step) by its Taylor
/// series to `x^9` (truncated below 1e-18 relative), else the library's.
#[inline(always)]
pub(crate) fn exp(x: f64) -> f64 {
    if x.abs() <= 0.0625 {
        exp_series(x)
    } else {
        x.exp()
    }
}

#[inline(always)]
fn exp_series(x: f64) -> f64 {
    let x2 = x * x;
    let x4 = x2 * x2;
    let low = (1.0 + x) + x2 * (0.5 + x * (1.0 / 6.0));
    let high = (1.0 / 24.0 + x * (1.0 / 120.0)) + x2 * (1.0 / 720.0 + x * (1.0 / 5040.0));
    let top = 1.0 / 40_320.0 + x * (1.0 / 362_880.0);
    low + x4 * (high + x4 * top)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ulps(a: f64, b: f64) -> f64 {
        (a - b).abs() / (f64::EPSILON * b.abs().max(f64::MIN_POSITIVE))
    }

    #[test]
    fn the_series_are_the_library_s_sine_cosine_and_exponential_to_an_ulp() {
        crate::testing::timeout(30, || {
            for k in -1000..=1000 {
                let x = SERIES_ANGLE * k as f64 / 1000.0;
                let ((s, c), (ls, lc)) = (sin_cos(x), x.sin_cos());
                assert!(ulps(s, ls) <= 1.0 && ulps(c, lc) <= 1.0, "{x}");
                let x = 0.0625 * k as f64 / 1000.0;
                assert!(ulps(exp(x), x.exp()) <= 1.0, "{x}");
            }
            assert_eq!(sin_cos(2.0), 2f64.sin_cos());
        });
    }

    #[test]
    fn sine_and_cosine_by_quadrant_are_the_library_s_to_two_ulps() {
        crate::testing::timeout(30, || {
            // Angles of every quadrant up to and past the reduced range, near
            // multiples of pi/2 too (where one of the two is small: there the
            // error is taken against 1, the functions' scale).
            let mut worst = 0.0f64;
            for i in -200_000..=200_000 {
                let x = f64::from(i) * 0.612_345_678_9;
                for x in [x, (f64::from(i) * std::f64::consts::FRAC_PI_2).next_up()] {
                    let ((s, c), (ls, lc)) = (sin_cos_by_quadrant(x), x.sin_cos());
                    worst = worst.max((s - ls).abs().max((c - lc).abs()) / f64::EPSILON);
                }
            }
            assert!(worst <= 2.0, "{worst} ulps of 1");
            assert_eq!(sin_cos_by_quadrant(2e5), 2e5f64.sin_cos());
            assert!(sin_cos_by_quadrant(f64::NAN).0.is_nan());
        });
    }
}
