//! What a system is made of, as the scenario gives it: the structure, its
//! dampers and stops with their laws, gravity and the excitations.

use crate::error::{within, Error, Result};
use crate::model::contact::Contact;
use crate::model::signals::Signal;
use crate::model::structure::Structure;

/// What happens when a gap closes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PairLaw {
    /// A compliant contact law with its contact damper.
    Compliant(Contact),
    /// An instantaneous impact with Newton's restitution `e` in [0, 1]:
    /// the relative normal speed after is `e` times the one before.
    Rigid { restitution: f64 },
}

impl PairLaw {
    /// Newton's rigid law, `restitution` in [0, 1].
    pub fn rigid(restitution: f64) -> Result<Self> {
        Ok(Self::Rigid {
            restitution: within("restitution", restitution, 0.0, 1.0, false, "in [0, 1]")?,
        })
    }
}

/// A loose mass rattling against a point of the structure, between a lower
/// and an upper wall: free while `-lower_clearance < z - h.q < upper_clearance`.
/// An infinite clearance is a side with no wall (a mass on a floor, or one
/// wall of a damper left out to locate the other's grazing); one side at
/// least has a wall.
#[derive(Debug, Clone, PartialEq)]
pub struct Damper {
    /// kg (> 0).
    pub mass: f64,
    /// The point (a coordinate index, or m along a cantilever).
    pub at: f64,
    /// m (>= 0, or infinite: no lower wall).
    pub lower_clearance: f64,
    /// m (>= 0, or infinite: no upper wall).
    pub upper_clearance: f64,
    pub law: PairLaw,
}

/// Which way a stop limits its point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    /// The point stays at or below `+gap`.
    Upper,
    /// The point stays at or above `-gap`.
    Lower,
}

impl Side {
    pub const NAMES: &'static str = "\"upper\", \"lower\"";
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "upper" => Ok(Self::Upper),
            "lower" => Ok(Self::Lower),
            _ => Err(Error::UnknownChoice {
                field: "side",
                allowed: Self::NAMES,
                value: name.to_string(),
            }),
        }
    }
}

/// A stop that a point of the structure hits: fixed to the base, or carried
/// by another point of the structure (`against`: pounding between the two).
#[derive(Debug, Clone, PartialEq)]
pub struct Stop {
    pub at: f64,
    pub side: Side,
    /// m (>= 0): how far `at` may move past the stop's position (the base's,
    /// or `against`'s displacement).
    pub gap: f64,
    pub law: PairLaw,
    /// The point carrying the stop; `None`: the base.
    pub against: Option<f64>,
}

/// Where an excitation acts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Load {
    /// A force (N) at a point of the structure.
    Force { at: f64 },
    /// A base (support) acceleration (m/s^2): every coordinate is relative
    /// to the base, and stops move with it.
    Base,
}

/// An excitation: a signal applied as a force or a base acceleration.
#[derive(Debug, Clone, PartialEq)]
pub struct Excitation {
    pub load: Load,
    pub signal: Signal,
}

/// Two loose masses that strike each other (a multi-unit or particle-column
/// damper): damper `dampers[0]` below damper `dampers[1]` along the axis,
/// touching when the displacement of the first minus that of the second
/// reaches `gap`.
#[derive(Debug, Clone, PartialEq)]
pub struct Collision {
    /// Indices into [`SystemSpec::dampers`], the lower first; distinct.
    pub dampers: [usize; 2],
    /// m (>= 0): their free distance at rest.
    pub gap: f64,
    pub law: PairLaw,
}

/// Where a dry-friction element acts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FrictionSite {
    /// Between a loose mass (an index into [`SystemSpec::dampers`]) and its
    /// carrier point (a horizontal damper sliding on its cavity's floor).
    Damper(usize),
    /// Between a point of the structure (as a stop's `at`) and another
    /// (`against`), or the base (`None`): a Den Hartog dry-friction damper.
    Points { at: f64, against: Option<f64> },
}

/// Coulomb friction along the axis: while the two sides slide, a force
/// `coefficient * normal_force` opposes their relative velocity; they stick
/// when it reaches zero and the force holding them is within
/// `static_coefficient * normal_force`, and slip again when it is not.
#[derive(Debug, Clone, PartialEq)]
pub struct Friction {
    pub site: FrictionSite,
    /// Kinetic coefficient (>= 0).
    pub coefficient: f64,
    /// Static coefficient (>= `coefficient`).
    pub static_coefficient: f64,
    /// N (>= 0): the weight of a horizontal damper, or a preload.
    pub normal_force: f64,
}

/// Everything a run needs to know about the system.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemSpec {
    pub structure: Structure,
    pub dampers: Vec<Damper>,
    pub stops: Vec<Stop>,
    /// Loose masses striking each other, after the stops' pairs.
    pub collisions: Vec<Collision>,
    /// Dry-friction elements, after the collisions' pairs.
    pub frictions: Vec<Friction>,
    /// m/s^2 (>= 0), along -x.
    pub gravity: f64,
    pub excitations: Vec<Excitation>,
    /// Points of the structure whose displacement the reductions follow
    /// beside its coordinates (each as a damper's `at`: a coordinate index,
    /// or m from a beam's clamp); with `moments`, at most [`MAX_POINTS`].
    pub points: Vec<f64>,
    /// Positions along a cantilever (m from the clamp) whose bending moment
    /// the reductions follow after the points.
    pub moments: Vec<f64>,
}

impl SystemSpec {
    /// `structure` carrying `dampers`, with no stop, collision, friction,
    /// gravity, excitation or point followed: the other parts set by field
    /// (`SystemSpec { gravity: 9.81, ..SystemSpec::of(structure, dampers) }`).
    pub fn of(structure: Structure, dampers: Vec<Damper>) -> Self {
        Self {
            structure,
            dampers,
            stops: vec![],
            collisions: vec![],
            frictions: vec![],
            gravity: 0.0,
            excitations: vec![],
            points: vec![],
            moments: vec![],
        }
    }

    /// A column of loose masses (`masses`, kg) at point `at` of `structure`
    /// (see [`Damper::at`]) under gravity (9.81 m/s^2): the first `floor`
    /// (m) above its lower wall, the last `ceiling` (m) below its upper one,
    /// neighbours colliding across `gap` (m), every pair with `law`. A
    /// particle column in a vibrating cavity; the other parts set by field.
    pub fn column(
        structure: Structure,
        at: f64,
        masses: &[f64],
        [floor, gap, ceiling]: [f64; 3],
        law: PairLaw,
    ) -> Self {
        let count = masses.len();
        let dampers = masses
            .iter()
            .enumerate()
            .map(|(j, &mass)| Damper {
                mass,
                at,
                lower_clearance: if j == 0 { floor } else { f64::INFINITY },
                upper_clearance: if j + 1 == count {
                    ceiling
                } else {
                    f64::INFINITY
                },
                law,
            })
            .collect();
        let collisions = (1..count)
            .map(|j| Collision {
                dampers: [j - 1, j],
                gap,
                law,
            })
            .collect();
        Self {
            collisions,
            gravity: 9.81,
            ..Self::of(structure, dampers)
        }
    }
}

/// The most points a run may follow (each is a row of the structure's
/// coordinates, a peak and a mean square).
pub const MAX_POINTS: usize = 10_000;

/// The most pairs (dampers, stops and collisions) a system may have: simultaneous
/// impacts and sticking solve a system over every interaction (its matrix
/// grows as their square: 70,000 stops asked for 39 GB).
pub const MAX_PAIRS: usize = 1_000;
