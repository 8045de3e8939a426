use super::model::{targets, Model, FRICTION_TYPES};
use super::{get, is_on, lag_samples, set};
use crate::catalog::EffectId;
use hydrocyl_friction::{FrictionInput, FrictionLaw, FrictionModel};
use hydrocyl_ports::Velocity;
use hydrocyl_system::netlist::registry;
use hydrocyl_system::valve_rig::ValveRig;

fn on(r: &ValveRig, id: EffectId) -> bool {
    is_on(&Model::from_valve_rig(r).unwrap(), id)
}

fn force(law: &FrictionLaw, v: f64) -> f64 {
    law.force(&FrictionInput::at_velocity(Velocity::new(v)), &[])
        .si()
}

/// Every target of the catalog names a parameter its component type has.
#[test]
fn every_target_is_a_registry_parameter() {
    for id in EffectId::ALL {
        for q in id.params() {
            for tg in targets(id, q.name) {
                let ty = registry::lookup(tg.ty).unwrap_or_else(|| panic!("{}", tg.ty));
                assert!(ty.param(tg.param).is_some(), "{}.{}", tg.ty, tg.param);
            }
        }
    }
    for ty in FRICTION_TYPES {
        assert!(registry::lookup(ty).is_some(), "{ty}");
    }
}

/// Which effects apply is read from the components: the valve rig has
/// all of them; the hybrid rig (pump, no servovalve, Wang's law) the
/// cylinder's, the load's, the pump's and the seal terms, and the
/// others name the component type they need.
#[test]
fn the_effects_that_apply_follow_the_components() {
    let valve = Model::new(&hydrocyl_system::rig::preset("leaney-moog").unwrap()).unwrap();
    for id in EffectId::ALL {
        assert!(valve.applies(id).is_ok(), "{id:?}: {:?}", valve.applies(id));
    }
    let hybrid = Model::new(&hydrocyl_system::rig::preset("wang-hybrid").unwrap()).unwrap();
    let yes = [
        EffectId::InternalLeakage,
        EffectId::ExternalLeakage,
        EffectId::BulkModulus,
        EffectId::ExternalForce,
        EffectId::PressureViscous,
        EffectId::AccelerationFriction,
        EffectId::FlowGainError,
        EffectId::SensorLag,
    ];
    for id in EffectId::ALL {
        let ok = hybrid.applies(id);
        assert_eq!(ok.is_ok(), yes.contains(&id), "{id:?}: {ok:?}");
    }
    let why = hybrid.applies(EffectId::ValveNullBias).unwrap_err();
    assert!(why.contains("four_way_valve"), "{why}");
    // the bulk modulus reaches the chambers and both lines
    assert_eq!(
        hybrid.paths_of(EffectId::BulkModulus),
        [
            "cylinder.bulk_modulus",
            "line_1.bulk_modulus",
            "line_2.bulk_modulus"
        ]
    );
    // the pump's gain is scaled by kw
    let mut h = hybrid.clone();
    assert_eq!(get(&h, EffectId::FlowGainError, "kw"), Some(1.0));
    set(&mut h, EffectId::FlowGainError, "kw", 1.1);
    let g = h.param("pump", "gain").unwrap();
    assert!((g / 1.07e-5 - 1.1).abs() < 1e-12, "{g}");
    assert!(is_on(&h, EffectId::FlowGainError));
}

#[test]
fn friction_effects_map_onto_a_stribeck_law() {
    let rig = ValveRig::leaney_moog();
    let cv = rig.friction;
    let vs = [-0.2, -0.01, -1e-3, -1e-5, 0.0, 1e-5, 1e-3, 0.01, 0.2];
    // off: both effects read 0; setting them to 0 rewrites the
    // coulomb-viscous law as the equivalent Stribeck law, exactly
    let mut r = rig.clone();
    assert!(!on(&r, EffectId::CoulombAsymmetry) && !on(&r, EffectId::Stribeck));
    set(&mut r, EffectId::CoulombAsymmetry, "dFc", 0.0);
    set(&mut r, EffectId::Stribeck, "Fs", 0.0);
    assert!(
        matches!(r.friction, FrictionLaw::Stribeck(_)),
        "{:?}",
        r.friction
    );
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
    assert!(on(&r, EffectId::Stribeck));
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
    assert!(!on(&r, EffectId::Stribeck));
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
    assert!(!on(&r, EffectId::LugreDynamics));
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

/// t34 defect 2: `internal_leakage` was added first and kept after later
/// effects were added, though the last joint refit had widened its interval
/// to include zero (Cl = 7.23e-14 ± 2.64e-13). The backward step makes the
/// acceptance rule's interval test again on every added effect: the leak is
/// dropped with the reason, the rest refitted and kept.
#[test]
fn an_added_effect_whose_interval_widened_to_include_zero_is_dropped() {
    use crate::diagnose::EffectReport;
    use crate::lm::LmResult;
    use std::collections::BTreeMap;
    let net = hydrocyl_system::rig::preset("leaney-moog").unwrap();
    let declared = Model::new(&net).unwrap();
    // the record has an external force of 400 N and no leak
    let mut truth = declared.clone();
    set(&mut truth, EffectId::ExternalForce, "F0", 400.0);
    let rec =
        crate::synth::netlist_record(&truth.net, 1000, 1e-3, 81, &crate::synth::valve_command)
            .unwrap();
    let (p, _) = super::sim::prepare(&rec, None, &[], declared.stroke()).unwrap();
    // the loop's model after its last joint refit: the leak and the force
    let mut model = super::sim::with_initial(&declared, &p);
    set(&mut model, EffectId::InternalLeakage, "Cl", 7.23e-14);
    set(&mut model, EffectId::ExternalForce, "F0", 400.0);
    let mut free = vec![
        (EffectId::InternalLeakage, "Cl"),
        (EffectId::ExternalForce, "F0"),
    ];
    let res = LmResult {
        x: vec![7.23e-14, 400.0, model.x0(), model.v0()],
        ci95: vec![2.64e-13, 5.0, f64::NAN, f64::NAN],
        rss: 1.0,
        m: 4000,
        iterations: 1,
        evaluations: 1,
        at_bound: vec![false; 4],
    };
    let report = |id: EffectId, name: &str, v: f64, ci: f64| EffectReport {
        id: id.id().into(),
        params: BTreeMap::from([(name.to_string(), v)]),
        ci95: BTreeMap::from([(name.to_string(), Some(ci))]),
        explained_share: 0.9,
        heldout_share: 0.9,
        delta_bic: -100.0,
        note: None,
    };
    let mut added = vec![
        report(EffectId::InternalLeakage, "Cl", 7.23e-14, 2.64e-13),
        report(EffectId::ExternalForce, "F0", 400.0, 5.0),
    ];
    let mut warnings = Vec::new();
    let dropped = super::accept::backward(
        (&mut model, &mut free),
        Some(res),
        &mut added,
        &declared,
        &p,
        0.3,
        &mut warnings,
    );
    assert!(warnings.is_empty(), "{warnings:?}");
    let ids: Vec<&str> = dropped.iter().map(|d| d.effect.id.as_str()).collect();
    assert_eq!(ids, ["internal_leakage"]);
    let why = &dropped[0].reason;
    assert!(
        why.starts_with("added, then dropped after the last joint refit")
            && why.contains("Cl's 95 % interval includes zero"),
        "{why}"
    );
    assert_eq!(get(&model, EffectId::InternalLeakage, "Cl"), Some(0.0));
    assert_eq!(free, [(EffectId::ExternalForce, "F0")]);
    // the force, refitted alone (its interval is the refit's, not the one
    // it came with), stays: its interval excludes zero
    assert_eq!(added.len(), 1);
    let f0 = added[0].params["F0"];
    let ci = added[0].ci95["F0"].unwrap();
    assert_ne!(ci, 5.0);
    assert!(
        ci < 0.5 * f0.abs() && (f0 - 400.0).abs() <= 2.0 * ci.max(1.0),
        "F0 = {f0} ± {ci}"
    );
}

/// The compare after the forward step (`pairs::compare`): a forward step
/// that added the nearest single effect (`flow_gain_error`, as the old loop
/// did on t34's rec_leakbias) on a record of a leak and a null bias of
/// opposite drift is replaced by the pair traced and refitted from the
/// declared model, which passes the acceptance rule and leaves less; the
/// replaced effect is rejected saying so, and the pair's notes name it.
#[test]
fn the_compare_replaces_a_greedy_set_that_a_pair_explains_better() {
    use super::fit::refit_polished;
    use super::pairs::{compare, Round};
    use super::sim::{compared_floors, prepare, rss_all_held, rss_of, simulate, with_initial};
    use crate::diagnose::{DiagnoseOptions, EffectReport};
    use std::collections::BTreeMap;
    let net = hydrocyl_system::rig::preset("leaney-moog").unwrap();
    let declared = Model::new(&net).unwrap();
    let mut truth = declared.clone();
    set(&mut truth, EffectId::InternalLeakage, "Cl", 5e-12);
    set(&mut truth, EffectId::ValveNullBias, "xb", -8e-6);
    let rec =
        crate::synth::netlist_record(&truth.net, 1250, 2e-3, 63, &crate::synth::valve_command)
            .unwrap();
    let opts = DiagnoseOptions::default();
    let (p, _) = prepare(&rec, None, &[], declared.stroke()).unwrap();
    let pt = super::sim::Prepared {
        rtol: 1e-6,
        ..p.clone()
    };
    let rig0 = with_initial(&declared, &p);
    // the forward step's set: flow_gain_error alone, refitted
    let mut model = rig0.clone();
    set(&mut model, EffectId::FlowGainError, "kw", 0.95);
    let mut free = vec![(EffectId::FlowGainError, "kw")];
    let res = refit_polished(&mut model, &free, &p, opts.holdout).unwrap();
    let rss = rss_of(&p, &simulate(&model, &p).unwrap(), opts.holdout);
    let mut added = vec![EffectReport {
        id: "flow_gain_error".into(),
        params: BTreeMap::from([("kw".to_string(), res.x[0])]),
        ci95: BTreeMap::from([("kw".to_string(), Some(res.ci95[0]))]),
        explained_share: 0.9,
        heldout_share: 0.8,
        delta_bic: -10.0,
        note: None,
    }];
    let mut last = BTreeMap::new();
    let floors = compared_floors(&p);
    let r = Round {
        model: &rig0,
        free: &Vec::new(),
        pt: &pt,
        p: &p,
        opts: &opts,
        declared: &declared,
        floors: &floors,
        null: rss_all_held(&rig0, &pt, opts.holdout),
        neff: 500.0,
        first: None,
    };
    // the first round's singles: the leak and the bias each explain little
    // alone; the linearised ranking brings the pair in
    let singles = [
        (EffectId::FlowGainError, 0.9),
        (EffectId::SupplyDroop, 0.8),
        (EffectId::InternalLeakage, -1.0),
        (EffectId::ValveNullBias, 0.0),
    ];
    let swapped = compare(
        &r,
        &singles,
        rss,
        (&mut model, &mut free),
        &mut added,
        &mut last,
        &mut |_| {},
    );
    assert!(swapped, "{added:?}");
    let mut ids: Vec<&str> = added.iter().map(|a| a.id.as_str()).collect();
    ids.sort();
    assert_eq!(ids, ["internal_leakage", "valve_null_bias"]);
    for a in &added {
        let note = a.note.as_deref().unwrap_or_default();
        assert!(
            note.contains("in place of the forward step's flow_gain_error"),
            "{note}"
        );
    }
    let cl = added.iter().find(|a| a.id == "internal_leakage").unwrap();
    let (v, ci) = (cl.params["Cl"], cl.ci95["Cl"].unwrap());
    assert!((v - 5e-12).abs() <= ci, "Cl = {v} ± {ci}");
    let why = &last[&EffectId::FlowGainError].reason;
    assert!(
        why.starts_with("added by the forward step, then replaced"),
        "{why}"
    );
    assert_eq!(get(&model, EffectId::FlowGainError, "kw"), Some(1.0));
    assert_eq!(free.len(), 2);
}

/// A logger gap (0.8 s to 1.2 s of a 2.5 s record dropped, the command
/// interpolated across it) made the open-loop simulation drift on an input
/// nobody measured: without a restart this record's planted leak came out
/// at Cl = 1.212e-11 ± 5.6e-13 (3.8 intervals from the truth), and a
/// noise-free 3 s record of the CLI got a false `flow_gain_error` of 1.043
/// beside it. Restarted after the gap from the measured state, the loop
/// finds the leak alone, within its interval.
#[test]
fn a_logger_gap_restarts_the_simulation_and_leaves_the_leak_fit_unbiased() {
    use crate::diagnose::DiagnoseOptions;
    let net = hydrocyl_system::rig::preset("leaney-moog").unwrap();
    let declared = Model::new(&net).unwrap();
    let mut truth = declared.clone();
    set(&mut truth, EffectId::InternalLeakage, "Cl", 1e-11);
    let mut rec =
        crate::synth::netlist_record(&truth.net, 1250, 2e-3, 17, &crate::synth::valve_command)
            .unwrap();
    let kept: Vec<bool> = rec.time.iter().map(|&t| !(0.8..1.2).contains(&t)).collect();
    let keep = |v: &mut Vec<f64>| {
        let mut k = kept.iter();
        v.retain(|_| *k.next().unwrap());
    };
    keep(&mut rec.time);
    for v in rec.signals.values_mut() {
        keep(v);
    }
    rec.lines.clear();
    assert_eq!(rec.time.len(), 1050);
    let (p, _) = super::sim::prepare(&rec, None, &[], declared.stroke()).unwrap();
    let gaps: Vec<usize> = p
        .restarts
        .iter()
        .filter(|r| r.cause == super::restart::Cause::Gap)
        .map(|r| r.index)
        .collect();
    assert_eq!(
        gaps,
        [400],
        "one restart, at the first sample after the gap"
    );
    let out = super::diagnose_rig(
        &declared,
        &rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    let ids: Vec<&str> = out.effects_added.iter().map(|a| a.id.as_str()).collect();
    assert_eq!(ids, ["internal_leakage"], "{:?}", out.effects_added);
    let a = &out.effects_added[0];
    let (v, ci) = (a.params["Cl"], a.ci95["Cl"].unwrap());
    assert!((v - 1e-11).abs() <= ci && ci < 0.2e-11, "Cl = {v} ± {ci}");
}
