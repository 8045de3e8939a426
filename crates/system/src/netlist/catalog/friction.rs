//! Friction laws on a rod (eqs 2.34–2.40, 5.1–5.14): one component type per
//! law of the friction crate. Each reads the rod's velocity and, where the
//! law has a pressure term, the chamber pressures at the optional ports `A`
//! and `B`. The parameter names are the law's field paths.

use super::super::registry::{
    param, ComponentType, Default::*, Instance, ParamSpec, PortSpec, Range, Role, StateSpec,
};
use super::{built, join, port};
use crate::circuit::Component;
use crate::components::Friction;
use hydrocyl_friction::{
    CoulombViscous, Dahl, FrictionLaw, Karnopp, LuGre, SealTerms, Stribeck, Wang, WithSealTerms,
};
use serde::de::DeserializeOwned;

const PORTS: &[PortSpec] = &[
    port(
        "rod",
        super::MECH,
        Role::Reads,
        false,
        "the rod (body) it acts on",
    ),
    port(
        "A",
        super::HYD,
        Role::Reads,
        true,
        "cap-side chamber (pressure terms)",
    ),
    port(
        "B",
        super::HYD,
        Role::Reads,
        true,
        "rod-side chamber (pressure terms)",
    ),
];

const PROBES: &[(&str, &str)] = &[("force", "N")];

macro_rules! curve {
    ($p:literal) => {
        [
            param(
                concat!($p, ".coulomb"),
                "N",
                Required,
                Range::POSITIVE,
                "Coulomb level Fc",
            ),
            param(
                concat!($p, ".stiction"),
                "N",
                Required,
                Range::POSITIVE,
                "stiction (break-away) level Fs",
            ),
            param(
                concat!($p, ".stribeck_velocity"),
                "m/s",
                Required,
                Range::POSITIVE,
                "Stribeck velocity vs",
            ),
            param(
                concat!($p, ".stribeck_exponent"),
                "-",
                Required,
                Range::POSITIVE,
                "Stribeck exponent δ",
            ),
        ]
    };
}

const SIGMA2_E: ParamSpec = param(
    "extending.sigma2",
    "N s/m",
    Required,
    Range::NON_NEGATIVE,
    "viscous coefficient σ2, extending",
);
const SIGMA2_R: ParamSpec = param(
    "retracting.sigma2",
    "N s/m",
    Required,
    Range::NON_NEGATIVE,
    "viscous coefficient σ2, retracting",
);
const SIGMA0: ParamSpec = param(
    "sigma0",
    "N/m",
    Required,
    Range::POSITIVE,
    "bristle stiffness σ0",
);
const SIGMA1: ParamSpec = param(
    "sigma1",
    "N s/m",
    Required,
    Range::NON_NEGATIVE,
    "bristle damping σ1",
);

/// The additive seal terms every law may carry (catalog
/// `pressure_viscous`, `acceleration_friction`; 0 = off).
const SEAL: [ParamSpec; 5] = [
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
        Range::NON_NEGATIVE,
        "additive acceleration term K H a (eq 5.12), with K above",
    ),
    param(
        "seal.dp_max",
        "Pa",
        Value(0.0),
        Range::NON_NEGATIVE,
        "bound of |p1 − p2| in every seal term, K min(|p1 − p2|, Δp_max)² v; 0 = unbounded (eq 5.4)",
    ),
    param(
        "seal.dp_max_extend",
        "Pa",
        Value(0.0),
        Range::NON_NEGATIVE,
        "Δp_max while extending (v > 0); 0 = seal.dp_max",
    ),
    param(
        "seal.dp_max_retract",
        "Pa",
        Value(0.0),
        Range::NON_NEGATIVE,
        "Δp_max while retracting (v < 0); 0 = seal.dp_max",
    ),
];

const COULOMB_VISCOUS_LAW: [ParamSpec; 3] = [
    param(
        "coulomb",
        "N",
        Required,
        Range::NON_NEGATIVE,
        "Coulomb level Fc",
    ),
    param(
        "viscous",
        "N s/m",
        Required,
        Range::NON_NEGATIVE,
        "viscous coefficient b",
    ),
    param(
        "smoothing_velocity",
        "m/s",
        Required,
        Range::POSITIVE,
        "smoothing velocity of the tanh",
    ),
];

const COULOMB_VISCOUS: [ParamSpec; 8] = join(COULOMB_VISCOUS_LAW, SEAL);

const STRIBECK_LAW: [ParamSpec; 11] = join(
    join::<4, 4, 8>(curve!("extending.curve"), curve!("retracting.curve")),
    [
        SIGMA2_E,
        SIGMA2_R,
        param(
            "smoothing_velocity",
            "m/s",
            Required,
            Range::POSITIVE,
            "smoothing velocity of the tanh",
        ),
    ],
);

const STRIBECK: [ParamSpec; 16] = join(STRIBECK_LAW, SEAL);

const KARNOPP_LAW: [ParamSpec; 5] = join(
    curve!("curve"),
    [param(
        "sigma2",
        "N s/m",
        Required,
        Range::NON_NEGATIVE,
        "viscous coefficient σ2",
    )],
);

const DAHL_LAW: [ParamSpec; 3] = [
    param(
        "coulomb",
        "N",
        Required,
        Range::POSITIVE,
        "Coulomb level Fc",
    ),
    SIGMA0,
    param(
        "sigma2",
        "N s/m",
        Required,
        Range::NON_NEGATIVE,
        "viscous coefficient σ2",
    ),
];
const DAHL: [ParamSpec; 8] = join(DAHL_LAW, SEAL);
const KARNOPP: [ParamSpec; 10] = join(KARNOPP_LAW, SEAL);

const LUGRE_LAW: [ParamSpec; 12] = join(
    [SIGMA0, SIGMA1],
    join::<8, 2, 10>(
        join::<4, 4, 8>(curve!("extending.curve"), curve!("retracting.curve")),
        [SIGMA2_E, SIGMA2_R],
    ),
);

const WANG_LAW: [ParamSpec; 14] = join(
    [SIGMA0, SIGMA1],
    join::<8, 4, 12>(
        join::<4, 4, 8>(curve!("extending.curve"), curve!("retracting.curve")),
        [
            param(
                "extending.k_pressure",
                "m^3 s/N",
                Required,
                Range::NON_NEGATIVE,
                "seal gain K (K (p1 − p2)² v), extending",
            ),
            param(
                "extending.h_acceleration",
                "N^2 s/m^4",
                Required,
                Range::NON_NEGATIVE,
                "acceleration gain H (K H a), extending",
            ),
            param(
                "retracting.k_pressure",
                "m^3 s/N",
                Required,
                Range::NON_NEGATIVE,
                "seal gain K, retracting",
            ),
            param(
                "retracting.h_acceleration",
                "N^2 s/m^4",
                Required,
                Range::NON_NEGATIVE,
                "acceleration gain H, retracting",
            ),
        ],
    ),
);

const LUGRE: [ParamSpec; 17] = join(LUGRE_LAW, SEAL);
const WANG: [ParamSpec; 19] = join(WANG_LAW, SEAL);

/// The additive seal terms of an instance of one of these types.
pub(crate) fn terms_of(inst: &Instance) -> SealTerms {
    SealTerms {
        k_pressure: inst.opt("seal.k_pressure").unwrap_or(0.0),
        h_acceleration: inst.opt("seal.h_acceleration").unwrap_or(0.0),
        dp_max: inst.opt("seal.dp_max").unwrap_or(0.0),
        dp_max_extend: inst.opt("seal.dp_max_extend").unwrap_or(0.0),
        dp_max_retract: inst.opt("seal.dp_max_retract").unwrap_or(0.0),
    }
}

fn build_with<T: DeserializeOwned>(
    inst: &Instance,
    wrap: fn(T) -> FrictionLaw,
) -> Result<Box<dyn Component>, String> {
    let mut params = inst.clone();
    params.params.retain(|k, _| !k.starts_with("seal."));
    let law = bound_seal(wrap(params.law::<T>("")?), inst);
    hydrocyl_friction::FrictionModel::validate(&law).map_err(|e| e.to_string())?;
    let chambers =
        (inst.connected("A") && inst.connected("B")).then(|| (inst.node("A"), inst.node("B")));
    if inst.connected("A") != inst.connected("B") {
        return Err("connect both chamber ports `A` and `B`, or neither".into());
    }
    let terms = terms_of(inst);
    if terms.k_pressure > 0.0 && chambers.is_none() {
        return Err(
            "the seal term K (p1 − p2)² v needs the chamber ports `A` and `B` connected".into(),
        );
    }
    let model: Box<dyn hydrocyl_friction::FrictionModel> = if terms.is_off() {
        Box::new(law)
    } else {
        Box::new(WithSealTerms { inner: law, terms })
    };
    let z0 = inst.initial("z").unwrap_or(0.0);
    built(Friction::new(&inst.name, inst.node("rod"), chambers, model).with_initial_state(z0))
}

/// Wang's own seal term takes the component's `seal.dp_max*` bounds too.
fn bound_seal(law: FrictionLaw, inst: &Instance) -> FrictionLaw {
    match law {
        FrictionLaw::Wang(w) => {
            let t = terms_of(inst);
            FrictionLaw::Wang(
                w.with_seal_bound(t.dp_max)
                    .with_seal_bounds(t.dp_max_extend, t.dp_max_retract),
            )
        }
        other => other,
    }
}

/// The friction law of a typed view of the valve or hybrid rig (which holds
/// no friction state): a bristle that starts deflected (`initial.z` other
/// than 0) is refused rather than dropped, since the view starts it at 0.
pub(crate) fn typed_view_law(inst: &Instance) -> Option<Result<FrictionLaw, String>> {
    if let Some(z) = inst.initial("z").filter(|&z| z != 0.0) {
        return Some(Err(format!(
            "initial.z = {z} m: this study's view of the rig starts the bristle at z = 0 and would \
             drop it (`hydrocyl simulate` runs it as given); leave initial.z at 0 here"
        )));
    }
    law_of(inst)
}

/// The friction law of an instance of one of these types (`None` for
/// another type).
pub(crate) fn law_of(inst: &Instance) -> Option<Result<FrictionLaw, String>> {
    let mut without = inst.clone();
    without.params.retain(|k, _| !k.starts_with("seal."));
    let bounded = |law: FrictionLaw| bound_seal(law, inst);
    let inst = &without;
    Some(match inst.ty.name {
        "friction_coulomb_viscous" => inst
            .law::<CoulombViscous>("")
            .map(FrictionLaw::CoulombViscous),
        "friction_stribeck" => inst.law::<Stribeck>("").map(FrictionLaw::Stribeck),
        "friction_karnopp" => inst.law::<Karnopp>("").map(FrictionLaw::Karnopp),
        "friction_dahl" => inst.law::<Dahl>("").map(FrictionLaw::Dahl),
        "friction_lugre" => inst.law::<LuGre>("").map(FrictionLaw::LuGre),
        "friction_wang" => inst.law::<Wang>("").map(|w| bounded(FrictionLaw::Wang(w))),
        _ => return None,
    })
}

/// The initial state of the laws with a bristle (Dahl, LuGre, Wang): the
/// deflection z they start from (0, as before it could be given: at rest
/// with the bristles relaxed).
const BRISTLE: &[StateSpec] = &[StateSpec {
    name: "z",
    unit: "m",
    default: Value(0.0),
    doc: "initial bristle deflection z (the friction force starts at σ0 z)",
}];

macro_rules! friction_type {
    ($name:literal, $summary:literal, $params:expr, $law:ty, $variant:path) => {
        friction_type!($name, $summary, $params, $law, $variant, &[])
    };
    ($name:literal, $summary:literal, $params:expr, $law:ty, $variant:path, $states:expr) => {
        ComponentType {
            name: $name,
            summary: $summary,
            ports: PORTS,
            params: $params,
            states: $states,
            build: |i| build_with::<$law>(i, $variant),
            hints: None,
            probes: PROBES,
        }
    };
}

/// The friction component types.
pub const TYPES: &[ComponentType] = &[
    friction_type!(
        "friction_coulomb_viscous",
        "Coulomb + viscous friction, Fc tanh(v/v_t) + b v",
        &COULOMB_VISCOUS,
        CoulombViscous,
        FrictionLaw::CoulombViscous
    ),
    friction_type!(
        "friction_stribeck",
        "static Stribeck friction with extending/retracting curves (eq 2.40, g of eq 2.36)",
        &STRIBECK,
        Stribeck,
        FrictionLaw::Stribeck
    ),
    friction_type!(
        "friction_karnopp",
        "Karnopp stick–slip friction (section 2.4.2.1, which gives it no equation; slip on the Stribeck curve of eq 2.36)",
        &KARNOPP,
        Karnopp,
        FrictionLaw::Karnopp
    ),
    friction_type!(
        "friction_dahl",
        "Dahl bristle friction (section 2.4.2.2, which gives it no equation; eq 2.34 with g(v) ≡ Fc)",
        &DAHL,
        Dahl,
        FrictionLaw::Dahl,
        BRISTLE
    ),
    friction_type!(
        "friction_lugre",
        "LuGre friction with directional Stribeck curves (eqs 2.34–2.36)",
        &LUGRE,
        LuGre,
        FrictionLaw::LuGre,
        BRISTLE
    ),
    friction_type!(
        "friction_wang",
        "Wang's LuGre friction with seal-pressure and acceleration terms (eq 5.14)",
        &WANG,
        Wang,
        FrictionLaw::Wang,
        BRISTLE
    ),
];

#[cfg(test)]
mod tests {
    use crate::rig;
    use crate::signal::Signal;
    use hydrocyl_friction::{Dahl, FrictionLaw, LuGre, Wang};

    /// The bristle's deflection of a rig's circuit at its start.
    fn start_z(v: &serde_json::Value) -> f64 {
        let c = rig::circuit(v, Signal::Constant { value: 0.0 }).unwrap();
        let k = c
            .state_names()
            .iter()
            .position(|n| n == "friction.z0")
            .expect("a bristle state");
        c.initial_state()[k]
    }

    /// Every law with a bristle takes `initial.z` (`--set
    /// friction.initial.z=…`), lists it with the rig's parameters and
    /// writes it out with `--print-rig`; by default it starts at 0, where
    /// it started before it could be given.
    #[test]
    fn a_bristle_law_takes_its_initial_deflection() {
        let laws = [
            FrictionLaw::Dahl(Dahl::new(100.0, 1e6, 500.0).unwrap()),
            FrictionLaw::LuGre(LuGre::table_5_11()),
            FrictionLaw::Wang(Wang::table_5_8()),
        ];
        for law in laws {
            let mut v = rig::preset("leaney-moog").unwrap();
            v["components"]["friction"] = crate::valve_netlist::friction_component(&law).0;
            let ty = v["components"]["friction"]["type"].clone();
            assert_eq!(start_z(&v), 0.0, "{ty}");
            let listed = rig::parameters(&v);
            let z = listed
                .iter()
                .find(|p| p.path == "friction.initial.z")
                .unwrap_or_else(|| panic!("{ty}: friction.initial.z is not listed"));
            assert_eq!((z.value, z.unit), (Some(0.0), Some("m")), "{ty}");
            let shown = crate::netlist::expanded(&v).unwrap();
            assert_eq!(shown["components"]["friction"]["initial"]["z"], 0.0, "{ty}");
            rig::apply_set(&mut v, "friction.initial.z=1e-6").unwrap();
            assert_eq!(start_z(&v), 1e-6, "{ty}");
        }
        // the hybrid preset's Wang friction, as the user tried it
        let mut v = rig::preset("wang-hybrid").unwrap();
        rig::apply_set(&mut v, "friction.initial.z=1e-6").unwrap();
        assert_eq!(start_z(&v), 1e-6);
        // the typed views of the rigs, which carry no friction state, refuse
        // a deflected start instead of dropping it
        let e = crate::hybrid::WangHybrid::from_netlist(&v)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("components.friction") && e.contains("initial.z = 0.000001 m"),
            "{e}"
        );
        let mut v = rig::preset("leaney-moog").unwrap();
        v["components"]["friction"] = crate::valve_netlist::friction_component(&laws[1]).0;
        assert!(crate::valve_rig::ValveRig::from_netlist(&v).is_ok());
        rig::apply_set(&mut v, "friction.initial.z=1e-6").unwrap();
        let e = crate::valve_rig::ValveRig::from_netlist(&v)
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("components.friction") && e.contains("would drop it"),
            "{e}"
        );
        // a law without a bristle has no such state
        let mut v = rig::preset("leaney-moog").unwrap();
        let e = rig::apply_set(&mut v, "friction.initial.z=1e-6")
            .unwrap_err()
            .to_string();
        assert!(e.contains("unknown rig parameter"), "{e}");
    }
}
