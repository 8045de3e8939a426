//! A command-switched (solenoid) four-way valve for a pump-controlled
//! cylinder: the thesis's proposed replacement of the pilot-shifted DDDC
//! valve (section 9.2), which also makes relief valves 1 and 2 unnecessary.
//!
//! ```text
//!   command u ─▶ target σ = +1 (u > u_d), −1 (u < −u_d), 0 otherwise
//!   spool s:     τ ds/dt = σ − s            (first-order solenoid shift)
//!   s > 0:  P1 ══[A_P s]══▶ A     B ══[A_T s]══▶ T
//!   s < 0:  P2 ══[A_P |s|]══▶ B   A ══[A_T |s|]══▶ T
//! ```
//!
//! Every path is the regularised sharp-edged orifice of `hydrocyl-valves`
//! (`Q = Cd A √(2|Δp|/ρ) sgn Δp`, both directions), its area proportional to
//! the spool's travel towards that side. With `s = 0` all four ports are shut
//! (closed centre). The spool follows the solenoid target with the time
//! constant τ (a DC solenoid valve shifts in 10–40 ms); a switching function
//! at `u = ±u_d` ends a step at every change of target. Power is dissipated
//! only in the four orifices (the massless spool stores none).

use crate::circuit::{
    BuildError, Causality, Component, Netlist, PowerTerms, Probe, Tangents, Wire,
};
use crate::wires::HydraulicNode;
use crate::Wires;
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Area, Pressure, VolumeFlow};
use hydrocyl_valves::orifice::Orifice;

/// The law of a [`SolenoidFourWay`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolenoidLaw {
    /// Open area of each supply path (P1→A, P2→B) at full shift \[m²\].
    pub area_supply: Area,
    /// Open area of each return path (A→T, B→T) at full shift \[m²\].
    pub area_return: Area,
    /// The orifice law of every path.
    pub orifice: Orifice,
    /// Command magnitude above which a solenoid is energised \[V\].
    pub threshold: f64,
    /// Time constant τ of the spool's shift \[s\].
    pub time_constant: f64,
}

impl SolenoidLaw {
    /// The solenoid target σ for command `u`: +1, −1 or 0.
    pub fn target(&self, u: f64) -> f64 {
        if u > self.threshold {
            1.0
        } else if u < -self.threshold {
            -1.0
        } else {
            0.0
        }
    }

    /// The four path flows `[P1→A, B→T, P2→B, A→T]` \[m³/s\] at spool `s`
    /// and port pressures `[p1, p2, pa, pb, pt]`.
    pub fn flows(&self, s: f64, p: [Pressure; 5]) -> [VolumeFlow; 4] {
        let [p1, p2, pa, pb, pt] = p;
        let (f, r) = (s.max(0.0), (-s).max(0.0));
        let o = &self.orifice;
        [
            o.flow(self.area_supply * f, p1, pa),
            o.flow(self.area_return * f, pb, pt),
            o.flow(self.area_supply * r, p2, pb),
            o.flow(self.area_return * r, pa, pt),
        ]
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), String> {
        for (name, v) in [
            ("area_supply", self.area_supply.si()),
            ("area_return", self.area_return.si()),
            ("time_constant", self.time_constant),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!("`{name}` = {v} must be positive"));
            }
        }
        if !(self.threshold.is_finite() && self.threshold >= 0.0) {
            return Err(format!(
                "`threshold` = {} must be non-negative",
                self.threshold
            ));
        }
        self.orifice
            .validate("solenoid four-way valve")
            .map_err(|e| e.to_string())
    }
}

/// The nodes a [`SolenoidFourWay`] joins: command, P1, P2, A, B, T.
pub type SolenoidNodes = [String; 6];

/// A command-switched closed-centre four-way valve (see the module docs).
#[derive(Clone, Debug)]
pub struct SolenoidFourWay {
    name: String,
    nodes: SolenoidNodes,
    /// The valve's law.
    pub law: SolenoidLaw,
    /// Initial spool position s(0) \[-\], in \[−1, 1\].
    pub initial_spool: f64,
    command: Wire<f64>,
    ports: [HydraulicNode; 5],
    spool: Wire<f64>,
    switches: usize,
}

impl SolenoidFourWay {
    /// Valve `name` on the nodes `[command, P1, P2, A, B, T]`.
    pub fn new(name: &str, nodes: SolenoidNodes, law: SolenoidLaw, initial_spool: f64) -> Self {
        Self {
            name: name.into(),
            nodes,
            law,
            initial_spool,
            command: Wire::UNBOUND,
            ports: [HydraulicNode::UNBOUND; 5],
            spool: Wire::UNBOUND,
            switches: 0,
        }
    }

    fn pressures(&self, w: &Wires) -> [Pressure; 5] {
        self.ports.map(|n| w.get(n.pressure))
    }
}

impl Component for SolenoidFourWay {
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
        d.state(self.spool, 0, 1.0);
    }
    fn evaluate_tangents(&self, _t: f64, x: &[f64], w: &Wires, d: &mut Tangents) {
        let p = self.pressures(w);
        let s = x[0];
        let o = &self.law.orifice;
        let (ap, at) = (self.law.area_supply, self.law.area_return);
        // (area per unit opening, ∂opening/∂s, from, to) of P1→A, B→T, P2→B, A→T
        let (df, dr) = (f64::from(s > 0.0), -f64::from(s < 0.0));
        let (f, r) = (s.max(0.0), (-s).max(0.0));
        let edges = [
            (ap, f, df, 0, 2),
            (at, f, df, 3, 4),
            (ap, r, dr, 1, 3),
            (at, r, dr, 2, 4),
        ];
        let unit = Area::new(1.0);
        for (area, open, dopen, from, to) in edges {
            let (up, down) = (self.ports[from], self.ports[to]);
            let g = o.conductance(area * open, p[from], p[to]);
            d.resistive(up, down, g, None);
            // the edge's flow is linear in its area
            let dq = area.si() * dopen * o.flow(unit, p[from], p[to]).si();
            d.state(up.inflow, 0, -dq);
            d.state(down.inflow, 0, dq);
        }
    }
    fn derivative_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        // the target is piecewise constant in the command (events at ±threshold)
        d.rate_state(0, 0, -1.0 / self.law.time_constant);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        let bad = |message: String| BuildError::Component {
            component: self.name.clone(),
            message,
        };
        self.law.validate().map_err(bad)?;
        if self.initial_spool.is_nan() || self.initial_spool.abs() > 1.0 {
            return Err(bad(format!(
                "`initial.spool` = {} must lie in [-1, 1]",
                self.initial_spool
            )));
        }
        self.command = net.signal(&self.nodes[0]);
        for k in 0..5 {
            self.ports[k] = net.hydraulic(&self.nodes[k + 1]);
        }
        self.spool = net.own_signal(&format!("{}.spool", self.name), Causality::Stored)?;
        Ok(())
    }
    fn n_states(&self) -> usize {
        1
    }
    fn state_names(&self) -> Vec<String> {
        vec![format!("{}.spool", self.name)]
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = 1.0;
    }
    fn initial_state(&self, x: &mut [f64]) {
        x[0] = self.initial_spool;
    }
    fn publish(&self, _t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.spool, x[0]);
    }
    fn evaluate(&self, _t: f64, x: &[f64], w: &mut Wires) {
        let [p1, p2, a, b, t] = self.ports;
        let [q_pa, q_bt, q_pb, q_at] = self.law.flows(x[0], self.pressures(w));
        w.add(p1.inflow, -q_pa);
        w.add(a.inflow, q_pa - q_at);
        w.add(p2.inflow, -q_pb);
        w.add(b.inflow, q_pb - q_bt);
        w.add(t.inflow, q_bt + q_at);
    }
    fn inflow_slope(&self, _t: f64, x: &[f64], w: &Wires, node: Wire<Pressure>) -> Option<f64> {
        let p = self.pressures(w);
        let [p1, p2, pa, pb, pt] = p;
        let (f, r) = (x[0].max(0.0), (-x[0]).max(0.0));
        let o = &self.law.orifice;
        let (ap, at) = (self.law.area_supply, self.law.area_return);
        let g_pa = o.conductance(ap * f, p1, pa);
        let g_bt = o.conductance(at * f, pb, pt);
        let g_pb = o.conductance(ap * r, p2, pb);
        let g_at = o.conductance(at * r, pa, pt);
        // ∂(flow into the node)/∂(its pressure), from each path touching it
        let [n1, n2, na, nb, nt] = self.ports.map(|n| n.pressure);
        let mut s = 0.0;
        if node == n1 {
            s -= g_pa;
        }
        if node == n2 {
            s -= g_pb;
        }
        if node == na {
            s -= g_pa + g_at;
        }
        if node == nb {
            s -= g_pb + g_bt;
        }
        if node == nt {
            s -= g_bt + g_at;
        }
        Some(s)
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        dx[0] = (self.law.target(w.get(self.command)) - x[0]) / self.law.time_constant;
    }
    fn n_events(&self) -> usize {
        2
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        let u = w.get(self.command);
        g[0] = u - self.law.threshold;
        g[1] = u + self.law.threshold;
    }
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        which: usize,
        _dir: Crossing,
    ) -> EventAction {
        // with no dead zone the two switching functions are one: count once
        if which == 0 || self.law.threshold > 0.0 {
            self.switches += 1;
        }
        EventAction::Continue
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.switches = 0;
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        let [p1, p2, pa, pb, pt] = self.pressures(w);
        let [q_pa, q_bt, q_pb, q_at] = self.law.flows(x[0], [p1, p2, pa, pb, pt]);
        p.dissipated =
            ((p1 - pa) * q_pa + (pb - pt) * q_bt + (p2 - pb) * q_pb + (pa - pt) * q_at).si();
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of("spool", self.spool)]
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![("switches".into(), self.switches as f64)]
    }
}
