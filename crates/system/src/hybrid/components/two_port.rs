//! Pressure-operated two-port valves — the relief valve (eq 6.10) and the
//! check valve — as one assembler component: a law of `hydrocyl-valves`
//! between two named nodes, its flow a probe and a quadrature (the volume
//! passed), its dissipation in the energy ledger, its switching functions
//! forwarded as events whose rising crossings are counted per run.

use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, Netlist, PowerTerms, Probe, Tangents, Wire,
    Wires,
};
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Power, Pressure, VolumeFlow};
use hydrocyl_valves::check::CheckValve;
use hydrocyl_valves::relief::ReliefValve;

use super::UNBOUND_NODE;

/// What [`TwoPortValve`] asks of a pressure-operated valve's law: its
/// flow, slope and dissipation at the two pressures, and its switching
/// functions.
pub trait TwoPortLaw: Clone + std::fmt::Debug {
    /// One name per switching function: the diagnostic that counts its
    /// rising crossings (`cracked`, `fully_opened`, `opened`).
    const CROSSINGS: &'static [&'static str];
    /// The law's parameter check (its constructor's), as a message.
    fn check(&self) -> Result<(), String>;
    /// Flow from the inlet at `p_in` to the outlet at `p_out`.
    fn flow(&self, p_in: Pressure, p_out: Pressure) -> VolumeFlow;
    /// `∂Q/∂(p_in − p_out)` \[m³/(s Pa)\] (the node solve's slope).
    fn conductance(&self, p_in: Pressure, p_out: Pressure) -> f64;
    /// Power dissipated across the valve.
    fn power_dissipated(&self, p_in: Pressure, p_out: Pressure) -> Power;
    /// The switching functions, one per [`TwoPortLaw::CROSSINGS`] entry.
    fn margins(&self, p_in: Pressure, p_out: Pressure, g: &mut [f64]);
}

impl TwoPortLaw for ReliefValve {
    const CROSSINGS: &'static [&'static str] = &["cracked", "fully_opened"];
    fn check(&self) -> Result<(), String> {
        ReliefValve::new(self.cracking, self.kv, self.full_open)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }
    fn flow(&self, p_in: Pressure, p_out: Pressure) -> VolumeFlow {
        ReliefValve::flow(self, p_in, p_out)
    }
    fn conductance(&self, p_in: Pressure, p_out: Pressure) -> f64 {
        ReliefValve::conductance(self, p_in, p_out)
    }
    fn power_dissipated(&self, p_in: Pressure, p_out: Pressure) -> Power {
        ReliefValve::power_dissipated(self, p_in, p_out)
    }
    fn margins(&self, p_in: Pressure, p_out: Pressure, g: &mut [f64]) {
        g[0] = self.crack_margin(p_in, p_out);
        g[1] = self.full_open_margin(p_in, p_out);
    }
}

impl TwoPortLaw for CheckValve {
    const CROSSINGS: &'static [&'static str] = &["opened"];
    fn check(&self) -> Result<(), String> {
        CheckValve::new(self.cracking, self.opening_range, self.k_open)
            .map(|_| ())
            .map_err(|e| e.to_string())
    }
    fn flow(&self, p_in: Pressure, p_out: Pressure) -> VolumeFlow {
        CheckValve::flow(self, p_in, p_out)
    }
    fn conductance(&self, p_in: Pressure, p_out: Pressure) -> f64 {
        CheckValve::conductance(self, p_in, p_out)
    }
    fn power_dissipated(&self, p_in: Pressure, p_out: Pressure) -> Power {
        CheckValve::power_dissipated(self, p_in, p_out)
    }
    fn margins(&self, p_in: Pressure, p_out: Pressure, g: &mut [f64]) {
        g[0] = self.crack_margin(p_in, p_out);
    }
}

/// A pressure-operated valve of law `L` from node `inlet` to node `outlet`.
/// Events: the law's switching functions (their rising crossings counted).
#[derive(Clone, Debug)]
pub struct TwoPortValve<L> {
    name: String,
    inlet: String,
    outlet: String,
    /// The law.
    pub valve: L,
    i: HydraulicNode,
    o: HydraulicNode,
    flow: Wire<VolumeFlow>,
    /// Rising crossings per switching function this run.
    crossings: Vec<usize>,
}

/// A relief valve (eq 6.10). Events: cracking and full opening.
pub type ReliefComponent = TwoPortValve<ReliefValve>;

/// A check valve. Event: cracking (openings counted).
pub type CheckComponent = TwoPortValve<CheckValve>;

impl<L: TwoPortLaw> TwoPortValve<L> {
    /// A valve `name` of law `valve` from `inlet` to `outlet`.
    pub fn new(name: &str, valve: L, inlet: &str, outlet: &str) -> Self {
        Self {
            name: name.into(),
            inlet: inlet.into(),
            outlet: outlet.into(),
            valve,
            i: UNBOUND_NODE,
            o: UNBOUND_NODE,
            flow: Wire::UNBOUND,
            crossings: vec![0; L::CROSSINGS.len()],
        }
    }

    /// The pressures at the inlet and the outlet.
    fn pressures(&self, w: &Wires) -> (Pressure, Pressure) {
        (w.get(self.i.pressure), w.get(self.o.pressure))
    }
}

impl<L: TwoPortLaw> Component for TwoPortValve<L> {
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
        // the regime the pressures select (closed, cracking, open)
        let (pi, po) = self.pressures(w);
        d.resistive(
            self.i,
            self.o,
            self.valve.conductance(pi, po),
            Some(self.flow),
        );
    }
    fn quadrature_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        d.quadrature_chain(0, 1.0, self.flow);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.valve
            .check()
            .map_err(|message| BuildError::Component {
                component: self.name.clone(),
                message,
            })?;
        self.i = net.hydraulic(&self.inlet);
        self.o = net.hydraulic(&self.outlet);
        self.flow = net.own_signal(&format!("{}.flow", self.name), Causality::Algebraic)?;
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        let (pi, po) = self.pressures(w);
        let q = self.valve.flow(pi, po);
        w.add(self.i.inflow, -q);
        w.add(self.o.inflow, q);
        w.set(self.flow, q);
    }
    fn n_events(&self) -> usize {
        L::CROSSINGS.len()
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        let (pi, po) = self.pressures(w);
        self.valve.margins(pi, po, g);
    }
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        which: usize,
        dir: Crossing,
    ) -> EventAction {
        if dir == Crossing::Rising {
            if let Some(n) = self.crossings.get_mut(which) {
                *n += 1;
            }
        }
        EventAction::Continue
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        let (pi, po) = self.pressures(w);
        p.dissipated = self.valve.power_dissipated(pi, po).si();
    }
    fn n_quadratures(&self) -> usize {
        1
    }
    fn quadrature_names(&self) -> Vec<String> {
        vec![format!("{}.volume", self.name)]
    }
    fn quadratures(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], q: &mut [f64]) {
        q[0] = w.get(self.flow).si();
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of(format!("{}_flow", self.name), self.flow)]
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        L::CROSSINGS
            .iter()
            .zip(&self.crossings)
            .map(|(name, &n)| ((*name).to_string(), n as f64))
            .collect()
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.crossings.iter_mut().for_each(|n| *n = 0);
    }
}
