//! The integration kernel: steps any integrator over any contact law, keeps a
//! thinned time history and builds the table of contacts, with contact
//! instants located inside the step.

use crate::contact::{Contact, ContactLaw, LawVisitor};
use crate::error::{positive, within, Error, Result};
use crate::events::integrate_events;
use crate::hermite;
use crate::integrators::{Integrator, Newmark, Rk4};
use crate::model::{Excitation, Free, Model};
use crate::steppers::{Dop853Stepper, Dopri5Stepper, NewmarkFamily, Rk4Stepper, Tolerances};
use crate::system::{ImpactDamper, State};

/// How contact instants are reported.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactTiming {
    /// Onset and separation located inside the step (cubic Hermite root of
    /// the indentation on the step's end values and rates).
    Located,
    /// The founding paper's way: the first sample in contact and the first
    /// sample out of it, so durations are whole multiples of `dt`.
    StepCount,
}

impl ContactTiming {
    pub const NAMES: &'static str = "\"located\", \"step-count\"";
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "located" => Ok(Self::Located),
            "step-count" => Ok(Self::StepCount),
            _ => Err(Error::UnknownChoice {
                field: "contact_timing",
                allowed: Self::NAMES,
                value: name.to_string(),
            }),
        }
    }
}

/// Options of the methods, by name; each method reads the ones it uses.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MethodOptions {
    /// Newmark's beta, in [0, 0.5] (default 1/4).
    pub beta: f64,
    /// Newmark's gamma, in [0.5, 1] (default 1/2).
    pub gamma: f64,
    /// Generalised-alpha's spectral radius at infinite frequency, in [0, 1].
    pub spectral_radius: f64,
    /// Relative tolerance of the adaptive methods.
    pub rtol: f64,
    /// Absolute tolerance of the adaptive methods (m and m/s).
    pub atol: f64,
}

impl Default for MethodOptions {
    fn default() -> Self {
        Self {
            beta: 0.25,
            gamma: 0.5,
            spectral_radius: 0.9,
            rtol: 1e-8,
            atol: 1e-12,
        }
    }
}

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
        let beta = within("beta", options.beta, 0.0, 0.5, false, "in [0, 0.5]")?;
        let gamma = within("gamma", options.gamma, 0.5, 1.0, false, "in [0.5, 1]")?;
        let spectral_radius = within(
            "spectral_radius",
            options.spectral_radius,
            0.0,
            1.0,
            false,
            "in [0, 1]",
        )?;
        let tolerances = Tolerances {
            rtol: within("rtol", options.rtol, 1e-15, 0.1, false, "in [1e-15, 0.1]")?,
            atol: positive("atol", options.atol)?,
        };
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
pub const DEFAULT_MAX_ROWS: u64 = 20_000_000;
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
pub const DEFAULT_ENERGY_TOLERANCE: f64 = 5e-2;
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
    /// Relative tolerance of the energy-balance checks (see [`simulate`]).
    pub energy_tolerance: f64,
}

impl Settings {
    /// `stepping` None takes the method's default: "fixed" for the paper's
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
        let dt = dt.map(|dt| positive("dt", dt)).transpose()?;
        let t_end = positive("t_end", t_end)?;
        if every == 0 {
            return Err(Error::InvalidParameter {
                field: "every",
                allowed: "a whole number >= 1",
                value: 0.0,
            });
        }
        if max_steps == 0 {
            return Err(Error::InvalidParameter {
                field: "max_steps",
                allowed: "a whole number >= 1",
                value: 0.0,
            });
        }
        if dt.is_none() && !method.is_adaptive() {
            return Err(Error::Inconsistent(format!(
                "dt is required for method {:?} (a step in s > 0)",
                method.name()
            )));
        }
        let default = if method.has_fixed_stepping() {
            Stepping::Fixed
        } else {
            Stepping::Events
        };
        let stepping = stepping.unwrap_or(default);
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
    /// (`energy_tolerance`, positive); None keeps the default. A fixed-step
    /// history that cannot fit is refused here.
    pub fn with_limits(
        self,
        history: bool,
        max_rows: Option<u64>,
        energy_tolerance: Option<f64>,
    ) -> Result<Self> {
        let max_rows = max_rows.unwrap_or(DEFAULT_MAX_ROWS);
        if max_rows == 0 {
            return Err(Error::InvalidParameter {
                field: "max_rows",
                allowed: "a whole number >= 1",
                value: 0.0,
            });
        }
        let energy_tolerance = match energy_tolerance {
            Some(tolerance) => positive("energy_tolerance", tolerance)?,
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
        Ok(())
    }

    /// `t_end / dt` rounded up, as f64 (a relative 1e-9 of slack keeps
    /// `0.3 / 1e-4` at 3000 despite rounding); infinite when it overflows.
    fn step_count(&self, dt: f64) -> f64 {
        ((self.t_end / dt) * (1.0 - 1e-9)).ceil().max(1.0)
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

/// One contact, from onset to separation. Speeds are relative normal speeds
/// (m/s, positive); a contact still open at the end has NaN separation,
/// duration, rebound speed, restitution and energy change.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactRecord {
    /// s.
    pub onset: f64,
    /// s.
    pub separation: f64,
    /// s.
    pub duration: f64,
    /// m.
    pub max_indentation: f64,
    /// Indentation rate at onset, m/s.
    pub approach_speed: f64,
    /// Separation speed at the end of the contact, m/s.
    pub rebound_speed: f64,
    /// Effective restitution: `rebound_speed / approach_speed`.
    pub restitution: f64,
    /// Work done during the contact by the contact's dissipative forces (the
    /// law's hysteresis and the contact damper `c1`), J, >= 0: the integral
    /// of `(F - F_elastic) * delta'` over the contact, as the run integrates
    /// it. The main damper `C` and any external force are not in it.
    pub energy_dissipated: f64,
    /// Net change of the whole system's mechanical energy over the contact
    /// (kinetic energy of both masses, main spring and contact elastic energy,
    /// at separation minus at onset), J. Without a main damper or external
    /// force it is `-energy_dissipated` (to the method's accuracy: the
    /// contact's energy balance); with them it also holds their work during
    /// the contact, which may make it positive.
    pub energy_change: f64,
}

/// Time history columns (SI units), one row per kept step.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct History {
    pub time: Vec<f64>,
    pub main_displacement: Vec<f64>,
    pub main_velocity: Vec<f64>,
    pub impact_displacement: Vec<f64>,
    pub impact_velocity: Vec<f64>,
    /// Force between the bodies (law + contact damper), N; > 0 pushes apart.
    pub contact_force: Vec<f64>,
}

impl History {
    fn with_capacity(rows: usize) -> Self {
        Self {
            time: Vec::with_capacity(rows),
            main_displacement: Vec::with_capacity(rows),
            main_velocity: Vec::with_capacity(rows),
            impact_displacement: Vec::with_capacity(rows),
            impact_velocity: Vec::with_capacity(rows),
            contact_force: Vec::with_capacity(rows),
        }
    }

    fn reserve_exact(&mut self, rows: usize) {
        self.time.reserve_exact(rows);
        self.main_displacement.reserve_exact(rows);
        self.main_velocity.reserve_exact(rows);
        self.impact_displacement.reserve_exact(rows);
        self.impact_velocity.reserve_exact(rows);
        self.contact_force.reserve_exact(rows);
    }

    #[inline(always)]
    fn push(&mut self, time: f64, s: &State, force: f64) {
        self.time.push(time);
        self.main_displacement.push(s.main_displacement);
        self.main_velocity.push(s.main_velocity);
        self.impact_displacement.push(s.impact_displacement);
        self.impact_velocity.push(s.impact_velocity);
        self.contact_force.push(force);
    }
}

/// What a run keeps, within `max_rows`: the history (if kept) and the
/// contacts. Storage grows only as far as `max_rows` allows, so the rows
/// allocated never exceed it; a row or a contact beyond it stops the run with
/// [`Error::RowLimit`].
pub(crate) struct Records {
    pub(crate) history: History,
    pub(crate) contacts: Vec<ContactRecord>,
    keep_history: bool,
    max_rows: u64,
}

impl Records {
    /// Room for `rows` history rows from the start (as far as `max_rows`
    /// allows; an up-front check has refused a fixed-step history beyond it).
    pub(crate) fn new(settings: &Settings, rows: u64) -> Self {
        let rows = if settings.history {
            rows.min(settings.max_rows)
        } else {
            0
        };
        Self {
            history: History::with_capacity(rows as usize),
            contacts: Vec::new(),
            keep_history: settings.history,
            max_rows: settings.max_rows,
        }
    }

    /// Whether the history is kept at all.
    #[inline(always)]
    pub(crate) fn keeps_history(&self) -> bool {
        self.keep_history
    }

    fn full(&self, time: f64) -> Error {
        Error::RowLimit {
            time,
            max_rows: self.max_rows,
            rows: self.history.time.len() as u64,
            contacts: self.contacts.len() as u64,
            advice: if self.keep_history {
                "raise every, set history = false, shorten t_end or raise max_rows"
            } else {
                "the contacts alone fill it: shorten t_end or raise max_rows"
            },
        }
    }

    /// How many more rows may be allocated: as many as the `current` length
    /// (at least `least`), as far as `max_rows` allows.
    fn growth(&self, current: usize, least: usize) -> usize {
        let allocated = (self.history.time.capacity() + self.contacts.capacity()) as u64;
        let room = self.max_rows.saturating_sub(allocated);
        (current.max(least) as u64).min(room) as usize
    }

    /// Keeps one history row (when the history is kept).
    #[inline(always)]
    pub(crate) fn keep(&mut self, time: f64, s: &State, force: f64) -> Result<()> {
        if !self.keep_history {
            return Ok(());
        }
        if self.history.time.len() == self.history.time.capacity() {
            self.grow_history(time)?;
        }
        self.history.push(time, s, force);
        Ok(())
    }

    #[cold]
    #[inline(never)]
    fn grow_history(&mut self, time: f64) -> Result<()> {
        let more = self.growth(self.history.time.len(), 64);
        if more == 0 {
            return Err(self.full(time));
        }
        self.history.reserve_exact(more);
        Ok(())
    }

    /// Keeps one contact record; `time` is the run's time, for the message.
    pub(crate) fn contact(&mut self, record: ContactRecord, time: f64) -> Result<()> {
        if self.contacts.len() == self.contacts.capacity() {
            // Eight at first: a small allocation, as most runs have few contacts.
            let more = self.growth(self.contacts.len(), 8);
            if more == 0 {
                return Err(self.full(time));
            }
            self.contacts.reserve_exact(more);
        }
        self.contacts.push(record);
        Ok(())
    }
}

/// What a run returns.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
    /// Empty when the run kept no history.
    pub history: History,
    pub contacts: Vec<ContactRecord>,
    /// Steps taken (accepted).
    pub steps: u64,
    /// Steps rejected by the error control of the adaptive methods.
    pub rejected_steps: u64,
    /// Touches shallower than round-off that were not treated as contacts.
    pub grazing_contacts: u64,
    /// Right-hand-side (force) evaluations.
    pub rhs_evaluations: u64,
    pub final_time: f64,
    pub final_state: State,
    /// Largest relative growth of the mechanical energy of an unforced system
    /// over the run, `max(E) / E(0) - 1` (checked every few steps); NaN when
    /// forced or starting at rest. Physically it can only be <= 0.
    pub energy_growth: f64,
    /// Largest residual of the energy balance found by the checks, relative
    /// to the energy in play (see [`simulate`]); NaN when nothing was in play
    /// (a system at rest). The run is refused when it exceeds the tolerance.
    pub energy_residual: f64,
}

/// A contact being followed.
#[derive(Debug, Clone, Copy)]
struct OpenContact {
    side: f64,
    onset: f64,
    approach_speed: f64,
    max_indentation: f64,
    dissipated: f64,
    /// Mechanical energy at onset, J.
    energy: f64,
    /// The ledger's non-conservative work at onset, J.
    work: f64,
}

/// How often (in steps) the kernel asks whether to stop; a power of two, a
/// multiple of `ENERGY_INTERVAL`.
const INTERRUPT_INTERVAL: u64 = 1 << 16;
/// How often (in steps) the energy balance is checked; a power of two.
const ENERGY_INTERVAL: u64 = 32;
/// An unforced system whose energy grows by more than this factor has blown up.
const ENERGY_GROWTH_LIMIT: f64 = 1.5;

/// Refuses a start with the bodies interpenetrating (indentation beyond
/// round-off): no contact law gives that state a meaning (its onset, approach
/// speed and restitution would be invented). At the wall is fine.
pub(crate) fn check_start<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    initial: &State,
) -> Result<()> {
    let u = initial.relative_displacement();
    let indentation = u.abs() - model.clearance;
    let round_off = 4.0
        * f64::EPSILON
        * (initial.main_displacement.abs() + initial.impact_displacement.abs() + model.clearance);
    if indentation > round_off {
        return Err(Error::Inconsistent(format!(
            "the initial state starts the impact mass {indentation:.6e} m inside the wall: \
             |impact_displacement - main_displacement| = {:e} m is more than the clearance {:e} m; \
             start with |impact_displacement - main_displacement| <= clearance (at the wall at most)",
            u.abs(),
            model.clearance
        )));
    }
    Ok(())
}

/// The work of the main damper `C` over the fixed-step kernel's equal steps
/// `dt`: the trapezoidal sum of `C w'^2`, from the kernel's sum of the squares
/// of `w'` at the step ends (`squares += w1'^2`, one multiply and one add a
/// step in the hot loop), with Euler-Maclaurin's end correction at each
/// check, so that it is fourth order wherever the motion is smooth.
pub(crate) struct DamperWork {
    damping: f64,
    dt: f64,
    /// `w'^2` at the start.
    start: f64,
    /// `w' w''` at the start, for the end correction.
    start_slope: f64,
}

impl DamperWork {
    /// From the start's main velocity and acceleration.
    pub(crate) fn new(damping: f64, dt: f64, velocity: f64, acceleration: f64) -> Self {
        Self {
            damping,
            dt,
            start: velocity * velocity,
            start_slope: velocity * acceleration,
        }
    }

    /// The work so far without the end correction, J, from the sum of
    /// squares and the main velocity now (for differences over a contact,
    /// where the correction is of the order of the contact's own quadrature
    /// error).
    #[inline(always)]
    pub(crate) fn so_far(&self, squares: f64, velocity: f64) -> f64 {
        // The trapezoidal sum: every square twice, less half of each end's.
        0.5 * self.damping * self.dt * (2.0 * squares - velocity * velocity + self.start)
    }

    /// The work so far, J, with the end correction, from the sum of squares
    /// and the main velocity and acceleration now.
    pub(crate) fn corrected(&self, squares: f64, velocity: f64, acceleration: f64) -> f64 {
        let correction = self.dt * self.dt / 6.0 * (velocity * acceleration - self.start_slope);
        self.so_far(squares, velocity) - self.damping * correction
    }
}

/// The integral of `w'^2` over the step `s0 -> s1` of length `h`, m^2/s:
/// exact for the step's cubic Hermite interpolant of `w`, whose velocity is
/// the quadratic through `w0'`, `(3/2)(w1 - w0)/h - (w0' + w1')/4` at
/// mid-step, and `w1'` (fourth order, from the step's end values alone).
#[inline(always)]
pub(crate) fn speed_squared_integral(h: f64, s0: &State, s1: &State) -> f64 {
    let (a, b) = (h * s0.main_velocity, h * s1.main_velocity);
    let m = 1.5 * (s1.main_displacement - s0.main_displacement) - 0.25 * (a + b);
    // h^2 times the integral of the quadratic's square over [0, 1].
    let squares = 2.0 * (a * a + b * b) + 8.0 * m * m + 2.0 * m * (a + b) - a * b;
    squares / (15.0 * h)
}

/// The external force's work over the step `s0 -> s1` of length `h` from
/// `time`, J: Simpson's rule on `F(t) w'(t)`, `w'` the velocity of the
/// step's cubic Hermite interpolant.
#[inline(always)]
pub(crate) fn external_work<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    time: f64,
    h: f64,
    s0: &State,
    s1: &State,
) -> f64 {
    if X::IS_FREE {
        return 0.0;
    }
    // Velocities times h at 0, 1/2 and 1.
    let (a, b) = (h * s0.main_velocity, h * s1.main_velocity);
    let m = 1.5 * (s1.main_displacement - s0.main_displacement) - 0.25 * (a + b);
    let f0 = model.external_force(time);
    let fm = model.external_force(time + 0.5 * h);
    let f1 = model.external_force(time + h);
    (f0 * a + 4.0 * fm * m + f1 * b) / 6.0
}

/// The energy bookkeeping of a run, shared by both kernels.
///
/// Checked every few steps: the mechanical energy now, plus the work of the
/// dissipative forces so far (the contact's, summed by the kernel, and the
/// main damper's, see [`DamperWork`]), minus the work of the external force,
/// must equal the energy at the start to within `tolerance` times the energy
/// in play (the energy at the start plus all the work done since). At each
/// separation the same balance must close over the contact alone: the
/// contact forces' net work (the energy change less the damper's and external
/// work) must be minus what they dissipate, never positive (a contact cannot
/// create energy; for two free bodies that is a restitution <= 1, but a main
/// spring can rightly give a larger rebound ratio, so the ratio itself is not
/// the test). An unforced system whose energy grows by half is a numerical
/// blow-up, as before.
pub(crate) struct EnergyLedger {
    initial: f64,
    largest: f64,
    free: bool,
    tolerance: f64,
    /// Work of the external force so far, J.
    external: f64,
    /// Largest relative residual found.
    worst: f64,
}

impl EnergyLedger {
    pub(crate) fn new(initial: f64, free: bool, tolerance: f64) -> Self {
        Self {
            initial,
            largest: initial,
            free,
            tolerance,
            external: 0.0,
            worst: f64::NAN,
        }
    }

    /// Adds the external force's work over the step `s0 -> s1` of length `h`
    /// from `time`: Simpson's rule on `F(t) w'(t)`, `w'` the velocity of the
    /// step's cubic Hermite interpolant (nothing for an unforced system).
    #[inline(always)]
    pub(crate) fn external_step<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        time: f64,
        h: f64,
        s0: &State,
        s1: &State,
    ) {
        if !X::IS_FREE {
            self.external += external_work(model, time, h, s0, s1);
        }
    }

    /// The external force's work so far, J.
    #[inline(always)]
    pub(crate) fn external(&self) -> f64 {
        self.external
    }

    /// Whether to check at this many steps (every few steps, and at the end).
    #[inline(always)]
    pub(crate) fn due(&self, steps: u64, last: bool) -> bool {
        steps % ENERGY_INTERVAL == 0 || last
    }

    /// The balance with mechanical energy `energy` and the non-conservative
    /// work `losses` so far (J): the work of the dissipative forces (the
    /// contact's and the main damper's) less the external force's.
    pub(crate) fn check(&mut self, energy: f64, losses: f64, time: f64) -> Result<()> {
        if self.free {
            self.largest = self.largest.max(energy);
            if energy > ENERGY_GROWTH_LIMIT * self.initial {
                return Err(Error::NumericalBlowUp {
                    time,
                    reason: "the energy of the unforced system grew by more than 50 %",
                });
            }
        }
        let residual = energy + losses - self.initial;
        // The energy at the start, the dissipated work and the external work.
        let scale = self.initial + (losses + self.external) + self.external.abs();
        if scale > 0.0 {
            let ratio = residual.abs() / scale;
            // NaN (nothing found yet) gives way to any ratio.
            self.worst = self.worst.max(ratio);
            if ratio > self.tolerance || ratio.is_nan() {
                return Err(Error::EnergyBalance {
                    time,
                    residual,
                    scale,
                    tolerance: self.tolerance,
                });
            }
        }
        Ok(())
    }

    /// A closed contact's own balance: its energy change, plus the work of
    /// its dissipative forces, plus `work` (the main damper's minus the
    /// external force's work over the contact), is zero to within the tolerance of the energy in play (`energy`
    /// at onset and all that work). Positive, the contact created energy.
    pub(crate) fn check_contact(
        &self,
        record: &ContactRecord,
        energy: f64,
        work: f64,
    ) -> Result<()> {
        let residual = record.energy_change + record.energy_dissipated + work;
        let scale = energy + record.energy_dissipated + work.abs();
        if residual.abs() > self.tolerance * scale || residual.is_nan() {
            return Err(Error::ContactEnergy {
                onset: record.onset,
                separation: record.separation,
                change: record.energy_change,
                dissipated: record.energy_dissipated,
                work,
                scale,
                restitution: record.restitution,
                tolerance: self.tolerance,
            });
        }
        Ok(())
    }

    /// `max(E) / E(0) - 1`; NaN when forced or starting at rest.
    pub(crate) fn growth(&self) -> f64 {
        if self.free && self.initial > 0.0 {
            self.largest / self.initial - 1.0
        } else {
            f64::NAN
        }
    }

    /// The largest relative residual found (NaN if nothing was in play).
    pub(crate) fn residual(&self) -> f64 {
        self.worst
    }
}

/// The generic kernel. `interrupt` is called every few tens of thousands of
/// steps; returning true stops the run with `Error::Interrupted`.
pub fn integrate<L: ContactLaw, X: Excitation, I: Integrator>(
    model: &Model<L, X>,
    integrator: &mut I,
    initial: &State,
    settings: &Settings,
    rhs_per_step: u64,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<Solution> {
    settings.check_steps()?;
    check_start(model, initial)?;
    let dt = settings.dt.expect("fixed stepping has a step");
    let n_steps = settings.steps();
    let every = settings.every;
    let rows = n_steps / every + 2;
    settings.check_rows(rows)?;
    let located = settings.timing == ContactTiming::Located;
    let t0 = 0.0;
    let d = model.clearance;
    let c1 = model.contact_damping;

    let mut records = Records::new(settings, rows);
    let keep = records.keeps_history();

    let mut s = *initial;
    let side0 = model.side(&s);
    let mut approach = side0 * s.relative_velocity();
    let start = model.contact(&s, approach);
    records.keep(t0, &s, start.total_force)?;
    let mut ledger = EnergyLedger::new(model.energy(&s), X::IS_FREE, settings.energy_tolerance);
    let mut open: Option<OpenContact> = if start.indentation > 0.0 {
        Some(OpenContact {
            side: start.side,
            onset: t0,
            approach_speed: start.rate,
            max_indentation: start.indentation,
            dissipated: 0.0,
            energy: ledger.initial,
            work: 0.0,
        })
    } else {
        None
    };
    // Work of the contact's dissipative forces in the contacts closed so far.
    let mut closed_dissipation = 0.0;
    let start_acceleration = model.accelerations(t0, &s, approach).0;
    let damper = DamperWork::new(model.damping, dt, s.main_velocity, start_acceleration);
    // Sum of w'^2 at the step ends, for the damper's work (see DamperWork).
    let mut squares = 0.0;
    integrator.start(model, &s, t0, dt, approach);
    // A countdown, not `step % every`: an integer division per step would
    // cost more than a Newmark step.
    let mut until_kept = every;

    for n in 0..n_steps {
        let t = t0 + n as f64 * dt;
        let t1 = t0 + (n + 1) as f64 * dt;
        if open.is_none() {
            // Provisional latch for stages that enter contact within this step;
            // replaced by the located onset rate once the onset is found.
            approach = model.side(&s) * s.relative_velocity();
        }
        let s1 = integrator.step(model, &s, t, dt, approach);
        if !s1.is_finite() {
            return Err(Error::NumericalBlowUp {
                time: t1,
                reason: "the state is no longer finite",
            });
        }
        squares += s1.main_velocity * s1.main_velocity;
        ledger.external_step(model, t, dt, &s, &s1);

        match open.as_mut() {
            None => {
                let side = model.side(&s1);
                let g1 = side * s1.relative_displacement() - d;
                if g1 > 0.0 {
                    let g0 = side * s.relative_displacement() - d;
                    let m0 = side * s.relative_velocity() * dt;
                    let m1 = side * s1.relative_velocity() * dt;
                    // A step that jumps from one wall's contact to the other's
                    // cannot be interpolated; the onset is then the step start.
                    let theta = if g0 <= 0.0 {
                        hermite::root(g0, g1, m0, m1)
                    } else {
                        0.0
                    };
                    let (_, slope) = hermite::eval(g0, g1, m0, m1, theta);
                    let rate = slope / dt;
                    // Counting steps, a sample exactly at the wall (|y - w| = d) is
                    // already touching, as in the paper's |y - w| >= d.
                    let onset = if located {
                        t + theta * dt
                    } else if g0 >= 0.0 {
                        t
                    } else {
                        t1
                    };
                    let c = model.contact(&s1, rate);
                    let p_onset = c1 * rate * rate;
                    let p1 = model.contact_dissipation(&c);
                    let (before, after) =
                        step_work(model, &damper, squares, &ledger, t, dt, &s, &s1);
                    open = Some(OpenContact {
                        side,
                        onset,
                        approach_speed: rate,
                        max_indentation: g1,
                        dissipated: 0.5 * (1.0 - theta) * dt * (p_onset + p1),
                        energy: within_step(model.energy(&s), model.energy(&s1), theta),
                        work: within_step(before, after, theta),
                    });
                    approach = rate;
                }
            }
            Some(oc) => {
                let side = oc.side;
                let g0 = side * s.relative_displacement() - d;
                let g1 = side * s1.relative_displacement() - d;
                let m0 = side * s.relative_velocity() * dt;
                let m1 = side * s1.relative_velocity() * dt;
                if located && m0 > 0.0 && m1 <= 0.0 {
                    let theta = hermite::argmax(g0, g1, m0, m1);
                    let peak = hermite::eval(g0, g1, m0, m1, theta).0;
                    oc.max_indentation = oc.max_indentation.max(peak);
                }
                oc.max_indentation = oc.max_indentation.max(g1);
                let c0 = model.contact(&s, approach);
                let p0 = model.contact_dissipation(&c0);
                if g1 > 0.0 {
                    let c = model.contact(&s1, approach);
                    oc.dissipated += 0.5 * dt * (p0 + model.contact_dissipation(&c));
                } else {
                    let theta = if g0 > 0.0 {
                        hermite::root(g0, g1, m0, m1)
                    } else {
                        0.0
                    };
                    let rate = hermite::eval(g0, g1, m0, m1, theta).1 / dt;
                    let p_sep = c1 * rate * rate;
                    let separation = if located { t + theta * dt } else { t1 };
                    let energy = within_step(model.energy(&s), model.energy(&s1), theta);
                    let (before, after) =
                        step_work(model, &damper, squares, &ledger, t, dt, &s, &s1);
                    let work = within_step(before, after, theta);
                    let record = ContactRecord {
                        onset: oc.onset,
                        separation,
                        duration: separation - oc.onset,
                        max_indentation: oc.max_indentation,
                        approach_speed: oc.approach_speed,
                        rebound_speed: -rate,
                        restitution: crate::events::restitution(-rate, oc.approach_speed),
                        energy_dissipated: oc.dissipated + 0.5 * theta * dt * (p0 + p_sep),
                        energy_change: energy - oc.energy,
                    };
                    ledger.check_contact(&record, oc.energy, work - oc.work)?;
                    closed_dissipation += record.energy_dissipated;
                    records.contact(record, t1)?;
                    open = None;
                }
            }
        }

        s = s1;
        let step = n + 1;
        until_kept -= 1;
        // The rare work, behind one test in the hot loop: a history row, the
        // energy check, the question whether to stop (its interval a
        // multiple of the energy check's).
        let last = step == n_steps;
        if until_kept == 0 || ledger.due(step, last) {
            if until_kept == 0 || last {
                until_kept = every;
                if keep {
                    let force = model.contact(&s, approach).total_force;
                    records.keep(t1, &s, force)?;
                }
            }
            if ledger.due(step, last) {
                let open_dissipation = open.map_or(0.0, |oc| oc.dissipated);
                let acceleration = model.accelerations(t1, &s, approach).0;
                let damper = damper.corrected(squares, s.main_velocity, acceleration);
                let losses = closed_dissipation + open_dissipation + damper - ledger.external();
                ledger.check(model.energy(&s), losses, t1)?;
                if step % INTERRUPT_INTERVAL == 0 && interrupt() {
                    return Err(Error::Interrupted { time: t1 });
                }
            }
        }
        // No step count check: n_steps <= max_steps was checked up front.
    }

    let final_time = t0 + n_steps as f64 * dt;
    if let Some(oc) = open {
        let record = open_record(
            oc.onset,
            oc.approach_speed,
            oc.max_indentation,
            oc.dissipated,
        );
        records.contact(record, final_time)?;
    }

    Ok(Solution {
        history: records.history,
        contacts: records.contacts,
        steps: n_steps,
        rejected_steps: 0,
        grazing_contacts: 0,
        rhs_evaluations: n_steps * rhs_per_step,
        final_time,
        final_state: s,
        energy_growth: ledger.growth(),
        energy_residual: ledger.residual(),
    })
}

/// The record of a contact still open at the end of a run: no separation,
/// so no duration, rebound, restitution or energy change.
pub(crate) fn open_record(
    onset: f64,
    approach_speed: f64,
    max_indentation: f64,
    energy_dissipated: f64,
) -> ContactRecord {
    ContactRecord {
        onset,
        separation: f64::NAN,
        duration: f64::NAN,
        max_indentation,
        approach_speed,
        rebound_speed: f64::NAN,
        restitution: f64::NAN,
        energy_dissipated,
        energy_change: f64::NAN,
    }
}

/// The non-conservative work outside the contact (main damper minus external
/// force, J) at the start and at the end of the fixed step `s0 -> s1` just
/// summed: for a contact event inside it.
#[allow(clippy::too_many_arguments)]
fn step_work<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    damper: &DamperWork,
    squares: f64,
    ledger: &EnergyLedger,
    time: f64,
    dt: f64,
    s0: &State,
    s1: &State,
) -> (f64, f64) {
    let after = damper.so_far(squares, s1.main_velocity) - ledger.external();
    let (v0, v1) = (s0.main_velocity, s1.main_velocity);
    let step =
        0.5 * model.damping * dt * (v0 * v0 + v1 * v1) - external_work(model, time, dt, s0, s1);
    (after - step, after)
}

/// A quantity at fraction `theta` of a step, between its values at the
/// step's ends (second order, like the fixed-step kernel's other sums).
#[inline]
fn within_step(start: f64, end: f64, theta: f64) -> f64 {
    start + theta * (end - start)
}

fn with_method<L: ContactLaw>(
    model: &Model<L, Free>,
    initial: &State,
    settings: &Settings,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<Solution> {
    let events = settings.stepping == Stepping::Events;
    match settings.method {
        Method::Newmark { beta, gamma } if !events => integrate(
            model,
            &mut Newmark::new(beta, gamma),
            initial,
            settings,
            1,
            interrupt,
        ),
        Method::Rk4 if !events => integrate(model, &mut Rk4, initial, settings, 4, interrupt),
        Method::Newmark { beta, gamma } => {
            let mut stepper = NewmarkFamily::newmark(beta, gamma, true);
            integrate_events(model, &mut stepper, initial, settings, interrupt)
        }
        Method::NewmarkImplicit { beta, gamma } => {
            let mut stepper = NewmarkFamily::newmark(beta, gamma, false);
            integrate_events(model, &mut stepper, initial, settings, interrupt)
        }
        Method::GeneralizedAlpha { spectral_radius } => {
            let mut stepper = NewmarkFamily::generalized_alpha(spectral_radius);
            integrate_events(model, &mut stepper, initial, settings, interrupt)
        }
        Method::Rk4 => integrate_events(
            model,
            &mut Rk4Stepper::default(),
            initial,
            settings,
            interrupt,
        ),
        Method::Dopri5(tolerances) => {
            let mut stepper = Dopri5Stepper::new(tolerances);
            integrate_events(model, &mut stepper, initial, settings, interrupt)
        }
        Method::Dop853(tolerances) => {
            let mut stepper = Dop853Stepper::new(tolerances);
            integrate_events(model, &mut stepper, initial, settings, interrupt)
        }
    }
}

/// Integrate the unforced impact damper: dispatches once on the contact law
/// and the method, then runs the monomorphised kernel.
///
/// Every run has limits, each refused up front where it is known and stopped
/// with a clear error where it is not: steps (`max_steps`; a fixed-step
/// count `t_end / dt` beyond it is refused before the first step), memory
/// (`max_rows` history rows plus contacts; a fixed-step
/// history beyond it is refused, any other stops at it; `history = false`
/// keeps none), and physics: a start with the bodies interpenetrating is
/// refused, and a result whose energy balance misses by more than
/// `energy_tolerance` of the energy in play, or one of whose contacts creates
/// energy beyond it, is an error, never output (see `EnergyLedger`).
pub fn simulate(
    system: &ImpactDamper,
    contact: &Contact,
    initial: &State,
    settings: &Settings,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<Solution> {
    struct Run<'a> {
        system: &'a ImpactDamper,
        contact_damping: f64,
        initial: &'a State,
        settings: &'a Settings,
        interrupt: &'a mut dyn FnMut() -> bool,
    }
    impl LawVisitor for Run<'_> {
        type Output = Result<Solution>;
        fn visit<L: ContactLaw>(self, law: L) -> Result<Solution> {
            let model = Model::new(self.system, law, self.contact_damping, Free);
            with_method(&model, self.initial, self.settings, self.interrupt)
        }
    }
    contact.visit(Run {
        system,
        contact_damping: contact.damping,
        initial,
        settings,
        interrupt,
    })
}
