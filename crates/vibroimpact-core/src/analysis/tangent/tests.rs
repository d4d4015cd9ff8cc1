//! The tangent flow against central differences of whole runs and against
//! the identities an impacting flow satisfies exactly.

use super::lyapunov::orthonormalise;
use super::*;
use crate::kernel::events::RunOptions;
use crate::methods::registry::{AnyStepper, Options};
use crate::model::assembly::{initial_state, Damper, Excitation, Load, PairLaw, SystemSpec};
use crate::model::signals::Signal;
use crate::model::structure::Structure;

const RESTITUTION: f64 = 0.6;
const DAMPING: f64 = 2.0;
const MASS: f64 = 1.0;

/// A forced damped oscillator carrying a rigid impact damper.
fn damper_system() -> Assembly {
    forced_damper(60.0, 8.0)
}

/// The damper's system forced at `frequency` (Hz) with `amplitude` (N).
fn forced_damper(frequency: f64, amplitude: f64) -> Assembly {
    forced_with(frequency, amplitude, PairLaw::rigid(RESTITUTION).unwrap())
}

/// The damper's system with its pair's `law`.
fn forced_with(frequency: f64, amplitude: f64, law: PairLaw) -> Assembly {
    let signal = Signal::harmonic(frequency, amplitude, 0.0).unwrap();
    damper_on_oscillator((3000.0, 0.05, 0.01), law, 0.0, signal)
}

/// An oscillator (1 kg, 2 N s/m, its `stiffness`) driven by `signal` (N) and
/// carrying a damper (`damper_mass`, `clearance` to each wall) of pair
/// `law`, under `gravity` (m/s^2).
pub(super) fn damper_on_oscillator(
    (stiffness, damper_mass, clearance): (f64, f64, f64),
    law: PairLaw,
    gravity: f64,
    signal: Signal,
) -> Assembly {
    let spec = SystemSpec {
        structure: Structure::oscillator(MASS, stiffness, DAMPING).unwrap(),
        dampers: vec![Damper {
            mass: damper_mass,
            at: 0.0,
            lower_clearance: clearance,
            upper_clearance: clearance,
            law,
        }],
        collisions: vec![],
        frictions: vec![],
        stops: vec![],
        gravity,
        excitations: vec![Excitation {
            load: Load::Force { at: 0.0 },
            signal,
        }],
        points: vec![],
        moments: vec![],
    };
    Assembly::new(&spec).unwrap()
}

pub(super) fn options(t_end: f64, dt: Option<f64>) -> RunOptions {
    RunOptions {
        dt,
        t_end,
        every: 1,
        keep_history: false,
        max_steps: 100_000_000,
        max_rows: 1_000_000,
        energy_tolerance: 1e-6,
        reduce: Default::default(),
    }
}

/// The end state (`x` then `v`) and the tangent flow of a run to `t_end`.
fn run(system: &Assembly, y0: &[f64], t_end: f64) -> (Vec<f64>, Vec<f64>, u64) {
    run_with(system, y0, t_end, "exact")
}

/// [`run`] by `method` (an adaptive one at rtol 1e-12).
pub(super) fn run_with(
    system: &Assembly,
    y0: &[f64],
    t_end: f64,
    method: &str,
) -> (Vec<f64>, Vec<f64>, u64) {
    let tight = Options {
        rtol: 1e-12,
        atol: 1e-15,
        ..Options::default()
    };
    let mut stepper = AnyStepper::new(system, method, &tight).unwrap();
    let dt = match method {
        "rk4" => Some(2e-7),
        _ => stepper.step(None, t_end, f64::INFINITY),
    };
    observed(system, &mut stepper, y0, t_end, dt)
}

/// [`run`] by the fixed-step `method` in steps of `dt` s.
fn run_fixed(
    system: &Assembly,
    y0: &[f64],
    t_end: f64,
    method: &str,
    dt: f64,
) -> (Vec<f64>, Vec<f64>, u64) {
    let mut stepper = AnyStepper::new(system, method, &Options::default()).unwrap();
    observed(system, &mut stepper, y0, t_end, Some(dt))
}

/// The end state, the tangent flow and the impacts of a run by `stepper`.
fn observed(
    system: &Assembly,
    stepper: &mut AnyStepper,
    y0: &[f64],
    t_end: f64,
    dt: Option<f64>,
) -> (Vec<f64>, Vec<f64>, u64) {
    let mut flow = Tangent::product(system).unwrap();
    let solution = stepper
        .integrate_observed(system, y0, &options(t_end, dt), &mut || false, &mut flow)
        .unwrap();
    let size = 2 * system.dim;
    assert!(flow.grazings().is_empty());
    (
        solution.final_state[..size].to_vec(),
        flow.matrix().to_vec(),
        flow.impacts(),
    )
}

fn start(system: &Assembly) -> Vec<f64> {
    initial_state(system, &[0.004], &[-0.2], &[0.002], &[0.3]).unwrap()
}

pub(super) fn determinant(a: &[f64], n: usize) -> f64 {
    let mut a = a.to_vec();
    let mut det = 1.0;
    for c in 0..n {
        let p = (c..n)
            .max_by(|&i, &j| a[i * n + c].abs().total_cmp(&a[j * n + c].abs()))
            .unwrap();
        if p != c {
            for k in 0..n {
                a.swap(c * n + k, p * n + k);
            }
            det = -det;
        }
        det *= a[c * n + c];
        for r in c + 1..n {
            let f = a[r * n + c] / a[c * n + c];
            for k in c..n {
                a[r * n + k] -= f * a[c * n + k];
            }
        }
    }
    det
}

#[test]
fn the_tangent_map_is_the_runs_central_differences() {
    crate::testing::timeout(60, || {
        for method in ["exact", "dop853"] {
            central_differences_of(method);
        }
    });
}

/// The tangent map of a run by `method` against the central differences of
/// its end states.
fn central_differences_of(method: &str) {
    {
        let system = damper_system();
        let y0 = start(&system);
        let t_end = 0.4;
        let (_, _, impacts) = run_with(&system, &y0, t_end, method);
        assert!(impacts >= 6, "{impacts} impacts");
        let worst = worst_difference(&system, t_end, method, 1e-7);
        assert!(worst < 1e-5, "{method}: worst scaled difference {worst:e}");
    }
}

/// The largest difference between the tangent map of a run of `system` by
/// `method` to `t_end` and the central differences of its end states (steps
/// of `step` times each coordinate's scale), scaled as the coordinates are.
fn worst_difference(system: &Assembly, t_end: f64, method: &str, step: f64) -> f64 {
    let scales = [1e-3, 1e-3, 0.1, 0.1];
    worst_difference_from(system, (&start(system), &scales), t_end, method, step)
}

/// [`worst_difference`] from `y0`, with each coordinate's scale.
pub(super) fn worst_difference_from(
    system: &Assembly,
    (y0, scales): (&[f64], &[f64]),
    t_end: f64,
    method: &str,
    step: f64,
) -> f64 {
    let (_, tangent, _) = run_with(system, y0, t_end, method);
    let size = 2 * system.dim;
    let mut worst = 0.0f64;
    for c in 0..size {
        let h = step * scales[c];
        let mut plus = y0.to_vec();
        plus[c] += h;
        let mut minus = y0.to_vec();
        minus[c] -= h;
        let (p, _, _) = run_with(system, &plus, t_end, method);
        let (m, _, _) = run_with(system, &minus, t_end, method);
        for r in 0..size {
            let difference = (p[r] - m[r]) / (2.0 * h);
            let exact = tangent[r * size + c];
            // Scaled as the state's coordinates are.
            let error = (difference - exact).abs() * scales[c] / scales[r];
            worst = worst.max(error / (1.0 + exact.abs() * scales[c] / scales[r]));
        }
    }
    worst
}

/// The forced damper with a compliant pair: Hertz (its force and slope zero
/// at the onset: no saltation) and a linear spring with a contact damper
/// of `CONTACT_DAMPING` N s/m (its force jumps by `c g'` at the onset and
/// the separation: saltations).
fn compliant_dampers() -> Vec<(&'static str, Assembly)> {
    use crate::model::contact::{Contact, LawKind};
    [
        ("hertz", LawKind::Hertz, 1e9, 0.0),
        ("linear", LawKind::Linear, 2e6, CONTACT_DAMPING),
        ("hyster-hertz", LawKind::HysterHertz, 1e9, 0.0),
        ("hertz-damped", LawKind::HertzDamped, 1e9, 0.0),
    ]
    .into_iter()
    .map(|(name, law, stiffness, damping)| {
        let restitution = law.uses_restitution().then_some(0.7);
        let contact = Contact::new(law, stiffness, restitution, damping).unwrap();
        (name, forced_with(60.0, 8.0, PairLaw::Compliant(contact)))
    })
    .collect()
}

const CONTACT_DAMPING: f64 = 40.0;

/// The largest difference between two tangent maps of the damper, scaled
/// as the state's coordinates are.
fn scaled_difference(a: &[f64], b: &[f64]) -> f64 {
    let scales = [1e-3, 1e-3, 0.1, 0.1];
    let mut worst = 0.0f64;
    for r in 0..4 {
        for c in 0..4 {
            let (x, y) = (a[r * 4 + c], b[r * 4 + c]);
            let scale = scales[c] / scales[r];
            worst = worst.max((x - y).abs() * scale / (1.0 + x.abs() * scale));
        }
    }
    worst
}

#[test]
fn through_compliant_contacts_the_tangent_map_is_the_runs_central_differences() {
    crate::testing::timeout(120, || {
        // Over the first contacts (the flow expands fast: over 0.3 s the
        // differences' own noise is 1e-4).
        let t_end = 0.06;
        for (name, system) in compliant_dampers() {
            let worst = worst_difference(&system, t_end, "dop853", 1e-5);
            assert!(worst < 1e-6, "{name}: dop853 against differences {worst:e}");
            // Every method's trajectory carries the same tangent flow: the
            // explicit ones' to 1e-7 (a uniform RK4 along a Hertz contact,
            // whose slope grows as the square root of the indentation, had
            // been 3e-4 off); the implicit generalized-alpha's converges at
            // second order with its step.
            let y0 = start(&system);
            let (_, reference, _) = run_with(&system, &y0, t_end, "dop853");
            for method in ["rk4", "dopri5"] {
                let (_, tangent, _) = run_with(&system, &y0, t_end, method);
                let off = scaled_difference(&reference, &tangent);
                assert!(off < 5e-7, "{name} {method}: {off:e} from dop853's");
            }
            let off = |dt: f64| {
                let (_, tangent, _) = run_fixed(&system, &y0, t_end, "generalized-alpha", dt);
                scaled_difference(&reference, &tangent)
            };
            let (coarse, fine) = (off(2e-7), off(5e-8));
            assert!(
                fine < 1e-4 && coarse > 10.0 * fine,
                "{name}: {coarse:e} then {fine:e}"
            );
        }
    });
}

#[test]
fn through_compliant_contacts_phase_volume_follows_the_trace_of_the_flow() {
    crate::testing::timeout(60, || {
        // Liouville: det Phi = exp(integral of trace J). The structure's
        // damper takes -c / M throughout, a contact damper -c_k h M^-1 h^T
        // while in contact; a saltation's determinant is (grad g . f+) /
        // (grad g . f-), 1 where the gap's rate is continuous: the onset and
        // the separation of a compliant contact.
        let t_end = 0.3;
        for (name, system) in compliant_dampers().into_iter().take(2) {
            let y0 = start(&system);
            let tight = Options {
                rtol: 1e-12,
                atol: 1e-15,
                ..Options::default()
            };
            let mut stepper = AnyStepper::new(&system, "dop853", &tight).unwrap();
            // The product's determinant loses to its conditioning (1e-6 over
            // 13 contacts): the QR's logarithms keep it.
            let mut flow = Tangent::orthonormal(&system).unwrap();
            let solution = stepper
                .integrate_observed(
                    &system,
                    &y0,
                    &options(t_end, None),
                    &mut || false,
                    &mut flow,
                )
                .unwrap();
            let in_contact: f64 = solution.contacts.iter().map(|c| c.duration).sum();
            assert!(
                solution.contacts.len() >= 4,
                "{name}: {} contacts",
                solution.contacts.len()
            );
            let contact_damping = if name == "linear" {
                CONTACT_DAMPING
            } else {
                0.0
            };
            let inverse_mass = system.interactions()[0].inverse_mass;
            let expected = -DAMPING / MASS * t_end - contact_damping * inverse_mass * in_contact;
            let sum: f64 = flow.logs().iter().sum();
            assert!(
                (sum - expected).abs() < 1e-9 * expected.abs(),
                "{name}: log det {sum} against {expected}"
            );
        }
    });
}

#[test]
fn each_impact_multiplies_phase_volume_by_the_square_of_its_restitution() {
    crate::testing::timeout(60, || {
        // Liouville between impacts (volume shrinks as exp(trace A t), trace
        // A = -c / M: the damper flies freely) and e^2 at each impact.
        // Forced near resonance, the damper rattles without sticking.
        let system = forced_damper(9.0, 40.0);
        let y0 = start(&system);
        for t_end in [0.1, 0.3] {
            let (_, tangent, impacts) = run(&system, &y0, t_end);
            let det = determinant(&tangent, 2 * system.dim);
            let expected = RESTITUTION.powi(2 * impacts as i32) * (-DAMPING / MASS * t_end).exp();
            assert!(
                ((det - expected) / expected).abs() < 1e-10,
                "t_end {t_end}: det {det:e} against {expected:e} ({impacts} impacts)"
            );
        }
        // Over many impacts the product is ill-conditioned; its QR's
        // logarithms sum to log |det| to round-off.
        let t_end = 20.0;
        let mut stepper = AnyStepper::new(&system, "exact", &Options::default()).unwrap();
        let dt = stepper.step(None, t_end, f64::INFINITY);
        let mut flow = Tangent::orthonormal(&system).unwrap();
        stepper
            .integrate_observed(&system, &y0, &options(t_end, dt), &mut || false, &mut flow)
            .unwrap();
        let impacts = flow.impacts() as f64;
        assert!(impacts > 30.0, "{impacts} impacts");
        let sum: f64 = flow.logs().iter().sum();
        let expected = 2.0 * impacts * RESTITUTION.ln() - DAMPING / MASS * t_end;
        assert!(
            ((sum - expected) / expected).abs() < 1e-11,
            "sum of logarithms {sum} against {expected}"
        );
    });
}

#[test]
fn orthonormalising_keeps_the_stretches_logarithms() {
    crate::testing::timeout(10, || {
        // An upper-triangular matrix's QR has its diagonal as R (up to signs).
        let a = [2.0, 1.0, 3.0, 0.0, 0.5, -1.0, 0.0, 0.0, 0.25];
        let mut q = a.to_vec();
        let mut logs = vec![0.0; 3];
        orthonormalise(&mut q, 3, &mut logs, &mut []);
        for (l, d) in logs.iter().zip([2.0f64, 0.5, 0.25]) {
            assert!((l - d.ln()).abs() < 1e-14, "{l} against {}", d.ln());
        }
        for i in 0..3 {
            for j in 0..3 {
                let dot: f64 = (0..3).map(|k| q[k * 3 + i] * q[k * 3 + j]).sum();
                let expected = if i == j { 1.0 } else { 0.0 };
                assert!((dot - expected).abs() < 1e-14);
            }
        }
    });
}

/// The Lyapunov exponents of damped oscillators driven by a force and never
/// touching anything: each pair of exponents is its oscillator's `-c / (2 m)`
/// (closed form; 1 kg: -4/s at 8 N s/m beside 100 N/m, -15/s at 30 N s/m
/// beside 400 N/m), over 1000 s of one smooth stretch (no event to
/// re-orthonormalise at); within the finite time's `ln(cond) / T` (the
/// eigenvectors' condition, about 100), and their sum `trace(A)` (Liouville)
/// to round-off.
#[test]
fn a_long_stretch_without_events_keeps_every_exponent() {
    crate::testing::timeout(20, || {
        let rows = |a: f64, b: f64| vec![vec![a, 0.0], vec![0.0, b]];
        let pair = Structure::matrices(&rows(1.0, 1.0), &rows(100.0, 400.0), &rows(8.0, 30.0));
        for (structure, expected) in [
            (
                Structure::oscillator(1.0, 100.0, 8.0).unwrap(),
                vec![-4.0; 2],
            ),
            (pair.unwrap(), vec![-4.0, -4.0, -15.0, -15.0]),
        ] {
            let spec = SystemSpec {
                excitations: vec![Excitation {
                    load: Load::Force { at: 0.0 },
                    signal: Signal::harmonic(1.0, 1.0, 0.0).unwrap(),
                }],
                ..SystemSpec::of(structure, vec![])
            };
            let system = Assembly::new(&spec).unwrap();
            let y0 = initial_state(&system, &[], &[], &[], &[]).unwrap();
            let t_end = 1000.0;
            let mut stepper = AnyStepper::new(&system, "exact", &Options::default()).unwrap();
            let dt = stepper.step(None, t_end, f64::INFINITY);
            let mut flow = Tangent::orthonormal(&system).unwrap();
            stepper
                .integrate_observed(&system, &y0, &options(t_end, dt), &mut || false, &mut flow)
                .unwrap();
            let mut exponents: Vec<f64> = flow.logs().iter().map(|l| l / t_end).collect();
            exponents.sort_by(|a, b| b.total_cmp(a));
            for (got, want) in exponents.iter().zip(&expected) {
                assert!(
                    (got - want).abs() < 0.01,
                    "{exponents:?} against {expected:?}"
                );
            }
            let (sum, trace) = (exponents.iter().sum::<f64>(), expected.iter().sum::<f64>());
            assert!(
                (sum - trace).abs() < 1e-9 * trace.abs(),
                "{sum} against {trace}"
            );
        }
    });
}
