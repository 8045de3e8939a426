//! `hydrocyl.Rig`: a rig file or preset as `hydrocyl simulate --rig` reads
//! it, edited by the same parameter paths as `--set`, checked after every
//! edit, and simulated on a sampled command.

use crate::convert::{args, json_to_py, key_arg, mapping_arg, set_text, vector_arg};
use crate::errors::interruptible;
use crate::run::PyRun;
use crate::sim;
use hydrocyl_system::{netlist, rig};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde_json::Value;
use std::path::PathBuf;
use std::sync::{Arc, Mutex, PoisonError};

/// A rig: its JSON value (kind and parameters, SI units as the rig files
/// name them), always checked.
///
/// The value is held as a shared snapshot behind a lock rather than in a
/// mutable Python object: `simulate`, `simulate_batch` and `diagnose` take
/// the snapshot and release the GIL without borrowing the rig, so a `set`
/// from another thread meanwhile succeeds (it replaces the snapshot) and
/// does not change the run under way.
#[pyclass(module = "hydrocyl", name = "Rig", frozen)]
pub struct Rig {
    /// The rig's JSON value (checked), replaced whole by every edit.
    value: Mutex<Arc<Value>>,
}

/// How `Rig.from_json` names its text in messages, where `Rig.load` names
/// the file.
const JSON_TEXT: &str = "JSON text";

/// A bad rig or path as the CLI words it.
fn input(e: rig::RigError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

/// A rig source (preset name or file path) read as `--rig` reads it:
/// [`rig::load`] (duplicate keys refused, an older kind migrated to its
/// netlist, a retired kind named), then checked, a bad path's line in the
/// file added to the message.
fn read_rig(source: &str) -> Result<Value, rig::RigError> {
    let value = rig::load(source)?;
    rig::check(&value).map_err(|e| rig::at_line(e, source))?;
    Ok(value)
}

/// Every parameter of a rig value with its value as the rig gives it: for
/// a netlist, [`netlist::parameters_of`] the netlist as read (defaults
/// filled in, unit and meaning from the component registry), so that a
/// `null` the rig computes (an initial chamber pressure from the steady
/// state) is `None`, not the computed value; other kinds as
/// [`rig::parameters`] lists them.
fn parameters_of(v: &Value) -> Vec<rig::Parameter> {
    if v.get("kind").and_then(Value::as_str) == Some(netlist::KIND) {
        if let Ok(s) = netlist::read(v) {
            return netlist::parameters_of(&s)
                .into_iter()
                .map(rig::Parameter::from)
                .collect();
        }
    }
    rig::parameters(v)
}

/// The parameters under the inner path `path` (those whose path starts
/// with `path.`) as one JSON object nested as their paths are, in
/// parameter order (a group where its first parameter is):
/// `{"area_1": ..., "initial": {"p1": null, ...}}` for
/// `cylinder`. `None` when no parameter is under `path`.
fn inner(params: &[rig::Parameter], path: &str) -> Option<Value> {
    let prefix = format!("{path}.");
    let mut root = serde_json::Map::new();
    for p in params {
        let Some(rest) = p.path.strip_prefix(&prefix) else {
            continue;
        };
        let value = p.value.map_or(Value::Null, Value::from);
        let mut segs: Vec<&str> = rest.split('.').collect();
        let last = segs.pop().unwrap_or(rest);
        let mut at = &mut root;
        for seg in segs {
            let entry = at
                .entry(seg.to_string())
                .or_insert_with(|| Value::Object(serde_json::Map::new()));
            // a path under a parameter's own path cannot happen (a
            // parameter is a number); should it, the rest stays one key
            at = match entry {
                Value::Object(m) => m,
                _ => return None,
            };
        }
        at.insert(last.to_string(), value);
    }
    (!root.is_empty()).then_some(Value::Object(root))
}

impl Rig {
    /// Names of the built-in presets.
    pub fn preset_names() -> Vec<&'static str> {
        rig::PRESETS.iter().map(|p| p.name).collect()
    }

    /// A rig holding `value` (checked by the caller).
    fn new(value: Value) -> Self {
        Self {
            value: Mutex::new(Arc::new(value)),
        }
    }

    /// A checked rig from a JSON value.
    fn checked(value: Value) -> PyResult<Self> {
        rig::check(&value).map_err(input)?;
        Ok(Self::new(value))
    }

    /// The rig's value now: a snapshot that later edits of the rig leave
    /// alone (they replace it).
    pub fn snapshot(&self) -> Arc<Value> {
        Arc::clone(&self.value.lock().unwrap_or_else(PoisonError::into_inner))
    }

    /// Applies `--set` assignments to a copy of the rig's value, checks it
    /// and, when all is well, makes it the rig's value; on error the rig is
    /// unchanged. No Python code runs in between, so no other thread's edit
    /// is lost.
    fn edit(&self, assignments: &[String]) -> PyResult<()> {
        let mut v = Value::clone(&self.snapshot());
        for a in assignments {
            rig::apply_set(&mut v, a).map_err(input)?;
        }
        // the parameters were named as `--set` names them: so are the errors
        rig::check(&v).map_err(|e| input(rig::set_form(e, &v)))?;
        *self.value.lock().unwrap_or_else(PoisonError::into_inner) = Arc::new(v);
        Ok(())
    }

    /// The value at a parameter path: a parameter [`parameters_of`] lists
    /// (every `--set` path of a netlist); an inner path of those (a
    /// component, `cylinder`, or a group in one, `cylinder.initial`) as the
    /// object of its parameters ([`inner`]); else a JSON path of an older
    /// rig kind (object keys, array indices); or the error `--set` gives
    /// for it.
    fn at(&self, path: &str) -> Result<Value, rig::RigError> {
        let value = self.snapshot();
        let params = parameters_of(&value);
        if let Some(p) = params.iter().find(|p| p.path == path) {
            return Ok(p.value.map_or(Value::Null, Value::from));
        }
        if let Some(v) = inner(&params, path) {
            return Ok(v);
        }
        let mut cur = &*value;
        let netlist = self.kind() == netlist::KIND;
        for seg in path.split('.') {
            let next = match cur {
                Value::Object(m) if !netlist => m.get(seg),
                Value::Array(a) if !netlist => seg.parse::<usize>().ok().and_then(|i| a.get(i)),
                _ => None,
            };
            match next {
                Some(v) => cur = v,
                None => {
                    // Same wording as `--set` on a missing path.
                    let mut probe = Value::clone(&value);
                    return Err(rig::apply_set(&mut probe, &format!("{path}=0"))
                        .err()
                        .unwrap_or_else(|| rig::RigError::UnknownPath {
                            path: path.into(),
                            hint: String::new(),
                        }));
                }
            }
        }
        Ok(cur.clone())
    }
}

#[pymethods]
impl Rig {
    /// Loads a preset by name (`Rig.presets()`) or a rig JSON file by path
    /// (a `str` or any `os.PathLike`), as `hydrocyl simulate --rig
    /// NAME_OR_PATH` does, and checks it: a duplicate key is refused, an
    /// older rig kind (`valve-cylinder`, `hybrid-pump`) is read as its
    /// netlist. Raises ValueError with the CLI's message for an unknown
    /// preset, an unreadable or malformed file or a parameter out of range.
    #[staticmethod]
    fn load(name_or_path: PathBuf) -> PyResult<Self> {
        let source = name_or_path.to_str().ok_or_else(|| {
            PyValueError::new_err(format!(
                "rig `{}`: the path is not valid UTF-8",
                name_or_path.display()
            ))
        })?;
        Ok(Self::new(read_rig(source).map_err(input)?))
    }

    /// A rig from the text of a rig JSON file, read exactly as `load` reads
    /// the file (`rig::parse`: duplicate keys refused with their line, an
    /// older kind read as its netlist, a retired kind named, then checked);
    /// messages name the text `JSON text` where `load` names the file.
    #[staticmethod]
    fn from_json(#[pyo3(from_py_with = args::text)] text: String) -> PyResult<Self> {
        let text = text.as_str();
        let value = rig::parse(text, JSON_TEXT).map_err(input)?;
        rig::check(&value).map_err(|e| input(rig::at_line_in(e, text, JSON_TEXT)))?;
        Ok(Self::new(value))
    }

    /// A rig from its own `to_json` text (how a pickled rig is restored):
    /// that text is a checked netlist already, so it is only parsed and
    /// checked again.
    #[staticmethod]
    fn _from_rig_json(text: &str) -> PyResult<Self> {
        let v: Value = serde_json::from_str(text).map_err(|e| {
            input(rig::RigError::Invalid {
                path: JSON_TEXT.into(),
                why: format!("not valid JSON: {e}"),
            })
        })?;
        Self::checked(v)
    }

    /// Names of the built-in presets.
    #[staticmethod]
    fn presets() -> Vec<&'static str> {
        Self::preset_names()
    }

    /// The rig kind (`netlist` for every rig read by `load`/`from_json`).
    #[getter]
    fn kind(&self) -> String {
        self.snapshot()
            .get("kind")
            .and_then(Value::as_str)
            .unwrap_or_default()
            .to_string()
    }

    /// Sets one parameter by its path, exactly as `--set path=value` does
    /// (a number replaces a number or a `null`; None sets `null`, which for
    /// an initial chamber pressure means "computed from the steady state";
    /// a string replaces a string), then checks the rig. On error
    /// (ValueError, the CLI's message) the rig is unchanged. Values are SI,
    /// as the rig file names them.
    fn set(
        &self,
        #[pyo3(from_py_with = args::path)] path: String,
        value: &Bound<'_, PyAny>,
    ) -> PyResult<()> {
        self.edit(&[format!("{path}={}", set_text(&path, value)?)])
    }

    /// Sets several parameters (`{path: value}`, None for `null`), in
    /// order, then checks the rig once (for changes that are only
    /// consistent together). On error the rig is unchanged.
    /// `rig.update(rig.parameters())` changes no value (a default it writes out stays the default).
    fn update(&self, values: &Bound<'_, PyAny>) -> PyResult<()> {
        let values = mapping_arg("values", "{path: value}", values)?;
        let mut assignments = Vec::with_capacity(values.len());
        for (k, x) in values.iter() {
            let path = key_arg("values", "parameter path", &k)?;
            assignments.push(format!("{path}={}", set_text(&path, &x)?));
        }
        self.edit(&assignments)
    }

    /// The value at a parameter path: a number, None for a `null` such as
    /// an initial pressure the rig computes, or for an inner path — a
    /// component (`"cylinder"`) or a group in one (`"valve.orifice"`,
    /// `"cylinder.initial"`) — a dict of the parameters under it, nested as
    /// their paths are (`rig.get("valve")["orifice"]["cd"] ==
    /// rig.get("valve.orifice.cd")`; the values of `parameters()`). An older
    /// rig kind's JSON path may also give a string or a list. ValueError for
    /// a path the rig does not have.
    fn get<'py>(
        &self,
        py: Python<'py>,
        #[pyo3(from_py_with = args::path)] path: String,
    ) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.at(&path).map_err(input)?)
    }

    /// Every numeric (or `null`) parameter: `{path: value}` in component
    /// order, the paths `set` and `--set` take (values SI, defaults filled
    /// in; None for `null`, e.g. an initial chamber pressure the rig
    /// computes from the steady state, so that `update(parameters())` keeps
    /// it computed).
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in parameters_of(&self.snapshot()) {
            d.set_item(p.path, p.value)?;
        }
        Ok(d)
    }

    /// Every parameter with its SI unit and meaning:
    /// `{path: {"value": ..., "unit": ..., "doc": ...}}`, the paths and
    /// values of `parameters()`. A netlist's units and meanings are those
    /// of the component registry (`hydrocyl components`); a rig kind that
    /// declares none gives None for them.
    fn describe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in parameters_of(&self.snapshot()) {
            let e = PyDict::new(py);
            e.set_item("value", p.value)?;
            e.set_item("unit", p.unit)?;
            e.set_item("doc", p.doc)?;
            d.set_item(p.path, e)?;
        }
        Ok(d)
    }

    /// The rig as the JSON text of a rig file, as `--print-rig` prints
    /// it: a netlist with every parameter and initial state written out
    /// (defaults filled in, [`rig::printed`]).
    fn to_json(&self) -> PyResult<String> {
        rig::printed(&self.snapshot()).map_err(input)
    }

    /// A copy (edits of the copy leave this rig alone).
    fn copy(&self) -> Self {
        Self {
            value: Mutex::new(self.snapshot()),
        }
    }

    fn __copy__(&self) -> Self {
        self.copy()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.copy()
    }

    /// Pickles as its JSON text (for multiprocessing and Dask workers).
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let ctor = py.get_type::<Rig>().getattr("_from_rig_json")?;
        Ok((ctor, PyTuple::new(py, [self.snapshot().to_string()])?))
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.snapshot() == other.snapshot()
    }

    fn __repr__(&self) -> String {
        format!(
            "Rig(kind={:?}, {} parameters)",
            self.kind(),
            parameters_of(&self.snapshot()).len()
        )
    }

    /// Simulates the rig on the command `u` given at times `t` [s] (linear
    /// between samples, as `hydrocyl simulate --command` reads its CSV) and
    /// samples the run at `t`. `u` is the normalised spool demand of a valve
    /// rig or the drive voltage [V] of a pump rig; `t` and `u` are 1-D
    /// arrays of the same length.
    ///
    /// `solver`: "auto" (default, as the CLI's: Dormand–Prince while the
    /// run is not stiff, Rosenbrock while it is), "dp45", "rosenbrock",
    /// "rk4" or "exponential"; `rtol`: relative tolerance of the adaptive
    /// methods, in [1e-14, 1) as the CLI's `--rtol`; `rk4_step` [s]: the
    /// step of the fixed-step methods; `h_max`: largest step [s] (default
    /// 0.01); `ledger=True` adds the energy ledger
    /// (`run.ledger`). The run is of the rig as it is when called (a `set`
    /// from another thread meanwhile does not change it); the GIL is
    /// released while it runs, and Ctrl-C (SIGINT) stops it within a few
    /// tens of milliseconds with KeyboardInterrupt.
    ///
    /// ValueError for bad input (the CLI's message); SimulationError when
    /// the solver fails or the run blows up (time and state in the
    /// message). A chamber pressure far below vacuum in a run that did not
    /// blow up (the constant-B oil cavitating) warns with
    /// `hydrocyl.CavitationWarning`, a command beyond the maximum speed of
    /// the pump it drives with `hydrocyl.RatingWarning` (the CLI's
    /// warning), and the run is returned.
    #[pyo3(signature = (t, u, *, solver = "auto", rtol = 1e-6, rk4_step = 2e-5, h_max = None, ledger = false))]
    #[allow(clippy::too_many_arguments)]
    fn simulate(
        &self,
        py: Python<'_>,
        t: &Bound<'_, PyAny>,
        u: &Bound<'_, PyAny>,
        #[pyo3(from_py_with = args::solver)] solver: &'static str,
        #[pyo3(from_py_with = args::rtol)] rtol: f64,
        #[pyo3(from_py_with = args::rk4_step)] rk4_step: f64,
        #[pyo3(from_py_with = args::h_max)] h_max: Option<f64>,
        #[pyo3(from_py_with = args::ledger)] ledger: bool,
    ) -> PyResult<PyRun> {
        let (t, u) = (vector_arg("t", t)?, vector_arg("u", u)?);
        let value = self.snapshot();
        let out = interruptible(py, |stop| {
            let opts = sim::options(solver, rtol, rk4_step, h_max, ledger)?;
            let cmd = sim::command(&t, &u)?;
            sim::simulate(&value, &cmd, &t, &opts, stop)
        })?;
        for w in &out.warnings {
            w.warn(py)?;
        }
        PyRun::new(py, out)
    }
}
