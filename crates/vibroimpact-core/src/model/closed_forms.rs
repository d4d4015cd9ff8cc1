//! Closed-form references: Goldsmith's Hertz impact, the linear-spring
//! contact, and the founding paper's adequacy factor (its Eq. 15).

use crate::error::{non_negative, positive, within, Error, Result};

/// Goldsmith's constant in `Tc = 2.9432 delta_max / v`, as printed.
pub const GOLDSMITH_CONSTANT: f64 = 2.9432;
/// The same constant exactly: `2 * (2/5) * B(2/5, 1/2)`.
pub const HERTZ_DURATION_CONSTANT: f64 = 2.943_275_184_324_705;

/// A result `value` (the `what`, in `unit`) must be finite and > 0;
/// otherwise `inputs` are out of floating-point range together.
pub(crate) fn representable(what: &str, unit: &str, value: f64, inputs: &str) -> Result<f64> {
    if value.is_finite() && value > 0.0 {
        Ok(value)
    } else {
        Err(Error::Inconsistent(format!(
            "the {what} is {value:e} {unit}, out of floating-point range: {inputs} are too large or too small together"
        )))
    }
}

/// What the closed forms' results depend on.
const INPUTS: &str = "the masses, stiffness and speed";

/// `K* = (m + M) / (m M)`, 1/kg.
fn inverse_effective_mass(impact_mass: f64, main_mass: f64) -> Result<f64> {
    let m = positive("impact_mass", impact_mass)?;
    let big = positive("main_mass", main_mass)?;
    Ok((m + big) / (m * big))
}

/// Maximum indentation of a Hertz impact between two free bodies, m:
/// `delta_max = (5 v^2 / (4 K* K_hz))^(2/5)`.
pub fn goldsmith_max_indentation(
    impact_mass: f64,
    main_mass: f64,
    hertz_stiffness: f64,
    approach_speed: f64,
) -> Result<f64> {
    let k_star = inverse_effective_mass(impact_mass, main_mass)?;
    let k = positive("hertz_stiffness", hertz_stiffness)?;
    let v = positive("approach_speed", approach_speed)?;
    representable(
        "maximum indentation",
        "m",
        hertz_deepest(k_star, k, v),
        INPUTS,
    )
}

/// Goldsmith's deepest indentation (m) of a Hertz contact of `stiffness`
/// (N/m^1.5) between bodies of inverse effective mass `inverse_mass`
/// (1/kg) approaching at `speed` (m/s), its inputs unchecked:
/// `(5 v^2 / (4 K* K))^(2/5)`.
pub(crate) fn hertz_deepest(inverse_mass: f64, stiffness: f64, speed: f64) -> f64 {
    (5.0 * speed * speed / (4.0 * inverse_mass * stiffness)).powf(0.4)
}

/// Goldsmith's Hertz contact duration, s:
/// `Tc = 2.9432 / v^0.2 * (5 / (4 K* K_hz))^(2/5)`. With `exact_constant`
/// the constant is `2.943275...` (the closed-form value of the integral)
/// instead of Goldsmith's printed 2.9432.
pub fn goldsmith_contact_duration(
    impact_mass: f64,
    main_mass: f64,
    hertz_stiffness: f64,
    approach_speed: f64,
    exact_constant: bool,
) -> Result<f64> {
    let delta_max =
        goldsmith_max_indentation(impact_mass, main_mass, hertz_stiffness, approach_speed)?;
    let constant = if exact_constant {
        HERTZ_DURATION_CONSTANT
    } else {
        GOLDSMITH_CONSTANT
    };
    representable(
        "contact duration",
        "s",
        constant * delta_max / approach_speed,
        INPUTS,
    )
}

/// Contact duration of a linear spring `k1` with a damper `c1` between two
/// free bodies (half a damped period), s:
/// `Tc = 2 m M pi / (sqrt(m + M) sqrt(4 m M k1 - c1^2 (m + M)))`.
pub fn linear_contact_duration(
    impact_mass: f64,
    main_mass: f64,
    stiffness: f64,
    damping: f64,
) -> Result<f64> {
    let m = positive("impact_mass", impact_mass)?;
    let big = positive("main_mass", main_mass)?;
    let k1 = positive("stiffness", stiffness)?;
    let c1 = non_negative("damping", damping)?;
    let discriminant = 4.0 * m * big * k1 - c1 * c1 * (m + big);
    if discriminant.is_nan() {
        // inf - inf: both terms overflow.
        return representable(
            "discriminant 4 m M k1 - c1^2 (m + M)",
            "N kg^2/m",
            discriminant,
            INPUTS,
        );
    }
    if discriminant <= 0.0 {
        return Err(Error::Inconsistent(format!(
            "damping {c1} N s/m is at or above critical for stiffness {k1} N/m: the contact does not oscillate"
        )));
    }
    representable(
        "contact duration",
        "s",
        2.0 * m * big * std::f64::consts::PI / ((m + big).sqrt() * discriminant.sqrt()),
        INPUTS,
    )
}

/// The paper's adequacy factor (Eq. 15), percent:
/// `A = ((1 - error/max_error) wf1 + (1 - cpu_time/max_cpu_time) (1 - wf1)) * 100`.
pub fn adequacy(
    error: f64,
    max_error: f64,
    cpu_time: f64,
    max_cpu_time: f64,
    error_weight: f64,
) -> Result<f64> {
    let error = non_negative("error", error)?;
    let max_error = positive("max_error", max_error)?;
    let cpu_time = non_negative("cpu_time", cpu_time)?;
    let max_cpu_time = positive("max_cpu_time", max_cpu_time)?;
    let wf1 = within("error_weight", error_weight, 0.0, 1.0, false, "in [0, 1]")?;
    let factor =
        ((1.0 - error / max_error) * wf1 + (1.0 - cpu_time / max_cpu_time) * (1.0 - wf1)) * 100.0;
    if factor.is_finite() {
        Ok(factor)
    } else {
        Err(Error::Inconsistent(format!(
            "the adequacy factor is {factor}: error / max_error or cpu_time / max_cpu_time is out of floating-point range"
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::contact::tests::field;

    #[test]
    fn exact_constant_matches_the_integral() {
        crate::testing::timeout(60, || {
            // 2 * int_0^1 dx / sqrt(1 - x^(5/2)), by the substitution x = 1 - s^2
            // (which removes the end singularity) and a fine midpoint rule.
            let n = 200_000;
            let h = 1.0 / n as f64;
            let mut sum = 0.0;
            for i in 0..n {
                let s = (i as f64 + 0.5) * h;
                let x: f64 = 1.0 - s * s;
                sum += 2.0 * s / (1.0 - x.powf(2.5)).sqrt() * h;
            }
            assert!(
                (2.0 * sum - HERTZ_DURATION_CONSTANT).abs() < 1e-8,
                "{}",
                2.0 * sum
            );
        });
    }

    #[test]
    fn every_argument_is_checked_and_named() {
        crate::testing::timeout(60, || {
            for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
                let duration = |m, big, k, v| goldsmith_contact_duration(m, big, k, v, true);
                assert_eq!(field(duration(bad, 1.0, 1.0, 1.0)), "impact_mass");
                assert_eq!(field(duration(1.0, bad, 1.0, 1.0)), "main_mass");
                assert_eq!(field(duration(1.0, 1.0, bad, 1.0)), "hertz_stiffness");
                assert_eq!(field(duration(1.0, 1.0, 1.0, bad)), "approach_speed");
                let indentation = |m, big, k, v| goldsmith_max_indentation(m, big, k, v);
                assert_eq!(field(indentation(bad, 1.0, 1.0, 1.0)), "impact_mass");
                assert_eq!(field(indentation(1.0, 1.0, 1.0, bad)), "approach_speed");
                let linear = |m, big, k, c| linear_contact_duration(m, big, k, c);
                assert_eq!(field(linear(bad, 1.0, 1.0, 0.0)), "impact_mass");
                assert_eq!(field(linear(1.0, bad, 1.0, 0.0)), "main_mass");
                assert_eq!(field(linear(1.0, 1.0, bad, 0.0)), "stiffness");
                assert_eq!(field(linear(1.0, 1.0, 1.0, bad)), "damping");
                assert_eq!(field(adequacy(bad, 1.0, 1.0, 1.0, 0.5)), "error");
                assert_eq!(field(adequacy(1.0, bad, 1.0, 1.0, 0.5)), "max_error");
                assert_eq!(field(adequacy(1.0, 1.0, bad, 1.0, 0.5)), "cpu_time");
                assert_eq!(field(adequacy(1.0, 1.0, 1.0, bad, 0.5)), "max_cpu_time");
                assert_eq!(field(adequacy(1.0, 1.0, 1.0, 1.0, bad)), "error_weight");
            }
        });
    }

    #[test]
    fn results_beyond_floating_point_are_errors() {
        crate::testing::timeout(60, || {
            let out_of_range = |r: Result<f64>| match r {
                Err(Error::Inconsistent(message)) => {
                    assert!(message.contains("out of floating-point range"), "{message}")
                }
                other => panic!("expected an out-of-range error, got {other:?}"),
            };
            // (5 v^2 / (4 K* K_hz))^0.4 overflows; the duration delta_max / v underflows to 0.
            out_of_range(goldsmith_max_indentation(1e300, 1e300, 1e-300, 1e300));
            out_of_range(goldsmith_contact_duration(
                1e-300, 1e-300, 1e300, 1e300, false,
            ));
            // 4 m M k1 and c1^2 (m + M) both overflow (inf - inf).
            out_of_range(linear_contact_duration(1e300, 1e300, 1e300, 1e300));
            out_of_range(adequacy(1e308, 1e-308, 0.0, 1.0, 0.5));
        });
    }

    #[test]
    fn table1_values() {
        crate::testing::timeout(60, || {
            let tc = goldsmith_contact_duration(0.25, 1.0, 3000.0, 0.1, false).unwrap();
            assert!((tc - 0.1089).abs() < 5e-5, "{tc}");
            let tl = linear_contact_duration(0.25, 1.0, 49.05, 0.01).unwrap();
            assert!((tl - 0.2006).abs() < 5e-5, "{tl}");
        });
    }
}
