//! Reading one component of a netlist: its type, its parameters (checked,
//! defaults filled) and its initial states, into an [`Instance`].

use super::{err, kind_of, valid_name, NetlistError};
use crate::netlist::registry::{lookup, types, Default, Instance};
use serde_json::{Map, Value};
use std::collections::BTreeMap;

/// Flattens a component's parameter object into dotted names; `null`
/// leaves are left out (absent).
/// A parameter given twice, flat (`"orifice.cd"`) and nested (`"orifice":
/// {"cd": …}`), is refused at the later key: `given` holds how each dotted
/// name was spelled.
fn flatten(
    m: &Map<String, Value>,
    prefix: &str,
    path: &str,
    out: &mut BTreeMap<String, f64>,
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
            Value::Null => {}
            Value::Object(o) => flatten(o, &name, &at, out, given)?,
            other => {
                return err(
                    at,
                    format!("a parameter is a number, got {}", kind_of(other)),
                );
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
    let rest: Map<String, Value> = obj
        .iter()
        .filter(|(k, _)| !RESERVED.contains(&k.as_str()))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    flatten(&rest, "", &path, &mut given, &mut BTreeMap::new())?;
    for k in given.keys() {
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
        let at = format!("{path}.{}", p.name);
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
            Some(other) => return err(at, format!("must be a number, got {}", kind_of(other))),
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
