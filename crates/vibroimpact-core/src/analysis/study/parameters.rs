//! The parameters a study varies: dotted paths into the scenario, parsed
//! once and applied to a copy of the base system for each run.

use super::settings::StudySettings;
use crate::error::{Error, Result};
use crate::methods::registry::check_steps_resolve;
use crate::model::assembly::{FrictionSite, Load, PairLaw, SystemSpec};
use crate::model::contact::Contact;
use crate::model::signals::{RecipeKey, Signal};

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
    CollisionGap(usize),
    CollisionRestitution(usize),
    CollisionStiffness(usize),
    CollisionDamping(usize),
    /// An entry of [`SystemSpec::frictions`] and its key: 0 the kinetic
    /// coefficient (the static one follows where they were equal), 1 the
    /// static coefficient, 2 the normal force.
    Friction(usize, u8),
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
     lower_clearance, upper_clearance, restitution, stiffness, damping, friction, \
     static_friction, normal_force}, stop.N.{at, \
     gap, restitution, stiffness, damping}, collision.N.{gap, restitution, stiffness, damping}, \
     friction.N.{coefficient, static_coefficient, normal_force}, \
     gravity.acceleration, excitation.N.at (forces), \
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

pub(super) const INITIAL: [&str; 4] = [
    "structure_displacement",
    "structure_velocity",
    "damper_displacement",
    "damper_velocity",
];

/// A study axis's path being parsed: each error names it.
struct AxisPath<'a>(&'a str);

impl AxisPath<'_> {
    /// Not a path a study can vary.
    fn bad(&self) -> Error {
        Error::Inconsistent(format!(
            "study axis {:?}: not a path a study can vary; allowed: {PATHS}",
            self.0
        ))
    }

    /// The index `text` of one of `count` sections named `what`.
    fn index(&self, text: &str, count: usize, what: &str) -> Result<usize> {
        let i: usize = text.parse().map_err(|_| self.bad())?;
        if i < count {
            Ok(i)
        } else {
            Err(Error::Inconsistent(format!(
                "study axis {:?}: the scenario has {count} {what}",
                self.0
            )))
        }
    }

    /// `damper.i.key`.
    fn damper(&self, spec: &SystemSpec, i: usize, key: &str) -> Result<Target> {
        Ok(match key {
            "at" => Target::DamperAt(i),
            "mass" => Target::DamperMass(i),
            "clearance" => Target::DamperClearance(i),
            "lower_clearance" => Target::DamperLowerClearance(i),
            "upper_clearance" => Target::DamperUpperClearance(i),
            "restitution" => Target::DamperRestitution(i),
            "stiffness" => Target::DamperStiffness(i),
            "damping" => Target::DamperDamping(i),
            "friction" | "static_friction" | "normal_force" => {
                let f = spec
                    .frictions
                    .iter()
                    .position(|f| f.site == FrictionSite::Damper(i))
                    .ok_or_else(|| {
                        Error::Inconsistent(format!(
                            "study axis {:?}: damper {i} has no friction (give it friction and \
                             normal_force)",
                            self.0
                        ))
                    })?;
                let key = ["friction", "static_friction", "normal_force"]
                    .iter()
                    .position(|k| *k == key)
                    .unwrap_or(0);
                Target::Friction(f, key as u8)
            }
            _ => return Err(self.bad()),
        })
    }

    /// `structure.key`: an input of the structure's kind.
    fn structure(&self, spec: &SystemSpec, key: &str) -> Result<Target> {
        let mut recipe = spec.structure.recipe();
        let kind = recipe.kind();
        if recipe.input(key).is_none() {
            let allowed = match recipe.keys() {
                "" => format!(
                    "a structure of kind \"{kind}\" has no inputs a study can vary (only kinds \
                     \"oscillator\" and \"cantilever\" do)"
                ),
                keys => format!("allowed for kind \"{kind}\": structure.{{{keys}}}"),
            };
            return Err(Error::Inconsistent(format!(
                "study axis {:?}: not a path a study can vary; {allowed}",
                self.0
            )));
        }
        let at = STRUCTURE_KEYS.iter().position(|k| *k == key);
        Ok(Target::Structure(at.expect("every recipe input is listed")))
    }

    /// `excitation.i.key`: a force's point, or its signal's input.
    fn excitation(&self, spec: &SystemSpec, i: usize, key: &str) -> Result<Target> {
        let path = self.0;
        if key == "at" {
            if !matches!(spec.excitations[i].load, Load::Force { .. }) {
                return Err(Error::Inconsistent(format!(
                    "study axis {path:?}: excitation {i} is a base excitation, which acts at no \
                     point"
                )));
            }
            return Ok(Target::ExcitationAt(i));
        }
        let signal = &spec.excitations[i].signal;
        if let Some(recipe) = signal.recipe() {
            let key = RecipeKey::parse(key, recipe).ok_or_else(|| {
                Error::Inconsistent(format!(
                    "study axis {path:?}: not a path a study can vary; allowed for excitation \
                     {i} (a {} signal): excitation.{i}.{{{}}}",
                    recipe.name(),
                    recipe.keys()
                ))
            })?;
            Ok(Target::ExcitationRecipe(i, key))
        } else if matches!(signal, Signal::Harmonic(_)) {
            Ok(match key {
                "amplitude" => Target::ExcitationAmplitude(i),
                "frequency" => Target::ExcitationFrequency(i),
                "phase" => Target::ExcitationPhase(i),
                _ => return Err(self.bad()),
            })
        } else {
            Err(Error::Inconsistent(format!(
                "study axis {path:?}: excitation {i} is neither a harmonic nor a random \
                 (white-noise, kanai-tajimi) signal; allowed: {PATHS}"
            )))
        }
    }
}

/// Whether a study may set `key` of `law` (what [`Parameter::apply`] sets).
fn law_takes(law: &PairLaw, key: &str) -> bool {
    match (law, key) {
        (PairLaw::Rigid { .. }, "restitution") => true,
        (PairLaw::Compliant(_), "stiffness" | "damping") => true,
        (PairLaw::Compliant(c), "restitution") => c.law.uses_restitution(),
        _ => false,
    }
}

impl Target {
    /// The pair's law and its key, for a target that sets a law's value.
    fn law_key<'a>(&self, spec: &'a SystemSpec) -> Option<(&'a PairLaw, &'static str)> {
        Some(match *self {
            Target::DamperRestitution(i) => (&spec.dampers[i].law, "restitution"),
            Target::DamperStiffness(i) => (&spec.dampers[i].law, "stiffness"),
            Target::DamperDamping(i) => (&spec.dampers[i].law, "damping"),
            Target::StopRestitution(i) => (&spec.stops[i].law, "restitution"),
            Target::StopStiffness(i) => (&spec.stops[i].law, "stiffness"),
            Target::StopDamping(i) => (&spec.stops[i].law, "damping"),
            Target::CollisionRestitution(i) => (&spec.collisions[i].law, "restitution"),
            Target::CollisionStiffness(i) => (&spec.collisions[i].law, "stiffness"),
            Target::CollisionDamping(i) => (&spec.collisions[i].law, "damping"),
            _ => return None,
        })
    }
}

impl Parameter {
    /// Parse `path` against `spec` (indices must exist).
    pub fn parse(path: &str, spec: &SystemSpec) -> Result<Self> {
        let parts: Vec<&str> = path.split('.').collect();
        let axis = AxisPath(path);
        let target = match parts.as_slice() {
            ["damper", i, key] => {
                let i = axis.index(i, spec.dampers.len(), "[[damper]]")?;
                axis.damper(spec, i, key)?
            }
            ["stop", i, key] => {
                let i = axis.index(i, spec.stops.len(), "[[stop]]")?;
                match *key {
                    "at" => Target::StopAt(i),
                    "gap" => Target::StopGap(i),
                    "restitution" => Target::StopRestitution(i),
                    "stiffness" => Target::StopStiffness(i),
                    "damping" => Target::StopDamping(i),
                    _ => return Err(axis.bad()),
                }
            }
            ["collision", i, key] => {
                let i = axis.index(i, spec.collisions.len(), "[[collision]]")?;
                match *key {
                    "gap" => Target::CollisionGap(i),
                    "restitution" => Target::CollisionRestitution(i),
                    "stiffness" => Target::CollisionStiffness(i),
                    "damping" => Target::CollisionDamping(i),
                    _ => return Err(axis.bad()),
                }
            }
            ["friction", i, key] => {
                let elements: Vec<usize> = (0..spec.frictions.len())
                    .filter(|&f| matches!(spec.frictions[f].site, FrictionSite::Points { .. }))
                    .collect();
                let i = axis.index(i, elements.len(), "[[friction]]")?;
                let key = match *key {
                    "coefficient" => 0,
                    "static_coefficient" => 1,
                    "normal_force" => 2,
                    _ => return Err(axis.bad()),
                };
                Target::Friction(elements[i], key)
            }
            ["gravity", "acceleration"] => Target::Gravity,
            ["structure", key] => axis.structure(spec, key)?,
            ["excitation", i, key] => {
                let i = axis.index(i, spec.excitations.len(), "[[excitation]]")?;
                axis.excitation(spec, i, key)?
            }
            ["initial", array, i] => {
                let which = INITIAL
                    .iter()
                    .position(|a| a == array)
                    .ok_or_else(|| axis.bad())?;
                let size = if which < 2 {
                    spec.structure.dofs()
                } else {
                    spec.dampers.len()
                };
                Target::Initial(which, axis.index(i, size, array)?)
            }
            _ => return Err(axis.bad()),
        };
        // A key the pair's law lacks is refused here, not by every run.
        if let Some((law, key)) = target.law_key(spec) {
            if !law_takes(law, key) {
                let takes = match law {
                    PairLaw::Rigid { .. } => "a rigid pair's takes restitution",
                    PairLaw::Compliant(c) if c.law.uses_restitution() => {
                        "it takes stiffness, damping and restitution"
                    }
                    PairLaw::Compliant(_) => "it takes stiffness and damping",
                };
                return Err(Error::Inconsistent(format!(
                    "study axis {path:?}: the pair's law has no {key} ({takes})"
                )));
            }
        }
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
            // The arms `law_takes` accepts.
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
            Target::CollisionGap(i) => spec.collisions[i].gap = value,
            Target::CollisionRestitution(i) => {
                law(&mut spec.collisions[i].law, "restitution")?;
            }
            Target::CollisionStiffness(i) => law(&mut spec.collisions[i].law, "stiffness")?,
            Target::CollisionDamping(i) => law(&mut spec.collisions[i].law, "damping")?,
            Target::Friction(f, key) => {
                let friction = &mut spec.frictions[f];
                match key {
                    0 => {
                        if friction.static_coefficient == friction.coefficient {
                            friction.static_coefficient = value;
                        }
                        friction.coefficient = value;
                    }
                    1 => friction.static_coefficient = value,
                    _ => friction.normal_force = value,
                }
            }
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
    pub(super) fn apply_start(&self, spec: &SystemSpec, initial: &mut [Vec<f64>; 4], value: f64) {
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

/// The study's system and start at one row's `values`: the parameters
/// applied, then the checks a single run of that point makes before its
/// first step and the values can change ([`check_steps_resolve`]). A study
/// had run such points: a 2 kHz force sampled at one phase by dt = 1e-3 s
/// was a constant load, and 126 m a "settled" amplitude.
pub(super) fn row_system(
    spec: &SystemSpec,
    initial: &[Vec<f64>; 4],
    parameters: &[Parameter],
    values: &[f64],
    settings: &StudySettings,
) -> Result<(SystemSpec, [Vec<f64>; 4])> {
    let mut spec = spec.clone();
    let mut initial = initial.clone();
    for (p, v) in parameters.iter().zip(values) {
        p.apply(&mut spec, &mut initial, *v)?;
    }
    check_steps_resolve(&spec, &settings.method, settings.dt, settings.options)?;
    Ok((spec, initial))
}

/// A core error about an input of `section` (a dotted path), named by it.
pub(super) fn in_section(section: &str, e: Error) -> Error {
    match e {
        Error::InvalidParameter { .. } | Error::UnknownChoice { .. } => {
            Error::Inconsistent(format!("{section}.{e}"))
        }
        Error::Inconsistent(text) if text.starts_with(section) => Error::Inconsistent(text),
        other => Error::Inconsistent(format!("{section}: {other}")),
    }
}

pub(super) fn rebuilt(
    c: &Contact,
    stiffness: f64,
    restitution: f64,
    damping: f64,
) -> Result<Contact> {
    let restitution = c.law.uses_restitution().then_some(restitution);
    Contact::new(c.law, stiffness, restitution, damping)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::assembly::{Excitation, Load};
    use crate::model::structure::Structure;

    fn noisy(structure: Structure, signal: Signal) -> SystemSpec {
        SystemSpec {
            excitations: vec![Excitation {
                load: Load::Base,
                signal,
            }],
            ..SystemSpec::of(structure, vec![])
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
