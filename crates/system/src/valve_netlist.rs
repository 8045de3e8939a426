//! The `valve-cylinder` rig as a netlist and back: its topology lives in the
//! netlist files `fixtures/rigs/leaney-moog.json` (fundamental form) and
//! `fixtures/rigs/leaney-moog-generalised.json` (generalised form), not in
//! code. [`ValveRig::to_netlist`] fills one of them with the rig's values;
//! [`ValveRig::from_netlist`] reads the values back from a netlist of that
//! circuit (the typed view the diagnosis and the energy studies work on).

use crate::netlist::{self, registry::Instance, Schematic};
use crate::rig::RigError;
use crate::valve_rig::{
    ControllerSpec, CylinderSpec, FluidSpec, Formulation, InitialSpec, LoadSpec, SensorSpec,
    SupplySpec, ValveRig, ValveSpec, KIND,
};
use hydrocyl_friction::FrictionLaw;
use hydrocyl_valves::servovalve::SpoolDynamics;
use serde_json::{json, Value};

/// The fundamental-form circuit (the `leaney-moog` preset).
pub const FUNDAMENTAL: &str = include_str!("../../../fixtures/rigs/leaney-moog.json");
/// The generalised-form circuit (the `leaney-moog-generalised` preset).
pub const GENERALISED: &str = include_str!("../../../fixtures/rigs/leaney-moog-generalised.json");
/// The fundamental-form circuit in closed loop (the `leaney-moog-closed-loop`
/// preset): a `position_controller` between the reference input and the spool.
pub const CLOSED_LOOP: &str = include_str!("../../../fixtures/rigs/leaney-moog-closed-loop.json");

/// Pressure sensors on a valve-cylinder circuit's chambers, as an overlay
/// ([`netlist::overlay`]): `sensor_A`, `sensor_B` read `cylinder.A`,
/// `cylinder.B`; the outputs `p1`, `p2` become their readings and the
/// chamber pressures `p1_chamber`, `p2_chamber`.
pub const CHAMBER_SENSORS: &str =
    include_str!("../../../fixtures/legacy/circuits/chamber-sensors.json");

fn template(text: &str) -> Value {
    serde_json::from_str(text).expect("the embedded netlist is valid JSON (tested)")
}

/// A friction law as a netlist component object (`friction_<model>`), and
/// the bounds of its seal term `[common, extending, retracting]` (Wang's
/// `seal_dp_max*`, which the netlist names `seal.dp_max*`; 0 = unbounded /
/// the common one).
pub(crate) fn friction_component(law: &FrictionLaw) -> (Value, [f64; 3]) {
    let mut v = serde_json::to_value(law).expect("a friction law serialises");
    let obj = v.as_object_mut().expect("a tagged object");
    obj.remove("model");
    let mut take = |k: &str| obj.remove(k).and_then(|b| b.as_f64()).unwrap_or(0.0);
    let bound = [
        take("seal_dp_max"),
        take("seal_dp_max_extend"),
        take("seal_dp_max_retract"),
    ];
    let mut out = serde_json::Map::new();
    out.insert(
        "type".into(),
        Value::from(format!("friction_{}", law.name().replace('-', "_"))),
    );
    out.extend(obj.clone());
    (Value::Object(out), bound)
}

impl ValveRig {
    /// This rig as a netlist: the fundamental or generalised circuit with
    /// this rig's values (initial pressures written out as the rig computes
    /// them), plus pressure sensors on the chambers when they lag.
    pub fn to_netlist(&self) -> Result<Value, RigError> {
        self.validate()?;
        let fundamental = self.cylinder.formulation == Formulation::Fundamental;
        let mut v = template(if fundamental {
            FUNDAMENTAL
        } else {
            GENERALISED
        });
        v["name"] = Value::from(self.name.clone());
        v["description"] = Value::from(self.description.clone());
        let (p1, p2) = self.initial_pressures()?;
        // the optional parts first, so that the rig's values set below
        // hold whatever the overlays bring
        let tau = self.sensors.pressure_lag_s;
        if tau > 0.0 {
            netlist::overlay::overlay(&mut v, &template(CHAMBER_SENSORS))?;
            for (name, p0) in [("sensor_A", p1), ("sensor_B", p2)] {
                netlist::set(&mut v, &format!("{name}.time_constant"), Value::from(tau))?;
                netlist::set(&mut v, &format!("{name}.initial.reading"), Value::from(p0))?;
            }
        }
        if let Some(c) = &self.controller {
            // the loop the `leaney-moog-closed-loop` preset closes around
            // `leaney-moog`, closed here around this rig's circuit (before
            // the rig's values are set: tested to touch only the command,
            // the reference and the controller)
            let closing =
                netlist::overlay::difference(&template(FUNDAMENTAL), &template(CLOSED_LOOP))?;
            netlist::overlay::overlay(&mut v, &closing)?;
            for (k, x) in [
                ("gain", c.gain_per_m),
                ("integral_time", c.integral_time_s),
                ("bias", c.bias),
                ("output_min", c.output_min),
                ("output_max", c.output_max),
            ] {
                netlist::set(&mut v, &format!("controller.{k}"), Value::from(x))?;
            }
        }
        let (va, c, s, i) = (&self.valve, &self.cylinder, &self.supply, &self.initial);
        let metering = if fundamental { "valve" } else { "cylinder" };
        let mut sets: Vec<(String, f64)> = vec![
            ("supply.pressure".into(), s.pressure_pa),
            ("tank.pressure".into(), s.tank_pressure_pa),
            ("cylinder.area_1".into(), c.area_1_m2),
            ("cylinder.area_2".into(), c.area_2_m2),
            ("cylinder.stroke".into(), c.stroke_m),
            ("cylinder.chamber_length_1".into(), c.chamber_length_1_m),
            ("cylinder.chamber_length_2".into(), c.chamber_length_2_m),
            ("cylinder.bulk_modulus".into(), self.fluid.bulk_modulus_pa),
            (
                "cylinder.internal_leakage".into(),
                c.internal_leakage_m3_per_s_pa,
            ),
            (
                "cylinder.external_leakage_1".into(),
                c.external_leakage_1_m3_per_s_pa,
            ),
            (
                "cylinder.external_leakage_2".into(),
                c.external_leakage_2_m3_per_s_pa,
            ),
            (
                "cylinder.cavitation_pressure".into(),
                c.cavitation_pressure_pa,
            ),
            ("cylinder.initial.position".into(), i.position),
            ("cylinder.initial.velocity".into(), i.velocity),
            ("load.mass".into(), self.load.mass_kg),
            ("load.external_force".into(), self.load.external_force_n),
        ];
        for (k, x) in [
            ("underlap", va.underlap_m),
            ("spool_diameter", va.spool_diameter_m),
            ("orifice.cd", va.discharge_coefficient),
            ("orifice.density", self.fluid.density_kg_per_m3),
            ("orifice.dp_transition", va.regularisation_pa),
            ("null_bias", va.null_bias_m),
            ("flow_gain", va.flow_gain),
        ] {
            sets.push((format!("{metering}.{k}"), x));
        }
        if fundamental {
            sets.push((
                "valve.supply_resistance".into(),
                s.droop_resistance_pa_s_per_m3,
            ));
            sets.push(("valve.dead_band".into(), va.dead_band_m));
            sets.push(("cylinder.initial.p1".into(), p1));
            sets.push(("cylinder.initial.p2".into(), p2));
        } else {
            if s.droop_resistance_pa_s_per_m3 > 0.0 {
                return Err(RigError::Invalid {
                    path: "supply.droop_resistance_pa_s_per_m3".into(),
                    why: "supply droop needs the `fundamental` formulation".into(),
                });
            }
            if va.dead_band_m > 0.0 {
                return Err(RigError::Invalid {
                    path: "valve.dead_band_m".into(),
                    why: "a valve dead band needs the `fundamental` formulation".into(),
                });
            }
            let tol = match c.formulation {
                Formulation::GeneralisedNumerical => c.x_tolerance,
                _ => 0.0,
            };
            sets.push(("cylinder.x_tolerance".into(), tol));
            let cyl = self.cylinder_model();
            let p_le = cyl
                .force(
                    hydrocyl_ports::Pressure::new(p1),
                    hydrocyl_ports::Pressure::new(p2),
                )
                .si()
                / cyl.effective_area().si();
            sets.push(("cylinder.initial.load_pressure".into(), p_le));
        }
        v["components"]["spool"] = match va.dynamics {
            SpoolDynamics::First { time_constant_s } => json!({
                "type": "servo_spool_first_order",
                "stroke": va.stroke_m,
                "time_constant": time_constant_s,
                "initial": { "position": i.spool }
            }),
            SpoolDynamics::Second {
                natural_frequency_rad_per_s,
                damping_ratio,
            } => json!({
                "type": "servo_spool_second_order",
                "stroke": va.stroke_m,
                "natural_frequency": natural_frequency_rad_per_s,
                "damping_ratio": damping_ratio,
                "initial": { "position": i.spool }
            }),
        };
        let (friction, bound) = friction_component(&self.friction);
        v["components"]["friction"] = friction;
        let t = self.friction_terms;
        sets.push(("friction.seal.k_pressure".into(), t.k_pressure));
        sets.push(("friction.seal.h_acceleration".into(), t.h_acceleration));
        // one set of bounds for every seal term of the component
        sets.push(("friction.seal.dp_max".into(), t.dp_max.max(bound[0])));
        let (ext, ret) = (
            t.dp_max_extend.max(bound[1]),
            t.dp_max_retract.max(bound[2]),
        );
        if ext > 0.0 {
            sets.push(("friction.seal.dp_max_extend".into(), ext));
        }
        if ret > 0.0 {
            sets.push(("friction.seal.dp_max_retract".into(), ret));
        }
        for (path, x) in sets {
            netlist::set(&mut v, &path, Value::from(x))?;
        }
        Ok(v)
    }

    /// The rig a netlist of the valve-cylinder circuit describes: the
    /// components `supply`, `tank`, `command`, `spool`, `valve` (fundamental
    /// form), `cylinder`, `load`, `friction` (and optional chamber pressure
    /// sensors `sensor_A`, `sensor_B`), wired as in the `leaney-moog` preset;
    /// or in closed loop, `reference` and `controller` in place of `command`
    /// (wired as in `leaney-moog-closed-loop`).
    /// Another circuit is refused, naming what differs.
    pub fn from_netlist(v: &Value) -> Result<ValveRig, RigError> {
        let s = netlist::read(v)?;
        let bad = |path: &str, why: String| RigError::Invalid {
            path: path.to_string(),
            why,
        };
        let get = |name: &str, types: &[&str]| -> Result<&Instance, RigError> {
            let i = s.instance(name).ok_or_else(|| {
                bad(
                    "components",
                    format!(
                        "a valve-cylinder circuit has a component `{name}` ({})",
                        types.join(" or ")
                    ),
                )
            })?;
            if !types.iter().any(|t| {
                i.ty.name == *t || (t.ends_with('*') && i.ty.name.starts_with(&t[..t.len() - 1]))
            }) {
                return Err(bad(
                    &format!("components.{name}.type"),
                    format!(
                        "is `{}`; the valve-cylinder circuit needs {}",
                        i.ty.name,
                        types.join(" or ")
                    ),
                ));
            }
            Ok(i)
        };
        let cyl = get("cylinder", &["cylinder", "generalised_cylinder"])?;
        let fundamental = cyl.ty.name == "cylinder";
        let known = [
            "supply",
            "tank",
            "command",
            "spool",
            "valve",
            "cylinder",
            "load",
            "friction",
            "sensor_A",
            "sensor_B",
            "reference",
            "controller",
        ];
        if let Some(extra) = s
            .instances
            .iter()
            .find(|i| !known.contains(&i.name.as_str()))
        {
            return Err(bad(
                &format!("components.{}", extra.name),
                "is not part of the valve-cylinder circuit that this study works on (components supply, tank, command, spool, valve, cylinder, load, friction)".into(),
            ));
        }
        let supply = get("supply", &["pressure_source"])?;
        let tank = get("tank", &["pressure_source"])?;
        let closed = s.instance("controller").is_some();
        let controller = if closed {
            get("reference", &["command_input"])?;
            let c = get("controller", &["position_controller"])?;
            Some(ControllerSpec {
                gain_per_m: c.get("gain"),
                integral_time_s: c.get("integral_time"),
                bias: c.get("bias"),
                output_min: c.get("output_min"),
                output_max: c.get("output_max"),
            })
        } else {
            get("command", &["command_input"])?;
            None
        };
        let spool = get("spool", &["servo_spool_*"])?;
        let load = get("load", &["mass"])?;
        let friction = get("friction", &["friction_*"])?;
        let metering = if fundamental {
            get("valve", &["four_way_valve"])?
        } else {
            cyl
        };
        wired_as_the_preset(&s, fundamental, closed)?;
        let law = crate::netlist::typed_view_friction_law(friction)
            .expect("a friction_* type")
            .map_err(|why| bad(&format!("components.{}", friction.name), why))?;
        let lag = match (s.instance("sensor_A"), s.instance("sensor_B")) {
            (None, None) => 0.0,
            (Some(a), Some(b)) if a.get("time_constant") == b.get("time_constant") => {
                a.get("time_constant")
            }
            _ => {
                return Err(bad(
                    "components.sensor_A",
                    "both chambers' sensors, with one time constant, or none".into(),
                ))
            }
        };
        let dynamics = if spool.ty.name == "servo_spool_first_order" {
            SpoolDynamics::First {
                time_constant_s: spool.get("time_constant"),
            }
        } else {
            SpoolDynamics::Second {
                natural_frequency_rad_per_s: spool.get("natural_frequency"),
                damping_ratio: spool.get("damping_ratio"),
            }
        };
        let tol = cyl.opt("x_tolerance").unwrap_or(0.0);
        let formulation = match (fundamental, tol > 0.0) {
            (true, _) => Formulation::Fundamental,
            (false, true) => Formulation::GeneralisedNumerical,
            (false, false) => Formulation::GeneralisedAnalytical,
        };
        let motion = |k: &str| cyl.initial(k).or_else(|| load.initial(k)).unwrap_or(0.0);
        let r = ValveRig {
            kind: KIND.into(),
            name: s.name.clone(),
            description: v
                .get("description")
                .and_then(Value::as_str)
                .unwrap_or_default()
                .to_string(),
            fluid: FluidSpec {
                density_kg_per_m3: metering.get("orifice.density"),
                bulk_modulus_pa: cyl.get("bulk_modulus"),
            },
            supply: SupplySpec {
                pressure_pa: supply.get("pressure"),
                tank_pressure_pa: tank.get("pressure"),
                droop_resistance_pa_s_per_m3: metering.opt("supply_resistance").unwrap_or(0.0),
            },
            valve: ValveSpec {
                stroke_m: spool.get("stroke"),
                underlap_m: metering.get("underlap"),
                spool_diameter_m: metering.get("spool_diameter"),
                discharge_coefficient: metering.get("orifice.cd"),
                regularisation_pa: metering.get("orifice.dp_transition"),
                null_bias_m: metering.get("null_bias"),
                flow_gain: metering.get("flow_gain"),
                dead_band_m: metering.opt("dead_band").unwrap_or(0.0),
                dynamics,
            },
            cylinder: CylinderSpec {
                area_1_m2: cyl.get("area_1"),
                area_2_m2: cyl.get("area_2"),
                stroke_m: cyl.get("stroke"),
                chamber_length_1_m: cyl.get("chamber_length_1"),
                chamber_length_2_m: cyl.get("chamber_length_2"),
                internal_leakage_m3_per_s_pa: cyl.get("internal_leakage"),
                external_leakage_1_m3_per_s_pa: cyl.get("external_leakage_1"),
                external_leakage_2_m3_per_s_pa: cyl.get("external_leakage_2"),
                cavitation_pressure_pa: cyl.get("cavitation_pressure"),
                formulation,
                x_tolerance: if tol > 0.0 { tol } else { 1e-12 },
            },
            load: LoadSpec {
                mass_kg: load.get("mass"),
                external_force_n: load.get("external_force"),
            },
            friction: law,
            friction_terms: crate::netlist::catalog_friction_terms(friction),
            initial: InitialSpec {
                position: motion("position"),
                velocity: motion("velocity"),
                spool: spool.initial("position").unwrap_or(0.0),
                p1: if fundamental { cyl.initial("p1") } else { None },
                p2: if fundamental { cyl.initial("p2") } else { None },
            },
            sensors: SensorSpec {
                pressure_lag_s: lag,
            },
            controller,
        };
        r.validate()?;
        Ok(r)
    }
}

/// Checks that the netlist joins the ports as the preset's circuit does.
fn wired_as_the_preset(s: &Schematic, fundamental: bool, closed: bool) -> Result<(), RigError> {
    let meter = if fundamental { "valve" } else { "cylinder" };
    let mut same: Vec<[(&str, &str); 2]> = if closed {
        vec![
            [("reference", "out"), ("controller", "reference")],
            [("controller", "command"), ("spool", "command")],
            [("controller", "rod"), ("load", "rod")],
        ]
    } else {
        vec![[("command", "out"), ("spool", "command")]]
    };
    same.extend([
        [("spool", "spool"), (meter, "spool")],
        [("supply", "port"), (meter, "P")],
        [("tank", "port"), (meter, "T")],
        [("cylinder", "A"), ("friction", "A")],
        [("cylinder", "B"), ("friction", "B")],
        [("cylinder", "rod"), ("load", "rod")],
        [("cylinder", "rod"), ("friction", "rod")],
    ]);
    if fundamental {
        same.push([("valve", "A"), ("cylinder", "A")]);
        same.push([("valve", "B"), ("cylinder", "B")]);
    }
    for [(c1, p1), (c2, p2)] in same {
        let n1 = s.instance(c1).map(|i| i.node(p1)).unwrap_or("");
        let n2 = s.instance(c2).map(|i| i.node(p2)).unwrap_or("");
        if n1.is_empty() || n1 != n2 {
            return Err(RigError::Invalid {
                path: "connections".into(),
                why: format!(
                    "`{c1}.{p1}` and `{c2}.{p2}` must be joined for the valve-cylinder circuit this study works on"
                ),
            });
        }
    }
    Ok(())
}
