use super::energies::{NODES, OFFSETS, WEIGHTS};
use super::oscillator::Oscillator;
use super::ExactFlow;
use crate::methods::steppers::SystemStepper;
use crate::model::assembly::{
    initial_state, Assembly, Damper, Excitation, Load, Mode, PairLaw, Scratch, SystemSpec, INPUT,
};
use crate::model::signals::Signal;
use crate::model::structure::Structure;

#[test]
fn nodes_by_the_addition_theorems_are_the_factors_there() {
    crate::testing::timeout(30, || {
        let h = 0.01;
        // Underdamped, near critical, overdamped, free, free and damped.
        for (w2, c) in [
            (4e3, 3.0),
            (400.0, 40.0),
            (100.0, 60.0),
            (0.0, 0.0),
            (0.0, 5.0),
        ] {
            let o = Oscillator::new(w2, c, 0.0);
            let (mid, far, near) = (
                o.factors(0.5 * h),
                o.factors(OFFSETS[0] * h),
                o.factors(OFFSETS[1] * h),
            );
            let derived = [
                o.difference(mid, far),
                o.difference(mid, near),
                mid,
                o.sum(mid, near),
                o.sum(mid, far),
            ];
            for (x, d) in NODES.iter().zip(derived) {
                let direct = o.factors(x * h);
                assert!(
                    (d.0 - direct.0).abs() <= 1e-15,
                    "{w2} {c}: {d:?} {direct:?}"
                );
                assert!(
                    (d.1 - direct.1).abs() <= 1e-15 * h,
                    "{w2} {c}: {d:?} {direct:?}"
                );
            }
        }
    });
}

/// The forced damper (a structure and a loose mass, gravity), its flow
/// started at a state in motion.
fn forced_flow(damping: f64) -> (Assembly, ExactFlow, Vec<f64>) {
    let spec = SystemSpec {
        structure: Structure::oscillator(1.0, 3000.0, damping).unwrap(),
        dampers: vec![Damper {
            mass: 0.05,
            at: 0.0,
            lower_clearance: 0.01,
            upper_clearance: 0.01,
            law: PairLaw::rigid(0.6).unwrap(),
        }],
        collisions: vec![],
        frictions: vec![],
        stops: vec![],
        gravity: 9.81,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(20.0, 7.0, 0.3).unwrap(),
        }],
        points: vec![],
        moments: vec![],
    };
    let system = Assembly::new(&spec).unwrap();
    let y = initial_state(&system, &[0.004], &[-0.2], &[0.002], &[0.3]).unwrap();
    let flow = ExactFlow::new(&system).unwrap();
    (system, flow, y)
}

#[test]
fn end_derivatives_are_the_system_s_accelerations_and_their_rates() {
    crate::testing::timeout(30, || {
        for damping in [3.0, 200.0] {
            let (system, mut flow, y) = forced_flow(damping);
            let (dim, len) = (system.dim, system.state_len());
            let modes = vec![Mode::Open; system.interactions.len()];
            let mut scratch = Scratch::new(&system);
            let (mut end, mut rates) = (vec![0.0; len], vec![0.0; len]);
            let (mut accel, mut jerk) = (vec![0.0; dim], vec![0.0; dim]);
            let (time, h) = (0.37, 0.6 * flow.step());
            // The accelerations at `t` after the start, by the system.
            let mut accelerations = |flow: &mut ExactFlow, t: f64| {
                flow.attempt(&system, time, &y, t, &modes, &mut scratch, &mut end)
                    .unwrap();
                system.rates(time + t, &end, &modes, &mut scratch, &mut rates);
                rates[dim..2 * dim].to_vec()
            };
            let expected = accelerations(&mut flow, h);
            assert!(flow.end_derivatives(&system, &mut accel, &mut jerk));
            let delta = 1e-5 * h;
            let (ahead, behind) = (
                accelerations(&mut flow, h + delta),
                accelerations(&mut flow, h - delta),
            );
            for i in 0..dim {
                let scale = expected.iter().fold(0.0f64, |m, a| m.max(a.abs()));
                assert!(
                    (accel[i] - expected[i]).abs() <= 1e-12 * scale,
                    "{damping}: {accel:?} {expected:?}"
                );
                let difference = (ahead[i] - behind[i]) / (2.0 * delta);
                let jerk_scale = jerk.iter().fold(0.0f64, |m, a| m.max(a.abs()));
                assert!(
                    (jerk[i] - difference).abs() <= 1e-6 * jerk_scale,
                    "{damping}: {jerk:?} {difference}"
                );
            }
            // Only for the last evaluation, once.
            assert!(flow.end_derivatives(&system, &mut accel, &mut jerk));
            assert!(!flow.end_derivatives(&system, &mut accel, &mut jerk));
        }
    });
}

#[test]
fn energies_left_to_a_later_step_are_the_steps_own_sum() {
    crate::testing::timeout(30, || {
        for damping in [3.0, 200.0] {
            let (system, mut flow, y0) = forced_flow(damping);
            let (at, len) = (2 * system.dim, system.state_len());
            let modes = vec![Mode::Open; system.interactions.len()];
            let mut scratch = Scratch::new(&system);
            let h = 0.7 * flow.step();
            // Seven steps, settled every step or at the third and the last.
            let mut run = |settle_at: &dyn Fn(usize) -> bool| {
                let (mut y, mut end) = (y0.clone(), vec![0.0; len]);
                let mut time = 0.25;
                for k in 0..7 {
                    flow.attempt(&system, time, &y, h, &modes, &mut scratch, &mut end)
                        .unwrap();
                    flow.finish(
                        &system,
                        time,
                        &y,
                        h,
                        &modes,
                        &mut scratch,
                        &mut end,
                        settle_at(k),
                    )
                    .unwrap();
                    if !settle_at(k) {
                        assert_eq!(end[at..], y[at..], "left as they were");
                    }
                    std::mem::swap(&mut y, &mut end);
                    time += h;
                }
                y
            };
            let each = run(&|_| true);
            let later = run(&|k| k == 2 || k == 6);
            assert_eq!(each[..at], later[..at]);
            for k in at..len {
                let scale = each[k].abs().max(1e-300);
                assert!(
                    (each[k] - later[k]).abs() <= 1e-12 * scale,
                    "{damping}: {each:?} {later:?}"
                );
            }
            assert!(each[at..].iter().any(|e| e.abs() > 0.0));
        }
    });
}

#[test]
fn near_an_undamped_resonance_the_state_and_its_input_work_keep_their_digits() {
    crate::testing::timeout(30, || {
        // 1 Hz forcing 1e-5 below an undamped mode (issue 23): the
        // particular response is 1.2e4 m, the motion from rest 0.4 m/s
        // a second. Without losses the work put in is the energy stored.
        let spec = SystemSpec {
            structure: Structure::oscillator(1.0, 39.478, 0.0).unwrap(),
            dampers: vec![],
            collisions: vec![],
            frictions: vec![],
            stops: vec![],
            gravity: 0.0,
            excitations: vec![Excitation {
                load: Load::Force { at: 0.0 },
                signal: Signal::harmonic(5.0, 1.0, 0.0).unwrap(),
            }],
            points: vec![],
            moments: vec![],
        };
        let system = Assembly::new(&spec).unwrap();
        let mut flow = ExactFlow::new(&system).unwrap();
        let (at, len) = (2 * system.dim, system.state_len());
        let modes = vec![Mode::Open; system.interactions.len()];
        let mut scratch = Scratch::new(&system);
        let (mut y, mut end) = (vec![0.0; len], vec![0.0; len]);
        let (h, mut time) = (1e-3, 0.0);
        for k in 0..2000 {
            flow.attempt(&system, time, &y, h, &modes, &mut scratch, &mut end)
                .unwrap();
            let settle = k % 32 == 31;
            flow.finish(&system, time, &y, h, &modes, &mut scratch, &mut end, settle)
                .unwrap();
            std::mem::swap(&mut y, &mut end);
            time += h;
        }
        // Undamped from rest: x = Z (cos W t - cos w t), Z = P / (w^2 - W^2),
        // as a product that divides nothing small.
        let (w, forcing) = (39.478f64.sqrt(), std::f64::consts::TAU);
        let (sum, difference) = (0.5 * (w + forcing), 0.5 * (w - forcing));
        let x = 5.0 / (2.0 * sum * difference) * (sum * time).sin() * (difference * time).sin();
        // The motion is 0.8 m at most and the particular response 1.2e4 m:
        // its round-off (eps of it a step) had been 1e-10 m after these
        // 2000 steps.
        assert!((y[0] - x).abs() <= 2e-12, "{} {x}", y[0]);
        let stored = system.energy(&y, &modes);
        assert!(stored > 0.1, "{stored}");
        // Round-off of the flow's states (eps of the particular response
        // a step) bounds the miss, not the closed form's 1e-5 J a stretch.
        assert!(
            (y[at + INPUT] - stored).abs() <= 1e-9 * stored,
            "{} {stored}",
            y[at + INPUT]
        );
    });
}

#[test]
fn closed_form_step_energies_are_the_gauss_legendre_quadrature_s() {
    crate::testing::timeout(30, || {
        for damping in [3.0, 200.0] {
            let (system, mut flow, y) = forced_flow(damping);
            let dim = system.dim;
            let modes = vec![Mode::Open; system.interactions.len()];
            let index = flow.select(&system, &modes).unwrap();
            let mut end = vec![0.0; system.state_len()];
            for (time, h) in [(0.0, flow.step()), (1.37, 0.3 * flow.step()), (2.0, 1e-6)] {
                flow.begin(index, dim, time, &y);
                flow.at(index, dim, h, &mut end);
                let r = flow.modes[index].configuration.modes;
                flow.span_modal[..r].copy_from_slice(&flow.origin_modal[..r]);
                let phasor = flow.phasors[0];
                let (viscous, input) = flow.step_energies(index, dim, h, phasor, &end);
                flow.node_factors(index, h);
                let (mut v, mut i) = (0.0, 0.0);
                for (k, (x, w)) in NODES.iter().zip(WEIGHTS).enumerate() {
                    let (pv, pi) = flow.powers_at(index, k, x * h);
                    v += w * h * pv;
                    i += w * h * pi;
                }
                let scale = v.abs().max(i.abs());
                assert!(
                    (viscous - v).abs() <= 1e-10 * scale,
                    "{damping} {h}: {viscous} {v}"
                );
                assert!(
                    (input - i).abs() <= 1e-10 * scale,
                    "{damping} {h}: {input} {i}"
                );
            }
        }
    });
}

/// Ten loose masses in a row on a forced, damped oscillator under gravity,
/// drawing apart in free flight: a flow of eleven coordinates, taken by the
/// non-zero entries of its transforms (each free mass's mode is its own
/// coordinate), must give each mass its parabola and every coordinate the
/// accelerations (and their rates) the system's own rates give.
#[test]
fn a_large_system_s_flow_is_its_free_flights_and_its_rates() {
    crate::testing::timeout(30, || {
        let structure = Structure::oscillator(1.0, 3000.0, 3.0).unwrap();
        let masses: Vec<f64> = (0..10).map(|j| 0.01 * (1.0 + j as f64)).collect();
        let law = PairLaw::rigid(0.9).unwrap();
        let spec = SystemSpec {
            excitations: vec![Excitation {
                load: Load::Force { at: 0.0 },
                signal: Signal::harmonic(20.0, 7.0, 0.3).unwrap(),
            }],
            ..SystemSpec::column(structure, 0.0, &masses, [0.05, 0.05, 0.5], law)
        };
        let system = Assembly::new(&spec).unwrap();
        let (dim, len) = (system.dim, system.state_len());
        assert_eq!(dim, 11);
        let speeds: Vec<f64> = (0..10).map(|j| 0.01 * j as f64).collect();
        let y = initial_state(&system, &[0.004], &[-0.2], &[0.0; 10], &speeds).unwrap();
        let mut flow = ExactFlow::new(&system).unwrap();
        let modes = vec![Mode::Open; system.interactions.len()];
        let mut scratch = Scratch::new(&system);
        let (mut end, mut rates) = (vec![0.0; len], vec![0.0; len]);
        let (time, h) = (0.37, 0.6 * flow.step());
        flow.attempt(&system, time, &y, h, &modes, &mut scratch, &mut end)
            .unwrap();
        for k in 1..dim {
            // x0 + v0 h - g h^2 / 2, v0 - g h.
            let (x, v) = (
                y[k] + y[dim + k] * h - 0.5 * 9.81 * h * h,
                y[dim + k] - 9.81 * h,
            );
            assert!(
                (end[k] - x).abs() <= 1e-15 * (1.0 + x.abs()),
                "{k}: {} {x}",
                end[k]
            );
            assert!(
                (end[dim + k] - v).abs() <= 1e-14,
                "{k}: {} {v}",
                end[dim + k]
            );
        }
        // The flow's accelerations at the end against the system's rates.
        system.rates(time + h, &end, &modes, &mut scratch, &mut rates);
        let (mut accel, mut jerk) = (vec![0.0; dim], vec![0.0; dim]);
        assert!(flow.end_derivatives(&system, &mut accel, &mut jerk));
        let scale = rates[dim..2 * dim]
            .iter()
            .fold(0.0f64, |m, a| m.max(a.abs()));
        for i in 0..dim {
            assert!(
                (accel[i] - rates[dim + i]).abs() <= 1e-12 * scale,
                "{i}: {accel:?} {rates:?}"
            );
        }
        // A free mass's acceleration is gravity's alone: no jerk.
        assert!(jerk[1..].iter().all(|j| *j == 0.0), "{jerk:?}");
        assert!(jerk[0] != 0.0);
    });
}
