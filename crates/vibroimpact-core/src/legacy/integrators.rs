//! The two-mass system's classical RK4 ([`rk4_step`]) and the founding
//! paper's Newmark-beta with the contact force lagged one step
//! ([`PaperNewmark`]), each once: the fixed-step kernel (`run.rs`) drives
//! them through [`Integrator`], the event-driven kernel (`events.rs`)
//! through its steppers (`steppers.rs`).

use crate::legacy::equations::{Excitation, Model};
use crate::model::contact::ContactLaw;
use crate::model::impact_damper::State;

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

/// One classical RK4 step of `y' = f(t, y)` from `(time, y)`: stage points
/// `y + (h/2) k` and `y + h k`, the end `y + (h/6) (k1 + 2 (k2 + k3) + k4)`.
/// The one RK4 of the two-mass system, for the fixed-step kernel ([`Rk4`])
/// and the event-driven one ([`crate::legacy::steppers::Rk4Stepper`]) alike.
/// Systems of any size step with `system_steppers::ExplicitRk` on slices
/// (the same tableau, summed as the other explicit methods are).
#[inline(always)]
pub fn rk4_step<const N: usize>(
    time: f64,
    y: &[f64; N],
    h: f64,
    mut f: impl FnMut(f64, &[f64; N]) -> [f64; N],
) -> [f64; N] {
    let advance = |step: f64, k: &[f64; N]| -> [f64; N] {
        let mut point = *y;
        for n in 0..N {
            point[n] += step * k[n];
        }
        point
    };
    let half = 0.5 * h;
    let k1 = f(time, y);
    let k2 = f(time + half, &advance(half, &k1));
    let k3 = f(time + half, &advance(half, &k2));
    let k4 = f(time + h, &advance(h, &k3));
    let sixth = h / 6.0;
    let mut end = *y;
    for n in 0..N {
        end[n] += sixth * (k1[n] + 2.0 * (k2[n] + k3[n]) + k4[n]);
    }
    end
}

/// Classical RK4 on `(w, w', y, y')` with the nonlinear contact force in
/// every stage ([`rk4_step`]).
#[derive(Debug, Clone, Copy, Default)]
pub struct Rk4;

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
        let y = [
            s.main_displacement,
            s.main_velocity,
            s.impact_displacement,
            s.impact_velocity,
        ];
        let end = rk4_step(time, &y, dt, |t, p| {
            let s = State {
                main_displacement: p[0],
                main_velocity: p[1],
                impact_displacement: p[2],
                impact_velocity: p[3],
            };
            let (aw, ay) = model.accelerations(t, &s, approach_rate);
            [p[1], aw, p[3], ay]
        });
        State {
            main_displacement: unpaired(end[0]),
            main_velocity: unpaired(end[1]),
            impact_displacement: unpaired(end[2]),
            impact_velocity: unpaired(end[3]),
        }
    }
}

/// `x` unchanged, through an empty instruction the optimiser cannot see
/// into: it keeps LLVM's SLP vectoriser from packing the two bodies' chains
/// of the RK4 step in pairs, whose shuffles cost more than they save: the
/// fixed-step kernel runs 10 % faster without them (numba, which runs no SLP
/// pass, never makes them). No instruction is emitted, no value changed.
#[inline(always)]
fn unpaired(mut x: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: an empty assembly string that names `x`'s register: it reads,
    // writes and changes nothing.
    unsafe {
        std::arch::asm!(
            "/* {0} */",
            inout(xmm_reg) x,
            options(pure, nomem, nostack, preserves_flags)
        );
    }
    x
}

/// Inverse of a symmetric 2x2 matrix `[a b; b d]`, as `(a, b, d)`.
fn inverse_sym2(a: f64, b: f64, d: f64) -> (f64, f64, f64) {
    let det = a * d - b * b;
    (d / det, -b / det, a / det)
}

/// The founding paper's Newmark-beta on the two-mass system: the structure's
/// spring and dampers (and the contact damper `c1` while in contact) are
/// implicit; the contact law's force is taken from the start of the step (the
/// paper's "piecewise linearisation"), so the new accelerations solve linear
/// equations whose matrix is constant between contact changes. The one
/// implementation of the method: the fixed-step kernel's [`Newmark`] keeps
/// its two inverses for its one step size, the event-driven kernel's
/// [`crate::legacy::steppers::NewmarkFamily`] (lagged) makes them for each step.
#[derive(Debug, Clone, Copy)]
pub struct PaperNewmark {
    pub beta: f64,
    pub gamma: f64,
    /// Inverse effective matrices (symmetric: a, b, d) apart and in contact.
    inv_free: (f64, f64, f64),
    inv_contact: (f64, f64, f64),
    /// The step they were made for, s.
    dt: f64,
}

/// The contact's part in one step of [`PaperNewmark`]: the side pressed
/// (+1 the wall at `y - w = +d`), the law's force at the start of the step
/// (N, at least zero) and whether the contact damper acts.
#[derive(Debug, Clone, Copy)]
pub struct LaggedContact {
    pub side: f64,
    pub law_force: f64,
    pub in_contact: bool,
}

impl PaperNewmark {
    pub fn new(beta: f64, gamma: f64) -> Self {
        Self {
            beta,
            gamma,
            inv_free: (0.0, 0.0, 0.0),
            inv_contact: (0.0, 0.0, 0.0),
            dt: f64::NAN,
        }
    }

    /// The effective matrices' inverses for steps of `dt`, made again only
    /// when the step changes.
    #[inline(always)]
    pub fn prepare<L: ContactLaw, X: Excitation>(&mut self, model: &Model<L, X>, dt: f64) {
        if dt == self.dt {
            return;
        }
        let g = self.gamma * dt;
        let b = self.beta * dt * dt;
        let main = model.main_mass + g * model.damping + b * model.stiffness;
        self.inv_free = inverse_sym2(main, 0.0, model.impact_mass);
        let c1 = model.contact_damping;
        self.inv_contact = inverse_sym2(main + g * c1, -g * c1, model.impact_mass + g * c1);
        self.dt = dt;
    }

    /// One step `dt` (after [`Self::prepare`] for it) from `s` at `time`
    /// with accelerations `accel` (m/s^2): the new state and accelerations.
    #[inline(always)]
    pub fn step<L: ContactLaw, X: Excitation>(
        &self,
        model: &Model<L, X>,
        s: &State,
        accel: (f64, f64),
        time: f64,
        dt: f64,
        contact: LaggedContact,
    ) -> (State, (f64, f64)) {
        let (aw, ay) = accel;
        let db = (0.5 - self.beta) * dt * dt;
        let dg = (1.0 - self.gamma) * dt;
        let xw = s.main_displacement + dt * s.main_velocity + db * aw;
        let vw = s.main_velocity + dg * aw;
        let xy = s.impact_displacement + dt * s.impact_velocity + db * ay;
        let vy = s.impact_velocity + dg * ay;
        let push = contact.side * contact.law_force;
        let mut rw =
            model.external_force(time + dt) + push - model.damping * vw - model.stiffness * xw;
        let mut ry = -push;
        let inv = if contact.in_contact {
            let damper = model.contact_damping * (vy - vw);
            rw += damper;
            ry -= damper;
            self.inv_contact
        } else {
            self.inv_free
        };
        let aw1 = inv.0 * rw + inv.1 * ry;
        let ay1 = inv.1 * rw + inv.2 * ry;
        let bb = self.beta * dt * dt;
        let gg = self.gamma * dt;
        let end = State {
            main_displacement: xw + bb * aw1,
            main_velocity: vw + gg * aw1,
            impact_displacement: xy + bb * ay1,
            impact_velocity: vy + gg * ay1,
        };
        (end, (aw1, ay1))
    }
}

/// [`PaperNewmark`] at a fixed step, with the contact as the state at the
/// step's start has it. Defaults `beta = 1/4`, `gamma = 1/2` (average
/// acceleration).
#[derive(Debug, Clone, Copy)]
pub struct Newmark {
    method: PaperNewmark,
    /// Accelerations at the current step, m/s^2.
    accel: (f64, f64),
}

impl Newmark {
    pub fn new(beta: f64, gamma: f64) -> Self {
        Self {
            method: PaperNewmark::new(beta, gamma),
            accel: (0.0, 0.0),
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
        // Made afresh: the integrator may be started again for another model.
        self.method.dt = f64::NAN;
        self.method.prepare(model, dt);
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
        let contact = LaggedContact {
            side: c.side,
            law_force: c.law_force,
            in_contact: c.indentation > 0.0,
        };
        let (end, accel) = self.method.step(model, s, self.accel, time, dt, contact);
        self.accel = accel;
        end
    }
}
