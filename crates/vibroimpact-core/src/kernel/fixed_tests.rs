//! Fixed stepping against 0.1's two-mass kernel, a closed form and the
//! energy balance of a contact.

use crate::kernel::events::{
    integrate_system_stepped, ContactTiming, PairContact, RunOptions, Stepping, SystemSolution,
};
use crate::kernel::memory::MAX_RECORD_BYTES;
use crate::kernel::reductions::ReduceOptions;
use crate::methods::registry::two_mass::{self as settings, Method, Settings};
use crate::methods::steppers::{ExplicitRk, NewmarkFamily, SystemStepper};
use crate::model::assembly::{initial_state, Assembly, Damper, PairLaw, SystemSpec};
use crate::model::closed_forms::linear_contact_duration;
use crate::model::contact::{Contact, LawKind};
use crate::model::impact_damper::{ImpactDamper, State};
use crate::model::structure::Structure;

/// The two-mass impact damper written as a general system: an oscillator
/// with one damper of equal clearances.
fn spec(system: &ImpactDamper, contact: &Contact) -> SystemSpec {
    SystemSpec {
        structure: Structure::oscillator(system.main_mass, system.stiffness, system.damping)
            .unwrap(),
        dampers: vec![Damper {
            mass: system.impact_mass,
            at: 0.0,
            lower_clearance: system.clearance,
            upper_clearance: system.clearance,
            law: PairLaw::Compliant(*contact),
        }],
        stops: vec![],
        gravity: 0.0,
        excitations: vec![],
        points: vec![],
        moments: vec![],
    }
}

fn options(dt: f64, t_end: f64) -> RunOptions {
    RunOptions {
        dt: Some(dt),
        t_end,
        every: 1,
        keep_history: true,
        max_steps: u64::MAX,
        max_rows: u64::MAX,
        energy_tolerance: 1e-2,
        reduce: ReduceOptions::default(),
    }
}

/// The run of `system` from `start` with fixed steps of `dt`.
fn fixed<S: SystemStepper>(
    system: &ImpactDamper,
    contact: &Contact,
    start: &State,
    stepper: &mut S,
    (dt, t_end, timing, tolerance): (f64, f64, ContactTiming, f64),
) -> crate::Result<SystemSolution> {
    let assembly = Assembly::new(&spec(system, contact)).unwrap();
    let y = initial_state(
        &assembly,
        &[start.main_displacement],
        &[start.main_velocity],
        &[start.impact_displacement],
        &[start.impact_velocity],
    )
    .unwrap();
    let stepping = Stepping::Fixed {
        contact_timing: timing,
    };
    integrate_system_stepped(
        &assembly,
        stepper,
        &y,
        &RunOptions {
            energy_tolerance: tolerance,
            ..options(dt, t_end)
        },
        stepping,
        &mut || false,
        MAX_RECORD_BYTES,
    )
}

/// 0.1's fixed-step run of the same system (`tolerance`: its energy check).
fn legacy(
    system: &ImpactDamper,
    contact: &Contact,
    start: &State,
    method: Method,
    (dt, t_end, timing, tolerance): (f64, f64, ContactTiming, f64),
) -> crate::legacy::records::Solution {
    let timing = match timing {
        ContactTiming::Located => settings::ContactTiming::Located,
        ContactTiming::StepCount => settings::ContactTiming::StepCount,
    };
    let fixed = Some(settings::Stepping::Fixed);
    let mut settings = Settings::new(method, Some(dt), t_end, 1, timing, fixed, u64::MAX).unwrap();
    settings.energy_tolerance = tolerance;
    crate::legacy::run::simulate(system, contact, start, &settings, &mut || false).unwrap()
}

fn rk4(system: &ImpactDamper) -> ExplicitRk {
    ExplicitRk::rk4(Assembly::new(&spec(system, &hertz())).unwrap().state_len())
}

fn hertz() -> Contact {
    Contact::new(LawKind::Hertz, 1e9, None, 0.0).unwrap()
}

/// The largest difference between two numbers relative to `scale`.
fn off(a: f64, b: f64, scale: f64) -> f64 {
    if a.is_nan() && b.is_nan() {
        0.0
    } else {
        (a - b).abs() / scale
    }
}

/// The largest differences between the records of two runs of `system`
/// with steps of `dt` (as many contacts in each): onset and separation in
/// steps, the speeds relative to the approach, the deepest indentation
/// relative to itself, the energies relative to the approach's kinetic
/// energy, the restitution.
fn worst(
    system: &ImpactDamper,
    dt: f64,
    ours: &SystemSolution,
    theirs: &crate::legacy::records::Solution,
    label: &str,
) -> [f64; 8] {
    assert_eq!(ours.contacts.len(), theirs.contacts.len(), "{label}");
    let mut worst = [0.0f64; 8];
    for (a, b) in ours.contacts.iter().zip(&theirs.contacts) {
        let speed = b.approach_speed;
        let energy = 0.5 * system.effective_mass() * speed * speed;
        let pairs = [
            off(a.onset, b.onset, dt),
            off(a.separation, b.separation, dt),
            off(a.approach_speed, b.approach_speed, speed),
            off(a.rebound_speed, b.rebound_speed, speed),
            off(a.max_indentation, b.max_indentation, b.max_indentation),
            off(a.energy_dissipated, b.energy_dissipated, energy),
            off(a.energy_change, b.energy_change, energy),
            off(a.restitution, b.restitution, 1.0),
        ];
        for (w, p) in worst.iter_mut().zip(pairs) {
            *w = w.max(p);
        }
    }
    worst
}

#[test]
fn fixed_rk4_is_the_0_1_kernel_to_round_off() {
    crate::testing::timeout(60, || {
        let system = ImpactDamper::new(1.0, 3947.8, 0.0, 0.05, 1e-3).unwrap();
        let start = State::new(0.0, 0.0, 0.0, 0.8).unwrap();
        let laws = [
            hertz(),
            Contact::new(LawKind::HysterHertz, 1e9, Some(0.7), 0.0).unwrap(),
            Contact::new(LawKind::Linear, 2e6, None, 0.0).unwrap(),
        ];
        for contact in laws {
            for timing in [ContactTiming::Located, ContactTiming::StepCount] {
                let (dt, t_end) = (2e-6, 0.05);
                let ours = fixed(
                    &system,
                    &contact,
                    &start,
                    &mut rk4(&system),
                    (dt, t_end, timing, 1e-2),
                )
                .unwrap();
                let tolerance = 1e-2;
                let theirs = legacy(
                    &system,
                    &contact,
                    &start,
                    Method::Rk4,
                    (dt, t_end, timing, tolerance),
                );
                let label = format!("{:?} {timing:?}", contact.law);
                assert!(
                    theirs.contacts.len() >= 4,
                    "{label}: {}",
                    theirs.contacts.len()
                );
                assert_eq!(ours.steps, theirs.steps, "{label}");
                let worst = worst(&system, dt, &ours, &theirs, &label);
                assert!(worst.iter().all(|w| *w < 1e-9), "{label}: {worst:?}");
            }
        }
    });
}

#[test]
fn a_contact_damper_acts_only_where_the_pair_is_indented() {
    crate::testing::timeout(120, || {
        // 0.1's fixed-step force is a function of the state: the law's and
        // the contact damper's force act where the pair is indented, nothing
        // apart (in the stages past a separation or before an onset within
        // a step). With the damper on through a step in contact mode (the
        // rule before), the speeds agreed only to 2.5e-3 (linear, c1 = 20),
        // 2.6e-4 (Table 1, hertz) and 3.5e-3 (hyster-hertz), the onsets
        // and separations to 4.4, 18.6 and 47.7 steps.
        let system = ImpactDamper::new(1.0, 3947.8, 0.0, 0.05, 1e-3).unwrap();
        let start = State::new(0.0, 0.0, 0.0, 0.8).unwrap();
        let contact = Contact::new(LawKind::Linear, 2e6, None, 20.0).unwrap();
        // The founding paper's Table 1 system, its contact damper c1 on
        // both laws, with many contacts.
        let table1 = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.01).unwrap();
        let table1_start = State::new(0.0, 0.0, 0.01, 0.1).unwrap();
        let cases = [
            (system, start, contact, (2e-6, 0.01)),
            (
                table1,
                table1_start,
                Contact::new(LawKind::Hertz, 3000.0, None, 0.01).unwrap(),
                (1e-4, 20.0),
            ),
            (
                table1,
                table1_start,
                Contact::new(LawKind::HysterHertz, 3000.0, Some(0.9), 0.01).unwrap(),
                (1e-4, 20.0),
            ),
        ];
        for (system, start, contact, (dt, t_end)) in cases {
            for timing in [ContactTiming::Located, ContactTiming::StepCount] {
                let run = (dt, t_end, timing, 1e-2);
                let ours = fixed(&system, &contact, &start, &mut rk4(&system), run).unwrap();
                let theirs = legacy(&system, &contact, &start, Method::Rk4, run);
                let label = format!("{:?} {timing:?}", contact.law);
                assert!(theirs.contacts.len() >= 3, "{label}");
                let worst = worst(&system, dt, &ours, &theirs, &label);
                // Round-off apart (the sums' order differs), grown over
                // Table 1's 2e5 steps: measured to 1.2e-7 of a step at the
                // onsets and separations, 1.1e-11 in the rest.
                let (times, rest) = worst.split_at(2);
                assert!(times.iter().all(|w| *w < 1e-6), "{label}: {worst:?}");
                assert!(rest.iter().all(|w| *w < 1e-10), "{label}: {worst:?}");
            }
        }
    });
}

#[test]
fn a_linear_contact_lasts_half_a_damped_period() {
    crate::testing::timeout(60, || {
        // Two free bodies (no main spring): the closed form's setting.
        let system = ImpactDamper::new(1.0, 0.0, 0.0, 0.05, 1e-3).unwrap();
        let (k1, c1) = (1e6, 5.0);
        let contact = Contact::new(LawKind::Linear, k1, None, c1).unwrap();
        let start = State::new(0.0, 0.0, 0.0, 0.5).unwrap();
        let expected = linear_contact_duration(0.05, 1.0, k1, c1).unwrap();
        let run = fixed(
            &system,
            &contact,
            &start,
            &mut rk4(&system),
            (1e-6, 0.01, ContactTiming::Located, 1e-2),
        )
        .unwrap();
        let first: &PairContact = &run.contacts[0];
        assert!(
            (first.duration - expected).abs() < 1e-5 * expected,
            "{} against {expected}",
            first.duration
        );
        // Counted in whole steps: within a step at each end.
        let counted = fixed(
            &system,
            &contact,
            &start,
            &mut rk4(&system),
            (1e-6, 0.01, ContactTiming::StepCount, 1e-2),
        )
        .unwrap();
        assert!((counted.contacts[0].duration - expected).abs() <= 2e-6);
        assert_eq!(
            counted.contacts[0].onset,
            (counted.contacts[0].onset / 1e-6).round() * 1e-6
        );
    });
}

#[test]
fn an_undamped_contact_changes_the_energy_by_what_it_dissipates() {
    crate::testing::timeout(60, || {
        let system = ImpactDamper::new(1.0, 0.0, 0.0, 0.05, 1e-3).unwrap();
        let start = State::new(0.0, 0.0, 0.0, 0.5).unwrap();
        for contact in [
            Contact::new(LawKind::HysterHertz, 1e9, Some(0.6), 0.0).unwrap(),
            Contact::new(LawKind::Linear, 1e6, None, 5.0).unwrap(),
        ] {
            let dt = 1e-6;
            let settings = (dt, 0.01, ContactTiming::Located, 1e-2);
            let run = fixed(&system, &contact, &start, &mut rk4(&system), settings).unwrap();
            let c = &run.contacts[0];
            assert!(c.energy_dissipated > 1e-4, "{c:?}");
            // The stored energy is interpolated linearly to the onset and
            // the separation inside their steps, where the contact damper's
            // power jumps between 0 and c1 v^2: off by up to dt c1 v^2 / 4
            // at each: 1.1e-7 J of 4.1e-4 here, 3.2e-7 in 0.1's kernel,
            // whose rule this is.
            let c1 = contact.damping;
            let (va, vr) = (c.approach_speed, c.rebound_speed);
            let kinks = 0.25 * dt * c1 * (va * va + vr * vr);
            let theirs = legacy(&system, &contact, &start, Method::Rk4, settings);
            let b = &theirs.contacts[0];
            for (change, dissipated) in [
                (c.energy_change, c.energy_dissipated),
                (b.energy_change, b.energy_dissipated),
            ] {
                assert!(
                    (change + dissipated).abs() < 1e-5 * dissipated + kinks,
                    "{c:?} {b:?}"
                );
            }
            // The same in the event-driven kernel.
            let assembly = Assembly::new(&spec(&system, &contact)).unwrap();
            let y = initial_state(&assembly, &[0.0], &[0.0], &[0.0], &[0.5]).unwrap();
            let events = crate::kernel::events::integrate_system(
                &assembly,
                &mut rk4(&system),
                &y,
                &options(1e-6, 0.01),
                &mut || false,
            )
            .unwrap();
            let c = &events.contacts[0];
            assert!(
                (c.energy_change + c.energy_dissipated).abs() < 1e-6 * c.energy_dissipated,
                "{c:?}"
            );
        }
    });
}

#[test]
fn a_damped_contact_dissipates_the_kinetic_energy_lost() {
    crate::testing::timeout(60, || {
        // Two free bodies of Table 1 (no spring, no damper: every joule
        // lost is the contact's), hertz with c1 = 0.2 N s/m, fixed steps of
        // 1e-5 s (tests/test_verification.py's hertz+c1 case). The
        // contact's dissipation by the trapezoidal sum of its power against
        // the kinetic energy lost over the run: 0.1's RK4 holds them to
        // 2.4e-5. With the damper on through the steps in contact mode,
        // 1.2e-4 (rk4), 6.5e-5 (newmark-implicit), 1.5e-4
        // (generalized-alpha); now 2.4e-5, 1.2e-5 and 3.5e-6.
        let system = ImpactDamper::new(1.0, 0.0, 0.0, 0.25, 0.01).unwrap();
        let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.2).unwrap();
        let start = State::new(0.0, 0.0, 0.01, 0.1).unwrap();
        let settings = (1e-5, 0.3, ContactTiming::Located, 1e-2);
        let kinetic = |main: f64, impact: f64| 0.5 * (main * main + 0.25 * impact * impact);
        let initial = kinetic(0.0, 0.1);
        let check = |label: &str, lost: f64, dissipated: f64| {
            assert!(lost > 0.0, "{label}");
            let off = (dissipated - lost).abs() / lost;
            assert!(off < 5e-5, "{label}: {dissipated} against {lost}: {off:e}");
        };
        let theirs = legacy(&system, &contact, &start, Method::Rk4, settings);
        let end = theirs.final_state;
        let lost = initial - kinetic(end.main_velocity, end.impact_velocity);
        check("0.1", lost, theirs.contacts[0].energy_dissipated);
        let assembly = Assembly::new(&spec(&system, &contact)).unwrap();
        let runs = [
            (
                "rk4",
                fixed(&system, &contact, &start, &mut rk4(&system), settings),
            ),
            (
                "newmark-implicit",
                fixed(
                    &system,
                    &contact,
                    &start,
                    &mut NewmarkFamily::newmark(&assembly, 0.25, 0.5),
                    settings,
                ),
            ),
            (
                "generalized-alpha",
                fixed(
                    &system,
                    &contact,
                    &start,
                    &mut NewmarkFamily::generalized_alpha(&assembly, 1.0),
                    settings,
                ),
            ),
        ];
        for (label, run) in runs {
            let ours = run.unwrap();
            assert_eq!(ours.contacts.len(), 1, "{label}");
            // [w, y, w', y'] and the accumulators.
            let v = &ours.final_state;
            let lost = initial - kinetic(v[2], v[3]);
            check(label, lost, ours.contacts[0].energy_dissipated);
        }
    });
}

#[test]
fn fixed_stepping_refuses_rigid_pairs_and_adaptive_methods() {
    crate::testing::timeout(30, || {
        let system = ImpactDamper::new(1.0, 0.0, 0.0, 0.05, 1e-3).unwrap();
        let start = State::new(0.0, 0.0, 0.0, 0.5).unwrap();
        let rigid = Contact::new(LawKind::Linear, 1e6, None, 0.0).unwrap();
        let mut spec = spec(&system, &rigid);
        spec.dampers[0].law = PairLaw::rigid(0.5).unwrap();
        let assembly = Assembly::new(&spec).unwrap();
        let y = initial_state(&assembly, &[0.0], &[0.0], &[0.0], &[0.5]).unwrap();
        let stepping = Stepping::Fixed {
            contact_timing: ContactTiming::Located,
        };
        let run = |stepper: &mut ExplicitRk, assembly: &Assembly| {
            integrate_system_stepped(
                assembly,
                stepper,
                &y,
                &options(1e-6, 0.01),
                stepping,
                &mut || false,
                MAX_RECORD_BYTES,
            )
        };
        let message = run(&mut rk4(&system), &assembly).unwrap_err().to_string();
        assert!(
            message.contains("stepping") && message.contains("rigid"),
            "{message}"
        );
        let compliant = Assembly::new(&self::spec(&system, &rigid)).unwrap();
        let mut dop853 = ExplicitRk::dop853(compliant.state_len(), 1e-8, 1e-10);
        let message = run(&mut dop853, &compliant).unwrap_err().to_string();
        assert!(
            message.contains("stepping") && message.contains("dop853"),
            "{message}"
        );
        let _ = start;
    });
}

#[test]
fn fixed_paper_newmark_is_the_0_1_kernel() {
    crate::testing::timeout(60, || {
        // Every record to the bit, on both contact timings, the contact
        // damper too: the same operations in the same order.
        let system = ImpactDamper::new(1.0, 3947.8, 0.0, 0.05, 1e-3).unwrap();
        let start = State::new(0.0, 0.0, 0.0, 0.8).unwrap();
        for contact in [
            hertz(),
            Contact::new(LawKind::HysterHertz, 1e9, Some(0.7), 0.0).unwrap(),
            Contact::new(LawKind::Linear, 2e6, None, 20.0).unwrap(),
        ] {
            for timing in [ContactTiming::Located, ContactTiming::StepCount] {
                let (dt, t_end) = (1e-6, 0.02);
                let assembly = Assembly::new(&spec(&system, &contact)).unwrap();
                let mut stepper =
                    crate::methods::paper_newmark::PaperNewmark::new(&assembly, 0.25, 0.5).unwrap();
                let ours = fixed(
                    &system,
                    &contact,
                    &start,
                    &mut stepper,
                    (dt, t_end, timing, 0.5),
                )
                .unwrap();
                let method = Method::Newmark {
                    beta: 0.25,
                    gamma: 0.5,
                };
                // The lag creates energy at every contact (see
                // `creates_contact_energy`).
                let theirs = legacy(&system, &contact, &start, method, (dt, t_end, timing, 0.5));
                let label = format!("{:?} {timing:?}", contact.law);
                assert!(theirs.contacts.len() >= 2, "{label}");
                assert_eq!(ours.contacts.len(), theirs.contacts.len(), "{label}");
                for (a, b) in ours.contacts.iter().zip(&theirs.contacts) {
                    let same = [
                        (a.onset, b.onset),
                        (a.separation, b.separation),
                        (a.approach_speed, b.approach_speed),
                        (a.rebound_speed, b.rebound_speed),
                        (a.max_indentation, b.max_indentation),
                        (a.energy_dissipated, b.energy_dissipated),
                        (a.energy_change, b.energy_change),
                    ];
                    // The same operations in the same order: the same bits.
                    assert!(
                        same.iter().all(|(x, y)| x.to_bits() == y.to_bits()),
                        "{label}: {a:?} {b:?}"
                    );
                }
            }
        }
    });
}

#[test]
fn fixed_rk4_s_fast_path_is_its_general_path_to_the_bit() {
    crate::testing::timeout(60, || {
        // Forced and damped (a contact damper on one law), kept every 7th
        // step, a recorded window and strobes: every field of the solution.
        let system = ImpactDamper::new(1.0, 3947.8, 2.5, 0.05, 1e-3).unwrap();
        let laws = [
            hertz(),
            Contact::new(LawKind::Linear, 2e6, None, 20.0).unwrap(),
        ];
        // Unforced too: the free flights' stretch without a force.
        let cases = laws.iter().flat_map(|c| {
            [
                (c, ContactTiming::Located, true),
                (c, ContactTiming::StepCount, true),
            ]
        });
        for (contact, timing, forced) in cases.chain([(&laws[0], ContactTiming::Located, false)]) {
            let mut spec = spec(&system, contact);
            spec.excitations = vec![crate::model::assembly::Excitation {
                load: crate::model::assembly::Load::Force { at: 0.0 },
                signal: crate::model::signals::Signal::harmonic(20.0, 9.0, 0.3).unwrap(),
            }];
            spec.excitations.truncate(usize::from(forced));
            let assembly = Assembly::new(&spec).unwrap();
            assert!(assembly.compact.is_some());
            let y = initial_state(&assembly, &[0.0], &[0.0], &[0.0], &[0.3]).unwrap();
            let mut o = options(1e-5, 0.5);
            o.every = 7;
            o.reduce = ReduceOptions {
                record_from: 0.1,
                strobe_period: 1.0 / 9.0,
                mean_square: false,
                ..ReduceOptions::default()
            };
            let stepping = Stepping::Fixed {
                contact_timing: timing,
            };
            let [fast, general] = [true, false].map(|compact| {
                let mut stepper = ExplicitRk::rk4(assembly.state_len());
                stepper.compact = compact;
                let run = integrate_system_stepped(
                    &assembly,
                    &mut stepper,
                    &y,
                    &o,
                    stepping,
                    &mut || false,
                    MAX_RECORD_BYTES,
                );
                format!("{run:?}")
            });
            assert!(fast.contains("Compliant"), "{fast:.300}");
            assert!(fast == general, "{:?} {timing:?}", contact.law);
        }
    });
}
