//! Reading a netlist: JSON value → checked [`Schematic`] (instances with
//! their parameters, initial states and nodes). Every error names the JSON
//! path it is about.

use super::registry::{lookup, types, Default, Domain, Instance, Role};
use serde_json::{Map, Value};
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

/// What a JSON value is, for messages (`a string`, `an array`, ...).
pub(super) fn kind_of(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// Keys of a component object that are not parameters.
const RESERVED: [&str; 3] = ["type", "initial", "description"];

fn read_instance(name: &str, v: &Value) -> Result<Instance, NetlistError> {
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

/// Union–find over connection endpoints.
struct Sets {
    parent: Vec<usize>,
}

impl Sets {
    fn find(&mut self, i: usize) -> usize {
        let mut r = i;
        while self.parent[r] != r {
            r = self.parent[r];
        }
        let mut j = i;
        while self.parent[j] != r {
            let n = self.parent[j];
            self.parent[j] = r;
            j = n;
        }
        r
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[rb.max(ra)] = ra.min(rb);
        }
    }
}

/// An endpoint: a component port, or a named node.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum End {
    Port(usize, &'static str),
    Named(String),
}

/// What the endpoints joined so far into one set hold: checked as each
/// endpoint joins, so that a conflict is named at the connection element
/// that brings it in (not where the node was first used).
#[derive(Clone, Debug, Default)]
struct Part {
    /// The set's domain and the first port that gave it.
    domain: Option<(Domain, String)>,
    /// The owning ports in the set.
    owners: Vec<String>,
    /// The set's node name, when a named node is in it.
    named: Option<String>,
}

impl Part {
    fn of(e: &End, instances: &[Instance]) -> Self {
        match e {
            End::Named(n) => Part {
                named: Some(n.clone()),
                ..Part::default()
            },
            End::Port(ci, p) => {
                let inst = &instances[*ci];
                let spec = inst.ty.port(p).expect("checked when read");
                let label = format!("{}.{p}", inst.name);
                Part {
                    owners: if spec.role == Role::Owns {
                        vec![label.clone()]
                    } else {
                        Vec::new()
                    },
                    domain: Some((spec.domain, label)),
                    named: None,
                }
            }
        }
    }
}

/// Joins `item` (the element `item_label` at JSON path `at`, its endpoint
/// `e`) to the set
/// of `to`: a domain, owner or name conflict between the two sets is an
/// error at `at`, naming the ports (or nodes) on both sides.
fn join(
    sets: &mut Sets,
    parts: &mut [Part],
    to: usize,
    item: usize,
    e: &End,
    item_label: &str,
    at: &str,
) -> Result<(), NetlistError> {
    let (ra, rb) = (sets.find(to), sets.find(item));
    if ra == rb {
        return Ok(());
    }
    let (a, b) = (&parts[ra], &parts[rb]);
    if let (Some(da), Some(db)) = (&a.domain, &b.domain) {
        if da.0 != db.0 {
            // the element itself where it is a port, else a port on its node
            let port = match e {
                End::Port(..) => format!("`{item_label}`"),
                End::Named(n) => format!("`{}` (on node `{n}`)", db.1),
            };
            return err(
                at,
                format!(
                    "{port} is {} but `{}` is {}: connected ports share a domain",
                    db.0.name(),
                    da.1,
                    da.0.name()
                ),
            );
        }
    }
    if let (Some(na), Some(nb)) = (&a.named, &b.named) {
        if na != nb {
            return err(
                at,
                format!("nodes `{na}` and `{nb}` are joined: a node has one name"),
            );
        }
    }
    if !a.owners.is_empty() && !b.owners.is_empty() {
        let domain = a
            .domain
            .as_ref()
            .or(b.domain.as_ref())
            .expect("owners have ports");
        return err(
            at,
            format!(
                "the {} node is owned by both {} and {}: a node has exactly one owner",
                domain.0.name(),
                a.owners.join(" and "),
                b.owners.join(" and ")
            ),
        );
    }
    let b = std::mem::take(&mut parts[rb]);
    let a = &mut parts[ra];
    a.domain = a.domain.take().or(b.domain);
    a.owners.extend(b.owners);
    a.named = a.named.take().or(b.named);
    sets.union(ra, rb);
    let root = sets.find(ra);
    if root != ra {
        parts.swap(root, ra);
    }
    Ok(())
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
    let name = root
        .get("name")
        .and_then(Value::as_str)
        .unwrap_or("netlist")
        .to_string();
    let Some(Value::Object(comps)) = root.get("components") else {
        return err("components", "missing: an object of named components");
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
        if items.len() < 2 {
            return err(at, "a connection joins two or more ports");
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
                        "port `{}` ({}, {}) is not connected",
                        p.name,
                        p.domain.name(),
                        p.doc
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
                    return err(
                        at,
                        format!(
                            "`{c}` ({}) has no output `{pr}` (its outputs: {})",
                            inst.ty.name,
                            inst.ty
                                .probes
                                .iter()
                                .map(|(n, _)| *n)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
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
