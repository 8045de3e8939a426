//! Older rig-file kinds read as netlists: one conversion per kind, so that a
//! rig file of an older kind runs, prints (`--print-rig`) and takes `--set`
//! under the netlist's `<component>.<parameter>` scheme like every preset.
//!
//! * `valve-cylinder` ([`ValveRig`]): [`ValveRig::to_netlist`], the
//!   fundamental or generalised valve circuit; initial chamber pressures the
//!   file leaves `null` stay absent, so the netlist computes them from its
//!   steady state at rest ([`super::steady`]) after any `--set`.
//! * `hybrid-pump` ([`WangHybrid`]): [`WangHybrid::to_netlist`], the hybrid
//!   circuit of `fixtures/rigs/wang-hybrid.json` with the file's values.
//! * `friction-bench` ([`bench::to_netlist`]): the circuit of
//!   `fixtures/legacy/circuits/friction-bench.json` (the bench's drive,
//!   measured pressures, piston and `friction_bench` law) with the file's
//!   values; its identification fields
//!   (refits, column map, steady-state flag) become the netlist's
//!   identification section ([`crate::netlist::identify`]).
//!
//! Older files keep loading: every command that takes a rig file reads them
//! through this conversion, with the results of their netlists
//! (`fixtures/legacy/` keeps one of each kind, tested against its netlist in
//! `fixtures/measured/`). `hydrocyl simulate --rig OLD.json --print-rig >
//! NEW.json` writes the netlist.
//!
//! The typed rigs stay the identification and study views of their
//! circuits (`ValveRig::from_netlist`, `WangHybrid::from_netlist`,
//! identify's `FrictionBench::from_netlist`).

use crate::hybrid::{self, WangHybrid};
use crate::rig::RigError;
use crate::valve_rig::{self, ValveRig};
use serde_json::Value;

pub mod bench;

/// The rig kinds that [`migrate`] converts.
pub const MIGRATED_KINDS: [&str; 3] = [valve_rig::KIND, hybrid::KIND, bench::KIND];

/// Deserialises an older rig kind, naming the JSON path of a type error.
pub(crate) fn typed<T: serde::de::DeserializeOwned>(v: &Value) -> Result<T, RigError> {
    serde_path_to_error::deserialize::<_, T>(v.clone()).map_err(|e| {
        let path = e.path().to_string();
        RigError::Invalid {
            path: if path == "." { "rig".into() } else { path },
            why: e.into_inner().to_string(),
        }
    })
}

/// The netlist of a rig value of an older kind ([`MIGRATED_KINDS`]), or
/// `None` for any other kind (a netlist is returned as it is by the caller).
/// Errors name the JSON path in the older file.
pub fn migrate(v: &Value) -> Result<Option<Value>, RigError> {
    match v.get("kind").and_then(Value::as_str) {
        Some(valve_rig::KIND) => {
            let r: ValveRig = typed(v)?;
            r.validate()?;
            let mut n = r.to_netlist()?;
            // pressures the file leaves to the steady state stay so
            let absent = ["p1", "p2"].iter().all(|k| {
                v.pointer(&format!("/initial/{k}"))
                    .is_none_or(Value::is_null)
            });
            if absent {
                if let Some(init) = n
                    .pointer_mut("/components/cylinder/initial")
                    .and_then(Value::as_object_mut)
                {
                    for k in ["p1", "p2", "load_pressure"] {
                        init.remove(k);
                    }
                }
            }
            Ok(Some(n))
        }
        Some(hybrid::KIND) => {
            let r: WangHybrid = typed(v)?;
            r.validate()?;
            let mut n = r.to_netlist()?;
            for k in ["name", "description"] {
                if let Some(s) = v.get(k).filter(|s| s.is_string()) {
                    n[k] = s.clone();
                }
            }
            Ok(Some(n))
        }
        Some(bench::KIND) => bench::to_netlist(v).map(Some),
        _ => Ok(None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::RunOptions;
    use crate::signal::Signal;

    /// The largest relative difference between two runs' common channels.
    fn worst(a: &crate::run::Run, b: &crate::run::Run) -> f64 {
        let mut w: f64 = 0.0;
        for c in &a.channels {
            let Some(d) = b.channel(&c.name) else {
                continue;
            };
            let scale = c.values.iter().fold(1e-12f64, |m, x| m.max(x.abs()));
            for (x, y) in c.values.iter().zip(d) {
                w = w.max((x - y).abs() / scale);
            }
        }
        w
    }

    /// A `valve-cylinder` file and its migrated netlist simulate alike (the
    /// old kind's own circuit: the typed rig's), and `--set` reaches the
    /// migrated file under the netlist's paths; its steady initial pressures
    /// follow a changed supply.
    #[test]
    fn a_valve_cylinder_file_migrates_to_an_equal_netlist() {
        let old = serde_json::to_value(ValveRig::leaney_moog()).unwrap();
        let new = migrate(&old).unwrap().unwrap();
        assert_eq!(new["kind"], crate::netlist::KIND);
        let t: Vec<f64> = (0..=200).map(|k| k as f64 * 1e-3).collect();
        let cmd = || Signal::Constant { value: 0.3 };
        let a = ValveRig::leaney_moog()
            .simulate(cmd(), &t, &RunOptions::default())
            .unwrap();
        let b = crate::netlist::simulate(&new, cmd(), &t, &RunOptions::default()).unwrap();
        assert!(a.channel("velocity").unwrap()[200] > 0.01);
        let w = worst(&a, &b);
        assert!(w < 1e-9, "relative difference {w}");
        // --set on the migrated file, under the netlist's paths
        let mut set = new.clone();
        crate::rig::apply_set(&mut set, "cylinder.initial.position=0.05").unwrap();
        crate::rig::apply_set(&mut set, "supply.pressure=5e6").unwrap();
        let c = crate::netlist::simulate(&set, cmd(), &t, &RunOptions::default()).unwrap();
        assert!((c.channel("position").unwrap()[0] - 0.05).abs() < 1e-12);
        let mut lower = ValveRig::leaney_moog();
        lower.supply.pressure_pa = 5e6;
        let p1 = lower.initial_pressures().unwrap().0;
        assert!((c.channel("p1").unwrap()[0] - p1).abs() < 1e-6 * p1);
    }

    /// `null` for a number in an older rig kind is refused by its JSON path
    /// (tester t38d D10: a netlist took it as the default), in each kind;
    /// a `valve-cylinder` file's initial `p1`/`p2` keep `null` (steady state).
    #[test]
    fn null_for_a_number_in_an_older_kind_is_refused_by_its_path() {
        let valve = serde_json::to_value(ValveRig::leaney_moog()).unwrap();
        let hybrid = serde_json::to_value(WangHybrid::preset()).unwrap();
        let bench: Value = serde_json::from_str(include_str!(
            "../../../../fixtures/legacy/bench-acceleration_friction.rig.json"
        ))
        .unwrap();
        for (old, pointer, path) in [
            (&valve, "/valve/null_bias_m", "valve.null_bias_m"),
            (&valve, "/load/mass_kg", "load.mass_kg"),
            (&hybrid, "/pump_line_volume", "pump_line_volume"),
            (&bench, "/friction/coulomb", "friction.coulomb"),
            (
                &bench,
                "/friction/effects/viscous/b",
                "friction.effects.viscous.b",
            ),
        ] {
            let mut v = old.clone();
            *v.pointer_mut(pointer).unwrap() = Value::Null;
            let e = migrate(&v).unwrap_err().to_string();
            assert!(
                e.contains(&format!("`{path}`")) && e.contains("null"),
                "{path}: {e}"
            );
        }
        let mut v = valve.clone();
        v["initial"]["p1"] = Value::Null;
        v["initial"]["p2"] = Value::Null;
        assert!(migrate(&v).unwrap().is_some());
    }

    /// A `hybrid-pump` file and its migrated netlist simulate alike.
    #[test]
    fn a_hybrid_pump_file_migrates_to_an_equal_netlist() {
        let old = serde_json::to_value(WangHybrid::preset()).unwrap();
        assert_eq!(old["kind"], hybrid::KIND);
        let new = migrate(&old).unwrap().unwrap();
        let t: Vec<f64> = (0..=100).map(|k| k as f64 * 2e-3).collect();
        let cmd = || Signal::Constant { value: 2.0 };
        let a = WangHybrid::preset()
            .simulate(cmd(), &t, &RunOptions::default())
            .unwrap();
        let b = crate::netlist::simulate(&new, cmd(), &t, &RunOptions::default()).unwrap();
        assert!(a.channel("position").unwrap()[100] != a.channel("position").unwrap()[0]);
        let w = worst(&a, &b);
        assert!(w < 1e-9, "relative difference {w}");
    }

    /// The typed view of a migrated `valve-cylinder` file is the file's own
    /// rig, field for field (so a study or a diagnosis on either starts from
    /// the same model): the measured-data fixture and the built-in rig.
    #[test]
    fn a_migrated_valve_rig_reads_back_as_the_same_rig() {
        let festo: Value = serde_json::from_str(include_str!(
            "../../../../fixtures/legacy/festo-hanging-load.rig.json"
        ))
        .unwrap();
        let leaney = serde_json::to_value(ValveRig::leaney_moog()).unwrap();
        for old in [festo, leaney] {
            let typed = crate::rig::valve_rig_from(&old).unwrap();
            let back = ValveRig::from_netlist(&migrate(&old).unwrap().unwrap()).unwrap();
            assert_eq!(back, typed, "{}", typed.name);
        }
    }

    /// Each older file kept in `fixtures/legacy/` loads as the netlist that
    /// replaced it in `fixtures/measured/`, parameter for parameter (both
    /// with every default written out): the same circuit and the same
    /// identification section, so every command gives the same results on
    /// either file.
    #[test]
    fn legacy_files_load_as_their_netlists() {
        let fixtures = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
        let mut seen = 0;
        for entry in std::fs::read_dir(fixtures.join("legacy")).unwrap() {
            let old = entry.unwrap().path();
            if old.is_dir() {
                continue; // `circuits/`: what the older kinds become
            }
            let new = fixtures.join("measured").join(old.file_name().unwrap());
            let loaded = crate::rig::load(old.to_str().unwrap()).unwrap();
            let file = crate::rig::load(new.to_str().unwrap()).unwrap();
            assert_eq!(file["kind"], crate::netlist::KIND, "{}", new.display());
            assert_eq!(
                crate::netlist::expanded(&loaded).unwrap(),
                crate::netlist::expanded(&file).unwrap(),
                "{}",
                old.display()
            );
            seen += 1;
        }
        assert!(seen >= 4, "{seen}");
    }

    #[test]
    fn errors_name_the_path_in_the_older_file() {
        let mut old = serde_json::to_value(ValveRig::leaney_moog()).unwrap();
        old["load"]["mass_kg"] = Value::from("heavy");
        let e = migrate(&old).unwrap_err().to_string();
        assert!(e.contains("load.mass_kg"), "{e}");
        let e = migrate(&serde_json::json!({"kind": "netlist"})).unwrap();
        assert!(e.is_none());
    }
}
