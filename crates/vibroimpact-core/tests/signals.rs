//! Excitation signals against independent values: cycle counts of swept
//! sines from their frequency laws, recorded data at and between samples,
//! and the statistics of the random signals from their spectral densities.

mod common;

use std::f64::consts::{PI, TAU};
use vibroimpact_core::model::signals::{Signal, SweepLaw};
use vibroimpact_core::Error;

/// Sign changes of `signal` sampled every `step` over [0, end].
fn zero_crossings(signal: &Signal, end: f64, step: f64) -> u64 {
    let n = (end / step).round() as u64;
    let mut count = 0;
    let mut last = signal.value(0.0);
    for k in 1..=n {
        let v = signal.value(k as f64 * step);
        if (v > 0.0) != (last > 0.0) {
            count += 1;
        }
        last = v;
    }
    count
}

#[test]
fn harmonic_has_its_amplitude_period_and_phase() {
    common::timeout(10, || {
        let s = Signal::harmonic(2.5, 4.0, 0.3).unwrap();
        // cos(phase) at t = 0, the same a period later, the opposite half a period later.
        assert!((s.value(0.0) - 2.5 * 0.3f64.cos()).abs() < 1e-15);
        assert!((s.value(0.25) - s.value(0.0)).abs() < 1e-13);
        assert!((s.value(0.125) + s.value(0.0)).abs() < 1e-13);
        // 4 Hz over 10 s: 80 zero crossings.
        let shifted = Signal::harmonic(1.0, 4.0, 0.1).unwrap();
        assert_eq!(zero_crossings(&shifted, 10.0, 1e-4), 80);
    });
}

#[test]
fn sum_of_harmonics_is_the_sum() {
    common::timeout(10, || {
        let parts = [(1.0, 3.0, 0.2), (0.5, 7.0, -1.0), (0.25, 0.0, 0.0)];
        let list = parts
            .iter()
            .map(|&(a, f, p)| vibroimpact_core::model::signals::Harmonic::new(a, f, p).unwrap())
            .collect();
        let sum = Signal::Harmonics(list);
        for t in [0.0, 0.013, 0.5, 2.7] {
            let expected: f64 = parts
                .iter()
                .map(|&(a, f, p)| a * (TAU * f * t + p).cos())
                .sum();
            assert!((sum.value(t) - expected).abs() < 1e-14);
        }
    });
}

#[test]
fn swept_sines_pass_through_as_many_cycles_as_their_frequency_law_says() {
    common::timeout(20, || {
        // Cycles over the sweep: the integral of f(t). Linear: (f0 + f1) T / 2;
        // logarithmic: f0 T (r - 1) / ln r with r = f1 / f0. Two crossings a cycle.
        let (f0, f1, duration) = (2.0, 20.0, 10.0);
        let linear = Signal::sweep(1.0, f0, f1, duration, SweepLaw::Linear, PI / 2.0).unwrap();
        let cycles = (f0 + f1) * duration / 2.0;
        let counted = zero_crossings(&linear, duration, 1e-5) as f64;
        assert!(
            (counted - 2.0 * cycles).abs() <= 1.0,
            "{counted} vs {}",
            2.0 * cycles
        );

        let log = Signal::sweep(1.0, f0, f1, duration, SweepLaw::Logarithmic, PI / 2.0).unwrap();
        let r: f64 = f1 / f0;
        let cycles = f0 * duration * (r - 1.0) / r.ln();
        let counted = zero_crossings(&log, duration, 1e-5) as f64;
        assert!(
            (counted - 2.0 * cycles).abs() <= 1.0,
            "{counted} vs {}",
            2.0 * cycles
        );

        // After the sweep it goes on at the end frequency: 20 Hz for 5 s.
        let after =
            zero_crossings(&log, duration + 5.0, 1e-5) - zero_crossings(&log, duration, 1e-5);
        assert!((after as f64 - 200.0).abs() <= 1.0);
        // Continuous through the end of the sweep.
        let jump = (log.value(duration + 1e-9) - log.value(duration - 1e-9)).abs();
        assert!(jump < 1e-6);
    });
}

#[test]
fn logarithmic_sweep_takes_equal_time_per_octave() {
    common::timeout(20, || {
        // 1 -> 16 Hz in 8 s: four octaves, 2 s each; the octave from 4 to 8 Hz
        // (t in [4, 6]) holds 2 s times the mean frequency 4 / ln 2 per second.
        let s = Signal::sweep(1.0, 1.0, 16.0, 8.0, SweepLaw::Logarithmic, PI / 2.0).unwrap();
        let crossings = zero_crossings(&s, 6.0, 1e-5) - zero_crossings(&s, 4.0, 1e-5);
        let expected = 2.0 * 2.0 * 4.0 / 2f64.ln();
        assert!((crossings as f64 - expected).abs() <= 1.0);
    });
}

#[test]
fn recorded_signal_interpolates_linearly_and_is_zero_outside() {
    common::timeout(10, || {
        let time = vec![0.5, 1.0, 2.0, 4.0];
        let value = vec![1.0, -1.0, 3.0, 0.0];
        let s = Signal::recorded(time.clone(), value.clone(), 2.0).unwrap();
        for (t, v) in time.iter().zip(&value) {
            assert_eq!(s.value(*t), 2.0 * v);
        }
        assert_eq!(s.value(0.75), 0.0); // halfway between 1 and -1
        assert!((s.value(1.25) - 2.0 * 0.0).abs() < 1e-15); // a quarter from -1 to 3
        assert!((s.value(3.0) - 2.0 * 1.5).abs() < 1e-15);
        assert_eq!(s.value(0.4999), 0.0);
        assert_eq!(s.value(4.0001), 0.0);
    });
}

#[test]
fn recorded_signal_refuses_bad_records() {
    common::timeout(10, || {
        let bad = |t: Vec<f64>, v: Vec<f64>, scale: f64| Signal::recorded(t, v, scale).unwrap_err();
        let message = |e: Error| e.to_string();
        assert!(message(bad(vec![0.0, 1.0, 1.0], vec![0.0; 3], 1.0)).contains("increase strictly"));
        assert!(message(bad(vec![0.0, 2.0, 1.0], vec![0.0; 3], 1.0)).contains("row 2"));
        assert!(message(bad(vec![0.0, 1.0], vec![0.0; 3], 1.0)).contains("as many values"));
        assert!(message(bad(vec![0.0], vec![0.0], 1.0)).contains("at least 2"));
        assert!(message(bad(vec![], vec![], 1.0)).contains("at least 2"));
        assert!(message(bad(vec![0.0, f64::NAN], vec![0.0; 2], 1.0)).contains("finite"));
        assert!(message(bad(vec![0.0, 1.0], vec![0.0, f64::INFINITY], 1.0)).contains("finite"));
        assert!(message(bad(vec![0.0, 1.0], vec![0.0; 2], f64::NAN)).contains("scale"));
    });
}

#[test]
fn bad_signal_parameters_name_the_field() {
    common::timeout(10, || {
        let field = |e: Error| match e {
            Error::InvalidParameter { field, .. } => field,
            other => panic!("{other}"),
        };
        assert_eq!(
            field(Signal::harmonic(f64::NAN, 1.0, 0.0).unwrap_err()),
            "amplitude"
        );
        assert_eq!(
            field(Signal::harmonic(1.0, -1.0, 0.0).unwrap_err()),
            "frequency"
        );
        assert_eq!(
            field(Signal::harmonic(1.0, 1.0, f64::INFINITY).unwrap_err()),
            "phase"
        );
        let log = SweepLaw::Logarithmic;
        assert_eq!(
            field(Signal::sweep(1.0, 0.0, 5.0, 1.0, log, 0.0).unwrap_err()),
            "start_frequency"
        );
        assert_eq!(
            field(Signal::sweep(1.0, 1.0, 5.0, 0.0, log, 0.0).unwrap_err()),
            "duration"
        );
        assert_eq!(
            field(Signal::white_noise(-1.0, 10.0, 1.0, 0).unwrap_err()),
            "intensity"
        );
        assert_eq!(
            field(Signal::white_noise(1.0, 0.0, 1.0, 0).unwrap_err()),
            "cutoff_frequency"
        );
        assert_eq!(
            field(Signal::kanai_tajimi(1.0, 2.0, 0.0, 10.0, 1.0, 0).unwrap_err()),
            "ground_damping"
        );
        assert!(SweepLaw::parse("exponential")
            .unwrap_err()
            .to_string()
            .contains("\"linear\""));
        // A cutoff below the ground frequency, and a record too long to hold.
        assert!(Signal::kanai_tajimi(1.0, 20.0, 0.5, 10.0, 1.0, 0).is_err());
        let huge = Signal::white_noise(1.0, 1e6, 1e6, 0)
            .unwrap_err()
            .to_string();
        assert!(huge.contains("at most"), "{huge}");
    });
}

/// Samples of a generated signal at its own sample instants.
fn samples(signal: &Signal) -> &[f64] {
    match signal {
        Signal::Sampled { value, .. } => value,
        _ => panic!("not sampled"),
    }
}

#[test]
fn white_noise_is_reproducible_from_its_seed() {
    common::timeout(10, || {
        let a = Signal::white_noise(0.1, 25.0, 10.0, 42).unwrap();
        let b = Signal::white_noise(0.1, 25.0, 10.0, 42).unwrap();
        let c = Signal::white_noise(0.1, 25.0, 10.0, 43).unwrap();
        let bits = |s: &Signal| samples(s).iter().map(|v| v.to_bits()).collect::<Vec<_>>();
        assert_eq!(bits(&a), bits(&b));
        assert_ne!(bits(&a), bits(&c));
        // Between samples, linear; the sample interval is pi / omega_c = 1 / (2 fc).
        let (v0, v1) = (samples(&a)[3], samples(&a)[4]);
        let interval = 1.0 / 50.0;
        assert!((a.value(3.25 * interval) - (0.75 * v0 + 0.25 * v1)).abs() < 1e-15);
    });
}

#[test]
fn white_noise_has_the_variance_and_independence_of_its_spectral_density() {
    common::timeout(20, || {
        // Two-sided density S0 up to omega_c: variance 2 S0 omega_c.
        let (s0, fc) = (0.02, 25.0);
        let noise = Signal::white_noise(s0, fc, 8000.0, 7).unwrap();
        let x = samples(&noise);
        let n = x.len() as f64;
        let mean = x.iter().sum::<f64>() / n;
        let variance = x.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / n;
        let expected = 2.0 * s0 * TAU * fc;
        // n = 4e5: the estimate's relative spread is sqrt(2 / n) = 0.22 %.
        assert!(
            (variance / expected - 1.0).abs() < 0.01,
            "{variance} vs {expected}"
        );
        assert!(mean.abs() < 5.0 * (expected / n).sqrt());
        // Independent samples: lag-1 correlation within 5 / sqrt(n).
        let lag1 = x
            .windows(2)
            .map(|w| (w[0] - mean) * (w[1] - mean))
            .sum::<f64>()
            / n;
        assert!((lag1 / variance).abs() < 5.0 / n.sqrt());
        // Gaussian: kurtosis 3 (its estimate's spread is sqrt(24 / n) = 0.8 %).
        let fourth = x.iter().map(|v| (v - mean).powi(4)).sum::<f64>() / n;
        assert!((fourth / (variance * variance) - 3.0).abs() < 0.05);
    });
}

#[test]
fn kanai_tajimi_variance_matches_its_spectral_density() {
    common::timeout(30, || {
        // Variance = int S0 |H(w)|^2 T(w) dw over all w, with the Kanai-Tajimi
        // filter H and T = sinc^4(w dt / 2), the spectrum of linearly
        // interpolated independent samples (dt = pi / omega_c), integrated here
        // by the trapezoidal rule on a fine grid.
        let (s0, fg, zg, fc) = (0.05, 2.0, 0.6, 25.0);
        let signal = Signal::kanai_tajimi(s0, fg, zg, fc, 4000.0, 11).unwrap();
        let x = samples(&signal);
        let skip = 2000; // the filter's start-up (40 s, many times 1 / (zg wg))
        let tail = &x[skip..];
        let n = tail.len() as f64;
        let variance = tail.iter().map(|v| v * v).sum::<f64>() / n;

        let (wg, dt) = (TAU * fg, 0.5 / fc);
        let density = |w: f64| {
            let num = wg.powi(4) + 4.0 * zg * zg * wg * wg * w * w;
            let den = (wg * wg - w * w).powi(2) + 4.0 * zg * zg * wg * wg * w * w;
            let half = 0.5 * w * dt;
            let sinc = if half == 0.0 { 1.0 } else { half.sin() / half };
            s0 * num / den * sinc.powi(4)
        };
        let (top, steps) = (400.0 * wg, 2_000_000);
        let h = top / steps as f64;
        let integral: f64 = (0..=steps)
            .map(|k| {
                let weight = if k == 0 || k == steps { 0.5 } else { 1.0 };
                weight * density(k as f64 * h)
            })
            .sum::<f64>()
            * h
            * 2.0;
        // About 2e5 samples with a correlation time of a few tenths of a second:
        // some 1e4 independent values, a relative spread of about 1.5 %.
        assert!(
            (variance / integral - 1.0).abs() < 0.06,
            "{variance} vs {integral}"
        );
        // The first sample is the filter at rest.
        assert_eq!(x[0], 0.0);
    });
}

/// A 1 Hz oscillator (1 kg, 2 % damped) struck at 5 s by a recorded 1 ms
/// triangular pulse of 0.05 N s, by rk4 at `dt`: its displacement at 6 s.
fn struck_by_a_pulse(dt: f64) -> Result<f64, Error> {
    use vibroimpact_core::kernel::events::RunOptions;
    use vibroimpact_core::methods::registry::{AnyStepper, Options};
    use vibroimpact_core::model::assembly::{
        initial_state, Assembly, Excitation, Load, SystemSpec,
    };
    use vibroimpact_core::model::structure::Structure;
    let w = TAU;
    let mut spec = SystemSpec::of(Structure::oscillator(1.0, w * w, 2.0 * 0.02 * w)?, vec![]);
    let pulse = Signal::recorded(vec![5.0, 5.0005, 5.001], vec![0.0, 100.0, 0.0], 1.0)?;
    spec.excitations = vec![Excitation {
        load: Load::Force { at: 0.0 },
        signal: pulse,
    }];
    let system = Assembly::new(&spec)?;
    let y0 = initial_state(&system, &[0.0], &[0.0], &[], &[])?;
    let mut method = AnyStepper::new(&system, "rk4", &Options::default())?;
    let options = RunOptions {
        dt: Some(dt),
        t_end: 6.0,
        every: 1,
        keep_history: false,
        max_steps: 100_000_000,
        max_rows: 1_000_000,
        energy_tolerance: 1e-2,
        reduce: Default::default(),
    };
    let run = method.integrate(&system, &y0, &options, &mut || false)?;
    Ok(run.final_state[0])
}

#[test]
fn a_fixed_step_longer_than_a_records_samples_is_refused_not_a_pulse_lost() {
    common::timeout(60, || {
        // The impulse response I / (m w_d) e^(-zeta w t) sin(w_d t), 1 s after the
        // pulse's centre (its 1 ms width shifts it by far less than the tolerance).
        let (zeta, w) = (0.02, TAU);
        let wd = w * (1.0f64 - zeta * zeta).sqrt();
        let t = 1.0 - 0.0005;
        let expected = 0.05 / wd * (-zeta * w * t).exp() * (wd * t).sin();
        let found = struck_by_a_pulse(1e-4).unwrap();
        assert!(
            (found - expected).abs() < 1e-3 * expected.abs(),
            "{found} {expected}"
        );
        // At dt = 3e-3 s the pulse fell between two steps' stages: x(6) = 0 and no
        // input work, without a word.
        let refused = struck_by_a_pulse(3e-3).unwrap_err().to_string();
        assert!(
            refused.contains("\"recorded\" excitation changes every 5.000e-4 s")
                && refused.contains("dt = 3e-3 s"),
            "{refused}"
        );
    });
}

#[test]
fn a_ground_filter_too_stiff_over_the_whole_record_is_refused_at_once() {
    common::timeout(10, || {
        // 1.3e6 filter steps a sample over 50,001 samples: it had been accepted
        // (each sample's steps within bounds) and ran for minutes past Ctrl-C.
        let error = Signal::kanai_tajimi(1.0, 2.5, 1e5, 25.0, 1000.0, 7).unwrap_err();
        assert!(
            error
                .to_string()
                .contains("too stiff to integrate over 1000 s"),
            "{error}"
        );
        // A soil's damping over the same record is generated.
        assert!(Signal::kanai_tajimi(1.0, 2.5, 0.6, 25.0, 1000.0, 7).is_ok());
    });
}
