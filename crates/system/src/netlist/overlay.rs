//! Changing a circuit with another piece of netlist: an **overlay** adds,
//! replaces or removes components, joins new connections to the nodes
//! already there, and adds, renames or drops outputs — so that a variant of
//! a circuit (a closed loop around an open-loop one, sensors on its
//! chambers) is written as data, not as code that edits JSON.
//!
//! ```json
//! {
//!   "components": {
//!     "command": null,
//!     "reference": { "type": "command_input" },
//!     "controller": { "type": "position_controller", "gain": 50.0 }
//!   },
//!   "connections": [
//!     ["reference.out", "controller.reference"],
//!     ["controller.command", "spool.command"],
//!     ["controller.rod", "cylinder.rod"]
//!   ],
//!   "outputs": { "reference": "reference.command", "command": "controller.command" }
//! }
//! ```
//!
//! * `components`: an object replaces the component of that name or adds
//!   one (new ones take the place of the first component removed, else go
//!   last: the components' order is the state vector's); `null` removes it,
//!   and its endpoints leave their connections (a connection left with one
//!   endpoint goes too, unless the overlay joins that endpoint again).
//! * `connections`: each is joined to the base's connection that shares an
//!   endpoint with it (the endpoints are one node, as in Modelica's
//!   `connect`), or added as a new one: before the next connection of the
//!   overlay that joins one already there, else last.
//! * `outputs`: a string sets the column (a column already there keeps its
//!   place; a new one goes before the next column of the overlay that is
//!   already there, else last); `null` drops it.
//!
//! So the difference of two netlists applied to the first gives the second
//! in its order too, where the second adds its parts next to what they
//! replace (tested on the closed-loop preset).
//!
//! [`difference`] gives the overlay that turns one netlist into another, so
//! that a preset's variant (`leaney-moog-closed-loop` against
//! `leaney-moog`) is applied to another circuit that shares the parts it
//! touches.

use crate::rig::RigError;
use serde_json::{Map, Value};

fn invalid(path: &str, why: impl Into<String>) -> RigError {
    RigError::Invalid {
        path: path.to_string(),
        why: why.into(),
    }
}

/// The endpoints of a connection value (`["a.x", "b.y"]`).
fn endpoints(c: &Value) -> Vec<String> {
    c.as_array()
        .map(|a| {
            a.iter()
                .filter_map(Value::as_str)
                .map(str::to_string)
                .collect()
        })
        .unwrap_or_default()
}

/// The component an endpoint names (`cylinder` of `cylinder.rod`; a bare
/// node name is its own).
fn component_of(endpoint: &str) -> &str {
    endpoint.split_once('.').map_or(endpoint, |(c, _)| c)
}

/// Connections joined into nodes: connections that share an endpoint
/// become one (at the first one's place, its endpoints first), as the
/// reader joins them.
fn nodes(conns: Vec<Vec<String>>) -> Vec<Vec<String>> {
    let mut out: Vec<Vec<String>> = Vec::new();
    for c in conns {
        let mut node = c;
        let mut at = None;
        let mut i = 0;
        while i < out.len() {
            if out[i].iter().any(|p| node.contains(p)) {
                let mut first = std::mem::take(&mut out[i]);
                for p in node {
                    if !first.contains(&p) {
                        first.push(p);
                    }
                }
                node = first;
                at.get_or_insert(i);
            }
            i += 1;
        }
        match at {
            Some(i) => out[i] = node,
            None => out.push(node),
        }
        out.retain(|e| !e.is_empty());
    }
    out
}

/// Applies `part` to the netlist `base` (see the module's rules); on an
/// error `base` is left as it was. Errors name the overlay's JSON path
/// (`overlay.components.x`); the result is checked when it is read, as any
/// netlist.
pub fn overlay(base: &mut Value, part: &Value) -> Result<(), RigError> {
    if !base.is_object() {
        return Err(invalid("rig", "a netlist is an object"));
    }
    let mut v = base.clone();
    apply(&mut v, part)?;
    // an output may not read a component the overlay removed
    let removed = |c: &str| {
        part.pointer("/components")
            .and_then(|m| m.get(c))
            .is_some_and(Value::is_null)
    };
    if let Some((k, probe)) = v.get("outputs").and_then(Value::as_object).and_then(|o| {
        o.iter()
            .filter_map(|(k, p)| p.as_str().map(|p| (k, p)))
            .find(|(_, p)| removed(component_of(p)))
    }) {
        return Err(invalid(
            &format!("overlay.components.{}", component_of(probe)),
            format!("removes the component the output `{k}` reads (`{probe}`): set or drop that output in the overlay's `outputs`"),
        ));
    }
    *base = v;
    Ok(())
}

fn apply(base: &mut Value, part: &Value) -> Result<(), RigError> {
    let part = part
        .as_object()
        .ok_or_else(|| invalid("overlay", "an overlay is an object"))?;
    if let Some(k) = part
        .keys()
        .find(|k| !["components", "connections", "outputs"].contains(&k.as_str()))
    {
        return Err(invalid(
            &format!("overlay.{k}"),
            "unknown key (an overlay has components, connections, outputs)",
        ));
    }
    // as nodes, so that removing a component never parts what it joined
    let mut conns: Vec<Vec<String>> = nodes(
        base.get("connections")
            .and_then(Value::as_array)
            .map(|a| a.iter().map(endpoints).collect())
            .unwrap_or_default(),
    );
    if let Some(comps) = part.get("components") {
        let comps = comps
            .as_object()
            .ok_or_else(|| invalid("overlay.components", "must be an object"))?;
        let target = base
            .get_mut("components")
            .and_then(Value::as_object_mut)
            .ok_or_else(|| invalid("components", "the base netlist has no components"))?;
        // new components take the place of the first one removed (the
        // components' order is the state vector's), else go last
        let at = comps
            .iter()
            .find(|(n, c)| c.is_null() && target.contains_key(*n))
            .map(|(n, _)| n.clone());
        let mut added = Map::new();
        for (name, c) in comps {
            match c {
                Value::Null => {
                    if !target.contains_key(name) {
                        return Err(invalid(
                            &format!("overlay.components.{name}"),
                            "removes a component the circuit does not have",
                        ));
                    }
                    for e in &mut conns {
                        e.retain(|p| component_of(p) != name);
                    }
                }
                Value::Object(_) if target.contains_key(name) => {
                    target.insert(name.clone(), c.clone());
                }
                Value::Object(_) => {
                    added.insert(name.clone(), c.clone());
                }
                _ => {
                    return Err(invalid(
                        &format!("overlay.components.{name}"),
                        "must be a component object or null",
                    ))
                }
            }
        }
        let mut out = Map::new();
        for (name, c) in std::mem::take(target) {
            if Some(&name) == at.as_ref() {
                out.append(&mut added);
            }
            if comps.get(&name).is_none_or(|x| !x.is_null()) {
                out.insert(name, c);
            }
        }
        out.append(&mut added);
        *target = out;
    }
    conns.retain(|e| !e.is_empty());
    if let Some(add) = part.get("connections") {
        let add = add
            .as_array()
            .ok_or_else(|| invalid("overlay.connections", "must be an array"))?;
        // new connections wait to go before the next one that joins a
        // node already there (at its place), else last
        let mut pending: Vec<Vec<String>> = Vec::new();
        for (k, c) in add.iter().enumerate() {
            let new = endpoints(c);
            if new.len() < 2 || c.as_array().is_none_or(|a| a.len() != new.len()) {
                return Err(invalid(
                    &format!("overlay.connections[{k}]"),
                    "a connection joins two or more endpoints (strings)",
                ));
            }
            let touches = |e: &Vec<String>, node: &[String]| e.iter().any(|p| node.contains(p));
            let Some(i) = conns.iter().position(|e| touches(e, &new)) else {
                pending.push(new);
                continue;
            };
            // the node keeps the existing connection's order, with the new
            // endpoints after it, unless the new one lists all of it
            let old = std::mem::take(&mut conns[i]);
            let (mut node, rest) = if old.iter().all(|p| new.contains(p)) {
                (new, Vec::new())
            } else {
                (old, new)
            };
            for p in rest {
                if !node.contains(&p) {
                    node.push(p);
                }
            }
            // every other connection touching it joins it
            while let Some(j) = conns.iter().position(|e| touches(e, &node)) {
                for p in std::mem::take(&mut conns[j]) {
                    if !node.contains(&p) {
                        node.push(p);
                    }
                }
            }
            conns[i] = node;
            let n = pending.len();
            conns.splice(i..i, pending.drain(..));
            debug_assert!(conns[i + n].len() > 1);
        }
        conns.append(&mut pending);
    }
    // a connection left with one endpoint joins nothing
    conns.retain(|e| e.len() > 1);
    base["connections"] = Value::Array(
        conns
            .into_iter()
            .map(|e| Value::Array(e.into_iter().map(Value::from).collect()))
            .collect(),
    );
    if let Some(outs) = part.get("outputs") {
        let outs = outs
            .as_object()
            .ok_or_else(|| invalid("overlay.outputs", "must be an object"))?;
        if base
            .get("outputs")
            .and_then(Value::as_object)
            .is_none_or(Map::is_empty)
        {
            // without outputs every probe is one: the overlay's columns
            // alone would drop the rest
            return Err(invalid(
                "overlay.outputs",
                "the circuit lists no outputs (every probe is one): list them before an overlay sets some",
            ));
        }
        let target = base["outputs"]
            .as_object_mut()
            .ok_or_else(|| invalid("outputs", "must be an object"))?;
        // a new column waits to go before the next column the overlay sets
        // that is already there, else last
        let mut pending = Map::new();
        for (k, o) in outs {
            match o {
                Value::Null => {
                    target.shift_remove(k);
                }
                Value::String(_) if target.contains_key(k) => {
                    target.insert(k.clone(), o.clone());
                    if !pending.is_empty() {
                        let mut out = Map::new();
                        for (key, x) in std::mem::take(target) {
                            if &key == k {
                                out.append(&mut pending);
                            }
                            out.insert(key, x);
                        }
                        *target = out;
                    }
                }
                Value::String(_) => {
                    pending.insert(k.clone(), o.clone());
                }
                _ => {
                    return Err(invalid(
                        &format!("overlay.outputs.{k}"),
                        "must be a probe (`component.probe`) or null",
                    ))
                }
            }
        }
        target.append(&mut pending);
    }
    Ok(())
}

/// The overlay that turns netlist `from` into netlist `to`: the components
/// `to` adds or changes and those it removes, the connections of `to` that
/// `from` does not have, the outputs it adds, changes or drops. An error
/// where `to` parts endpoints that `from` joins among the components it
/// keeps (an overlay joins and removes, it does not rewire).
pub fn difference(from: &Value, to: &Value) -> Result<Value, RigError> {
    let obj = |v: &Value, k: &str| {
        v.get(k)
            .and_then(Value::as_object)
            .cloned()
            .unwrap_or_default()
    };
    let diff = |a: &Map<String, Value>, b: &Map<String, Value>| {
        let mut d = Map::new();
        for k in a.keys().filter(|k| !b.contains_key(*k)) {
            d.insert(k.clone(), Value::Null);
        }
        for (k, x) in b {
            if a.get(k) != Some(x) {
                d.insert(k.clone(), x.clone());
            }
        }
        d
    };
    let conns = |v: &Value| -> Vec<Vec<String>> {
        v.get("connections")
            .and_then(Value::as_array)
            .map(|a| a.iter().map(endpoints).collect())
            .unwrap_or_default()
    };
    let comps = diff(&obj(from, "components"), &obj(to, "components"));
    let kept = |p: &String| !comps.get(component_of(p)).is_some_and(Value::is_null);
    let to_nodes = nodes(conns(to));
    for node in nodes(conns(from)) {
        let node: Vec<&String> = node.iter().filter(|p| kept(p)).collect();
        if node.len() > 1 && !to_nodes.iter().any(|n| node.iter().all(|p| n.contains(p))) {
            return Err(invalid(
                "connections",
                format!(
                    "the second netlist parts endpoints the first joins ({}): an overlay cannot rewire",
                    node.iter().map(|p| p.as_str()).collect::<Vec<_>>().join(", ")
                ),
            ));
        }
    }
    let sorted = |e: &[String]| {
        let mut e = e.to_vec();
        e.sort();
        e
    };
    let old: Vec<Vec<String>> = conns(from).iter().map(|e| sorted(e)).collect();
    let added: Vec<Value> = conns(to)
        .into_iter()
        .filter(|e| !old.contains(&sorted(e)))
        .map(|e| Value::Array(e.into_iter().map(Value::from).collect()))
        .collect();
    let mut d = Map::new();
    d.insert("components".into(), Value::Object(comps));
    d.insert("connections".into(), Value::Array(added));
    d.insert(
        "outputs".into(),
        Value::Object(diff(&obj(from, "outputs"), &obj(to, "outputs"))),
    );
    Ok(Value::Object(d))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn preset(name: &str) -> Value {
        crate::rig::preset(name).unwrap()
    }

    /// The same circuit: the same components and outputs, and the same
    /// nodes (connections compared as sets of endpoints).
    fn same_circuit(a: &Value, b: &Value) -> bool {
        let nodes = |v: &Value| {
            let mut n: Vec<Vec<String>> = v["connections"]
                .as_array()
                .unwrap()
                .iter()
                .map(|c| {
                    let mut e = endpoints(c);
                    e.sort();
                    e
                })
                .collect();
            n.sort();
            n
        };
        a["components"] == b["components"] && a["outputs"] == b["outputs"] && nodes(a) == nodes(b)
    }

    /// Applying the difference of two netlists to the first gives the
    /// second, for a variant that removes, adds and joins (the closed loop).
    #[test]
    fn the_difference_applied_gives_the_other_netlist() {
        let (open, closed) = (preset("leaney-moog"), preset("leaney-moog-closed-loop"));
        let d = difference(&open, &closed).unwrap();
        assert_eq!(d["components"]["command"], Value::Null);
        assert_eq!(d["components"]["controller"]["type"], "position_controller");
        let mut v = open.clone();
        overlay(&mut v, &d).unwrap();
        assert!(same_circuit(&v, &closed), "{v:#}");
        for k in ["name", "description"] {
            v[k] = closed[k].clone();
        }
        assert_eq!(v, closed, "in the same order");
        let order = |v: &Value| -> Vec<String> {
            v["components"]
                .as_object()
                .unwrap()
                .keys()
                .cloned()
                .collect()
        };
        assert_eq!(order(&v), order(&closed), "the state vector's order");
        let columns = |v: &Value| -> Vec<String> {
            v["outputs"].as_object().unwrap().keys().cloned().collect()
        };
        assert_eq!(columns(&v), columns(&closed), "the columns' order");
        crate::netlist::read(&v).unwrap();
        // the closed loop touches only the command, the reference and the
        // controller (so `ValveRig::to_netlist` may close it around the
        // generalised circuit and set every other value after)
        let touched: Vec<&String> = d["components"].as_object().unwrap().keys().collect();
        assert_eq!(touched, ["command", "reference", "controller"]);
        // and nothing from a netlist to itself
        let mut w = open.clone();
        overlay(&mut w, &difference(&open, &open).unwrap()).unwrap();
        assert!(same_circuit(&w, &open));
    }

    /// A new connection sharing an endpoint joins that node; outputs keep
    /// their place when changed and go last when new.
    #[test]
    fn connections_join_existing_nodes_and_outputs_keep_their_place() {
        let mut v = preset("leaney-moog");
        let part = json!({
            "components": { "gauge": { "type": "pressure_sensor", "time_constant": 1e-3 } },
            "connections": [["cylinder.A", "gauge.port"]],
            "outputs": { "p1": "gauge.reading", "p1_chamber": "cylinder.p1", "p_le": null }
        });
        overlay(&mut v, &part).unwrap();
        let joined: Vec<&Value> = v["connections"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|c| endpoints(c).contains(&"gauge.port".to_string()))
            .collect();
        assert_eq!(joined.len(), 1);
        assert_eq!(
            endpoints(joined[0]),
            ["valve.A", "cylinder.A", "friction.A", "gauge.port"]
        );
        let keys: Vec<String> = v["outputs"].as_object().unwrap().keys().cloned().collect();
        assert_eq!(keys.iter().position(|k| *k == "p1"), Some(3));
        assert_eq!(keys.last().unwrap().as_str(), "p1_chamber");
        crate::netlist::read(&v).unwrap();
        // a new column before one already there goes before it
        overlay(
            &mut v,
            &json!({ "outputs": { "first": "gauge.reading", "command": "command.command" } }),
        )
        .unwrap();
        assert_eq!(
            v["outputs"].as_object().unwrap().keys().next().unwrap(),
            "first"
        );
        assert!(!keys.iter().any(|k| *k == "p_le"));
    }

    /// Removing a component keeps the node it joined whole, however the
    /// base spells it (one connection or two sharing the endpoint).
    #[test]
    fn removing_a_component_keeps_its_node_whole() {
        let base = json!({
            "kind": "netlist", "name": "n",
            "components": { "a": {}, "b": {}, "c": {} },
            "connections": [["a.x", "b.y"], ["b.y", "c.z"]]
        });
        let mut v = base.clone();
        overlay(&mut v, &json!({ "components": { "b": null } })).unwrap();
        assert_eq!(v["connections"], json!([["a.x", "c.z"]]));
    }

    /// What an overlay cannot say is refused: a difference that rewires
    /// (a sensor moved from one chamber to the other), an output left on a
    /// removed component, outputs on a circuit that lists none; and a
    /// refused overlay leaves the circuit as it was.
    #[test]
    fn what_an_overlay_cannot_say_is_refused() {
        let open = preset("leaney-moog");
        let sensor = |port: &str| {
            let mut v = open.clone();
            overlay(
                &mut v,
                &json!({
                    "components": { "gauge": { "type": "pressure_sensor", "time_constant": 1e-3 } },
                    "connections": [[format!("cylinder.{port}"), "gauge.port"]]
                }),
            )
            .unwrap();
            v
        };
        let e = difference(&sensor("A"), &sensor("B"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("rewire") && e.contains("gauge.port"), "{e}");
        let mut v = open.clone();
        let e = overlay(&mut v, &json!({ "components": { "command": null } }))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("`overlay.components.command`") && e.contains("`command`"),
            "{e}"
        );
        assert_eq!(v, open);
        let mut bare = open.clone();
        bare.as_object_mut().unwrap().shift_remove("outputs");
        let e = overlay(&mut bare, &json!({ "outputs": { "x": "load.position" } }))
            .unwrap_err()
            .to_string();
        assert!(e.contains("`overlay.outputs`"), "{e}");
    }

    #[test]
    fn errors_name_the_overlays_path() {
        let cases = [
            (
                json!({ "components": { "nothing": null } }),
                "overlay.components.nothing",
            ),
            (json!({ "components": { "x": 3 } }), "overlay.components.x"),
            (
                json!({ "connections": [["a.b"]] }),
                "overlay.connections[0]",
            ),
            (json!({ "outputs": { "p": 1 } }), "overlay.outputs.p"),
            (json!({ "wires": [] }), "overlay.wires"),
        ];
        for (part, path) in cases {
            let e = overlay(&mut preset("leaney-moog"), &part)
                .unwrap_err()
                .to_string();
            assert!(e.contains(&format!("`{path}`")), "{e}");
        }
    }
}
