//! A 0.2 system: a structure, loose masses (dampers) rattling against its
//! points, stops fixed to the base or carried by another point (pounding),
//! gravity and excitations; assembled into the plain data the kernel
//! integrates.
//!
//! Coordinates `x = (q, z)`: the structure's `q` (n) and the dampers'
//! displacements `z` (k), all relative to the base. Each wall of a pair is an
//! interaction with a gap `g = offset + h . x` (open while `g > 0`), as
//! Siconos writes `y = H q + b`; its contact force `lambda >= 0` acts along
//! `h^T`, so it accelerates the coordinates by `M^-1 h^T lambda`.
//! Gravity along -x and any base acceleration act on every mass as an
//! inertial load `-M r a(t)` (`r`: the influence vector, 1 for each damper).

mod build;
mod constraints;
mod energy;
mod gaps;
mod linear;
mod rates;
mod scales;
mod scratch;
mod spec;
mod state;

pub(crate) use gaps::{h_dot, same_row};
pub use linear::{HarmonicLoad, LinearParts};
pub(crate) use rates::{apart_damping, elastic};
pub use scratch::Scratch;
pub(crate) use scratch::{rotated, same_increment, same_instant, Cached, CachedParts, RESYNC};
pub use spec::{
    Collision, Damper, Excitation, Friction, FrictionSite, Load, PairLaw, Side, Stop, SystemSpec,
    MAX_PAIRS, MAX_POINTS,
};
pub use state::{initial_state, resumed_state};

use crate::kernel::compact::Compact;
use crate::model::contact::AnyLaw;
use crate::model::signals::Signal;

/// The law of one interaction, ready for the kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InteractionLaw {
    Compliant {
        law: AnyLaw,
        damping: f64,
    },
    Rigid {
        restitution: f64,
    },
    /// Coulomb friction along the row `h` (its rate the sliding velocity):
    /// the sliding force and the most the sides hold while stuck, N.
    Friction {
        kinetic_force: f64,
        static_force: f64,
    },
}

impl InteractionLaw {
    /// Whether the law's force depends on the approach rate latched at its
    /// contact's onset ([`AnyLaw::HysterHertz`]: `hertz-damped`,
    /// `hyster-hertz`), which a state (x, v) inside the contact does not hold.
    pub fn latches(&self) -> bool {
        matches!(
            self,
            Self::Compliant {
                law: AnyLaw::HysterHertz(_),
                ..
            }
        )
    }

    /// Whether this is a friction element (no wall: its row's rate is a
    /// sliding velocity).
    #[inline(always)]
    pub fn is_friction(&self) -> bool {
        matches!(self, Self::Friction { .. })
    }
}

/// One wall of a pair: a gap `offset + h . x` and its law.
#[derive(Debug, Clone, PartialEq)]
pub struct Interaction {
    /// Index into [`Assembly::pairs`].
    pub pair: usize,
    /// Over all coordinates `x` (dense, length `dim`).
    pub h: Vec<f64>,
    /// `sum |h_k|`: the gap's scale is at most `|offset| + h_norm max |x_k|`.
    pub h_norm: f64,
    pub offset: f64,
    /// `M^-1 h^T`: the acceleration per newton of contact force.
    pub push: Vec<f64>,
    /// `h M^-1 h^T`, 1/kg: the inverse of the effective mass at the gap.
    pub inverse_mass: f64,
    pub law: InteractionLaw,
    /// The coordinates where `h` or `push` is not zero, in order, where
    /// those are few in many (see [`SPARSE_FROM`]); empty where the
    /// products run over every coordinate.
    pub support: Vec<usize>,
}

/// The fewest coordinates whose interactions take their products over the
/// non-zero entries of their rows alone (a column of ten particles: each
/// pair's row touches two of eleven). Smaller systems take every entry, in
/// loops of a length known at compile time, as the fixed-size paths
/// ([`crate::kernel::compact`]) take them: the same bits.
pub const SPARSE_FROM: usize = 7;

/// A force excitation, ready for the kernel.
#[derive(Debug, Clone, PartialEq)]
struct ForceLoad {
    /// The point's row over `q`.
    row: Vec<f64>,
    /// `M^-1 row^T`.
    push: Vec<f64>,
    signal: Signal,
}

/// The system in the kernel's plain data.
#[derive(Debug, Clone, PartialEq)]
pub struct Assembly {
    /// Structure coordinates.
    pub n: usize,
    /// Dampers.
    pub k: usize,
    /// All coordinates, `n + k`.
    pub dim: usize,
    mass: Vec<f64>,
    stiffness: Vec<f64>,
    damping: Vec<f64>,
    /// `M^-1 K` and `M^-1 C` of the structure.
    minv_k: Vec<f64>,
    minv_c: Vec<f64>,
    damper_mass: Vec<f64>,
    /// Whether M, K and C are all diagonal (modal coordinates).
    diagonal: bool,
    /// `[M^-1 K, M^-1 C, C, r]` of each coordinate (used when diagonal).
    diagonals: Vec<[f64; 4]>,
    /// `r`, and `M r` (for the work of base loads).
    influence: Vec<f64>,
    mass_influence: Vec<f64>,
    gravity: f64,
    forces: Vec<ForceLoad>,
    base: Vec<Signal>,
    /// Crate-private: [`Assembly::compact`] holds a copy made once.
    pub(crate) interactions: Vec<Interaction>,
    /// Whether an interaction's `h` is the previous one's negated (the two
    /// walls of a damper): its products are then that one's negated, to the
    /// bit (round-to-nearest is symmetric).
    mirrors_previous: Vec<bool>,
    /// The structure's longest natural period (s; infinite without a
    /// spring): the time scale of the run's resolution.
    pub longest_period: f64,
    /// The fastest time scale of the system and its excitations (s; a tenth
    /// of the shortest natural or forcing period): how long an adaptive step
    /// may be while a pair sticks, whose release nothing else foretells.
    pub sticking_step: f64,
    /// For each rigid wall, the static force of a friction element on the
    /// same row (N; 0 for none): sticking there, the wall and the friction
    /// hold the pair together, so it lets go only where the wall would pull
    /// by more than that.
    pub(crate) friction_hold: Vec<f64>,
    /// The total mass times the square of the largest acceleration acting
    /// (gravity, base, force), kg m^2/s^4, and the system's time scale (its
    /// shortest period or signal's, infinite for none), s: see
    /// [`Assembly::energy_floor`].
    floor_mass_acceleration: f64,
    time_scale: f64,
    /// The least scale of a rigid pair's gap, m: a thousandth of the
    /// smallest free distance at rest of the system's pairs, or where every
    /// pair touches at rest, of the length the largest acceleration moves
    /// the system over its time scale (0 where it has neither). Without a
    /// scale, a body resting on a stop at displacement 0 (a ball on a
    /// shaken table, a mass on a spring pressed by gravity onto a stop at
    /// its unstretched length) landed from the round-off band at 1e-9 m/s,
    /// a flight no landing test took for rest: the exact flow recorded
    /// those phantom impacts (at restitution 1, twenty million in 1e-4 s).
    /// A rigid pair touching at rest at displacement
    /// 0 has a gap scale, so a round-off, of 0 without it: the round-off of
    /// the motion itself (bodies falling together under gravity, 4e-15 m/s^2
    /// apart through the exact flow's modal transform) read as impacts at
    /// 3e-82 m/s, a sequence no run sums (55 of 100 exact-flow columns
    /// stopped as chattering at 1e-7 s). Not for compliant pairs: a contact
    /// begun later by the band latches a smaller approach rate, and its
    /// damping, which goes as its inverse, made a settling column creep.
    gap_floor: f64,
    /// See [`Assembly::finest_signal_interval`] (found once, when assembled).
    finest_signal: Option<(f64, &'static str)>,
    /// Pair names, as the contact table gives them ("damper 0", "stop 1").
    pub pairs: Vec<String>,
    /// The rows (over the structure coordinates, `n` each) of the points
    /// the reductions follow, then of the moments (see [`SystemSpec::points`]
    /// and [`SystemSpec::moments`]).
    pub point_rows: Vec<f64>,
    /// The system in fixed-size arrays, where it is small and modal (RK4's
    /// fast path, [`crate::kernel::compact`]).
    pub(crate) compact: Option<Compact>,
}

/// What [`Compact::of`] reads of a modal system.
pub(crate) struct CompactParts<'a> {
    pub diagonals: &'a [[f64; 4]],
    /// Each force's signal, `M^-1 row^T` and row.
    pub forces: Vec<(&'a Signal, &'a [f64], &'a [f64])>,
    pub has_base: bool,
    pub gravity: f64,
    pub mirrors: &'a [bool],
}

/// What [`Assembly::rates_with`] reads of the system, cut to the sizes `n`
/// (structure coordinates) and `k` (dampers).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RatesParts<'a> {
    n: usize,
    k: usize,
    /// `[M^-1 K, M^-1 C, C, r]` of each structure coordinate, for modal ones.
    diagonals: Option<&'a [[f64; 4]]>,
    /// The first force, added in the pass over modal coordinates: its
    /// signal, push and row.
    first: Option<(&'a Signal, &'a [f64], &'a [f64])>,
    /// How many forces that pass adds (0 or 1), and whether there are more.
    fused: usize,
    unfused: bool,
    /// Whether there are base signals.
    base: bool,
    interactions: &'a [Interaction],
    gravity: f64,
}

/// Accumulators after the coordinates and velocities in the state vector:
/// the viscous loss, the input work, then each interaction's contact loss
/// (so that overlapping contacts of different pairs keep their own).
pub const VISCOUS: usize = 0;
pub const INPUT: usize = 1;
pub const CONTACT: usize = 2;

/// What one interaction is doing.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Mode {
    Open,
    /// A compliant contact, with the indentation rate latched at its onset.
    Compliant {
        approach_rate: f64,
        /// Whether its forces (the law's and the contact damper's) act only
        /// where the pair is indented: fixed stepping's rule (0.1's, whose
        /// force was a function of the state), where the mode is held
        /// through a step that may leave or enter the contact. Else (events)
        /// the mode is the contact, and the damper acts through it.
        indented_only: bool,
    },
    /// A rigid pair moving together after a chattering sequence: the gap
    /// and its rate stay zero, held by a constraint force.
    Sticking,
    /// A friction element sliding along `direction` (+1 or -1, the sign of
    /// its row's rate), under the kinetic force against it.
    Sliding {
        direction: f64,
    },
    /// A friction element stuck: its row's rate held at zero by a
    /// constraint force within the static force, at `h . x + offset = 0`;
    /// `shadowed` while a sticking rigid pair holds the same row (that
    /// pair's constraint then carries the force, one constraint per row).
    Stuck {
        offset: f64,
        shadowed: bool,
    },
}

impl Mode {
    /// Whether an interaction in this mode may switch within a step whose
    /// gap and rate are `start` and `end` at its ends: a cheap test that
    /// passes every switch the event search could find (and some it will
    /// not), so that most steps skip the search.
    #[inline(always)]
    pub fn may_cross(&self, start: (f64, f64), end: (f64, f64)) -> bool {
        let ((_, r0), (g1, r1)) = (start, end);
        match self {
            Mode::Open => g1 < 0.0 || (r0 < 0.0 && r1 > 0.0),
            Mode::Compliant { .. } => g1 > 0.0 || (r0 > 0.0 && r1 < 0.0),
            Mode::Sticking | Mode::Stuck { .. } => true,
            // Sliding ends where the sliding velocity reaches zero, at a step's
            // end or within it (`locate::sliding_crossing` looks).
            Mode::Sliding { .. } => true,
        }
    }

    /// Whether this is a constraint (a rigid pair sticking or a friction
    /// element stuck), held by a force the rates solve for.
    #[inline(always)]
    pub fn is_held(&self) -> bool {
        matches!(self, Mode::Sticking | Mode::Stuck { .. })
    }
}
