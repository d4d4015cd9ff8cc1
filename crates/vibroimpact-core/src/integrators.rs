//! Fixed-step integrators: the founding paper's Newmark-beta with the contact
//! force lagged one step, and classical fourth-order Runge-Kutta.

use crate::contact::ContactLaw;
use crate::model::{Excitation, Model};
use crate::system::State;

/// One fixed-step method. `approach_rate` is the indentation rate latched at
/// the onset of the current contact (used by rate-dependent laws).
pub trait Integrator {
    /// Prepare for steps of size `dt` starting from `s` at `time`.
    fn start<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        s: &State,
        time: f64,
        dt: f64,
        approach_rate: f64,
    );
    /// Advance `s` from `time` to `time + dt`.
    fn step<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        s: &State,
        time: f64,
        dt: f64,
        approach_rate: f64,
    ) -> State;
}

/// Classical RK4 on `(w, w', y, y')` with the nonlinear contact force in
/// every stage.
#[derive(Debug, Clone, Copy, Default)]
pub struct Rk4;

#[inline(always)]
fn advance(s: &State, h: f64, d: (f64, f64, f64, f64)) -> State {
    State {
        main_displacement: s.main_displacement + h * d.0,
        main_velocity: s.main_velocity + h * d.1,
        impact_displacement: s.impact_displacement + h * d.2,
        impact_velocity: s.impact_velocity + h * d.3,
    }
}

#[inline(always)]
fn derivative<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    time: f64,
    s: &State,
    approach_rate: f64,
) -> (f64, f64, f64, f64) {
    let (aw, ay) = model.accelerations(time, s, approach_rate);
    (s.main_velocity, aw, s.impact_velocity, ay)
}

impl Integrator for Rk4 {
    fn start<L: ContactLaw, X: Excitation>(
        &mut self,
        _: &Model<L, X>,
        _: &State,
        _: f64,
        _: f64,
        _: f64,
    ) {
    }

    #[inline(always)]
    fn step<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        s: &State,
        time: f64,
        dt: f64,
        approach_rate: f64,
    ) -> State {
        let half = 0.5 * dt;
        let k1 = derivative(model, time, s, approach_rate);
        let k2 = derivative(model, time + half, &advance(s, half, k1), approach_rate);
        let k3 = derivative(model, time + half, &advance(s, half, k2), approach_rate);
        let k4 = derivative(model, time + dt, &advance(s, dt, k3), approach_rate);
        let sixth = dt / 6.0;
        State {
            main_displacement: s.main_displacement + sixth * (k1.0 + 2.0 * (k2.0 + k3.0) + k4.0),
            main_velocity: s.main_velocity + sixth * (k1.1 + 2.0 * (k2.1 + k3.1) + k4.1),
            impact_displacement: s.impact_displacement
                + sixth * (k1.2 + 2.0 * (k2.2 + k3.2) + k4.2),
            impact_velocity: s.impact_velocity + sixth * (k1.3 + 2.0 * (k2.3 + k3.3) + k4.3),
        }
    }
}

/// Inverse of a symmetric 2x2 matrix `[a b; b d]`, as `(a, b, d)`.
fn inverse_sym2(a: f64, b: f64, d: f64) -> (f64, f64, f64) {
    let det = a * d - b * b;
    (d / det, -b / det, a / det)
}

/// Newmark-beta with the founding paper's "piecewise linearisation": the
/// structure's spring and dampers (and the contact damper `c1` while in
/// contact) are implicit; the contact law's force is taken from the previous
/// step. The effective matrix is therefore constant between contact changes.
/// Defaults `beta = 1/4`, `gamma = 1/2` (average acceleration).
#[derive(Debug, Clone, Copy)]
pub struct Newmark {
    pub beta: f64,
    pub gamma: f64,
    /// Accelerations at the current step, m/s^2.
    accel: (f64, f64),
    /// Inverse effective matrices (symmetric: a, b, d) out of and in contact.
    inv_free: (f64, f64, f64),
    inv_contact: (f64, f64, f64),
}

impl Newmark {
    pub fn new(beta: f64, gamma: f64) -> Self {
        Self {
            beta,
            gamma,
            accel: (0.0, 0.0),
            inv_free: (0.0, 0.0, 0.0),
            inv_contact: (0.0, 0.0, 0.0),
        }
    }
}

impl Default for Newmark {
    fn default() -> Self {
        Self::new(0.25, 0.5)
    }
}

impl Integrator for Newmark {
    fn start<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        s: &State,
        time: f64,
        dt: f64,
        approach_rate: f64,
    ) {
        let g = self.gamma * dt;
        let b = self.beta * dt * dt;
        let main = model.main_mass + g * model.damping + b * model.stiffness;
        self.inv_free = inverse_sym2(main, 0.0, model.impact_mass);
        let c1 = model.contact_damping;
        self.inv_contact = inverse_sym2(main + g * c1, -g * c1, model.impact_mass + g * c1);
        // Initial accelerations from the full equations of motion.
        self.accel = model.accelerations(time, s, approach_rate);
    }

    #[inline(always)]
    fn step<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        s: &State,
        time: f64,
        dt: f64,
        approach_rate: f64,
    ) -> State {
        // The contact law's force at the previous step (the paper's lag).
        let c = model.contact(s, approach_rate);
        let in_contact = c.indentation > 0.0;
        let (aw, ay) = self.accel;
        let db = (0.5 - self.beta) * dt * dt;
        let dg = (1.0 - self.gamma) * dt;
        let xw = s.main_displacement + dt * s.main_velocity + db * aw;
        let vw = s.main_velocity + dg * aw;
        let xy = s.impact_displacement + dt * s.impact_velocity + db * ay;
        let vy = s.impact_velocity + dg * ay;
        let mut rw = model.excitation.main_force(time + dt) + c.side * c.law_force
            - model.damping * vw
            - model.stiffness * xw;
        let mut ry = -c.side * c.law_force;
        let inv = if in_contact {
            let damper = model.contact_damping * (vy - vw);
            rw += damper;
            ry -= damper;
            self.inv_contact
        } else {
            self.inv_free
        };
        let aw1 = inv.0 * rw + inv.1 * ry;
        let ay1 = inv.1 * rw + inv.2 * ry;
        self.accel = (aw1, ay1);
        let bb = self.beta * dt * dt;
        let gg = self.gamma * dt;
        State {
            main_displacement: xw + bb * aw1,
            main_velocity: vw + gg * aw1,
            impact_displacement: xy + bb * ay1,
            impact_velocity: vy + gg * ay1,
        }
    }
}
