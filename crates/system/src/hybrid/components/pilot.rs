//! The pilot-operated four-way valve of the hybrid drive as an assembler
//! [`Component`]: its opening moves with the two pilot (pump line)
//! pressures; the open chamber returns to the T port through an orifice
//! law, which it declares to an algebraic node there
//! ([`Component::orifice_inflow`]).

use super::UNBOUND_NODE;
use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, Netlist, PowerTerms, Probe, Tangents, Wire,
    Wires,
};
use crate::series::OrificeInflow;
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Position, Pressure, VolumeFlow};
use hydrocyl_valves::orifice::{signed_sqrt_regularised, signed_sqrt_regularised_derivative};
use hydrocyl_valves::pilot_valve::PilotFourWay;

/// The nodes a [`PilotValve`] joins.
#[derive(Clone, Copy, Debug)]
pub struct PilotNodes<'a> {
    /// Pump line 1: pilot port 1 of the four-way valve.
    pub pilot_1: &'a str,
    /// Pump line 2: pilot port 6.
    pub pilot_2: &'a str,
    /// Work port A: cylinder chamber 1.
    pub a: &'a str,
    /// Work port B: cylinder chamber 2.
    pub b: &'a str,
    /// The T port (joined to the needle valve by a short pipe).
    pub t: &'a str,
}

/// The DDDC four-way valve, piloted by the pump lines: it opens the chamber
/// that is not fed (B when `Pp1 > Pp2`, A otherwise) to its T port
/// (section 6.2.2.3, Fig 7-3), `Q = k_T(y) √(p_x − p_T)` (regularised). The
/// P port is not connected: the fed chamber is supplied through its relief
/// valve directly, as in `pcyl4_1.m`. On the rig the T port feeds the
/// [`NeedleComponent`](super::NeedleComponent) through an algebraic node
/// ([`AlgebraicNode`](crate::series::AlgebraicNode)).
///
/// Events: the valve shifting into either state and reaching full shift.
#[derive(Clone, Debug)]
pub struct PilotValve {
    name: String,
    nodes: [String; 5],
    /// The pilot four-way valve (private: the opening caches below are
    /// computed from it when bound).
    four_way: PilotFourWay,
    pp1: HydraulicNode,
    pp2: HydraulicNode,
    a: HydraulicNode,
    b: HydraulicNode,
    t: HydraulicNode,
    spool: Wire<Position>,
    flow_a: Wire<VolumeFlow>,
    flow_b: Wire<VolumeFlow>,
    counts: [usize; 3],
    /// The last `(Pp1, Pp2, y)`: the opening (two circle segments) is
    /// computed once per pilot pressures, not once per trial of the T
    /// port's Newton solve.
    last_opening: std::cell::Cell<[f64; 3]>,
    /// [`PilotFourWay::full_open_area`], computed when bound.
    full_open_area: f64,
}

impl PilotValve {
    /// The pilot four-way valve.
    pub fn four_way(&self) -> &PilotFourWay {
        &self.four_way
    }

    /// The valve `name` joined to `nodes`.
    pub fn new(name: &str, four_way: PilotFourWay, nodes: PilotNodes<'_>) -> Self {
        Self {
            name: name.into(),
            nodes: [
                nodes.pilot_1.into(),
                nodes.pilot_2.into(),
                nodes.a.into(),
                nodes.b.into(),
                nodes.t.into(),
            ],
            four_way,
            pp1: UNBOUND_NODE,
            pp2: UNBOUND_NODE,
            a: UNBOUND_NODE,
            b: UNBOUND_NODE,
            t: UNBOUND_NODE,
            spool: Wire::UNBOUND,
            flow_a: Wire::UNBOUND,
            flow_b: Wire::UNBOUND,
            counts: [0; 3],
            last_opening: std::cell::Cell::new([f64::NAN; 3]),
            full_open_area: f64::NAN,
        }
    }

    /// The signed opening `y` at the pilot pressures on `w` (memoised).
    fn opening(&self, w: &Wires) -> f64 {
        let (pp1, pp2) = (w.get(self.pp1.pressure), w.get(self.pp2.pressure));
        let [a, b, y] = self.last_opening.get();
        if a == pp1.si() && b == pp2.si() {
            return y;
        }
        let y = self
            .four_way
            .opening_given_full_area(pp1, pp2, self.full_open_area);
        self.last_opening.set([pp1.si(), pp2.si(), y]);
        y
    }

    /// The opening `y`, the flow from the open chamber to the T port and the
    /// open chamber's pressure.
    fn state(&self, w: &Wires) -> (f64, VolumeFlow, Pressure) {
        let y = self.opening(w);
        let px = if y > 0.0 {
            w.get(self.b.pressure)
        } else {
            w.get(self.a.pressure)
        };
        let k = self.four_way.return_coefficient(y);
        if k <= 0.0 {
            return (y, VolumeFlow::ZERO, px);
        }
        let xt = self.four_way.dp_transition.si();
        let dp = (px - w.get(self.t.pressure)).si();
        (y, VolumeFlow::new(k * signed_sqrt_regularised(dp, xt)), px)
    }
}

impl Component for PilotValve {
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
        let (pp1, pp2) = (w.get(self.pp1.pressure), w.get(self.pp2.pressure));
        // the spool travel and the opening move with pp1 − pp2
        let ds = self.four_way.spool_travel_slope(pp1, pp2);
        d.chain(self.spool, ds, self.pp1.pressure);
        d.chain(self.spool, -ds, self.pp2.pressure);
        let y = self.opening(w);
        let k = self.four_way.return_coefficient(y);
        if k <= 0.0 {
            return;
        }
        // Q = k(y) ssr(p_x − p_T) leaves the open chamber x and enters T
        let (open, q) = if y > 0.0 {
            (self.b, self.flow_b)
        } else {
            (self.a, self.flow_a)
        };
        let xt = self.four_way.dp_transition.si();
        let dp = (w.get(open.pressure) - w.get(self.t.pressure)).si();
        let dk = self.four_way.k_t * y.signum() * self.four_way.opening_slope(pp1, pp2);
        let c_pilot = dk * signed_sqrt_regularised(dp, xt);
        let g = k * signed_sqrt_regularised_derivative(dp, xt);
        d.chain(q, c_pilot, self.pp1.pressure);
        d.chain(q, -c_pilot, self.pp2.pressure);
        d.chain(q, g, open.pressure);
        d.chain(q, -g, self.t.pressure);
        d.chain(open.inflow, -1.0, q);
        d.chain(self.t.inflow, 1.0, q);
    }
    fn quadrature_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        d.quadrature_chain(0, 1.0, self.flow_a);
        d.quadrature_chain(1, 1.0, self.flow_b);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.four_way
            .validate()
            .map_err(|e| BuildError::Component {
                component: self.name.clone(),
                message: e.to_string(),
            })?;
        self.full_open_area = self.four_way.full_open_area();
        self.pp1 = net.hydraulic(&self.nodes[0]);
        self.pp2 = net.hydraulic(&self.nodes[1]);
        self.a = net.hydraulic(&self.nodes[2]);
        self.b = net.hydraulic(&self.nodes[3]);
        self.t = net.hydraulic(&self.nodes[4]);
        self.spool = net.own_signal(&format!("{}.spool", self.name), Causality::Algebraic)?;
        self.flow_a = net.own_signal(&format!("{}.flow_a", self.name), Causality::Algebraic)?;
        self.flow_b = net.own_signal(&format!("{}.flow_b", self.name), Causality::Algebraic)?;
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        let (y, q, _) = self.state(w);
        let from = if y > 0.0 {
            self.b.inflow
        } else {
            self.a.inflow
        };
        w.add(from, -q);
        w.add(self.t.inflow, q);
        let s = self
            .four_way
            .spool_travel(w.get(self.pp1.pressure), w.get(self.pp2.pressure));
        w.set(self.spool, s);
        let none = VolumeFlow::ZERO;
        w.set(self.flow_a, if y > 0.0 { none } else { q });
        w.set(self.flow_b, if y > 0.0 { q } else { none });
    }
    fn orifice_inflow(
        &self,
        _t: f64,
        _x: &[f64],
        w: &Wires,
        node: Wire<Pressure>,
    ) -> Option<OrificeInflow> {
        if node == self.pp1.pressure || node == self.pp2.pressure {
            return None; // the opening moves with the pilot pressures
        }
        // Q = k √(p_x − p_T) leaves the open chamber and enters T
        let y = self.opening(w);
        let open = if y > 0.0 { self.b } else { self.a };
        let k = self.four_way.return_coefficient(y);
        OrificeInflow::between(k, self.four_way.dp_transition.si(), (open, self.t), w, node)
    }
    fn n_events(&self) -> usize {
        3
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        let (pp1, pp2) = (w.get(self.pp1.pressure), w.get(self.pp2.pressure));
        g[0] = self.four_way.extend_shift_margin(pp1, pp2);
        g[1] = self.four_way.retract_shift_margin(pp1, pp2);
        g[2] = self.four_way.full_shift_margin(pp1, pp2);
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
            self.counts[which] += 1;
        }
        EventAction::Continue
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        let (_, q, px) = self.state(w);
        p.dissipated = ((px - w.get(self.t.pressure)) * q).si();
    }
    fn n_quadratures(&self) -> usize {
        2
    }
    fn quadrature_names(&self) -> Vec<String> {
        vec![
            format!("{}.volume_a", self.name),
            format!("{}.volume_b", self.name),
        ]
    }
    fn quadratures(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], q: &mut [f64]) {
        q[0] = w.get(self.flow_a).si();
        q[1] = w.get(self.flow_b).si();
    }
    fn probes(&self) -> Vec<Probe> {
        vec![
            Probe::of("pilot_spool", self.spool),
            Probe::of("return_flow_1", self.flow_a),
            Probe::of("return_flow_2", self.flow_b),
        ]
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![
            ("shifted_extend".into(), self.counts[0] as f64),
            ("shifted_retract".into(), self.counts[1] as f64),
            ("fully_shifted".into(), self.counts[2] as f64),
        ]
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.counts = [0; 3];
    }
}
