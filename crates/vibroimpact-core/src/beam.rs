//! A cantilever beam reduced to one degree of freedom by the Ritz method on
//! its free-vibration mode shapes.

use crate::error::{positive, within, Error, Result};

/// The root `b_i L` of the cantilever frequency equation
/// `cos(x) cosh(x) + 1 = 0`, for mode `i` >= 1.
///
/// Solved as `cos(x) + 1/cosh(x) = 0`, which is well conditioned for every
/// mode, by bisection on `[(i - 1) pi, i pi]` (one root lies in each).
pub fn cantilever_root(mode: u32) -> Result<f64> {
    if mode == 0 {
        return Err(Error::InvalidParameter {
            field: "mode",
            allowed: "a whole number >= 1",
            value: 0.0,
        });
    }
    let f = |x: f64| x.cos() + 1.0 / x.cosh();
    let pi = std::f64::consts::PI;
    let (mut lo, mut hi) = ((mode - 1) as f64 * pi, mode as f64 * pi);
    let f_lo = f(lo);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if (f(mid) > 0.0) == (f_lo > 0.0) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    Ok(0.5 * (lo + hi))
}

/// Mode shape `phi(x)` for root `beta_l = b L`, in the founding paper's
/// unnormalised form, at `xi = x / L`.
///
/// Written with `cosh - cos` and `sinh - sin` combined so that large
/// `sinh`/`cosh` terms of higher modes cancel without losing digits.
pub fn mode_shape_unnormalised(beta_l: f64, xi: f64) -> f64 {
    let (s, c) = beta_l.sin_cos();
    let sigma = (s + beta_l.sinh()) / (c + beta_l.cosh());
    let z = beta_l * xi;
    (z.sin() - z.sinh()) - sigma * (z.cos() - z.cosh())
}

/// `int_0^1 phi(xi)^2 d xi` by composite Simpson on 4000 intervals.
fn shape_norm(beta_l: f64) -> f64 {
    let n = 4000;
    let h = 1.0 / n as f64;
    let mut sum = 0.0;
    for i in 0..=n {
        let w = if i == 0 || i == n {
            1.0
        } else if i % 2 == 1 {
            4.0
        } else {
            2.0
        };
        let p = mode_shape_unnormalised(beta_l, i as f64 * h);
        sum += w * p * p;
    }
    sum * h / 3.0
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
    let beta_l = cantilever_root(mode)?;
    let scale = (1.0 / shape_norm(beta_l)).sqrt();
    let shape = scale * mode_shape_unnormalised(beta_l, position / length);
    if shape.abs() < 1e-9 {
        return Err(Error::Inconsistent(format!(
            "position {position} m is a node of mode {mode}: the mode does not move there"
        )));
    }
    let modal_stiffness = beta_l.powi(4) * e * i / length.powi(3);
    let modal_mass = rho * a * length;
    let s2 = shape * shape;
    Ok(BeamMode {
        mode,
        beta_l,
        angular_frequency: (modal_stiffness / modal_mass).sqrt(),
        modal_stiffness,
        modal_mass,
        position,
        shape_at_position: shape,
        stiffness_at_position: modal_stiffness / s2,
        mass_at_position: modal_mass / s2,
    })
}

/// Normalised mode shape `phi(x)` (`int_0^L phi^2 dx = L`) at `x` (m).
pub fn cantilever_mode_shape(length: f64, mode: u32, x: f64) -> Result<f64> {
    let length = positive("length", length)?;
    let x = within("x", x, 0.0, length, false, "in [0, length]")?;
    let beta_l = cantilever_root(mode)?;
    Ok(mode_shape_unnormalised(beta_l, x / length) / shape_norm(beta_l).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_match_the_tabulated_values() {
        for (mode, expected) in [(1, 1.875104), (2, 4.694091), (3, 7.854757), (4, 10.995541)] {
            let r = cantilever_root(mode).unwrap();
            assert!((r - expected).abs() < 2e-6, "mode {mode}: {r}");
            assert!((r.cos() * r.cosh() + 1.0).abs() < 1e-9 * r.cosh());
        }
    }

    #[test]
    fn first_mode_constants() {
        let b = cantilever_mode(1.0, 1.0, 1.0, 1.0, 1.0, 1, None).unwrap();
        assert!((b.modal_stiffness - 12.362361).abs() < 1e-5);
        assert!((b.shape_at_position.abs() - 2.0).abs() < 1e-9);
        assert!((b.stiffness_at_position - 3.0906).abs() < 1e-4);
        assert!((b.mass_at_position - 0.25).abs() < 1e-9);
    }
}
