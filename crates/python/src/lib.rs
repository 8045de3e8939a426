//! # hydrocyl-python — the `hydrocyl` Python package
//!
//! PyO3 bindings of hydrocyl for numpy users, built by maturin into one
//! abi3 wheel (CPython >= 3.9). It models nothing itself: it exposes the
//! rig facade of `hydrocyl-system` (rig files and presets, `--set` paths,
//! runs), the energy ledger of `hydrocyl-energy` (eqs 8.1–8.12), Leaney's X
//! factor of `hydrocyl-xfactor` (eqs 3.4–3.30) and the measured-data loop
//! of `hydrocyl-identify`, mirroring the `hydrocyl` CLI:
//!
//! ```python
//! import numpy as np, hydrocyl
//! rig = hydrocyl.Rig.load("leaney-moog")            # preset or rig file
//! rig.set("load.mass", 50)                           # a --set path
//! t = np.linspace(0, 0.5, 501); u = np.where(t < 0.05, 0.0, 0.5)
//! run = rig.simulate(t, u, solver="dp45", rtol=1e-6)
//! run["position"]                                    # numpy array [m]
//! batch = hydrocyl.simulate_batch(rig, t, u, {"load.mass": np.linspace(50, 150, 64)})
//! ```
//!
//! Errors: ValueError with the CLI's one-line message for bad input,
//! `hydrocyl.SimulationError` for a solver failure (time and state in the
//! message), RuntimeError for a caught panic (a bug); a run kept although a
//! chamber's constant-B oil left its range warns with
//! `hydrocyl.CavitationWarning`, one whose command is beyond the spool's
//! stroke or the pump's rating with `hydrocyl.RatingWarning`; array
//! arguments are real numbers in any layout (`convert::real_array`). The
//! GIL is released
//! while Rust runs; `simulate_batch` runs its parameter sets on rayon's
//! threads. The type stubs are `hydrocyl.pyi` beside this crate's manifest;
//! the pytest suite is `tests/` (`cargo xtask test` builds the wheel and
//! runs it).

mod batch;
mod convert;
mod diagnose;
mod errors;
mod rig;
mod run;
mod sim;
mod xfactor;

use pyo3::prelude::*;

/// Panics on purpose, for the test that a panic becomes a RuntimeError
/// rather than unwinding into the interpreter.
#[pyfunction]
fn _panic_for_test(py: Python<'_>) -> PyResult<()> {
    errors::detached(py, || -> errors::Outcome<()> {
        panic!("deliberate test panic")
    })
}

/// The `hydrocyl` module.
#[pymodule]
fn hydrocyl(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add(
        "SimulationError",
        m.py().get_type::<errors::SimulationError>(),
    )?;
    m.add(
        "CavitationWarning",
        m.py().get_type::<errors::CavitationWarning>(),
    )?;
    m.add("RatingWarning", m.py().get_type::<errors::RatingWarning>())?;
    m.add(
        "ParameterWarning",
        m.py().get_type::<errors::ParameterWarning>(),
    )?;
    m.add_class::<rig::Rig>()?;
    m.add_class::<run::PyRun>()?;
    m.add_class::<batch::PyBatch>()?;
    m.add_function(wrap_pyfunction!(batch::simulate_batch, m)?)?;
    m.add_function(wrap_pyfunction!(xfactor::xfactor, m)?)?;
    m.add_function(wrap_pyfunction!(diagnose::diagnose, m)?)?;
    m.add_function(wrap_pyfunction!(_panic_for_test, m)?)?;
    m.add("PRESETS", rig::Rig::preset_names())?;
    m.add("MAX_THREADS", batch::MAX_THREADS)?;
    Ok(())
}
