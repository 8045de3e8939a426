//! `hydrocyl.simulate_batch`: N parameter sets of one rig on one command,
//! run in parallel (rayon) with the GIL released; results stacked as
//! `(N, len(t))` arrays in parameter-set order, so they do not depend on
//! the number of threads (each run is sequential and deterministic).

use crate::convert::{
    args, array, count_arg, frozen, key_arg, mapping_arg, names_arg, no_channel, vector_arg, Named,
};
use crate::errors::{interruptible, stopped, Failure, Outcome, RunWarning, Stop};
use crate::rig::Rig;
use crate::run::state_array;
use crate::sim;
use hydrocyl_system::rig;
use hydrocyl_system::run::{ProbeSet, Run};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyUntypedArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyIterator, PyList, PyTuple};
use rayon::prelude::*;
use serde_json::Value;

/// Runs of a batch: `time` [s] and per channel a `(N, len(time))` array
/// (row i is parameter set i), the parameter sets, per-run statistics and,
/// with `on_error="nan"`, which runs failed and why.
///
/// The arrays are read-only (numpy `flags.writeable` is False): they are
/// the batch's own, handed out without copying. A batch pickles (for Dask
/// and multiprocessing) and unpickles equal bit for bit.
#[pyclass(module = "hydrocyl", name = "BatchRun", frozen)]
pub struct PyBatch {
    time: Py<PyArray1<f64>>,
    channels: Named<PyArray2<f64>>,
    params: Vec<(String, Py<PyArray1<f64>>)>,
    stats: Vec<(String, Py<PyArray1<f64>>)>,
    ok: Py<PyArray1<bool>>,
    errors: Vec<Option<String>>,
    interval: (f64, f64),
}

/// The most threads `simulate_batch` takes: a larger `threads` is refused
/// (`hydrocyl.MAX_THREADS`).
pub const MAX_THREADS: usize = 1024;

/// The `threads` argument: None (all cores), or a count from 1 to
/// [`MAX_THREADS`]; otherwise a ValueError naming `threads`.
fn threads_arg(x: Option<&Bound<'_, PyAny>>) -> PyResult<Option<usize>> {
    let Some(x) = x.filter(|x| !x.is_none()) else {
        return Ok(None);
    };
    let too_many = |what: String| {
        PyValueError::new_err(format!(
            "threads: {what} is more than {MAX_THREADS} threads (hydrocyl.MAX_THREADS); a batch uses at most one thread per run, and more threads than cores only add overhead"
        ))
    };
    let n = match x.extract::<i64>() {
        Ok(n) => n,
        // an int beyond i64: far too many, or below 1
        Err(_) if x.is_instance_of::<pyo3::types::PyInt>() => {
            return Err(if x.gt(0)? {
                too_many(x.str()?.to_string())
            } else {
                PyValueError::new_err(format!(
                    "threads: {} is not a thread count (must be at least 1)",
                    x.str()?
                ))
            });
        }
        Err(_) => {
            return Err(pyo3::exceptions::PyTypeError::new_err(format!(
                "threads: expected an int or None, got a {}",
                x.get_type().name()?
            )))
        }
    };
    let k = count_arg("threads", "thread count", Some(n))?;
    match k {
        Some(k) if k > MAX_THREADS => Err(too_many(k.to_string())),
        k => Ok(k),
    }
}

/// A pickled batch's state that is not one: a ValueError saying so.
fn bad_state(what: &str) -> PyErr {
    PyValueError::new_err(format!(
        "not the pickled state of a hydrocyl.BatchRun: {what}"
    ))
}

/// Seconds since the Unix epoch (Python's `time.time()` scale).
fn unix_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(f64::NAN, |d| d.as_secs_f64())
}

/// The parameter sets: paths and, per path, N values.
struct Sets {
    paths: Vec<String>,
    columns: Vec<Vec<f64>>,
    n: usize,
}

impl Sets {
    /// The `--set` assignments of set `i`.
    fn assignments(&self, i: usize) -> Vec<String> {
        self.paths
            .iter()
            .zip(&self.columns)
            .map(|(p, c)| format!("{p}={:?}", c[i]))
            .collect()
    }
}

/// What one run leaves: its channels (the selected ones), statistics and
/// its warnings (naming the run).
struct Row {
    names: Vec<String>,
    units: Vec<String>,
    values: Vec<Vec<f64>>,
    stats: [f64; 4],
    warnings: Vec<RunWarning>,
}

#[allow(clippy::too_many_arguments)]
fn one(
    base: &Value,
    sets: &Sets,
    i: usize,
    cmd: &hydrocyl_system::signal::Signal,
    t: &[f64],
    opts: &hydrocyl_system::run::RunOptions,
    keep: Option<&[String]>,
    stop: &Stop,
) -> Outcome<Row> {
    // a batch being interrupted starts no more runs
    if stopped(stop) {
        return Err(Failure::Interrupted);
    }
    let ctx = |e: Failure| e.context(&format!("run {i} ({})", sets.assignments(i).join(", ")));
    let mut v = base.clone();
    for a in sets.assignments(i) {
        rig::apply_set(&mut v, &a).map_err(|e| ctx(Failure::Input(e.to_string())))?;
    }
    // `simulate` reads, checks and assembles the rig once (its errors are
    // the same input failures a separate `rig::check` would give)
    let sim::Simulated {
        run:
            Run {
                channels,
                stats,
                wall,
                ..
            },
        warnings,
        ..
    } = sim::simulate(&v, cmd, t, opts, stop).map_err(|e| match e {
        Failure::Interrupted => e,
        e => ctx(e),
    })?;
    let mut names = Vec::new();
    let mut units = Vec::new();
    let mut values = Vec::new();
    for c in channels {
        if keep.is_none_or(|k| k.contains(&c.name)) {
            names.push(c.name);
            units.push(c.unit.to_string());
            values.push(c.values);
        }
    }
    Ok(Row {
        names,
        units,
        values,
        stats: [
            stats.steps as f64,
            stats.rejected as f64,
            stats.rhs_evals as f64,
            wall.as_secs_f64(),
        ],
        warnings: warnings
            .into_iter()
            .map(|w| w.context(&format!("run {i} ({})", sets.assignments(i).join(", "))))
            .collect(),
    })
}

/// Runs the rig once per parameter set, in parallel on all cores (or on
/// `threads` threads), with the GIL released.
///
/// `params` maps parameter paths (as `Rig.set` and `--set` take them, see
/// `rig.parameters()`) to equal-length 1-D arrays of values (SI): set i
/// applies element i of every array to a copy of `rig`. `t` [s], `u` and
/// the solver settings are those of `Rig.simulate`. `channels` (default:
/// all) limits the channels returned.
///
/// The runs are of `rig` as it is when called (a `set` from another thread
/// meanwhile does not change them). `threads` is from 1 to
/// `hydrocyl.MAX_THREADS` (1024; more is a ValueError); the batch uses
/// `min(threads, N)` of them (one run is one thread's work). Ctrl-C
/// (SIGINT) stops every run within a few tens of milliseconds with
/// KeyboardInterrupt.
///
/// `on_error="raise"` (default) raises the error of the first failing set
/// (ValueError for an invalid set, SimulationError for a solver failure,
/// both naming the set); `on_error="nan"` fills its rows with NaN and
/// reports it in `batch.ok` / `batch.errors`. A set whose chamber fell far
/// below vacuum without blowing up is kept, with a
/// `hydrocyl.CavitationWarning` naming it; a set whose command is beyond
/// the maximum speed of the pump it drives warns with a
/// `hydrocyl.RatingWarning` naming it.
#[pyfunction]
#[pyo3(signature = (rig, t, u, params, *, solver = "auto", rtol = 1e-6, rk4_step = 2e-5, h_max = None, channels = None, threads = None, on_error = "raise"))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_batch(
    py: Python<'_>,
    rig: &Rig,
    t: &Bound<'_, PyAny>,
    u: &Bound<'_, PyAny>,
    params: &Bound<'_, PyAny>,
    #[pyo3(from_py_with = args::solver)] solver: &'static str,
    #[pyo3(from_py_with = args::rtol)] rtol: f64,
    #[pyo3(from_py_with = args::rk4_step)] rk4_step: f64,
    #[pyo3(from_py_with = args::h_max)] h_max: Option<f64>,
    channels: Option<&Bound<'_, PyAny>>,
    threads: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = args::on_error)] on_error: &'static str,
) -> PyResult<PyBatch> {
    let raise = on_error == "raise";
    let threads = threads_arg(threads)?;
    let channels = names_arg("channels", channels)?;
    let (t, u) = (vector_arg("t", t)?, vector_arg("u", u)?);
    let mut sets = Sets {
        paths: Vec::new(),
        columns: Vec::new(),
        n: 0,
    };
    let params = mapping_arg("params", "{path: values}", params)?;
    for (k, v) in params.iter() {
        let path = key_arg("params", "parameter path", &k)?;
        let col = vector_arg(&format!("params[{path:?}]"), &v)?;
        if sets.paths.is_empty() {
            sets.n = col.len();
        } else if col.len() != sets.n {
            return Err(PyValueError::new_err(format!(
                "params[{path:?}]: {} values, but params[{:?}] has {}",
                col.len(),
                sets.paths[0],
                sets.n
            )));
        }
        sets.paths.push(path);
        sets.columns.push(col);
    }
    if sets.n == 0 {
        return Err(PyValueError::new_err(
            "params: no parameter sets (give {path: array of N values}, N >= 1)",
        ));
    }
    let snapshot = rig.snapshot();
    let base = &*snapshot;
    let keep = channels.as_deref();
    // the channels asked for are checked once, before any run, and only
    // they are read in each (a stored one, e.g. a position or a chamber
    // pressure, without evaluating the circuit); on the first set's rig:
    // where it does not build, its run says why
    if let Some(k) = keep {
        if let Some(names) = channel_names(base, &sets, &t, &u) {
            if let Some(missing) = k.iter().find(|c| !names.contains(c)) {
                return Err(no_channel(missing, &names));
            }
        }
    }
    // one run is one thread's work: no more threads than runs
    let threads = threads.map(|k| k.min(sets.n));
    let sets = &sets;
    let (rows, interval): (Vec<Outcome<Row>>, (f64, f64)) = interruptible(py, |stop| {
        let start = unix_now();
        let opts = hydrocyl_system::run::RunOptions {
            only_channels: channels.clone(),
            ..sim::options(solver, rtol, rk4_step, h_max, false)?
        };
        let cmd = sim::command(&t, &u)?;
        let work = || {
            (0..sets.n)
                .into_par_iter()
                .map(|i| crate::errors::guard(|| one(base, sets, i, &cmd, &t, &opts, keep, stop)))
                .collect::<Vec<_>>()
        };
        let rows = match threads {
            None => work(),
            Some(k) => rayon::ThreadPoolBuilder::new()
                .num_threads(k)
                .build()
                .map_err(|e| Failure::Input(format!("threads: {e}")))?
                .install(work),
        };
        Ok((rows, (start, unix_now())))
    })?;
    let mut b = stack(py, t, rows, sets, keep, raise)?;
    b.interval = interval;
    Ok(b)
}

/// The channels a run of the rig `value` with the first parameter set on
/// the command `(t, u)` has (every set has the same: a set changes
/// parameters, not components); `None` where that rig does not build.
fn channel_names(value: &Value, sets: &Sets, t: &[f64], u: &[f64]) -> Option<Vec<String>> {
    let mut v = value.clone();
    for a in sets.assignments(0) {
        rig::apply_set(&mut v, &a).ok()?;
    }
    let circuit = rig::circuit(&v, sim::command(t, u).ok()?).ok()?;
    // in the order of a run's channels
    Some(ProbeSet::of(&circuit).names().map(str::to_string).collect())
}

/// Stacks the rows into `(N, T)` arrays (failed rows NaN), or raises the
/// first failure when `raise`.
fn stack(
    py: Python<'_>,
    t: Vec<f64>,
    rows: Vec<Outcome<Row>>,
    sets: &Sets,
    keep: Option<&[String]>,
    raise: bool,
) -> PyResult<PyBatch> {
    if raise {
        if let Some(Err(e)) = rows.iter().find(|r| r.is_err()) {
            return Err(e.clone().into_pyerr(py));
        }
    }
    let Some(first) = rows.iter().find_map(|r| r.as_ref().ok()) else {
        let e = rows.into_iter().find_map(Result::err);
        return Err(e
            .map(|e| e.context("every run failed; the first"))
            .unwrap_or_else(|| Failure::Input("no runs".into()))
            .into_pyerr(py));
    };
    let (names, units) = (first.names.clone(), first.units.clone());
    if let Some(k) = keep {
        if let Some(missing) = k.iter().find(|c| !names.contains(c)) {
            return Err(no_channel(missing, &first.names));
        }
    }
    let (n, m) = (rows.len(), t.len());
    let mut data = vec![vec![f64::NAN; n * m]; names.len()];
    let mut stats = [(); 4].map(|_| vec![f64::NAN; n]);
    let mut errors = Vec::with_capacity(n);
    let mut warnings = Vec::new();
    for (i, r) in rows.into_iter().enumerate() {
        match r {
            Ok(row) if row.names == names => {
                warnings.extend(row.warnings);
                for (d, v) in data.iter_mut().zip(&row.values) {
                    d[i * m..(i + 1) * m].copy_from_slice(v);
                }
                for (s, v) in stats.iter_mut().zip(row.stats) {
                    s[i] = v;
                }
                errors.push(None);
            }
            Ok(row) => {
                let e = Failure::Input(format!(
                    "run {i}: channels {} differ from the first run's {}",
                    row.names.join(", "),
                    names.join(", ")
                ));
                if raise {
                    return Err(e.into_pyerr(py));
                }
                errors.push(Some(e.message().to_string()));
            }
            Err(e) => errors.push(Some(e.message().to_string())),
        }
    }
    let values = data
        .into_iter()
        .map(|d| {
            Array2::from_shape_vec((n, m), d)
                .map_err(|e| PyValueError::new_err(e.to_string()))
                .and_then(|a| frozen(a.into_pyarray(py)))
        })
        .collect::<PyResult<Vec<_>>>()?;
    let params = sets
        .paths
        .iter()
        .zip(&sets.columns)
        .map(|(p, c)| Ok((p.clone(), array(py, c.clone())?)))
        .collect::<PyResult<Vec<_>>>()?;
    let ok: Vec<bool> = errors.iter().map(Option::is_none).collect();
    let stats = ["steps", "rejected", "rhs_evals", "wall_s"]
        .into_iter()
        .zip(stats)
        .map(|(k, v)| Ok((k.to_string(), array(py, v)?)))
        .collect::<PyResult<Vec<_>>>()?;
    // the sets kept, in order, once the batch is sure to be returned
    for w in &warnings {
        w.warn(py)?;
    }
    Ok(PyBatch {
        time: array(py, t)?,
        channels: Named {
            names,
            units,
            values,
        },
        params,
        stats,
        ok: frozen(PyArray1::from_vec(py, ok))?,
        errors,
        interval: (f64::NAN, f64::NAN),
    })
}

#[pymethods]
impl PyBatch {
    /// Output times [s].
    #[getter]
    fn time(&self, py: Python<'_>) -> Py<PyArray1<f64>> {
        self.time.clone_ref(py)
    }

    /// Channel names (their units: `units`).
    #[getter]
    fn names(&self) -> Vec<String> {
        self.channels.names.clone()
    }

    /// `{channel: SI unit}` of the channels kept, as `Run.units` (the CLI
    /// header's: `Pa` gauge, `-` dimensionless, `command` in `V` on a
    /// pump rig).
    #[getter]
    fn units<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.channels.units_dict(py)
    }

    /// `{channel: (N, len(time)) array}`; row i is parameter set i.
    #[getter]
    fn channels<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        self.channels.dict(py)
    }

    /// The parameter sets: `{path: (N,) array}` as given (a new dict of
    /// the batch's read-only arrays).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.params {
            d.set_item(k, v.clone_ref(py))?;
        }
        Ok(d)
    }

    /// Per-run solver statistics: `{steps, rejected, rhs_evals, wall_s}`,
    /// each an (N,) float array (NaN for a failed run).
    #[getter]
    fn stats<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (k, v) in &self.stats {
            d.set_item(k, v.clone_ref(py))?;
        }
        Ok(d)
    }

    /// (N,) bool array: which runs succeeded.
    #[getter]
    fn ok(&self, py: Python<'_>) -> Py<PyArray1<bool>> {
        self.ok.clone_ref(py)
    }

    /// Per run: None, or the one-line error of a failed run.
    #[getter]
    fn errors(&self) -> Vec<Option<String>> {
        self.errors.clone()
    }

    /// When the runs started and ended, in seconds since the Unix epoch
    /// (`time.time()`), measured with the GIL released: two batches whose
    /// intervals overlap ran at the same time.
    #[getter]
    fn interval_s(&self) -> (f64, f64) {
        self.interval
    }

    fn __len__(&self) -> usize {
        self.errors.len()
    }

    fn __getitem__(&self, py: Python<'_>, name: &str) -> PyResult<Py<PyArray2<f64>>> {
        self.channels.get(py, name)
    }

    fn __contains__(&self, name: &str) -> bool {
        self.channels.contains(name)
    }

    /// The channel names.
    fn keys(&self) -> Vec<String> {
        self.channels.names.clone()
    }

    /// Iterates over the channel names, as a dict over its keys (`len` is
    /// the number of runs).
    fn __iter__<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyIterator>> {
        PyList::new(py, &self.channels.names)?.try_iter()
    }

    /// Pickles as its state ([`PyBatch::_from_state`]): the arrays (numpy
    /// pickles them bit for bit), names, units, parameter sets, statistics,
    /// errors and interval.
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let pairs = |v: &[(String, Py<PyArray1<f64>>)]| {
            v.iter()
                .map(|(k, a)| (k.clone(), a.clone_ref(py)))
                .collect::<Vec<_>>()
        };
        let d = PyDict::new(py);
        d.set_item("time", self.time.clone_ref(py))?;
        self.channels.pickle_into(&d)?;
        d.set_item("params", pairs(&self.params))?;
        d.set_item("stats", pairs(&self.stats))?;
        d.set_item("ok", self.ok.clone_ref(py))?;
        d.set_item("errors", self.errors.clone())?;
        d.set_item("interval_s", self.interval)?;
        let ctor = py.get_type::<PyBatch>().getattr("_from_state")?;
        Ok((ctor, PyTuple::new(py, [d])?))
    }

    /// A batch from the state its `__reduce__` gives (how a pickled batch
    /// is restored); its arrays are made read-only again.
    #[staticmethod]
    fn _from_state(state: &Bound<'_, PyDict>) -> PyResult<Self> {
        let py = state.py();
        let item = |k: &str| {
            state
                .get_item(k)?
                .ok_or_else(|| bad_state(&format!("no `{k}`")))
        };
        let time = state_array::<f64, numpy::Ix1>(&item("time")?, "time", bad_state)?;
        let m = time.bind(py).len();
        let errors: Vec<Option<String>> = item("errors")?.extract()?;
        let n = errors.len();
        let names: Vec<String> = item("names")?.extract()?;
        let values = item("values")?
            .try_iter()?
            .map(|v| {
                let a = state_array::<f64, numpy::Ix2>(&v?, "values", bad_state)?;
                if a.bind(py).shape() != [n, m] {
                    return Err(bad_state("a channel's shape is not (N, len(time))"));
                }
                Ok(a)
            })
            .collect::<PyResult<Vec<_>>>()?;
        let units: Vec<String> = item("units")?.extract()?;
        let channels = Named::from_state(names, units, values).map_err(bad_state)?;
        let pairs = |k: &str| -> PyResult<Vec<(String, Py<PyArray1<f64>>)>> {
            item(k)?
                .try_iter()?
                .map(|p| {
                    let (name, a): (String, Bound<'_, PyAny>) = p?.extract()?;
                    Ok((name, state_array(&a, k, bad_state)?))
                })
                .collect()
        };
        let ok = state_array::<bool, numpy::Ix1>(&item("ok")?, "ok", bad_state)?;
        if ok.bind(py).len() != n {
            return Err(bad_state("`ok` and `errors` differ in length"));
        }
        Ok(Self {
            time,
            channels,
            params: pairs("params")?,
            stats: pairs("stats")?,
            ok,
            errors,
            interval: item("interval_s")?.extract()?,
        })
    }

    fn __repr__(&self) -> String {
        format!(
            "BatchRun({} runs ({} failed), channels: {})",
            self.errors.len(),
            self.errors.iter().filter(|e| e.is_some()).count(),
            self.channels.names.join(", ")
        )
    }
}
