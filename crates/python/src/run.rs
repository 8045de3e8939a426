//! `hydrocyl.Run`: one run's named numpy arrays (the columns `hydrocyl
//! simulate` writes), solver statistics, component counters and the energy
//! ledger.

use crate::convert::{array, frozen, json_to_py, py_to_json, readable, Named};
use crate::sim::Simulated;
use hydrocyl_energy::ledger::Ledger;
use numpy::{
    IntoPyArray, PyArray1, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyImportError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyIterator, PyList, PyTuple};
use serde_json::Value;

/// A run: `time` [s] and one array per channel, SI units (`units` names
/// them): `command`, `position` [m], `velocity` [m/s], `p1`, `p2` [Pa gauge],
/// then the rig's other outputs. `run["position"]` is a channel.
///
/// The arrays are read-only (numpy `flags.writeable` is False): they are
/// the run's own, handed out without copying. A run pickles (for Dask and
/// multiprocessing) and unpickles equal bit for bit.
#[pyclass(module = "hydrocyl", name = "Run", frozen)]
pub struct PyRun {
    time: Py<PyArray1<f64>>,
    n: usize,
    channels: Named<PyArray1<f64>>,
    stats: Vec<(String, f64)>,
    diagnostics: Vec<(String, f64)>,
    /// [`Ledger::to_json`], or why there is no ledger; `None` unless asked.
    ledger: Option<Result<Value, String>>,
}

/// A pickled run's state that is not one: a ValueError saying so.
fn bad_state(what: &str) -> PyErr {
    PyValueError::new_err(format!("not the pickled state of a hydrocyl.Run: {what}"))
}

/// The array `x` of a pickled state (element type `T`, dimension `D`),
/// copied into an array of the result's own, read-only as a fresh result's
/// ([`frozen`]; an unpickled array may be a view of a writable buffer). It
/// is read through [`readable`]: an unpickled array is often unaligned (and
/// may be big-endian, from another machine), which is read as its values.
/// An array of another kind of element (not float for `f64`, not bool for
/// `bool`) or of another dimension is not a pickled result's.
pub fn state_array<T: numpy::Element, D: numpy::ndarray::Dimension>(
    x: &Bound<'_, PyAny>,
    what: &str,
    bad: fn(&str) -> PyErr,
) -> PyResult<Py<numpy::PyArray<T, D>>> {
    let wrong = || {
        bad(&format!(
            "`{what}` is not an array of the right type and shape"
        ))
    };
    let kind = numpy::dtype::<T>(x.py()).kind();
    let same_kind = x
        .cast::<PyUntypedArray>()
        .is_ok_and(|a| a.dtype().kind() == kind);
    if !same_kind {
        return Err(wrong());
    }
    let a = readable::<T, D>(x).map_err(|_| wrong())?;
    frozen(a.to_owned_array().into_pyarray(x.py()))
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
            time: array(py, r.time)?,
            channels: Named {
                names: r.channels.iter().map(|c| c.name.clone()).collect(),
                units: r.channels.iter().map(|c| c.unit.to_string()).collect(),
                values: r
                    .channels
                    .into_iter()
                    .map(|c| array(py, c.values))
                    .collect::<PyResult<_>>()?,
            },
            stats: [
                ("steps", st.steps as f64),
                ("rejected", st.rejected as f64),
                ("rhs_evals", st.rhs_evals as f64),
                ("jac_evals", st.jac_evals as f64),
                ("lu_decomps", st.lu_decomps as f64),
                ("events", st.events as f64),
                ("wall_s", r.wall.as_secs_f64()),
            ]
            .map(|(k, v)| (k.to_string(), v))
            .into(),
            diagnostics: r.diagnostics,
            ledger: s.ledger.map(|l| l.map(|l: Ledger| l.to_json())),
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

    /// `{channel: numpy array}` (the arrays themselves, not copies:
    /// read-only).
    #[getter]
    fn channels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.channels.dict(py)
    }

    /// `{channel: SI unit}`, the CLI header's (`Pa` is gauge pressure, `-`
    /// dimensionless; `command` in `V` on a pump rig).
    #[getter]
    fn units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.channels.units_dict(py)
    }

    /// Solver statistics: `steps`, `rejected`, `rhs_evals`, `jac_evals`,
    /// `lu_decomps`, `events` (counts) and `wall_s` (solve time [s]).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.stats {
            if k == "wall_s" {
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
    /// fractions of `reference_j` (the energy in; where none comes in, the
    /// largest other term), and `efficiency` (cylinder output / energy in;
    /// None where no energy comes in). ValueError when the ledger cannot be
    /// taken (an energy that is not finite).
    #[getter]
    fn ledger<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyAny>>> {
        match &self.ledger {
            None => Ok(None),
            Some(Ok(l)) => json_to_py(py, l).map(Some),
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

    /// Pickles as its state ([`PyRun::_from_state`]): the arrays (numpy
    /// pickles them bit for bit), names, units, statistics, counters and
    /// the ledger.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let d = PyDict::new(py);
        d.set_item("time", self.time.clone_ref(py))?;
        self.channels.pickle_into(&d)?;
        d.set_item("stats", self.stats.clone())?;
        d.set_item("diagnostics", self.diagnostics.clone())?;
        match &self.ledger {
            None => d.set_item("ledger", py.None())?,
            Some(Ok(l)) => d.set_item("ledger", ("ok", json_to_py(py, l)?))?,
            Some(Err(e)) => d.set_item("ledger", ("error", e))?,
        }
        let ctor = py.get_type::<PyRun>().getattr("_from_state")?;
        Ok((ctor, PyTuple::new(py, [d])?))
    }

    /// A run from the state its `__reduce__` gives (how a pickled run is
    /// restored); its arrays are made read-only again.
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyDict>) -> PyResult<Self> {
        let item = |k: &str| {
            state
                .get_item(k)?
                .ok_or_else(|| bad_state(&format!("no `{k}`")))
        };
        let time = state_array::<f64, numpy::Ix1>(&item("time")?, "time", bad_state)?;
        let n = time.bind(state.py()).len();
        let names: Vec<String> = item("names")?.extract()?;
        let values = item("values")?
            .try_iter()?
            .map(|v| {
                let a = state_array::<f64, numpy::Ix1>(&v?, "values", bad_state)?;
                if a.bind(state.py()).len() != n {
                    return Err(bad_state("a channel's length differs from time's"));
                }
                Ok(a)
            })
            .collect::<PyResult<Vec<_>>>()?;
        let units: Vec<String> = item("units")?.extract()?;
        let channels = Named::from_state(names, units, values).map_err(bad_state)?;
        let ledger = item("ledger")?;
        let ledger = if ledger.is_none() {
            None
        } else {
            let (tag, v): (String, Bound<'_, PyAny>) = ledger.extract()?;
            Some(match tag.as_str() {
                "ok" => Ok(py_to_json(&v).ok_or_else(|| bad_state("the ledger is not JSON"))?),
                _ => Err(v.extract::<String>()?),
            })
        };
        Ok(Self {
            time,
            n,
            channels,
            stats: item("stats")?.extract()?,
            diagnostics: item("diagnostics")?.extract()?,
            ledger,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "Run({} samples, channels: {})",
            self.n,
            self.channels.names.join(", ")
        )
    }
}
