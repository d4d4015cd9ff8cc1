//! A run continued from another's final state with the compliant contacts it
//! left open (`integrate_system_continued`) is the one run in two pieces: the
//! contact keeps its onset and a damped law its latched approach rate, where a
//! fresh start inside the contact begins it again.

mod common;

use vibroimpact_core::kernel::events::{
    integrate_system_continued, CarriedContact, RunOptions, Stepping, SystemSolution,
};
use vibroimpact_core::kernel::memory::MAX_RECORD_BYTES;
use vibroimpact_core::methods::steppers::ExplicitRk;
use vibroimpact_core::model::assembly::{
    resumed_state, Assembly, Damper, Excitation, Load, PairLaw, SystemSpec,
};
use vibroimpact_core::model::contact::{Contact, LawKind};
use vibroimpact_core::model::signals::Signal;
use vibroimpact_core::model::structure::Structure;

const FREQUENCY: f64 = 11.5;

/// A forced oscillator with a hertz-damped damper whose settled orbit is
/// inside a contact at each multiple of the forcing period.
fn system() -> Assembly {
    let contact = Contact::new(LawKind::HertzDamped, 1e8, Some(0.8), 0.0).unwrap();
    Assembly::new(&SystemSpec {
        dampers: vec![Damper {
            mass: 0.05,
            at: 0.0,
            lower_clearance: 0.005,
            upper_clearance: 0.005,
            law: PairLaw::Compliant(contact),
        }],
        excitations: vec![Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(5.0, FREQUENCY, 0.0535).unwrap(),
        }],
        ..SystemSpec::of(Structure::oscillator(1.0, 3947.8, 2.513).unwrap(), vec![])
    })
    .unwrap()
}

/// `periods` forcing periods from the flat state `z` (x then v), continuing
/// `carried`.
fn run(
    system: &Assembly,
    z: &[f64],
    carried: &[Option<CarriedContact>],
    periods: f64,
) -> vibroimpact_core::Result<SystemSolution> {
    let (n, d) = (system.n, system.dim);
    let y = resumed_state(system, [&z[..n], &z[d..d + n], &z[n..d], &z[d + n..]])?;
    let options = RunOptions {
        dt: None,
        t_end: periods / FREQUENCY,
        every: 1,
        keep_history: false,
        max_steps: 10_000_000,
        max_rows: 10_000_000,
        energy_tolerance: 1e-6,
        reduce: Default::default(),
    };
    let mut stepper = ExplicitRk::dop853(system.state_len(), 1e-10, 1e-13);
    integrate_system_continued(
        system,
        &mut stepper,
        (&y, carried),
        &options,
        Stepping::Events,
        &mut || false,
        MAX_RECORD_BYTES,
    )
}

#[test]
fn a_run_continued_with_its_open_contacts_is_the_run_in_two_pieces() {
    common::timeout(60, || {
        let system = system();
        let settled = run(&system, &[0.0; 4], &[], 300.0).unwrap();
        let start = (&settled.final_state, settled.carried());
        assert!(
            start.1.iter().any(Option::is_some),
            "the strobe is in a contact"
        );
        let whole = run(&system, start.0, &start.1, 12.0).unwrap();
        let first = run(&system, start.0, &start.1, 7.0).unwrap();
        let open = first.carried();
        let second = run(&system, &first.final_state, &open, 5.0).unwrap();
        let fresh = run(&system, &first.final_state, &[], 5.0).unwrap();
        // The contact continued: its onset the first run's, shifted.
        let (pair, c) = open
            .iter()
            .enumerate()
            .find_map(|(i, c)| c.map(|c| (i, c)))
            .unwrap();
        let record = second.contacts.iter().find(|r| r.onset < 0.0).unwrap();
        assert_eq!(record.pair, system.interactions()[pair].pair);
        assert_eq!(
            (record.onset, record.approach_speed),
            (c.onset, c.approach_speed)
        );
        assert!(fresh.contacts.iter().all(|r| r.onset >= 0.0));
        let scale = whole
            .final_state
            .iter()
            .fold(0.0_f64, |m, v| m.max(v.abs()));
        let off = |sol: &SystemSolution| {
            sol.final_state
                .iter()
                .zip(&whole.final_state)
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()))
                / scale
        };
        // Measured: 1.9e-9 carried (the adaptive steps restart), 2.6 fresh.
        assert!(off(&second) < 1e-7, "{}", off(&second));
        assert!(off(&fresh) > 1e-2, "{}", off(&fresh));
        // Begun in the pieces: as many as in the whole.
        let begun = |sol: &SystemSolution| sol.contacts.iter().filter(|r| r.onset >= 0.0).count();
        assert_eq!(begun(&first) + begun(&second), begun(&whole));
    });
}

#[test]
fn carried_contacts_no_run_could_leave_are_refused() {
    common::timeout(30, || {
        let system = system();
        let one = [None];
        let err = run(&system, &[0.0; 4], &one, 1.0).unwrap_err().to_string();
        assert!(err.contains("one per interaction (2), got 1"), "{err}");
        let later = CarriedContact {
            approach_rate: 1.0,
            onset: 0.5,
            approach_speed: 1.0,
            max_indentation: 0.0,
        };
        let err = run(&system, &[0.0; 4], &[None, Some(later)], 1.0)
            .unwrap_err()
            .to_string();
        assert!(err.contains("carried contact 1: "), "{err}");
    });
}
