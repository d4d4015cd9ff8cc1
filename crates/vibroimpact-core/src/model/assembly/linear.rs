//! The system between contacts as a linear one (what the exact flow takes).

use super::{Assembly, InteractionLaw};
use crate::error::{Error, Result};
use crate::model::signals::Signal;

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
