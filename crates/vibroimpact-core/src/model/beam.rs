//! Cantilever (clamped-free Euler-Bernoulli) modes, and one mode reduced to a
//! single degree of freedom by the Ritz method on its free-vibration shape.
//!
//! Mode `i` has the root `b_i L` of `cos(x) cosh(x) + 1 = 0` and the shape
//! `phi_i(x) = cosh z - cos z - sigma_i (sinh z - sin z)`, `z = b_i x`,
//! `sigma_i = (sinh b L - sin b L) / (cosh b L + cos b L)`, for which
//! `int_0^L phi_i phi_j dx = L delta_ij` and `|phi_i(L)| = 2` exactly.
//! Written that way the shape subtracts terms of size `e^(b L) / 2` and loses
//! every digit by mode 13 (and overflows from mode 227); here it is evaluated
//! in a form whose terms are all of order one, so that every mode is right to
//! round-off, and no mode number overflows.

use crate::error::{at_least_one, positive, within, Error, Result};
use crate::model::closed_forms::representable;

/// `1 / cosh(x)` and `tanh(x)` for `x >= 0`, from `e^-x` so that neither
/// overflows however large `x` is.
fn sech_tanh(x: f64) -> (f64, f64) {
    let e = (-x).exp();
    let e2 = e * e;
    (2.0 * e / (1.0 + e2), (1.0 - e2) / (1.0 + e2))
}

/// The root `b_i L` of the cantilever frequency equation
/// `cos(x) cosh(x) + 1 = 0` for mode `mode` >= 1 (any `u32`), to round-off.
///
/// Newton's method on `cos(x) + 1/cosh(x) = 0` (the same roots; the form never
/// overflows and its slope stays near 1), from the asymptote `(2i - 1) pi / 2`.
pub fn cantilever_root(mode: u32) -> Result<f64> {
    at_least_one("mode", u64::from(mode))?;
    let mut x = (2.0 * f64::from(mode) - 1.0) * std::f64::consts::FRAC_PI_2;
    // Converges in at most 6 steps (mode 1, 0.3 from its start); the cap only
    // guards against a cycle at round-off.
    for _ in 0..50 {
        let (sech, tanh) = sech_tanh(x);
        let (sin, cos) = x.sin_cos();
        let step = (cos + sech) / (-sin - sech * tanh);
        x -= step;
        if step.abs() <= 2.0 * f64::EPSILON * x {
            break;
        }
    }
    Ok(x)
}

/// Mode shape `phi_i` of a cantilever as a pure function of `xi = x / L`,
/// normalised so that `int_0^1 phi_i phi_j d xi = delta_ij` (`|phi_i(1)| = 2`,
/// positive at the tip for odd modes, negative for even ones).
///
/// Evaluated as `e^-z + (1 - sigma) sinh z - cos z + sigma sin z`, with
/// `(1 - sigma) sinh z` taken as `r (e^(z - bL) - e^(-z - bL)) / 2`, `r =
/// (1 - sigma) e^(bL)` computed without cancellation: every term is at most of
/// order one, so values are right to round-off; the absolute error grows like
/// `i * 1e-16` only because `x -> phi(x)` itself is that sensitive to `x`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CantileverShape {
    /// Mode number (1 = fundamental).
    pub mode: u32,
    /// `b_i L`, dimensionless.
    pub beta_l: f64,
    /// `sigma_i`.
    sigma: f64,
    /// `(1 - sigma_i) e^(b_i L)`, of order one.
    excess: f64,
}

impl CantileverShape {
    /// The shape of mode `mode` >= 1.
    pub fn new(mode: u32) -> Result<Self> {
        let b = cantilever_root(mode)?;
        let (sin, cos) = b.sin_cos();
        let e = (-b).exp();
        // cosh b + cos b and sinh b - sin b, both divided by e^b / 2.
        let denominator = 1.0 + e * (2.0 * cos + e);
        let sigma = (1.0 - e * (2.0 * sin + e)) / denominator;
        // 1 - sigma = (e^-b + cos b + sin b) / (cosh b + cos b): no cancellation,
        // since cos b + sin b is near +-1 (or 0.65 for mode 1) at every root.
        let excess = 2.0 * (e + cos + sin) / denominator;
        Ok(Self {
            mode,
            beta_l: b,
            sigma,
            excess,
        })
    }

    /// `[phi, dphi/dxi, d2phi/dxi2, d3phi/dxi3]` at `xi = x / L` in [0, 1]
    /// (divide the k-th by `L^k` for derivatives in x, 1/m^k).
    pub fn derivatives(&self, xi: f64) -> Result<[f64; 4]> {
        let xi = within("xi", xi, 0.0, 1.0, false, "in [0, 1] (x / length)")?;
        let b = self.beta_l;
        let z = b * xi;
        let decay = (-z).exp();
        // (1 - sigma) e^(+-z) = excess e^(+-z - b), exponents <= 0.
        let rising = self.excess * (z - b).exp();
        let falling = self.excess * (-z - b).exp();
        let q_sinh = 0.5 * (rising - falling);
        let q_cosh = 0.5 * (rising + falling);
        let (sin, cos) = z.sin_cos();
        let s = self.sigma;
        // cosh z - sigma sinh z = e^-z + (1 - sigma) sinh z, and
        // sinh z - sigma cosh z = -e^-z + (1 - sigma) cosh z.
        let even = decay + q_sinh;
        let odd = -decay + q_cosh;
        Ok([
            even - cos + s * sin,
            b * (odd + sin + s * cos),
            b * b * (even + cos - s * sin),
            b * b * b * (odd - sin - s * cos),
        ])
    }

    /// `phi(xi)` at `xi = x / L` in [0, 1].
    pub fn value(&self, xi: f64) -> Result<f64> {
        Ok(self.derivatives(xi)?[0])
    }
}

/// One cantilever mode reduced to a single degree of freedom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeamMode {
    /// Mode number (1 = fundamental).
    pub mode: u32,
    /// `b_i L`, dimensionless.
    pub beta_l: f64,
    /// Natural frequency, rad/s.
    pub angular_frequency: f64,
    /// Generalised stiffness with `int_0^L phi^2 dx = L`: `(b L)^4 E I / L^3`, N/m.
    pub modal_stiffness: f64,
    /// Generalised mass with the same normalisation: `rho A L`, kg.
    pub modal_mass: f64,
    /// Where the enclosure sits, m from the clamp.
    pub position: f64,
    /// `phi(position)` with `int_0^L phi^2 dx = L` (2 at the tip of every mode, up to sign).
    pub shape_at_position: f64,
    /// Stiffness referred to `position`: `modal_stiffness / phi(position)^2`, N/m.
    pub stiffness_at_position: f64,
    /// Mass referred to `position`: `modal_mass / phi(position)^2`, kg.
    pub mass_at_position: f64,
}

/// Reduce mode `mode` of a cantilever (length `length` m, Young's modulus
/// `youngs_modulus` Pa, second moment of area `second_moment` m^4, density
/// `density` kg/m^3, cross-section `area` m^2) to one degree of freedom, and
/// refer it to the point `position` (m from the clamp; the tip by default).
pub fn cantilever_mode(
    length: f64,
    youngs_modulus: f64,
    second_moment: f64,
    density: f64,
    area: f64,
    mode: u32,
    position: Option<f64>,
) -> Result<BeamMode> {
    let length = positive("length", length)?;
    let e = positive("youngs_modulus", youngs_modulus)?;
    let i = positive("second_moment", second_moment)?;
    let rho = positive("density", density)?;
    let a = positive("area", area)?;
    let position = match position {
        Some(p) => within("position", p, 0.0, length, true, "in (0, length]")?,
        None => length,
    };
    let shape = CantileverShape::new(mode)?;
    let beta_l = shape.beta_l;
    let phi = shape.value((position / length).min(1.0))?;
    // Below the shape's own round-off (which grows with the mode) a point
    // cannot be told from a node.
    if phi.abs() < 1e-9_f64.max(64.0 * f64::EPSILON * beta_l) {
        return Err(Error::Inconsistent(format!(
            "position {position} m is a node of mode {mode}: the mode does not move there"
        )));
    }
    let modal_stiffness = representable(
        "modal stiffness (b L)^4 E I / L^3",
        "N/m",
        beta_l.powi(4) * (e * i / length.powi(3)),
        "youngs_modulus, second_moment, length and mode",
    )?;
    let modal_mass = representable(
        "modal mass rho A L",
        "kg",
        rho * a * length,
        "density, area and length",
    )?;
    let s2 = phi * phi;
    Ok(BeamMode {
        mode,
        beta_l,
        angular_frequency: representable(
            "angular frequency",
            "rad/s",
            (modal_stiffness / modal_mass).sqrt(),
            "the beam's properties",
        )?,
        modal_stiffness,
        modal_mass,
        position,
        shape_at_position: phi,
        stiffness_at_position: representable(
            "stiffness at the position",
            "N/m",
            modal_stiffness / s2,
            "the beam's properties",
        )?,
        mass_at_position: representable(
            "mass at the position",
            "kg",
            modal_mass / s2,
            "the beam's properties",
        )?,
    })
}

/// `[phi, phi', phi'', phi''']` of mode `mode` of a cantilever of `length`
/// (m) at `x` (m from the clamp, in [0, length]), normalised so that
/// `int_0^L phi^2 dx = L`; the derivatives in x, in 1/m, 1/m^2, 1/m^3.
pub fn cantilever_mode_shape_derivatives(length: f64, mode: u32, x: f64) -> Result<[f64; 4]> {
    let length = positive("length", length)?;
    let x = within("x", x, 0.0, length, false, "in [0, length]")?;
    let d = CantileverShape::new(mode)?.derivatives((x / length).min(1.0))?;
    let scaled = [
        d[0],
        d[1] / length,
        d[2] / (length * length),
        d[3] / (length * length * length),
    ];
    if scaled.iter().all(|v| v.is_finite()) {
        Ok(scaled)
    } else {
        Err(Error::Inconsistent(format!(
            "the derivatives of mode {mode} of a beam {length} m long overflow (they scale as 1/length^3): length is too small"
        )))
    }
}

/// Normalised mode shape `phi(x)` (`int_0^L phi^2 dx = L`) of mode `mode` of
/// a cantilever of `length` (m), at `x` (m from the clamp, in [0, length]).
pub fn cantilever_mode_shape(length: f64, mode: u32, x: f64) -> Result<f64> {
    Ok(cantilever_mode_shape_derivatives(length, mode, x)?[0])
}
