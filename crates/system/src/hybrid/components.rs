//! The hybrid drive's components as assembler [`Component`]s: the pump (its
//! identified command → flow model), relief valves, check valves, the
//! pilot-operated four-way valve and the needle valve (joined in series by an
//! algebraic node, [`crate::series`]). Each wraps a pure constitutive law of
//! `hydrocyl-valves` or `hydrocyl-pump-motor`, binds to named nodes, and
//! forwards the law's switching functions as events (counted per run in its
//! diagnostics); the valves give the slopes the node's Newton solve uses.

use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, Netlist, PowerTerms, Probe, Tangents, Wire,
    Wires,
};
use crate::series::OrificeInflow;
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Pressure, Voltage, VolumeFlow};
use hydrocyl_pump_motor::IdentifiedPump;
use hydrocyl_valves::needle::NeedleValve;

const UNBOUND_NODE: HydraulicNode = HydraulicNode::UNBOUND;

/// The servomotor and gear pump as the identified second-order command →
/// flow model, moving flow from node `line_b` to node `line_a` (negative
/// flow reverses it). States `[Q, Q̇]`.
#[derive(Clone, Debug)]
pub struct PumpComponent {
    name: String,
    command: String,
    line_a: String,
    line_b: String,
    /// The model.
    pub pump: IdentifiedPump,
    /// The command in volts (the command signal is untyped: a normalised
    /// command on the valve rig, the servo drive's voltage here).
    u: Wire<f64>,
    a: HydraulicNode,
    b: HydraulicNode,
    flow: Wire<VolumeFlow>,
    reversals: usize,
}

impl PumpComponent {
    /// A pump `name` driven by signal `command` between pump lines `line_a`, `line_b`.
    pub fn new(
        name: &str,
        pump: IdentifiedPump,
        command: &str,
        line_a: &str,
        line_b: &str,
    ) -> Self {
        Self {
            name: name.into(),
            command: command.into(),
            line_a: line_a.into(),
            line_b: line_b.into(),
            pump,
            u: Wire::UNBOUND,
            a: UNBOUND_NODE,
            b: UNBOUND_NODE,
            flow: Wire::UNBOUND,
            reversals: 0,
        }
    }
}

impl Component for PumpComponent {
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn publish_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        d.state(self.flow, 0, 1.0);
    }
    fn evaluate_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        d.state(self.a.inflow, 0, 1.0);
        d.state(self.b.inflow, 0, -1.0);
    }
    fn derivative_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        let j = self.pump.jacobian();
        for (k, jk) in j.iter().enumerate() {
            d.rate_state(k / 2, k % 2, *jk);
        }
        let wn = self.pump.natural_frequency;
        d.rate_chain(1, wn * wn * self.pump.gain, self.u);
    }
    fn quadrature_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        d.quadrature_state(0, 0, 1.0);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        IdentifiedPump::new(
            self.pump.gain,
            self.pump.natural_frequency,
            self.pump.damping,
        )
        .map_err(|e| BuildError::Component {
            component: self.name.clone(),
            message: e.to_string(),
        })?;
        self.u = net.signal(&self.command);
        self.a = net.hydraulic(&self.line_a);
        self.b = net.hydraulic(&self.line_b);
        self.flow = net.own_signal(&format!("{}.flow", self.name), Causality::Stored)?;
        Ok(())
    }
    fn n_states(&self) -> usize {
        IdentifiedPump::N_STATES
    }
    fn state_names(&self) -> Vec<String> {
        vec![
            format!("{}.flow", self.name),
            format!("{}.flow_rate", self.name),
        ]
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = 1.0e-5;
        s[1] = 1.0e-3;
    }
    fn publish(&self, _t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.flow, VolumeFlow::new(x[0]));
    }
    fn evaluate(&self, _t: f64, x: &[f64], w: &mut Wires) {
        let q = self.pump.flow(x);
        w.add(self.a.inflow, q);
        w.add(self.b.inflow, -q);
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        self.pump.derivatives(x, Voltage::new(w.get(self.u)), dx);
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&self, _t: f64, x: &[f64], _w: &Wires, g: &mut [f64]) {
        g[0] = self.pump.reversal_margin(x);
    }
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        _which: usize,
        _dir: Crossing,
    ) -> EventAction {
        self.reversals += 1;
        EventAction::Continue
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        // the pump takes Q in at p_B and delivers it at p_A: its shaft brings (p_A − p_B) Q
        p.source = ((w.get(self.a.pressure) - w.get(self.b.pressure)) * VolumeFlow::new(x[0])).si();
    }
    fn n_quadratures(&self) -> usize {
        1
    }
    fn quadrature_names(&self) -> Vec<String> {
        vec![format!("{}.volume", self.name)]
    }
    fn quadratures(&self, _t: f64, x: &[f64], _w: &Wires, _dx: &[f64], q: &mut [f64]) {
        q[0] = x[0];
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of("pump_flow", self.flow)]
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![("reversals".into(), self.reversals as f64)]
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.reversals = 0;
    }
}

/// The needle valve with its reverse-flow check from node `inlet` to node
/// `outlet` (metered forward flow, the check opening for reverse flow).
/// Event: the reverse check cracking (openings counted).
#[derive(Clone, Debug)]
pub struct NeedleComponent {
    name: String,
    inlet: String,
    outlet: String,
    /// The valve.
    pub needle: NeedleValve,
    i: HydraulicNode,
    o: HydraulicNode,
    openings: usize,
}

impl NeedleComponent {
    /// A needle valve `name` from `inlet` to `outlet`.
    pub fn new(name: &str, needle: NeedleValve, inlet: &str, outlet: &str) -> Self {
        Self {
            name: name.into(),
            inlet: inlet.into(),
            outlet: outlet.into(),
            needle,
            i: UNBOUND_NODE,
            o: UNBOUND_NODE,
            openings: 0,
        }
    }
}

impl Component for NeedleComponent {
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn evaluate_tangents(&self, _t: f64, _x: &[f64], w: &Wires, d: &mut Tangents) {
        let g = self
            .needle
            .conductance(w.get(self.i.pressure), w.get(self.o.pressure));
        d.resistive(self.i, self.o, g, None);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        NeedleValve::new(
            self.needle.area,
            self.needle.effective_factor,
            self.needle.orifice,
            self.needle.reverse_check,
        )
        .map_err(|e| BuildError::Component {
            component: self.name.clone(),
            message: e.to_string(),
        })?;
        self.i = net.hydraulic(&self.inlet);
        self.o = net.hydraulic(&self.outlet);
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        let q = self
            .needle
            .flow(w.get(self.i.pressure), w.get(self.o.pressure));
        w.add(self.i.inflow, -q);
        w.add(self.o.inflow, q);
    }
    fn orifice_inflow(
        &self,
        _t: f64,
        _x: &[f64],
        w: &Wires,
        node: Wire<Pressure>,
    ) -> Option<OrificeInflow> {
        OrificeInflow::needle(&self.needle, (self.i, self.o), w, node)
    }
    fn inflow_slope(&self, _t: f64, _x: &[f64], w: &Wires, node: Wire<Pressure>) -> Option<f64> {
        // Q leaves the inlet and enters the outlet; ∂Q/∂p_in = −∂Q/∂p_out = g
        let g = self
            .needle
            .conductance(w.get(self.i.pressure), w.get(self.o.pressure));
        Some(if node == self.i.pressure || node == self.o.pressure {
            -g
        } else {
            0.0
        })
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        g[0] = self
            .needle
            .reverse_check_margin(w.get(self.i.pressure), w.get(self.o.pressure));
    }
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        _which: usize,
        dir: Crossing,
    ) -> EventAction {
        if dir == Crossing::Rising {
            self.openings += 1;
        }
        EventAction::Continue
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        p.dissipated = self
            .needle
            .power_dissipated(w.get(self.i.pressure), w.get(self.o.pressure))
            .si();
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![("check_opened".into(), self.openings as f64)]
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.openings = 0;
    }
}

mod pilot;
mod two_port;
pub use pilot::{PilotNodes, PilotValve};
pub use two_port::{CheckComponent, ReliefComponent, TwoPortLaw, TwoPortValve};

#[cfg(test)]
mod tests;
