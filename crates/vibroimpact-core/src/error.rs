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
    /// A compliant contact a fixed step cannot resolve: its law holds the
    /// pair for `duration` (s) at its approach speed, under two steps of `dt`.
    #[error(
        "a contact beginning at t = {time:.6e} s at {approach:.3e} m/s lasts about {duration:.3e} s \
         by its law, under two steps of dt = {dt} s: a fixed step cannot resolve it (its rebound \
         and losses would be the step's); reduce dt to about {suggested:.1e} s, or use an \
         adaptive method (dop853)",
        suggested = .duration / 20.0
    )]
    UnresolvedContact {
        time: f64,
        approach: f64,
        duration: f64,
        dt: f64,
    },
    /// Newton's method did not converge within a step of an implicit method.
    #[error("Newton iterations did not converge in the step from t = {time:.6e} s; reduce dt")]
    NewtonFailed { time: f64 },
    /// Contacts and separations follow each other ever faster.
    #[error(
        "chattering at t = {time:.6e} s: {events} contact changes in a row less than {interval:.1e} s apart, \
         below the run's time resolution (an impact mass settling against a wall, a zero clearance, or a contact far too stiff \
         for the clearance); the run was stopped there"
    )]
    Chattering {
        time: f64,
        events: u64,
        interval: f64,
    },
    /// The adaptive step size fell to round-off.
    #[error(
        "step size {step:.3e} s too small at t = {time:.6e} s (at the round-off of the run's times, \
         which reach t_end); loosen rtol/atol or shorten t_end"
    )]
    StepSizeTooSmall { time: f64, step: f64 },
    /// More steps than allowed.
    #[error("maximum number of steps ({max_steps}) reached at t = {time:.6e} s; raise max_steps")]
    TooManySteps { time: f64, max_steps: u64 },
    /// The caller asked to stop (for example Ctrl-C in Python).
    #[error("interrupted at t = {time:.6e} s")]
    Interrupted { time: f64 },
    /// The history rows plus contacts a run keeps reached `max_rows`.
    #[error(
        "the run kept {rows} history rows and {contacts} contacts by t = {time:.6e} s, reaching \
         max_rows = {max_rows}: {advice}"
    )]
    RowLimit {
        time: f64,
        max_rows: u64,
        rows: u64,
        contacts: u64,
        /// What to change.
        advice: &'static str,
    },
    /// The records a run keeps (history, stroboscopic states, contacts) would
    /// pass [`crate::kernel::memory::MAX_RECORD_BYTES`], or the machine refused the
    /// memory for them.
    #[error(
        "the run's records ({rows} history rows and {strobes} stroboscopic rows of {columns} values, \
         {contacts} contacts) reached \
         {held_mib:.1} MiB by t = {time:.6e} s and {cause}: {advice}"
    )]
    MemoryLimit {
        time: f64,
        rows: u64,
        strobes: u64,
        columns: u64,
        contacts: u64,
        held_mib: f64,
        /// "would pass the limit of 2048 MiB" or "the machine refused more".
        cause: String,
        /// What to change: for the records that hold the most.
        advice: &'static str,
    },
    /// The energy balance does not close: stored energy plus the work of the
    /// dissipative forces minus the external work differs from the energy at
    /// the start by more than `tolerance` times the energy in play.
    #[error(
        "energy balance violated at t = {time:.6e} s: stored energy + dissipated work - external work \
         differs from the energy at the start by {residual:.3e} J, {ratio:.2e} of the energy in play \
         ({scale:.3e} J), more than energy_tolerance = {tolerance:e}; the result would be physically \
         impossible: {advice} (raise energy_tolerance only to accept it)",
        ratio = .residual.abs() / .scale
    )]
    EnergyBalance {
        time: f64,
        residual: f64,
        scale: f64,
        tolerance: f64,
        advice: EnergyAdvice,
    },
    /// A contact whose energy balance does not close: over the contact the
    /// system's energy change plus the work of the contact's dissipative
    /// forces plus that of the main damper, minus the external work, is not
    /// zero to within `tolerance` of the energy in play. Positive, the
    /// contact created energy, which no contact can: `created` when that is
    /// beyond the bound on creation that `energy_tolerance` cannot raise.
    #[error(
        "the contact from t = {onset:.6e} s to {separation:.6e} s does not balance its energy: the \
         system's energy changed by {change:.3e} J, the contact dissipated {dissipated:.3e} J and the \
         other dampers and the external forces account for {work:.3e} J; these must sum to zero, \
         but leave {residual:.3e} J ({ratio:.2e} of the energy in play, {scale:.3e} J; \
         rebound/approach speed {restitution:.4}; a positive residual is energy the contact \
         created), {limit}",
        residual = .change + .work + .dissipated,
        ratio = (.change + .work + .dissipated).abs() / .scale,
        limit = contact_limit(*.tolerance, *.created, *.advice)
    )]
    ContactEnergy {
        onset: f64,
        separation: f64,
        change: f64,
        dissipated: f64,
        work: f64,
        scale: f64,
        restitution: f64,
        tolerance: f64,
        created: bool,
        advice: EnergyAdvice,
    },
}

/// What to change when a run's energy does not balance, as its method's kind
/// gives it: a fixed step's is its `dt`, an adaptive method's its
/// tolerances, the exact flow's the step that caps its search for contacts.
/// The kernel raises [`EnergyAdvice::Any`]; the registry's runs, which know
/// the method, make it theirs ([`Error::advised`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EnergyAdvice {
    Any,
    FixedStep,
    Adaptive,
    Exact,
}

impl std::fmt::Display for EnergyAdvice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Any => "reduce dt, choose another method (e.g. \"dop853\") or tighten rtol/atol",
            Self::FixedStep => "reduce dt or choose another method (e.g. \"dop853\", adaptive)",
            Self::Adaptive => {
                "tighten rtol and atol, or choose another method (e.g. \"rk4\" with a small dt)"
            }
            Self::Exact => {
                "reduce dt (it caps the exact flow's step, between which contacts are sought) or \
                 choose another method (e.g. \"dop853\")"
            }
        })
    }
}

impl Error {
    /// This error with `advice` where it advises on a run's energy (the
    /// method's own, in place of the kernel's [`EnergyAdvice::Any`]).
    pub fn advised(mut self, advice: EnergyAdvice) -> Self {
        if let Self::EnergyBalance { advice: a, .. } | Self::ContactEnergy { advice: a, .. } =
            &mut self
        {
            *a = advice;
        }
        self
    }
}

pub type Result<T> = std::result::Result<T, Error>;

/// The end of a contact energy error: the bound passed and what to change.
fn contact_limit(tolerance: f64, created: bool, advice: EnergyAdvice) -> String {
    if created {
        format!(
            "more than {tolerance:e}, the most a contact may create whatever energy_tolerance \
             says (a contact can only lose energy: this is the method's error); {advice}"
        )
    } else {
        format!(
            "more than energy_tolerance = {tolerance:e}; {advice} (raise energy_tolerance only to \
             accept it)"
        )
    }
}

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

/// A count (`every`, `max_steps`, a number of periods) must be at least 1.
pub(crate) fn at_least_one(field: &'static str, value: u64) -> Result<u64> {
    if value >= 1 {
        Ok(value)
    } else {
        Err(Error::InvalidParameter {
            field,
            allowed: "a whole number >= 1",
            value: value as f64,
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
