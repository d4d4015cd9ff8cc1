//! Compliant contact laws.
//!
//! A law gives the force `F(delta, delta', delta'_minus)` pushing the bodies
//! apart for an indentation `delta > 0`. The force never pulls the bodies
//! together: it is clamped at zero. The contact damper `c1` is not part of the
//! law; it is a linear damper on the relative velocity that acts only while in
//! contact, exactly as in the founding paper's equations of motion.

use crate::error::{non_negative, positive, within, Error, Result};

/// A contact law, generic so that the integration kernels monomorphise over it.
pub trait ContactLaw: Copy + Send + Sync {
    /// Force in N (>= 0) at indentation `indentation` > 0 (m), indentation
    /// rate `rate` (m/s, > 0 while approaching) and the rate latched at the
    /// onset of this contact `approach_rate` (m/s).
    fn force(&self, indentation: f64, rate: f64, approach_rate: f64) -> f64;
    /// The conservative (elastic) part of the force, N.
    fn elastic_force(&self, indentation: f64) -> f64;
    /// Elastic energy stored at `indentation`, J.
    fn potential(&self, indentation: f64) -> f64;
}

/// Hertz: `F = k delta^(3/2)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hertz {
    /// K_hz, N/m^1.5.
    pub stiffness: f64,
}

impl ContactLaw for Hertz {
    #[inline(always)]
    fn force(&self, indentation: f64, _rate: f64, _approach_rate: f64) -> f64 {
        self.elastic_force(indentation)
    }
    #[inline(always)]
    fn elastic_force(&self, indentation: f64) -> f64 {
        self.stiffness * indentation * indentation.sqrt()
    }
    fn potential(&self, indentation: f64) -> f64 {
        0.4 * self.stiffness * indentation * indentation * indentation.sqrt()
    }
}

/// Lankarani-Nikravesh ("Hyster-Hertz"):
/// `F = k delta^(3/2) (1 + (3/4)(1 - e^2) delta' / delta'_minus)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HysterHertz {
    /// K_hz, N/m^1.5.
    pub stiffness: f64,
    /// `(3/4)(1 - e^2)`, precomputed.
    pub hysteresis: f64,
}

impl HysterHertz {
    pub fn new(stiffness: f64, restitution: f64) -> Self {
        Self {
            stiffness,
            hysteresis: 0.75 * (1.0 - restitution * restitution),
        }
    }
}

/// Below this approach rate (m/s) a contact is a graze and the damping term,
/// which divides by the approach rate, is left out.
const GRAZING_RATE: f64 = 1e-12;

impl ContactLaw for HysterHertz {
    #[inline(always)]
    fn force(&self, indentation: f64, rate: f64, approach_rate: f64) -> f64 {
        let elastic = self.elastic_force(indentation);
        if approach_rate > GRAZING_RATE {
            (elastic * (1.0 + self.hysteresis * rate / approach_rate)).max(0.0)
        } else {
            elastic
        }
    }
    #[inline(always)]
    fn elastic_force(&self, indentation: f64) -> f64 {
        self.stiffness * indentation * indentation.sqrt()
    }
    fn potential(&self, indentation: f64) -> f64 {
        0.4 * self.stiffness * indentation * indentation * indentation.sqrt()
    }
}

/// Linear spring: `F = k delta`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Linear {
    /// k1, N/m.
    pub stiffness: f64,
}

impl ContactLaw for Linear {
    #[inline(always)]
    fn force(&self, indentation: f64, _rate: f64, _approach_rate: f64) -> f64 {
        self.stiffness * indentation
    }
    #[inline(always)]
    fn elastic_force(&self, indentation: f64) -> f64 {
        self.stiffness * indentation
    }
    fn potential(&self, indentation: f64) -> f64 {
        0.5 * self.stiffness * indentation * indentation
    }
}

/// The named contact laws.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LawKind {
    Hertz,
    HysterHertz,
    Linear,
}

impl LawKind {
    pub const NAMES: &'static str = "\"hertz\", \"hyster-hertz\", \"linear\"";

    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "hertz" => Ok(Self::Hertz),
            "hyster-hertz" => Ok(Self::HysterHertz),
            "linear" => Ok(Self::Linear),
            _ => Err(Error::UnknownChoice {
                field: "law",
                allowed: Self::NAMES,
                value: name.to_string(),
            }),
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Hertz => "hertz",
            Self::HysterHertz => "hyster-hertz",
            Self::Linear => "linear",
        }
    }
}

/// A validated contact description: law, its stiffness, restitution (used by
/// "hyster-hertz" only) and the contact damper `c1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Contact {
    pub law: LawKind,
    /// K_hz in N/m^1.5 for the Hertz laws, k1 in N/m for "linear".
    pub stiffness: f64,
    /// e in (0, 1]; 1 for the laws that do not use it.
    pub restitution: f64,
    /// c1, N s/m, acting on the relative velocity only while in contact.
    pub damping: f64,
}

impl Contact {
    /// `restitution` must be given for "hyster-hertz" and only for it.
    pub fn new(
        law: LawKind,
        stiffness: f64,
        restitution: Option<f64>,
        damping: f64,
    ) -> Result<Self> {
        let stiffness = positive("stiffness", stiffness)?;
        let damping = non_negative("damping", damping)?;
        let restitution = match (law, restitution) {
            (LawKind::HysterHertz, Some(e)) => {
                within("restitution", e, 0.0, 1.0, true, "in (0, 1]")?
            }
            (LawKind::HysterHertz, None) => {
                return Err(Error::Inconsistent(
                    "restitution is required for law \"hyster-hertz\" (a number in (0, 1])".into(),
                ))
            }
            (_, Some(_)) => {
                return Err(Error::Inconsistent(format!(
                    "restitution applies only to law \"hyster-hertz\", not {:?}",
                    law.name()
                )))
            }
            (_, None) => 1.0,
        };
        Ok(Self {
            law,
            stiffness,
            restitution,
            damping,
        })
    }

    /// The law's force (N, clamped at zero), without the contact damper.
    pub fn law_force(&self, indentation: f64, rate: f64, approach_rate: f64) -> f64 {
        if indentation <= 0.0 {
            return 0.0;
        }
        match self.law {
            LawKind::Hertz => Hertz {
                stiffness: self.stiffness,
            }
            .force(indentation, rate, approach_rate),
            LawKind::HysterHertz => HysterHertz::new(self.stiffness, self.restitution).force(
                indentation,
                rate,
                approach_rate,
            ),
            LawKind::Linear => Linear {
                stiffness: self.stiffness,
            }
            .force(indentation, rate, approach_rate),
        }
    }
}
