//! The loop on the hybrid (pump-controlled) rig `wang-hybrid`: the same
//! catalog, reached through the rig's components (cylinder, load, pump,
//! Wang friction with its additive seal terms). Records generated from the
//! preset with one effect planted, 20 µm / 20 kPa noise; 2 s at 500 Hz to
//! keep the stiff rig's simulations cheap.

use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::data::Record;
use hydrocyl_identify::diagnose::{DiagnoseOptions, Report};
use hydrocyl_identify::synth::netlist_record;
use hydrocyl_identify::valve::{diagnose_rig, set, Model};

fn declared() -> Model {
    Model::new(&hydrocyl_system::rig::preset("wang-hybrid").unwrap()).unwrap()
}

/// The pump command \[V\]: a 0.7 Hz sine of 3 V on a slower one (the piston
/// moves ±12 mm at up to 40 mm/s, both ways, with reversals).
fn command(t: f64) -> f64 {
    use std::f64::consts::PI;
    3.0 * (2.0 * PI * 0.7 * t).sin() + 1.0 * (2.0 * PI * 1.9 * t).sin()
}

fn record(planted: &[(EffectId, &str, f64)], seed: u64) -> Record {
    let mut t = declared();
    for (id, name, v) in planted {
        set(&mut t, *id, name, *v);
    }
    netlist_record(&t.net, 1000, 2e-3, seed, &command).unwrap()
}

fn diagnose(rec: &Record) -> Report {
    diagnose_rig(
        &declared(),
        rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap()
}

use crate::{check_found, ids};

#[test]
fn a_clean_hybrid_record_finds_nothing_and_says_what_applies() {
    let r = diagnose(&record(&[], 91));
    eprintln!("{}", r.human());
    assert!(ids(&r).is_empty(), "{}", r.human());
    let na: Vec<&str> = r
        .effects_not_applicable
        .iter()
        .map(|e| e.id.as_str())
        .collect();
    for id in [
        "valve_null_bias",
        "supply_droop",
        "valve_dead_band",
        "stribeck",
    ] {
        assert!(na.contains(&id), "{id} should not apply: {na:?}");
    }
    let why = &r
        .effects_not_applicable
        .iter()
        .find(|e| e.id == "valve_null_bias")
        .unwrap()
        .why;
    assert!(why.contains("four_way_valve"), "{why}");
    let ap: Vec<&str> = r.effects_applicable.iter().map(|e| e.id.as_str()).collect();
    for id in [
        "internal_leakage",
        "external_force",
        "pressure_viscous",
        "flow_gain_error",
    ] {
        assert!(ap.contains(&id), "{id} should apply: {ap:?}");
    }
}

#[test]
fn an_internal_leak_is_found_on_the_hybrid_rig() {
    let r = diagnose(&record(&[(EffectId::InternalLeakage, "Cl", 2e-12)], 92));
    eprintln!("{}", r.human());
    check_found(&r, EffectId::InternalLeakage, "Cl", 2e-12);
}

#[test]
fn an_external_force_is_found_on_the_hybrid_rig() {
    let r = diagnose(&record(&[(EffectId::ExternalForce, "F0", 300.0)], 93));
    eprintln!("{}", r.human());
    check_found(&r, EffectId::ExternalForce, "F0", 300.0);
}

#[test]
fn an_additive_pressure_viscous_term_is_found_on_the_hybrid_rig() {
    // on top of Wang's own seal terms, bounded like them at the preset's
    // seal.dp_max = 0.5 MPa: up to 2e-8 (5e5)² 0.04 = 200 N at 40 mm/s
    let r = diagnose(&record(&[(EffectId::PressureViscous, "K", 2e-8)], 94));
    eprintln!("{}", r.human());
    check_found(&r, EffectId::PressureViscous, "K", 2e-8);
}
