//! The `friction-bench` kind read as a netlist: the circuit of
//! `fixtures/legacy/circuits/friction-bench.json` ([`CIRCUIT`]: a drive
//! imposing the record's velocity and acceleration, `imposed_motion` fed by
//! the inputs `drive` and `acceleration`; the record's chamber pressures on
//! `signal_pressure_source`s, inputs `p1`, `p2`; the cylinder under test
//! `cylinder`, a rigid `piston` keeping its position in the bore; and the
//! `friction_bench` law), with the file's values set by netlist path: its
//! mass, force sign, areas, Coulomb level and catalog effects.
//!
//! The file's identification fields (`refit`, `columns`, `steady_state`)
//! become the netlist's identification section ([`crate::netlist::identify`],
//! model `friction-bench`), the refits under their netlist paths
//! ([`refit_path`]: `Fc` is `friction.coulomb`, `viscous.b` is
//! `friction.viscous`).

use super::typed;
use crate::netlist::registry;
use crate::rig::RigError;
use serde::Deserialize;
use serde_json::{json, Map, Value};
use std::collections::BTreeMap;

/// The circuit a friction-bench file becomes (its values filled in by
/// netlist path): `fixtures/legacy/circuits/friction-bench.json`.
pub const CIRCUIT: &str =
    include_str!("../../../../../fixtures/legacy/circuits/friction-bench.json");

/// The `kind` of a friction-bench rig file.
pub const KIND: &str = "friction-bench";

/// The names of a bench netlist's inputs, in the order a record gives them:
/// the imposed velocity \[m/s\], the imposed acceleration \[m/s²\] and the
/// chamber pressures p1, p2 \[Pa\].
pub const INPUTS: [&str; 4] = ["drive", "acceleration", "p1", "p2"];

/// The friction component's name in a bench netlist.
pub const FRICTION: &str = "friction";

/// The drive's name in a bench netlist (the `imposed_motion` with the
/// moving mass and the load cell).
pub const DRIVE: &str = "drive";

/// The cylinder under test's name in a bench netlist (the `piston` with
/// the chamber areas and its position in the bore).
pub const CYLINDER: &str = "cylinder";

/// The catalog effects a friction bench carries, each parameter with the
/// `friction_bench` parameter it is.
pub const EFFECT_PARAMS: &[(&str, &str, &str)] = &[
    ("coulomb_asymmetry", "dFc", "asymmetry"),
    ("stribeck", "Fs", "stiction"),
    ("stribeck", "vs", "stribeck_velocity"),
    ("stribeck", "alpha", "stribeck_exponent"),
    ("viscous", "b", "viscous"),
    ("pressure_viscous", "K", "seal.k_pressure"),
    ("acceleration_friction", "H", "seal.h_acceleration"),
    ("lugre_dynamics", "sigma0", "sigma0"),
    ("lugre_dynamics", "sigma1", "sigma1"),
    ("external_force", "F0", "external_force"),
];

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(dead_code)] // `kind` is matched before
struct BenchFile {
    kind: String,
    name: String,
    #[serde(default)]
    area1: f64,
    #[serde(default)]
    area2: f64,
    mass: f64,
    force_sign: f64,
    friction: FrictionFile,
    #[serde(default)]
    steady_state: bool,
    #[serde(default)]
    refit: Vec<String>,
    #[serde(default)]
    columns: Map<String, Value>,
}

/// The netlist path of a fitted parameter as a `friction-bench` file names
/// it: a netlist path (`friction.coulomb`, `drive.mass`,
/// `friction.<parameter>`) as it is, or the catalog name `Fc`, `m` or
/// `effect.param` (`viscous.b` → `friction.viscous`, through
/// [`EFFECT_PARAMS`]); `None` for anything else.
pub fn refit_path(name: &str) -> Option<String> {
    match name {
        "Fc" => return Some(format!("{FRICTION}.coulomb")),
        "m" => return Some(format!("{DRIVE}.mass")),
        _ => {}
    }
    let (a, b) = name.split_once('.')?;
    if let Some((_, _, target)) = EFFECT_PARAMS.iter().find(|(e, p, _)| *e == a && *p == b) {
        return Some(format!("{FRICTION}.{target}"));
    }
    let known = match a {
        DRIVE => b == "mass",
        FRICTION => b == "coulomb" || EFFECT_PARAMS.iter().any(|(_, _, t)| *t == b),
        _ => false,
    };
    known.then(|| name.to_string())
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct FrictionFile {
    coulomb: f64,
    smoothing_velocity: f64,
    #[serde(default)]
    effects: BTreeMap<String, BTreeMap<String, f64>>,
}

fn out_of_range(path: &str, value: f64, why: &str) -> RigError {
    RigError::OutOfRange {
        path: path.into(),
        value,
        why: why.into(),
    }
}

/// The netlist of a `friction-bench` rig value; errors name the path in
/// the file (`friction.effects.stribeck.vs`).
pub fn to_netlist(v: &Value) -> Result<Value, RigError> {
    let f: BenchFile = typed(v)?;
    for (path, x) in [("area1", f.area1), ("area2", f.area2), ("mass", f.mass)] {
        if !(x.is_finite() && x >= 0.0) {
            return Err(out_of_range(path, x, "must be finite and >= 0"));
        }
    }
    if f.force_sign != 1.0 && f.force_sign != -1.0 {
        return Err(out_of_range("force_sign", f.force_sign, "must be 1 or -1"));
    }
    let spec = registry::lookup("friction_bench").expect("friction_bench is in the catalog");
    let check = |path: &str, name: &str, x: f64| -> Result<(), RigError> {
        let p = spec
            .params
            .iter()
            .find(|p| p.name == name)
            .expect("EFFECT_PARAMS names friction_bench parameters");
        if p.range.contains(x) {
            Ok(())
        } else {
            Err(out_of_range(
                path,
                x,
                &format!("must be {} [{}]", p.range.describe(), p.unit),
            ))
        }
    };
    check("friction.coulomb", "coulomb", f.friction.coulomb)?;
    check(
        "friction.smoothing_velocity",
        "smoothing_velocity",
        f.friction.smoothing_velocity,
    )?;
    let mut v: Value =
        serde_json::from_str(CIRCUIT).expect("the embedded bench circuit is valid JSON (tested)");
    v["name"] = Value::from(f.name.clone());
    let mut sets: Vec<(String, f64)> = vec![
        (format!("{DRIVE}.mass"), f.mass),
        (format!("{DRIVE}.force_sign"), f.force_sign),
        (format!("{CYLINDER}.area_1"), f.area1),
        (format!("{CYLINDER}.area_2"), f.area2),
        (format!("{FRICTION}.coulomb"), f.friction.coulomb),
        (
            format!("{FRICTION}.smoothing_velocity"),
            f.friction.smoothing_velocity,
        ),
    ];
    for (id, params) in &f.friction.effects {
        let here = format!("friction.effects.{id}");
        let of_effect: Vec<_> = EFFECT_PARAMS.iter().filter(|(e, _, _)| e == id).collect();
        if of_effect.is_empty() {
            let mut known: Vec<&str> = EFFECT_PARAMS.iter().map(|(e, _, _)| *e).collect();
            known.dedup();
            return Err(RigError::Invalid {
                path: here,
                why: format!(
                    "`{id}` is not an effect of the friction bench's force balance (known: {})",
                    known.join(", ")
                ),
            });
        }
        if let Some(k) = params
            .keys()
            .find(|k| !of_effect.iter().any(|(_, p, _)| p == k))
        {
            return Err(RigError::Invalid {
                path: format!("{here}.{k}"),
                why: format!("unknown parameter of `{id}`"),
            });
        }
        for (_, p, target) in &of_effect {
            let path = format!("{here}.{p}");
            let x = *params.get(*p).ok_or_else(|| RigError::Invalid {
                path: here.clone(),
                why: format!("parameter `{p}` missing"),
            })?;
            check(&path, target, x)?;
            if *target == "sigma0" && x <= 0.0 {
                return Err(out_of_range(&path, x, "must be > 0"));
            }
            sets.push((format!("{FRICTION}.{target}"), x));
        }
    }
    for (path, x) in sets {
        crate::netlist::set(&mut v, &path, Value::from(x))?;
    }
    let mut identify = Map::new();
    identify.insert(
        "model".into(),
        json!(crate::netlist::identify::IdentifyModel::FrictionBench.name()),
    );
    if !f.columns.is_empty() {
        identify.insert("columns".into(), Value::Object(f.columns.clone()));
    }
    if !f.refit.is_empty() {
        let paths = f
            .refit
            .iter()
            .enumerate()
            .map(|(k, r)| {
                refit_path(r).map(Value::from).ok_or_else(|| RigError::Invalid {
                    path: format!("refit[{k}]"),
                    why: format!("`{r}` is not a bench parameter (`friction.coulomb`, `drive.mass`, `friction.<parameter>`, or Fc, m, effect.param)"),
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        identify.insert("refit".into(), Value::Array(paths));
    }
    if f.steady_state {
        identify.insert("steady_state".into(), json!(true));
    }
    v["identify"] = Value::Object(identify);
    // the identification section checked here, so that its errors name the
    // file's own keys (`columns.torque`, `refit[1]`)
    crate::netlist::read(&v).map_err(|e| RigError::Invalid {
        path: e
            .path
            .strip_prefix("identify.")
            .unwrap_or(&e.path)
            .to_string(),
        why: e.why,
    })?;
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::netlist::{assemble_inputs, schematic};
    use crate::run::RunOptions;
    use crate::signal::Signal;
    use crate::simulation::Simulation;

    fn file() -> Value {
        json!({
            "kind": "friction-bench", "name": "b", "area1": 1e-3, "area2": 4e-4,
            "mass": 2.0, "force_sign": -1.0,
            "friction": { "coulomb": 20.0, "smoothing_velocity": 1e-3, "effects": {
                "viscous": { "b": 300.0 },
                "stribeck": { "Fs": 30.0, "vs": 0.01, "alpha": 1.0 },
                "coulomb_asymmetry": { "dFc": 3.0 },
                "pressure_viscous": { "K": 1e-9 },
                "acceleration_friction": { "H": 2e7 },
                "external_force": { "F0": 5.0 }
            } },
            "refit": ["Fc"], "columns": {}
        })
    }

    /// The migrated bench's load cell reads the bench's force balance with
    /// every effect of the file: `s (m a + F_f + F0 − p1 A1 + p2 A2)`.
    #[test]
    fn a_bench_file_migrates_to_its_force_balance() {
        let n = to_netlist(&file()).unwrap();
        let s = schematic(&n).unwrap();
        let c = |x: f64| Signal::Constant { value: x };
        let (v, a, p1, p2) = (0.02, 0.3, 5e5, 1e5);
        let inputs: Vec<_> = INPUTS
            .iter()
            .map(|n| n.to_string())
            .zip([c(v), c(a), c(p1), c(p2)])
            .collect();
        let mut sim = Simulation::of_circuit(assemble_inputs(&s, &inputs).unwrap())
            .options(RunOptions::dp45());
        let r = sim.run(&[0.0, 0.01]).unwrap();
        let th = (v / 1e-3f64).tanh();
        let g = 20.0 + 10.0 * (-(v / 0.01f64).abs()).exp();
        let ff = g * th + 300.0 * v + 1e-9 * (p1 - p2).powi(2) * v + 1e-9 * 2e7 * a + 1.5 * th;
        let expect = -(2.0 * a + ff + 5.0 - p1 * 1e-3 + p2 * 4e-4);
        let f = r.channel("force").unwrap();
        assert!(
            (f[1] - expect).abs() < 1e-9 * expect.abs(),
            "{} vs {expect}",
            f[1]
        );
    }

    #[test]
    fn errors_name_the_path_in_the_bench_file() {
        let cases: [(&str, Value, &str); 6] = [
            ("/mass", json!(-1.0), "mass"),
            ("/force_sign", json!(0.5), "force_sign"),
            ("/friction/coulomb", json!("lots"), "friction.coulomb"),
            (
                "/friction/effects/stribeck/vs",
                json!(-0.1),
                "friction.effects.stribeck.vs",
            ),
            (
                "/friction/effects/viscous/c",
                json!(1.0),
                "friction.effects.viscous.c",
            ),
            (
                "/friction/effects/internal_leakage",
                json!({"Cl": 1e-12}),
                "friction.effects.internal_leakage",
            ),
        ];
        for (ptr, bad, path) in cases {
            let mut v = file();
            let (parent, key) = ptr.rsplit_once('/').unwrap();
            v.pointer_mut(parent).unwrap()[key] = bad;
            let e = to_netlist(&v).unwrap_err().to_string();
            assert!(e.contains(&format!("`{path}`")), "{ptr}: {e}");
            assert_eq!(e.lines().count(), 1, "{e}");
        }
        let mut v = file();
        v["friction"]["effects"]["stribeck"]
            .as_object_mut()
            .unwrap()
            .remove("vs");
        let e = to_netlist(&v).unwrap_err().to_string();
        assert!(
            e.contains("friction.effects.stribeck") && e.contains("`vs` missing"),
            "{e}"
        );
    }
}
