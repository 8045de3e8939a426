//! Values between Python and the rig JSON / numpy: JSON values as Python
//! objects, Python values as the text `--set path=value` takes, arrays.

use numpy::ndarray::{ArrayD, Dimension, IxDyn};
use numpy::{
    Element, PyArray, PyArray1, PyArrayDescrMethods, PyArrayMethods, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::{PyKeyError, PyTypeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyComplex, PyDict, PyFloat, PyInt, PyList, PyString, PyTuple};
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

/// A Python value for the parameter `path` as the text after `=` of a CLI
/// `--set path=value`, so that `Rig.set` parses it exactly as the CLI
/// does: `True` (or numpy's `True`) → `true`, `None` → `null`, an int as
/// itself, a float at full precision (`nan` stays `NaN` and is refused
/// like `--set x=NaN`), a string as given; a numpy number or 0-D array as
/// its number ([`number_arg`]). A complex number (Python's or numpy's) is
/// refused, not read as its real part, and so is anything else, each a
/// TypeError naming the parameter (``rig `load.mass`: (3+1j) is complex;
/// a parameter is a real number``).
pub fn set_text(path: &str, v: &Bound<'_, PyAny>) -> PyResult<String> {
    if v.is_none() {
        return Ok("null".into());
    }
    let np = v.py().import("numpy")?;
    if v.is_instance_of::<PyBool>() || v.is_instance(&np.getattr("bool_")?)? {
        return Ok(if v.is_truthy()? { "true" } else { "false" }.into());
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(v.str()?.to_string());
    }
    if let Ok(s) = v.cast::<PyString>() {
        return Ok(s.to_string());
    }
    let name = format!("rig `{path}`");
    let complex_array = v
        .cast::<PyUntypedArray>()
        .is_ok_and(|a| a.dtype().kind() == b'c');
    if complex_array
        || v.is_instance_of::<PyComplex>()
        || v.is_instance(&np.getattr("complexfloating")?)?
    {
        return Err(PyTypeError::new_err(format!(
            "{name}: {} is complex; a parameter is a real number",
            v.repr()?
        )));
    }
    let x = if v.cast::<PyUntypedArray>().is_ok() || v.is_instance(&np.getattr("number")?)? {
        number_arg(&name, v)?
    } else {
        v.extract::<f64>().map_err(|_| -> PyErr {
            match v.get_type().name() {
                Ok(t) => PyTypeError::new_err(format!(
                    "{name}: a parameter is a number, a string, a bool or None, not {t}"
                )),
                Err(e) => e,
            }
        })?
    };
    Ok(format!("{x:?}"))
}

/// The one reader of numpy arrays: `x` as an array of element type `T`
/// (its own dtype converted to `T`'s where it differs, e.g. an int array to
/// float), in native byte order, aligned and C-contiguous. An array that is
/// not so — unaligned (read from a buffer at an odd offset, or unpickled:
/// Dask's arrays arrive so), big-endian (`>f8`), strided (a slice) — is
/// copied by numpy (`numpy.require(x, dtype, ["C", "A"])`); one that is, is
/// taken as it is. Reading the result never meets a pointer the Rust side
/// cannot read (an unaligned one is a panic, not an error). Every array
/// the package reads comes through here: [`real_array`] for arguments,
/// [`state_array`](crate::run::state_array) for pickled results.
pub fn readable<'py, T: Element, D: Dimension>(
    x: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray<T, D>>> {
    let py = x.py();
    let a =
        py.import("numpy")?
            .getattr("require")?
            .call1((x, numpy::dtype::<T>(py), ["C", "A"]))?;
    Ok(a.cast_into::<PyArray<T, D>>()?)
}

/// Where element `flat` (in C order) of an array of `shape` is, as Python
/// indexes it: `[3]`, `[1, 2]`, `[]` for a 0-D array.
fn index_of(flat: usize, shape: &[usize]) -> String {
    let mut rest = flat;
    let mut at = vec![0; shape.len()];
    for (i, &n) in shape.iter().enumerate().rev() {
        if n > 0 {
            at[i] = rest % n;
            rest /= n;
        }
    }
    format!(
        "[{}]",
        at.iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// The real numbers given as argument `name`, of any shape, copied (through
/// [`readable`]: an unaligned, big-endian or strided array is read as its
/// values). `expected` says what the argument is, for the messages (`a 1-D
/// array of numbers`). Ints and floats are numbers; anything else is
/// refused rather than cast, with the argument named:
///
/// * complex numbers (a complex array, or a complex element of a list):
///   TypeError `u: complex numbers are not accepted ...` — numpy would
///   drop the imaginary part with only a ComplexWarning;
/// * booleans (a bool array, an element of an object array, or of a list
///   or tuple, which numpy would read as 0 or 1): TypeError — a command or
///   a parameter is a number, and `True` is not read as `1.0`;
/// * an element that is not a number (an object array or a list holding
///   `None`, a string, ...): TypeError naming the element
///   (`u[3]: None is not a number`), not read as NaN;
/// * an array of strings, dates or records, or a ragged list: ValueError
///   `u: expected ..., got a list that is not numbers`.
pub fn real_array(name: &str, expected: &str, x: &Bound<'_, PyAny>) -> PyResult<ArrayD<f64>> {
    let py = x.py();
    let not_numbers =
        |what: String| PyValueError::new_err(format!("{name}: expected {expected}, got {what}"));
    let type_name = |x: &Bound<'_, PyAny>| {
        x.get_type()
            .name()
            .map_or_else(|_| "?".to_string(), |n| n.to_string())
    };
    let np = py.import("numpy")?;
    // numpy reads a bool in a list of numbers as 0 or 1: refused first
    if x.is_instance_of::<PyList>() || x.is_instance_of::<PyTuple>() {
        let np_bool = np.getattr("bool_")?;
        for (k, e) in x.try_iter()?.enumerate() {
            let e = e?;
            if e.is_instance_of::<PyBool>() || e.is_instance(&np_bool)? {
                return Err(PyTypeError::new_err(format!(
                    "{name}[{k}]: {} is a bool, not a number",
                    e.repr()?
                )));
            }
        }
    }
    let a = np
        .getattr("asanyarray")?
        .call1((x,))
        .map_err(|_| not_numbers(format!("a {} that is not numbers", type_name(x))))?;
    let a = a.cast_into::<PyUntypedArray>()?;
    let dtype = a.dtype();
    match dtype.kind() {
        b'i' | b'u' | b'f' => {}
        b'c' => {
            return Err(PyTypeError::new_err(format!(
                "{name}: complex numbers are not accepted (got an array of {dtype}); give the real numbers meant (e.g. {name}.real)"
            )))
        }
        b'b' => {
            return Err(PyTypeError::new_err(format!(
                "{name}: booleans are not accepted as numbers (got an array of bool); give numbers (e.g. {name}.astype(float))"
            )))
        }
        b'O' => {
            let shape = a.shape().to_vec();
            let (np_bool, np_complex) = (np.getattr("bool_")?, np.getattr("complexfloating")?);
            for (k, e) in a.call_method0("ravel")?.try_iter()?.enumerate() {
                let e = e?;
                let why = if e.is_instance_of::<PyBool>() || e.is_instance(&np_bool)? {
                    Some(format!("{} is a bool, not a number", e.repr()?))
                } else if e.is_instance_of::<PyComplex>() || e.is_instance(&np_complex)? {
                    Some(format!(
                        "{} is complex; complex numbers are not accepted",
                        e.repr()?
                    ))
                } else if e.extract::<f64>().is_err() {
                    Some(format!("{} is not a number (a {})", e.repr()?, type_name(&e)))
                } else {
                    None
                };
                if let Some(why) = why {
                    return Err(PyTypeError::new_err(format!(
                        "{name}{}: {why}",
                        index_of(k, &shape)
                    )));
                }
            }
        }
        _ => {
            return Err(not_numbers(format!(
                "a {} of {dtype} (not numbers)",
                type_name(x)
            )))
        }
    }
    Ok(readable::<f64, IxDyn>(a.as_any())?.to_owned_array())
}

/// An array of shape `dims` in messages: `a 2-D array of shape (2, 401)`.
fn array_of_shape(dims: &[usize]) -> String {
    format!(
        "a {}-D array of shape ({})",
        dims.len(),
        dims.iter()
            .map(usize::to_string)
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// The 1-D float array given as argument `name` (any array-like of real
/// numbers, [`real_array`]), copied; anything else is a one-line error
/// naming the argument, the shape expected and what was given (`t: expected
/// a 1-D array of numbers, got a 2-D array of shape (2, 401)`).
pub fn vector_arg(name: &str, x: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
    const EXPECTED: &str = "a 1-D array of numbers";
    let got = if x.is_none() {
        "None".to_string()
    } else {
        let a = real_array(name, EXPECTED, x)?;
        match a.shape() {
            [_] => return Ok(a.iter().copied().collect()),
            [] => "a scalar (a 0-D array)".to_string(),
            dims => array_of_shape(dims),
        }
    };
    Err(PyValueError::new_err(format!(
        "{name}: expected {EXPECTED}, got {got}"
    )))
}

/// One real number given as argument `name`: an int or a float (a numpy
/// scalar or a 0-D array too), read by [`real_array`], so that anything
/// else is refused with the argument named, as an array argument's is: a
/// complex or a bool is a TypeError saying so, and so is a string or an
/// array of another shape (`rtol: expected a number, got a str ('1e-6')`,
/// `gamma: expected a number, got a 1-D array of shape (2)`), where PyO3
/// would say only `must be real number, not str`.
pub fn number_arg(name: &str, x: &Bound<'_, PyAny>) -> PyResult<f64> {
    const EXPECTED: &str = "a number";
    let got = if x.is_instance_of::<PyString>() {
        format!("a str ({})", x.repr()?)
    } else if x.is_none() {
        "None".to_string()
    } else {
        let a = real_array(name, EXPECTED, x).map_err(|e| {
            // a value that is not numbers at all is a wrong type here
            if e.is_instance_of::<PyValueError>(x.py()) {
                PyTypeError::new_err(e.value(x.py()).to_string())
            } else {
                e
            }
        })?;
        match a.shape() {
            [] => return Ok(a.iter().copied().next().unwrap_or(f64::NAN)),
            dims => array_of_shape(dims),
        }
    };
    Err(PyTypeError::new_err(format!(
        "{name}: expected {EXPECTED}, got {got}"
    )))
}

/// What a value is, for the messages of the argument readers: its repr
/// and its type, `1 (an int)`, `'yes' (a str)`, or `None`.
fn given(x: &Bound<'_, PyAny>) -> PyResult<String> {
    if x.is_none() {
        return Ok("None".into());
    }
    let t = x.get_type().name()?.to_string();
    let article = if t.starts_with(['a', 'e', 'i', 'o', 'u']) {
        "an"
    } else {
        "a"
    };
    Ok(format!("{} ({article} {t})", x.repr()?))
}

/// A str given as argument `name`; anything else is a TypeError naming
/// the argument (`solver: expected a str, got None`), not PyO3's bare
/// `'None' is not an instance of 'str'`.
pub fn text_arg(name: &str, x: &Bound<'_, PyAny>) -> PyResult<String> {
    match x.cast::<PyString>() {
        Ok(s) => Ok(s.to_string()),
        Err(_) => Err(PyTypeError::new_err(format!(
            "{name}: expected a str, got {}",
            given(x)?
        ))),
    }
}

/// A bool (Python's or numpy's) given as argument `name`; anything else,
/// an int included, is a TypeError naming the argument (`ledger: expected
/// True or False, got 1 (an int)`).
pub fn flag_arg(name: &str, x: &Bound<'_, PyAny>) -> PyResult<bool> {
    let np_bool = x.py().import("numpy")?.getattr("bool_")?;
    if x.is_instance_of::<PyBool>() || x.is_instance(&np_bool)? {
        return x.is_truthy();
    }
    Err(PyTypeError::new_err(format!(
        "{name}: expected True or False, got {}",
        given(x)?
    )))
}

/// An int (Python's or numpy's, not a bool) given as argument `name`, or
/// None; anything else is a TypeError naming the argument and what the
/// int counts (`window: expected an int (samples) or None, got 3.5 (a
/// float)`).
pub fn int_arg(name: &str, counts: &str, x: &Bound<'_, PyAny>) -> PyResult<Option<i64>> {
    if x.is_none() {
        return Ok(None);
    }
    let np_int = x.py().import("numpy")?.getattr("integer")?;
    let is_int =
        (x.is_instance_of::<PyInt>() && !x.is_instance_of::<PyBool>()) || x.is_instance(&np_int)?;
    let bad = || -> PyResult<PyErr> {
        Ok(PyTypeError::new_err(format!(
            "{name}: expected an int ({counts}) or None, got {}",
            given(x)?
        )))
    };
    if !is_int {
        return Err(bad()?);
    }
    x.extract::<i64>().map(Some).or_else(|_| Err(bad()?))
}

/// Extractors of the arguments for `#[pyo3(from_py_with = ...)]`, one per
/// argument name: each reads its argument with [`number_arg`],
/// [`text_arg`], [`flag_arg`] or [`int_arg`] under its name, so that a
/// value of another type is a TypeError naming it (PyO3 0.30 only adds a
/// note to the traceback). PyO3 keeps the signature's default for an
/// argument not given.
pub mod args {
    use super::{flag_arg, int_arg, number_arg, text_arg};
    use pyo3::prelude::*;

    macro_rules! extractors {
        ($($(#[$doc:meta])* $f:ident: $t:ty = $read:ident($($arg:expr),*);)*) => {$(
            $(#[$doc])*
            pub fn $f(x: &Bound<'_, PyAny>) -> PyResult<$t> {
                $read($($arg,)* x)
            }
        )*};
    }

    extractors! {
        /// `gamma` (`xfactor`).
        gamma: f64 = number_arg("gamma");
        /// `rtol` (`simulate`, `simulate_batch`).
        rtol: f64 = number_arg("rtol");
        /// `rk4_step` (`simulate`, `simulate_batch`).
        rk4_step: f64 = number_arg("rk4_step");
        /// `min_share` (`diagnose`).
        min_share: f64 = number_arg("min_share");
        /// `holdout` (`diagnose`).
        holdout: f64 = number_arg("holdout");
        /// `path` (`Rig.set`, `Rig.get`).
        path: String = text_arg("path");
        /// `text` (`Rig.from_json`).
        text: String = text_arg("text");
        /// `ledger` (`simulate`).
        ledger: bool = flag_arg("ledger");
        /// `window` (`diagnose`): None is the smoother's own choice.
        window: Option<i64> = int_arg("window", "samples");
    }

    /// `solver` (`simulate`, `simulate_batch`): a method's name, checked as
    /// the CLI's `--solver` is; a name that is no str is a TypeError naming
    /// the argument. The name is returned as the method's own (`'static`:
    /// the signature's default, `"auto"`, is then a literal its text
    /// signature shows).
    pub fn solver(x: &Bound<'_, PyAny>) -> PyResult<&'static str> {
        let name = text_arg("solver", x)?;
        hydrocyl_system::run::Solver::parse_or_why(&name)
            .map(hydrocyl_system::run::Solver::name)
            .map_err(|why| pyo3::exceptions::PyValueError::new_err(format!("solver: {why}")))
    }

    /// `on_error` (`simulate_batch`): `"raise"` or `"nan"`.
    pub fn on_error(x: &Bound<'_, PyAny>) -> PyResult<&'static str> {
        match text_arg("on_error", x)?.as_str() {
            "raise" => Ok("raise"),
            "nan" => Ok("nan"),
            other => Err(pyo3::exceptions::PyValueError::new_err(format!(
                "on_error: `{other}` is not `raise` or `nan`"
            ))),
        }
    }

    /// `h_max` (`simulate`, `simulate_batch`): None is the default bound.
    pub fn h_max(x: &Bound<'_, PyAny>) -> PyResult<Option<f64>> {
        if x.is_none() {
            return Ok(None);
        }
        number_arg("h_max", x).map(Some)
    }
}

/// A mapping given as argument `name` (`what` its keys and values map,
/// for the message): a dict as it is, or any other object with `keys()`
/// and `[]` — a `collections.abc.Mapping`, a `mappingproxy`, a pandas
/// DataFrame (its columns) — as `dict(x)`, the dict of its items.
/// `None` when `x` is none of these; [`mapping_arg`] makes that an error.
pub fn as_mapping<'py>(x: &Bound<'py, PyAny>) -> PyResult<Option<Bound<'py, PyDict>>> {
    if let Ok(d) = x.cast::<PyDict>() {
        return Ok(Some(d.clone()));
    }
    if x.is_instance_of::<PyString>() || !x.hasattr("keys")? {
        return Ok(None);
    }
    let d = x.py().get_type::<PyDict>().call1((x,))?;
    Ok(Some(d.cast_into::<PyDict>()?))
}

/// [`as_mapping`], where anything else is a TypeError naming the argument
/// (`params: expected a dict of {path: values}, got [('load.mass', ...)]
/// (a list)`).
pub fn mapping_arg<'py>(
    name: &str,
    what: &str,
    x: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyDict>> {
    as_mapping(x)?.ok_or_else(|| match given(x) {
        Ok(g) => PyTypeError::new_err(format!("{name}: expected a dict of {what}, got {g}")),
        Err(e) => e,
    })
}

/// A dict key given in argument `name` that is to be `what` (`parameter
/// path`, `column name`): a str, else a TypeError naming the argument and
/// the key (`params: a key is a parameter path (a str), got 1 (an int)`),
/// not PyO3's bare `'int' object is not an instance of 'str'`.
pub fn key_arg(name: &str, what: &str, k: &Bound<'_, PyAny>) -> PyResult<String> {
    match k.cast::<PyString>() {
        Ok(s) => Ok(s.to_string()),
        Err(_) => Err(PyTypeError::new_err(format!(
            "{name}: a key is a {what} (a str), got {}",
            given(k)?
        ))),
    }
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

/// Named arrays (the channels of a run or a batch), in order, with their
/// units.
pub struct Named<T> {
    /// Names, in order.
    pub names: Vec<String>,
    /// One unit per name: the CLI header's (`m`, `Pa`, `-`; `V` for a
    /// pump rig's `command`).
    pub units: Vec<String>,
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

    /// `{name: unit}`, in order.
    pub fn units_dict<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let d = PyDict::new(py);
        for (n, u) in self.names.iter().zip(&self.units) {
            d.set_item(n, u)?;
        }
        Ok(d)
    }

    /// Whether there is an array named `name`.
    pub fn contains(&self, name: &str) -> bool {
        self.names.iter().any(|n| n == name)
    }

    /// Puts the names (`"names"`), units (`"units"`) and the arrays in
    /// order (`"values"`) into a pickled state `d`.
    pub fn pickle_into(&self, d: &Bound<'_, PyDict>) -> PyResult<()> {
        let py = d.py();
        d.set_item("names", &self.names)?;
        d.set_item("units", &self.units)?;
        d.set_item(
            "values",
            PyList::new(py, self.values.iter().map(|v| v.clone_ref(py)))?,
        )
    }

    /// Named arrays from a pickled state's `names`, `units` and `values`
    /// ([`Named::pickle_into`]); `Err` with what is wrong when their
    /// numbers differ.
    pub fn from_state(
        names: Vec<String>,
        units: Vec<String>,
        values: Vec<Py<T>>,
    ) -> Result<Self, &'static str> {
        if values.len() != names.len() || units.len() != names.len() {
            return Err("names, values and units differ in number");
        }
        Ok(Self {
            names,
            units,
            values,
        })
    }
}

/// A `KeyError` naming the channels there are.
pub fn no_channel(name: &str, names: &[String]) -> PyErr {
    PyKeyError::new_err(format!(
        "no channel `{name}` (channels: {})",
        names.join(", ")
    ))
}
