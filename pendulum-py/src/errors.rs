//! The library's errors as Python exceptions: a bad value `ValueError`, a failed
//! computation `RuntimeError`, a run stopped by Ctrl-C `KeyboardInterrupt`, each with the
//! CLI's one-line message, the options it names spelled as keyword arguments.

use pyo3::PyErr;
use pyo3::exceptions::{PyKeyboardInterrupt, PyRuntimeError, PyValueError};

/// [`pendulum_experiment::Error`] as a Python exception.
pub fn run_error(e: pendulum_experiment::Error) -> PyErr {
    let message = e.message(pendulum_experiment::Front::Python);
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

/// An error of a call on many states: the core's error, and the state it came from (its
/// row in the call's table) if it is one state's.
#[derive(Debug)]
pub struct StatesError {
    state: Option<usize>,
    error: pendulum_core::Error,
}

impl StatesError {
    /// `error` of the state in row `state`.
    pub fn of_state(state: usize, error: pendulum_core::Error) -> Self {
        Self { state: Some(state), error }
    }

    /// As `ValueError`, a state's error naming the state by its numpy index in arrays of
    /// leading shape `lead` ("state (1, 0): link 2 sits at …"); the error alone for a call
    /// on one state (`lead` empty) or of the call as a whole.
    pub fn named(self, lead: &[usize]) -> PyErr {
        match self.state {
            Some(row) if !lead.is_empty() => {
                invalid(format!("state {}: {}", numpy_index(row, lead), self.error))
            }
            _ => core_error(self.error),
        }
    }
}

/// An error of the call as a whole (its chain, its sizes), no state's.
impl From<pendulum_core::Error> for StatesError {
    fn from(error: pendulum_core::Error) -> Self {
        Self { state: None, error }
    }
}

/// A result of a call on many states.
pub type StatesResult<T> = Result<T, StatesError>;

/// Row `row` of a C-ordered array with leading shape `lead`, as numpy writes its index:
/// `(1, 2)`; a single leading axis as `4`, none as `0`.
pub fn numpy_index(mut row: usize, lead: &[usize]) -> String {
    let mut index = vec![0; lead.len()];
    for (i, &extent) in lead.iter().enumerate().rev() {
        (index[i], row) = (row % extent.max(1), row / extent.max(1));
    }
    match index.as_slice() {
        [] => "0".to_string(),
        [i] => i.to_string(),
        more => format!("({})", more.iter().map(usize::to_string).collect::<Vec<_>>().join(", ")),
    }
}

/// `ValueError` with `message`.
pub fn invalid(message: impl Into<String>) -> PyErr {
    PyValueError::new_err(message.into())
}

/// The error of a `precision` that is neither `"float64"` nor `"float32"`.
pub fn unknown_precision(precision: &str) -> PyErr {
    invalid(format!("precision: '{precision}' is neither 'float64' nor 'float32'"))
}
