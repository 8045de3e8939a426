//! The catalog effects on a netlist rig: reading and setting them (through
//! the parameter targets of [`model`](super::model), or the friction-law
//! edits), their typical sizes, negligible sizes, fit bounds and trace
//! starts, and what the data checks need to know about the rig.

use super::*;
use serde_json::{json, Value};

/// One direction's Stribeck set of a friction law: Coulomb and stiction
/// levels, Stribeck velocity and exponent, viscous σ2.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Set {
    pub fc: f64,
    pub fs: f64,
    pub vs: f64,
    pub alpha: f64,
    pub s2: f64,
}

/// Smoothing velocity of `sgn(v)` given to a static law made from a LuGre
/// law when `lugre_dynamics` is switched off again (LuGre has none; the
/// declared one is not kept) \[m·s⁻¹\]: the `leaney-moog` value.
pub(super) const STATIC_SMOOTHING: f64 = 1e-3;

/// The two direction sets of the rig's friction law: a LuGre's, a
/// Stribeck law's or a Wang law's own; the coulomb-viscous law's exact
/// Stribeck equivalent (`Fc tanh(v/v_t) + b v` is the Stribeck law with
/// `Fs = Fc`, no hump, `σ2 = b` both ways; its `vs` = 10 mm/s and `α` = 1
/// are then inert). `None` for the other laws.
pub(super) fn friction_sets(m: &Model) -> Option<(Set, Set)> {
    let f = m.roles.friction.as_deref()?;
    let r = |p: &str| m.param(f, p);
    match m.friction_type()?.as_str() {
        "friction_coulomb_viscous" => {
            let s = Set {
                fc: r("coulomb")?,
                fs: r("coulomb")?,
                vs: 0.01,
                alpha: 1.0,
                s2: r("viscous")?,
            };
            Some((s, s))
        }
        "friction_stribeck" | "friction_lugre" | "friction_wang" => {
            let set = |d: &str| {
                Some(Set {
                    fc: r(&format!("{d}.curve.coulomb"))?,
                    fs: r(&format!("{d}.curve.stiction"))?,
                    vs: r(&format!("{d}.curve.stribeck_velocity"))?,
                    alpha: r(&format!("{d}.curve.stribeck_exponent"))?,
                    s2: r(&format!("{d}.sigma2")).unwrap_or(0.0),
                })
            };
            Some((set("extending")?, set("retracting")?))
        }
        _ => None,
    }
}

fn set_json(s: &Set) -> Value {
    json!({
        "curve": {
            "coulomb": s.fc,
            "stiction": s.fs,
            "stribeck_velocity": s.vs,
            "stribeck_exponent": s.alpha,
        },
        "sigma2": s.s2,
    })
}

/// Rewrites the friction component with the law `ty` (`friction_stribeck`
/// or `friction_lugre`) on sets `e`, `r`, keeping its ports' connections,
/// its seal terms and (for LuGre) `sigma`s.
fn rewrite(m: &mut Model, ty: &str, e: &Set, r: &Set, sigmas: Option<(f64, f64)>) {
    let Some(f) = m.roles.friction.clone() else {
        return;
    };
    let Some(c) = m.net["components"].get_mut(&f) else {
        return;
    };
    let smoothing = c
        .get("smoothing_velocity")
        .and_then(Value::as_f64)
        .unwrap_or(STATIC_SMOOTHING);
    let Some(obj) = c.as_object_mut() else {
        return;
    };
    for k in [
        "coulomb",
        "viscous",
        "smoothing_velocity",
        "extending",
        "retracting",
        "sigma0",
        "sigma1",
    ] {
        obj.remove(k);
    }
    obj.insert("type".into(), Value::from(ty));
    obj.insert("extending".into(), set_json(e));
    obj.insert("retracting".into(), set_json(r));
    match sigmas {
        Some((s0, s1)) => {
            obj.insert("sigma0".into(), Value::from(s0));
            obj.insert("sigma1".into(), Value::from(s1));
        }
        None => {
            obj.insert("smoothing_velocity".into(), Value::from(smoothing));
        }
    }
}

/// Edits the two direction sets: a LuGre's or a Stribeck law's in place;
/// a coulomb-viscous law becomes the equivalent Stribeck law first.
fn with_sets(m: &mut Model, f: impl FnOnce(&mut Set, &mut Set)) {
    let Some((mut e, mut r)) = friction_sets(m) else {
        return;
    };
    f(&mut e, &mut r);
    match m.friction_type().as_deref() {
        Some("friction_lugre") => {
            let fr = m.roles.friction.clone().unwrap_or_default();
            let s0 = m.param(&fr, "sigma0").unwrap_or(0.0);
            let s1 = m.param(&fr, "sigma1").unwrap_or(0.0);
            rewrite(m, "friction_lugre", &e, &r, Some((s0, s1)));
        }
        Some("friction_stribeck" | "friction_coulomb_viscous") => {
            rewrite(m, "friction_stribeck", &e, &r, None);
        }
        _ => {}
    }
}

/// `true` when the direction sets have a hump.
fn has_hump(e: &Set, r: &Set) -> bool {
    e.fs != e.fc || r.fs != r.fc
}

/// Mean Coulomb level of the two directions \[N\] (the declared Fc).
pub(super) fn mean_coulomb(m: &Model) -> f64 {
    friction_sets(m).map_or(0.0, |(e, r)| 0.5 * (e.fc + r.fc))
}

/// Value of catalog parameter `name` of effect `id` in the model (SI);
/// `None` where the rig has no component it acts on.
pub(super) fn read_effect(m: &Model, id: EffectId, name: &str) -> Option<f64> {
    if m.applies(id).is_err() {
        return None;
    }
    match id {
        EffectId::SensorLag => Some(m.lag),
        EffectId::CoulombAsymmetry => {
            let (e, r) = friction_sets(m)?;
            Some(e.fc - r.fc)
        }
        EffectId::Stribeck => {
            let (e, r) = friction_sets(m)?;
            if !has_hump(&e, &r) {
                return Some(0.0);
            }
            match name {
                // the mean stiction level: Fc (mean) + the hump
                "Fs" => Some(0.5 * (e.fs + r.fs)),
                "vs" => Some(e.vs),
                "alpha" => Some(e.alpha),
                _ => None,
            }
        }
        EffectId::LugreDynamics => {
            friction_sets(m)?;
            if m.friction_type().as_deref() != Some("friction_lugre") {
                return Some(0.0);
            }
            let f = m.roles.friction.as_deref()?;
            match name {
                "sigma0" | "sigma1" => m.param(f, name),
                _ => None,
            }
        }
        _ => m.read_target(id, name),
    }
}

/// Sets catalog parameter `name` of effect `id` in the model.
pub(super) fn write_effect(m: &mut Model, id: EffectId, name: &str, v: f64) {
    match (id, name) {
        (EffectId::SensorLag, _) => m.lag = v,
        (EffectId::CoulombAsymmetry, _) => with_sets(m, |e, r| {
            // extending Fc + dFc/2, retracting Fc − dFc/2 (as on the friction
            // bench), each direction's hump kept
            let mean = 0.5 * (e.fc + r.fc);
            for (s, level) in [(e, mean + 0.5 * v), (r, mean - 0.5 * v)] {
                let hump = s.fs - s.fc;
                s.fc = level;
                s.fs = level + hump;
            }
        }),
        (EffectId::Stribeck, n) => with_sets(m, |e, r| {
            let on = has_hump(e, r);
            match n {
                // Fs = 0 is the catalog's "off": no hump
                "Fs" => {
                    let mean = 0.5 * (e.fc + r.fc);
                    let hump = if v == 0.0 { 0.0 } else { v - mean };
                    for s in [e, r] {
                        s.fs = s.fc + hump;
                    }
                }
                // vs and alpha are inert without a hump; 0 (off) leaves them
                "vs" if on || v != 0.0 => {
                    e.vs = v;
                    r.vs = v;
                }
                "alpha" if on || v != 0.0 => {
                    e.alpha = v;
                    r.alpha = v;
                }
                _ => {}
            }
        }),
        // σ0 = 0 is the catalog's "off": the static law with the same
        // curves; σ0 ≠ 0 puts the bristles in, keeping the curves and σ2
        (EffectId::LugreDynamics, "sigma0") => {
            let Some((e, r)) = friction_sets(m) else {
                return;
            };
            let lugre = m.friction_type().as_deref() == Some("friction_lugre");
            let f = m.roles.friction.clone().unwrap_or_default();
            match (lugre, v != 0.0) {
                (true, true) => m.set_param(&f, "sigma0", Value::from(v)),
                (true, false) => rewrite(m, "friction_stribeck", &e, &r, None),
                (false, true) => rewrite(m, "friction_lugre", &e, &r, Some((v, 0.0))),
                (false, false) => {}
            }
        }
        // σ1 is inert without bristles
        (EffectId::LugreDynamics, "sigma1") => {
            if m.friction_type().as_deref() == Some("friction_lugre") {
                let f = m.roles.friction.clone().unwrap_or_default();
                m.set_param(&f, "sigma1", Value::from(v));
            }
        }
        _ => m.write_target(id, name, v),
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
pub(super) fn trace_starts(rig: &Model, id: EffectId) -> Vec<Model> {
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
pub fn is_on(rig: &Model, id: EffectId) -> bool {
    id.params().iter().any(|p| {
        get(rig, id, p.name).is_some_and(|v| match id {
            EffectId::FlowGainError => v != 1.0,
            _ => v != 0.0,
        })
    })
}

/// A typical magnitude of a parameter (scales the fit and its first step).
pub(super) fn typical(id: EffectId, name: &str, rig: &Model) -> f64 {
    match (id, name) {
        (EffectId::ValveNullBias | EffectId::ValveDeadBand, _) => 0.01 * rig.spool_stroke(),
        (EffectId::FlowGainError, _) => 1.0,
        (EffectId::InternalLeakage | EffectId::ExternalLeakage, _) => 1e-12,
        (EffectId::BulkModulus, _) => get(rig, EffectId::BulkModulus, "B").unwrap_or(1e9),
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
        // 10 N at half the supply (or the seal's Δp bound) across the piston and 10 mm/s
        (EffectId::PressureViscous, _) => 10.0 / (rig.seal_dp().powi(2) * 0.01).max(1e-300),
        // K H = 10 % of the moving mass
        (EffectId::AccelerationFriction, _) => 0.1 * rig.mass() / k_pressure(rig).max(1e-300),
    }
}

/// The smallest size of an effect worth adding: below it the effect cannot
/// be told from the declared rig by any measurement (a flow gain 0.1 % off
/// nominal, a leakage passing 1e-14 m³/s per Pa). A fit that lands below it
/// is absorbing simulation or initial-state error, not finding an effect.
pub(super) fn negligible(id: EffectId, rig: &Model, declared: &Model) -> bool {
    let v = |n: &str| get(rig, id, n).unwrap_or(0.0);
    match id {
        EffectId::ValveNullBias => v("xb").abs() < 1e-3 * rig.spool_stroke(),
        EffectId::ValveDeadBand => v("xd") < 1e-3 * rig.spool_stroke(),
        EffectId::FlowGainError => (v("kw") - 1.0).abs() < 5e-3,
        EffectId::InternalLeakage => v("Cl") < 1e-14,
        EffectId::ExternalLeakage => v("Ce1").max(v("Ce2")) < 1e-14,
        EffectId::BulkModulus => {
            (v("B") / get(declared, id, "B").unwrap_or(f64::NAN) - 1.0).abs() < 0.02
        }
        EffectId::ExternalForce => v("F0").abs() < 5.0,
        EffectId::Viscous => v("b").abs() < 10.0,
        // droop below 0.5 % of the supply at the valve's full-opening flow
        // (half the supply across each edge)
        EffectId::SupplyDroop => v("Rs") * full_opening_flow(rig) < 5e-3 * rig.supply(),
        // a lag under 0.1 ms is below any record's resolution here
        EffectId::SensorLag => v("tau") < 1e-4,
        // under 1 N at half the supply across the piston and 10 mm/s
        EffectId::PressureViscous => v("K") * rig.seal_dp().powi(2) * 0.01 < 1.0,
        // an added mass K H under 1 % of the moving mass
        EffectId::AccelerationFriction => k_pressure(rig) * v("H") < 0.01 * rig.mass(),
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
pub(super) fn bounds(id: EffectId, name: &str, rig: &Model) -> (f64, f64) {
    match id {
        EffectId::ValveNullBias => (-rig.spool_stroke(), rig.spool_stroke()),
        // a dead zone up to half the spool stroke
        EffectId::ValveDeadBand => (0.0, 0.5 * rig.spool_stroke()),
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

/// The additive seal term's K of the model (0 when off or absent).
pub(super) fn k_pressure(rig: &Model) -> f64 {
    get(rig, EffectId::PressureViscous, "K").unwrap_or(0.0)
}

/// Flow of the servovalve's supply edge at full opening with half the
/// supply across it \[m³/s\] (0 without a `four_way_valve`).
fn full_opening_flow(rig: &Model) -> f64 {
    let Some(cs) = rig.net.get("components").and_then(Value::as_object) else {
        return 0.0;
    };
    let Some((name, _)) = cs
        .iter()
        .find(|(_, c)| c.get("type").and_then(Value::as_str) == Some("four_way_valve"))
    else {
        return 0.0;
    };
    let p = |k: &str| rig.param(name, k);
    let (Some(cd), Some(rho), Some(d)) =
        (p("orifice.cd"), p("orifice.density"), p("spool_diameter"))
    else {
        return 0.0;
    };
    let kw = p("flow_gain").unwrap_or(1.0);
    let u = p("underlap").unwrap_or(0.0);
    cd * (2.0 / rho).sqrt()
        * std::f64::consts::PI
        * d
        * kw
        * (rig.spool_stroke() + u)
        * (0.5 * rig.supply()).max(0.0).sqrt()
}

/// What the data checks need to know about a rig: the stroke, the supply
/// above tank ([`Model::supply`]) and, where the netlist is the
/// valve-cylinder circuit, the steady velocity per unit command at full
/// demand (mean of the two directions; none with a drooping supply).
pub fn rig_facts(rig: &Model) -> RigFacts {
    let gain = ValveRig::from_netlist(&rig.net).ok().and_then(|v| {
        let xm = v.valve.stroke_m;
        match (v.steady_velocity(xm), v.steady_velocity(-xm)) {
            (Ok(up), Ok(down)) if up > 0.0 && down < 0.0 => Some(0.5 * (up - down)),
            _ => None,
        }
    });
    let cyl = &rig.roles.cylinder;
    let areas = match (rig.param(cyl, "area_1"), rig.param(cyl, "area_2")) {
        (Some(a1), Some(a2)) => Some((a1, a2)),
        _ => None,
    };
    // the command a closed-loop rig's record carries is its controller's
    // output, the valve's normalised demand; an open-loop rig's is its input
    let command_unit = if rig.roles.controller.is_some() {
        Some("-")
    } else {
        hydrocyl_system::netlist::schematic(&rig.net)
            .ok()
            .and_then(|s| s.input_unit())
    };
    RigFacts {
        stroke: rig.stroke(),
        supply: rig.supply(),
        velocity_gain: gain,
        areas,
        mass: rig.mass(),
        command_unit,
    }
}
