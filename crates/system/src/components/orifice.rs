//! A fixed sharp-edged orifice between two nodes.

use crate::circuit::{
    BuildError, Component, HydraulicNode, Netlist, PowerTerms, Tangents, Wire, Wires,
};
use crate::series::OrificeInflow;
use hydrocyl_ports::{Pressure, VolumeFlow};
use hydrocyl_valves::orifice::Orifice;

/// A fixed sharp-edged orifice between two nodes (flow from `a` to `b`).
#[derive(Debug)]
pub struct FixedOrifice {
    name: String,
    a_name: String,
    b_name: String,
    /// Opening area \[m²\].
    pub area: hydrocyl_ports::Area,
    /// The orifice law.
    pub orifice: Orifice,
    a: HydraulicNode,
    b: HydraulicNode,
}

impl FixedOrifice {
    /// An orifice of `area` between nodes `a` and `b`.
    pub fn new(name: &str, a: &str, b: &str, area: hydrocyl_ports::Area, orifice: Orifice) -> Self {
        Self {
            name: name.into(),
            a_name: a.into(),
            b_name: b.into(),
            area,
            orifice,
            a: HydraulicNode::UNBOUND,
            b: HydraulicNode::UNBOUND,
        }
    }
    fn flow(&self, w: &Wires) -> VolumeFlow {
        self.orifice
            .flow(self.area, w.get(self.a.pressure), w.get(self.b.pressure))
    }
}

impl Component for FixedOrifice {
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
            .orifice
            .conductance(self.area, w.get(self.a.pressure), w.get(self.b.pressure));
        d.resistive(self.a, self.b, g, None);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.a = net.hydraulic(&self.a_name);
        self.b = net.hydraulic(&self.b_name);
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        let q = self.flow(w);
        w.add(self.a.inflow, -q);
        w.add(self.b.inflow, q);
    }
    fn orifice_inflow(
        &self,
        _t: f64,
        _x: &[f64],
        w: &Wires,
        node: Wire<Pressure>,
    ) -> Option<OrificeInflow> {
        let k = self.orifice.coefficient() * self.area.si();
        let transition = self.orifice.dp_transition.si();
        OrificeInflow::between(k, transition, (self.a, self.b), w, node)
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        p.dissipated = ((w.get(self.a.pressure) - w.get(self.b.pressure)) * self.flow(w)).si();
    }
}
