//! `hydrocyl.Rig`: a rig file or preset as `hydrocyl simulate --rig` reads
//! it, edited by the same parameter paths as `--set`, checked after every
//! edit, and simulated on a sampled command.

use crate::convert::{json_to_py, set_text, vector};
use crate::errors::detached;
use crate::run::PyRun;
use crate::sim;
use hydrocyl_system::rig;
use numpy::{AllowTypeChange, PyArrayLike1};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};
use serde_json::Value;

/// A rig: its JSON value (kind and parameters, SI units as the rig files
/// name them), always checked.
#[pyclass(module = "hydrocyl", name = "Rig")]
#[derive(Clone)]
pub struct Rig {
    /// The rig's JSON value (checked).
    pub value: Value,
}

/// A bad rig or path as the CLI words it.
fn input(e: rig::RigError) -> PyErr {
    PyValueError::new_err(e.to_string())
}

impl Rig {
    /// Names of the built-in presets.
    pub fn preset_names() -> Vec<&'static str> {
        rig::PRESETS.iter().map(|p| p.name).collect()
    }

    /// A checked rig from a JSON value.
    pub fn checked(value: Value) -> PyResult<Self> {
        rig::check(&value).map_err(input)?;
        Ok(Self { value })
    }

    /// The value at a parameter path: a parameter `rig::parameters` lists
    /// (every `--set` path of a netlist), else a JSON path of an older rig
    /// kind (object keys, array indices); or the error `--set` gives for it.
    fn at(&self, path: &str) -> Result<Value, rig::RigError> {
        if let Some(p) = rig::parameters(&self.value)
            .into_iter()
            .find(|p| p.path == path)
        {
            return Ok(p.value.map_or(Value::Null, Value::from));
        }
        let mut cur = &self.value;
        let netlist = self.kind() == hydrocyl_system::netlist::KIND;
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
                    let mut probe = self.value.clone();
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
    /// Loads a preset by name (`Rig.presets()`) or a rig JSON file by path,
    /// as `hydrocyl simulate --rig NAME_OR_PATH` does, and checks it.
    /// Raises ValueError with the CLI's message for an unknown preset, an
    /// unreadable or malformed file or a parameter out of range.
    #[staticmethod]
    fn load(name_or_path: &str) -> PyResult<Self> {
        let value = rig::load(name_or_path).map_err(input)?;
        rig::check(&value).map_err(|e| input(rig::at_line(e, name_or_path)))?;
        Ok(Self { value })
    }

    /// A rig from the text of a rig JSON file (as `to_json` writes it).
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Self> {
        let v: Value = serde_json::from_str(text).map_err(|e| {
            input(rig::RigError::Invalid {
                path: "rig".into(),
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

    /// The rig kind (`valve-cylinder`, `wang-hybrid`, ...).
    #[getter]
    fn kind(&self) -> String {
        self.value
            .get("kind")
            .and_then(Value::as_str)
            .unwrap_or_default()
            .to_string()
    }

    /// Sets one parameter by its path, exactly as `--set path=value` does
    /// (a number replaces a number or a `null`; a string a string), then
    /// checks the rig. On error (ValueError, the CLI's message) the rig is
    /// unchanged. Values are SI, as the rig file names them.
    fn set(&mut self, path: &str, value: &Bound<'_, PyAny>) -> PyResult<()> {
        let mut v = self.value.clone();
        rig::apply_set(&mut v, &format!("{path}={}", set_text(value)?)).map_err(input)?;
        *self = Self::checked(v)?;
        Ok(())
    }

    /// Sets several parameters (`{path: value}`), in order, then checks the
    /// rig once (for changes that are only consistent together). On error
    /// the rig is unchanged.
    fn update(&mut self, values: &Bound<'_, PyDict>) -> PyResult<()> {
        let mut v = self.value.clone();
        for (k, x) in values.iter() {
            let path: String = k.extract()?;
            rig::apply_set(&mut v, &format!("{path}={}", set_text(&x)?)).map_err(input)?;
        }
        *self = Self::checked(v)?;
        Ok(())
    }

    /// The value at a parameter path (a number, a string, None for a `null`
    /// such as an initial pressure the rig computes, or a dict/list for an
    /// inner path). ValueError for a path the rig does not have.
    fn get<'py>(&self, py: Python<'py>, path: &str) -> PyResult<Bound<'py, PyAny>> {
        json_to_py(py, &self.at(path).map_err(input)?)
    }

    /// Every numeric (or `null`) parameter: `{path: value}` in sorted path
    /// order, the paths `set` and `--set` take (values SI; None for `null`).
    fn parameters<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for p in rig::parameters(&self.value) {
            d.set_item(p.path, p.value)?;
        }
        Ok(d)
    }

    /// The rig as the JSON text of a rig file (what `--print-rig` prints).
    fn to_json(&self) -> PyResult<String> {
        serde_json::to_string_pretty(&self.value).map_err(|e| {
            input(rig::RigError::Invalid {
                path: "rig".into(),
                why: e.to_string(),
            })
        })
    }

    /// A copy (edits of the copy leave this rig alone).
    fn copy(&self) -> Self {
        self.clone()
    }

    fn __copy__(&self) -> Self {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.clone()
    }

    /// Pickles as its JSON text (for multiprocessing and Dask workers).
    fn __reduce__<'py>(
        &self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyAny>, Bound<'py, PyTuple>)> {
        let ctor = py.get_type::<Rig>().getattr("from_json")?;
        Ok((ctor, PyTuple::new(py, [self.value.to_string()])?))
    }

    fn __eq__(&self, other: &Self) -> bool {
        self.value == other.value
    }

    fn __repr__(&self) -> String {
        format!(
            "Rig(kind={:?}, {} parameters)",
            self.kind(),
            rig::parameters(&self.value).len()
        )
    }

    /// Simulates the rig on the command `u` given at times `t` [s] (linear
    /// between samples, as `hydrocyl simulate --command` reads its CSV) and
    /// samples the run at `t`. `u` is the normalised spool demand of a valve
    /// rig or the drive voltage [V] of a pump rig.
    ///
    /// `solver`: "dp45" (default), "rosenbrock" or "rk4"; `rtol`: relative
    /// tolerance of the adaptive methods; `rk4_step` [s]; `h_max`: largest
    /// step [s] (default 0.01); `ledger=True` adds the energy ledger
    /// (`run.ledger`). The GIL is released while it runs.
    ///
    /// ValueError for bad input (the CLI's message); SimulationError when
    /// the solver fails (time and state in the message).
    #[pyo3(signature = (t, u, *, solver = "dp45", rtol = 1e-6, rk4_step = 2e-5, h_max = None, ledger = false))]
    #[allow(clippy::too_many_arguments)]
    fn simulate(
        &self,
        py: Python<'_>,
        t: PyArrayLike1<'_, f64, AllowTypeChange>,
        u: PyArrayLike1<'_, f64, AllowTypeChange>,
        solver: &str,
        rtol: f64,
        rk4_step: f64,
        h_max: Option<f64>,
        ledger: bool,
    ) -> PyResult<PyRun> {
        let (t, u) = (vector(t), vector(u));
        let value = &self.value;
        let out = detached(py, || {
            let opts = sim::options(solver, rtol, rk4_step, h_max, ledger)?;
            let cmd = sim::command(&t, &u)?;
            sim::simulate(value, &cmd, &t, &opts)
        })?;
        PyRun::new(py, out)
    }
}
