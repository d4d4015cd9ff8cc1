//! Python dicts (the sections of a 0.2 scenario, already checked for unknown keys
//! and types by `vibroimpact.system`) into the core's system spec: one conversion
//! per core type (structure, pair law, signal, the spec).

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use vibroimpact_core as core;
use vibroimpact_core::model::assembly::{
    Collision, Damper, Excitation, Friction, FrictionSite, Load, PairLaw, Side, Stop, SystemSpec,
};
use vibroimpact_core::model::signals::{Harmonic, Signal, SweepLaw};
use vibroimpact_core::model::structure::Structure;

use crate::errors::{short_numbers, to_py, InvalidInputError};

/// `where key` must be present: the Python side fills defaults, so a missing
/// key is a bug of the caller's dict, reported as bad input all the same.
pub(crate) fn get<'py, T: pyo3::conversion::FromPyObjectOwned<'py>>(
    d: &Bound<'py, PyDict>,
    place: &str,
    key: &str,
) -> PyResult<T> {
    match d.get_item(key)? {
        Some(value) => value.extract::<T>().map_err(|_| {
            InvalidInputError::new_err(format!("{place}.{key} has the wrong type: {value}"))
        }),
        None => Err(InvalidInputError::new_err(format!(
            "{place}.{key} is required"
        ))),
    }
}

fn optional<'py, T: pyo3::conversion::FromPyObjectOwned<'py>>(
    d: &Bound<'py, PyDict>,
    place: &str,
    key: &str,
) -> PyResult<Option<T>> {
    match d.get_item(key)? {
        Some(value) if !value.is_none() => get(d, place, key).map(Some),
        _ => Ok(None),
    }
}

/// A core error about `place` (a section or list entry), prefixed with it.
fn named(place: &str) -> impl Fn(core::Error) -> PyErr + '_ {
    move |e| match e {
        core::Error::InvalidParameter { .. } | core::Error::UnknownChoice { .. } => {
            InvalidInputError::new_err(short_numbers(&format!("{place}.{e}")))
        }
        other => to_py(other),
    }
}

pub(crate) fn structure(d: &Bound<'_, PyDict>) -> PyResult<Structure> {
    let place = "structure";
    let kind: String = get(d, place, "kind")?;
    match kind.as_str() {
        "oscillator" => Structure::oscillator(
            get(d, place, "mass")?,
            get(d, place, "stiffness")?,
            get(d, place, "damping")?,
        ),
        "matrices" => Structure::matrices(
            &get::<Vec<Vec<f64>>>(d, place, "mass")?,
            &get::<Vec<Vec<f64>>>(d, place, "stiffness")?,
            &get::<Vec<Vec<f64>>>(d, place, "damping")?,
        ),
        "cantilever" => Structure::cantilever(
            get(d, place, "length")?,
            get(d, place, "youngs_modulus")?,
            get(d, place, "second_moment")?,
            get(d, place, "mass_per_length")?,
            get(d, place, "modes")?,
            get(d, place, "damping_ratio")?,
        ),
        other => {
            return Err(InvalidInputError::new_err(format!(
                "structure.kind must be one of \"oscillator\", \"matrices\", \"cantilever\", got {other:?}"
            )))
        }
    }
    .map_err(named(place))
}

/// A pair's law from its `law`, `stiffness`, `restitution`, `damping`.
fn pair_law(d: &Bound<'_, PyDict>, place: &str) -> PyResult<PairLaw> {
    let law: String = get(d, place, "law")?;
    let restitution: Option<f64> = optional(d, place, "restitution")?;
    if law == "rigid" {
        let e = restitution.ok_or_else(|| {
            InvalidInputError::new_err(format!(
                "{place}.restitution is required for law \"rigid\" (a number in [0, 1])"
            ))
        })?;
        return PairLaw::rigid(e).map_err(named(place));
    }
    let kind = core::LawKind::parse(&law).map_err(|_| {
        InvalidInputError::new_err(format!(
            "{place}.law must be one of \"rigid\", {}, got {law:?}",
            core::LawKind::NAMES
        ))
    })?;
    let stiffness: f64 = optional(d, place, "stiffness")?.ok_or_else(|| {
        InvalidInputError::new_err(format!(
            "{place}.stiffness is required for law {law:?} (N/m^1.5, or N/m for \"linear\")"
        ))
    })?;
    let damping: f64 = optional(d, place, "damping")?.unwrap_or(0.0);
    core::Contact::new(kind, stiffness, restitution, damping)
        .map(PairLaw::Compliant)
        .map_err(named(place))
}

fn signal(d: &Bound<'_, PyDict>, place: &str, t_end: f64) -> PyResult<Signal> {
    let kind: String = get(d, place, "signal")?;
    let number = |key: &str| get::<f64>(d, place, key);
    let duration = || Ok::<f64, PyErr>(optional::<f64>(d, place, "duration")?.unwrap_or(t_end));
    match kind.as_str() {
        "harmonic" => Signal::harmonic(
            number("amplitude")?,
            number("frequency")?,
            optional(d, place, "phase")?.unwrap_or(0.0),
        ),
        "sweep" => {
            let law: String = optional(d, place, "sweep")?.unwrap_or_else(|| "linear".into());
            Signal::sweep(
                number("amplitude")?,
                number("start_frequency")?,
                number("end_frequency")?,
                duration()?,
                SweepLaw::parse(&law).map_err(named(place))?,
                optional(d, place, "phase")?.unwrap_or(0.0),
            )
        }
        "harmonics" => {
            let amplitudes: Vec<f64> = get(d, place, "amplitudes")?;
            let frequencies: Vec<f64> = get(d, place, "frequencies")?;
            let phases: Vec<f64> =
                optional(d, place, "phases")?.unwrap_or_else(|| vec![0.0; amplitudes.len()]);
            if frequencies.len() != amplitudes.len() || phases.len() != amplitudes.len() {
                return Err(InvalidInputError::new_err(format!(
                    "{place}: amplitudes, frequencies and phases must have the same length, got {}, {} and {}",
                    amplitudes.len(),
                    frequencies.len(),
                    phases.len()
                )));
            }
            amplitudes
                .iter()
                .zip(&frequencies)
                .zip(&phases)
                .map(|((&a, &f), &p)| Harmonic::new(a, f, p))
                .collect::<core::Result<Vec<_>>>()
                .map(Signal::Harmonics)
        }
        "recorded" => Signal::recorded(
            get(d, place, "time")?,
            get(d, place, "value")?,
            optional(d, place, "scale")?.unwrap_or(1.0),
        ),
        "white-noise" => Signal::white_noise(
            number("intensity")?,
            number("cutoff_frequency")?,
            duration()?,
            get(d, place, "seed")?,
        ),
        "kanai-tajimi" => Signal::kanai_tajimi(
            number("intensity")?,
            number("ground_frequency")?,
            number("ground_damping")?,
            number("cutoff_frequency")?,
            duration()?,
            get(d, place, "seed")?,
        ),
        other => {
            return Err(InvalidInputError::new_err(format!(
                "{place}.signal must be one of \"harmonic\", \"sweep\", \"harmonics\", \"recorded\", \
                 \"white-noise\", \"kanai-tajimi\", got {other:?}"
            )))
        }
    }
    .map_err(named(place))
}

pub(crate) fn entries<'py>(d: &Bound<'py, PyDict>, key: &str) -> PyResult<Vec<Bound<'py, PyDict>>> {
    match d.get_item(key)? {
        Some(list) => list
            .cast::<PyList>()
            .map_err(|_| InvalidInputError::new_err(format!("{key} must be a list of tables")))?
            .iter()
            .map(|item| {
                item.cast_into::<PyDict>()
                    .map_err(|_| InvalidInputError::new_err(format!("each {key} must be a table")))
            })
            .collect(),
        None => Ok(vec![]),
    }
}

/// The system from its sections; signals without a duration last `t_end`.
pub(crate) fn system_spec(spec: &Bound<'_, PyDict>, t_end: f64) -> PyResult<SystemSpec> {
    let structure_dict = spec
        .get_item("structure")?
        .ok_or_else(|| InvalidInputError::new_err("[structure] is required"))?
        .cast_into::<PyDict>()
        .map_err(|_| InvalidInputError::new_err("structure must be a table"))?;
    let mut dampers = Vec::new();
    let mut frictions = Vec::new();
    for (j, d) in entries(spec, "damper")?.iter().enumerate() {
        let place = format!("damper {j}");
        if let Some(coefficient) = optional::<f64>(d, &place, "friction")? {
            frictions.push(Friction {
                site: FrictionSite::Damper(j),
                coefficient,
                static_coefficient: optional(d, &place, "static_friction")?.unwrap_or(coefficient),
                normal_force: get(d, &place, "normal_force")?,
            });
        }
        dampers.push(Damper {
            mass: get(d, &place, "mass")?,
            at: get(d, &place, "at")?,
            lower_clearance: get(d, &place, "lower_clearance")?,
            upper_clearance: get(d, &place, "upper_clearance")?,
            law: pair_law(d, &place)?,
        });
    }
    let mut stops = Vec::new();
    for (j, d) in entries(spec, "stop")?.iter().enumerate() {
        let place = format!("stop {j}");
        let side: String = get(d, &place, "side")?;
        stops.push(Stop {
            at: get(d, &place, "at")?,
            side: Side::parse(&side).map_err(named(&place))?,
            gap: get(d, &place, "gap")?,
            law: pair_law(d, &place)?,
            against: optional(d, &place, "against")?,
        });
    }
    let mut collisions = Vec::new();
    for (j, d) in entries(spec, "collision")?.iter().enumerate() {
        let place = format!("collision {j}");
        let [lower, upper]: [usize; 2] = get(d, &place, "dampers")?;
        collisions.push(Collision {
            dampers: [lower, upper],
            gap: get(d, &place, "gap")?,
            law: pair_law(d, &place)?,
        });
    }
    for (j, d) in entries(spec, "friction")?.iter().enumerate() {
        let place = format!("friction {j}");
        let coefficient: f64 = get(d, &place, "coefficient")?;
        frictions.push(Friction {
            site: FrictionSite::Points {
                at: get(d, &place, "at")?,
                against: optional(d, &place, "against")?,
            },
            coefficient,
            static_coefficient: optional(d, &place, "static_coefficient")?.unwrap_or(coefficient),
            normal_force: get(d, &place, "normal_force")?,
        });
    }
    let mut excitations = Vec::new();
    for (j, d) in entries(spec, "excitation")?.iter().enumerate() {
        let place = format!("excitation {j}");
        let kind: String = get(d, &place, "kind")?;
        let load = match kind.as_str() {
            "force" => Load::Force {
                at: get(d, &place, "at")?,
            },
            "base" => Load::Base,
            other => {
                return Err(InvalidInputError::new_err(format!(
                    "{place}.kind must be \"force\" or \"base\", got {other:?}"
                )))
            }
        };
        excitations.push(Excitation {
            load,
            signal: signal(d, &place, t_end)?,
        });
    }
    Ok(SystemSpec {
        structure: structure(&structure_dict)?,
        dampers,
        stops,
        collisions,
        frictions,
        gravity: optional(spec, "system", "gravity")?.unwrap_or(0.0),
        excitations,
        points: optional(spec, "output", "points")?.unwrap_or_default(),
        moments: optional(spec, "output", "moments")?.unwrap_or_default(),
    })
}
