//! `hydrocyl.xfactor`: Leaney's X factor (thesis eqs 3.4–3.30, crate
//! `hydrocyl-xfactor`) over an array of spool travels.

use crate::convert::{args, real_array};
use crate::errors::{detached, Failure};
use hydrocyl_xfactor::XFactorError;
use numpy::{IntoPyArray, PyArrayDyn};
use pyo3::prelude::*;

/// Leaney's X factor for the cylinder area ratio `gamma` = A1/A2 (>= 1) at
/// each normalised spool travel in `travel` (spool position / underlap:
/// -1..1 is inside the underlap, beyond it X is 1 or gamma²). Returns an
/// array of `travel`'s shape (dimensionless). ValueError (the CLI's message)
/// for a gamma below 1 or not finite, or a NaN travel.
#[pyfunction]
pub fn xfactor<'py>(
    py: Python<'py>,
    #[pyo3(from_py_with = args::gamma)] gamma: f64,
    travel: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArrayDyn<f64>>> {
    let travel = real_array("travel", "an array of numbers", travel)?;
    let x = detached(py, || {
        let mut out = travel.clone();
        for (i, (o, t)) in out.iter_mut().zip(travel.iter()).enumerate() {
            *o = hydrocyl_xfactor::x_factor_checked(gamma, *t).map_err(|e| {
                Failure::Input(match e {
                    XFactorError::GammaOutOfRange { .. } => format!("xfactor: {e}"),
                    _ => format!("xfactor: travel[{i}]: {e}"),
                })
            })?;
        }
        Ok(out)
    })?;
    Ok(x.into_pyarray(py))
}
