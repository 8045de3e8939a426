//! `hydrocyl.diagnose`: `hydrocyl diagnose` on a valve rig and one measured
//! record (crate `hydrocyl-identify`): residuals, the missing effects,
//! refits, before/after; the report as a dict (the CLI's `--report` JSON).

use crate::convert::{args, as_mapping, json_to_py, key_arg, vector_arg};
use crate::errors::{detached, Failure};
use crate::rig::Rig;
use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::data::{ColumnMap, Record};
use hydrocyl_identify::diagnose::DiagnoseOptions;
use hydrocyl_identify::valve::diagnose_valve;
use hydrocyl_system::rig::valve_rig_from;
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// Name of a record given as a dict, in messages (its CSV rows: row 2 is
/// element 0).
const DICT_RECORD: &str = "record (dict; row 2 = element 0)";

/// The measured record: a CSV path (str or path-like), or a dict of
/// equal-length arrays keyed by measured-data column names (`time`,
/// `command`, `position`, `p1 [bar]`, ...), checked by the same rules.
fn read_record(obj: &Bound<'_, PyAny>) -> PyResult<Record> {
    let input = |e: hydrocyl_identify::data::DataError| PyValueError::new_err(e.to_string());
    if let Some(d) = as_mapping(obj)? {
        let mut w = csv::Writer::from_writer(Vec::new());
        let mut cols = Vec::new();
        let mut header = Vec::new();
        for (k, v) in d.iter() {
            let name = key_arg("record", "column name", &k)?;
            cols.push(vector_arg(&format!("{DICT_RECORD}: column '{name}'"), &v)?);
            header.push(name);
        }
        let csv_err = |e: csv::Error| PyValueError::new_err(format!("{DICT_RECORD}: {e}"));
        w.write_record(&header).map_err(csv_err)?;
        // the columns' headers in quotes, as the CSV readers name them
        let longest = (0..cols.len()).max_by_key(|&j| (cols[j].len(), usize::MAX - j));
        let n = longest.map_or(0, |j| cols[j].len());
        if let Some((h, c)) = header.iter().zip(&cols).find(|(_, c)| c.len() != n) {
            return Err(PyValueError::new_err(format!(
                "{DICT_RECORD}: column '{h}' has {} values, column '{}' {n}",
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
            .map_err(|e| PyValueError::new_err(format!("{DICT_RECORD}: {e}")))?;
        return Record::parse(
            DICT_RECORD,
            &String::from_utf8_lossy(&text),
            &ColumnMap::default(),
        )
        .map_err(input);
    }
    let path: std::path::PathBuf = obj.extract().map_err(|_| {
        PyValueError::new_err("record: a CSV path or a dict of arrays by column name")
    })?;
    Record::read(&path).map_err(input)
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

/// Diagnoses `rig` (the valve-cylinder circuit: its netlist, e.g. the
/// `leaney-moog` preset, or a `valve-cylinder` rig file) against one measured `record` as
/// `hydrocyl diagnose --rig ... --data ...` does and returns its report as
/// a dict (NRMSEs before/after, effects added and rejected with their
/// parameters in SI, declared parameters refitted, warnings).
///
/// `record`: a CSV path or a dict of arrays by column name (measured-data
/// format: `time` [s], `command`, `position` [m], optionally `velocity`,
/// `p1`, `p2` [Pa gauge]; unit suffixes such as `p1 [bar]` convert).
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
    let valve =
        valve_rig_from(&rig.snapshot()).map_err(|e| PyValueError::new_err(e.to_string()))?;
    let rec = read_record(record)?;
    let opts = DiagnoseOptions {
        min_share,
        holdout,
        half_window: window,
        candidates,
        ..DiagnoseOptions::default()
    };
    let report = detached(py, || {
        let r = diagnose_valve(&valve, &rec, &opts, &mut |_, _, _| {})
            .map_err(|e| Failure::Input(e.to_string()))?;
        serde_json::to_value(&r).map_err(|e| Failure::Input(format!("report: {e}")))
    })?;
    json_to_py(py, &report)
}
