//! The methods of a run by name, defined once: the table of methods (their
//! kinds, steppings, options, defaults and ranges, [`table`]), each model
//! kind's default method and stepping ([`defaults`]), the up-front
//! limits of a run ([`limits`]) and of an analysis's forcing period
//! ([`forcing`]), the stepper made once for a system, the
//! fixed step it takes, and the run. Every front end (the binding's runs, a
//! study's runs, Python's schemas through the binding) reads it, so that a
//! method means the same in each.

mod defaults;
mod forcing;
mod limits;
mod table;
pub mod two_mass;

pub use defaults::{ModelKind, RunDefaults, RUN_DEFAULTS, SYSTEM, TWO_MASS};
pub use forcing::{check_forcing_period, ForcingPlan};
pub use limits::{
    check_run, check_scales, check_step_within, check_steps_resolve, RunPlan, RunScales,
    MAX_PERIODS,
};
pub use table::{
    check_settings, method, Kind, MethodSpec, OptionSpec, Options, ATOL, BETA, DEFAULT_MAX_ROWS,
    DEFAULT_MAX_STEPS, DT, ENERGY_TOLERANCE, FORCING_PERIOD, GAMMA, MAX_STEPS, METHOD_OPTIONS,
    METHOD_SPECS, RECORD_FROM, RTOL, SPECTRAL_RADIUS, STROBE_PERIOD, TOLERANCE, T_END,
};

use crate::error::{EnergyAdvice, Error, Result};
use crate::kernel::events::{
    integrate_system, integrate_system_continued, integrate_system_observed, CarriedContact,
    RunOptions, Stepping, SystemSolution,
};
use crate::kernel::fixed;
use crate::kernel::memory::MAX_RECORD_BYTES;
use crate::kernel::observe::EventObserver;
use crate::methods::exact::ExactFlow;
use crate::methods::paper_newmark::PaperNewmark;
use crate::methods::steppers::{ExplicitRk, NewmarkFamily, SystemStepper};
use crate::model::assembly::Assembly;

/// A 0.2 method, made for one system.
#[derive(Debug, Clone)]
pub enum AnyStepper {
    Rk(ExplicitRk),
    Newmark(NewmarkFamily),
    /// The founding paper's Newmark, its contact force lagged one step.
    Paper(PaperNewmark),
    Exact(ExactFlow),
}

/// The methods' names, in the registry's order: what [`AnyStepper::new`]
/// makes, in the order its unknown-name message lists them.
pub const METHODS: [&str; 7] = {
    let mut names = [""; 7];
    let mut i = 0;
    while i < names.len() {
        names[i] = METHOD_SPECS[i].name;
        i += 1;
    }
    names
};

impl AnyStepper {
    /// The method named `method` for `system`, with its `options` (the
    /// registry's defaults where not given: `Options::default()`); every
    /// option checked against the registry's range whatever the method (a
    /// wrong value is never silently ignored), an unknown name refused with
    /// the registry's names.
    pub fn new(system: &Assembly, method: &str, options: &Options) -> Result<Self> {
        let spec = table::method(method)?;
        let Options {
            rtol,
            atol,
            beta,
            gamma,
            spectral_radius,
        } = options.checked()?;
        let len = system.state_len();
        Ok(match spec.name {
            "rk4" => Self::Rk(ExplicitRk::rk4(len)),
            "dopri5" => Self::Rk(ExplicitRk::dopri5(len, rtol, atol)),
            "dop853" => Self::Rk(ExplicitRk::dop853(len, rtol, atol)),
            "newmark" => Self::Paper(PaperNewmark::new(system, beta, gamma)?),
            "newmark-implicit" => Self::Newmark(NewmarkFamily::newmark(system, beta, gamma)),
            "generalized-alpha" => {
                Self::Newmark(NewmarkFamily::generalized_alpha(system, spectral_radius))
            }
            "exact" => Self::Exact(ExactFlow::new(system)?),
            // A name listed in the table without a stepper here: the test
            // every_listed_method_is_made catches it before a user does.
            other => {
                return Err(Error::Inconsistent(format!(
                    "method {other:?} is listed but not built"
                )))
            }
        })
    }

    /// The fixed step of a run to `t_end` given `dt` (the exact flow's own
    /// step, capped by `dt`), shortened to divide `strobe_period` (infinite:
    /// none) so that the steps land on its multiples; None for the adaptive
    /// methods without `dt`.
    pub fn step(&self, dt: Option<f64>, t_end: f64, strobe_period: f64) -> Option<f64> {
        let fit = |step: f64| {
            if strobe_period.is_finite() {
                strobe_period / (strobe_period / step - 1e-9).ceil().max(1.0)
            } else {
                step
            }
        };
        match self {
            // dt, when given, caps the flow's own step (a finer check of the
            // gaps between step ends).
            Self::Exact(flow) => Some(fit(dt.unwrap_or(f64::INFINITY).min(flow.step()).min(t_end))),
            _ => dt.map(fit),
        }
    }

    /// Whether this method may step `system` as `stepping` asks: fixed steps take a
    /// fixed-step method and compliant pairs only. The check a run makes when it starts
    /// ([`crate::kernel::fixed`]), for a caller preparing runs to refuse them up front.
    pub fn check_stepping(&self, system: &Assembly, stepping: Stepping) -> Result<()> {
        if stepping == Stepping::Events {
            return Ok(());
        }
        match self {
            Self::Rk(s) => fixed::check(system, s),
            Self::Newmark(s) => fixed::check(system, s),
            Self::Paper(s) => fixed::check(system, s),
            Self::Exact(s) => fixed::check(system, s),
        }
    }

    /// What a run of this method changes when its energy does not balance.
    fn energy_advice(&self) -> EnergyAdvice {
        match self {
            Self::Rk(s) if s.is_adaptive() => EnergyAdvice::Adaptive,
            Self::Rk(_) | Self::Newmark(_) | Self::Paper(_) => EnergyAdvice::FixedStep,
            Self::Exact(_) => EnergyAdvice::Exact,
        }
    }

    /// Integrate `system` from `y0` with this method.
    pub fn integrate(
        &mut self,
        system: &Assembly,
        y0: &[f64],
        options: &RunOptions,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<SystemSolution> {
        let advice = self.energy_advice();
        match self {
            Self::Rk(s) => integrate_system(system, s, y0, options, interrupt),
            Self::Newmark(s) => integrate_system(system, s, y0, options, interrupt),
            Self::Paper(s) => integrate_system(system, s, y0, options, interrupt),
            Self::Exact(s) => integrate_system(system, s, y0, options, interrupt),
        }
        .map_err(|e| e.advised(advice))
    }

    /// [`Self::integrate`] with `observer` told of the run's start, events
    /// and end (see [`crate::kernel::observe`]; steps cut at events).
    pub fn integrate_observed(
        &mut self,
        system: &Assembly,
        y0: &[f64],
        options: &RunOptions,
        interrupt: &mut dyn FnMut() -> bool,
        observer: &mut dyn EventObserver,
    ) -> Result<SystemSolution> {
        self.integrate_observed_continued(system, (y0, &[]), options, interrupt, observer)
    }

    /// [`Self::integrate_observed`] continuing a run from its final state,
    /// with the compliant contacts it left open (see
    /// [`Self::integrate_continued`]).
    pub fn integrate_observed_continued(
        &mut self,
        system: &Assembly,
        start: (&[f64], &[Option<CarriedContact>]),
        options: &RunOptions,
        interrupt: &mut dyn FnMut() -> bool,
        observer: &mut dyn EventObserver,
    ) -> Result<SystemSolution> {
        let (limit, advice) = (MAX_RECORD_BYTES, self.energy_advice());
        match self {
            Self::Rk(s) => {
                integrate_system_observed(system, s, start, options, interrupt, limit, observer)
            }
            Self::Newmark(s) => {
                integrate_system_observed(system, s, start, options, interrupt, limit, observer)
            }
            Self::Paper(s) => {
                integrate_system_observed(system, s, start, options, interrupt, limit, observer)
            }
            Self::Exact(s) => {
                integrate_system_observed(system, s, start, options, interrupt, limit, observer)
            }
        }
        .map_err(|e| e.advised(advice))
    }

    /// [`Self::integrate`] stepping as `stepping` says: cut at events, or
    /// in fixed steps (see [`crate::kernel::fixed`]).
    pub fn integrate_stepped(
        &mut self,
        system: &Assembly,
        y0: &[f64],
        options: &RunOptions,
        stepping: Stepping,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<SystemSolution> {
        self.integrate_continued(system, (y0, &[]), options, stepping, interrupt)
    }

    /// [`Self::integrate_stepped`] continuing a run from its final state
    /// `y0`, with the compliant contacts it left open `carried` (see
    /// [`crate::kernel::events::integrate_system_continued`]).
    pub fn integrate_continued(
        &mut self,
        system: &Assembly,
        start: (&[f64], &[Option<CarriedContact>]),
        options: &RunOptions,
        stepping: Stepping,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<SystemSolution> {
        let (limit, advice) = (MAX_RECORD_BYTES, self.energy_advice());
        match self {
            Self::Rk(s) => {
                integrate_system_continued(system, s, start, options, stepping, interrupt, limit)
            }
            Self::Newmark(s) => {
                integrate_system_continued(system, s, start, options, stepping, interrupt, limit)
            }
            Self::Paper(s) => {
                integrate_system_continued(system, s, start, options, stepping, interrupt, limit)
            }
            Self::Exact(s) => {
                integrate_system_continued(system, s, start, options, stepping, interrupt, limit)
            }
        }
        .map_err(|e| e.advised(advice))
    }
}
