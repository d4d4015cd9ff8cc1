//! The up-front limits of a run, checked before its first step (SI units):
//! the steps it may take, the rows and memory its records may keep, and the
//! time scales its steps must resolve (the fastest natural mode against an
//! explicit fixed step or a mode-stepped method, a harmonic forcing against
//! the step). Each refusal is one line naming the field (as a scenario's
//! `[solver]`, `[output]` or `[[excitation]]` key) and what is allowed.

use super::table::{method, Kind, MethodSpec, Options, BETA, DT, T_END};
use crate::error::{Error, Result};
use crate::kernel::memory::MAX_RECORD_BYTES;
use crate::model::assembly::SystemSpec;
use crate::model::structure::Structure;

/// The most forcing periods one run of an analysis may settle and record in
/// all: with a few impacts and tens of steps a period is already minutes of
/// computing, and every kept impact is memory; more is a typo (1e12 for
/// 1e2), refused before it starts.
pub const MAX_PERIODS: u64 = 10_000_000;

/// What a run is asked to do, as far as its limits go.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RunPlan<'a> {
    pub method: &'a str,
    /// Step, s: required by the fixed-step methods, the cap of the exact
    /// flow's step, an adaptive method's first step.
    pub dt: Option<f64>,
    /// End time, s.
    pub t_end: f64,
    pub max_steps: u64,
    /// The history rows plus contacts the run may keep.
    pub max_rows: u64,
    /// Every `every`-th step kept in the history.
    pub every: u64,
    /// Whether the history is kept.
    pub history: bool,
    /// Stroboscopic sampling period, s (None: none).
    pub strobe_period: Option<f64>,
    /// The method's options: a Newmark step (`beta`, `gamma`) with `2 beta <
    /// gamma` is stable only below a step (see [`stable_steps_per_period`]).
    pub options: Options,
}

/// What the limits read of a system: its structure, its coordinates (the
/// structure's and one a damper) and the frequencies (Hz) of its harmonic
/// forcing, each with its excitation's index.
#[derive(Debug, Clone, PartialEq)]
pub struct RunScales<'a> {
    pub structure: &'a Structure,
    pub coordinates: usize,
    pub forcing: Vec<(usize, f64)>,
}

impl<'a> RunScales<'a> {
    /// The scales of `system`.
    pub fn of(system: &'a SystemSpec) -> Self {
        let mut forcing = Vec::new();
        for (index, excitation) in system.excitations.iter().enumerate() {
            let (_, frequencies) = excitation.signal.harmonic_frequencies();
            forcing.extend(
                frequencies
                    .unwrap_or_default()
                    .into_iter()
                    .map(|f| (index, f)),
            );
        }
        Self {
            structure: &system.structure,
            coordinates: system.structure.dofs() + system.dampers.len(),
            forcing,
        }
    }
}

/// Refuse a run of `system` that `plan` cannot complete within its limits,
/// before any step: the step count of a fixed step (or of the exact flow's
/// capped step) beyond `max_steps`, an explicit fixed step over the fastest
/// mode's period, a mode-stepped method through more than `max_steps` of its
/// periods, a harmonic forcing sampled below two steps a period (or, for the
/// exact flow, through more than `max_steps` periods), a history or a strobe
/// record beyond `max_rows` or the records' memory.
pub fn check_run(system: &SystemSpec, plan: &RunPlan) -> Result<()> {
    check_scales(&RunScales::of(system), plan)
}

/// The checks of [`check_run`] that a study's point can fail where its
/// base system passed, its values changing the system but not the run's
/// settings: an explicit step over the fastest mode, a harmonic sampled
/// below two steps a period by the `method`'s fixed step `dt` (s).
pub fn check_steps_resolve(
    system: &SystemSpec,
    method_name: &str,
    dt: Option<f64>,
    options: Options,
) -> Result<()> {
    let spec = method(method_name)?;
    // No end, no rows: the run's settings, the study's own, were checked once.
    let plan = RunPlan {
        method: method_name,
        dt,
        t_end: 0.0,
        max_steps: u64::MAX,
        max_rows: u64::MAX,
        every: 1,
        history: false,
        strobe_period: None,
        options,
    };
    let scales = RunScales::of(system);
    check_natural_period(spec, &plan, scales.structure, None)?;
    check_forcing_steps(spec, &plan, &scales.forcing)
}

/// Refuse a fixed step `dt` (s) longer than the run, `t_end` (s): its one
/// step would end past `t_end` (or be cut to it), a run no fixed-step
/// method is meant for. `field` names the step in the message (the
/// scenario's `[solver] dt:`, or `dt`), `method` the method.
pub fn check_step_within(dt: f64, t_end: f64, method: &str, field: &str) -> Result<()> {
    if dt > t_end {
        return Err(Error::Inconsistent(format!(
            "{field} must be at most t_end ({} s) for the fixed-step method '{method}', got {}",
            python_repr(t_end),
            python_repr(dt)
        )));
    }
    Ok(())
}

/// [`check_run`] on what it reads of the system.
pub fn check_scales(system: &RunScales, plan: &RunPlan) -> Result<()> {
    let spec = method(plan.method)?;
    plan.options.checked()?;
    if let Some(dt) = plan.dt {
        DT.check(dt)?;
    }
    T_END.check(plan.t_end)?;
    if let Some(period) = plan.strobe_period.filter(|p| !(p.is_finite() && *p > 0.0)) {
        return Err(Error::Inconsistent(format!(
            "[output] strobe_period: must be finite and > 0 s, got {}",
            python_repr(period)
        )));
    }
    let fixed = spec.kind.is_fixed_step();
    if fixed && plan.dt.is_none() {
        return Err(Error::Inconsistent(format!(
            "[solver] dt: is required for method '{}' (a step in s > 0)",
            spec.name
        )));
    }
    if let Some(dt) = plan.dt.filter(|_| fixed) {
        check_step_within(dt, plan.t_end, spec.name, "[solver] dt:")?;
    }
    // The exact flow steps at most dt where one is given: as many steps.
    let step = plan.dt.filter(|_| fixed || spec.kind == Kind::Exact);
    if let Some(dt) = step {
        let steps = plan.t_end / dt;
        if steps > plan.max_steps as f64 {
            return Err(Error::Inconsistent(format!(
                "[solver] t_end / dt = {} steps exceeds max_steps ({}): raise dt or max_steps, or \
                 shorten t_end",
                python_e3(steps),
                plan.max_steps
            )));
        }
    }
    let top = check_finite_modes(system.structure)?;
    check_natural_period(spec, plan, system.structure, top)?;
    // After the natural period's check: a mode too fast for the run's steps
    // (a mass of 1e-300 kg) is said as such, with its advice.
    check_damping_rate(system.structure)?;
    check_forcing_steps(spec, plan, &system.forcing)?;
    let width = 1 + 2 * system.coordinates;
    if let Some(dt) = step.filter(|_| plan.history) {
        check_history(
            plan,
            plan.t_end / dt / plan.every.max(1) as f64 + 2.0,
            width,
        )?;
    }
    if let Some(period) = plan.strobe_period {
        let strobes = plan.t_end / period;
        if strobes > plan.max_rows as f64 || strobes * (width * 8) as f64 > MAX_RECORD_BYTES as f64
        {
            return Err(Error::Inconsistent(format!(
                "[output] strobe_period: t_end / strobe_period = {} rows of {width} values, more \
                 than max_rows = {} or the {} MiB a run's records may take: lengthen \
                 strobe_period or shorten t_end",
                python_e3(strobes),
                plan.max_rows,
                MAX_RECORD_BYTES >> 20
            )));
        }
    }
    Ok(())
}

/// A fixed-step history of `rows` rows of `width` values is known before the
/// run: refused up front rather than stopped at the cap.
fn check_history(plan: &RunPlan, rows: f64, width: usize) -> Result<()> {
    if rows > plan.max_rows as f64 {
        return Err(Error::Inconsistent(format!(
            "[solver] the history would keep {} rows (t_end / dt / every), more than max_rows = \
             {}: raise every, set history = false, shorten t_end or raise max_rows",
            python_e3(rows),
            plan.max_rows
        )));
    }
    let bytes = rows * (width * 8) as f64;
    if bytes > MAX_RECORD_BYTES as f64 {
        return Err(Error::Inconsistent(format!(
            "[output] history: the history would keep {} rows of {width} values, {:.0} MiB, more \
             than the {} MiB a run's records may take: raise every, set history = false or \
             shorten t_end",
            python_e3(rows),
            bytes / (1u64 << 20) as f64,
            MAX_RECORD_BYTES >> 20
        )));
    }
    Ok(())
}

/// An upper bound (Hz) of the structure's highest natural frequency without
/// its eigenvalues: w^2 is at most K's largest absolute row sum over the
/// lower end of M's smallest Gershgorin disc (infinite where that end is not
/// above 0); 0 where K is zero.
fn frequency_bound(structure: &Structure) -> f64 {
    let n = structure.dofs();
    let (mass, stiffness) = (structure.mass(), structure.stiffness());
    let row_sum = |m: &[f64], r: usize| m[r * n..(r + 1) * n].iter().map(|v| v.abs()).sum::<f64>();
    let top = (0..n).map(|r| row_sum(stiffness, r)).fold(0.0, f64::max);
    if top.is_nan() || top <= 0.0 {
        return 0.0;
    }
    let lowest = (0..n)
        .map(|r| 2.0 * mass[r * n + r] - row_sum(mass, r))
        .fold(f64::INFINITY, f64::min);
    if lowest > 0.0 {
        (top / lowest).sqrt() / std::f64::consts::TAU
    } else {
        f64::INFINITY
    }
}

/// Refuse a structure whose natural frequencies overflow a double (its
/// stiffness over its mass beyond 1.8e308 s^-2): every method's run of it is
/// meaningless (the exact flow's phase, an adaptive step of no length), and
/// the checks against its fastest mode would read it as a free body. The
/// eigenvalues only where the bound is not finite: then the highest natural
/// frequency (Hz) they give, for [`check_natural_period`] to reuse.
fn check_finite_modes(structure: &Structure) -> Result<Option<f64>> {
    if frequency_bound(structure).is_finite() {
        return Ok(None);
    }
    let top = top_angular_frequency(structure);
    if top.is_finite() {
        return Ok(Some(top / std::f64::consts::TAU));
    }
    Err(Error::Inconsistent(
        "[structure]: its natural frequencies overflow a double (stiffness / mass beyond \
         1.8e308 s^-2); check mass and stiffness, or write them in other units"
            .into(),
    ))
}

/// The most a coordinate's damping may be over its mass, `c / m` (1/s): its
/// square, which the modes' and the flow's eigenvalues take, stays a double.
/// A damping of 1e308 N s/m on 1 kg had been refused as "dt must be finite
/// and > 0 s, or left out, got 0" (the exact flow's step underflowed).
const MAX_DAMPING_RATE: f64 = 1e150;

/// Refuse a structure whose damping over its mass (a diagonal term's
/// `|c_ii| / m_ii`) is beyond [`MAX_DAMPING_RATE`].
fn check_damping_rate(structure: &Structure) -> Result<()> {
    let n = structure.dofs();
    let (mass, damping) = (structure.mass(), structure.damping());
    let rate = (0..n)
        .map(|r| damping[r * n + r].abs() / mass[r * n + r])
        .fold(0.0f64, f64::max);
    if rate <= MAX_DAMPING_RATE {
        return Ok(());
    }
    Err(Error::Inconsistent(format!(
        "[structure] damping: its damping over its mass, {rate:.3e} 1/s, is beyond \
         {MAX_DAMPING_RATE:e} 1/s (a decay time no double resolves); check damping and \
         mass, or write them in other units"
    )))
}

/// The largest of the structure's natural angular frequencies (rad/s; 0 for
/// none; infinite or NaN where they overflow a double).
fn top_angular_frequency(structure: &Structure) -> f64 {
    structure
        .natural_frequencies()
        .into_iter()
        .fold(0.0f64, f64::max)
}

/// The structure's highest natural frequency (Hz; 0 for none).
pub(super) fn highest_frequency(structure: &Structure) -> f64 {
    let top = top_angular_frequency(structure);
    if top.is_finite() {
        top / std::f64::consts::TAU
    } else {
        0.0
    }
}

/// The fewest steps of an explicit method (RK4) in an undamped mode's period
/// where it is stable: `omega dt <= 2 sqrt(2)`, RK4's reach along the
/// imaginary axis, is a period of `pi / sqrt(2)` (2.22) steps. (A period of
/// 1.5 steps had run, grown by 1e63 and stopped on the energy check.)
const EXPLICIT_STEPS_PER_PERIOD: f64 = std::f64::consts::PI / std::f64::consts::SQRT_2;

/// The error of a fixed step `dt` (s) over `steps` of the fastest mode's
/// `period` (s; of `frequency`, Hz), where `spec`'s method is unstable.
fn unstable_step(
    spec: &MethodSpec,
    options: &Options,
    (period, frequency): (f64, f64),
    steps: f64,
    dt: f64,
) -> Error {
    if spec.kind == Kind::Explicit {
        return Error::Inconsistent(format!(
            "[solver] dt: the fastest mode's period, {} s ({} Hz), is below 2.22 steps of dt = \
             {} s (pi / sqrt(2)), where {} is unstable: reduce dt to about {} s (20 steps a \
             period; at the stability limit itself the run is stable but not accurate), use an \
             implicit method (newmark-implicit, generalized-alpha), or check mass and stiffness",
            python_g3(period),
            python_g3(frequency),
            python_repr(dt),
            spec.name,
            python_g3(period / 20.0)
        ));
    }
    Error::Inconsistent(format!(
        "[solver] dt: {} with beta = {} < gamma / 2 (gamma = {}) is stable only where \
         2 pi f dt <= 1 / sqrt(gamma / 2 - beta) = {}, and the fastest mode ({} Hz) gives {}: \
         reduce dt below {} s, or set beta >= gamma / 2 (beta = 0.25, gamma = 0.5: stable on \
         any mode)",
        spec.name,
        python_repr(options.beta),
        python_repr(options.gamma),
        python_g3(std::f64::consts::TAU / steps),
        python_g3(frequency),
        python_g3(std::f64::consts::TAU * frequency * dt),
        python_g3(period / steps)
    ))
}

/// The fewest steps a mode-stepped method takes in a period of the fastest
/// natural mode: the exact flow an eighth of it at most (its cubic event
/// search's step), an adaptive method at least one.
fn steps_per_period(spec: &MethodSpec) -> f64 {
    if spec.kind == Kind::Exact {
        8.0
    } else {
        1.0
    }
}

/// The fewest fixed steps in an undamped mode's period at which `spec`'s
/// method with `options` is stable, None where it is on any mode: an
/// explicit one's [`EXPLICIT_STEPS_PER_PERIOD`], and a Newmark step (the
/// methods reading `beta`) with `2 beta < gamma`, stable where `omega dt <=
/// 1 / sqrt(gamma / 2 - beta)` (Hughes, The Finite Element Method, 9.1.2:
/// beta = 0, gamma = 1/2, central differences, at `omega dt <= 2`).
fn stable_steps_per_period(spec: &MethodSpec, options: &Options) -> Option<f64> {
    if spec.kind == Kind::Explicit {
        return Some(EXPLICIT_STEPS_PER_PERIOD);
    }
    let newmark = spec.options.iter().any(|o| o.name == BETA.name);
    let margin = 0.5 * options.gamma - options.beta;
    (newmark && margin > 0.0).then(|| std::f64::consts::TAU * margin.sqrt())
}

/// Whether a run of `spec` and `plan` resolves a fastest mode of `frequency`.
fn resolves(spec: &MethodSpec, plan: &RunPlan, frequency: f64) -> bool {
    let stable = stable_steps_per_period(spec, &plan.options);
    if stable.is_some_and(|steps| frequency * steps * plan.dt.unwrap_or(0.0) > 1.0) {
        return false;
    }
    let steps = plan.t_end * frequency * steps_per_period(spec);
    !(spec.kind.is_mode_stepped() && steps > plan.max_steps as f64)
}

/// Refuse a run that cannot resolve the structure's fastest mode: a fixed
/// step is unstable on a mode whose period is shorter than its
/// [`stable_steps_per_period`] (an explicit method's, a Newmark step's with
/// `2 beta < gamma`); an adaptive method or the exact flow steps at least
/// once in each period of that mode. The eigenvalues only where the bound
/// does not settle it (they had cost a dropped ball's run a quarter of its
/// time), and once: `known` is the highest frequency (Hz) where already
/// computed.
fn check_natural_period(
    spec: &MethodSpec,
    plan: &RunPlan,
    structure: &Structure,
    known: Option<f64>,
) -> Result<()> {
    let stable = stable_steps_per_period(spec, &plan.options);
    if stable.is_none() && !spec.kind.is_mode_stepped() {
        return Ok(());
    }
    if resolves(spec, plan, frequency_bound(structure)) {
        return Ok(());
    }
    let frequency = known.unwrap_or_else(|| highest_frequency(structure));
    if frequency.is_nan() || frequency <= 0.0 {
        return Ok(());
    }
    let period = 1.0 / frequency;
    let unstable = stable
        .zip(plan.dt)
        .filter(|(steps, dt)| period < steps * dt);
    if let Some((steps, dt)) = unstable {
        return Err(unstable_step(
            spec,
            &plan.options,
            (period, frequency),
            steps,
            dt,
        ));
    }
    let (periods, per_period) = (plan.t_end * frequency, steps_per_period(spec));
    if spec.kind.is_mode_stepped() && periods * per_period > plan.max_steps as f64 {
        return Err(Error::Inconsistent(format!(
            "[solver] t_end = {} s spans {} periods of the fastest mode ({} Hz), and {} steps at \
             least {} in each: more than max_steps ({}); shorten t_end below {} s, raise \
             max_steps, or check mass and stiffness",
            python_repr(plan.t_end),
            python_g3(periods),
            python_g3(frequency),
            spec.name,
            times(per_period),
            plan.max_steps,
            python_g3(plan.max_steps as f64 / (frequency * per_period))
        )));
    }
    Ok(())
}

/// Refuse a harmonic forcing the run's steps cannot follow: a fixed step
/// samples it below two steps a period (its result aliased), and the exact
/// flow steps at least once in each of its periods.
fn check_forcing_steps(spec: &MethodSpec, plan: &RunPlan, forcing: &[(usize, f64)]) -> Result<()> {
    for &(index, frequency) in forcing {
        let fixed_dt = plan.dt.filter(|_| spec.kind.is_fixed_step());
        if let Some(dt) = fixed_dt.filter(|dt| frequency * 2.0 * dt > 1.0) {
            return Err(Error::Inconsistent(format!(
                "[[excitation]] {index}: frequency {} Hz is sampled below two steps of dt = {} s \
                 a period: give at most {} Hz, or reduce dt below {} s",
                python_repr(frequency),
                python_repr(dt),
                python_g3(1.0 / (2.0 * dt)),
                python_g3(1.0 / (20.0 * frequency))
            )));
        }
        let periods = frequency * plan.t_end;
        if spec.kind == Kind::Exact && periods > plan.max_steps as f64 {
            return Err(Error::Inconsistent(format!(
                "[[excitation]] {index}: frequency {} Hz: t_end = {} s spans {} of its periods, \
                 and the exact flow steps at least once in each: more than max_steps ({}); give \
                 at most {} Hz or shorten t_end",
                python_repr(frequency),
                python_repr(plan.t_end),
                python_g3(periods),
                plan.max_steps,
                python_g3(plan.max_steps as f64 / plan.t_end)
            )));
        }
    }
    Ok(())
}

/// "once", or "8 times".
fn times(count: f64) -> String {
    if count == 1.0 {
        "once".to_string()
    } else {
        format!("{count} times")
    }
}

/// Rust's exponent (`1e8`, `1e-5`) as Python writes it (`1e+08`, `1e-05`),
/// so that a message reads the same from either language.
fn python_exponent(text: &str) -> String {
    match text.split_once('e') {
        Some((mantissa, exponent)) => {
            let value: i32 = exponent.parse().unwrap_or(0);
            let sign = if value < 0 { '-' } else { '+' };
            format!("{mantissa}e{sign}{:02}", value.abs())
        }
        None => text.to_string(),
    }
}

/// `x` as Python's `repr` writes a float (shortest round trip).
pub(crate) fn python_repr(x: f64) -> String {
    if x.is_nan() {
        return "nan".into();
    }
    if x.is_infinite() {
        return if x > 0.0 { "inf" } else { "-inf" }.into();
    }
    python_exponent(&format!("{x:?}"))
}

/// `x` as Python's `format(x, ".3e")` writes it.
pub(crate) fn python_e3(x: f64) -> String {
    if !x.is_finite() {
        return python_repr(x);
    }
    python_exponent(&format!("{x:.3e}"))
}

/// `x` as Python's `format(x, ".3g")` writes it: three significant digits,
/// fixed between 1e-4 and 1e3, trailing zeros dropped.
pub(crate) fn python_g3(x: f64) -> String {
    python_g(x, 3)
}

/// `x` as Python's `format(x, ".{digits}g")` writes it: `digits` significant
/// digits, fixed between 1e-4 and 10^digits, trailing zeros dropped.
pub(crate) fn python_g(x: f64, digits: usize) -> String {
    if !x.is_finite() {
        return python_repr(x);
    }
    if x == 0.0 {
        return "0".into();
    }
    let decimals = digits.max(1) - 1;
    let scientific = format!("{x:.decimals$e}");
    let (mantissa, exponent) = scientific.split_once('e').expect("an exponent");
    let exponent: i32 = exponent.parse().expect("an integer exponent");
    let trim = |s: &str| -> String {
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s.to_string()
        }
    };
    if (-4..digits as i32).contains(&exponent) {
        let decimals = (decimals as i32 - exponent) as usize;
        trim(&format!("{x:.decimals$}"))
    } else {
        let sign = if exponent < 0 { '-' } else { '+' };
        format!("{}e{sign}{:02}", trim(mantissa), exponent.abs())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `a a^T` of a pseudo-random `n x n` matrix `a` (entries in
    /// [-scale, scale]), plus `diagonal` on its diagonal.
    fn gram(next: &mut impl FnMut() -> f64, n: usize, scale: f64, diagonal: f64) -> Vec<Vec<f64>> {
        let a: Vec<f64> = (0..n * n).map(|_| scale * (2.0 * next() - 1.0)).collect();
        (0..n)
            .map(|i| {
                (0..n)
                    .map(|j| {
                        let dot: f64 = (0..n).map(|p| a[i * n + p] * a[j * n + p]).sum();
                        dot + if i == j {
                            diagonal * (0.1 + next())
                        } else {
                            0.0
                        }
                    })
                    .collect()
            })
            .collect()
    }

    /// check_natural_period skips the eigenvalues where the bound passes: a
    /// bound below the fastest mode would let an unresolvable run through.
    #[test]
    fn the_frequency_bound_is_never_below_the_fastest_mode() {
        crate::testing::timeout(20, || {
            let mut state = 7u64;
            let mut next = move || {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 53) as f64
            };
            let mut finite = 0;
            for n in [1, 2, 3, 5, 8] {
                for _ in 0..50 {
                    let scale = 0.05 + next();
                    let mass = gram(&mut next, n, scale, 2.0);
                    let spring = 1e3 * next();
                    let stiffness = gram(&mut next, n, spring, 0.0);
                    let damping = vec![vec![0.0; n]; n];
                    let structure = Structure::matrices(&mass, &stiffness, &damping).unwrap();
                    let (bound, exact) =
                        (frequency_bound(&structure), highest_frequency(&structure));
                    assert!(bound >= exact * (1.0 - 1e-12), "{n}: {bound} < {exact}");
                    finite += usize::from(bound.is_finite());
                }
            }
            assert!(finite > 100, "{finite}");
            // Exact for one coordinate, zero without a spring.
            let one = Structure::oscillator(2.0, 8.0, 0.0).unwrap();
            let expected = 2.0 / std::f64::consts::TAU;
            assert!((frequency_bound(&one) - expected).abs() <= 1e-15 * expected);
            let free = Structure::oscillator(2.0, 0.0, 0.0).unwrap();
            assert_eq!(frequency_bound(&free), 0.0);
        });
    }

    /// An oscillator of 1e-200 kg on 1e200 N/m (w^2 = 1e400 s^-2, past a
    /// double) ran: dop853 stopped as a "numerical blow-up" (exit 1), the
    /// exact flow returned its start after a second (exit 0).
    #[test]
    fn natural_frequencies_beyond_a_double_are_refused() {
        crate::testing::timeout(10, || {
            let overflowing = Structure::oscillator(1e-200, 1e200, 0.0).unwrap();
            let error = check_finite_modes(&overflowing).unwrap_err().to_string();
            assert!(error.contains("overflow a double"), "{error}");
            // Two coordinates, the overflow in the second mode only.
            let mass = [vec![1e-160, 0.0], vec![0.0, 1e-160]];
            let stiffness = [vec![1e-160, 0.0], vec![0.0, 1e160]];
            let damping = [vec![0.0; 2], vec![0.0; 2]];
            let matrices = Structure::matrices(&mass, &stiffness, &damping).unwrap();
            assert!(check_finite_modes(&matrices).is_err());
            let overdamped = Structure::oscillator(1.0, 3947.8, 1e308).unwrap();
            let error = check_damping_rate(&overdamped).unwrap_err().to_string();
            assert!(error.contains("[structure] damping"), "{error}");
            assert!(check_damping_rate(&Structure::oscillator(1.0, 1.0, 1e150).unwrap()).is_ok());
            // As large as a double holds: w = 1e150 rad/s, and a free body.
            for (m, k) in [(1e-150, 1e150), (1.0, 0.0), (1e-300, 1.0)] {
                let fine = Structure::oscillator(m, k, 0.0).unwrap();
                assert!(check_finite_modes(&fine).is_ok(), "{m} {k}");
            }
            // The bound settles a diagonal mass; a mass coupled past its
            // diagonal (Gershgorin's disc reaching 0) has its eigenvalues
            // computed, and their top frequency in Hz handed on to the
            // period check, so it computes them no second time.
            let diagonal = Structure::oscillator(1.0, 4.0 * std::f64::consts::PI.powi(2), 0.0);
            assert_eq!(check_finite_modes(&diagonal.unwrap()).unwrap(), None);
            let coupled = Structure::matrices(
                &[vec![1.0, 2.0], vec![2.0, 5.0]],
                &[vec![3.0, -1.0], vec![-1.0, 1.0]],
                &[vec![0.0; 2], vec![0.0; 2]],
            )
            .unwrap();
            let top = check_finite_modes(&coupled).unwrap().unwrap();
            assert_eq!(top, highest_frequency(&coupled));
        });
    }

    #[test]
    fn numbers_are_written_as_python_writes_them() {
        crate::testing::timeout(10, || {
            // Python's own outputs: repr(x), format(x, ".3e"), format(x, ".3g").
            for (x, repr) in [
                (1e-5, "1e-05"),
                (1e9, "1000000000.0"),
                (1e16, "1e+16"),
                (0.1, "0.1"),
                (2.0, "2.0"),
                (1.5e-7, "1.5e-07"),
                (-3e300, "-3e+300"),
            ] {
                assert_eq!(python_repr(x), repr);
            }
            for (x, e3) in [
                (1e8, "1.000e+08"),
                (3.0e-12, "3.000e-12"),
                (12345.0, "1.234e+04"),
            ] {
                assert_eq!(python_e3(x), e3);
            }
            for (x, g3) in [
                (2e9, "2e+09"),
                (0.00123456, "0.00123"),
                (123.456, "123"),
                (1234.5, "1.23e+03"),
                (0.5, "0.5"),
                (1.0, "1"),
                (9.999e-5, "0.0001"),
                (1e-5, "1e-05"),
                (0.0, "0"),
                (f64::INFINITY, "inf"),
            ] {
                assert_eq!(python_g3(x), g3, "{x}");
            }
            // format(x, ".6g").
            for (x, g6) in [
                (1e8, "1e+08"),
                (0.1, "0.1"),
                (123456.7, "123457"),
                (1234567.0, "1.23457e+06"),
                (3.33333333e-9, "3.33333e-09"),
                (0.000123456789, "0.000123457"),
            ] {
                assert_eq!(python_g(x, 6), g6, "{x}");
            }
        });
    }
}
