//! The equations of motion in the plain-data form the kernels use.

use crate::model::contact::ContactLaw;
use crate::model::impact_damper::{ImpactDamper, State};
use crate::numerics::hermite;

/// A force on the main mass that depends on time only (N). The hook for
/// excitations; `Free` is the unforced system.
pub trait Excitation: Copy + Send + Sync {
    /// True when the force is identically zero, so that energy can only
    /// decrease and an increase betrays a numerical blow-up.
    const IS_FREE: bool;
    fn main_force(&self, time: f64) -> f64;
}

/// No external force.
#[derive(Debug, Clone, Copy, Default)]
pub struct Free;

impl Excitation for Free {
    const IS_FREE: bool = true;
    #[inline(always)]
    fn main_force(&self, _time: f64) -> f64 {
        0.0
    }
}

/// What the contact does in one state.
#[derive(Debug, Clone, Copy)]
pub struct ContactState {
    /// +1 when the impact mass presses on the wall at `y - w = +d`, -1 for
    /// the wall at `-d`.
    pub side: f64,
    /// `|y - w| - d`, m; > 0 in contact.
    pub indentation: f64,
    /// Rate of indentation, m/s.
    pub rate: f64,
    /// The law's force (clamped at zero), N.
    pub law_force: f64,
    /// Law force plus the contact damper `c1 * rate`, N; pushes apart when > 0.
    pub total_force: f64,
}

/// The contact regime of the event-driven kernel: the contact force acts
/// exactly while in `Contact` mode, so the right-hand side is smooth within a
/// mode and every non-smooth instant is a located mode switch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mode {
    Free,
    Contact {
        /// +1 at the wall `y - w = +d`, -1 at `-d`.
        side: f64,
        /// Indentation rate at onset, m/s (latched for rate-dependent laws).
        approach_rate: f64,
    },
}

/// A contact onset located inside a fixed step ([`Model::onset_in_step`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Onset {
    /// Fraction of the step, in [0, 1].
    pub theta: f64,
    /// Indentation rate at the onset, m/s (> 0 approaching).
    pub rate: f64,
    /// The gap function at the step start, m (> 0: already past the wall).
    pub gap_at_start: f64,
}

/// The impact damper with its contact law and excitation, ready to integrate.
#[derive(Debug, Clone, Copy)]
pub struct Model<L: ContactLaw, X: Excitation> {
    pub main_mass: f64,
    pub impact_mass: f64,
    pub stiffness: f64,
    pub damping: f64,
    pub clearance: f64,
    pub contact_damping: f64,
    pub law: L,
    pub excitation: X,
    /// `1 / main_mass` and `1 / impact_mass`: multiplications in the hot loop.
    pub(crate) inverse_main_mass: f64,
    pub(crate) inverse_impact_mass: f64,
    pub(crate) damping_per_mass: f64,
    pub(crate) stiffness_per_mass: f64,
}

impl<L: ContactLaw, X: Excitation> Model<L, X> {
    pub fn new(system: &ImpactDamper, law: L, contact_damping: f64, excitation: X) -> Self {
        Self {
            main_mass: system.main_mass,
            impact_mass: system.impact_mass,
            stiffness: system.stiffness,
            damping: system.damping,
            clearance: system.clearance,
            contact_damping,
            law,
            excitation,
            inverse_main_mass: 1.0 / system.main_mass,
            inverse_impact_mass: 1.0 / system.impact_mass,
            damping_per_mass: system.damping / system.main_mass,
            stiffness_per_mass: system.stiffness / system.main_mass,
        }
    }

    /// Which wall the impact mass is at or heading for, and its signed gap
    /// function `side * (y - w) - d` (> 0 in contact).
    #[inline(always)]
    pub fn side(&self, s: &State) -> f64 {
        let u = s.relative_displacement();
        if u > 0.0 || (u == 0.0 && s.relative_velocity() >= 0.0) {
            1.0
        } else {
            -1.0
        }
    }

    /// A contact onset against wall `side` in the fixed step `s0 -> s1` of
    /// length `dt` (s1 past the wall): where the cubic Hermite interpolant
    /// of the gap crosses zero, as a fraction `theta` of the step, and the
    /// indentation rate there (m/s). A step that starts past the wall (it
    /// jumped from one wall's contact to the other's) cannot be
    /// interpolated: its onset is the step start.
    #[inline]
    pub fn onset_in_step(&self, s0: &State, s1: &State, side: f64, dt: f64) -> Onset {
        let d = self.clearance;
        let gap_at_start = side * s0.relative_displacement() - d;
        let g1 = side * s1.relative_displacement() - d;
        let m0 = side * s0.relative_velocity() * dt;
        let m1 = side * s1.relative_velocity() * dt;
        let theta = if gap_at_start <= 0.0 {
            hermite::root(gap_at_start, g1, m0, m1)
        } else {
            0.0
        };
        let (_, slope) = hermite::eval(gap_at_start, g1, m0, m1, theta);
        Onset {
            theta,
            rate: slope / dt,
            gap_at_start,
        }
    }

    /// The contact in state `s` (zero forces when not in contact).
    #[inline(always)]
    pub fn contact(&self, s: &State, approach_rate: f64) -> ContactState {
        let c = self.contact_at(s, self.side(s), approach_rate);
        if c.indentation > 0.0 {
            c
        } else {
            // Apart: by the sign of the indentation, no force at all (the
            // fixed-step kernels have no contact mode to keep the damper on).
            ContactState {
                law_force: 0.0,
                total_force: 0.0,
                ..c
            }
        }
    }

    /// The main mass's acceleration from its spring and damper alone,
    /// `-(C w' + K w) / M` in m/s^2, computed as `(-C/M) w' - (K/M) w`: the
    /// same value (rounding is symmetric in sign; at most the sign of an
    /// exact zero differs, where the two terms cancel), with no negation
    /// after the sum. That keeps each RK stage's dependency chain at one
    /// multiply and one subtraction (the per-unit-mass coefficients, and the
    /// negated damping hoisted out of the loop): one cycle less a stage in
    /// the fixed-step kernel, whose steps wait on that chain.
    #[inline(always)]
    pub(crate) fn structural_acceleration(&self, s: &State) -> f64 {
        (-self.damping_per_mass) * s.main_velocity - self.stiffness_per_mass * s.main_displacement
    }

    /// Accelerations `(w'', y'')` in m/s^2.
    #[inline(always)]
    pub fn accelerations(&self, time: f64, s: &State, approach_rate: f64) -> (f64, f64) {
        let mut main = self.structural_acceleration(s);
        if !X::IS_FREE {
            main += self.excitation.main_force(time) * self.inverse_main_mass;
        }
        let u = s.relative_displacement();
        // Cheap test first: the full contact evaluation only when touching.
        if u.abs() > self.clearance {
            let c = self.contact(s, approach_rate);
            let push = c.side * c.total_force;
            (
                main + push * self.inverse_main_mass,
                -push * self.inverse_impact_mass,
            )
        } else {
            (main, 0.0)
        }
    }

    /// The contact against wall `side` in state `s`; the law's force is zero
    /// where the indentation is not positive, the contact damper acts anyway
    /// (the caller decides that the bodies are in contact).
    #[inline(always)]
    pub fn contact_at(&self, s: &State, side: f64, approach_rate: f64) -> ContactState {
        let indentation = side * s.relative_displacement() - self.clearance;
        let rate = side * s.relative_velocity();
        let law_force = if indentation > 0.0 {
            self.law.force(indentation, rate, approach_rate)
        } else {
            0.0
        };
        ContactState {
            side,
            indentation,
            rate,
            law_force,
            total_force: law_force + self.contact_damping * rate,
        }
    }

    /// Accelerations `(w'', y'')` (m/s^2) in a given mode.
    #[inline(always)]
    pub fn accelerations_in(&self, time: f64, s: &State, mode: Mode) -> (f64, f64) {
        let (aw, ay, _) = self.rates_in(time, s, mode);
        (aw, ay)
    }

    /// Accelerations (m/s^2) and the non-conservative power (W) in a given
    /// mode, from one evaluation of the contact. Apart: the power the main
    /// damper takes from the system less what the external force gives it.
    /// In contact: the power the contact's dissipative forces take (the
    /// damper's and the external force's there are summed by the kernel, so
    /// that the method integrates each contact's own dissipation alone).
    #[inline(always)]
    pub fn rates_in(&self, time: f64, s: &State, mode: Mode) -> (f64, f64, f64) {
        let mut main = self.structural_acceleration(s);
        let mut force = 0.0;
        if !X::IS_FREE {
            force = self.excitation.main_force(time);
            main += force * self.inverse_main_mass;
        }
        match mode {
            Mode::Free => (
                main,
                0.0,
                (self.damping * s.main_velocity - force) * s.main_velocity,
            ),
            Mode::Contact {
                side,
                approach_rate,
            } => {
                let indentation = side * s.relative_displacement() - self.clearance;
                let rate = side * s.relative_velocity();
                let (law_force, elastic) = if indentation > 0.0 {
                    self.law.force_and_elastic(indentation, rate, approach_rate)
                } else {
                    (0.0, 0.0)
                };
                let total = law_force + self.contact_damping * rate;
                let push = side * total;
                (
                    main + push * self.inverse_main_mass,
                    -push * self.inverse_impact_mass,
                    (total - elastic) * rate,
                )
            }
        }
    }

    /// The non-conservative power (W) at `time` in a given mode (see
    /// [`Model::rates_in`]).
    #[inline(always)]
    pub fn losses_in(&self, time: f64, s: &State, mode: Mode) -> f64 {
        self.rates_in(time, s, mode).2
    }

    /// The external force on the main mass, N.
    #[inline(always)]
    pub fn external_force(&self, time: f64) -> f64 {
        if X::IS_FREE {
            0.0
        } else {
            self.excitation.main_force(time)
        }
    }

    /// Mechanical energy: kinetic, main spring and elastic contact energy, J.
    #[inline]
    pub fn energy(&self, s: &State) -> f64 {
        let side = self.side(s);
        let indentation = side * s.relative_displacement() - self.clearance;
        let contact = if indentation > 0.0 {
            self.law.potential(indentation)
        } else {
            0.0
        };
        0.5 * (self.main_mass * s.main_velocity * s.main_velocity
            + self.impact_mass * s.impact_velocity * s.impact_velocity
            + self.stiffness * s.main_displacement * s.main_displacement)
            + contact
    }

    /// Power dissipated in the contact (W): the law's non-elastic part plus
    /// the contact damper.
    #[inline]
    pub fn contact_dissipation(&self, c: &ContactState) -> f64 {
        if c.indentation > 0.0 {
            (c.total_force - self.law.elastic_force(c.indentation)) * c.rate
        } else {
            0.0
        }
    }
}
