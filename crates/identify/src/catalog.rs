//! The effect catalog of `spec/measured-data.md`, as data: stable ids, the
//! balance each belongs to, the term it adds and its parameters with units,
//! bounds and a typical magnitude (for scaling fits).

use serde::{Deserialize, Serialize};
use std::fmt;

/// A balance equation of the rig model.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Balance {
    /// Piston force balance `p1 A1 − p2 A2 − m a − F_friction − F_ext = 0`.
    Force,
    /// Chamber 1 flow balance.
    Flow1,
    /// Chamber 2 flow balance.
    Flow2,
    /// Chamber 1 and 2 flow balances together.
    Flow12,
    /// Valve flow (orifice) equation.
    Valve,
    /// The measurement chain (sensor model).
    Measurement,
}

/// One parameter of an effect.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ParamSpec {
    /// Name as in the catalog (`dFc`, `K`, ...).
    pub name: &'static str,
    /// SI unit.
    pub unit: &'static str,
    /// Lower bound of a fit.
    pub lower: f64,
    /// Upper bound of a fit.
    pub upper: f64,
    /// Where it is written in a netlist: a parameter of every component of
    /// a type (empty for the law edits and the measurement model).
    pub targets: &'static [Target],
}

/// One place an effect parameter is written: parameter `param` of every
/// component of type `ty`, as its [`Scale`] says.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Target {
    /// Component type.
    pub ty: &'static str,
    /// Parameter path within the component.
    pub param: &'static str,
    /// How the catalog value becomes the component's value.
    pub scale: Scale,
}

/// How a catalog value is written to the components a [`Target`] reaches.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// The catalog value itself.
    Absolute,
    /// The catalog value times the component's declared value (a flow gain
    /// kw = 1.05 on a pump: its gain 5 % up).
    Factor,
    /// The catalog value is the effect's first component's (the one it is
    /// read from); every component keeps its declared ratio to that one (a
    /// bulk modulus: a line declared with a stiffer oil than the cylinder's
    /// stays that much stiffer).
    Ratio,
}

const fn t(ty: &'static str, param: &'static str) -> Target {
    Target {
        ty,
        param,
        scale: Scale::Absolute,
    }
}

const fn ratio(ty: &'static str, param: &'static str) -> Target {
    Target {
        ty,
        param,
        scale: Scale::Ratio,
    }
}

/// The pressure seal term of every friction type.
const SEAL_K: [Target; 6] = [
    t("friction_coulomb_viscous", "seal.k_pressure"),
    t("friction_stribeck", "seal.k_pressure"),
    t("friction_karnopp", "seal.k_pressure"),
    t("friction_dahl", "seal.k_pressure"),
    t("friction_lugre", "seal.k_pressure"),
    t("friction_wang", "seal.k_pressure"),
];
/// The acceleration seal term of every friction type.
const SEAL_H: [Target; 6] = [
    t("friction_coulomb_viscous", "seal.h_acceleration"),
    t("friction_stribeck", "seal.h_acceleration"),
    t("friction_karnopp", "seal.h_acceleration"),
    t("friction_dahl", "seal.h_acceleration"),
    t("friction_lugre", "seal.h_acceleration"),
    t("friction_wang", "seal.h_acceleration"),
];

/// An effect of the catalog.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum EffectId {
    /// Different Coulomb level extending vs retracting (`dFc`).
    CoulombAsymmetry,
    /// `(Fs − Fc) exp(−|v/vs|^α) sgn(v)` (`Fs`, `vs`, `alpha`).
    Stribeck,
    /// `b v` (`b`).
    Viscous,
    /// `K (p1 − p2)² v`, thesis eq 5.4 (`K`).
    PressureViscous,
    /// `K H a`, thesis eq 5.12 (`H`).
    AccelerationFriction,
    /// LuGre bristle state z, eq 5.1, in place of static friction (`sigma0`, `sigma1`).
    LugreDynamics,
    /// Constant force, e.g. gravity on a vertical rod (`F0`).
    ExternalForce,
    /// `Cl (p1 − p2)` from chamber 1 to chamber 2 (`Cl`).
    InternalLeakage,
    /// `Ce p` to drain (`Ce1`, `Ce2`).
    ExternalLeakage,
    /// Spool offset added to the spool position (`xb`).
    ValveNullBias,
    /// Scale on the port area gradient (`kw`).
    FlowGainError,
    /// Effective bulk modulus other than declared (`B`).
    BulkModulus,
    /// `Ps = Ps0 − Rs Qs` (`Rs`).
    SupplyDroop,
    /// First-order lag on the pressure sensors (`tau`).
    SensorLag,
    /// A dead zone on the spool: the metering sees `sign(xs) max(0, |xs| − xd)` (`xd`).
    ValveDeadBand,
}

const fn p(name: &'static str, unit: &'static str, lower: f64, upper: f64) -> ParamSpec {
    ParamSpec {
        name,
        unit,
        lower,
        upper,
        targets: &[],
    }
}

/// [`p`] written to `targets` in a netlist.
const fn pt(
    name: &'static str,
    unit: &'static str,
    lower: f64,
    upper: f64,
    targets: &'static [Target],
) -> ParamSpec {
    ParamSpec {
        name,
        unit,
        lower,
        upper,
        targets,
    }
}

impl EffectId {
    /// Every effect, in catalog order.
    pub const ALL: [EffectId; 15] = [
        EffectId::CoulombAsymmetry,
        EffectId::Stribeck,
        EffectId::Viscous,
        EffectId::PressureViscous,
        EffectId::AccelerationFriction,
        EffectId::LugreDynamics,
        EffectId::ExternalForce,
        EffectId::InternalLeakage,
        EffectId::ExternalLeakage,
        EffectId::ValveNullBias,
        EffectId::FlowGainError,
        EffectId::BulkModulus,
        EffectId::SupplyDroop,
        EffectId::SensorLag,
        EffectId::ValveDeadBand,
    ];

    /// The stable id of the catalog.
    pub fn id(self) -> &'static str {
        match self {
            EffectId::CoulombAsymmetry => "coulomb_asymmetry",
            EffectId::Stribeck => "stribeck",
            EffectId::Viscous => "viscous",
            EffectId::PressureViscous => "pressure_viscous",
            EffectId::AccelerationFriction => "acceleration_friction",
            EffectId::LugreDynamics => "lugre_dynamics",
            EffectId::ExternalForce => "external_force",
            EffectId::InternalLeakage => "internal_leakage",
            EffectId::ExternalLeakage => "external_leakage",
            EffectId::ValveNullBias => "valve_null_bias",
            EffectId::FlowGainError => "flow_gain_error",
            EffectId::BulkModulus => "bulk_modulus",
            EffectId::SupplyDroop => "supply_droop",
            EffectId::SensorLag => "sensor_lag",
            EffectId::ValveDeadBand => "valve_dead_band",
        }
    }

    /// The effect with this id.
    pub fn from_id(id: &str) -> Option<EffectId> {
        EffectId::ALL.into_iter().find(|e| e.id() == id)
    }

    /// The balance it belongs to.
    pub fn balance(self) -> Balance {
        match self {
            EffectId::CoulombAsymmetry
            | EffectId::Stribeck
            | EffectId::Viscous
            | EffectId::PressureViscous
            | EffectId::AccelerationFriction
            | EffectId::LugreDynamics
            | EffectId::ExternalForce => Balance::Force,
            EffectId::InternalLeakage | EffectId::BulkModulus | EffectId::ExternalLeakage => {
                Balance::Flow12
            }
            EffectId::ValveNullBias
            | EffectId::FlowGainError
            | EffectId::SupplyDroop
            | EffectId::ValveDeadBand => Balance::Valve,
            EffectId::SensorLag => Balance::Measurement,
        }
    }

    /// The term it adds, in words.
    pub fn term(self) -> &'static str {
        match self {
            EffectId::CoulombAsymmetry => "different Coulomb level extending vs retracting",
            EffectId::Stribeck => "(Fs - Fc) exp(-|v/vs|^alpha) sgn(v)",
            EffectId::Viscous => "b v",
            EffectId::PressureViscous => "K (p1 - p2)^2 v (eq 5.4)",
            EffectId::AccelerationFriction => "K H a (eq 5.12)",
            EffectId::LugreDynamics => "bristle state z (eq 5.1) in place of static friction",
            EffectId::ExternalForce => "constant force F0",
            EffectId::InternalLeakage => "Cl (p1 - p2) from chamber 1 to chamber 2",
            EffectId::ExternalLeakage => "Ce p to drain",
            EffectId::ValveNullBias => "spool offset xb",
            EffectId::FlowGainError => "scale kw on the port area gradient",
            EffectId::BulkModulus => "effective bulk modulus B",
            EffectId::SupplyDroop => "Ps = Ps0 - Rs Qs",
            EffectId::SensorLag => "first-order lag tau on the pressure sensors",
            EffectId::ValveDeadBand => "sign(xs) max(0, |xs| - xd): a dead zone on the spool",
        }
    }

    /// Its parameters, in catalog order, with SI units and fit bounds.
    pub fn params(self) -> &'static [ParamSpec] {
        const INF: f64 = f64::INFINITY;
        match self {
            EffectId::CoulombAsymmetry => {
                const P: &[ParamSpec] = &[p("dFc", "N", -INF, INF)];
                P
            }
            EffectId::Stribeck => {
                const P: &[ParamSpec] = &[
                    p("Fs", "N", 0.0, INF),
                    p("vs", "m/s", 1e-5, 1.0),
                    p("alpha", "-", 0.05, 4.0),
                ];
                P
            }
            EffectId::Viscous => {
                const P: &[ParamSpec] = &[pt(
                    "b",
                    "N s/m",
                    0.0,
                    INF,
                    &[
                        t("friction_coulomb_viscous", "viscous"),
                        t("friction_stribeck", "extending.sigma2"),
                        t("friction_stribeck", "retracting.sigma2"),
                        t("friction_lugre", "extending.sigma2"),
                        t("friction_lugre", "retracting.sigma2"),
                        t("friction_karnopp", "sigma2"),
                        t("friction_dahl", "sigma2"),
                    ],
                )];
                P
            }
            EffectId::PressureViscous => {
                const P: &[ParamSpec] = &[pt("K", "m^3 s/N", 0.0, INF, &SEAL_K)];
                P
            }
            EffectId::AccelerationFriction => {
                const P: &[ParamSpec] = &[pt("H", "N^2 s/m^4", -INF, INF, &SEAL_H)];
                P
            }
            EffectId::LugreDynamics => {
                const P: &[ParamSpec] = &[
                    p("sigma0", "N/m", 1e2, 1e10),
                    p("sigma1", "N s/m", 0.0, 1e6),
                ];
                P
            }
            EffectId::ExternalForce => {
                const P: &[ParamSpec] = &[pt("F0", "N", -INF, INF, &[t("mass", "external_force")])];
                P
            }
            EffectId::InternalLeakage => {
                const P: &[ParamSpec] = &[pt(
                    "Cl",
                    "m^3/(s Pa)",
                    0.0,
                    1e-9,
                    &[
                        t("cylinder", "internal_leakage"),
                        t("generalised_cylinder", "internal_leakage"),
                    ],
                )];
                P
            }
            EffectId::ExternalLeakage => {
                const P: &[ParamSpec] = &[
                    pt(
                        "Ce1",
                        "m^3/(s Pa)",
                        0.0,
                        1e-9,
                        &[
                            t("cylinder", "external_leakage_1"),
                            t("generalised_cylinder", "external_leakage_1"),
                        ],
                    ),
                    pt(
                        "Ce2",
                        "m^3/(s Pa)",
                        0.0,
                        1e-9,
                        &[
                            t("cylinder", "external_leakage_2"),
                            t("generalised_cylinder", "external_leakage_2"),
                        ],
                    ),
                ];
                P
            }
            EffectId::ValveNullBias => {
                const P: &[ParamSpec] = &[pt(
                    "xb",
                    "m",
                    -1e-3,
                    1e-3,
                    &[
                        t("four_way_valve", "null_bias"),
                        t("generalised_cylinder", "null_bias"),
                    ],
                )];
                P
            }
            EffectId::FlowGainError => {
                const P: &[ParamSpec] = &[pt(
                    "kw",
                    "-",
                    0.1,
                    10.0,
                    &[
                        t("four_way_valve", "flow_gain"),
                        t("generalised_cylinder", "flow_gain"),
                        Target {
                            ty: "pump_identified",
                            param: "gain",
                            scale: Scale::Factor,
                        },
                    ],
                )];
                P
            }
            EffectId::BulkModulus => {
                const P: &[ParamSpec] = &[pt(
                    "B",
                    "Pa",
                    1e7,
                    1e10,
                    // the oil's: the chambers' and every line volume's, each
                    // scaled with the cylinder's (B is the cylinder's)
                    &[
                        ratio("cylinder", "bulk_modulus"),
                        ratio("generalised_cylinder", "bulk_modulus"),
                        ratio("volume", "bulk_modulus"),
                    ],
                )];
                P
            }
            EffectId::SupplyDroop => {
                const P: &[ParamSpec] = &[pt(
                    "Rs",
                    "Pa s/m^3",
                    0.0,
                    INF,
                    &[t("four_way_valve", "supply_resistance")],
                )];
                P
            }
            EffectId::SensorLag => {
                const P: &[ParamSpec] = &[p("tau", "s", 0.0, 1.0)];
                P
            }
            EffectId::ValveDeadBand => {
                const P: &[ParamSpec] = &[pt(
                    "xd",
                    "m",
                    0.0,
                    1e-3,
                    &[t("four_way_valve", "dead_band")],
                )];
                P
            }
        }
    }
}

impl fmt::Display for EffectId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.id())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalog_matches_the_spec_table() {
        // The spec's table, id → parameter names, transcribed.
        let spec = [
            ("coulomb_asymmetry", "dFc"),
            ("stribeck", "Fs,vs,alpha"),
            ("viscous", "b"),
            ("pressure_viscous", "K"),
            ("acceleration_friction", "H"),
            ("lugre_dynamics", "sigma0,sigma1"),
            ("external_force", "F0"),
            ("internal_leakage", "Cl"),
            ("external_leakage", "Ce1,Ce2"),
            ("valve_null_bias", "xb"),
            ("flow_gain_error", "kw"),
            ("bulk_modulus", "B"),
            ("supply_droop", "Rs"),
            ("sensor_lag", "tau"),
            ("valve_dead_band", "xd"),
        ];
        assert_eq!(spec.len(), EffectId::ALL.len());
        for (e, (id, params)) in EffectId::ALL.iter().zip(spec) {
            assert_eq!(e.id(), id);
            assert_eq!(EffectId::from_id(id), Some(*e));
            let names: Vec<&str> = e.params().iter().map(|p| p.name).collect();
            assert_eq!(names.join(","), params);
            for p in e.params() {
                assert!(p.lower < p.upper, "{id} {}", p.name);
            }
        }
        assert_eq!(EffectId::from_id("transport_delay"), None);
    }
}
