//! The exact flow (`method = "exact"`) against closed forms written here: a
//! free oscillator under-, critically and over-damped, a forced one on its
//! steady state, a free mass under gravity, a loose mass stuck to a
//! structure (the combined mass's frequency), the bouncing ball's Zeno time,
//! the reductions (located peak, RMS, strobe) and what it refuses.

mod common;

use std::f64::consts::TAU;
use vibroimpact_core::kernel::events::{integrate_system, ContactKind, RunOptions, SystemSolution};
use vibroimpact_core::kernel::reductions::ReduceOptions;
use vibroimpact_core::methods::exact::ExactFlow;
use vibroimpact_core::methods::steppers::ExplicitRk;
use vibroimpact_core::model::assembly::{
    initial_state, Assembly, Damper, Excitation, Load, PairLaw, Side, Stop, SystemSpec,
};
use vibroimpact_core::model::contact::{Contact, LawKind};
use vibroimpact_core::model::signals::{Signal, SweepLaw};
use vibroimpact_core::model::structure::Structure;

fn spec(structure: Structure) -> SystemSpec {
    SystemSpec::of(structure, vec![])
}

fn exact(
    spec: &SystemSpec,
    y0: &[Vec<f64>; 4],
    t_end: f64,
    reduce: ReduceOptions,
) -> SystemSolution {
    let system = Assembly::new(spec).unwrap();
    let y = initial_state(&system, &y0[0], &y0[1], &y0[2], &y0[3]).unwrap();
    let mut flow = ExactFlow::new(&system).unwrap();
    let options = RunOptions {
        dt: Some(flow.step().min(t_end)),
        t_end,
        every: 1,
        keep_history: true,
        max_steps: 100_000_000,
        max_rows: 100_000_000,
        energy_tolerance: 1e-9,
        reduce,
    };
    integrate_system(&system, &mut flow, &y, &options, &mut || false).unwrap()
}

fn close(a: f64, b: f64, tolerance: f64) -> bool {
    (a - b).abs() <= tolerance * b.abs().max(1e-300)
}

#[test]
fn free_oscillator_matches_its_closed_form_in_each_damping_regime() {
    common::timeout(60, || {
        let (m, k, x0, v0, t): (f64, f64, f64, f64, f64) = (2.0, 800.0, 0.01, -0.3, 0.37);
        let wn = (k / m).sqrt();
        for zeta in [0.0, 0.05, 1.0, 3.0] {
            let c = 2.0 * zeta * m * wn;
            let s = spec(Structure::oscillator(m, k, c).unwrap());
            let sol = exact(
                &s,
                &[vec![x0], vec![v0], vec![], vec![]],
                t,
                ReduceOptions::default(),
            );
            // x(t) by the textbook forms of each regime.
            let sigma = zeta * wn;
            let (x, v) = if zeta < 1.0 {
                let wd = wn * (1.0 - zeta * zeta).sqrt();
                let (a, b) = (x0, (v0 + sigma * x0) / wd);
                let e = (-sigma * t).exp();
                let x = e * (a * (wd * t).cos() + b * (wd * t).sin());
                let v = -sigma * x + e * wd * (-a * (wd * t).sin() + b * (wd * t).cos());
                (x, v)
            } else if zeta == 1.0 {
                let (a, b) = (x0, v0 + wn * x0);
                let e = (-wn * t).exp();
                (e * (a + b * t), e * (b - wn * (a + b * t)))
            } else {
                let r = wn * (zeta * zeta - 1.0).sqrt();
                let (l1, l2) = (-sigma + r, -sigma - r);
                let b = (v0 - l1 * x0) / (l2 - l1);
                let a = x0 - b;
                (
                    a * (l1 * t).exp() + b * (l2 * t).exp(),
                    a * l1 * (l1 * t).exp() + b * l2 * (l2 * t).exp(),
                )
            };
            let end = &sol.final_state;
            assert!(close(end[0], x, 1e-11), "zeta {zeta}: x {} vs {x}", end[0]);
            assert!(close(end[1], v, 1e-11), "zeta {zeta}: v {} vs {v}", end[1]);
            // The viscous loss is the energy that left: the balance closes.
            assert!(
                sol.energy.residual.abs() <= 1e-10 * sol.energy.stored_start,
                "zeta {zeta}: {:?}",
                sol.energy
            );
        }
    });
}

#[test]
fn forced_oscillator_stays_on_its_steady_state_and_reduces_it() {
    common::timeout(60, || {
        let (m, k, c, force, f) = (1.0, 3000.0, 3.0, 2.0, 7.0);
        let w = TAU * f;
        // Q = F / (k - m w^2 + i c w).
        let (re, im) = (k - m * w * w, c * w);
        let norm = re * re + im * im;
        let (qr, qi) = (force * re / norm, -force * im / norm);
        let mut s = spec(Structure::oscillator(m, k, c).unwrap());
        s.excitations.push(Excitation {
            load: Load::Force { at: 0.0 },
            signal: Signal::harmonic(force, f, 0.0).unwrap(),
        });
        let periods = 20.0;
        let sol = exact(
            &s,
            &[vec![qr], vec![-w * qi], vec![], vec![]],
            periods / f,
            ReduceOptions {
                record_from: 0.0,
                strobe_period: 1.0 / f,
                mean_square: true,
                contacts_from: f64::NEG_INFINITY,
            },
        );
        let amplitude = (qr * qr + qi * qi).sqrt();
        assert!(
            close(sol.final_state[0], qr, 1e-9),
            "{} vs {qr}",
            sol.final_state[0]
        );
        let r = &sol.reductions;
        assert!(
            close(r.peaks[0], amplitude, 1e-10),
            "peak {} vs {amplitude}",
            r.peaks[0]
        );
        let rms = (r.square_integrals[0] / r.recorded_time).sqrt();
        assert!(close(rms, amplitude / 2f64.sqrt(), 1e-5), "rms {rms}");
        assert_eq!(r.strobe_time.len(), periods as usize);
        for row in r.strobe.chunks(2) {
            assert!(close(row[0], qr, 1e-9), "strobe {row:?} vs {qr}");
        }
        // Input work equals the viscous loss over whole periods (steady state).
        let e = sol.energy;
        assert!(close(e.input_work, e.viscous, 1e-8), "{e:?}");
        assert!(close(
            e.viscous,
            periods * 0.5 * c * w * w * amplitude * amplitude / f,
            1e-8
        ));
    });
}

#[test]
fn a_free_mass_falls_as_a_parabola() {
    common::timeout(60, || {
        let g = 9.81;
        let mut s = spec(Structure::oscillator(0.3, 0.0, 0.0).unwrap());
        s.gravity = g;
        let t = 0.8;
        let sol = exact(
            &s,
            &[vec![1.0], vec![2.0], vec![], vec![]],
            t,
            ReduceOptions::default(),
        );
        assert!(close(
            sol.final_state[0],
            1.0 + 2.0 * t - 0.5 * g * t * t,
            1e-14
        ));
        assert!(close(sol.final_state[1], 2.0 - g * t, 1e-14));
    });
}

#[test]
fn ball_on_a_floor_accumulates_at_the_zeno_time_then_rests() {
    common::timeout(60, || {
        let (g, h, e) = (9.81, 1.0, 0.8);
        let mut s = spec(Structure::oscillator(0.2, 0.0, 0.0).unwrap());
        s.gravity = g;
        s.stops.push(Stop {
            at: 0.0,
            side: Side::Lower,
            gap: h,
            law: PairLaw::rigid(e).unwrap(),
            against: None,
        });
        let sol = exact(
            &s,
            &[vec![], vec![], vec![], vec![]],
            6.0,
            ReduceOptions::default(),
        );
        let t_inf = (2.0 * h / g).sqrt() * (1.0 + e) / (1.0 - e);
        let last = sol.contacts.last().unwrap();
        assert_eq!(last.kind, ContactKind::Sticking);
        assert!(close(last.onset, t_inf, 1e-9), "{} vs {t_inf}", last.onset);
        // Impact speeds sqrt(2 g h) e^(n - 1).
        let first = sqrt_2gh(g, h);
        for (n, c) in sol
            .contacts
            .iter()
            .filter(|c| c.kind == ContactKind::Impact)
            .take(10)
            .enumerate()
        {
            assert!(close(c.approach_speed, first * e.powi(n as i32), 1e-9));
        }
        assert!(close(sol.final_state[0], -h, 1e-12));
        assert!(sol.final_state[1].abs() < 1e-12);
    });
}

/// Two storeys that start touching (a gap of zero), shaken at the base from
/// rest: their gap first closes as t^3, and the exact flow's first step (a
/// millisecond) holds tiny rebounds whose landings are a microsecond away. It
/// had located each landing at the step's start, again and again, and
/// stopped with a chattering error after 5 us; the impacts of the pounding
/// that follows are those of DOP853 at a tight tolerance.
#[test]
fn storeys_that_start_touching_pound_as_dop853_has_them() {
    common::timeout(60, || {
        let mut s = spec(
            Structure::matrices(
                &[vec![1e5, 0.0], vec![0.0, 2e5]],
                &[vec![1.579e7, 0.0], vec![0.0, 7.896e6]],
                &[vec![1.2566e5, 0.0], vec![0.0, 1.2566e5]],
            )
            .unwrap(),
        );
        s.stops.push(Stop {
            at: 0.0,
            side: Side::Upper,
            gap: 0.0,
            law: PairLaw::rigid(0.65).unwrap(),
            against: Some(1.0),
        });
        s.excitations.push(Excitation {
            load: Load::Base,
            signal: Signal::harmonic(2.0, 1.5, 0.0).unwrap(),
        });
        let zero = [vec![], vec![], vec![], vec![]];
        let sol = exact(&s, &zero, 3.0, ReduceOptions::default());
        let system = Assembly::new(&s).unwrap();
        let y = initial_state(&system, &[], &[], &[], &[]).unwrap();
        let mut dop853 = ExplicitRk::dop853(system.state_len(), 1e-12, 1e-15);
        let options = RunOptions {
            dt: None,
            t_end: 3.0,
            every: 1,
            keep_history: false,
            max_steps: 10_000_000,
            max_rows: 10_000_000,
            energy_tolerance: 1e-6,
            reduce: ReduceOptions::default(),
        };
        let reference =
            integrate_system(&system, &mut dop853, &y, &options, &mut || false).unwrap();
        // The pounding's impacts (faster than a millimetre per second).
        let impacts = |sol: &SystemSolution| {
            sol.contacts
                .iter()
                .filter(|c| c.kind == ContactKind::Impact && c.approach_speed > 1e-3)
                .map(|c| (c.onset, c.approach_speed))
                .collect::<Vec<_>>()
        };
        let (ours, theirs) = (impacts(&sol), impacts(&reference));
        assert!(ours.len() >= 6, "{ours:?}");
        assert_eq!(ours.len(), theirs.len());
        for ((t, v), (t_ref, v_ref)) in ours.iter().zip(&theirs) {
            assert!((t - t_ref).abs() < 1e-8, "{t} vs {t_ref}");
            assert!(close(*v, *v_ref, 1e-6), "{v} vs {v_ref}");
        }
    });
}

fn sqrt_2gh(g: f64, h: f64) -> f64 {
    (2.0 * g * h).sqrt()
}

#[test]
fn a_loose_mass_stuck_to_its_structure_moves_with_the_combined_mass() {
    common::timeout(60, || {
        // A vertical oscillator carrying a loose mass resting on its lower
        // wall: with a gentle motion (peak acceleration below g) the mass never
        // lifts off, so after the first touch they oscillate together at
        // sqrt(k / (M + m)) about the combined static deflection.
        let (big, small, k, g) = (1.0, 0.25, 400.0, 9.81);
        let mut s = spec(Structure::oscillator(big, k, 0.0).unwrap());
        s.gravity = g;
        s.dampers.push(Damper {
            mass: small,
            at: 0.0,
            lower_clearance: 0.0,
            upper_clearance: 0.05,
            law: PairLaw::rigid(0.0).unwrap(),
        });
        let static_both = -(big + small) * g / k;
        let amplitude = 0.1 * g / (k / (big + small)); // peak acceleration 0.1 g
        let x0 = static_both + amplitude;
        let t = 0.9;
        // Start resting together on the wall (gap zero, same velocity).
        let sol = exact(
            &s,
            &[vec![x0], vec![0.0], vec![x0], vec![0.0]],
            t,
            ReduceOptions::default(),
        );
        let w = (k / (big + small)).sqrt();
        let x = static_both + amplitude * (w * t).cos();
        assert!(
            close(sol.final_state[0], x, 1e-8),
            "{} vs {x}",
            sol.final_state[0]
        );
        assert!(
            close(sol.final_state[1], x, 1e-8),
            "{:?} {:?}",
            sol.final_state,
            sol.contacts
        );
        // Starting on the wall, the first located touch is an impact at round-off
        // speed, then one sticking contact to the end.
        let sticking: Vec<_> = sol
            .contacts
            .iter()
            .filter(|c| c.kind == ContactKind::Sticking)
            .collect();
        assert_eq!(sticking.len(), 1, "{:?}", sol.contacts);
        assert!(sticking[0].onset < 1e-6 && sticking[0].separation.is_nan());
        assert!(sol
            .contacts
            .iter()
            .all(|c| c.kind == ContactKind::Sticking || c.approach_speed < 1e-6));
    });
}

#[test]
fn refuses_what_it_cannot_integrate_exactly() {
    common::timeout(60, || {
        let base = spec(Structure::oscillator(1.0, 100.0, 0.1).unwrap());
        let mut hertz = base.clone();
        hertz.stops.push(Stop {
            at: 0.0,
            side: Side::Upper,
            gap: 0.01,
            law: PairLaw::Compliant(Contact::new(LawKind::Hertz, 1e7, None, 0.5).unwrap()),
            against: None,
        });
        let mut swept = base.clone();
        swept.excitations.push(Excitation {
            load: Load::Base,
            signal: Signal::sweep(1.0, 1.0, 2.0, 1.0, SweepLaw::Linear, 0.0).unwrap(),
        });
        for (what, s, word) in [("hertz", hertz, "linear"), ("sweep", swept, "harmonic")] {
            let system = Assembly::new(&s).unwrap();
            let err = ExactFlow::new(&system).unwrap_err().to_string();
            assert!(err.contains("exact") && err.contains(word), "{what}: {err}");
        }
    });
}

#[test]
fn a_linear_contact_between_free_masses_lasts_half_its_damped_period() {
    common::timeout(60, || {
        // Two free masses, a spring-dashpot contact (k, c): the indentation is
        // a damped oscillator of the effective mass, so the contact lasts
        // pi / w_d and the rebound is v0 exp(-zeta w_n pi / w_d). The damper
        // makes the damping non-classical: the matrix exponential's path.
        let (big, small, k, c, v0) = (1.0, 0.1, 2e5, 5.0, 0.5);
        let mut s = spec(Structure::oscillator(big, 0.0, 0.0).unwrap());
        s.dampers.push(Damper {
            mass: small,
            at: 0.0,
            // Far from the lower wall: one contact, with the upper one.
            lower_clearance: 0.1,
            upper_clearance: 0.0,
            law: PairLaw::Compliant(Contact::new(LawKind::Linear, k, None, c).unwrap()),
        });
        let sol = exact(
            &s,
            &[vec![], vec![], vec![], vec![v0]],
            0.003,
            ReduceOptions::default(),
        );
        let me = big * small / (big + small);
        let wn = (k / me).sqrt();
        let zeta = c / (2.0 * me * wn);
        let wd = wn * (1.0 - zeta * zeta).sqrt();
        let contact = sol.contacts[0];
        assert_eq!(contact.kind, ContactKind::Compliant);
        let duration = std::f64::consts::PI / wd;
        assert!(close(contact.duration, duration, 1e-12), "{contact:?}");
        let rebound = v0 * (-zeta * wn * duration).exp();
        assert!(close(contact.rebound_speed, rebound, 1e-12), "{contact:?}");
        // Momentum is kept and the energy taken is the dashpot's.
        let momentum = big * sol.final_state[2] + small * sol.final_state[3];
        assert!(close(momentum, small * v0, 1e-12));
        let lost = 0.5 * me * (v0 * v0 - rebound * rebound);
        assert!(close(sol.energy.contact, lost, 1e-9), "{:?}", sol.energy);
    });
}

/// A 3-mode aluminium cantilever driven by 0.5 N at its tip at 8 Hz, with
/// its steady modal amplitudes solved mode by mode, `Q_i = f_i / (K_ii - w^2
/// M_ii + i w C_ii)` (re, im), the spec of that forcing, and the state on
/// that steady motion at t = 0 (displacements `Re Q`, velocities `-w Im Q`).
#[allow(clippy::type_complexity)]
fn forced_beam() -> (Structure, Vec<(f64, f64)>, SystemSpec, [Vec<f64>; 4]) {
    let (length, force, f) = (0.5, 0.5, 8.0);
    let beam = Structure::cantilever(length, 7e10, 1e-10, 0.27, 3, 0.01).unwrap();
    let w = TAU * f;
    let tip = beam.point("tip", length).unwrap();
    let (m, k, c) = (beam.mass(), beam.stiffness(), beam.damping());
    let q: Vec<(f64, f64)> = (0..3)
        .map(|i| {
            let d = i * 3 + i;
            let (re, im) = (k[d] - w * w * m[d], w * c[d]);
            let norm = re * re + im * im;
            let fi = force * tip[i];
            (fi * re / norm, -fi * im / norm)
        })
        .collect();
    let mut s = spec(beam.clone());
    s.excitations.push(Excitation {
        load: Load::Force { at: length },
        signal: Signal::harmonic(force, f, 0.0).unwrap(),
    });
    let x0 = q.iter().map(|(re, _)| *re).collect();
    let v0 = q.iter().map(|(_, im)| -w * im).collect();
    (beam, q, s, [x0, v0, vec![], vec![]])
}

/// Peaks and mean squares of the whole run, no strobe, every contact kept.
fn recorded() -> ReduceOptions {
    ReduceOptions {
        record_from: 0.0,
        strobe_period: f64::INFINITY,
        mean_square: true,
        contacts_from: f64::NEG_INFINITY,
    }
}

/// The amplitude of `row . Q e^{i w t}`.
fn amplitude_of(row: &[f64], q: &[(f64, f64)]) -> f64 {
    let (re, im) = row
        .iter()
        .zip(q)
        .fold((0.0, 0.0), |(a, b), (r, (qr, qi))| (a + r * qr, b + r * qi));
    re.hypot(im)
}

#[test]
fn a_forced_cantilever_s_points_reduce_its_deflection_there() {
    common::timeout(60, || {
        let (beam, q, mut s, start) = forced_beam();
        let (length, f) = (0.5, 8.0);
        let points = [length, 0.3, 0.0];
        s.points = points.to_vec();
        let reduce = recorded();
        let exact_run = exact(&s, &start, 10.0 / f, reduce);
        // And RK4's, which places peaks by its interpolant (fifth order).
        let system = Assembly::new(&s).unwrap();
        let y = initial_state(&system, &start[0], &start[1], &[], &[]).unwrap();
        let mut rk4 = ExplicitRk::rk4(system.state_len());
        let options = RunOptions {
            dt: Some(1.0 / (400.0 * f)),
            t_end: 10.0 / f,
            every: 1,
            keep_history: false,
            max_steps: 100_000_000,
            max_rows: 100_000_000,
            energy_tolerance: 1e-6,
            reduce,
        };
        let fixed = integrate_system(&system, &mut rk4, &y, &options, &mut || false).unwrap();
        for (sol, tolerance) in [(&exact_run, 1e-9), (&fixed, 1e-7)] {
            let r = &sol.reductions;
            assert_eq!(r.peaks.len(), 3 + points.len());
            for (j, &at) in points.iter().enumerate() {
                // The deflection there is Re(sum_i row_i Q_i e^{i w t}).
                let amplitude = amplitude_of(&beam.point("point", at).unwrap(), &q);
                let peak = r.peaks[3 + j];
                let rms = (r.square_integrals[3 + j] / r.recorded_time).sqrt();
                if at == 0.0 {
                    // The clamp does not move.
                    assert!(peak <= 1e-12 * r.peaks[3], "clamp {peak}");
                    continue;
                }
                assert!(
                    close(peak, amplitude, tolerance),
                    "at {at}: peak {peak} vs {amplitude}"
                );
                assert!(
                    close(rms, amplitude / 2f64.sqrt(), 1e-6),
                    "at {at}: rms {rms}"
                );
            }
            // A point is no coordinate: the tip's amplitude is not a mode's.
            assert!(r.peaks[3] > 1.1 * r.peaks[0], "{:?}", r.peaks);
        }
    });
}

#[test]
fn points_outside_the_structure_are_refused_by_name() {
    common::timeout(10, || {
        let mut s = spec(Structure::cantilever(0.5, 7e10, 1e-10, 0.27, 3, 0.01).unwrap());
        s.points = vec![0.2, 0.7];
        let err = Assembly::new(&s).unwrap_err().to_string();
        assert!(
            err.contains("[output] points[1] must be a position along the beam in [0, 0.5] m"),
            "{err}"
        );
        let mut s = spec(Structure::oscillator(1.0, 1.0, 0.0).unwrap());
        s.points = vec![0.0; vibroimpact_core::model::assembly::MAX_POINTS + 1];
        let err = Assembly::new(&s).unwrap_err().to_string();
        assert!(err.contains("points: at most"), "{err}");
    });
}

#[test]
fn a_cantilever_s_bending_moment_is_statics_and_its_peaks_reduce() {
    common::timeout(60, || {
        // Statics first: under a tip load P the modal deflections are
        // q_i = phi_i(L) P / K_ii, and the moment E I w'' there must be
        // P (L - x), the series converging as the modes are added.
        let (length, ei, load) = (0.5, 7e10 * 1e-10, 2.0);
        let beam = Structure::cantilever(length, 7e10, 1e-10, 0.27, 30, 0.01).unwrap();
        let tip = beam.point("tip", length).unwrap();
        let q: Vec<f64> = (0..30)
            .map(|i| tip[i] * load / beam.stiffness()[i * 30 + i])
            .collect();
        for (x, tolerance) in [(0.0, 2e-3), (0.1, 2e-2), (0.25, 2e-2)] {
            let row = beam.moment_row("moment", x).unwrap();
            let moment: f64 = row.iter().zip(&q).map(|(r, q)| r * q).sum();
            assert!(
                close(moment, load * (length - x), tolerance),
                "x {x}: {moment} vs {}",
                load * (length - x)
            );
        }
        // The root's curvature row is E I phi''(0) / L^2 = E I (2 b^2) / L^2.
        let root = beam.moment_row("moment", 0.0).unwrap();
        let b = 1.875104068711961;
        assert!(close(root[0], ei * 2.0 * b * b / (length * length), 1e-12));
        // Forced on its steady state (as the points above), the peak moment at
        // the root is |row . Q|.
        let (beam, q, mut s, start) = forced_beam();
        s.points = vec![length];
        s.moments = vec![0.0, 0.2];
        let sol = exact(&s, &start, 10.0 / 8.0, recorded());
        let r = &sol.reductions;
        assert_eq!(r.peaks.len(), 3 + 1 + 2);
        for (j, x) in [0.0, 0.2].into_iter().enumerate() {
            let amplitude = amplitude_of(&beam.moment_row("moment", x).unwrap(), &q);
            assert!(
                close(r.peaks[4 + j], amplitude, 1e-9),
                "x {x}: {} vs {amplitude}",
                r.peaks[4 + j]
            );
        }
        // Only a cantilever bends.
        let mut s = spec(Structure::oscillator(1.0, 1.0, 0.0).unwrap());
        s.moments = vec![0.0];
        let err = Assembly::new(&s).unwrap_err().to_string();
        assert!(
            err.contains("[output] moments[0]: only a cantilever has bending moments"),
            "{err}"
        );
    });
}
