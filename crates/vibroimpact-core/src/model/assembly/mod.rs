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

use crate::error::{finite, non_negative, positive, within, Error, Result};
use crate::kernel::compact::Compact;
use crate::kernel::sized::by_size;
use crate::model::contact::{AnyLaw, Contact, ContactLaw};
use crate::model::signals::{Harmonic, Signal};
use crate::model::structure::Structure;
use crate::numerics::linalg;
use crate::numerics::series::{sin_cos, sin_cos_by_quadrant};

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
#[derive(Debug, Clone, PartialEq)]
pub struct Damper {
    /// kg (> 0).
    pub mass: f64,
    /// The point (a coordinate index, or m along a cantilever).
    pub at: f64,
    /// m (>= 0).
    pub lower_clearance: f64,
    /// m (>= 0).
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

/// Everything a run needs to know about the system.
#[derive(Debug, Clone, PartialEq)]
pub struct SystemSpec {
    pub structure: Structure,
    pub dampers: Vec<Damper>,
    pub stops: Vec<Stop>,
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

/// The most points a run may follow (each is a row of the structure's
/// coordinates, a peak and a mean square).
pub const MAX_POINTS: usize = 10_000;

/// The most pairs (dampers and stops) a system may have: simultaneous
/// impacts and sticking solve a system over every interaction (its matrix
/// grows as their square: 70,000 stops asked for 39 GB).
pub const MAX_PAIRS: usize = 1_000;

/// The law of one interaction, ready for the kernel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum InteractionLaw {
    Compliant { law: AnyLaw, damping: f64 },
    Rigid { restitution: f64 },
}

/// One wall of a pair: a gap `offset + h . x` and its law.
#[derive(Debug, Clone, PartialEq)]
pub struct Interaction {
    /// Index into [`Assembly::pairs`].
    pub pair: usize,
    /// Over all coordinates `x` (dense, length `dim`).
    pub h: Vec<f64>,
    pub offset: f64,
    /// `M^-1 h^T`: the acceleration per newton of contact force.
    pub push: Vec<f64>,
    /// `h M^-1 h^T`, 1/kg: the inverse of the effective mass at the gap.
    pub inverse_mass: f64,
    pub law: InteractionLaw,
}

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
    /// The total mass times the square of the largest acceleration acting
    /// (gravity, base, force), kg m^2/s^4, and the system's time scale (its
    /// shortest period or signal's, infinite for none), s: see
    /// [`Assembly::energy_floor`].
    floor_mass_acceleration: f64,
    time_scale: f64,
    /// Pair names, as the contact table gives them ("damper 0", "stop 1").
    pub pairs: Vec<String>,
    /// The rows (over the structure coordinates, `n` each) of the points
    /// the reductions follow, then of the moments (see [`SystemSpec::points`]
    /// and [`SystemSpec::moments`]).
    pub point_rows: Vec<f64>,
    /// The system in fixed-size arrays, where it is small and modal (RK4's
    /// fast path, [`crate::kernel::compact`]).
    pub(crate) compact: Option<Box<Compact>>,
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
    },
    /// A rigid pair moving together after a chattering sequence: the gap
    /// and its rate stay zero, held by a constraint force.
    Sticking,
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
            Mode::Sticking => true,
        }
    }
}

impl Assembly {
    /// Assemble and check a system. Errors name the input (`damper 1 at`).
    pub fn new(spec: &SystemSpec) -> Result<Self> {
        let s = &spec.structure;
        let (n, k) = (s.dofs(), spec.dampers.len());
        let dim = n + k;
        let l = linalg::cholesky(s.mass(), n).expect("a structure's mass is positive definite");
        let minv = linalg::inverse_from_cholesky(&l, n);
        let product = |a: &[f64]| {
            let mut out = vec![0.0; n * n];
            for i in 0..n {
                for j in 0..n {
                    out[i * n + j] = (0..n).map(|p| minv[i * n + p] * a[p * n + j]).sum();
                }
            }
            out
        };
        let minv_k = product(s.stiffness());
        let minv_c = product(s.damping());
        let diagonals = (0..n)
            .map(|i| {
                [
                    minv_k[i * n + i],
                    minv_c[i * n + i],
                    s.damping()[i * n + i],
                    s.influence()[i],
                ]
            })
            .collect();
        let mut mass_influence = vec![0.0; n];
        linalg::multiply(s.mass(), s.influence(), &mut mass_influence);
        let gravity = non_negative("gravity", spec.gravity)?;

        let mut damper_mass = Vec::with_capacity(k);
        let mut interactions = Vec::new();
        let mut pairs = Vec::new();
        let full_push = |h: &[f64]| {
            let mut push = vec![0.0; dim];
            linalg::multiply(&minv, &h[..n], &mut push[..n]);
            for j in 0..k {
                push[n + j] = h[n + j] / spec.dampers[j].mass;
            }
            push
        };
        let pairs_asked = spec.dampers.len() + spec.stops.len();
        if pairs_asked > MAX_PAIRS {
            return Err(Error::Inconsistent(format!(
                "[[damper]], [[stop]]: at most {MAX_PAIRS} pairs in all, got {pairs_asked}"
            )));
        }
        for (j, d) in spec.dampers.iter().enumerate() {
            let name = format!("damper {j}");
            damper_mass.push(positive_named(&name, "mass", d.mass)?);
            let lower = non_negative_named(&name, "lower_clearance", d.lower_clearance)?;
            let upper = non_negative_named(&name, "upper_clearance", d.upper_clearance)?;
            let point = s.point(&format!("{name} at"), d.at)?;
            let law = interaction_law(&name, &d.law)?;
            let pair = pairs.len();
            pairs.push(name);
            // Relative displacement u = z_j - point . q; upper wall: g = upper - u,
            // lower wall: g = lower + u.
            for (sign, offset) in [(-1.0, upper), (1.0, lower)] {
                let mut h = vec![0.0; dim];
                for i in 0..n {
                    h[i] = -sign * point[i];
                }
                h[n + j] = sign;
                interactions.push(Interaction {
                    pair,
                    push: vec![],
                    inverse_mass: 0.0,
                    h,
                    offset,
                    law,
                });
            }
        }
        for (j, stop) in spec.stops.iter().enumerate() {
            let name = format!("stop {j}");
            let gap = non_negative_named(&name, "gap", stop.gap)?;
            let mut point = s.point(&format!("{name} at"), stop.at)?;
            if let Some(against) = stop.against {
                // Pounding: the gap closes with the displacement of `at`
                // relative to `against`'s.
                let carrier = s.point(&format!("{name} against"), against)?;
                for (p, c) in point.iter_mut().zip(&carrier) {
                    *p -= c;
                }
                if point.iter().all(|p| *p == 0.0) {
                    return Err(Error::Inconsistent(format!(
                        "{name} against: {against} moves as at = {} does, so the gap between \
                         them never changes: choose another point",
                        stop.at
                    )));
                }
            }
            let law = interaction_law(&name, &stop.law)?;
            let sign = match stop.side {
                Side::Upper => -1.0,
                Side::Lower => 1.0,
            };
            let mut h = vec![0.0; dim];
            for i in 0..n {
                h[i] = sign * point[i];
            }
            let pair = pairs.len();
            pairs.push(name);
            interactions.push(Interaction {
                pair,
                push: vec![],
                inverse_mass: 0.0,
                h,
                offset: gap,
                law,
            });
        }
        for interaction in &mut interactions {
            interaction.push = full_push(&interaction.h);
            interaction.inverse_mass = linalg::dot(&interaction.h, &interaction.push);
            if interaction.inverse_mass.is_nan() || interaction.inverse_mass <= 0.0 {
                return Err(Error::Inconsistent(format!(
                    "{} acts at a point that does not move (every mode has a node there): \
                     move it",
                    pairs[interaction.pair]
                )));
            }
        }
        let mut forces = Vec::new();
        let mut base = Vec::new();
        for (j, excitation) in spec.excitations.iter().enumerate() {
            match excitation.load {
                Load::Force { at } => {
                    let row = s.point(&format!("excitation {j} at"), at)?;
                    let mut push = vec![0.0; n];
                    linalg::multiply(&minv, &row, &mut push);
                    forces.push(ForceLoad {
                        row,
                        push,
                        signal: excitation.signal.clone(),
                    });
                }
                Load::Base => base.push(excitation.signal.clone()),
            }
        }
        let frequencies = s.natural_frequencies();
        let fastest_natural = frequencies.iter().fold(0.0f64, |m, w| m.max(*w));
        let mut shortest = if fastest_natural > 0.0 {
            std::f64::consts::TAU / fastest_natural
        } else {
            f64::INFINITY
        };
        let total_mass: f64 =
            linalg::dot(&mass_influence, s.influence()) + damper_mass.iter().sum::<f64>();
        let mut acceleration = gravity;
        for excitation in &spec.excitations {
            let (largest, period) = excitation.signal.extent();
            shortest = shortest.min(period);
            acceleration += match excitation.load {
                Load::Base => largest,
                Load::Force { .. } => largest / total_mass,
            };
        }
        let longest_period = frequencies
            .iter()
            .find(|w| **w > 0.0)
            .map_or(f64::INFINITY, |w| std::f64::consts::TAU / w);
        // Without a period (a ball under gravity), the time to fall through
        // the largest gap: a long run's length would make the floor of the
        // energy check grow without bound.
        let largest_gap = interactions
            .iter()
            .fold(0.0f64, |g, it| g.max(it.offset.abs()));
        let fall_time = if acceleration > 0.0 && largest_gap > 0.0 {
            (2.0 * largest_gap / acceleration).sqrt()
        } else {
            f64::INFINITY
        };
        let time_scale = match shortest.min(longest_period) {
            period if period.is_finite() => period,
            _ => fall_time,
        };
        duplicate_walls(&interactions, &pairs)?;
        let mirrors_previous = (0..interactions.len())
            .map(|i| {
                i > 0
                    && interactions[i]
                        .h
                        .iter()
                        .zip(&interactions[i - 1].h)
                        .all(|(a, b)| *a == -*b)
            })
            .collect();
        let followed = spec.points.len() + spec.moments.len();
        if followed > MAX_POINTS {
            return Err(Error::Inconsistent(format!(
                "points: at most {MAX_POINTS} points and moments may be followed, got {followed}"
            )));
        }
        let mut point_rows = Vec::with_capacity(followed * n);
        for (j, &at) in spec.points.iter().enumerate() {
            point_rows.extend(s.point(&format!("[output] points[{j}]"), at)?);
        }
        for (j, &at) in spec.moments.iter().enumerate() {
            point_rows.extend(s.moment_row(&format!("[output] moments[{j}]"), at)?);
        }
        let mut assembly = Self {
            compact: None,
            point_rows,
            mirrors_previous,
            sticking_step: 0.1 * shortest,
            floor_mass_acceleration: total_mass * acceleration * acceleration,
            time_scale,
            n,
            k,
            dim,
            mass: s.mass().to_vec(),
            stiffness: s.stiffness().to_vec(),
            damping: s.damping().to_vec(),
            minv_k,
            minv_c,
            damper_mass,
            diagonals,
            diagonal: [s.mass(), s.stiffness(), s.damping()]
                .iter()
                .all(|a| (0..n * n).all(|p| p % (n + 1) == 0 || a[p] == 0.0)),
            influence: s.influence().to_vec(),
            mass_influence,
            gravity,
            forces,
            base,
            interactions,
            longest_period,
            pairs,
        };
        assembly.compact = Compact::of(&assembly).map(Box::new);
        Ok(assembly)
    }

    /// What [`Compact::of`] reads, for a system with diagonal matrices.
    pub(crate) fn compact_parts(&self) -> Option<CompactParts<'_>> {
        self.diagonal.then(|| CompactParts {
            diagonals: &self.diagonals,
            forces: self
                .forces
                .iter()
                .map(|f| (&f.signal, &f.push[..], &f.row[..]))
                .collect(),
            has_base: !self.base.is_empty(),
            gravity: self.gravity,
            mirrors: &self.mirrors_previous,
        })
    }

    /// Length of the state vector: `x`, `v` and the accumulators.
    pub fn state_len(&self) -> usize {
        2 * self.dim + CONTACT + self.interactions.len()
    }

    /// The quantities the reductions follow: each structure coordinate, then
    /// each point of [`SystemSpec::points`], then each moment.
    pub fn observed(&self) -> usize {
        self.n + self.point_rows.len() / self.n
    }

    /// Observed quantity `j` (see [`Self::observed`]) of `block`, the
    /// structure coordinates' displacements, velocities or accelerations.
    #[inline]
    pub fn observe(&self, j: usize, block: &[f64]) -> f64 {
        let n = self.n;
        if j < n {
            block[j]
        } else {
            let row = (j - n) * n..(j - n + 1) * n;
            linalg::dot(&self.point_rows[row], &block[..n])
        }
    }

    /// Whether nothing forces the system (energy can then only fall).
    pub fn is_free(&self) -> bool {
        self.forces.is_empty() && self.base.is_empty()
    }

    /// The gap of interaction `i` and its rate at state `y`.
    #[inline(always)]
    pub fn gap(&self, i: usize, y: &[f64]) -> (f64, f64) {
        let it = &self.interactions[i];
        let d = self.dim;
        (
            it.offset + linalg::dot(&it.h, &y[..d]),
            linalg::dot(&it.h, &y[d..2 * d]),
        )
    }

    /// Every interaction's gap and its rate at state `y` into `out`, as
    /// [`Self::gap`] gives them (a damper's two walls share their products).
    pub fn gaps(&self, y: &[f64], out: &mut [(f64, f64)]) {
        by_size!(self, |n, k| self.gaps_in(n + k, y, out))
    }

    /// [`Self::gaps`] over `d` coordinates (a constant where inlined).
    #[inline(always)]
    pub(crate) fn gaps_in(&self, d: usize, y: &[f64], out: &mut [(f64, f64)]) {
        let (x, v) = (&y[..d], &y[d..2 * d]);
        let mut products = (0.0, 0.0);
        for ((it, mirror), out) in self
            .interactions
            .iter()
            .zip(&self.mirrors_previous)
            .zip(out.iter_mut())
        {
            products = if *mirror {
                (-products.0, -products.1)
            } else {
                dots(&it.h[..d], x, v)
            };
            *out = (it.offset + products.0, products.1);
        }
    }

    /// The derivative of the state `y` at `time` in `modes` into `out`; the
    /// constraint forces of sticking interactions are solved for on the way
    /// (`scratch` holds them). Allocates nothing.
    pub fn rates(
        &self,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) {
        by_size!(self, |n, k| self
            .rates_in(n, k, time, y, modes, scratch, out))
    }

    /// The second derivative of interaction `i`'s gap at `time` and state `y`
    /// in `modes` (m/s^2, < 0 pressing it shut): `h . a` from [`Self::rates`],
    /// which `work` (the state's length) receives.
    pub fn gap_acceleration(
        &self,
        i: usize,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        work: &mut [f64],
    ) -> f64 {
        self.rates(time, y, modes, scratch, work);
        linalg::dot(&self.interactions[i].h, &work[self.dim..2 * self.dim])
    }

    /// [`Self::rates`] for `n` structure coordinates and `k` dampers: inlined
    /// where they are constants, every slice then has a length known at
    /// compile time (loops unrolled, no bounds checks).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(crate) fn rates_in(
        &self,
        n: usize,
        k: usize,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) {
        self.rates_with(&self.rates_parts(n, k), time, y, modes, scratch, out)
    }

    /// The parts of the system [`Self::rates_with`] reads, cut to their
    /// sizes: a method that evaluates the rates several times a step (RK4)
    /// makes them once, and the lengths are checked once.
    #[inline(always)]
    pub(crate) fn rates_parts(&self, n: usize, k: usize) -> RatesParts<'_> {
        let (diagonals, first) = match (self.diagonal, self.forces.first()) {
            (true, Some(f)) => (
                Some(&self.diagonals[..n]),
                Some((&f.signal, &f.push[..n], &f.row[..n])),
            ),
            (true, None) => (Some(&self.diagonals[..n]), None),
            (false, _) => (None, None),
        };
        let fused = usize::from(first.is_some());
        RatesParts {
            n,
            k,
            diagonals,
            fused,
            unfused: self.forces.len() > fused,
            base: !self.base.is_empty(),
            first,
            interactions: &self.interactions[..],
            gravity: self.gravity,
        }
    }

    /// [`Self::rates`] from its parts (see [`Self::rates_parts`]).
    #[inline(always)]
    pub(crate) fn rates_with(
        &self,
        parts: &RatesParts<'_>,
        time: f64,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        out: &mut [f64],
    ) {
        let (n, k) = (parts.n, parts.k);
        let d = n + k;
        let count = parts.interactions.len();
        let (x, v) = (&y[..d], &y[d..2 * d]);
        let (velocity, rest) = out[..2 * d + CONTACT + count].split_at_mut(d);
        let (acc, rest) = rest.split_at_mut(d);
        let (head, losses) = rest.split_at_mut(CONTACT);
        // What few systems have is out of line (its fields are then not
        // loaded, nor kept, by a method's loop over the evaluations).
        let base = if parts.base {
            self.base_value(time, scratch)
        } else {
            0.0
        };
        let inertial = base + parts.gravity;
        // The velocities are copied inside the loops over the coordinates
        // (a lone copy of a handful of values becomes a call to memmove).
        let mut input = 0.0;
        let fused = parts.fused;
        let viscous = if let Some(diagonals) = parts.diagonals {
            // Modal coordinates: the matrices are diagonal. The first force
            // is added in the same pass (each sum in the same order).
            let (x, v) = (&x[..n], &v[..n]);
            let (acc, velocity) = (&mut acc[..n], &mut velocity[..n]);
            let mut viscous = 0.0;
            if let (Some((signal, push, row)), Some(cache)) =
                (parts.first, scratch.force_values.first_mut())
            {
                let value = cache.value(signal, time);
                let mut power = -0.0;
                for i in 0..n {
                    let [k, c, damping, r] = diagonals[i];
                    velocity[i] = v[i];
                    acc[i] = -(k * x[i] + c * v[i]) - r * inertial + push[i] * value;
                    viscous += damping * v[i] * v[i];
                    power += row[i] * v[i];
                }
                input += value * power;
            } else {
                for i in 0..n {
                    let [k, c, damping, r] = diagonals[i];
                    velocity[i] = v[i];
                    acc[i] = -(k * x[i] + c * v[i]) - r * inertial;
                    viscous += damping * v[i] * v[i];
                }
            }
            viscous
        } else {
            self.coupled_rates(n, x, v, inertial, acc, velocity)
        };
        for ((a, o), v) in acc[n..d].iter_mut().zip(&mut velocity[n..d]).zip(&v[n..d]) {
            *o = *v;
            *a = -inertial;
        }
        if parts.unfused {
            input = self.unfused_forces(n, fused, time, v, input, acc, scratch);
        }
        if base != 0.0 {
            input -= base * self.base_momentum(n, k, v);
        }
        let mut sticking = 0;
        // `h . x`, `h . v` of the last interaction whose products were taken:
        // a damper's second wall has the first's row negated (see `gaps`).
        let mut products: Option<(f64, f64)> = None;
        for (i, (((it, mode), loss), mirror)) in parts
            .interactions
            .iter()
            .zip(&modes[..count])
            .zip(losses.iter_mut())
            .zip(&self.mirrors_previous)
            .enumerate()
        {
            *loss = 0.0;
            // Only the interaction just before may lend its products.
            let previous = products.take();
            match (mode, &it.law) {
                (Mode::Compliant { approach_rate }, InteractionLaw::Compliant { law, damping }) => {
                    let (approach_rate, damping) = (*approach_rate, *damping);
                    let (hx, hv) = match previous {
                        Some((hx, hv)) if *mirror => (-hx, -hv),
                        _ => (h_dot(&it.h[..d], x), h_dot(&it.h[..d], v)),
                    };
                    products = Some((hx, hv));
                    let (indentation, rate) = (-(it.offset + hx), -hv);
                    let (force, elastic) = if indentation > 0.0 {
                        law.force_and_elastic(indentation, rate, approach_rate)
                    } else {
                        (0.0, 0.0)
                    };
                    let total = force + damping * rate;
                    // Apart with no contact damper there is no force to add.
                    if total != 0.0 {
                        for (a, p) in acc.iter_mut().zip(&it.push[..d]) {
                            *a += p * total;
                        }
                    }
                    *loss = (total - elastic) * rate;
                }
                (Mode::Sticking, _) => {
                    scratch.sticking[sticking] = i;
                    sticking += 1;
                }
                _ => {}
            }
        }
        if sticking > 0 {
            self.add_constraint_forces(sticking, acc, scratch);
        }
        scratch.count = sticking;
        head[VISCOUS] = viscous;
        head[INPUT] = input;
    }

    fn signals(&self) -> impl Iterator<Item = &Signal> {
        self.forces.iter().map(|f| &f.signal).chain(&self.base)
    }

    /// Whether any excitation's signal has kinks.
    pub fn has_breakpoints(&self) -> bool {
        self.signals().any(Signal::has_breakpoints)
    }

    /// The first kink of any excitation's signal after `time` (s; see
    /// [`Signal::next_breakpoint`]), or infinity.
    pub fn next_breakpoint(&self, time: f64) -> f64 {
        self.signals()
            .map(|signal| signal.next_breakpoint(time))
            .fold(f64::INFINITY, f64::min)
    }

    /// The sum of the base signals at `time`.
    #[inline(never)]
    fn base_value(&self, time: f64, scratch: &mut Scratch) -> f64 {
        let mut base = 0.0;
        for (signal, cache) in self.base.iter().zip(&mut scratch.base_values) {
            base += cache.value(signal, time);
        }
        base
    }

    /// The momentum `v . M r` whose rate the base signals' inertial load
    /// `-M r a` works on.
    #[inline(never)]
    fn base_momentum(&self, n: usize, k: usize, v: &[f64]) -> f64 {
        linalg::dot(&self.mass_influence[..n], &v[..n])
            + self.damper_mass[..k]
                .iter()
                .zip(&v[n..n + k])
                .map(|(m, v)| m * v)
                .sum::<f64>()
    }

    /// The structure's accelerations (and velocities) where its matrices
    /// couple the coordinates; returns the viscous power.
    #[inline(never)]
    fn coupled_rates(
        &self,
        n: usize,
        x: &[f64],
        v: &[f64],
        inertial: f64,
        acc: &mut [f64],
        velocity: &mut [f64],
    ) -> f64 {
        for (i, a) in acc[..n].iter_mut().enumerate() {
            let row = i * n..(i + 1) * n;
            velocity[i] = v[i];
            *a = -linalg::dot(&self.minv_k[row.clone()], &x[..n])
                - linalg::dot(&self.minv_c[row], &v[..n])
                - self.influence[i] * inertial;
        }
        linalg::quadratic_form(&self.damping[..n * n], &v[..n])
    }

    /// The forces after the first `fused` onto the accelerations; returns
    /// the input power with their work added to `input`.
    #[allow(clippy::too_many_arguments)]
    #[inline(never)]
    fn unfused_forces(
        &self,
        n: usize,
        fused: usize,
        time: f64,
        v: &[f64],
        mut input: f64,
        acc: &mut [f64],
        scratch: &mut Scratch,
    ) -> f64 {
        for (f, cache) in self.forces[fused..]
            .iter()
            .zip(&mut scratch.force_values[fused..])
        {
            let value = cache.value(&f.signal, time);
            for (a, p) in acc[..n].iter_mut().zip(&f.push[..n]) {
                *a += p * value;
            }
            input += value * linalg::dot(&f.row[..n], &v[..n]);
        }
        input
    }

    /// The constraint forces of the `sticking` interactions listed in
    /// `scratch` into it and onto the accelerations (out of line: rare).
    #[inline(never)]
    pub(crate) fn add_constraint_forces(
        &self,
        sticking: usize,
        acc: &mut [f64],
        scratch: &mut Scratch,
    ) {
        if sticking == 1 {
            // One constraint: W lambda = -h . a with W = h M^-1 h^T, what
            // the elimination below gives for one row.
            let it = &self.interactions[scratch.sticking[0]];
            let lambda = -h_dot(&it.h, acc) / it.inverse_mass;
            scratch.forces[0] = lambda;
            for (a, p) in acc.iter_mut().zip(&it.push) {
                *a += p * lambda;
            }
        } else {
            self.constraint_forces(
                &scratch.sticking[..sticking],
                acc,
                &mut scratch.matrix,
                &mut scratch.forces,
            );
            for (s, &i) in scratch.sticking[..sticking].iter().enumerate() {
                let lambda = scratch.forces[s];
                for (a, p) in acc.iter_mut().zip(&self.interactions[i].push) {
                    *a += p * lambda;
                }
            }
        }
    }

    /// The Jacobians of the accelerations (the middle `dim` rates) with
    /// respect to the coordinates `x` and the velocities `v` at state `y`, as
    /// row-major `dim x dim` matrices, for Newton's method: the structure's
    /// `-M^-1 K` and `-M^-1 C`, the compliant contacts' slopes along
    /// `M^-1 h^T h`, and sticking pairs' constraints projected out.
    pub fn acceleration_jacobian(
        &self,
        y: &[f64],
        modes: &[Mode],
        scratch: &mut Scratch,
        dadx: &mut [f64],
        dadv: &mut [f64],
    ) {
        let (n, d) = (self.n, self.dim);
        let (x, v) = (&y[..d], &y[d..2 * d]);
        dadx.iter_mut().for_each(|a| *a = 0.0);
        dadv.iter_mut().for_each(|a| *a = 0.0);
        for i in 0..n {
            for j in 0..n {
                dadx[i * d + j] = -self.minv_k[i * n + j];
                dadv[i * d + j] = -self.minv_c[i * n + j];
            }
        }
        let mut sticking = 0;
        for (i, (it, mode)) in self.interactions.iter().zip(modes).enumerate() {
            match (*mode, it.law) {
                (Mode::Compliant { approach_rate }, InteractionLaw::Compliant { law, damping }) => {
                    let indentation = -(it.offset + h_dot(&it.h, x));
                    let rate = -h_dot(&it.h, v);
                    let (_, by_indentation, by_rate) = if indentation > 0.0 {
                        law.force_derivatives(indentation, rate, approach_rate)
                    } else {
                        (0.0, 0.0, 0.0)
                    };
                    // lambda(delta, delta'), delta = -(b + h.x): d/dx = -lambda_delta h.
                    for (r, p) in it.push.iter().enumerate() {
                        for (c, h) in it.h.iter().enumerate() {
                            dadx[r * d + c] -= p * by_indentation * h;
                            dadv[r * d + c] -= p * (by_rate + damping) * h;
                        }
                    }
                }
                (Mode::Sticking, _) => {
                    scratch.sticking[sticking] = i;
                    sticking += 1;
                }
                _ => {}
            }
        }
        if sticking == 0 {
            return;
        }
        // The constraint force -W^-1 H a makes the accelerations P a with
        // P = I - Push W^-1 H: project each column of both Jacobians.
        let active = &scratch.sticking[..sticking];
        for matrix in [&mut *dadx, &mut *dadv] {
            for c in 0..d {
                for (r, &i) in active.iter().enumerate() {
                    for (q, &j) in active.iter().enumerate() {
                        scratch.matrix[r * sticking + q] =
                            linalg::dot(&self.interactions[i].h, &self.interactions[j].push);
                    }
                    scratch.forces[r] = (0..d)
                        .map(|k| self.interactions[i].h[k] * matrix[k * d + c])
                        .sum();
                }
                linalg::solve_in_place(
                    &mut scratch.matrix[..sticking * sticking],
                    &mut scratch.forces[..sticking],
                    sticking,
                );
                for (r, &i) in active.iter().enumerate() {
                    for k in 0..d {
                        matrix[k * d + c] -= self.interactions[i].push[k] * scratch.forces[r];
                    }
                }
            }
        }
    }

    /// The forces `lambda` of the sticking interactions `active` that keep
    /// their gaps' accelerations at zero: `W lambda = -H a`, `W = H M^-1
    /// H^T`, by Gaussian elimination with partial pivoting (a few rows).
    fn constraint_forces(
        &self,
        active: &[usize],
        acc: &[f64],
        matrix: &mut [f64],
        forces: &mut [f64],
    ) {
        let m = active.len();
        for (r, &i) in active.iter().enumerate() {
            for (c, &j) in active.iter().enumerate() {
                matrix[r * m + c] =
                    linalg::dot(&self.interactions[i].h, &self.interactions[j].push);
            }
            forces[r] = -h_dot(&self.interactions[i].h, acc);
        }
        linalg::solve_in_place(&mut matrix[..m * m], &mut forces[..m], m);
    }

    /// Stored energy: kinetic, strain, gravity's potential and the elastic
    /// energy of compliant contacts, J.
    pub fn energy(&self, y: &[f64], modes: &[Mode]) -> f64 {
        self.energy_terms(y, modes).0
    }

    /// The stored energy and the sum of its terms' magnitudes (J): the
    /// scale against which a balance residual is judged (gravity's
    /// potential can cancel the kinetic energy exactly).
    pub fn energy_terms(&self, y: &[f64], modes: &[Mode]) -> (f64, f64) {
        let (n, d) = (self.n, self.dim);
        let (x, v) = (&y[..d], &y[d..2 * d]);
        let kinetic = 0.5 * linalg::quadratic_form(&self.mass, &v[..n])
            + self
                .damper_mass
                .iter()
                .zip(&v[n..])
                .map(|(m, v)| 0.5 * m * v * v)
                .sum::<f64>();
        let strain = 0.5 * linalg::quadratic_form(&self.stiffness, &x[..n]);
        let gravity = self.gravity
            * (linalg::dot(&self.mass_influence, &x[..n])
                + self
                    .damper_mass
                    .iter()
                    .zip(&x[n..])
                    .map(|(m, z)| m * z)
                    .sum::<f64>());
        let mut contact = 0.0;
        for (it, mode) in self.interactions.iter().zip(modes) {
            if let (Mode::Compliant { .. }, InteractionLaw::Compliant { law, .. }) = (mode, it.law)
            {
                let indentation = -(it.offset + h_dot(&it.h, x));
                if indentation > 0.0 {
                    contact += law.potential(indentation);
                }
            }
        }
        (
            kinetic + strain + gravity + contact,
            kinetic + strain + gravity.abs() + contact,
        )
    }

    /// When open interaction `i` at state `y`, its coordinates' accelerations
    /// `acc` (m/s^2), would reach its wall on its gap's parabola (s after
    /// now); None where the gap's acceleration does not close it.
    pub fn landing_time(&self, i: usize, y: &[f64], acc: &[f64]) -> Option<f64> {
        let (gap, rate) = self.gap(i, y);
        let closing = -linalg::dot(&self.interactions[i].h, &acc[..self.dim]);
        (closing > 0.0)
            .then(|| (rate + (rate * rate + 2.0 * closing * gap.max(0.0)).sqrt()) / closing)
    }

    /// Whether interaction `i` is a wall whose other wall (of the same
    /// damper) is sticking: its gap is then held too, at the sum of the
    /// clearances (0 for a zero clearance, to round-off), and it has no
    /// event of its own. Sticking it as well would make the constraints
    /// dependent.
    pub fn held_by_mirror(&self, i: usize, modes: &[Mode]) -> bool {
        let before = self.mirrors_previous[i] && modes[i - 1] == Mode::Sticking;
        let after =
            self.mirrors_previous.get(i + 1) == Some(&true) && modes[i + 1] == Mode::Sticking;
        before || after
    }

    /// Whether interaction `i` is a wall of a damper with no clearance at
    /// all (its two walls' offsets sum to zero): stuck, the damper is locked
    /// to its point, its constraint force of either sign (the force passes
    /// from one wall to the other without a release, which round-off would
    /// otherwise turn into a release and a re-sticking, without end).
    pub fn locked(&self, i: usize) -> bool {
        let mirror = if self.mirrors_previous[i] {
            Some(i - 1)
        } else if self.mirrors_previous.get(i + 1) == Some(&true) {
            Some(i + 1)
        } else {
            None
        };
        mirror.is_some_and(|j| {
            let (a, b) = (self.interactions[i].offset, self.interactions[j].offset);
            (a + b).abs() <= 4.0 * f64::EPSILON * (a.abs() + b.abs())
        })
    }

    /// The scale of interaction `i`'s gap at state `y`, m: its offset and
    /// the magnitudes of the terms `h . x` sums, whose round-off the gap
    /// carries.
    pub fn gap_scale(&self, i: usize, y: &[f64]) -> f64 {
        let it = &self.interactions[i];
        it.offset.abs()
            + it.h
                .iter()
                .zip(&y[..self.dim])
                .map(|(h, x)| (h * x).abs())
                .sum::<f64>()
    }

    /// An energy (J) below which a balance residual is round-off: 1e-12 of
    /// what the largest acceleration acting (gravity, base, force) gives the
    /// total mass over the system's time scale (its shortest period, or
    /// without one the time to fall through its largest gap), or over the
    /// run's length `t_end` (s) where that is shorter or there is neither (a
    /// ball resting on a floor at the origin).
    pub fn energy_floor(&self, t_end: f64) -> f64 {
        1e-12 * self.floor_mass_acceleration * self.time_scale.min(t_end).powi(2)
    }

    /// The system's time scale (s): its shortest natural or forcing period,
    /// or without one the time to fall through its largest gap (infinite
    /// for neither).
    pub(crate) fn time_scale(&self) -> f64 {
        self.time_scale
    }

    /// A sticking pair `i` released: held on its wall only to round-off, it
    /// is put at rest relative to the wall (no approach left) with its gap
    /// a few units of that round-off open, along `M^-1 h^T` (the momentum
    /// and energy that moves are round-off too). Without it a gap a hair
    /// below zero, slowly opening, reads as a new contact at every step
    /// until the pair has moved away by more than the round-off.
    pub fn release(&self, i: usize, y: &mut [f64]) {
        let it = &self.interactions[i];
        let d = self.dim;
        let (gap, rate) = (
            it.offset + linalg::dot(&it.h, &y[..d]),
            linalg::dot(&it.h, &y[d..2 * d]),
        );
        let opening = (16.0 * f64::EPSILON * self.gap_scale(i, y) - gap) / it.inverse_mass;
        let lift = -rate.min(0.0) / it.inverse_mass;
        for (k, p) in it.push.iter().enumerate() {
            y[k] += p * opening;
            y[d + k] += p * lift;
        }
    }
}

/// `(h . x, h . v)` in one pass, each summed in order as [`linalg::dot`]
/// sums it (the same bits): a wall's gap and rate as the events see them.
#[inline(always)]
fn dots(h: &[f64], x: &[f64], v: &[f64]) -> (f64, f64) {
    let n = h.len();
    let (x, v) = (&x[..n], &v[..n]);
    let (mut hx, mut hv) = (-0.0, -0.0);
    for i in 0..n {
        hx += h[i] * x[i];
        hv += h[i] * v[i];
    }
    (hx, hv)
}

/// A wall's `h` times a vector where the product leads to a force: a
/// compliant wall's indentation and rate, and a sticking wall's `h . a` for
/// its constraint. The even and the odd terms are summed apart, then
/// together: two chains of half the length on a step's critical path (a
/// stage's contact force waits on it). The gaps that the events watch are
/// summed in order ([`dots`]); the two differ in the last bits at most, and
/// every path sums each quantity the same way (the same bits).
#[inline(always)]
pub(crate) fn h_dot(h: &[f64], x: &[f64]) -> f64 {
    let n = h.len();
    let x = &x[..n];
    let mut sum = [-0.0; 2];
    for i in 0..n {
        sum[i % 2] += h[i] * x[i];
    }
    sum[0] + sum[1]
}

/// Refuses two rigid walls with the same gap (the same points, side and
/// offset, such as a stop given twice, or as `lower` from the other point):
/// an impact resolves one of them, which one depending on their order.
fn duplicate_walls(interactions: &[Interaction], pairs: &[String]) -> Result<()> {
    let mut rigid: Vec<(u64, usize)> = interactions
        .iter()
        .enumerate()
        .filter(|(_, it)| matches!(it.law, InteractionLaw::Rigid { .. }))
        .map(|(i, it)| (it.offset.to_bits(), i))
        .collect();
    rigid.sort_unstable();
    for group in rigid.chunk_by(|a, b| a.0 == b.0) {
        for (k, &(_, i)) in group.iter().enumerate() {
            for &(_, j) in &group[..k] {
                let (a, b) = (&interactions[i], &interactions[j]);
                if a.pair != b.pair && a.h == b.h {
                    let (first, second) = (a.pair.min(b.pair), a.pair.max(b.pair));
                    return Err(Error::Inconsistent(format!(
                        "{} has the same gap as {} (the same points, side and gap): give it \
                         once (with the restitution wanted)",
                        pairs[second], pairs[first]
                    )));
                }
            }
        }
    }
    Ok(())
}

/// One harmonic load over all coordinates: `amplitude cos(omega t + phase)`
/// times `shape` (N per unit of the signal).
#[derive(Debug, Clone, PartialEq)]
pub struct HarmonicLoad {
    pub amplitude: f64,
    /// rad/s.
    pub omega: f64,
    pub phase: f64,
    pub shape: Vec<f64>,
}

/// The system between contacts as a linear one over all coordinates `x`:
/// `M x'' + C x' + K x = constant + sum of harmonic loads`, each matrix
/// row-major `dim x dim`. What the exact flow integrates in closed form.
#[derive(Debug, Clone, PartialEq)]
pub struct LinearParts {
    pub mass: Vec<f64>,
    pub stiffness: Vec<f64>,
    pub damping: Vec<f64>,
    /// N: gravity's weight along -x.
    pub constant: Vec<f64>,
    pub harmonics: Vec<HarmonicLoad>,
}

impl Assembly {
    /// The linear parts of the system, or an error naming the first
    /// excitation whose signal is not a sum of harmonics (`method` names the
    /// caller in it).
    pub fn linear_parts(&self, method: &str) -> Result<LinearParts> {
        let (n, d) = (self.n, self.dim);
        let mut mass = vec![0.0; d * d];
        let mut stiffness = vec![0.0; d * d];
        let mut damping = vec![0.0; d * d];
        for i in 0..n {
            for j in 0..n {
                mass[i * d + j] = self.mass[i * n + j];
                stiffness[i * d + j] = self.stiffness[i * n + j];
                damping[i * d + j] = self.damping[i * n + j];
            }
        }
        for (j, m) in self.damper_mass.iter().enumerate() {
            mass[(n + j) * d + n + j] = *m;
        }
        // The inertial load of a unit base (or gravity) acceleration: -M r.
        let mut inertial: Vec<f64> = self.mass_influence.iter().map(|m| -m).collect();
        inertial.extend(self.damper_mass.iter().map(|m| -m));
        let constant = inertial.iter().map(|f| f * self.gravity).collect();
        let mut harmonics = Vec::new();
        let mut add = |signal: &Signal, shape: &[f64], which: String| -> Result<()> {
            let list = match signal {
                Signal::Harmonic(h) => std::slice::from_ref(h),
                Signal::Harmonics(list) => list.as_slice(),
                _ => {
                    return Err(Error::Inconsistent(format!(
                        "method {method:?} takes harmonic or harmonics signals only, and {which} \
                         has another; use \"dop853\""
                    )))
                }
            };
            for h in list {
                harmonics.push(HarmonicLoad {
                    amplitude: h.amplitude,
                    omega: std::f64::consts::TAU * h.frequency,
                    phase: h.phase,
                    shape: shape.to_vec(),
                });
            }
            Ok(())
        };
        let (mut forces, mut bases) = (0, 0);
        // Excitations in the order given: forces and base signals are kept
        // apart, so their names count each kind (the binding keeps the order).
        for f in &self.forces {
            let mut shape = f.row.clone();
            shape.resize(d, 0.0);
            add(&f.signal, &shape, format!("force excitation {forces}"))?;
            forces += 1;
        }
        for signal in &self.base {
            add(signal, &inertial, format!("base excitation {bases}"))?;
            bases += 1;
        }
        Ok(LinearParts {
            mass,
            stiffness,
            damping,
            constant,
            harmonics,
        })
    }

    /// Whether anything does work on the system or dissipates between
    /// contacts (else the viscous and input accumulators stay zero).
    pub fn has_powers(&self) -> bool {
        !self.is_free() || self.damping.iter().any(|c| *c != 0.0)
    }

    /// Whether every interaction is rigid.
    pub fn all_rigid(&self) -> bool {
        self.interactions
            .iter()
            .all(|it| matches!(it.law, InteractionLaw::Rigid { .. }))
    }
}

/// The last value of a signal: Runge-Kutta stages share times (RK4's two
/// midpoints, a step's end and the next one's start), and a harmonic's
/// cosine is the costliest part of a small system's right-hand side. For a
/// harmonic it also keeps the phasor `(cos, sin)` of its angle and the
/// rotation of the last time increment: fixed steps repeat the same
/// increments, so most values are a rotation (four multiplications), with a
/// direct evaluation every `RESYNC` rotations to keep round-off from growing.
/// Direct evaluations reduce the angle to a quadrant and take the short
/// series (see [`crate::numerics::series`]): the library's sine and cosine also save
/// and restore the rounding mode, which cost 5 % of a run with many events.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Cached {
    time: f64,
    value: f64,
    cos: f64,
    sin: f64,
    delta: f64,
    delta_cos: f64,
    delta_sin: f64,
    rotations: u32,
}

/// Rotations between direct evaluations of a harmonic.
const RESYNC: u32 = 64;

impl Cached {
    const EMPTY: Self = Self {
        time: f64::NAN,
        value: 0.0,
        cos: 1.0,
        sin: 0.0,
        delta: f64::NAN,
        delta_cos: 1.0,
        delta_sin: 0.0,
        rotations: RESYNC,
    };

    /// The phasor turned by the cached increment.
    #[inline(always)]
    fn rotate(&mut self) {
        let (c, s) = (self.cos, self.sin);
        self.cos = c * self.delta_cos - s * self.delta_sin;
        self.sin = s * self.delta_cos + c * self.delta_sin;
        self.rotations += 1;
    }

    /// The phasor at `time`, `delta` after the last, where the steps' path
    /// (`rotate`) does not serve: the first repeat of an increment, whose
    /// rotation it computes, or a new increment or a resync, where the angle
    /// is evaluated directly (a value then depends on its time alone, as in
    /// adaptive steps, whose increments do not repeat). `same`: whether the
    /// increment is the cached one. Out of line.
    #[cold]
    #[inline(never)]
    fn turn(&mut self, h: &Harmonic, time: f64, same: bool) {
        let omega = std::f64::consts::TAU * h.frequency;
        if same && self.rotations == 0 {
            (self.delta_sin, self.delta_cos) = sin_cos(omega * self.delta);
            self.rotate();
        } else {
            (self.sin, self.cos) = sin_cos_by_quadrant(omega * time + h.phase);
            if same {
                // A resync: the increment, and so its rotation, stands.
                self.rotations = 1;
            } else {
                self.delta = time - self.time;
                self.rotations = 0;
            }
        }
    }

    #[inline(always)]
    fn value(&mut self, signal: &Signal, time: f64) -> f64 {
        if time.to_bits() == self.time.to_bits() {
            return self.value;
        }
        match signal {
            Signal::Harmonic(h) => {
                let delta = time - self.time;
                // The same increment to the round-off of the times themselves
                // (t + h/2 and t + h differ by h/2 only to a few ulps of t):
                // rotating by the cached one errs no more than the cosine's
                // own argument does.
                let same = (delta - self.delta).abs() <= 8.0 * f64::EPSILON * time.abs();
                if same && self.rotations > 0 && self.rotations < RESYNC {
                    self.rotate();
                } else {
                    self.turn(h, time, same);
                }
                self.value = h.amplitude * self.cos;
            }
            _ => self.value = signal.value(time),
        }
        self.time = time;
        self.value
    }
}

/// Work space of [`Assembly::rates`], allocated once per run.
#[derive(Debug, Clone)]
pub struct Scratch {
    force_values: Vec<Cached>,
    base_values: Vec<Cached>,
    pub(crate) sticking: Vec<usize>,
    matrix: Vec<f64>,
    /// Constraint forces of the sticking interactions (N), after `rates`.
    pub forces: Vec<f64>,
    /// How many interactions were sticking in the last `rates`.
    pub count: usize,
}

impl Scratch {
    pub fn new(assembly: &Assembly) -> Self {
        let m = assembly.interactions.len().max(1);
        let empty = Cached::EMPTY;
        Self {
            force_values: vec![empty; assembly.forces.len()],
            base_values: vec![empty; assembly.base.len()],
            sticking: vec![0; m],
            matrix: vec![0.0; m * m],
            forces: vec![0.0; m],
            count: 0,
        }
    }

    /// The first force's signal cache, which a step that is taken back
    /// restores (the next values then come as they would have).
    pub(crate) fn first_cache(&mut self) -> Option<&mut Cached> {
        self.force_values.first_mut()
    }

    /// The first force's signal at `time`, through its cache (the value the
    /// general right-hand side takes, to the bit).
    #[inline(always)]
    pub(crate) fn first_force_value(&mut self, signal: &Signal, time: f64) -> f64 {
        self.force_values[0].value(signal, time)
    }

    /// The constraint force of interaction `i` in the last `rates` (N), or
    /// None when it was not sticking.
    pub fn force_of(&self, i: usize) -> Option<f64> {
        self.sticking[..self.count]
            .iter()
            .position(|&j| j == i)
            .map(|s| self.forces[s])
    }
}

fn interaction_law(name: &str, law: &PairLaw) -> Result<InteractionLaw> {
    Ok(match *law {
        PairLaw::Compliant(contact) => InteractionLaw::Compliant {
            law: contact.any_law(),
            damping: contact.damping,
        },
        PairLaw::Rigid { restitution } => {
            if !(0.0..=1.0).contains(&restitution) {
                return Err(Error::Inconsistent(format!(
                    "{name} restitution must be in [0, 1], got {restitution}"
                )));
            }
            InteractionLaw::Rigid { restitution }
        }
    })
}

fn positive_named(name: &str, key: &'static str, value: f64) -> Result<f64> {
    positive(key, value).map_err(|e| Error::Inconsistent(format!("{name} {e}")))
}

fn non_negative_named(name: &str, key: &'static str, value: f64) -> Result<f64> {
    non_negative(key, value).map_err(|e| Error::Inconsistent(format!("{name} {e}")))
}

/// The initial state vector from the four arrays of `[initial]` (zeros where
/// empty), checked against the system's sizes and finite.
pub fn initial_state(
    assembly: &Assembly,
    structure_displacement: &[f64],
    structure_velocity: &[f64],
    damper_displacement: &[f64],
    damper_velocity: &[f64],
) -> Result<Vec<f64>> {
    state_from(
        assembly,
        [
            structure_displacement,
            structure_velocity,
            damper_displacement,
            damper_velocity,
        ],
        false,
    )
}

/// A state to continue from, as a run left it: the same as
/// [`initial_state`] but a compliant pair may be in contact (the kernel
/// resumes the contact, its approach rate taken as the indentation rate
/// then); a rigid pair may not be inside its wall.
pub fn resumed_state(assembly: &Assembly, arrays: [&[f64]; 4]) -> Result<Vec<f64>> {
    state_from(assembly, arrays, true)
}

/// A depth inside a wall (m) that no system resolves, five orders below an
/// atom's size: a resumed state that deep is on its wall whatever its scale.
/// A ball resting on a vibrating table at a gap of 0 (a scale of 0) ends a
/// run 4e-19 m inside it, the drift of its sticking constraint.
const NEGLIGIBLE_DEPTH: f64 = 1e-15;

fn state_from(assembly: &Assembly, arrays: [&[f64]; 4], resumed: bool) -> Result<Vec<f64>> {
    let [structure_displacement, structure_velocity, damper_displacement, damper_velocity] = arrays;
    let (n, k, d) = (assembly.n, assembly.k, assembly.dim);
    let mut y = vec![0.0; assembly.state_len()];
    for (key, values, size, at) in [
        ("structure_displacement", structure_displacement, n, 0),
        ("structure_velocity", structure_velocity, n, d),
        ("damper_displacement", damper_displacement, k, n),
        ("damper_velocity", damper_velocity, k, d + n),
    ] {
        if !values.is_empty() && values.len() != size {
            let unit = if size == 1 { "value" } else { "values" };
            return Err(Error::Inconsistent(format!(
                "initial.{key} must have {size} {unit} (or none), got {}",
                values.len()
            )));
        }
        for (slot, &value) in y[at..at + values.len()].iter_mut().zip(values) {
            *slot = finite(key, value)?;
        }
    }
    for i in 0..assembly.interactions.len() {
        let (gap, _) = assembly.gap(i, &y);
        let it = &assembly.interactions[i];
        if resumed && matches!(it.law, InteractionLaw::Compliant { .. }) {
            continue;
        }
        // On the wall to round-off is at the wall.
        let scale = assembly.gap_scale(i, &y);
        let round_off = 8.0 * f64::EPSILON * scale;
        if resumed && gap < -round_off && gap >= -(1e-8 * scale).max(NEGLIGIBLE_DEPTH) {
            // A run's end with a pair resting or stuck on its wall is inside
            // it by the drift of the method's solution (1e-12 m at dop853's
            // default tolerances; or a round-off of no length at all, where
            // the wall and the point are both at the origin): put back on the
            // wall, the least change of the coordinates along the gap's row.
            let norm: f64 = it.h.iter().map(|h| h * h).sum();
            for (x, h) in y[..d].iter_mut().zip(&it.h) {
                *x -= gap * h / norm;
            }
            continue;
        }
        if gap < -round_off {
            return Err(Error::Inconsistent(format!(
                "initial state: {} starts {:.6e} m inside its wall; start every pair apart or just touching",
                assembly.pairs[it.pair],
                -gap
            )));
        }
    }
    Ok(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_harmonic_s_cached_value_is_its_cosine_along_steps_events_and_returns() {
        crate::testing::timeout(30, || {
            let signal = Signal::harmonic(0.5, 8.0, 0.3).unwrap();
            let Signal::Harmonic(h) = &signal else {
                unreachable!()
            };
            let exact =
                |t: f64| h.amplitude * (std::f64::consts::TAU * h.frequency * t + h.phase).cos();
            let mut cache = Cached::EMPTY;
            let (dt, mut time, mut worst) = (1e-5, 0.0, 0.0f64);
            let mut check = |cache: &mut Cached, t: f64| {
                worst = worst.max((cache.value(&signal, t) - exact(t)).abs());
            };
            for step in 0..200_000u64 {
                // RK4's stage times on the grid; every 97th step an event:
                // a fraction of a step, a look back, and a long jump every
                // 1001st (more than an eighth of a turn).
                let next = if step % 97 == 0 {
                    check(&mut cache, time - 0.3 * dt);
                    time + 0.37 * dt
                } else if step % 1001 == 0 {
                    time + 0.02
                } else {
                    (time / dt).floor() * dt + dt
                };
                for t in [time, time + 0.5 * (next - time), next] {
                    check(&mut cache, t);
                }
                time = next;
            }
            // The angle's own round-off at t ~ 5 s is ~1e-13 rad; rotations
            // by increments equal to a few ulps of t add ~1e-11.
            assert!(time > 4.0 && worst < 1e-10, "{time} {worst}");
        });
    }
}
