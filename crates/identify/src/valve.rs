//! The loop on the valve-controlled rig (`valve-cylinder`, preset
//! `leaney-moog`, assembled by hydrocyl-system): output-error simulation on
//! the measured command from the measured initial state, effect tracing by
//! output error, LM refits.
//!
//! ```text
//!   command u ─▶ servovalve (xb, kw) ─▶ chambers p1, p2 (Cl, Ce1, Ce2, B) ─▶ piston x, v (F0, b)
//!                                          measured: position, [velocity], p1, p2
//! ```
//!
//! Catalog effects that the rig file already has as parameters are switched
//! by those parameters: `valve_null_bias` (valve.null_bias_m), `flow_gain_error`
//! (valve.flow_gain), `internal_leakage` and `external_leakage`
//! (cylinder.*_leakage), `bulk_modulus` (fluid.bulk_modulus_pa),
//! `external_force` (load.external_force_n, + opposing extension),
//! `viscous` (the coulomb-viscous law's b), `supply_droop`
//! (supply.droop_resistance_pa_s_per_m3) and `sensor_lag`
//! (sensors.pressure_lag_s: the simulated p1/p2 are then the lagged sensor
//! readings the record is compared with) and `valve_dead_band`
//! (valve.dead_band_m). An effect is "off" at its neutral
//! value (0, or kw = 1); `bulk_modulus` is always declared, so tracing it
//! means refitting B away from the declared value.
//!
//! Tracing here is by output error, not equation error: each candidate's
//! parameters are estimated on the training part of the record by two
//! Gauss–Newton steps of the simulated whole rig, and scored by the share of the output-error sum of squares they
//! remove, each channel weighted by the inverse of its noise level (the
//! maximum-likelihood weighting for Gaussian sensor noise) (whole record, held-out part, ΔBIC). The valve rig
//! simulates 3 s in about 20 ms, so this is affordable and avoids the
//! chamber-volume and spool-state reconstruction an equation-error flow
//! residual needs.

use std::collections::BTreeMap;
use std::time::Instant;

use hydrocyl_friction::{FrictionLaw, LuGre, SteadySet, Stribeck, StribeckCurve};
use hydrocyl_ports::{Force, Velocity};
use hydrocyl_system::run::RunOptions;
use hydrocyl_system::signal::Signal as CmdSignal;
use hydrocyl_system::valve_rig::ValveRig;

use crate::catalog::EffectId;
use crate::data::{Record, Signal};
use crate::data_checks::{check_record, ProblemKind, RigFacts};
use crate::diagnose::{
    nrmse, DiagnoseError, DiagnoseOptions, EffectReport, NotApplicable, Probe, RecordTrace, Report,
};
use crate::lm::{self, LmOptions};
use crate::smooth::{noise_sigma, smooth_gcv, smooth_with};

mod accept;
mod stops;

/// Most candidates refitted in one round of the loop (the best by traced
/// share first); each refit is a full Levenberg–Marquardt fit.
const MAX_REFITS_PER_ROUND: usize = 3;

/// Effects the valve rig exposes as parameters.
pub const VALVE_EFFECTS: [EffectId; 15] = [
    EffectId::CoulombAsymmetry,
    EffectId::Stribeck,
    EffectId::PressureViscous,
    EffectId::AccelerationFriction,
    EffectId::LugreDynamics,
    EffectId::ValveNullBias,
    EffectId::FlowGainError,
    EffectId::InternalLeakage,
    EffectId::ExternalLeakage,
    EffectId::BulkModulus,
    EffectId::ExternalForce,
    EffectId::Viscous,
    EffectId::SupplyDroop,
    EffectId::SensorLag,
    EffectId::ValveDeadBand,
];

/// Why effect `id` is not tried on this valve rig.
fn not_applicable_why(id: EffectId, rig: &ValveRig, opts: &DiagnoseOptions) -> String {
    if opts.candidates.as_ref().is_some_and(|c| !c.contains(&id)) {
        return "left out by --effects".into();
    }
    if !VALVE_EFFECTS.contains(&id) {
        return "not a parameter of the valve rig".into();
    }
    format!(
        "its parameters are not switchable on the declared friction law `{}` (coulomb-viscous, stribeck and lugre are)",
        rig.friction.name()
    )
}

/// The channels compared, in report order.
const CHANNELS: [Signal; 4] = [Signal::Position, Signal::Velocity, Signal::P1, Signal::P2];

/// Value of catalog parameter `name` of effect `id` in the rig (SI).
pub fn get(rig: &ValveRig, id: EffectId, name: &str) -> Option<f64> {
    Some(match (id, name) {
        (EffectId::ValveNullBias, "xb") => rig.valve.null_bias_m,
        (EffectId::FlowGainError, "kw") => rig.valve.flow_gain,
        (EffectId::InternalLeakage, "Cl") => rig.cylinder.internal_leakage_m3_per_s_pa,
        (EffectId::ExternalLeakage, "Ce1") => rig.cylinder.external_leakage_1_m3_per_s_pa,
        (EffectId::ExternalLeakage, "Ce2") => rig.cylinder.external_leakage_2_m3_per_s_pa,
        (EffectId::BulkModulus, "B") => rig.fluid.bulk_modulus_pa,
        (EffectId::ExternalForce, "F0") => rig.load.external_force_n,
        (EffectId::SupplyDroop, "Rs") => rig.supply.droop_resistance_pa_s_per_m3,
        (EffectId::SensorLag, "tau") => rig.sensors.pressure_lag_s,
        (EffectId::ValveDeadBand, "xd") => rig.valve.dead_band_m,
        (EffectId::PressureViscous, "K") => rig.friction_terms.k_pressure,
        (EffectId::AccelerationFriction, "H") => rig.friction_terms.h_acceleration,
        (EffectId::Viscous, "b") => match &rig.friction {
            FrictionLaw::CoulombViscous(c) => c.viscous,
            law => friction_sets(law)?.0.sigma2,
        },
        (EffectId::CoulombAsymmetry, "dFc") => {
            let (e, r) = friction_sets(&rig.friction)?;
            e.curve.coulomb.si() - r.curve.coulomb.si()
        }
        (EffectId::Stribeck, n) => {
            let (e, r) = friction_sets(&rig.friction)?;
            if !has_hump(&e, &r) {
                0.0
            } else {
                match n {
                    // the mean stiction level: Fc (mean) + the hump, which
                    // both directions share
                    "Fs" => 0.5 * (e.curve.stiction.si() + r.curve.stiction.si()),
                    "vs" => e.curve.stribeck_velocity.si(),
                    "alpha" => e.curve.stribeck_exponent,
                    _ => return None,
                }
            }
        }
        (EffectId::LugreDynamics, n) => match &rig.friction {
            FrictionLaw::LuGre(l) => match n {
                "sigma0" => l.sigma0,
                "sigma1" => l.sigma1,
                _ => return None,
            },
            law => {
                friction_sets(law)?;
                0.0
            }
        },
        _ => return None,
    })
}

/// `true` when the direction sets have a hump (stiction level away from
/// the Coulomb level in either direction).
fn has_hump(e: &SteadySet, r: &SteadySet) -> bool {
    e.curve.stiction != e.curve.coulomb || r.curve.stiction != r.curve.coulomb
}

/// Smoothing velocity of `sgn(v)` given to a static law made from a LuGre
/// law when `lugre_dynamics` is switched off again (LuGre has none; the
/// declared one is not kept) \[m·s⁻¹\]: the `leaney-moog` value.
const STATIC_SMOOTHING: f64 = 1e-3;

/// The two direction sets (Stribeck curve and σ2) of the rig's friction
/// law: a LuGre's or a Stribeck law's own, the coulomb-viscous law's exact
/// Stribeck equivalent ([`as_stribeck`]); `None` for the other laws.
fn friction_sets(law: &FrictionLaw) -> Option<(SteadySet, SteadySet)> {
    match law {
        FrictionLaw::LuGre(l) => Some((l.extending, l.retracting)),
        _ => as_stribeck(law).map(|s| (s.extending, s.retracting)),
    }
}

/// Edits the two direction sets in place: a LuGre law's, else those of the
/// law as a Stribeck law (the coulomb-viscous law is converted exactly).
fn with_sets(law: &mut FrictionLaw, f: impl FnOnce(&mut SteadySet, &mut SteadySet)) {
    match law {
        FrictionLaw::LuGre(l) => f(&mut l.extending, &mut l.retracting),
        _ => {
            if let Some(mut s) = as_stribeck(law) {
                f(&mut s.extending, &mut s.retracting);
                *law = FrictionLaw::Stribeck(s);
            }
        }
    }
}

/// The valve rig's friction law as a [`Stribeck`] law (two direction sets),
/// converting the declared coulomb-viscous law exactly: `Fc tanh(v/v_t) + b v`
/// is the Stribeck law with `Fs = Fc` (no hump) and `σ2 = b` in both
/// directions (its `vs` = 10 mm/s and `α` = 1 are then inert). Other laws:
/// `None` (their friction effects are not switchable here).
fn as_stribeck(law: &FrictionLaw) -> Option<Stribeck> {
    match law {
        FrictionLaw::Stribeck(s) => Some(*s),
        FrictionLaw::CoulombViscous(c) => {
            let set = SteadySet {
                curve: StribeckCurve {
                    coulomb: c.coulomb,
                    stiction: c.coulomb,
                    stribeck_velocity: Velocity::new(0.01),
                    stribeck_exponent: 1.0,
                },
                sigma2: c.viscous,
            };
            Some(Stribeck {
                extending: set,
                retracting: set,
                smoothing_velocity: c.smoothing_velocity,
            })
        }
        _ => None,
    }
}

/// Mean Coulomb level of the two directions \[N\] (the declared Fc).
fn mean_coulomb(rig: &ValveRig) -> f64 {
    friction_sets(&rig.friction).map_or(0.0, |(e, r)| {
        0.5 * (e.curve.coulomb.si() + r.curve.coulomb.si())
    })
}

/// Sets catalog parameter `name` of effect `id` in the rig.
pub fn set(rig: &mut ValveRig, id: EffectId, name: &str, v: f64) {
    match (id, name) {
        (EffectId::ValveNullBias, "xb") => rig.valve.null_bias_m = v,
        (EffectId::FlowGainError, "kw") => rig.valve.flow_gain = v,
        (EffectId::InternalLeakage, "Cl") => rig.cylinder.internal_leakage_m3_per_s_pa = v,
        (EffectId::ExternalLeakage, "Ce1") => rig.cylinder.external_leakage_1_m3_per_s_pa = v,
        (EffectId::ExternalLeakage, "Ce2") => rig.cylinder.external_leakage_2_m3_per_s_pa = v,
        (EffectId::BulkModulus, "B") => rig.fluid.bulk_modulus_pa = v,
        (EffectId::ExternalForce, "F0") => rig.load.external_force_n = v,
        (EffectId::SupplyDroop, "Rs") => rig.supply.droop_resistance_pa_s_per_m3 = v,
        (EffectId::SensorLag, "tau") => rig.sensors.pressure_lag_s = v,
        (EffectId::ValveDeadBand, "xd") => rig.valve.dead_band_m = v,
        (EffectId::PressureViscous, "K") => rig.friction_terms.k_pressure = v,
        (EffectId::AccelerationFriction, "H") => rig.friction_terms.h_acceleration = v,
        (EffectId::Viscous, "b") => match &mut rig.friction {
            FrictionLaw::CoulombViscous(c) => c.viscous = v,
            law => with_sets(law, |e, r| {
                e.sigma2 = v;
                r.sigma2 = v;
            }),
        },
        (EffectId::CoulombAsymmetry, "dFc") => with_sets(&mut rig.friction, |e, r| {
            // extending Fc + dFc/2, retracting Fc − dFc/2 (as on the friction
            // bench), each direction's hump kept
            let mean = 0.5 * (e.curve.coulomb.si() + r.curve.coulomb.si());
            for (set, level) in [(e, mean + 0.5 * v), (r, mean - 0.5 * v)] {
                let hump = set.curve.stiction.si() - set.curve.coulomb.si();
                set.curve.coulomb = Force::new(level);
                set.curve.stiction = Force::new(level + hump);
            }
        }),
        (EffectId::Stribeck, n) => with_sets(&mut rig.friction, |e, r| {
            let on = has_hump(e, r);
            match n {
                // Fs = 0 is the catalog's "off": no hump
                "Fs" => {
                    let mean = 0.5 * (e.curve.coulomb.si() + r.curve.coulomb.si());
                    let hump = if v == 0.0 { 0.0 } else { v - mean };
                    for set in [e, r] {
                        set.curve.stiction = Force::new(set.curve.coulomb.si() + hump);
                    }
                }
                // vs and alpha are inert without a hump; 0 (off) leaves them
                "vs" if on || v != 0.0 => {
                    e.curve.stribeck_velocity = Velocity::new(v);
                    r.curve.stribeck_velocity = Velocity::new(v);
                }
                "alpha" if on || v != 0.0 => {
                    e.curve.stribeck_exponent = v;
                    r.curve.stribeck_exponent = v;
                }
                _ => {}
            }
        }),
        // σ0 = 0 is the catalog's "off": the static law with the same
        // curves; σ0 ≠ 0 puts the bristles in, keeping the curves and σ2
        (EffectId::LugreDynamics, "sigma0") => match &mut rig.friction {
            FrictionLaw::LuGre(l) if v != 0.0 => l.sigma0 = v,
            FrictionLaw::LuGre(l) => {
                rig.friction = FrictionLaw::Stribeck(Stribeck {
                    extending: l.extending,
                    retracting: l.retracting,
                    smoothing_velocity: Velocity::new(STATIC_SMOOTHING),
                });
            }
            law if v != 0.0 => {
                if let Some((e, r)) = friction_sets(law) {
                    *law = FrictionLaw::LuGre(LuGre {
                        sigma0: v,
                        sigma1: 0.0,
                        extending: e,
                        retracting: r,
                    });
                }
            }
            _ => {}
        },
        // σ1 is inert without bristles
        (EffectId::LugreDynamics, "sigma1") => {
            if let FrictionLaw::LuGre(l) = &mut rig.friction {
                l.sigma1 = v;
            }
        }
        _ => {}
    }
}

/// Where the trace of an effect that is off starts (one rig per start;
/// the trace keeps the best): its neutral values, except
/// * `stribeck`, whose hump must exist for vs and α to be seen at all (at
///   Fs = Fc their Jacobian columns vanish): Fs = 2 Fc, vs = 10 mm/s, α = 1;
/// * `lugre_dynamics`, where a tiny σ0 would be soft, metre-long bristles,
///   not a small step from "off": σ1 = 1000 N·s/m with σ0 = 1e5 and 1e6 N/m
///   (relaxation lengths Fc/σ0 of 0.5 mm and 50 µm at the preset's Fc). The
///   σ0–σ1 surface has two basins on this rig: from 1e6 alone the fit of a
///   planted σ0 = 2e5, σ1 = 600 stopped at σ0 = 3.5e5, σ1 ≈ 0 (a slightly
///   worse fit, with an interval that excluded the truth), so both are tried.
///
/// Generic values, not the planted ones.
fn trace_starts(rig: &ValveRig, id: EffectId) -> Vec<ValveRig> {
    let mut r = rig.clone();
    if is_on(rig, id) {
        return vec![r];
    }
    match id {
        EffectId::Stribeck => {
            let fc = mean_coulomb(rig);
            set(&mut r, id, "Fs", 2.0 * fc);
            set(&mut r, id, "vs", 0.01);
            set(&mut r, id, "alpha", 1.0);
            vec![r]
        }
        EffectId::LugreDynamics => [1e5, 1e6]
            .iter()
            .map(|&s0| {
                let mut r = rig.clone();
                set(&mut r, id, "sigma0", s0);
                set(&mut r, id, "sigma1", 1000.0);
                r
            })
            .collect(),
        _ => vec![r],
    }
}

/// `true` when effect `id` is on (a parameter away from its neutral value).
pub fn is_on(rig: &ValveRig, id: EffectId) -> bool {
    id.params().iter().any(|p| {
        get(rig, id, p.name).is_some_and(|v| match id {
            EffectId::FlowGainError => v != 1.0,
            _ => v != 0.0,
        })
    })
}

/// A typical magnitude of a parameter (scales the fit and its first step).
fn typical(id: EffectId, name: &str, rig: &ValveRig) -> f64 {
    match (id, name) {
        (EffectId::ValveNullBias | EffectId::ValveDeadBand, _) => 0.01 * rig.valve.stroke_m,
        (EffectId::FlowGainError, _) => 1.0,
        (EffectId::InternalLeakage | EffectId::ExternalLeakage, _) => 1e-12,
        (EffectId::BulkModulus, _) => rig.fluid.bulk_modulus_pa,
        (EffectId::ExternalForce, _) => 100.0,
        (EffectId::Viscous, _) => 1000.0,
        (EffectId::CoulombAsymmetry, _) | (EffectId::Stribeck, "Fs") => mean_coulomb(rig).max(1.0),
        (EffectId::Stribeck, "vs") => 0.01,
        (EffectId::Stribeck, _) => 1.0,
        (EffectId::LugreDynamics, "sigma0") => 1e6,
        (EffectId::LugreDynamics, _) => 1000.0,
        // a droop of 1 bar at 6 l/min
        (EffectId::SupplyDroop, _) => 1e9,
        (EffectId::SensorLag, _) => 5e-3,
        // 10 N at half the supply across the piston and 10 mm/s
        (EffectId::PressureViscous, _) => {
            10.0 / ((0.5 * rig.supply.pressure_pa).powi(2) * 0.01).max(1e-300)
        }
        // K H = 10 % of the moving mass
        (EffectId::AccelerationFriction, _) => {
            0.1 * rig.load.mass_kg / rig.friction_terms.k_pressure.max(1e-300)
        }
    }
}

/// The smallest size of an effect worth adding: below it the effect cannot
/// be told from the declared rig by any measurement (a flow gain 0.1 % off
/// nominal, a leakage passing 1e-14 m³/s per Pa). A fit that lands below it
/// is absorbing simulation or initial-state error, not finding an effect.
fn negligible(id: EffectId, rig: &ValveRig, declared: &ValveRig) -> bool {
    let v = |n: &str| get(rig, id, n).unwrap_or(0.0);
    match id {
        EffectId::ValveNullBias => v("xb").abs() < 1e-3 * rig.valve.stroke_m,
        EffectId::ValveDeadBand => v("xd") < 1e-3 * rig.valve.stroke_m,
        EffectId::FlowGainError => (v("kw") - 1.0).abs() < 5e-3,
        EffectId::InternalLeakage => v("Cl") < 1e-14,
        EffectId::ExternalLeakage => v("Ce1").max(v("Ce2")) < 1e-14,
        EffectId::BulkModulus => (v("B") / declared.fluid.bulk_modulus_pa - 1.0).abs() < 0.02,
        EffectId::ExternalForce => v("F0").abs() < 5.0,
        EffectId::Viscous => v("b").abs() < 10.0,
        // droop below 0.5 % of the supply at the valve's full-opening flow
        // (half the supply across each edge)
        EffectId::SupplyDroop => {
            let m = rig.metering();
            let q_full = m.orifice.coefficient()
                * m.area_gradient()
                * (rig.valve.stroke_m + rig.valve.underlap_m)
                * (0.5 * rig.supply.pressure_pa).max(0.0).sqrt();
            v("Rs") * q_full < 5e-3 * rig.supply.pressure_pa
        }
        // a lag under 0.1 ms is below any record's resolution here
        EffectId::SensorLag => v("tau") < 1e-4,
        // under 1 N at half the supply across the piston and 10 mm/s
        EffectId::PressureViscous => v("K") * (0.5 * rig.supply.pressure_pa).powi(2) * 0.01 < 1.0,
        // an added mass K H under 1 % of the moving mass
        EffectId::AccelerationFriction => {
            rig.friction_terms.k_pressure * v("H") < 0.01 * rig.load.mass_kg
        }
        // friction terms under 5 % of the declared Coulomb level
        EffectId::CoulombAsymmetry => v("dFc").abs() < 0.05 * mean_coulomb(declared),
        EffectId::Stribeck => {
            v("Fs") == 0.0 || (v("Fs") - mean_coulomb(rig)).abs() < 0.05 * mean_coulomb(declared)
        }
        // bristles so stiff that their relaxation length Fc/σ0 is under
        // 10 µm (half the position noise of the generated records) act as
        // static friction
        EffectId::LugreDynamics => v("sigma0") == 0.0 || mean_coulomb(rig) / v("sigma0") < 1e-5,
    }
}

/// Fit bounds of a valve-rig parameter (the catalog's, with the spool
/// offset limited to the spool stroke).
fn bounds(id: EffectId, name: &str, rig: &ValveRig) -> (f64, f64) {
    match id {
        EffectId::ValveNullBias => (-rig.valve.stroke_m, rig.valve.stroke_m),
        // a dead zone up to half the spool stroke
        EffectId::ValveDeadBand => (0.0, 0.5 * rig.valve.stroke_m),
        // both directions keep a positive Coulomb level
        EffectId::CoulombAsymmetry => {
            let fc = mean_coulomb(rig);
            (-1.9 * fc, 1.9 * fc)
        }
        // A break-away level beyond 10x the Coulomb level would say the
        // declared friction is wrong altogether, not that it lacks a hump; α
        // down to 0.1 (the thesis's Table 5-8 has 0.11) and vs from 0.1 mm/s.
        // Without these limits a Gauss-Newton step from the generic start
        // went to Fs = 17 kN, α = 0.07, where the curve is so steep at v = 0
        // that one simulation took seconds.
        EffectId::Stribeck => match name {
            "Fs" => (0.0, 10.0 * mean_coulomb(rig)),
            "vs" => (1e-4, 1.0),
            _ => (0.1, 4.0),
        },
        // σ0 above 1e7 N/m makes the bristle state stiff for the explicit
        // integrator (relaxation time Fc/(σ0 |v|) of 0.1 ms at 50 mm/s) and is
        // static friction to within the position noise anyway (below)
        EffectId::LugreDynamics => match name {
            "sigma0" => (1e3, 1e7),
            _ => (0.0, 1e5),
        },
        EffectId::ExternalForce => (-1e6, 1e6),
        // K up to 1 kN at half the supply and 10 mm/s; K H up to 10x the mass
        EffectId::PressureViscous => (0.0, 100.0 * typical(id, name, rig)),
        EffectId::AccelerationFriction => (0.0, 100.0 * typical(id, name, rig)),
        _ => id
            .params()
            .iter()
            .find(|p| p.name == name)
            .map_or((f64::NEG_INFINITY, f64::INFINITY), |p| (p.lower, p.upper)),
    }
}

/// What the data checks need to know about a valve rig: the stroke, the
/// supply above tank and the steady velocity per unit command at full
/// demand (mean of the two directions; none with a drooping supply).
pub fn rig_facts(rig: &ValveRig) -> RigFacts {
    let xm = rig.valve.stroke_m;
    let gain = match (rig.steady_velocity(xm), rig.steady_velocity(-xm)) {
        (Ok(up), Ok(down)) if up > 0.0 && down < 0.0 => Some(0.5 * (up - down)),
        _ => None,
    };
    RigFacts {
        stroke: rig.cylinder.stroke_m,
        supply: rig.supply.pressure_pa - rig.supply.tank_pressure_pa,
        velocity_gain: gain,
    }
}

#[derive(Clone)]
struct Prepared {
    /// Relative tolerance of the simulations (looser while tracing).
    rtol: f64,
    t: Vec<f64>,
    /// The run's input: the measured command (open loop) or the position
    /// reference (a closed-loop record, whose rig's controller computes the
    /// command).
    input: Vec<f64>,
    /// Whether the record is closed loop (it has a `reference` column).
    closed: bool,
    /// The measured command at the first sample (the initial spool demand;
    /// `None` in a closed-loop record without a `command` column: the
    /// controller's output at the first sample is taken).
    command0: Option<f64>,
    /// Measured channels present (velocity: measured, else smoothed derivative).
    meas: Vec<(Signal, Vec<f64>)>,
    ranges: Vec<f64>,
    /// Weight of each channel in the output error: 1/σ (its noise, floored at
    /// 1e-4 of its range); 0 for a velocity derived from position (it would
    /// count the position twice).
    weights: Vec<f64>,
    /// Initial state estimates: smoothed position, velocity, p1, p2 at t0.
    x0: Option<f64>,
    v0: Option<f64>,
    p10: Option<f64>,
    p20: Option<f64>,
    /// Restarts of the simulation where the measured piston leaves a stop.
    restarts: Vec<stops::Restart>,
}

fn prepare(
    rec: &Record,
    half: Option<usize>,
    excluded: &[Signal],
    stroke: f64,
) -> Result<(Prepared, crate::smooth::SmootherInfo), DiagnoseError> {
    let t = rec.time.clone();
    let closed = rec.get(Signal::Reference).is_some();
    let input = if closed {
        rec.require(Signal::Reference)?.to_vec()
    } else {
        rec.require(Signal::Command)?.to_vec()
    };
    let command0 = rec.get(Signal::Command).map(|u| u[0]);
    let x = rec.require(Signal::Position)?;
    let s = match half {
        Some(h) => smooth_with(&t, x, h, 3),
        None => smooth_gcv(&t, x, 3, 400),
    };
    let position_ok = !excluded.contains(&Signal::Position);
    let mut meas = Vec::new();
    // In closed loop the measured command is an output: compared like the others.
    let compared = CHANNELS
        .into_iter()
        .chain(closed.then_some(Signal::Command));
    for ch in compared {
        if excluded.contains(&ch) {
            continue;
        }
        match (ch, rec.get(ch)) {
            (_, Some(v)) => meas.push((ch, v.to_vec())),
            (Signal::Velocity, None) if position_ok => meas.push((ch, s.d1.clone())),
            _ => {}
        }
    }
    let ranges = meas
        .iter()
        .map(|(_, v)| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (hi - lo).max(1e-300)
        })
        .collect();
    let weights = meas
        .iter()
        .zip(&ranges)
        .map(|((ch, y), r)| {
            if *ch == Signal::Velocity && rec.get(Signal::Velocity).is_none() {
                0.0
            } else {
                1.0 / noise_sigma(y).max(1e-4 * r)
            }
        })
        .collect();
    // A position left out of the fit (a data problem) gives no initial
    // state: the rig's declared one is kept.
    let v0 = match rec.get(Signal::Velocity) {
        Some(v) if !excluded.contains(&Signal::Velocity) => Some(v[0]),
        _ => position_ok.then(|| s.d1[0]),
    };
    // The first sample's noise would start the simulation off the record:
    // take the smoothed values at t0 (local cubic fit over the GCV window).
    let p0 = |sig: Signal| {
        (!excluded.contains(&sig))
            .then(|| rec.get(sig).map(|y| smooth_gcv(&t, y, 3, 100).value[0]))
            .flatten()
    };
    let (p10, p20) = (p0(Signal::P1), p0(Signal::P2));
    let restarts = if position_ok {
        stops::restarts(x, stroke, (5.0 * noise_sigma(x)).max(1e-4 * stroke))
    } else {
        Vec::new()
    };
    Ok((
        Prepared {
            rtol: 1e-8,
            x0: position_ok.then(|| s.value[0]),
            p10,
            p20,
            restarts,
            t,
            input,
            closed,
            command0,
            meas,
            ranges,
            weights,
            v0,
        },
        s.info,
    ))
}

/// Sets the rig's initial state from the record: measured position, velocity
/// and chamber pressures at the first sample (the steady pressures of the
/// rig when p1/p2 are not measured), spool at the first command.
fn with_initial(rig: &ValveRig, p: &Prepared) -> ValveRig {
    let mut r = rig.clone();
    if let Some(x0) = p.x0 {
        let half = 0.5 * r.cylinder.stroke_m;
        r.initial.position = x0.clamp(-half, half);
    }
    if let Some(v0) = p.v0 {
        r.initial.velocity = v0;
    }
    let u0 = match (p.command0, &r.controller) {
        (Some(u), _) => u,
        (None, Some(c)) => (c.gain_per_m * (p.input[0] - r.initial.position) + c.bias)
            .clamp(c.output_min, c.output_max),
        (None, None) => 0.0,
    };
    r.initial.spool = (u0 * r.valve.stroke_m).clamp(-r.valve.stroke_m, r.valve.stroke_m);
    r.initial.p1 = p.p10;
    r.initial.p2 = p.p20;
    r
}

/// Simulates and returns, per measured channel, the simulated series.
///
/// `sensor_lag` is applied here as a measurement model on the simulated
/// samples ([`lag_samples`]) rather than by the rig's sensor states: the rig
/// is run with ideal sensors. A lag state with τ far below the integrator's
/// step makes the system stiff (the fit's first finite-difference steps
/// start from τ = 0), and the sampled filter is smooth in τ down to 0. On
/// 1 kHz records of this rig the two agree to well under the sensor noise
/// (the planted `sensor_lag` test generates its record with the states).
fn simulate(rig: &ValveRig, p: &Prepared) -> Result<Vec<Vec<f64>>, String> {
    simulate_prefix(rig, p, p.t.len())
}

/// [`simulate`] over the first `n` samples only (the training part needs no
/// more; at least two samples are simulated).
fn simulate_prefix(rig: &ValveRig, p: &Prepared, n: usize) -> Result<Vec<Vec<f64>>, String> {
    let n = n.clamp(2.min(p.t.len()), p.t.len());
    let t = &p.t[..n];
    let cmd = CmdSignal::table(p.t.clone(), p.input.clone()).map_err(|e| e.to_string())?;
    let opts = RunOptions {
        rtol: p.rtol,
        ..RunOptions::default()
    };
    let tau = rig.sensors.pressure_lag_s;
    if !(tau.is_finite() && tau >= 0.0) {
        return Err(format!(
            "sensors.pressure_lag_s must be finite and non-negative, got {tau}"
        ));
    }
    let mut seg = rig.clone();
    seg.sensors.pressure_lag_s = 0.0;
    let mut out: Vec<Vec<f64>> = vec![Vec::with_capacity(n); p.meas.len()];
    // One segment per stretch between restarts at stop exits (`stops`).
    let mut cuts = p
        .restarts
        .iter()
        .filter(|r| r.index > 0 && r.index + 1 < n)
        .peekable();
    let mut a = 0;
    loop {
        let next = cuts.next();
        let b = next.map_or(n - 1, |r| r.index);
        let run = seg
            .simulate(cmd.clone(), &t[a..=b], &opts)
            .map_err(|e| e.to_string())?;
        // the restart sample belongs to the next segment
        let keep = if next.is_some() { b - a } else { b - a + 1 };
        for (o, (ch, _)) in out.iter_mut().zip(&p.meas) {
            let v = run
                .channel(ch.name())
                .ok_or_else(|| format!("simulation has no channel '{}'", ch.name()))?;
            o.extend_from_slice(&v[..keep]);
        }
        let Some(r) = next else { break };
        let last = |name: &str| run.channel(name).and_then(|v| v.last().copied());
        let xm = seg.valve.stroke_m;
        seg.initial.position = r.position;
        seg.initial.velocity = 0.0;
        seg.initial.spool = last("spool").unwrap_or(0.0).clamp(-xm, xm);
        seg.initial.p1 = last("p1");
        seg.initial.p2 = last("p2");
        a = b;
    }
    if tau > 0.0 {
        for (o, (ch, _)) in out.iter_mut().zip(&p.meas) {
            if matches!(ch, Signal::P1 | Signal::P2) {
                *o = lag_samples(t, o, tau);
            }
        }
    }
    Ok(out)
}

/// A first-order lag `τ dy/dt = u − y` applied to samples `u` at times `t`,
/// exact when `u` is linear between samples (first-order hold): over a step
/// `h` with `a = exp(−h/τ)` and slope `s = Δu/h`,
/// `y ← a y + (1 − a) u_k + s (h − τ (1 − a))`. It starts at rest
/// (`y_0 = u_0`), as the rig's sensor states do; `τ = 0` returns `u`.
pub fn lag_samples(t: &[f64], u: &[f64], tau: f64) -> Vec<f64> {
    let mut y = Vec::with_capacity(u.len());
    let Some(&u0) = u.first() else {
        return y;
    };
    y.push(u0);
    for k in 1..u.len().min(t.len()) {
        let h = t[k] - t[k - 1];
        let (a, tau_1a) = if tau > 0.0 {
            let a = (-h / tau).exp();
            (a, tau * (1.0 - a))
        } else {
            (0.0, 0.0)
        };
        let s = (u[k] - u[k - 1]) / h;
        let prev = y[k - 1];
        y.push(a * prev + (1.0 - a) * u[k - 1] + s * (h - tau_1a));
    }
    y
}

#[derive(Clone, Copy, PartialEq)]
enum Part {
    All,
    Train,
    Held,
}

fn residual(
    rig: &ValveRig,
    p: &Prepared,
    holdout: f64,
    part: Part,
    out: &mut Vec<f64>,
) -> Result<(), String> {
    let n = p.t.len();
    let cut = ((1.0 - holdout) * n as f64) as usize;
    let sims = if part == Part::Train {
        simulate_prefix(rig, p, cut)?
    } else {
        simulate(rig, p)?
    };
    let range = match part {
        Part::All => 0..n,
        Part::Train => 0..cut,
        Part::Held => cut..n,
    };
    out.clear();
    for ((_, m), (s, w)) in p.meas.iter().zip(sims.iter().zip(&p.weights)) {
        if *w == 0.0 {
            continue;
        }
        for i in range.clone() {
            out.push((s[i] - m[i]) * w);
        }
    }
    Ok(())
}

fn rss(rig: &ValveRig, p: &Prepared, holdout: f64, part: Part) -> f64 {
    let mut r = Vec::new();
    match residual(rig, p, holdout, part, &mut r) {
        Ok(()) => r.iter().map(|v| v * v).sum(),
        Err(_) => f64::INFINITY,
    }
}

type ParamList = Vec<(EffectId, &'static str)>;

/// Fits `params` of `rig` in place on `part`, together with the initial
/// piston position and velocity (nuisance parameters: the rig integrates
/// flow into position, so a few micrometres of initial offset would
/// otherwise be absorbed by whichever effect shifts the position; and the
/// smoother's derivative at the record's first sample is one-sided and
/// noisy, and an initial velocity a few cm/s off rings the chambers for a
/// tenth of a second). The result's last two entries are the initial
/// position and velocity.
fn fit(
    rig: &mut ValveRig,
    params: &ParamList,
    p: &Prepared,
    holdout: f64,
    part: Part,
) -> Result<lm::LmResult, lm::LmError> {
    let mut x0: Vec<f64> = params
        .iter()
        .map(|(id, n)| get(rig, *id, n).unwrap_or(0.0))
        .collect();
    let (mut lo, mut hi): (Vec<f64>, Vec<f64>) =
        params.iter().map(|(id, n)| bounds(*id, n, rig)).unzip();
    let mut typ: Vec<f64> = params
        .iter()
        .zip(&x0)
        .map(|((id, n), x)| x.abs().max(typical(*id, n, rig)))
        .collect();
    // the initial position stays within the stroke (a record may start
    // with the piston on a stop)
    let xi = rig.initial.position;
    let half = 0.5 * rig.cylinder.stroke_m;
    x0.push(xi);
    lo.push((xi - 0.01).max(-half));
    hi.push((xi + 0.01).min(half));
    typ.push(1e-3);
    let vi = rig.initial.velocity;
    x0.push(vi);
    lo.push(vi - 0.2);
    hi.push(vi + 0.2);
    typ.push(1e-2);
    let k = params.len();
    let mut work = rig.clone();
    let res = lm::fit(
        |x, r| {
            for ((id, n), v) in params.iter().zip(x) {
                set(&mut work, *id, n, *v);
            }
            work.initial.position = x[k];
            work.initial.velocity = x[k + 1];
            residual(&work, p, holdout, part, r)
        },
        &x0,
        &lo,
        &hi,
        &typ,
        &LmOptions {
            max_evaluations: 600,
            ftol: 1e-6,
            fd_step: 1e-3,
            blocks: p.weights.iter().filter(|w| **w > 0.0).count(),
        },
    )?;
    for ((id, n), v) in params.iter().zip(&res.x) {
        set(rig, *id, n, *v);
    }
    rig.initial.position = res.x[k];
    rig.initial.velocity = res.x[k + 1];
    Ok(res)
}

/// Traces a candidate cheaply: up to three backtracking Gauss–Newton steps on `part` from the
/// current values, with a finite-difference Jacobian (step 10 % of each
/// parameter's typical size) and the initial position and velocity as nuisance columns,
/// then clamped to the bounds. A handful of simulations per candidate instead
/// of a full Levenberg–Marquardt fit; the effect that is added is refitted
/// properly afterwards.
fn gauss_newton_trace(
    rig: &mut ValveRig,
    params: &ParamList,
    p: &Prepared,
    holdout: f64,
    part: Part,
) -> Result<(), String> {
    let k = params.len() + 2;
    for _ in 0..3 {
        let mut r0 = Vec::new();
        residual(rig, p, holdout, part, &mut r0)?;
        let m = r0.len();
        let mut jac = nalgebra::DMatrix::<f64>::zeros(m, k);
        for j in 0..k {
            let mut t = rig.clone();
            let h = if j < params.len() {
                let (id, n) = params[j];
                let h = 0.1 * typical(id, n, rig);
                set(&mut t, id, n, get(rig, id, n).unwrap_or(0.0) + h);
                h
            } else if j == params.len() {
                // step away from a stop the piston may start on
                let h = if t.initial.position + 1e-5 > 0.5 * rig.cylinder.stroke_m {
                    -1e-5
                } else {
                    1e-5
                };
                t.initial.position += h;
                h
            } else {
                t.initial.velocity += 1e-4;
                1e-4
            };
            let mut r1 = Vec::new();
            residual(&t, p, holdout, part, &mut r1)?;
            for i in 0..m {
                jac[(i, j)] = (r1[i] - r0[i]) / h;
            }
        }
        let rhs = jac.transpose() * nalgebra::DVector::from_column_slice(&r0);
        let mut a = jac.transpose() * &jac;
        for j in 0..k {
            a[(j, j)] *= 1.0 + 1e-9;
        }
        let delta = a
            .cholesky()
            .ok_or("singular trace Jacobian")?
            .solve(&(-rhs));
        // Backtrack: take the largest of 1, 1/2, 1/4, 1/8 of the step that
        // lowers the sum of squares (keep the point if none does).
        let rss0: f64 = r0.iter().map(|v| v * v).sum();
        let mut accepted = None;
        for alpha in [1.0, 0.5, 0.25, 0.125] {
            let mut t = rig.clone();
            for (j, (id, n)) in params.iter().enumerate() {
                let (lo, hi) = bounds(*id, n, rig);
                let v = (get(rig, *id, n).unwrap_or(0.0) + alpha * delta[j]).clamp(lo, hi);
                set(&mut t, *id, n, v);
            }
            let half = 0.5 * rig.cylinder.stroke_m;
            t.initial.position = (t.initial.position + alpha * delta[k - 2]).clamp(-half, half);
            t.initial.velocity += alpha * delta[k - 1];
            if rss(&t, p, holdout, part) < rss0 {
                accepted = Some(t);
                break;
            }
        }
        match accepted {
            Some(t) => *rig = t,
            None => break,
        }
    }
    Ok(())
}

/// Runs `f` on every item, spread over the available cores (at most one
/// thread per item; each thread takes the next item not yet taken, so a
/// slow item does not hold up a queue), and returns the results in the
/// order of `items`.
fn trace_parallel<I: Sync, T: Send>(items: &[I], f: &(dyn Fn(&I) -> T + Sync)) -> Vec<T> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len())
        .max(1);
    if threads == 1 {
        return items.iter().map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let mut slots: Vec<Option<T>> = std::iter::repeat_with(|| None).take(items.len()).collect();
    std::thread::scope(|sc| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                sc.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(item) = items.get(i) else { break };
                        done.push((i, f(item)));
                    }
                    done
                })
            })
            .collect();
        for h in handles {
            // A panicking trace is a bug; re-raise it on this thread.
            match h.join() {
                Ok(v) => {
                    for (i, r) in v {
                        slots[i] = Some(r);
                    }
                }
                Err(e) => std::panic::resume_unwind(e),
            }
        }
    });
    slots.into_iter().flatten().collect()
}

/// Out-of-catalog probe: the command reaching the rig late by τ (a
/// transport delay), τ on a grid up to 60 ms, initial position refitted.
fn delay_probe(rig: &ValveRig, p: &Prepared, holdout: f64) -> Option<Probe> {
    if p.closed {
        // the input is the reference, not the command the valve receives
        return None;
    }
    let rss0 = rss(rig, p, holdout, Part::All);
    let mut best = (0.0, rss0);
    for tau in [0.002, 0.005, 0.01, 0.015, 0.02, 0.03, 0.045, 0.06] {
        let mut q = Prepared {
            rtol: p.rtol,
            input: p
                .t
                .iter()
                .map(|&t| crate::data::interp_linear(&p.t, &p.input, t - tau))
                .collect(),
            closed: p.closed,
            command0: p.command0,
            t: p.t.clone(),
            meas: p.meas.clone(),
            ranges: p.ranges.clone(),
            weights: p.weights.clone(),
            x0: p.x0,
            v0: p.v0,
            p10: p.p10,
            p20: p.p20,
            restarts: p.restarts.clone(),
        };
        q.input[0] = p.input[0];
        let r = rss(rig, &q, holdout, Part::All);
        if r < best.1 {
            best = (tau, r);
        }
    }
    (best.0 > 0.0).then(|| Probe {
        kind: "delay".into(),
        what: "transport delay of the command".into(),
        value: best.0,
        explained_share: 1.0 - best.1 / rss0.max(1e-300),
    })
}

fn channel_nrmse(rig: &ValveRig, p: &Prepared) -> BTreeMap<String, f64> {
    simulate(rig, p).map_or_else(|_| BTreeMap::new(), |sims| nrmse_of(p, &sims))
}

/// NRMSE per measured channel of the simulated series `sims`.
fn nrmse_of(p: &Prepared, sims: &[Vec<f64>]) -> BTreeMap<String, f64> {
    p.meas
        .iter()
        .zip(sims)
        .map(|((ch, meas), s)| (ch.name().to_string(), nrmse(meas, s)))
        .collect()
}

/// Everything the loop on the valve rig produces: the report, the series for
/// plots (one [`RecordTrace`] per compared channel: measured, the declared
/// model after its initial-state fit, and the final model) and the final rig.
#[derive(Clone, Debug)]
pub struct ValveOutcome {
    /// The report.
    pub report: Report,
    /// Measured vs simulated before and after, per channel (SI units).
    pub traces: Vec<RecordTrace>,
    /// The final model: the declared rig with the added effects, refitted.
    pub rig: ValveRig,
}

/// Runs the loop on a valve-controlled rig and one record (command,
/// position, optionally velocity, p1, p2).
pub fn diagnose_valve(
    declared: &ValveRig,
    rec: &Record,
    opts: &DiagnoseOptions,
    progress: &mut dyn FnMut(&str, usize, usize),
) -> Result<Report, DiagnoseError> {
    diagnose_valve_traced(declared, rec, opts, progress).map(|o| o.report)
}

/// Measured, before and after series of every compared channel, from the
/// runs the report's NRMSEs were computed on (empty where a run failed).
fn traces(rec: &Record, p: &Prepared, before: &[Vec<f64>], after: &[Vec<f64>]) -> Vec<RecordTrace> {
    let velocity = p
        .meas
        .iter()
        .find(|(ch, _)| *ch == Signal::Velocity)
        .map_or_else(Vec::new, |(_, v)| v.clone());
    p.meas
        .iter()
        .zip(before.iter().zip(after))
        .map(|((ch, m), (b, a))| RecordTrace {
            source: rec.source.clone(),
            t: p.t.clone(),
            velocity: velocity.clone(),
            channel: ch.name().to_string(),
            measured: m.clone(),
            before: b.clone(),
            after: a.clone(),
            regressor: None,
        })
        .collect()
}

/// [`diagnose_valve`], also returning the measured and simulated series
/// before and after (the runs the report's NRMSEs come from) and the final rig.
pub fn diagnose_valve_traced(
    declared: &ValveRig,
    rec: &Record,
    opts: &DiagnoseOptions,
    progress: &mut dyn FnMut(&str, usize, usize),
) -> Result<ValveOutcome, DiagnoseError> {
    let start = Instant::now();
    let mut clock = crate::diagnose::StageClock::new();
    match (rec.get(Signal::Reference).is_some(), declared.controller.is_some()) {
        (true, false) => {
            return Err(DiagnoseError::Rig(format!(
                "{}: the record has a `reference` column (closed loop), but rig `{}` has no controller: use a closed-loop rig (e.g. the `leaney-moog-closed-loop` preset)",
                rec.source, declared.name
            )))
        }
        (false, true) => {
            return Err(DiagnoseError::Rig(format!(
                "{}: rig `{}` is closed loop (it has a controller), but the record has no `reference` column to drive it",
                rec.source, declared.name
            )))
        }
        _ => {}
    }
    // Data problems first: each named channel is left out of the fit.
    let data_problems = check_record(rec, Some(&rig_facts(declared)));
    let mut excluded: Vec<Signal> = data_problems
        .iter()
        .filter_map(|p| Signal::from_name(&p.channel))
        .collect();
    if data_problems.iter().any(|p| p.kind == ProblemKind::Sign) {
        excluded.push(Signal::Velocity);
    }
    let (p, info) = prepare(rec, opts.half_window, &excluded, declared.cylinder.stroke_m)?;
    if p.weights.iter().all(|w| *w == 0.0) {
        let why = if data_problems.is_empty() {
            "no measured channel to compare (position, velocity, p1, p2)".to_string()
        } else {
            data_problems
                .iter()
                .map(|p| p.message.as_str())
                .collect::<Vec<_>>()
                .join("; ")
        };
        return Err(DiagnoseError::Unusable {
            file: rec.source.clone(),
            why,
        });
    }
    let mut rig0 = with_initial(declared, &p);
    simulate(&rig0, &p)
        .map_err(|e| DiagnoseError::Rig(format!("declared model does not simulate: {e}")))?;
    let nrmse_declared = channel_nrmse(&rig0, &p);
    let mut warnings: Vec<String> = data_problems
        .iter()
        .map(|p| format!("{} left out of the fit: {}", p.channel, p.message))
        .collect();
    // Tracing compares candidates with each other, and the initial-state
    // fit below only starts the refits: a looser integration tolerance is
    // enough there. The refits use the tight one (a loose one puts
    // integration noise into the finite-difference Jacobian, which narrows
    // the confidence intervals below their coverage).
    let pt = Prepared {
        rtol: 1e-6,
        ..p.clone()
    };
    // The declared model's own refit: the initial position and velocity
    // only (the nuisance parameters of every later fit), so that what the
    // effects are scored against is not an initial transient.
    {
        let mut r = rig0.clone();
        match fit(&mut r, &Vec::new(), &pt, opts.holdout, Part::All) {
            Ok(_) => rig0 = r,
            Err(e) => warnings.push(format!(
                "initial-state fit: {e}; the smoother's initial position and velocity are kept"
            )),
        }
    }
    clock.lap("checks, smoothing and initial-state fit");
    let sims_before = simulate(&rig0, &p).unwrap_or_default();
    let nrmse_before = nrmse_of(&p, &sims_before);
    let rss_before = rss(&rig0, &p, opts.holdout, Part::All);
    let candidates: Vec<EffectId> = opts
        .candidates
        .clone()
        .unwrap_or_else(|| EffectId::ALL.to_vec())
        .into_iter()
        .filter(|e| VALVE_EFFECTS.contains(e))
        .filter(|e| e.params().iter().all(|q| get(&rig0, *e, q.name).is_some()))
        .collect();
    // Noise floor of each compared channel as an NRMSE (the weights' floor
    // of 1e-4 of the range for noise-free records).
    let floors: BTreeMap<String, f64> = p
        .meas
        .iter()
        .zip(p.ranges.iter().zip(&p.weights))
        .filter(|(_, (_, w))| **w > 0.0)
        .map(|((ch, _), (r, w))| (ch.name().to_string(), 1.0 / (w * r)))
        .collect();
    let mut model = rig0.clone();
    let mut free: ParamList = Vec::new();
    let mut added: Vec<EffectReport> = Vec::new();
    let mut last: BTreeMap<EffectId, EffectReport> = BTreeMap::new();
    let mut resembles: Option<Probe> = None;
    let total = opts.max_effects + 1;
    for round in 0..opts.max_effects {
        progress(&format!("tracing, round {}", round + 1), round, total);
        let mut r0 = Vec::new();
        residual(&model, &pt, opts.holdout, Part::All, &mut r0)
            .map_err(|e| DiagnoseError::Rig(e.to_string()))?;
        let rss0: f64 = r0.iter().map(|v| v * v).sum();
        let rss0_held = rss(&model, &pt, opts.holdout, Part::Held);
        let rho = lm::lag1_autocorrelation(&r0).clamp(0.0, 0.999);
        let neff = (r0.len() as f64 * (1.0 - rho) / (1.0 + rho)).max(2.0);
        let mut todo: Vec<EffectId> = candidates
            .iter()
            .copied()
            .filter(|&id| id == EffectId::BulkModulus || !is_on(&model, id))
            .filter(|id| !added.iter().any(|a| a.id == id.id()))
            .collect();
        // `K H a` needs the pressure term's K (eq 5.12)
        if model.friction_terms.k_pressure == 0.0 {
            let id = EffectId::AccelerationFriction;
            if let Some(k) = todo.iter().position(|e| *e == id) {
                todo.remove(k);
                last.insert(
                    id,
                    EffectReport {
                        id: id.id().into(),
                        params: BTreeMap::new(),
                        ci95: BTreeMap::new(),
                        explained_share: 0.0,
                        heldout_share: 0.0,
                        delta_bic: 0.0,
                        reason: Some(
                            "not traced: needs pressure_viscous's K (the term is K H a, eq 5.12)"
                                .into(),
                        ),
                    },
                );
            }
        }
        // One job per candidate and start (see `trace_starts`).
        let jobs: Vec<(EffectId, ValveRig)> = todo
            .iter()
            .flat_map(|&id| trace_starts(&model, id).into_iter().map(move |r| (id, r)))
            .collect();
        let trace_one = |job: &(EffectId, ValveRig)| -> (ValveRig, EffectReport, f64) {
            let id = job.0;
            let params: ParamList = id.params().iter().map(|q| (id, q.name)).collect();
            // The candidate is traced together with the effects already added
            // (refitted jointly), so that an earlier effect that was standing
            // in for this one can give way.
            let joint: ParamList = free.iter().chain(params.iter()).copied().collect();
            let mut trial = job.1.clone();
            let res = gauss_newton_trace(&mut trial, &joint, &pt, opts.holdout, Part::Train);
            let rss_train = rss(&trial, &pt, opts.holdout, Part::Train);
            let rss1 = rss(&trial, &pt, opts.holdout, Part::All);
            let rss1_held = rss(&trial, &pt, opts.holdout, Part::Held);
            // A trace whose simulation fails scores nothing (finite numbers
            // only reach the report) and says why below.
            let sim_failed = !(rss1.is_finite() && rss1_held.is_finite() && rss_train.is_finite());
            let (share, held, dbic) = if sim_failed {
                (0.0, 0.0, 0.0)
            } else {
                (
                    1.0 - rss1 / rss0.max(1e-300),
                    1.0 - rss1_held / rss0_held.max(1e-300),
                    neff * (rss1 / rss0.max(1e-300)).max(1e-300).ln()
                        + params.len() as f64 * neff.ln(),
                )
            };
            let mut rep = EffectReport {
                id: id.id().into(),
                params: params
                    .iter()
                    .filter_map(|(eid, n)| get(&trial, *eid, n).map(|v| (n.to_string(), v)))
                    .collect(),
                ci95: BTreeMap::new(),
                explained_share: share,
                heldout_share: held,
                delta_bic: dbic,
                reason: None,
            };
            if let Err(e) = &res {
                rep.reason = Some(format!("fit failed: {e}"));
            } else if sim_failed {
                rep.reason = Some("the rig does not simulate at the traced values".into());
            } else if share < opts.min_share {
                rep.reason = Some(format!(
                    "explains {:.1} % < {:.1} %",
                    100.0 * share,
                    100.0 * opts.min_share
                ));
            } else if held < 0.5 * opts.min_share {
                rep.reason = Some(format!(
                    "held-out share {:.1} %: does not generalise",
                    100.0 * held
                ));
            } else if dbic >= 0.0 {
                rep.reason = Some(format!("BIC does not fall (ΔBIC = {dbic:.1})"));
            } else if negligible(id, &trial, declared) {
                rep.reason =
                    Some("fitted size negligible (indistinguishable from the declared rig)".into());
            }
            (trial, rep, rss_train)
        };
        // The jobs are independent: trace them on the available cores
        // (results taken in catalog order, so the outcome does not depend on
        // the number of threads). Of a candidate's starts, the one ending
        // lowest on the training part is kept.
        let mut traced: Vec<Option<(EffectId, ValveRig, EffectReport, f64)>> =
            trace_parallel(&jobs, &trace_one)
                .into_iter()
                .zip(&jobs)
                .map(|((t, r, x), (id, _))| Some((*id, t, r, x)))
                .collect();
        let mut chosen: Vec<(EffectId, ValveRig, EffectReport)> = Vec::new();
        for &id in &todo {
            let mut pick: Option<(ValveRig, EffectReport, f64)> = None;
            for slot in traced.iter_mut() {
                if slot.as_ref().is_some_and(|s| s.0 == id) {
                    if let Some((_, t, r, x)) = slot.take() {
                        if pick.as_ref().is_none_or(|p| x < p.2) {
                            pick = Some((t, r, x));
                        }
                    }
                }
            }
            if let Some((t, r, _)) = pick {
                chosen.push((id, t, r));
            }
        }
        // Candidates that explain a share worth having, best first.
        let mut eligible: Vec<(EffectId, ValveRig, EffectReport)> = Vec::new();
        for (id, trial, rep) in chosen {
            if rep.reason.is_none() {
                eligible.push((id, trial, rep.clone()));
            }
            last.insert(id, rep);
        }
        eligible.sort_by(|a, b| b.2.explained_share.total_cmp(&a.2.explained_share));
        if let Some(pr) = delay_probe(&model, &pt, opts.holdout) {
            let top = eligible.first().map(|(id, _, r)| (*id, r.explained_share));
            if pr.explained_share >= opts.min_share
                && top.is_none_or(|(_, share)| pr.explained_share > share + opts.min_share)
            {
                if let Some((id, _)) = top {
                    if let Some(r) = last.get_mut(&id) {
                        r.reason = Some(format!(
                            "the residual is better explained by a {} ({:.1} %), which is not in the catalog",
                            pr.what,
                            100.0 * pr.explained_share
                        ));
                    }
                }
                resembles = Some(pr);
                break;
            }
        }
        // The acceptance rule (`accept`): refit each candidate in turn with
        // the effects already added; the first that earns its place is added.
        clock.lap("tracing");
        let base = accept::Baseline {
            model: &model,
            declared,
            nrmse: channel_nrmse(&model, &p),
            floors: floors.clone(),
            p: &p,
            holdout: opts.holdout,
        };
        let mut accepted: Option<(EffectId, ValveRig, EffectReport, ParamList, lm::LmResult)> =
            None;
        for (id, _, _) in eligible.iter().skip(MAX_REFITS_PER_ROUND) {
            if let Some(r) = last.get_mut(id) {
                r.reason = Some(format!(
                    "not refitted: {MAX_REFITS_PER_ROUND} candidates explaining more were refitted first in its round"
                ));
            }
        }
        for (id, trial, rep) in eligible.into_iter().take(MAX_REFITS_PER_ROUND) {
            progress(&format!("refit {}", id.id()), round + 1, total);
            let joint: ParamList = free
                .iter()
                .copied()
                .chain(id.params().iter().map(|q| (id, q.name)))
                .collect();
            let mut refit = trial;
            let verdict = match fit(&mut refit, &joint, &p, opts.holdout, Part::All) {
                Ok(res) => accept::verdict(id, &joint, &res, &refit, &base).map(|()| res),
                Err(e) => Err(format!("refit failed: {e}")),
            };
            match verdict {
                Ok(res) => {
                    accepted = Some((id, refit, rep, joint, res));
                    break;
                }
                Err(why) => {
                    if let Some(r) = last.get_mut(&id) {
                        r.reason = Some(why);
                    }
                }
            }
        }
        let Some((id, refit, rep, joint, res)) = accepted else {
            break;
        };
        model = refit;
        free = joint;
        last.remove(&id);
        added.push(rep);
        for ((eid, n), (x, ci)) in free.iter().zip(res.x.iter().zip(&res.ci95)) {
            if let Some(a) = added.iter_mut().find(|a| a.id == eid.id()) {
                a.params.insert(n.to_string(), *x);
                a.ci95.insert(n.to_string(), ci.is_finite().then_some(*ci));
            }
        }
    }
    clock.lap("refits");
    // Backward step: an effect whose refitted size became negligible once
    // later effects were added was standing in for them; drop it and refit.
    let stale: Vec<EffectId> = added
        .iter()
        .filter_map(|a| EffectId::from_id(&a.id))
        .filter(|id| negligible(*id, &model, declared))
        .collect();
    if !stale.is_empty() {
        for id in &stale {
            for q in id.params() {
                let neutral = if *id == EffectId::FlowGainError {
                    1.0
                } else {
                    0.0
                };
                let v = if *id == EffectId::BulkModulus {
                    declared.fluid.bulk_modulus_pa
                } else {
                    neutral
                };
                set(&mut model, *id, q.name, v);
            }
            free.retain(|(e, _)| e != id);
            if let Some(pos) = added.iter().position(|a| a.id == id.id()) {
                let mut rep = added.remove(pos);
                rep.reason = Some(
                    "added, then gave way: its refitted size became negligible once later effects were added".into(),
                );
                last.insert(*id, rep);
            }
        }
        if !free.is_empty() {
            let mut refit = model.clone();
            let res = match fit(&mut refit, &free, &p, opts.holdout, Part::All) {
                Ok(r) => {
                    model = refit;
                    r
                }
                Err(e) => {
                    warnings.push(format!("refit after the backward step: {e}"));
                    return Err(DiagnoseError::Fit {
                        what: "refit after the backward step".into(),
                        reason: e.to_string(),
                    });
                }
            };
            for ((eid, n), (x, ci)) in free.iter().zip(res.x.iter().zip(&res.ci95)) {
                if let Some(a) = added.iter_mut().find(|a| a.id == eid.id()) {
                    a.params.insert(n.to_string(), *x);
                    a.ci95.insert(n.to_string(), ci.is_finite().then_some(*ci));
                }
            }
        }
    }
    progress("report", total, total);
    clock.lap("backward step");
    let sims_after = simulate(&model, &p).unwrap_or_default();
    let nrmse_after = nrmse_of(&p, &sims_after);
    let rss_after = rss(&model, &p, opts.holdout, Part::All);
    let mut noise_floor = BTreeMap::new();
    let mut noise_ss = 0.0;
    for (((ch, m), r), w) in p.meas.iter().zip(&p.ranges).zip(&p.weights) {
        let sig = if *w == 0.0 { 0.0 } else { noise_sigma(m) };
        noise_floor.insert(ch.name().to_string(), sig / r);
        // Weighted residuals of pure noise have unit variance.
        if *w > 0.0 {
            noise_ss += (sig * w).powi(2) * m.len() as f64;
        }
    }
    let traces = traces(rec, &p, &sims_before, &sims_after);
    let report = Report {
        rig: declared.name.clone(),
        rig_kind: "valve-cylinder".into(),
        records: vec![rec.source.clone()],
        samples: rec.len(),
        data_problems,
        smoother: info.clone(),
        smoother_windows: vec![info.half_window],
        initial_state: "velocity and chamber pressures at the first sample from the smoother's local cubic fit (not the raw noisy sample), initial position and velocity fitted first on the declared model and again with every refit (the rig integrates flow into position; the smoother's one-sided derivative at the first sample is noisy); spool at the first command; the rig's steady pressures where p1/p2 are not measured".into(),
        nrmse_declared,
        nrmse_before,
        nrmse_after,
        noise_floor,
        declared_refit: vec![],
        effects_added: added,
        effects_rejected: last.into_values().collect(),
        effects_not_applicable: EffectId::ALL
            .iter()
            .filter(|e| !candidates.contains(e))
            .map(|e| NotApplicable {
                id: e.id().to_string(),
                why: not_applicable_why(*e, declared, opts),
            })
            .collect(),
        unexplained_share: rss_after / rss_before.max(1e-300),
        unexplained_resembles: resembles,
        warnings,
        noise_share: (noise_ss / rss_after.max(1e-300)).min(1.0),
        selection: format!(
            "output-error tracing: add the effect removing the largest share of the noise-weighted output-error SS if share >= {:.0} %, held-out share >= {:.1} % and BIC falls; refit all added parameters on the output error",
            100.0 * opts.min_share,
            50.0 * opts.min_share
        ),
        wall_times_s: clock.finish(),
        elapsed_s: start.elapsed().as_secs_f64(),
    };
    Ok(ValveOutcome {
        report,
        traces,
        rig: model,
    })
}

#[cfg(test)]
mod tests {
    use super::{as_stribeck, get, is_on, lag_samples, set};
    use crate::catalog::EffectId;
    use hydrocyl_friction::{FrictionInput, FrictionLaw, FrictionModel};
    use hydrocyl_ports::Velocity;
    use hydrocyl_system::valve_rig::ValveRig;

    fn force(law: &FrictionLaw, v: f64) -> f64 {
        law.force(&FrictionInput::at_velocity(Velocity::new(v)), &[])
            .si()
    }

    #[test]
    fn friction_effects_map_onto_a_stribeck_law() {
        let rig = ValveRig::leaney_moog();
        let cv = rig.friction;
        let st = FrictionLaw::Stribeck(as_stribeck(&cv).unwrap());
        let vs = [-0.2, -0.01, -1e-3, -1e-5, 0.0, 1e-5, 1e-3, 0.01, 0.2];
        // the conversion of the declared coulomb-viscous law is exact
        for v in vs {
            assert!((force(&cv, v) - force(&st, v)).abs() < 1e-12, "v {v}");
        }
        // off: both effects read 0; setting them to 0 changes nothing
        let mut r = rig.clone();
        assert!(!is_on(&r, EffectId::CoulombAsymmetry) && !is_on(&r, EffectId::Stribeck));
        set(&mut r, EffectId::CoulombAsymmetry, "dFc", 0.0);
        set(&mut r, EffectId::Stribeck, "Fs", 0.0);
        for v in vs {
            assert!(
                (force(&cv, v) - force(&r.friction, v)).abs() < 1e-12,
                "v {v}"
            );
        }
        // asymmetry: extending Fc + dFc/2, retracting Fc − dFc/2, read back
        set(&mut r, EffectId::CoulombAsymmetry, "dFc", 40.0);
        assert_eq!(get(&r, EffectId::CoulombAsymmetry, "dFc"), Some(40.0));
        let b = 500.0;
        assert!((force(&r.friction, 0.2) - (70.0 + b * 0.2)).abs() < 1e-9);
        assert!((force(&r.friction, -0.2) - (-30.0 - b * 0.2)).abs() < 1e-9);
        // a hump on top keeps the asymmetry: g(0+) = Fs + dFc/2
        set(&mut r, EffectId::Stribeck, "Fs", 150.0);
        assert!(is_on(&r, EffectId::Stribeck));
        assert_eq!(get(&r, EffectId::Stribeck, "Fs"), Some(150.0));
        // (vs = 10 mm/s and α = 1 from the conversion, v_t = 1 mm/s)
        for v in [5e-3, -5e-3] {
            let level = if v > 0.0 { 70.0 } else { 30.0 };
            let g = level + 100.0 * (-(v / 0.01f64).abs()).exp();
            let want = (v / 1e-3f64).tanh() * g + b * v;
            assert!((force(&r.friction, v) - want).abs() < 1e-9, "v {v}");
        }
        // and the hump switches off again at Fs = 0
        set(&mut r, EffectId::Stribeck, "Fs", 0.0);
        assert!(!is_on(&r, EffectId::Stribeck));
        assert!((force(&r.friction, 0.2) - (70.0 + b * 0.2)).abs() < 1e-9);
        // bristles in (the curves and σ2 kept), and out again
        set(&mut r, EffectId::LugreDynamics, "sigma0", 2e5);
        set(&mut r, EffectId::LugreDynamics, "sigma1", 600.0);
        match &r.friction {
            FrictionLaw::LuGre(l) => {
                assert_eq!((l.sigma0, l.sigma1), (2e5, 600.0));
                assert_eq!(l.extending.curve.coulomb.si(), 70.0);
                assert_eq!(l.retracting.sigma2, b);
            }
            other => panic!("expected a LuGre law, got {other:?}"),
        }
        assert_eq!(get(&r, EffectId::CoulombAsymmetry, "dFc"), Some(40.0));
        set(&mut r, EffectId::LugreDynamics, "sigma0", 0.0);
        assert!(!is_on(&r, EffectId::LugreDynamics));
        assert!((force(&r.friction, 0.2) - (70.0 + b * 0.2)).abs() < 1e-9);
    }

    #[test]
    fn lag_of_samples_is_exact_for_a_ramp_and_identity_at_zero() {
        // uneven steps; u = 2 + 3 t, y(0) = u(0): y = u - 3 τ (1 - exp(-t/τ))
        let t = [0.0, 0.001, 0.0025, 0.003, 0.01, 0.0101, 0.05];
        let u: Vec<f64> = t.iter().map(|t| 2.0 + 3.0 * t).collect();
        let tau = 0.004;
        let y = lag_samples(&t, &u, tau);
        for (k, &tk) in t.iter().enumerate() {
            let want = u[k] - 3.0 * tau * (1.0 - (-tk / tau).exp());
            assert!((y[k] - want).abs() < 1e-14, "t {tk}: {} vs {want}", y[k]);
        }
        assert_eq!(lag_samples(&t, &u, 0.0), u);
        // a step held after the first sample settles to the new value
        let t: Vec<f64> = (0..200).map(|k| k as f64 * 1e-3).collect();
        let mut u = vec![1.0; 200];
        u[0] = 0.0;
        let y = lag_samples(&t, &u, 0.01);
        assert!(y[1] > 0.0 && y[1] < 1.0 && (y[199] - 1.0).abs() < 1e-6);
        assert!(lag_samples(&[], &[], 0.01).is_empty());
    }
}
