//! `hydrocyl.diagnose`: `hydrocyl diagnose` on any rig the CLI diagnoses
//! (a friction bench, or a netlist with a cylinder on a mass: the choice is
//! `hydrocyl_identify::diagnose::DiagnoseRig`'s, the CLI's) and one measured
//! record or several fitted jointly: residuals, the missing effects,
//! refits, before/after; the report as a dict (the CLI's `--report` JSON).

use crate::convert::{args, as_mapping, json_to_py, key_arg, vector_arg};
use crate::errors::{detached, Failure};
use crate::rig::Rig;
use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::data::{repeated_record, ColumnMap, Record, RecordInput};
use hydrocyl_identify::diagnose::{DiagnoseError, DiagnoseOptions, DiagnoseRig};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::{PyList, PyTuple};
use std::path::PathBuf;

/// Name of a record given as a dict, in messages (its CSV rows: row 2 is
/// element 0); `record <k> (dict; ...)` for the `k`-th (from 1) of a list.
const DICT_RECORD: &str = "record (dict; row 2 = element 0)";

/// A measured record as given, before the rig's column map reads it: a CSV
/// file, or a dict of arrays written as CSV text under its name.
enum Given {
    /// A CSV file.
    File(PathBuf),
    /// A dict's columns as CSV text, and the name messages give it.
    Text(String, Vec<u8>),
}

impl Given {
    /// As [`repeated_record`] compares it.
    fn input(&self) -> RecordInput<'_> {
        match self {
            Given::File(p) => RecordInput::File(p),
            Given::Text(_, t) => RecordInput::Text(t),
        }
    }

    /// The record in a message refusing it as given twice.
    fn label(&self, k: usize) -> String {
        match self {
            Given::File(p) => format!("record {}", p.display()),
            Given::Text(..) => format!("record {} (dict)", k + 1),
        }
    }

    /// The record read through the rig's column map `columns`, as the CLI
    /// reads a `--data` file.
    fn read(&self, columns: &ColumnMap) -> PyResult<Record> {
        let input = |e: hydrocyl_identify::data::DataError| PyValueError::new_err(e.to_string());
        match self {
            Given::File(p) => Record::read_mapped(p, columns).map_err(input),
            Given::Text(name, t) => {
                Record::parse(name, &String::from_utf8_lossy(t), columns).map_err(input)
            }
        }
    }
}

/// One measured record: a CSV path (str or path-like), or a dict of
/// equal-length arrays keyed by measured-data column names (`time`,
/// `command`, `position`, `p1 [bar]`, ...; or the headers of the rig's
/// column map), written as CSV text and read by the same rules; `name`
/// names a dict in messages.
fn given_record(obj: &Bound<'_, PyAny>, name: &str) -> PyResult<Given> {
    if let Some(d) = as_mapping(obj)? {
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut cols = Vec::new();
        let mut header = Vec::new();
        for (k, v) in d.iter() {
            let column = key_arg("record", "column name", &k)?;
            cols.push(vector_arg(&format!("{name}: column '{column}'"), &v)?);
            header.push(column);
        }
        let csv_err = |e: csv::Error| PyValueError::new_err(format!("{name}: {e}"));
        w.write_record(&header).map_err(csv_err)?;
        // the columns' headers in quotes, as the CSV readers name them
        let longest = (0..cols.len()).max_by_key(|&j| (cols[j].len(), usize::MAX - j));
        let n = longest.map_or(0, |j| cols[j].len());
        if let Some((h, c)) = header.iter().zip(&cols).find(|(_, c)| c.len() != n) {
            return Err(PyValueError::new_err(format!(
                "{name}: column '{h}' has {} values, column '{}' {n}",
                c.len(),
                header[longest.unwrap_or(0)]
            )));
        }
        for i in 0..n {
            w.write_record(cols.iter().map(|c| format!("{:?}", c[i])))
                .map_err(csv_err)?;
        }
        let text = w
            .into_inner()
            .map_err(|e| PyValueError::new_err(format!("{name}: {e}")))?;
        return Ok(Given::Text(name.to_string(), text));
    }
    let path: PathBuf = obj.extract().map_err(|_| {
        PyValueError::new_err(
            "record: a CSV path or a dict of arrays by column name, or a list of those",
        )
    })?;
    Ok(Given::File(path))
}

/// The `record` argument as the records it gives: a list or tuple is
/// several (fitted jointly, as the CLI's repeated `--data`), anything else
/// one.
fn given_records(obj: &Bound<'_, PyAny>) -> PyResult<Vec<Given>> {
    if obj.is_instance_of::<PyList>() || obj.is_instance_of::<PyTuple>() {
        return obj
            .try_iter()?
            .enumerate()
            .map(|(k, r)| given_record(&r?, &format!("record {} (dict; row 2 = element 0)", k + 1)))
            .collect();
    }
    Ok(vec![given_record(obj, DICT_RECORD)?])
}

/// The `effects` argument as ids: a string is one id, or several separated by
/// commas (as `--effects`); a sequence of strings is a list of ids.
fn effect_ids(obj: &Bound<'_, PyAny>) -> PyResult<Vec<String>> {
    if let Ok(s) = obj.extract::<String>() {
        return Ok(s.split(',').map(|id| id.trim().to_string()).collect());
    }
    obj.extract::<Vec<String>>().map_err(|_| {
        pyo3::exceptions::PyTypeError::new_err(format!(
            "effects: a list of effect ids or one id as a string, got {}",
            obj.get_type()
                .name()
                .map_or_else(|_| "?".to_string(), |n| n.to_string())
        ))
    })
}

/// Diagnoses `rig` against measured `record`(s) as `hydrocyl diagnose
/// --rig ... --data ...` does and returns its report as a dict (the JSON
/// of `--report`: NRMSEs before/after, effects added and rejected with
/// their parameters in SI, declared parameters refitted, warnings).
///
/// `rig`: every rig the CLI's `diagnose` takes — a friction bench (the
/// `tudelft-seal-25`, `tudelft-seal-257` and `emps` presets, or a netlist
/// whose `identify` section names the `friction-bench` model), or any
/// netlist with a `cylinder` (or `generalised_cylinder`) on a `mass` (the
/// valve rig `leaney-moog`, the hybrid rig `wang-hybrid`, a user's
/// circuit). Another rig is a ValueError naming why.
///
/// `record`: a CSV path or a dict of arrays by column name (measured-data
/// format: `time` [s], `command`, `position` [m], optionally `velocity`,
/// `p1`, `p2` [Pa gauge], `force` [N]; unit suffixes such as `p1 [bar]`
/// convert), read through the column map of the rig's `identify.columns`
/// as the CLI reads it; or a list of those, fitted jointly (a friction
/// bench; a circuit takes one record at a time). A record given twice (the
/// same file, or the same content) is refused: its samples would count
/// twice.
/// `min_share`, `holdout`, `window`, `effects` are the CLI's options;
/// `effects` is a list of effect ids or one string, which is split at commas
/// as the CLI's `--effects` is (`"internal_leakage"`, `"a,b"`); anything else
/// is a TypeError naming the argument.
/// The GIL is released while it runs. ValueError with the CLI's message
/// for bad input.
#[pyfunction]
#[pyo3(signature = (rig, record, *, min_share = 0.03, holdout = 0.3, window = None, effects = None))]
pub fn diagnose<'py>(
    py: Python<'py>,
    rig: &Rig,
    record: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::min_share)] min_share: f64,
    #[pyo3(from_py_with = args::holdout)] holdout: f64,
    #[pyo3(from_py_with = args::window)] window: Option<i64>,
    effects: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyAny>> {
    let bad = |m: String| Err(PyValueError::new_err(m));
    if !(0.0..1.0).contains(&min_share) {
        return bad(format!("min_share {min_share}: must be in [0, 1)"));
    }
    if !(0.05..=0.5).contains(&holdout) {
        return bad(format!("holdout {holdout}: must be in [0.05, 0.5]"));
    }
    let window = match window.map(|w| (w, hydrocyl_identify::smooth::check_half_window(w))) {
        Some((w, Err(why))) => return bad(format!("window {w}: {why}")),
        Some((_, Ok(h))) => Some(h),
        None => None,
    };
    let effects = effects.map(effect_ids).transpose()?;
    let candidates = effects
        .map(|ids| {
            ids.iter()
                .map(|id| {
                    EffectId::from_id(id.trim()).ok_or_else(|| {
                        PyValueError::new_err(format!("effects: unknown effect '{id}'"))
                    })
                })
                .collect::<PyResult<Vec<_>>>()
        })
        .transpose()?;
    // a record given twice would count its samples twice (the CLI's rule)
    let given = given_records(record)?;
    let inputs: Vec<RecordInput<'_>> = given.iter().map(Given::input).collect();
    if let Some(r) = repeated_record(&inputs) {
        return bad(r.message(
            &given[r.first].label(r.first),
            &given[r.second].label(r.second),
            "records",
        ));
    }
    // which loop, with which column map: the CLI's decision
    let rig = DiagnoseRig::from_value(&rig.snapshot())
        .map_err(|e| PyValueError::new_err(format!("rig: {e}")))?;
    let records = given
        .iter()
        .map(|g| g.read(rig.columns()))
        .collect::<PyResult<Vec<_>>>()?;
    let opts = DiagnoseOptions {
        min_share,
        holdout,
        half_window: window,
        candidates,
        ..DiagnoseOptions::default()
    };
    let report = detached(py, || {
        let (r, _) = rig
            .diagnose(&records, &opts, &mut |_, _, _| {})
            .map_err(|e| match e {
                DiagnoseError::OneRecordAtATime(_) => Failure::Input(format!("record: {e}")),
                e => Failure::Input(e.to_string()),
            })?;
        serde_json::to_value(&r).map_err(|e| Failure::Input(format!("report: {e}")))
    })?;
    json_to_py(py, &report)
}
