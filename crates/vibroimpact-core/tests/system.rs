//! The 0.2 kernel on any system, against closed forms and conservation laws:
//! forced linear responses started on their steady state, a cantilever's free
//! modes, the bouncing ball's accumulation time, momentum through rigid
//! impacts, the energy balance closing, and compliant contact tending to
//! rigid as its stiffness grows.

mod common;

use std::f64::consts::TAU;
use vibroimpact_core::kernel::events::{integrate_system, ContactKind, RunOptions, SystemSolution};
use vibroimpact_core::methods::steppers::{ExplicitRk, NewmarkFamily, SystemStepper};
use vibroimpact_core::model::assembly::{
    initial_state, Assembly, Damper, Excitation, Load, PairLaw, Side, Stop, SystemSpec,
};
use vibroimpact_core::model::contact::{Contact, LawKind};
use vibroimpact_core::model::signals::Signal;
use vibroimpact_core::model::structure::Structure;

fn options(dt: Option<f64>, t_end: f64) -> RunOptions {
    RunOptions {
        dt,
        t_end,
        every: 1,
        keep_history: true,
        max_steps: 100_000_000,
        max_rows: 100_000_000,
        energy_tolerance: 1e-6,
        reduce: Default::default(),
    }
}

fn spec(structure: Structure) -> SystemSpec {
    SystemSpec::of(structure, vec![])
}

fn run(spec: &SystemSpec, y0: &[Vec<f64>; 4], method: &str, dt: f64, t_end: f64) -> SystemSolution {
    let system = Assembly::new(spec).unwrap();
    let y = initial_state(&system, &y0[0], &y0[1], &y0[2], &y0[3]).unwrap();
    let len = system.state_len();
    let dt = (!matches!(method, "dopri5" | "dop853")).then_some(dt);
    let mut o = options(dt, t_end);
    if method.contains("newmark") || method.contains("alpha") {
        // Trapezoidal work against the method's own energy: an O(h^2) residual.
        o.energy_tolerance = 1e-2;
    }
    let result = match method {
        "rk4" => integrate(&system, &mut ExplicitRk::rk4(len), &y, &o),
        "dopri5" => integrate(&system, &mut ExplicitRk::dopri5(len, 1e-11, 1e-14), &y, &o),
        "dop853" => integrate(&system, &mut ExplicitRk::dop853(len, 1e-12, 1e-15), &y, &o),
        "newmark-implicit" => integrate(
            &system,
            &mut NewmarkFamily::newmark(&system, 0.25, 0.5),
            &y,
            &o,
        ),
        "generalized-alpha" => integrate(
            &system,
            &mut NewmarkFamily::generalized_alpha(&system, 0.9),
            &y,
            &o,
        ),
        _ => unreachable!(),
    };
    result.unwrap_or_else(|e| panic!("{method}: {e}"))
}

fn integrate<S: SystemStepper>(
    system: &Assembly,
    stepper: &mut S,
    y: &[f64],
    o: &RunOptions,
) -> vibroimpact_core::Result<SystemSolution> {
    integrate_system(system, stepper, y, o, &mut || false)
}

/// Steady response `Re(Q e^(i w t))` of `(K - w^2 M + i w C) Q = f`, for 1
/// or 2 coordinates: (amplitude parts) `Q = a + i b`.
fn steady(m: &[f64], k: &[f64], c: &[f64], f: &[f64], w: f64) -> (Vec<f64>, Vec<f64>) {
    let n = f.len();
    // Complex matrix A = K - w^2 M + i w C as real 2n x 2n [[Re, -Im], [Im, Re]].
    let mut a = vec![0.0; 4 * n * n];
    let mut rhs = vec![0.0; 2 * n];
    for i in 0..n {
        for j in 0..n {
            let re = k[i * n + j] - w * w * m[i * n + j];
            let im = w * c[i * n + j];
            a[i * 2 * n + j] = re;
            a[i * 2 * n + n + j] = -im;
            a[(n + i) * 2 * n + j] = im;
            a[(n + i) * 2 * n + n + j] = re;
        }
        rhs[i] = f[i];
    }
    vibroimpact_core::numerics::linalg::solve_in_place(&mut a, &mut rhs, 2 * n);
    (rhs[..n].to_vec(), rhs[n..].to_vec())
}

#[test]
fn forced_oscillator_stays_on_its_steady_state() {
    common::timeout(20, || {
        let (m, k, c, f0, freq) = (2.0, 800.0, 3.0, 5.0, 2.7);
        let w = TAU * freq;
        let (re, im) = steady(&[m], &[k], &[c], &[f0], w);
        let mut s = spec(Structure::oscillator(m, k, c).unwrap());
        s.excitations.push(Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(f0, freq, 0.0).unwrap(),
        });
        let y0 = [vec![re[0]], vec![-w * im[0]], vec![], vec![]];
        // Five whole periods (RK4's grid rounds t_end up by less than dt).
        let periods = 5.0;
        for (method, dt, tolerance) in [("rk4", 1e-4, 1e-11), ("dop853", 0.0, 1e-10)] {
            let sol = run(&s, &y0, method, dt, periods / freq);
            let amplitude = re[0].hypot(im[0]);
            for (row, t) in sol.time.iter().enumerate() {
                let exact = re[0] * (w * t).cos() - im[0] * (w * t).sin();
                let x = sol.states[row * 2];
                assert!(
                    (x - exact).abs() < tolerance * amplitude,
                    "{method} t = {t}: {x} vs {exact}"
                );
            }
            // The viscous loss per period of a steady response X: pi c w X^2.
            let e = sol.energy;
            let per_period = std::f64::consts::PI * c * w * amplitude * amplitude;
            assert!(
                (e.viscous / (periods * per_period) - 1.0).abs() < 1e-3,
                "{e:?}"
            );
            assert!(e.residual.abs() < 1e-9 * e.input_work.abs(), "{e:?}");
        }
    });
}

#[test]
fn tuned_absorber_and_base_excitation_match_their_steady_states() {
    common::timeout(20, || {
        // Main mass 1 kg on 1000 N/m, absorber 0.1 kg on 90 N/m, light damping.
        let m = [1.0, 0.0, 0.0, 0.1];
        let k = [1090.0, -90.0, -90.0, 90.0];
        let c = [0.5, -0.05, -0.05, 0.05];
        let rows = |a: &[f64]| vec![a[..2].to_vec(), a[2..].to_vec()];
        let structure = Structure::matrices(&rows(&m), &rows(&k), &rows(&c)).unwrap();
        let (a0, freq) = (2.0, 4.5);
        let w = TAU * freq;
        // Base acceleration a0 cos(w t): relative coordinates obey M q'' + C q'
        // + K q = -M r a(t), r = (1, 1).
        let (re, im) = steady(&m, &k, &c, &[-a0 * 1.0, -a0 * 0.1], w);
        let mut s = spec(structure);
        s.excitations.push(Excitation {
            load: Load::Base,
            signal: Signal::harmonic(a0, freq, 0.0).unwrap(),
        });
        let y0 = [re.clone(), vec![-w * im[0], -w * im[1]], vec![], vec![]];
        let sol = run(&s, &y0, "rk4", 2e-4, 1.5);
        let scale = re[1].hypot(im[1]);
        for (row, t) in sol.time.iter().enumerate() {
            for dof in 0..2 {
                let exact = re[dof] * (w * t).cos() - im[dof] * (w * t).sin();
                let x = sol.states[row * 4 + dof];
                assert!(
                    (x - exact).abs() < 1e-9 * scale,
                    "t = {t} dof {dof}: {x} vs {exact}"
                );
            }
        }
        let e = sol.energy;
        assert!(e.residual.abs() < 1e-9 * e.viscous, "{e:?}");
    });
}

#[test]
fn cantilever_free_modes_ring_at_their_frequencies() {
    common::timeout(20, || {
        let structure = Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.0).unwrap();
        let w = structure.natural_frequencies();
        let s = spec(structure);
        // Mode 2 displaced alone: q2(t) = q0 cos(w2 t), the others stay at rest.
        let y0 = [vec![0.0, 1e-3, 0.0], vec![], vec![], vec![]];
        let sol = run(&s, &y0, "dop853", 0.0, 0.2);
        for (row, t) in sol.time.iter().enumerate() {
            let q = &sol.states[row * 6..row * 6 + 3];
            assert!((q[1] - 1e-3 * (w[1] * t).cos()).abs() < 1e-12, "t = {t}");
            assert_eq!((q[0], q[2]), (0.0, 0.0));
        }
    });
}

/// A ball of `mass` dropped from rest `height` m above a rigid floor.
fn ball(height: f64, restitution: f64) -> SystemSpec {
    let mut s = spec(Structure::oscillator(0.2, 0.0, 0.0).unwrap());
    s.gravity = 9.81;
    s.stops.push(Stop {
        at: 0.0,
        side: Side::Lower,
        gap: height,
        law: PairLaw::rigid(restitution).unwrap(),
        against: None,
    });
    s
}

#[test]
fn a_ball_at_rest_on_the_floor_stays_there_whatever_its_restitution() {
    common::timeout(20, || {
        // Started on the floor at rest, the ball only presses on it: one
        // sticking contact from the first instant, no impact, no release,
        // even with e = 1 (whose impacts never accumulate: the round-off
        // micro-bounces were once stopped as "chattering").
        for (e, floor) in [(1.0, 0.0), (0.8, 0.0), (0.0, 0.0), (1.0, 1.0), (0.8, 1.0)] {
            for (method, dt) in [
                ("rk4", 1e-3),
                ("dopri5", 0.0),
                ("dop853", 0.0),
                ("newmark-implicit", 1e-3),
                ("generalized-alpha", 1e-3),
            ] {
                // The floor `floor` m below the origin, the ball on it.
                let start = [vec![-floor], vec![], vec![], vec![]];
                let sol = run(&ball(floor, e), &start, method, dt, 2.0);
                assert_eq!(sol.contacts.len(), 1, "{method} e={e}: {:?}", sol.contacts);
                let rest = &sol.contacts[0];
                assert_eq!(rest.kind, ContactKind::Sticking, "{method} e={e}");
                assert!(rest.onset < 1e-6, "{method} e={e}: {}", rest.onset);
                assert!(rest.separation.is_nan(), "{method} e={e}: released");
                assert_eq!(sol.final_time, 2.0);
                let (x, v) = (sol.final_state[0], sol.final_state[1]);
                assert!(
                    (x + floor).abs() < 1e-12 && v.abs() < 1e-12,
                    "{method} e={e}: {x} {v}"
                );
                assert!(sol.energy.impact.abs() < 1e-12, "{:?}", sol.energy);
            }
        }
    });
}

#[test]
fn a_pair_that_sticks_is_held_through_another_pairs_impact_at_the_same_instant() {
    common::timeout(20, || {
        // A structure reaching its stop with a loose mass on its cavity's
        // lower wall, both moving down: at the first instant the damper
        // lands (and sticks) and the stop strikes the structure back. The
        // damper must be held by its wall (a plastic impact), not left to
        // pass through it (it once sank 4.5 mm of its 10 mm clearance).
        let (gap, clearance, v) = (0.05, 0.01, -0.3);
        let mut s = spec(Structure::oscillator(1.0, 100.0, 0.0).unwrap());
        s.stops.push(Stop {
            at: 0.0,
            side: Side::Lower,
            gap,
            law: PairLaw::rigid(0.5).unwrap(),
            against: None,
        });
        s.dampers.push(Damper {
            mass: 0.1,
            at: 0.0,
            lower_clearance: clearance,
            upper_clearance: clearance,
            law: PairLaw::rigid(0.5).unwrap(),
        });
        let start = [vec![-gap], vec![v], vec![-gap - clearance], vec![v]];
        for (method, dt) in [("rk4", 1e-4), ("dopri5", 0.0), ("dop853", 0.0)] {
            let sol = run(&s, &start, method, dt, 0.01);
            for (row, t) in sol.time.iter().enumerate() {
                let state = &sol.states[4 * row..4 * row + 4];
                let (structure, damper) = (state[0], state[1]);
                let inside = (structure - clearance) - damper;
                assert!(inside < 1e-12, "{method}: {inside} m inside at {t} s");
                assert!(
                    structure >= -gap - 1e-12,
                    "{method}: through the stop at {t} s"
                );
            }
            assert!(
                sol.energy.residual.abs() < 1e-9,
                "{method}: {:?}",
                sol.energy
            );
        }
    });
}

#[test]
fn bouncing_ball_comes_to_rest_at_its_accumulation_time() {
    common::timeout(20, || {
        // Impacts at t1 (1 + 2 e + 2 e^2 + ...), t1 = sqrt(2 h / g): they
        // accumulate at t1 (1 + e) / (1 - e), after which the ball rests.
        let (h, e, g): (f64, f64, f64) = (1.0, 0.8, 9.81);
        let t1 = (2.0 * h / g).sqrt();
        let t_inf = t1 * (1.0 + e) / (1.0 - e);
        for (method, dt) in [("rk4", 1e-3), ("dop853", 0.0)] {
            let sol = run(
                &ball(h, e),
                &[vec![], vec![], vec![], vec![]],
                method,
                dt,
                6.0,
            );
            let impacts: Vec<_> = sol
                .contacts
                .iter()
                .filter(|c| c.kind == ContactKind::Impact)
                .collect();
            let mut expected = t1;
            for (n, c) in impacts.iter().take(10).enumerate() {
                assert!(
                    (c.onset - expected).abs() < 1e-9,
                    "{method} impact {n}: {} vs {expected}",
                    c.onset
                );
                let speed = (2.0 * g * h).sqrt() * e.powi(n as i32);
                assert!((c.approach_speed / speed - 1.0).abs() < 1e-9);
                assert!((c.rebound_speed / (e * c.approach_speed) - 1.0).abs() < 1e-12);
                expected += 2.0 * t1 * e.powi(n as i32 + 1);
            }
            let rest = sol
                .contacts
                .iter()
                .find(|c| c.kind == ContactKind::Sticking)
                .expect("the ball comes to rest");
            assert!(
                (rest.onset - t_inf).abs() < 1e-8,
                "{method}: {} vs {t_inf}",
                rest.onset
            );
            assert!(rest.separation.is_nan(), "it never leaves the floor");
            // At rest on the floor, and all the potential energy m g h lost.
            let (x, v) = (sol.final_state[0], sol.final_state[1]);
            assert!((x + h).abs() < 1e-9 && v.abs() < 1e-9, "{x} {v}");
            let energy = sol.energy;
            assert!((energy.impact - 0.2 * g * h).abs() < 1e-9, "{energy:?}");
            assert!(energy.residual.abs() < 1e-9);
        }
    });
}

#[test]
fn rigid_impacts_conserve_momentum_and_apply_newtons_law() {
    common::timeout(20, || {
        // A free mass (K = C = 0) carrying a loose mass in a 10 mm gap.
        let mut s = spec(Structure::oscillator(1.5, 0.0, 0.0).unwrap());
        s.dampers.push(Damper {
            mass: 0.4,
            at: 0.0,
            lower_clearance: 0.01,
            upper_clearance: 0.01,
            law: PairLaw::rigid(0.6).unwrap(),
        });
        let y0 = [vec![0.0], vec![0.3], vec![0.0], vec![-0.5]];
        let sol = run(&s, &y0, "rk4", 1e-3, 0.5);
        let momentum = 1.5 * 0.3 + 0.4 * (-0.5);
        for row in 0..sol.time.len() {
            let v = &sol.states[row * 4 + 2..row * 4 + 4];
            assert!((1.5 * v[0] + 0.4 * v[1] - momentum).abs() < 1e-13);
        }
        // Relative speed 0.8 m/s, reduced by e = 0.6 at each impact; each wall
        // reached after 20 mm of relative travel (10 mm the first time).
        assert!(sol.contacts.len() >= 3);
        let mut speed = 0.8;
        let mut t = 0.01 / speed;
        for c in &sol.contacts {
            assert!((c.onset - t).abs() < 1e-12, "{} vs {t}", c.onset);
            assert!((c.approach_speed - speed).abs() < 1e-12);
            speed *= 0.6;
            t += 0.02 / speed;
        }
        let m_eff = 1.5 * 0.4 / 1.9;
        let lost: f64 = sol.contacts.iter().map(|c| c.energy_dissipated).sum();
        let expected: f64 = sol
            .contacts
            .iter()
            .map(|c| 0.5 * m_eff * (c.approach_speed.powi(2) - c.rebound_speed.powi(2)))
            .sum();
        assert!((lost - expected).abs() < 1e-14);
        assert_eq!(sol.contacts[0].pair, 0);
    });
}

#[test]
fn compliant_damper_in_a_forced_beam_closes_its_energy_balance() {
    common::timeout(30, || {
        let mut s = spec(Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.01).unwrap());
        let contact = Contact::new(LawKind::HertzDamped, 1e7, Some(0.6), 0.0).unwrap();
        for at in [0.5, 0.3] {
            s.dampers.push(Damper {
                mass: 0.01,
                at,
                lower_clearance: 1e-4,
                upper_clearance: 1e-4,
                law: PairLaw::Compliant(contact),
            });
        }
        s.excitations.push(Excitation {
            load: Load::Force { at: 0.5 },
            signal: Signal::harmonic(0.5, 8.0, 0.0).unwrap(),
        });
        let sol = run(&s, &[vec![], vec![], vec![], vec![]], "dopri5", 0.0, 1.0);
        assert!(sol.contacts.len() > 10, "{}", sol.contacts.len());
        let e = sol.energy;
        assert!(e.contact > 0.0 && e.viscous > 0.0 && e.input_work > 0.0);
        assert!(e.residual.abs() < 1e-7 * e.input_work, "{e:?}");
        // Each contact of "hertz-damped" between a free ball and the beam
        // point... its dissipation adds up to the contact loss.
        let sum: f64 = sol.contacts.iter().map(|c| c.energy_dissipated).sum();
        assert!(
            (sum - e.contact).abs() < 1e-9 * e.contact,
            "{sum} vs {}",
            e.contact
        );
        assert!(sol.contacts.iter().any(|c| c.pair == 1));
    });
}

#[test]
fn stiffer_compliant_floor_tends_to_the_rigid_bounce() {
    common::timeout(30, || {
        // First rebound of a ball on a hertz-damped floor (e = 0.8): as the
        // stiffness grows, the contact shortens and the second impact time
        // tends to the rigid one, t1 (1 + 2 e).
        let (h, e, g): (f64, f64, f64) = (0.1, 0.8, 9.81);
        let t1 = (2.0 * h / g).sqrt();
        let rigid = t1 * (1.0 + 2.0 * e);
        let mut last = f64::INFINITY;
        // The contact lasts ~ K^(-2/5): two decades of stiffness should cut the
        // error by about 100^(2/5) = 6.3.
        for stiffness in [1e6, 1e8, 1e10, 1e12] {
            let mut s = ball(h, e);
            s.stops[0].law = PairLaw::Compliant(
                Contact::new(LawKind::HertzDamped, stiffness, Some(e), 0.0).unwrap(),
            );
            let sol = run(
                &s,
                &[vec![], vec![], vec![], vec![]],
                "dop853",
                0.0,
                rigid + 0.01,
            );
            let second = sol.contacts[1].onset;
            let error = (second - rigid).abs();
            assert!(error * 4.0 < last, "K {stiffness}: {error} after {last}");
            last = error;
            // Gravity acts during the contact too: the rebound differs from e
            // by less than gravity's impulse over the contact, g T / v.
            let first = sol.contacts[0];
            let bound = g * first.duration / first.approach_speed;
            assert!((first.restitution - e).abs() < bound, "{first:?}");
        }
        assert!(last < 3e-5, "{last}");
    });
}

#[test]
fn bad_systems_are_refused_naming_the_input() {
    common::timeout(10, || {
        let mut s = spec(Structure::oscillator(1.0, 1.0, 0.0).unwrap());
        s.dampers.push(Damper {
            mass: 0.1,
            at: 1.0,
            lower_clearance: 0.01,
            upper_clearance: 0.01,
            law: PairLaw::rigid(0.5).unwrap(),
        });
        let e = Assembly::new(&s).unwrap_err().to_string();
        assert!(
            e.starts_with("damper 0 at must be a coordinate index"),
            "{e}"
        );
        s.dampers[0].at = 0.0;
        s.dampers[0].mass = -1.0;
        assert!(Assembly::new(&s)
            .unwrap_err()
            .to_string()
            .starts_with("damper 0 mass"));
        s.dampers[0].mass = 0.1;
        let system = Assembly::new(&s).unwrap();
        let e = initial_state(&system, &[0.0, 1.0], &[], &[], &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("initial.structure_displacement must have 1 value (or none)"),
            "{e}"
        );
        let e = initial_state(&system, &[], &[], &[0.02], &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("damper 0 starts") && e.contains("inside its wall"),
            "{e}"
        );
        assert!(PairLaw::rigid(1.5).is_err());
    });
}

#[test]
fn newmark_family_converges_at_second_order_on_a_forced_beam() {
    common::timeout(30, || {
        // Two modes of a cantilever driven at the tip, started at rest: the
        // answer at 0.1 s from DOP853 at rtol 1e-12; halving the step must
        // cut the Newmark family's error by 4.
        let mut s = spec(Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 2, 0.02).unwrap());
        s.excitations.push(Excitation {
            load: Load::Force { at: 0.5 },
            signal: Signal::harmonic(0.3, 6.0, 0.4).unwrap(),
        });
        let zero = [vec![], vec![], vec![], vec![]];
        let exact = run(&s, &zero, "dop853", 0.0, 0.1).final_state;
        for method in ["newmark-implicit", "generalized-alpha"] {
            let error = |dt: f64| {
                let end = run(&s, &zero, method, dt, 0.1).final_state;
                (end[0] - exact[0]).abs()
            };
            let (coarse, fine) = (error(2e-4), error(1e-4));
            let order = (coarse / fine).log2();
            assert!((order - 2.0).abs() < 0.1, "{method}: order {order}");
        }
    });
}

#[test]
fn newmark_family_bounces_the_ball_and_closes_the_balance() {
    common::timeout(30, || {
        // Average acceleration integrates the free flight under gravity
        // exactly, so the impacts and the accumulation are as the rigid ones.
        let (h, e, g): (f64, f64, f64) = (1.0, 0.8, 9.81);
        let t1 = (2.0 * h / g).sqrt();
        let sol = run(
            &ball(h, e),
            &[vec![], vec![], vec![], vec![]],
            "newmark-implicit",
            1e-3,
            6.0,
        );
        assert!((sol.contacts[0].onset - t1).abs() < 1e-9);
        let rest = sol.contacts.last().unwrap();
        assert_eq!(rest.kind, ContactKind::Sticking);
        assert!((rest.onset - t1 * (1.0 + e) / (1.0 - e)).abs() < 1e-8);
        assert!(sol.energy.residual.abs() < 1e-9);
        // A compliant damper in a forced beam: the balance closes to the method's order.
        let mut beam = spec(Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.01).unwrap());
        let contact = Contact::new(LawKind::HertzDamped, 1e7, Some(0.6), 0.0).unwrap();
        beam.dampers.push(Damper {
            mass: 0.01,
            at: 0.5,
            lower_clearance: 1e-4,
            upper_clearance: 1e-4,
            law: PairLaw::Compliant(contact),
        });
        beam.excitations.push(Excitation {
            load: Load::Force { at: 0.5 },
            signal: Signal::harmonic(0.5, 8.0, 0.0).unwrap(),
        });
        for method in ["newmark-implicit", "generalized-alpha"] {
            let sol = run(&beam, &[vec![], vec![], vec![], vec![]], method, 1e-5, 0.5);
            assert!(sol.contacts.len() > 5, "{method}");
            let e = sol.energy;
            assert!(e.residual.abs() < 1e-4 * e.input_work, "{method}: {e:?}");
        }
    });
}

#[test]
fn a_run_without_history_ends_where_the_run_with_one_does() {
    common::timeout(60, || {
        // Many steps without a history (the way studies run; its countdown of
        // steps to the next row must not overflow): the same end, no rows.
        let system = Assembly::new(&spec(Structure::oscillator(1.0, 100.0, 0.2).unwrap())).unwrap();
        let y = initial_state(&system, &[0.01], &[0.0], &[], &[]).unwrap();
        let len = system.state_len();
        let kept = options(Some(1e-3), 1.0);
        let bare = RunOptions {
            keep_history: false,
            ..kept
        };
        let a = integrate(&system, &mut ExplicitRk::rk4(len), &y, &kept).unwrap();
        let b = integrate(&system, &mut ExplicitRk::rk4(len), &y, &bare).unwrap();
        assert_eq!(a.final_state, b.final_state);
        assert!(a.time.len() > 1000 && b.time.is_empty());
    });
}

#[test]
fn the_run_reports_its_energy_growth_and_largest_balance_residual() {
    common::timeout(20, || {
        let (m, k, x0) = (2.0, 800.0, 0.01);
        let stored = 0.5 * k * x0 * x0;
        let y0 = [vec![x0], vec![0.0], vec![], vec![]];
        // Damped and free: the energy only falls, so its largest is the start's.
        let damped = run(
            &spec(Structure::oscillator(m, k, 3.0).unwrap()),
            &y0,
            "rk4",
            1e-3,
            2.0,
        );
        assert_eq!(damped.energy_growth, 0.0);
        // Undamped: average-acceleration Newmark keeps a linear system's energy
        // to round-off, RK4 loses (w dt)^6 / 72 a step (1.8e-9 over 2000 steps
        // at w dt = 0.02); the largest residual is at least the end's.
        let free = spec(Structure::oscillator(m, k, 0.0).unwrap());
        for (method, bound) in [("newmark-implicit", 1e-12), ("rk4", 3e-9)] {
            let sol = run(&free, &y0, method, 1e-3, 2.0);
            assert!(
                sol.energy_growth >= 0.0 && sol.energy_growth < 1e-12,
                "{method}: {}",
                sol.energy_growth
            );
            let end = sol.energy.residual.abs() / stored;
            assert!(
                sol.energy_residual >= 0.999 * end && sol.energy_residual < bound,
                "{method}: {} vs {end}",
                sol.energy_residual
            );
        }
        // Forced: its energy may grow, so no growth is reported.
        let mut forced = spec(Structure::oscillator(m, k, 3.0).unwrap());
        forced.excitations.push(Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(5.0, 2.7, 0.0).unwrap(),
        });
        let sol = run(&forced, &y0, "rk4", 1e-3, 1.0);
        assert!(sol.energy_growth.is_nan() && sol.energy_residual < 1e-9);
    });
}
