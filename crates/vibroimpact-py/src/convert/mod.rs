//! Argument conversions shared by the functions: whole numbers and floats
//! from Python ints of any size, as InvalidInputError naming the field.

pub(crate) mod system;

use pyo3::prelude::*;
use pyo3::types::PyBool;

use crate::errors::InvalidInputError;

/// `value` as Python shows it, cut short for a one-line message (a NumPy
/// array's repr breaks its rows over lines: joined by one space).
fn shown(value: &Bound<'_, PyAny>) -> String {
    let text = value
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "?".into());
    let text = one_line(&text);
    if text.chars().count() > 60 {
        let head: String = text.chars().take(57).collect();
        format!("{head}...")
    } else {
        text
    }
}

/// `text` with each line break, and the blanks around it, as one space.
fn one_line(text: &str) -> String {
    if !text.contains('\n') {
        return text.to_string();
    }
    text.split('\n')
        .map(str::trim)
        .collect::<Vec<_>>()
        .join(" ")
}

/// A whole number >= 1 from a Python int; one too large or too small for the
/// core is an InvalidInputError naming the field, not an OverflowError.
pub(crate) fn whole(field: &str, value: &Bound<'_, PyAny>) -> PyResult<u64> {
    // A float (1e9, 2.5, nan), a string or an int out of range: all invalid
    // input naming the field, never a bare TypeError or OverflowError. A
    // bool is an int to Python, but True for a count is a mistake.
    let count = if value.is_instance_of::<PyBool>() {
        None
    } else {
        value.extract::<i64>().ok()
    };
    match count {
        Some(v) if v >= 1 => Ok(v as u64),
        _ => Err(InvalidInputError::new_err(format!(
            "{field} must be a whole number in [1, {}] (an int, not a float), got {}",
            i64::MAX,
            shown(value)
        ))),
    }
}

/// `history`: true or false only.
pub(crate) fn history_arg(value: &Bound<'_, PyAny>) -> PyResult<bool> {
    value.extract::<bool>().map_err(|_| {
        InvalidInputError::new_err(format!(
            "history must be True or False, got {}",
            shown(value)
        ))
    })
}

/// A float argument `field`: a Python float or int, or anything with
/// `__float__` but a bool (NumPy's reals). A Python int beyond the range of a
/// float (`10**400`) becomes an infinity of its sign, as a float computation
/// beyond the range would, instead of an OverflowError: the core then refuses
/// it like any non-finite value. Anything else is an InvalidInputError naming
/// the field (PyO3's own would be a TypeError).
pub(crate) fn real(field: &str, value: &Bound<'_, PyAny>) -> PyResult<f64> {
    let refused =
        || InvalidInputError::new_err(format!("{field} must be a number, got {}", shown(value)));
    if value.is_instance_of::<PyBool>() || value.is_instance_of::<pyo3::types::PyString>() {
        return Err(refused());
    }
    match value.extract::<f64>() {
        Ok(v) => Ok(v),
        Err(err) if err.is_instance_of::<pyo3::exceptions::PyOverflowError>(value.py()) => {
            Ok(if value.lt(0)? {
                f64::NEG_INFINITY
            } else {
                f64::INFINITY
            })
        }
        Err(_) => Err(refused()),
    }
}

/// [`real`] for a parameter that may be None.
pub(crate) fn real_or_none(field: &str, value: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    if value.is_none() {
        Ok(None)
    } else {
        real(field, value).map(Some)
    }
}

/// A text argument `field` (a method's or a law's name), as an
/// InvalidInputError naming the field when it is not a str.
pub(crate) fn text(field: &str, value: &Bound<'_, PyAny>) -> PyResult<String> {
    value.extract::<String>().map_err(|_| {
        InvalidInputError::new_err(format!("{field} must be a str, got {}", shown(value)))
    })
}

/// The `from_py_with` of each argument by its name: PyO3 passes no name to
/// the conversion, and its own errors (TypeErrors) are the ones it names.
macro_rules! by_name {
    ($module:ident, $convert:ident -> $out:ty: $($name:ident),* $(,)?) => {
        pub(crate) mod $module {
            use pyo3::prelude::*;
            $(
                pub(crate) fn $name(value: &Bound<'_, PyAny>) -> PyResult<$out> {
                    super::$convert(stringify!($name), value)
                }
            )*
        }
    };
}

by_name!(arg, real -> f64: approach_rate, approach_speed, area, block_time, clearance, cpu_time, damping, density, error, error_weight, forcing_period, hertz_stiffness, impact_displacement, impact_mass, impact_velocity, indentation, length, main_displacement, main_mass, main_velocity, max_cpu_time, max_error, other_poisson_ratio, other_youngs_modulus, poisson_ratio, radius, rate, record_from, second_moment, stiffness, t_end, tolerance, x, youngs_modulus);
by_name!(optional, real_or_none -> Option<f64>: atol, beta, dt, energy_tolerance, forcing_period, gamma, other_radius, position, record_from, restitution, rtol, spectral_radius, strobe_period);
by_name!(named_text, text -> String: law);

/// A flat state (`state`): a sequence of numbers, invalid input naming the
/// argument where it is not one (never a bare TypeError: None had said
/// "'None' is not an instance of 'Sequence'", a string "Can't extract `str`
/// to `Vec`").
pub(crate) fn state_arg(value: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    value.extract::<Vec<f64>>().map_err(|_| {
        InvalidInputError::new_err(format!(
            "state must be a sequence of numbers (the flat state, m and m/s), got {}",
            shown(value)
        ))
    })
}

/// `max_iterations`: a whole number >= 1 (-1 had raised an OverflowError).
pub(crate) fn max_iterations_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    whole("max_iterations", value).map(|v| usize::try_from(v).unwrap_or(usize::MAX))
}

pub(crate) fn every_arg(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole("every", value)
}

pub(crate) fn blocks_arg(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole("blocks", value)
}

pub(crate) fn max_steps_arg(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole("max_steps", value)
}

/// `max_steps`, None where left to the registry's default.
pub(crate) fn optional_max_steps(value: &Bound<'_, PyAny>) -> PyResult<Option<u64>> {
    if value.is_none() {
        Ok(None)
    } else {
        max_steps_arg(value).map(Some)
    }
}

pub(crate) fn max_rows_arg(value: &Bound<'_, PyAny>) -> PyResult<Option<u64>> {
    if value.is_none() {
        Ok(None)
    } else {
        whole("max_rows", value).map(Some)
    }
}

pub(crate) fn mode_arg(value: &Bound<'_, PyAny>) -> PyResult<u32> {
    let mode = whole("mode", value)?;
    u32::try_from(mode).map_err(|_| {
        InvalidInputError::new_err(format!("mode must be at most {}, got {mode}", u32::MAX))
    })
}

/// Which derivative of a mode shape: 0, 1, 2 or 3 (a huge int is invalid
/// input, not an OverflowError).
pub(crate) fn derivative_arg(value: &Bound<'_, PyAny>) -> PyResult<usize> {
    if value.is_instance_of::<PyBool>() {
        return Err(InvalidInputError::new_err(format!(
            "derivative must be 0, 1, 2 or 3 (an int), got {value}"
        )));
    }
    match value.extract::<i64>() {
        Ok(k @ 0..=3) => Ok(k as usize),
        Ok(_) => Err(InvalidInputError::new_err(format!(
            "derivative must be 0, 1, 2 or 3, got {value}"
        ))),
        Err(err) if err.is_instance_of::<pyo3::exceptions::PyOverflowError>(value.py()) => Err(
            InvalidInputError::new_err(format!("derivative must be 0, 1, 2 or 3, got {value}")),
        ),
        Err(err) => Err(err),
    }
}

/// The carried contacts of `PreparedSystem.run`'s `carried` (None: none).
pub(crate) fn carried_contacts(
    carried: Option<Vec<Option<[f64; 4]>>>,
) -> Vec<Option<vibroimpact_core::kernel::events::CarriedContact>> {
    carried
        .unwrap_or_default()
        .into_iter()
        .map(|c| c.map(carried_contact))
        .collect()
}

/// A carried contact from its four values (see `PreparedSystem.run`).
pub(crate) fn carried_contact(
    [approach_rate, onset, approach_speed, max_indentation]: [f64; 4],
) -> vibroimpact_core::kernel::events::CarriedContact {
    vibroimpact_core::kernel::events::CarriedContact {
        approach_rate,
        onset,
        approach_speed,
        max_indentation,
    }
}

/// A carried contact's four values (see `PreparedSystem.run`).
pub(crate) fn carried_values(c: vibroimpact_core::kernel::events::CarriedContact) -> [f64; 4] {
    [
        c.approach_rate,
        c.onset,
        c.approach_speed,
        c.max_indentation,
    ]
}
