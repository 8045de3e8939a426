//! The `wang-hybrid` rig: the hybrid pump-controlled asymmetric cylinder of
//! thesis chapters 4, 6 and 7, assembled from its netlist
//! (`fixtures/rigs/wang-hybrid.json`, filled with the rig's values by
//! [`WangHybrid::to_netlist`]) through the [`Circuit`] — no hand-written
//! topology, no whole-circuit equations.
//!
//! ```text
//!                      ┌── check 1 ◀── tank          tank ──▶ check 2 ──┐
//!   command ─▶ pump ═══╡ pump line 1 (Pp1, V_pl)      pump line 2 (Pp2) ╞═══ pump
//!                      ├── relief 3 ──▶ tank   tank ◀── relief 3 ───────┤
//!                      └── relief 1 ──▶ chamber 1 (p1)   chamber 2 (p2) ◀── relief 2 ──┘
//!                                         │   cylinder, mass, friction  │
//!                                         └─▶ A   DDDC four-way   B ◀───┘
//!                                       piloted by Pp1 − Pp2; T ──▶ needle (NCCC) ──▶ tank
//! ```
//!
//! * pump: [`IdentifiedPump`] (section 6.2.1), flow from line 2 to line 1 for
//!   positive command (clockwise, extending, Fig 4-3);
//! * pump lines: two volumes of 3.5628e-5 m³ (`rlv_1.m`) with bulk modulus B;
//! * relief valves 1, 2 (RBAE, eq 6.10, outlet-referred cracking at the DDDC's
//!   10.34 bar minimum pilot pressure) from each pump line to its chamber;
//! * relief valve 3 (200 bar): the pump-line safety valve; the single valve
//!   behind a shuttle is modelled as one eq 6.10 law per line (equivalent:
//!   only the higher line can reach 200 bar);
//! * two anti-cavitation check valves from the tank to the pump lines (the
//!   pump's suction side is a dead end otherwise: the relief valves do not
//!   pass reverse flow);
//! * the DDDC four-way valve opens the chamber that is not fed to its T port
//!   (`B → T` when `Pp1 > Pp2`), the NCCC needle valve (with its reverse-flow
//!   check) throttles it to the tank ([`PilotValve`], [`NeedleComponent`]);
//!   the T port between them is an algebraic node
//!   ([`AlgebraicNode`](crate::series::AlgebraicNode)) whose pressure the
//!   assembler solves;
//! * the C10 cylinder (Table 4-6), a moving mass, the new friction model of
//!   chapter 5 (eq 5.14, Tables 5-8 to 5-10).
//!
//! Every value is a field of [`WangHybrid`], whose `Default` is the rigs.md
//! preset and whose JSON form is `fixtures/rigs/wang-hybrid.json`.

pub mod components;
mod netlist;

pub use components::{
    CheckComponent, NeedleComponent, PilotNodes, PilotValve, PumpComponent, ReliefComponent,
};

use crate::circuit::{BuildError, Circuit};
use crate::rig::RigError;
use crate::run::{Run, RunOptions};
use crate::signal::Signal;
use hydrocyl_actuator::{Cylinder, EntrainedAir};
use hydrocyl_friction::{FrictionLaw, FrictionModel, Wang};
use hydrocyl_ports::{Area, Position, Pressure};
use hydrocyl_pump_motor::IdentifiedPump;
use hydrocyl_valves::check::CheckValve;
use hydrocyl_valves::needle::NeedleValve;
use hydrocyl_valves::pilot_valve::PilotFourWay;
use hydrocyl_valves::relief::ReliefValve;
use serde::{Deserialize, Serialize};

/// The JSON `kind` of this rig.
pub const KIND: &str = "hybrid-pump";

/// Node names of the rig (stable: probes and tests use them).
pub mod nodes {
    /// Pump line 1 (extending side).
    pub const LINE_1: &str = "pump_line_1";
    /// Pump line 2 (retracting side).
    pub const LINE_2: &str = "pump_line_2";
    /// Cylinder chamber 1 (cap side).
    pub const CHAMBER_1: &str = "chamber_1";
    /// Cylinder chamber 2 (rod side).
    pub const CHAMBER_2: &str = "chamber_2";
    /// The tank.
    pub const TANK: &str = "tank";
    /// The four-way valve's T port, joined to the needle valve (algebraic).
    pub const RETURN_PORT: &str = "return_port";
    /// The piston rod and load.
    pub const ROD: &str = "rod";
    /// The pump command signal \[V\].
    pub const COMMAND: &str = "pump_command";
}

/// Every parameter of the `wang-hybrid` rig (SI units).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WangHybrid {
    /// Rig kind, always [`KIND`].
    pub kind: String,
    /// Servomotor and pump, identified command → flow model.
    pub pump: IdentifiedPump,
    /// Volume of each pump line \[m³\].
    pub pump_line_volume: f64,
    /// Effective bulk modulus of the oil in the pump lines \[Pa\] (the
    /// cylinder's is `cylinder.bulk_modulus`).
    pub bulk_modulus: f64,
    /// Relief valves 1 and 2 (pump line → chamber).
    pub relief_pilot: ReliefValve,
    /// Relief valve 3 (pump line → tank), the safety valve.
    pub relief_safety: ReliefValve,
    /// Anti-cavitation check valves (tank → pump line).
    pub check: CheckValve,
    /// The DDDC pilot-shifted four-way valve.
    pub four_way: PilotFourWay,
    /// The NCCC needle valve in the return line.
    pub needle: NeedleValve,
    /// The C10 cylinder.
    pub cylinder: Cylinder,
    /// Moving mass: piston, rod, tray and load \[kg\].
    pub mass: f64,
    /// External force opposing extension (gravity on a vertical rod) \[N\].
    pub external_force: f64,
    /// Friction law on the rod.
    pub friction: FrictionLaw,
    /// Tank pressure (gauge) \[Pa\].
    pub tank_pressure: f64,
    /// Vapour pressure of the oil (gauge): a chamber below it is reported as
    /// cavitating \[Pa\].
    pub vapour_pressure: f64,
    /// Initial piston position from mid-stroke \[m\].
    pub initial_position: f64,
    /// Entrained air in the oil of every volume (pump lines and chambers);
    /// none: the constant bulk moduli (`hydrocyl_actuator::fluid`).
    #[serde(default)]
    pub entrained_air: EntrainedAir,
}

impl Default for WangHybrid {
    fn default() -> Self {
        Self::preset()
    }
}

/// The C10 18-series cylinder (Table 4-6) with `V = A (0.16 ± x)`: eqs 6.20,
/// 6.21 write 0.15 m, which leaves no oil in a chamber at its stroke end; the
/// extra 10 mm of bore-equivalent length is the assumed dead volume of ports
/// and hoses (8 cm³ cap side, 5.5 cm³ rod side).
pub fn c10_cylinder(bulk_modulus: f64) -> Cylinder {
    Cylinder {
        area_1: Area::new(8.042e-4),
        area_2: Area::new(5.50e-4),
        stroke: Position::new(0.300),
        chamber_length_1: Position::new(0.16),
        chamber_length_2: Position::new(0.16),
        bulk_modulus: Pressure::new(bulk_modulus),
        internal_leakage: 0.0,
        external_leakage_1: 0.0,
        external_leakage_2: 0.0,
    }
}

impl WangHybrid {
    /// The rigs.md preset: 20 kg load (chapter 8), Table 5-8 friction with the
    /// seal term bounded per direction to its identification range
    /// (`hydrocyl_friction::seal`).
    pub fn preset() -> Self {
        use hydrocyl_friction::seal;
        let b = 7.0e8;
        Self {
            kind: KIND.into(),
            pump: IdentifiedPump::wang(),
            pump_line_volume: 3.5628e-5,
            bulk_modulus: b,
            relief_pilot: ReliefValve::rbae_pilot(),
            relief_safety: ReliefValve::rbae_safety(),
            check: CheckValve::anti_cavitation(),
            four_way: PilotFourWay::dddc(),
            needle: NeedleValve::nccc(),
            cylinder: c10_cylinder(b),
            mass: 20.0,
            external_force: 0.0,
            friction: FrictionLaw::Wang(
                // Table 5-8 with its K H a term (blended across v = 0,
                // hydrocyl_friction::ACCELERATION_BLEND_VELOCITY; docs/hybrid.md item 7)
                // and the seal term bounded per direction to the largest pressure
                // difference Table 5-3 implies in that direction (2.72 / 5.03 bar;
                // the common 5.03-bar bound gave 447 N at +50 mm/s against the
                // rig's 220 N: docs/hybrid.md item 8)
                Wang::table_5_8()
                    .with_seal_bound(seal::TABLE_5_8_DP_MAX)
                    .with_seal_bounds(seal::TABLE_5_8_DP_MAX_EXTEND, seal::TABLE_5_8_DP_MAX),
            ),
            tank_pressure: 0.0,
            vapour_pressure: -0.99e5,
            initial_position: 0.0,
            entrained_air: EntrainedAir::NONE,
        }
    }

    /// The rig from its JSON form (the `fixtures/rigs/wang-hybrid.json` format), checked.
    pub fn from_json(text: &str) -> Result<Self, RigError> {
        if let Ok(v) = serde_json::from_str::<serde_json::Value>(text) {
            if v.get("kind").and_then(serde_json::Value::as_str) == Some(crate::netlist::KIND) {
                return Self::from_netlist(&v);
            }
        }
        let r: Self = serde_json::from_str(text).map_err(|e| RigError::Invalid {
            path: "rig".into(),
            why: format!("line {} column {}: {e}", e.line(), e.column()),
        })?;
        r.validate()?;
        Ok(r)
    }

    /// The rig from a JSON value, checked.
    pub fn from_value(v: &serde_json::Value) -> Result<Self, RigError> {
        if v.get("kind").and_then(serde_json::Value::as_str) == Some(crate::netlist::KIND) {
            return Self::from_netlist(v);
        }
        let r: Self = crate::netlist::migrate::typed(v)?;
        r.validate()?;
        Ok(r)
    }

    /// Simulates the rig on `command` \[V\], output at `t_eval`.
    pub fn simulate(
        &self,
        command: Signal,
        t_eval: &[f64],
        opts: &RunOptions,
    ) -> Result<Run, RigError> {
        crate::simulation::Simulation::of_circuit(self.build(command)?)
            .options(opts.clone())
            .run(t_eval)
    }

    /// Checks the parameters that no component checks on its own.
    pub fn validate(&self) -> Result<(), BuildError> {
        if self.kind != KIND {
            return Err(BuildError::Component {
                component: "wang-hybrid".into(),
                message: format!("`kind` must be `{KIND}`, got `{}`", self.kind),
            });
        }
        let bad = |what: &str, v: f64| BuildError::Component {
            component: "wang-hybrid".into(),
            message: format!("`{what}` = {v} must be finite and > 0"),
        };
        for (what, v) in [
            ("pump_line_volume", self.pump_line_volume),
            ("bulk_modulus", self.bulk_modulus),
            ("mass", self.mass),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(what, v));
            }
        }
        for (what, v) in [
            ("external_force", self.external_force),
            ("tank_pressure", self.tank_pressure),
            ("vapour_pressure", self.vapour_pressure),
            ("initial_position", self.initial_position),
        ] {
            if !v.is_finite() {
                return Err(BuildError::Component {
                    component: "wang-hybrid".into(),
                    message: format!("`{what}` = {v} must be finite"),
                });
            }
        }
        if let Some((which, why)) =
            crate::rig::gauge_pressure_problem(self.tank_pressure, self.vapour_pressure)
        {
            let (field, value) = match which {
                crate::rig::GaugePressure::Tank => ("tank_pressure", self.tank_pressure),
                crate::rig::GaugePressure::Vapour => ("vapour_pressure", self.vapour_pressure),
            };
            return Err(BuildError::Component {
                component: "wang-hybrid".into(),
                message: format!("`{field}` = {value} Pa {why}"),
            });
        }
        self.friction
            .validate()
            .map_err(|e| BuildError::Component {
                component: "friction".into(),
                message: e.to_string(),
            })?;
        self.cylinder
            .validate()
            .map_err(|e| BuildError::Component {
                component: "cylinder".into(),
                message: e.to_string(),
            })?;
        self.four_way.validate().map_err(|e| BuildError::Component {
            component: "four_way".into(),
            message: e.to_string(),
        })
    }

    /// The assembled circuit driven by `command` \[V\]: the netlist of
    /// [`WangHybrid::to_netlist`].
    pub fn build(&self, command: Signal) -> Result<Circuit, RigError> {
        crate::netlist::assemble(&crate::netlist::schematic(&self.to_netlist()?)?, command)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preset_matches_rigs_md() {
        let r = WangHybrid::preset();
        assert_eq!(r.pump.gain, 1.07e-5);
        assert_eq!(r.pump.natural_frequency, 47.62);
        assert_eq!(r.pump.damping, 0.64);
        assert_eq!(r.pump_line_volume, 3.5628e-5);
        assert_eq!(r.relief_pilot.kv, 8.2864e-8);
        assert_eq!(r.relief_pilot.cracking.si(), 10.34e5);
        assert_eq!(r.relief_safety.cracking.si(), 200e5);
        assert_eq!(r.four_way.k_p, 1.0644e-6);
        assert_eq!(r.four_way.k_t, 1.3730e-6);
        assert_eq!(r.needle.area.si(), 4.0e-6);
        assert_eq!(r.needle.orifice.cd, 0.65);
        assert_eq!(r.needle.orifice.density.si(), 900.0);
        assert_eq!(r.cylinder.area_1.si(), 8.042e-4);
        assert_eq!(r.cylinder.area_2.si(), 5.50e-4);
        assert_eq!(r.mass, 20.0);
        assert!(r.validate().is_ok());
    }

    #[test]
    fn the_preset_as_a_netlist_is_the_fixture_file() {
        let file: serde_json::Value = serde_json::from_str(netlist::CIRCUIT).unwrap();
        assert_eq!(WangHybrid::preset().to_netlist().unwrap(), file);
    }

    #[test]
    fn fixture_file_is_the_preset() {
        let text = include_str!("../../../../fixtures/rigs/wang-hybrid.json");
        let r = WangHybrid::from_json(text).unwrap();
        assert_eq!(r, WangHybrid::preset());
    }

    #[test]
    fn builds_and_names_its_parts() {
        let c = WangHybrid::preset()
            .build(Signal::Constant { value: 1.0 })
            .unwrap();
        assert_eq!(c.n_states(), 2 + 1 + 1 + 2 + 2 + 1);
        let names: Vec<String> = c.probes().into_iter().map(|p| p.name).collect();
        for n in [
            "command",
            "pump_flow",
            "pp1",
            "pp2",
            "p1",
            "p2",
            "position",
            "velocity",
            "pilot_spool",
        ] {
            assert!(names.iter().any(|m| m == n), "{n} missing from {names:?}");
        }
    }

    #[test]
    fn rejects_bad_rig_files() {
        let e = WangHybrid::from_json("{\"pump\": 3}").unwrap_err();
        assert!(e.to_string().contains("line 1"), "{e}");
        let mut v = serde_json::to_value(WangHybrid::preset()).unwrap();
        v["kind"] = serde_json::Value::from("valve-cylinder");
        assert!(WangHybrid::from_value(&v)
            .unwrap_err()
            .to_string()
            .contains("kind"));
        let mut r = WangHybrid::preset();
        r.pump_line_volume = -1.0;
        assert!(r
            .build(Signal::Constant { value: 0.0 })
            .unwrap_err()
            .to_string()
            .contains("pump_line_volume"));
        let mut r = WangHybrid::preset();
        r.relief_pilot.full_open = Pressure::new(1.0);
        assert!(r.build(Signal::Constant { value: 0.0 }).is_err());
        // pressures below absolute vacuum, vapour above the tank, Cd above 1
        for (field, value) in [
            ("tank_pressure", -2.0e5),
            ("vapour_pressure", -2.0e5),
            ("vapour_pressure", 1.0e6),
        ] {
            let mut r = WangHybrid::preset();
            match field {
                "tank_pressure" => r.tank_pressure = value,
                _ => r.vapour_pressure = value,
            }
            let e = r.build(Signal::Constant { value: 0.0 }).unwrap_err();
            assert!(e.to_string().contains(field), "{field}={value}: {e}");
        }
        let mut r = WangHybrid::preset();
        r.needle.orifice.cd = 1.5;
        let e = r.build(Signal::Constant { value: 0.0 }).unwrap_err();
        assert!(e.to_string().contains("needle_valve.orifice.cd"), "{e}");
    }
}
