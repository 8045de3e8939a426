//! A servo needle valve: the NCCC needle valve (eq 6.1 with the opening of eq 6.11) whose opening
//! follows the velocity command instead of being set by hand (thesis section
//! 9.2: "the opening of the needle valve should be adjusted with the speed").
//!
//! ```text
//!   opening  Avn(u) = clamp(A_0 + g₊ max(u, 0) + g₋ max(−u, 0), A_0, A_max)
//!   inlet ══[ needle valve at Avn(u), reverse check ]══ outlet
//! ```
//!
//! The command `u` is the drive's velocity command (the pump command \[V\],
//! proportional to the commanded speed), so the opening grows with the
//! speed asked for; separate gains per sign let the law follow the return
//! flow, which differs by the area ratio between the two directions. The
//! servo is taken as fast against the command (the needle's own lag is not
//! modelled). Switching functions: `u = 0` and the opening reaching `A_max`
//! (the law's kinks), and the reverse check's cracking.

use crate::circuit::{
    BuildError, Causality, Component, Netlist, PowerTerms, Probe, Tangents, Wire,
};
use crate::series::OrificeInflow;
use crate::wires::HydraulicNode;
use crate::Wires;
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Area, Pressure};
use hydrocyl_valves::needle::NeedleValve;

/// The opening law of a [`ServoNeedle`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpeningLaw {
    /// Opening at zero command A_0 \[m²\].
    pub area_min: f64,
    /// Largest opening A_max \[m²\].
    pub area_max: f64,
    /// Opening per volt of positive command g₊ \[m²/V\].
    pub gain_positive: f64,
    /// Opening per volt of negative command g₋ \[m²/V\].
    pub gain_negative: f64,
}

impl OpeningLaw {
    /// The unclamped opening for command `u` \[m²\].
    fn raw(&self, u: f64) -> f64 {
        self.area_min + self.gain_positive * u.max(0.0) + self.gain_negative * (-u).max(0.0)
    }

    /// The opening for command `u` \[m²\].
    pub fn area(&self, u: f64) -> f64 {
        self.raw(u).min(self.area_max)
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), String> {
        let ok = |v: f64| v.is_finite() && v >= 0.0;
        if !(ok(self.area_min) && ok(self.gain_positive) && ok(self.gain_negative)) {
            return Err(
                "`area_min`, `gain_positive` and `gain_negative` must be non-negative".into(),
            );
        }
        if !(self.area_max.is_finite() && self.area_max > self.area_min) {
            return Err(format!(
                "`area_max` = {} must exceed `area_min` = {}",
                self.area_max, self.area_min
            ));
        }
        Ok(())
    }
}

/// A needle valve whose opening follows a command signal (module docs).
#[derive(Clone, Debug)]
pub struct ServoNeedle {
    name: String,
    nodes: [String; 3],
    /// The valve at its base opening (the `area` field is set per command).
    pub needle: NeedleValve,
    /// The opening law.
    pub law: OpeningLaw,
    command: Wire<f64>,
    i: HydraulicNode,
    o: HydraulicNode,
    opening: Wire<f64>,
    openings: usize,
}

impl ServoNeedle {
    /// Valve `name` on the nodes `[command, inlet, outlet]`.
    pub fn new(name: &str, nodes: [String; 3], needle: NeedleValve, law: OpeningLaw) -> Self {
        Self {
            name: name.into(),
            nodes,
            needle,
            law,
            command: Wire::UNBOUND,
            i: HydraulicNode::UNBOUND,
            o: HydraulicNode::UNBOUND,
            opening: Wire::UNBOUND,
            openings: 0,
        }
    }

    /// The needle valve at the opening for command `u`.
    pub fn valve_at(&self, u: f64) -> NeedleValve {
        NeedleValve {
            area: Area::new(self.law.area(u)),
            ..self.needle
        }
    }

    fn valve(&self, w: &Wires) -> NeedleValve {
        self.valve_at(w.get(self.command))
    }
}

impl Component for ServoNeedle {
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
        let v = self.valve(w);
        let (pi, po) = (w.get(self.i.pressure), w.get(self.o.pressure));
        d.resistive(self.i, self.o, v.conductance(pi, po), None);
        // the opening law's slope on the branch the command is on
        let u = w.get(self.command);
        let da = if self.law.raw(u) > self.law.area_max {
            0.0
        } else if u > 0.0 {
            self.law.gain_positive
        } else if u < 0.0 {
            -self.law.gain_negative
        } else {
            0.0
        };
        // the metered flow is linear in the area
        let unit = Area::new(1.0);
        let dq = da * v.effective_factor * v.orifice.flow(unit, pi, po).si();
        d.chain(self.opening, da, self.command);
        d.chain(self.i.inflow, -dq, self.command);
        d.chain(self.o.inflow, dq, self.command);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        let bad = |message: String| BuildError::Component {
            component: self.name.clone(),
            message,
        };
        self.law.validate().map_err(bad)?;
        let n = self.valve_at(0.0);
        NeedleValve::new(n.area, n.effective_factor, n.orifice, n.reverse_check)
            .map_err(|e| bad(e.to_string()))?;
        self.command = net.signal(&self.nodes[0]);
        self.i = net.hydraulic(&self.nodes[1]);
        self.o = net.hydraulic(&self.nodes[2]);
        self.opening = net.own_signal(&format!("{}.opening", self.name), Causality::Algebraic)?;
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        let v = self.valve(w);
        let q = v.flow(w.get(self.i.pressure), w.get(self.o.pressure));
        w.add(self.i.inflow, -q);
        w.add(self.o.inflow, q);
        w.set(self.opening, v.area.si());
    }
    fn orifice_inflow(
        &self,
        _t: f64,
        _x: &[f64],
        w: &Wires,
        node: Wire<Pressure>,
    ) -> Option<OrificeInflow> {
        OrificeInflow::needle(&self.valve(w), (self.i, self.o), w, node)
    }
    fn inflow_slope(&self, _t: f64, _x: &[f64], w: &Wires, node: Wire<Pressure>) -> Option<f64> {
        let g = self
            .valve(w)
            .conductance(w.get(self.i.pressure), w.get(self.o.pressure));
        Some(if node == self.i.pressure || node == self.o.pressure {
            -g
        } else {
            0.0
        })
    }
    fn n_events(&self) -> usize {
        3
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        let u = w.get(self.command);
        g[0] = u;
        g[1] = self.law.raw(u) - self.law.area_max;
        g[2] = self
            .valve(w)
            .reverse_check_margin(w.get(self.i.pressure), w.get(self.o.pressure));
    }
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        which: usize,
        dir: Crossing,
    ) -> EventAction {
        if which == 2 && dir == Crossing::Rising {
            self.openings += 1;
        }
        EventAction::Continue
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        p.dissipated = self
            .valve(w)
            .power_dissipated(w.get(self.i.pressure), w.get(self.o.pressure))
            .si();
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of("opening", self.opening)]
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![("check_opened".into(), self.openings as f64)]
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.openings = 0;
    }
}
