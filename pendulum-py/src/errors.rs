//! The library's errors as Python exceptions: a bad value `ValueError`, a failed
//! computation `RuntimeError`, a run stopped by Ctrl-C `KeyboardInterrupt`, each with the
//! CLI's one-line message.

use pyo3::PyErr;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};

/// [`pendulum_experiment::Error`] as a Python exception.
pub fn run_error(e: pendulum_experiment::Error) -> PyErr {
    let message = e.to_string();
    match e {
        pendulum_experiment::Error::Invalid(_) => PyValueError::new_err(message),
        pendulum_experiment::Error::Failed(_) => PyRuntimeError::new_err(message),
        pendulum_experiment::Error::Interrupted(_) => PyKeyboardInterrupt::new_err(message),
    }
}

/// An error of the core (a bad chain, state or input) as `ValueError`.
pub fn core_error(e: pendulum_core::Error) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// `ValueError` with `message`.
pub fn invalid(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// The error of a `precision` that is neither `"float64"` nor `"float32"`.
pub fn unknown_precision(precision: &str) -> PyErr {
    invalid(format!("precision: '{precision}' is neither 'float64' nor 'float32'"))
}
