//! Argument conversions shared by the functions: whole numbers and floats
//! from Python ints of any size, as InvalidInputError naming the field.

use pyo3::prelude::*;

use crate::errors::InvalidInputError;

/// `value` as Python shows it, cut short for a one-line message.
fn shown(value: &Bound<'_, PyAny>) -> String {
    let text = value
        .repr()
        .map(|r| r.to_string())
        .unwrap_or_else(|_| "?".into());
    if text.chars().count() > 60 {
        let head: String = text.chars().take(57).collect();
        format!("{head}...")
    } else {
        text
    }
}

/// A whole number >= 1 from a Python int; one too large or too small for the
/// core is an InvalidInputError naming the field, not an OverflowError.
pub(crate) fn whole(field: &str, value: &Bound<'_, PyAny>) -> PyResult<u64> {
    // A float (1e9, 2.5, nan), a string or an int out of range: all invalid
    // input naming the field, never a bare TypeError or OverflowError.
    match value.extract::<i64>() {
        Ok(v) if v >= 1 => Ok(v as u64),
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

/// A float argument (the `from_py_with` of every float parameter). A Python
/// int beyond the range of a float (`10**400`) becomes an infinity of its
/// sign, as a float computation beyond the range would, instead of an
/// OverflowError: the core then refuses it like any non-finite value, in an
/// InvalidInputError that names the field.
pub(crate) fn real(value: &Bound<'_, PyAny>) -> PyResult<f64> {
    match value.extract::<f64>() {
        Ok(v) => Ok(v),
        Err(err) if err.is_instance_of::<pyo3::exceptions::PyOverflowError>(value.py()) => {
            Ok(if value.lt(0)? {
                f64::NEG_INFINITY
            } else {
                f64::INFINITY
            })
        }
        Err(err) => Err(err),
    }
}

/// [`real`] for a parameter that may be None.
pub(crate) fn real_or_none(value: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
    if value.is_none() {
        Ok(None)
    } else {
        real(value).map(Some)
    }
}

pub(crate) fn every_arg(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole("every", value)
}

pub(crate) fn max_steps_arg(value: &Bound<'_, PyAny>) -> PyResult<u64> {
    whole("max_steps", value)
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
