//! The component registry: every component type a netlist can name, with its
//! ports, parameters (unit, range, default) and initial states, and the
//! builder that makes the component from a checked instance.
//!
//! One table serves the JSON reader (names, ranges, defaults), `--set` and
//! [`parameters`](super::parameters) (paths and units), `hydrocyl components`
//! and the docs table ([`catalog_markdown`]).

use crate::circuit::Component;
use serde::de::DeserializeOwned;
use serde_json::{Map, Value};
use std::collections::BTreeMap;

/// The physical domain of a port: what its node carries.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Domain {
    /// Pressure \[Pa\] (effort) and volume flow \[m³·s⁻¹\] (flow).
    Hydraulic,
    /// Force \[N\] (effort), velocity \[m·s⁻¹\] (flow) and position \[m\] of a rigid body.
    Mechanical,
    /// A scalar signal (a command, a spool position) with one writer.
    Signal,
}

impl Domain {
    /// The name used in messages and the catalog.
    pub fn name(self) -> &'static str {
        match self {
            Domain::Hydraulic => "hydraulic",
            Domain::Mechanical => "mechanical",
            Domain::Signal => "signal",
        }
    }
}

/// Causality of a port: whether the component sets the node's effort.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// Sets the effort (pressure, body motion, signal value): every node has
    /// exactly one owner.
    Owns,
    /// Reads the effort and adds flow (or force) to the node.
    Reads,
}

/// A port a component type declares.
#[derive(Clone, Copy, Debug)]
pub struct PortSpec {
    /// Port name, unique within the type (`A`, `rod`, `spool`).
    pub name: &'static str,
    /// Its domain.
    pub domain: Domain,
    /// Whether the component owns the node.
    pub role: Role,
    /// An optional port may be left unconnected.
    pub optional: bool,
    /// What the port is.
    pub doc: &'static str,
}

impl PortSpec {
    /// The unit the port's declaration ends in (`command [V]` → `V`): the
    /// unit in which a signal port reads or writes its node; `None` where
    /// the declaration names none (a port that takes its readers' unit).
    pub fn unit(&self) -> Option<&'static str> {
        let doc = self.doc.strip_suffix(']')?;
        doc.rfind('[').map(|o| &doc[o + 1..])
    }
}

/// The default of a parameter or initial state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Default {
    /// Must be given.
    Required,
    /// Taken when absent.
    Value(f64),
    /// May be absent (or `null`): the component then does without it
    /// (e.g. no end stops), or an initial state is computed.
    Absent,
}

/// The admissible interval of a parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    /// Lower bound.
    pub lo: f64,
    /// Upper bound.
    pub hi: f64,
    /// Whether `lo` itself is excluded.
    pub lo_open: bool,
    /// Whether `hi` itself is excluded.
    pub hi_open: bool,
}

impl Range {
    /// Any finite number.
    pub const ANY: Range = Range {
        lo: f64::NEG_INFINITY,
        hi: f64::INFINITY,
        lo_open: true,
        hi_open: true,
    };
    /// `> 0`.
    pub const POSITIVE: Range = Range {
        lo: 0.0,
        hi: f64::INFINITY,
        lo_open: true,
        hi_open: true,
    };
    /// `≥ 0`.
    pub const NON_NEGATIVE: Range = Range {
        lo: 0.0,
        hi: f64::INFINITY,
        lo_open: false,
        hi_open: true,
    };
    /// `(0, 1]` (discharge coefficients, area factors).
    pub const UNIT: Range = Range {
        lo: 0.0,
        hi: 1.0,
        lo_open: true,
        hi_open: false,
    };
    /// `> -101325 Pa` gauge: above absolute vacuum.
    pub const GAUGE_PRESSURE: Range = Range {
        lo: crate::rig::ABSOLUTE_VACUUM_GAUGE_PA,
        hi: f64::INFINITY,
        lo_open: false,
        hi_open: true,
    };

    /// The values inside both (the higher lower bound, the lower upper
    /// one; a bound both share is open when either has it open).
    pub fn intersect(self, other: Range) -> Range {
        use std::cmp::Ordering;
        let (lo, lo_open) = match self.lo.total_cmp(&other.lo) {
            Ordering::Greater => (self.lo, self.lo_open),
            Ordering::Less => (other.lo, other.lo_open),
            Ordering::Equal => (self.lo, self.lo_open || other.lo_open),
        };
        let (hi, hi_open) = match self.hi.total_cmp(&other.hi) {
            Ordering::Less => (self.hi, self.hi_open),
            Ordering::Greater => (other.hi, other.hi_open),
            Ordering::Equal => (self.hi, self.hi_open || other.hi_open),
        };
        Range {
            lo,
            hi,
            lo_open,
            hi_open,
        }
    }

    /// Whether `v` is finite and inside.
    pub fn contains(&self, v: f64) -> bool {
        v.is_finite()
            && (if self.lo_open {
                v > self.lo
            } else {
                v >= self.lo
            })
            && (if self.hi_open {
                v < self.hi
            } else {
                v <= self.hi
            })
    }

    /// `(0, 1]`, `≥ 0`, `any` ... for messages and the catalog.
    pub fn describe(&self) -> String {
        let lo = if self.lo == f64::NEG_INFINITY {
            None
        } else {
            Some(self.lo)
        };
        let hi = if self.hi == f64::INFINITY {
            None
        } else {
            Some(self.hi)
        };
        match (lo, hi) {
            (None, None) => "any finite value".into(),
            (Some(l), None) => format!("{} {l}", if self.lo_open { ">" } else { "≥" }),
            (None, Some(h)) => format!("{} {h}", if self.hi_open { "<" } else { "≤" }),
            (Some(l), Some(h)) => format!(
                "{}{l}, {h}{}",
                if self.lo_open { "(" } else { "[" },
                if self.hi_open { ")" } else { "]" }
            ),
        }
    }
}

/// A numeric parameter of a component type. Nested names (`orifice.cd`)
/// are written as nested JSON objects in a netlist and as dotted paths in
/// `--set` (`valve.orifice.cd=0.6`).
#[derive(Clone, Copy, Debug)]
pub struct ParamSpec {
    /// Dotted name within the component.
    pub name: &'static str,
    /// SI unit (`Pa`, `m^3/s`, `-`).
    pub unit: &'static str,
    /// Default.
    pub default: Default,
    /// Admissible values.
    pub range: Range,
    /// What it is.
    pub doc: &'static str,
    /// The span real rigs' values lie in, `(low, high)`, where it is narrow
    /// enough that a value far outside is a unit slip (bar for Pa, mm for
    /// m): [`ParamSpec::implausible`] warns of it; the value still runs.
    pub typical: Option<(f64, f64)>,
}

/// Other units a value may have been written in by mistake, by SI unit:
/// the name and what one of it is in the SI unit.
const SLIPS: &[(&str, &[(&str, f64)])] = &[
    (
        "Pa",
        &[("bar", 1e5), ("MPa", 1e6), ("kPa", 1e3), ("psi", 6894.757)],
    ),
    ("m", &[("mm", 1e-3), ("cm", 1e-2)]),
    ("m^2", &[("mm²", 1e-6), ("cm²", 1e-4)]),
    ("kg/m^3", &[("g/cm³", 1e3)]),
];

impl ParamSpec {
    /// This parameter with the span real rigs' values lie in (see
    /// [`ParamSpec::typical`]).
    pub const fn typical(mut self, low: f64, high: f64) -> Self {
        self.typical = Some((low, high));
        self
    }

    /// Why `value` (inside the range) is far outside the span real rigs'
    /// values lie in, with the unit it may have been written in: `14000
    /// [Pa] is far outside the usual 5e7 to 5e9 [Pa] of effective bulk
    /// modulus …: a value in bar? (14000 bar = 1.4e9 Pa)`; `None` inside
    /// the span, or for a parameter without one.
    pub fn implausible(&self, value: f64) -> Option<String> {
        let (low, high) = self.typical?;
        if !value.is_finite() || (low..=high).contains(&value) {
            return None;
        }
        let unit = self.unit;
        let slip = SLIPS
            .iter()
            .find(|(u, _)| *u == unit)
            .and_then(|(_, slips)| {
                slips
                    .iter()
                    .find(|(_, f)| (low..=high).contains(&(value * f)))
            })
            .map_or_else(
                || "check its unit: every rig value is SI".to_string(),
                |(name, f)| {
                    format!(
                        "a value in {name}? ({value} {name} = {:e} {unit})",
                        value * f
                    )
                },
            );
        Some(format!(
            "{value} [{unit}] is far outside the usual {low:e} to {high:e} [{unit}] of {}: {slip}",
            self.doc
        ))
    }

    /// Checks a value given for this parameter on its own: inside its
    /// range. The error says the value and the rule.
    pub fn check(&self, value: f64) -> Result<(), String> {
        if self.range.contains(value) {
            Ok(())
        } else {
            Err(format!(
                "{value} [{}] is out of range: must be {}",
                self.unit,
                self.range.describe()
            ))
        }
    }
}

/// Shorthand for a [`ParamSpec`] table entry.
pub const fn param(
    name: &'static str,
    unit: &'static str,
    default: Default,
    range: Range,
    doc: &'static str,
) -> ParamSpec {
    ParamSpec {
        name,
        unit,
        default,
        range,
        doc,
        typical: None,
    }
}

/// An initial state a netlist may give under `<component>.initial.<name>`.
#[derive(Clone, Copy, Debug)]
pub struct StateSpec {
    /// State name.
    pub name: &'static str,
    /// SI unit.
    pub unit: &'static str,
    /// Default when absent.
    pub default: Default,
    /// What it is.
    pub doc: &'static str,
}

impl StateSpec {
    /// Checks an initial value given for this state on its own: finite, and
    /// a chamber's or a volume's gauge pressure (`p1`, `p2`, `pressure` in
    /// Pa; not a difference such as a load pressure) not below absolute
    /// vacuum. The error says the rule.
    pub fn check(&self, value: f64) -> Result<(), String> {
        if !value.is_finite() {
            return Err("must be finite".into());
        }
        let vacuum = crate::rig::ABSOLUTE_VACUUM_GAUGE_PA;
        if self.unit == "Pa" && matches!(self.name, "p1" | "p2" | "pressure") && value < vacuum {
            return Err(format!(
                "{value} Pa is below absolute vacuum ({vacuum} Pa gauge)"
            ));
        }
        Ok(())
    }
}

/// Makes the component from a checked instance.
pub type Builder = fn(&Instance) -> Result<Box<dyn Component>, String>;

/// What a component tells the owner of the node at one of its ports before
/// the build (a cylinder gives the rod's owner its end stops and initial
/// position): `(port, key, value)`.
pub type NodeHints = fn(&Instance) -> Vec<(&'static str, &'static str, f64)>;

/// A component type.
#[derive(Clone, Copy)]
pub struct ComponentType {
    /// Type name used in netlists (`four_way_valve`).
    pub name: &'static str,
    /// One line: what it models and its thesis equations.
    pub summary: &'static str,
    /// Its ports.
    pub ports: &'static [PortSpec],
    /// Its parameters.
    pub params: &'static [ParamSpec],
    /// Its initial states.
    pub states: &'static [StateSpec],
    /// The builder.
    pub build: Builder,
    /// Hints for the owners of its ports' nodes (`None`: none).
    pub hints: Option<NodeHints>,
    /// Output probes it publishes, `(probe, unit)`, named
    /// `<component>.<probe>` in a run.
    pub probes: &'static [(&'static str, &'static str)],
}

impl std::fmt::Debug for ComponentType {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ComponentType")
            .field("name", &self.name)
            .finish()
    }
}

impl ComponentType {
    /// The port named `name`.
    pub fn port(&self, name: &str) -> Option<&'static PortSpec> {
        self.ports.iter().find(|p| p.name == name)
    }
    /// The parameter named `name`.
    pub fn param(&self, name: &str) -> Option<&'static ParamSpec> {
        self.params.iter().find(|p| p.name == name)
    }
    /// The initial state named `name`.
    pub fn state(&self, name: &str) -> Option<&'static StateSpec> {
        self.states.iter().find(|s| s.name == name)
    }
}

/// Marks the two ends of the path in an [`error_at`] message.
const PATH_MARK: char = '\u{1f}';

/// A [`Builder`] error about the value at JSON `path` of the netlist (one
/// another component gave it as a hint) rather than the building component:
/// the error is named at `path`.
pub fn error_at(path: &str, why: &str) -> String {
    format!("{PATH_MARK}{path}{PATH_MARK}{why}")
}

/// A [`Builder`] error of component `component` as `(path, why)`: the path
/// [`error_at`] gave, else `components.<component>`.
pub(crate) fn error_path(component: &str, message: String) -> (String, String) {
    if let Some(rest) = message.strip_prefix(PATH_MARK) {
        if let Some((path, why)) = rest.split_once(PATH_MARK) {
            return (path.to_string(), why.to_string());
        }
    }
    (format!("components.{component}"), message)
}

/// A checked component instance: what a [`Builder`] works from.
#[derive(Clone, Debug)]
pub struct Instance {
    /// Instance name (unique in the netlist).
    pub name: String,
    /// Its type.
    pub ty: &'static ComponentType,
    /// Parameter values by dotted name, defaults filled in (absent
    /// optional parameters are missing).
    pub params: BTreeMap<String, f64>,
    /// Initial states given or defaulted (`None`: absent / computed).
    pub initial: BTreeMap<String, Option<f64>>,
    /// The node each connected port is on.
    pub nodes: BTreeMap<String, String>,
    /// Hints from the components at the nodes it owns, by `(port, key)`.
    pub hints: BTreeMap<(String, String), f64>,
    /// The component that gave each hint, by `(port, key)`.
    pub hint_from: BTreeMap<(String, String), String>,
    /// The run's command, for an input component (`command_input`).
    pub input: Option<crate::signal::Signal>,
}

impl Instance {
    /// A parameter's value (0 for an unknown name: the tables and builders
    /// are checked against each other by the registry's tests).
    pub fn get(&self, name: &str) -> f64 {
        self.params.get(name).copied().unwrap_or(0.0)
    }
    /// An optional parameter.
    pub fn opt(&self, name: &str) -> Option<f64> {
        self.params.get(name).copied()
    }
    /// An initial state (`None`: absent).
    pub fn initial(&self, name: &str) -> Option<f64> {
        self.initial.get(name).copied().flatten()
    }
    /// The node a port is on (`""` for an unconnected optional port).
    pub fn node(&self, port: &str) -> &str {
        self.nodes.get(port).map(String::as_str).unwrap_or("")
    }
    /// Whether a port is connected.
    pub fn connected(&self, port: &str) -> bool {
        self.nodes.contains_key(port)
    }
    /// A hint given for the node at `port` (see [`NodeHints`]).
    pub fn hint(&self, port: &str, key: &str) -> Option<f64> {
        self.hints
            .get(&(port.to_string(), key.to_string()))
            .copied()
    }
    /// The JSON path of the value behind a hint (`key` of the component that
    /// gave it: `components.cylinder.initial.position`), for errors about
    /// it ([`error_at`]).
    pub fn hint_path(&self, port: &str, key: &str) -> Option<String> {
        self.hint_from
            .get(&(port.to_string(), key.to_string()))
            .map(|c| format!("components.{c}.{key}"))
    }
    /// The parameters under `prefix` (all with `""`) as a nested JSON
    /// object, deserialised into a law's serde struct: the parameter names
    /// are that struct's field paths.
    pub fn law<T: DeserializeOwned>(&self, prefix: &str) -> Result<T, String> {
        let mut root = Map::new();
        for (k, v) in &self.params {
            let rest = if prefix.is_empty() {
                k.as_str()
            } else if let Some(r) = k.strip_prefix(prefix).and_then(|r| r.strip_prefix('.')) {
                r
            } else {
                continue;
            };
            insert_path(&mut root, rest, Value::from(*v));
        }
        serde_json::from_value(Value::Object(root)).map_err(|e| e.to_string())
    }
}

/// Inserts `value` at dotted `path` in a JSON object, creating objects. A
/// key spelled flat in the object (`"orifice.cd"`, or `"orifice.x"` holding
/// `{"cd": …}`) is followed as it is spelled, so that the parameter stays
/// given once.
pub(crate) fn insert_path(root: &mut Map<String, Value>, path: &str, value: Value) {
    if root.contains_key(path) {
        root.insert(path.to_string(), value);
        return;
    }
    let flat_head = path
        .match_indices('.')
        .map(|(i, _)| i)
        .find(|&i| root.get(&path[..i]).is_some_and(Value::is_object) && path[..i].contains('.'));
    if let Some(i) = flat_head {
        if let Some(Value::Object(m)) = root.get_mut(&path[..i]) {
            return insert_path(m, &path[i + 1..], value);
        }
    }
    match path.split_once('.') {
        None => {
            root.insert(path.to_string(), value);
        }
        Some((head, rest)) => {
            let child = root
                .entry(head.to_string())
                .or_insert_with(|| Value::Object(Map::new()));
            if let Value::Object(m) = child {
                insert_path(m, rest, value);
            }
        }
    }
}

/// Every component type, in catalog order.
pub fn types() -> &'static [ComponentType] {
    super::catalog::all()
}

/// The component type named `name`.
pub fn lookup(name: &str) -> Option<&'static ComponentType> {
    types().iter().find(|t| t.name == name)
}

/// Checks `value` for parameter `param` of component type `ty` against the
/// parameter's declared range (what a built component's
/// [`Component::set_parameter`]
/// accepts); the error says the range and unit.
pub fn check_param(ty: &str, param: &str, value: f64) -> Result<(), String> {
    let spec = lookup(ty)
        .and_then(|t| t.params.iter().find(|p| p.name == param))
        .ok_or_else(|| format!("`{ty}` has no parameter `{param}`"))?;
    spec.check(value)
}

/// The catalog as Markdown (the docs table and `hydrocyl components`):
/// one section per type with its ports, parameters and states.
pub fn catalog_markdown() -> String {
    let mut s = String::from("| type | what it models | ports |\n|---|---|---|\n");
    for t in types() {
        let ports: Vec<String> = t
            .ports
            .iter()
            .map(|p| {
                format!(
                    "`{}` ({}{}{})",
                    p.name,
                    p.domain.name(),
                    if p.role == Role::Owns { ", owns" } else { "" },
                    if p.optional { ", optional" } else { "" }
                )
            })
            .collect();
        s.push_str(&format!(
            "| `{}` | {} | {} |\n",
            t.name,
            t.summary,
            ports.join(", ")
        ));
    }
    for t in types() {
        s.push('\n');
        s.push_str(&type_markdown(t));
    }
    s
}

/// One type's section of the catalog: its ports, parameters, initial
/// states and outputs.
pub fn type_markdown(t: &ComponentType) -> String {
    let mut s = format!("### `{}`\n\n{}\n\n", t.name, t.summary);
    s.push_str("| port | domain | role | meaning |\n|---|---|---|---|\n");
    for p in t.ports {
        s.push_str(&format!(
            "| `{}` | {} | {}{} | {} |\n",
            p.name,
            p.domain.name(),
            if p.role == Role::Owns {
                "owns"
            } else {
                "reads"
            },
            if p.optional { ", optional" } else { "" },
            p.doc
        ));
    }
    if !t.params.is_empty() {
        s.push_str("\n| parameter | unit | default | range | meaning |\n|---|---|---|---|---|\n");
        for p in t.params {
            s.push_str(&format!(
                "| `{}` | {} | {} | {} | {} |\n",
                p.name,
                p.unit,
                describe_default(p.default),
                p.range.describe(),
                p.doc
            ));
        }
    }
    if !t.states.is_empty() {
        s.push_str("\n| initial state | unit | default | meaning |\n|---|---|---|---|\n");
        for st in t.states {
            s.push_str(&format!(
                "| `initial.{}` | {} | {} | {} |\n",
                st.name,
                st.unit,
                describe_default(st.default),
                st.doc
            ));
        }
    }
    if !t.probes.is_empty() {
        let p: Vec<String> = t
            .probes
            .iter()
            .map(|(n, u)| format!("`{n}` [{u}]"))
            .collect();
        s.push_str(&format!("\nOutputs: {}.\n", p.join(", ")));
    }
    s
}

fn describe_default(d: Default) -> String {
    match d {
        Default::Required => "required".into(),
        Default::Value(v) => format!("{v}"),
        Default::Absent => "none".into(),
    }
}
