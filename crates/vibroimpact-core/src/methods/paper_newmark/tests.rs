//! The founding paper's Newmark on the general kernel against closed forms,
//! the trapezoidal rule it is on linear systems, the registry's checks and
//! the kernel's durations (its steps on the two-mass system against the
//! paper's equations written out: `two_mass_tests.rs`).

use super::two_mass_tests::table_1;
use super::*;
use crate::model::assembly::{initial_state, Excitation, Load, SystemSpec};
use crate::model::contact::{Contact, LawKind};
use crate::model::impact_damper::State;
use crate::model::signals::Signal;
use crate::model::structure::Structure;
use std::f64::consts::TAU;

/// A structure alone (no pair), with `excitations`.
fn bare(structure: Structure, excitations: Vec<Excitation>) -> Assembly {
    Assembly::new(&SystemSpec {
        excitations,
        ..SystemSpec::of(structure, vec![])
    })
    .unwrap()
}

/// `steps` steps `h` of the paper's Newmark (average acceleration) from
/// `y0` with every pair open: the end state.
fn free_steps(system: &Assembly, y0: &[f64], h: f64, steps: usize) -> Vec<f64> {
    let mut stepper = PaperNewmark::new(system, 0.25, 0.5).unwrap();
    let mut scratch = Scratch::new(system);
    let modes = vec![Mode::Open; system.interactions.len()];
    let (mut y, mut end) = (y0.to_vec(), y0.to_vec());
    for n in 0..steps {
        stepper
            .attempt(system, n as f64 * h, &y, h, &modes, &mut scratch, &mut end)
            .unwrap();
        stepper.accept();
        std::mem::swap(&mut y, &mut end);
    }
    y
}

#[test]
fn free_oscillation_has_newmark_s_period_elongation() {
    crate::testing::timeout(30, || {
        // Average acceleration is the trapezoidal rule: on x'' = -w^2 x it
        // turns the phase by 2 atan(w h / 2) a step, exactly, at constant
        // amplitude, so x_n = cos(n theta) from x = 1, v = 0. The period
        // grows by w h / (2 atan(w h / 2)) - 1 = (w h)^2 / 12 + O(h^4):
        // the error is second order with constant 1/12.
        let w = TAU;
        let system = bare(
            Structure::oscillator(2.0, 2.0 * w * w, 0.0).unwrap(),
            vec![],
        );
        let y0 = initial_state(&system, &[1.0], &[0.0], &[], &[]).unwrap();
        let mut elongations = vec![];
        for per_period in [20, 40, 80, 160] {
            let h = 1.0 / per_period as f64;
            let steps = 3 * per_period;
            let y = free_steps(&system, &y0, h, steps);
            let theta = 2.0 * (w * h / 2.0).atan();
            let phase = steps as f64 * theta;
            assert!((y[0] - phase.cos()).abs() < 1e-12, "{per_period}: {}", y[0]);
            assert!(
                (y[1] + w * phase.sin()).abs() < 1e-11,
                "{per_period}: {}",
                y[1]
            );
            // Three numerical periods take 3 T (1 + elongation).
            let elongation = w * h / theta - 1.0;
            let lag = (3.0 * TAU - phase) / phase;
            assert!((lag - elongation).abs() < 1e-12, "{per_period}");
            let leading = (w * h).powi(2) / 12.0;
            assert!(((elongation - leading) / leading).abs() < 0.25 * (w * h).powi(2));
            // Against the exact motion cos(w t): off by the phase lag only.
            let exact = (w * steps as f64 * h).cos();
            assert!((y[0] - exact).abs() <= 1.01 * (3.0 * TAU - phase).abs());
            elongations.push(elongation);
        }
        for pair in elongations.windows(2) {
            let order = (pair[0] / pair[1]).log2();
            assert!((order - 2.0).abs() < 0.01, "order {order}");
        }
    });
}

/// The trapezoidal rule on `z' = A z + b(t)` for `z = (x, v)` of a
/// structure (`M`, `C`, `K`, a force `f(t)` on coordinate 0), written as
/// its own linear solve a step: the reference for the Newmark stepper.
fn trapezoidal(
    (m, c, k): (&[f64], &[f64], &[f64]),
    force: impl Fn(f64) -> f64,
    y0: &[f64],
    h: f64,
    steps: usize,
) -> Vec<f64> {
    let n = y0.len() / 2;
    let minv = linalg::inverse_from_cholesky(&linalg::cholesky(m, n).unwrap(), n);
    let product = |a: &[f64]| {
        let mut out = vec![0.0; n * n];
        linalg::matmul(&minv, a, &mut out, n);
        out
    };
    let (mk, mc) = (product(k), product(c));
    let s = 2 * n;
    let mut a = vec![0.0; s * s];
    for i in 0..n {
        a[i * s + n + i] = 1.0;
        for j in 0..n {
            a[(n + i) * s + j] = -mk[i * n + j];
            a[(n + i) * s + n + j] = -mc[i * n + j];
        }
    }
    let b = |t: f64| {
        let mut out = vec![0.0; s];
        for i in 0..n {
            out[n + i] = minv[i * n] * force(t);
        }
        out
    };
    let mut z = y0.to_vec();
    for step in 0..steps {
        let t = step as f64 * h;
        let (b0, b1) = (b(t), b(t + h));
        let mut lhs = vec![0.0; s * s];
        let mut rhs = vec![0.0; s];
        for i in 0..s {
            rhs[i] = z[i] + 0.5 * h * (b0[i] + b1[i]);
            for j in 0..s {
                let identity = if i == j { 1.0 } else { 0.0 };
                lhs[i * s + j] = identity - 0.5 * h * a[i * s + j];
                rhs[i] += 0.5 * h * a[i * s + j] * z[j];
            }
        }
        linalg::solve_in_place(&mut lhs, &mut rhs, s);
        z = rhs;
    }
    z
}

#[test]
fn forced_damped_coupled_structures_step_as_the_trapezoidal_rule() {
    crate::testing::timeout(30, || {
        // One, two and three coupled coordinates (the 1x1, the adjugate
        // and the elimination inverse), damped, forced harmonically on the
        // first: the stepper (its loads from the assembly's linear parts,
        // its start accelerations from the assembly's rates where the
        // matrices are not diagonal) against the trapezoidal rule solved
        // directly on the first-order system.
        let signal = Signal::harmonic(0.7, 1.3, 0.4).unwrap();
        let force = |t: f64| 0.7 * (TAU * 1.3 * t + 0.4).cos();
        let chain = |n: usize| {
            let row = |i: usize, diagonal: f64, off: f64| {
                (0..n)
                    .map(|j| match i.abs_diff(j) {
                        0 => diagonal,
                        1 => off,
                        _ => 0.0,
                    })
                    .collect::<Vec<_>>()
            };
            let mass: Vec<_> = (0..n).map(|i| row(i, 1.0 + 0.5 * i as f64, 0.1)).collect();
            let stiffness: Vec<_> = (0..n).map(|i| row(i, 80.0, -30.0)).collect();
            let damping: Vec<_> = (0..n).map(|i| row(i, 0.4, -0.1)).collect();
            Structure::matrices(&mass, &stiffness, &damping).unwrap()
        };
        for n in 1..=3 {
            let structure = chain(n);
            let parts = (
                structure.mass().to_vec(),
                structure.damping().to_vec(),
                structure.stiffness().to_vec(),
            );
            let excitation = Excitation {
                load: Load::Force { at: 0.0 },
                signal: signal.clone(),
            };
            let system = bare(structure, vec![excitation]);
            let x0: Vec<f64> = (0..n).map(|i| 0.01 * (i as f64 + 1.0)).collect();
            let v0: Vec<f64> = (0..n).map(|i| 0.2 - 0.15 * i as f64).collect();
            let y0 = initial_state(&system, &x0, &v0, &[], &[]).unwrap();
            let (h, steps) = (2e-3, 2000);
            let ours = free_steps(&system, &y0, h, steps);
            let z0 = [x0.clone(), v0.clone()].concat();
            let reference = trapezoidal((&parts.0, &parts.1, &parts.2), force, &z0, h, steps);
            for (i, (a, b)) in ours.iter().zip(&reference).enumerate() {
                assert!((a - b).abs() < 1e-11, "{n} coordinates, {i}: {a} vs {b}");
            }
        }
    });
}

#[test]
fn the_registry_makes_it_as_newmark_with_checked_options() {
    crate::testing::timeout(30, || {
        use crate::methods::registry::{AnyStepper, Options, METHODS};
        use crate::model::assembly::{Damper, PairLaw};
        let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.01).unwrap();
        let system = table_1(0.005).assembly(&contact).unwrap();
        let make = |method: &str, beta: f64, gamma: f64| {
            AnyStepper::new(
                &system,
                method,
                &Options {
                    beta,
                    gamma,
                    ..Options::default()
                },
            )
        };
        let message = |method: &str, beta: f64, gamma: f64| match make(method, beta, gamma) {
            Ok(_) => panic!("{method} with beta {beta}, gamma {gamma} accepted"),
            Err(e) => e.to_string(),
        };
        assert!(matches!(
            make("newmark", 0.25, 0.5),
            Ok(AnyStepper::Paper(_))
        ));
        assert!(matches!(
            make("newmark", 0.0, 1.0),
            Ok(AnyStepper::Paper(_))
        ));
        for method in ["newmark", "newmark-implicit"] {
            for (beta, gamma, field) in [
                (0.51, 0.5, "beta"),
                (-0.01, 0.5, "beta"),
                (f64::NAN, 0.5, "beta"),
                (0.25, 0.49, "gamma"),
                (0.25, 1.01, "gamma"),
            ] {
                let text = message(method, beta, gamma);
                assert!(text.contains(field), "{method}: {text}");
            }
        }
        // Every name the registry lists is known (the exact flow refuses
        // this system's Hertz law, not its name); any other is refused with
        // the list.
        for method in METHODS {
            if let Err(e) = make(method, 0.25, 0.5) {
                assert!(!e.to_string().contains("must be one of"), "{method}: {e}");
            }
        }
        assert_eq!(
            message("newmark-lagged", 0.25, 0.5),
            "method must be one of \"rk4\", \"dopri5\", \"dop853\", \"newmark\", \
             \"newmark-implicit\", \"generalized-alpha\", \"exact\" for a [structure] system, \
             got \"newmark-lagged\""
        );
        // A rigid pair has no force to lag: refused, naming it.
        let mut spec = table_1(0.005).spec(&contact).unwrap();
        spec.dampers.push(Damper {
            law: PairLaw::rigid(0.5).unwrap(),
            ..spec.dampers[0].clone()
        });
        let rigid = Assembly::new(&spec).unwrap();
        let refused = PaperNewmark::new(&rigid, 0.25, 0.5)
            .unwrap_err()
            .to_string();
        assert!(refused.contains("damper 1 is rigid"), "{refused}");
    });
}

#[test]
fn the_kernel_runs_it_at_the_paper_s_first_order_duration_error() {
    crate::testing::timeout(60, || {
        // Table 1's collision through the registry and the event kernel
        // (onset and separation located, the step cut there): the contact
        // lasts what the high-accuracy reference gives (0.1089819 s for
        // Hertz, 0.1100637 s for Hyster-Hertz e = 0.9, paper-model.md) but
        // for the lag's error, about 0.05 % at dt = 1e-4 s and 0.01 % at
        // 2e-5 s: first order.
        use crate::kernel::events::RunOptions;
        use crate::methods::registry::{AnyStepper, Options};
        for (law, restitution, exact) in [
            (LawKind::Hertz, None, 0.1089819),
            (LawKind::HysterHertz, Some(0.9), 0.1100637),
        ] {
            let contact = Contact::new(law, 3000.0, restitution, 0.01).unwrap();
            let system = table_1(0.01).assembly(&contact).unwrap();
            let y0 = State::new(0.0, 0.0, 0.01, 0.1)
                .unwrap()
                .vector(&system)
                .unwrap();
            let mut errors = vec![];
            for dt in [1e-4, 2e-5] {
                let options = RunOptions {
                    dt: Some(dt),
                    t_end: 0.15,
                    every: 1,
                    keep_history: false,
                    max_steps: 1_000_000,
                    max_rows: 1_000_000,
                    energy_tolerance: 0.05,
                    reduce: Default::default(),
                };
                let mut stepper = AnyStepper::new(&system, "newmark", &Options::default()).unwrap();
                let sol = stepper
                    .integrate(&system, &y0, &options, &mut || false)
                    .unwrap();
                assert_eq!(sol.contacts.len(), 1, "{law:?}, dt {dt}");
                errors.push((sol.contacts[0].duration / exact - 1.0).abs());
            }
            assert!(
                errors[0] < 7e-4 && errors[1] < 1.5e-4,
                "{law:?}: {errors:?}"
            );
            let ratio = errors[0] / errors[1];
            assert!((4.0..6.5).contains(&ratio), "{law:?}: {errors:?}");
        }
    });
}

#[test]
fn it_counts_one_evaluation_a_step() {
    crate::testing::timeout(30, || {
        // 0.1's fixed-step kernel reported steps x 1 right-hand-side
        // evaluations for the paper's Newmark; restarts are not counted.
        let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.01).unwrap();
        let system = table_1(0.005).assembly(&contact).unwrap();
        let mut stepper = PaperNewmark::new(&system, 0.25, 0.5).unwrap();
        let mut scratch = Scratch::new(&system);
        let y = State::new(0.0, 0.0, 0.0, 0.1)
            .unwrap()
            .vector(&system)
            .unwrap();
        let mut end = y.clone();
        let modes = [Mode::Open; 2];
        for step in 0..10 {
            if step % 3 == 0 {
                stepper.reset();
            }
            stepper
                .attempt(&system, 0.0, &y, 1e-4, &modes, &mut scratch, &mut end)
                .unwrap();
            stepper.accept();
        }
        assert_eq!(stepper.evaluations(), 10);
    });
}

#[test]
fn its_accumulator_rates_are_the_assembly_s() {
    crate::testing::timeout(30, || {
        // The powers the stepper takes at a step's end without the
        // accelerations equal `Assembly::rates`' last slots: a modal beam
        // and a coupled chain, forced and on a base, each damper apart, in
        // contact, and in compliant mode while apart (only its damper acts).
        use crate::model::assembly::{Damper, PairLaw};
        let contact = Contact::new(LawKind::HertzDamped, 1e5, Some(0.6), 0.3).unwrap();
        let coupled = Structure::matrices(
            &[vec![1.0, 0.1], vec![0.1, 2.0]],
            &[vec![50.0, -20.0], vec![-20.0, 40.0]],
            &[vec![0.3, -0.1], vec![-0.1, 0.2]],
        )
        .unwrap();
        let beam = Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.01).unwrap();
        for (structure, at) in [(coupled, 1.0), (beam, 0.5)] {
            let system = Assembly::new(&SystemSpec {
                structure,
                dampers: vec![Damper {
                    mass: 0.05,
                    at,
                    lower_clearance: 1e-3,
                    upper_clearance: 2e-3,
                    law: PairLaw::Compliant(contact),
                }],
                collisions: vec![],
                frictions: vec![],
                stops: vec![],
                gravity: 9.81,
                excitations: vec![
                    Excitation {
                        load: Load::Force { at },
                        signal: Signal::harmonic(0.5, 8.0, 0.3).unwrap(),
                    },
                    Excitation {
                        load: Load::Base,
                        signal: Signal::harmonic(1.5, 5.0, 0.1).unwrap(),
                    },
                ],
                points: vec![],
                moments: vec![],
            })
            .unwrap();
            let stepper = PaperNewmark::new(&system, 0.25, 0.5).unwrap();
            let mut scratch = Scratch::new(&system);
            let (d, len) = (system.dim, system.state_len());
            let (mut rates, mut ours) = (vec![0.0; len], vec![0.0; len - 2 * d]);
            for seed in 0..20 {
                let y: Vec<f64> = (0..len)
                    .map(|i| 2e-3 * (seed as f64 + 0.37 * i as f64).sin())
                    .collect();
                let compliant = Mode::Compliant {
                    approach_rate: 0.2,
                    indented_only: false,
                };
                for modes in [
                    [Mode::Open; 2],
                    [compliant, Mode::Open],
                    [Mode::Open, compliant],
                ] {
                    let time = 0.01 * seed as f64;
                    system.rates(time, &y, &modes, &mut scratch, &mut rates);
                    stepper.end_powers(
                        &system,
                        (system.n, d),
                        time,
                        &y[..2 * d],
                        &modes,
                        &mut ours,
                    );
                    for (k, (a, b)) in rates[2 * d..].iter().zip(&ours).enumerate() {
                        let scale = a.abs().max(1e-30);
                        assert!(
                            (a - b).abs() <= 1e-12 * scale,
                            "{seed} {modes:?} {k}: {a} {b}"
                        );
                    }
                }
            }
        }
    });
}
