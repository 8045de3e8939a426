//! A netlist's optional identification section, `"identify"`: what
//! `hydrocyl diagnose` needs of a rig beyond its circuit — which model it
//! builds from the circuit, where the record's signals are in files whose
//! headers are not the measured-data format's, which declared parameters it
//! refits, and whether each sample is a steady state.
//!
//! ```json
//! "identify": {
//!   "model": "friction-bench",
//!   "columns": { "time": "t_s", "velocity": "velocity_cm_per_s [cm/s]", "force": "force_N [N]" },
//!   "refit": ["friction.coulomb", "friction.viscous"],
//!   "steady_state": false
//! }
//! ```
//!
//! * `model` (default `cylinder`): `cylinder` — the record's `command` (or
//!   `reference`) drives the circuit's input and its `position`, `p1`, `p2`
//!   are compared with the outputs of those names; `friction-bench` — the
//!   record's motion drives the `imposed_motion` component `drive` (its
//!   velocity, and the acceleration smoothed from it), its `p1`, `p2` the
//!   chamber inputs of those names, and its `force` is compared with the
//!   output `force` (the circuit of a migrated `friction-bench` file).
//! * `columns`: measured-data signal ([`COLUMN_ROLES`]) → the header that
//!   holds it (`"header"` or `"header [unit]"`); signals not named are
//!   looked up under their own name.
//! * `refit` (friction-bench only): parameter paths `<component>.<parameter>`
//!   of this netlist fitted before the effects are traced, each once.
//! * `steady_state` (friction-bench only, default false): each sample is a
//!   steady state (a table of velocity against force): the measured velocity
//!   is used as it is and the acceleration is zero.
//! * `smoothing_velocity` (friction-bench only, m/s, > 0): the velocity of
//!   the static law's tanh where the circuit's friction law has none
//!   (`friction_lugre`; default 1e-3).
//!
//! The reader checks every key, role, path and type; each error names its
//! JSON path (`identify.refit[1]`).

use super::reader::{kind_of as type_name, NetlistError};
use super::registry::Instance;
use serde_json::{Map, Value};
use std::collections::BTreeMap;

/// The measured-data signals a record column can hold (the names of
/// `../shared/spec/measured-data.md`, in its column order).
pub const COLUMN_ROLES: [&str; 10] = [
    "time",
    "command",
    "position",
    "velocity",
    "p1",
    "p2",
    "ps",
    "flow",
    "force",
    "reference",
];

/// The keys of the identification section.
const KEYS: [&str; 5] = [
    "model",
    "columns",
    "refit",
    "steady_state",
    "smoothing_velocity",
];

/// The model `diagnose` builds from a netlist.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IdentifyModel {
    /// A circuit with a cylinder on a mass, driven by the record's command.
    #[default]
    Cylinder,
    /// A friction bench: the record's motion drives the `imposed_motion`
    /// drive, its force is compared with the output `force`.
    FrictionBench,
}

impl IdentifyModel {
    /// Its name in the file.
    pub fn name(self) -> &'static str {
        match self {
            IdentifyModel::Cylinder => "cylinder",
            IdentifyModel::FrictionBench => "friction-bench",
        }
    }
}

/// A netlist's checked identification section.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Identify {
    /// The model `diagnose` builds.
    pub model: IdentifyModel,
    /// Signal ([`COLUMN_ROLES`]) → the header holding it.
    pub columns: BTreeMap<String, String>,
    /// Parameter paths refitted before tracing, in file order.
    pub refit: Vec<String>,
    /// Each sample is a steady state.
    pub steady_state: bool,
    /// The static law's tanh smoothing velocity \[m/s\] where the bench's
    /// friction law has none (`friction_lugre`); `None`: the default.
    pub smoothing_velocity: Option<f64>,
}

fn err<T>(path: impl Into<String>, why: impl Into<String>) -> Result<T, NetlistError> {
    Err(NetlistError {
        path: path.into(),
        why: why.into(),
    })
}

/// The name of the component of the friction-bench model that the record's
/// motion drives.
pub const BENCH_DRIVE: &str = "drive";

/// A friction law's parameters as the friction-bench model's catalog
/// parameters: each catalog parameter with the law's parameters that are
/// it (see [`bench_law_params`]).
struct BenchLaw {
    /// The law's component type.
    ty: &'static str,
    /// `(catalog parameter, the law's parameters that are it)`, in the
    /// order a fitted value is set; a catalog parameter not listed is not
    /// in the law.
    params: &'static [(&'static str, &'static [&'static str])],
    /// Without a Stribeck hump the law's stiction level is its Coulomb
    /// level (a bench reads the hump as the `stribeck` effect only where
    /// they differ), so `Fc` is `stribeck.Fs`'s parameters too.
    stiction_is_coulomb: bool,
}

/// The additive seal terms every friction law carries.
const SEAL_TERMS: [(&str, &[&str]); 2] = [
    ("pressure_viscous.K", &["seal.k_pressure"]),
    ("acceleration_friction.H", &["seal.h_acceleration"]),
];

/// The friction laws other than `friction_bench` that a friction bench's
/// netlist may carry.
const BENCH_LAWS: [BenchLaw; 2] = [
    BenchLaw {
        ty: "friction_coulomb_viscous",
        params: &[
            ("Fc", &["coulomb"]),
            ("viscous.b", &["viscous"]),
            SEAL_TERMS[0],
            SEAL_TERMS[1],
        ],
        stiction_is_coulomb: false,
    },
    BenchLaw {
        ty: "friction_lugre",
        params: &[
            (
                "Fc",
                &["extending.curve.coulomb", "retracting.curve.coulomb"],
            ),
            (
                "stribeck.Fs",
                &["extending.curve.stiction", "retracting.curve.stiction"],
            ),
            (
                "stribeck.vs",
                &[
                    "extending.curve.stribeck_velocity",
                    "retracting.curve.stribeck_velocity",
                ],
            ),
            (
                "stribeck.alpha",
                &[
                    "extending.curve.stribeck_exponent",
                    "retracting.curve.stribeck_exponent",
                ],
            ),
            ("lugre_dynamics.sigma0", &["sigma0"]),
            ("lugre_dynamics.sigma1", &["sigma1"]),
            ("viscous.b", &["extending.sigma2", "retracting.sigma2"]),
            SEAL_TERMS[0],
            SEAL_TERMS[1],
        ],
        stiction_is_coulomb: true,
    },
];

/// The parameters of a friction law of type `ty` (the friction bench's
/// law, `friction_coulomb_viscous`, `friction_lugre` or `friction_bench`)
/// that are the friction-bench model's catalog parameter `catalog` — `Fc`,
/// or an effect's `effect.param` such as `viscous.b`, as a friction-bench
/// file names them — in the order a fitted value is set: two for a law
/// with one set per direction, none for one the law does not have.
/// `stribeck`: the bench declares the Stribeck effect (without it, a
/// LuGre law's stiction level is its Coulomb level, so `Fc` is both).
/// `friction_bench`'s parameters are the catalog's: `coulomb` and
/// [`EFFECT_PARAMS`](super::migrate::bench::EFFECT_PARAMS). `None`: a
/// type with no friction-bench view.
pub fn bench_law_params(ty: &str, catalog: &str, stribeck: bool) -> Option<Vec<&'static str>> {
    if ty == "friction_bench" {
        let (effect, param) = catalog.split_once('.').unwrap_or(("", catalog));
        return Some(if catalog == "Fc" {
            vec!["coulomb"]
        } else {
            super::migrate::bench::EFFECT_PARAMS
                .iter()
                .filter(|(e, p, _)| *e == effect && *p == param)
                .map(|(_, _, target)| *target)
                .collect()
        });
    }
    let law = BENCH_LAWS.iter().find(|l| l.ty == ty)?;
    let of = |c: &str| {
        law.params
            .iter()
            .find(|(q, _)| *q == c)
            .map_or(&[][..], |(_, ps)| *ps)
    };
    let mut ps = of(catalog).to_vec();
    if catalog == "Fc" && law.stiction_is_coulomb && !stribeck {
        ps.extend(of("stribeck.Fs"));
    }
    Some(ps)
}

/// Whether a friction law of type `ty`'s stiction level is its Coulomb
/// level where the bench declares no Stribeck hump (`friction_lugre`: its
/// curves always carry a stiction level), so a bench reads the hump as
/// declared only where the two differ. `false` for a law whose hump is a
/// parameter of its own (`friction_bench`) or that has none.
pub fn bench_law_stiction_is_coulomb(ty: &str) -> bool {
    BENCH_LAWS
        .iter()
        .any(|l| l.ty == ty && l.stiction_is_coulomb)
}

/// Reads and checks the `identify` value of a netlist whose components are
/// `instances`.
pub fn read(v: &Value, instances: &[Instance]) -> Result<Identify, NetlistError> {
    let Value::Object(m) = v else {
        return err(
            "identify",
            format!("must be an object, got {}", type_name(v)),
        );
    };
    if let Some(k) = m.keys().find(|k| !KEYS.contains(&k.as_str())) {
        return err(
            format!("identify.{k}"),
            format!("unknown key (identify has {})", KEYS.join(", ")),
        );
    }
    let model = match m.get("model") {
        None => IdentifyModel::Cylinder,
        Some(Value::String(s)) if s == "cylinder" => IdentifyModel::Cylinder,
        Some(Value::String(s)) if s == "friction-bench" => IdentifyModel::FrictionBench,
        Some(other) => {
            return err(
                "identify.model",
                format!("`{other}`: must be \"cylinder\" or \"friction-bench\""),
            )
        }
    };
    if model == IdentifyModel::FrictionBench
        && !instances
            .iter()
            .any(|i| i.name == BENCH_DRIVE && i.ty.name == "imposed_motion")
    {
        return err(
            "identify.model",
            format!("a friction-bench model needs an `imposed_motion` component named `{BENCH_DRIVE}` (the drive the record's motion moves)"),
        );
    }
    let columns = match m.get("columns") {
        None => BTreeMap::new(),
        Some(Value::Object(c)) => columns(c)?,
        Some(other) => {
            return err(
                "identify.columns",
                format!("must be an object, got {}", type_name(other)),
            )
        }
    };
    let refit = match m.get("refit") {
        None => Vec::new(),
        Some(Value::Array(a)) => refit(a, instances)?,
        Some(other) => {
            return err(
                "identify.refit",
                format!(
                    "must be an array of parameter paths, got {}",
                    type_name(other)
                ),
            )
        }
    };
    let steady_state = match m.get("steady_state") {
        None => false,
        Some(Value::Bool(b)) => *b,
        Some(other) => {
            return err(
                "identify.steady_state",
                format!("must be true or false, got {}", type_name(other)),
            )
        }
    };
    let smoothing_velocity = match m.get("smoothing_velocity") {
        None => None,
        Some(Value::Number(n)) if n.as_f64().is_some_and(|x| x.is_finite() && x > 0.0) => {
            n.as_f64()
        }
        Some(other) => {
            return err(
                "identify.smoothing_velocity",
                format!("must be a number > 0 [m/s], got {other}"),
            )
        }
    };
    if model == IdentifyModel::Cylinder {
        let only = |key: &str| {
            err(
                format!("identify.{key}"),
                "only a friction-bench model takes it (set identify.model to \"friction-bench\")",
            )
        };
        if !refit.is_empty() {
            return only("refit");
        }
        if steady_state {
            return only("steady_state");
        }
        if smoothing_velocity.is_some() {
            return only("smoothing_velocity");
        }
    }
    Ok(Identify {
        model,
        columns,
        refit,
        steady_state,
        smoothing_velocity,
    })
}

fn columns(c: &Map<String, Value>) -> Result<BTreeMap<String, String>, NetlistError> {
    let mut out = BTreeMap::new();
    for (role, header) in c {
        let at = format!("identify.columns.{role}");
        if !COLUMN_ROLES.contains(&role.as_str()) {
            return err(
                at,
                format!(
                    "unknown column role `{role}` (roles: {})",
                    COLUMN_ROLES.join(", ")
                ),
            );
        }
        match header {
            Value::String(h) if !h.trim().is_empty() => {
                out.insert(role.clone(), h.clone());
            }
            Value::String(_) => return err(at, "a column header is not empty"),
            other => {
                return err(
                    at,
                    format!("must be a column header string, got {}", type_name(other)),
                )
            }
        }
    }
    Ok(out)
}

fn refit(a: &[Value], instances: &[Instance]) -> Result<Vec<String>, NetlistError> {
    let mut out: Vec<String> = Vec::new();
    for (k, item) in a.iter().enumerate() {
        let at = format!("identify.refit[{k}]");
        let Value::String(path) = item else {
            return err(
                at,
                format!(
                    "must be a parameter path `<component>.<parameter>`, got {}",
                    type_name(item)
                ),
            );
        };
        let Some((comp, param)) = path.split_once('.') else {
            return err(
                at,
                format!("`{path}`: a parameter path is `<component>.<parameter>`"),
            );
        };
        let Some(inst) = instances.iter().find(|i| i.name == comp) else {
            return err(
                at,
                format!(
                    "`{path}`: no component `{comp}` (components: {})",
                    instances
                        .iter()
                        .map(|i| i.name.as_str())
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            );
        };
        if inst.ty.param(param).is_none() {
            return err(
                at,
                format!(
                    "`{path}`: `{comp}` is {} {} and has no parameter `{param}` (its parameters: {})",
                    super::a_or_an(inst.ty.name),
                    inst.ty.name,
                    inst.ty
                        .params
                        .iter()
                        .map(|p| p.name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            );
        }
        if out.contains(path) {
            return err(at, format!("`{path}` is listed twice"));
        }
        out.push(path.clone());
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use crate::netlist::read;
    use crate::rig::RigError;
    use serde_json::{json, Value};

    /// Every law parameter the friction-bench view names is a parameter of
    /// its law's component type.
    #[test]
    fn the_bench_laws_parameters_are_their_types() {
        for law in &super::BENCH_LAWS {
            let ty = crate::netlist::registry::lookup(law.ty).unwrap();
            for (catalog, ps) in law.params {
                for p in *ps {
                    assert!(ty.param(p).is_some(), "{}: {catalog}: {p}", law.ty);
                }
            }
        }
        let ty = crate::netlist::registry::lookup("friction_bench").unwrap();
        for (e, p, _) in crate::netlist::migrate::bench::EFFECT_PARAMS {
            let catalog = format!("{e}.{p}");
            for q in super::bench_law_params("friction_bench", &catalog, false).unwrap() {
                assert!(ty.param(q).is_some(), "friction_bench: {catalog}: {q}");
            }
        }
        assert_eq!(super::bench_law_params("friction_wang", "Fc", false), None);
    }

    /// A friction-bench netlist (the migration of a `friction-bench` file).
    fn bench() -> Value {
        crate::netlist::migrate::bench::to_netlist(&json!({
            "kind": "friction-bench", "name": "b", "area2": 1e-3, "mass": 2.0,
            "force_sign": 1.0,
            "friction": { "coulomb": 20.0, "smoothing_velocity": 1e-3,
                          "effects": { "viscous": { "b": 300.0 } } },
            "refit": ["Fc", "viscous.b"],
            "columns": { "force": "load [N]" },
            "steady_state": true
        }))
        .unwrap()
    }

    #[test]
    fn a_migrated_bench_carries_its_identification() {
        let s = read(&bench()).unwrap();
        let id = s.identify.unwrap();
        assert_eq!(id.model, super::IdentifyModel::FrictionBench);
        assert_eq!(id.refit, ["friction.coulomb", "friction.viscous"]);
        assert_eq!(id.columns["force"], "load [N]");
        assert!(id.steady_state);
        // absent: no section
        let mut v = bench();
        v.as_object_mut().unwrap().remove("identify");
        assert!(read(&v).unwrap().identify.is_none());
    }

    /// Every bad identification names its JSON path, in one line.
    #[test]
    fn errors_name_the_path() {
        let cases: [(&str, Value, &str, &str); 11] = [
            ("", json!([]), "identify", "must be an object"),
            ("/colour", json!(1), "identify.colour", "unknown key"),
            ("/model", json!("robot"), "identify.model", "cylinder"),
            (
                "/columns",
                json!(["force"]),
                "identify.columns",
                "an object",
            ),
            (
                "/columns/torque",
                json!("T [N]"),
                "identify.columns.torque",
                "unknown column role",
            ),
            (
                "/columns/force",
                json!(3),
                "identify.columns.force",
                "got a number",
            ),
            (
                "/refit",
                json!("friction.coulomb"),
                "identify.refit",
                "an array",
            ),
            (
                "/refit/1",
                json!("friction.warp"),
                "identify.refit[1]",
                "no parameter `warp`",
            ),
            (
                "/refit/1",
                json!("motor.mass"),
                "identify.refit[1]",
                "no component `motor`",
            ),
            (
                "/refit/1",
                json!("friction.coulomb"),
                "identify.refit[1]",
                "listed twice",
            ),
            (
                "/steady_state",
                json!("yes"),
                "identify.steady_state",
                "true or false",
            ),
        ];
        for (ptr, bad, path, why) in cases {
            let mut v = bench();
            if ptr.is_empty() {
                v["identify"] = bad;
            } else {
                let (parent, key) = ptr.rsplit_once('/').unwrap();
                let node = v.pointer_mut(&format!("/identify{parent}")).unwrap();
                match node {
                    Value::Array(a) => a[key.parse::<usize>().unwrap()] = bad,
                    _ => node[key] = bad,
                }
            }
            let e = RigError::from(read(&v).unwrap_err()).to_string();
            assert!(
                e.contains(&format!("`{path}`")) && e.contains(why),
                "{ptr}: {e}"
            );
            assert_eq!(e.lines().count(), 1, "{e}");
        }
        // refits and steady states are a friction bench's
        let mut v = bench();
        v["identify"]["model"] = json!("cylinder");
        let e = RigError::from(read(&v).unwrap_err()).to_string();
        assert!(e.contains("`identify.refit`"), "{e}");
        v["identify"]["refit"] = json!([]);
        let e = RigError::from(read(&v).unwrap_err()).to_string();
        assert!(e.contains("`identify.steady_state`"), "{e}");
        // a friction-bench model needs its drive
        let mut v = bench();
        let comps = v["components"].as_object_mut().unwrap();
        let drive = comps.remove("drive").unwrap();
        comps.insert("motor".into(), drive);
        for c in v["connections"].as_array_mut().unwrap() {
            for e in c.as_array_mut().unwrap() {
                *e = json!(e.as_str().unwrap().replace("drive.", "motor."));
            }
        }
        v["outputs"] = json!({});
        let e = RigError::from(read(&v).unwrap_err()).to_string();
        assert!(
            e.contains("`identify.model`") && e.contains("`drive`"),
            "{e}"
        );
    }

    /// A key given twice in the file's identification section is refused by
    /// the file reader with its path and line.
    #[test]
    fn a_duplicate_key_is_refused_with_its_path() {
        let text = serde_json::to_string_pretty(&bench()).unwrap().replacen(
            "\"steady_state\": true",
            "\"steady_state\": true, \"steady_state\": false",
            1,
        );
        let dir =
            std::env::temp_dir().join(format!("hydrocyl-identify-dup-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("dup.json");
        std::fs::write(&f, text).unwrap();
        let e = crate::rig::load(f.to_str().unwrap())
            .unwrap_err()
            .to_string();
        std::fs::remove_dir_all(&dir).ok();
        assert!(
            e.contains("identify.steady_state") && e.contains("duplicate key"),
            "{e}"
        );
    }
}
