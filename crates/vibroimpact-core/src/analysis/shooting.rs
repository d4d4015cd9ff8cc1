//! Shooting for periodic orbits: Newton's method on `P(z) - z = 0`, `P` a
//! stroboscopic map, with its Jacobian from the tangent flow through the
//! impacts ([`shoot_by_tangent`], exact) or by central differences
//! ([`shoot`]: across impacts the differences include the saltation). At the
//! orbit the Jacobian is the monodromy matrix, whose eigenvalues are the
//! Floquet multipliers.

use crate::analysis::settling;
use crate::error::{Error, Result};
use crate::numerics::linalg;

/// What a shooting found.
#[derive(Debug, Clone, PartialEq)]
pub struct Shot {
    pub state: Vec<f64>,
    /// `dP/dz` at `state`, row-major.
    pub monodromy: Vec<f64>,
    pub converged: bool,
    pub iterations: usize,
    /// `max |P(z) - z|`, displacements relative to the size of the motion
    /// and velocities to that times the forcing's angular frequency (see
    /// [`shoot`]).
    pub residual: f64,
    /// Maps evaluated.
    pub maps: usize,
    /// Why the last Newton step was given up (every fraction of it refused).
    pub refusal: Option<String>,
}

/// A start the map refuses (inside a wall) is a bad Newton step, not a failure.
fn refused(e: &Error) -> bool {
    matches!(e, Error::Inconsistent(_) | Error::InvalidParameter { .. })
}

/// A Newton iterate whose run fails numerically (it blew up, its energy
/// balance broke, it chattered or its steps shrank to nothing: a step far
/// off the orbit, into motions the method's settings do not resolve) is a
/// bad step too, to be shortened; a run's limits (steps, rows, memory, an
/// interrupt) are not.
fn bad_step(e: &Error) -> bool {
    refused(e)
        || matches!(
            e,
            Error::NumericalBlowUp { .. }
                | Error::UnresolvedContact { .. }
                | Error::NewtonFailed { .. }
                | Error::Chattering { .. }
                | Error::StepSizeTooSmall { .. }
                | Error::EnergyBalance { .. }
                | Error::ContactEnergy { .. }
        )
}

/// Shoot from `z0` (displacements then velocities) for `P(z) = z`.
///
/// The residual and the Jacobian's steps are scaled by the size of the motion,
/// as settling judges it: each coordinate's `(x, v)` counts as the amplitude
/// `hypot(x, v / w)`, w = 2 pi / `forcing_period` (s), displacements relative
/// to the largest and velocities to that times w. Scaled by the strobed
/// displacements alone, an orbit strobed at its zero crossing (a linear
/// oscillator at resonance) had a scale of round-off and was never found.
pub fn shoot(
    map: &mut dyn FnMut(&[f64]) -> Result<Vec<f64>>,
    z0: &[f64],
    forcing_period: f64,
    tolerance: f64,
    max_iterations: usize,
) -> Result<Shot> {
    check_shooting(z0, forcing_period, tolerance)?;
    let size = z0.len();
    let mut checked = |z: &[f64]| sized("the map's image", map(z)?, size);
    let mut by = Differences { map: &mut checked };
    newton(&mut by, z0, forcing_period, tolerance, max_iterations)
}

/// [`shoot`] with the Jacobian of the tangent flow: `run` maps `z` and
/// returns its image with the derivative of the image by `z` (row-major),
/// each Newton iteration's one run giving both.
pub fn shoot_by_tangent(
    run: &mut TangentMap<'_>,
    z0: &[f64],
    forcing_period: f64,
    tolerance: f64,
    max_iterations: usize,
) -> Result<Shot> {
    check_shooting(z0, forcing_period, tolerance)?;
    let size = z0.len();
    let mut checked = |z: &[f64]| {
        let (image, matrix) = run(z)?;
        Ok((
            sized("the map's image", image, size)?,
            sized("the map's Jacobian", matrix, size * size)?,
        ))
    };
    let mut by = ByTangent {
        run: &mut checked,
        last: None,
    };
    newton(&mut by, z0, forcing_period, tolerance, max_iterations)
}

/// Refuses a shooting no map can serve: a start `z0` of displacements then
/// velocities (an even number of values, at least 2, finite), a forcing
/// period and a tolerance in the registry's ranges.
fn check_shooting(z0: &[f64], forcing_period: f64, tolerance: f64) -> Result<()> {
    use crate::methods::registry::{FORCING_PERIOD, TOLERANCE};
    FORCING_PERIOD.check(forcing_period)?;
    TOLERANCE.check(tolerance)?;
    if z0.is_empty() || z0.len() % 2 != 0 {
        return Err(Error::Inconsistent(format!(
            "a shooting starts from displacements then velocities (an even number of values, \
             at least 2), got {}",
            z0.len()
        )));
    }
    match z0.iter().position(|v| !v.is_finite()) {
        Some(at) => Err(Error::Inconsistent(format!(
            "a shooting's start must be finite: value {at} is {}",
            z0[at]
        ))),
        None => Ok(()),
    }
}

/// `values`, where there are `len` of them: what a map must return.
fn sized(what: &str, values: Vec<f64>, len: usize) -> Result<Vec<f64>> {
    if values.len() == len {
        Ok(values)
    } else {
        Err(Error::Inconsistent(format!(
            "{what} must have {len} values, got {}",
            values.len()
        )))
    }
}

/// A map that returns its image with its Jacobian (row-major).
pub type TangentMap<'m> = dyn FnMut(&[f64]) -> Result<(Vec<f64>, Vec<f64>)> + 'm;

/// How Newton's method evaluates the map and its Jacobian.
trait Evaluate {
    fn map(&mut self, z: &[f64]) -> Result<Vec<f64>>;
    /// The Jacobian at `z`, whose image is `image`; `scale` is the motion's
    /// size per coordinate; `maps` counts the maps evaluated.
    fn jacobian(
        &mut self,
        z: &[f64],
        image: &[f64],
        scale: &[f64],
        maps: &mut usize,
    ) -> Result<Vec<f64>>;
}

/// Central differences of the map.
struct Differences<'m> {
    map: &'m mut dyn FnMut(&[f64]) -> Result<Vec<f64>>,
}

impl Evaluate for Differences<'_> {
    fn map(&mut self, z: &[f64]) -> Result<Vec<f64>> {
        (self.map)(z)
    }

    fn jacobian(
        &mut self,
        z: &[f64],
        image: &[f64],
        scale: &[f64],
        maps: &mut usize,
    ) -> Result<Vec<f64>> {
        jacobian(self.map, z, image, scale, maps)
    }
}

/// The tangent flow: each map's run carries its Jacobian, kept for the
/// iteration that asks for it.
struct ByTangent<'m> {
    run: &'m mut TangentMap<'m>,
    last: Option<(Vec<f64>, Vec<f64>)>,
}

impl Evaluate for ByTangent<'_> {
    fn map(&mut self, z: &[f64]) -> Result<Vec<f64>> {
        let (image, matrix) = (self.run)(z)?;
        self.last = Some((z.to_vec(), matrix));
        Ok(image)
    }

    fn jacobian(
        &mut self,
        z: &[f64],
        _image: &[f64],
        _scale: &[f64],
        maps: &mut usize,
    ) -> Result<Vec<f64>> {
        match self.last.take() {
            Some((at, matrix)) if at == z => Ok(matrix),
            _ => {
                *maps += 1;
                Ok((self.run)(z)?.1)
            }
        }
    }
}

/// Newton's method on `P(z) = z` (see [`shoot`]).
fn newton(
    by: &mut dyn Evaluate,
    z0: &[f64],
    forcing_period: f64,
    tolerance: f64,
    max_iterations: usize,
) -> Result<Shot> {
    let size = z0.len();
    let dim = size / 2;
    let mut maps = 0usize;
    let slow = settling::per_radian(forcing_period);
    let scales = |z: &[f64], image: &[f64]| {
        let x = (0..dim)
            .flat_map(|i| {
                [
                    settling::amplitude(z[i], z[dim + i], slow),
                    settling::amplitude(image[i], image[dim + i], slow),
                ]
            })
            .fold(1e-12f64, f64::max);
        (0..size)
            .map(|i| if i < dim { x } else { x / slow })
            .collect::<Vec<f64>>()
    };
    let mut z = z0.to_vec();
    maps += 1;
    let mut image = by.map(&z)?;
    let residual_of = |z: &[f64], image: &[f64], scale: &[f64]| {
        (0..size)
            .map(|i| (image[i] - z[i]).abs() / scale[i])
            .fold(0.0f64, f64::max)
    };
    let (mut residual, mut converged, mut iterations) = (f64::INFINITY, false, 0);
    let mut refusal = None;
    while iterations < max_iterations {
        iterations += 1;
        let scale = scales(&z, &image);
        residual = residual_of(&z, &image, &scale);
        if residual <= tolerance {
            converged = true;
            break;
        }
        let jac = by.jacobian(&z, &image, &scale, &mut maps)?;
        let mut system = jac.clone();
        for i in 0..size {
            system[i * size + i] -= 1.0;
        }
        let mut step: Vec<f64> = (0..size).map(|i| z[i] - image[i]).collect();
        linalg::solve_in_place(&mut system, &mut step, size);
        let mut factor = 1.0;
        let stalled = loop {
            let trial: Vec<f64> = z.iter().zip(&step).map(|(z, s)| z + factor * s).collect();
            maps += 1;
            match by.map(&trial) {
                // A step far beyond the motion whose residual grows as far is
                // a diverging iteration (a hertz damper's iterates reached
                // 6.6e4 m/s, each map a run of seconds, then minutes):
                // shortened as a step a map refuses.
                Ok(next) if diverges((&z, &trial), (&next, &scale), residual) => {
                    if factor > 1e-6 {
                        factor *= 0.5;
                        continue;
                    }
                    refusal = Some(
                        "every fraction of the Newton step took the state ten times beyond the \
                         motion, its residual ten times further: the iteration diverges"
                            .to_string(),
                    );
                    break true;
                }
                Ok(next) => {
                    z = trial;
                    image = next;
                    break false;
                }
                Err(e) if bad_step(&e) && factor > 1e-6 => factor *= 0.5,
                // Even a millionth of the step is inside a wall (or fails):
                // the step is Newton's breakdown (a nearly singular I - J),
                // not a start the user gave; the shooting stops, not
                // converged.
                Err(e) if bad_step(&e) => {
                    refusal = Some(e.to_string());
                    break true;
                }
                Err(e) => return Err(e),
            }
        };
        if stalled {
            break;
        }
    }
    if !converged {
        let scale = scales(&z, &image);
        residual = residual_of(&z, &image, &scale);
        converged = residual <= tolerance;
    }
    let scale = scales(&z, &image);
    let monodromy = by.jacobian(&z, &image, &scale, &mut maps)?;
    Ok(Shot {
        state: z,
        monodromy,
        converged,
        iterations,
        residual,
        maps,
        refusal,
    })
}

/// How far beyond the motion (and its residual) a Newton step diverges.
const DIVERGING: f64 = 10.0;

/// Whether the Newton step from `z` to `trial` (its image `next`) diverges:
/// its largest coordinate beyond [`DIVERGING`] times the motion's size
/// (`scale`, per coordinate, as the residual takes it) and its residual in
/// that scale beyond [`DIVERGING`] times `residual`, the iterate's.
fn diverges((z, trial): (&[f64], &[f64]), (next, scale): (&[f64], &[f64]), residual: f64) -> bool {
    let beyond = |values: &[f64]| {
        values
            .iter()
            .zip(scale)
            .map(|(v, s)| v.abs() / s)
            .fold(0.0f64, f64::max)
    };
    let far = beyond(trial) > DIVERGING * beyond(z).max(1.0);
    let missed: Vec<f64> = next.iter().zip(trial).map(|(n, t)| n - t).collect();
    far && beyond(&missed) > DIVERGING * residual
}

/// Relative disagreement of the one-sided differences beyond which a column's
/// step is taken to straddle a change of the map's smooth piece.
const ONE_SIDED_AGREEMENT: f64 = 1e-2;
/// Steps tried per column: 1e-6, 1e-8 and 1e-10 of `scale`.
const STEP_TRIALS: usize = 3;

/// The central-difference Jacobian of `map` at `z` (`image = map(z)`), steps
/// of 1e-6 of `scale`; one-sided where one side is refused (inside a wall).
/// Near a grazing a step may carry one side of the difference onto a
/// trajectory that touches a wall the orbit misses (or misses one it
/// touches): the one-sided differences then disagree, far beyond the map's
/// curvature, and the column is taken again with a step a hundred times
/// shorter (keeping the most consistent one), so the multipliers are those
/// of the orbit's own smooth piece.
fn jacobian(
    map: &mut dyn FnMut(&[f64]) -> Result<Vec<f64>>,
    z: &[f64],
    image: &[f64],
    scale: &[f64],
    maps: &mut usize,
) -> Result<Vec<f64>> {
    let size = z.len();
    let mut jac = vec![0.0; size * size];
    for j in 0..size {
        let mut best: Option<(f64, Vec<f64>)> = None;
        let mut h = 1e-6 * scale[j];
        for _ in 0..STEP_TRIALS {
            let (column, disagreement) = difference(map, z, image, j, h, maps)?;
            let consistent = disagreement <= ONE_SIDED_AGREEMENT;
            if best.as_ref().is_none_or(|(d, _)| disagreement < *d) {
                best = Some((disagreement, column));
            }
            if consistent {
                break;
            }
            h *= 1e-2;
        }
        let (_, column) = best.expect("at least one step is tried");
        for i in 0..size {
            jac[i * size + j] = column[i];
        }
    }
    Ok(jac)
}

/// Column `j` of the Jacobian by differences of step `h`, and how far its
/// forward and backward differences disagree (relative to their size; 0
/// where one side is refused and the difference is one-sided).
fn difference(
    map: &mut dyn FnMut(&[f64]) -> Result<Vec<f64>>,
    z: &[f64],
    image: &[f64],
    j: usize,
    h: f64,
    maps: &mut usize,
) -> Result<(Vec<f64>, f64)> {
    let (mut plus, mut minus) = (z.to_vec(), z.to_vec());
    plus[j] += h;
    minus[j] -= h;
    *maps += 2;
    let up = map(&plus);
    let down = map(&minus);
    Ok(match (up, down) {
        (Ok(a), Ok(b)) => {
            let (mut gap, mut size) = (0.0f64, 0.0f64);
            let column = (0..z.len())
                .map(|i| {
                    let (forward, backward) = ((a[i] - image[i]) / h, (image[i] - b[i]) / h);
                    gap = gap.max((forward - backward).abs());
                    size = size.max(forward.abs() + backward.abs());
                    (a[i] - b[i]) / (2.0 * h)
                })
                .collect();
            (column, if size > 0.0 { gap / size } else { 0.0 })
        }
        (Ok(a), Err(e)) if refused(&e) => {
            (a.iter().zip(image).map(|(a, b)| (a - b) / h).collect(), 0.0)
        }
        (Err(e), Ok(b)) if refused(&e) => (
            image.iter().zip(&b).map(|(a, b)| (a - b) / h).collect(),
            0.0,
        ),
        (Err(e), _) | (_, Err(e)) => return Err(e),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    /// `P(z) = 2 z + 1` has its fixed point at z = -1, where the "wall" z[0] >= 0
    /// refuses to start: each Newton step from z >= 0 points inside it.
    fn walled(z: &[f64]) -> Result<Vec<f64>> {
        if z[0] < 0.0 {
            return Err(Error::Inconsistent("inside the wall".into()));
        }
        Ok(z.iter().map(|z| 2.0 * z + 1.0).collect())
    }

    #[test]
    fn a_newton_step_that_stays_inside_a_wall_ends_the_shooting_unconverged() {
        crate::testing::timeout(60, || {
            let shot = shoot(&mut walled, &[1.0, 1.0], TAU, 1e-10, 40).unwrap();
            assert!(!shot.converged);
            // Halved to the wall (z[0] = 0, to the halvings' resolution), where no
            // fraction of the next step is admissible.
            assert!((0.0..1e-5).contains(&shot.state[0]), "{}", shot.state[0]);
            assert!(shot.iterations < 40, "{}", shot.iterations);
        });
    }

    #[test]
    fn a_newton_step_whose_run_blows_up_is_shortened() {
        crate::testing::timeout(60, || {
            // P(x) = x - (x^3 - 1) / 3 (fixed point 1), its run failing
            // beyond |x| = 10 as a method's does far off its resolution. From
            // 0.1 Newton's first step reaches 111: halved, not an error.
            let mut cubic = |z: &[f64]| -> Result<Vec<f64>> {
                if z[0].abs() > 10.0 {
                    return Err(Error::EnergyBalance {
                        time: 0.1,
                        residual: 1.0,
                        scale: 1.0,
                        tolerance: 1e-6,
                        advice: crate::error::EnergyAdvice::Any,
                    });
                }
                Ok(vec![z[0] - (z[0].powi(3) - 1.0) / 3.0, 0.5 * z[1]])
            };
            let shot = shoot(&mut cubic, &[0.1, 0.0], TAU, 1e-10, 40).unwrap();
            assert!(shot.converged, "{shot:?}");
            assert!((shot.state[0] - 1.0).abs() < 1e-9, "{}", shot.state[0]);
        });
    }

    #[test]
    fn a_kink_within_the_difference_step_does_not_enter_the_monodromy() {
        crate::testing::timeout(60, || {
            // P has its fixed point at z0 = 1, where its slope is 2; a kink (a
            // grazing's new impact) 1e-7 beyond it, inside the first difference
            // step (1e-6 of the scale), steepens the map to slope 102. The
            // orbit's multiplier is 2; the straddling difference gave 47.
            let mut map = |z: &[f64]| -> Result<Vec<f64>> {
                let kink = 100.0 * (z[0] - (1.0 + 1e-7)).max(0.0);
                Ok(vec![2.0 * z[0] - 1.0 + kink, 0.5 * z[1]])
            };
            let shot = shoot(&mut map, &[1.0, 0.0], TAU, 1e-12, 40).unwrap();
            assert!(shot.converged);
            assert!(
                (shot.monodromy[0] - 2.0).abs() < 1e-6,
                "{}",
                shot.monodromy[0]
            );
            assert!(
                (shot.monodromy[3] - 0.5).abs() < 1e-6,
                "{}",
                shot.monodromy[3]
            );
        });
    }

    #[test]
    fn an_admissible_fixed_point_is_found() {
        crate::testing::timeout(60, || {
            // P(z) = 2 z - 1, nothing refused: the fixed point z = 1.
            let mut map =
                |z: &[f64]| -> Result<Vec<f64>> { Ok(z.iter().map(|z| 2.0 * z - 1.0).collect()) };
            let shot = shoot(&mut map, &[3.0, 0.5], TAU, 1e-12, 40).unwrap();
            assert!(shot.converged);
            for z in &shot.state {
                assert!((z - 1.0).abs() < 1e-12, "{z}");
            }
            // The monodromy of a linear map is its matrix: 2 I.
            assert!((shot.monodromy[0] - 2.0).abs() < 1e-9 && shot.monodromy[1].abs() < 1e-9);
        });
    }

    #[test]
    fn an_orbit_strobed_at_its_zero_crossing_is_found() {
        crate::testing::timeout(60, || {
            // A damped oscillator forced at resonance (w = 2 pi rad/s), strobed
            // where its displacement crosses zero: about z* = (1e-10 m, 1 m/s) the
            // map turns (x, v / w) by 0.01 rad and shrinks it by a = 0.939, its
            // displacement computed, as a flow computes it, from terms of the
            // motion's size (0.16 m), whose round-off it keeps. Scaled by the
            // displacements alone (1e-10 m) that round-off was a residual of 1e-7
            // and Newton never converged.
            let (a, angle, fixed, slow) = (0.939, 0.01f64, [1e-10, 1.0], 1.0 / TAU);
            let mut map = |z: &[f64]| -> Result<Vec<f64>> {
                let (dx, dv) = (z[0] - fixed[0], (z[1] - fixed[1]) * slow);
                let x = a * (angle.cos() * dx + angle.sin() * dv);
                let v = a * (angle.cos() * dv - angle.sin() * dx);
                let size = 0.16;
                Ok(vec![(fixed[0] + x + size) - size, fixed[1] + v / slow])
            };
            let shot = shoot(&mut map, &[0.0, 0.0], 1.0, 1e-10, 40).unwrap();
            assert!(shot.converged, "{}", shot.residual);
            assert!(shot.iterations <= 3, "{}", shot.iterations);
            assert!((shot.state[1] - 1.0).abs() < 1e-8, "{}", shot.state[1]);
            // The multipliers a e^(+-0.01 i): trace 2 a cos 0.01, determinant a^2.
            let m = &shot.monodromy;
            let (trace, det) = (m[0] + m[3], m[0] * m[3] - m[1] * m[2]);
            assert!((trace - 2.0 * a * angle.cos()).abs() < 1e-6, "{trace}");
            assert!((det - a * a).abs() < 1e-6, "{det}");
        });
    }
}
