//! The Python exceptions, the mapping of core errors onto them, and runs
//! with the GIL released.

use pyo3::create_exception;
use pyo3::exceptions::{
    PyArithmeticError, PyKeyboardInterrupt, PyRuntimeError, PyUserWarning, PyValueError,
};
use pyo3::prelude::*;
use vibroimpact_core as core;
// The module path makes the exceptions picklable (e.g. from worker processes).
create_exception!(
    vibroimpact._core,
    InvalidInputError,
    PyValueError,
    "An input is outside what the model allows; the message names the field."
);
create_exception!(
    vibroimpact._core,
    NumericalBlowUpError,
    PyArithmeticError,
    "The integration blew up (non-finite state or energy created from nothing)."
);

create_exception!(
    vibroimpact._core,
    EnergyBalanceError,
    NumericalBlowUpError,
    "The result would be physically impossible: its energy balance does not close, or a contact \
     created energy (beyond energy_tolerance)."
);

create_exception!(
    vibroimpact._core,
    SimulationError,
    PyRuntimeError,
    "The run could not go on: chattering, Newton failure, step size at round-off, or too many steps."
);
create_exception!(
    vibroimpact._core,
    RestitutionWarning,
    PyUserWarning,
    "The contact law will not rebound at the restitution it was given."
);

pub(crate) fn to_py(err: core::Error) -> PyErr {
    use core::Error as E;
    let message = short_numbers(&err.to_string());
    match err {
        E::NumericalBlowUp { .. } | E::UnresolvedContact { .. } => {
            NumericalBlowUpError::new_err(message)
        }
        E::EnergyBalance { .. } | E::ContactEnergy { .. } => EnergyBalanceError::new_err(message),
        E::Interrupted { .. } => PyKeyboardInterrupt::new_err(message),
        E::NewtonFailed { .. }
        | E::Chattering { .. }
        | E::StepSizeTooSmall { .. }
        | E::TooManySteps { .. }
        | E::RowLimit { .. }
        | E::MemoryLimit { .. } => SimulationError::new_err(message),
        E::InvalidParameter { .. } | E::UnknownChoice { .. } | E::Inconsistent(_) => {
            InvalidInputError::new_err(message)
        }
    }
}

/// Runs `work` with the GIL released, giving it a question to ask now and
/// then: has Ctrl-C been pressed? An interruption becomes the Python
/// exception (KeyboardInterrupt) that caused it, even where the work ended
/// all the same; other errors map by kind.
pub(crate) fn released<T, F>(py: Python<'_>, work: F) -> PyResult<T>
where
    T: Send,
    F: FnOnce(&mut dyn FnMut() -> bool) -> core::Result<T> + Send,
{
    let mut signal: Option<PyErr> = None;
    let result = py.detach(|| {
        work(&mut || match Python::attach(|py| py.check_signals()) {
            Ok(()) => false,
            Err(e) => {
                signal = Some(e);
                true
            }
        })
    });
    // A signal seen is the caller's stop whatever the work's end: checking
    // ran its handler, so Python will not see it again (a study's watcher may
    // see it after the last run has finished; taken as a result, the study
    // had gone on to write over the earlier output).
    match (signal, result) {
        (Some(stop), _) => Err(stop),
        (None, Ok(value)) => Ok(value),
        (None, Err(e)) => Err(to_py(e)),
    }
}

/// `text` with every number the core wrote in full (`{}` of 1e-300 is a fraction of
/// 300 zeros, of 1e300 a 301-digit integer) rewritten as Python's repr writes it
/// (`1e-300`, `1e+300`): a number standing alone (not part of a word or a longer
/// number) of 21 or more integer digits, or a fraction with 6 or more leading zeros.
/// The same rule as `vibroimpact.messages.short_numbers`.
pub(crate) fn short_numbers(text: &str) -> String {
    let bytes = text.as_bytes();
    let word = |b: u8| b.is_ascii_alphanumeric() || b == b'_';
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < bytes.len() {
        let sign = usize::from(bytes[i] == b'-');
        let alone = i == 0 || !(word(bytes[i - 1]) || bytes[i - 1] == b'.');
        if alone && bytes.get(i + sign).is_some_and(u8::is_ascii_digit) {
            let digits = i + sign;
            let mut end = digits;
            while bytes.get(end).is_some_and(u8::is_ascii_digit) {
                end += 1;
            }
            let whole = end - digits;
            let mut zeros = 0;
            if bytes.get(end) == Some(&b'.') && bytes.get(end + 1).is_some_and(u8::is_ascii_digit) {
                let mut k = end + 1;
                while bytes.get(k) == Some(&b'0') {
                    k += 1;
                }
                zeros = k - end - 1;
                while bytes.get(k).is_some_and(u8::is_ascii_digit) {
                    k += 1;
                }
                end = k;
            }
            let ends = match bytes.get(end) {
                None => true,
                Some(&b'.') => !bytes.get(end + 1).is_some_and(u8::is_ascii_digit),
                Some(&b) => !word(b),
            };
            let long = whole >= 21 || (whole == 1 && bytes[digits] == b'0' && zeros >= 6);
            match text[i..end].parse::<f64>() {
                Ok(value) if ends && long => out.push_str(&python_repr(value)),
                _ => out.push_str(&text[i..end]),
            }
            i = end;
        } else {
            let c = text[i..].chars().next().unwrap_or(' ');
            out.push(c);
            i += c.len_utf8();
        }
    }
    out
}

/// A float in exponent form as Python's repr writes it: the shortest digits that
/// read back the same, a sign and at least two digits in the exponent (`1e+300`,
/// `1.5e-07`).
fn python_repr(value: f64) -> String {
    let text = format!("{value:e}");
    match text.split_once('e') {
        Some((mantissa, exponent)) => {
            let power: i32 = exponent.parse().unwrap_or(0);
            let sign = if power < 0 { '-' } else { '+' };
            format!("{mantissa}e{sign}{:02}", power.unsigned_abs())
        }
        None => text,
    }
}
