//! Rig files as `hydrocyl simulate` reads them: a preset or a file
//! (duplicate keys refused, an older rig kind read as its netlist:
//! [`rig::load`]), checked once ([`check`]): every error names the JSON path
//! and, for a file, its line — or the `--set` that gave the value — those
//! found when the circuit is assembled (an algebraic loop) too
//! ([`Checked::circuit`]).

use crate::error::CliError;
use hydrocyl_system::netlist::{self, Schematic};
use hydrocyl_system::rig::{self, RigError};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::Circuit;
use serde_json::Value;

/// A rig error with the line of its JSON path in `source` added (when
/// `source` is a file), or, when a `--set` of `sets` gave the value at that
/// path, that `--set` ([`at_line_or_set`]).
pub fn locate(e: RigError, source: &str, sets: &[String]) -> CliError {
    CliError::Input(at_line_or_set(e, source, sets).to_string())
}

/// [`rig::at_line`], except for an error about a value a `--set` of `sets`
/// gave: the file's line holds the value the `--set` replaced, so the
/// message names the `--set` instead, `(set by --set load.mass=-1 on
/// lm.json)` (a preset has no lines: [`rig::at_line`] names its paths as
/// `--set` takes them). A path is matched with or without its
/// `components.` prefix.
///
/// An error about a relation between parameters (a chamber length against
/// the stroke, a tank against the supply) is named at the parameter the
/// relation bounds; when a `--set` gave one of the others the message names
/// (by its path, or by its bare name within the erring component), that
/// `--set` is named too, `(with --set cylinder.stroke=0.7)`: the line of the
/// bounded parameter holds a value the user did not change.
pub fn at_line_or_set(e: RigError, source: &str, sets: &[String]) -> RigError {
    let (path, why) = match &e {
        RigError::Invalid { path, why } | RigError::OutOfRange { path, why, .. } => {
            (path.clone(), why.clone())
        }
        _ => return rig::at_line(e, source),
    };
    let bare = |p: &str| p.trim().trim_start_matches("components.").to_string();
    let set_path = |s: &String| {
        s.split_once('=')
            .map(|(p, _)| bare(p))
            .filter(|p| !p.is_empty())
    };
    let direct = sets
        .iter()
        .find(|s| set_path(s).is_some_and(|p| p == bare(&path)));
    let component = bare(&path)
        .split('.')
        .next()
        .unwrap_or_default()
        .to_string();
    let others: Vec<String> = sets
        .iter()
        .filter(|s| Some(*s) != direct)
        .filter(|s| {
            set_path(s).is_some_and(|p| {
                mentions(&why, &p)
                    || p.split_once('.')
                        .is_some_and(|(c, name)| c == component && mentions(&why, name))
            })
        })
        .map(|s| format!("--set {s}"))
        .collect();
    let others = others.join(", ");
    // a preset has no lines: its message names the path as `--set` takes
    // it, as Python's `Rig.set` words it
    let by = match (direct, rig::is_preset(source), others.is_empty()) {
        (Some(set), false, true) => format!("(set by --set {set} on {source})"),
        (Some(set), false, false) => format!("(set by --set {set} on {source}, with {others})"),
        (_, _, false) => format!("(with {others})"),
        (_, _, true) => return rig::at_line(e, source),
    };
    let e = match e {
        RigError::Invalid { path, why } => RigError::Invalid {
            why: format!("{why} {by}"),
            path,
        },
        RigError::OutOfRange { path, value, why } => RigError::OutOfRange {
            why: format!("{why} {by}"),
            path,
            value,
        },
        other => other,
    };
    match (direct, rig::is_preset(source)) {
        (Some(_), false) => e,
        _ => rig::at_line(e, source),
    }
}

/// Whether `text` names `word` (a parameter path or name) as a whole:
/// not inside a longer name (`area_1` in `area_10`, `stroke` in
/// `spool.stroke`), though `components.` may stand before it.
fn mentions(text: &str, word: &str) -> bool {
    let part = |c: char| c.is_ascii_alphanumeric() || c == '_';
    text.match_indices(word).any(|(i, _)| {
        let before = &text[..i];
        let after = &text[i + word.len()..];
        let starts = before
            .chars()
            .next_back()
            .is_none_or(|c| !part(c) && c != '.')
            || before.ends_with("components.");
        let ends = after.chars().next().is_none_or(|c| !part(c))
            && !(after.starts_with('.') && after[1..].starts_with(|c: char| part(c)));
        starts && ends
    })
}

/// A rig read and checked once, ready to be assembled.
pub struct Checked {
    /// The netlist's checked schematic (steady initial pressures filled).
    schematic: Box<Schematic>,
    /// Where it was read from (`--rig`: a preset name or a file), for the
    /// lines of the errors found when it is assembled.
    source: String,
    /// The `--set`s applied to it, which those errors name rather than a
    /// line of the file ([`at_line_or_set`]).
    sets: Vec<String>,
}

/// Reads and checks a rig value of a kind `simulate` runs, after the
/// `--set`s `sets` (see [`locate`]).
pub fn check(value: &Value, source: &str, sets: &[String]) -> Result<Checked, CliError> {
    let checked = match value.get("kind").and_then(Value::as_str) {
        Some(netlist::KIND) => netlist::schematic(value).map(|s| Checked {
            schematic: s.into(),
            source: source.to_string(),
            sets: sets.to_vec(),
        }),
        // a missing or unknown kind: the error names the kinds there are
        _ => Err(match rig::kind_of(value) {
            Err(e) => e,
            Ok(k) => RigError::Invalid {
                path: "kind".into(),
                why: format!("`{}` is not a rig kind `simulate` runs", k.kind),
            },
        }),
    };
    checked.map_err(|e| locate(e, source, sets))
}

impl Checked {
    /// The unit in which the rig takes its input (the reading port's, see
    /// [`Schematic::input_unit`]).
    pub fn input_unit(&self) -> Option<&'static str> {
        self.schematic.input_unit()
    }

    /// Whether the run's input is a position set-point (a controller's
    /// `reference` reads it, [`netlist::Schematic::input_is_set_point`]).
    pub fn input_is_set_point(&self) -> bool {
        self.schematic.input_is_set_point()
    }

    /// Holds a warning ([`crate::console::hold_warning`]) for each
    /// parameter far outside what real rigs have
    /// ([`netlist::implausible`]: a unit slip, which runs), named by the
    /// path `--set` takes.
    pub fn hold_implausible(&self) {
        for w in netlist::implausible(&self.schematic) {
            crate::console::hold_warning(w);
        }
    }

    /// What the run's command is checked against (the spool's stroke, a
    /// pump's rating, or nothing: [`rig::CommandLimit::of`], from this one
    /// reading of the netlist, as
    /// [`Simulation::command_limit`](hydrocyl_system::simulation::Simulation::command_limit)
    /// has it for the Python package).
    pub fn command_limit(&self) -> Option<rig::CommandLimit> {
        rig::CommandLimit::of(&self.schematic)
    }

    /// The registry type of each component, by instance name
    /// ([`crate::simulate::Types`]).
    pub fn component_types(&self) -> crate::simulate::Types {
        self.schematic
            .instances
            .iter()
            .map(|i| (i.name.clone(), i.ty))
            .collect()
    }

    /// Every numeric parameter as `(path, value, unit)`.
    pub fn parameters(&self) -> Vec<rig::Parameter> {
        netlist::parameters_of(&self.schematic)
            .into_iter()
            .map(rig::Parameter::from)
            .collect()
    }

    /// Assembles the rig's circuit driven by `command`; an error found
    /// only now (an algebraic loop, a component refusing its parameters)
    /// names its JSON path and, for a file, its line ([`rig::at_line`]), or
    /// the `--set` that gave the value ([`at_line_or_set`]).
    pub fn circuit(&self, command: Signal) -> Result<Circuit, RigError> {
        netlist::assemble(&self.schematic, command)
            .map_err(|e| at_line_or_set(e, &self.source, &self.sets))
    }
}
