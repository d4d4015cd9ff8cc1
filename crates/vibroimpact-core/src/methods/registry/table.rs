//! The one table of methods: each method's name, kind, the steppings it
//! takes and its options with their defaults and ranges. Every front end
//! (the core's [`super::AnyStepper::new`], the binding, Python's schemas)
//! reads it, so that a default or a range is written once.

use crate::error::{Error, Result};

/// How a method steps.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Fixed steps of `dt`, explicit: stable only where `dt` is a fraction of
    /// the fastest mode's period.
    Explicit,
    /// Fixed steps of `dt`, implicit: stable on any mode.
    Implicit,
    /// Steps chosen by an error control (`dt`, if given, is the first).
    Adaptive,
    /// The exact flow between contacts, stepping at least once in each period
    /// of the fastest mode (`dt`, if given, caps its step).
    Exact,
    /// The founding paper's Newmark, its contact force lagged one step.
    Paper,
}

impl Kind {
    /// The kind's name, as the binding exports it.
    pub fn name(self) -> &'static str {
        match self {
            Self::Explicit => "explicit",
            Self::Implicit => "implicit",
            Self::Adaptive => "adaptive",
            Self::Exact => "exact",
            Self::Paper => "paper",
        }
    }

    /// Whether the method steps by a given `dt` (which it then requires).
    pub fn is_fixed_step(self) -> bool {
        matches!(self, Self::Explicit | Self::Implicit | Self::Paper)
    }

    /// Whether the method steps at least once in each period of the fastest
    /// mode (so a run through more than `max_steps` of them cannot end).
    pub fn is_mode_stepped(self) -> bool {
        matches!(self, Self::Adaptive | Self::Exact)
    }
}

/// A numeric option: its default and the range it must lie in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OptionSpec {
    pub name: &'static str,
    /// None: no default (required where the method needs it).
    pub default: Option<f64>,
    pub low: f64,
    pub high: f64,
    /// Whether `low` itself is excluded.
    pub low_open: bool,
    /// What is allowed, as an error message says it.
    pub allowed: &'static str,
}

impl OptionSpec {
    /// `value` if finite and in range, else an error naming the option and
    /// what is allowed (`rtol must be in [1e-15, 0.1], got 0.5`).
    pub fn check(&self, value: f64) -> Result<f64> {
        let above = if self.low_open {
            value > self.low
        } else {
            value >= self.low
        };
        if value.is_finite() && above && value <= self.high {
            Ok(value)
        } else {
            Err(Error::InvalidParameter {
                field: self.name,
                allowed: self.allowed,
                value,
            })
        }
    }

    /// The default (0 for an option without one; never read then).
    pub fn default_value(&self) -> f64 {
        self.default.unwrap_or(0.0)
    }
}

/// The step (s): required by the fixed-step methods, the first step of the
/// adaptive ones, the exact flow's cap.
pub const DT: OptionSpec = OptionSpec {
    name: "dt",
    default: None,
    low: 0.0,
    high: f64::MAX,
    low_open: true,
    allowed: "finite and > 0 s, or left out",
};
/// The relative tolerance of an error control: looser than a tenth controls
/// nothing (the run would stop on its energy balance); tighter than 1e-15 is
/// below round-off.
pub const RTOL: OptionSpec = OptionSpec {
    name: "rtol",
    default: Some(1e-8),
    low: 1e-15,
    high: 0.1,
    low_open: false,
    allowed: "in [1e-15, 0.1]",
};
/// The absolute tolerance (m, m/s): an error of a metre (a metre a second)
/// in every coordinate controls nothing a vibro-impact run could resolve.
pub const ATOL: OptionSpec = OptionSpec {
    name: "atol",
    default: Some(1e-12),
    low: 0.0,
    high: 1.0,
    low_open: true,
    allowed: "in (0, 1] (m, m/s)",
};
/// Newmark's beta (default 1/4 with gamma 1/2: average acceleration).
pub const BETA: OptionSpec = OptionSpec {
    name: "beta",
    default: Some(0.25),
    low: 0.0,
    high: 0.5,
    low_open: false,
    allowed: "in [0, 0.5]",
};
/// Newmark's gamma.
pub const GAMMA: OptionSpec = OptionSpec {
    name: "gamma",
    default: Some(0.5),
    low: 0.5,
    high: 1.0,
    low_open: false,
    allowed: "in [0.5, 1]",
};
/// Generalised-alpha's spectral radius at infinite frequency.
pub const SPECTRAL_RADIUS: OptionSpec = OptionSpec {
    name: "spectral_radius",
    default: Some(0.9),
    low: 0.0,
    high: 1.0,
    low_open: false,
    allowed: "in [0, 1]",
};
/// The most steps (accepted and rejected) a run may take.
pub const MAX_STEPS: OptionSpec = OptionSpec {
    name: "max_steps",
    default: Some(1e9),
    low: 1.0,
    // 2^63 - 1, as the scenarios and Python take it (rounded to 2^63).
    high: i64::MAX as f64,
    low_open: false,
    allowed: "a whole number >= 1",
};

/// A run's end time (s).
pub const T_END: OptionSpec = OptionSpec {
    name: "t_end",
    default: None,
    low: 0.0,
    high: f64::MAX,
    low_open: true,
    allowed: "finite and > 0 s",
};
/// The relative tolerance of a run's energy-balance checks: the balance may
/// miss by this fraction of the energy in play (default 5 %, a guard against
/// impossible results, not an accuracy control). A tolerance of 1 already
/// accepts a residual as large as all of it, so a larger one checks nothing.
pub const ENERGY_TOLERANCE: OptionSpec = OptionSpec {
    name: "energy_tolerance",
    default: Some(5e-2),
    low: 0.0,
    high: 1.0,
    low_open: true,
    allowed: "in (0, 1]",
};
/// When a run's peaks and RMS start being recorded (s from the start).
pub const RECORD_FROM: OptionSpec = OptionSpec {
    name: "record_from",
    default: None,
    low: 0.0,
    high: f64::MAX,
    low_open: false,
    allowed: "finite and >= 0 s",
};
/// The period of a run's stroboscopic record (s).
pub const STROBE_PERIOD: OptionSpec = OptionSpec {
    name: "strobe_period",
    default: None,
    low: 0.0,
    high: f64::MAX,
    low_open: true,
    allowed: "finite and > 0 s",
};
/// The forcing period an analysis samples or shoots over (s).
pub const FORCING_PERIOD: OptionSpec = OptionSpec {
    name: "forcing_period",
    default: None,
    low: 0.0,
    high: f64::MAX,
    low_open: true,
    allowed: "finite and > 0 s",
};
/// An analysis's relative tolerance (a steady state's repeat, an orbit's
/// residual).
pub const TOLERANCE: OptionSpec = OptionSpec {
    name: "tolerance",
    default: None,
    low: 0.0,
    high: f64::MAX,
    low_open: true,
    allowed: "finite and > 0",
};
/// The default of `max_rows`, the history rows plus contacts a run may keep:
/// 20 million (under 1 GB of two-mass history), room for any run a
/// workstation can plot, yet a run growing without bound stops within seconds.
pub const DEFAULT_MAX_ROWS: u64 = 20_000_000;

/// The method options every method is given (and every one checked,
/// whatever the method, so that a wrong value is never silently ignored), in
/// the order they are checked.
pub const METHOD_OPTIONS: [OptionSpec; 5] = [RTOL, ATOL, BETA, GAMMA, SPECTRAL_RADIUS];

/// The default of `max_steps` as a whole number.
pub const DEFAULT_MAX_STEPS: u64 = 1_000_000_000;

/// A method: its name, kind, the steppings it takes and the options it
/// reads (beside `max_steps`, which every run takes).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodSpec {
    pub name: &'static str,
    pub kind: Kind,
    /// "events" first (every method's), then "fixed" where it takes it.
    pub steppings: &'static [&'static str],
    pub options: &'static [OptionSpec],
}

const EVENTS: &[&str] = &["events"];
const EVENTS_OR_FIXED: &[&str] = &["events", "fixed"];

/// The methods of a run, in the order the unknown-name message lists them.
pub const METHOD_SPECS: [MethodSpec; 7] = [
    MethodSpec {
        name: "rk4",
        kind: Kind::Explicit,
        steppings: EVENTS_OR_FIXED,
        options: &[DT, MAX_STEPS],
    },
    MethodSpec {
        name: "dopri5",
        kind: Kind::Adaptive,
        steppings: EVENTS,
        options: &[DT, RTOL, ATOL, MAX_STEPS],
    },
    MethodSpec {
        name: "dop853",
        kind: Kind::Adaptive,
        steppings: EVENTS,
        options: &[DT, RTOL, ATOL, MAX_STEPS],
    },
    MethodSpec {
        name: "newmark",
        kind: Kind::Paper,
        steppings: EVENTS_OR_FIXED,
        options: &[DT, BETA, GAMMA, MAX_STEPS],
    },
    MethodSpec {
        name: "newmark-implicit",
        kind: Kind::Implicit,
        steppings: EVENTS_OR_FIXED,
        options: &[DT, BETA, GAMMA, MAX_STEPS],
    },
    MethodSpec {
        name: "generalized-alpha",
        kind: Kind::Implicit,
        steppings: EVENTS_OR_FIXED,
        options: &[DT, SPECTRAL_RADIUS, MAX_STEPS],
    },
    MethodSpec {
        name: "exact",
        kind: Kind::Exact,
        steppings: EVENTS,
        options: &[DT, MAX_STEPS],
    },
];

/// The method named `name`, or the one error every front end gives for an
/// unknown name, listing the registry's names.
pub fn method(name: &str) -> Result<&'static MethodSpec> {
    METHOD_SPECS
        .iter()
        .find(|spec| spec.name == name)
        .ok_or_else(|| {
            let names: Vec<String> = METHOD_SPECS
                .iter()
                .map(|m| format!("{:?}", m.name))
                .collect();
            Error::Inconsistent(format!(
                "method must be one of {} for a [structure] system, got {name:?}",
                names.join(", ")
            ))
        })
}

/// The options of a method, by name; each method reads the ones it uses.
/// The default is the registry's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    pub rtol: f64,
    pub atol: f64,
    pub beta: f64,
    pub gamma: f64,
    pub spectral_radius: f64,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rtol: RTOL.default_value(),
            atol: ATOL.default_value(),
            beta: BETA.default_value(),
            gamma: GAMMA.default_value(),
            spectral_radius: SPECTRAL_RADIUS.default_value(),
        }
    }
}

/// A run's settings beside its method options, each checked against the
/// registry (`t_end`, `dt` where given, `energy_tolerance`), then the method
/// options ([`Options::checked`]); the first outside is named.
pub fn check_settings(
    t_end: f64,
    dt: Option<f64>,
    options: Options,
    energy_tolerance: f64,
) -> Result<Options> {
    T_END.check(t_end)?;
    if let Some(dt) = dt {
        DT.check(dt)?;
    }
    let options = options.checked()?;
    ENERGY_TOLERANCE.check(energy_tolerance)?;
    Ok(options)
}

impl Options {
    /// The options given, each left out (None) taking the registry's default.
    pub fn or_defaults(
        rtol: Option<f64>,
        atol: Option<f64>,
        beta: Option<f64>,
        gamma: Option<f64>,
        spectral_radius: Option<f64>,
    ) -> Self {
        let d = Self::default();
        Self {
            rtol: rtol.unwrap_or(d.rtol),
            atol: atol.unwrap_or(d.atol),
            beta: beta.unwrap_or(d.beta),
            gamma: gamma.unwrap_or(d.gamma),
            spectral_radius: spectral_radius.unwrap_or(d.spectral_radius),
        }
    }

    /// Every option checked against its range, in [`METHOD_OPTIONS`]'s order
    /// (whatever the method), or the first outside named.
    pub fn checked(&self) -> Result<Self> {
        Ok(Self {
            rtol: RTOL.check(self.rtol)?,
            atol: ATOL.check(self.atol)?,
            beta: BETA.check(self.beta)?,
            gamma: GAMMA.check(self.gamma)?,
            spectral_radius: SPECTRAL_RADIUS.check(self.spectral_radius)?,
        })
    }
}

#[cfg(test)]
#[path = "table_tests.rs"]
mod tests;
