//! The integration kernel: steps any integrator over any contact law, keeps a
//! thinned time history and builds the table of contacts, with contact
//! instants located inside the step.

use crate::contact::{Contact, ContactLaw, LawVisitor};
use crate::error::{positive, within, Error, Result};
use crate::hermite;
use crate::integrators::{Integrator, Newmark, Rk4};
use crate::model::{Excitation, Free, Model};
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

/// The integration method.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// The paper's Newmark-beta with the contact force lagged one step.
    Newmark { beta: f64, gamma: f64 },
    /// Classical fourth-order Runge-Kutta.
    Rk4,
}

impl Method {
    pub const NAMES: &'static str = "\"newmark\", \"rk4\"";

    /// Method by name; `beta`, `gamma` apply to "newmark" only.
    pub fn parse(name: &str, beta: f64, gamma: f64) -> Result<Self> {
        // Checked whatever the method, so that a wrong value is never silently ignored.
        let beta = within("beta", beta, 0.0, 0.5, false, "in [0, 0.5]")?;
        let gamma = within("gamma", gamma, 0.5, 1.0, false, "in [0.5, 1]")?;
        match name {
            "newmark" => Ok(Self::Newmark { beta, gamma }),
            "rk4" => Ok(Self::Rk4),
            _ => Err(Error::UnknownChoice {
                field: "method",
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
    /// Step, s (> 0).
    pub dt: f64,
    /// End time, s (> 0); rounded up to a whole number of steps.
    pub t_end: f64,
    /// Keep every `every`-th step in the history (the last step always).
    pub every: u64,
    pub timing: ContactTiming,
}

impl Settings {
    pub fn new(
        method: Method,
        dt: f64,
        t_end: f64,
        every: u64,
        timing: ContactTiming,
    ) -> Result<Self> {
        let dt = positive("dt", dt)?;
        let t_end = positive("t_end", t_end)?;
        if every == 0 {
            return Err(Error::InvalidParameter {
                field: "every",
                allowed: "a whole number >= 1",
                value: 0.0,
            });
        }
        let settings = Self {
            method,
            dt,
            t_end,
            every,
            timing,
        };
        let rows = settings.steps() / every + 2;
        if rows > MAX_HISTORY_ROWS {
            return Err(Error::Inconsistent(format!(
                "the history would keep {rows} rows (t_end / dt / every); at most {MAX_HISTORY_ROWS} \
                 are allowed: raise every"
            )));
        }
        Ok(settings)
    }

    /// Number of steps: `t_end / dt` rounded up (a relative 1e-9 of slack
    /// keeps `0.3 / 1e-4` at 3000 despite rounding).
    pub fn steps(&self) -> u64 {
        let ratio = self.t_end / self.dt;
        (ratio * (1.0 - 1e-9)).ceil().max(1.0) as u64
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

    #[inline]
    fn push(&mut self, time: f64, s: &State, force: f64) {
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
    /// Steps taken.
    pub steps: u64,
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
    let dt = settings.dt;
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
    let energy0 = model.energy(&s);
    let mut max_energy = energy0;
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
        if X::IS_FREE && (step % ENERGY_INTERVAL == 0 || step == n_steps) {
            let energy = model.energy(&s);
            max_energy = max_energy.max(energy);
            if energy > ENERGY_GROWTH_LIMIT * energy0 {
                return Err(Error::NumericalBlowUp {
                    time: t1,
                    reason: "the energy of the unforced system grew by more than 50 %",
                });
            }
        }
        if step % INTERRUPT_INTERVAL == 0 && interrupt() {
            return Err(Error::Interrupted { time: t1 });
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
            energy_dissipated: oc.dissipated,
        });
    }

    Ok(Solution {
        history,
        contacts,
        steps: n_steps,
        rhs_evaluations: n_steps * rhs_per_step,
        final_time: t0 + n_steps as f64 * dt,
        final_state: s,
        energy_growth: if X::IS_FREE && energy0 > 0.0 {
            max_energy / energy0 - 1.0
        } else {
            f64::NAN
        },
    })
}

fn with_method<L: ContactLaw>(
    model: &Model<L, Free>,
    initial: &State,
    settings: &Settings,
    interrupt: &mut dyn FnMut() -> bool,
) -> Result<Solution> {
    match settings.method {
        Method::Newmark { beta, gamma } => integrate(
            model,
            &mut Newmark::new(beta, gamma),
            initial,
            settings,
            1,
            interrupt,
        ),
        Method::Rk4 => integrate(model, &mut Rk4, initial, settings, 4, interrupt),
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
