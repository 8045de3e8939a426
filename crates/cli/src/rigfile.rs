//! Rig files as `hydrocyl simulate` reads them: a preset or a file
//! (duplicate keys refused, an older rig kind read as its netlist:
//! [`rig::load`]), checked once ([`check`]): every error names the JSON path
//! and, for a file, its line — those found when the circuit is assembled
//! (an algebraic loop) too ([`Checked::circuit`]).

use crate::error::CliError;
use hydrocyl_system::netlist::{self, Schematic};
use hydrocyl_system::rig::{self, RigError};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::Circuit;
use serde_json::Value;

/// A rig error with the line of its JSON path in `source` added (when
/// `source` is a file).
pub fn locate(e: RigError, source: &str) -> CliError {
    CliError::Input(rig::at_line(e, source).to_string())
}

/// A rig read and checked once, ready to be assembled.
pub struct Checked {
    /// The netlist's checked schematic (steady initial pressures filled).
    schematic: Box<Schematic>,
    /// Where it was read from (`--rig`: a preset name or a file), for the
    /// lines of the errors found when it is assembled.
    source: String,
}

/// Reads and checks a rig value of a kind `simulate` runs (see [`locate`]).
pub fn check(value: &Value, source: &str) -> Result<Checked, CliError> {
    let checked = match value.get("kind").and_then(Value::as_str) {
        Some(netlist::KIND) => netlist::schematic(value).map(|s| Checked {
            schematic: s.into(),
            source: source.to_string(),
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
    checked.map_err(|e| locate(e, source))
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
    /// names its JSON path and, for a file, its line ([`rig::at_line`]).
    pub fn circuit(&self, command: Signal) -> Result<Circuit, RigError> {
        netlist::assemble(&self.schematic, command).map_err(|e| rig::at_line(e, &self.source))
    }
}
