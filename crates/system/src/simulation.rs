//! The one run path: a rig (or an assembled circuit) + its command + solver
//! options → a [`Run`] (channels, statistics, diagnostics and, when asked,
//! the energy ledger's quadratures).
//!
//! Every caller that simulates a rig goes through [`Simulation`]:
//! [`rig::simulate`], the CLI's `simulate`, the studies
//! (chapter 3, 7 and 8), identification, the Python package and the benches.
//! A rig value is read, checked and assembled once, in [`Simulation::new`];
//! [`Simulation::run`] then integrates it and maps every failure to one
//! [`RigError`].
//!
//! ```
//! use hydrocyl_system::{rig, signal::Signal, simulation::Simulation, run::RunOptions};
//!
//! let rig = rig::load("leaney-moog").unwrap();
//! let t: Vec<f64> = (0..=50).map(|k| k as f64 * 0.01).collect();
//! let run = Simulation::new(&rig, Signal::Constant { value: 0.1 })
//!     .unwrap()
//!     .options(RunOptions::default())
//!     .run(&t)
//!     .unwrap();
//! assert!(run.channel("velocity").unwrap()[50] > 0.0); // a positive command extends
//! ```

use crate::circuit::Circuit;
use crate::rig::{self, RigError};
use crate::run::{run, Run, RunOptions, SimError};
use crate::signal::Signal;
use serde_json::Value;

/// One simulation: an assembled circuit, its initial state and the solver
/// options. Build it from a rig value ([`Simulation::new`]) or from a circuit
/// assembled by hand ([`Simulation::of_circuit`]); run it with
/// [`Simulation::run`] (as many times as wanted: each run starts from the
/// initial state).
pub struct Simulation {
    circuit: Circuit,
    initial: Vec<f64>,
    options: RunOptions,
}

impl Simulation {
    /// Reads, checks and assembles `rig` (a preset's or file's JSON value of
    /// any rig kind, after any `--set`) driven by `command`. Errors name the
    /// JSON path.
    pub fn new(rig: &Value, command: Signal) -> Result<Self, RigError> {
        Ok(Self::of_circuit(rig::circuit(rig, command)?))
    }

    /// A simulation of an assembled circuit, from the circuit's own initial
    /// state ([`Circuit::initial_state`]) with the default options.
    pub fn of_circuit(circuit: Circuit) -> Self {
        let initial = circuit.initial_state();
        Simulation {
            circuit,
            initial,
            options: RunOptions::default(),
        }
    }

    /// Sets the solver options.
    pub fn options(mut self, options: RunOptions) -> Self {
        self.options = options;
        self
    }

    /// Starts from `x0` instead of the circuit's initial state (one value per
    /// state, in [`Circuit::state_names`] order; checked by [`Simulation::run`]).
    pub fn initial_state(mut self, x0: Vec<f64>) -> Self {
        self.initial = x0;
        self
    }

    /// The assembled circuit (its components, probes, state names; the energy
    /// ledger's power terms after a run).
    pub fn circuit(&self) -> &Circuit {
        &self.circuit
    }

    /// The assembled circuit, mutable (e.g. to step it by hand).
    pub fn circuit_mut(&mut self) -> &mut Circuit {
        &mut self.circuit
    }

    /// The solver options the runs use.
    pub fn run_options(&self) -> &RunOptions {
        &self.options
    }

    /// Integrates from the initial state at `t_eval[0]` to the last of
    /// `t_eval`, sampling every `t_eval` time (sorted, strictly increasing,
    /// at least two). A solver failure is [`RigError::Sim`] with the method,
    /// time and reason; bad settings name the setting.
    pub fn run(&mut self, t_eval: &[f64]) -> Result<Run, RigError> {
        run(&mut self.circuit, &self.initial, t_eval, &self.options).map_err(|e| match e {
            SimError::Build(b) => RigError::from(b),
            other => RigError::Sim(other.to_string()),
        })
    }

    /// The circuit, consumed (for callers that keep it after the runs).
    pub fn into_circuit(self) -> Circuit {
        self.circuit
    }
}
