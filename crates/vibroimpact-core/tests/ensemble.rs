//! Issue 10: lockstep ensembles. Each lane is the general kernel's fixed-step
//! RK4 run of its member (the two-mass `simulate`, located contacts) bit for
//! bit (final state and contact count, every law, lanes with different
//! parameters, a group not filled); the results do not depend
//! on the number of threads nor on the grouping; the reductions against
//! closed forms; a run that blows up fails alone.

mod common;

use vibroimpact_core::analysis::ensemble::{
    run_ensemble, EnsembleOptions, Member, MemberResult, LANES,
};
use vibroimpact_core::kernel::events::SystemSolution;
use vibroimpact_core::methods::registry::two_mass::simulate;
use vibroimpact_core::{
    Contact, ContactTiming, ImpactDamper, LawKind, Method, Settings, State, Stepping,
};

fn contact(kind: LawKind) -> Contact {
    let (stiffness, restitution) = match kind {
        LawKind::Linear => (2.0e4, None),
        LawKind::Hertz => (3000.0, None),
        _ => (3000.0, Some(0.7)),
    };
    Contact::new(kind, stiffness, restitution, 0.01).unwrap()
}

/// Members that differ in every lane: masses, clearance, stiffness, start.
fn members(kind: LawKind, count: usize) -> Vec<Member> {
    (0..count)
        .map(|i| {
            let f = i as f64 / count as f64;
            let base = contact(kind);
            let contact = Contact::new(
                kind,
                base.stiffness * (1.0 + f),
                kind_restitution(kind),
                0.01 * f,
            )
            .unwrap();
            Member {
                system: ImpactDamper::new(1.0 + 0.5 * f, 1.0, 0.01, 0.25, 0.005 + 0.01 * f)
                    .unwrap(),
                contact,
                initial: State::new(0.0, 0.02 * f, 0.0, 0.05 + 0.1 * f).unwrap(),
            }
        })
        .collect()
}

fn kind_restitution(kind: LawKind) -> Option<f64> {
    matches!(kind, LawKind::HysterHertz | LawKind::HertzDamped).then_some(0.7)
}

fn options(steps: u64) -> EnsembleOptions {
    EnsembleOptions {
        dt: 1e-4,
        steps,
        record_from: 0.0,
        energy_tolerance: 0.05,
    }
}

fn single(member: &Member, dt: f64, steps: u64) -> SystemSolution {
    let settings = Settings::new(
        Method::Rk4,
        Some(dt),
        steps as f64 * dt,
        1,
        ContactTiming::Located,
        Some(Stepping::Fixed),
        u64::MAX,
    )
    .unwrap();
    simulate(
        &member.system,
        &member.contact,
        &member.initial,
        &settings,
        &mut || false,
    )
    .unwrap()
}

#[test]
fn every_lane_is_the_fixed_step_kernels_run_bit_for_bit() {
    common::timeout(180, || {
        for kind in [
            LawKind::Hertz,
            LawKind::Linear,
            LawKind::HysterHertz,
            LawKind::HertzDamped,
        ] {
            // 2 LANES - 3 members: a full group and a padded one.
            let members = members(kind, 2 * LANES - 3);
            let steps = 30_000;
            let results = run_ensemble(&members, &options(steps), 1, &|| false).unwrap();
            assert_eq!(results.len(), members.len());
            let mut touched = 0;
            for (member, result) in members.iter().zip(&results) {
                let sol = single(member, 1e-4, steps);
                assert_eq!(result.reason, None, "{kind:?}");
                let end = State::of_vector(&sol.final_state);
                assert_eq!(result.final_state, end, "{kind:?}");
                assert_eq!(result.contacts, sol.contacts.len() as u64, "{kind:?}");
                touched += usize::from(result.contacts > 0);
                // Peak and RMS from the kernel's history, step ends only: the
                // located peak is at least the largest step end, and not above
                // it by more than the step's curvature allows.
                // The main mass's displacement, the first column of each row.
                let width = sol.states.len() / sol.time.len();
                let w: Vec<f64> = sol.states.iter().step_by(width).copied().collect();
                let largest = w.iter().fold(0.0f64, |m, x| m.max(x.abs()));
                assert!(result.peak >= largest && result.peak <= largest * (1.0 + 1e-6));
                let sum: f64 = w.iter().map(|x| x * x).sum::<f64>()
                    - 0.5 * (w[0] * w[0] + w[w.len() - 1] * w[w.len() - 1]);
                let rms = (sum / (w.len() - 1) as f64).sqrt();
                assert!(
                    (result.rms - rms).abs() <= 1e-12 * rms,
                    "{} {rms}",
                    result.rms
                );
            }
            assert!(
                touched >= members.len() - 1,
                "{kind:?}: the members must collide"
            );
        }
    });
}

#[test]
fn a_lane_crossing_from_wall_to_wall_in_a_step_is_the_kernels_run() {
    common::timeout(180, || {
        // No clearance: the loose mass leaves one wall indenting the other
        // within a step, which the kernel then takes again with both walls'
        // forces (the one still in contact, the one entered).
        for kind in [LawKind::Hertz, LawKind::HysterHertz, LawKind::Linear] {
            let members: Vec<Member> = (0..LANES + 2)
                .map(|i| Member {
                    system: ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.0).unwrap(),
                    contact: Contact::new(kind, 2.0e4, kind_restitution(kind), 0.0).unwrap(),
                    initial: State::new(0.0, 0.0, 0.0, 0.05 + 0.01 * i as f64).unwrap(),
                })
                .collect();
            let steps = 5_000;
            let results = run_ensemble(&members, &options(steps), 1, &|| false).unwrap();
            for (member, result) in members.iter().zip(&results) {
                let sol = single(member, 1e-4, steps);
                assert_eq!(result.reason, None, "{kind:?}");
                let end = State::of_vector(&sol.final_state);
                assert_eq!(result.final_state, end, "{kind:?}");
                assert_eq!(result.contacts, sol.contacts.len() as u64, "{kind:?}");
                assert!(result.contacts >= 5, "{kind:?}: {}", result.contacts);
            }
        }
    });
}

#[test]
fn results_do_not_depend_on_threads_or_grouping() {
    common::timeout(60, || {
        let members = members(LawKind::Hertz, 3 * LANES + 1);
        let all = run_ensemble(&members, &options(10_000), 1, &|| false).unwrap();
        let two = run_ensemble(&members, &options(10_000), 2, &|| false).unwrap();
        assert_eq!(all, two);
        // Shifted by one: every member in another lane and group.
        let shifted = run_ensemble(&members[1..], &options(10_000), 2, &|| false).unwrap();
        assert_eq!(&all[1..], &shifted[..]);
    });
}

#[test]
fn free_oscillation_reductions_match_the_closed_form() {
    common::timeout(30, || {
        // The loose mass never reaches a wall: w = A cos(t) (K = M = 1, C = 0).
        // Over whole periods the peak is A and the RMS A / sqrt(2); recorded
        // from t = pi / 3 (w = A / 2, falling), the peak is still A (at t = pi).
        let amplitude = 0.02;
        let member = Member {
            system: ImpactDamper::new(1.0, 1.0, 0.0, 0.1, 1.0).unwrap(),
            contact: contact(LawKind::Hertz),
            initial: State::new(amplitude, 0.0, 0.0, 0.0).unwrap(),
        };
        let dt = 2.0 * std::f64::consts::PI / 20_000.0;
        let run = |record_from: f64, steps: u64| -> MemberResult {
            let options = EnsembleOptions {
                dt,
                steps,
                record_from,
                energy_tolerance: 0.05,
            };
            run_ensemble(&[member], &options, 1, &|| false)
                .unwrap()
                .remove(0)
        };
        let whole = run(0.0, 3 * 20_000);
        assert_eq!(whole.contacts, 0);
        assert!((whole.peak - amplitude).abs() < 1e-12 * amplitude);
        assert!((whole.rms - amplitude / 2f64.sqrt()).abs() < 1e-10 * amplitude);
        // From t = pi / 3 (not a step end) over the trough at t = pi (a step
        // end here; the case below puts it inside a step).
        let later = run(std::f64::consts::PI / 3.0, 20_000);
        assert!((later.peak - amplitude).abs() < 1e-12 * amplitude);
        // The RMS from the first step end at or after pi / 3 to 2 pi: the
        // integral of cos^2 is t / 2 + sin(2 t) / 4 (the trapezoidal rule
        // errs by ~dt^2 / 12 of it, 1e-8 here).
        let start = (std::f64::consts::PI / 3.0 / dt).ceil() * dt;
        let end = 20_000.0 * dt;
        let integral = |t: f64| t / 2.0 + (2.0 * t).sin() / 4.0;
        let rms = amplitude * ((integral(end) - integral(start)) / (end - start)).sqrt();
        assert!((later.rms - rms).abs() < 1e-7 * rms, "{} {rms}", later.rms);
        let odd = EnsembleOptions {
            dt: 2.2e-3,
            steps: 2000,
            record_from: 0.3,
            energy_tolerance: 0.05,
        };
        // To t = 4.4 s from 0.3 s: the trough at t = pi lies inside a step
        // (pi / dt = 1427.997), where the step ends miss A by 6e-7 of it.
        let inside = run_ensemble(&[member], &odd, 1, &|| false)
            .unwrap()
            .remove(0);
        assert!((inside.peak - amplitude).abs() < 1e-12 * amplitude);
        // Nothing recorded: no numbers.
        let none = run(10.0, 100);
        assert!(none.peak.is_nan() && none.rms.is_nan());
    });
}

#[test]
fn contacts_are_counted_from_record_from() {
    common::timeout(30, || {
        let member = members(LawKind::Hertz, 4)[2];
        let sol = single(&member, 1e-4, 30_000);
        assert!(sol.contacts.len() >= 3);
        let from = 0.5 * (sol.contacts[0].onset + sol.contacts[1].onset);
        let options = EnsembleOptions {
            record_from: from,
            ..options(30_000)
        };
        let r = run_ensemble(&[member], &options, 1, &|| false).unwrap();
        let expected = sol.contacts.iter().filter(|c| c.onset >= from).count() as u64;
        assert_eq!(r[0].contacts, expected);
        assert_eq!(expected, sol.contacts.len() as u64 - 1);
    });
}

#[test]
fn a_run_that_blows_up_fails_alone() {
    common::timeout(30, || {
        let mut members = members(LawKind::Hertz, 3);
        // A contact far too stiff for the step: RK4 is unstable in it.
        members[1].contact = Contact::new(LawKind::Hertz, 1e12, None, 0.0).unwrap();
        let r = run_ensemble(&members, &options(20_000), 1, &|| false).unwrap();
        assert_eq!(r[0].reason, None);
        assert_eq!(r[2].reason, None);
        let reason = r[1].reason.as_deref().expect("the stiff member fails");
        assert!(reason.contains("reduce dt"), "{reason}");
        assert!(r[1].peak.is_nan() && r[1].final_state.main_displacement.is_nan());
        // The single-run kernel refuses the same run.
        let settings = Settings::new(
            Method::Rk4,
            Some(1e-4),
            2.0,
            1,
            ContactTiming::Located,
            Some(Stepping::Fixed),
            u64::MAX,
        )
        .unwrap();
        assert!(simulate(
            &members[1].system,
            &members[1].contact,
            &members[1].initial,
            &settings,
            &mut || false
        )
        .is_err());
    });
}

#[test]
fn a_start_inside_the_wall_fails_and_an_interrupt_stops() {
    common::timeout(30, || {
        let mut members = members(LawKind::Hertz, 2);
        members[0].initial = State::new(0.0, 0.0, 0.5, 0.0).unwrap();
        let r = run_ensemble(&members, &options(1000), 1, &|| false).unwrap();
        assert!(r[0].reason.as_deref().unwrap().contains("inside the wall"));
        assert_eq!(r[1].reason, None);
        let err = run_ensemble(&members, &options(100_000), 1, &|| true).unwrap_err();
        assert!(err.to_string().contains("interrupted"), "{err}");
        // Mixed laws cannot share lanes.
        members[1].contact = contact(LawKind::Linear);
        assert!(run_ensemble(&members, &options(10), 1, &|| false).is_err());
    });
}
