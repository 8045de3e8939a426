//! A solenoid-operated on/off valve switched by the sign of a signal: the
//! circuit part of the thesis's first improvement (sections 8.2, 9.2: relief
//! valves 1 and 2 replaced by solenoid valves).
//!
//! ```text
//!   signal u ─▶ open when  direction · u > 0
//!   inlet ══[ orifice, area A when open, 0 when shut ]══ outlet
//! ```
//!
//! The open valve is the regularised sharp-edged orifice of
//! `hydrocyl-valves` (both flow directions, `Q = Cd A √(2|Δp|/ρ) sgn Δp`);
//! the switch is instantaneous (a solenoid's ~10 ms is short against the
//! 2.5–5 s periods of chapter 8). A switching function `g = u` ends a step at
//! every switch.

use crate::circuit::{BuildError, Component, HydraulicNode, Netlist, PowerTerms, Wire};
use crate::Wires;
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Area, VolumeFlow};
use hydrocyl_valves::orifice::Orifice;

/// An on/off valve between two nodes, open while `direction · signal > 0`.
#[derive(Clone, Debug)]
pub struct SwitchedOrifice {
    name: String,
    signal_name: String,
    inlet_name: String,
    outlet_name: String,
    /// Open area A \[m²\].
    pub area: Area,
    /// The orifice law (Cd \[-\], ρ \[kg·m⁻³\], regularisation \[Pa\]).
    pub orifice: Orifice,
    /// +1: open for a positive signal; −1: open for a negative one.
    pub direction: f64,
    signal: Wire<f64>,
    inlet: HydraulicNode,
    outlet: HydraulicNode,
    switches: usize,
}

impl SwitchedOrifice {
    /// Valve `name` between `inlet` and `outlet`, open while
    /// `direction · signal > 0` (`direction` ±1).
    pub fn new(
        name: &str,
        signal: &str,
        inlet: &str,
        outlet: &str,
        area: Area,
        orifice: Orifice,
        direction: f64,
    ) -> Self {
        let unbound = HydraulicNode::UNBOUND;
        Self {
            name: name.into(),
            signal_name: signal.into(),
            inlet_name: inlet.into(),
            outlet_name: outlet.into(),
            area,
            orifice,
            direction,
            signal: Wire::UNBOUND,
            inlet: unbound,
            outlet: unbound,
            switches: 0,
        }
    }

    /// Flow from inlet to outlet \[m³·s⁻¹\].
    fn flow(&self, w: &Wires) -> VolumeFlow {
        if self.direction * w.get(self.signal) > 0.0 {
            self.orifice.flow(
                self.area,
                w.get(self.inlet.pressure),
                w.get(self.outlet.pressure),
            )
        } else {
            VolumeFlow::ZERO
        }
    }
}

impl Component for SwitchedOrifice {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        let bad = |m: String| BuildError::Component {
            component: self.name.clone(),
            message: m,
        };
        if !(self.area.si() > 0.0 && self.area.si().is_finite()) {
            return Err(bad(format!(
                "open area must be positive, got {} m^2",
                self.area.si()
            )));
        }
        self.orifice
            .validate("switched orifice")
            .map_err(|e| bad(e.to_string()))?;
        if self.direction.abs() != 1.0 {
            return Err(bad(format!(
                "direction must be +1 or -1, got {}",
                self.direction
            )));
        }
        self.signal = net.signal(&self.signal_name);
        self.inlet = net.hydraulic(&self.inlet_name);
        self.outlet = net.hydraulic(&self.outlet_name);
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        let q = self.flow(w);
        w.add(self.inlet.inflow, -q);
        w.add(self.outlet.inflow, q);
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        g[0] = w.get(self.signal);
    }
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        _which: usize,
        _dir: Crossing,
    ) -> EventAction {
        self.switches += 1;
        EventAction::Continue
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.switches = 0;
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        p.dissipated =
            ((w.get(self.inlet.pressure) - w.get(self.outlet.pressure)) * self.flow(w)).si();
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![("switches".into(), self.switches as f64)]
    }
}
