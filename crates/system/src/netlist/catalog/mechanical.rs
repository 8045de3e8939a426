//! The asymmetric cylinder in its two forms (eqs 2.10–2.15; the generalised
//! one-pressure form of eqs 2.16–2.26, 3.3–3.4) and the moving mass with its
//! end stops (eq 2.27).

use super::super::registry::{
    param, ComponentType, Default::*, Instance, ParamSpec, Range, Role, StateSpec,
};
use super::hydraulic::{air, AIR};
use super::servo::{metering, METERING};
use super::{built, join, port, HYD, MECH, SIG};
use crate::circuit::Component;
use crate::components::{CylinderNodes, GeneralisedCylinder, Mass, TwoChamberCylinder};
use hydrocyl_actuator::generalised::XMethod;
use hydrocyl_actuator::{Cylinder, StrokeEnds};
use hydrocyl_ports::{Area, Position, Pressure};

/// The cylinder's parameters (names of [`Cylinder`]'s fields) and the
/// reported cavitation pressure.
const CYLINDER: [ParamSpec; 10] = [
    param(
        "area_1",
        "m^2",
        Required,
        Range::POSITIVE,
        "cap-side piston area A1",
    )
    .typical(1e-7, 1.0),
    param(
        "area_2",
        "m^2",
        Required,
        Range::POSITIVE,
        "rod-side annulus area A2",
    )
    .typical(1e-7, 1.0),
    param(
        "stroke",
        "m",
        Required,
        Range::POSITIVE,
        "stroke; the piston moves in ±stroke/2 from mid-stroke",
    )
    .typical(1e-4, 20.0),
    param(
        "chamber_length_1",
        "m",
        Required,
        Range::POSITIVE,
        "V1 = A1 (l1 + x)",
    )
    .typical(1e-4, 20.0),
    param(
        "chamber_length_2",
        "m",
        Required,
        Range::POSITIVE,
        "V2 = A2 (l2 − x)",
    )
    .typical(1e-4, 20.0),
    param(
        "bulk_modulus",
        "Pa",
        Required,
        Range::POSITIVE,
        "effective bulk modulus B of the chambers",
    )
    .typical(5e7, 5e9),
    param(
        "internal_leakage",
        "m^3/(s Pa)",
        Value(0.0),
        Range::NON_NEGATIVE,
        "internal leakage coefficient Cl (A → B)",
    ),
    param(
        "external_leakage_1",
        "m^3/(s Pa)",
        Value(0.0),
        Range::NON_NEGATIVE,
        "external leakage coefficient of chamber 1",
    ),
    param(
        "external_leakage_2",
        "m^3/(s Pa)",
        Value(0.0),
        Range::NON_NEGATIVE,
        "external leakage coefficient of chamber 2",
    ),
    param(
        "cavitation_pressure",
        "Pa",
        Value(0.0),
        Range::GAUGE_PRESSURE,
        "chamber pressure below which cavitation is reported",
    ),
];

/// The two-chamber cylinder's parameters: [`CYLINDER`] and the chambers'
/// entrained air (the generalised form keeps the constant B).
const TWO_CHAMBER: [ParamSpec; 13] = join(CYLINDER, AIR);

pub(crate) fn cylinder(i: &Instance) -> Result<Cylinder, String> {
    let c = Cylinder {
        area_1: Area::new(i.get("area_1")),
        area_2: Area::new(i.get("area_2")),
        stroke: Position::new(i.get("stroke")),
        chamber_length_1: Position::new(i.get("chamber_length_1")),
        chamber_length_2: Position::new(i.get("chamber_length_2")),
        bulk_modulus: Pressure::new(i.get("bulk_modulus")),
        internal_leakage: i.get("internal_leakage"),
        external_leakage_1: i.get("external_leakage_1"),
        external_leakage_2: i.get("external_leakage_2"),
    };
    c.validate().map_err(|e| match e {
        // a chamber's length against the stroke: named at the length
        hydrocyl_actuator::ActuatorError::EmptyChamber { chamber, .. } => {
            crate::netlist::registry::error_at(
                &format!("components.{}.chamber_length_{chamber}", i.name),
                &e.to_string(),
            )
        }
        // the rod side against the cap side: named at the rod side's area
        hydrocyl_actuator::ActuatorError::AreaRatio { .. } => crate::netlist::registry::error_at(
            &format!("components.{}.area_2", i.name),
            &e.to_string(),
        ),
        e => e.to_string(),
    })?;
    Ok(c)
}

/// The rod's end stops and any initial motion given on the cylinder, for the
/// rod's owner (the mass).
fn rod_hints(i: &Instance) -> Vec<(&'static str, &'static str, f64)> {
    let s = i.get("stroke");
    let mut h = vec![("rod", "stop_min", -0.5 * s), ("rod", "stop_max", 0.5 * s)];
    if let Some(x) = i.initial("position") {
        h.push(("rod", "initial.position", x));
    }
    if let Some(v) = i.initial("velocity") {
        h.push(("rod", "initial.velocity", v));
    }
    h
}

const MOTION: [StateSpec; 2] = [
    StateSpec {
        name: "position",
        unit: "m",
        default: Absent,
        doc: "initial piston position from mid-stroke (given to the rod's mass)",
    },
    StateSpec {
        name: "velocity",
        unit: "m/s",
        default: Absent,
        doc: "initial piston velocity (given to the rod's mass)",
    },
];

const GENERALISED: [ParamSpec; 18] = join(
    join::<10, 7, 17>(CYLINDER, METERING),
    [param(
        "x_tolerance",
        "-",
        Value(0.0),
        Range::NON_NEGATIVE,
        "absolute tolerance of a bracketing X root; 0 = the exact analytical root",
    )],
);

fn generalised(i: &Instance) -> Result<Box<dyn Component>, String> {
    let p_le = i
        .initial("load_pressure")
        .ok_or("initial.load_pressure is required")?;
    let tol = i.get("x_tolerance");
    let x_method = if tol > 0.0 {
        XMethod::Numerical { tol }
    } else {
        XMethod::Analytical
    };
    let mut g = GeneralisedCylinder::new(
        &i.name,
        super::servo::four_way_nodes(i),
        i.node("rod"),
        cylinder(i)?,
        metering(i)?,
        x_method,
        p_le,
    );
    g.cavitation_pressure = i.get("cavitation_pressure");
    built(g)
}

/// The component types of this family.
pub const TYPES: &[ComponentType] = &[
    ComponentType {
        name: "cylinder",
        summary: "asymmetric (single-rod) cylinder: two chamber pressures, leakage, force on the rod (eqs 2.10–2.15)",
        ports: &[
            port("A", HYD, Role::Owns, false, "cap-side chamber (p1)"),
            port("B", HYD, Role::Owns, false, "rod-side chamber (p2)"),
            port("rod", MECH, Role::Reads, false, "the rod: + extending"),
        ],
        params: &TWO_CHAMBER,
        states: &[
            StateSpec { name: "p1", unit: "Pa", default: Absent, doc: "initial cap-side pressure (default: the steady state at rest of the valve feeding it, section 3.3.4)" },
            StateSpec { name: "p2", unit: "Pa", default: Absent, doc: "initial rod-side pressure (default: as p1)" },
            MOTION[0],
            MOTION[1],
        ],
        build: |i| {
            let (Some(p1), Some(p2)) = (i.initial("p1"), i.initial("p2")) else {
                return Err("initial.p1 and initial.p2 are needed".into());
            };
            let p = (p1, p2);
            let nodes = CylinderNodes {
                a: i.node("A"),
                b: i.node("B"),
                rod: i.node("rod"),
            };
            let mut c = TwoChamberCylinder::new(&i.name, nodes, cylinder(i)?, p);
            c.cavitation_pressure = i.get("cavitation_pressure");
            c.air = air(i);
            built(c)
        },
        hints: Some(rod_hints),
        probes: &[("p1", "Pa"), ("p2", "Pa"), ("p_le", "Pa")],
    },
    ComponentType {
        name: "generalised_cylinder",
        summary: "the generalised one-pressure actuator with the valve's metering merged in, Leaney's X factor (eqs 2.16–2.26, 3.3, 3.4)",
        ports: &[
            port("spool", SIG, Role::Reads, false, "spool position x_s [m]"),
            port("P", HYD, Role::Reads, false, "supply port"),
            port("T", HYD, Role::Reads, false, "tank port"),
            port("A", HYD, Role::Owns, false, "cap-side chamber (p1, algebraic)"),
            port("B", HYD, Role::Owns, false, "rod-side chamber (p2, algebraic)"),
            port("rod", MECH, Role::Reads, false, "the rod: + extending"),
        ],
        params: &GENERALISED,
        states: &[
            StateSpec { name: "load_pressure", unit: "Pa", default: Absent, doc: "initial load pressure P_LE (default: the steady state at rest, section 3.3.4)" },
            MOTION[0],
            MOTION[1],
        ],
        build: generalised,
        hints: Some(rod_hints),
        probes: &[("p1", "Pa"), ("p2", "Pa"), ("p_le", "Pa")],
    },
    ComponentType {
        name: "mass",
        summary: "the moving mass (piston, rod, load) with hard end stops: (m + Σc) a = ΣF − F_ext (eq 2.27)",
        ports: &[port("rod", MECH, Role::Owns, false, "the body it moves")],
        params: &[
            param("mass", "kg", Required, Range::POSITIVE, "moving mass m"),
            param("external_force", "N", Value(0.0), Range::ANY, "external force F_ext opposing extension"),
            param("stop_min", "m", Absent, Range::ANY, "retracted end stop (default: from a cylinder on the rod)"),
            param("stop_max", "m", Absent, Range::ANY, "extended end stop (default: from a cylinder on the rod)"),
        ],
        states: &[
            StateSpec { name: "position", unit: "m", default: Absent, doc: "initial position (default 0 or the cylinder's)" },
            StateSpec { name: "velocity", unit: "m/s", default: Absent, doc: "initial velocity (default 0 or the cylinder's)" },
        ],
        build: |i| {
            // stops of its own lie inside the travel a cylinder on the rod
            // allows: the piston cannot pass the cylinder's heads
            for (key, beyond) in [("stop_min", -1.0), ("stop_max", 1.0)] {
                if let (Some(own), Some(end)) = (i.opt(key), i.hint("rod", key)) {
                    if beyond * (own - end) > 0.0 {
                        let cylinder = i.hint_path("rod", key).unwrap_or_default();
                        let cylinder = cylinder.trim_end_matches(&format!(".{key}"));
                        let why = format!(
                            "{own} m is beyond the end of the stroke of {cylinder} ({end} m from mid-stroke): the piston cannot pass the cylinder's head; give a stop inside the stroke or leave it out"
                        );
                        return Err(crate::netlist::registry::error_at(
                            &format!("components.{}.{key}", i.name),
                            &why,
                        ));
                    }
                }
            }
            let lo = i.opt("stop_min").or_else(|| i.hint("rod", "stop_min"));
            let hi = i.opt("stop_max").or_else(|| i.hint("rod", "stop_max"));
            let stops = match (lo, hi) {
                (Some(lo), Some(hi)) if lo < hi => Some(StrokeEnds {
                    min: Position::new(lo),
                    max: Position::new(hi),
                }),
                (None, None) => None,
                _ => return Err("give both end stops stop_min < stop_max, or neither".into()),
            };
            let pick = |k: &str| {
                let own = i.initial(k);
                let key = format!("initial.{k}");
                let given = i.hint("rod", &key);
                match (own, given) {
                    // named here, with the way on: the value on the
                    // cylinder, or the cylinder's cleared
                    (Some(a), Some(b)) => {
                        let cylinder = i
                            .hint_from
                            .get(&("rod".to_string(), key.clone()))
                            .cloned()
                            .unwrap_or_else(|| "cylinder".into());
                        Err(crate::netlist::registry::error_at(
                            &format!("components.{}.{key}", i.name),
                            &format!(
                                "{a} is given here and {b} on the cylinder at the rod (components.{cylinder}.{key}); give it once: on the cylinder (`--set {cylinder}.{key}={a}`), or here with the cylinder's cleared (`--set {cylinder}.{key}=null`)"
                            ),
                        ))
                    }
                    (a, b) => Ok(a.or(b).unwrap_or(0.0)),
                }
            };
            let x0 = (pick("position")?, pick("velocity")?);
            if let Some(s) = stops {
                if !(s.min.si()..=s.max.si()).contains(&x0.0) {
                    let why = format!(
                        "initial position {} m is outside the end stops [{}, {}] m",
                        x0.0,
                        s.min.si(),
                        s.max.si()
                    );
                    // named where it was given: on the cylinder at the rod
                    return Err(match (i.initial("position"), i.hint_path("rod", "initial.position")) {
                        (None, Some(path)) => crate::netlist::registry::error_at(&path, &why),
                        // given here: named at its own path (a `--set`
                        // that gave it is then blamed, not the file's line)
                        (Some(_), _) => crate::netlist::registry::error_at(
                            &format!("components.{}.initial.position", i.name),
                            &why,
                        ),
                        (None, None) => why,
                    });
                }
            }
            built(Mass::new(&i.name, i.node("rod"), i.get("mass"), i.get("external_force"), stops, x0))
        },
        hints: None,
        probes: &[("position", "m"), ("velocity", "m/s")],
    },
];

#[cfg(test)]
mod tests {
    use crate::rig;
    use crate::run::RunOptions;
    use crate::signal::Signal;

    /// The generalised cylinder outputs its own state, the load pressure
    /// `p_le`, as the fundamental cylinder does: both forms' runs have the
    /// same columns, and it equals the chambers' net force over the
    /// effective area (eq 2.16) that the form sets p1, p2 from.
    #[test]
    fn the_generalised_cylinder_outputs_its_load_pressure() {
        let t: Vec<f64> = (0..=100).map(|k| k as f64 * 1e-3).collect();
        let command = Signal::Step {
            time_s: 0.01,
            before: 0.0,
            after: 0.3,
        };
        let run = |name: &str| {
            rig::simulate(
                &rig::preset(name).unwrap(),
                command.clone(),
                &t,
                &RunOptions::default(),
            )
            .unwrap()
        };
        let (gen, fund) = (run("leaney-moog-generalised"), run("leaney-moog"));
        // the same columns (the measured-data ones first, `run::ORDER`;
        // the others in component order, where `ps` is the supply's here
        // and the valve's there)
        let names = |r: &crate::run::Run| -> Vec<(String, &'static str)> {
            let mut n: Vec<_> = r
                .channels
                .iter()
                .map(|c| (c.name.clone(), c.unit))
                .collect();
            n[5..].sort();
            n
        };
        assert_eq!(names(&gen), names(&fund));
        assert!(names(&gen).contains(&("p_le".to_string(), "Pa")));
        let ple = gen.channel("p_le").expect("a p_le column");
        let v = rig::preset("leaney-moog-generalised").unwrap();
        let c = &v["components"]["cylinder"];
        let (a1, a2) = (c["area_1"].as_f64().unwrap(), c["area_2"].as_f64().unwrap());
        let (p1, p2) = (gen.channel("p1").unwrap(), gen.channel("p2").unwrap());
        for k in 0..t.len() {
            let net = (p1[k] * a1 - p2[k] * a2) / (0.5 * (a1 + a2));
            assert!(
                (ple[k] - net).abs() <= 1e-9 * net.abs().max(1.0),
                "t {}: p_le {} vs {net}",
                t[k],
                ple[k]
            );
        }
        assert!(ple[t.len() - 1] != ple[0], "the load pressure moves");
    }
}
