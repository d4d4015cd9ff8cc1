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
    let message = err.to_string();
    match err {
        E::NumericalBlowUp { .. } => NumericalBlowUpError::new_err(message),
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
/// exception (KeyboardInterrupt) that caused it; other errors map by kind.
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
    match result {
        Ok(value) => Ok(value),
        Err(core::Error::Interrupted { .. }) if signal.is_some() => {
            Err(signal.take().expect("checked"))
        }
        Err(e) => Err(to_py(e)),
    }
}
