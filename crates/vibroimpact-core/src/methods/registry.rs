//! The methods of a 0.2 run by name: the stepper made once for a system, the
//! fixed step it takes, and the run. What the binding's runs and a study's
//! runs share, so that a method means the same in both.

use crate::error::{within, Error, Result};
use crate::kernel::events::{
    integrate_system, integrate_system_stepped, RunOptions, Stepping, SystemSolution,
};
use crate::kernel::memory::MAX_RECORD_BYTES;
use crate::methods::exact::ExactFlow;
use crate::methods::paper_newmark::PaperNewmark;
use crate::methods::steppers::{ExplicitRk, NewmarkFamily};
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

/// The methods of a `[structure]` system, by name: what [`AnyStepper::new`]
/// makes, in the order its unknown-name message lists them.
pub const METHODS: [&str; 7] = [
    "rk4",
    "dopri5",
    "dop853",
    "newmark",
    "newmark-implicit",
    "generalized-alpha",
    "exact",
];

/// Newmark's `beta` in [0, 0.5] and `gamma` in [0.5, 1] (defaults 1/4, 1/2:
/// average acceleration), or an error naming the one outside.
fn newmark_options(beta: f64, gamma: f64) -> Result<(f64, f64)> {
    Ok((
        within("beta", beta, 0.0, 0.5, false, "in [0, 0.5]")?,
        within("gamma", gamma, 0.5, 1.0, false, "in [0.5, 1]")?,
    ))
}

impl AnyStepper {
    /// The method named `method` for `system`, with its settings.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        system: &Assembly,
        method: &str,
        rtol: f64,
        atol: f64,
        beta: f64,
        gamma: f64,
        spectral_radius: f64,
    ) -> Result<Self> {
        let len = system.state_len();
        Ok(match method {
            "rk4" => Self::Rk(ExplicitRk::rk4(len)),
            "dopri5" => Self::Rk(ExplicitRk::dopri5(len, rtol, atol)),
            "dop853" => Self::Rk(ExplicitRk::dop853(len, rtol, atol)),
            "newmark" => {
                let (beta, gamma) = newmark_options(beta, gamma)?;
                Self::Paper(PaperNewmark::new(system, beta, gamma)?)
            }
            "newmark-implicit" => {
                let (beta, gamma) = newmark_options(beta, gamma)?;
                Self::Newmark(NewmarkFamily::newmark(system, beta, gamma))
            }
            "generalized-alpha" => {
                Self::Newmark(NewmarkFamily::generalized_alpha(system, spectral_radius))
            }
            "exact" => Self::Exact(ExactFlow::new(system)?),
            other => {
                let names: Vec<String> = METHODS.iter().map(|m| format!("{m:?}")).collect();
                return Err(Error::Inconsistent(format!(
                    "method must be one of {} for a [structure] system, got {other:?}",
                    names.join(", ")
                )));
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

    /// Integrate `system` from `y0` with this method.
    pub fn integrate(
        &mut self,
        system: &Assembly,
        y0: &[f64],
        options: &RunOptions,
        interrupt: &mut dyn FnMut() -> bool,
    ) -> Result<SystemSolution> {
        match self {
            Self::Rk(s) => integrate_system(system, s, y0, options, interrupt),
            Self::Newmark(s) => integrate_system(system, s, y0, options, interrupt),
            Self::Paper(s) => integrate_system(system, s, y0, options, interrupt),
            Self::Exact(s) => integrate_system(system, s, y0, options, interrupt),
        }
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
        let limit = MAX_RECORD_BYTES;
        match self {
            Self::Rk(s) => {
                integrate_system_stepped(system, s, y0, options, stepping, interrupt, limit)
            }
            Self::Newmark(s) => {
                integrate_system_stepped(system, s, y0, options, stepping, interrupt, limit)
            }
            Self::Paper(s) => {
                integrate_system_stepped(system, s, y0, options, stepping, interrupt, limit)
            }
            Self::Exact(s) => {
                integrate_system_stepped(system, s, y0, options, stepping, interrupt, limit)
            }
        }
    }
}
