//! Command-switched valves of the hybrid drive's further work (thesis
//! section 9.2): the solenoid four-way valve that replaces the pilot-shifted
//! DDDC valve (and with it relief valves 1 and 2), and the servo needle
//! valve whose opening follows the velocity command.

use super::super::registry::{
    param, ComponentType, Default::*, Instance, ParamSpec, Range, Role, StateSpec,
};
use super::hydraulic::orifice_params;
use super::{built, port, HYD, SIG};
use crate::circuit::Component;
use crate::components::{OpeningLaw, ServoNeedle, SolenoidFourWay, SolenoidLaw};
use hydrocyl_ports::{Area, Density, Pressure};
use hydrocyl_valves::check::CheckValve;
use hydrocyl_valves::needle::NeedleValve;
use hydrocyl_valves::orifice::Orifice;

fn orifice(i: &Instance, prefix: &str) -> Orifice {
    Orifice {
        cd: i.get(&format!("{prefix}cd")),
        density: Density::new(i.get(&format!("{prefix}density"))),
        dp_transition: Pressure::new(i.get(&format!("{prefix}dp_transition"))),
    }
}

const SOLENOID: [ParamSpec; 7] = {
    let o = orifice_params!("orifice.");
    [
        param(
            "area_supply",
            "m^2",
            Required,
            Range::POSITIVE,
            "open area of P1→A and P2→B at full shift",
        ),
        param(
            "area_return",
            "m^2",
            Required,
            Range::POSITIVE,
            "open area of A→T and B→T at full shift",
        ),
        param(
            "threshold",
            "V",
            Value(0.05),
            Range::NON_NEGATIVE,
            "command magnitude u_d above which a solenoid is energised",
        ),
        param(
            "time_constant",
            "s",
            Value(0.01),
            Range::POSITIVE,
            "time constant τ of the spool's shift",
        ),
        o[0],
        o[1],
        o[2],
    ]
};

fn solenoid(i: &Instance) -> Result<Box<dyn Component>, String> {
    let law = SolenoidLaw {
        area_supply: Area::new(i.get("area_supply")),
        area_return: Area::new(i.get("area_return")),
        orifice: orifice(i, "orifice."),
        threshold: i.get("threshold"),
        time_constant: i.get("time_constant"),
    };
    law.validate()?;
    let nodes = ["command", "P1", "P2", "A", "B", "T"].map(|p| i.node(p).to_string());
    built(SolenoidFourWay::new(
        &i.name,
        nodes,
        law,
        i.initial("spool").unwrap_or(0.0),
    ))
}

const SERVO_NEEDLE: [ParamSpec; 11] = {
    let o = orifice_params!("orifice.");
    [
        param(
            "area_min",
            "m^2",
            Required,
            Range::NON_NEGATIVE,
            "opening A_0 at zero command",
        ),
        param(
            "area_max",
            "m^2",
            Required,
            Range::POSITIVE,
            "largest opening A_max",
        ),
        param(
            "gain_positive",
            "m^2/V",
            Required,
            Range::NON_NEGATIVE,
            "opening per volt of positive command g₊",
        ),
        param(
            "gain_negative",
            "m^2/V",
            Required,
            Range::NON_NEGATIVE,
            "opening per volt of negative command g₋",
        ),
        param(
            "effective_factor",
            "-",
            Required,
            Range::UNIT,
            "effective-area factor",
        ),
        o[0],
        o[1],
        o[2],
        param(
            "reverse_check.cracking",
            "Pa",
            Required,
            Range::NON_NEGATIVE,
            "reverse check's cracking pressure p_c",
        ),
        param(
            "reverse_check.opening_range",
            "Pa",
            Required,
            Range::POSITIVE,
            "reverse check's opening range Δp_o",
        ),
        param(
            "reverse_check.k_open",
            "m^3/(s Pa^0.5)",
            Required,
            Range::POSITIVE,
            "reverse check's full-open coefficient K_c",
        ),
    ]
};

fn servo_needle(i: &Instance) -> Result<Box<dyn Component>, String> {
    let law = OpeningLaw {
        area_min: i.get("area_min"),
        area_max: i.get("area_max"),
        gain_positive: i.get("gain_positive"),
        gain_negative: i.get("gain_negative"),
    };
    law.validate().map_err(|why| {
        // the one relation between two parameters is area_max's
        if law.area_max.is_finite() && law.area_max <= law.area_min {
            crate::netlist::registry::error_at(&format!("components.{}.area_max", i.name), &why)
        } else {
            why
        }
    })?;
    let needle = NeedleValve::new(
        Area::new(law.area_min),
        i.get("effective_factor"),
        orifice(i, "orifice."),
        CheckValve::new(
            Pressure::new(i.get("reverse_check.cracking")),
            Pressure::new(i.get("reverse_check.opening_range")),
            i.get("reverse_check.k_open"),
        )
        .map_err(|e| e.to_string())?,
    )
    .map_err(|e| e.to_string())?;
    let nodes = ["command", "inlet", "outlet"].map(|p| i.node(p).to_string());
    built(ServoNeedle::new(&i.name, nodes, needle, law))
}

/// The component types of this family.
pub const TYPES: &[ComponentType] = &[
    ComponentType {
        name: "solenoid_four_way",
        summary: "command-switched closed-centre four-way valve, spool τ ṡ = σ(u) − s; P1→A, B→T for s > 0, P2→B, A→T for s < 0 (section 9.2)",
        ports: &[
            port("command", SIG, Role::Reads, false, "the command u that energises a solenoid [V]"),
            port("P1", HYD, Role::Reads, false, "supply for a positive command (pump line 1)"),
            port("P2", HYD, Role::Reads, false, "supply for a negative command (pump line 2)"),
            port("A", HYD, Role::Reads, false, "work port A (chamber 1)"),
            port("B", HYD, Role::Reads, false, "work port B (chamber 2)"),
            port("T", HYD, Role::Reads, false, "return port (tank, or the needle valve through an algebraic node)"),
        ],
        params: &SOLENOID,
        states: &[StateSpec {
            name: "spool",
            unit: "-",
            default: Value(0.0),
            doc: "initial spool position s in [-1, 1]",
        }],
        build: solenoid,
        hints: None,
        probes: &[("spool", "-")],
    },
    ComponentType {
        name: "servo_needle_valve",
        summary: "needle valve (eq 6.1 with the opening area Avn of eq 6.11) whose opening follows the command: Avn = clamp(A_0 + g₊ u⁺ + g₋ u⁻, A_0, A_max) (section 9.2)",
        ports: &[
            port("command", SIG, Role::Reads, false, "the velocity command u [V]"),
            port("inlet", HYD, Role::Reads, false, "inlet (metered flow inlet → outlet)"),
            port("outlet", HYD, Role::Reads, false, "outlet (the reverse check opens outlet → inlet)"),
        ],
        params: &SERVO_NEEDLE,
        states: &[],
        build: servo_needle,
        hints: None,
        probes: &[("opening", "m^2")],
    },
];
