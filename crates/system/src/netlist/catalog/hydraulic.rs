//! Generic hydraulic components: fixed-pressure sources, volumes (eq 2.10's
//! mass balance on a fixed volume), fixed orifices (eq 6.1, the metering terms of eqs 2.6–2.9) and a
//! first-order pressure sensor.

use super::super::registry::{
    param, ComponentType, Default::*, Instance, ParamSpec, Range, Role, StateSpec,
};
use super::{built, port, HYD};
use crate::components::{FixedOrifice, PressureSource, Volume};
use crate::sensor::LaggedPressureSensor;
use hydrocyl_actuator::EntrainedAir;
use hydrocyl_ports::{Area, Density, Pressure};
use hydrocyl_valves::orifice::Orifice;

/// The entrained-air parameters of a volume or a cylinder's chambers
/// ([`EntrainedAir`]; `air_fraction` 0 is the constant-B liquid).
pub(super) const AIR: [ParamSpec; 3] = [
    param(
        "air_fraction",
        "-",
        Value(0.0),
        Range { lo: 0.0, hi: 1.0, lo_open: false, hi_open: true },
        "entrained (undissolved) air, volume fraction at atmospheric pressure; 0 = pure liquid of constant B",
    ),
    param(
        "polytropic_index",
        "-",
        Value(1.0),
        Range { lo: 1.0, hi: 1.4, lo_open: false, hi_open: false },
        "polytropic index n of the air (1 isothermal, 1.4 adiabatic)",
    ),
    param(
        "atmospheric_pressure",
        "Pa",
        Value(hydrocyl_actuator::fluid::STANDARD_ATMOSPHERE),
        Range::POSITIVE,
        "absolute pressure at gauge zero (the air's reference)",
    ),
];

/// The entrained air an instance's [`AIR`] parameters give.
pub(super) fn air(i: &Instance) -> EntrainedAir {
    EntrainedAir {
        fraction: i.get("air_fraction"),
        polytropic_index: i.get("polytropic_index"),
        atmospheric_pressure: i.get("atmospheric_pressure"),
    }
}

/// The orifice law's parameters under `prefix` (Cd, ρ, regularisation).
macro_rules! orifice_params {
    ($p:literal) => {
        [
            param(
                concat!($p, "cd"),
                "-",
                Required,
                Range::UNIT,
                "discharge coefficient Cd",
            ),
            param(
                concat!($p, "density"),
                "kg/m^3",
                Required,
                Range::POSITIVE,
                "oil density ρ",
            )
            .typical(500.0, 2000.0),
            param(
                concat!($p, "dp_transition"),
                "Pa",
                Value(1000.0),
                Range::POSITIVE,
                "transition pressure of the regularised square root",
            ),
        ]
    };
}
pub(super) use orifice_params;

const ORIFICE: [ParamSpec; 4] = {
    let o = orifice_params!("");
    [
        param("area", "m^2", Required, Range::NON_NEGATIVE, "opening area"),
        o[0],
        o[1],
        o[2],
    ]
};

/// The component types of this family.
pub const TYPES: &[ComponentType] = &[
    ComponentType {
        name: "pressure_source",
        summary: "a node held at a fixed pressure (supply with accumulator, or tank)",
        ports: &[port("port", HYD, Role::Owns, false, "the node it holds")],
        params: &[param(
            "pressure",
            "Pa",
            Required,
            Range::GAUGE_PRESSURE,
            "the pressure (gauge)",
        )],
        states: &[],
        build: |i| {
            built(PressureSource::new(
                &i.name,
                i.node("port"),
                Pressure::new(i.get("pressure")),
                Some("p"),
            ))
        },
        hints: None,
        probes: &[("p", "Pa")],
    },
    ComponentType {
        name: "volume",
        summary: "a fixed volume of oil, dp/dt = B_eff(p)/V ΣQ (a line, a hose, a pump port); B_eff = B without entrained air",
        ports: &[port(
            "port",
            HYD,
            Role::Owns,
            false,
            "the node whose pressure it holds",
        )],
        params: &[
            param("volume", "m^3", Required, Range::POSITIVE, "volume V"),
            param(
                "bulk_modulus",
                "Pa",
                Required,
                Range::POSITIVE,
                "bulk modulus B of the liquid (the effective one without air)",
            ).typical(5e7, 5e9),
            AIR[0],
            AIR[1],
            AIR[2],
        ],
        states: &[StateSpec {
            name: "pressure",
            unit: "Pa",
            default: Value(0.0),
            doc: "initial pressure (gauge)",
        }],
        build: |i| {
            let mut v = Volume::new(
                &i.name,
                i.node("port"),
                i.get("volume"),
                i.get("bulk_modulus"),
                i.initial("pressure").unwrap_or(0.0),
                Some("p"),
            );
            v.air = air(i);
            built(v)
        },
        hints: None,
        probes: &[("p", "Pa")],
    },
    ComponentType {
        name: "algebraic_node",
        summary: "a node between resistive components with no volume: the assembler solves its pressure so the flows into it sum to zero (Newton on the components' slopes); a component may join only one such node (a longer chain needs a volume between nodes)",
        ports: &[port(
            "node",
            HYD,
            Role::Owns,
            false,
            "the node whose pressure is solved",
        )],
        params: &[],
        states: &[],
        build: |i| {
            built(crate::series::AlgebraicNode::new(
                &i.name,
                i.node("node"),
                Some("p"),
            ))
        },
        hints: None,
        probes: &[("p", "Pa")],
    },
    ComponentType {
        name: "orifice",
        summary: "a fixed sharp-edged orifice, Q = Cd A √(2Δp/ρ) regularised (eq 6.1; the metering terms of eqs 2.6–2.9)",
        ports: &[
            port(
                "a",
                HYD,
                Role::Reads,
                false,
                "one side (flow a → b positive)",
            ),
            port("b", HYD, Role::Reads, false, "the other side"),
        ],
        params: &ORIFICE,
        states: &[],
        build: |i| {
            let o = Orifice {
                cd: i.get("cd"),
                density: Density::new(i.get("density")),
                dp_transition: Pressure::new(i.get("dp_transition")),
            };
            built(FixedOrifice::new(
                &i.name,
                i.node("a"),
                i.node("b"),
                Area::new(i.get("area")),
                o,
            ))
        },
        hints: None,
        probes: &[],
    },
    ComponentType {
        name: "pressure_sensor",
        summary: "a pressure transducer with a first-order lag τ (catalog `sensor_lag`)",
        ports: &[port(
            "port",
            HYD,
            Role::Reads,
            false,
            "the node it measures",
        )],
        params: &[param(
            "time_constant",
            "s",
            Required,
            Range::POSITIVE,
            "lag τ",
        )],
        states: &[StateSpec {
            name: "reading",
            unit: "Pa",
            default: Value(0.0),
            doc: "initial reading",
        }],
        build: |i| {
            built(LaggedPressureSensor::new(
                &i.name,
                i.node("port"),
                "reading",
                i.get("time_constant"),
                i.initial("reading").unwrap_or(0.0),
            ))
        },
        hints: None,
        probes: &[("reading", "Pa")],
    },
];
