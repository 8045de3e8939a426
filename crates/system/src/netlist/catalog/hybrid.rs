//! The hybrid pump-controlled drive's components (chapter 6): the identified
//! servomotor–pump (section 6.2.1), relief valves (eqs 6.6–6.10), check
//! valves (section 4.1; the thesis gives no check-valve law), the
//! pilot-operated DDDC four-way valve (eqs 6.1–6.5) and the NCCC needle valve
//! with its reverse check (section 6.2.2.3: eq 6.1 with the opening of eq
//! 6.11), joined in series by an `algebraic_node`.

use super::super::registry::{
    error_at, param, ComponentType, Default::*, Instance, ParamSpec, Range, Role,
};
use super::hydraulic::orifice_params;
use super::{built, port, HYD, SIG};
use crate::hybrid::components::{
    CheckComponent, NeedleComponent, PilotNodes, PilotValve, PumpComponent, ReliefComponent,
};
use hydrocyl_pump_motor::IdentifiedPump;
use hydrocyl_valves::check::{CheckValve, ParameterError};
use hydrocyl_valves::needle::NeedleValve;
use hydrocyl_valves::pilot_valve::PilotFourWay;
use hydrocyl_valves::relief::ReliefValve;
use serde::de::DeserializeOwned;

/// A law from the instance's parameters under `prefix`, checked by `check`.
fn law<T: DeserializeOwned>(
    i: &Instance,
    prefix: &str,
    check: impl Fn(&T) -> Result<(), ParameterError>,
) -> Result<T, String> {
    let t: T = i.law(prefix)?;
    check(&t).map_err(|e| param_error(i, prefix, &e))?;
    Ok(t)
}

/// A valve's parameter error named at the JSON path of the parameter it
/// names (`components.rv.cracking`: a relation between two parameters is
/// the one its message names first), when the type has that parameter
/// under `prefix`; else at the component.
fn param_error(i: &Instance, prefix: &str, e: &ParameterError) -> String {
    let name = if prefix.is_empty() {
        e.name.to_string()
    } else {
        format!("{prefix}.{}", e.name)
    };
    if i.ty.param(&name).is_some() {
        error_at(&format!("components.{}.{name}", i.name), &e.to_string())
    } else {
        e.to_string()
    }
}

macro_rules! check_params {
    ($p:literal) => {
        [
            param(
                concat!($p, "cracking"),
                "Pa",
                Required,
                Range::NON_NEGATIVE,
                "cracking pressure p_c",
            ),
            param(
                concat!($p, "opening_range"),
                "Pa",
                Required,
                Range::POSITIVE,
                "opening range Δp_o (fully open at p_c + Δp_o)",
            ),
            param(
                concat!($p, "k_open"),
                "m^3/(s Pa^0.5)",
                Required,
                Range::POSITIVE,
                "full-open flow coefficient K_c",
            ),
        ]
    };
}

const CHECK: [ParamSpec; 3] = check_params!("");

const PILOT: [ParamSpec; 7] = [
    param(
        "spring_rate",
        "Pa/m",
        Required,
        Range::POSITIVE,
        "pilot spool centring spring rate k_s",
    ),
    param("overlap", "m", Required, Range::NON_NEGATIVE, "overlap x_o"),
    param(
        "stroke",
        "m",
        Required,
        Range::POSITIVE,
        "opening travel beyond the overlap",
    ),
    param(
        "hole_radius",
        "m",
        Required,
        Range::POSITIVE,
        "radius of each port hole",
    ),
    param(
        "k_p",
        "m^3/(s Pa^0.5)",
        Required,
        Range::POSITIVE,
        "full-shift coefficient P→A, P→B (eq 6.4)",
    ),
    param(
        "k_t",
        "m^3/(s Pa^0.5)",
        Required,
        Range::POSITIVE,
        "full-shift coefficient A→T, B→T (eq 6.5)",
    ),
    param(
        "dp_transition",
        "Pa",
        Value(1000.0),
        Range::POSITIVE,
        "transition pressure of the regularised root",
    ),
];

const NEEDLE: [ParamSpec; 8] = {
    let o = orifice_params!("orifice.");
    let c = check_params!("reverse_check.");
    [
        param(
            "area",
            "m^2",
            Required,
            Range::NON_NEGATIVE,
            "needle opening area Avn",
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
        c[0],
        c[1],
        c[2],
    ]
};

/// The component types of this family.
pub const TYPES: &[ComponentType] = &[
    ComponentType {
        name: "pump_identified",
        summary: "servomotor and bidirectional gear pump, identified 2nd-order command → flow model (section 6.2.1)",
        ports: &[
            port("command", SIG, Role::Reads, false, "command [V]"),
            port("a", HYD, Role::Reads, false, "port delivering for a positive command"),
            port("b", HYD, Role::Reads, false, "port delivering for a negative command"),
        ],
        params: &[
            param("gain", "m^3/(s V)", Required, Range::POSITIVE, "steady flow per volt K"),
            param("natural_frequency", "rad/s", Required, Range::POSITIVE, "natural frequency ω_n"),
            param("damping", "-", Required, Range::POSITIVE, "damping ratio ζ"),
            param("displacement", "m^3/rad", Absent, Range::POSITIVE, "pump displacement per radian of the shaft (2.05 cc/rev = 3.2627e-7 m^3/rad, Table 4-2); with max_speed, the rating a command is checked against"),
            param("max_speed", "rad/s", Absent, Range::POSITIVE, "the motor's maximum speed (8000 rpm = 837.76 rad/s, Table 4-2): a command whose steady flow K u turns the pump faster, abs(K u) / displacement > max_speed, is warned of (not limited: a rating, not a stop); absent = no rating"),
        ],
        states: &[],
        build: |i| {
            if i.opt("max_speed").is_some() && i.opt("displacement").is_none() {
                return Err(error_at(
                    &format!("components.{}.max_speed", i.name),
                    &format!(
                        "needs the pump's displacement (components.{}.displacement [m^3/rad]) to relate the speed to the flow",
                        i.name
                    ),
                ));
            }
            let p = IdentifiedPump {
                gain: i.get("gain"),
                natural_frequency: i.get("natural_frequency"),
                damping: i.get("damping"),
            };
            built(PumpComponent::new(&i.name, p, i.node("command"), i.node("a"), i.node("b")))
        },
        hints: None,
        probes: &[("flow", "m^3/s")],
    },
    ComponentType {
        name: "relief_valve",
        summary: "direct relief valve with linear opening between p_c and P_m (eqs 6.6–6.10)",
        ports: &[
            port("inlet", HYD, Role::Reads, false, "inlet"),
            port("outlet", HYD, Role::Reads, false, "outlet (p_c is referred to it)"),
        ],
        params: &[
            param("cracking", "Pa", Required, Range::NON_NEGATIVE, "cracking pressure p_c"),
            param("full_open", "Pa", Required, Range::POSITIVE, "pressure difference P_m at full opening (> p_c)"),
            param("kv", "m^3/(s Pa^0.5)", Required, Range::POSITIVE, "fully-open flow coefficient K_v"),
        ],
        states: &[],
        build: |i| {
            let v: ReliefValve = law(i, "", |v: &ReliefValve| {
                ReliefValve::new(v.cracking, v.kv, v.full_open).map(|_| ())
            })?;
            built(ReliefComponent::new(&i.name, v, i.node("inlet"), i.node("outlet")))
        },
        hints: None,
        probes: &[("flow", "m^3/s")],
    },
    ComponentType {
        name: "check_valve",
        summary: "spring-loaded check valve, inlet → outlet (the anti-cavitation check valves of section 4.1; the thesis gives no check-valve law: law and defaults assumed)",
        ports: &[
            port("inlet", HYD, Role::Reads, false, "inlet"),
            port("outlet", HYD, Role::Reads, false, "outlet"),
        ],
        params: &CHECK,
        states: &[],
        build: |i| {
            let v: CheckValve = law(i, "", |v: &CheckValve| {
                CheckValve::new(v.cracking, v.opening_range, v.k_open).map(|_| ())
            })?;
            built(CheckComponent::new(&i.name, v, i.node("inlet"), i.node("outlet")))
        },
        hints: None,
        probes: &[("flow", "m^3/s")],
    },
    ComponentType {
        name: "pilot_valve",
        summary: "pilot-shifted DDDC four-way valve opening the unfed chamber to its T port, Q = k_T(y) √(p_x − p_T) (eqs 6.2–6.5)",
        ports: &[
            port("pilot_1", HYD, Role::Reads, false, "pilot port 1 (pump line 1)"),
            port("pilot_2", HYD, Role::Reads, false, "pilot port 6 (pump line 2)"),
            port("A", HYD, Role::Reads, false, "work port A (chamber 1)"),
            port("B", HYD, Role::Reads, false, "work port B (chamber 2)"),
            port("T", HYD, Role::Reads, false, "the T port (to the needle valve: an algebraic node)"),
        ],
        params: &PILOT,
        states: &[],
        build: |i| {
            let fw: PilotFourWay = law(i, "", PilotFourWay::validate)?;
            built(PilotValve::new(
                &i.name,
                fw,
                PilotNodes {
                    pilot_1: i.node("pilot_1"),
                    pilot_2: i.node("pilot_2"),
                    a: i.node("A"),
                    b: i.node("B"),
                    t: i.node("T"),
                },
            ))
        },
        hints: None,
        probes: &[("pilot_spool", "m"), ("return_flow_1", "m^3/s"), ("return_flow_2", "m^3/s")],
    },
    ComponentType {
        name: "needle_valve",
        summary: "NCCC needle valve with its reverse-flow check, inlet → outlet, Q = Cd Avn √(2/ρ) √Δp (section 6.2.2.3: eq 6.1 with the opening area of eq 6.11, Table 6-1)",
        ports: &[
            port("inlet", HYD, Role::Reads, false, "inlet (metered flow inlet → outlet)"),
            port("outlet", HYD, Role::Reads, false, "outlet (the reverse check opens outlet → inlet)"),
        ],
        params: &NEEDLE,
        states: &[],
        build: |i| {
            let needle: NeedleValve = law(i, "", |n: &NeedleValve| {
                NeedleValve::new(n.area, n.effective_factor, n.orifice, n.reverse_check).map(|_| ())
            })?;
            built(NeedleComponent::new(&i.name, needle, i.node("inlet"), i.node("outlet")))
        },
        hints: None,
        probes: &[],
    },
];
