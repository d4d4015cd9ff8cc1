//! Steppers of the event-driven kernel: each advances the state by one step
//! within one contact mode, where the right-hand side is smooth.
//!
//! Explicit Runge-Kutta (classical RK4, Dormand-Prince 5(4), DOP853) and the
//! Newmark family solved by Newton's method (implicit Newmark,
//! generalised-alpha, and the founding paper's lagged Newmark).

use crate::error::{Error, Result};
use crate::legacy::equations::{Excitation, Mode, Model};
use crate::legacy::integrators::{rk4_step, LaggedContact, PaperNewmark};
use crate::methods::tableau::*;
use crate::model::contact::ContactLaw;
use crate::model::impact_damper::State;

/// The integrated variables: `w, w', y, y'` and the non-conservative work so
/// far (J: apart, what the main damper took less what the external force
/// gave; in contact, what the contact's dissipative forces took; see
/// [`Model::rates_in`]), integrated by the method itself.
pub type Vector = [f64; 5];

#[inline(always)]
pub fn to_vector(s: &State, dissipated: f64) -> Vector {
    [
        s.main_displacement,
        s.main_velocity,
        s.impact_displacement,
        s.impact_velocity,
        dissipated,
    ]
}

#[inline(always)]
pub fn to_state(v: &Vector) -> State {
    State {
        main_displacement: v[0],
        main_velocity: v[1],
        impact_displacement: v[2],
        impact_velocity: v[3],
    }
}

/// One attempted step.
#[derive(Debug, Clone, Copy)]
pub struct Attempt {
    /// The end point, with the non-conservative work in the last slot.
    pub end: Vector,
    /// Scaled error estimate (accept when <= 1); 0 for fixed-step methods.
    pub error: f64,
}

/// A method the event-driven kernel can drive.
pub trait Stepper {
    /// Whether the step size is controlled by an error estimate.
    const ADAPTIVE: bool;
    /// Order of the error estimate plus one, for the step-size controller.
    const CONTROL_EXPONENT: f64;
    /// `error^(-1 / CONTROL_EXPONENT)`, the step-size factor's core.
    #[inline(always)]
    fn shrink(error: f64) -> f64 {
        error.powf(-1.0 / Self::CONTROL_EXPONENT)
    }
    /// Whether `accept` needs the last attempt to be the accepted step (it
    /// carries data from it); a stateless stepper need not redo a step.
    const CARRIES_DATA: bool = true;
    /// Start, or restart after a mode switch: data carried from step to step
    /// (accelerations, first-same-as-last stages) is rebuilt, because the
    /// right-hand side jumps at a mode switch.
    fn reset<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        mode: Mode,
    );
    /// Attempt a step `h` from `(time, y)`. May be called several times from
    /// the same point (rejections, event location) before `accept`.
    fn attempt<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        h: f64,
        mode: Mode,
    ) -> Result<Attempt>;
    /// The last attempt is the new current point.
    fn accept(&mut self);
    /// Right-hand-side evaluations so far.
    fn evaluations(&self) -> u64;
    /// Relative tolerance of an adaptive method (for its first step).
    fn tolerance(&self) -> f64 {
        1e-6
    }
}

#[inline(always)]
fn derivative<L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    time: f64,
    y: &Vector,
    mode: Mode,
) -> Vector {
    let (aw, ay, power) = model.rates_in(time, &to_state(y), mode);
    [y[1], aw, y[3], ay, power]
}

/// `y + h * sum(w * k)` over the four state variables (and, with `all`,
/// the non-conservative work too), for literal weight lists: the
/// compiler unrolls and constant-folds these where it would not a loop.
macro_rules! stage_point {
    ($y:expr, $h:expr; $($w:expr, $k:expr);+) => {{
        let mut p = *$y;
        for n in 0..4 {
            p[n] += $h * (0.0 $(+ $w * $k[n])+);
        }
        p
    }};
    (all $y:expr, $h:expr; $($w:expr, $k:expr);+) => {{
        let mut p = *$y;
        for n in 0..5 {
            p[n] += $h * (0.0 $(+ $w * $k[n])+);
        }
        p
    }};
}

/// `sum(w * k)` for the four state variables, for literal weight lists.
macro_rules! weighted {
    ($($w:expr, $k:expr);+) => {{
        let mut sum = [0.0; 4];
        for n in 0..4 {
            sum[n] = 0.0 $(+ $w * $k[n])+;
        }
        sum
    }};
}

/// Runs the stages of an explicit tableau; `k[0]` must hold `f(time, y)`.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn stages<const S: usize, L: ContactLaw, X: Excitation>(
    model: &Model<L, X>,
    time: f64,
    y: &Vector,
    h: f64,
    mode: Mode,
    c: &[f64; S],
    a: &[[f64; S]; S],
    k: &mut [Vector; S],
) {
    for i in 1..S {
        // Sum the stage increments first, then scale once by h: fewer
        // operations and a straight line the compiler can vectorise.
        // The non-conservative work (slot 4) feeds no force: stage values of
        // the four state variables suffice.
        let mut sum = [0.0; 4];
        for (aij, kj) in a[i].iter().zip(k.iter()).take(i) {
            for n in 0..4 {
                sum[n] += aij * kj[n];
            }
        }
        let mut yi = *y;
        for n in 0..4 {
            yi[n] += h * sum[n];
        }
        k[i] = derivative(model, time + c[i] * h, &yi, mode);
    }
}

#[inline(always)]
fn combine<const S: usize>(y: &Vector, h: f64, b: &[f64; S], k: &[Vector; S]) -> Vector {
    let mut sum = [0.0; 5];
    for (bi, ki) in b.iter().zip(k.iter()) {
        for n in 0..5 {
            sum[n] += bi * ki[n];
        }
    }
    let mut out = *y;
    for n in 0..5 {
        out[n] += h * sum[n];
    }
    out
}

pub use crate::methods::registry::two_mass::Tolerances;

/// The weight of variable `n` in the error norm (the non-conservative work
/// is an output, not controlled).
#[inline(always)]
fn scale(tolerances: &Tolerances, y: &Vector, end: &Vector, n: usize) -> f64 {
    tolerances.atol + tolerances.rtol * y[n].abs().max(end[n].abs())
}

/// Classical fourth-order Runge-Kutta, fixed step: the fixed-step kernel's
/// [`rk4_step`], with the non-conservative work integrated alongside.
#[derive(Debug, Clone, Default)]
pub struct Rk4Stepper {
    evaluations: u64,
}

impl Stepper for Rk4Stepper {
    const ADAPTIVE: bool = false;
    const CONTROL_EXPONENT: f64 = 5.0;
    const CARRIES_DATA: bool = false;
    fn reset<L: ContactLaw, X: Excitation>(
        &mut self,
        _: &Model<L, X>,
        _: f64,
        _: &Vector,
        _: Mode,
    ) {
    }

    #[inline(always)]
    fn attempt<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        h: f64,
        mode: Mode,
    ) -> Result<Attempt> {
        self.evaluations += 4;
        Ok(Attempt {
            end: rk4_step(time, y, h, |t, p| derivative(model, t, p, mode)),
            error: 0.0,
        })
    }

    fn accept(&mut self) {}

    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}

/// An embedded Runge-Kutta pair: one step from `f` at its start, giving the
/// end point, the scaled error and `f` at the end (first same as last).
pub trait EmbeddedPair {
    /// Order of the error estimate plus one, for the step-size controller.
    const CONTROL_EXPONENT: f64;
    /// `error^(-1 / CONTROL_EXPONENT)`.
    #[inline(always)]
    fn shrink(error: f64) -> f64 {
        error.powf(-1.0 / Self::CONTROL_EXPONENT)
    }
    /// Right-hand-side evaluations per step (the start's excluded).
    const EVALUATIONS: u64;
    #[allow(clippy::too_many_arguments)]
    fn step<L: ContactLaw, X: Excitation>(
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        h: f64,
        mode: Mode,
        start: &Vector,
        tolerances: &Tolerances,
    ) -> (Vector, f64, Vector);
}

/// Dormand-Prince 5(4).
#[derive(Debug, Clone, Copy)]
pub struct Dopri5;

impl EmbeddedPair for Dopri5 {
    const CONTROL_EXPONENT: f64 = 5.0;
    const EVALUATIONS: u64 = 6;

    fn step<L: ContactLaw, X: Excitation>(
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        h: f64,
        mode: Mode,
        start: &Vector,
        tolerances: &Tolerances,
    ) -> (Vector, f64, Vector) {
        let mut k = [[0.0; 5]; 7];
        k[0] = *start;
        stages(model, time, y, h, mode, &DOPRI5_C, &DOPRI5_A, &mut k);
        let end = combine(y, h, &DOPRI5_B, &k);
        let mut sum = 0.0;
        for n in 0..4 {
            let e: f64 = DOPRI5_E
                .iter()
                .zip(k.iter())
                .map(|(ei, ki)| ei * ki[n])
                .sum();
            let ratio = h * e / scale(tolerances, y, &end, n);
            sum += ratio * ratio;
        }
        (end, (sum / 4.0).sqrt(), k[6])
    }
}

/// DOP853, with its combined fifth/third-order error estimate.
#[derive(Debug, Clone, Copy)]
pub struct Dop853;

impl EmbeddedPair for Dop853 {
    const CONTROL_EXPONENT: f64 = 8.0;
    /// The eighth root by three square roots: several times cheaper than
    /// `powf`, which showed in the profile of short runs.
    #[inline(always)]
    fn shrink(error: f64) -> f64 {
        1.0 / error.sqrt().sqrt().sqrt()
    }
    const EVALUATIONS: u64 = 12;

    fn step<L: ContactLaw, X: Excitation>(
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        h: f64,
        mode: Mode,
        start: &Vector,
        tolerances: &Tolerances,
    ) -> (Vector, f64, Vector) {
        // Written out stage by stage over the tableau's nonzero entries: as
        // generic loops over twelve stages the compiler neither unrolls them
        // nor folds the zeros, and the step costs several times more.
        let mut k = [[0.0; 5]; 12];
        k[0] = *start;
        k[1] = derivative(
            model,
            time + DOP853_C[1] * h,
            &stage_point!(y, h; DOP853_A[1][0], k[0]),
            mode,
        );
        k[2] = derivative(
            model,
            time + DOP853_C[2] * h,
            &stage_point!(y, h; DOP853_A[2][0], k[0]; DOP853_A[2][1], k[1]),
            mode,
        );
        k[3] = derivative(
            model,
            time + DOP853_C[3] * h,
            &stage_point!(y, h; DOP853_A[3][0], k[0]; DOP853_A[3][2], k[2]),
            mode,
        );
        k[4] = derivative(
            model,
            time + DOP853_C[4] * h,
            &stage_point!(y, h; DOP853_A[4][0], k[0]; DOP853_A[4][2], k[2]; DOP853_A[4][3], k[3]),
            mode,
        );
        k[5] = derivative(
            model,
            time + DOP853_C[5] * h,
            &stage_point!(y, h; DOP853_A[5][0], k[0]; DOP853_A[5][3], k[3]; DOP853_A[5][4], k[4]),
            mode,
        );
        k[6] = derivative(
            model,
            time + DOP853_C[6] * h,
            &stage_point!(y, h; DOP853_A[6][0], k[0]; DOP853_A[6][3], k[3]; DOP853_A[6][4], k[4]; DOP853_A[6][5], k[5]),
            mode,
        );
        k[7] = derivative(
            model,
            time + DOP853_C[7] * h,
            &stage_point!(y, h; DOP853_A[7][0], k[0]; DOP853_A[7][3], k[3]; DOP853_A[7][4], k[4]; DOP853_A[7][5], k[5]; DOP853_A[7][6], k[6]),
            mode,
        );
        k[8] = derivative(
            model,
            time + DOP853_C[8] * h,
            &stage_point!(y, h; DOP853_A[8][0], k[0]; DOP853_A[8][3], k[3]; DOP853_A[8][4], k[4]; DOP853_A[8][5], k[5]; DOP853_A[8][6], k[6]; DOP853_A[8][7], k[7]),
            mode,
        );
        k[9] = derivative(
            model,
            time + DOP853_C[9] * h,
            &stage_point!(y, h; DOP853_A[9][0], k[0]; DOP853_A[9][3], k[3]; DOP853_A[9][4], k[4]; DOP853_A[9][5], k[5]; DOP853_A[9][6], k[6]; DOP853_A[9][7], k[7]; DOP853_A[9][8], k[8]),
            mode,
        );
        k[10] = derivative(
            model,
            time + DOP853_C[10] * h,
            &stage_point!(y, h; DOP853_A[10][0], k[0]; DOP853_A[10][3], k[3]; DOP853_A[10][4], k[4]; DOP853_A[10][5], k[5]; DOP853_A[10][6], k[6]; DOP853_A[10][7], k[7]; DOP853_A[10][8], k[8]; DOP853_A[10][9], k[9]),
            mode,
        );
        k[11] = derivative(
            model,
            time + DOP853_C[11] * h,
            &stage_point!(y, h; DOP853_A[11][0], k[0]; DOP853_A[11][3], k[3]; DOP853_A[11][4], k[4]; DOP853_A[11][5], k[5]; DOP853_A[11][6], k[6]; DOP853_A[11][7], k[7]; DOP853_A[11][8], k[8]; DOP853_A[11][9], k[9]; DOP853_A[11][10], k[10]),
            mode,
        );
        let end = stage_point!(all y, h; DOP853_B[0], k[0]; DOP853_B[5], k[5]; DOP853_B[6], k[6]; DOP853_B[7], k[7]; DOP853_B[8], k[8]; DOP853_B[9], k[9]; DOP853_B[10], k[10]; DOP853_B[11], k[11]);
        let last = derivative(model, time + h, &end, mode);
        let e5 = weighted!(DOP853_E5[0], k[0]; DOP853_E5[5], k[5]; DOP853_E5[6], k[6]; DOP853_E5[7], k[7]; DOP853_E5[8], k[8]; DOP853_E5[9], k[9]; DOP853_E5[10], k[10]; DOP853_E5[11], k[11]; DOP853_E5[12], last);
        let e3 = weighted!(DOP853_E3[0], k[0]; DOP853_E3[5], k[5]; DOP853_E3[6], k[6]; DOP853_E3[7], k[7]; DOP853_E3[8], k[8]; DOP853_E3[9], k[9]; DOP853_E3[10], k[10]; DOP853_E3[11], k[11]; DOP853_E3[12], last);
        let (mut err5, mut err3) = (0.0, 0.0);
        for n in 0..4 {
            let scale = scale(tolerances, y, &end, n);
            err5 += (e5[n] / scale) * (e5[n] / scale);
            err3 += (e3[n] / scale) * (e3[n] / scale);
        }
        let denominator = err5 + 0.01 * err3;
        let error = if denominator > 0.0 {
            h.abs() * err5 / (denominator * 4.0).sqrt()
        } else {
            0.0
        };
        (end, error, last)
    }
}

/// An embedded pair with error control, carrying `f` from step to step.
#[derive(Debug, Clone)]
pub struct Adaptive<P: EmbeddedPair> {
    tolerances: Tolerances,
    /// `f` at the current point, valid after `reset` or `accept`.
    start: Vector,
    /// `f` at the end of the last attempt.
    pending: Vector,
    evaluations: u64,
    pair: std::marker::PhantomData<P>,
}

impl<P: EmbeddedPair> Adaptive<P> {
    pub fn new(tolerances: Tolerances) -> Self {
        Self {
            tolerances,
            start: [0.0; 5],
            pending: [0.0; 5],
            evaluations: 0,
            pair: std::marker::PhantomData,
        }
    }
}

/// Dormand-Prince 5(4) with error control.
pub type Dopri5Stepper = Adaptive<Dopri5>;
/// DOP853 with error control.
pub type Dop853Stepper = Adaptive<Dop853>;

impl<P: EmbeddedPair> Stepper for Adaptive<P> {
    const ADAPTIVE: bool = true;
    const CONTROL_EXPONENT: f64 = P::CONTROL_EXPONENT;

    #[inline(always)]
    fn shrink(error: f64) -> f64 {
        P::shrink(error)
    }

    fn reset<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        mode: Mode,
    ) {
        self.start = derivative(model, time, y, mode);
        self.evaluations += 1;
    }

    fn attempt<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        h: f64,
        mode: Mode,
    ) -> Result<Attempt> {
        let (end, error, last) = P::step(model, time, y, h, mode, &self.start, &self.tolerances);
        self.evaluations += P::EVALUATIONS;
        self.pending = last;
        Ok(Attempt { end, error })
    }

    fn accept(&mut self) {
        self.start = self.pending;
    }

    fn evaluations(&self) -> u64 {
        self.evaluations
    }

    fn tolerance(&self) -> f64 {
        self.tolerances.rtol
    }
}

/// The Newmark family on the two equations of motion, written for the new
/// accelerations and solved by Newton's method:
///
/// `M a_(n+1-am) + C v_(n+1-af) + K x_(n+1-af) - f(t_(n+1-af), x, v) = 0`
///
/// with Newmark's `x_(n+1)`, `v_(n+1)` in `beta`, `gamma`. `am = af = 0` is
/// Newmark-beta (average acceleration for 1/4, 1/2: second order, no
/// numerical damping); Chung-Hulbert's generalised-alpha sets all four from
/// the spectral radius at infinite frequency. With `lagged` the contact law's
/// force is taken from the start of the step, leaving only the contact
/// damper implicit: the founding paper's method, which the fixed-step kernel
/// runs too, one implementation ([`PaperNewmark`]) for both.
#[derive(Debug, Clone)]
pub struct NewmarkFamily {
    pub alpha_m: f64,
    pub alpha_f: f64,
    pub beta: f64,
    pub gamma: f64,
    /// The founding paper's lagged Newmark, which takes no Newton iteration.
    paper: Option<PaperNewmark>,
    /// Accelerations at the current point and at the end of the last attempt.
    accel: (f64, f64),
    pending: (f64, f64),
    /// Non-conservative power at the current point and at the end of the
    /// last attempt (W), for the trapezoidal rule on it.
    losses: f64,
    pending_losses: f64,
    evaluations: u64,
}

/// Newton iterations allowed per step.
const NEWTON_ITERATIONS: usize = 40;

impl NewmarkFamily {
    /// Newmark-beta solved implicitly (Newton on the contact force).
    pub fn newmark(beta: f64, gamma: f64, lagged: bool) -> Self {
        Self {
            alpha_m: 0.0,
            alpha_f: 0.0,
            beta,
            gamma,
            paper: lagged.then(|| PaperNewmark::new(beta, gamma)),
            accel: (0.0, 0.0),
            pending: (0.0, 0.0),
            losses: 0.0,
            pending_losses: 0.0,
            evaluations: 0,
        }
    }

    /// Chung-Hulbert generalised-alpha with spectral radius `rho` in [0, 1]
    /// at infinite frequency (1: no numerical damping).
    pub fn generalized_alpha(rho: f64) -> Self {
        let alpha_m = (2.0 * rho - 1.0) / (rho + 1.0);
        let alpha_f = rho / (rho + 1.0);
        let gamma = 0.5 - alpha_m + alpha_f;
        let beta = 0.25 * (1.0 - alpha_m + alpha_f).powi(2);
        Self {
            alpha_m,
            alpha_f,
            beta,
            gamma,
            paper: None,
            accel: (0.0, 0.0),
            pending: (0.0, 0.0),
            losses: 0.0,
            pending_losses: 0.0,
            evaluations: 0,
        }
    }
}

impl Stepper for NewmarkFamily {
    const ADAPTIVE: bool = false;
    const CONTROL_EXPONENT: f64 = 3.0;

    fn reset<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        mode: Mode,
    ) {
        // After a jump the physical accelerations, not the algorithmic ones.
        let (aw, ay, losses) = model.rates_in(time, &to_state(y), mode);
        (self.accel, self.losses) = ((aw, ay), losses);
        self.evaluations += 1;
    }

    fn attempt<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        h: f64,
        mode: Mode,
    ) -> Result<Attempt> {
        let (end_state, accel) = match &mut self.paper {
            Some(paper) => {
                paper.prepare(model, h);
                let s0 = to_state(y);
                let contact = match mode {
                    Mode::Free => LaggedContact {
                        side: 1.0,
                        law_force: 0.0,
                        in_contact: false,
                    },
                    Mode::Contact {
                        side,
                        approach_rate,
                    } => LaggedContact {
                        side,
                        law_force: model.contact_at(&s0, side, approach_rate).law_force,
                        in_contact: true,
                    },
                };
                self.evaluations += 1;
                paper.step(model, &s0, self.accel, time, h, contact)
            }
            None => self.newton(model, time, y, h, mode)?,
        };
        // Non-conservative work by the trapezoidal rule, second order like the
        // method (the power at the start carried from the step before).
        let power1 = model.losses_in(time + h, &end_state, mode);
        self.pending = accel;
        self.pending_losses = power1;
        Ok(Attempt {
            end: to_vector(&end_state, y[4] + 0.5 * h * (self.losses + power1)),
            error: 0.0,
        })
    }

    fn accept(&mut self) {
        self.accel = self.pending;
        self.losses = self.pending_losses;
    }

    fn evaluations(&self) -> u64 {
        self.evaluations
    }
}

impl NewmarkFamily {
    /// The new state and accelerations by Newton's method on the residual.
    fn newton<L: ContactLaw, X: Excitation>(
        &mut self,
        model: &Model<L, X>,
        time: f64,
        y: &Vector,
        h: f64,
        mode: Mode,
    ) -> Result<(State, (f64, f64))> {
        let (am, af, beta, gamma) = (self.alpha_m, self.alpha_f, self.beta, self.gamma);
        let (m_main, m_imp) = (model.main_mass, model.impact_mass);
        let (a0w, a0y) = self.accel;
        // Predictors: the parts of x_(n+1), v_(n+1) that do not depend on a_(n+1).
        let xw = y[0] + h * y[1] + h * h * (0.5 - beta) * a0w;
        let xy = y[2] + h * y[3] + h * h * (0.5 - beta) * a0y;
        let vw = y[1] + h * (1.0 - gamma) * a0w;
        let vy = y[3] + h * (1.0 - gamma) * a0y;
        let (bx, gv) = (beta * h * h, gamma * h);
        let force_ext =
            (1.0 - af) * model.external_force(time + h) + af * model.external_force(time);
        let kx = (1.0 - af) * bx;
        let cv = (1.0 - af) * gv;
        // Residual of both equations at trial accelerations, with the slopes
        // of the contact force (Jacobian) and the size of the forces in play.
        let residual = |aw: f64, ay: f64| {
            let xfw = (1.0 - af) * (xw + bx * aw) + af * y[0];
            let xfy = (1.0 - af) * (xy + bx * ay) + af * y[2];
            let vfw = (1.0 - af) * (vw + gv * aw) + af * y[1];
            let vfy = (1.0 - af) * (vy + gv * ay) + af * y[3];
            // Contact force on the main mass (+side F) and its slopes in the
            // indentation (F_d) and its rate (F_r).
            let (push, f_d, f_r) = match mode {
                Mode::Free => (0.0, 0.0, 0.0),
                Mode::Contact {
                    side,
                    approach_rate,
                } => {
                    let indentation = side * (xfy - xfw) - model.clearance;
                    let rate = side * (vfy - vfw);
                    let c1 = model.contact_damping;
                    if indentation > 0.0 {
                        let (f, fd, fr) =
                            model
                                .law
                                .force_derivatives(indentation, rate, approach_rate);
                        (side * (f + c1 * rate), fd, fr + c1)
                    } else {
                        (side * c1 * rate, 0.0, c1)
                    }
                }
            };
            let amw = (1.0 - am) * aw + am * a0w;
            let amy = (1.0 - am) * ay + am * a0y;
            let rw = m_main * amw + model.damping * vfw + model.stiffness * xfw - force_ext - push;
            let ry = m_imp * amy + push;
            let coupling = kx * f_d + cv * f_r;
            // Round-off in the residual: the terms' sizes, and the contact
            // force's response to the last bits of the (absolute) positions
            // and velocities from which the indentation is computed.
            let noise = 4.0
                * f64::EPSILON
                * ((m_main * amw).abs()
                    + (model.damping * vfw).abs()
                    + (model.stiffness * xfw).abs()
                    + force_ext.abs()
                    + push.abs()
                    + f_d * (xfw.abs() + xfy.abs())
                    + f_r * (vfw.abs() + vfy.abs()));
            (rw, ry, coupling, noise)
        };
        let norm = |rw: f64, ry: f64| rw.abs().max(ry.abs());
        let (mut aw, mut ay) = (a0w, a0y);
        let (mut rw, mut ry, mut coupling, mut noise) = residual(aw, ay);
        self.evaluations += 1;
        let mut converged = false;
        // Apart, the equations are linear in the new accelerations: one
        // Newton update solves them exactly.
        let linear = matches!(mode, Mode::Free);
        for _ in 0..NEWTON_ITERATIONS {
            // Jacobian d(r)/d(a_(n+1)): symmetric 2x2.
            let j11 = (1.0 - am) * m_main + kx * model.stiffness + cv * model.damping + coupling;
            let j22 = (1.0 - am) * m_imp + coupling;
            let j12 = -coupling;
            let det = j11 * j22 - j12 * j12;
            let daw = -(j22 * rw - j12 * ry) / det;
            let day = -(-j12 * rw + j11 * ry) / det;
            if !(daw.is_finite() && day.is_finite()) {
                break;
            }
            // Converged when the update can no longer change the new
            // displacements or velocities (round-off), is relatively tiny, or
            // is within the round-off of the residual itself.
            let floor = noise / j11.min(j22);
            let invisible = |da: f64, a: f64, x: f64, v: f64| {
                let mut tol = (1e-13 * a.abs().max(a0w.abs()).max(a0y.abs())).max(floor);
                let by_v = 4.0 * f64::EPSILON * v.abs() / gv;
                let by_x = if bx > 0.0 {
                    4.0 * f64::EPSILON * x.abs() / bx
                } else {
                    f64::INFINITY
                };
                tol = tol.max(by_v.min(by_x));
                da.abs() <= tol
            };
            let done = invisible(daw, aw, xw + bx * aw, vw + gv * aw)
                && invisible(day, ay, xy + bx * ay, vy + gv * ay);
            // Backtracking: halve the update until the residual falls, which
            // keeps Newton from cycling across the kink where a law's force is
            // clamped at zero.
            if done || linear {
                // The update is at round-off, or exact: take it as it is.
                (aw, ay) = (aw + daw, ay + day);
                converged = true;
                break;
            }
            let before = norm(rw, ry);
            let mut lambda = 1.0;
            loop {
                let (cw, cy) = (aw + lambda * daw, ay + lambda * day);
                let (nw, ny, nc, nn) = residual(cw, cy);
                self.evaluations += 1;
                if norm(nw, ny) < before || lambda < 1e-3 {
                    (aw, ay, rw, ry, coupling, noise) = (cw, cy, nw, ny, nc, nn);
                    break;
                }
                lambda *= 0.5;
            }
            if norm(rw, ry) == 0.0 {
                converged = true;
                break;
            }
        }
        if !converged {
            return Err(Error::NewtonFailed { time });
        }
        let end_state = State {
            main_displacement: xw + bx * aw,
            main_velocity: vw + gv * aw,
            impact_displacement: xy + bx * ay,
            impact_velocity: vy + gv * ay,
        };
        Ok((end_state, (aw, ay)))
    }
}

#[cfg(test)]
mod tests {
    //! Newton's method in the Newmark family. Its Jacobian must be the exact
    //! derivative of the residual: then one update solves a linear residual
    //! and the iterates of a nonlinear one converge quadratically. A wrong
    //! Jacobian (say, without the off-diagonal coupling of the two bodies)
    //! still converges, linearly, in more iterations, which is what these
    //! tests count.
    use super::*;
    use crate::legacy::equations::Free;
    use crate::model::contact::{Contact, LawKind, LawVisitor};
    use crate::model::impact_damper::ImpactDamper;

    const CLEARANCE: f64 = 0.01;

    /// Residual evaluations of one implicit step `h` (s) of `stepper` from a
    /// state in contact with the wall at +d: `indentation` m, `rate` m/s.
    struct OneStep {
        stepper: NewmarkFamily,
        indentation: f64,
        rate: f64,
        h: f64,
    }

    impl LawVisitor for OneStep {
        type Output = u64;
        fn visit<L: ContactLaw>(mut self, law: L) -> u64 {
            let system = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, CLEARANCE).unwrap();
            let model = Model::new(&system, law, 0.01, Free);
            let start = State::new(0.0, 0.0, CLEARANCE + self.indentation, self.rate).unwrap();
            let y = to_vector(&start, 0.0);
            let mode = Mode::Contact {
                side: 1.0,
                approach_rate: 0.1,
            };
            self.stepper.reset(&model, 0.0, &y, mode);
            let before = self.stepper.evaluations();
            self.stepper.attempt(&model, 0.0, &y, self.h, mode).unwrap();
            self.stepper.evaluations() - before
        }
    }

    fn implicit_methods() -> [(&'static str, NewmarkFamily); 3] {
        [
            ("newmark-implicit", NewmarkFamily::newmark(0.25, 0.5, false)),
            (
                "generalized-alpha 0.8",
                NewmarkFamily::generalized_alpha(0.8),
            ),
            ("generalized-alpha 0", NewmarkFamily::generalized_alpha(0.0)),
        ]
    }

    #[test]
    fn newton_solves_a_linear_contact_in_one_update() {
        crate::testing::timeout(60, || {
            // A linear spring and the contact damper make the residual linear in
            // the new accelerations. With the exact Jacobian one update lands on
            // the solution: the first evaluation is at the predictor, the second
            // finds round-off, and the next update is too small to need a third.
            // The step keeps the indentation positive (the force is linear only
            // there): k1 h^2 <= 0.16 kg against the reduced mass of 0.2 kg keeps
            // the phase of the contact oscillation within 1 rad. That still
            // couples the two bodies (k1 h^2 up to 0.16 of their masses), so an
            // error in the coupling terms shows.
            for (name, stepper) in implicit_methods() {
                for stiffness in [3e3, 1e6, 1e9, 1e12] {
                    let contact = Contact::new(LawKind::Linear, stiffness, None, 0.01).unwrap();
                    for h in [0.01, 0.1, 0.4].map(|f: f64| f / f64::sqrt(stiffness)) {
                        for rate in [0.05, -0.05, 0.0] {
                            let evaluations = contact.visit(OneStep {
                                stepper: stepper.clone(),
                                indentation: 3e-3,
                                rate,
                                h,
                            });
                            assert_eq!(
                                evaluations, 2,
                                "{name}, k1 = {stiffness:e} N/m, h = {h:e} s, rate {rate} m/s: \
                                 {evaluations} residual evaluations for a linear residual"
                            );
                        }
                    }
                }
            }
        });
    }

    #[test]
    fn newton_converges_quadratically_on_a_hertz_contact() {
        crate::testing::timeout(60, || {
            // From the predictor the first iterate is at worst wrong in its
            // leading digit; quadratic convergence doubles the correct digits at
            // each update, so 53 bits take at most 6 updates (log2 53 < 6), plus
            // the evaluation at the predictor. A Jacobian without the coupling
            // converges linearly and takes 10 to 27 evaluations in some of these
            // cases (K_hz = 3e3 N/m^1.5 with h = 1e-2 s, 1e6 with 1e-4 and 1e-3 s).
            for (name, stepper) in implicit_methods() {
                for stiffness in [3e3, 1e6, 1e9, 1e12] {
                    let contact =
                        Contact::new(LawKind::HertzDamped, stiffness, Some(0.5), 0.01).unwrap();
                    for h in [1e-4, 1e-3, 1e-2] {
                        for (indentation, rate) in [(1e-3, 0.05), (1e-3, -0.05), (3e-3, 0.0)] {
                            let evaluations = contact.visit(OneStep {
                                stepper: stepper.clone(),
                                indentation,
                                rate,
                                h,
                            });
                            assert!(
                                evaluations <= 7,
                                "{name}, K_hz = {stiffness:e} N/m^1.5, h = {h:e} s, indentation \
                                 {indentation} m, rate {rate} m/s: {evaluations} residual \
                                 evaluations, more than quadratic convergence needs"
                            );
                        }
                    }
                }
            }
        });
    }

    /// Checks a law's slopes, which make the contact terms of the Jacobian,
    /// against central differences of its force.
    struct Slopes(&'static str);

    impl LawVisitor for Slopes {
        type Output = ();
        fn visit<L: ContactLaw>(self, law: L) {
            let name = self.0;
            let approach = 0.1;
            // A relative step of 1e-5: truncation ~1e-10, round-off ~1e-11.
            let central = |f: &dyn Fn(f64) -> f64, x: f64, step: f64| {
                (f(x + step) - f(x - step)) / (2.0 * step)
            };
            for (indentation, rate) in [(1e-3, 0.05), (2e-3, -0.03), (3e-3, 0.0)] {
                let (force, by_indentation, by_rate) =
                    law.force_derivatives(indentation, rate, approach);
                let direct = law.force(indentation, rate, approach);
                assert!((force - direct).abs() <= 1e-15 * direct, "{name}: F");
                let fd_indentation = central(
                    &|d| law.force(d, rate, approach),
                    indentation,
                    1e-5 * indentation,
                );
                let fd_rate = central(
                    &|r| law.force(indentation, r, approach),
                    rate,
                    1e-5 * approach,
                );
                assert!(
                    (by_indentation - fd_indentation).abs() <= 1e-8 * fd_indentation.abs(),
                    "{name}: dF/d delta {by_indentation} vs {fd_indentation}"
                );
                // Scaled by the force over the approach rate (dF/d delta' is 0
                // for the elastic laws).
                assert!(
                    (by_rate - fd_rate).abs() <= 1e-8 * direct / approach,
                    "{name}: dF/d delta' {by_rate} vs {fd_rate}"
                );
            }
        }
    }

    #[test]
    fn contact_law_slopes_match_finite_differences() {
        crate::testing::timeout(60, || {
            for (name, law, restitution) in [
                ("hertz", LawKind::Hertz, None),
                ("hyster-hertz", LawKind::HysterHertz, Some(0.5)),
                ("hertz-damped", LawKind::HertzDamped, Some(0.5)),
                ("linear", LawKind::Linear, None),
            ] {
                Contact::new(law, 3e3, restitution, 0.0)
                    .unwrap()
                    .visit(Slopes(name));
            }
        });
    }
}
