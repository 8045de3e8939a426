//! The two-chamber cylinder (eqs 2.10–2.15, 2.27).

use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, MechanicalNode, Netlist, PowerTerms, Probe,
    Tangents, Wire, Wires,
};
use hydrocyl_actuator::{Cylinder, EntrainedAir};
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::Pressure;

/// How far below its threshold a chamber pressure (or a volume's, below
/// absolute vacuum) must fall for an entry to count \[Pa\]: the default
/// solver's absolute tolerance on a pressure state (rtol 1e-6 × the 1 MPa
/// scale of chamber and volume pressures). Within it of the threshold a
/// pressure is the solver's noise (a closed chamber at tank pressure
/// dithering at −1e-3 Pa, or sitting exactly at vacuum), not an entry; a
/// real entry goes kPa deep. The switching function of an entry is
/// `p − (threshold − margin)`, the same whatever the run's tolerance.
pub const CAVITATION_MARGIN_PA: f64 = 1.0;

/// Cavitation bookkeeping of a chamber.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Cavitation {
    pub(super) entries: usize,
}

impl Cavitation {
    /// Counts an entry of chamber `which` when its switching function falls.
    pub(super) fn count(cav: &mut [Cavitation; 2], which: usize, dir: Crossing) -> EventAction {
        if dir == Crossing::Falling {
            cav[which].entries += 1;
        }
        EventAction::Continue
    }
}

/// The fundamental two-chamber cylinder (eqs 2.10–2.15, 2.27): owns the
/// chamber nodes A (cap side, p1) and B (rod side, p2), pushes the rod.
///
/// Cavitation is **reported**, not hidden: a switching function per chamber
/// crosses zero when its pressure falls below `cavitation_pressure` (by more
/// than [`CAVITATION_MARGIN_PA`]), and the entries are counted ([`Component::diagnostics`] `cavitation_entries_1/2`).
/// With no entrained air (`air` = [`EntrainedAir::NONE`], constant B) the
/// fluid model is not changed below it, so a run with entries has left the
/// model's range there; with air the chambers' bulk modulus is
/// `B_eff(p)` ([`hydrocyl_actuator::fluid`]) and no chamber goes below
/// absolute zero.
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
    /// Entrained air in the chambers' oil (none: the constant B of eqs 2.10–2.15).
    pub air: EntrainedAir,
    cav: [Cavitation; 2],
    a: HydraulicNode,
    b: HydraulicNode,
    rod: MechanicalNode,
    p_le: Wire<Pressure>,
}

/// What a [`TwoChamberCylinder`] connects to, by port: named fields, so
/// that swapping the chambers is a visible edit rather than two positional
/// strings.
#[derive(Clone, Copy, Debug)]
pub struct CylinderNodes<'a> {
    /// Chamber 1, the cap side (port A, pressure p1).
    pub a: &'a str,
    /// Chamber 2, the rod side (port B, pressure p2).
    pub b: &'a str,
    /// The body the rod pushes (mechanical node).
    pub rod: &'a str,
}

impl TwoChamberCylinder {
    /// A cylinder owning the chamber nodes `nodes.a` (chamber 1) and
    /// `nodes.b` (chamber 2), acting on the body `nodes.rod`.
    pub fn new(
        name: &str,
        nodes: CylinderNodes<'_>,
        cylinder: Cylinder,
        initial_pressures: (f64, f64),
    ) -> Self {
        Self {
            name: name.into(),
            a_name: nodes.a.into(),
            b_name: nodes.b.into(),
            rod_name: nodes.rod.into(),
            cylinder,
            cavitation_pressure: 0.0,
            initial_pressures,
            air: EntrainedAir::NONE,
            cav: [Cavitation::default(); 2],
            a: HydraulicNode::UNBOUND,
            b: HydraulicNode::UNBOUND,
            rod: MechanicalNode::UNBOUND,
            p_le: Wire::UNBOUND,
        }
    }

    /// The chambers' effective bulk moduli `(B_eff(p1), B_eff(p2))` \[Pa\].
    fn moduli(&self, x: &[f64]) -> (f64, f64) {
        let b = self.cylinder.bulk_modulus.si();
        (
            self.air.bulk_modulus(b, x[0]),
            self.air.bulk_modulus(b, x[1]),
        )
    }

    /// `(dp1/dt, dp2/dt)` at this instant \[Pa·s⁻¹\]: the cylinder's rates
    /// with B replaced by `B_eff(p)` (exactly the cylinder's without air).
    fn rates(&self, x: &[f64], w: &Wires) -> (f64, f64) {
        let (d1, d2) = self.cylinder.pressure_rates(
            w.get(self.rod.position),
            w.get(self.rod.velocity),
            Pressure::new(x[0]),
            Pressure::new(x[1]),
            w.get(self.a.inflow),
            -w.get(self.b.inflow),
        );
        if self.air.is_none() {
            return (d1, d2);
        }
        let b = self.cylinder.bulk_modulus.si();
        let (b1, b2) = self.moduli(x);
        (d1 * (b1 / b), d2 * (b2 / b))
    }
}

impl Component for TwoChamberCylinder {
    fn is_actuator(&self) -> bool {
        true
    }
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
        d.state(self.a.pressure, 0, 1.0);
        d.state(self.b.pressure, 1, 1.0);
    }
    fn evaluate_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        let (a1, a2) = (self.cylinder.area_1.si(), self.cylinder.area_2.si());
        let ae = self.cylinder.effective_area().si();
        d.state(self.rod.force, 0, a1);
        d.state(self.rod.force, 1, -a2);
        d.state(self.p_le, 0, a1 / ae);
        d.state(self.p_le, 1, -a2 / ae);
    }
    fn derivative_tangents(&self, _t: f64, x: &[f64], w: &Wires, d: &mut Tangents) {
        // dp1/dt = B/V1 (Q1 − Cl (p1 − p2) − Ce1 p1 − A1 v), V1 = A1 (L1 + x);
        // dp2/dt = B/V2 (A2 v + Cl (p1 − p2) − Ce2 p2 + Q2_in), V2 = A2 (L2 − x)
        let c = &self.cylinder;
        let (a1, a2, b) = (c.area_1.si(), c.area_2.si(), c.bulk_modulus.si());
        let (s1, s2) = (
            self.air.bulk_modulus_and_slope(b, x[0]),
            self.air.bulk_modulus_and_slope(b, x[1]),
        );
        let (cl, ce1, ce2) = (
            c.internal_leakage,
            c.external_leakage_1,
            c.external_leakage_2,
        );
        let (v1, v2) = c.volumes(w.get(self.rod.position));
        let (v1, v2) = (v1.si(), v2.si());
        let (d1, d2) = self.rates(x, w);
        let (k1, k2) = (s1.0 / v1, s2.0 / v2);
        // B_eff(p): d/dp of (B_eff/V) n = B_eff'/B_eff · dp/dt + B_eff/V dn/dp
        d.rate_state(0, 0, s1.1 / s1.0 * d1);
        d.rate_state(1, 1, s2.1 / s2.0 * d2);
        d.rate_chain(0, k1, self.a.inflow);
        d.rate_state(0, 0, -k1 * (cl + ce1));
        d.rate_state(0, 1, k1 * cl);
        d.rate_chain(0, -k1 * a1, self.rod.velocity);
        d.rate_chain(0, -d1 / v1 * a1, self.rod.position);
        d.rate_chain(1, k2, self.b.inflow);
        d.rate_state(1, 0, k2 * cl);
        d.rate_state(1, 1, -k2 * (cl + ce2));
        d.rate_chain(1, k2 * a2, self.rod.velocity);
        d.rate_chain(1, d2 / v2 * a2, self.rod.position);
    }
    fn quadrature_tangents(&self, _t: f64, x: &[f64], w: &Wires, d: &mut Tangents) {
        let v = w.get(self.rod.velocity).si();
        let b = self.cylinder.bulk_modulus.si();
        let (a1, a2) = (self.cylinder.area_1.si(), self.cylinder.area_2.si());
        let (b1, b2) = self.moduli(x);
        let (c1, c2) = (self.air.compliance(b, x[0]), self.air.compliance(b, x[1]));
        d.quadrature_chain(0, 1.0, self.a.inflow);
        d.quadrature_chain(1, 1.0, self.b.inflow);
        d.quadrature_state(2, 0, a1 * v / b1);
        d.quadrature_chain(2, c1 * a1, self.rod.velocity);
        d.quadrature_state(3, 1, a2 * v / b2);
        d.quadrature_chain(3, c2 * a2, self.rod.velocity);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.cylinder
            .validate()
            .and_then(|()| self.air.validate())
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
        w.set(self.a.pressure, Pressure::new(x[0]));
        w.set(self.b.pressure, Pressure::new(x[1]));
    }
    fn evaluate(&self, _t: f64, x: &[f64], w: &mut Wires) {
        let f = self
            .cylinder
            .force(Pressure::new(x[0]), Pressure::new(x[1]));
        w.add(self.rod.force, f);
        w.set(self.p_le, f / self.cylinder.effective_area());
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
        let floor = self.cavitation_pressure - CAVITATION_MARGIN_PA;
        g[0] = x[0] - floor;
        g[1] = x[1] - floor;
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
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {
        self.cav = [Cavitation::default(); 2];
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, dx: &[f64], p: &mut PowerTerms) {
        let (v1, v2) = self.cylinder.volumes(w.get(self.rod.position));
        let (v1, v2) = (v1.si(), v2.si());
        let b = self.cylinder.bulk_modulus.si();
        let (b1, b2) = self.moduli(x);
        let (p1, p2) = (Pressure::new(x[0]), Pressure::new(x[1]));
        let (ql, qe1, qe2) = self.cylinder.leakage(p1, p2);
        p.storage = x[0] * v1 / b1 * dx[0] + x[1] * v2 / b2 * dx[1];
        p.dissipated = ql.si() * (x[0] - x[1]) + qe1.si() * x[0] + qe2.si() * x[1];
        let (e1, e2) = (
            self.air.stored_energy(b, x[0], v1),
            self.air.stored_energy(b, x[1], v2),
        );
        p.stored = e1 + e2;
        // the walls move: V1 grows by A1 v, V2 shrinks by A2 v (the stored
        // energy is proportional to the volume at a given pressure)
        let v = w.get(self.rod.velocity).si();
        p.moved = e1 / v1 * self.cylinder.area_1.si() * v - e2 / v2 * self.cylinder.area_2.si() * v;
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
        // ∫Q1 dt, ∫Q2_in dt (the valve's flows), ∫C(p1) A1 v dt, ∫C(p2) A2 v dt
        // with C(p) = ∫dp/B_eff (p/B without air): with these,
        // ∫(Q1 − A1 v − V1/B_eff dp1/dt) dt is computable exactly
        // (∫V1 dC(p1) = [V1 C(p1)] − ∫C(p1) A1 v dt).
        let v = w.get(self.rod.velocity).si();
        let b = self.cylinder.bulk_modulus.si();
        q[0] = w.get(self.a.inflow).si();
        q[1] = w.get(self.b.inflow).si();
        q[2] = self.air.compliance(b, x[0]) * self.cylinder.area_1.si() * v;
        q[3] = self.air.compliance(b, x[1]) * self.cylinder.area_2.si() * v;
    }
    fn probes(&self) -> Vec<Probe> {
        vec![
            Probe::of("p1", self.a.pressure),
            Probe::of("p2", self.b.pressure),
            Probe::of("p_le", self.p_le),
        ]
    }
    fn diagnostics(&self) -> Vec<(String, f64)> {
        vec![
            ("cavitation_entries_1".into(), self.cav[0].entries as f64),
            ("cavitation_entries_2".into(), self.cav[1].entries as f64),
        ]
    }
}
