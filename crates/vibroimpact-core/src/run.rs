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

/// Most history rows one run may keep (6 columns of f64: about 4.8 GB).
pub const MAX_HISTORY_ROWS: u64 = 100_000_000;

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
}

impl Settings {
    /// `stepping` None takes the method's default: "fixed" for the paper's
    /// "newmark" and "rk4", "events" for the others (which have no other).
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
        };
        if !method.is_adaptive() {
            let rows = settings.steps() / every + 2;
            if rows > MAX_HISTORY_ROWS {
                return Err(Error::Inconsistent(format!(
                    "the history would keep {rows} rows (t_end / dt / every); at most {MAX_HISTORY_ROWS} \
                     are allowed: raise every"
                )));
            }
        }
        Ok(settings)
    }

    /// Number of fixed steps: `t_end / dt` rounded up (a relative 1e-9 of
    /// slack keeps `0.3 / 1e-4` at 3000 despite rounding); 0 without dt.
    pub fn steps(&self) -> u64 {
        match self.dt {
            Some(dt) => ((self.t_end / dt) * (1.0 - 1e-9)).ceil().max(1.0) as u64,
            None => 0,
        }
    }
}

/// One contact, from onset to separation. Speeds are relative normal speeds
/// (m/s, positive); a contact still open at the end has NaN separation,
/// duration and rebound speed.
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
    /// Work done by the contact's dissipative forces (law hysteresis and the
    /// contact damper), J.
    pub energy_dissipated: f64,
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
    pub(crate) fn with_capacity(rows: usize) -> Self {
        Self {
            time: Vec::with_capacity(rows),
            main_displacement: Vec::with_capacity(rows),
            main_velocity: Vec::with_capacity(rows),
            impact_displacement: Vec::with_capacity(rows),
            impact_velocity: Vec::with_capacity(rows),
            contact_force: Vec::with_capacity(rows),
        }
    }

    #[inline]
    pub(crate) fn push(&mut self, time: f64, s: &State, force: f64) {
        self.time.push(time);
        self.main_displacement.push(s.main_displacement);
        self.main_velocity.push(s.main_velocity);
        self.impact_displacement.push(s.impact_displacement);
        self.impact_velocity.push(s.impact_velocity);
        self.contact_force.push(force);
    }
}

/// What a run returns.
#[derive(Debug, Clone, PartialEq)]
pub struct Solution {
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
}

/// A contact being followed.
#[derive(Debug, Clone, Copy)]
struct OpenContact {
    side: f64,
    onset: f64,
    approach_speed: f64,
    max_indentation: f64,
    dissipated: f64,
}

/// How often (in steps) the kernel asks whether to stop; a power of two.
const INTERRUPT_INTERVAL: u64 = 1 << 16;
/// How often (in steps) energy is checked for a blow-up; a power of two.
const ENERGY_INTERVAL: u64 = 32;
/// An unforced system whose energy grows by more than this factor has blown up.
const ENERGY_GROWTH_LIMIT: f64 = 1.5;

/// Watches the mechanical energy of an unforced system, which can only fall:
/// growth by half is a numerical blow-up, and the largest growth is reported.
pub(crate) struct EnergyWatch {
    initial: f64,
    largest: f64,
    /// Only an unforced system is watched.
    active: bool,
}

impl EnergyWatch {
    pub(crate) fn new(initial: f64, active: bool) -> Self {
        Self {
            initial,
            largest: initial,
            active,
        }
    }

    /// Whether to check at this many steps (every few steps, and at the end).
    #[inline(always)]
    pub(crate) fn due(&self, steps: u64, last: bool) -> bool {
        self.active && (steps % ENERGY_INTERVAL == 0 || last)
    }

    pub(crate) fn check(&mut self, energy: f64, time: f64) -> Result<()> {
        self.largest = self.largest.max(energy);
        if energy > ENERGY_GROWTH_LIMIT * self.initial {
            return Err(Error::NumericalBlowUp {
                time,
                reason: "the energy of the unforced system grew by more than 50 %",
            });
        }
        Ok(())
    }

    /// `max(E) / E(0) - 1`; NaN when forced or starting at rest.
    pub(crate) fn growth(&self) -> f64 {
        if self.active && self.initial > 0.0 {
            self.largest / self.initial - 1.0
        } else {
            f64::NAN
        }
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
    let dt = settings.dt.expect("fixed stepping has a step");
    let n_steps = settings.steps();
    let every = settings.every;
    let located = settings.timing == ContactTiming::Located;
    let t0 = 0.0;
    let d = model.clearance;
    let c1 = model.contact_damping;

    let rows = (n_steps / every + 2) as usize;
    let mut history = History::with_capacity(rows);
    let mut contacts: Vec<ContactRecord> = Vec::with_capacity(16);

    let mut s = *initial;
    let side0 = model.side(&s);
    let mut approach = side0 * s.relative_velocity();
    let start = model.contact(&s, approach);
    history.push(t0, &s, start.total_force);
    let mut open: Option<OpenContact> = if start.indentation > 0.0 {
        Some(OpenContact {
            side: start.side,
            onset: t0,
            approach_speed: start.rate,
            max_indentation: start.indentation,
            dissipated: 0.0,
        })
    } else {
        None
    };
    let mut watch = EnergyWatch::new(model.energy(&s), X::IS_FREE);
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
                    open = Some(OpenContact {
                        side,
                        onset,
                        approach_speed: rate,
                        max_indentation: g1,
                        dissipated: 0.5 * (1.0 - theta) * dt * (p_onset + p1),
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
                    contacts.push(ContactRecord {
                        onset: oc.onset,
                        separation,
                        duration: separation - oc.onset,
                        max_indentation: oc.max_indentation,
                        approach_speed: oc.approach_speed,
                        rebound_speed: -rate,
                        restitution: crate::events::restitution(-rate, oc.approach_speed),
                        energy_dissipated: oc.dissipated + 0.5 * theta * dt * (p0 + p_sep),
                    });
                    open = None;
                }
            }
        }

        s = s1;
        let step = n + 1;
        until_kept -= 1;
        if until_kept == 0 || step == n_steps {
            until_kept = every;
            let force = model.contact(&s, approach).total_force;
            history.push(t1, &s, force);
        }
        if watch.due(step, step == n_steps) {
            watch.check(model.energy(&s), t1)?;
        }
        if step % INTERRUPT_INTERVAL == 0 && interrupt() {
            return Err(Error::Interrupted { time: t1 });
        }
        if step == settings.max_steps && step < n_steps {
            return Err(Error::TooManySteps {
                time: t1,
                max_steps: settings.max_steps,
            });
        }
    }

    if let Some(oc) = open {
        contacts.push(ContactRecord {
            onset: oc.onset,
            separation: f64::NAN,
            duration: f64::NAN,
            max_indentation: oc.max_indentation,
            approach_speed: oc.approach_speed,
            rebound_speed: f64::NAN,
            restitution: f64::NAN,
            energy_dissipated: oc.dissipated,
        });
    }

    Ok(Solution {
        history,
        contacts,
        steps: n_steps,
        rejected_steps: 0,
        grazing_contacts: 0,
        rhs_evaluations: n_steps * rhs_per_step,
        final_time: t0 + n_steps as f64 * dt,
        final_state: s,
        energy_growth: watch.growth(),
    })
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
