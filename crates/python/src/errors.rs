//! How failures cross into Python: bad input is a `ValueError` carrying the
//! CLI's one-line message, a solver failure a [`SimulationError`] with the
//! time and the state where it stopped, and a Rust panic (a bug) a
//! `RuntimeError` — never an unwinding panic through the interpreter. A run
//! that is kept but left its model's range warns with a
//! [`CavitationWarning`], one whose command is beyond the pump's rating
//! with a [`RatingWarning`] ([`RunWarning`]).

use pyo3::exceptions::{
    PyException, PyKeyboardInterrupt, PyRuntimeError, PyUserWarning, PyValueError,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

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

pyo3::create_exception!(
    hydrocyl,
    RatingWarning,
    PyUserWarning,
    "The command goes beyond the limit of what the run's input drives: \
     samples of a normalised spool demand outside +-1 (the spool's stroke, \
     where the valve clamps them), or past the maximum speed of a pump \
     driven in volts (its `displacement` and `max_speed`; the pump is not \
     limited to it, its flow follows the command). The run is returned. The \
     message is the CLI's warning (`hydrocyl simulate`): the count of \
     samples beyond, the largest and when (for a pump, the rated speed and \
     the command reaching it); a batch names the run."
);

pyo3::create_exception!(
    hydrocyl,
    ParameterWarning,
    PyUserWarning,
    "A rig parameter inside its range but far outside what real rigs have \
     (a bulk modulus of 7000 Pa, a bore area of 1963 m^2, an oil density of \
     0.87 kg/m^3): the mark of a value written in another unit (bar, mm^2, \
     g/cm^3), which runs and gives consistent nonsense. The run is returned; \
     the message names the parameter by its path, the usual span and the \
     unit the value was likely meant in (the CLI's warning)."
);

/// A warning a run that is returned leaves, raised with Python's
/// `warnings.warn` once the run is (once per run; in a batch, naming it).
#[derive(Debug, Clone, PartialEq)]
pub enum RunWarning {
    /// The command beyond the spool's stroke or the rating of the pump
    /// the input drives (`CommandLimit::check`): a [`RatingWarning`].
    Rating(String),
    /// A chamber far below vacuum in a run that did not blow up: a
    /// [`CavitationWarning`].
    Cavitation(String),
    /// A parameter far outside what real rigs have (a unit slip,
    /// `netlist::implausible`): a [`ParameterWarning`].
    Parameter(String),
}

impl RunWarning {
    /// Prefixes the message (e.g. with the batch row it is of).
    pub fn context(self, what: &str) -> Self {
        match self {
            RunWarning::Rating(m) => RunWarning::Rating(format!("{what}: {m}")),
            RunWarning::Cavitation(m) => RunWarning::Cavitation(format!("{what}: {m}")),
            RunWarning::Parameter(m) => RunWarning::Parameter(format!("{what}: {m}")),
        }
    }

    /// Warns with it (an error when the warning filters make it one).
    pub fn warn(&self, py: Python<'_>) -> PyResult<()> {
        let (category, message) = match self {
            RunWarning::Rating(m) => (py.get_type::<RatingWarning>(), m),
            RunWarning::Cavitation(m) => (py.get_type::<CavitationWarning>(), m),
            RunWarning::Parameter(m) => (py.get_type::<ParameterWarning>(), m),
        };
        let message = std::ffi::CString::new(message.replace('\0', " "))
            .map_err(|e| PyValueError::new_err(e.to_string()))?;
        PyErr::warn(py, category.as_any(), &message, 1)
    }
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
    /// The run was stopped by a signal (Ctrl-C): Python's own exception
    /// (KeyboardInterrupt) is raised in its place ([`interruptible`]).
    Interrupted,
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
            Failure::Interrupted => Failure::Interrupted,
        }
    }

    /// The message alone.
    pub fn message(&self) -> &str {
        match self {
            Failure::Input(m) | Failure::Panic(m) => m,
            Failure::Solver { message, .. } => message,
            Failure::Interrupted => "interrupted",
        }
    }

    /// The Python exception.
    pub fn into_pyerr(self, py: Python<'_>) -> PyErr {
        match self {
            Failure::Input(m) => PyValueError::new_err(m),
            Failure::Interrupted => PyKeyboardInterrupt::new_err("interrupted"),
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

/// How often a run started by [`interruptible`] lets Python handle its
/// signals (wall time).
const SIGNAL_POLL: Duration = Duration::from_millis(25);

/// Stack of the thread a run goes on: the main thread's usual 8 MiB.
const RUN_STACK: usize = 8 << 20;

/// The flag that stops a run ([`hydrocyl_system::simulation::Simulation::stop_on`]).
pub type Stop = Arc<AtomicBool>;

/// Whether `stop` has been set.
pub fn stopped(stop: &Stop) -> bool {
    stop.load(Ordering::Relaxed)
}

/// How an [`interruptible`] call ended.
enum Ended<T> {
    /// `f` returned.
    Done(Outcome<T>),
    /// A signal handler raised (KeyboardInterrupt for SIGINT); `f` was
    /// stopped and has returned.
    Signal(PyErr),
}

/// [`detached`] for a long run that Ctrl-C must be able to stop: `f` runs
/// on a thread of its own with the GIL released, while the calling thread
/// waits for it and every [`SIGNAL_POLL`] takes the GIL to let Python run
/// its signal handlers (`PyErr_CheckSignals`, which does anything only on
/// the main thread). When a handler raises (KeyboardInterrupt), `stop` is
/// set, `f` — which passes it to its runs, read once a solver step — ends
/// within a step, its thread is joined, and the handler's exception is
/// raised: no thread is left running.
pub fn interruptible<T: Send>(
    py: Python<'_>,
    f: impl FnOnce(&Stop) -> Outcome<T> + Send,
) -> PyResult<T> {
    let stop: Stop = Arc::new(AtomicBool::new(false));
    let ended = py.detach(|| {
        std::thread::scope(|s| {
            let (tx, rx) = mpsc::channel();
            let worker_stop = Arc::clone(&stop);
            let spawned = std::thread::Builder::new()
                .name("hydrocyl-run".into())
                .stack_size(RUN_STACK)
                .spawn_scoped(s, move || {
                    let _ = tx.send(guard(|| f(&worker_stop)));
                });
            if let Err(e) = spawned {
                return Ended::Done(Err(Failure::Panic(format!(
                    "cannot start the run's thread: {e}"
                ))));
            }
            loop {
                match rx.recv_timeout(SIGNAL_POLL) {
                    Ok(r) => return Ended::Done(r),
                    Err(RecvTimeoutError::Disconnected) => {
                        return Ended::Done(Err(Failure::Panic(
                            "the run's thread ended without a result".into(),
                        )))
                    }
                    Err(RecvTimeoutError::Timeout) => {
                        if let Err(e) = Python::attach(|py| py.check_signals()) {
                            stop.store(true, Ordering::Relaxed);
                            // the scope joins the run's thread, which
                            // returns at its next step
                            return Ended::Signal(e);
                        }
                    }
                }
            }
        })
    });
    match ended {
        Ended::Done(r) => r.map_err(|e| e.into_pyerr(py)),
        Ended::Signal(e) => Err(e),
    }
}
