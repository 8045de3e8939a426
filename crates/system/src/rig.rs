//! Rig files and presets: JSON in, checked rig out; `--set path=value`
//! overrides on the JSON before it is checked.
//!
//! A rig file is a JSON object with a `kind` field that selects the rig
//! type ([`RIG_KINDS`]); a preset is a named built-in rig ([`PRESETS`]).
//! Overrides act on the JSON value, so they work for every rig kind.

use crate::circuit::BuildError;
use crate::run::{Run, RunOptions};
use crate::signal::Signal;
use crate::valve_rig::ValveRig;
use serde_json::Value;
use thiserror::Error;

/// A bad rig: names the JSON path (or file) and what is wrong.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum RigError {
    /// A parameter outside its range.
    #[error("rig parameter `{path}` = {value}: {why}")]
    OutOfRange {
        /// JSON path, e.g. `cylinder.area_1_m2`.
        path: String,
        /// The value given.
        value: f64,
        /// The rule it breaks.
        why: String,
    },
    /// Another problem with a parameter or the file's shape.
    #[error("rig `{path}`: {why}")]
    Invalid {
        /// JSON path or file.
        path: String,
        /// What is wrong.
        why: String,
    },
    /// A `--set` path that the rig does not have.
    #[error("unknown rig parameter `{path}`{hint}")]
    UnknownPath {
        /// The path given.
        path: String,
        /// The keys that exist there, formatted.
        hint: String,
    },
    /// An error placed in the rig file (or text) it is about: its message,
    /// then `(line N of <file>)`, or `(in <file>)` where there is no line
    /// to name. Made by [`at_line_in`] (which leaves an error placed
    /// already as it is) and by [`parse`] for a duplicate key, whose line
    /// is the repeated key's, not the first's that its path would find.
    #[error("{error} {}", placed_in(.file, *.line))]
    InFile {
        /// The error, unplaced: [`RigError::Invalid`] or
        /// [`RigError::OutOfRange`].
        error: Box<RigError>,
        /// The file as the user named it (or `JSON text`).
        file: String,
        /// The 1-based line in `file`, where the error has one.
        line: Option<usize>,
    },
    /// Assembly failed.
    #[error("assembling the rig: {0}")]
    Build(#[from] BuildError),
    /// The simulation failed.
    #[error("simulation: {0}")]
    Sim(String),
}

/// Where an [`RigError::InFile`] is: `(line N of <file>)` or `(in <file>)`.
fn placed_in(file: &str, line: Option<usize>) -> String {
    match line {
        Some(l) => format!("(line {l} of {file})"),
        None => format!("(in {file})"),
    }
}

/// Absolute vacuum on the gauge scale every rig uses \[Pa\]: no pressure
/// parameter (tank, vapour/cavitation) may lie below it.
pub const ABSOLUTE_VACUUM_GAUGE_PA: f64 = -101_325.0;

/// Which of a rig's tank and vapour (cavitation) pressures \[Pa gauge\] is
/// unphysical and why: the tank must be above absolute vacuum, the vapour
/// pressure between absolute vacuum and the tank pressure. `None` when both
/// are physical (and finite).
pub fn gauge_pressure_problem(tank: f64, vapour: f64) -> Option<(GaugePressure, String)> {
    if !(tank.is_finite() && tank > ABSOLUTE_VACUUM_GAUGE_PA) {
        return Some((
            GaugePressure::Tank,
            format!("must be above absolute vacuum ({ABSOLUTE_VACUUM_GAUGE_PA} Pa gauge)"),
        ));
    }
    if !(ABSOLUTE_VACUUM_GAUGE_PA..=tank).contains(&vapour) {
        return Some((
            GaugePressure::Vapour,
            format!(
                "must lie between absolute vacuum ({ABSOLUTE_VACUUM_GAUGE_PA} Pa gauge) and the tank pressure ({tank} Pa)"
            ),
        ));
    }
    None
}

/// The pressure [`gauge_pressure_problem`] objects to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GaugePressure {
    /// The tank (return) pressure.
    Tank,
    /// The vapour (cavitation) pressure.
    Vapour,
}

/// A built-in rig.
pub struct Preset {
    /// Name (`--rig <name>`).
    pub name: &'static str,
    /// Its JSON value (equal to `fixtures/rigs/<name>.json`).
    pub json: fn() -> Value,
}

/// The built-in presets: the netlist files of `fixtures/rigs/`.
pub const PRESETS: &[Preset] = &[
    Preset {
        name: "leaney-moog",
        json: || netlist_preset(crate::valve_netlist::FUNDAMENTAL),
    },
    Preset {
        name: "leaney-moog-generalised",
        json: || netlist_preset(crate::valve_netlist::GENERALISED),
    },
    Preset {
        name: "leaney-moog-closed-loop",
        json: || netlist_preset(crate::valve_netlist::CLOSED_LOOP),
    },
    Preset {
        name: "wang-valve-c10",
        json: || netlist_preset(include_str!("../../../fixtures/rigs/wang-valve-c10.json")),
    },
    Preset {
        name: "wang-hybrid",
        json: || netlist_preset(include_str!("../../../fixtures/rigs/wang-hybrid.json")),
    },
    Preset {
        name: "tudelft-seal-25",
        json: || netlist_preset(include_str!("../../../fixtures/rigs/tudelft-seal-25.json")),
    },
    Preset {
        name: "tudelft-seal-257",
        json: || netlist_preset(include_str!("../../../fixtures/rigs/tudelft-seal-257.json")),
    },
    Preset {
        name: "emps",
        json: || netlist_preset(include_str!("../../../fixtures/rigs/emps.json")),
    },
];

/// An embedded preset file's value (`Null` if it did not parse, which the
/// presets' tests rule out).
fn netlist_preset(text: &str) -> Value {
    serde_json::from_str(text).unwrap_or(Value::Null)
}

/// A rig kind: how a JSON value of that kind is checked and assembled (a
/// [`Simulation`](crate::simulation::Simulation) then runs any of them).
pub struct RigKind {
    /// The `kind` field's value.
    pub kind: &'static str,
    /// Deserialises and validates the rig (errors name the JSON path).
    pub check: fn(&Value) -> Result<(), RigError>,
    /// Assembles the rig's circuit driven by a command (for callers that
    /// step the circuit themselves, e.g. a co-simulation export).
    pub circuit: fn(&Value, Signal) -> Result<crate::Circuit, RigError>,
}

/// The rig kinds hydrocyl assembles. Other rig kinds add an entry here; the
/// older kinds of [`MIGRATED_KINDS`](crate::netlist::migrate::MIGRATED_KINDS)
/// are read as netlists ([`crate::netlist::migrate`]).
pub const RIG_KINDS: &[RigKind] = &[RigKind {
    kind: crate::netlist::KIND,
    check: crate::netlist::check,
    circuit: crate::netlist::circuit,
}];

/// Deserialises and validates a `valve-cylinder` rig: a rig file of that
/// kind, or a netlist of the valve-cylinder circuit
/// ([`ValveRig::from_netlist`]).
pub fn valve_rig_from(v: &Value) -> Result<ValveRig, RigError> {
    if v.get("kind").and_then(Value::as_str) == Some(crate::netlist::KIND) {
        return ValveRig::from_netlist(v);
    }
    let r: ValveRig = crate::netlist::migrate::typed(v)?;
    r.validate()?;
    Ok(r)
}

/// The `kind` of the retired base-rig-plus-swaps variant files (issue 13):
/// loading one fails with a note naming the netlists that replace it.
const RETIRED_VARIANT_KIND: &str = "hybrid-variant";

/// Whether `name` names a preset: by its name alone ([`preset`] builds
/// the preset's JSON, which costs each start of a command that only asks).
pub fn is_preset(name: &str) -> bool {
    PRESETS.iter().any(|p| p.name == name)
}

/// The JSON of preset `name`, if there is one.
pub fn preset(name: &str) -> Option<Value> {
    PRESETS.iter().find(|p| p.name == name).map(|p| (p.json)())
}

/// A preset by name, or else a rig file by path; a file of an older kind
/// (`valve-cylinder`, `hybrid-pump`) as its netlist
/// ([`crate::netlist::migrate`]), so `--set` and `--print-rig` take
/// `<component>.<parameter>` paths on every rig.
pub fn load(name_or_path: &str) -> Result<Value, RigError> {
    if let Some(v) = preset(name_or_path) {
        return Ok(v);
    }
    let text = std::fs::read_to_string(name_or_path).map_err(|e| RigError::Invalid {
        path: name_or_path.into(),
        why: format!(
            "not a preset ({}) and not a readable file: {e}",
            PRESETS
                .iter()
                .map(|p| p.name)
                .collect::<Vec<_>>()
                .join(", ")
        ),
    })?;
    parse(&text, name_or_path)
}

/// Reads the text of a rig file (`source` names it in messages: the file,
/// or `JSON text`): a leading byte-order mark skipped, duplicate keys
/// refused with their line, a retired kind named, an older kind read as its
/// netlist. [`load`] reads a file through it.
pub fn parse(text: &str, source: &str) -> Result<Value, RigError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if text.trim().is_empty() {
        return Err(RigError::Invalid {
            path: source.into(),
            why: "empty, or only blanks: a rig is a JSON object (`hydrocyl simulate --rig leaney-moog --print-rig` prints one to start from)".into(),
        });
    }
    let v: Value = serde_json::from_str(text).map_err(|e| RigError::Invalid {
        path: source.into(),
        why: format!("not valid JSON: {e}"),
    })?;
    if let Some((key, line)) = crate::netlist::locate::scan(text).duplicate {
        // placed at the repeated key, not at the first its path names
        return Err(RigError::InFile {
            error: Box::new(RigError::Invalid {
                path: key,
                why: "duplicate key (a key may appear once in an object)".into(),
            }),
            file: source.into(),
            line: Some(line),
        });
    }
    if v.get("kind").and_then(Value::as_str) == Some(RETIRED_VARIANT_KIND) {
        let e = RigError::Invalid {
            path: "kind".into(),
            why: "the `hybrid-variant` kind is retired: its circuits are netlists now \
                  (fixtures/rigs/wang-hybrid-{solenoid,needle,improved}.json), and the needle \
                  opening per speed is the parameter `needle_valve.area` (`--set needle_valve.area=<m^2>`)"
                .into(),
        };
        return Err(at_line_in(e, text, source));
    }
    // an older rig kind is read as its netlist
    match crate::netlist::migrate::migrate(&v) {
        Ok(Some(n)) => Ok(n),
        Ok(None) => Ok(v),
        Err(e) => Err(at_line_in(e, text, source)),
    }
}

/// Adds the line of the error's JSON path in the rig file `source` (when
/// `source` is a file, not a preset name, and the path is in it) to the
/// message: `... (line 12 of rig.json)`. On a preset, which the user knows
/// by its `--set` paths (there is no file to look in), the paths of the
/// error are written as `--set` takes them ([`set_form`]).
pub fn at_line(e: RigError, source: &str) -> RigError {
    if let Some(v) = preset(source) {
        return set_form(e, &v);
    }
    let Ok(text) = std::fs::read_to_string(source) else {
        return e;
    };
    at_line_in(e, &text, source)
}

/// The error `e` about the netlist `rig` with its JSON paths of parameters
/// (`components.load.mass`, `components.cylinder`) written as `--set` and
/// [`parameters`] name them (`load.mass`, `cylinder`): in the path it is
/// named at and in its message. Other paths (`connections[3]`, `kind`) are
/// left as they are.
pub fn set_form(e: RigError, rig: &Value) -> RigError {
    let names: Vec<&str> = rig
        .get("components")
        .and_then(Value::as_object)
        .map(|m| m.keys().map(String::as_str).collect())
        .unwrap_or_default();
    let rewrite = |text: &str| {
        let mut out = String::with_capacity(text.len());
        let mut rest = text;
        while let Some(i) = rest.find("components.") {
            let after = &rest[i + "components.".len()..];
            let named = names.iter().find(|n| {
                after.starts_with(**n)
                    && !after[n.len()..]
                        .starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_' || c == '-')
            });
            out.push_str(&rest[..i]);
            if named.is_none() {
                out.push_str("components.");
            }
            rest = after;
        }
        out.push_str(rest);
        out
    };
    match e {
        RigError::Invalid { path, why } => RigError::Invalid {
            path: rewrite(&path),
            why: rewrite(&why),
        },
        RigError::OutOfRange { path, value, why } => RigError::OutOfRange {
            path: rewrite(&path),
            value,
            why: rewrite(&why),
        },
        other => other,
    }
}

/// [`at_line`] on the rig's text `text`, named `source` in the message: an
/// [`RigError::Invalid`] or [`RigError::OutOfRange`] becomes a
/// [`RigError::InFile`] at the line of its JSON path (the file named alone
/// where the path has none). An error placed already (an `InFile`, e.g. a
/// duplicate key at its own line) and one about the file itself (its path
/// is `source`: the text does not read) are left as they are.
pub fn at_line_in(e: RigError, text: &str, source: &str) -> RigError {
    let path = match &e {
        RigError::Invalid { path, .. } | RigError::OutOfRange { path, .. } => path,
        _ => return e,
    };
    if path == source {
        return e;
    }
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let line = Some(path)
        .filter(|p| !p.is_empty())
        .and_then(|p| crate::netlist::locate::scan(text).line_of(p));
    RigError::InFile {
        error: Box::new(e),
        file: source.into(),
        line,
    }
}

/// The kind entry of a rig value.
pub fn kind_of(v: &Value) -> Result<&'static RigKind, RigError> {
    let k = match v.get("kind") {
        Some(Value::String(k)) => k.as_str(),
        None => {
            return Err(RigError::Invalid {
                path: "kind".into(),
                why: "missing (a rig file names its kind)".into(),
            })
        }
        Some(other) => {
            return Err(RigError::Invalid {
                path: "kind".into(),
                why: format!(
                    "must be a string (the rig's kind, e.g. `{}`), got {}",
                    crate::netlist::KIND,
                    crate::netlist::reader::kind_of(other)
                ),
            })
        }
    };
    RIG_KINDS
        .iter()
        .find(|r| r.kind == k)
        .ok_or_else(|| RigError::Invalid {
            path: "kind".into(),
            why: format!(
                "unknown rig kind `{k}` (known: {})",
                RIG_KINDS
                    .iter()
                    .map(|r| r.kind)
                    .chain(crate::netlist::migrate::MIGRATED_KINDS)
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        })
}

/// A rig value of an older kind as its netlist ([`crate::netlist::migrate`]),
/// any other as it is.
fn migrated(v: &Value) -> Result<std::borrow::Cow<'_, Value>, RigError> {
    Ok(match crate::netlist::migrate::migrate(v)? {
        Some(n) => std::borrow::Cow::Owned(n),
        None => std::borrow::Cow::Borrowed(v),
    })
}

/// Checks a rig value of any kind.
pub fn check(v: &Value) -> Result<(), RigError> {
    let v = migrated(v)?;
    (kind_of(&v)?.check)(&v)
}

/// The rig as `--print-rig` prints it (and `hydrocyl.Rig.to_json` gives
/// it): the JSON text, pretty-printed, of a netlist with every parameter
/// and initial state written out under the paths `--set` takes (defaults
/// filled in, [`netlist::expanded`](crate::netlist::expanded)); a rig of
/// another kind as it is given.
pub fn printed(v: &Value) -> Result<String, RigError> {
    let expanded;
    let shown = if v.get("kind").and_then(Value::as_str) == Some(crate::netlist::KIND) {
        expanded = crate::netlist::expanded(v)?;
        &expanded
    } else {
        v
    };
    // a `Value` always serializes (string keys, finite numbers)
    Ok(serde_json::to_string_pretty(shown).expect("a JSON value serializes"))
}

/// Simulates a rig value of any kind: [`Simulation::new`](crate::simulation::Simulation::new)
/// then [`Simulation::run`](crate::simulation::Simulation::run).
pub fn simulate(
    v: &Value,
    command: Signal,
    t_eval: &[f64],
    opts: &RunOptions,
) -> Result<Run, RigError> {
    crate::simulation::Simulation::new(v, command)?
        .options(opts.clone())
        .run(t_eval)
}

/// Assembles the circuit of a rig value of any kind, driven by `command`.
/// Its [`Circuit::initial_state`](crate::Circuit::initial_state) is the
/// rig's initial state.
pub fn circuit(v: &Value, command: Signal) -> Result<crate::Circuit, RigError> {
    let v = migrated(v)?;
    (kind_of(&v)?.circuit)(&v, command)
}

/// Assembles the circuit of a rig value of any kind, driven by `command`,
/// with the limit its command is checked against ([`CommandLimit::of`]),
/// both from the one reading of its netlist: what
/// [`Simulation::new`](crate::simulation::Simulation::new) keeps
/// ([`Simulation::command_limit`](crate::simulation::Simulation::command_limit)).
/// A rig kind that is not a netlist has no limit.
pub(crate) fn assembled(
    v: &Value,
    command: Signal,
) -> Result<(crate::Circuit, Option<CommandLimit>, Vec<String>), RigError> {
    let v = migrated(v)?;
    let kind = kind_of(&v)?;
    if kind.kind != crate::netlist::KIND {
        return Ok(((kind.circuit)(&v, command)?, None, Vec::new()));
    }
    // `netlist::circuit`, with the schematic kept for the limit and the
    // parameters' plausibility
    let s = crate::netlist::schematic(&v)?;
    let limit = CommandLimit::of(&s);
    let implausible = crate::netlist::implausible(&s);
    Ok((crate::netlist::assemble(&s, command)?, limit, implausible))
}

/// What a rig's command is checked against before a run, as `hydrocyl
/// simulate` and the Python package check it; a command beyond it is
/// warned of, not refused. A rig's is read with its netlist, once
/// ([`CommandLimit::of`]: a [`Simulation`](crate::simulation::Simulation)
/// keeps it, [`Simulation::command_limit`](crate::simulation::Simulation::command_limit)).
#[derive(Clone, Debug, PartialEq)]
pub enum CommandLimit {
    /// A normalised spool demand: ±1, the spool's stroke, where the valve
    /// clamps it ([`crate::netlist::stroke_warning`]).
    Stroke,
    /// A pump driven in volts, with a maximum speed
    /// ([`Schematic::input_rating`](crate::netlist::Schematic::input_rating)).
    Rating(crate::netlist::InputRating),
}

impl CommandLimit {
    /// The limit of a netlist's command, from the unit its input is read
    /// in (as the CLI reads a command file): a position \[m\], a velocity
    /// \[m/s\] or a set-point has none, a pump's voltage \[V\] its rating
    /// when the pump has one, anything else is a normalised spool demand
    /// (±1). A parameter changed by a `--set` (a pump's `max_speed`) is the
    /// schematic's own: the limit is the run's rig's.
    pub fn of(s: &crate::netlist::Schematic) -> Option<Self> {
        match s.input_unit() {
            Some("m" | "m/s") => None,
            Some("V") => s.input_rating().map(CommandLimit::Rating),
            _ => Some(CommandLimit::Stroke),
        }
    }

    /// The command magnitude beyond which a sample is warned of: 1 for the
    /// stroke, the rating's [`limit`](crate::netlist::InputRating::limit)
    /// \[V\].
    pub fn bound(&self) -> f64 {
        match self {
            CommandLimit::Stroke => 1.0,
            CommandLimit::Rating(r) => r.limit,
        }
    }

    /// The warning of `outside` command samples beyond the limit, the
    /// largest in magnitude `peak` = (value, time); `None` when none is.
    /// One text for every front end, which says where the command came
    /// from before it (the CLI its file, Python `command (t, u)`).
    pub fn warning(&self, outside: usize, peak: (f64, f64)) -> Option<String> {
        match self {
            CommandLimit::Stroke => crate::netlist::stroke_warning(outside, peak),
            CommandLimit::Rating(r) => r.warning(outside, peak),
        }
    }

    /// The warning of the command samples `u` at times `t` beyond the
    /// limit (the count and the largest); `None` when none is.
    pub fn check(&self, t: &[f64], u: &[f64]) -> Option<String> {
        let (outside, peak) = crate::netlist::samples_beyond(t, u, self.bound());
        self.warning(outside, peak)
    }
}

/// The registry type of component `name` in a rig value of any kind (an
/// older kind read as its netlist), `None` when it has no such component:
/// what a message may propose to set on the component is looked up in it
/// ([`ComponentType::param`](crate::netlist::registry::ComponentType::param)).
pub fn component_type(
    v: &Value,
    name: &str,
) -> Option<&'static crate::netlist::registry::ComponentType> {
    let v = migrated(v).ok()?;
    let ty = v.get("components")?.get(name)?.get("type")?.as_str()?;
    crate::netlist::registry::lookup(ty)
}

/// One numeric parameter of a rig: its path (as `--set` takes it) and value.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// Dotted path, e.g. `load.mass` (`--set` syntax).
    pub path: String,
    /// Current value (`None` for a parameter left `null`, e.g. an initial
    /// pressure that the rig computes from its steady state).
    pub value: Option<f64>,
    /// SI unit, where the rig kind declares it (netlists do).
    pub unit: Option<&'static str>,
    /// What it is, where the rig kind declares it.
    pub doc: Option<&'static str>,
}

impl From<crate::netlist::ParamInfo> for Parameter {
    /// A netlist's parameter, with its unit and meaning.
    fn from(p: crate::netlist::ParamInfo) -> Self {
        Self {
            path: p.path,
            value: p.value,
            unit: Some(p.unit),
            doc: Some(p.doc),
        }
    }
}

/// Every parameter of a rig as `--set` paths. For a netlist: every
/// parameter and initial state of every component, defaults filled in, with
/// unit and meaning (a netlist that does not read gives none). For the older
/// rig kinds: every numeric (or `null`) leaf of the value, in file order.
pub fn parameters(v: &Value) -> Vec<Parameter> {
    if v.get("kind").and_then(Value::as_str) == Some(crate::netlist::KIND) {
        return crate::netlist::parameters(v)
            .map(|ps| ps.into_iter().map(Parameter::from).collect())
            .unwrap_or_default();
    }
    fn walk(v: &Value, prefix: &str, out: &mut Vec<Parameter>) {
        let join = |k: &str| {
            if prefix.is_empty() {
                k.to_string()
            } else {
                format!("{prefix}.{k}")
            }
        };
        match v {
            Value::Object(m) => m.iter().for_each(|(k, v)| walk(v, &join(k), out)),
            Value::Array(a) => a
                .iter()
                .enumerate()
                .for_each(|(i, v)| walk(v, &join(&i.to_string()), out)),
            Value::Number(n) => out.push(Parameter {
                path: prefix.to_string(),
                value: n.as_f64(),
                unit: None,
                doc: None,
            }),
            Value::Null => out.push(Parameter {
                path: prefix.to_string(),
                value: None,
                unit: None,
                doc: None,
            }),
            _ => {}
        }
    }
    let mut out = Vec::new();
    walk(v, "", &mut out);
    out
}

/// Applies the overrides `sets` in turn ([`apply_set`]), each path once
/// ([`each_path_once`]).
pub fn apply_sets(rig: &mut Value, sets: &[String]) -> Result<(), RigError> {
    each_path_once(sets)?;
    sets.iter().try_for_each(|s| apply_set(rig, s))
}

/// Refuses overrides that give one path twice (its value would depend on
/// the order they were written in), as a key given twice in a rig file is.
pub fn each_path_once(sets: &[String]) -> Result<(), RigError> {
    let path = |s: &str| s.split_once('=').map(|(p, _)| p.trim().to_string());
    for (k, s) in sets.iter().enumerate() {
        let Some(p) = path(s) else { continue };
        if let Some(first) = sets[..k].iter().find(|e| path(e).as_ref() == Some(&p)) {
            return Err(RigError::Invalid {
                path: p,
                why: format!(
                    "set twice (`{}` and `{}`): give each path once",
                    first.trim(),
                    s.trim()
                ),
            });
        }
    }
    Ok(())
}

/// An override's value: its JSON, else a number as a shell user writes it
/// and JSON does not (`+50`, `.5`, `5.`), else the text as a string.
fn set_value(text: &str) -> Value {
    if let Ok(v) = serde_json::from_str(text) {
        return v;
    }
    if let Ok(x) = text.parse::<f64>() {
        // `+50` keeps its integer form; `.5` and `5.` become 0.5 and 5.0
        if let Ok(v @ Value::Number(_)) = serde_json::from_str(text.trim_start_matches('+')) {
            return v;
        }
        if let Some(n) = serde_json::Number::from_f64(x) {
            return Value::Number(n);
        }
    }
    Value::String(text.to_string())
}

/// Applies one `path=value` override (`cylinder.area_1_m2=1.2e-3`,
/// `initial.p1=3e6`, `valve.dynamics.order="second"`; on a netlist
/// `<component>.<parameter>`, see [`crate::netlist::set`]). The path must exist in
/// the rig (a `null` entry such as `initial.p1` exists); the value is read
/// as `set_value` reads it (JSON, else a number as a shell user writes it, else a
/// string); a number may only replace a number (or a `null`), a string a
/// string.
pub fn apply_set(rig: &mut Value, assignment: &str) -> Result<(), RigError> {
    let (path, text) = assignment
        .split_once('=')
        .ok_or_else(|| RigError::Invalid {
            path: assignment.into(),
            why: "an override is `path=value`".into(),
        })?;
    let path = path.trim();
    // `1e400`, `inf`, `NaN`: a number, but not one a rig can hold
    if text.trim().parse::<f64>().is_ok_and(|x| !x.is_finite()) {
        return Err(RigError::Invalid {
            path: path.to_string(),
            why: format!("`{}` is not a finite number", text.trim()),
        });
    }
    let new = set_value(text.trim());
    if rig.get("kind").and_then(Value::as_str) == Some(crate::netlist::KIND) {
        return crate::netlist::set(rig, path, new);
    }
    let mut cur = rig;
    let mut walked = String::new();
    for seg in path.split('.') {
        let keys = |v: &Value| match v {
            Value::Object(m) => format!(
                " (at `{}` the keys are: {})",
                if walked.is_empty() { "." } else { &walked },
                m.keys().cloned().collect::<Vec<_>>().join(", ")
            ),
            _ => String::new(),
        };
        let hint = keys(cur);
        let next = match cur {
            Value::Object(m) => m.get_mut(seg),
            Value::Array(a) => seg.parse::<usize>().ok().and_then(|i| a.get_mut(i)),
            _ => None,
        };
        cur = next.ok_or_else(|| RigError::UnknownPath {
            path: path.to_string(),
            hint,
        })?;
        if !walked.is_empty() {
            walked.push('.');
        }
        walked.push_str(seg);
    }
    let compatible = match (&*cur, &new) {
        (Value::Number(_), Value::Number(_)) => true,
        (Value::Null, Value::Number(_) | Value::Null) => true,
        (Value::Number(_), Value::Null) => path.starts_with("initial."),
        (Value::String(_), Value::String(_)) => true,
        (Value::Bool(_), Value::Bool(_)) => true,
        (Value::Object(_), Value::Object(_)) => true,
        (Value::Array(_), Value::Array(_)) => true,
        _ => false,
    };
    if !compatible {
        return Err(RigError::Invalid {
            path: path.to_string(),
            why: format!("cannot replace {} with `{}`", describe(cur), text.trim()),
        });
    }
    *cur = new;
    Ok(())
}

fn describe(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

#[cfg(test)]
mod tests;
