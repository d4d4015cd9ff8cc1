//! The adaptive methods' step-size control, one for both event-driven
//! kernels (the two-mass `events.rs` and the general `system_events.rs`):
//! Hairer's controller on the scaled error, with the limits every run has.

use crate::error::{Error, Result};

/// Whether the error control rejects a step (a NaN error too).
#[inline(always)]
pub fn rejects(error: f64) -> bool {
    error.is_nan() || error > 1.0
}

/// The first step of an adaptive method from `y`, whose rates are `f0`
/// (`rates(time, y1, f1)` gives them at another state): Hairer's choice
/// (HINIT of dop853.f; Hairer, Norsett & Wanner, "Solving Ordinary
/// Differential Equations I", 2nd ed., II.4), which scipy's `solve_ivp`
/// and 0.1 make too: the size at which an Euler step's change of the
/// derivative meets the tolerances, the norm the RMS over the `coordinates`
/// (the error control's) scaled by `atol + rtol |y|`; at most `longest`
/// (s). `shrink(e)` is the controller's `e^(-1 / exponent)`; `y1`, `f1` are
/// buffers of the state's length.
#[allow(clippy::too_many_arguments)]
pub fn initial_step(
    y: &[f64],
    f0: &[f64],
    coordinates: usize,
    (rtol, atol): (f64, f64),
    shrink: impl Fn(f64) -> f64,
    longest: f64,
    (y1, f1): (&mut [f64], &mut [f64]),
    mut rates: impl FnMut(f64, &[f64], &mut [f64]),
) -> f64 {
    let norm = |v: &dyn Fn(usize) -> f64| {
        let sum: f64 = (0..coordinates)
            .map(|n| (v(n) / (atol + rtol * y[n].abs())).powi(2))
            .sum();
        (sum / coordinates as f64).sqrt()
    };
    let (d0, d1) = (norm(&|n| y[n]), norm(&|n| f0[n]));
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    }
    .min(longest);
    y1.copy_from_slice(y);
    for n in 0..coordinates {
        y1[n] = y[n] + h0 * f0[n];
    }
    rates(h0, y1, f1);
    let d2 = norm(&|n| f1[n] - f0[n]) / h0;
    let h1 = if d1 <= 1e-15 && d2 <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        // (0.01 / max(d1, d2))^(1 / exponent)
        shrink(d1.max(d2) / 0.01)
    };
    (100.0 * h0).min(h1).min(longest)
}

/// The step size to try next, and what the controller remembers.
#[derive(Debug, Clone, Copy)]
pub struct StepControl {
    /// The next step to attempt, s.
    pub h: f64,
    /// Steps rejected so far.
    pub rejected: u64,
    /// The last attempt was rejected: the next may not grow.
    just_rejected: bool,
}

impl StepControl {
    pub fn new(h: f64) -> Self {
        Self {
            h,
            rejected: 0,
            just_rejected: false,
        }
    }

    /// A step given up before its error was judged (an event inside it
    /// asked for a shorter one): try `h` next.
    pub fn retry(&mut self, h: f64) {
        self.rejected += 1;
        self.h = h;
        self.just_rejected = true;
    }

    /// Judges an attempt of `taken` s with scaled `error` (`shrink(error)` is
    /// `error^(-1 / (order + 1))`). Rejected: `Ok(false)`, `h` shrunk, or an
    /// error when the step has fallen to the round-off of the time or the run
    /// has used its `max_steps`. Accepted: `Ok(true)`, and with `grow` the
    /// next `h` from the error (a step cut at an event says little about the
    /// step the solution allows).
    #[allow(clippy::too_many_arguments)]
    pub fn judge(
        &mut self,
        error: f64,
        taken: f64,
        shrink: impl Fn(f64) -> f64,
        grow: bool,
        time: f64,
        t_end: f64,
        accepted: u64,
        max_steps: u64,
    ) -> Result<bool> {
        if rejects(error) {
            let factor = if error.is_finite() {
                (0.9 * shrink(error)).clamp(0.1, 0.9)
            } else {
                0.1
            };
            self.retry(taken * factor);
            if self.h <= 16.0 * f64::EPSILON * time.abs().max(t_end) {
                return Err(Error::StepSizeTooSmall { time, step: self.h });
            }
            if accepted + self.rejected >= max_steps {
                return Err(Error::TooManySteps { time, max_steps });
            }
            return Ok(false);
        }
        let most = if self.just_rejected { 1.0 } else { 5.0 };
        let factor = if error > 0.0 {
            (0.9 * shrink(error)).clamp(0.2, most)
        } else {
            most
        };
        if grow {
            self.h = taken * factor;
        }
        self.just_rejected = false;
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::initial_step;

    /// Hairer's first step for `x'' = -4 x` from `(1, 0.5)`, DOP853's
    /// exponent 8, against scipy 1.x's `select_initial_step` (the values it
    /// gave, `order=7`): both bound by the derivative's change, not `100 h0`.
    #[test]
    fn the_first_step_is_scipys() {
        crate::testing::timeout(10, || {
            let rates = |_: f64, y: &[f64], f: &mut [f64]| f.copy_from_slice(&[y[1], -4.0 * y[0]]);
            for ((rtol, atol), scipy) in [
                ((1e-6, 1e-9), 0.08052496746923198),
                ((1e-10, 1e-13), 0.025464230571373776),
            ] {
                let (y, mut f0) = ([1.0, 0.5], [0.0; 2]);
                rates(0.0, &y, &mut f0);
                let (mut y1, mut f1) = ([0.0; 2], [0.0; 2]);
                let h = initial_step(
                    &y,
                    &f0,
                    2,
                    (rtol, atol),
                    |e: f64| e.powf(-1.0 / 8.0),
                    10.0,
                    (&mut y1, &mut f1),
                    rates,
                );
                assert!((h / scipy - 1.0).abs() < 1e-12, "{h} against {scipy}");
                // At most the longest step allowed.
                let (mut y1, mut f1) = ([0.0; 2], [0.0; 2]);
                let capped = initial_step(
                    &y,
                    &f0,
                    2,
                    (rtol, atol),
                    |e: f64| e.powf(-1.0 / 8.0),
                    1e-3,
                    (&mut y1, &mut f1),
                    rates,
                );
                assert_eq!(capped, 1e-3);
            }
        });
    }
}
