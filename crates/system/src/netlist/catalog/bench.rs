//! Friction-bench components: a drive that imposes the motion of a rod and
//! reports the force that takes (the load cell of a seal or axis friction
//! bench), and a rigid piston that turns chamber pressures into a rod force.
//!
//! With the motion imposed, the rod's force balance (eq 5.9 with the drive
//! force added) gives the drive force instead of the acceleration:
//! `F_drive = (m + Σc) a − ΣF`, where `ΣF` is every other force on the rod
//! (friction, pressure) and `Σc` the acceleration-proportional friction terms
//! (eq 5.12). The load cell reads `s F_drive`, `s = ±1` the way its positive
//! force pushes. This is the inverse model of the robotics IDIM practice: for
//! a bench whose drive imposes the motion it is the well-posed simulation.

use super::super::registry::{
    check_param, param, ComponentType, Default::*, Range, Role, StateSpec,
};
use super::{built, port, HYD, MECH, SIG};
use crate::circuit::{
    BuildError, Component, HydraulicNode, MechanicalNode, Netlist, PowerTerms, Probe, Tangents,
    Wire, Wires,
};
use crate::signal::Signal;
use hydrocyl_ports::{Force, Position, Velocity, VolumeFlow};
use std::cell::Cell;

/// The drive of a friction bench: owns the rod, whose velocity is the run's
/// command \[m·s⁻¹\] (first-order hold between samples) and whose position is
/// its integral; reports the load-cell force it takes to impose it.
#[derive(Debug)]
pub struct ImposedMotion {
    name: String,
    rod_name: String,
    /// The imposed velocity \[m·s⁻¹\] as a signal of time.
    pub velocity: Signal,
    /// Moving mass between the load cell and the rod \[kg\].
    pub mass: f64,
    /// +1 when a positive load-cell force pushes the rod in + direction.
    pub force_sign: f64,
    /// Initial position \[m\].
    pub initial_position: f64,
    hint: Cell<usize>,
    /// The signal giving the imposed acceleration \[m·s⁻²\], when port
    /// `acceleration` is connected (else the velocity's slope).
    acceleration_name: Option<String>,
    acceleration: Option<Wire<f64>>,
    rod: MechanicalNode,
    force: Wire<Force>,
}

impl ImposedMotion {
    /// The imposed acceleration at `t` \[m·s⁻²\]: the `acceleration`
    /// signal's, or the velocity's slope.
    fn acceleration_at(&self, t: f64, w: &Wires) -> f64 {
        match self.acceleration {
            Some(a) => w.get(a),
            None => self.velocity.slope_hinted(t, &self.hint),
        }
    }

    /// The drive force on the rod in + direction (not the load cell's sign)
    /// at `t`, with every other component evaluated \[N\].
    fn drive_force(&self, t: f64, w: &Wires) -> f64 {
        let a = self.acceleration_at(t, w);
        (self.mass + w.get(self.rod.added_mass).si()) * a - w.get(self.rod.force).si()
    }
}

impl Component for ImposedMotion {
    fn name(&self) -> &str {
        &self.name
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn publish_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        // the velocity is the command's: no state moves it
        d.state(self.rod.position, 0, 1.0);
    }
    fn evaluate_tangents(&self, t: f64, _x: &[f64], w: &Wires, d: &mut Tangents) {
        // F = s ((m + Σc) a − ΣF)
        let s = self.force_sign;
        d.chain(
            self.force,
            s * self.acceleration_at(t, w),
            self.rod.added_mass,
        );
        d.chain(self.force, -s, self.rod.force);
        if let Some(a) = self.acceleration {
            d.chain(
                self.force,
                s * (self.mass + w.get(self.rod.added_mass).si()),
                a,
            );
        }
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.rod = net.own_mechanical(&self.rod_name)?;
        self.acceleration = self.acceleration_name.as_deref().map(|n| net.signal(n));
        self.force = net.private("force");
        Ok(())
    }
    fn n_states(&self) -> usize {
        1
    }
    fn state_names(&self) -> Vec<String> {
        vec![format!("{}.x", self.name)]
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = 0.1;
    }
    fn initial_state(&self, x: &mut [f64]) {
        x[0] = self.initial_position;
    }
    fn publish(&self, t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.rod.position, Position::new(x[0]));
        let v = self.velocity.value_hinted(t, &self.hint);
        w.set(self.rod.velocity, Velocity::new(v));
    }
    fn evaluates_last(&self) -> bool {
        true
    }
    fn evaluate(&self, t: f64, _x: &[f64], w: &mut Wires) {
        let f = self.force_sign * self.drive_force(t, w);
        w.set(self.force, Force::new(f));
    }
    fn derivatives(&self, _t: f64, _x: &[f64], w: &Wires, dx: &mut [f64]) {
        // the velocity `publish` set from the command
        dx[0] = w.get(self.rod.velocity).si();
    }
    fn power(&self, t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        let v = self.velocity.value_hinted(t, &self.hint);
        let a = self.acceleration_at(t, w);
        // the drive's work on the rod comes from outside the circuit; the
        // moving mass (with the friction's added mass) stores m v a
        p.source = self.drive_force(t, w) * v;
        p.storage = (self.mass + w.get(self.rod.added_mass).si()) * v * a;
        p.stored = 0.5 * (self.mass + w.get(self.rod.added_mass).si()) * v * v;
    }
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), String> {
        check_param("imposed_motion", name, value)?;
        match name {
            "mass" => self.mass = value,
            "force_sign" if value == 1.0 || value == -1.0 => self.force_sign = value,
            "force_sign" => return Err(format!("force_sign must be 1 or -1, got {value}")),
            _ => unreachable!("check_param knows imposed_motion's parameters"),
        }
        Ok(())
    }
    fn probes(&self) -> Vec<Probe> {
        vec![
            Probe::of("position", self.rod.position),
            Probe::of("velocity", self.rod.velocity),
            Probe::of(format!("{}_force", self.name), self.force),
            // the run's command as the drive imposes it (the `command`
            // column every rig writes)
            Probe::of("command", self.rod.velocity),
        ]
    }
}

/// A rigid piston: pushes the rod with `p1 A1 − p2 A2` and displaces
/// `A1 v` out of port A's node into the chamber (and `A2 v` back out of the
/// rod side); lossless, no chamber volume. An unconnected port is at 0 Pa.
///
/// Its one state is the piston's position in its bore, the integral of the
/// rod's velocity from `initial.position`: the stroke coordinate of the
/// cylinder under test, whose datum need not be the drive's (a bench drive
/// keeps its own, `drive.initial.position`). No force depends on it.
#[derive(Debug)]
pub struct Piston {
    name: String,
    a_name: Option<String>,
    b_name: Option<String>,
    rod_name: String,
    /// Area on which p1 pushes in + direction \[m²\].
    pub area_1: f64,
    /// Area on which p2 pushes in − direction \[m²\].
    pub area_2: f64,
    /// Initial position of the piston in its bore \[m\].
    pub initial_position: f64,
    a: Option<HydraulicNode>,
    b: Option<HydraulicNode>,
    rod: MechanicalNode,
    force: Wire<Force>,
    position: Wire<Position>,
}

impl Component for Piston {
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
    fn derivative_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        d.rate_chain(0, 1.0, self.rod.velocity);
    }
    fn evaluate_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        for (node, area) in [(self.a, self.area_1), (self.b, -self.area_2)] {
            if let Some(n) = node {
                d.chain(self.force, area, n.pressure);
                d.chain(n.inflow, -area, self.rod.velocity);
            }
        }
        d.chain(self.rod.force, 1.0, self.force);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.a = self.a_name.as_deref().map(|n| net.hydraulic(n));
        self.b = self.b_name.as_deref().map(|n| net.hydraulic(n));
        self.rod = net.mechanical(&self.rod_name);
        self.force = net.private("force");
        self.position = net.private("position");
        Ok(())
    }
    fn n_states(&self) -> usize {
        1
    }
    fn state_names(&self) -> Vec<String> {
        vec![format!("{}.x", self.name)]
    }
    fn state_scales(&self, s: &mut [f64]) {
        s[0] = 0.1;
    }
    fn initial_state(&self, x: &mut [f64]) {
        x[0] = self.initial_position;
    }
    fn publish(&self, _t: f64, x: &[f64], w: &mut Wires) {
        w.set(self.position, Position::new(x[0]));
    }
    fn publish_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        d.state(self.position, 0, 1.0);
    }
    fn derivatives(&self, _t: f64, _x: &[f64], w: &Wires, dx: &mut [f64]) {
        dx[0] = w.get(self.rod.velocity).si();
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        let v = w.get(self.rod.velocity).si();
        let mut f = 0.0;
        if let Some(a) = self.a {
            f += w.get(a.pressure).si() * self.area_1;
            w.add(a.inflow, VolumeFlow::new(-self.area_1 * v));
        }
        if let Some(b) = self.b {
            f -= w.get(b.pressure).si() * self.area_2;
            w.add(b.inflow, VolumeFlow::new(self.area_2 * v));
        }
        w.add(self.rod.force, Force::new(f));
        w.set(self.force, Force::new(f));
    }
    fn power(&self, _t: f64, _x: &[f64], _w: &Wires, _dx: &[f64], _p: &mut PowerTerms) {
        // lossless: the hydraulic power in is the mechanical power out
    }
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), String> {
        check_param("piston", name, value)?;
        match name {
            "area_1" => self.area_1 = value,
            _ => self.area_2 = value,
        }
        Ok(())
    }
    fn probes(&self) -> Vec<Probe> {
        vec![
            Probe::of("position", self.position),
            Probe::of("velocity", self.rod.velocity),
            Probe::of(format!("{}_force", self.name), self.force),
        ]
    }
}

/// The friction-bench component types.
pub const TYPES: &[ComponentType] = &[
    ComponentType {
        name: "imposed_motion",
        summary: "a bench drive: the rod's velocity is the run's command [m/s], the load-cell force is s((m + Σc) a − ΣF) (eq 5.9 solved for the drive force)",
        ports: &[
            port("rod", MECH, Role::Owns, false, "the rod it moves"),
            port("acceleration", SIG, Role::Reads, true, "the imposed acceleration [m/s^2] (a measured record's; else the velocity's slope)"),
        ],
        params: &[
            param("mass", "kg", Value(0.0), Range::NON_NEGATIVE, "moving mass between the load cell and the rod"),
            param("force_sign", "-", Value(1.0), Range { lo: -1.0, hi: 1.0, lo_open: false, hi_open: false }, "+1 when a positive load-cell force pushes the rod in + direction, −1 otherwise"),
        ],
        states: &[StateSpec {
            name: "position",
            unit: "m",
            default: Value(0.0),
            doc: "initial rod position",
        }],
        build: |i| {
            let s = i.get("force_sign");
            if s != 1.0 && s != -1.0 {
                return Err(format!("force_sign must be 1 or -1, got {s}"));
            }
            let Some(velocity) = i.input.clone() else {
                return Err("no command given for this input".into());
            };
            built(ImposedMotion {
                name: i.name.clone(),
                rod_name: i.node("rod").into(),
                velocity,
                mass: i.get("mass"),
                force_sign: s,
                initial_position: i.initial("position").unwrap_or(0.0),
                hint: Cell::new(0),
                acceleration_name: i.connected("acceleration").then(|| i.node("acceleration").to_string()),
                acceleration: None,
                rod: MechanicalNode::UNBOUND,
                force: Wire::UNBOUND,
            })
        },
        hints: None,
        probes: &[("position", "m"), ("velocity", "m/s"), ("force", "N"), ("command", "m/s")],
    },
    ComponentType {
        name: "piston",
        summary: "a rigid piston: force p1 A1 − p2 A2 on the rod, displaced flows A1 v and A2 v, no chamber volume (a bench chamber held by a pressure source); its state is its position in the bore",
        ports: &[
            port("A", HYD, Role::Reads, true, "cap-side chamber (p1 pushes +)"),
            port("B", HYD, Role::Reads, true, "rod-side chamber (p2 pushes −)"),
            port("rod", MECH, Role::Reads, false, "the rod"),
        ],
        params: &[
            param("area_1", "m^2", Value(0.0), Range::NON_NEGATIVE, "area A1 on which p1 pushes in + direction"),
            param("area_2", "m^2", Value(0.0), Range::NON_NEGATIVE, "area A2 on which p2 pushes in − direction"),
        ],
        states: &[StateSpec {
            name: "position",
            unit: "m",
            default: Value(0.0),
            doc: "initial position of the piston in its bore (its own datum, not the drive's)",
        }],
        build: |i| {
            let a = i.connected("A").then(|| i.node("A").to_string());
            let b = i.connected("B").then(|| i.node("B").to_string());
            if a.is_none() && b.is_none() {
                return Err("connect port `A` or `B` (or both)".into());
            }
            built(Piston {
                name: i.name.clone(),
                a_name: a,
                b_name: b,
                rod_name: i.node("rod").into(),
                area_1: i.get("area_1"),
                area_2: i.get("area_2"),
                initial_position: i.initial("position").unwrap_or(0.0),
                a: None,
                b: None,
                rod: MechanicalNode::UNBOUND,
                force: Wire::UNBOUND,
                position: Wire::UNBOUND,
            })
        },
        hints: None,
        probes: &[("position", "m"), ("velocity", "m/s"), ("force", "N")],
    },
];

#[cfg(test)]
mod tests {
    use crate::rig;
    use crate::run::RunOptions;
    use crate::signal::Signal;

    fn run(name: &str, sets: &[&str], v: Signal, t: &[f64]) -> crate::run::Run {
        let mut value = rig::preset(name).unwrap();
        for s in sets {
            rig::apply_set(&mut value, s).unwrap();
        }
        let mut opts = RunOptions::dp45();
        opts.rtol = 1e-10;
        rig::simulate(&value, v, t, &opts).unwrap()
    }

    /// Coulomb + viscous friction under a velocity ramp: the drive force is
    /// `m a + Fc tanh(v/v_t) + b v` at every instant (no state).
    #[test]
    fn drive_force_is_the_force_balance_under_a_ramp() {
        let t: Vec<f64> = (0..=100).map(|k| k as f64 * 0.01).collect();
        let cmd = Signal::Ramp {
            from: -0.05,
            to: 0.05,
            t0_s: 0.0,
            t1_s: 1.0,
        };
        let r = run(
            "emps",
            &["drive.mass=20", "drive.initial.position=0.1"],
            cmd,
            &t,
        );
        let (x, v, f) = (
            r.channel("position").unwrap(),
            r.channel("velocity").unwrap(),
            r.channel("force").unwrap(),
        );
        for k in 0..t.len() - 1 {
            let vk = -0.05 + 0.1 * t[k];
            let a = 0.1;
            let expect = 20.0 * a + 10.0 * (vk / 1e-3).tanh() + 100.0 * vk;
            assert!((v[k] - vk).abs() < 1e-15, "v at {}", t[k]);
            assert!(
                (f[k] - expect).abs() < 1e-9,
                "t {}: {} vs {expect}",
                t[k],
                f[k]
            );
            let xk = 0.1 - 0.05 * t[k] + 0.05 * t[k] * t[k];
            assert!((x[k] - xk).abs() < 1e-9, "x at {}: {} vs {xk}", t[k], x[k]);
        }
    }

    /// LuGre pre-sliding from rest at constant velocity with σ1 = σ2 = 0:
    /// `dz/dx = 1 − σ0 z / Fc`, so the friction is `Fc (1 − exp(−σ0 x/Fc))`;
    /// the load cell adds the chamber's `p A2` (the piston).
    #[test]
    fn lugre_presliding_through_the_piston_follows_the_closed_form() {
        let v0 = 1e-4;
        let t: Vec<f64> = (0..=200).map(|k| k as f64 * 1e-3).collect();
        let r = run(
            "tudelft-seal-25",
            &["chamber.pressure=2e5"],
            Signal::Constant { value: v0 },
            &t,
        );
        let f = r.channel("force").unwrap();
        let area = std::f64::consts::PI * 0.0125f64.powi(2);
        for (k, &tk) in t.iter().enumerate() {
            let x = v0 * tk;
            let closed = 2e5 * area + 5.0 * (1.0 - (-1e5 * x / 5.0).exp());
            assert!((f[k] - closed).abs() < 1e-6, "t {tk}: {} vs {closed}", f[k]);
        }
    }
}
