//! Reading a netlist: JSON value → checked [`Schematic`] (instances with
//! their parameters, initial states and nodes). Every error names the JSON
//! path it is about.

mod component;
mod nodes;

use super::registry::{Domain, Instance, Role};
use component::read_instance;
use nodes::{join, End, Part, Sets};
use serde_json::Value;
use std::collections::BTreeMap;

/// A netlist problem at a JSON path.
#[derive(Clone, Debug, PartialEq)]
pub struct NetlistError {
    /// JSON path, e.g. `components.valve.orifice.cd` or `connections[3]`.
    pub path: String,
    /// What is wrong.
    pub why: String,
}

fn err<T>(path: impl Into<String>, why: impl Into<String>) -> Result<T, NetlistError> {
    Err(NetlistError {
        path: path.into(),
        why: why.into(),
    })
}

/// A checked netlist.
#[derive(Clone, Debug)]
pub struct Schematic {
    /// The netlist's name.
    pub name: String,
    /// The components, in file order (the state vector's order).
    pub instances: Vec<Instance>,
    /// Output columns `(column, probe path)`; empty = every probe under its
    /// `<component>.<probe>` path.
    pub outputs: Vec<(String, String)>,
    /// The nodes: name → (domain, the ports on it as `component.port`).
    pub nodes: BTreeMap<String, (Domain, Vec<String>)>,
    /// The identification section (`identify`), when the file has one.
    pub identify: Option<super::identify::Identify>,
}

impl Schematic {
    /// The instance named `name`.
    pub fn instance(&self, name: &str) -> Option<&Instance> {
        self.instances.iter().find(|i| i.name == name)
    }
}

fn valid_name(s: &str) -> bool {
    !s.is_empty()
        && s.chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '-')
}

/// What a JSON value is, for messages (`a string`, `an array`, ...).
pub(crate) fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// Whether the one-element connection `items` names a port that owns its
/// node (`["cylinder.B"]`): listed alone, it keeps the node to itself (a
/// chamber nothing else reads, a blocked port), where a port left out is
/// refused as dangling. An unknown component or port is not such a port
/// (the connection is then refused as too short).
fn alone_owns(items: &[Value], instances: &[Instance]) -> bool {
    let [Value::String(s)] = items else {
        return false;
    };
    s.split_once('.').is_some_and(|(c, p)| {
        instances
            .iter()
            .find(|i| i.name == c)
            .and_then(|i| i.ty.port(p))
            .is_some_and(|ps| ps.role == Role::Owns)
    })
}

/// Why `got` is refused where a number is expected (a parameter, or an
/// initial state when `what` says so), for a value meaning `doc` in `unit`:
/// what it is, its meaning and unit, and how to write it — a quoted number
/// without its quotes, a value with a unit (`"160 bar"`) as the number in
/// the SI unit the rig takes.
pub(crate) fn not_a_number(what: &str, got: &Value, doc: &str, unit: &str) -> String {
    let meaning = format!("{doc} [{unit}]");
    let how = match got {
        Value::String(s) => match s.trim().parse::<f64>() {
            Ok(x) if x.is_finite() => format!("write the number without quotes: {}", s.trim()),
            _ if unit == "-" => "give a plain number (every rig value is SI)".to_string(),
            _ => format!("give the number in {unit}: every rig value is SI"),
        },
        _ if unit == "-" => "give a plain number".to_string(),
        _ => format!("give the number in {unit}"),
    };
    let shown = match got {
        Value::String(_) => format!("the string `{got}`"),
        other => kind_of(other).to_string(),
    };
    format!("{what} is a number, got {shown} ({meaning}; {how})")
}

/// Why `col` cannot be an output column beside `before` (the columns
/// named so far): a CSV header cell holds a name and a `[unit]`, and the
/// first column is `time`.
fn check_column(col: &str, before: &[(String, String)]) -> Result<(), String> {
    if col.trim().is_empty() {
        return Err("an output name is blank".into());
    }
    if col.trim() != col {
        return Err(format!(
            "the output name `{col}` starts or ends with a space"
        ));
    }
    if let Some(c) = col
        .chars()
        .find(|c| matches!(c, ',' | '[' | ']' | '"' | ';') || c.is_control())
    {
        return Err(format!(
            "the output name `{col}` holds `{}`: a column name has no `,`, `;`, `\"`, `[` or `]` (the unit is added as ` [unit]`)",
            c.escape_default()
        ));
    }
    if col.eq_ignore_ascii_case("time") {
        return Err("`time` is the first column of every run: name the output otherwise".into());
    }
    if let Some((other, _)) = before.iter().find(|(o, _)| o.eq_ignore_ascii_case(col)) {
        return Err(format!(
            "the output names `{other}` and `{col}` are one column"
        ));
    }
    Ok(())
}

/// Whether two connections join the same endpoints (in any order).
fn same_connection(a: &Value, b: &Value) -> bool {
    let set = |v: &Value| {
        let mut s: Vec<String> = v
            .as_array()
            .map(|a| a.iter().map(Value::to_string).collect())
            .unwrap_or_default();
        s.sort();
        s
    };
    set(a) == set(b)
}

/// Reads and checks a netlist value.
pub fn read(v: &Value) -> Result<Schematic, NetlistError> {
    let Value::Object(root) = v else {
        return err("", "a netlist is a JSON object");
    };
    for k in root.keys() {
        if ![
            "kind",
            "name",
            "description",
            "components",
            "connections",
            "outputs",
            "identify",
        ]
        .contains(&k.as_str())
        {
            return err(
                k.clone(),
                "unknown key (a netlist has kind, name, description, components, connections, outputs, identify)",
            );
        }
    }
    let name = match root.get("name") {
        None => "netlist".to_string(),
        Some(Value::String(s)) => s.clone(),
        Some(other) => return err("name", format!("must be a string, got {}", kind_of(other))),
    };
    // free text for people, but text: a number or an object is a mistake
    if let Some(d) = root.get("description").filter(|d| !d.is_string()) {
        return err(
            "description",
            format!("must be a string, got {}", kind_of(d)),
        );
    }
    let comps = match root.get("components") {
        Some(Value::Object(comps)) => comps,
        None => return err("components", "missing: an object of named components"),
        // present but not an object (`[]`, a list of components): say so
        Some(other) => {
            return err(
                "components",
                format!(
                    "must be an object of named components (`{{\"valve\": {{\"type\": ...}}, ...}}`), got {}",
                    kind_of(other)
                ),
            )
        }
    };
    if comps.is_empty() {
        return err(
            "components",
            "no components: a netlist names at least its components and their connections",
        );
    }
    let mut instances = comps
        .iter()
        .map(|(n, c)| read_instance(n, c))
        .collect::<Result<Vec<_>, _>>()?;

    // endpoints and their sets, joined connection by connection: a conflict
    // is named at the element that brings it in
    let mut ends: Vec<End> = Vec::new();
    let mut first_use: Vec<String> = Vec::new();
    let mut parts: Vec<Part> = Vec::new();
    let mut sets = Sets { parent: Vec::new() };
    // where each node name is first used
    let mut named_at: BTreeMap<String, String> = BTreeMap::new();
    let conns = match root.get("connections") {
        None => Vec::new(),
        Some(Value::Array(a)) => a.clone(),
        Some(other) => {
            return err(
                "connections",
                format!("must be an array, got {}", kind_of(other)),
            )
        }
    };
    for (ci, c) in conns.iter().enumerate() {
        let at = format!("connections[{ci}]");
        let Value::Array(items) = c else {
            return err(
                at,
                "a connection is an array of two or more `component.port` (or node) names",
            );
        };
        if items.len() < 2 && !alone_owns(items, &instances) {
            let why = match items.first().and_then(Value::as_str) {
                Some(s) if s.contains('.') => format!(
                    "a connection joins two or more ports; a port is listed alone only to keep the node it owns to itself, and `{s}` reads its node (join it to the node's owner)"
                ),
                _ => "a connection joins two or more ports".to_string(),
            };
            return err(at, why);
        }
        if let Some(j) = conns[..ci].iter().position(|d| same_connection(c, d)) {
            return err(
                at,
                format!("repeats `connections[{j}]`: list a connection once"),
            );
        }
        let mut first = None;
        let mut here: Vec<End> = Vec::new();
        for (k, item) in items.iter().enumerate() {
            let at_k = format!("{at}[{k}]");
            let Value::String(s) = item else {
                return err(at_k, "must be a string `component.port` or a node name");
            };
            let e = match s.split_once('.') {
                Some((c, p)) => {
                    let Some(ci) = instances.iter().position(|i| i.name == c) else {
                        return err(at_k, format!("no component named `{c}`"));
                    };
                    let ty = instances[ci].ty;
                    let Some(ps) = ty.port(p) else {
                        return err(
                            at_k,
                            format!(
                                "`{c}` ({}) has no port `{p}` (its ports: {})",
                                ty.name,
                                ty.ports
                                    .iter()
                                    .map(|p| p.name)
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            ),
                        );
                    };
                    End::Port(ci, ps.name)
                }
                None if valid_name(s) => {
                    named_at.entry(s.clone()).or_insert_with(|| at_k.clone());
                    End::Named(s.clone())
                }
                None => return err(at_k, "a node name is ASCII letters, digits, `_` and `-`"),
            };
            if here.contains(&e) {
                return err(
                    at_k,
                    format!("`{s}` is named twice in this connection: name each port once"),
                );
            }
            here.push(e.clone());
            let id = match ends.iter().position(|x| *x == e) {
                Some(i) => i,
                None => {
                    parts.push(Part::of(&e, &instances));
                    ends.push(e.clone());
                    first_use.push(at.clone());
                    sets.parent.push(ends.len() - 1);
                    ends.len() - 1
                }
            };
            match first {
                None => first = Some(id),
                Some(f) => join(&mut sets, &mut parts, f, id, &e, s, &at_k)?,
            }
        }
    }
    let mut groups: BTreeMap<usize, Vec<usize>> = BTreeMap::new();
    for i in 0..ends.len() {
        groups.entry(sets.find(i)).or_default().push(i);
    }

    // each group is a node (one domain, at most one owner and one name, as
    // joined above): it must join a port and have its owner
    let mut nodes = BTreeMap::new();
    for (root, members) in &groups {
        // the connection where the node is first used
        let at = &first_use[members[0]];
        let part = &parts[*root];
        let ports: Vec<String> = members
            .iter()
            .filter_map(|&m| match &ends[m] {
                End::Port(ci, p) => Some(format!("{}.{p}", instances[*ci].name)),
                End::Named(_) => None,
            })
            .collect();
        // a node named after a component (`"tank"` beside `"tank.port"`) must
        // hold one of its ports: else the name was meant as a port
        if let Some(n) = &part.named {
            if let Some(inst) = instances.iter().find(|i| i.name == *n) {
                if !ports
                    .iter()
                    .any(|p| p.split_once('.').is_some_and(|(c, _)| c == n))
                {
                    let names: Vec<&str> = inst.ty.ports.iter().map(|p| p.name).collect();
                    return err(
                        named_at[n].clone(),
                        format!(
                            "`{n}` is a component: name one of its ports ({}), e.g. `{n}.{}`",
                            names.join(", "),
                            names.first().copied().unwrap_or("port")
                        ),
                    );
                }
            }
        }
        let Some((domain, _)) = part.domain else {
            return err(at.clone(), "this node joins no component port");
        };
        let Some(owner) = part.owners.first() else {
            return err(
                at.clone(),
                format!(
                    "the {} node of {} has no owner: {}",
                    domain.name(),
                    ports.join(", "),
                    match domain {
                        Domain::Hydraulic =>
                            "connect a volume, a cylinder chamber or a pressure source to it (or an `algebraic_node` between two resistive components)",
                        Domain::Mechanical => "connect a mass to it",
                        Domain::Signal => "connect a signal source (command input, spool) to it",
                    }
                ),
            );
        };
        // a signal is read in one unit: a spool's demand [-] is not a pump's
        // volts [V] (the type system sees two dimensionless numbers)
        if domain == Domain::Signal {
            let mut declared: Option<(String, &str)> = None;
            for &m in members {
                let End::Port(ci, p) = &ends[m] else { continue };
                let inst = &instances[*ci];
                let Some(unit) = inst.ty.port(p).and_then(|q| q.unit()) else {
                    continue;
                };
                let label = format!("{}.{p}", inst.name);
                match &declared {
                    None => declared = Some((label, unit)),
                    Some((first, u)) if *u != unit => {
                        return err(
                            first_use[m].clone(),
                            format!(
                                "`{label}` takes its signal in [{unit}] but `{first}` on the same node in [{u}]: a signal carries one unit (connect each to a source of its own)"
                            ),
                        );
                    }
                    Some(_) => {}
                }
            }
        }
        let node = part.named.clone().unwrap_or_else(|| owner.clone());
        for &m in members {
            if let End::Port(ci, p) = &ends[m] {
                instances[*ci].nodes.insert(p.to_string(), node.clone());
            }
        }
        nodes.insert(node, (domain, ports));
    }

    // every required port connected
    for inst in &instances {
        for p in inst.ty.ports {
            if !p.optional && !inst.nodes.contains_key(p.name) {
                return err(
                    format!("components.{}", inst.name),
                    format!(
                        "port `{}` ({}, {}) is not connected{}",
                        p.name,
                        p.domain.name(),
                        p.doc,
                        match p.role {
                            Role::Owns => format!(
                                ": join it, or list it alone, `[\"{}.{}\"]`, to keep the node it owns to itself",
                                inst.name, p.name
                            ),
                            Role::Reads => String::new(),
                        }
                    ),
                );
            }
        }
    }

    // hints to the owners of nodes; several components hinting one node (two
    // cylinders on one rod) combine: the end stops to the travel both allow,
    // anything else must agree
    let mut hints: BTreeMap<(String, &str), (f64, String)> = BTreeMap::new();
    for inst in &instances {
        if let Some(h) = inst.ty.hints {
            for (port, key, value) in h(inst) {
                let Some(node) = inst.nodes.get(port) else {
                    continue;
                };
                let from = inst.name.clone();
                match hints.get_mut(&(node.clone(), key)) {
                    None => {
                        hints.insert((node.clone(), key), (value, from));
                    }
                    // the tighter stop, and the component it comes from
                    Some((v, by)) if key == "stop_min" => {
                        if value > *v {
                            (*v, *by) = (value, from);
                        }
                    }
                    Some((v, by)) if key == "stop_max" => {
                        if value < *v {
                            (*v, *by) = (value, from);
                        }
                    }
                    Some((v, _)) if *v == value => {}
                    Some((v, first)) => {
                        return err(
                            format!("components.{from}.{key}"),
                            format!(
                                "{value} differs from components.{first}.{key} = {v}, and both are on node `{node}`: give it on one of them"
                            ),
                        )
                    }
                }
            }
        }
    }
    for ((node, key), (value, from)) in hints {
        for inst in instances.iter_mut() {
            let owned: Vec<String> = inst
                .nodes
                .iter()
                .filter(|(p, n)| {
                    **n == node && inst.ty.port(p).is_some_and(|s| s.role == Role::Owns)
                })
                .map(|(p, _)| p.clone())
                .collect();
            for p in owned {
                inst.hint_from
                    .insert((p.clone(), key.to_string()), from.clone());
                inst.hints.insert((p, key.to_string()), value);
            }
        }
    }

    // outputs
    let mut outputs = Vec::new();
    match root.get("outputs") {
        None => {}
        Some(Value::Object(m)) => {
            for (col, probe) in m {
                let at = format!("outputs.{col}");
                check_column(col, &outputs).or_else(|why| err(at.clone(), why))?;
                let Value::String(p) = probe else {
                    return err(at, "an output names a probe `component.probe`");
                };
                let Some((c, pr)) = p.split_once('.') else {
                    return err(at, "an output names a probe `component.probe`");
                };
                let Some(inst) = instances.iter().find(|i| i.name == c) else {
                    return err(at, format!("no component named `{c}`"));
                };
                if !inst.ty.probes.iter().any(|(n, _)| *n == pr) {
                    let has = if inst.ty.probes.is_empty() {
                        "it has no outputs".to_string()
                    } else {
                        format!(
                            "its outputs: {}",
                            inst.ty
                                .probes
                                .iter()
                                .map(|(n, _)| *n)
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    };
                    return err(
                        at,
                        format!("`{c}` ({}) has no output `{pr}` ({has})", inst.ty.name),
                    );
                }
                if let Some((first, _)) = outputs.iter().find(|(_, q)| q == p) {
                    return err(
                        at,
                        format!("`{p}` is already the output `{first}`: a probe is written once, under one name"),
                    );
                }
                outputs.push((col.clone(), p.clone()));
            }
        }
        Some(other) => {
            return err(
                "outputs",
                format!("must be an object, got {}", kind_of(other)),
            )
        }
    }

    let identify = root
        .get("identify")
        .map(|v| super::identify::read(v, &instances))
        .transpose()?;

    Ok(Schematic {
        name,
        instances,
        outputs,
        nodes,
        identify,
    })
}
