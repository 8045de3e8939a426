//! The component library: the building blocks of the `leaney-moog` rig and
//! generic pieces (fixed-pressure sources, volumes, orifices) other rigs reuse.
//!
//! | component | owns (effort) | states | reads | adds |
//! |---|---|---|---|---|
//! | [`PressureSource`] | node pressure | – | – | – |
//! | [`Volume`] | node pressure | p | node inflow | – |
//! | [`FixedOrifice`] | – | – | 2 node pressures | flow a→b |
//! | [`CommandInput`] | signal | – | – | – |
//! | [`ServoSpool`] | spool signal | x_s (, ẋ_s) | command | – |
//! | [`FourWayValve`] | – | – | spool, P, T, A, B | flows at P, T, A, B |
//! | [`TwoChamberCylinder`] | A, B pressures | p1, p2 | rod x, v; inflows | force on rod |
//! | [`GeneralisedCylinder`] | A, B pressures (algebraic) | P_LE | spool, P, T, rod | flows at P, T; force |
//! | [`Mass`] | rod x, v | x, v | forces on rod | – |
//! | [`Friction`] | – | model's (z) | rod v; A, B pressures | −F, added mass |

use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, MechanicalNode, Netlist, PowerTerms, Probe,
    Wire, Wires,
};
use crate::signal::Signal;
use hydrocyl_actuator::generalised as gen;
use hydrocyl_actuator::{Cylinder, StrokeEnds};
use hydrocyl_friction::{FrictionInput, FrictionMode, FrictionModel};
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::{Force, Position, Pressure, Velocity, VolumeFlow};
use hydrocyl_valves::orifice::Orifice;
use hydrocyl_valves::servovalve::{Metering, Spool};
use std::cell::Cell;

const UNBOUND: Wire = Wire::UNBOUND;

fn unbound_h() -> HydraulicNode {
    HydraulicNode {
        pressure: UNBOUND,
        inflow: UNBOUND,
    }
}

fn unbound_m() -> MechanicalNode {
    MechanicalNode {
        position: UNBOUND,
        velocity: UNBOUND,
        force: UNBOUND,
        added_mass: UNBOUND,
        hold: UNBOUND,
    }
}

/// A node held at a fixed pressure: a supply (pressure-compensated pump with
/// accumulator) or the tank. It delivers whatever flow the circuit draws.
#[derive(Debug)]
pub struct PressureSource {
    name: String,
    node_name: String,
    /// The fixed pressure \[Pa\].
    pub pressure: Pressure,
    probe: Option<String>,
    node: HydraulicNode,
}

impl PressureSource {
    /// A source named `name` holding node `node` at `pressure`; `probe`
    /// names its pressure as an output column (e.g. `ps`).
    pub fn new(name: &str, node: &str, pressure: Pressure, probe: Option<&str>) -> Self {
        Self {
            name: name.into(),
            node_name: node.into(),
            pressure,
            probe: probe.map(str::to_string),
            node: unbound_h(),
        }
    }
}

impl Component for PressureSource {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.node = net.own_hydraulic(&self.node_name, Causality::Stored)?;
        Ok(())
    }
    fn publish(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        w.set(self.node.pressure, self.pressure.si());
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        // flow drawn from the node, delivered at its pressure
        p.source = -self.pressure.si() * w.get(self.node.inflow);
    }
    fn probes(&self) -> Vec<Probe> {
        self.probe
            .iter()
            .map(|n| Probe {
                name: n.clone(),
                unit: "Pa",
                wire: self.node.pressure,
            })
            .collect()
    }
}

/// A constant hydraulic volume (a pipeline, a hose, a pump line):
/// `dp/dt = B/V ΣQ_in`.
#[derive(Debug)]
pub struct Volume {
    name: String,
    node_name: String,
    /// Volume V \[m³\].
    pub volume: f64,
    /// Effective bulk modulus B \[Pa\].
    pub bulk_modulus: f64,
    /// Initial pressure \[Pa\].
    pub initial_pressure: f64,
    probe: Option<String>,
    node: HydraulicNode,
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
            initial_pressure,
            probe: probe.map(str::to_string),
            node: unbound_h(),
        }
    }
}

impl Component for Volume {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        if !(self.volume > 0.0
            && self.volume.is_finite()
            && self.bulk_modulus > 0.0
            && self.bulk_modulus.is_finite())
        {
            return Err(BuildError::Component {
                component: self.name.clone(),
                message: format!(
                    "volume {} m^3 and bulk modulus {} Pa must be positive",
                    self.volume, self.bulk_modulus
                ),
            });
        }
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
        w.set(self.node.pressure, x[0]);
    }
    fn derivatives(&self, _t: f64, _x: &[f64], w: &Wires, dx: &mut [f64]) {
        dx[0] = self.bulk_modulus / self.volume * w.get(self.node.inflow);
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        p.storage = x[0] * w.get(self.node.inflow);
        p.stored = 0.5 * self.volume * x[0] * x[0] / self.bulk_modulus;
    }
    fn probes(&self) -> Vec<Probe> {
        self.probe
            .iter()
            .map(|n| Probe {
                name: n.clone(),
                unit: "Pa",
                wire: self.node.pressure,
            })
            .collect()
    }
}

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
            a: unbound_h(),
            b: unbound_h(),
        }
    }
    fn flow(&self, w: &Wires) -> f64 {
        self.orifice
            .flow(
                self.area,
                Pressure::new(w.get(self.a.pressure)),
                Pressure::new(w.get(self.b.pressure)),
            )
            .si()
    }
}

impl Component for FixedOrifice {
    fn name(&self) -> &str {
        &self.name
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
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        p.dissipated = (w.get(self.a.pressure) - w.get(self.b.pressure)) * self.flow(w);
    }
}

/// A command signal source (writes signal `output` from a [`Signal`] of time).
#[derive(Debug)]
pub struct CommandInput {
    name: String,
    output_name: String,
    /// The signal.
    pub signal: Signal,
    hint: Cell<usize>,
    out: Wire,
}

impl CommandInput {
    /// A source named `name` writing signal `output`.
    pub fn new(name: &str, output: &str, signal: Signal) -> Self {
        Self {
            name: name.into(),
            output_name: output.into(),
            signal,
            hint: Cell::new(0),
            out: UNBOUND,
        }
    }
}

impl Component for CommandInput {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.out = net.own_signal(&self.output_name, Causality::Stored)?;
        Ok(())
    }
    fn publish(&self, t: f64, _x: &[f64], w: &mut Wires) {
        w.set(self.out, self.signal.value_hinted(t, &self.hint));
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe {
            name: "command".into(),
            unit: "-",
            wire: self.out,
        }]
    }
}

/// The servovalve spool: normalised command in, spool position out
/// (first- or second-order dynamics with saturation, eqs 2.2, 2.3/3.1).
#[derive(Debug)]
pub struct ServoSpool {
    name: String,
    input_name: String,
    output_name: String,
    /// Stroke and dynamics.
    pub spool: Spool,
    /// Initial spool position \[m\].
    pub initial_position: f64,
    input: Wire,
    out: Wire,
}

impl ServoSpool {
    /// A spool reading signal `input` (normalised command) and writing signal `output` \[m\].
    pub fn new(name: &str, input: &str, output: &str, spool: Spool, initial_position: f64) -> Self {
        Self {
            name: name.into(),
            input_name: input.into(),
            output_name: output.into(),
            spool,
            initial_position,
            input: UNBOUND,
            out: UNBOUND,
        }
    }
}

impl Component for ServoSpool {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.spool.validate().map_err(|e| BuildError::Component {
            component: self.name.clone(),
            message: e.to_string(),
        })?;
        self.input = net.signal(&self.input_name);
        self.out = net.own_signal(&self.output_name, Causality::Stored)?;
        Ok(())
    }
    fn n_states(&self) -> usize {
        self.spool.dynamics.n_states()
    }
    fn state_names(&self) -> Vec<String> {
        let mut v = vec![format!("{}.x", self.name)];
        if self.n_states() > 1 {
            v.push(format!("{}.v", self.name));
        }
        v
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = self.spool.stroke.si();
        if s.len() > 1 {
            s[1] = self.spool.stroke.si() * 100.0;
        }
    }
    fn initial_state(&self, x: &mut [f64]) {
        self.spool.dynamics.rest_state(self.initial_position, x);
    }
    fn publish(&self, _t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.out, self.spool.position(x));
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        let d = self.spool.demand(w.get(self.input));
        self.spool.dynamics.derivatives(d, x, dx);
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe {
            name: "spool".into(),
            unit: "m",
            wire: self.out,
        }]
    }
}

/// The four-way metering of the servovalve between supply P, tank T and the
/// service ports A, B (eqs 2.8, 2.9, 3.2).
#[derive(Debug)]
pub struct FourWayValve {
    name: String,
    ports: [String; 4],
    spool_name: String,
    /// Metering geometry and orifice law.
    pub metering: Metering,
    /// Supply droop resistance Rs \[Pa·s·m⁻³\]: the valve sees
    /// `Ps = P − Rs Q_P` ([`Metering::drooped_supply`]); 0 = off.
    pub supply_resistance: f64,
    /// Output name of the supply pressure the valve sees (with droop on).
    pub supply_probe: Option<String>,
    spool: Wire,
    p: HydraulicNode,
    t: HydraulicNode,
    a: HydraulicNode,
    b: HydraulicNode,
    ps: Wire,
}

impl FourWayValve {
    /// A valve reading signal `spool` \[m\], joining nodes `p`, `t`, `a`, `b`.
    pub fn new(
        name: &str,
        spool: &str,
        p: &str,
        t: &str,
        a: &str,
        b: &str,
        metering: Metering,
    ) -> Self {
        Self {
            name: name.into(),
            ports: [p.into(), t.into(), a.into(), b.into()],
            spool_name: spool.into(),
            metering,
            supply_resistance: 0.0,
            supply_probe: None,
            spool: UNBOUND,
            p: unbound_h(),
            t: unbound_h(),
            a: unbound_h(),
            b: unbound_h(),
            ps: UNBOUND,
        }
    }

    /// The flows and the supply pressure the valve sees (drooped when
    /// `supply_resistance > 0`).
    fn flows(&self, w: &Wires) -> (hydrocyl_valves::servovalve::MeteringFlows, f64) {
        let g = |n: &HydraulicNode| Pressure::new(w.get(n.pressure));
        let (f, ps) = self.metering.flows_drooped(
            Position::new(w.get(self.spool)),
            g(&self.p),
            self.supply_resistance,
            g(&self.t),
            g(&self.a),
            g(&self.b),
        );
        (f, ps.si())
    }
}

impl Component for FourWayValve {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.metering
            .validate()
            .map_err(|e| BuildError::Component {
                component: self.name.clone(),
                message: e.to_string(),
            })?;
        self.spool = net.signal(&self.spool_name);
        self.p = net.hydraulic(&self.ports[0]);
        self.t = net.hydraulic(&self.ports[1]);
        self.a = net.hydraulic(&self.ports[2]);
        self.b = net.hydraulic(&self.ports[3]);
        if !(self.supply_resistance.is_finite() && self.supply_resistance >= 0.0) {
            return Err(BuildError::Component {
                component: self.name.clone(),
                message: format!(
                    "supply_resistance must be finite and non-negative, got {}",
                    self.supply_resistance
                ),
            });
        }
        self.ps = net.private("ps");
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        let (f, ps) = self.flows(w);
        w.add(self.p.inflow, -f.qp.si());
        w.add(self.t.inflow, f.qt.si());
        w.add(self.a.inflow, f.qa.si());
        w.add(self.b.inflow, -f.qb.si());
        w.set(self.ps, ps);
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        p.dissipated = self.flows(w).0.dissipated;
    }
    fn probes(&self) -> Vec<Probe> {
        self.supply_probe
            .iter()
            .map(|n| Probe {
                name: n.clone(),
                unit: "Pa",
                wire: self.ps,
            })
            .collect()
    }
}

/// Cavitation bookkeeping of a chamber.
#[derive(Clone, Copy, Debug, Default)]
struct Cavitation {
    entries: usize,
}

/// The fundamental two-chamber cylinder (eqs 2.10–2.15, 2.27): owns the
/// chamber nodes A (cap side, p1) and B (rod side, p2), pushes the rod.
///
/// Cavitation is **reported**, not hidden: a switching function per chamber
/// crosses zero when its pressure falls below `cavitation_pressure`, and the
/// entries are counted ([`Component::diagnostics`] `cavitation_entries_1/2`).
/// The fluid model is not changed below it (constant B), so a run with
/// entries has left the model's range there.
#[derive(Debug)]
pub struct TwoChamberCylinder {
    name: String,
    a_name: String,
    b_name: String,
    rod_name: String,
    /// The cylinder.
    pub cylinder: Cylinder,
    /// Pressure below which a chamber is reported as cavitating \[Pa\].
    pub cavitation_pressure: f64,
    /// Initial (p1, p2) \[Pa\].
    pub initial_pressures: (f64, f64),
    cav: [Cavitation; 2],
    a: HydraulicNode,
    b: HydraulicNode,
    rod: MechanicalNode,
    p_le: Wire,
}

impl TwoChamberCylinder {
    /// A cylinder owning nodes `a` (chamber 1) and `b` (chamber 2), acting on body `rod`.
    pub fn new(
        name: &str,
        a: &str,
        b: &str,
        rod: &str,
        cylinder: Cylinder,
        initial_pressures: (f64, f64),
    ) -> Self {
        Self {
            name: name.into(),
            a_name: a.into(),
            b_name: b.into(),
            rod_name: rod.into(),
            cylinder,
            cavitation_pressure: 0.0,
            initial_pressures,
            cav: [Cavitation::default(); 2],
            a: unbound_h(),
            b: unbound_h(),
            rod: unbound_m(),
            p_le: UNBOUND,
        }
    }

    /// `(dp1/dt, dp2/dt)` at this instant \[Pa·s⁻¹\].
    fn rates(&self, x: &[f64], w: &Wires) -> (f64, f64) {
        self.cylinder.pressure_rates(
            Position::new(w.get(self.rod.position)),
            Velocity::new(w.get(self.rod.velocity)),
            Pressure::new(x[0]),
            Pressure::new(x[1]),
            VolumeFlow::new(w.get(self.a.inflow)),
            VolumeFlow::new(-w.get(self.b.inflow)),
        )
    }
}

impl Component for TwoChamberCylinder {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.cylinder
            .validate()
            .map_err(|e| BuildError::Component {
                component: self.name.clone(),
                message: e.to_string(),
            })?;
        self.a = net.own_hydraulic(&self.a_name, Causality::Stored)?;
        self.b = net.own_hydraulic(&self.b_name, Causality::Stored)?;
        self.rod = net.mechanical(&self.rod_name);
        self.p_le = net.private("p_le");
        Ok(())
    }
    fn n_states(&self) -> usize {
        2
    }
    fn state_names(&self) -> Vec<String> {
        vec![format!("{}.p1", self.name), format!("{}.p2", self.name)]
    }
    fn state_scales(&self, s: &mut [f64]) {
        s.fill(1.0e6);
    }
    fn initial_state(&self, x: &mut [f64]) {
        x[0] = self.initial_pressures.0;
        x[1] = self.initial_pressures.1;
    }
    fn publish(&self, _t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.a.pressure, x[0]);
        w.set(self.b.pressure, x[1]);
    }
    fn evaluate(&self, _t: f64, x: &[f64], w: &mut Wires) {
        let f = self
            .cylinder
            .force(Pressure::new(x[0]), Pressure::new(x[1]))
            .si();
        w.add(self.rod.force, f);
        w.set(self.p_le, f / self.cylinder.effective_area().si());
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        let (d1, d2) = self.rates(x, w);
        dx[0] = d1;
        dx[1] = d2;
    }
    fn n_events(&self) -> usize {
        2
    }
    fn events(&self, _t: f64, x: &[f64], _w: &Wires, g: &mut [f64]) {
        g[0] = x[0] - self.cavitation_pressure;
        g[1] = x[1] - self.cavitation_pressure;
    }
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        which: usize,
        dir: Crossing,
    ) -> EventAction {
        if dir == Crossing::Falling {
            self.cav[which].entries += 1;
        }
        EventAction::Continue
    }
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.cav = [Cavitation::default(); 2];
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, dx: &[f64], p: &mut PowerTerms) {
        let xp = Position::new(w.get(self.rod.position));
        let (v1, v2) = self.cylinder.volumes(xp);
        let b = self.cylinder.bulk_modulus.si();
        let (p1, p2) = (Pressure::new(x[0]), Pressure::new(x[1]));
        let (ql, qe1, qe2) = self.cylinder.leakage(p1, p2);
        p.storage = x[0] * v1.si() / b * dx[0] + x[1] * v2.si() / b * dx[1];
        p.dissipated = ql.si() * (x[0] - x[1]) + qe1.si() * x[0] + qe2.si() * x[1];
        p.stored = 0.5 * (v1.si() * x[0] * x[0] + v2.si() * x[1] * x[1]) / b;
    }
    fn n_quadratures(&self) -> usize {
        4
    }
    fn quadrature_names(&self) -> Vec<String> {
        ["q1_in", "q2_in", "p1_a1_v_over_b", "p2_a2_v_over_b"]
            .iter()
            .map(|s| format!("{}.{s}", self.name))
            .collect()
    }
    fn quadratures(&self, _t: f64, x: &[f64], w: &Wires, _dx: &[f64], q: &mut [f64]) {
        // ∫Q1 dt, ∫Q2_in dt (the valve's flows), ∫p1 A1 v/B dt, ∫p2 A2 v/B dt:
        // with these, ∫(Q1 − A1 v − V1/B dp1/dt) dt is computable exactly
        // (∫V1/B dp1 = [V1 p1/B] − ∫p1 A1 v/B dt).
        let v = w.get(self.rod.velocity);
        let b = self.cylinder.bulk_modulus.si();
        q[0] = w.get(self.a.inflow);
        q[1] = w.get(self.b.inflow);
        q[2] = x[0] * self.cylinder.area_1.si() * v / b;
        q[3] = x[1] * self.cylinder.area_2.si() * v / b;
    }
    fn probes(&self) -> Vec<Probe> {
        vec![
            Probe {
                name: "p1".into(),
                unit: "Pa",
                wire: self.a.pressure,
            },
            Probe {
                name: "p2".into(),
                unit: "Pa",
                wire: self.b.pressure,
            },
            Probe {
                name: "p_le".into(),
                unit: "Pa",
                wire: self.p_le,
            },
        ]
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![
            ("cavitation_entries_1".into(), self.cav[0].entries as f64),
            ("cavitation_entries_2".into(), self.cav[1].entries as f64),
        ]
    }
}

pub use hydrocyl_actuator::generalised::XMethod;

/// Leaney's generalised one-pressure actuator (eqs 2.16–2.26, 3.3) with the
/// servovalve metering folded in: it owns the chamber nodes A and B but sets
/// their pressures *algebraically* from its one state `P_LE` and X (eqs 2.21,
/// 2.22). It replaces [`FourWayValve`] + [`TwoChamberCylinder`] as one
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
    spool: Wire,
    p: HydraulicNode,
    t: HydraulicNode,
    a: HydraulicNode,
    b: HydraulicNode,
    rod: MechanicalNode,
    dp: Wire,
    vte: Wire,
    xf: Wire,
    x_calls: Cell<u64>,
}

impl GeneralisedCylinder {
    /// The generalised actuator reading `spool`, joined to `p`, `t`, owning `a`, `b`, pushing `rod`.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        name: &str,
        spool: &str,
        p: &str,
        t: &str,
        a: &str,
        b: &str,
        rod: &str,
        cylinder: Cylinder,
        metering: Metering,
        x_method: XMethod,
        initial_load_pressure: f64,
    ) -> Self {
        Self {
            name: name.into(),
            ports: [p.into(), t.into(), a.into(), b.into()],
            spool_name: spool.into(),
            rod_name: rod.into(),
            cylinder,
            metering,
            x_method,
            initial_load_pressure,
            cavitation_pressure: 0.0,
            cav: [Cavitation::default(); 2],
            spool: UNBOUND,
            p: unbound_h(),
            t: unbound_h(),
            a: unbound_h(),
            b: unbound_h(),
            rod: unbound_m(),
            dp: UNBOUND,
            vte: UNBOUND,
            xf: UNBOUND,
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
        let areas = self.metering.areas(Position::new(xs));
        let o = self.metering.orifice;
        gen::evaluate(
            &self.cylinder,
            |a, up, down| o.flow(a, up, down),
            areas.av1,
            areas.av2,
            Pressure::new(w.get(self.p.pressure)),
            Pressure::new(w.get(self.t.pressure)),
            self.x_factor(xs),
            x[0],
            w.get(self.rod.position),
            Velocity::new(w.get(self.rod.velocity)),
        )
    }
}

impl Component for GeneralisedCylinder {
    fn name(&self) -> &str {
        &self.name
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
        self.vte = net.private("v_te");
        self.xf = net.private("x");
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
        w.set(self.a.pressure, s.p1.si());
        w.set(self.b.pressure, s.p2.si());
        w.add(self.p.inflow, -s.q_supply.si());
        w.add(self.t.inflow, s.q_tank.si());
        w.add(self.rod.force, x[0] * self.cylinder.effective_area().si());
        w.set(self.dp, s.dp_le);
        w.set(
            self.vte,
            gen::effective_volume(&self.cylinder, w.get(self.rod.position)),
        );
    }
    fn derivatives(&self, _t: f64, _x: &[f64], w: &Wires, dx: &mut [f64]) {
        let extra = 0.5 * (w.get(self.a.inflow) - w.get(self.b.inflow));
        dx[0] = w.get(self.dp) + 4.0 * self.cylinder.bulk_modulus.si() / w.get(self.vte) * extra;
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        let s = self.state(x, w);
        p.dissipated = s.dissipated;
        // the form is not energy-consistent (see docs/models.md): storage is the
        // compression power of the two chambers along the eq 2.21/2.22 line
        let (v1, v2) = self
            .cylinder
            .volumes(Position::new(w.get(self.rod.position)));
        let g = self.cylinder.gamma();
        let (k, d) = (0.5 * (1.0 + g), 1.0 + g * g * g);
        let b = self.cylinder.bulk_modulus.si();
        let dple = w.get(self.dp);
        p.storage = (s.p1.si() * v1.si() * g * g * k / d - s.p2.si() * v2.si() * k / d) * dple / b;
    }
    fn probes(&self) -> Vec<Probe> {
        vec![
            Probe {
                name: "p1".into(),
                unit: "Pa",
                wire: self.a.pressure,
            },
            Probe {
                name: "p2".into(),
                unit: "Pa",
                wire: self.b.pressure,
            },
        ]
    }
    fn n_events(&self) -> usize {
        2
    }
    fn events(&self, _t: f64, _x: &[f64], w: &Wires, g: &mut [f64]) {
        g[0] = w.get(self.a.pressure) - self.cavitation_pressure;
        g[1] = w.get(self.b.pressure) - self.cavitation_pressure;
    }
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        which: usize,
        dir: Crossing,
    ) -> EventAction {
        if dir == Crossing::Falling {
            self.cav[which].entries += 1;
        }
        EventAction::Continue
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

/// Mode of the stroke-end stop.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum StopMode {
    Free,
    AtMin,
    AtMax,
}

/// The moving mass (piston, rod and load, eq 2.27): owns the rod's position
/// and velocity, `(m + Σc) dv/dt = ΣF − F_ext`, with the hard stroke-end stops
/// of [`StrokeEnds`] as events (see there).
#[derive(Debug)]
pub struct Mass {
    name: String,
    rod_name: String,
    /// Moving mass m \[kg\].
    pub mass: f64,
    /// External force F_ext opposing extension (eq 2.27) \[N\].
    pub external_force: f64,
    /// The stroke ends (`None`: unlimited travel).
    pub stops: Option<StrokeEnds>,
    /// Initial (x, v) \[m, m·s⁻¹\].
    pub initial: (f64, f64),
    mode: StopMode,
    impacts: usize,
    impact_energy: f64,
    rod: MechanicalNode,
}

impl Mass {
    /// A mass owning body `rod`.
    pub fn new(
        name: &str,
        rod: &str,
        mass: f64,
        external_force: f64,
        stops: Option<StrokeEnds>,
        initial: (f64, f64),
    ) -> Self {
        Self {
            name: name.into(),
            rod_name: rod.into(),
            mass,
            external_force,
            stops,
            initial,
            mode: StopMode::Free,
            impacts: 0,
            impact_energy: 0.0,
            rod: unbound_m(),
        }
    }

    fn net_force(&self, w: &Wires) -> f64 {
        w.get(self.rod.force)
    }
}

impl Component for Mass {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        if !(self.mass > 0.0 && self.mass.is_finite()) {
            return Err(BuildError::Component {
                component: self.name.clone(),
                message: format!("mass must be positive, got {} kg", self.mass),
            });
        }
        if !self.external_force.is_finite() {
            return Err(BuildError::Component {
                component: self.name.clone(),
                message: format!(
                    "external force must be finite, got {} N",
                    self.external_force
                ),
            });
        }
        if let Some(s) = self.stops {
            if !s.contains(Position::new(self.initial.0)) {
                return Err(BuildError::Component {
                    component: self.name.clone(),
                    message: format!(
                        "initial position {} m is outside the stroke [{}, {}] m",
                        self.initial.0,
                        s.min.si(),
                        s.max.si()
                    ),
                });
            }
        }
        self.rod = net.own_mechanical(&self.rod_name)?;
        Ok(())
    }
    fn n_states(&self) -> usize {
        2
    }
    fn state_names(&self) -> Vec<String> {
        vec![format!("{}.x", self.name), format!("{}.v", self.name)]
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = 0.1;
        s[1] = 0.1;
    }
    fn initial_state(&self, x: &mut [f64]) {
        x[0] = self.initial.0;
        x[1] = self.initial.1;
    }
    fn publish(&self, _t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.rod.position, x[0]);
        w.set(self.rod.velocity, x[1]);
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        w.add(self.rod.force, -self.external_force);
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        if w.get(self.rod.hold) > 0.0 {
            dx[0] = x[1];
            dx[1] = 0.0;
        } else if self.mode == StopMode::Free {
            dx[0] = x[1];
            dx[1] = self.net_force(w) / (self.mass + w.get(self.rod.added_mass));
        } else {
            dx[0] = 0.0;
            dx[1] = 0.0;
        }
    }
    fn n_events(&self) -> usize {
        if self.stops.is_some() {
            2
        } else {
            0
        }
    }
    fn events(&self, _t: f64, x: &[f64], w: &Wires, g: &mut [f64]) {
        let Some(s) = self.stops else { return };
        match self.mode {
            StopMode::Free => {
                g[0] = x[0] - s.min.si();
                g[1] = s.max.si() - x[0];
            }
            StopMode::AtMin => {
                g[0] = -self.net_force(w);
                g[1] = 1.0;
            }
            StopMode::AtMax => {
                g[0] = 1.0;
                g[1] = self.net_force(w);
            }
        }
    }
    fn on_event(
        &mut self,
        _t: f64,
        x: &mut [f64],
        _w: &Wires,
        which: usize,
        dir: Crossing,
    ) -> EventAction {
        let Some(s) = self.stops else {
            return EventAction::Continue;
        };
        if dir != Crossing::Falling {
            return EventAction::Continue;
        }
        match self.mode {
            StopMode::Free => {
                // plastic impact: clamp to the end and stop; `after_event`
                // decides, with the forces at rest, whether it is held there
                self.impacts += 1;
                self.impact_energy += 0.5 * self.mass * x[1] * x[1];
                x[1] = 0.0;
                if which == 0 {
                    x[0] = s.min.si();
                    self.mode = StopMode::AtMin;
                } else {
                    x[0] = s.max.si();
                    self.mode = StopMode::AtMax;
                }
            }
            StopMode::AtMin | StopMode::AtMax => self.mode = StopMode::Free,
        }
        EventAction::Continue
    }
    fn after_event(&mut self, _t: f64, x: &mut [f64], w: &Wires) {
        if w.get(self.rod.hold) > 0.0 {
            x[1] = 0.0;
        }
        // held at a stop only while the force at rest pushes into it
        let f = self.net_force(w);
        if (self.mode == StopMode::AtMin && f >= 0.0) || (self.mode == StopMode::AtMax && f <= 0.0)
        {
            self.mode = StopMode::Free;
        }
    }
    fn reset(&mut self, _t: f64, x: &[f64], w: &Wires) {
        self.impacts = 0;
        self.impact_energy = 0.0;
        self.mode = StopMode::Free;
        if let Some(s) = self.stops {
            let f = self.net_force(w);
            if x[0] <= s.min.si() && f < 0.0 && x[1] <= 0.0 {
                self.mode = StopMode::AtMin;
            } else if x[0] >= s.max.si() && f > 0.0 && x[1] >= 0.0 {
                self.mode = StopMode::AtMax;
            }
        }
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, dx: &[f64], p: &mut PowerTerms) {
        // acceleration-proportional friction terms (c a) act as added mass:
        // their power c a v is stored with the kinetic energy
        p.storage = (self.mass + w.get(self.rod.added_mass)) * x[1] * dx[1];
        p.load = self.external_force * x[1];
        p.stored = 0.5 * self.mass * x[1] * x[1];
    }
    fn probes(&self) -> Vec<Probe> {
        vec![
            Probe {
                name: "position".into(),
                unit: "m",
                wire: self.rod.position,
            },
            Probe {
                name: "velocity".into(),
                unit: "m/s",
                wire: self.rod.velocity,
            },
        ]
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![
            ("stop_impacts".into(), self.impacts as f64),
            ("stop_impact_energy_j".into(), self.impact_energy),
        ]
    }
}

/// A friction law acting on a rod, through the friction crate's
/// [`FrictionModel`] (any model: internal states, pressure and acceleration
/// terms, stick modes with events). The acceleration-proportional term goes
/// to the mass side as added mass; in a stick mode the component asks the
/// mass to hold the rod ([`MechanicalNode::hold`]) and the friction force is
/// the drive force (everything else acting on the rod).
pub struct Friction {
    name: String,
    rod_name: String,
    chambers: Option<(String, String)>,
    /// The friction law.
    pub model: Box<dyn FrictionModel>,
    mode: FrictionMode,
    rod: MechanicalNode,
    p1: Option<Wire>,
    p2: Option<Wire>,
    force: Wire,
}

impl std::fmt::Debug for Friction {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Friction")
            .field("name", &self.name)
            .field("mode", &self.mode)
            .finish()
    }
}

impl Friction {
    /// Friction on body `rod`; `chambers` names the nodes whose pressures the
    /// law reads as p1, p2 (pressure-dependent laws).
    pub fn new(
        name: &str,
        rod: &str,
        chambers: Option<(&str, &str)>,
        model: Box<dyn FrictionModel>,
    ) -> Self {
        Self {
            name: name.into(),
            rod_name: rod.into(),
            chambers: chambers.map(|(a, b)| (a.to_string(), b.to_string())),
            model,
            mode: FrictionMode::Slip,
            rod: unbound_m(),
            p1: None,
            p2: None,
            force: UNBOUND,
        }
    }

    fn input(&self, w: &Wires) -> FrictionInput {
        FrictionInput {
            velocity: Velocity::new(w.get(self.rod.velocity)),
            acceleration: hydrocyl_ports::Acceleration::ZERO,
            p1: Pressure::new(self.p1.map_or(0.0, |p| w.get(p))),
            p2: Pressure::new(self.p2.map_or(0.0, |p| w.get(p))),
        }
    }

    /// The drive force (all forces on the rod but this friction) \[N\]; valid
    /// once every component has been evaluated.
    fn drive(&self, w: &Wires) -> Force {
        // the accumulator holds −F (slip) or nothing (stick) from this component
        Force::new(w.get(self.rod.force) + w.get(self.force))
    }
}

impl Component for Friction {
    fn name(&self) -> &str {
        &self.name
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.model.validate().map_err(|e| BuildError::Component {
            component: self.name.clone(),
            message: e.to_string(),
        })?;
        self.rod = net.mechanical(&self.rod_name);
        if let Some((a, b)) = self.chambers.clone() {
            self.p1 = Some(net.hydraulic(&a).pressure);
            self.p2 = Some(net.hydraulic(&b).pressure);
        }
        self.force = net.private("force");
        Ok(())
    }
    fn n_states(&self) -> usize {
        self.model.n_states()
    }
    fn state_names(&self) -> Vec<String> {
        (0..self.n_states())
            .map(|i| format!("{}.z{i}", self.name))
            .collect()
    }
    fn state_scales(&self, s: &mut [f64]) {
        s.fill(1.0e-4);
    }
    fn initial_state(&self, x: &mut [f64]) {
        x.fill(0.0);
    }
    fn evaluate(&self, _t: f64, x: &[f64], w: &mut Wires) {
        let input = self.input(w);
        if self.mode == FrictionMode::Stick {
            w.add(self.rod.hold, 1.0);
            w.set(self.force, 0.0);
        } else {
            let f = self.model.force(&input, x).si();
            w.add(self.rod.force, -f);
            w.set(self.force, f);
            w.add(
                self.rod.added_mass,
                self.model.acceleration_coefficient(&input).si(),
            );
        }
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        self.model.state_derivative(&self.input(w), x, dx);
    }
    fn n_events(&self) -> usize {
        self.model.n_events()
    }
    fn events(&self, _t: f64, x: &[f64], w: &Wires, g: &mut [f64]) {
        self.model.events(&self.input(w), self.drive(w), x, g);
    }
    fn on_event(
        &mut self,
        _t: f64,
        x: &mut [f64],
        w: &Wires,
        which: usize,
        dir: Crossing,
    ) -> EventAction {
        if dir == Crossing::Falling {
            let (input, drive) = (self.input(w), self.drive(w));
            self.mode = self.model.on_event(which, &input, drive, x);
        }
        EventAction::Continue
    }
    fn reset(&mut self, _t: f64, _x: &[f64], w: &Wires) {
        self.mode = FrictionMode::Slip;
        let (input, drive) = (self.input(w), self.drive(w));
        self.mode = self.model.initialise_mode(&input, drive);
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        let input = self.input(w);
        if self.mode == FrictionMode::Stick {
            return; // v = 0: no power
        }
        let f = self.model.force(&input, x).si();
        let diss = self.model.dissipated_power(&input, x).si();
        p.dissipated = diss;
        p.storage = f * input.velocity.si() - diss;
        p.stored = self.model.stored_energy(x).si();
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe {
            name: format!("{}_force", self.name),
            unit: "N",
            wire: self.force,
        }]
    }
}
