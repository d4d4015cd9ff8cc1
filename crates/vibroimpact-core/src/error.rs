//! Errors of the core. Every variant says what went wrong in one line.

/// Everything that can go wrong in the core.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Error {
    /// An input value is outside what the model allows. `field` is the
    /// parameter's public name, `allowed` what it may be.
    #[error("{field} must be {allowed}, got {value}")]
    InvalidParameter {
        field: &'static str,
        allowed: &'static str,
        value: f64,
    },
    /// A named choice (method, law, timing) that does not exist.
    #[error("{field} must be one of {allowed}, got {value:?}")]
    UnknownChoice {
        field: &'static str,
        allowed: &'static str,
        value: String,
    },
    /// Two inputs that are each valid but do not go together.
    #[error("{0}")]
    Inconsistent(String),
    /// The integration produced a non-finite or energy-creating state.
    #[error(
        "numerical blow-up at t = {time:.6e} s ({reason}); reduce dt or choose a more stable method"
    )]
    NumericalBlowUp { time: f64, reason: &'static str },
    /// Newton's method did not converge within a step of an implicit method.
    #[error("Newton iterations did not converge in the step from t = {time:.6e} s; reduce dt")]
    NewtonFailed { time: f64 },
    /// Contacts and separations follow each other ever faster.
    #[error(
        "chattering at t = {time:.6e} s: {events} contact changes in a row less than {interval:.1e} s apart, \
         below the run's time resolution (an impact mass settling against a wall, or a contact far too stiff \
         for the clearance); the run was stopped there"
    )]
    Chattering {
        time: f64,
        events: u64,
        interval: f64,
    },
    /// The adaptive step size fell to round-off.
    #[error("step size {step:.3e} s too small at t = {time:.6e} s; loosen rtol/atol")]
    StepSizeTooSmall { time: f64, step: f64 },
    /// More steps than allowed.
    #[error("maximum number of steps ({max_steps}) reached at t = {time:.6e} s; raise max_steps")]
    TooManySteps { time: f64, max_steps: u64 },
    /// The caller asked to stop (for example Ctrl-C in Python).
    #[error("interrupted at t = {time:.6e} s")]
    Interrupted { time: f64 },
}

pub type Result<T> = std::result::Result<T, Error>;

/// `value` must be finite and strictly positive.
pub(crate) fn positive(field: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            field,
            allowed: "a finite number > 0",
            value,
        })
    }
}

/// `value` must be finite and not negative.
pub(crate) fn non_negative(field: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() && value >= 0.0 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            field,
            allowed: "a finite number >= 0",
            value,
        })
    }
}

/// `value` must be finite (any sign).
pub(crate) fn finite(field: &'static str, value: f64) -> Result<f64> {
    if value.is_finite() {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            field,
            allowed: "a finite number",
            value,
        })
    }
}

/// `value` must lie in `[lo, hi]` (`allowed` describes the range for the message).
pub(crate) fn within(
    field: &'static str,
    value: f64,
    lo: f64,
    hi: f64,
    lo_open: bool,
    allowed: &'static str,
) -> Result<f64> {
    let above = if lo_open { value > lo } else { value >= lo };
    if value.is_finite() && above && value <= hi {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            field,
            allowed,
            value,
        })
    }
}
