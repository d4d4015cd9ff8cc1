//! The state vector: its length, what the reductions observe of it, and the
//! initial or resumed state checked against the system.

use super::{Assembly, InteractionLaw, CONTACT};
use crate::error::{finite, Error, Result};
use crate::numerics::linalg;

impl Assembly {
    /// Length of the state vector: `x`, `v` and the accumulators.
    pub fn state_len(&self) -> usize {
        2 * self.dim + CONTACT + self.interactions.len()
    }

    /// Interactions (a pair's walls, each with its law): the length of the
    /// modes a stepper is given.
    pub fn interaction_count(&self) -> usize {
        self.interactions.len()
    }

    /// Whether any pair is rigid (only those stick or take impacts).
    pub fn has_rigid(&self) -> bool {
        self.interactions
            .iter()
            .any(|it| matches!(it.law, InteractionLaw::Rigid { .. }))
    }

    /// Whether any friction element acts (stick-slip: its stuck constraint
    /// is solved with the sticking pairs').
    pub fn has_friction(&self) -> bool {
        self.interactions.iter().any(|it| it.law.is_friction())
    }

    /// The quantities the reductions follow: each structure coordinate, then
    /// each point of [`super::SystemSpec::points`], then each moment.
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
}

/// The initial state vector from the four arrays of `[initial]` (zeros where
/// empty), checked against the system's sizes and finite; no rigid pair
/// inside its wall (a compliant one may be, pressed in).
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
/// [`initial_state`] but a rigid pair within the drift of a method's
/// solution inside its wall is put back on it.
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
        // A friction element's row is no gap: it has no wall to be inside.
        // A compliant pair may start pressed into its wall (a damper resting
        // on its seat under gravity): its force is the law's at that depth,
        // and the kernel takes the contact as one in progress.
        if matches!(it.law, InteractionLaw::Compliant { .. }) || it.law.is_friction() {
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
