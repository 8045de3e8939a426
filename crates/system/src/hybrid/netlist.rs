//! The `hybrid-pump` rig as a netlist and back: its topology lives in the
//! netlist file `fixtures/rigs/wang-hybrid.json`, not in code.
//! [`WangHybrid::to_netlist`] fills it with the rig's values;
//! [`WangHybrid::from_netlist`] reads them back from a netlist of that
//! circuit (the typed view the chapter-7 and chapter-8 studies work on).

use super::{WangHybrid, KIND};
use crate::netlist::{self, registry::Instance};
use crate::rig::RigError;
use hydrocyl_actuator::{Cylinder, EntrainedAir};
use hydrocyl_ports::{Area, Position, Pressure};
use serde_json::{json, Value};

/// The hybrid circuit (the `wang-hybrid` preset).
pub const CIRCUIT: &str = include_str!("../../../../fixtures/rigs/wang-hybrid.json");

/// A law as a netlist component object of type `ty`.
fn component<T: serde::Serialize>(ty: &str, law: &T) -> Value {
    let mut v = serde_json::to_value(law).expect("a law serialises");
    v.as_object_mut()
        .expect("a law is an object")
        .insert("type".into(), Value::from(ty));
    v
}

/// The preset circuit's schematic: the reference [`WangHybrid::from_netlist`]
/// checks a netlist against (its components by name and type, and which of
/// their ports are joined), so that the topology is written once, in the file.
fn reference() -> netlist::Schematic {
    let v: Value =
        serde_json::from_str(CIRCUIT).expect("the embedded netlist is valid JSON (tested)");
    netlist::read(&v).expect("the embedded netlist reads (tested)")
}

/// Whether an instance of type `actual` may stand where the preset has
/// `wanted`: the same type, or any friction law for the preset's friction.
fn same_kind(wanted: &str, actual: &str) -> bool {
    wanted == actual || (wanted.starts_with("friction_") && actual.starts_with("friction_"))
}

/// A law from an instance's parameters under `prefix`.
fn typed<T: serde::de::DeserializeOwned>(i: &Instance, prefix: &str) -> Result<T, RigError> {
    i.law(prefix)
        .map_err(|e| bad(format!("components.{}", i.name), e))
}

fn bad(path: impl Into<String>, why: impl Into<String>) -> RigError {
    RigError::Invalid {
        path: path.into(),
        why: why.into(),
    }
}

impl WangHybrid {
    /// This rig as a netlist: the hybrid circuit with this rig's values
    /// (every volume starting at the tank pressure).
    pub fn to_netlist(&self) -> Result<Value, RigError> {
        self.validate()?;
        let mut v: Value =
            serde_json::from_str(CIRCUIT).expect("the embedded netlist is valid JSON (tested)");
        let c = &mut v["components"];
        let tank = self.tank_pressure;
        // the identified law into the file's pump, which keeps its rating
        // (displacement, maximum speed: Table 4-2)
        if let (Some(pump), Value::Object(law)) = (
            c["pump"].as_object_mut(),
            component("pump_identified", &self.pump),
        ) {
            pump.extend(law);
        }
        for line in ["line_1", "line_2"] {
            c[line] = json!({
                "type": "volume",
                "volume": self.pump_line_volume,
                "bulk_modulus": self.bulk_modulus,
                "initial": { "pressure": tank }
            });
        }
        let cyl = &self.cylinder;
        c["cylinder"] = json!({
            "type": "cylinder",
            "area_1": cyl.area_1.si(),
            "area_2": cyl.area_2.si(),
            "stroke": cyl.stroke.si(),
            "chamber_length_1": cyl.chamber_length_1.si(),
            "chamber_length_2": cyl.chamber_length_2.si(),
            "bulk_modulus": cyl.bulk_modulus.si(),
            "internal_leakage": cyl.internal_leakage,
            "external_leakage_1": cyl.external_leakage_1,
            "external_leakage_2": cyl.external_leakage_2,
            "cavitation_pressure": self.vapour_pressure,
            "initial": { "position": self.initial_position, "velocity": 0.0, "p1": tank, "p2": tank }
        });
        if !self.entrained_air.is_none() {
            let a = &self.entrained_air;
            for v in ["line_1", "line_2", "cylinder"] {
                c[v]["air_fraction"] = json!(a.fraction);
                c[v]["polytropic_index"] = json!(a.polytropic_index);
                c[v]["atmospheric_pressure"] = json!(a.atmospheric_pressure);
            }
        }
        c["load"] = json!({
            "type": "mass",
            "mass": self.mass,
            "external_force": self.external_force
        });
        let (friction, dp_max) = crate::valve_netlist::friction_component(&self.friction);
        c["friction"] = friction;
        // the bounds of Wang's own seal term (0 = the thesis's unbounded form /
        // the common bound)
        for (key, b) in ["dp_max", "dp_max_extend", "dp_max_retract"]
            .iter()
            .zip(dp_max)
        {
            if b > 0.0 {
                c["friction"]["seal"][*key] = json!(b);
            }
        }
        c["tank"] = json!({ "type": "pressure_source", "pressure": tank });
        for r in ["relief_1", "relief_2"] {
            c[r] = component("relief_valve", &self.relief_pilot);
        }
        for r in ["relief_3_line_1", "relief_3_line_2"] {
            c[r] = component("relief_valve", &self.relief_safety);
        }
        for k in ["check_1", "check_2"] {
            c[k] = component("check_valve", &self.check);
        }
        c["pilot_valve"] = component("pilot_valve", &self.four_way);
        c["needle_valve"] = component("needle_valve", &self.needle);
        Ok(v)
    }

    /// The rig a netlist of the hybrid circuit describes (the components and
    /// wiring of the `wang-hybrid` preset; relief valves 1/2, 3 and the
    /// check valves each pairwise equal). Another circuit is refused, naming
    /// what differs.
    pub fn from_netlist(v: &Value) -> Result<WangHybrid, RigError> {
        let s = netlist::read(v)?;
        let preset = reference();
        if let Some(extra) = s
            .instances
            .iter()
            .find(|i| preset.instance(&i.name).is_none())
        {
            return Err(bad(
                format!("components.{}", extra.name),
                "is not part of the hybrid circuit this study works on (the wang-hybrid preset's components)",
            ));
        }
        let get = |name: &str| -> Result<&Instance, RigError> {
            let ty = preset.instance(name).map_or("", |i| i.ty.name);
            let i = s.instance(name).ok_or_else(|| {
                bad(
                    "components",
                    format!("the hybrid circuit has a component `{name}` ({ty})"),
                )
            })?;
            if !same_kind(ty, i.ty.name) {
                return Err(bad(
                    format!("components.{name}.type"),
                    format!("is `{}`; the hybrid circuit needs `{ty}`", i.ty.name),
                ));
            }
            Ok(i)
        };
        for i in &preset.instances {
            get(&i.name)?;
        }
        // every pair of ports the preset joins must be joined here: each port
        // against the first port of its node in the preset
        let mut first: Vec<(&str, &str, &str)> = Vec::new(); // (node, component, port)
        for i in &preset.instances {
            for (port, node) in &i.nodes {
                match first.iter().find(|(n, _, _)| n == node) {
                    None => first.push((node, &i.name, port)),
                    Some(&(_, c0, p0)) => {
                        let n0 = get(c0)?.node(p0);
                        if n0.is_empty() || get(&i.name)?.node(port) != n0 {
                            return Err(bad("connections", format!("`{c0}.{p0}` and `{}.{port}` must be joined for the hybrid circuit this study works on", i.name)));
                        }
                    }
                }
            }
        }
        for (a, b) in [
            ("relief_1", "relief_2"),
            ("relief_3_line_1", "relief_3_line_2"),
            ("check_1", "check_2"),
            ("line_1", "line_2"),
        ] {
            if get(a)?.params != get(b)?.params {
                return Err(bad(
                    format!("components.{b}"),
                    format!("differs from `{a}`; the hybrid rig's studies take them equal"),
                ));
            }
        }
        let cyl = get("cylinder")?;
        let load = get("load")?;
        let friction = get("friction")?;
        let tank = get("tank")?.get("pressure");
        let line = get("line_1")?;
        let air = |i: &Instance| EntrainedAir {
            fraction: i.get("air_fraction"),
            polytropic_index: i.get("polytropic_index"),
            atmospheric_pressure: i.get("atmospheric_pressure"),
        };
        let entrained_air = air(line);
        if air(cyl) != entrained_air {
            return Err(bad(
                "components.cylinder.air_fraction",
                "differs from the pump lines' entrained air; the hybrid rig's studies take one fluid in every volume",
            ));
        }
        let r = WangHybrid {
            kind: KIND.into(),
            pump: typed(get("pump")?, "")?,
            pump_line_volume: line.get("volume"),
            bulk_modulus: line.get("bulk_modulus"),
            relief_pilot: typed(get("relief_1")?, "")?,
            relief_safety: typed(get("relief_3_line_1")?, "")?,
            check: typed(get("check_1")?, "")?,
            four_way: typed(get("pilot_valve")?, "")?,
            needle: typed(get("needle_valve")?, "")?,
            cylinder: Cylinder {
                area_1: Area::new(cyl.get("area_1")),
                area_2: Area::new(cyl.get("area_2")),
                stroke: Position::new(cyl.get("stroke")),
                chamber_length_1: Position::new(cyl.get("chamber_length_1")),
                chamber_length_2: Position::new(cyl.get("chamber_length_2")),
                bulk_modulus: Pressure::new(cyl.get("bulk_modulus")),
                internal_leakage: cyl.get("internal_leakage"),
                external_leakage_1: cyl.get("external_leakage_1"),
                external_leakage_2: cyl.get("external_leakage_2"),
            },
            mass: load.get("mass"),
            external_force: load.get("external_force"),
            friction: netlist::typed_view_friction_law(friction)
                .expect("a friction_* type")
                .map_err(|e| bad("components.friction", e))?,
            tank_pressure: tank,
            vapour_pressure: cyl.get("cavitation_pressure"),
            initial_position: cyl
                .initial("position")
                .or_else(|| load.initial("position"))
                .unwrap_or(0.0),
            entrained_air,
        };
        // the rig starts at rest with every volume at the tank pressure
        for (name, state) in [
            ("cylinder", "p1"),
            ("cylinder", "p2"),
            ("line_1", "pressure"),
            ("line_2", "pressure"),
        ] {
            if get(name)?.initial(state).is_some_and(|p| p != tank) {
                return Err(bad(
                    format!("components.{name}.initial.{state}"),
                    "the hybrid rig's studies start with every volume at the tank pressure",
                ));
            }
        }
        r.validate()?;
        Ok(r)
    }
}
