//! The loop on generated `leaney-moog` records with planted valve-rig effects.

use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::data::Record;
use hydrocyl_identify::diagnose::{nrmse, DiagnoseOptions, Report};
use hydrocyl_identify::synth::{valve_planted, valve_planted_all, valve_record};
use hydrocyl_identify::valve::{diagnose_valve, diagnose_valve_traced, get, set, ValveOutcome};
use hydrocyl_system::valve_rig::ValveRig;

/// A 2 s record of `leaney-moog` with the `planted` effects, diagnosed
/// against the rig without them.
fn run_traced(planted: &[EffectId], seed: u64) -> (Record, ValveOutcome) {
    let mut truth = ValveRig::leaney_moog();
    for id in planted {
        for (name, v) in valve_planted_all(*id) {
            set(&mut truth, *id, name, v);
        }
    }
    let rec = valve_record(&truth, 2000, 1e-3, seed).unwrap();
    let o = diagnose_valve_traced(
        &ValveRig::leaney_moog(),
        &rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    (rec, o)
}

fn run(planted: &[EffectId], seed: u64) -> Report {
    run_traced(planted, seed).1.report
}

#[test]
fn traced_outcome_matches_its_report() {
    // The series behind `--plots` are the runs the report's NRMSEs come
    // from, and the final rig carries the added effect at its reported value.
    let (rec, o) = run_traced(&[EffectId::InternalLeakage], 31);
    let r = &o.report;
    assert_eq!(o.traces.len(), r.nrmse_after.len());
    for tr in &o.traces {
        assert_eq!(tr.t.len(), rec.len());
        let (b, a) = (
            nrmse(&tr.measured, &tr.before),
            nrmse(&tr.measured, &tr.after),
        );
        assert_eq!(b, r.nrmse_before[&tr.channel], "{} before", tr.channel);
        assert_eq!(a, r.nrmse_after[&tr.channel], "{} after", tr.channel);
    }
    let e = &r.effects_added[0];
    assert_eq!(e.id, "internal_leakage");
    for (name, v) in &e.params {
        assert_eq!(get(&o.rig, EffectId::InternalLeakage, name), Some(*v));
    }
}

fn check(id: EffectId, seed: u64) -> Report {
    let r = run(&[id], seed);
    let text = r.human();
    // Shown with `--nocapture`: the numbers docs/diagnose.md quotes.
    eprintln!("{text}");
    assert!(!r.effects_added.is_empty(), "{text}");
    assert_eq!(r.effects_added[0].id, id.id(), "{text}");
    let (name, truth) = valve_planted(id).unwrap();
    let got = r.effects_added[0].params[name];
    let ci = r.effects_added[0].ci95[name].expect("interval");
    assert!(
        (got - truth).abs() <= ci,
        "{id}.{name} = {got} ± {ci}, planted {truth}\n{text}"
    );
    for (ch, after) in &r.nrmse_after {
        let floor = r.noise_floor[ch];
        if ch != "velocity" {
            assert!(
                *after <= 1.5 * floor,
                "{ch}: {after} vs floor {floor}\n{text}"
            );
        }
    }
    r
}

#[test]
fn internal_leakage_is_found() {
    check(EffectId::InternalLeakage, 31);
}

#[test]
fn external_leakage_is_found() {
    // Planted on chamber 1 only: Ce2 is fitted alongside and must stay
    // negligible (its true value 0 sits on the bound, where the linearised
    // interval says little, so it is checked against Ce1's size instead).
    let r = check(EffectId::ExternalLeakage, 40);
    let p = &r.effects_added[0].params;
    assert!(p["Ce2"] < 1e-2 * p["Ce1"], "{}", r.human());
}

#[test]
fn supply_droop_is_found() {
    check(EffectId::SupplyDroop, 41);
}

#[test]
fn sensor_lag_is_found() {
    check(EffectId::SensorLag, 42);
}

#[test]
fn coulomb_asymmetry_is_found() {
    check(EffectId::CoulombAsymmetry, 43);
}

#[test]
fn coulomb_asymmetry_is_told_from_a_constant_force_when_the_record_rests() {
    // On the moving-only records a planted asymmetry comes back as an
    // external force dFc/2 on some noise draws (docs/diagnose.md); with rests
    // in the record the two differ. Seeds 51, 52, 57 are draws where the
    // moving-only record was attributed to external_force.
    let declared = ValveRig::leaney_moog();
    let xm = declared.valve.stroke_m;
    let hold = declared.spool_for_velocity(0.0).unwrap() / xm;
    let mut truth = ValveRig::leaney_moog();
    for (name, v) in valve_planted_all(EffectId::CoulombAsymmetry) {
        set(&mut truth, EffectId::CoulombAsymmetry, name, v);
    }
    for seed in [51, 52, 57] {
        let rec =
            hydrocyl_identify::synth::valve_record_with(&truth, 2000, 1e-3, seed, 0.0, &|t| {
                hydrocyl_identify::synth::valve_command_with_rests(t, hold)
            })
            .unwrap();
        let r = diagnose_valve(
            &declared,
            &rec,
            &DiagnoseOptions::default(),
            &mut |_, _, _| {},
        )
        .unwrap();
        let text = r.human();
        assert_eq!(
            r.effects_added.first().map(|e| e.id.as_str()),
            Some("coulomb_asymmetry"),
            "seed {seed}\n{text}"
        );
        assert!(
            r.effects_added.iter().all(|e| e.id != "external_force"),
            "seed {seed}\n{text}"
        );
        // the attribution is the point here; the value to 2 % (its interval
        // is checked in `coulomb_asymmetry_is_found`; on one of these three
        // draws it misses by 1.24x its half-width, see the coverage numbers)
        let got = r.effects_added[0].params["dFc"];
        eprintln!(
            "seed {seed}: dFc {got:.3} ± {:.3}, p1 NRMSE {:.5} -> {:.5} (floor {:.5})",
            r.effects_added[0].ci95["dFc"].unwrap_or(f64::NAN),
            r.nrmse_before["p1"],
            r.nrmse_after["p1"],
            r.noise_floor["p1"]
        );
        assert!(
            (got / 40.0 - 1.0).abs() < 0.02,
            "seed {seed}: {got}\n{text}"
        );
    }
}

#[test]
fn stribeck_is_found() {
    // Fs is checked against its interval; vs and alpha are fitted with it
    // from generic starting values (10 mm/s, 1), not the planted 20 mm/s, 0.7.
    let r = check(EffectId::Stribeck, 44);
    let p = &r.effects_added[0].params;
    assert!((p["vs"] / 0.02 - 1.0).abs() < 0.2, "{}", r.human());
    assert!((p["alpha"] / 0.7 - 1.0).abs() < 0.2, "{}", r.human());
}

#[test]
fn lugre_dynamics_is_found() {
    let r = check(EffectId::LugreDynamics, 45);
    let p = &r.effects_added[0].params;
    let ci = &r.effects_added[0].ci95;
    let s1 = ci["sigma1"].expect("interval");
    assert!((p["sigma1"] - 600.0).abs() <= s1, "{}", r.human());
}

#[test]
fn valve_null_bias_is_found() {
    check(EffectId::ValveNullBias, 32);
}

#[test]
fn nothing_missing_adds_nothing_on_the_valve_rig() {
    let r = run(&[], 33);
    assert!(r.effects_added.is_empty(), "{}", r.human());
}

#[test]
fn flow_gain_error_is_found() {
    check(EffectId::FlowGainError, 34);
}

#[test]
fn external_force_is_found() {
    check(EffectId::ExternalForce, 35);
}

#[test]
fn bulk_modulus_is_found() {
    check(EffectId::BulkModulus, 36);
}

#[test]
fn flow_gain_and_external_force_together_are_both_found() {
    let r = run(&[EffectId::FlowGainError, EffectId::ExternalForce], 37);
    let mut ids: Vec<&str> = r.effects_added.iter().map(|e| e.id.as_str()).collect();
    ids.sort();
    assert_eq!(ids, ["external_force", "flow_gain_error"], "{}", r.human());
}

#[test]
fn leak_and_bias_together_are_both_found() {
    let r = run(&[EffectId::InternalLeakage, EffectId::ValveNullBias], 38);
    let mut ids: Vec<&str> = r.effects_added.iter().map(|e| e.id.as_str()).collect();
    ids.sort();
    assert_eq!(
        ids,
        ["internal_leakage", "valve_null_bias"],
        "{}",
        r.human()
    );
}

#[test]
fn command_delay_is_reported_unexplained() {
    // A 15 ms transport delay on the command: not a catalog effect.
    let truth = ValveRig::leaney_moog();
    let rec =
        hydrocyl_identify::synth::valve_record_delayed(&truth, 2000, 1e-3, 39, 0.015).unwrap();
    let r = diagnose_valve(
        &ValveRig::leaney_moog(),
        &rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    assert!(r.effects_added.is_empty(), "{}", r.human());
    assert!(r.noise_share < 0.5, "{}", r.human());
    let p = r
        .unexplained_resembles
        .as_ref()
        .expect("a probe names the shape");
    assert!(
        p.kind == "delay" && (p.value - 0.015).abs() < 2.5e-3,
        "{}",
        r.human()
    );
}

/// A record of the declared rig whose `signal` column reads `gain` times its
/// value (a sensor's calibration error), diagnosed against that rig.
fn run_with_gain(signal: hydrocyl_identify::data::Signal, gain: f64, seed: u64) -> Report {
    let truth = ValveRig::leaney_moog();
    let mut rec = valve_record(&truth, 2000, 1e-3, seed).unwrap();
    rec.signals
        .get_mut(&signal)
        .expect("the column")
        .iter_mut()
        .for_each(|v| *v *= gain);
    diagnose_valve(&truth, &rec, &DiagnoseOptions::default(), &mut |_, _, _| {}).unwrap()
}

/// A sensor's gain error is not a catalog effect: nothing is added and the
/// probe names the sensor and its gain (a pressure's was a zero error, a
/// position's a flow gain beside a stiffer oil before the gain probes).
fn check_gain(signal: hydrocyl_identify::data::Signal, gain: f64, kind: &str, seed: u64) {
    let r = run_with_gain(signal, gain, seed);
    assert!(r.effects_added.is_empty(), "{}", r.human());
    let p = r
        .unexplained_resembles
        .as_ref()
        .expect("a probe names the shape");
    assert_eq!(p.kind, kind, "{}", r.human());
    assert!(
        (p.value - (gain - 1.0)).abs() < 0.1 * (gain - 1.0).abs(),
        "{}",
        r.human()
    );
}

#[test]
fn a_pressure_sensor_gain_error_is_unexplained_and_named() {
    check_gain(hydrocyl_identify::data::Signal::P2, 1.05, "p2_gain", 41);
}

#[test]
fn a_position_sensor_gain_error_is_unexplained_and_named() {
    check_gain(
        hydrocyl_identify::data::Signal::Position,
        1.03,
        "position_gain",
        42,
    );
}
