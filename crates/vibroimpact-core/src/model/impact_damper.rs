//! The impact damper: a main mass on a spring and damper carrying an
//! enclosure in which a loose impact mass moves with a clearance on each side.

use crate::error::{finite, non_negative, positive, Result};

/// Parameters of the two-mass impact damper (SI units).
///
/// The main structure (one mode: `main_mass` M, `stiffness` K, `damping` C,
/// displacement `w`) carries an enclosure; the impact mass `impact_mass` m
/// (displacement `y`) moves freely while `|y - w| < clearance`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImpactDamper {
    /// M, kg (> 0).
    pub main_mass: f64,
    /// K, N/m (>= 0).
    pub stiffness: f64,
    /// C, N s/m (>= 0).
    pub damping: f64,
    /// m, kg (> 0).
    pub impact_mass: f64,
    /// d, m (>= 0), on each side of the impact mass.
    pub clearance: f64,
}

impl ImpactDamper {
    /// Validated constructor: every field must be finite, masses positive,
    /// stiffness, damping and clearance non-negative.
    pub fn new(
        main_mass: f64,
        stiffness: f64,
        damping: f64,
        impact_mass: f64,
        clearance: f64,
    ) -> Result<Self> {
        Ok(Self {
            main_mass: positive("main_mass", main_mass)?,
            stiffness: non_negative("stiffness", stiffness)?,
            damping: non_negative("damping", damping)?,
            impact_mass: positive("impact_mass", impact_mass)?,
            clearance: non_negative("clearance", clearance)?,
        })
    }

    /// Effective mass of the colliding pair, `m M / (m + M)`, kg.
    pub fn effective_mass(&self) -> f64 {
        self.main_mass * self.impact_mass / (self.main_mass + self.impact_mass)
    }
}

/// Displacements (m) and velocities (m/s) of both masses.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct State {
    /// w, m.
    pub main_displacement: f64,
    /// w', m/s.
    pub main_velocity: f64,
    /// y, m.
    pub impact_displacement: f64,
    /// y', m/s.
    pub impact_velocity: f64,
}

impl State {
    /// Validated constructor: all four values must be finite.
    pub fn new(
        main_displacement: f64,
        main_velocity: f64,
        impact_displacement: f64,
        impact_velocity: f64,
    ) -> Result<Self> {
        Ok(Self {
            main_displacement: finite("main_displacement", main_displacement)?,
            main_velocity: finite("main_velocity", main_velocity)?,
            impact_displacement: finite("impact_displacement", impact_displacement)?,
            impact_velocity: finite("impact_velocity", impact_velocity)?,
        })
    }

    /// Relative displacement `y - w`, m.
    #[inline(always)]
    pub fn relative_displacement(&self) -> f64 {
        self.impact_displacement - self.main_displacement
    }

    /// Relative velocity `y' - w'`, m/s.
    #[inline(always)]
    pub fn relative_velocity(&self) -> f64 {
        self.impact_velocity - self.main_velocity
    }

    #[inline(always)]
    pub(crate) fn is_finite(&self) -> bool {
        (self.main_displacement
            + self.main_velocity
            + self.impact_displacement
            + self.impact_velocity)
            .is_finite()
    }
}
