//! A Rust caller may write the core's public structs as literals, skipping
//! their checking constructors: every run, study and shooting checks what it
//! is given when it starts, and a bad value is an error naming it, never a
//! panic, an empty run taken for a result, or a check quietly switched off.
//! (Each case here panicked or ran `Ok` before these checks.)

mod common;

use vibroimpact_core::analysis::settling::checked_strobe_period;
use vibroimpact_core::analysis::shooting::shoot;
use vibroimpact_core::analysis::study::{run_study, Analysis, Parameter, StudySettings};
use vibroimpact_core::error::Error;
use vibroimpact_core::kernel::events::RunOptions;
use vibroimpact_core::methods::registry::{AnyStepper, Options};
use vibroimpact_core::model::assembly::{
    initial_state, Assembly, Damper, Excitation, Load, PairLaw, SystemSpec,
};
use vibroimpact_core::model::contact::{Contact, LawKind};
use vibroimpact_core::model::signals::{Harmonic, Signal};
use vibroimpact_core::model::structure::Structure;
use vibroimpact_core::{simulate, ContactTiming, ImpactDamper, Method, Settings, State};

/// A forced oscillator carrying a Hertzian damper.
fn spec(signal: Signal, contact: Contact) -> SystemSpec {
    let damper = Damper {
        mass: 0.05,
        at: 0.0,
        lower_clearance: 5e-3,
        upper_clearance: 5e-3,
        law: PairLaw::Compliant(contact),
    };
    let mut spec = SystemSpec::of(
        Structure::oscillator(1.0, 3947.8, 2.513).unwrap(),
        vec![damper],
    );
    spec.excitations = vec![Excitation {
        load: Load::Force { at: 0.0 },
        signal,
    }];
    spec
}

fn hertz() -> Contact {
    Contact::new(LawKind::Hertz, 1e8, None, 0.0).unwrap()
}

fn harmonic() -> Signal {
    Signal::harmonic(5.0, 10.0, 0.0).unwrap()
}

fn options() -> RunOptions {
    RunOptions {
        dt: None,
        t_end: 0.2,
        every: 1,
        keep_history: false,
        max_steps: 1_000_000,
        max_rows: 1_000_000,
        energy_tolerance: 1e-3,
        reduce: Default::default(),
    }
}

/// The error of assembling `spec`, as text.
fn assembly_error(spec: &SystemSpec) -> String {
    match Assembly::new(spec) {
        Ok(_) => panic!("assembled: {spec:?}"),
        Err(e) => e.to_string(),
    }
}

/// The error of a dop853 run of the harmonic system with `options` from `y0`
/// (its right length unless given).
fn run_error(options: &RunOptions, y0: Option<Vec<f64>>) -> String {
    let system = Assembly::new(&spec(harmonic(), hertz())).unwrap();
    let y0 = y0.unwrap_or_else(|| initial_state(&system, &[0.0], &[0.0], &[0.0], &[0.0]).unwrap());
    let mut method = AnyStepper::new(&system, "dop853", &Options::default()).unwrap();
    match method.integrate(&system, &y0, options, &mut || false) {
        Ok(run) => panic!("ran {} steps: {options:?}", run.steps),
        Err(e) => e.to_string(),
    }
}

#[test]
fn signals_written_as_literals_are_checked_when_assembled() {
    common::timeout(30, || {
        let recorded = |time: Vec<f64>, value: Vec<f64>| Signal::Recorded { time, value };
        let sampled = |interval: f64, value: Vec<f64>| Signal::Sampled {
            interval,
            value,
            recipe: None,
        };
        let cases = [
            (recorded(vec![], vec![]), "at least 2 samples"),
            (
                recorded(vec![0.0, 1.0, 2.0], vec![1.0]),
                "as many values as times",
            ),
            (recorded(vec![0.0], vec![1.0]), "at least 2 samples"),
            // Decreasing times had run with no forcing at all (input work 0).
            (
                recorded(vec![1.0, 0.0], vec![1.0, 2.0]),
                "increase strictly",
            ),
            (recorded(vec![0.0, 1.0], vec![f64::NAN, 2.0]), "finite"),
            (sampled(0.01, vec![]), "1 to"),
            (
                sampled(0.0, vec![1.0, 2.0]),
                "interval must be a finite number > 0",
            ),
            (sampled(f64::NAN, vec![1.0, 2.0]), "interval must be"),
            (sampled(-0.01, vec![1.0, 2.0]), "interval must be"),
            (sampled(0.01, vec![1.0, f64::INFINITY]), "sample 1"),
            (
                Signal::Harmonic(Harmonic {
                    amplitude: f64::NAN,
                    frequency: 10.0,
                    phase: 0.0,
                }),
                "amplitude must be a finite number",
            ),
            (
                Signal::Harmonics(vec![Harmonic {
                    amplitude: 1.0,
                    frequency: -10.0,
                    phase: 0.0,
                }]),
                "frequency must be",
            ),
        ];
        for (signal, says) in cases {
            let error = assembly_error(&spec(signal.clone(), hertz()));
            assert!(
                error.starts_with("excitation 0 signal: ") && error.contains(says),
                "{signal:?}: {error}"
            );
        }
        // What the constructors make passes.
        let record = Signal::recorded(vec![0.0, 0.1, 0.2], vec![0.0, 1.0, 0.0], 2.0).unwrap();
        assert!(Assembly::new(&spec(record, hertz())).is_ok());
    });
}

#[test]
fn contact_laws_written_as_literals_are_checked_when_assembled() {
    common::timeout(30, || {
        let law = |law, stiffness, restitution, damping| Contact {
            law,
            stiffness,
            restitution,
            damping,
        };
        let cases = [
            // A negative contact damper puts energy in: it had run Ok.
            (law(LawKind::Hertz, 1e8, 1.0, -1.0), "damping must be"),
            (law(LawKind::Hertz, -1e8, 1.0, 0.0), "stiffness must be"),
            (
                law(LawKind::Linear, f64::NAN, 1.0, 0.0),
                "stiffness must be",
            ),
            (
                law(LawKind::HertzDamped, 1e8, 0.0, 0.0),
                "restitution must be in (0, 1]",
            ),
            (
                law(LawKind::HysterHertz, 1e8, 1.5, 0.0),
                "restitution must be in (0, 1]",
            ),
        ];
        for (contact, says) in cases {
            let error = assembly_error(&spec(harmonic(), contact));
            assert!(
                error.starts_with("damper 0") && error.contains(says),
                "{contact:?}: {error}"
            );
        }
    });
}

#[test]
fn run_options_are_checked_when_a_run_starts() {
    common::timeout(30, || {
        let with = |change: &dyn Fn(&mut RunOptions)| {
            let mut o = options();
            change(&mut o);
            o
        };
        let cases: [(RunOptions, &str); 12] = [
            // NaN or negative t_end had returned Ok with no step.
            (
                with(&|o| o.t_end = f64::NAN),
                "t_end must be finite and > 0 s",
            ),
            (with(&|o| o.t_end = -1.0), "t_end must be"),
            // An infinite one ran until max_steps.
            (with(&|o| o.t_end = f64::INFINITY), "t_end must be"),
            (with(&|o| o.dt = Some(f64::NAN)), "dt must be"),
            // A NaN tolerance had switched the energy checks off.
            (
                with(&|o| o.energy_tolerance = f64::NAN),
                "energy_tolerance must be in (0, 1]",
            ),
            (
                with(&|o| o.energy_tolerance = 0.0),
                "energy_tolerance must be",
            ),
            (with(&|o| o.every = 0), "every must be a whole number >= 1"),
            (with(&|o| o.max_steps = 0), "max_steps must be"),
            (
                with(&|o| o.reduce.strobe_period = 0.0),
                "strobe_period must be",
            ),
            (
                with(&|o| o.reduce.strobe_period = f64::NAN),
                "strobe_period must be",
            ),
            (
                with(&|o| o.reduce.record_from = f64::NAN),
                "record_from must be",
            ),
            (
                with(&|o| o.reduce.record_from = -1.0),
                "record_from must be",
            ),
        ];
        for (options, says) in cases {
            let error = run_error(&options, None);
            assert!(error.contains(says), "{options:?}: {error}");
        }
        // A NaN start had been "a numerical blow-up; reduce dt".
        let mut y0 = vec![0.0; 8];
        y0[2] = f64::NAN;
        let error = run_error(&options(), Some(y0));
        assert!(
            error.contains("initial state must be finite: value 2"),
            "{error}"
        );
    });
}

#[test]
fn two_mass_literals_are_checked_as_the_two_mass_model_names_them() {
    common::timeout(30, || {
        let damper = ImpactDamper::new(1.0, 1.0, 0.01, 0.25, 0.01).unwrap();
        let contact = Contact::new(LawKind::Hertz, 3000.0, None, 0.0).unwrap();
        let start = State::new(0.0, 0.0, 0.01, 0.1).unwrap();
        let settings = Settings::new(
            Method::Rk4,
            Some(1e-3),
            1.0,
            1,
            ContactTiming::Located,
            None,
            10_000,
        )
        .unwrap();
        let run = |d: &ImpactDamper, s: &State, t: &Settings| {
            simulate(d, &contact, s, t, &mut || false).map(|_| ())
        };
        assert_eq!(run(&damper, &start, &settings), Ok(()));
        let error = |e: Result<(), Error>| e.unwrap_err().to_string();
        let cases = [
            (
                error(run(
                    &damper,
                    &start,
                    &Settings {
                        t_end: f64::NAN,
                        ..settings
                    },
                )),
                "t_end must be",
            ),
            (
                error(run(
                    &damper,
                    &start,
                    &Settings {
                        every: 0,
                        ..settings
                    },
                )),
                "every must be",
            ),
            (
                error(run(
                    &damper,
                    &start,
                    &Settings {
                        energy_tolerance: f64::NAN,
                        ..settings
                    },
                )),
                "energy_tolerance must be",
            ),
            // Named as the two-mass model names it, not "damper 0 mass".
            (
                error(run(
                    &ImpactDamper {
                        impact_mass: -0.25,
                        ..damper
                    },
                    &start,
                    &settings,
                )),
                "impact_mass must be",
            ),
            (
                error(run(
                    &damper,
                    &State {
                        main_velocity: f64::NAN,
                        ..start
                    },
                    &settings,
                )),
                "main_velocity must be",
            ),
        ];
        for (error, says) in cases {
            assert!(error.starts_with(says), "{error}");
        }
    });
}

#[test]
fn study_settings_and_values_are_checked_before_any_run() {
    common::timeout(60, || {
        let spec = spec(harmonic(), hertz());
        let initial: [Vec<f64>; 4] = [vec![0.0], vec![0.0], vec![0.0], vec![0.0]];
        let parameter = Parameter::parse("damper.0.mass", &spec).unwrap();
        let settings = StudySettings {
            method: "dop853".into(),
            dt: None,
            options: Options::default(),
            max_steps: 1_000_000,
            energy_tolerance: 1e-3,
            analysis: Analysis::Run {
                t_end: 0.05,
                record_from: 0.0,
            },
            mean_square: false,
            lockstep: false,
            lyapunov: false,
        };
        let study = |settings: &StudySettings, values: &[f64]| {
            let parameters = [parameter.clone()];
            run_study(&spec, &initial, &parameters, values, settings, 1, &|| false)
        };
        let results = study(&settings, &[0.05, 0.06]).unwrap();
        assert_eq!(results.iter().map(|r| r.status).collect::<Vec<_>>(), [0, 0]);
        let with = |analysis| StudySettings {
            analysis,
            ..settings.clone()
        };
        let cases = [
            // A NaN t_end had given status 0 and empty metrics.
            (
                with(Analysis::Run {
                    t_end: f64::NAN,
                    record_from: 0.0,
                }),
                "t_end must be",
            ),
            (
                with(Analysis::Run {
                    t_end: 0.05,
                    record_from: 0.05,
                }),
                "record_from must be",
            ),
            // Overflowed (a panic in a debug build, a wrap in release).
            (
                with(Analysis::SteadyState {
                    settle: u64::MAX,
                    record: 10,
                    tolerance: 1e-6,
                }),
                "at most 10000000 forcing periods",
            ),
            // Zero periods had reported a "stable" orbit of multiplier 1.
            (
                with(Analysis::Orbit {
                    settle: 10,
                    periods: 0,
                }),
                "orbit_periods must be",
            ),
            (
                StudySettings {
                    energy_tolerance: f64::NAN,
                    ..settings.clone()
                },
                "energy_tolerance must be",
            ),
        ];
        for (settings, says) in cases {
            let error = study(&settings, &[0.05]).unwrap_err().to_string();
            assert!(error.contains(says), "{:?}: {error}", settings.analysis);
        }
        // Three values for one row of two parameters had dropped the third.
        let two = [
            parameter.clone(),
            Parameter::parse("damper.0.clearance", &spec).unwrap(),
        ];
        let error = run_study(
            &spec,
            &initial,
            &two,
            &[0.05, 5e-3, 0.06],
            &settings,
            1,
            &|| false,
        )
        .unwrap_err()
        .to_string();
        assert!(error.contains("2 values a row, got 3"), "{error}");
    });
}

#[test]
fn a_shooting_checks_its_start_and_its_map() {
    common::timeout(30, || {
        // A linear map with a fixed point at (1, 0): it converges when given
        // what it asks.
        let mut good = |z: &[f64]| Ok(vec![0.5 * z[0] + 0.5, 0.5 * z[1]]);
        let shot = shoot(&mut good, &[0.0, 0.0], 0.1, 1e-10, 20).unwrap();
        assert!(shot.converged && (shot.state[0] - 1.0).abs() < 1e-9);
        // A map of the wrong length had panicked (index out of bounds).
        let mut wrong = |_: &[f64]| Ok(vec![0.0]);
        let error = shoot(&mut wrong, &[0.0, 0.0], 0.1, 1e-10, 20).unwrap_err();
        assert!(
            error
                .to_string()
                .contains("image must have 2 values, got 1"),
            "{error}"
        );
        let cases: [(&[f64], f64, &str); 4] = [
            (&[0.0, 0.0], f64::NAN, "forcing_period must be"),
            // An empty start had reported "converged".
            (&[], 0.1, "an even number of values"),
            (&[0.0, 0.0, 0.0], 0.1, "an even number of values"),
            (&[0.0, f64::NAN], 0.1, "value 1 is NaN"),
        ];
        for (z0, period, says) in cases {
            let error = shoot(&mut good, z0, period, 1e-10, 20)
                .unwrap_err()
                .to_string();
            assert!(error.contains(says), "{z0:?} {period}: {error}");
        }
        // Rows that do not divide the data had returned Ok(None).
        let error = checked_strobe_period(&[0.0; 6], 4, 0.1, 1e-6, 2).unwrap_err();
        assert!(
            error.to_string().contains("must divide the 6 values"),
            "{error}"
        );
    });
}
