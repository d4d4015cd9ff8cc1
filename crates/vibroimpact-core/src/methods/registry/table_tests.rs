//! The table's defaults, ranges and names.

use super::*;

#[test]
fn the_default_options_are_the_table_s_and_in_range() {
    crate::testing::timeout(10, || {
        let options = Options::default();
        assert_eq!(options.checked(), Ok(options));
        let pairs = [
            (options.rtol, RTOL),
            (options.atol, ATOL),
            (options.beta, BETA),
            (options.gamma, GAMMA),
            (options.spectral_radius, SPECTRAL_RADIUS),
        ];
        for (value, spec) in pairs {
            assert_eq!(Some(value), spec.default, "{}", spec.name);
            assert_eq!(spec.check(value), Ok(value));
        }
        assert_eq!(MAX_STEPS.default, Some(DEFAULT_MAX_STEPS as f64));
    });
}

#[test]
fn each_option_outside_its_range_is_named_with_what_is_allowed() {
    crate::testing::timeout(10, || {
        let outside = [
            (RTOL, [1e-16, 0.2, f64::NAN]),
            (ATOL, [0.0, 1.5, f64::INFINITY]),
            (BETA, [-0.01, 0.51, f64::NAN]),
            (GAMMA, [0.49, 1.01, f64::NAN]),
            (SPECTRAL_RADIUS, [-0.1, 1.1, f64::NAN]),
        ];
        for (spec, values) in outside {
            for value in values {
                let mut options = Options::default();
                match spec.name {
                    "rtol" => options.rtol = value,
                    "atol" => options.atol = value,
                    "beta" => options.beta = value,
                    "gamma" => options.gamma = value,
                    _ => options.spectral_radius = value,
                }
                let text = options.checked().unwrap_err().to_string();
                let expected = format!("{} must be {}, got", spec.name, spec.allowed);
                assert!(text.starts_with(&expected), "{text}");
                assert!(!text.contains('\n'));
            }
        }
        // The ends of each range are allowed (the low end of atol excluded).
        for spec in METHOD_OPTIONS {
            assert_eq!(spec.check(spec.high), Ok(spec.high), "{}", spec.name);
            assert_eq!(
                spec.check(spec.low).is_ok(),
                !spec.low_open,
                "{}",
                spec.name
            );
        }
    });
}

#[test]
fn the_kinds_say_which_methods_step_by_dt() {
    crate::testing::timeout(10, || {
        let fixed: Vec<&str> = METHOD_SPECS
            .iter()
            .filter(|m| m.kind.is_fixed_step())
            .map(|m| m.name)
            .collect();
        assert_eq!(
            fixed,
            ["rk4", "newmark", "newmark-implicit", "generalized-alpha"]
        );
        for spec in METHOD_SPECS {
            // Fixed stepping is for the methods that step by dt, and only them.
            assert_eq!(spec.steppings.contains(&"fixed"), spec.kind.is_fixed_step());
            assert_eq!(spec.steppings[0], "events");
            assert_eq!(method(spec.name), Ok(&spec));
        }
        let text = method("newmark-lagged").unwrap_err().to_string();
        for spec in METHOD_SPECS {
            assert!(text.contains(&format!("\"{}\"", spec.name)), "{text}");
        }
    });
}

#[test]
fn a_run_s_settings_are_checked_with_its_options() {
    crate::testing::timeout(10, || {
        let good = Options::default();
        assert_eq!(check_settings(1.0, Some(1e-3), good, 0.05), Ok(good));
        assert_eq!(check_settings(1.0, None, good, 1.0), Ok(good));
        let bad_rtol = Options { rtol: 1.0, ..good };
        for (t_end, dt, options, tolerance, expected) in [
            (
                0.0,
                None,
                good,
                0.05,
                "t_end must be finite and > 0 s, got 0",
            ),
            (
                1.0,
                Some(-1.0),
                good,
                0.05,
                "dt must be finite and > 0 s, or left out, got -1",
            ),
            (
                1.0,
                None,
                bad_rtol,
                0.05,
                "rtol must be in [1e-15, 0.1], got 1",
            ),
            (
                1.0,
                None,
                good,
                1.5,
                "energy_tolerance must be in (0, 1], got 1.5",
            ),
            (
                f64::NAN,
                None,
                good,
                0.05,
                "t_end must be finite and > 0 s, got NaN",
            ),
        ] {
            let err = check_settings(t_end, dt, options, tolerance).unwrap_err();
            assert_eq!(err.to_string(), expected);
        }
    });
}

#[test]
fn an_analysis_s_times_and_tolerance_are_checked_with_their_texts() {
    crate::testing::timeout(10, || {
        // record_from may be 0 (the start); the periods and the tolerance may not.
        assert_eq!(RECORD_FROM.check(0.0), Ok(0.0));
        for spec in [STROBE_PERIOD, FORCING_PERIOD, TOLERANCE, T_END] {
            assert!(spec.check(0.0).is_err(), "{}", spec.name);
            assert_eq!(spec.check(1e-300), Ok(1e-300));
        }
        for spec in [RECORD_FROM, STROBE_PERIOD, FORCING_PERIOD, TOLERANCE] {
            for value in [-1.0, f64::NAN, f64::INFINITY] {
                let text = spec.check(value).unwrap_err().to_string();
                let expected = format!("{} must be finite and ", spec.name);
                assert!(text.starts_with(&expected), "{text}");
            }
        }
    });
}
