//! Study settings: the method and limits of each run, and the analysis it makes.

use crate::methods::registry::Options;

/// How each run of a study is made and what it keeps.
#[derive(Debug, Clone, PartialEq)]
pub struct StudySettings {
    pub method: String,
    pub dt: Option<f64>,
    /// The method's options (checked when its stepper is made).
    pub options: Options,
    pub max_steps: u64,
    pub energy_tolerance: f64,
    /// `"run"` (to `t_end`) or `"steady-state"` (whole forcing periods).
    pub analysis: Analysis,
    /// Whether to integrate the mean squares (the RMS metric).
    pub mean_square: bool,
    /// Fixed steps without cutting them at events, the runs advanced in
    /// lockstep: RK4 runs of one mass on a spring with one compliant damper,
    /// unforced ([`crate::analysis::ensemble`]), or of any small modal system the
    /// compact path takes ([`crate::analysis::lanes`]).
    pub lockstep: bool,
    /// Whether to carry the tangent flow for the largest Lyapunov exponent
    /// (runs and steady states: over the recorded time; orbits: from the
    /// largest multiplier).
    pub lyapunov: bool,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Analysis {
    /// A run to `t_end`, metrics from `record_from` on.
    Run { t_end: f64, record_from: f64 },
    /// `settle` then `record` periods (at least MAX_PERIOD: see
    /// `recorded_periods`) of the first harmonic excitation; settled when
    /// the stroboscopic state repeats after p <= 8 periods
    /// within `tolerance` (relative: see [`crate::analysis::settling::strobe_period`]).
    SteadyState {
        settle: u64,
        record: u64,
        tolerance: f64,
    },
    /// `settle` forcing periods, then Newton shooting for an orbit of
    /// `periods` periods from there (see [`crate::analysis::shooting`]): its Floquet
    /// multipliers, amplitude and impacts.
    Orbit { settle: u64, periods: u64 },
}
