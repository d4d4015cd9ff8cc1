//! What a two-mass run is asked to do: the method and its options, the
//! stepping, the step and end time, what to keep, and the run's limits (steps,
//! rows, energy balance), checked before it starts.

use crate::error::{at_least_one, Error, Result};
use crate::kernel::contact_balance::CONTACT_CREATION_LIMIT;
use crate::kernel::events::{self, RunOptions};
use crate::methods::registry::{self, ATOL, RTOL};

/// Tolerances of the adaptive methods: `rtol` relative, `atol` absolute (in
/// the units of each variable: m and m/s).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    pub rtol: f64,
    pub atol: f64,
}

/// The relative tolerance (`rtol`) a method with error control takes, and
/// its description: an error control looser than a tenth controls nothing
/// (the run would stop on its energy balance); tighter than 1e-15 is below
/// round-off. Every check of an rtol (here, the binding's, the Python
/// scenario's) reads these.
pub const RTOL_RANGE: (f64, f64) = (RTOL.low, RTOL.high);
pub const RTOL_ALLOWED: &str = RTOL.allowed;

/// The absolute tolerance (`atol`, m and m/s) a method with error control
/// takes, and its description: an error of a metre (a metre a second)
/// allowed in every coordinate controls nothing a vibro-impact run could
/// resolve (1e300 had been accepted). Every check of an atol reads these.
pub const ATOL_MAX: f64 = ATOL.high;
pub const ATOL_ALLOWED: &str = ATOL.allowed;

/// The largest `energy_tolerance`, and its description. The balance's
/// residual is measured against the energy in play (all the energy there was
/// and all the work done); a tolerance of 1 already accepts a residual as
/// large as all of it, so a larger one would check nothing (a run may then
/// report energy that never was). Every check of the tolerance (here, the
/// binding's, the Python scenario's) reads these.
pub const MAX_ENERGY_TOLERANCE: f64 = registry::ENERGY_TOLERANCE.high;
pub const ENERGY_TOLERANCE_ALLOWED: &str = registry::ENERGY_TOLERANCE.allowed;

/// An `energy_tolerance` in (0, [`MAX_ENERGY_TOLERANCE`]]: the registry's check.
pub fn checked_energy_tolerance(tolerance: f64) -> Result<f64> {
    registry::ENERGY_TOLERANCE.check(tolerance)
}

/// How a fixed-step run times contact instants: the kernel's own.
pub use crate::kernel::events::ContactTiming;

/// Options of the methods, by name; each method reads the ones it uses:
/// the registry's, with its defaults.
pub type MethodOptions = registry::Options;

/// The integration method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// The paper's Newmark-beta with the contact force lagged one step.
    Newmark { beta: f64, gamma: f64 },
    /// Newmark-beta with Newton iterations on the contact force.
    NewmarkImplicit { beta: f64, gamma: f64 },
    /// Chung-Hulbert generalised-alpha.
    GeneralizedAlpha { spectral_radius: f64 },
    /// Classical fourth-order Runge-Kutta.
    Rk4,
    /// Dormand-Prince 5(4), adaptive.
    Dopri5(Tolerances),
    /// DOP853, adaptive.
    Dop853(Tolerances),
}

impl Method {
    pub const NAMES: &'static str =
        "\"newmark\", \"newmark-implicit\", \"generalized-alpha\", \"rk4\", \"dopri5\", \"dop853\"";

    /// Method by name. Every option is checked whatever the method, so that
    /// a wrong value is never silently ignored.
    pub fn parse(name: &str, options: &MethodOptions) -> Result<Self> {
        // The registry's ranges, in its order (rtol, atol, beta, gamma,
        // spectral_radius).
        let registry::Options {
            rtol,
            atol,
            beta,
            gamma,
            spectral_radius,
        } = options.checked()?;
        let tolerances = Tolerances { rtol, atol };
        match name {
            "newmark" => Ok(Self::Newmark { beta, gamma }),
            "newmark-implicit" => Ok(Self::NewmarkImplicit { beta, gamma }),
            "generalized-alpha" => Ok(Self::GeneralizedAlpha { spectral_radius }),
            "rk4" => Ok(Self::Rk4),
            "dopri5" => Ok(Self::Dopri5(tolerances)),
            "dop853" => Ok(Self::Dop853(tolerances)),
            _ => Err(Error::UnknownChoice {
                field: "method",
                allowed: Self::NAMES,
                value: name.to_string(),
            }),
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Self::Newmark { .. } => "newmark",
            Self::NewmarkImplicit { .. } => "newmark-implicit",
            Self::GeneralizedAlpha { .. } => "generalized-alpha",
            Self::Rk4 => "rk4",
            Self::Dopri5(_) => "dopri5",
            Self::Dop853(_) => "dop853",
        }
    }

    /// Whether the step size is adaptive (dt is then only the first step).
    pub fn is_adaptive(&self) -> bool {
        matches!(self, Self::Dopri5(_) | Self::Dop853(_))
    }

    /// The founding paper's two methods also run in its fixed stepping.
    pub fn has_fixed_stepping(&self) -> bool {
        matches!(self, Self::Newmark { .. } | Self::Rk4)
    }
}

/// How steps meet contact events.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stepping {
    /// The founding paper's way: fixed steps that may straddle an onset or a
    /// separation (contact instants then located or counted afterwards).
    Fixed,
    /// Events located to round-off, the step cut there and restarted.
    Events,
}

impl Stepping {
    pub const NAMES: &'static str = "\"fixed\", \"events\"";
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "fixed" => Ok(Self::Fixed),
            "events" => Ok(Self::Events),
            _ => Err(Error::UnknownChoice {
                field: "stepping",
                allowed: Self::NAMES,
                value: name.to_string(),
            }),
        }
    }
}

/// Default of `max_rows`, the history rows plus contacts a run may keep: 20
/// million. A history row is 48 bytes (six f64 columns) and a contact 72
/// (nine), so that is under 1 GB of history (1.44 GB of contacts at most):
/// room for any run a workstation can plot or save, yet a run that would grow
/// without bound (an adaptive run keeping every step) stops within seconds
/// with a clear message instead of exhausting the machine's memory.
pub const DEFAULT_MAX_ROWS: u64 = registry::DEFAULT_MAX_ROWS;
/// Default of `energy_tolerance`: the energy balance may miss by 5 % of the
/// energy in play. A guard against impossible results, not an accuracy
/// control (that is dt or rtol): on the founding paper's collision every
/// method but the paper's closes the balance to 1e-3 or better even at the
/// coarsest steps studied (4e-3 s, rtol 1e-4), and the paper's lagged Newmark
/// at its own dt = 1e-4 s stays within 2.3 % over 1e7 steps of rattling; its
/// run at dt = 1e-3 s misses by 8.6 % in one collision (it rebounds at 1.049
/// of the approach speed) and is refused, as are the gross failures (a
/// contact stepped over whole, "dissipating" a million times the energy
/// there is).
pub const DEFAULT_ENERGY_TOLERANCE: f64 = match registry::ENERGY_TOLERANCE.default {
    Some(tolerance) => tolerance,
    None => 0.0,
};
/// Most fixed steps a run may take: beyond 2^53 the step indices, and so the
/// step times `n dt`, are no longer exact in f64.
const MAX_EXACT_STEPS: f64 = 9_007_199_254_740_992.0;

/// How to integrate and what to keep.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Settings {
    pub method: Method,
    /// Step, s (> 0): required by the fixed-step methods, the first step of
    /// the adaptive ones (chosen automatically when None).
    pub dt: Option<f64>,
    /// End time, s (> 0); rounded up to a whole number of steps by the
    /// fixed-step methods.
    pub t_end: f64,
    /// Keep every `every`-th step in the history (the last step always).
    pub every: u64,
    pub timing: ContactTiming,
    pub stepping: Stepping,
    /// Most steps (accepted and rejected) a run may take.
    pub max_steps: u64,
    /// Whether to keep the time history; without it a run keeps only its
    /// contacts and statistics, in constant memory apart from the contacts.
    pub history: bool,
    /// Most history rows plus contacts a run may keep.
    pub max_rows: u64,
    /// Relative tolerance of the energy-balance checks (see [`super::simulate`]).
    pub energy_tolerance: f64,
}

impl Settings {
    /// `stepping` None takes the method's default, the registry's for the
    /// two-mass damper ([`registry::TWO_MASS`]): "fixed" for the paper's
    /// "newmark" and "rk4", "events" for the others (which have no other).
    /// The history is kept, within [`DEFAULT_MAX_ROWS`], and the energy
    /// checked to [`DEFAULT_ENERGY_TOLERANCE`]; see [`Settings::with_limits`].
    /// A fixed-step run of more than `max_steps` steps is refused here.
    pub fn new(
        method: Method,
        dt: Option<f64>,
        t_end: f64,
        every: u64,
        timing: ContactTiming,
        stepping: Option<Stepping>,
        max_steps: u64,
    ) -> Result<Self> {
        // The registry's ranges and messages, as every other path's.
        let dt = dt.map(|dt| registry::DT.check(dt)).transpose()?;
        let t_end = registry::T_END.check(t_end)?;
        at_least_one("every", every)?;
        at_least_one("max_steps", max_steps)?;
        if dt.is_none() && !method.is_adaptive() {
            return Err(Error::Inconsistent(format!(
                "dt is required for method {:?} (a step in s > 0)",
                method.name()
            )));
        }
        if let Some(dt) = dt.filter(|_| !method.is_adaptive()) {
            registry::check_step_within(dt, t_end, method.name(), "dt")?;
        }
        let stepping = match stepping {
            Some(stepping) => stepping,
            None => Stepping::parse(registry::TWO_MASS.stepping(method.name())?)?,
        };
        if stepping == Stepping::Fixed && !method.has_fixed_stepping() {
            return Err(Error::Inconsistent(format!(
                "stepping \"fixed\" is the founding paper's, for methods \"newmark\" and \"rk4\" only, not {:?}",
                method.name()
            )));
        }
        if stepping == Stepping::Events && timing == ContactTiming::StepCount {
            return Err(Error::Inconsistent(
                "contact_timing \"step-count\" needs stepping \"fixed\": with events the contact instants are exact"
                    .into(),
            ));
        }
        let settings = Self {
            method,
            dt,
            t_end,
            every,
            timing,
            stepping,
            max_steps,
            history: true,
            max_rows: DEFAULT_MAX_ROWS,
            energy_tolerance: DEFAULT_ENERGY_TOLERANCE,
        };
        settings.check_steps()?;
        Ok(settings)
    }

    /// The same settings with the run's other limits: whether to keep the
    /// history, the history rows plus contacts it may keep (`max_rows`, at
    /// least 1) and the relative tolerance of the energy checks
    /// (`energy_tolerance`, in (0, 1]); None keeps the default. A fixed-step
    /// history that cannot fit is refused here.
    pub fn with_limits(
        self,
        history: bool,
        max_rows: Option<u64>,
        energy_tolerance: Option<f64>,
    ) -> Result<Self> {
        let max_rows = at_least_one("max_rows", max_rows.unwrap_or(DEFAULT_MAX_ROWS))?;
        let energy_tolerance = match energy_tolerance {
            Some(tolerance) => checked_energy_tolerance(tolerance)?,
            None => DEFAULT_ENERGY_TOLERANCE,
        };
        let settings = Self {
            history,
            max_rows,
            energy_tolerance,
            ..self
        };
        settings.check_memory()?;
        Ok(settings)
    }

    /// The same settings through [`Settings::new`] and
    /// [`Settings::with_limits`]: a literal's fields (they are public) in
    /// their ranges, and a history that fits in memory.
    pub fn checked(&self) -> Result<Self> {
        Self::new(
            self.method,
            self.dt,
            self.t_end,
            self.every,
            self.timing,
            Some(self.stepping),
            self.max_steps,
        )?
        .with_limits(
            self.history,
            Some(self.max_rows),
            Some(self.energy_tolerance),
        )
    }

    /// The most energy a contact may create, relative to the energy in play:
    /// `energy_tolerance`, and for every method but the paper's lagged
    /// Newmark no more than [`CONTACT_CREATION_LIMIT`].
    pub fn contact_creation_limit(&self) -> f64 {
        match self.method {
            Method::Newmark { .. } => self.energy_tolerance,
            _ => self.energy_tolerance.min(CONTACT_CREATION_LIMIT),
        }
    }

    /// Refuses a fixed-step run whose step count `t_end / dt` is beyond
    /// `max_steps` or beyond what f64 counts exactly (2^53), before any step.
    pub fn check_steps(&self) -> Result<()> {
        let Some(dt) = self.dt.filter(|_| !self.method.is_adaptive()) else {
            return Ok(());
        };
        let count = self.step_count(dt);
        if count > MAX_EXACT_STEPS {
            return Err(Error::Inconsistent(format!(
                "t_end / dt = {count:.3e} steps, beyond 2^53 (where the step times are no longer \
                 exact, whatever max_steps): raise dt or shorten t_end"
            )));
        }
        if count > self.max_steps as f64 {
            return Err(Error::Inconsistent(format!(
                "t_end / dt = {count:.0} steps, more than max_steps = {}: raise dt, shorten t_end or \
                 raise max_steps",
                self.max_steps
            )));
        }
        Ok(())
    }

    /// Refuses a history beyond `max_rows`: a fixed-step run keeps
    /// `t_end / dt / every` rows at least (an event-driven one a few more,
    /// and an adaptive one an unknown number: those stop at `max_rows`).
    pub fn check_memory(&self) -> Result<()> {
        if self.method.is_adaptive() {
            return Ok(());
        }
        self.check_rows(self.steps() / self.every + 2)
    }

    /// Refuses a history of `rows` rows (if kept) beyond `max_rows`.
    pub(crate) fn check_rows(&self, rows: u64) -> Result<()> {
        if self.history && rows > self.max_rows {
            return Err(Error::Inconsistent(format!(
                "the history would keep {rows} rows (t_end / dt / every), more than max_rows = {}: \
                 raise every, set history = false, shorten t_end or raise max_rows",
                self.max_rows
            )));
        }
        // Six f64 columns a row.
        if self.history && rows.saturating_mul(48) > crate::kernel::memory::MAX_RECORD_BYTES {
            return Err(Error::Inconsistent(format!(
                "the history would keep {rows} rows (t_end / dt / every) of 48 bytes, more than the \
                 {} MiB a run's records may take: raise every, set history = false or shorten t_end",
                crate::kernel::memory::MAX_RECORD_BYTES >> 20
            )));
        }
        Ok(())
    }

    /// `t_end / dt` rounded up, as f64 (a relative 1e-9 of slack keeps
    /// `0.3 / 1e-4` at 3000 despite rounding); infinite when it overflows.
    fn step_count(&self, dt: f64) -> f64 {
        // The kernel's count: its last step ends within 1e-9 of a step of
        // t_end (`Schedule::at_end`). A slack relative to the count had
        // dropped 10 of 1e10 steps from the message.
        ((self.t_end / dt) - 1e-9).ceil().max(1.0)
    }

    /// The general kernel's options for this run of the two-mass preset
    /// ([`crate::ImpactDamper::assembly`]), as a 0.2 run of the same system
    /// takes them: no reductions.
    pub fn run_options(&self) -> RunOptions {
        RunOptions {
            dt: self.dt,
            t_end: self.t_end,
            every: self.every,
            keep_history: self.history,
            max_steps: self.max_steps,
            max_rows: self.max_rows,
            energy_tolerance: self.energy_tolerance,
            reduce: Default::default(),
        }
    }

    /// The general kernel's stepping for this run (fixed steps with their
    /// contact timing, or events).
    pub fn kernel_stepping(&self) -> events::Stepping {
        match self.stepping {
            Stepping::Events => events::Stepping::Events,
            Stepping::Fixed => events::Stepping::Fixed {
                contact_timing: self.timing,
            },
        }
    }

    /// Number of fixed steps: `t_end / dt` rounded up; 0 without dt.
    pub fn steps(&self) -> u64 {
        match self.dt {
            // Saturates for an adaptive method's tiny first step; a fixed
            // step's count is checked by `check_steps`.
            Some(dt) => self.step_count(dt) as u64,
            None => 0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rtol_description_states_its_range() {
        crate::testing::timeout(10, || {
            let stated = format!("in [{:e}, {}]", RTOL_RANGE.0, RTOL_RANGE.1);
            assert_eq!(RTOL_ALLOWED, stated);
        });
    }

    #[test]
    fn energy_tolerance_beyond_its_bound_is_refused() {
        crate::testing::timeout(10, || {
            let stated = format!("in (0, {}]", MAX_ENERGY_TOLERANCE);
            assert_eq!(ENERGY_TOLERANCE_ALLOWED, stated);
            let settings = Settings::new(
                Method::Rk4,
                Some(1e-3),
                1.0,
                1,
                ContactTiming::Located,
                None,
                1_000_000,
            )
            .unwrap();
            assert!(settings.with_limits(true, None, Some(1.0)).is_ok());
            for bad in [1.0 + 1e-12, 2.0, 1e300, f64::INFINITY, 0.0, -0.5, f64::NAN] {
                let err = settings.with_limits(true, None, Some(bad)).unwrap_err();
                let text = err.to_string();
                assert!(
                    text.contains("energy_tolerance") && text.contains("in (0, 1]"),
                    "{bad}: {text}"
                );
            }
        });
    }

    /// A fixed step longer than the run is refused, naming dt, t_end and
    /// the method; a step of the whole run is not, nor an adaptive method's
    /// first step longer than the run (it is cut to the run).
    #[test]
    fn a_fixed_step_longer_than_the_run_is_refused() {
        crate::testing::timeout(10, || {
            let settings = |method: Method, dt: f64, t_end: f64| {
                let timing = ContactTiming::Located;
                Settings::new(method, Some(dt), t_end, 1, timing, None, 1_000_000)
            };
            for method in [
                Method::Rk4,
                Method::Newmark {
                    beta: 0.25,
                    gamma: 0.5,
                },
            ] {
                let name = method.name();
                let text = settings(method, 0.5, 0.3).unwrap_err().to_string();
                let said = format!(
                    "dt must be at most t_end (0.3 s) for the fixed-step method '{name}', got 0.5"
                );
                assert_eq!(text, said);
                let above = f64::from_bits(0.3f64.to_bits() + 1);
                assert!(
                    settings(method, above, 0.3).is_err(),
                    "{name}: one ulp above"
                );
                assert!(settings(method, 0.3, 0.3).is_ok(), "{name}: the whole run");
            }
            let tolerances = Tolerances {
                rtol: 1e-8,
                atol: 1e-12,
            };
            assert!(settings(Method::Dop853(tolerances), 0.5, 0.3).is_ok());
        });
    }
}
