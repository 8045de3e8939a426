//! Initial chamber pressures left out of a netlist: the steady state at
//! rest of the valve-controlled drive the cylinder is in (section 3.3.4,
//! [`steady_pressures_at_rest`]), found from the circuit's topology — the
//! four-way valve on the cylinder's chambers, the pressure sources on its
//! supply and tank ports, the spool feeding it, and the mass and friction on
//! the rod.

use super::catalog::{cylinder_of, friction_law_of, friction_terms_of, metering_of};
use super::reader::{NetlistError, Schematic};
use super::registry::{error_path, Instance, Role};
use crate::valve_rig::{steady_pressures_at_rest, SteadyDrive};
use hydrocyl_friction::{FrictionInput, FrictionModel, WithSealTerms};
use hydrocyl_ports::{Pressure, Velocity};

/// The instance that owns node `node`.
fn owner<'a>(s: &'a Schematic, node: &str) -> Option<&'a Instance> {
    s.instances.iter().find(|i| {
        i.nodes
            .iter()
            .any(|(p, n)| n == node && i.ty.port(p).is_some_and(|ps| ps.role == Role::Owns))
    })
}

/// A builder's error about `inst` ([`error_path`]: at the parameter it
/// names, else at the component).
fn refused(inst: &Instance) -> impl Fn(String) -> NetlistError + '_ {
    |message| {
        let (path, why) = error_path(&inst.name, message);
        NetlistError { path, why }
    }
}

fn fail<T>(inst: &Instance, state: &str, why: &str) -> Result<T, NetlistError> {
    Err(NetlistError {
        path: format!("components.{}.initial.{state}", inst.name),
        why: format!("not given, and {why}: give it"),
    })
}

/// The steady drive around the metering instance `valve` feeding `cyl`.
fn drive(
    s: &Schematic,
    valve: &Instance,
    cyl: &Instance,
    state: &str,
) -> Result<(f64, f64), NetlistError> {
    let source = |port: &str| {
        owner(s, valve.node(port))
            .filter(|o| o.ty.name == "pressure_source")
            .map(|o| (o.get("pressure"), o.name.as_str()))
    };
    let (Some((supply, p_source)), Some((tank, t_source))) = (source("P"), source("T")) else {
        return fail(cyl, state, "the valve's P and T ports are not on pressure sources, so there is no steady state at rest to start from");
    };
    // the cause, where it was given: the tank at or above the supply
    if tank >= supply {
        return Err(NetlistError {
            path: format!("components.{t_source}.pressure"),
            why: format!(
                "the tank pressure {tank} Pa (on the T port of `{}`) is not below the supply pressure {supply} Pa (components.{p_source}.pressure, on its P port): with no pressure drop across the valve there is no steady state at rest to start components.{}.initial.{state} from; give the tank a pressure below the supply",
                valve.name, cyl.name
            ),
        });
    }
    let spool = owner(s, valve.node("spool"))
        .and_then(|o| o.initial("position"))
        .unwrap_or(0.0);
    let rod = cyl.node("rod");
    let mass = owner(s, rod);
    let external = mass.map(|m| m.get("external_force")).unwrap_or(0.0);
    let v0 = mass
        .and_then(|m| {
            m.initial("velocity")
                .or_else(|| m.hint("rod", "initial.velocity"))
        })
        .unwrap_or(0.0);
    let mut friction = 0.0;
    for f in s.instances.iter().filter(|i| i.node("rod") == rod) {
        if let Some(law) = friction_law_of(f) {
            let law = law.map_err(refused(f))?;
            let model = WithSealTerms {
                inner: law,
                terms: friction_terms_of(f),
            };
            friction += model
                .steady_force(&FrictionInput::at_velocity(Velocity::new(v0)))
                .si();
        }
    }
    let d = SteadyDrive {
        metering: metering_of(valve).map_err(refused(valve))?,
        cylinder: cylinder_of(cyl).map_err(refused(cyl))?,
        supply,
        tank,
        droop_resistance: valve.opt("supply_resistance").unwrap_or(0.0),
        spool,
        load: external + friction,
    };
    steady_pressures_at_rest(&d).map_err(|why| NetlistError {
        path: format!("components.{}.initial.{state}", cyl.name),
        why,
    })
}

/// Fills every cylinder's absent initial chamber pressures (and a
/// generalised cylinder's load pressure) with the steady state at rest.
pub fn fill(s: &mut Schematic) -> Result<(), NetlistError> {
    for k in 0..s.instances.len() {
        let inst = &s.instances[k];
        match inst.ty.name {
            "cylinder" if inst.initial("p1").is_none() || inst.initial("p2").is_none() => {
                let state = if inst.initial("p1").is_none() {
                    "p1"
                } else {
                    "p2"
                };
                let Some(valve) = s.instances.iter().find(|v| {
                    v.ty.name == "four_way_valve"
                        && v.node("A") == inst.node("A")
                        && v.node("B") == inst.node("B")
                }) else {
                    return fail(inst, state, "no four-way valve feeds this cylinder's chambers A and B, so there is no steady state at rest to start from");
                };
                let (p1, p2) = drive(s, valve, inst, state)?;
                let inst = &mut s.instances[k];
                for (name, p) in [("p1", p1), ("p2", p2)] {
                    let e = inst.initial.entry(name.to_string()).or_insert(None);
                    if e.is_none() {
                        *e = Some(p);
                    }
                }
            }
            "generalised_cylinder" if inst.initial("load_pressure").is_none() => {
                let (p1, p2) = drive(s, inst, inst, "load_pressure")?;
                let c = cylinder_of(inst).map_err(refused(inst))?;
                let p_le =
                    c.force(Pressure::new(p1), Pressure::new(p2)).si() / c.effective_area().si();
                s.instances[k]
                    .initial
                    .insert("load_pressure".into(), Some(p_le));
            }
            _ => {}
        }
    }
    Ok(())
}
