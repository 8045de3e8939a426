//! The servovalve drive's signal chain and metering: the command input, the
//! spool (eqs 2.2, 2.3/3.1) and the four-way metering (eqs 2.8, 2.9, 3.2).

use super::super::registry::{
    param, ComponentType, Default::*, Instance, ParamSpec, Range, Role, StateSpec,
};
use super::hydraulic::orifice_params;
use super::{built, join, port, HYD, SIG};
use crate::circuit::Component;
use crate::components::{CommandInput, FourWayNodes, FourWayValve, ServoSpool};
use hydrocyl_ports::{Density, Position, Pressure};
use hydrocyl_valves::orifice::Orifice;
use hydrocyl_valves::servovalve::{Metering, Spool, SpoolDynamics};

/// The metering parameters (names of [`Metering`]'s fields).
pub(super) const METERING: [ParamSpec; 7] = {
    let o = orifice_params!("orifice.");
    [
        param(
            "underlap",
            "m",
            Required,
            Range::NON_NEGATIVE,
            "equivalent underlap u0 (eq 3.2)",
        ),
        param(
            "spool_diameter",
            "m",
            Required,
            Range::POSITIVE,
            "spool diameter D; area gradient π D",
        )
        .typical(1e-4, 0.2),
        o[0],
        o[1],
        o[2],
        param(
            "null_bias",
            "m",
            Value(0.0),
            Range::ANY,
            "spool null bias x_b (catalog `valve_null_bias`)",
        ),
        param(
            "flow_gain",
            "-",
            Value(1.0),
            Range::POSITIVE,
            "scale on the area gradient (catalog `flow_gain_error`)",
        ),
    ]
};

/// The nodes of a four-way metering's ports `spool`, `P`, `T`, `A`, `B`
/// (the servovalve's and the generalised cylinder's).
pub(crate) fn four_way_nodes(i: &Instance) -> FourWayNodes<'_> {
    FourWayNodes {
        spool: i.node("spool"),
        p: i.node("P"),
        t: i.node("T"),
        a: i.node("A"),
        b: i.node("B"),
    }
}

/// The [`Metering`] of an instance with [`METERING`] parameters.
pub(crate) fn metering(i: &Instance) -> Result<Metering, String> {
    let m = Metering {
        underlap: Position::new(i.get("underlap")),
        spool_diameter: Position::new(i.get("spool_diameter")),
        orifice: Orifice {
            cd: i.get("orifice.cd"),
            density: Density::new(i.get("orifice.density")),
            dp_transition: Pressure::new(i.get("orifice.dp_transition")),
        },
        null_bias: Position::new(i.get("null_bias")),
        flow_gain: i.get("flow_gain"),
    };
    m.validate().map_err(|e| e.to_string())?;
    Ok(m)
}

const FOUR_WAY: [ParamSpec; 9] = join(
    METERING,
    [
        param(
            "supply_resistance",
            "Pa s/m^3",
            Value(0.0),
            Range::NON_NEGATIVE,
            "supply droop Rs: the valve sees Ps = P − Rs Q_P (catalog `supply_droop`)",
        ),
        param(
            "dead_band",
            "m",
            Value(0.0),
            Range::NON_NEGATIVE,
            "spool dead band x_d: the metering sees sign(x_s) max(0, abs(x_s) − x_d) (catalog `valve_dead_band`)",
        ),
    ],
);

const SPOOL_PORTS: &[super::PortSpec] = &[
    port(
        "command",
        SIG,
        Role::Reads,
        false,
        "normalised command u [-]",
    ),
    port("spool", SIG, Role::Owns, false, "spool position x_s [m]"),
];

const SPOOL_STATES: &[StateSpec] = &[StateSpec {
    name: "position",
    unit: "m",
    default: Value(0.0),
    doc: "initial spool position",
}];

fn spool(i: &Instance, dynamics: SpoolDynamics) -> Result<Box<dyn Component>, String> {
    let s = Spool {
        stroke: Position::new(i.get("stroke")),
        dynamics,
    };
    s.validate().map_err(|e| e.to_string())?;
    let x0 = i.initial("position").unwrap_or(0.0);
    if x0.abs() > i.get("stroke") {
        // named at its own path, so that a `--set` that gave it is blamed
        // rather than the file's line
        return Err(super::super::registry::error_at(
            &format!("components.{}.initial.position", i.name),
            &format!(
                "{x0} m is outside the spool stroke [-{s}, {s}] m",
                s = i.get("stroke")
            ),
        ));
    }
    built(ServoSpool::new(
        &i.name,
        i.node("command"),
        i.node("spool"),
        s,
        x0,
    ))
}

/// The component types of this family.
pub const TYPES: &[ComponentType] = &[
    ComponentType {
        name: "command_input",
        summary: "the run's command (a `--command` record or a signal), as a signal",
        ports: &[port("out", SIG, Role::Owns, false, "the command")],
        params: &[],
        states: &[],
        build: |i| match &i.input {
            Some(s) => built(CommandInput::new(&i.name, i.node("out"), s.clone())),
            None => Err("no command given for this input".into()),
        },
        hints: None,
        probes: &[("command", "-")],
    },
    ComponentType {
        name: "servo_spool_first_order",
        summary:
            "servovalve spool, first-order lag τ ẋ = u x_max − x with saturation (eqs 2.3, 3.1)",
        ports: SPOOL_PORTS,
        params: &[
            param(
                "stroke",
                "m",
                Required,
                Range::POSITIVE,
                "spool stroke x_max (demand u · x_max, saturation)",
            )
            .typical(1e-5, 0.02),
            param(
                "time_constant",
                "s",
                Required,
                Range::POSITIVE,
                "time constant τ",
            ),
        ],
        states: SPOOL_STATES,
        build: |i| {
            spool(
                i,
                SpoolDynamics::First {
                    time_constant_s: i.get("time_constant"),
                },
            )
        },
        hints: None,
        probes: &[("spool", "m")],
    },
    ComponentType {
        name: "servo_spool_second_order",
        summary:
            "servovalve spool, second order ẍ = ω²(u x_max − x) − 2ζω ẋ with saturation (eq 2.2)",
        ports: SPOOL_PORTS,
        params: &[
            param(
                "stroke",
                "m",
                Required,
                Range::POSITIVE,
                "spool stroke x_max",
            )
            .typical(1e-5, 0.02),
            param(
                "natural_frequency",
                "rad/s",
                Required,
                Range::POSITIVE,
                "natural frequency ω_n",
            ),
            param(
                "damping_ratio",
                "-",
                Required,
                Range::POSITIVE,
                "damping ratio ζ",
            ),
        ],
        states: SPOOL_STATES,
        build: |i| {
            spool(
                i,
                SpoolDynamics::Second {
                    natural_frequency_rad_per_s: i.get("natural_frequency"),
                    damping_ratio: i.get("damping_ratio"),
                },
            )
        },
        hints: None,
        probes: &[("spool", "m")],
    },
    ComponentType {
        name: "four_way_valve",
        summary:
            "servovalve four-way metering between P, T, A, B with underlap (eqs 2.8, 2.9, 3.2)",
        ports: &[
            port("spool", SIG, Role::Reads, false, "spool position x_s [m]"),
            port("P", HYD, Role::Reads, false, "supply port"),
            port("T", HYD, Role::Reads, false, "tank port"),
            port(
                "A",
                HYD,
                Role::Reads,
                false,
                "service port A (opened to P for x_s > 0)",
            ),
            port(
                "B",
                HYD,
                Role::Reads,
                false,
                "service port B (opened to T for x_s > 0)",
            ),
        ],
        params: &FOUR_WAY,
        states: &[],
        build: |i| {
            let mut v = FourWayValve::new(&i.name, four_way_nodes(i), metering(i)?);
            v.supply_resistance = i.get("supply_resistance");
            v.dead_band = i.get("dead_band");
            v.supply_probe = Some("ps".into());
            built(v)
        },
        hints: None,
        probes: &[("ps", "Pa")],
    },
];
