//! Sensor models: what a rig's transducers report, as opposed to the state
//! they measure (catalog `sensor_lag`).
//!
//! ```text
//!   node pressure p ─▶ [ 1 / (τ s + 1) ] ─▶ reading y      (probe, e.g. `p1_sensor`)
//! ```
//!
//! A [`LaggedPressureSensor`] owns one state, its reading `y`, with
//! `dy/dt = (p − y)/τ` (a first-order lag, the usual model of a pressure
//! transducer with its tubing and signal filter). It only reads the node: it
//! adds no flow and no force, so the rig's physics is unchanged by it. The
//! lag is integrated with the rig's states (not applied afterwards to the
//! sampled output), so it is exact to the integrator's tolerance whatever the
//! output rate.

use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, Netlist, Probe, Wire, Wires,
};
use hydrocyl_ports::Pressure;

/// A pressure transducer with a first-order lag on hydraulic node `node`.
#[derive(Debug)]
pub struct LaggedPressureSensor {
    name: String,
    node_name: String,
    probe: String,
    /// Time constant τ \[s\] (> 0).
    pub time_constant: f64,
    /// Reading at the start \[Pa\] (the node's initial pressure: a sensor at rest).
    pub initial_reading: f64,
    node: Option<HydraulicNode>,
    out: Wire<Pressure>,
}

impl LaggedPressureSensor {
    /// A sensor named `name` reading node `node` with lag `time_constant`
    /// \[s\], starting at `initial_reading` \[Pa\]; its reading is the
    /// output column `probe`.
    pub fn new(
        name: &str,
        node: &str,
        probe: &str,
        time_constant: f64,
        initial_reading: f64,
    ) -> Self {
        Self {
            name: name.into(),
            node_name: node.into(),
            probe: probe.into(),
            time_constant,
            initial_reading,
            node: None,
            out: Wire::UNBOUND,
        }
    }
}

impl Component for LaggedPressureSensor {
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        if !(self.time_constant.is_finite() && self.time_constant > 0.0) {
            return Err(BuildError::Component {
                component: self.name.clone(),
                message: format!(
                    "time_constant must be positive and finite, got {}",
                    self.time_constant
                ),
            });
        }
        if !self.initial_reading.is_finite() {
            return Err(BuildError::Component {
                component: self.name.clone(),
                message: format!("initial reading {} is not finite", self.initial_reading),
            });
        }
        self.node = Some(net.hydraulic(&self.node_name));
        self.out = net.own_signal(&format!("{}:reading", self.name), Causality::Stored)?;
        Ok(())
    }
    fn n_states(&self) -> usize {
        1
    }
    fn state_names(&self) -> Vec<String> {
        vec![format!("{}.reading", self.name)]
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = 1.0e6;
    }
    fn initial_state(&self, x: &mut [f64]) {
        x[0] = self.initial_reading;
    }
    fn publish(&self, _t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.out, Pressure::new(x[0]));
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        let p = self.node.map_or(x[0], |n| w.get(n.pressure).si());
        dx[0] = (p - x[0]) / self.time_constant;
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of(self.probe.clone(), self.out)]
    }
}
