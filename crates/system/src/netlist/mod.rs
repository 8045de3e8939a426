//! Circuits as data: a **netlist** names components by type and parameters
//! and joins their typed ports; [`circuit`] turns it into a [`Circuit`].
//!
//! ```json
//! {
//!   "kind": "netlist",
//!   "name": "fill",
//!   "components": {
//!     "supply": { "type": "pressure_source", "pressure": 7.0e6 },
//!     "restrictor": { "type": "orifice", "area": 1.0e-7, "cd": 0.65, "density": 870.0 },
//!     "line": { "type": "volume", "volume": 1.0e-4, "bulk_modulus": 7.0e8 }
//!   },
//!   "connections": [
//!     ["supply.port", "restrictor.a"],
//!     ["restrictor.b", "line.port"]
//!   ],
//!   "outputs": { "p_line": "line.p" }
//! }
//! ```
//!
//! * `components`: each entry's `type` is a registered component type
//!   ([`registry::types`], `hydrocyl components`); its other keys are the
//!   type's parameters (nested objects for dotted names such as
//!   `orifice.cd`), `initial` its initial states. Absent parameters take
//!   their defaults; every value is range-checked.
//! * `connections`: each entry joins two or more endpoints, `component.port`
//!   or a bare node name. Joined ports form a node; connected ports share a
//!   domain (hydraulic, mechanical, signal); each node has exactly one owner
//!   (a volume, chamber or pressure source; a mass; a signal source); every
//!   required port is connected.
//! * `outputs` (optional): output columns → probes `component.probe`. Without
//!   it every probe is an output named `component.probe`.
//! * `identify` (optional): what `hydrocyl diagnose` needs beyond the
//!   circuit — the model it builds, the record's column map, the parameter
//!   paths it refits, the steady-state flag ([`identify`]).
//!
//! The parameter path of every value is `<component>.<parameter>` and
//! `<component>.initial.<state>` — in `--set`, [`parameters`] and the docs.
//! The components' order is the state vector's order.

pub mod identify;
mod inputs;
pub mod locate;
pub mod migrate;
pub mod overlay;
mod plausible;
pub mod reader;
pub mod registry;

mod catalog;
pub mod steady;

use crate::circuit::{BuildError, Circuit};
use crate::rig::RigError;
use crate::run::{Run, RunOptions};
use crate::signal::Signal;
pub(crate) use catalog::friction_terms_of as catalog_friction_terms;
pub(crate) use catalog::typed_view_friction_law;
pub use inputs::{samples_beyond, stroke_warning, InputRating, INPUT_TYPES};
pub use plausible::implausible;
pub use reader::{read, NetlistError, Schematic};
use registry::StateSpec;
use serde_json::{Map, Value};

/// The `kind` of a netlist rig file.
pub const KIND: &str = "netlist";

impl From<NetlistError> for RigError {
    fn from(e: NetlistError) -> Self {
        RigError::Invalid {
            path: e.path,
            why: e.why,
        }
    }
}

/// The path `component.probe` of a probe a component publishes: a probe
/// name that repeats the instance's (`relief_1_flow` of `relief_1`) is
/// shortened to the type's declared name (`flow`).
fn probe_path(component: &str, declared: &[(&str, &str)], probe: &str) -> String {
    let local = probe
        .strip_prefix(component)
        .and_then(|r| r.strip_prefix('_'))
        .filter(|r| declared.iter().any(|(n, _)| n == r))
        .unwrap_or(probe);
    format!("{component}.{local}")
}

/// Assembles the circuit of a checked netlist, its command input (one of
/// [`INPUT_TYPES`]) driven by `command`.
pub fn assemble(s: &Schematic, command: Signal) -> Result<Circuit, RigError> {
    command.validate().map_err(|e| RigError::Invalid {
        path: "command".into(),
        why: e.to_string(),
    })?;
    let inputs: Vec<&str> = s.inputs().map(|i| i.name.as_str()).collect();
    if inputs.len() > 1 {
        return Err(RigError::Invalid {
            path: format!("components.{}", inputs[1]),
            why: format!(
                "a netlist with several inputs ({}) is driven by one signal per input, by name",
                inputs.join(", ")
            ),
        });
    }
    let drive: Vec<(String, Signal)> = inputs
        .iter()
        .map(|n| (n.to_string(), command.clone()))
        .collect();
    assemble_driven(s, &drive)
}

/// Assembles a netlist with several inputs: each input component
/// ([`INPUT_TYPES`], [`Schematic::inputs`]) driven by the signal given under
/// its name. Every input must be given, and only inputs; each signal is
/// checked and named by its component in errors.
pub fn assemble_inputs(s: &Schematic, inputs: &[(String, Signal)]) -> Result<Circuit, RigError> {
    for (k, (name, sig)) in inputs.iter().enumerate() {
        if inputs[..k].iter().any(|(n, _)| n == name) {
            return Err(RigError::Invalid {
                path: format!("inputs.{name}"),
                why: "given twice (one signal per input)".into(),
            });
        }
        sig.validate().map_err(|e| RigError::Invalid {
            path: format!("inputs.{name}"),
            why: e.to_string(),
        })?;
    }
    assemble_driven(s, inputs)
}

fn assemble_driven(s: &Schematic, drive: &[(String, Signal)]) -> Result<Circuit, RigError> {
    let names: Vec<&str> = s.inputs().map(|i| i.name.as_str()).collect();
    if let Some((n, _)) = drive.iter().find(|(n, _)| !names.contains(&n.as_str())) {
        return Err(RigError::Invalid {
            path: format!("inputs.{n}"),
            why: format!(
                "is not an input of the netlist (its inputs: {})",
                if names.is_empty() {
                    "none".to_string()
                } else {
                    names.join(", ")
                }
            ),
        });
    }
    let mut comps = Vec::with_capacity(s.instances.len());
    for inst in &s.instances {
        let mut inst = inst.clone();
        if INPUT_TYPES.contains(&inst.ty.name) {
            inst.input = drive
                .iter()
                .find(|(n, _)| *n == inst.name)
                .map(|(_, sig)| sig.clone());
        }
        let c = (inst.ty.build)(&inst).map_err(|message| {
            let (path, why) = registry::error_path(&inst.name, message);
            RigError::Invalid { path, why }
        })?;
        comps.push(c);
    }
    let mut c = Circuit::build(comps).map_err(|e| match e {
        BuildError::Component { component, message } => RigError::Invalid {
            path: format!("components.{component}"),
            why: message,
        },
        // named at the first component on the cycle (in file order), so
        // that the error has a line in the file
        BuildError::AlgebraicLoop(names) => RigError::Invalid {
            path: format!("components.{}", names.first().map_or("", String::as_str)),
            why: format!(
                "algebraic loop between components {}: put a volume or a mass between them",
                names.join(", ")
            ),
        },
        // a signal joins two ports whose quantities differ (a plain command
        // straight into a spool position [m]): named at the second reader
        BuildError::UnitMismatch {
            wire,
            first,
            second,
            component,
        } => RigError::Invalid {
            path: format!("components.{component}"),
            why: format!(
                "reads the signal `{}` as a quantity in {second}, but its source gives it in {first}: connect it to a source in {second} (a command input gives a plain number; a spool makes a position from it)",
                wire.strip_prefix("sig:").unwrap_or(&wire)
            ),
        },
        other => RigError::Build(other),
    })?;
    // the run's input is shown in the unit in which its readers take it
    // (a bench drive's `command` is the velocity it imposes, in m/s)
    if let (Some(unit), Some(input)) = (s.input_unit(), s.inputs().next()) {
        if input.ty.probes.iter().any(|(p, _)| *p == "command") {
            c.set_probe_unit(&input.name, "command", unit);
        }
    }
    // a command computed inside (a closed loop's controller) likewise, in
    // the unit of what it drives (a pump's volts, a spool's demand)
    for (name, unit) in s.command_units() {
        c.set_probe_unit(name, "command", unit);
    }
    let outputs = s.outputs.clone();
    let declared: Vec<(String, &[(&str, &str)])> = s
        .instances
        .iter()
        .map(|i| (i.name.clone(), i.ty.probes))
        .collect();
    // a state by the name its netlist gives it (`v.pressure`, what
    // `v.initial.pressure` sets), where the component's states are the
    // ones its type declares
    let states: Vec<(&str, &[StateSpec])> = s
        .instances
        .iter()
        .map(|i| (i.name.as_str(), i.ty.states))
        .collect();
    c.name_states(|comp, k, n| {
        let (_, declared) = states.iter().find(|(name, _)| *name == comp)?;
        (declared.len() == n).then(|| format!("{comp}.{}", declared[k].name))
    });
    c.name_probes(|comp, probe| {
        let Some(types) = declared.iter().find(|(n, _)| n == comp).map(|(_, p)| *p) else {
            return Some(probe.to_string());
        };
        let path = probe_path(comp, types, probe);
        if outputs.is_empty() {
            Some(path)
        } else {
            outputs
                .iter()
                .find(|(_, p)| *p == path)
                .map(|(col, _)| col.clone())
        }
    });
    Ok(c)
}

/// Reads and checks a netlist value completely: [`schematic`], then its
/// circuit assembled with every input held at zero, so that what only the
/// assembly finds (an algebraic loop, a component refusing its parameters,
/// a circuit with no state) is refused where a rig is loaded or checked too.
pub fn check(v: &Value) -> Result<(), RigError> {
    let s = schematic(v)?;
    let drive: Vec<(String, Signal)> = s
        .inputs()
        .map(|i| (i.name.clone(), Signal::Constant { value: 0.0 }))
        .collect();
    assemble_driven(&s, &drive).map(|_| ())
}

/// Reads a netlist value and assembles its circuit.
pub fn circuit(v: &Value, command: Signal) -> Result<Circuit, RigError> {
    assemble(&schematic(v)?, command)
}

/// Reads and checks a netlist value, with absent initial chamber pressures
/// filled in by the steady state at rest (see [`steady`]).
pub fn schematic(v: &Value) -> Result<Schematic, RigError> {
    let mut s = read(v)?;
    steady::fill(&mut s)?;
    Ok(s)
}

/// Simulates a netlist on `command`, output at `t_eval`.
pub fn simulate(
    v: &Value,
    command: Signal,
    t_eval: &[f64],
    opts: &RunOptions,
) -> Result<Run, RigError> {
    crate::simulation::Simulation::of_circuit(circuit(v, command)?)
        .options(opts.clone())
        .run(t_eval)
}

/// One parameter of a netlist: its path, value, unit and meaning.
#[derive(Clone, Debug, PartialEq)]
pub struct ParamInfo {
    /// `<component>.<parameter>` or `<component>.initial.<state>`.
    pub path: String,
    /// Its value (given or default; `None`: absent).
    pub value: Option<f64>,
    /// SI unit.
    pub unit: &'static str,
    /// What it is.
    pub doc: &'static str,
}

/// Every parameter and initial state of a netlist, defaults filled in, in
/// component order.
pub fn parameters(v: &Value) -> Result<Vec<ParamInfo>, RigError> {
    Ok(parameters_of(&schematic(v)?))
}

/// [`parameters`] of a checked schematic.
pub fn parameters_of(s: &Schematic) -> Vec<ParamInfo> {
    let mut out = Vec::new();
    for inst in &s.instances {
        for p in inst.ty.params {
            out.push(ParamInfo {
                path: format!("{}.{}", inst.name, p.name),
                value: inst.opt(p.name),
                unit: p.unit,
                doc: p.doc,
            });
        }
        for st in inst.ty.states {
            out.push(ParamInfo {
                path: format!("{}.initial.{}", inst.name, st.name),
                value: inst.initial(st.name),
                unit: st.unit,
                doc: st.doc,
            });
        }
    }
    out
}

/// Sets parameter `path` (`<component>.<parameter>` or
/// `<component>.initial.<state>`) to `value` (a number, or `null` for an
/// optional one) in a netlist value. The path must be a parameter of the
/// component's type; a parameter absent from the file (a default) is added.
pub fn set(v: &mut Value, path: &str, value: Value) -> Result<(), RigError> {
    let unknown = |hint: String| RigError::UnknownPath {
        path: path.to_string(),
        hint,
    };
    let (comp, rest) = path
        .split_once('.')
        .ok_or_else(|| unknown(" (a netlist parameter is `<component>.<parameter>`)".into()))?;
    let comps = v
        .get_mut("components")
        .and_then(Value::as_object_mut)
        .ok_or_else(|| unknown(" (the netlist has no components)".into()))?;
    let names: Vec<String> = comps.keys().cloned().collect();
    // a friction bench has no load (and emps no cylinder): its drive carries
    // the moving mass, and where there is no cylinder the rod's position
    let drive = comps
        .iter()
        .find(|(_, c)| c.get("type").and_then(Value::as_str) == Some("imposed_motion"))
        .map(|(n, _)| n.clone())
        .filter(|_| comp == "cylinder" || comp == "load");
    let obj = comps
        .get_mut(comp)
        .and_then(Value::as_object_mut)
        .ok_or_else(|| {
            let bench = drive.map_or(String::new(), |d| {
                if comp == "load" {
                    format!("; this bench's drive `{d}` carries the moving mass: `{d}.mass`")
                } else {
                    format!("; this bench has no cylinder: its drive `{d}` carries the moving mass and the rod's position, `{d}.mass`, `{d}.initial.position`")
                }
            });
            // the JSON path an error names (`components.load.mass`) copied:
            // the parameter's path is the part after `components.`
            let json_path = if comp == "components" {
                format!("; the parameter is named without the JSON path's `components.`: `{rest}`")
            } else {
                String::new()
            };
            unknown(format!(
                " (no component `{comp}`; components: {}{bench}{json_path})",
                names.join(", ")
            ))
        })?;
    let ty = obj
        .get("type")
        .and_then(Value::as_str)
        .and_then(registry::lookup)
        .ok_or_else(|| unknown(format!(" (component `{comp}` has no known type)")))?;
    let known = match rest.strip_prefix("initial.") {
        Some(state) => ty.state(state).is_some(),
        None => ty.param(rest).is_some(),
    };
    if !known {
        let mut all: Vec<String> = ty.params.iter().map(|p| p.name.to_string()).collect();
        all.extend(ty.states.iter().map(|s| format!("initial.{}", s.name)));
        return Err(unknown(format!(
            " (`{comp}` is {} {}; its parameters: {})",
            a_or_an(ty.name),
            ty.name,
            all.join(", ")
        )));
    }
    if !(value.is_number() || value.is_null()) {
        let spec = match rest.strip_prefix("initial.") {
            Some(state) => ty.state(state).map(|s| ("an initial state", s.doc, s.unit)),
            None => ty.param(rest).map(|p| ("a parameter", p.doc, p.unit)),
        };
        let why = match spec {
            Some((what, doc, unit)) => reader::not_a_number(what, &value, doc, unit),
            None => format!("a parameter is a number, got `{value}`"),
        };
        return Err(RigError::Invalid {
            path: path.to_string(),
            why,
        });
    }
    registry::insert_path(obj, rest, value);
    Ok(())
}

/// The netlist with every parameter and initial state written out
/// (defaults filled in): what `--print-rig` shows.
pub fn expanded(v: &Value) -> Result<Value, RigError> {
    let s = read(v)?;
    let mut out = v.clone();
    let comps = out
        .get_mut("components")
        .and_then(Value::as_object_mut)
        .expect("read checked it");
    for inst in &s.instances {
        let obj = comps
            .get_mut(&inst.name)
            .and_then(Value::as_object_mut)
            .expect("read checked it");
        for p in inst.ty.params {
            registry::insert_path(
                obj,
                p.name,
                inst.opt(p.name).map(Value::from).unwrap_or(Value::Null),
            );
        }
        if !inst.ty.states.is_empty() {
            let mut init = Map::new();
            for st in inst.ty.states {
                init.insert(
                    st.name.to_string(),
                    inst.initial(st.name)
                        .map(Value::from)
                        .unwrap_or(Value::Null),
                );
            }
            obj.insert("initial".into(), Value::Object(init));
        }
    }
    Ok(out)
}

/// The indefinite article before `word` in a message: `an` before a
/// vowel (`an orifice`, `an integral`), `a` otherwise (`a cylinder`).
pub(crate) fn a_or_an(word: &str) -> &'static str {
    match word.chars().next().map(|c| c.to_ascii_lowercase()) {
        Some('a' | 'e' | 'i' | 'o' | 'u') => "an",
        _ => "a",
    }
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    /// A component's type is named with its article: `an orifice`,
    /// `a cylinder`.
    #[test]
    fn a_type_is_named_with_a_or_an() {
        assert_eq!(super::a_or_an("orifice"), "an");
        assert_eq!(super::a_or_an("integral"), "an");
        assert_eq!(super::a_or_an("cylinder"), "a");
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        v["components"]["needle"] = json!({"type": "orifice"});
        let e = crate::rig::apply_set(&mut v, "needle.nope=1")
            .unwrap_err()
            .to_string();
        assert!(e.contains("(`needle` is an orifice; "), "{e}");
        let e = crate::rig::apply_set(&mut v, "cylinder.nope=1")
            .unwrap_err()
            .to_string();
        assert!(e.contains("(`cylinder` is a "), "{e}");
    }

    /// A value written as text where a number belongs (a quoted number, a
    /// value with its unit, `"160 bar"`) is refused at its path with the
    /// parameter's meaning and unit, and how to write it: the number
    /// without quotes, or the number in the SI unit the parameter takes.
    /// It used to say only "got a string".
    #[test]
    fn a_value_written_as_text_names_the_unit_to_give_it_in() {
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        v["components"]["supply"]["pressure"] = json!("160 bar");
        let e = read_error(&v);
        assert!(e.contains("components.supply.pressure"), "{e}");
        assert!(e.contains("[Pa]") && e.contains("in Pa"), "{e}");
        v["components"]["supply"]["pressure"] = json!("1.6e7");
        let e = read_error(&v);
        assert!(e.contains("without quotes: 1.6e7"), "{e}");
        // a nested parameter, and a boolean
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        v["components"]["valve"]["orifice"]["density"] = json!(true);
        let e = read_error(&v);
        assert!(e.contains("components.valve.orifice.density"), "{e}");
        assert!(e.contains("a boolean") && e.contains("[kg/m^3]"), "{e}");
        // an initial state, likewise
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        v["components"]["cylinder"]["initial"]["p1"] = json!("30 bar");
        let e = read_error(&v);
        assert!(e.contains("components.cylinder.initial.p1"), "{e}");
        assert!(e.contains("in Pa"), "{e}");
        // an unknown parameter is named as unknown, whatever its value
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        v["components"]["load"]["mas"] = json!("500 kg");
        let e = read_error(&v);
        assert!(e.contains("has no parameter `mas`"), "{e}");
        // and a --set of text
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        let e = crate::rig::apply_set(&mut v, "supply.pressure=160bar")
            .unwrap_err()
            .to_string();
        assert!(e.contains("[Pa]") && e.contains("in Pa"), "{e}");
        // a dimensionless one is a plain number
        let e = crate::rig::apply_set(&mut v, "valve.flow_gain=90%")
            .unwrap_err()
            .to_string();
        assert!(e.contains("a plain number"), "{e}");
    }

    /// A port that owns its node with nothing else to join (a generalised
    /// cylinder's rod-side chamber that no friction law reads, a blocked
    /// chamber) is listed alone, `["cylinder.B"]`: its node is its own. It
    /// could not be: a one-port connection was refused, and the port left
    /// out was refused as dangling, with no way out named. A reading port
    /// alone is still refused (its node would have no owner), and a port
    /// left out still is, naming the way out.
    #[test]
    fn an_owning_port_listed_alone_keeps_its_node_to_itself() {
        let mut v = crate::rig::preset("leaney-moog-generalised").unwrap();
        let conns = v["connections"].as_array_mut().unwrap();
        let b = conns
            .iter()
            .position(|c| c.as_array().unwrap().iter().any(|e| e == "cylinder.B"))
            .unwrap();
        conns.remove(b);
        let e = read_error(&v);
        assert!(e.starts_with("components.cylinder: port `B`"), "{e}");
        assert!(e.contains("list it alone, `[\"cylinder.B\"]`"), "{e}");
        v["connections"]
            .as_array_mut()
            .unwrap()
            .push(json!(["cylinder.B"]));
        // the friction law reads both chambers or neither: neither here
        for c in v["connections"].as_array_mut().unwrap() {
            c.as_array_mut().unwrap().retain(|e| e != "friction.A");
        }
        let s = super::read(&v).unwrap();
        let c = &s.instances.iter().find(|i| i.name == "cylinder").unwrap();
        assert_eq!(c.nodes.get("B").map(String::as_str), Some("cylinder.B"));
        let run = crate::rig::circuit(&v, crate::signal::Signal::Constant { value: 0.2 });
        assert!(run.is_ok(), "{:?}", run.err());
        // a reading port alone: refused at its connection
        let mut w = v.clone();
        w["connections"]
            .as_array_mut()
            .unwrap()
            .push(json!(["friction.A"]));
        let e = read_error(&w);
        assert!(e.contains("a connection joins two or more ports"), "{e}");
        assert!(e.contains("`friction.A` reads its node"), "{e}");
    }

    /// The error of reading `v`, as its path and message.
    fn read_error(v: &serde_json::Value) -> String {
        let e = super::read(v).unwrap_err();
        format!("{}: {}", e.path, e.why)
    }

    /// The netlist's name is a string: another value is refused at `name`,
    /// not passed over for the default name.
    #[test]
    fn a_name_that_is_not_a_string_is_refused() {
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        v["name"] = json!(5);
        let e = super::read(&v).unwrap_err();
        assert_eq!(
            (e.path.as_str(), e.why.as_str()),
            ("name", "must be a string, got a number")
        );
        v.as_object_mut().unwrap().remove("name");
        assert_eq!(super::read(&v).unwrap().name, "netlist");
    }

    /// The description is free text, but text: a number, an object or
    /// `null` is refused at `description` (in one line, at its line of the
    /// file), not passed over.
    #[test]
    fn a_description_that_is_not_a_string_is_refused() {
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        for (d, got) in [
            (json!(5), "a number"),
            (json!({"text": "x"}), "an object"),
            (json!(null), "null"),
        ] {
            v["description"] = d;
            let e = super::read(&v).unwrap_err();
            assert_eq!(
                (e.path.as_str(), e.why.as_str()),
                (
                    "description",
                    format!("must be a string, got {got}").as_str()
                )
            );
        }
        let text = "{\n  \"kind\": \"netlist\",\n  \"description\": 5\n}";
        let e = crate::rig::parse(text, "rig.json").unwrap();
        let e = crate::rig::at_line_in(crate::rig::check(&e).unwrap_err(), text, "rig.json");
        assert_eq!(
            e.to_string(),
            "rig `description`: must be a string, got a number (line 3 of rig.json)"
        );
        v["description"] = json!("a rig");
        assert!(super::read(&v).is_ok());
        v.as_object_mut().unwrap().remove("description");
        assert!(super::read(&v).is_ok());
    }

    /// What only the assembly finds is refused where a rig is checked:
    /// a controller reading its own command is an algebraic loop of one.
    #[test]
    fn check_refuses_a_signal_self_loop_and_a_parameter_given_twice() {
        let mut v = crate::rig::preset("leaney-moog-closed-loop").unwrap();
        let conns = v["connections"].as_array_mut().unwrap();
        conns[0] = json!(["reference.out", "spool.command"]);
        conns[1] = json!(["controller.command", "controller.reference"]);
        let e = crate::rig::check(&v).unwrap_err().to_string();
        assert!(
            e.contains("components.controller") && e.contains("algebraic loop"),
            "{e}"
        );

        let mut v = crate::rig::preset("leaney-moog").unwrap();
        v["components"]["valve"]["orifice.cd"] = json!(0.3);
        let e = crate::rig::check(&v).unwrap_err().to_string();
        assert!(
            e.contains("components.valve.orifice.cd") && e.contains("given twice"),
            "{e}"
        );
    }

    /// One signal read in two units is refused where the connection brings
    /// the second in: a spool's demand [-] and a pump's volts [V] are both
    /// plain numbers to the assembler (the header took the first reader's
    /// unit and the other read it silently), and a spool position [m] into
    /// a pump was refused only at assembly, without a path.
    #[test]
    fn a_signal_read_in_two_units_is_refused_at_its_connection() {
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        v["components"]["pump"] = json!({ "type": "pump_identified", "gain": 1e-5, "natural_frequency": 50.0, "damping": 0.7 });
        v["components"]["pump_line"] =
            json!({ "type": "volume", "volume": 1e-4, "bulk_modulus": 1e9 });
        let conns = v["connections"].as_array_mut().unwrap();
        conns[0] = json!(["command.out", "spool.command", "pump.command"]);
        conns.push(json!(["pump.a", "pump_line.port"]));
        conns.push(json!(["pump.b", "tank.port"]));
        let e = crate::rig::check(&v).unwrap_err().to_string();
        assert!(
            e.contains("connections[0]")
                && e.contains("`pump.command` takes its signal in [V]")
                && e.contains("`spool.command` on the same node in [-]"),
            "{e}"
        );
        let conns = v["connections"].as_array_mut().unwrap();
        conns[0] = json!(["command.out", "spool.command"]);
        conns[1] = json!(["spool.spool", "valve.spool", "pump.command"]);
        let e = crate::rig::check(&v).unwrap_err().to_string();
        assert!(e.contains("connections[1]") && e.contains("[m]"), "{e}");
        // a plain command straight onto a valve's spool position: the
        // quantities differ where the ports declare no unit to compare;
        // named at the reader, with the way out
        let mut v = crate::rig::preset("leaney-moog").unwrap();
        v["components"].as_object_mut().unwrap().remove("spool");
        v.as_object_mut().unwrap().remove("outputs");
        v["connections"][0] = json!(["command.out", "valve.spool"]);
        v["connections"].as_array_mut().unwrap().remove(1);
        let e = crate::rig::check(&v).unwrap_err().to_string();
        assert!(
            e.contains("components.valve") && e.contains("signal `command.out` as a quantity in m"),
            "{e}"
        );
    }

    /// A builder's error about one parameter, found where the steady
    /// initial pressures are worked out (a chamber length not over half
    /// the stroke), is named at that parameter, its message apart from
    /// its path (not `…chamber_length_1chamber 1 volume …`); on a preset
    /// the paths read as `--set` takes them, in a file as JSON paths.
    #[test]
    fn a_parameter_refused_for_the_steady_start_is_named_at_it() {
        use crate::rig;
        for name in ["leaney-moog", "leaney-moog-generalised"] {
            let mut v = rig::preset(name).unwrap();
            rig::apply_set(&mut v, "cylinder.chamber_length_1=0.2").unwrap();
            let e = rig::check(&v).unwrap_err();
            let rig::RigError::Invalid { path, why } = &e else {
                panic!("{name}: {e}");
            };
            assert_eq!(path, "components.cylinder.chamber_length_1", "{name}");
            assert!(why.starts_with("chamber 1 volume"), "{name}: {why}");
            assert!(!why.contains('\u{1f}'), "{name}: {why:?}");
            let shown = rig::at_line(e.clone(), name).to_string();
            assert!(
                shown.starts_with("rig `cylinder.chamber_length_1`: chamber 1 volume"),
                "{shown}"
            );
            assert!(!shown.contains("components."), "{shown}");
        }
    }

    /// A tank at or above the supply is named at the tank's pressure, the
    /// supply named beside it: the cause, not the steady state it spoils.
    #[test]
    fn a_tank_above_the_supply_is_named_as_the_cause() {
        use crate::rig;
        for name in ["leaney-moog", "leaney-moog-generalised"] {
            let mut v = rig::preset(name).unwrap();
            rig::apply_set(&mut v, "tank.pressure=1e7").unwrap();
            let e = rig::at_line(rig::check(&v).unwrap_err(), name).to_string();
            assert!(
                e.starts_with("rig `tank.pressure`: the tank pressure 10000000 Pa"),
                "{e}"
            );
            assert!(
                e.contains("supply pressure 7000000 Pa (supply.pressure"),
                "{e}"
            );
            assert!(!e.contains("ps = -3000000"), "{e}");
        }
    }

    /// On a preset (no file to look in) a range error and any other error
    /// name the parameter as `--set` does; in a user's file as its JSON path.
    #[test]
    fn errors_name_set_paths_on_a_preset_and_json_paths_in_a_file() {
        use crate::rig;
        let mut v = rig::preset("leaney-moog").unwrap();
        rig::apply_set(&mut v, "load.mass=-1").unwrap();
        let e = rig::check(&v).unwrap_err();
        assert!(
            rig::at_line(e.clone(), "leaney-moog")
                .to_string()
                .starts_with("rig `load.mass`: -1 [kg] is out of range"),
            "{e}"
        );
        let dir = std::env::temp_dir().join(format!("hydrocyl-setform-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("rig.json");
        std::fs::write(&file, serde_json::to_string_pretty(&v).unwrap()).unwrap();
        let shown = rig::at_line(e, file.to_str().unwrap()).to_string();
        assert!(shown.starts_with("rig `components.load.mass`"), "{shown}");
        assert!(shown.contains("(line "), "{shown}");
        std::fs::remove_dir_all(&dir).ok();
        // a name that only starts like a component's is left alone
        let e = rig::RigError::Invalid {
            path: "components.load".into(),
            why: "see components.loader.mass and components.load.mass".into(),
        };
        assert_eq!(
            rig::set_form(e, &v).to_string(),
            "rig `load`: see components.loader.mass and load.mass"
        );
    }

    /// `load.initial.position` on a preset whose cylinder gives the rod's
    /// position: the error names both paths and the two ways on, and the
    /// second (the cylinder's cleared) starts the rod where the load says.
    #[test]
    fn an_initial_position_given_twice_says_how_to_give_it_once() {
        use crate::rig;
        use crate::signal::Signal;
        let mut v = rig::preset("leaney-moog").unwrap();
        rig::apply_set(&mut v, "load.initial.position=0.05").unwrap();
        let e = rig::at_line(rig::check(&v).unwrap_err(), "leaney-moog").to_string();
        for part in [
            "rig `load.initial.position`",
            "cylinder.initial.position",
            "`--set cylinder.initial.position=0.05`",
            "`--set cylinder.initial.position=null`",
        ] {
            assert!(e.contains(part), "{part}: {e}");
        }
        rig::apply_set(&mut v, "cylinder.initial.position=null").unwrap();
        let c = rig::circuit(&v, Signal::Constant { value: 0.0 }).unwrap();
        let k = c.state_names().iter().position(|n| n == "load.x").unwrap();
        assert_eq!(c.initial_state()[k], 0.05);
    }

    /// `--set cylinder.…`/`load.…` on a friction bench without that
    /// component (emps has no cylinder; no bench has a load) names the
    /// drive's paths that hold the mass and the position; the seal benches'
    /// cylinder under test takes `cylinder.initial.position`.
    #[test]
    fn a_bench_set_names_the_drives_paths() {
        for (preset, missing) in [
            ("emps", &["cylinder.initial.position", "load.mass"][..]),
            ("tudelft-seal-25", &["load.mass"][..]),
        ] {
            let mut v = crate::rig::preset(preset).unwrap();
            for path in missing {
                let e = super::set(&mut v, path, 0.01.into())
                    .unwrap_err()
                    .to_string();
                assert!(e.contains("`drive.mass`"), "{e}");
                assert_eq!(
                    e.contains("`drive.initial.position`"),
                    path.starts_with("cylinder."),
                    "{e}"
                );
            }
            super::set(&mut v, "drive.initial.position", 0.01.into()).unwrap();
            if preset != "emps" {
                super::set(&mut v, "cylinder.initial.position", 0.02.into()).unwrap();
            }
            let e = super::set(&mut v, "pump.speed", 1.0.into())
                .unwrap_err()
                .to_string();
            assert!(!e.contains("drive.mass"), "{e}");
        }
    }
}
