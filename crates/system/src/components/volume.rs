//! A constant hydraulic volume (a capacitive node owner).

use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, Netlist, PowerTerms, Probe, Tangents, Wires,
};
use hydrocyl_actuator::EntrainedAir;
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{HydraulicPort, Pressure};

/// A constant hydraulic volume (a pipeline, a hose, a pump line):
/// `dp/dt = B_eff(p)/V ΣQ_in`, `B_eff` the liquid's `B` without entrained
/// air ([`hydrocyl_actuator::fluid`]).
///
/// A pressure below absolute vacuum is **reported**, not hidden: a switching
/// function crosses zero [`CAVITATION_MARGIN_PA`](super::CAVITATION_MARGIN_PA)
/// below it (exactly at vacuum is not below it) and the entries are counted
/// ([`Component::diagnostics`] `cavitation_entries`, which the run summary
/// reads as it reads a cylinder chamber's); the constant-B liquid has left
/// its range there (with entrained air the pressure stays above it).
#[derive(Debug)]
pub struct Volume {
    name: String,
    node_name: String,
    /// Volume V \[m³\].
    pub volume: f64,
    /// Bulk modulus B of the liquid (the effective one without air) \[Pa\].
    pub bulk_modulus: f64,
    /// Entrained air in the oil (none: the constant B).
    pub air: EntrainedAir,
    /// Initial pressure \[Pa\].
    pub initial_pressure: f64,
    probe: Option<String>,
    node: HydraulicNode,
    /// Entries below absolute vacuum in this run.
    below_vacuum: usize,
}

impl Volume {
    /// A volume `volume` \[m³\] with bulk modulus `bulk_modulus` \[Pa\] owning node `node`.
    pub fn new(
        name: &str,
        node: &str,
        volume: f64,
        bulk_modulus: f64,
        initial_pressure: f64,
        probe: Option<&str>,
    ) -> Self {
        Self {
            name: name.into(),
            node_name: node.into(),
            volume,
            bulk_modulus,
            air: EntrainedAir::NONE,
            initial_pressure,
            probe: probe.map(str::to_string),
            node: HydraulicNode::UNBOUND,
            below_vacuum: 0,
        }
    }
}

impl Component for Volume {
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
        d.state(self.node.pressure, 0, 1.0);
    }
    fn derivative_tangents(&self, _t: f64, x: &[f64], w: &Wires, d: &mut Tangents) {
        let (b, slope) = self.air.bulk_modulus_and_slope(self.bulk_modulus, x[0]);
        d.rate_chain(0, b / self.volume, self.node.inflow);
        if slope != 0.0 {
            d.rate_state(0, 0, slope / self.volume * w.get(self.node.inflow).si());
        }
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        let invalid = |message: String| BuildError::Component {
            component: self.name.clone(),
            message,
        };
        if !(self.volume > 0.0
            && self.volume.is_finite()
            && self.bulk_modulus > 0.0
            && self.bulk_modulus.is_finite())
        {
            return Err(invalid(format!(
                "volume {} m^3 and bulk modulus {} Pa must be positive",
                self.volume, self.bulk_modulus
            )));
        }
        self.air.validate().map_err(|e| invalid(e.to_string()))?;
        self.node = net.own_hydraulic(&self.node_name, Causality::Stored)?;
        Ok(())
    }
    fn n_states(&self) -> usize {
        1
    }
    fn state_names(&self) -> Vec<String> {
        vec![format!("{}.p", self.name)]
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = 1.0e6;
    }
    fn initial_state(&self, x: &mut [f64]) {
        x[0] = self.initial_pressure;
    }
    fn publish(&self, _t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.node.pressure, Pressure::new(x[0]));
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        let b = self.air.bulk_modulus(self.bulk_modulus, x[0]);
        dx[0] = b / self.volume * w.get(self.node.inflow).si();
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        let port = HydraulicPort::new(Pressure::new(x[0]), w.get(self.node.inflow));
        p.storage = port.power().si();
        p.stored = self.air.stored_energy(self.bulk_modulus, x[0], self.volume);
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&self, _t: f64, x: &[f64], _w: &Wires, g: &mut [f64]) {
        g[0] = x[0] - (crate::rig::ABSOLUTE_VACUUM_GAUGE_PA - super::CAVITATION_MARGIN_PA);
    }
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        _which: usize,
        dir: Crossing,
    ) -> EventAction {
        if dir == Crossing::Falling {
            self.below_vacuum += 1;
        }
        EventAction::Continue
    }
    /// Its event only counts entries below vacuum.
    fn events_change_evaluation(&self) -> bool {
        false
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.below_vacuum = 0;
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![("cavitation_entries".into(), self.below_vacuum as f64)]
    }
    fn probes(&self) -> Vec<Probe> {
        self.probe
            .iter()
            .map(|n| Probe::of(n.clone(), self.node.pressure))
            .collect()
    }
}
