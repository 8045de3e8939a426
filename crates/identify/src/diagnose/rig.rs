//! Which loop a rig is diagnosed by, and through which column map its
//! records are read: said once for every front end (the CLI's `hydrocyl
//! diagnose`, Python's `hydrocyl.diagnose`). A friction bench runs
//! [`diagnose_bench`] on one record or several fitted jointly; any netlist
//! with a cylinder on a mass (the valve rig, the hybrid rig, a user's
//! circuit) runs [`diagnose_rig_traced`] on one record.

use serde_json::Value;
use thiserror::Error;

use crate::bench::{self, is_bench_rig, FrictionBench};
use crate::data::{ColumnMap, Record, Signal};
use crate::diagnose::{diagnose_bench, DiagnoseError, DiagnoseOptions, RecordTrace, Report};
use crate::valve::{diagnose_rig_traced, Model};
use hydrocyl_system::{netlist, rig, valve_rig};

/// A rig `diagnose` can run.
#[derive(Clone, Debug)]
pub enum DiagnoseRig {
    /// A friction bench: a netlist whose identification section names the
    /// `friction-bench` model (its column map in [`FrictionBench::columns`]).
    Bench(FrictionBench),
    /// Any netlist with a cylinder on a mass (the valve rig, the hybrid rig,
    /// a user's circuit), or a `valve-cylinder` rig value as its netlist;
    /// with the column map of its identification section
    /// (`identify.columns`).
    Net(Box<Model>, ColumnMap),
}

/// Why a rig value is not one `diagnose` can run. The message is what
/// follows the rig's name (`--rig NAME: <message>`).
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RigKindError {
    /// A friction bench whose identification view does not read (by JSON
    /// path).
    #[error("{0}")]
    Bench(String),
    /// Neither a friction bench nor a netlist with a cylinder on a mass.
    #[error("not supported for this rig kind (diagnose takes a netlist with a `cylinder` on a `mass`, a valve-cylinder rig file or a friction bench): {0}")]
    Unsupported(String),
}

impl DiagnoseRig {
    /// The rig `diagnose` runs for a rig value (a preset's JSON or a rig
    /// file as read and checked, [`hydrocyl_system::rig::load`]): a
    /// friction bench where [`is_bench_rig`] says so
    /// ([`FrictionBench::from_rig`]); else a netlist (or `valve-cylinder`
    /// value) with a cylinder on a mass, its column map from
    /// `identify.columns`; any other kind or circuit is
    /// [`RigKindError::Unsupported`].
    pub fn from_value(v: &Value) -> Result<Self, RigKindError> {
        if is_bench_rig(v) {
            return FrictionBench::from_rig(v)
                .map(Self::Bench)
                .map_err(RigKindError::Bench);
        }
        let kind = v.get("kind").and_then(Value::as_str).unwrap_or("");
        if kind != netlist::KIND && kind != valve_rig::KIND {
            return Err(RigKindError::Unsupported(format!(
                "kind '{kind}' (kinds: {}, {}, {})",
                bench::KIND,
                netlist::KIND,
                valve_rig::KIND
            )));
        }
        let model = net_model(v).map_err(RigKindError::Unsupported)?;
        let columns = net_columns(v).map_err(RigKindError::Unsupported)?;
        Ok(Self::Net(Box::new(model), columns))
    }

    /// The column map the rig's records are read through
    /// ([`Record::read_mapped`], [`Record::parse`]).
    pub fn columns(&self) -> &ColumnMap {
        match self {
            Self::Bench(b) => &b.columns,
            Self::Net(_, columns) => columns,
        }
    }

    /// Runs the loop on `records` (read through [`DiagnoseRig::columns`]):
    /// the report and the measured and simulated series per record and
    /// compared channel. A bench fits several records jointly; a circuit
    /// takes one ([`DiagnoseError::OneRecordAtATime`] for more);
    /// [`DiagnoseError::NoData`] for none.
    pub fn diagnose(
        &self,
        records: &[Record],
        opts: &DiagnoseOptions,
        progress: &mut dyn FnMut(&str, usize, usize),
    ) -> Result<(Report, Vec<RecordTrace>), DiagnoseError> {
        match self {
            Self::Bench(b) => {
                diagnose_bench(b, records, opts, progress).map(|o| (o.report, o.traces))
            }
            Self::Net(m, _) => match records {
                [] => Err(DiagnoseError::NoData),
                [rec] => diagnose_rig_traced(m, rec, opts, progress).map(|o| (o.report, o.traces)),
                _ => Err(DiagnoseError::OneRecordAtATime(records.len())),
            },
        }
    }
}

/// The column map of a netlist's identification section
/// (`identify.columns`); a role that is no measured-data signal is refused
/// by its path.
fn net_columns(v: &Value) -> Result<ColumnMap, String> {
    let s = netlist::read(v).map_err(|e| rig::RigError::from(e).to_string())?;
    let mut map = ColumnMap::default();
    for (role, header) in s.identify.map(|i| i.columns).unwrap_or_default() {
        let sig = Signal::from_name(&role)
            .ok_or_else(|| format!("`identify.columns.{role}`: not a measured-data signal"))?;
        map.0.insert(sig, header);
    }
    Ok(map)
}

/// The model of a netlist with a cylinder on a mass, or of a
/// `valve-cylinder` value (its netlist, the sensor lag taken into the
/// measurement model).
fn net_model(v: &Value) -> Result<Model, String> {
    if v.get("kind").and_then(Value::as_str) == Some(valve_rig::KIND) {
        let r = rig::valve_rig_from(v).map_err(|e| e.to_string())?;
        return Model::from_valve_rig(&r);
    }
    Model::new(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A cylinder netlist's identification section gives diagnose its column
    /// map; a bad role is refused by its path.
    #[test]
    fn a_cylinder_netlist_brings_its_column_map() {
        let mut v = rig::preset("leaney-moog").unwrap();
        assert_eq!(net_columns(&v).unwrap(), ColumnMap::default());
        v["identify"] = serde_json::json!({ "columns": { "position": "x_mm [mm]" } });
        let map = net_columns(&v).unwrap();
        assert_eq!(map.0[&Signal::Position], "x_mm [mm]");
        assert!(matches!(DiagnoseRig::from_value(&v), Ok(DiagnoseRig::Net(_, ref m)) if *m == map));
        v["identify"]["columns"] = serde_json::json!({ "x": "x_mm [mm]" });
        let e = net_columns(&v).unwrap_err();
        assert!(e.contains("identify.columns.x"), "{e}");
    }

    /// The bench presets are benches (the bench `bench::preset` reads),
    /// the circuits with a cylinder nets; a netlist without one and a value
    /// of another kind are unsupported, with the reason.
    #[test]
    fn each_rig_gets_its_kind_of_diagnose() {
        for name in bench::PRESETS {
            let got = DiagnoseRig::from_value(&rig::preset(name).unwrap());
            let Ok(DiagnoseRig::Bench(b)) = got else {
                panic!("{name}: {got:?}");
            };
            assert_eq!(Some(b), bench::preset(name), "{name}");
        }
        for name in ["leaney-moog", "wang-hybrid"] {
            let got = DiagnoseRig::from_value(&rig::preset(name).unwrap());
            assert!(matches!(got, Ok(DiagnoseRig::Net(..))), "{name}: {got:?}");
        }
        let e = DiagnoseRig::from_value(&serde_json::json!({ "kind": "gearbox" })).unwrap_err();
        assert!(matches!(e, RigKindError::Unsupported(_)), "{e}");
        assert!(
            e.to_string()
                .ends_with("kind 'gearbox' (kinds: friction-bench, netlist, valve-cylinder)"),
            "{e}"
        );
    }
}
