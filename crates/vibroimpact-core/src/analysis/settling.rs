//! Whether a forced response has settled: the fewest forcing periods after
//! which its stroboscopic state repeats. The one criterion of the steady-state
//! analyses (through the binding) and of steady-state studies.

use crate::error::{positive, Error, Result};

/// The most forcing periods a settled response may take to repeat.
pub const MAX_PERIOD: usize = 8;

/// The size of a coordinate's motion through displacement `x` (m) and
/// velocity `v` (m/s): the amplitude `hypot(x, v / w)` of the harmonic motion
/// at the forcing's angular frequency w = 1 / `per_radian`, where
/// `per_radian` = forcing period / 2 pi (s), see [`per_radian`]. The scale of
/// settling and of shooting alike.
#[inline]
pub(crate) fn amplitude(x: f64, v: f64, per_radian: f64) -> f64 {
    x.hypot(v * per_radian)
}

/// The forcing period `forcing_period` (s) per radian: 1 / w.
#[inline]
pub(crate) fn per_radian(forcing_period: f64) -> f64 {
    forcing_period / (2.0 * std::f64::consts::PI)
}

/// [`strobe_period`] for a caller whose `forcing_period` (s) and `tolerance`
/// are not yet checked (the binding's): each must be finite and > 0.
pub fn checked_strobe_period(
    strobe: &[f64],
    width: usize,
    forcing_period: f64,
    tolerance: f64,
    max_period: usize,
) -> Result<Option<usize>> {
    positive("forcing_period", forcing_period)?;
    positive("tolerance", tolerance)?;
    if width == 0 || width % 2 != 0 || strobe.len() % width != 0 {
        return Err(Error::Inconsistent(format!(
            "stroboscopic rows of {width} values (displacements then velocities, an even \
             number >= 2) must divide the {} values given",
            strobe.len()
        )));
    }
    Ok(strobe_period(
        strobe,
        width,
        forcing_period,
        tolerance,
        max_period,
    ))
}

/// The smallest p in 1..=`max_period` with the last stroboscopic state (rows
/// of `width` = 2 n: n displacements, m, then n velocities, m/s) within
/// `tolerance` (relative) of the state p periods earlier; `None` if none is.
///
/// Both the distance and its scale are amplitudes: a coordinate's
/// displacement x and velocity v count as `hypot(x, v / w)`, w = 2 pi /
/// `forcing_period` (s), the amplitude of the harmonic motion through that
/// state. The distance is the largest such amplitude of the difference of the
/// two states over the coordinates; the scale the largest over the
/// coordinates and the last 2 `max_period` + 1 states: the size of the motion
/// whatever its phase at the strobe (at resonance the strobed displacements
/// are nought and the velocities carry it all; scaled by the displacements
/// alone, round-off had counted as unsettled).
pub fn strobe_period(
    strobe: &[f64],
    width: usize,
    forcing_period: f64,
    tolerance: f64,
    max_period: usize,
) -> Option<usize> {
    if width == 0 || width % 2 != 0 {
        return None;
    }
    let half = width / 2;
    let slow = per_radian(forcing_period);
    let rows: Vec<&[f64]> = strobe.chunks_exact(width).collect();
    // The amplitude of the motion of coordinate i through state a - b.
    let motion = |a: &[f64], b: Option<&[f64]>, i: usize| {
        let (x, v) = match b {
            Some(b) => (a[i] - b[i], a[half + i] - b[half + i]),
            None => (a[i], a[half + i]),
        };
        amplitude(x, v, slow)
    };
    let tail = &rows[rows.len().saturating_sub(2 * max_period + 1)..];
    let scale = tail
        .iter()
        .flat_map(|r| (0..half).map(move |i| motion(r, None, i)))
        .fold(0.0f64, f64::max)
        .max(1e-300);
    let last = rows.last()?;
    (1..=max_period.min(rows.len().saturating_sub(1))).find(|&p| {
        let other = rows[rows.len() - 1 - p];
        let distance = (0..half)
            .map(|i| motion(last, Some(other), i))
            .fold(0.0f64, f64::max);
        distance <= tolerance * scale
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// Strobed states of x = X cos(w t + phase) + drift t, a harmonic motion
    /// seen once a period (w = 2 pi), plus a slow drift.
    fn strobed(phase: f64, drift: f64, rows: usize) -> Vec<f64> {
        let w = 2.0 * PI;
        (0..rows)
            .flat_map(|k| {
                let t = k as f64;
                [0.05 * phase.cos() + drift * t, -0.05 * w * phase.sin()]
            })
            .collect()
    }

    #[test]
    fn a_response_in_quadrature_is_judged_on_its_amplitude() {
        crate::testing::timeout(60, || {
            // Strobed at its zero crossing: displacements of round-off, drifting
            // by 1e-14 m a period, 3e-13 of the amplitude.
            let strobe = strobed(PI / 2.0, 1e-14, 30);
            assert_eq!(strobe_period(&strobe, 2, 1.0, 1e-6, MAX_PERIOD), Some(1));
            // A drift of 1e-7 m a period (2e-6 of the amplitude) is not settled.
            let strobe = strobed(PI / 2.0, 1e-7, 30);
            assert_eq!(strobe_period(&strobe, 2, 1.0, 1e-6, MAX_PERIOD), None);
        });
    }

    #[test]
    fn the_fewest_periods_that_repeat() {
        crate::testing::timeout(60, || {
            let states = [[0.1, 2.0], [0.3, -1.0], [0.2, 0.5]];
            let strobe: Vec<f64> = (0..20).flat_map(|k| states[k % 3]).collect();
            assert_eq!(strobe_period(&strobe, 2, 0.1, 1e-9, MAX_PERIOD), Some(3));
            assert_eq!(strobe_period(&strobe, 2, 0.1, 1e-9, 2), None);
            assert_eq!(strobe_period(&strobe[..2], 2, 0.1, 1e-9, MAX_PERIOD), None);
            assert_eq!(strobe_period(&[], 2, 0.1, 1e-9, MAX_PERIOD), None);
        });
    }

    #[test]
    fn a_period_or_tolerance_that_is_not_a_positive_number_is_refused() {
        crate::testing::timeout(60, || {
            let strobe = strobed(0.0, 0.0, 5);
            for bad in [f64::NAN, f64::INFINITY, 0.0, -1.0] {
                let err = checked_strobe_period(&strobe, 2, bad, 1e-6, 8).unwrap_err();
                assert!(
                    err.to_string().starts_with("forcing_period must be"),
                    "{err}"
                );
                let err = checked_strobe_period(&strobe, 2, 1.0, bad, 8).unwrap_err();
                assert!(err.to_string().starts_with("tolerance must be"), "{err}");
            }
            assert_eq!(checked_strobe_period(&strobe, 2, 1.0, 1e-6, 8), Ok(Some(1)));
        });
    }
}
