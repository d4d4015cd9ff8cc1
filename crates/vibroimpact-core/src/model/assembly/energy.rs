//! The stored energy and the scales a balance residual is judged against.

use super::gaps::h_dot;
use super::{Assembly, InteractionLaw, Mode};
use crate::model::contact::ContactLaw;
use crate::numerics::linalg;

impl Assembly {
    /// Whether nothing forces the system (energy can then only fall).
    pub fn is_free(&self) -> bool {
        self.forces.is_empty() && self.base.is_empty()
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
}
