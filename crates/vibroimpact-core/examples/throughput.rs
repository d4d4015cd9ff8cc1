//! Steps per second of the core kernel alone (no Python), on the founding
//! paper's Table 1 system with Hyster-Hertz contact (e = 0.9), 1e7 steps.
//!
//!     cargo run --release -p vibroimpact-core --example throughput

use std::time::Instant;
use vibroimpact_core::{
    simulate, Contact, ContactTiming, ImpactDamper, LawKind, Method, Settings, State,
};

fn main() {
    let system = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.01).unwrap();
    let contact = Contact::new(LawKind::HysterHertz, 3000.0, Some(0.9), 0.01).unwrap();
    let start = State::new(0.0, 0.0, 0.01, 0.1).unwrap();
    let steps = 10_000_000u64;
    for (name, method) in [
        (
            "newmark",
            Method::Newmark {
                beta: 0.25,
                gamma: 0.5,
            },
        ),
        ("rk4", Method::Rk4),
    ] {
        let settings = Settings::new(
            method,
            1e-4,
            steps as f64 * 1e-4,
            100_000,
            ContactTiming::Located,
        )
        .unwrap();
        let mut times: Vec<f64> = (0..5)
            .map(|_| {
                let t0 = Instant::now();
                let sol = simulate(&system, &contact, &start, &settings, &mut || false).unwrap();
                assert_eq!(sol.steps, steps);
                t0.elapsed().as_secs_f64()
            })
            .collect();
        times.sort_by(f64::total_cmp);
        println!(
            "{name:8} {:.3e} steps/s (median of 5)",
            steps as f64 / times[2]
        );
    }
}
