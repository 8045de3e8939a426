//! Values between Python and the rig JSON / numpy: JSON values as Python
//! objects, Python values as the text `--set path=value` takes, arrays.

use numpy::{AllowTypeChange, PyArray1, PyArrayLike1, PyArrayLikeDyn, PyUntypedArrayMethods};
use pyo3::exceptions::{PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyList, PyString};
use serde_json::Value;

/// A JSON value as a Python object (`null` → `None`, objects → `dict`,
/// arrays → `list`, integers → `int`, other numbers → `float`).
pub fn json_to_py<'py>(py: Python<'py>, v: &Value) -> PyResult<Bound<'py, PyAny>> {
    Ok(match v {
        Value::Null => py.None().into_bound(py),
        Value::Bool(b) => PyBool::new(py, *b).to_owned().into_any(),
        Value::Number(n) => match (n.as_i64(), n.as_u64()) {
            (Some(i), _) => i.into_pyobject(py)?.into_any(),
            (None, Some(u)) => u.into_pyobject(py)?.into_any(),
            _ => PyFloat::new(py, n.as_f64().unwrap_or(f64::NAN)).into_any(),
        },
        Value::String(s) => PyString::new(py, s).into_any(),
        Value::Array(a) => {
            let l = PyList::empty(py);
            for x in a {
                l.append(json_to_py(py, x)?)?;
            }
            l.into_any()
        }
        Value::Object(m) => {
            let d = PyDict::new(py);
            for (k, x) in m {
                d.set_item(k, json_to_py(py, x)?)?;
            }
            d.into_any()
        }
    })
}

/// A Python value as the text after `=` of a CLI `--set path=value`, so that
/// `Rig.set` parses it exactly as the CLI does: `True` → `true`, `None` →
/// `null`, an int as itself, a float at full precision (`nan` stays `NaN`
/// and is refused like `--set x=NaN`), a string as given.
pub fn set_text(v: &Bound<'_, PyAny>) -> PyResult<String> {
    if v.is_none() {
        return Ok("null".into());
    }
    if let Ok(b) = v.cast::<PyBool>() {
        return Ok(if b.is_true() { "true" } else { "false" }.into());
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(v.str()?.to_string());
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(s.to_string());
    }
    if let Ok(x) = v.extract::<f64>() {
        return Ok(format!("{x:?}"));
    }
    Err(PyTypeError::new_err(format!(
        "a rig parameter is a number, a string, a bool or None, not {}",
        v.get_type().name()?
    )))
}

/// A 1-D float array from any array-like (list, numpy array of any real
/// dtype), copied.
pub fn vector(x: PyArrayLike1<'_, f64, AllowTypeChange>) -> Vec<f64> {
    x.as_array().to_vec()
}

/// The 1-D float array given as argument `name` (any array-like of real
/// numbers), copied; anything else is a one-line ValueError naming the
/// argument, the shape expected and what was given (`t: expected a 1-D
/// array of numbers, got a 2-D array of shape (2, 401)`).
pub fn vector_arg(name: &str, x: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    let got = if x.is_none() {
        "None".to_string()
    } else if let Ok(a) = x.extract::<PyArrayLike1<'_, f64, AllowTypeChange>>() {
        return Ok(vector(a));
    } else if let Ok(a) = x.extract::<PyArrayLikeDyn<'_, f64, AllowTypeChange>>() {
        match a.shape() {
            [] => "a scalar (a 0-D array)".to_string(),
            dims => format!(
                "a {}-D array of shape ({})",
                dims.len(),
                dims.iter()
                    .map(usize::to_string)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
    } else {
        format!("a {} that is not numbers", x.get_type().name()?)
    };
    Err(PyValueError::new_err(format!(
        "{name}: expected a 1-D array of numbers, got {got}"
    )))
}

/// A count given as argument `name` (at least 1), or `None`; below 1 is a
/// ValueError naming the argument and the rule: `{name}: -1 is not a
/// {what} (must be at least 1)`.
pub fn count_arg(name: &str, what: &str, n: Option<i64>) -> PyResult<Option<usize>> {
    n.map(|n| {
        usize::try_from(n).ok().filter(|&k| k >= 1).ok_or_else(|| {
            PyValueError::new_err(format!("{name}: {n} is not a {what} (must be at least 1)"))
        })
    })
    .transpose()
}

/// A names argument (`channels=["position", "p1"]`): a list, tuple or
/// other iterable of strings, or None. A single string is refused, not
/// read as its characters nor as one name, and anything else is a
/// TypeError naming the argument: `channels: expected a list of names,
/// got a str ('position'); write channels=['position']`.
pub fn names_arg(name: &str, x: Option<&Bound<'_, PyAny>>) -> PyResult<Option<Vec<String>>> {
    let Some(x) = x.filter(|x| !x.is_none()) else {
        return Ok(None);
    };
    if x.is_instance_of::<PyString>() {
        return Err(PyTypeError::new_err(format!(
            "{name}: expected a list of names, got a str ({s}); write {name}=[{s}]",
            s = x.repr()?
        )));
    }
    let bad =
        |got: String| PyTypeError::new_err(format!("{name}: expected a list of names, got {got}"));
    let mut names = Vec::new();
    for item in x.try_iter().map_err(|_| {
        bad(format!(
            "a {}",
            x.get_type()
                .name()
                .map_or_else(|_| "?".into(), |n| n.to_string())
        ))
    })? {
        let item = item?;
        match item.cast::<PyString>() {
            Ok(s) => names.push(s.to_string()),
            Err(_) => {
                return Err(bad(format!(
                    "an element that is a {}, not a str",
                    item.get_type().name()?
                )))
            }
        }
    }
    Ok(Some(names))
}

/// Makes a numpy array read-only (`flags.writeable = False`): a result's
/// arrays are handed out themselves, not copies, so that nobody may change
/// what the next reader gets.
pub fn frozen<T>(a: Bound<'_, T>) -> PyResult<Py<T>> {
    a.as_any().getattr("flags")?.setattr("writeable", false)?;
    Ok(a.unbind())
}

/// A read-only 1-D numpy array owning `v` ([`frozen`]).
pub fn array(py: Python<'_>, v: Vec<f64>) -> PyResult<Py<PyArray1<f64>>> {
    frozen(PyArray1::from_vec(py, v))
}

/// A JSON value from a Python object that [`json_to_py`] made (None, bool,
/// int, float, str, list, dict with str keys); `None` for anything else,
/// or a float that JSON cannot hold.
pub fn py_to_json(x: &Bound<'_, PyAny>) -> Option<Value> {
    if x.is_none() {
        return Some(Value::Null);
    }
    if let Ok(b) = x.cast::<PyBool>() {
        return Some(Value::Bool(b.is_true()));
    }
    if x.is_instance_of::<PyInt>() {
        return x
            .extract::<i64>()
            .map(Value::from)
            .or_else(|_| x.extract::<u64>().map(Value::from))
            .ok();
    }
    if let Ok(f) = x.cast::<PyFloat>() {
        return serde_json::Number::from_f64(f.value()).map(Value::Number);
    }
    if let Ok(s) = x.cast::<PyString>() {
        return Some(Value::String(s.to_string()));
    }
    if let Ok(l) = x.cast::<PyList>() {
        return l
            .iter()
            .map(|e| py_to_json(&e))
            .collect::<Option<Vec<_>>>()
            .map(Value::Array);
    }
    if let Ok(d) = x.cast::<PyDict>() {
        let mut m = serde_json::Map::new();
        for (k, v) in d.iter() {
            m.insert(k.extract::<String>().ok()?, py_to_json(&v)?);
        }
        return Some(Value::Object(m));
    }
    None
}

/// Named arrays (the channels of a run or a batch), in order.
pub struct Named<T> {
    /// Names, in order.
    pub names: Vec<String>,
    /// One array per name (read-only: [`frozen`]).
    pub values: Vec<Py<T>>,
}

impl<T: pyo3::PyTypeInfo> Named<T> {
    /// `{name: array}` (the arrays themselves, not copies: read-only).
    pub fn dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (n, v) in self.names.iter().zip(&self.values) {
            d.set_item(n, v.clone_ref(py))?;
        }
        Ok(d)
    }

    /// The array named `name`; a KeyError naming the others if none is.
    pub fn get(&self, py: Python<'_>, name: &str) -> PyResult<Py<T>> {
        self.names
            .iter()
            .position(|n| n == name)
            .map(|i| self.values[i].clone_ref(py))
            .ok_or_else(|| no_channel(name, &self.names))
    }

    /// Whether there is an array named `name`.
    pub fn contains(&self, name: &str) -> bool {
        self.names.iter().any(|n| n == name)
    }

    /// Puts the names (`"names"`) and the arrays in order (`"values"`)
    /// into a pickled state `d`.
    pub fn pickle_into(&self, d: &Bound<'_, PyDict>) -> PyResult<()> {
        let py = d.py();
        d.set_item("names", &self.names)?;
        d.set_item(
            "values",
            PyList::new(py, self.values.iter().map(|v| v.clone_ref(py)))?,
        )
    }
}

/// A `KeyError` naming the channels there are.
pub fn no_channel(name: &str, names: &[String]) -> PyErr {
    PyKeyError::new_err(format!(
        "no channel `{name}` (channels: {})",
        names.join(", ")
    ))
}
