//! The friction bench's own friction law and its measured-pressure source.
//!
//! `friction_bench` is the law `hydrocyl-identify` fits on a friction bench
//! (eqs 5.1, 5.4, 5.12), every term additive and each off at its default:
//!
//! * static: `g(v) tanh(v/v_t)`, `g(v) = Fc + (Fs − Fc) exp(−|v/vs|^α)`
//!   (the Stribeck curve, eq 5.1's g; no hump while `stiction` is absent);
//! * or, with `sigma0 > 0`, LuGre's bristle in place of the static curve:
//!   `σ0 z + σ1 ż`, `ż = v − σ0 |v| z / g(v)` (eq 5.1);
//! * `b v` (viscous), `K (p1 − p2)² v` (eq 5.4, `seal.k_pressure`),
//!   `K H a` (eq 5.12, `seal.h_acceleration`, moved to the rod's mass side);
//! * `(dFc/2) |tanh(v/v_t)|` (`asymmetry`: extending level `Fc + dFc/2`,
//!   retracting `Fc − dFc/2`) and a constant force `F0` (`external_force`).
//!
//! `signal_pressure_source` holds a node at the pressure a signal gives (a
//! bench record's measured chamber pressure, fed by a `command_input`).

use super::super::registry::{
    check_param, param, ComponentType, Default::*, ParamSpec, Range, Role, StateSpec,
};
use super::{built, port, HYD, MECH, SIG};
use crate::circuit::{
    BuildError, Causality, Component, HydraulicNode, MechanicalNode, Netlist, PowerTerms, Probe,
    Tangents, Wire, Wires,
};
use hydrocyl_ports::{Force, Mass, Pressure};
use std::cell::Cell;

mod law;
pub use law::{BenchLaw, Shape};

/// The bench law on a rod, reading the chamber pressures at `A` and `B`.
#[derive(Debug)]
pub struct BenchFriction {
    name: String,
    rod_name: String,
    chambers: Option<(String, String)>,
    /// The law.
    pub law: BenchLaw,
    /// Stribeck velocity and exponent, and σ1, kept while the hump or the
    /// bristle is off (so that a parameter set on the built law keeps them).
    shape: (f64, f64, f64),
    initial_z: f64,
    rod: MechanicalNode,
    p: Option<(Wire<Pressure>, Wire<Pressure>)>,
    force: Wire<Force>,
    /// The law's [`Shape`] at the last velocity asked (a run evaluates the
    /// force, the bristle's rate and their tangents at one velocity);
    /// cleared when a parameter changes.
    last: Cell<Option<Shape>>,
}

impl BenchFriction {
    /// The law's shape at the rod's velocity.
    fn shape(&self, w: &Wires) -> Shape {
        let v = w.get(self.rod.velocity).si();
        match self.last.get() {
            Some(s) if s.v.to_bits() == v.to_bits() => s,
            _ => {
                let s = self.law.shape(v);
                self.last.set(Some(s));
                s
            }
        }
    }
    fn pressures(&self, w: &Wires) -> (f64, f64) {
        self.p
            .map_or((0.0, 0.0), |(a, b)| (w.get(a).si(), w.get(b).si()))
    }
    fn z(&self, x: &[f64]) -> f64 {
        if self.law.lugre.is_some() {
            x[0]
        } else {
            0.0
        }
    }
}

impl Component for BenchFriction {
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn evaluate_tangents(&self, _t: f64, x: &[f64], w: &Wires, d: &mut Tangents) {
        let (p1, p2) = self.pressures(w);
        let j = self.law.partials_at(&self.shape(w), p1, p2, self.z(x));
        d.chain(self.force, j.df_dv, self.rod.velocity);
        if let Some((a, b)) = self.p {
            d.chain(self.force, j.df_dp1, a);
            d.chain(self.force, j.df_dp2, b);
        }
        if self.law.lugre.is_some() {
            d.state(self.force, 0, j.df_dz);
        }
        d.chain(self.rod.force, -1.0, self.force);
    }
    fn derivative_tangents(&self, _t: f64, x: &[f64], w: &Wires, d: &mut Tangents) {
        if self.law.lugre.is_some() {
            let (p1, p2) = self.pressures(w);
            let j = self.law.partials_at(&self.shape(w), p1, p2, x[0]);
            d.rate_state(0, 0, j.dzdot_dz);
            d.rate_chain(0, j.dzdot_dv, self.rod.velocity);
        }
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.rod = net.mechanical(&self.rod_name);
        if let Some((a, b)) = self.chambers.clone() {
            self.p = Some((net.hydraulic(&a).pressure, net.hydraulic(&b).pressure));
        }
        self.force = net.private("force");
        Ok(())
    }
    fn n_states(&self) -> usize {
        usize::from(self.law.lugre.is_some())
    }
    fn state_names(&self) -> Vec<String> {
        (0..self.n_states())
            .map(|_| format!("{}.z", self.name))
            .collect()
    }
    /// The bristle's scale is its steady deflection `Fc / σ0` (at least
    /// 1e-12 m): the force σ0 z is then held to the tolerance of the force.
    fn state_scales(&self, s: &mut [f64]) {
        let s0 = self.law.lugre.map_or(0.0, |(s0, _)| s0);
        s.fill(if s0 > 0.0 {
            (self.law.coulomb.max(1e-3) / s0).max(1e-12)
        } else {
            1.0e-4
        });
    }
    fn initial_state(&self, x: &mut [f64]) {
        x.fill(self.initial_z);
    }
    fn evaluate(&self, _t: f64, x: &[f64], w: &mut Wires) {
        let (p1, p2) = self.pressures(w);
        let f = self.law.force_at(&self.shape(w), p1, p2, self.z(x)) + self.law.external_force;
        w.add(self.rod.force, Force::new(-f));
        w.add(self.rod.added_mass, Mass::new(self.law.added_mass()));
        w.set(self.force, Force::new(f));
    }
    fn derivatives(&self, _t: f64, x: &[f64], w: &Wires, dx: &mut [f64]) {
        if self.law.lugre.is_some() {
            dx[0] = self.law.z_rate_at(&self.shape(w), x[0]);
        }
    }
    fn power(&self, _t: f64, x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        let v = w.get(self.rod.velocity).si();
        let (p1, p2) = self.pressures(w);
        let z = self.z(x);
        let f = self.law.force(v, p1, p2, z);
        // the bristle stores σ0 z ż of the friction power; F0 is work done
        // on the outside (a load), the rest is heat
        let (storage, stored) = match self.law.lugre {
            Some((s0, _)) => (s0 * z * self.law.z_rate(v, z), 0.5 * s0 * z * z),
            None => (0.0, 0.0),
        };
        p.storage = storage;
        p.stored = stored;
        p.dissipated = f * v - storage;
        p.load = self.law.external_force * v;
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of(format!("{}_force", self.name), self.force)]
    }
    /// Every parameter but a change of `sigma0` between 0 and > 0 (that
    /// adds or removes the bristle state) and a seal gain `K > 0` without
    /// the chamber ports; `stiction` switches the Stribeck hump on.
    fn set_parameter(&mut self, name: &str, value: f64) -> Result<(), String> {
        check_param("friction_bench", name, value)?;
        self.last.set(None);
        let l = &mut self.law;
        match name {
            "coulomb" => l.coulomb = value,
            "smoothing_velocity" => l.smoothing_velocity = value,
            "viscous" => l.viscous = value,
            "asymmetry" => l.asymmetry = value,
            "external_force" => l.external_force = value,
            "seal.h_acceleration" => l.h_acceleration = value,
            "seal.k_pressure" if value > 0.0 && self.chambers.is_none() => {
                return Err("the seal term needs the chamber ports `A` and `B` connected".into())
            }
            "seal.k_pressure" => l.k_pressure = value,
            "stiction" => l.stribeck = Some((value, self.shape.0, self.shape.1)),
            "stribeck_velocity" | "stribeck_exponent" => {
                if name == "stribeck_velocity" {
                    self.shape.0 = value;
                } else {
                    self.shape.1 = value;
                }
                if let Some((fs, _, _)) = l.stribeck {
                    l.stribeck = Some((fs, self.shape.0, self.shape.1));
                }
            }
            "sigma1" => {
                self.shape.2 = value;
                if let Some((s0, _)) = l.lugre {
                    l.lugre = Some((s0, value));
                }
            }
            "sigma0" => match (l.lugre, value > 0.0) {
                (Some(_), true) => l.lugre = Some((value, self.shape.2)),
                (None, false) => {}
                _ => {
                    return Err(
                        "switching the bristle (sigma0 between 0 and > 0) changes the states: assemble again"
                            .into(),
                    )
                }
            },
            _ => unreachable!("check_param knows friction_bench's parameters"),
        }
        Ok(())
    }
}

/// A node held at the pressure a signal gives \[Pa\] (gauge), delivering
/// whatever flow the circuit draws.
#[derive(Debug)]
pub struct SignalPressureSource {
    name: String,
    node_name: String,
    signal_name: String,
    node: HydraulicNode,
    signal: Wire<f64>,
}

impl Component for SignalPressureSource {
    fn name(&self) -> &str {
        &self.name
    }
    fn reads_time(&self, _t: f64) -> bool {
        false
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn evaluate_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, d: &mut Tangents) {
        d.chain(self.node.pressure, 1.0, self.signal);
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.signal = net.signal(&self.signal_name);
        self.node = net.own_hydraulic(&self.node_name, Causality::Algebraic)?;
        Ok(())
    }
    fn evaluate(&self, _t: f64, _x: &[f64], w: &mut Wires) {
        w.set(self.node.pressure, Pressure::new(w.get(self.signal)));
    }
    fn power(&self, _t: f64, _x: &[f64], w: &Wires, _dx: &[f64], p: &mut PowerTerms) {
        p.source = -w.get(self.node.pressure).si() * w.get(self.node.inflow).si();
    }
    fn probes(&self) -> Vec<Probe> {
        vec![Probe::of("p", self.node.pressure)]
    }
}

const LAW: &[ParamSpec] = &[
    param(
        "coulomb",
        "N",
        Required,
        Range::NON_NEGATIVE,
        "Coulomb level Fc",
    ),
    param(
        "smoothing_velocity",
        "m/s",
        Required,
        Range::POSITIVE,
        "smoothing velocity v_t of the tanh",
    ),
    param(
        "viscous",
        "N s/m",
        Value(0.0),
        Range::NON_NEGATIVE,
        "viscous coefficient b",
    ),
    param(
        "stiction",
        "N",
        Absent,
        Range::NON_NEGATIVE,
        "stiction level Fs of the Stribeck curve; absent = no hump (catalog `stribeck`)",
    ),
    param(
        "stribeck_velocity",
        "m/s",
        Value(0.01),
        Range::POSITIVE,
        "Stribeck velocity vs",
    ),
    param(
        "stribeck_exponent",
        "-",
        Value(1.0),
        Range::POSITIVE,
        "Stribeck exponent α",
    ),
    param(
        "asymmetry",
        "N",
        Value(0.0),
        Range::ANY,
        "dFc: extending level Fc + dFc/2, retracting Fc − dFc/2 (catalog `coulomb_asymmetry`)",
    ),
    param(
        "external_force",
        "N",
        Value(0.0),
        Range::ANY,
        "constant force F0 against + motion (catalog `external_force`)",
    ),
    param(
        "sigma0",
        "N/m",
        Value(0.0),
        Range::NON_NEGATIVE,
        "bristle stiffness σ0 (LuGre, eq 5.1); 0 = the static curve",
    ),
    param(
        "sigma1",
        "N s/m",
        Value(0.0),
        Range::NON_NEGATIVE,
        "bristle damping σ1",
    ),
    param(
        "seal.k_pressure",
        "m^3 s/N",
        Value(0.0),
        Range::NON_NEGATIVE,
        "additive seal term K (p1 − p2)² v (eq 5.4); needs ports A and B",
    ),
    param(
        "seal.h_acceleration",
        "N^2 s/m^4",
        Value(0.0),
        Range::ANY,
        "additive acceleration term K H a (eq 5.12), with K above",
    ),
];

/// The bench law of an instance of `friction_bench`.
fn law_of(i: &super::super::registry::Instance) -> BenchLaw {
    let s0 = i.get("sigma0");
    BenchLaw {
        coulomb: i.get("coulomb"),
        smoothing_velocity: i.get("smoothing_velocity"),
        stribeck: i
            .opt("stiction")
            .map(|fs| (fs, i.get("stribeck_velocity"), i.get("stribeck_exponent"))),
        lugre: (s0 > 0.0).then(|| (s0, i.get("sigma1"))),
        viscous: i.get("viscous"),
        k_pressure: i.get("seal.k_pressure"),
        h_acceleration: i.get("seal.h_acceleration"),
        asymmetry: i.get("asymmetry"),
        external_force: i.get("external_force"),
    }
}

/// The component types of this file.
pub const TYPES: &[ComponentType] = &[
    ComponentType {
        name: "friction_bench",
        summary: "the friction bench's law: g(v) tanh(v/v_t) with Stribeck g (or LuGre σ0 z + σ1 ż) + b v + K (p1 − p2)² v + K H a + (dFc/2) abs(tanh(v/v_t)) + F0 (eqs 5.1, 5.4, 5.12)",
        ports: &[
            port("rod", MECH, Role::Reads, false, "the rod (body) it acts on"),
            port("A", HYD, Role::Reads, true, "cap-side chamber (pressure term)"),
            port("B", HYD, Role::Reads, true, "rod-side chamber (pressure term)"),
        ],
        params: LAW,
        states: &[StateSpec {
            name: "z",
            unit: "m",
            default: Value(0.0),
            doc: "initial bristle deflection (with sigma0 > 0)",
        }],
        build: |i| {
            if i.connected("A") != i.connected("B") {
                return Err("connect both chamber ports `A` and `B`, or neither".into());
            }
            let chambers = i
                .connected("A")
                .then(|| (i.node("A").to_string(), i.node("B").to_string()));
            let law = law_of(i);
            if law.k_pressure > 0.0 && chambers.is_none() {
                return Err(
                    "the seal term K (p1 − p2)² v needs the chamber ports `A` and `B` connected"
                        .into(),
                );
            }
            built(BenchFriction {
                name: i.name.clone(),
                rod_name: i.node("rod").into(),
                chambers,
                law,
                shape: (
                    i.get("stribeck_velocity"),
                    i.get("stribeck_exponent"),
                    i.get("sigma1"),
                ),
                initial_z: i.initial("z").unwrap_or(0.0),
                rod: MechanicalNode::UNBOUND,
                p: None,
                force: Wire::UNBOUND,
                last: Cell::new(None),
            })
        },
        hints: None,
        probes: &[("force", "N")],
    },
    ComponentType {
        name: "signal_pressure_source",
        summary: "a node held at the pressure a signal gives [Pa] (a bench record's measured chamber pressure)",
        ports: &[
            port("port", HYD, Role::Owns, false, "the node it holds"),
            port("pressure", SIG, Role::Reads, false, "the pressure [Pa] (gauge)"),
        ],
        params: &[],
        states: &[],
        build: |i| {
            built(SignalPressureSource {
                name: i.name.clone(),
                node_name: i.node("port").into(),
                signal_name: i.node("pressure").into(),
                node: HydraulicNode::UNBOUND,
                signal: Wire::UNBOUND,
            })
        },
        hints: None,
        probes: &[("p", "Pa")],
    },
];

#[cfg(test)]
mod tests {
    use crate::netlist::{assemble_inputs, schematic};
    use crate::run::RunOptions;
    use crate::signal::Signal;
    use crate::simulation::Simulation;
    use serde_json::{json, Value};

    /// A bench: drive (velocity input `drive`, acceleration input `acc`),
    /// the pressure inputs `p1`, `p2` on signal-driven chambers, a piston
    /// and the law `law`.
    fn bench(law: Value) -> Value {
        let mut law = law;
        law["type"] = json!("friction_bench");
        json!({
            "kind": "netlist", "name": "b",
            "components": {
                "drive": { "type": "imposed_motion", "mass": 2.0, "force_sign": -1.0 },
                "acc": { "type": "command_input" },
                "p1": { "type": "command_input" },
                "p2": { "type": "command_input" },
                "chamber_1": { "type": "signal_pressure_source" },
                "chamber_2": { "type": "signal_pressure_source" },
                "piston": { "type": "piston", "area_1": 1e-3, "area_2": 5e-4 },
                "friction": law
            },
            "connections": [
                ["drive.rod", "piston.rod", "friction.rod"],
                ["acc.out", "drive.acceleration"],
                ["p1.out", "chamber_1.pressure"], ["p2.out", "chamber_2.pressure"],
                ["chamber_1.port", "piston.A", "friction.A"],
                ["chamber_2.port", "piston.B", "friction.B"]
            ]
        })
    }

    fn run(v: &Value, t: &[f64], sig: [Signal; 4]) -> crate::run::Run {
        let s = schematic(v).unwrap();
        let names = ["drive", "acc", "p1", "p2"];
        let inputs: Vec<_> = names.iter().map(|n| n.to_string()).zip(sig).collect();
        let mut opts = RunOptions::dp45();
        opts.rtol = 1e-10;
        let mut sim = Simulation::of_circuit(assemble_inputs(&s, &inputs).unwrap()).options(opts);
        sim.run(t).unwrap()
    }

    /// Every static term at once against its closed form: the load cell
    /// reads `s (m a + g(v) tanh(v/v_t) + b v + K (p1−p2)² v + K H a +
    /// (dFc/2)|tanh| + F0 − p1 A1 + p2 A2)` with the imposed acceleration
    /// (not the velocity's slope) and the signals' pressures.
    #[test]
    fn static_law_through_the_bench_is_the_closed_form() {
        let v = bench(json!({
            "coulomb": 20.0, "smoothing_velocity": 1e-3, "viscous": 300.0,
            "stiction": 35.0, "stribeck_velocity": 5e-3, "stribeck_exponent": 1.5,
            "asymmetry": 4.0, "external_force": -7.0,
            "seal": { "k_pressure": 2e-9, "h_acceleration": 3e7 }
        }));
        let t: Vec<f64> = (0..=400).map(|k| k as f64 * 1e-3).collect();
        let vel = |t: f64| 0.03 * (7.0 * t).sin();
        let table = |f: &dyn Fn(f64) -> f64| {
            Signal::table(t.clone(), t.iter().map(|&t| f(t)).collect()).unwrap()
        };
        let acc = |t: f64| 0.5 * (3.0 * t).cos();
        let p1 = |t: f64| 4e5 + 1e5 * t;
        let p2 = |t: f64| 1e5 - 2e4 * t;
        let r = run(&v, &t, [table(&vel), table(&acc), table(&p1), table(&p2)]);
        let f = r.channel("drive.force").unwrap();
        for (k, &tk) in t.iter().enumerate() {
            let (v, a, p1, p2) = (vel(tk), acc(tk), p1(tk), p2(tk));
            let th = (v / 1e-3).tanh();
            let g = 20.0 + 15.0 * (-(v / 5e-3).abs().powf(1.5)).exp();
            let ff =
                g * th + 300.0 * v + 2e-9 * (p1 - p2).powi(2) * v + 2e-9 * 3e7 * a + 2.0 * th.abs()
                    - 7.0;
            let expect = -(2.0 * a + ff - p1 * 1e-3 + p2 * 5e-4);
            assert!(
                (f[k] - expect).abs() < 1e-9 * expect.abs().max(1.0),
                "t {tk}: {} vs {expect}",
                f[k]
            );
        }
        let p = r.channel("chamber_1.p").unwrap();
        assert!((p[200] - 4.2e5).abs() < 1e-6);
    }

    /// LuGre pre-sliding from rest at constant velocity with σ1 = 0 and no
    /// hump: `dz/dx = 1 − σ0 z / Fc`, so the friction is
    /// `Fc (1 − exp(−σ0 x / Fc))`; a given `initial.z` starts elsewhere on
    /// the same curve.
    #[test]
    fn lugre_presliding_is_the_closed_form() {
        let mut v = bench(json!({
            "coulomb": 5.0, "smoothing_velocity": 1e-4, "sigma0": 1e5
        }));
        v["components"]["piston"]["area_1"] = json!(0.0);
        v["components"]["piston"]["area_2"] = json!(0.0);
        let v0 = 1e-4;
        let t: Vec<f64> = (0..=200).map(|k| k as f64 * 1e-3).collect();
        let c = |x: f64| Signal::Constant { value: x };
        let r = run(&v, &t, [c(v0), c(0.0), c(0.0), c(0.0)]);
        let f = r.channel("friction.force").unwrap();
        for (k, &tk) in t.iter().enumerate() {
            let closed = 5.0 * (1.0 - (-1e5 * v0 * tk / 5.0).exp());
            assert!((f[k] - closed).abs() < 1e-7, "t {tk}: {} vs {closed}", f[k]);
        }
        // from z0 = 2e-5 m (10 µm of travel further along the same curve)
        v["components"]["friction"]["initial"] = json!({ "z": 2e-5 });
        let r = run(&v, &t, [c(v0), c(0.0), c(0.0), c(0.0)]);
        let f = r.channel("friction.force").unwrap();
        let x0 = -5.0 / 1e5 * (1.0f64 - 1e5 * 2e-5 / 5.0).ln();
        for (k, &tk) in t.iter().enumerate() {
            let closed = 5.0 * (1.0 - (-1e5 * (x0 + v0 * tk) / 5.0).exp());
            assert!((f[k] - closed).abs() < 1e-7, "t {tk}: {} vs {closed}", f[k]);
        }
    }

    /// Parameters set on the built circuit by path give what a circuit
    /// assembled with them gives (static law: sampled without integration,
    /// equal to the integrated run; LuGre: integrated, `run_wires`), and
    /// what cannot change in place is refused by path.
    #[test]
    fn parameters_set_on_a_built_circuit_equal_a_new_assembly() {
        let law =
            json!({ "coulomb": 20.0, "smoothing_velocity": 1e-3, "sigma0": 1e5, "sigma1": 50.0 });
        let t: Vec<f64> = (0..=300).map(|k| k as f64 * 1e-3).collect();
        let vel: Vec<f64> = t.iter().map(|&t| 0.03 * (9.0 * t).sin()).collect();
        let sig = || {
            let c = |x: f64| Signal::Constant { value: x };
            [
                Signal::table(t.clone(), vel.clone()).unwrap(),
                c(0.2),
                c(4e5),
                c(1e5),
            ]
        };
        let build = |law: &Value| {
            let s = schematic(&bench(law.clone())).unwrap();
            let names = ["drive", "acc", "p1", "p2"];
            let inputs: Vec<_> = names.iter().map(|n| n.to_string()).zip(sig()).collect();
            Simulation::of_circuit(assemble_inputs(&s, &inputs).unwrap())
        };
        let sets = [
            ("friction.coulomb", 25.0),
            ("friction.viscous", 300.0),
            ("friction.stiction", 40.0),
            ("friction.stribeck_velocity", 5e-3),
            ("friction.sigma0", 3e5),
            ("friction.sigma1", 80.0),
            ("friction.seal.k_pressure", 1e-9),
            ("friction.external_force", -3.0),
            ("drive.mass", 3.0),
            ("piston.area_2", 6e-4),
        ];
        let mut expect = law.clone();
        for (path, v) in sets {
            let name = path.split_once('.').unwrap();
            match name {
                ("friction", "seal.k_pressure") => expect["seal"] = json!({ "k_pressure": v }),
                ("friction", p) => expect[p] = json!(v),
                _ => {}
            }
        }
        let mut fresh = bench(expect.clone());
        fresh["components"]["drive"]["mass"] = json!(3.0);
        fresh["components"]["piston"]["area_2"] = json!(6e-4);
        let s = schematic(&fresh).unwrap();
        let names = ["drive", "acc", "p1", "p2"];
        let inputs: Vec<_> = names.iter().map(|n| n.to_string()).zip(sig()).collect();
        let mut o = RunOptions::dp45();
        o.rtol = 1e-10;
        let mut want =
            Simulation::of_circuit(assemble_inputs(&s, &inputs).unwrap()).options(o.clone());
        let mut got = build(&law).options(o.clone());
        for (path, v) in sets {
            got.set_parameter(path, v).unwrap();
        }
        let probe = |sim: &Simulation| {
            let p = sim.circuit().probes().into_iter();
            p.filter(|p| p.name == "drive.force")
                .map(|p| p.wire)
                .next()
                .unwrap()
        };
        let force = probe(&got);
        let a = got.run_wires(&t, &[force]).unwrap().swap_remove(0);
        let b = want.run(&t).unwrap();
        let b = b.channel("drive.force").unwrap();
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() < 1e-9 * y.abs().max(1.0), "{x} vs {y}");
        }
        // the bristle cannot be switched off in place, nor can a parameter
        // the component does not have be set
        let e = got
            .set_parameter("friction.sigma0", 0.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("friction.sigma0") && e.contains("states"), "{e}");
        let e = got
            .set_parameter("friction.warp", 1.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("friction.warp"), "{e}");
        let e = got
            .set_parameter("friction.coulomb", -1.0)
            .unwrap_err()
            .to_string();
        assert!(e.contains("friction.coulomb"), "{e}");
        // LuGre's force depends on the bristle: not sampled without integration
        let e = got.sample_state_free(&t, &[force]).unwrap_err().to_string();
        assert!(e.contains("friction.z"), "{e}");
        // a static law: sampled without integration, the integrated run's force
        let mut stat = expect.clone();
        stat.as_object_mut().unwrap().remove("sigma0");
        let mut sim = build(&stat).options(o);
        let w = probe(&sim);
        let sampled = sim.sample_state_free(&t, &[w]).unwrap().swap_remove(0);
        let run = sim.run(&t).unwrap();
        assert_eq!(sampled.as_slice(), run.channel("drive.force").unwrap());
    }

    #[test]
    fn a_half_connected_or_pressure_less_seal_is_refused() {
        let mut v = bench(json!({
            "coulomb": 5.0, "smoothing_velocity": 1e-4, "seal": { "k_pressure": 1e-9 }
        }));
        let conns = v["connections"].as_array_mut().unwrap();
        conns[4] = json!(["chamber_1.port", "piston.A"]);
        let e = schematic(&v)
            .and_then(|s| {
                let c = |x: f64| Signal::Constant { value: x };
                let inputs: Vec<_> = ["drive", "acc", "p1", "p2"]
                    .iter()
                    .map(|n| (n.to_string(), c(0.0)))
                    .collect();
                assemble_inputs(&s, &inputs).map(|_| ())
            })
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("components.friction") && e.contains("`A` and `B`"),
            "{e}"
        );
    }
}
