//! Excitation signals: functions of time that scale a force (N) or a base
//! acceleration (m/s^2). Deterministic ones are evaluated in closed form;
//! random ones are generated once from a seed into samples that are then
//! interpolated linearly, so a run reads them without allocating (their
//! generators: [`crate::model::noise`]).

use crate::error::{finite, non_negative, positive, Error, Result};

/// Most samples a generated or recorded signal may hold (8 bytes each: 800 MB).
pub const MAX_SIGNAL_SAMPLES: usize = 100_000_000;

/// One harmonic, `amplitude cos(2 pi frequency t + phase)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Harmonic {
    /// In the unit of the signal (N or m/s^2).
    pub amplitude: f64,
    /// Hz (>= 0).
    pub frequency: f64,
    /// rad.
    pub phase: f64,
}

impl Harmonic {
    /// Validated: every value finite, the frequency not negative.
    pub fn new(amplitude: f64, frequency: f64, phase: f64) -> Result<Self> {
        Ok(Self {
            amplitude: finite("amplitude", amplitude)?,
            frequency: non_negative("frequency", frequency)?,
            phase: finite("phase", phase)?,
        })
    }

    #[inline(always)]
    fn value(&self, time: f64) -> f64 {
        self.amplitude * (std::f64::consts::TAU * self.frequency * time + self.phase).cos()
    }
}

/// How a swept sine's frequency moves from start to end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SweepLaw {
    /// `f(t) = f0 + (f1 - f0) t / T`.
    Linear,
    /// `f(t) = f0 (f1 / f0)^(t / T)`: the same time per octave.
    Logarithmic,
}

impl SweepLaw {
    pub const NAMES: &'static str = "\"linear\", \"logarithmic\"";
    pub fn parse(name: &str) -> Result<Self> {
        match name {
            "linear" => Ok(Self::Linear),
            "logarithmic" => Ok(Self::Logarithmic),
            _ => Err(Error::UnknownChoice {
                field: "sweep",
                allowed: Self::NAMES,
                value: name.to_string(),
            }),
        }
    }
}

/// A signal of time.
#[derive(Debug, Clone, PartialEq)]
pub enum Signal {
    /// One harmonic.
    Harmonic(Harmonic),
    /// A sum of harmonics.
    Harmonics(Vec<Harmonic>),
    /// `amplitude cos(theta(t) + phase)` whose instantaneous frequency
    /// `theta'(t) / 2 pi` goes from `start_frequency` to `end_frequency` (Hz)
    /// over `duration` (s), then stays at the end frequency (the phase is
    /// continuous throughout).
    Sweep {
        amplitude: f64,
        start_frequency: f64,
        end_frequency: f64,
        duration: f64,
        law: SweepLaw,
        phase: f64,
    },
    /// Values at increasing times, linearly interpolated, zero outside the
    /// record (a recorded ground motion ends at rest).
    Recorded { time: Vec<f64>, value: Vec<f64> },
    /// Values every `interval` s from t = 0, linearly interpolated, zero
    /// after the last sample (generated random signals), with the `recipe`
    /// they were generated from (to generate them again with another seed).
    Sampled {
        interval: f64,
        value: Vec<f64>,
        recipe: Option<Recipe>,
    },
}

/// What a random signal is generated from: kept beside its samples so that a
/// study can generate it again with one input changed (another seed, another
/// intensity), the same bit for bit as a scenario written with those inputs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Recipe {
    /// S0, the signal's unit^2 per rad/s.
    pub intensity: f64,
    /// Hz.
    pub cutoff_frequency: f64,
    /// s.
    pub duration: f64,
    pub seed: u64,
    /// The ground's frequency (Hz) and damping ratio of a Kanai-Tajimi
    /// signal; none for white noise.
    pub ground: Option<(f64, f64)>,
}

/// An input of a [`Recipe`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RecipeKey {
    Seed,
    Intensity,
    CutoffFrequency,
    Duration,
    /// Kanai-Tajimi only.
    GroundFrequency,
    /// Kanai-Tajimi only.
    GroundDamping,
}

/// A record's times and values: as many of each, 2 to
/// [`MAX_SIGNAL_SAMPLES`] samples, all finite, the times strictly increasing.
fn check_record(time: &[f64], value: &[f64]) -> Result<()> {
    if time.len() != value.len() {
        return Err(Error::Inconsistent(format!(
            "a recorded signal needs as many values as times, got {} times and {} values",
            time.len(),
            value.len()
        )));
    }
    if time.len() < 2 {
        return Err(Error::Inconsistent(format!(
            "a recorded signal needs at least 2 samples, got {}",
            time.len()
        )));
    }
    if time.len() > MAX_SIGNAL_SAMPLES {
        return Err(Error::Inconsistent(format!(
            "a recorded signal may hold at most {MAX_SIGNAL_SAMPLES} samples, got {}",
            time.len()
        )));
    }
    for (row, (&t, &v)) in time.iter().zip(value).enumerate() {
        if !t.is_finite() || !v.is_finite() {
            return Err(Error::Inconsistent(format!(
                "a recorded signal must be finite: row {row} has time {t} and value {v}"
            )));
        }
        if row > 0 && t <= time[row - 1] {
            return Err(Error::Inconsistent(format!(
                "recorded times must increase strictly: row {row} has {t} s after {} s",
                time[row - 1]
            )));
        }
    }
    Ok(())
}

/// A value whose differences with others like it stay finite: within half
/// the largest float (NaN is not).
fn within_half_range(value: f64) -> bool {
    value.abs() <= 0.5 * f64::MAX
}

/// The largest seed a study can set: a seed travels as an `f64` among the
/// study's values, whole numbers exactly so up to 2^53.
pub const MAX_STUDY_SEED: u64 = 1 << 53;

impl RecipeKey {
    /// The key of the scenario named `name` for a signal made by `recipe`,
    /// if it has one.
    pub fn parse(name: &str, recipe: &Recipe) -> Option<Self> {
        let key = match name {
            "seed" => Self::Seed,
            "intensity" => Self::Intensity,
            "cutoff_frequency" => Self::CutoffFrequency,
            "duration" => Self::Duration,
            "ground_frequency" => Self::GroundFrequency,
            "ground_damping" => Self::GroundDamping,
            _ => return None,
        };
        let ground = matches!(key, Self::GroundFrequency | Self::GroundDamping);
        (!ground || recipe.ground.is_some()).then_some(key)
    }
}

impl Recipe {
    /// The keys of this recipe's signal, for error messages.
    pub fn keys(&self) -> &'static str {
        match self.ground {
            None => "seed, intensity, cutoff_frequency, duration",
            Some(_) => {
                "seed, intensity, cutoff_frequency, duration, ground_frequency, ground_damping"
            }
        }
    }

    /// The signal's name in a scenario.
    pub fn name(&self) -> &'static str {
        match self.ground {
            None => "white-noise",
            Some(_) => "kanai-tajimi",
        }
    }

    /// Set `key` (see [`RecipeKey::parse`]) to `value`; a seed must be a whole
    /// number in [0, 2^53]. The other values are checked by [`Recipe::generate`].
    pub fn set(&mut self, key: RecipeKey, value: f64) -> Result<()> {
        match (key, &mut self.ground) {
            (RecipeKey::Seed, _) => {
                if !(value >= 0.0 && value <= MAX_STUDY_SEED as f64 && value.fract() == 0.0) {
                    return Err(Error::InvalidParameter {
                        field: "seed",
                        allowed: "a whole number in [0, 2^53]",
                        value,
                    });
                }
                self.seed = value as u64;
            }
            (RecipeKey::Intensity, _) => self.intensity = value,
            (RecipeKey::CutoffFrequency, _) => self.cutoff_frequency = value,
            (RecipeKey::Duration, _) => self.duration = value,
            (RecipeKey::GroundFrequency, Some((frequency, _))) => *frequency = value,
            (RecipeKey::GroundDamping, Some((_, damping))) => *damping = value,
            (RecipeKey::GroundFrequency | RecipeKey::GroundDamping, None) => {
                return Err(Error::Inconsistent(
                    "a white-noise signal has no ground_frequency or ground_damping".into(),
                ))
            }
        }
        Ok(())
    }

    /// The signal, generated (validated as [`Signal::white_noise`] and
    /// [`Signal::kanai_tajimi`] validate it).
    pub fn generate(&self) -> Result<Signal> {
        let Self {
            intensity,
            cutoff_frequency,
            duration,
            seed,
            ground,
        } = *self;
        match ground {
            None => Signal::white_noise(intensity, cutoff_frequency, duration, seed),
            Some((frequency, damping)) => Signal::kanai_tajimi(
                intensity,
                frequency,
                damping,
                cutoff_frequency,
                duration,
                seed,
            ),
        }
    }
}

/// How many times below the lowest forcing frequency a common fundamental is
/// looked for (20 and 30 Hz: 10 Hz, twice below).
const MAX_SUBHARMONIC: u32 = 64;

/// The period (s) of forcing that sums harmonics: `1 / f0` for the highest
/// `f0` of which every frequency is a whole multiple (found at most
/// [`MAX_SUBHARMONIC`] times below the lowest; 0 Hz terms, constant, fit any
/// period). `excitations` gives, per excitation, its signal's name and its
/// harmonic frequencies (Hz; `None` for a signal that is not a sum of
/// harmonics). The periodic analyses' rule, one place for all of them.
pub fn common_period(excitations: &[(&str, Option<Vec<f64>>)]) -> Result<f64> {
    let mut all = Vec::new();
    for (j, (name, frequencies)) in excitations.iter().enumerate() {
        let Some(frequencies) = frequencies else {
            return Err(Error::Inconsistent(format!(
                "excitation {j}: a {name:?} signal has no period; a periodic analysis needs \
                 harmonic forcing (\"harmonic\" or \"harmonics\"), or use simulate"
            )));
        };
        all.extend(frequencies.iter().filter(|f| **f > 0.0).map(|f| (j, *f)));
    }
    let lowest = all.iter().map(|(_, f)| *f).fold(f64::INFINITY, f64::min);
    if !lowest.is_finite() {
        return Err(Error::Inconsistent(
            "a periodic analysis needs a harmonic excitation (signal = \"harmonic\" with a \
             frequency > 0): its period is the forcing period"
                .to_string(),
        ));
    }
    let whole = |ratio: f64| (ratio - ratio.round()).abs() <= 1e-9 * ratio;
    for k in 1..=MAX_SUBHARMONIC {
        let fundamental = lowest / f64::from(k);
        if all.iter().all(|(_, f)| whole(f / fundamental)) {
            return Ok(1.0 / fundamental);
        }
    }
    let (j, f) = all
        .iter()
        .find(|(_, f)| !whole(f / lowest))
        .copied()
        .unwrap_or((0, lowest));
    Err(Error::Inconsistent(format!(
        "excitation {j}: frequency {f} Hz has no common period with {lowest} Hz (none within \
         {MAX_SUBHARMONIC} periods of the lowest frequency), so the forcing has no period for \
         a periodic analysis"
    )))
}

impl Signal {
    /// The signal's name (as in a scenario) and, for a sum of harmonics,
    /// their frequencies (Hz): what [`common_period`] takes.
    pub fn harmonic_frequencies(&self) -> (&'static str, Option<Vec<f64>>) {
        match self {
            Self::Harmonic(h) => ("harmonic", Some(vec![h.frequency])),
            Self::Harmonics(list) => (
                "harmonics",
                Some(list.iter().map(|h| h.frequency).collect()),
            ),
            Self::Sweep { .. } => ("sweep", None),
            Self::Recorded { .. } => ("recorded", None),
            Self::Sampled { recipe, .. } => (recipe.as_ref().map_or("sampled", |r| r.name()), None),
        }
    }

    /// One harmonic, `amplitude cos(2 pi frequency t + phase)`.
    pub fn harmonic(amplitude: f64, frequency: f64, phase: f64) -> Result<Self> {
        Harmonic::new(amplitude, frequency, phase).map(Self::Harmonic)
    }

    /// A swept sine (see [`Signal::Sweep`]); a logarithmic sweep needs both
    /// frequencies > 0.
    pub fn sweep(
        amplitude: f64,
        start_frequency: f64,
        end_frequency: f64,
        duration: f64,
        law: SweepLaw,
        phase: f64,
    ) -> Result<Self> {
        let check = match law {
            SweepLaw::Linear => non_negative,
            SweepLaw::Logarithmic => positive,
        };
        Ok(Self::Sweep {
            amplitude: finite("amplitude", amplitude)?,
            start_frequency: check("start_frequency", start_frequency)?,
            end_frequency: check("end_frequency", end_frequency)?,
            duration: positive("duration", duration)?,
            law,
            phase: finite("phase", phase)?,
        })
    }

    /// A recorded signal: `time` (s) strictly increasing, at least two
    /// samples, `value` of the same length, both finite; values multiplied by
    /// `scale`.
    pub fn recorded(time: Vec<f64>, value: Vec<f64>, scale: f64) -> Result<Self> {
        let scale = finite("scale", scale)?;
        check_record(&time, &value)?;
        let value: Vec<f64> = value.into_iter().map(|v| v * scale).collect();
        // Half the largest float, so that the interpolation's differences are finite too.
        if let Some(row) = value.iter().position(|v| !within_half_range(*v)) {
            return Err(Error::Inconsistent(format!(
                "a recorded signal's value times scale ({scale:e}) must stay within floating \
                 point: row {row} gives {:e}",
                value[row]
            )));
        }
        Ok(Self::Recorded { time, value })
    }

    /// Refuses a signal its constructors would not make: what a signal
    /// written as a literal (its fields are public) must hold before a run
    /// reads it, each value in its constructor's range.
    pub fn check(&self) -> Result<()> {
        match self {
            Self::Harmonic(h) => Harmonic::new(h.amplitude, h.frequency, h.phase).map(|_| ()),
            Self::Harmonics(list) if list.is_empty() => Err(Error::Inconsistent(
                "a harmonics signal needs at least one term (amplitudes and frequencies)".into(),
            )),
            Self::Harmonics(list) => list.iter().try_for_each(|h| Self::Harmonic(*h).check()),
            Self::Sweep {
                amplitude,
                start_frequency,
                end_frequency,
                duration,
                law,
                phase,
            } => Self::sweep(
                *amplitude,
                *start_frequency,
                *end_frequency,
                *duration,
                *law,
                *phase,
            )
            .map(|_| ()),
            Self::Recorded { time, value } => {
                check_record(time, value)?;
                match value.iter().position(|v| !within_half_range(*v)) {
                    Some(row) => Err(Error::Inconsistent(format!(
                        "a recorded signal's values must stay within half the largest float: \
                         row {row} has {:e}",
                        value[row]
                    ))),
                    None => Ok(()),
                }
            }
            Self::Sampled {
                interval, value, ..
            } => {
                positive("interval", *interval)?;
                if value.is_empty() || value.len() > MAX_SIGNAL_SAMPLES {
                    return Err(Error::Inconsistent(format!(
                        "a sampled signal needs 1 to {MAX_SIGNAL_SAMPLES} values, got {}",
                        value.len()
                    )));
                }
                match value.iter().position(|v| !within_half_range(*v)) {
                    Some(row) => Err(Error::Inconsistent(format!(
                        "a sampled signal's values must be finite and within half the largest \
                         float: sample {row} is {:e}",
                        value[row]
                    ))),
                    None => Ok(()),
                }
            }
        }
    }

    /// What a generated random signal was generated from.
    pub fn recipe(&self) -> Option<&Recipe> {
        match self {
            Self::Sampled { recipe, .. } => recipe.as_ref(),
            _ => None,
        }
    }

    /// The largest |value| the signal takes (in its unit) and its shortest
    /// period or sampling interval (s; infinite for a constant).
    pub fn extent(&self) -> (f64, f64) {
        let period = |f: f64| if f > 0.0 { 1.0 / f } else { f64::INFINITY };
        match self {
            Self::Harmonic(h) => (h.amplitude.abs(), period(h.frequency)),
            Self::Harmonics(list) => (
                list.iter().map(|h| h.amplitude.abs()).sum(),
                list.iter()
                    .map(|h| period(h.frequency))
                    .fold(f64::INFINITY, f64::min),
            ),
            Self::Sweep {
                amplitude,
                start_frequency,
                end_frequency,
                ..
            } => (amplitude.abs(), period(start_frequency.max(*end_frequency))),
            Self::Recorded { time, value } => (
                value.iter().fold(0.0, |m, v| m.max(v.abs())),
                time.windows(2)
                    .map(|w| 2.0 * (w[1] - w[0]))
                    .fold(f64::INFINITY, f64::min),
            ),
            Self::Sampled {
                interval, value, ..
            } => (
                value.iter().fold(0.0, |m, v| m.max(v.abs())),
                2.0 * interval,
            ),
        }
    }

    /// Whether the signal has kinks (see [`Signal::next_breakpoint`]).
    pub fn has_breakpoints(&self) -> bool {
        !matches!(self, Self::Harmonic(_) | Self::Harmonics(_))
    }

    /// The first instant after `time` (s; beyond its round-off) at which the
    /// signal has a kink (a sample of a recorded or generated signal, the end
    /// of a sweep), or infinity. An adaptive method steps onto each: its error
    /// estimate cannot see a kink ahead, and a system at rest under a signal
    /// that is zero for a while would grow its steps past a whole pulse.
    pub fn next_breakpoint(&self, time: f64) -> f64 {
        // Instants closer than this to `time` are `time` itself.
        let after = |t: f64| t > time + 1e-12 * time.abs().max(1e-300);
        match self {
            Self::Harmonic(_) | Self::Harmonics(_) => f64::INFINITY,
            Self::Sweep { duration, .. } if after(*duration) => *duration,
            Self::Sweep { .. } => f64::INFINITY,
            Self::Recorded { time: times, .. } => {
                let next = times.partition_point(|&t| t <= time);
                times[next..]
                    .iter()
                    .copied()
                    .find(|&t| after(t))
                    .unwrap_or(f64::INFINITY)
            }
            Self::Sampled {
                interval, value, ..
            } => {
                let last = (value.len() - 1) as f64;
                let start = (time / interval).floor().max(-1.0);
                (1..=2)
                    .map(|k| (start + k as f64).max(0.0))
                    .filter(|&index| index <= last)
                    .map(|index| index * interval)
                    .find(|&t| after(t))
                    .unwrap_or(f64::INFINITY)
            }
        }
    }

    /// The signal's value at `time` (s).
    #[inline]
    pub fn value(&self, time: f64) -> f64 {
        match self {
            Self::Harmonic(h) => h.value(time),
            Self::Harmonics(list) => list.iter().map(|h| h.value(time)).sum(),
            Self::Sweep {
                amplitude,
                start_frequency,
                end_frequency,
                duration,
                law,
                phase,
            } => {
                amplitude
                    * (sweep_phase(*start_frequency, *end_frequency, *duration, *law, time) + phase)
                        .cos()
            }
            Self::Recorded { time: times, value } => {
                let last = times.len() - 1;
                if !(time >= times[0] && time <= times[last]) {
                    return 0.0;
                }
                // The first sample after `time` (a binary search: the hot loop
                // reads it once per stage).
                let next = times.partition_point(|&t| t <= time).clamp(1, last);
                let (t0, t1) = (times[next - 1], times[next]);
                let (v0, v1) = (value[next - 1], value[next]);
                v0 + (v1 - v0) * ((time - t0) / (t1 - t0))
            }
            Self::Sampled {
                interval, value, ..
            } => {
                let position = time / interval;
                if position.is_nan() || position < 0.0 {
                    return 0.0;
                }
                let index = position.floor();
                let at = index as usize;
                if at + 1 >= value.len() {
                    return if at + 1 == value.len() && position == index {
                        value[at]
                    } else {
                        0.0
                    };
                }
                let fraction = position - index;
                value[at] + (value[at + 1] - value[at]) * fraction
            }
        }
    }
}

/// The phase `theta(t)` (rad) of a swept sine: the integral of
/// `2 pi f(t)` from 0, continued at the end frequency after `duration`.
fn sweep_phase(f0: f64, f1: f64, duration: f64, law: SweepLaw, time: f64) -> f64 {
    let tau = std::f64::consts::TAU;
    let during = time.min(duration);
    let after = (time - duration).max(0.0);
    let swept = match law {
        SweepLaw::Linear => f0 * during + 0.5 * (f1 - f0) * during * during / duration,
        SweepLaw::Logarithmic => {
            let ratio = f1 / f0;
            if (ratio - 1.0).abs() < 1e-12 {
                f0 * during
            } else {
                // f0 T (r^(t/T) - 1) / ln r, with exp_m1 for accuracy near r = 1.
                let log_ratio = ratio.ln();
                f0 * duration * (log_ratio * during / duration).exp_m1() / log_ratio
            }
        }
    };
    tau * (swept + f1 * after)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_record_whose_scaled_values_overflow_is_refused() {
        crate::testing::timeout(60, || {
            let err = Signal::recorded(vec![0.0, 1.0], vec![0.0, 1e308], 100.0).unwrap_err();
            assert!(err.to_string().contains("row 1 gives inf"), "{err}");
            assert!(Signal::recorded(vec![0.0, 1.0], vec![0.0, 1e305], 100.0).is_ok());
        });
    }

    #[test]
    fn breakpoints_are_the_samples_after_the_time_and_the_sweep_s_end() {
        crate::testing::timeout(60, || {
            let recorded = Signal::recorded(vec![1.0, 2.0, 4.0], vec![0.0, 1.0, 0.0], 1.0).unwrap();
            let sampled = Signal::Sampled {
                interval: 0.1,
                value: vec![0.0, 1.0, -1.0, 0.5],
                recipe: None,
            };
            for (signal, time, next) in [
                (&recorded, 0.0, 1.0),
                (&recorded, 1.0, 2.0),
                // Within round-off of a sample is on it.
                (&recorded, 2.0 - 1e-15, 4.0),
                (&recorded, 3.0, 4.0),
                (&recorded, 4.0, f64::INFINITY),
                (&sampled, -1.0, 0.0),
                (&sampled, 0.0, 0.1),
                (&sampled, 0.15, 0.2),
                // 3 x 0.1 is 0.30000000000000004: the last sample, not the one after.
                (&sampled, 0.2, 0.1 * 3.0),
                (&sampled, 0.1 * 3.0, f64::INFINITY),
            ] {
                assert_eq!(signal.next_breakpoint(time), next, "{time}");
            }
            let sweep = Signal::sweep(1.0, 1.0, 5.0, 2.0, SweepLaw::Linear, 0.0).unwrap();
            assert_eq!(sweep.next_breakpoint(1.0), 2.0);
            assert_eq!(sweep.next_breakpoint(2.0), f64::INFINITY);
            let harmonic = Signal::harmonic(1.0, 3.0, 0.0).unwrap();
            assert!(!harmonic.has_breakpoints() && sweep.has_breakpoints());
            assert_eq!(harmonic.next_breakpoint(0.0), f64::INFINITY);
        });
    }
}
