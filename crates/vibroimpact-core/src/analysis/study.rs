//! Studies: many runs of one system with some of its parameters varied, on
//! every core (rayon), each reduced to a few metrics instead of a history.
//!
//! A parameter is a dotted path into the scenario, parsed once
//! ([`Parameter::parse`]) and applied to a copy of the base system for each
//! run. Each run is independent of the others and of how they are shared out
//! among threads, so the results are the same bit for bit whatever the number
//! of threads. A run that fails (a blow-up, chattering, a bad combination of
//! values) is recorded with its reason and the others go on.

use rayon::prelude::*;

use crate::analysis::ensemble::{run_ensemble, EnsembleOptions, Member};
use crate::analysis::settling::{self, MAX_PERIOD};
use crate::error::{Error, Result};
use crate::kernel::events::{ContactKind, RunOptions, SystemSolution};
use crate::kernel::reductions::ReduceOptions;
use crate::legacy::settings::{ContactTiming, Method, Settings, Stepping};
use crate::methods::exact::ExactFlow;
use crate::methods::registry::AnyStepper;
use crate::model::assembly::{initial_state, resumed_state, Assembly, Load, PairLaw, SystemSpec};
use crate::model::contact::Contact;
use crate::model::impact_damper::{ImpactDamper, State};
use crate::model::signals::{RecipeKey, Signal};
use crate::{analysis::shooting, numerics::linalg};

/// Which entry of the scenario a study varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// The point a damper, stop or force acts at (a coordinate index, or m
    /// along a cantilever): the interaction's rows are made again.
    DamperAt(usize),
    StopAt(usize),
    ExcitationAt(usize),
    DamperMass(usize),
    DamperClearance(usize),
    DamperLowerClearance(usize),
    DamperUpperClearance(usize),
    DamperRestitution(usize),
    DamperStiffness(usize),
    DamperDamping(usize),
    StopGap(usize),
    StopRestitution(usize),
    StopStiffness(usize),
    StopDamping(usize),
    Gravity,
    ExcitationAmplitude(usize),
    ExcitationFrequency(usize),
    ExcitationPhase(usize),
    /// An input of a random signal's recipe: the signal is generated again.
    ExcitationRecipe(usize, RecipeKey),
    /// An input of the structure's recipe (the index into [`STRUCTURE_KEYS`]):
    /// the structure is made again.
    Structure(usize),
    /// One of the four arrays of `[initial]` (0 to 3, in their order) and
    /// its entry.
    Initial(usize, usize),
}

/// A parsed dotted path.
#[derive(Debug, Clone, PartialEq)]
pub struct Parameter {
    pub path: String,
    pub target: Target,
}

/// The paths a study can vary, for error messages.
pub const PATHS: &str = "structure.{mass, stiffness, damping} (kind \"oscillator\"), \
     structure.{length, youngs_modulus, second_moment, mass_per_length, damping_ratio} \
     (kind \"cantilever\"; none of kind \"matrices\"), damper.N.{at, mass, clearance, \
     lower_clearance, upper_clearance, restitution, stiffness, damping}, stop.N.{at, gap, \
     restitution, stiffness, damping}, gravity.acceleration, excitation.N.at (forces), \
     excitation.N.{amplitude, frequency, phase} (harmonic signals), excitation.N.{seed, intensity, cutoff_frequency, \
     duration} (white-noise and kanai-tajimi signals; also ground_frequency, ground_damping \
     for kanai-tajimi), initial.{structure_displacement, structure_velocity, \
     damper_displacement, damper_velocity}.I";

/// The keys of `[structure]` a study can vary (those of its kind).
pub const STRUCTURE_KEYS: [&str; 8] = [
    "mass",
    "stiffness",
    "damping",
    "length",
    "youngs_modulus",
    "second_moment",
    "mass_per_length",
    "damping_ratio",
];

const INITIAL: [&str; 4] = [
    "structure_displacement",
    "structure_velocity",
    "damper_displacement",
    "damper_velocity",
];

impl Parameter {
    /// Parse `path` against `spec` (indices must exist).
    pub fn parse(path: &str, spec: &SystemSpec) -> Result<Self> {
        let parts: Vec<&str> = path.split('.').collect();
        let bad = || {
            Error::Inconsistent(format!(
                "study axis {path:?}: not a path a study can vary; allowed: {PATHS}"
            ))
        };
        let index = |text: &str, count: usize, what: &str| -> Result<usize> {
            let i: usize = text.parse().map_err(|_| bad())?;
            if i < count {
                Ok(i)
            } else {
                Err(Error::Inconsistent(format!(
                    "study axis {path:?}: the scenario has {count} {what}"
                )))
            }
        };
        let target = match parts.as_slice() {
            ["damper", i, key] => {
                let i = index(i, spec.dampers.len(), "[[damper]]")?;
                match *key {
                    "at" => Target::DamperAt(i),
                    "mass" => Target::DamperMass(i),
                    "clearance" => Target::DamperClearance(i),
                    "lower_clearance" => Target::DamperLowerClearance(i),
                    "upper_clearance" => Target::DamperUpperClearance(i),
                    "restitution" => Target::DamperRestitution(i),
                    "stiffness" => Target::DamperStiffness(i),
                    "damping" => Target::DamperDamping(i),
                    _ => return Err(bad()),
                }
            }
            ["stop", i, key] => {
                let i = index(i, spec.stops.len(), "[[stop]]")?;
                match *key {
                    "at" => Target::StopAt(i),
                    "gap" => Target::StopGap(i),
                    "restitution" => Target::StopRestitution(i),
                    "stiffness" => Target::StopStiffness(i),
                    "damping" => Target::StopDamping(i),
                    _ => return Err(bad()),
                }
            }
            ["gravity", "acceleration"] => Target::Gravity,
            ["structure", key] => {
                let mut recipe = spec.structure.recipe();
                let kind = recipe.kind();
                if recipe.input(key).is_none() {
                    let allowed = match recipe.keys() {
                        "" => format!(
                            "a structure of kind \"{kind}\" has no inputs a study can vary \
                             (only kinds \"oscillator\" and \"cantilever\" do)"
                        ),
                        keys => format!("allowed for kind \"{kind}\": structure.{{{keys}}}"),
                    };
                    return Err(Error::Inconsistent(format!(
                        "study axis {path:?}: not a path a study can vary; {allowed}"
                    )));
                }
                let at = STRUCTURE_KEYS.iter().position(|k| k == key);
                Target::Structure(at.expect("every recipe input is listed"))
            }
            ["excitation", i, "at"] => {
                let i = index(i, spec.excitations.len(), "[[excitation]]")?;
                if !matches!(spec.excitations[i].load, Load::Force { .. }) {
                    return Err(Error::Inconsistent(format!(
                        "study axis {path:?}: excitation {i} is a base excitation, which acts \
                         at no point"
                    )));
                }
                Target::ExcitationAt(i)
            }
            ["excitation", i, key] => {
                let i = index(i, spec.excitations.len(), "[[excitation]]")?;
                let signal = &spec.excitations[i].signal;
                if let Some(recipe) = signal.recipe() {
                    let key = RecipeKey::parse(key, recipe).ok_or_else(|| {
                        Error::Inconsistent(format!(
                            "study axis {path:?}: not a path a study can vary; allowed for \
                             excitation {i} (a {} signal): excitation.{i}.{{{}}}",
                            recipe.name(),
                            recipe.keys()
                        ))
                    })?;
                    Target::ExcitationRecipe(i, key)
                } else if matches!(signal, Signal::Harmonic(_)) {
                    match *key {
                        "amplitude" => Target::ExcitationAmplitude(i),
                        "frequency" => Target::ExcitationFrequency(i),
                        "phase" => Target::ExcitationPhase(i),
                        _ => return Err(bad()),
                    }
                } else {
                    return Err(Error::Inconsistent(format!(
                        "study axis {path:?}: excitation {i} is neither a harmonic nor a random \
                         (white-noise, kanai-tajimi) signal; allowed: {PATHS}"
                    )));
                }
            }
            ["initial", array, i] => {
                let which = INITIAL.iter().position(|a| a == array).ok_or_else(bad)?;
                let size = if which < 2 {
                    spec.structure.dofs()
                } else {
                    spec.dampers.len()
                };
                Target::Initial(which, index(i, size, array)?)
            }
            _ => return Err(bad()),
        };
        Ok(Self {
            path: path.to_string(),
            target,
        })
    }

    /// Set this parameter to `value` in `spec` (or in `initial`). An input
    /// of the structure makes it again, an input of a random signal generates
    /// it again (the runs that vary neither pay nothing); an error names the
    /// input by its path.
    pub fn apply(
        &self,
        spec: &mut SystemSpec,
        initial: &mut [Vec<f64>; 4],
        value: f64,
    ) -> Result<()> {
        let law = |law: &mut PairLaw, key: &str| -> Result<()> {
            match (law, key) {
                (PairLaw::Rigid { restitution }, "restitution") => {
                    *restitution = value;
                    Ok(())
                }
                (PairLaw::Compliant(c), "stiffness") => {
                    *c = rebuilt(c, value, c.restitution, c.damping)?;
                    Ok(())
                }
                (PairLaw::Compliant(c), "damping") => {
                    *c = rebuilt(c, c.stiffness, c.restitution, value)?;
                    Ok(())
                }
                // The damped Hertz laws' restitution (the others have none).
                (PairLaw::Compliant(c), "restitution") if c.law.uses_restitution() => {
                    *c = rebuilt(c, c.stiffness, value, c.damping)?;
                    Ok(())
                }
                _ => Err(Error::Inconsistent(format!(
                    "study axis {:?}: the pair's law has no {key}",
                    self.path
                ))),
            }
        };
        match self.target {
            // The system checks the point (the run fails, naming it).
            Target::DamperAt(i) => spec.dampers[i].at = value,
            Target::StopAt(i) => spec.stops[i].at = value,
            Target::ExcitationAt(i) => {
                if let Load::Force { at } = &mut spec.excitations[i].load {
                    *at = value;
                }
            }
            Target::DamperMass(i) => spec.dampers[i].mass = value,
            Target::DamperClearance(i) => {
                // Checked here: the system would name the side it sets.
                if !(value.is_finite() && value >= 0.0) {
                    return Err(Error::Inconsistent(format!(
                        "{}: a clearance must be a finite number >= 0 m, got {value}",
                        self.path
                    )));
                }
                spec.dampers[i].lower_clearance = value;
                spec.dampers[i].upper_clearance = value;
            }
            Target::DamperLowerClearance(i) => spec.dampers[i].lower_clearance = value,
            Target::DamperUpperClearance(i) => spec.dampers[i].upper_clearance = value,
            Target::DamperRestitution(i) => law(&mut spec.dampers[i].law, "restitution")?,
            Target::DamperStiffness(i) => law(&mut spec.dampers[i].law, "stiffness")?,
            Target::DamperDamping(i) => law(&mut spec.dampers[i].law, "damping")?,
            Target::StopGap(i) => spec.stops[i].gap = value,
            Target::StopRestitution(i) => law(&mut spec.stops[i].law, "restitution")?,
            Target::StopStiffness(i) => law(&mut spec.stops[i].law, "stiffness")?,
            Target::StopDamping(i) => law(&mut spec.stops[i].law, "damping")?,
            Target::Gravity => spec.gravity = value,
            Target::ExcitationAmplitude(i)
            | Target::ExcitationFrequency(i)
            | Target::ExcitationPhase(i) => {
                if let Signal::Harmonic(h) = &mut spec.excitations[i].signal {
                    match self.target {
                        Target::ExcitationAmplitude(_) => h.amplitude = value,
                        Target::ExcitationFrequency(_) => {
                            if !(value >= 0.0 && value.is_finite()) {
                                return Err(Error::Inconsistent(format!(
                                    "{} must be >= 0 Hz, got {value}",
                                    self.path
                                )));
                            }
                            h.frequency = value
                        }
                        _ => h.phase = value,
                    }
                }
            }
            Target::Structure(key) => {
                let mut recipe = spec.structure.recipe();
                *recipe
                    .input(STRUCTURE_KEYS[key])
                    .expect("checked by Parameter::parse") = value;
                spec.structure = recipe.build().map_err(|e| in_section("structure", e))?;
            }
            Target::ExcitationRecipe(i, key) => {
                let signal = &mut spec.excitations[i].signal;
                let mut recipe = *signal.recipe().expect("checked by Parameter::parse");
                let section = || format!("excitation.{i}");
                recipe
                    .set(key, value)
                    .map_err(|e| in_section(&section(), e))?;
                *signal = recipe.generate().map_err(|e| in_section(&section(), e))?;
            }
            Target::Initial(..) => self.apply_start(spec, initial, value),
        }
        Ok(())
    }

    /// Set a start parameter (`initial.*`) to `value` in `initial`; the
    /// system `spec` is only read (its sizes). Other parameters: nothing.
    fn apply_start(&self, spec: &SystemSpec, initial: &mut [Vec<f64>; 4], value: f64) {
        if let Target::Initial(which, i) = self.target {
            let array = &mut initial[which];
            let size = if which < 2 {
                spec.structure.dofs()
            } else {
                spec.dampers.len()
            };
            if array.len() != size {
                array.resize(size, 0.0);
            }
            array[i] = value;
        }
    }
}

/// A core error about an input of `section` (a dotted path), named by it.
fn in_section(section: &str, e: Error) -> Error {
    match e {
        Error::InvalidParameter { .. } | Error::UnknownChoice { .. } => {
            Error::Inconsistent(format!("{section}.{e}"))
        }
        Error::Inconsistent(text) if text.starts_with(section) => Error::Inconsistent(text),
        other => Error::Inconsistent(format!("{section}: {other}")),
    }
}

fn rebuilt(c: &Contact, stiffness: f64, restitution: f64, damping: f64) -> Result<Contact> {
    let restitution = c.law.uses_restitution().then_some(restitution);
    Contact::new(c.law, stiffness, restitution, damping)
}

/// How each run of a study is made and what it keeps.
#[derive(Debug, Clone, PartialEq)]
pub struct StudySettings {
    pub method: String,
    pub dt: Option<f64>,
    pub rtol: f64,
    pub atol: f64,
    pub beta: f64,
    pub gamma: f64,
    pub spectral_radius: f64,
    pub max_steps: u64,
    pub energy_tolerance: f64,
    /// `"run"` (to `t_end`) or `"steady-state"` (whole forcing periods).
    pub analysis: Analysis,
    /// Whether to integrate the mean squares (the RMS metric).
    pub mean_square: bool,
    /// Fixed steps without cutting them at events, the runs advanced in
    /// lockstep ([`crate::analysis::ensemble`]): RK4 runs of one mass on a spring with
    /// one compliant damper, unforced.
    pub lockstep: bool,
}

#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Analysis {
    /// A run to `t_end`, metrics from `record_from` on.
    Run { t_end: f64, record_from: f64 },
    /// `settle` then `record` periods (at least MAX_PERIOD: see
    /// `recorded_periods`) of the first harmonic excitation; settled when
    /// the stroboscopic state repeats after p <= 8 periods
    /// within `tolerance` (relative: see [`settling::strobe_period`]).
    SteadyState {
        settle: u64,
        record: u64,
        tolerance: f64,
    },
    /// `settle` forcing periods, then Newton shooting for an orbit of
    /// `periods` periods from there (see [`crate::analysis::shooting`]): its Floquet
    /// multipliers, amplitude and impacts.
    Orbit { settle: u64, periods: u64 },
}

/// Newton's tolerance and iterations for an orbit study's shooting (as
/// `vibroimpact.analyses.orbit`'s defaults).
const ORBIT_TOLERANCE: f64 = 1e-10;
const ORBIT_ITERATIONS: usize = 40;

/// The metrics of one run. NaN where a run failed (see `status`).
#[derive(Debug, Clone, PartialEq)]
pub struct RunMetrics {
    /// 0 when the run completed, else 1 (the reason in `reason`).
    pub status: u8,
    pub reason: String,
    /// Per observed quantity (each structure coordinate, then each of the
    /// spec's points), m.
    pub peak: Vec<f64>,
    pub rms: Vec<f64>,
    /// Impacts and compliant contacts recorded (a sticking period is not
    /// an impact: it is left out).
    pub impacts: f64,
    /// Per pair, J, over the recorded time.
    pub energy_dissipated: Vec<f64>,
    /// Steady state only: impacts per forcing period, and 1 / 0 for settled.
    pub impacts_per_period: f64,
    pub settled: f64,
    /// Orbit only: 1 when Newton converged and every Floquet multiplier is
    /// inside the unit circle, else 0; the largest multiplier's modulus.
    pub stable: f64,
    pub largest_multiplier: f64,
}

/// Run the study: for each row of `values` (one value per parameter), set
/// the parameters in a copy of `spec` and `initial` and run; on `threads`
/// threads (0: all cores). Results in the order of the rows.
pub fn run_study(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    parameters: &[Parameter],
    values: &[f64],
    settings: &StudySettings,
    threads: usize,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<RunMetrics>> {
    if !matches!(settings.analysis, Analysis::Run { .. }) {
        // Refused up front on the base scenario; an axis may still make a
        // point aperiodic, which then fails alone.
        forcing_period(spec)?;
    }
    if settings.method == "exact" {
        // Every run alike would fail on a law's or a signal's kind, which no
        // axis changes: refused up front (a base whose values an axis
        // replaces may be unfit to assemble; its runs then say so).
        if let Ok(system) = Assembly::new(spec) {
            ExactFlow::takes(&system)?;
        }
    }
    let width = parameters.len().max(1);
    let rows = if parameters.is_empty() {
        1
    } else {
        values.len() / width
    };
    if settings.lockstep {
        return run_lockstep(
            spec, initial, parameters, values, rows, settings, threads, interrupt,
        );
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .build()
        .map_err(|e| Error::Inconsistent(format!("cannot start the study's threads: {e}")))?;
    let starts_only = !parameters.is_empty()
        && parameters
            .iter()
            .all(|p| matches!(p.target, Target::Initial(..)));
    if starts_only {
        return run_starts(
            spec, initial, parameters, values, rows, settings, &pool, interrupt,
        );
    }
    let results = pool.install(|| {
        (0..rows)
            .into_par_iter()
            .map(|row| {
                if interrupt() {
                    return Err(Error::Interrupted { time: 0.0 });
                }
                let row_values = if parameters.is_empty() {
                    &[][..]
                } else {
                    &values[row * width..(row + 1) * width]
                };
                one_run(spec, initial, parameters, row_values, settings, interrupt)
            })
            .collect::<Vec<Result<RunMetrics>>>()
    });
    results.into_iter().collect()
}

/// The forcing period of a steady-state or orbit study, s (see
/// [`crate::model::signals::common_period`]).
fn forcing_period(spec: &SystemSpec) -> Result<f64> {
    let parts: Vec<_> = spec
        .excitations
        .iter()
        .map(|e| e.signal.harmonic_frequencies())
        .collect();
    crate::model::signals::common_period(&parts)
}

/// The study's `rows` runs as a lockstep ensemble of fixed RK4 steps.
#[allow(clippy::too_many_arguments)]
fn run_lockstep(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    parameters: &[Parameter],
    values: &[f64],
    rows: usize,
    settings: &StudySettings,
    threads: usize,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<RunMetrics>> {
    let Analysis::Run { t_end, record_from } = settings.analysis else {
        return Err(Error::Inconsistent(
            "stepping = \"fixed\" runs each member to t_end: use analysis = \"run\"".into(),
        ));
    };
    if settings.method != "rk4" {
        return Err(Error::Inconsistent(format!(
            "stepping = \"fixed\" advances RK4 runs in lockstep: use method = \"rk4\" (got {:?})",
            settings.method
        )));
    }
    let run = Settings::new(
        Method::Rk4,
        settings.dt,
        t_end,
        1,
        ContactTiming::Located,
        Some(Stepping::Fixed),
        settings.max_steps,
    )?;
    run.check_steps()?;
    let dt = run.dt.expect("a fixed step was required");
    // The base system must fit; a row's values may still make one that does not.
    member_of(spec, initial)?;
    let width = parameters.len().max(1);
    let members: Vec<std::result::Result<Member, String>> = (0..rows)
        .map(|row| {
            let mut spec = spec.clone();
            let mut initial = initial.clone();
            let row_values = &values[(row * width).min(values.len())..][..parameters.len()];
            for (p, v) in parameters.iter().zip(row_values) {
                p.apply(&mut spec, &mut initial, *v)
                    .map_err(|e| e.to_string())?;
            }
            member_of(&spec, &initial).map_err(|e| e.to_string())
        })
        .collect();
    let runnable: Vec<Member> = members.iter().filter_map(|m| m.clone().ok()).collect();
    let options = EnsembleOptions {
        dt,
        steps: run.steps(),
        record_from,
        energy_tolerance: settings.energy_tolerance,
    };
    let mut results = run_ensemble(&runnable, &options, threads, interrupt)?.into_iter();
    let nan = f64::NAN;
    Ok(members
        .into_iter()
        .map(|member| {
            let (status, reason, result) = match member {
                Ok(_) => {
                    let r = results.next().expect("one result a member");
                    (
                        u8::from(r.reason.is_some()),
                        r.reason.clone().unwrap_or_default(),
                        Some(r),
                    )
                }
                Err(reason) => (1, reason, None),
            };
            let ok = result.filter(|r| r.reason.is_none());
            RunMetrics {
                status,
                reason,
                peak: vec![ok.as_ref().map_or(nan, |r| r.peak)],
                rms: vec![ok.as_ref().map_or(nan, |r| r.rms)],
                impacts: ok.as_ref().map_or(nan, |r| r.contacts as f64),
                energy_dissipated: vec![nan],
                impacts_per_period: nan,
                settled: nan,
                stable: nan,
                largest_multiplier: nan,
            }
        })
        .collect())
}

/// The two-mass impact damper a 0.2 system is, if it is one: one mass on a
/// spring and damper (its point the coordinate itself), one damper with equal
/// clearances and a compliant law, no stops, gravity or excitation.
fn member_of(spec: &SystemSpec, initial: &[Vec<f64>; 4]) -> Result<Member> {
    let unfit = |what: &str| {
        Error::Inconsistent(format!(
            "stepping = \"fixed\" (lockstep RK4 runs) takes one mass on a spring with one \
             [[damper]] of equal clearances and a compliant law, unforced, without stops or \
             gravity: {what}"
        ))
    };
    let structure = &spec.structure;
    if structure.dofs() != 1 {
        return Err(unfit("the structure has more than one coordinate"));
    }
    let [damper] = spec.dampers.as_slice() else {
        return Err(unfit("it needs exactly one [[damper]]"));
    };
    if !spec.stops.is_empty() || spec.gravity != 0.0 || !spec.excitations.is_empty() {
        return Err(unfit("the scenario has stops, gravity or an excitation"));
    }
    if !spec.points.is_empty() || !spec.moments.is_empty() {
        // Its one coordinate is its one point: its peak and rms are already kept.
        return Err(unfit(
            "[output] points and moments are followed by event-driven runs only",
        ));
    }
    if structure.point("damper.0.at", damper.at)? != [1.0] {
        return Err(unfit("the damper's point is not the coordinate itself"));
    }
    if damper.lower_clearance != damper.upper_clearance {
        return Err(unfit("the damper's lower and upper clearances differ"));
    }
    let PairLaw::Compliant(contact) = damper.law else {
        return Err(unfit("the damper's law is rigid"));
    };
    let first = |k: usize| initial[k].first().copied().unwrap_or(0.0);
    Ok(Member {
        system: ImpactDamper::new(
            structure.mass()[0],
            structure.stiffness()[0],
            structure.damping()[0],
            damper.mass,
            damper.lower_clearance,
        )?,
        contact,
        initial: State::new(first(0), first(1), first(2), first(3))?,
    })
}

/// The metrics of a run of `spec` that failed for `reason`: NaN.
fn failed_run(spec: &SystemSpec, reason: String) -> RunMetrics {
    // Each structure coordinate, then each followed point and moment.
    let n = spec.structure.dofs() + spec.points.len() + spec.moments.len();
    let pairs = spec.dampers.len() + spec.stops.len();
    RunMetrics {
        status: 1,
        reason,
        peak: vec![f64::NAN; n],
        rms: vec![f64::NAN; n],
        impacts: f64::NAN,
        energy_dissipated: vec![f64::NAN; pairs],
        impacts_per_period: f64::NAN,
        settled: f64::NAN,
        stable: f64::NAN,
        largest_multiplier: f64::NAN,
    }
}

/// Runs that vary only the start: one system for all, one method a thread.
#[allow(clippy::too_many_arguments)]
fn run_starts(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    parameters: &[Parameter],
    values: &[f64],
    rows: usize,
    settings: &StudySettings,
    pool: &rayon::ThreadPool,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<Vec<RunMetrics>> {
    let system = Assembly::new(spec)?;
    let width = parameters.len();
    let results = pool.install(|| {
        (0..rows)
            .into_par_iter()
            .map_init(
                || stepper_of(&system, settings),
                |stepper, row| {
                    if interrupt() {
                        return Err(Error::Interrupted { time: 0.0 });
                    }
                    // Only the start changes: no copy of the system.
                    let mut start = initial.clone();
                    for (p, v) in parameters
                        .iter()
                        .zip(&values[row * width..(row + 1) * width])
                    {
                        p.apply_start(spec, &mut start, *v);
                    }
                    let run = match stepper {
                        Ok(method) => {
                            measured_on(spec, &system, method, &start, settings, interrupt)
                        }
                        Err(e) => Err(e.clone()),
                    };
                    if let Err(e @ Error::Interrupted { .. }) = run {
                        return Err(e);
                    }
                    if run.is_err() {
                        // A run stopped part way may leave work in the method
                        // (the exact flow's pending energies): a fresh one next.
                        *stepper = stepper_of(&system, settings);
                    }
                    Ok(run.unwrap_or_else(|e| failed_run(spec, e.to_string())))
                },
            )
            .collect::<Vec<Result<RunMetrics>>>()
    });
    results.into_iter().collect()
}

/// One run of the study at `values`: its metrics, or those of a failed run
/// with its reason; an interrupt (which stops the run part way) is an error.
fn one_run(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    parameters: &[Parameter],
    values: &[f64],
    settings: &StudySettings,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<RunMetrics> {
    let mut spec = spec.clone();
    let mut initial = initial.clone();
    for (p, v) in parameters.iter().zip(values) {
        if let Err(e) = p.apply(&mut spec, &mut initial, *v) {
            return Ok(failed_run(&spec, e.to_string()));
        }
    }
    match measured(&spec, &initial, settings, interrupt) {
        Ok(metrics) => Ok(metrics),
        Err(e @ Error::Interrupted { .. }) => Err(e),
        Err(e) => Ok(failed_run(&spec, e.to_string())),
    }
}

fn measured(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    settings: &StudySettings,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<RunMetrics> {
    let system = Assembly::new(spec)?;
    let mut stepper = stepper_of(&system, settings)?;
    measured_on(spec, &system, &mut stepper, initial, settings, interrupt)
}

/// A run of `system` (made of `spec`) from `initial`, by `stepper` (which
/// starts afresh in every run, so that it may serve many).
fn measured_on(
    spec: &SystemSpec,
    system: &Assembly,
    stepper: &mut AnyStepper,
    initial: &[Vec<f64>; 4],
    settings: &StudySettings,
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<RunMetrics> {
    let y0 = initial_state(system, &initial[0], &initial[1], &initial[2], &initial[3])?;
    let period = || forcing_period(spec);
    let (t_end, record_from, strobe_period) = match settings.analysis {
        Analysis::Run { t_end, record_from } => (t_end, record_from, f64::INFINITY),
        Analysis::SteadyState { settle, record, .. } => {
            let t = period()?;
            let record = recorded_periods(record);
            ((settle + record) as f64 * t, settle as f64 * t, t)
        }
        Analysis::Orbit { settle, periods } => {
            return orbit_metrics(
                system,
                stepper,
                &y0,
                settings,
                (period()?, settle, periods),
                interrupt,
            );
        }
    };
    let options = run_options(
        settings,
        stepper.step(settings.dt, t_end, strobe_period),
        t_end,
        ReduceOptions {
            record_from,
            strobe_period,
            mean_square: settings.mean_square,
            // Only the recorded contacts are counted.
            contacts_from: record_from,
        },
    );
    let sol = stepper.integrate(system, &y0, &options, &mut || interrupt())?;
    Ok(metrics_of(
        system,
        &sol,
        (record_from, strobe_period),
        settings,
    ))
}

/// A study run's options: no history, the study's limits.
fn run_options(
    settings: &StudySettings,
    dt: Option<f64>,
    t_end: f64,
    reduce: ReduceOptions,
) -> RunOptions {
    RunOptions {
        dt,
        t_end,
        every: 1,
        keep_history: false,
        max_steps: settings.max_steps,
        max_rows: u64::MAX,
        energy_tolerance: settings.energy_tolerance,
        reduce,
    }
}

/// The study's method for `system`.
fn stepper_of(system: &Assembly, settings: &StudySettings) -> Result<AnyStepper> {
    AnyStepper::new(
        system,
        &settings.method,
        settings.rtol,
        settings.atol,
        settings.beta,
        settings.gamma,
        settings.spectral_radius,
    )
}

/// An orbit study's run: settle, shoot, then one more orbit recorded.
fn orbit_metrics(
    system: &Assembly,
    stepper: &mut AnyStepper,
    y0: &[f64],
    settings: &StudySettings,
    (period, settle, periods): (f64, u64, u64),
    interrupt: &(dyn Fn() -> bool + Sync),
) -> Result<RunMetrics> {
    let span = periods as f64 * period;
    let options = |t_end: f64, record: bool| {
        let from = if record { 0.0 } else { f64::INFINITY };
        let reduce = ReduceOptions {
            record_from: from,
            strobe_period: f64::INFINITY,
            mean_square: false,
            // Settling and shooting count no contact.
            contacts_from: from,
        };
        run_options(
            settings,
            stepper.step(settings.dt, t_end, period),
            t_end,
            reduce,
        )
    };
    let (n, d) = (system.n, system.dim);
    let settle_options = options(settle.max(1) as f64 * period, false);
    let span_options = options(span, false);
    let record_options = options(span, true);
    let mut z = if settle > 0 {
        stepper
            .integrate(system, y0, &settle_options, &mut || interrupt())?
            .final_state
    } else {
        y0[..2 * d].to_vec()
    };
    let mut run_from = |z: &[f64], options: &RunOptions| -> Result<SystemSolution> {
        let y = resumed_state(system, [&z[..n], &z[d..d + n], &z[n..d], &z[d + n..2 * d]])?;
        let run = stepper.integrate(system, &y, options, &mut || interrupt());
        if run.is_err() {
            // A run stopped part way may leave work in the method (the exact
            // flow's pending energies): the next starts with a fresh one.
            *stepper = stepper_of(system, settings)?;
        }
        run
    };
    let shot = shooting::shoot(
        &mut |z| Ok(run_from(z, &span_options)?.final_state),
        &z,
        period,
        ORBIT_TOLERANCE,
        ORBIT_ITERATIONS,
    )?;
    if !shot.converged {
        let refused = shot
            .refusal
            .map(|r| format!("; its last step was refused: {r}"))
            .unwrap_or_default();
        return Err(Error::Inconsistent(format!(
            "no orbit of {periods} forcing period(s) found near the settled state: Newton's \
             method stopped after {} iterations at residual {:.1e}{refused} (settle longer, or \
             look for an orbit of more periods)",
            shot.iterations, shot.residual
        )));
    }
    z.clone_from(&shot.state);
    let multipliers = linalg::eigenvalues(&shot.monodromy, 2 * d).ok_or_else(|| {
        Error::Inconsistent("the orbit's Floquet multipliers did not converge".into())
    })?;
    let largest = multipliers
        .iter()
        .map(|(re, im)| re.hypot(*im))
        .fold(0.0f64, f64::max);
    let orbit = run_from(&z, &record_options)?;
    let impacts = orbit
        .contacts
        .iter()
        .filter(|c| c.kind != ContactKind::Sticking)
        .count() as f64;
    let nan = f64::NAN;
    Ok(RunMetrics {
        status: 0,
        reason: String::new(),
        peak: orbit.reductions.peaks.clone(),
        rms: vec![nan; system.observed()],
        impacts,
        energy_dissipated: vec![nan; system.pairs.len()],
        impacts_per_period: impacts / periods as f64,
        settled: nan,
        stable: f64::from(u8::from(shot.converged && largest < 1.0)),
        largest_multiplier: largest,
    })
}

/// The forcing periods a steady-state run records for `record` asked: at
/// least MAX_PERIOD, so that one whole orbit of any period it may find fits
/// (impacts per period counted over part of an orbit depend on where the
/// window ends: a period-8 orbit had given 1, 2, 3 or 14 over one period).
fn recorded_periods(record: u64) -> u64 {
    record.max(MAX_PERIOD as u64)
}

/// The metrics of `sol`, recorded from `record_from` (s); `period` is the
/// forcing period (s) of a steady-state study.
fn metrics_of(
    system: &Assembly,
    sol: &SystemSolution,
    (record_from, period): (f64, f64),
    settings: &StudySettings,
) -> RunMetrics {
    let r = &sol.reductions;
    let rms = r
        .square_integrals
        .iter()
        .map(|s| {
            if r.recorded_time > 0.0 {
                (s / r.recorded_time).sqrt()
            } else {
                f64::NAN
            }
        })
        .collect();
    let recorded: Vec<_> = sol
        .contacts
        .iter()
        .filter(|c| c.onset >= record_from)
        .collect();
    let impacts = recorded
        .iter()
        .filter(|c| c.kind != ContactKind::Sticking)
        .count() as f64;
    let mut energy = vec![0.0; system.pairs.len()];
    for c in &recorded {
        if c.energy_dissipated.is_finite() {
            energy[c.pair] += c.energy_dissipated;
        }
    }
    let (impacts_per_period, settled) = match settings.analysis {
        Analysis::SteadyState {
            settle,
            record,
            tolerance,
        } => {
            // Judged at the end of settling, as the analysis does.
            let width = 2 * system.dim;
            let rows = (settle as usize).min(r.strobe.len() / width);
            let strobe = &r.strobe[..rows * width];
            let repeats = settling::strobe_period(strobe, width, period, tolerance, MAX_PERIOD);
            // Impacts counted over whole periods of the orbit (a window of
            // 20 periods of a period-8 orbit counts part of one).
            let orbit = repeats.map_or(1, |p| p as u64);
            let whole = recorded_periods(record) / orbit * orbit;
            let end = record_from + whole as f64 * period;
            let counted = recorded
                .iter()
                .filter(|c| c.kind != ContactKind::Sticking && c.onset < end)
                .count() as f64;
            (
                counted / whole as f64,
                f64::from(u8::from(repeats.is_some())),
            )
        }
        Analysis::Run { .. } | Analysis::Orbit { .. } => (f64::NAN, f64::NAN),
    };
    RunMetrics {
        status: 0,
        reason: String::new(),
        peak: r.peaks.clone(),
        rms,
        impacts,
        energy_dissipated: energy,
        impacts_per_period,
        settled,
        stable: f64::NAN,
        largest_multiplier: f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::assembly::{Excitation, Load};
    use crate::model::structure::Structure;

    fn noisy(structure: Structure, signal: Signal) -> SystemSpec {
        SystemSpec {
            structure,
            dampers: vec![],
            stops: vec![],
            gravity: 0.0,
            excitations: vec![Excitation {
                load: Load::Base,
                signal,
            }],
            points: vec![],
            moments: vec![],
        }
    }

    /// The structure of `spec` with its input `key` set to `value`.
    fn varied(spec: &SystemSpec, key: &str, value: f64) -> Structure {
        let p = Parameter::parse(&format!("structure.{key}"), spec).unwrap();
        let mut varied = spec.clone();
        p.apply(&mut varied, &mut Default::default(), value)
            .unwrap();
        varied.structure
    }

    fn oscillator() -> Structure {
        Structure::oscillator(1.0, 400.0, 1.0).unwrap()
    }

    #[test]
    fn a_seed_axis_generates_the_signal_the_scenario_would_have() {
        crate::testing::timeout(60, || {
            let spec = noisy(
                oscillator(),
                Signal::kanai_tajimi(0.1, 2.0, 0.6, 20.0, 1.0, 3).unwrap(),
            );
            let seed = Parameter::parse("excitation.0.seed", &spec).unwrap();
            let intensity = Parameter::parse("excitation.0.intensity", &spec).unwrap();
            let mut varied = spec.clone();
            let mut initial: [Vec<f64>; 4] = Default::default();
            seed.apply(&mut varied, &mut initial, 17.0).unwrap();
            intensity.apply(&mut varied, &mut initial, 0.3).unwrap();
            let written = Signal::kanai_tajimi(0.3, 2.0, 0.6, 20.0, 1.0, 17).unwrap();
            assert_eq!(varied.excitations[0].signal, written);
            // A seed that is not a whole number fails, naming the key.
            let error = seed
                .apply(&mut varied, &mut initial, 1.5)
                .unwrap_err()
                .to_string();
            assert!(
                error.starts_with("excitation.0.seed must be a whole number"),
                "{error}"
            );
        });
    }

    // Whole runs are compared with the runs made one by one in
    // tests/test_study_seeds.py (the Python suite's release build).
    #[test]
    fn structure_inputs_remake_the_structure_and_a_bad_value_names_its_key() {
        crate::testing::timeout(60, || {
            let signal = Signal::harmonic(1.0, 3.0, 0.0).unwrap();
            let spec = noisy(oscillator(), signal.clone());
            let mut initial: [Vec<f64>; 4] = Default::default();
            for (key, value, remade) in [
                ("mass", 2.0, Structure::oscillator(2.0, 400.0, 1.0)),
                ("stiffness", 9.0, Structure::oscillator(1.0, 9.0, 1.0)),
                ("damping", 0.0, Structure::oscillator(1.0, 400.0, 0.0)),
            ] {
                assert_eq!(varied(&spec, key, value), remade.unwrap(), "{key}");
            }
            let mass = Parameter::parse("structure.mass", &spec).unwrap();
            let error = mass
                .apply(&mut spec.clone(), &mut initial, -1.0)
                .unwrap_err()
                .to_string();
            assert!(
                error.starts_with("structure.mass must be a finite number > 0"),
                "{error}"
            );
            // A cantilever's inputs; a matrices structure has none.
            let beam = noisy(
                Structure::cantilever(0.5, 2e11, 1e-10, 0.8, 2, 0.01).unwrap(),
                signal.clone(),
            );
            for (key, value, remade) in [
                (
                    "length",
                    0.4,
                    Structure::cantilever(0.4, 2e11, 1e-10, 0.8, 2, 0.01),
                ),
                (
                    "youngs_modulus",
                    7e10,
                    Structure::cantilever(0.5, 7e10, 1e-10, 0.8, 2, 0.01),
                ),
                (
                    "second_moment",
                    2e-10,
                    Structure::cantilever(0.5, 2e11, 2e-10, 0.8, 2, 0.01),
                ),
                (
                    "mass_per_length",
                    0.3,
                    Structure::cantilever(0.5, 2e11, 1e-10, 0.3, 2, 0.01),
                ),
                (
                    "damping_ratio",
                    0.05,
                    Structure::cantilever(0.5, 2e11, 1e-10, 0.8, 2, 0.05),
                ),
            ] {
                assert_eq!(varied(&beam, key, value), remade.unwrap(), "{key}");
            }
            let ratio = Parameter::parse("structure.damping_ratio", &beam).unwrap();
            let error = ratio
                .apply(&mut beam.clone(), &mut initial, 1.5)
                .unwrap_err()
                .to_string();
            assert!(
                error.starts_with("structure.damping_ratio must be"),
                "{error}"
            );
            for path in ["structure.mass", "structure.modes"] {
                let error = Parameter::parse(path, &beam).unwrap_err().to_string();
                assert!(
                    error.contains(&format!("{path:?}")) && error.contains("mass_per_length"),
                    "{error}"
                );
            }
            let matrices = noisy(
                Structure::matrices(&[vec![1.0]], &[vec![1.0]], &[vec![0.0]]).unwrap(),
                signal,
            );
            let error = Parameter::parse("structure.mass", &matrices)
                .unwrap_err()
                .to_string();
            assert!(error.contains("\"matrices\""), "{error}");
        });
    }

    #[test]
    fn a_harmonic_signal_has_no_seed() {
        crate::testing::timeout(60, || {
            let spec = noisy(oscillator(), Signal::harmonic(1.0, 3.0, 0.0).unwrap());
            let error = Parameter::parse("excitation.0.seed", &spec)
                .unwrap_err()
                .to_string();
            assert!(error.contains("excitation.0.seed") && error.contains("allowed"));
            let noise = noisy(oscillator(), Signal::white_noise(1.0, 5.0, 1.0, 0).unwrap());
            let error = Parameter::parse("excitation.0.ground_damping", &noise)
                .unwrap_err()
                .to_string();
            assert!(
                error.contains("white-noise") && error.contains("intensity"),
                "{error}"
            );
        });
    }
}
