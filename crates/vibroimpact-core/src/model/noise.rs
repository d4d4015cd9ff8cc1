//! Random signals, generated once from a seed into samples that a run then
//! interpolates ([`Signal::Sampled`]): band-limited white noise and the
//! Kanai-Tajimi ground acceleration. Only IEEE-754 basic operations (+, -,
//! *, /, sqrt) are used, never the platform's `ln`, `exp` or `cos`, so the
//! same seed gives the same signal bit for bit on every platform.

use super::signals::{Recipe, Signal, MAX_SIGNAL_SAMPLES};
use crate::error::{non_negative, positive, Error, Result};

impl Signal {
    /// Band-limited Gaussian white noise of two-sided power spectral density
    /// `intensity` S0 (unit^2 per rad/s) up to `cutoff_frequency` (Hz), over
    /// `duration` (s): independent samples of variance `2 S0 omega_c` every
    /// `pi / omega_c` s (the Nyquist interval of the cutoff), linearly
    /// interpolated. Its spectral density at low frequency is S0.
    pub fn white_noise(
        intensity: f64,
        cutoff_frequency: f64,
        duration: f64,
        seed: u64,
    ) -> Result<Self> {
        let (interval, count) = noise_grid(intensity, cutoff_frequency, duration)?;
        let cutoff = std::f64::consts::TAU * cutoff_frequency;
        let deviation = (2.0 * intensity * cutoff).sqrt();
        let mut gauss = Gaussian::new(seed);
        let value = (0..count).map(|_| deviation * gauss.next()).collect();
        Ok(Self::Sampled {
            interval,
            value,
            recipe: Some(Recipe {
                intensity,
                cutoff_frequency,
                duration,
                seed,
                ground: None,
            }),
        })
    }

    /// The Kanai-Tajimi ground acceleration (m/s^2): band-limited white noise
    /// of intensity S0 (see [`Signal::white_noise`]) filtered by the ground,
    /// a damped oscillator of `ground_frequency` (Hz) and `ground_damping`,
    /// whose absolute acceleration is the signal. Its spectral density is
    /// `S0 (wg^4 + 4 zg^2 wg^2 w^2) / ((wg^2 - w^2)^2 + 4 zg^2 wg^2 w^2)`.
    /// The filter starts at rest; the cutoff must exceed the ground frequency.
    pub fn kanai_tajimi(
        intensity: f64,
        ground_frequency: f64,
        ground_damping: f64,
        cutoff_frequency: f64,
        duration: f64,
        seed: u64,
    ) -> Result<Self> {
        let ground = std::f64::consts::TAU * positive("ground_frequency", ground_frequency)?;
        let zeta = positive("ground_damping", ground_damping)?;
        if cutoff_frequency.is_finite() && cutoff_frequency <= ground_frequency {
            return Err(Error::Inconsistent(format!(
                "cutoff_frequency ({cutoff_frequency} Hz) must exceed ground_frequency ({ground_frequency} Hz)"
            )));
        }
        let Self::Sampled {
            interval, value, ..
        } = Self::white_noise(intensity, cutoff_frequency, duration, seed)?
        else {
            unreachable!("white_noise returns samples")
        };
        // The filter x'' + 2 zg wg x' + wg^2 x = -w(t) by RK4 on sub-steps of
        // at most 1/20 of its fastest time constant, the ground period's
        // radian unless it is overdamped (basic operations only: the result
        // is the same on every platform); w is linear in between.
        let fastest = if zeta > 1.0 {
            ground * (zeta + (zeta * zeta - 1.0).sqrt())
        } else {
            ground
        };
        let substeps = (20.0 * fastest * interval).ceil().max(1.0);
        // Bounded in all, not only per sample: the filter's steps over the whole
        // record are one loop without an interrupt (ground_damping 1e5 over 1000 s
        // had run past Ctrl-C and SIGTERM for minutes).
        let total = substeps * value.len().saturating_sub(1) as f64;
        if total > MAX_SIGNAL_SAMPLES as f64 {
            return Err(Error::Inconsistent(format!(
                "ground_damping {ground_damping} makes the ground filter too stiff to integrate \
                 over {duration} s ({substeps:.3e} steps per sample, {total:.3e} in all, more \
                 than {MAX_SIGNAL_SAMPLES}); a soil's damping ratio is below 1 or 2"
            )));
        }
        let substeps = substeps as usize;
        let h = interval / substeps as f64;
        let (a, b) = (2.0 * zeta * ground, ground * ground);
        let rate = |x: f64, v: f64, w: f64| (v, -a * v - b * x - w);
        let (mut x, mut v) = (0.0f64, 0.0f64);
        let mut out = Vec::with_capacity(value.len());
        out.push(0.0);
        for pair in value.windows(2) {
            let (w0, w1) = (pair[0], pair[1]);
            for k in 0..substeps {
                let at = |s: f64| w0 + (w1 - w0) * ((k as f64 + s) / substeps as f64);
                let (wa, wm, wb) = (at(0.0), at(0.5), at(1.0));
                let (k1x, k1v) = rate(x, v, wa);
                let (k2x, k2v) = rate(x + 0.5 * h * k1x, v + 0.5 * h * k1v, wm);
                let (k3x, k3v) = rate(x + 0.5 * h * k2x, v + 0.5 * h * k2v, wm);
                let (k4x, k4v) = rate(x + h * k3x, v + h * k3v, wb);
                x += h / 6.0 * (k1x + 2.0 * k2x + 2.0 * k3x + k4x);
                v += h / 6.0 * (k1v + 2.0 * k2v + 2.0 * k3v + k4v);
            }
            // The ground's absolute acceleration x'' + w.
            out.push(-a * v - b * x);
        }
        Ok(Self::Sampled {
            interval,
            value: out,
            recipe: Some(Recipe {
                intensity,
                cutoff_frequency,
                duration,
                seed,
                ground: Some((ground_frequency, ground_damping)),
            }),
        })
    }
}

/// The sample interval `pi / omega_c` (s) and the number of samples covering
/// `duration` for a random signal, validated.
fn noise_grid(intensity: f64, cutoff_frequency: f64, duration: f64) -> Result<(f64, usize)> {
    non_negative("intensity", intensity)?;
    let cutoff = positive("cutoff_frequency", cutoff_frequency)?;
    let duration = positive("duration", duration)?;
    let interval = 0.5 / cutoff;
    let count = (duration / interval).ceil() + 1.0;
    if count.is_nan() || count > MAX_SIGNAL_SAMPLES as f64 {
        return Err(Error::Inconsistent(format!(
            "a random signal of duration {duration} s and cutoff_frequency {cutoff} Hz needs {count:.0} samples; \
             at most {MAX_SIGNAL_SAMPLES} are allowed: lower the cutoff or the duration"
        )));
    }
    Ok((interval, count as usize))
}

/// Standard normal numbers from a seed, the same on every platform:
/// SplitMix64 uniforms and Marsaglia's polar method, with a logarithm of
/// basic operations only.
struct Gaussian {
    state: u64,
    spare: Option<f64>,
}

impl Gaussian {
    fn new(seed: u64) -> Self {
        Self {
            state: seed,
            spare: None,
        }
    }

    /// SplitMix64 (Steele, Lea and Flood 2014).
    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in (-1, 1), 53 bits.
    fn uniform(&mut self) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
        2.0 * unit - 1.0
    }

    fn next(&mut self) -> f64 {
        if let Some(value) = self.spare.take() {
            return value;
        }
        loop {
            let (u, v) = (self.uniform(), self.uniform());
            let s = u * u + v * v;
            if s > 0.0 && s < 1.0 {
                let factor = (-2.0 * portable_ln(s) / s).sqrt();
                self.spare = Some(v * factor);
                return u * factor;
            }
        }
    }
}

/// Natural logarithm of a positive normal number with basic operations only:
/// `x = m 2^k` with m in [1/sqrt 2, sqrt 2), then
/// `ln m = 2 atanh z = 2 (z + z^3/3 + z^5/5 + ...)`, `z = (m - 1)/(m + 1)`,
/// |z| <= 0.1716, so 14 terms reach round-off.
fn portable_ln(x: f64) -> f64 {
    debug_assert!(x > 0.0 && x.is_normal());
    let bits = x.to_bits();
    let mut exponent = ((bits >> 52) & 0x7ff) as i64 - 1023;
    let mut mantissa = f64::from_bits((bits & 0x000f_ffff_ffff_ffff) | 0x3ff0_0000_0000_0000);
    if mantissa > std::f64::consts::SQRT_2 {
        mantissa *= 0.5;
        exponent += 1;
    }
    let z = (mantissa - 1.0) / (mantissa + 1.0);
    let z2 = z * z;
    let mut term = z;
    let mut sum = 0.0;
    for n in 0..14 {
        sum += term / (2 * n + 1) as f64;
        term *= z2;
    }
    2.0 * sum + exponent as f64 * std::f64::consts::LN_2
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn splitmix64_matches_its_reference_sequence() {
        crate::testing::timeout(60, || {
            // The published outputs of SplitMix64 from seed 0.
            let mut g = Gaussian::new(0);
            assert_eq!(g.next_u64(), 0xE220_A839_7B1D_CDAF);
            assert_eq!(g.next_u64(), 0x6E78_9E6A_A1B9_65F4);
            assert_eq!(g.next_u64(), 0x06C4_5D18_8009_454F);
        });
    }

    #[test]
    fn portable_ln_matches_the_platform_to_round_off() {
        crate::testing::timeout(60, || {
            let mut x = 1e-300;
            while x < 1e300 {
                for y in [x, x * 1.234567, x * 0.7, x * 1.41] {
                    let (ours, std) = (portable_ln(y), y.ln());
                    assert!(
                        (ours - std).abs() <= 4.0 * f64::EPSILON * std.abs().max(1.0),
                        "ln({y}) = {ours}, std {std}"
                    );
                }
                x *= 10.0;
            }
        });
    }
}
