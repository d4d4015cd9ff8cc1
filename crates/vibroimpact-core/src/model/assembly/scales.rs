//! The system's scales, found once when it is assembled: its time scales,
//! the energy floor's and the rigid pairs' least gap scale.

use super::spec::{Load, SystemSpec};
use super::Interaction;
use crate::numerics::linalg;

/// The system's `Assembly::gap_floor`, m: a thousandth of the smallest free
/// distance at rest of its pairs, or where every pair touches at rest, of
/// the length its accelerations move it over its time scale
/// (`motion_length`; 0 for none).
pub(super) fn gap_floor(interactions: &[Interaction], motion_length: f64) -> f64 {
    let smallest = interactions
        .iter()
        .filter(|it| !it.law.is_friction())
        .map(|it| it.offset.abs())
        .filter(|o| *o > 0.0 && o.is_finite())
        .fold(f64::INFINITY, f64::min);
    if smallest.is_finite() {
        1e-3 * smallest
    } else if motion_length.is_finite() {
        1e-3 * motion_length
    } else {
        0.0
    }
}

/// The system's time scales (s) and the energy floor's mass times
/// acceleration squared (see [`super::Assembly::energy_floor`]).
pub(super) struct TimeScales {
    /// The shortest natural or forcing period (infinite for none).
    pub(super) shortest: f64,
    pub(super) longest_period: f64,
    pub(super) time_scale: f64,
    pub(super) floor_mass_acceleration: f64,
    /// The length the largest acceleration acting moves the system over its
    /// time scale, `a (T / 2 pi)^2` (m; a harmonic motion's amplitude at the
    /// period `T`): infinite without a time scale, 0 without an
    /// acceleration.
    pub(super) motion_length: f64,
    /// The finest interval over which a signal that is not a sum of
    /// harmonics changes (s), with its signal's name.
    pub(super) finest_signal: Option<(f64, &'static str)>,
}

impl TimeScales {
    pub(super) fn of(
        spec: &SystemSpec,
        mass_influence: &[f64],
        damper_mass: &[f64],
        gravity: f64,
        interactions: &[Interaction],
    ) -> Self {
        let s = &spec.structure;
        let frequencies = s.natural_frequencies();
        let fastest_natural = frequencies.iter().fold(0.0f64, |m, w| m.max(*w));
        let mut shortest = if fastest_natural > 0.0 {
            std::f64::consts::TAU / fastest_natural
        } else {
            f64::INFINITY
        };
        let total_mass: f64 =
            linalg::dot(mass_influence, s.influence()) + damper_mass.iter().sum::<f64>();
        let mut acceleration = gravity;
        let mut finest_signal: Option<(f64, &'static str)> = None;
        for excitation in &spec.excitations {
            let (largest, period) = excitation.signal.extent();
            shortest = shortest.min(period);
            // A record's or random signal's shortest sample interval (half its
            // extent's period), a sweep's half period at its highest frequency.
            let interval = 0.5 * period;
            if excitation.signal.has_breakpoints()
                && finest_signal.is_none_or(|(f, _)| interval < f)
            {
                finest_signal = Some((interval, excitation.signal.harmonic_frequencies().0));
            }
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
        Self {
            shortest,
            longest_period,
            time_scale,
            floor_mass_acceleration: total_mass * acceleration * acceleration,
            motion_length: acceleration * (time_scale / std::f64::consts::TAU).powi(2),
            finest_signal,
        }
    }
}
