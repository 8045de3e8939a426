//! Leaney's generalised one-pressure actuator (eqs 2.16–2.26, 3.3).

use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, MechanicalNode, Netlist, PowerTerms, Probe,
    Wire, Wires,
};
use hydrocyl_actuator::generalised as gen;
use hydrocyl_actuator::Cylinder;
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Position, Pressure};
use hydrocyl_valves::servovalve::Metering;
use std::cell::Cell;

use super::cylinder::Cavitation;
use super::four_way::FourWayNodes;

pub use hydrocyl_actuator::generalised::XMethod;

/// Leaney's generalised one-pressure actuator (eqs 2.16–2.26, 3.3) with the
/// servovalve metering folded in: it owns the chamber nodes A and B but sets
/// their pressures *algebraically* from its one state `P_LE` and X (eqs 2.21,
/// 2.22). It replaces [`FourWayValve`](super::FourWayValve) +
/// [`TwoChamberCylinder`](super::TwoChamberCylinder) as one
/// subsystem (the form needs the port areas to find X), reading the same
/// spool signal, supply and tank nodes and rod.
///
/// Flows other components add into A or B (e.g. an extra leakage element)
/// enter `Q_LE` as `(Q_inA − Q_inB)/2`.
#[derive(Debug)]
pub struct GeneralisedCylinder {
    name: String,
    ports: [String; 4],
    spool_name: String,
    rod_name: String,
    /// The cylinder.
    pub cylinder: Cylinder,
    /// The valve metering (areas and orifice law).
    pub metering: Metering,
    /// Where X comes from.
    pub x_method: XMethod,
    /// Initial `P_LE` \[Pa\].
    pub initial_load_pressure: f64,
    /// Pressure below which a chamber is reported as cavitating \[Pa\].
    pub cavitation_pressure: f64,
    cav: [Cavitation; 2],
    spool: Wire<Position>,
    p: HydraulicNode,
    t: HydraulicNode,
    a: HydraulicNode,
    b: HydraulicNode,
    rod: MechanicalNode,
    /// `dP_LE/dt` without the extra flows \[Pa·s⁻¹\] (no quantity type).
    dp: Wire<f64>,
    /// The load pressure `P_LE`, the state, as a probe.
    p_le: Wire<Pressure>,
    vte: Wire<hydrocyl_ports::Volume>,
    x_calls: Cell<u64>,
}

impl GeneralisedCylinder {
    /// The generalised actuator reading the spool position on `nodes.spool`,
    /// joined to `nodes.p`, `nodes.t`, owning `nodes.a`, `nodes.b` (the
    /// valve's ports and the chambers are one here), pushing the body `rod`.
    pub fn new(
        name: &str,
        nodes: FourWayNodes<'_>,
        rod: &str,
        cylinder: Cylinder,
        metering: Metering,
        x_method: XMethod,
        initial_load_pressure: f64,
    ) -> Self {
        Self {
            name: name.into(),
            ports: nodes.hydraulic(),
            spool_name: nodes.spool.into(),
            rod_name: rod.into(),
            cylinder,
            metering,
            x_method,
            initial_load_pressure,
            cavitation_pressure: 0.0,
            cav: [Cavitation::default(); 2],
            spool: Wire::UNBOUND,
            p: HydraulicNode::UNBOUND,
            t: HydraulicNode::UNBOUND,
            a: HydraulicNode::UNBOUND,
            b: HydraulicNode::UNBOUND,
            rod: MechanicalNode::UNBOUND,
            dp: Wire::UNBOUND,
            p_le: Wire::UNBOUND,
            vte: Wire::UNBOUND,
            x_calls: Cell::new(0),
        }
    }

    /// X at spool position `xs` \[m\] (travel = (x_s + x_b)/u0, eq 3.2 homogeneity).
    pub fn x_factor(&self, xs: f64) -> f64 {
        let g = self.cylinder.gamma();
        let u0 = self.metering.underlap.si();
        let xb = xs + self.metering.null_bias.si();
        let travel = if u0 > 0.0 {
            xb / u0
        } else if xb >= 0.0 {
            1.0
        } else {
            -1.0
        };
        self.x_calls.set(self.x_calls.get() + 1);
        self.x_method.x_factor(g, travel)
    }

    fn state(&self, x: &[f64], w: &Wires) -> gen::GeneralisedState {
        let xs = w.get(self.spool);
        let areas = self.metering.areas(xs);
        let o = self.metering.orifice;
        gen::evaluate(
            &self.cylinder,
            |a, up, down| o.flow(a, up, down),
            areas.av1,
            areas.av2,
            w.get(self.p.pressure),
            w.get(self.t.pressure),
            self.x_factor(xs.si()),
            x[0],
            w.get(self.rod.position).si(),
            w.get(self.rod.velocity),
        )
    }
}

impl Component for GeneralisedCylinder {
    fn is_actuator(&self) -> bool {
        true
    }
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        let err = |m: String| BuildError::Component {
            component: self.name.clone(),
            message: m,
        };
        self.cylinder.validate().map_err(|e| err(e.to_string()))?;
        self.metering.validate().map_err(|e| err(e.to_string()))?;
        if let XMethod::Numerical { tol } = self.x_method {
            if !(tol > 0.0 && tol.is_finite()) {
                return Err(err(format!("X tolerance must be positive, got {tol}")));
            }
        }
        self.spool = net.signal(&self.spool_name);
        self.p = net.hydraulic(&self.ports[0]);
        self.t = net.hydraulic(&self.ports[1]);
        self.a = net.own_hydraulic(&self.ports[2], Causality::Algebraic)?;
        self.b = net.own_hydraulic(&self.ports[3], Causality::Algebraic)?;
        self.rod = net.mechanical(&self.rod_name);
        self.dp = net.private("dp_le");
        self.p_le = net.private("p_le");
        self.vte = net.private("v_te");
        Ok(())
    }
    fn n_states(&self) -> usize {
        1
    }
    fn state_names(&self) -> Vec<String> {
        vec![format!("{}.p_le", self.name)]
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = 1.0e6;
    }
    fn initial_state(&self, x: &mut [f64]) {
        x[0] = self.initial_load_pressure;
    }
    fn evaluate(&self, _t: f64, x: &[f64], w: &mut Wires) {
        let s = self.state(x, w);
        w.set(self.a.pressure, s.p1);
        w.set(self.b.pressure, s.p2);
        w.add(self.p.inflow, -s.q_supply);
        w.add(self.t.inflow, s.q_tank);
        w.add(
            self.rod.force,
            Pressure::new(x[0]) * self.cylinder.effective_area(),
        );
        w.set(self.dp, s.dp_le);
        w.set(self.p_le, Pressure::new(x[0]));
        w.set(
            self.vte,
            hydrocyl_ports::Volume::new(gen::effective_volume(
                &self.cylinder,
                w.get(self.rod.position).si(),
            )),
        );
    }
    fn derivatives(&self, _t: f64, _x: &[f64], w: &Wires, dx: &mut [f64]) {
        let extra = 0.5 * (w.get(self.a.inflow) - w.get(self.b.inflow)).si();
        dx[0] =
            w.get(self.dp) + 4.0 * self.cylinder.bulk_modulus.si() / w.get(self.vte).si() * extra;
    }
    /// The form takes `p1 + γ² p2 = X Ps` as instantaneous and conserves
    /// neither chamber's mass on its own (docs/models.md, section 3).
    fn energy_consistent(&self) -> bool {
        false
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        let s = self.state(x, w);
        p.dissipated = s.dissipated;
        // the form is not energy-consistent (see docs/models.md): storage is the
        // compression power of the two chambers along the eq 2.21/2.22 line
        let (v1, v2) = self.cylinder.volumes(w.get(self.rod.position));
        let g = self.cylinder.gamma();
        let (k, d) = (0.5 * (1.0 + g), 1.0 + g * g * g);
        let b = self.cylinder.bulk_modulus.si();
        let dple = w.get(self.dp);
        p.storage = (s.p1.si() * v1.si() * g * g * k / d - s.p2.si() * v2.si() * k / d) * dple / b;
    }
    fn probes(&self) -> Vec<Probe> {
        vec![
            Probe::of("p1", self.a.pressure),
            Probe::of("p2", self.b.pressure),
            Probe::of("p_le", self.p_le),
        ]
    }
    fn n_events(&self) -> usize {
        2
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        let floor = self.cavitation_pressure - super::CAVITATION_MARGIN_PA;
        g[0] = w.get(self.a.pressure).si() - floor;
        g[1] = w.get(self.b.pressure).si() - floor;
    }
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        which: usize,
        dir: Crossing,
    ) -> EventAction {
        Cavitation::count(&mut self.cav, which, dir)
    }
    /// Its events only count cavitation entries.
    fn events_change_evaluation(&self) -> bool {
        false
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![
            ("x_factor_evaluations".into(), self.x_calls.get() as f64),
            ("cavitation_entries_1".into(), self.cav[0].entries as f64),
            ("cavitation_entries_2".into(), self.cav[1].entries as f64),
        ]
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.x_calls.set(0);
        self.cav = [Cavitation::default(); 2];
    }
}
