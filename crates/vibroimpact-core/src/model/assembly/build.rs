//! Assembling a [`SystemSpec`] into an [`Assembly`]: the structure's
//! matrices, the walls of each pair with their pushes, the excitations'
//! loads, the time scales and the followed points; every input checked.

use super::scales::{gap_floor, TimeScales};
use super::spec::{FrictionSite, Load, PairLaw, Side, SystemSpec, MAX_PAIRS, MAX_POINTS};
use super::{
    same_row, Assembly, CompactParts, ForceLoad, Interaction, InteractionLaw, SPARSE_FROM,
};
use crate::error::{non_negative, positive, Error, Result};
use crate::kernel::compact::Compact;
use crate::model::signals::Signal;
use crate::model::structure::Structure;
use crate::numerics::linalg;

impl Assembly {
    /// Assemble and check a system. Errors name the input (`damper 1 at`).
    pub fn new(spec: &SystemSpec) -> Result<Self> {
        let s = &spec.structure;
        let (n, k) = (s.dofs(), spec.dampers.len());
        let dim = n + k;
        let matrices = StructureMatrices::of(s);
        let gravity = non_negative("gravity", spec.gravity)?;
        let walls = Walls::of(spec, &matrices.minv)?;
        let (forces, base) = excitation_loads(spec, &matrices.minv)?;
        let scales = TimeScales::of(
            spec,
            &matrices.mass_influence,
            &walls.damper_mass,
            gravity,
            &walls.interactions,
        );
        let Walls {
            damper_mass,
            interactions,
            pairs,
        } = walls;
        duplicate_walls(&interactions, &pairs)?;
        let mirrors_previous = (0..interactions.len())
            .map(|i| {
                i > 0
                    && !interactions[i].law.is_friction()
                    && !interactions[i - 1].law.is_friction()
                    && interactions[i]
                        .h
                        .iter()
                        .zip(&interactions[i - 1].h)
                        .all(|(a, b)| *a == -*b)
            })
            .collect();
        let point_rows = followed_rows(spec)?;
        let friction_hold = friction_holds(&interactions);
        let gap_floor = gap_floor(&interactions, scales.motion_length);
        let mut assembly = Self {
            gap_floor,
            compact: None,
            point_rows,
            mirrors_previous,
            sticking_step: 0.1 * scales.shortest,
            friction_hold,
            floor_mass_acceleration: scales.floor_mass_acceleration,
            time_scale: scales.time_scale,
            finest_signal: scales.finest_signal,
            n,
            k,
            dim,
            mass: s.mass().to_vec(),
            stiffness: s.stiffness().to_vec(),
            damping: s.damping().to_vec(),
            minv_k: matrices.minv_k,
            minv_c: matrices.minv_c,
            damper_mass,
            diagonals: matrices.diagonals,
            diagonal: [s.mass(), s.stiffness(), s.damping()]
                .iter()
                .all(|a| (0..n * n).all(|p| p % (n + 1) == 0 || a[p] == 0.0)),
            influence: s.influence().to_vec(),
            mass_influence: matrices.mass_influence,
            gravity,
            forces,
            base,
            interactions,
            longest_period: scales.longest_period,
            pairs,
        };
        assembly.compact = Compact::of(&assembly);
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
}

/// Each rigid wall's friction hold (see [`Assembly::friction_hold`]): the
/// static force of the friction element whose row is the wall's, either sign.
fn friction_holds(interactions: &[Interaction]) -> Vec<f64> {
    interactions
        .iter()
        .map(|wall| {
            if !matches!(wall.law, InteractionLaw::Rigid { .. }) {
                return 0.0;
            }
            interactions
                .iter()
                .filter(|f| same_row(&f.h, &wall.h))
                .map(|f| match f.law {
                    InteractionLaw::Friction { static_force, .. } => static_force,
                    _ => 0.0,
                })
                .sum()
        })
        .collect()
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

fn interaction_law(name: &str, law: &PairLaw) -> Result<InteractionLaw> {
    Ok(match *law {
        PairLaw::Compliant(contact) => {
            // A law written as a literal has skipped `Contact::new`'s checks.
            let contact = contact
                .checked()
                .map_err(|e| Error::Inconsistent(format!("{name} {e}")))?;
            InteractionLaw::Compliant {
                law: contact.any_law(),
                damping: contact.damping,
            }
        }
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

/// A damper's clearance: a finite number >= 0 m, or +infinity (no wall).
fn clearance(name: &str, key: &'static str, value: f64) -> Result<f64> {
    if value == f64::INFINITY {
        Ok(value)
    } else {
        non_negative(key, value).map_err(|_| {
            Error::Inconsistent(format!(
                "{name} {key}: must be a finite number >= 0 m or infinite (no wall), got {value}"
            ))
        })
    }
}

/// The structure's matrices as the rates read them.
struct StructureMatrices {
    /// `M^-1`.
    minv: Vec<f64>,
    /// `M^-1 K` and `M^-1 C`.
    minv_k: Vec<f64>,
    minv_c: Vec<f64>,
    /// `[M^-1 K, M^-1 C, C, r]` of each coordinate (used when diagonal).
    diagonals: Vec<[f64; 4]>,
    /// `M r`.
    mass_influence: Vec<f64>,
}

impl StructureMatrices {
    fn of(s: &Structure) -> Self {
        let n = s.dofs();
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
        Self {
            minv,
            minv_k,
            minv_c,
            diagonals,
            mass_influence,
        }
    }
}

/// The walls of every pair (a damper's two, then each stop's one), with
/// the pairs' names and the dampers' masses.
struct Walls {
    damper_mass: Vec<f64>,
    interactions: Vec<Interaction>,
    pairs: Vec<String>,
}

impl Walls {
    /// The walls of `spec`'s pairs, each with its push `M^-1 h^T` (`minv`:
    /// the structure's `M^-1`) and inverse mass, checked.
    fn of(spec: &SystemSpec, minv: &[f64]) -> Result<Self> {
        let (n, k) = (spec.structure.dofs(), spec.dampers.len());
        let dim = n + k;
        let full_push = |h: &[f64]| {
            let mut push = vec![0.0; dim];
            linalg::multiply(minv, &h[..n], &mut push[..n]);
            for j in 0..k {
                push[n + j] = h[n + j] / spec.dampers[j].mass;
            }
            push
        };
        let pairs_asked =
            spec.dampers.len() + spec.stops.len() + spec.collisions.len() + spec.frictions.len();
        if pairs_asked > MAX_PAIRS {
            return Err(Error::Inconsistent(format!(
                "[[damper]], [[stop]], [[collision]], [[friction]]: at most {MAX_PAIRS} pairs \
                 in all, got {pairs_asked}"
            )));
        }
        let mut walls = Self {
            damper_mass: Vec::with_capacity(k),
            interactions: Vec::new(),
            pairs: Vec::new(),
        };
        walls.add_dampers(spec, n, dim)?;
        walls.add_stops(spec, n, dim)?;
        walls.add_collisions(spec, n, dim)?;
        walls.add_frictions(spec, n, dim)?;
        for interaction in &mut walls.interactions {
            interaction.push = full_push(&interaction.h);
            interaction.inverse_mass = linalg::dot(&interaction.h, &interaction.push);
            if dim >= SPARSE_FROM {
                interaction.support = (0..dim)
                    .filter(|&c| interaction.h[c] != 0.0 || interaction.push[c] != 0.0)
                    .collect();
                if 2 * interaction.support.len() > dim {
                    interaction.support = Vec::new();
                }
            }
            if interaction.inverse_mass.is_nan() || interaction.inverse_mass <= 0.0 {
                return Err(Error::Inconsistent(format!(
                    "{} acts at a point that does not move (every mode has a node there): \
                     move it",
                    walls.pairs[interaction.pair]
                )));
            }
        }
        Ok(walls)
    }

    /// A new pair named `name`: its index.
    fn pair(&mut self, name: String) -> usize {
        self.pairs.push(name);
        self.pairs.len() - 1
    }

    /// A wall of `pair`: the gap `offset + h . x` and its law (its push
    /// left to fill).
    fn wall(&mut self, pair: usize, h: Vec<f64>, offset: f64, law: InteractionLaw) {
        self.interactions.push(Interaction {
            pair,
            push: vec![],
            inverse_mass: 0.0,
            h_norm: h.iter().map(|v| v.abs()).sum(),
            h,
            offset,
            law,
            support: vec![],
        });
    }

    /// Each damper's two walls (pushes left to fill).
    fn add_dampers(&mut self, spec: &SystemSpec, n: usize, dim: usize) -> Result<()> {
        let s = &spec.structure;
        for (j, d) in spec.dampers.iter().enumerate() {
            let name = format!("damper {j}");
            self.damper_mass
                .push(positive_named(&name, "mass", d.mass)?);
            let lower = clearance(&name, "lower_clearance", d.lower_clearance)?;
            let upper = clearance(&name, "upper_clearance", d.upper_clearance)?;
            let collides = spec.collisions.iter().any(|c| c.dampers.contains(&j))
                || spec
                    .frictions
                    .iter()
                    .any(|f| f.site == FrictionSite::Damper(j) && f.normal_force > 0.0);
            if lower.is_infinite() && upper.is_infinite() && !collides {
                return Err(Error::Inconsistent(format!(
                    "{name}: lower_clearance and upper_clearance are both infinite (no wall) \
                     and neither a [[collision]] nor friction holds it: give one side a finite \
                     clearance"
                )));
            }
            let point = moving(&name, d.at, s.point(&format!("{name} at"), d.at)?)?;
            let law = interaction_law(&name, &d.law)?;
            let pair = self.pair(name);
            // Relative displacement u = z_j - point . q; upper wall: g = upper - u,
            // lower wall: g = lower + u.
            for (sign, offset) in [(-1.0, upper), (1.0, lower)] {
                if offset.is_infinite() {
                    continue; // no wall on this side
                }
                let mut h = vec![0.0; dim];
                for i in 0..n {
                    h[i] = -sign * point[i];
                }
                h[n + j] = sign;
                self.wall(pair, h, offset, law);
            }
        }
        Ok(())
    }

    /// Each stop's wall (pushes left to fill).
    fn add_stops(&mut self, spec: &SystemSpec, n: usize, dim: usize) -> Result<()> {
        let s = &spec.structure;
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
            let pair = self.pair(name);
            self.wall(pair, h, gap, law);
        }
        Ok(())
    }

    /// Each collision's wall: the gap `gap - (z_lower - z_upper)` between
    /// two loose masses (pushes left to fill).
    fn add_collisions(&mut self, spec: &SystemSpec, n: usize, dim: usize) -> Result<()> {
        let k = spec.dampers.len();
        for (c, collision) in spec.collisions.iter().enumerate() {
            let name = format!("collision {c}");
            let [lower, upper] = collision.dampers;
            if lower >= k || upper >= k || lower == upper {
                return Err(Error::Inconsistent(format!(
                    "{name} dampers: must be two different dampers among the {k} \
                     [[damper]] (0 to {}), got [{lower}, {upper}]",
                    k.saturating_sub(1)
                )));
            }
            let gap = non_negative_named(&name, "gap", collision.gap)?;
            let law = interaction_law(&name, &collision.law)?;
            let mut h = vec![0.0; dim];
            h[n + lower] = -1.0;
            h[n + upper] = 1.0;
            let pair = self.pair(name);
            self.wall(pair, h, gap, law);
        }
        Ok(())
    }
}

impl Walls {
    /// Each friction element's row: a damper's displacement relative to its
    /// carrier, or a point's relative to another's or to the base (pushes
    /// left to fill). Its "gap" is not a distance: only its rate, the
    /// sliding velocity, is read.
    fn add_frictions(&mut self, spec: &SystemSpec, n: usize, dim: usize) -> Result<()> {
        let s = &spec.structure;
        let k = spec.dampers.len();
        // A [[friction]] element is named by its place among the elements, not
        // among every friction (a damper's own is named by its damper).
        let mut elements = 0;
        for friction in &spec.frictions {
            let (name, h) = match friction.site {
                FrictionSite::Damper(j) => {
                    let name = format!("damper {j} friction");
                    if j >= k {
                        return Err(Error::Inconsistent(format!(
                            "{name}: there are {k} [[damper]]"
                        )));
                    }
                    let point = s.point(&format!("damper {j} at"), spec.dampers[j].at)?;
                    let mut h = vec![0.0; dim];
                    for i in 0..n {
                        h[i] = -point[i];
                    }
                    h[n + j] = 1.0;
                    (name, h)
                }
                FrictionSite::Points { at, against } => {
                    let name = format!("friction {elements}");
                    elements += 1;
                    let mut point = s.point(&format!("{name} at"), at)?;
                    if let Some(against) = against {
                        let other = s.point(&format!("{name} against"), against)?;
                        for (p, c) in point.iter_mut().zip(&other) {
                            *p -= c;
                        }
                        if point.iter().all(|p| *p == 0.0) {
                            return Err(Error::Inconsistent(format!(
                                "{name} against: {against} moves as at = {at} does, so they \
                                 never slide on each other: choose another point"
                            )));
                        }
                    }
                    let mut h = vec![0.0; dim];
                    h[..n].copy_from_slice(&point);
                    (name, h)
                }
            };
            // A damper's friction is written with the damper's keys.
            let (label, kinetic_key, static_key) = match friction.site {
                FrictionSite::Damper(j) => (format!("damper {j}"), "friction", "static_friction"),
                FrictionSite::Points { .. } => (name.clone(), "coefficient", "static_coefficient"),
            };
            let kinetic = non_negative_named(&label, kinetic_key, friction.coefficient)?;
            let normal = non_negative_named(&label, "normal_force", friction.normal_force)?;
            let held = non_negative_named(&label, static_key, friction.static_coefficient)?;
            if held < kinetic {
                return Err(Error::Inconsistent(format!(
                    "{label} {static_key}: must be >= {kinetic_key} {kinetic}, got {held}"
                )));
            }
            let (kinetic_force, static_force) = (kinetic * normal, held * normal);
            if !(kinetic_force.is_finite() && static_force.is_finite()) {
                return Err(Error::Inconsistent(format!(
                    "{name}: its friction force (coefficient times normal_force) must be \
                     finite, got {static_force} N"
                )));
            }
            // Every element is a pair, one of no force or merged with another too:
            // a study's runs then have the same pairs whatever their values.
            let pair = self.pair(name);
            if static_force == 0.0 {
                continue; // no force: no element
            }
            if let FrictionSite::Damper(j) = friction.site {
                // Held by rigid walls at no clearance, it never slides: its
                // friction would be a second constraint on the walls' row
                // (runs stopped as chattering), and does no work.
                let d = &spec.dampers[j];
                let rigid = matches!(d.law, PairLaw::Rigid { .. });
                if rigid && d.lower_clearance == 0.0 && d.upper_clearance == 0.0 {
                    continue;
                }
            }
            // Pads on one row (the same points, either way round) act as one:
            // their forces add (two constraints on one row would be one).
            if let Some(same) = self.interactions.iter_mut().find(|it| {
                it.law.is_friction() && (it.h == h || it.h.iter().zip(&h).all(|(a, b)| *a == -*b))
            }) {
                if let InteractionLaw::Friction {
                    kinetic_force: k,
                    static_force: s,
                } = &mut same.law
                {
                    *k += kinetic_force;
                    *s += static_force;
                }
                continue;
            }
            self.wall(
                pair,
                h,
                0.0,
                InteractionLaw::Friction {
                    kinetic_force,
                    static_force,
                },
            );
        }
        Ok(())
    }
}

/// The force excitations with their rows and pushes (`minv`: `M^-1`), and
/// the base signals.
fn excitation_loads(spec: &SystemSpec, minv: &[f64]) -> Result<(Vec<ForceLoad>, Vec<Signal>)> {
    let s = &spec.structure;
    let n = s.dofs();
    let mut forces = Vec::new();
    let mut base = Vec::new();
    for (j, excitation) in spec.excitations.iter().enumerate() {
        // A signal written as a literal has skipped its constructor's checks.
        excitation
            .signal
            .check()
            .map_err(|e| Error::Inconsistent(format!("excitation {j} signal: {e}")))?;
        match excitation.load {
            Load::Force { at } => {
                let name = format!("excitation {j}");
                let row = moving(&name, at, s.point(&format!("{name} at"), at)?)?;
                let mut push = vec![0.0; n];
                linalg::multiply(minv, &row, &mut push);
                forces.push(ForceLoad {
                    row,
                    push,
                    signal: excitation.signal.clone(),
                });
            }
            Load::Base => base.push(excitation.signal.clone()),
        }
    }
    Ok((forces, base))
}

/// The structure's `row` at `at` (m) of the part `name`, refused where no mode
/// moves there (a cantilever's clamp): a damper there rattles in a box that
/// never moves and a force there does no work, both silently (a stop or a
/// friction element there is refused as acting at a point that does not move).
fn moving(name: &str, at: f64, row: Vec<f64>) -> Result<Vec<f64>> {
    if row.iter().all(|&v| v == 0.0) {
        return Err(Error::Inconsistent(format!(
            "{name} at = {at} m is a point that does not move (every mode has a node there, \
             as at a cantilever's clamp): move it"
        )));
    }
    Ok(row)
}

/// The rows of the points, then of the moments, the reductions follow
/// (checked against [`MAX_POINTS`]).
fn followed_rows(spec: &SystemSpec) -> Result<Vec<f64>> {
    let s = &spec.structure;
    let followed = spec.points.len() + spec.moments.len();
    if followed > MAX_POINTS {
        return Err(Error::Inconsistent(format!(
            "points: at most {MAX_POINTS} points and moments may be followed, got {followed}"
        )));
    }
    let mut point_rows = Vec::with_capacity(followed * s.dofs());
    for (j, &at) in spec.points.iter().enumerate() {
        point_rows.extend(s.point(&format!("[output] points[{j}]"), at)?);
    }
    for (j, &at) in spec.moments.iter().enumerate() {
        point_rows.extend(s.moment_row(&format!("[output] moments[{j}]"), at)?);
    }
    Ok(point_rows)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::assembly::Damper;

    fn with_clearances(lower: f64, upper: f64) -> SystemSpec {
        let damper = Damper {
            mass: 0.05,
            at: 0.0,
            lower_clearance: lower,
            upper_clearance: upper,
            law: PairLaw::rigid(0.6).unwrap(),
        };
        SystemSpec {
            gravity: 9.81,
            ..SystemSpec::of(
                Structure::oscillator(1.0, 400.0, 0.5).unwrap(),
                vec![damper],
            )
        }
    }

    #[test]
    fn a_collision_is_a_wall_between_two_loose_masses() {
        crate::testing::timeout(10, || {
            use crate::model::assembly::Collision;
            let mut spec = with_clearances(2e-3, f64::INFINITY);
            let mut upper = spec.dampers[0].clone();
            (upper.mass, upper.lower_clearance, upper.upper_clearance) = (0.2, f64::INFINITY, 0.1);
            spec.dampers.push(upper);
            spec.collisions.push(Collision {
                dampers: [0, 1],
                gap: 5e-3,
                law: PairLaw::rigid(0.8).unwrap(),
            });
            let system = Assembly::new(&spec).unwrap();
            assert_eq!(system.pairs, ["damper 0", "damper 1", "collision 0"]);
            let it = &system.interactions[2];
            // g = gap - (y_0 - y_1) over (x, y_0, y_1); pushes 1/m on each mass.
            assert_eq!(
                (it.h.as_slice(), it.offset),
                ([0.0, -1.0, 1.0].as_slice(), 5e-3)
            );
            assert_eq!(it.push, vec![0.0, -1.0 / 0.05, 1.0 / 0.2]);
            assert!((it.inverse_mass - (1.0 / 0.05 + 1.0 / 0.2)).abs() < 1e-12);
            // A damper with no wall at all is held by its collision alone.
            spec.dampers[1].upper_clearance = f64::INFINITY;
            assert!(Assembly::new(&spec).is_ok());
            spec.collisions.clear();
            let err = Assembly::new(&spec).unwrap_err().to_string();
            assert!(
                err.contains("damper 1") && err.contains("[[collision]]"),
                "{err}"
            );
            for (dampers, gap) in [([1, 1], 0.0), ([1, 2], 0.0), ([0, 1], -1e-3)] {
                // Each names damper 1, so that its lack of walls passes and the
                // collision's own error is the one met.
                spec.collisions = vec![Collision {
                    dampers,
                    gap,
                    law: PairLaw::rigid(0.8).unwrap(),
                }];
                let err = Assembly::new(&spec).unwrap_err().to_string();
                assert!(err.contains("collision 0"), "{err}");
            }
        });
    }

    #[test]
    fn an_infinite_clearance_is_a_side_with_no_wall() {
        crate::testing::timeout(10, || {
            // Both walls: the upper's gap closes as the loose mass (coordinate
            // 1) rises, the lower's as it falls.
            let both = Assembly::new(&with_clearances(2e-3, 3e-3)).unwrap();
            let rows: Vec<(f64, f64)> = both
                .interactions
                .iter()
                .map(|it| (it.h[1], it.offset))
                .collect();
            assert_eq!(rows, vec![(-1.0, 3e-3), (1.0, 2e-3)]);
            // No upper wall: the lower alone, as it was.
            let floor = Assembly::new(&with_clearances(2e-3, f64::INFINITY)).unwrap();
            assert_eq!(floor.interactions.len(), 1);
            assert_eq!(floor.interactions[0], both.interactions[1]);
            assert_eq!(floor.pairs, vec!["damper 0".to_string()]);
            let ceiling = Assembly::new(&with_clearances(f64::INFINITY, 3e-3)).unwrap();
            assert_eq!(ceiling.interactions.len(), 1);
            assert_eq!(ceiling.interactions[0], both.interactions[0]);
            // Neither: refused, as are a negative and a NaN clearance or -inf.
            for (lower, upper) in [
                (f64::INFINITY, f64::INFINITY),
                (-1e-3, 1e-3),
                (1e-3, f64::NAN),
                (f64::NEG_INFINITY, 1e-3),
            ] {
                let err = Assembly::new(&with_clearances(lower, upper)).unwrap_err();
                assert!(err.to_string().contains("damper 0"), "{err}");
            }
        });
    }
}
