//! Steps per second of the core kernels alone (no Python), on the founding
//! paper's Table 1 system with Hyster-Hertz contact (e = 0.9), 1e7 steps of
//! 1e-4 s for each fixed-step method; then the time per collision of the
//! adaptive methods. Each method and stepping on the general kernel (the
//! preset [`ImpactDamper::assembly`]), as the two-mass `simulate` runs them;
//! fixed RK4 beside numba's bar (the 0.1 prototype's JIT loop, 7.1e7 steps/s
//! on this machine), and each other method and stepping beside fixed RK4
//! measured in the same run (a ratio the machine's load moves less).
//!
//!     cargo run --release -p vibroimpact-core --example throughput

use std::time::Instant;
use vibroimpact_core::methods::registry::two_mass;
use vibroimpact_core::{
    Contact, ContactTiming, ImpactDamper, LawKind, Method, Settings, State, Stepping, Tolerances,
};

/// numba's fixed-step RK4 on this system (the 0.1 prototype), steps/s: the
/// bar the two-mass RK4 keeps.
const NUMBA_RK4_STEPS_PER_SECOND: f64 = 7.1e7;

/// Median of `repeats` seconds of `run`, which returns the steps it took.
fn median_seconds(repeats: usize, least_steps: u64, mut run: impl FnMut() -> u64) -> f64 {
    let mut times: Vec<f64> = (0..repeats)
        .map(|_| {
            let t0 = Instant::now();
            assert!(run() >= least_steps);
            t0.elapsed().as_secs_f64()
        })
        .collect();
    times.sort_by(f64::total_cmp);
    times[repeats / 2]
}

/// The run of `settings` on the general kernel, as the binding makes it:
/// its steps (and one contact at least).
fn general(system: &ImpactDamper, contact: &Contact, start: &State, settings: &Settings) -> u64 {
    let sol = two_mass::simulate(system, contact, start, settings, &mut || false).unwrap();
    assert!(!sol.contacts.is_empty());
    sol.steps
}

fn main() {
    let system = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.01).unwrap();
    let contact = Contact::new(LawKind::HysterHertz, 3000.0, Some(0.9), 0.01).unwrap();
    let start = State::new(0.0, 0.0, 0.01, 0.1).unwrap();
    let steps = 10_000_000u64;
    let newmark = Method::Newmark {
        beta: 0.25,
        gamma: 0.5,
    };
    let runs = [
        // First: the peer of the lines after it.
        ("rk4 (fixed)", Method::Rk4, Stepping::Fixed),
        ("newmark (fixed)", newmark, Stepping::Fixed),
        ("newmark (events)", newmark, Stepping::Events),
        ("rk4 (events)", Method::Rk4, Stepping::Events),
        (
            "newmark-implicit",
            Method::NewmarkImplicit {
                beta: 0.25,
                gamma: 0.5,
            },
            Stepping::Events,
        ),
        (
            "generalized-alpha",
            Method::GeneralizedAlpha {
                spectral_radius: 0.9,
            },
            Stepping::Events,
        ),
    ];
    let mut rk4_rate = f64::NAN;
    for (name, method, stepping) in runs {
        let settings = Settings::new(
            method,
            Some(1e-4),
            steps as f64 * 1e-4,
            100_000,
            ContactTiming::Located,
            Some(stepping),
            u64::MAX,
        )
        .unwrap();
        let run = median_seconds(5, steps, || general(&system, &contact, &start, &settings));
        let rate = steps as f64 / run;
        let peer = if (method, stepping) == (Method::Rk4, Stepping::Fixed) {
            rk4_rate = rate;
            format!(
                "numba {NUMBA_RK4_STEPS_PER_SECOND:.1e}, {:.2}x",
                rate / NUMBA_RK4_STEPS_PER_SECOND
            )
        } else {
            format!("{:.2}x fixed rk4", rate / rk4_rate)
        };
        println!("{name:18} {rate:.3e} steps/s (median of 5; {peer})");
    }
    collision_times();
}

/// Median time per Table 1 collision (0.15 s from onset, Hertz contact) of
/// the adaptive methods.
fn collision_times() {
    let system = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.01).unwrap();
    let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.01).unwrap();
    let start = State::new(0.0, 0.0, 0.01, 0.1).unwrap();
    for rtol in [1e-6, 1e-8, 1e-10] {
        let tolerances = Tolerances {
            rtol,
            atol: rtol * 1e-3,
        };
        for (name, method) in [
            ("dopri5", Method::Dopri5(tolerances)),
            ("dop853", Method::Dop853(tolerances)),
        ] {
            let settings = Settings::new(
                method,
                None,
                0.15,
                1_000_000,
                ContactTiming::Located,
                None,
                u64::MAX,
            )
            .unwrap();
            let repeats = 2001;
            let run = median_seconds(repeats, 1, || general(&system, &contact, &start, &settings));
            println!(
                "{name:8} rtol {rtol:.0e}: {:.2} us per collision (median of {repeats})",
                run * 1e6
            );
        }
    }
}
