//! Hertz contact stiffness from materials and geometry.

use crate::error::{positive, within, Result};
use crate::model::closed_forms::representable;

/// Elastic constants of one body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus, Pa.
    pub youngs_modulus: f64,
    /// Poisson's ratio, in (-1, 0.5].
    pub poisson_ratio: f64,
}

impl Material {
    /// A material of Young's modulus `youngs_modulus` > 0 (Pa) and Poisson's
    /// ratio `poisson_ratio` in (-1, 0.5].
    pub fn new(youngs_modulus: f64, poisson_ratio: f64) -> Result<Self> {
        Self {
            youngs_modulus,
            poisson_ratio,
        }
        .checked("youngs_modulus", "poisson_ratio")
    }

    /// The material if its fields (public, so perhaps set directly) are
    /// valid, naming them `youngs` and `poisson` in an error.
    fn checked(self, youngs: &'static str, poisson: &'static str) -> Result<Self> {
        Ok(Self {
            youngs_modulus: positive(youngs, self.youngs_modulus)?,
            poisson_ratio: within(poisson, self.poisson_ratio, -1.0, 0.5, true, "in (-1, 0.5]")?,
        })
    }

    fn compliance(&self) -> f64 {
        (1.0 - self.poisson_ratio * self.poisson_ratio) / self.youngs_modulus
    }
}

/// Contact modulus `E*`: `1/E* = (1 - nu1^2)/E1 + (1 - nu2^2)/E2`, Pa; an
/// error names the second body's fields `other_youngs_modulus` and
/// `other_poisson_ratio`.
pub fn contact_modulus(a: &Material, b: &Material) -> Result<f64> {
    let a = a.checked("youngs_modulus", "poisson_ratio")?;
    let b = b.checked("other_youngs_modulus", "other_poisson_ratio")?;
    Ok(1.0 / (a.compliance() + b.compliance()))
}

/// Hertz stiffness `K_hz = (4/3) E* sqrt(R)` in N/m^1.5 of a sphere of radius
/// `radius` (m) on a flat (`other_radius` None) or on a second sphere of radius
/// `other_radius` (m), with `R = r1 r2 / (r1 + r2)`. The second body's fields
/// are named `other_...` in an error.
pub fn hertz_stiffness(
    radius: f64,
    sphere: &Material,
    other: &Material,
    other_radius: Option<f64>,
) -> Result<f64> {
    let modulus = contact_modulus(sphere, other)?;
    let r1 = positive("radius", radius)?;
    let r = match other_radius {
        Some(r2) => {
            let r2 = positive("other_radius", r2)?;
            r1 * r2 / (r1 + r2)
        }
        None => r1,
    };
    representable(
        "Hertz stiffness",
        "N/m^1.5",
        4.0 / 3.0 * modulus * r.sqrt(),
        "the moduli and radii",
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_papers_form() {
        crate::testing::timeout(60, || {
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
        });
    }
}

#[cfg(test)]
mod input_tests {
    use super::*;
    use crate::model::contact::tests::field;

    #[test]
    fn every_argument_is_checked_and_named() {
        crate::testing::timeout(60, || {
            let steel = Material::new(210e9, 0.3).unwrap();
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                assert_eq!(field(Material::new(bad, 0.3)), "youngs_modulus");
                assert_eq!(field(Material::new(1.0, bad)), "poisson_ratio");
                assert_eq!(field(hertz_stiffness(bad, &steel, &steel, None)), "radius");
                let r = Some(bad);
                assert_eq!(
                    field(hertz_stiffness(1.0, &steel, &steel, r)),
                    "other_radius"
                );
                // Fields set directly are checked too, the second body's as other_...
                let set = Material {
                    youngs_modulus: bad,
                    poisson_ratio: 0.3,
                };
                assert_eq!(field(contact_modulus(&set, &steel)), "youngs_modulus");
                assert_eq!(field(contact_modulus(&steel, &set)), "other_youngs_modulus");
                let set = Material {
                    youngs_modulus: 1.0,
                    poisson_ratio: bad,
                };
                assert_eq!(
                    field(hertz_stiffness(1.0, &steel, &set, None)),
                    "other_poisson_ratio"
                );
            }
            // 4/3 E* sqrt(R) beyond floating point is an error, not inf.
            let stiff = Material::new(1e308, 0.0).unwrap();
            let err = hertz_stiffness(1e10, &stiff, &stiff, None).unwrap_err();
            assert!(
                err.to_string().contains("out of floating-point range"),
                "{err}"
            );
        });
    }
}
