//! The servovalve's four-way metering (eqs 2.8, 2.9, 3.2).

use crate::circuit::{
    BuildError, Component, HydraulicNode, Netlist, PowerTerms, Probe, Tangents, Wire, Wires,
};
use hydrocyl_ports::{Position, Pressure};
use hydrocyl_valves::servovalve::Metering;

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
    /// Spool dead band x_d \[m\]: the metering sees
    /// `sign(x_s) max(0, |x_s| − x_d)` (catalog `valve_dead_band`; 0 = none).
    pub dead_band: f64,
    spool: Wire<Position>,
    p: HydraulicNode,
    t: HydraulicNode,
    a: HydraulicNode,
    b: HydraulicNode,
    ps: Wire<Pressure>,
}

/// What a [`FourWayValve`] connects to, by port: named fields, so that
/// swapping A and B is a visible edit rather than two positional strings.
#[derive(Clone, Copy, Debug)]
pub struct FourWayNodes<'a> {
    /// The signal wire holding the spool position \[m\].
    pub spool: &'a str,
    /// Supply port P.
    pub p: &'a str,
    /// Tank port T.
    pub t: &'a str,
    /// Service port A (opened to P for `x_s > 0`).
    pub a: &'a str,
    /// Service port B (opened to T for `x_s > 0`).
    pub b: &'a str,
}

impl FourWayNodes<'_> {
    /// The hydraulic node names `[P, T, A, B]`, owned.
    pub fn hydraulic(&self) -> [String; 4] {
        [self.p, self.t, self.a, self.b].map(String::from)
    }
}

impl FourWayValve {
    /// A valve reading the spool position on `nodes.spool`, joining the
    /// hydraulic nodes `nodes.p`, `nodes.t`, `nodes.a`, `nodes.b`.
    pub fn new(name: &str, nodes: FourWayNodes<'_>, metering: Metering) -> Self {
        Self {
            name: name.into(),
            ports: nodes.hydraulic(),
            spool_name: nodes.spool.into(),
            metering,
            supply_resistance: 0.0,
            supply_probe: None,
            spool: Wire::UNBOUND,
            dead_band: 0.0,
            p: HydraulicNode::UNBOUND,
            t: HydraulicNode::UNBOUND,
            a: HydraulicNode::UNBOUND,
            b: HydraulicNode::UNBOUND,
            ps: Wire::UNBOUND,
        }
    }

    /// The flows and the supply pressure the valve sees (drooped when
    /// `supply_resistance > 0`). Inlined: [`Component::evaluate`] drops the
    /// dissipated power it does not read.
    #[inline(always)]
    fn flows(&self, w: &Wires) -> (hydrocyl_valves::servovalve::MeteringFlows, Pressure) {
        let g = |n: &HydraulicNode| w.get(n.pressure);
        let xs = w.get(self.spool);
        let xs = if self.dead_band > 0.0 {
            Position::new(xs.si().signum() * (xs.si().abs() - self.dead_band).max(0.0))
        } else {
            xs
        };
        self.metering.flows_drooped(
            xs,
            g(&self.p),
            self.supply_resistance,
            g(&self.t),
            g(&self.a),
            g(&self.b),
        )
    }
}

impl FourWayValve {
    /// The tangents of [`FourWayValve::evaluate`]: the four metering edges'
    /// conductances and area gradients chained onto the spool and port
    /// pressures, the drooped supply by the implicit function theorem on
    /// `ps + R_s Q_P(ps) = p_P`.
    fn flow_tangents(&self, w: &Wires, d: &mut Tangents) {
        let m = &self.metering;
        let o = &m.orifice;
        let xs = w.get(self.spool).si();
        // d(effective travel)/d(spool): the dead band is flat
        let dxe = if self.dead_band > 0.0 && xs.abs() <= self.dead_band {
            0.0
        } else {
            1.0
        };
        let x = xs.signum() * (xs.abs() - self.dead_band).max(0.0) + m.null_bias.si();
        let x = if self.dead_band > 0.0 {
            x
        } else {
            xs + m.null_bias.si()
        };
        let (wg, u0) = (m.area_gradient(), m.underlap.si());
        let areas = m.areas(Position::new(x - m.null_bias.si()));
        // ∂A/∂x of each pair of edges (zero where an edge is shut)
        let da1 = if u0 + x > 0.0 { wg * dxe } else { 0.0 };
        let da2 = if u0 - x > 0.0 { -wg * dxe } else { 0.0 };
        let pr = |n: &HydraulicNode| w.get(n.pressure);
        let (ps, pt, pa, pb) = (w.get(self.ps), pr(&self.t), pr(&self.a), pr(&self.b));
        let unit = hydrocyl_ports::Area::new(1.0);
        // conductance and ∂Q/∂A of an edge
        let edge = |area, up, down| (o.conductance(area, up, down), o.flow(unit, up, down).si());
        let (g1, c1) = edge(areas.av1, ps, pa);
        let (g2, c2) = edge(areas.av2, pa, pt);
        let (g3, c3) = edge(areas.av1, pb, pt);
        let (g4, c4) = edge(areas.av2, ps, pb);
        // the supply pressure the edges see
        let rs = self.supply_resistance;
        let qx_p = c1 * da1 + c4 * da2;
        if rs == 0.0 {
            d.chain(self.ps, 1.0, self.p.pressure);
        } else {
            let den = 1.0 + rs * (g1 + g4);
            d.chain(self.ps, 1.0 / den, self.p.pressure);
            d.chain(self.ps, rs * g1 / den, self.a.pressure);
            d.chain(self.ps, rs * g4 / den, self.b.pressure);
            d.chain(self.ps, -rs * qx_p / den, self.spool);
        }
        // (accumulator, sign, [∂/∂ps, ∂/∂pa, ∂/∂pb, ∂/∂pt, ∂/∂x])
        let rows = [
            (
                self.a.inflow,
                1.0,
                [g1, -g1 - g2, 0.0, g2, c1 * da1 - c2 * da2],
            ),
            (
                self.b.inflow,
                -1.0,
                [-g4, 0.0, g3 + g4, -g3, c3 * da1 - c4 * da2],
            ),
            (self.p.inflow, -1.0, [g1 + g4, -g1, -g4, 0.0, qx_p]),
            (
                self.t.inflow,
                1.0,
                [0.0, g2, g3, -g2 - g3, c2 * da2 + c3 * da1],
            ),
        ];
        for (acc, sign, [dps, dpa, dpb, dpt, dx]) in rows {
            d.chain(acc, sign * dps, self.ps);
            d.chain(acc, sign * dpa, self.a.pressure);
            d.chain(acc, sign * dpb, self.b.pressure);
            d.chain(acc, sign * dpt, self.t.pressure);
            d.chain(acc, sign * dx, self.spool);
        }
    }
}

impl Component for FourWayValve {
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
        self.flow_tangents(w, d);
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
        w.add(self.p.inflow, -f.qp);
        w.add(self.t.inflow, f.qt);
        w.add(self.a.inflow, f.qa);
        w.add(self.b.inflow, -f.qb);
        w.set(self.ps, ps);
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        p.dissipated = self.flows(w).0.dissipated;
    }
    /// The supply pressure the edges see: without a supply resistance, the
    /// supply port's own pressure (the same value, read without evaluating
    /// the valve), else the drooped one `evaluate` solves for.
    fn probes(&self) -> Vec<Probe> {
        let ps = if self.supply_resistance == 0.0 {
            self.p.pressure
        } else {
            self.ps
        };
        self.supply_probe
            .iter()
            .map(|n| Probe::of(n.clone(), ps))
            .collect()
    }
}
