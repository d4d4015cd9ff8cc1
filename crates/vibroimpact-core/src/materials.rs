//! Hertz contact stiffness from materials and geometry.

use crate::error::{positive, within, Result};

/// Elastic constants of one body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus, Pa.
    pub youngs_modulus: f64,
    /// Poisson's ratio, in [0, 0.5).
    pub poisson_ratio: f64,
}

impl Material {
    pub fn new(youngs_modulus: f64, poisson_ratio: f64) -> Result<Self> {
        Ok(Self {
            youngs_modulus: positive("youngs_modulus", youngs_modulus)?,
            poisson_ratio: within(
                "poisson_ratio",
                poisson_ratio,
                -1.0,
                0.5,
                true,
                "in (-1, 0.5]",
            )?,
        })
    }

    fn compliance(&self) -> f64 {
        (1.0 - self.poisson_ratio * self.poisson_ratio) / self.youngs_modulus
    }
}

/// Contact modulus `E*`: `1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`, Pa.
pub fn contact_modulus(a: &Material, b: &Material) -> f64 {
    1.0 / (a.compliance() + b.compliance())
}

/// Hertz stiffness `K_hz = (4/3) E* sqrt(R)` in N/m^1.5 of a sphere of radius
/// `radius` (m) on a flat (`other_radius` None) or on a second sphere of radius
/// `other_radius` (m), with `R = r1 r2 / (r1 + r2)`.
pub fn hertz_stiffness(
    radius: f64,
    sphere: &Material,
    other: &Material,
    other_radius: Option<f64>,
) -> Result<f64> {
    let r1 = positive("radius", radius)?;
    let r = match other_radius {
        Some(r2) => {
            let r2 = positive("other_radius", r2)?;
            r1 * r2 / (r1 + r2)
        }
        None => r1,
    };
    Ok(4.0 / 3.0 * contact_modulus(sphere, other) * r.sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_papers_form() {
        // (4 / (3 pi)) sqrt(r) / ((1 - nu1^2)/(pi E1) + (1 - nu2^2)/(pi E2)).
        let steel = Material::new(210e9, 0.3).unwrap();
        let alu = Material::new(70e9, 0.33).unwrap();
        let r: f64 = 0.01;
        let pi = std::f64::consts::PI;
        let paper = 4.0 / (3.0 * pi) * r.sqrt()
            / ((1.0 - 0.09) / (pi * 210e9) + (1.0 - 0.33 * 0.33) / (pi * 70e9));
        let ours = hertz_stiffness(r, &steel, &alu, None).unwrap();
        assert!((ours / paper - 1.0).abs() < 1e-14);
        // Two equal spheres act like one sphere of half the radius on a flat.
        let two = hertz_stiffness(r, &steel, &steel, Some(r)).unwrap();
        let half = hertz_stiffness(r / 2.0, &steel, &steel, None).unwrap();
        assert!((two / half - 1.0).abs() < 1e-14);
    }
}
