use super::rk::{flatten, Estimate};
use super::*;
use crate::methods::tableau::*;
use crate::model::assembly::{
    initial_state, Damper, Excitation, Load, PairLaw, SystemSpec, CONTACT,
};
use crate::model::contact::{Contact, LawKind};
use crate::model::signals::Signal;
use crate::model::structure::Structure;

/// A modal cantilever with two dampers (one compliant, one rigid), two
/// forces, a base excitation and gravity: every term of the rates.
fn beam() -> Assembly {
    let contact = Contact::new(LawKind::HertzDamped, 1e7, Some(0.6), 1.0).unwrap();
    let spec = SystemSpec {
        structure: Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.01).unwrap(),
        dampers: vec![
            Damper {
                mass: 0.01,
                at: 0.5,
                lower_clearance: 2e-4,
                upper_clearance: 2e-4,
                law: PairLaw::Compliant(contact),
            },
            Damper {
                mass: 0.02,
                at: 0.25,
                lower_clearance: 1e-4,
                upper_clearance: 3e-4,
                law: PairLaw::rigid(0.5).unwrap(),
            },
        ],
        collisions: vec![],
        frictions: vec![],
        stops: vec![],
        gravity: 9.81,
        excitations: vec![
            Excitation {
                load: Load::Force { at: 0.5 },
                signal: Signal::harmonic(0.5, 8.0, 0.0).unwrap(),
            },
            Excitation {
                load: Load::Force { at: 0.3 },
                signal: Signal::harmonic(0.2, 13.0, 0.4).unwrap(),
            },
            Excitation {
                load: Load::Base,
                signal: Signal::harmonic(1.5, 5.0, 0.1).unwrap(),
            },
        ],
        points: vec![],
        moments: vec![],
    };
    Assembly::new(&spec).unwrap()
}

/// A state whose coordinates and accumulators are all nonzero.
fn state(system: &Assembly, seed: f64) -> Vec<f64> {
    let mut y = initial_state(system, &[], &[], &[], &[]).unwrap();
    for (i, v) in y.iter_mut().enumerate() {
        *v = 1e-4 * (seed + 0.37 * i as f64).sin();
    }
    y
}

/// Open, in compliant contact and sticking: each branch of the rates.
fn mode_sets(system: &Assembly) -> Vec<Vec<Mode>> {
    let count = system.interactions.len();
    let mut sets = vec![vec![Mode::Open; count]];
    let mut compliant = vec![Mode::Open; count];
    // Both rules of a compliant contact: the damper through the mode
    // (events) and only where indented (fixed stepping).
    for indented_only in [false, true] {
        compliant[1] = Mode::Compliant {
            approach_rate: 0.01,
            indented_only,
        };
        sets.push(compliant.clone());
    }
    compliant[2] = Mode::Sticking;
    sets.push(compliant);
    sets
}

#[test]
fn bodies_for_constant_sizes_match_the_general_one_to_the_bit() {
    crate::testing::timeout(60, || {
        let system = beam();
        let len = system.state_len();
        // Sizes the compiler cannot see: the general body.
        let (n, k) = std::hint::black_box((system.n, system.k));
        let (mut s1, mut s2) = (Scratch::new(&system), Scratch::new(&system));
        let (mut a, mut b) = (vec![0.0; len], vec![0.0; len]);
        let count = system.interactions.len();
        let (mut g1, mut g2) = (vec![(0.0, 0.0); count], vec![(0.0, 0.0); count]);
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        for modes in &mode_sets(&system) {
            for step in 0..100 {
                let (time, y) = (1e-5 * step as f64, state(&system, step as f64));
                system.rates(time, &y, modes, &mut s1, &mut a);
                system.rates_in(n, k, time, &y, modes, &mut s2, &mut b);
                assert_eq!(bits(&a), bits(&b), "step {step}, {modes:?}");
                assert_eq!(bits(&s1.forces), bits(&s2.forces));
                system.gaps(&y, &mut g1);
                system.gaps_in(n + k, &y, &mut g2);
                let pairs = |g: &[(f64, f64)]| {
                    g.iter()
                        .map(|p| (p.0.to_bits(), p.1.to_bits()))
                        .collect::<Vec<_>>()
                };
                assert_eq!(pairs(&g1), pairs(&g2));
            }
        }
    });
}

#[test]
fn rk4_own_loop_matches_its_tableau_to_the_bit() {
    crate::testing::timeout(60, || {
        let system = beam();
        let len = system.state_len();
        for modes in &mode_sets(&system) {
            let mut own = ExplicitRk::rk4(len);
            let mut tableau = ExplicitRk::build(
                "rk4 by its tableau",
                &RK4_C,
                flatten(&RK4_A),
                &RK4_B,
                Estimate::None,
                5.0,
                len,
            );
            let (mut s1, mut s2) = (Scratch::new(&system), Scratch::new(&system));
            let (mut a, mut b) = (vec![0.0; len], vec![0.0; len]);
            let mut time = 0.0;
            for step in 0..200 {
                let y = state(&system, step as f64);
                // Repeated attempts from one point reuse its rates.
                for h in [1e-5, 0.4e-5] {
                    own.attempt(&system, time, &y, h, modes, &mut s1, &mut a)
                        .unwrap();
                    tableau
                        .attempt(&system, time, &y, h, modes, &mut s2, &mut b)
                        .unwrap();
                    let same = a.iter().zip(&b).all(|(p, q)| p.to_bits() == q.to_bits());
                    assert!(same, "step {step}, h {h}: {a:?} != {b:?}");
                }
                own.accept();
                tableau.accept();
                time += 1e-5;
            }
            assert_eq!(own.evaluations(), tableau.evaluations());
            assert!(a[2 * system.dim + CONTACT..].iter().all(|l| l.is_finite()));
        }
    });
}

#[test]
fn all_gaps_at_once_match_each_gap_to_the_bit() {
    crate::testing::timeout(60, || {
        let system = beam();
        let mut gaps = vec![(0.0, 0.0); system.interactions.len()];
        for seed in 0..50 {
            let y = state(&system, seed as f64);
            system.gaps(&y, &mut gaps);
            for (i, (g, r)) in gaps.iter().enumerate() {
                let (g0, r0) = system.gap(i, &y);
                assert_eq!((g.to_bits(), r.to_bits()), (g0.to_bits(), r0.to_bits()));
            }
        }
    });
}
