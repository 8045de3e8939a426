//! `hydrocyl.Run`: one run's named numpy arrays (the columns `hydrocyl
//! simulate` writes), solver statistics, component counters and the energy
//! ledger.

use crate::convert::{array, json_to_py, Named};
use crate::sim::Simulated;
use hydrocyl_energy::ledger::Ledger;
use numpy::PyArray1;
use pyo3::exceptions::{PyImportError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyIterator, PyList};

/// A run: `time` [s] and one array per channel, SI units (`units` names
/// them): `command`, `position` [m], `velocity` [m/s], `p1`, `p2` [Pa gauge],
/// then the rig's other outputs. `run["position"]` is a channel.
#[pyclass(module = "hydrocyl", name = "Run", frozen)]
pub struct PyRun {
    time: Py<PyArray1<f64>>,
    n: usize,
    channels: Named<PyArray1<f64>>,
    units: Vec<&'static str>,
    stats: Vec<(&'static str, f64)>,
    diagnostics: Vec<(String, f64)>,
    ledger: Option<Result<Ledger, String>>,
}

/// The ledger as a dict: [`Ledger::to_json`], the object `hydrocyl
/// simulate --ledger` writes (energies in J, fractions dimensionless).
fn ledger_dict<'py>(py: Python<'py>, l: &Ledger) -> PyResult<Bound<'py, PyAny>> {
    json_to_py(py, &l.to_json())
}

impl PyRun {
    /// Wraps a finished run (needs the GIL: makes the numpy arrays); its
    /// channels' units are the CLI header's (the input's is the unit its
    /// readers take it in, `Circuit::set_probe_unit`).
    pub fn new(py: Python<'_>, s: Simulated) -> PyResult<Self> {
        let r = s.run;
        let st = &r.stats;
        Ok(Self {
            n: r.time.len(),
            time: array(py, r.time).unbind(),
            units: r.channels.iter().map(|c| c.unit).collect(),
            channels: Named {
                names: r.channels.iter().map(|c| c.name.clone()).collect(),
                values: r
                    .channels
                    .into_iter()
                    .map(|c| array(py, c.values).unbind())
                    .collect(),
            },
            stats: vec![
                ("steps", st.steps as f64),
                ("rejected", st.rejected as f64),
                ("rhs_evals", st.rhs_evals as f64),
                ("jac_evals", st.jac_evals as f64),
                ("lu_decomps", st.lu_decomps as f64),
                ("events", st.events as f64),
                ("wall_s", r.wall.as_secs_f64()),
            ],
            diagnostics: r.diagnostics,
            ledger: s.ledger,
        })
    }
}

#[pymethods]
impl PyRun {
    /// Output times [s] (the `t` given).
    #[getter]
    fn time(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.time.clone_ref(py)
    }

    /// Channel names, in the CLI's column order.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.channels.names.clone()
    }

    /// `{channel: numpy array}` (the arrays themselves, not copies).
    #[getter]
    fn channels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.channels.dict(py)
    }

    /// `{channel: SI unit}` (`Pa` is gauge pressure, `1` dimensionless).
    #[getter]
    fn units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (n, u) in self.channels.names.iter().zip(&self.units) {
            d.set_item(n, *u)?;
        }
        Ok(d)
    }

    /// Solver statistics: `steps`, `rejected`, `rhs_evals`, `jac_evals`,
    /// `lu_decomps`, `events` (counts) and `wall_s` (solve time [s]).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.stats {
            if *k == "wall_s" {
                d.set_item(k, v)?;
            } else {
                d.set_item(k, *v as u64)?;
            }
        }
        Ok(d)
    }

    /// Component counters `{<component>.<counter>: value}` (cavitation
    /// entries, end-stop impacts, X-factor evaluations).
    #[getter]
    fn diagnostics<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.diagnostics {
            d.set_item(k, v)?;
        }
        Ok(d)
    }

    /// The energy ledger over the whole run (`simulate(..., ledger=True)`),
    /// else None: the object `hydrocyl simulate --ledger` writes
    /// (`Ledger::to_json`): `components_j` (each component's `source`,
    /// `dissipated`, `storage`, `load`, `moved` [J]) and `totals_j`,
    /// `energy_in_j`, `load_out_j`, `cylinder_out_j`,
    /// `losses_j`/`sources_j`/`storage_j` by component [J],
    /// `stored_change_from_states_j`, `moving_walls_j` [J], the balance
    /// `closure_j` and `closure_relative` (= `error`), the
    /// `storage_check_j` and `storage_check_relative` (= `storage_error`),
    /// fractions of the energy in, and `efficiency` (cylinder output /
    /// energy in). ValueError when the run has no energy in to account for.
    #[getter]
    fn ledger<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match &self.ledger {
            None => Ok(None),
            Some(Ok(l)) => ledger_dict(py, l).map(Some),
            Some(Err(e)) => Err(PyValueError::new_err(format!("ledger: {e}"))),
        }
    }

    fn __getitem__(&self, py: Python<'_>, name: &str) -> PyResult<Py<PyArray1<f64>>> {
        if name == "time" {
            return Ok(self.time.clone_ref(py));
        }
        self.channels.get(py, name)
    }

    fn __contains__(&self, name: &str) -> bool {
        name == "time" || self.channels.contains(name)
    }

    /// The channel names (`time` is `run.time`).
    fn keys(&self) -> Vec<String> {
        self.channels.names.clone()
    }

    /// Iterates over the channel names, as a dict over its keys.
    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyIterator>> {
        PyList::new(py, &self.channels.names)?.try_iter()
    }

    /// A pandas DataFrame with `time` and every channel as columns (the
    /// CLI's CSV). Needs pandas, which hydrocyl does not require:
    /// ImportError without it.
    fn to_pandas<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let pd = py.import("pandas").map_err(|e| {
            PyImportError::new_err(format!(
                "Run.to_pandas needs pandas ({e}); the arrays are in run.time and run.channels"
            ))
        })?;
        let d = PyDict::new(py);
        d.set_item("time", self.time.clone_ref(py))?;
        d.update(self.channels.dict(py)?.as_mapping())?;
        pd.getattr("DataFrame")?.call1((d,))
    }

    fn __repr__(&self) -> String {
        format!(
            "Run({} samples, channels: {})",
            self.n,
            self.channels.names.join(", ")
        )
    }
}
