//! How failures cross into Python: bad input is a `ValueError` carrying the
//! CLI's one-line message, a solver failure a [`SimulationError`] with the
//! time and the state where it stopped, and a Rust panic (a bug) a
//! `RuntimeError` — never an unwinding panic through the interpreter. A run
//! that is kept but left its model's range warns with a
//! [`CavitationWarning`] ([`warn_cavitation`]).

use pyo3::exceptions::{PyException, PyRuntimeError, PyUserWarning, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::panic::{catch_unwind, AssertUnwindSafe};

pyo3::create_exception!(
    hydrocyl,
    SimulationError,
    PyException,
    "The solver failed (step size too small, too many steps, a non-finite state). \
     The message names the method, the time and the state where it stopped; \
     the attributes `time` [s] and `state` (dict: state name -> value, SI) hold them."
);

pyo3::create_exception!(
    hydrocyl,
    CavitationWarning,
    PyUserWarning,
    "A chamber pressure fell far below absolute vacuum (below -10 bar gauge) \
     without the run blowing up: the oil, a liquid of constant bulk modulus, \
     has left its range there (the chamber cavitates). The run is returned; \
     the message names the chamber, its lowest pressure and the remedy \
     (entrained air, where the cylinder's type has it)."
);

/// Warns with `message` as a [`CavitationWarning`] (an error when the
/// warning filters make it one).
pub fn warn_cavitation(py: Python<'_>, message: &str) -> PyResult<()> {
    let message = std::ffi::CString::new(message.replace('\0', " "))
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    PyErr::warn(py, py.get_type::<CavitationWarning>().as_any(), &message, 1)
}

/// A failure on the Rust side, before it becomes a Python exception (kept
/// free of Python objects so that it can leave a `detach`ed closure).
#[derive(Debug, Clone, PartialEq)]
pub enum Failure {
    /// Bad input: the CLI's one-line message.
    Input(String),
    /// The solver failed: the message, the time \[s\] it reached and the
    /// state there (name, value).
    Solver {
        /// One line: method, what happened, time and state.
        message: String,
        /// Time reached \[s\] (`NaN` if unknown).
        time: f64,
        /// The state at `time`, by state name (SI).
        state: Vec<(String, f64)>,
    },
    /// A panic caught at the boundary (a bug in hydrocyl).
    Panic(String),
}

impl Failure {
    /// Prefixes the message (e.g. with the batch row that failed).
    pub fn context(self, what: &str) -> Self {
        match self {
            Failure::Input(m) => Failure::Input(format!("{what}: {m}")),
            Failure::Solver {
                message,
                time,
                state,
            } => Failure::Solver {
                message: format!("{what}: {message}"),
                time,
                state,
            },
            Failure::Panic(m) => Failure::Panic(format!("{what}: {m}")),
        }
    }

    /// The message alone.
    pub fn message(&self) -> &str {
        match self {
            Failure::Input(m) | Failure::Panic(m) => m,
            Failure::Solver { message, .. } => message,
        }
    }

    /// The Python exception.
    pub fn into_pyerr(self, py: Python<'_>) -> PyErr {
        match self {
            Failure::Input(m) => PyValueError::new_err(m),
            Failure::Panic(m) => PyRuntimeError::new_err(format!(
                "hydrocyl internal error (a bug, please report it): {m}"
            )),
            Failure::Solver {
                message,
                time,
                state,
            } => {
                let err = SimulationError::new_err(message);
                // Attributes are best effort: the message already says it all.
                let value = err.value(py);
                let _ = value.setattr("time", time);
                let d = PyDict::new(py);
                for (k, v) in &state {
                    let _ = d.set_item(k, v);
                }
                let _ = value.setattr("state", d);
                err
            }
        }
    }
}

/// Result of the Rust side of a call.
pub type Outcome<T> = Result<T, Failure>;

/// Runs `f`, turning a panic into [`Failure::Panic`] (the last resort: every
/// expected failure is a `Failure` already).
pub fn guard<T>(f: impl FnOnce() -> Outcome<T>) -> Outcome<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => Err(Failure::Panic(
            payload
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "panic".into()),
        )),
    }
}

/// Runs `f` with the GIL released (the interpreter's other threads go on),
/// guarded against panics, and turns a failure into its exception.
pub fn detached<T: Send>(py: Python<'_>, f: impl FnOnce() -> Outcome<T> + Send) -> PyResult<T> {
    py.detach(|| guard(f)).map_err(|e| e.into_pyerr(py))
}
