//! Reading one component of a netlist: its type, its parameters (checked,
//! defaults filled) and its initial states, into an [`Instance`].

use super::{err, kind_of, not_a_number, valid_name, NetlistError};
use crate::netlist::registry::{lookup, types, Default, Instance};
use serde_json::{Map, Value};
use std::collections::BTreeMap;

/// Flattens a component's parameter object into dotted names; `null`
/// leaves go to `nulls` (dotted name → JSON path), not to `out`: `null` is
/// a value only for a parameter that may be absent (see [`read_instance`]).
/// A parameter given twice, flat (`"orifice.cd"`) and nested (`"orifice":
/// {"cd": …}`), is refused at the later key: `given` holds how each dotted
/// name was spelled. Leaves of another kind (a string, a boolean, an
/// array) go to `wrong` (dotted name → JSON path and value), refused by
/// [`read_instance`] once it knows the name is a parameter.
fn flatten(
    m: &Map<String, Value>,
    prefix: &str,
    path: &str,
    out: &mut BTreeMap<String, f64>,
    nulls: &mut BTreeMap<String, String>,
    wrong: &mut BTreeMap<String, (String, Value)>,
    given: &mut BTreeMap<String, String>,
) -> Result<(), NetlistError> {
    for (k, v) in m {
        let name = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        let at = format!("{path}.{k}");
        let spelled = if prefix.is_empty() {
            format!("as `{k}`")
        } else {
            format!("inside `{prefix}`")
        };
        if !matches!(v, Value::Object(_)) {
            if let Some(first) = given.insert(name.clone(), spelled.clone()) {
                return err(
                    at,
                    format!("`{name}` is given twice: {first} and {spelled} (give it once)"),
                );
            }
        }
        match v {
            Value::Number(n) => {
                let x = n.as_f64().unwrap_or(f64::NAN);
                out.insert(name, x);
            }
            Value::Null => {
                nulls.insert(name, at);
            }
            Value::Object(o) => flatten(o, &name, &at, out, nulls, wrong, given)?,
            other => {
                wrong.insert(name, (at, other.clone()));
            }
        }
    }
    Ok(())
}

/// Keys of a component object that are not parameters.
const RESERVED: [&str; 3] = ["type", "initial", "description"];

pub(super) fn read_instance(name: &str, v: &Value) -> Result<Instance, NetlistError> {
    let path = format!("components.{name}");
    if !valid_name(name) {
        return err(
            path,
            "a component name is ASCII letters, digits, `_` and `-` (no dots)",
        );
    }
    let Value::Object(obj) = v else {
        return err(
            path,
            format!("a component is an object, got {}", kind_of(v)),
        );
    };
    let ty_name = match obj.get("type") {
        Some(Value::String(s)) => s.as_str(),
        Some(other) => {
            return err(
                format!("{path}.type"),
                format!("must be a string, got {}", kind_of(other)),
            )
        }
        None => return err(path, "missing `type` (see `hydrocyl components`)"),
    };
    let Some(ty) = lookup(ty_name) else {
        return err(
            format!("{path}.type"),
            format!(
                "unknown component type `{ty_name}` (known: {})",
                types()
                    .iter()
                    .map(|t| t.name)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        );
    };
    // parameters
    let mut given = BTreeMap::new();
    let mut nulls = BTreeMap::new();
    let mut wrong = BTreeMap::new();
    let rest: Map<String, Value> = obj
        .iter()
        .filter(|(k, _)| !RESERVED.contains(&k.as_str()))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    flatten(
        &rest,
        "",
        &path,
        &mut given,
        &mut nulls,
        &mut wrong,
        &mut BTreeMap::new(),
    )?;
    for k in given.keys().chain(nulls.keys()).chain(wrong.keys()) {
        if ty.param(k).is_none() {
            return err(
                format!("{path}.{k}"),
                format!(
                    "`{ty_name}` has no parameter `{k}` (its parameters: {})",
                    ty.params
                        .iter()
                        .map(|p| p.name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ),
            );
        }
    }
    let mut params = BTreeMap::new();
    for p in ty.params {
        if let Some((at, v)) = wrong.get(p.name) {
            return err(at.clone(), not_a_number("a parameter", v, p.doc, p.unit));
        }
        let at = format!("{path}.{}", p.name);
        // `null` means "absent" only where absent has a meaning of its own
        // (no end stop, no Stribeck hump); elsewhere it would silently be
        // the default, so it is refused like any other non-number
        if nulls.contains_key(p.name) && p.default != Default::Absent {
            let leave_out = match p.default {
                Default::Value(d) => format!("leave the key out for the default, {d}"),
                _ => "it must be given".to_string(),
            };
            return err(
                at,
                format!(
                    "a parameter is a number, got null ({} [{}]; {leave_out})",
                    p.doc, p.unit
                ),
            );
        }
        match (given.get(p.name), p.default) {
            (Some(&x), _) => {
                if let Err(why) = p.check(x) {
                    return err(at, why);
                }
                params.insert(p.name.to_string(), x);
            }
            (None, Default::Value(d)) => {
                params.insert(p.name.to_string(), d);
            }
            (None, Default::Absent) => {}
            (None, Default::Required) => {
                return err(at, format!("missing ({} [{}])", p.doc, p.unit));
            }
        }
    }
    // initial states
    let mut initial = BTreeMap::new();
    let given_initial = match obj.get("initial") {
        None => Map::new(),
        Some(Value::Object(m)) => m.clone(),
        Some(other) => {
            return err(
                format!("{path}.initial"),
                format!("must be an object, got {}", kind_of(other)),
            )
        }
    };
    for k in given_initial.keys() {
        if ty.state(k).is_none() {
            return err(
                format!("{path}.initial.{k}"),
                format!(
                    "`{ty_name}` has no initial state `{k}` (its states: {})",
                    if ty.states.is_empty() {
                        "none".to_string()
                    } else {
                        ty.states
                            .iter()
                            .map(|s| s.name)
                            .collect::<Vec<_>>()
                            .join(", ")
                    }
                ),
            );
        }
    }
    for s in ty.states {
        let at = format!("{path}.initial.{}", s.name);
        let value = match given_initial.get(s.name) {
            Some(Value::Number(n)) => {
                let x = n.as_f64().unwrap_or(f64::NAN);
                if let Err(why) = s.check(x) {
                    return err(at, why);
                }
                Some(x)
            }
            Some(Value::Null) | None => match s.default {
                Default::Value(d) => Some(d),
                Default::Absent => None,
                Default::Required => return err(at, format!("missing ({} [{}])", s.doc, s.unit)),
            },
            Some(other) => return err(at, not_a_number("an initial state", other, s.doc, s.unit)),
        };
        initial.insert(s.name.to_string(), value);
    }
    Ok(Instance {
        name: name.to_string(),
        ty,
        params,
        initial,
        nodes: BTreeMap::new(),
        hints: BTreeMap::new(),
        hint_from: BTreeMap::new(),
        input: None,
    })
}

#[cfg(test)]
mod tests {
    use super::read_instance;
    use serde_json::json;

    fn bench_friction(extra: serde_json::Value) -> serde_json::Value {
        let mut v =
            json!({ "type": "friction_bench", "coulomb": 20.0, "smoothing_velocity": 1e-3 });
        for (k, x) in extra.as_object().unwrap() {
            v[k] = x.clone();
        }
        v
    }

    /// `null` for a parameter with a default would silently be that
    /// default: it is refused at its JSON path, as a string is.
    #[test]
    fn null_for_a_parameter_with_a_default_is_refused_by_its_path() {
        let e = read_instance("friction", &bench_friction(json!({ "viscous": null }))).unwrap_err();
        assert_eq!(e.path, "components.friction.viscous");
        assert!(
            e.why.starts_with("a parameter is a number, got null")
                && e.why.contains("leave the key out for the default, 0"),
            "{}",
            e.why
        );
        let e = read_instance("friction", &bench_friction(json!({ "coulomb": null }))).unwrap_err();
        assert_eq!(e.path, "components.friction.coulomb");
        assert!(e.why.contains("it must be given"), "{}", e.why);
        // a name the type does not have is refused, null or not
        let e = read_instance("friction", &bench_friction(json!({ "viscos": null }))).unwrap_err();
        assert_eq!(e.path, "components.friction.viscos");
        // a wrong type stays refused as before
        let e =
            read_instance("friction", &bench_friction(json!({ "viscous": "2.0" }))).unwrap_err();
        assert_eq!(e.path, "components.friction.viscous");
    }

    /// Where `null` has a meaning of its own it stays: a parameter that may
    /// be absent (no Stribeck hump, no end stop) and an initial state
    /// (computed, or cleared for the cylinder's).
    #[test]
    fn null_stays_where_absent_has_a_meaning() {
        let i = read_instance("friction", &bench_friction(json!({ "stiction": null }))).unwrap();
        assert_eq!(i.params.get("stiction"), None);
        assert_eq!(i.params["viscous"], 0.0);
        let mass = json!({
            "type": "mass", "mass": 2.0, "stop_min": null, "stop_max": null,
            "initial": { "position": null, "velocity": null }
        });
        let i = read_instance("load", &mass).unwrap();
        assert_eq!(i.params.get("stop_min"), None);
        assert_eq!(i.initial["position"], None);
    }
}
