//! The hybrid drive's components as assembler [`Component`]s: the pump (its
//! identified command → flow model), relief valves, check valves, and the
//! pilot four-way valve's return path with the needle valve. Each wraps a pure constitutive law of `hydrocyl-valves` or
//! `hydrocyl-pump-motor`, binds to named nodes, and forwards the law's
//! switching functions as events (counted per run in its diagnostics).

use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, Netlist, PowerTerms, Probe, Wire, Wires,
};
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Position, Pressure, Voltage, VolumeFlow};
use hydrocyl_pump_motor::IdentifiedPump;
use hydrocyl_valves::check::CheckValve;
use hydrocyl_valves::needle::NeedleValve;
use hydrocyl_valves::orifice::signed_sqrt_regularised;
use hydrocyl_valves::pilot_valve::{series_coefficient, PilotFourWay};
use hydrocyl_valves::relief::ReliefValve;

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

/// A relief valve (eq 6.10) from node `inlet` to node `outlet`. Events:
/// cracking and full opening (counted when rising).
#[derive(Clone, Debug)]
pub struct ReliefComponent {
    name: String,
    inlet: String,
    outlet: String,
    /// The law.
    pub valve: ReliefValve,
    i: HydraulicNode,
    o: HydraulicNode,
    flow: Wire<VolumeFlow>,
    cracks: usize,
    full_opens: usize,
}

impl ReliefComponent {
    /// A relief valve `name` from `inlet` to `outlet`.
    pub fn new(name: &str, valve: ReliefValve, inlet: &str, outlet: &str) -> Self {
        Self {
            name: name.into(),
            inlet: inlet.into(),
            outlet: outlet.into(),
            valve,
            i: UNBOUND_NODE,
            o: UNBOUND_NODE,
            flow: Wire::UNBOUND,
            cracks: 0,
            full_opens: 0,
        }
    }
}

impl Component for ReliefComponent {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        ReliefValve::new(self.valve.cracking, self.valve.kv, self.valve.full_open).map_err(
            |e| BuildError::Component {
                component: self.name.clone(),
                message: e.to_string(),
            },
        )?;
        self.i = net.hydraulic(&self.inlet);
        self.o = net.hydraulic(&self.outlet);
        self.flow = net.own_signal(&format!("{}.flow", self.name), Causality::Algebraic)?;
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        let q = self
            .valve
            .flow(w.get(self.i.pressure), w.get(self.o.pressure));
        w.add(self.i.inflow, -q);
        w.add(self.o.inflow, q);
        w.set(self.flow, q);
    }
    fn n_events(&self) -> usize {
        2
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        let (pi, po) = (w.get(self.i.pressure), w.get(self.o.pressure));
        g[0] = self.valve.crack_margin(pi, po);
        g[1] = self.valve.full_open_margin(pi, po);
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
            if which == 0 {
                self.cracks += 1;
            } else {
                self.full_opens += 1;
            }
        }
        EventAction::Continue
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        p.dissipated = self
            .valve
            .power_dissipated(w.get(self.i.pressure), w.get(self.o.pressure))
            .si();
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
        vec![
            ("cracked".into(), self.cracks as f64),
            ("fully_opened".into(), self.full_opens as f64),
        ]
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.cracks = 0;
        self.full_opens = 0;
    }
}

/// A check valve from node `inlet` to node `outlet`. Event: cracking
/// (openings counted).
#[derive(Clone, Debug)]
pub struct CheckComponent {
    name: String,
    inlet: String,
    outlet: String,
    /// The law.
    pub valve: CheckValve,
    i: HydraulicNode,
    o: HydraulicNode,
    flow: Wire<VolumeFlow>,
    openings: usize,
}

impl CheckComponent {
    /// A check valve `name` from `inlet` to `outlet`.
    pub fn new(name: &str, valve: CheckValve, inlet: &str, outlet: &str) -> Self {
        Self {
            name: name.into(),
            inlet: inlet.into(),
            outlet: outlet.into(),
            valve,
            i: UNBOUND_NODE,
            o: UNBOUND_NODE,
            flow: Wire::UNBOUND,
            openings: 0,
        }
    }
}

impl Component for CheckComponent {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        CheckValve::new(
            self.valve.cracking,
            self.valve.opening_range,
            self.valve.k_open,
        )
        .map_err(|e| BuildError::Component {
            component: self.name.clone(),
            message: e.to_string(),
        })?;
        self.i = net.hydraulic(&self.inlet);
        self.o = net.hydraulic(&self.outlet);
        self.flow = net.own_signal(&format!("{}.flow", self.name), Causality::Algebraic)?;
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        let q = self
            .valve
            .flow(w.get(self.i.pressure), w.get(self.o.pressure));
        w.add(self.i.inflow, -q);
        w.add(self.o.inflow, q);
        w.set(self.flow, q);
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        g[0] = self
            .valve
            .crack_margin(w.get(self.i.pressure), w.get(self.o.pressure));
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
            .valve
            .power_dissipated(w.get(self.i.pressure), w.get(self.o.pressure))
            .si();
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
        vec![("opened".into(), self.openings as f64)]
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.openings = 0;
    }
}

/// The nodes a [`ReturnPath`] joins.
#[derive(Clone, Copy, Debug)]
pub struct ReturnNodes<'a> {
    /// Pump line 1: pilot port 1 of the four-way valve.
    pub pilot_1: &'a str,
    /// Pump line 2: pilot port 6.
    pub pilot_2: &'a str,
    /// Work port A: cylinder chamber 1.
    pub a: &'a str,
    /// Work port B: cylinder chamber 2.
    pub b: &'a str,
    /// The tank, behind the needle valve.
    pub tank: &'a str,
}

/// The return path: the DDDC four-way valve, piloted by the pump lines,
/// opens the chamber that is not fed (B when `Pp1 > Pp2`, A otherwise) to its
/// T port, which a short pipe joins to the needle valve and on to the tank
/// (section 6.2.2.3, Fig 7-3). The four-way's T port and the needle are two
/// orifices in series (exact series coefficient while the needle's reverse
/// check is shut; the T-port pressure is solved by bisection when it opens).
/// The four-way's P port is not connected: the fed chamber is supplied
/// through its relief valve directly, as in `pcyl4_1.m`.
///
/// Events: the pilot valve shifting into either state and reaching full
/// shift, and the needle's reverse check cracking.
#[derive(Clone, Debug)]
pub struct ReturnPath {
    name: String,
    nodes: [String; 5],
    /// The pilot four-way valve.
    pub four_way: PilotFourWay,
    /// The needle valve with its reverse-flow check.
    pub needle: NeedleValve,
    pp1: HydraulicNode,
    pp2: HydraulicNode,
    a: HydraulicNode,
    b: HydraulicNode,
    t: HydraulicNode,
    spool: Wire<Position>,
    flow_a: Wire<VolumeFlow>,
    flow_b: Wire<VolumeFlow>,
    counts: [usize; 4],
}

impl ReturnPath {
    /// The return path `name`, piloted by `pilot_1`, `pilot_2`, opening
    /// chambers `a`, `b` to `tank` (the same as [`ReturnPath::with_nodes`]).
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: &str,
        four_way: PilotFourWay,
        needle: NeedleValve,
        pilot_1: &str,
        pilot_2: &str,
        a: &str,
        b: &str,
        tank: &str,
    ) -> Self {
        Self::with_nodes(
            name,
            four_way,
            needle,
            ReturnNodes {
                pilot_1,
                pilot_2,
                a,
                b,
                tank,
            },
        )
    }

    /// The return path `name` joined to `nodes`.
    pub fn with_nodes(
        name: &str,
        four_way: PilotFourWay,
        needle: NeedleValve,
        nodes: ReturnNodes<'_>,
    ) -> Self {
        Self {
            name: name.into(),
            nodes: [
                nodes.pilot_1.into(),
                nodes.pilot_2.into(),
                nodes.a.into(),
                nodes.b.into(),
                nodes.tank.into(),
            ],
            four_way,
            needle,
            pp1: UNBOUND_NODE,
            pp2: UNBOUND_NODE,
            a: UNBOUND_NODE,
            b: UNBOUND_NODE,
            t: UNBOUND_NODE,
            spool: Wire::UNBOUND,
            flow_a: Wire::UNBOUND,
            flow_b: Wire::UNBOUND,
            counts: [0; 4],
        }
    }

    /// Flow from a chamber at `p_x` to the tank at `p_t` through the four-way
    /// return port of coefficient `k_fw` and the needle valve, and the
    /// pressure between them.
    pub fn series_flow(&self, k_fw: f64, p_x: f64, p_t: f64) -> (f64, f64) {
        if k_fw <= 0.0 {
            return (0.0, p_t);
        }
        let xt = self.four_way.dp_transition.si();
        let crack = self.needle.reverse_check.cracking.si();
        if p_t - p_x <= crack {
            // the reverse check stays shut for any T pressure between p_x and p_t:
            // two square-root orifices in series
            let k = series_coefficient(k_fw, self.needle.coefficient());
            let q = k * signed_sqrt_regularised(p_x - p_t, xt);
            let k_n = self.needle.coefficient();
            let p_mid = if k_n > 0.0 {
                p_t + (p_x - p_t) * (k * k) / (k_n * k_n)
            } else {
                p_x
            };
            return (q, p_mid);
        }
        // reverse flow with the check open: solve Q_fw(p_x − p_T) = Q_needle(p_T → p_t)
        // for p_T in [p_x, p_t]; the residual falls monotonically in p_T.
        let resid = |pm: f64| {
            k_fw * signed_sqrt_regularised(p_x - pm, xt)
                - self.needle.flow(Pressure::new(pm), Pressure::new(p_t)).si()
        };
        let (mut lo, mut hi) = (p_x, p_t);
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if resid(mid) > 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let pm = 0.5 * (lo + hi);
        (k_fw * signed_sqrt_regularised(p_x - pm, xt), pm)
    }

    fn state(&self, w: &Wires) -> (f64, f64, f64, f64) {
        let y = self
            .four_way
            .opening(w.get(self.pp1.pressure), w.get(self.pp2.pressure));
        let (px, pt) = (
            if y > 0.0 {
                w.get(self.b.pressure).si()
            } else {
                w.get(self.a.pressure).si()
            },
            w.get(self.t.pressure).si(),
        );
        let (q, pm) = self.series_flow(self.four_way.return_coefficient(y), px, pt);
        (y, q, pm, pt)
    }
}

impl Component for ReturnPath {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        let err = |e: hydrocyl_valves::check::ParameterError| BuildError::Component {
            component: self.name.clone(),
            message: e.to_string(),
        };
        self.four_way.validate().map_err(err)?;
        NeedleValve::new(
            self.needle.area,
            self.needle.effective_factor,
            self.needle.orifice,
            self.needle.reverse_check,
        )
        .map_err(err)?;
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
        let (y, q, _, _) = self.state(w);
        let from = if y > 0.0 {
            self.b.inflow
        } else {
            self.a.inflow
        };
        let q = VolumeFlow::new(q);
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
    fn n_events(&self) -> usize {
        4
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        let (pp1, pp2) = (w.get(self.pp1.pressure), w.get(self.pp2.pressure));
        g[0] = self.four_way.extend_shift_margin(pp1, pp2);
        g[1] = self.four_way.retract_shift_margin(pp1, pp2);
        g[2] = self.four_way.full_shift_margin(pp1, pp2);
        let (_, _, pm, pt) = self.state(w);
        g[3] = pt - pm - self.needle.reverse_check.cracking.si();
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
        let (y, q, _, pt) = self.state(w);
        let px = if y > 0.0 {
            w.get(self.b.pressure).si()
        } else {
            w.get(self.a.pressure).si()
        };
        p.dissipated = q * (px - pt);
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
            ("pilot_shifted_extend".into(), self.counts[0] as f64),
            ("pilot_shifted_retract".into(), self.counts[1] as f64),
            ("pilot_fully_shifted".into(), self.counts[2] as f64),
            ("needle_check_opened".into(), self.counts[3] as f64),
        ]
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.counts = [0; 4];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn path() -> ReturnPath {
        ReturnPath::with_nodes(
            "return",
            PilotFourWay::dddc(),
            NeedleValve::nccc(),
            ReturnNodes {
                pilot_1: "l1",
                pilot_2: "l2",
                a: "a",
                b: "b",
                tank: "t",
            },
        )
    }

    #[test]
    fn forward_series_flow_splits_the_drop() {
        let r = path();
        let k_fw = r.four_way.k_t * 0.3;
        let (q, pm) = r.series_flow(k_fw, 5.0e5, 0.0);
        // the same flow through both orifices
        assert!((k_fw * (5.0e5 - pm).sqrt() - q).abs() < 1e-12 * q);
        assert!((r.needle.flow(Pressure::new(pm), Pressure::ZERO).si() - q).abs() < 1e-12 * q);
        assert_eq!(r.series_flow(0.0, 5.0e5, 0.0), (0.0, 0.0));
    }

    #[test]
    fn reverse_flow_through_the_open_check_is_continuous_in_the_node_pressure() {
        let r = path();
        let k_fw = r.four_way.k_t;
        let (q, pm) = r.series_flow(k_fw, -0.9e5, 0.0);
        assert!(q < 0.0 && pm > -0.9e5 && pm < 0.0);
        let q_needle = r.needle.flow(Pressure::new(pm), Pressure::ZERO).si();
        assert!((q - q_needle).abs() < 1e-9 * q.abs(), "{q} {q_needle}");
        // the reverse check opened: more backflow than the needle alone would pass
        let metered = r
            .needle
            .metered_flow(Pressure::new(pm), Pressure::ZERO)
            .si();
        assert!(q < metered);
    }
}
