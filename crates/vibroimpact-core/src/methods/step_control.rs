//! The adaptive methods' step-size control, one for both event-driven
//! kernels (the two-mass `events.rs` and the general `system_events.rs`):
//! Hairer's controller on the scaled error, with the limits every run has.

use crate::error::{Error, Result};

/// Whether the error control rejects a step (a NaN error too).
#[inline(always)]
pub fn rejects(error: f64) -> bool {
    error.is_nan() || error > 1.0
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
