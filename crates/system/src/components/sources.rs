//! Fixed-pressure sources (supply, tank) and command signal sources.

use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, Netlist, PowerTerms, Probe, Wire, Wires,
};
use crate::signal::Signal;
use hydrocyl_ports::{HydraulicPort, Pressure};
use std::cell::Cell;

/// A node held at a fixed pressure: a supply (pressure-compensated pump with
/// accumulator) or the tank. It delivers whatever flow the circuit draws.
#[derive(Debug)]
pub struct PressureSource {
    name: String,
    node_name: String,
    /// The fixed pressure \[Pa\].
    pub pressure: Pressure,
    probe: Option<String>,
    node: HydraulicNode,
}

impl PressureSource {
    /// A source named `name` holding node `node` at `pressure`; `probe`
    /// names its pressure as an output column (e.g. `ps`).
    pub fn new(name: &str, node: &str, pressure: Pressure, probe: Option<&str>) -> Self {
        Self {
            name: name.into(),
            node_name: node.into(),
            pressure,
            probe: probe.map(str::to_string),
            node: HydraulicNode::UNBOUND,
        }
    }
}

impl Component for PressureSource {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.node = net.own_hydraulic(&self.node_name, Causality::Stored)?;
        Ok(())
    }
    fn publish(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        w.set(self.node.pressure, self.pressure);
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        // the flow drawn from the node is delivered at its pressure: the
        // source's port is the node with the flow reversed
        let port = HydraulicPort::new(self.pressure, -w.get(self.node.inflow));
        p.source = port.power().si();
    }
    fn probes(&self) -> Vec<Probe> {
        self.probe
            .iter()
            .map(|n| Probe::of(n.clone(), self.node.pressure))
            .collect()
    }
}

/// A command signal source (writes signal `output` from a [`Signal`] of time).
#[derive(Debug)]
pub struct CommandInput {
    name: String,
    output_name: String,
    /// The signal.
    pub signal: Signal,
    hint: Cell<usize>,
    out: Wire<f64>,
}

impl CommandInput {
    /// A source named `name` writing signal `output`.
    pub fn new(name: &str, output: &str, signal: Signal) -> Self {
        Self {
            name: name.into(),
            output_name: output.into(),
            signal,
            hint: Cell::new(0),
            out: Wire::UNBOUND,
        }
    }
}

impl Component for CommandInput {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.out = net.own_signal(&self.output_name, Causality::Stored)?;
        Ok(())
    }
    fn publish(&self, t: f64, _x: &[f64], w: &mut Wires) {
        w.set(self.out, self.signal.value_hinted(t, &self.hint));
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of("command", self.out)]
    }
}
