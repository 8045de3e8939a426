//! Closed-loop records (a `reference` column): the rig's controller computes
//! the command from the reference and the simulated position, and the
//! measured command is a channel compared like the others. Generated
//! `leaney-moog-closed-loop` records with nothing, an external force, a
//! leak or a valve dead band planted.

use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::data::{Record, Signal};
use hydrocyl_identify::diagnose::{DiagnoseOptions, Report};
use hydrocyl_identify::synth::{valve_planted_all, valve_record_closed_loop, valve_reference};
use hydrocyl_identify::valve::{diagnose_valve, set};
use hydrocyl_system::valve_rig::ValveRig;

fn declared() -> ValveRig {
    let v = hydrocyl_system::rig::preset("leaney-moog-closed-loop").unwrap();
    hydrocyl_system::rig::valve_rig_from(&v).unwrap()
}

fn record(planted: &[(EffectId, &str, f64)], seed: u64) -> Record {
    let mut t = declared();
    for (id, name, v) in planted {
        set(&mut t, *id, name, *v);
    }
    valve_record_closed_loop(&t, 4000, 1e-3, seed, &valve_reference).unwrap()
}

fn diagnose(rec: &Record) -> Report {
    diagnose_valve(
        &declared(),
        rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap()
}

fn planted(id: EffectId) -> Vec<(EffectId, &'static str, f64)> {
    valve_planted_all(id)
        .into_iter()
        .map(|(n, v)| (id, n, v))
        .collect()
}

use crate::{check_found_within, ids};

/// The planted value's distance allowed on a closed-loop record, in 95 %
/// intervals. The recorded command is the controller's law on the *noisy*
/// position (as a real controller computes it), while the fit's controller
/// acts on the simulated one: an errors-in-variables bias the interval
/// (noise on the outputs only) leaves out. Measured on seeds 82 and 86
/// (F0, and Cl under PI), in intervals: 0.90 / 0.97 with the stiff solver's
/// finite-difference Jacobian, 1.04 / 1.09 with the analytic one, 1.24 / 1.03
/// with the fit on DP45 alone; the bias does not follow the solver.
const CLOSED_LOOP_BIAS: f64 = 1.5;

#[test]
fn a_closed_loop_record_compares_the_command_and_stays_on_the_measurement() {
    let rec = record(&[], 81);
    let r = diagnose(&rec);
    eprintln!("{}", r.human());
    assert!(ids(&r).is_empty(), "{}", r.human());
    assert!(r.nrmse_before.contains_key("command"), "{}", r.human());
    for (ch, floor) in r.noise_floor.iter().filter(|(_, f)| **f > 0.0) {
        let before = &r.nrmse_before[ch];
        assert!(*before <= 1.5 * floor, "{ch}: {before}\n{}", r.human());
    }
}

#[test]
fn an_external_force_is_found_in_closed_loop() {
    let (id, n, v) = planted(EffectId::ExternalForce)[0];
    let r = diagnose(&record(&[(id, n, v)], 82));
    eprintln!("{}", r.human());
    check_found_within(&r, id, n, v, CLOSED_LOOP_BIAS);
}

#[test]
fn an_internal_leak_is_found_in_closed_loop() {
    let (id, n, v) = planted(EffectId::InternalLeakage)[0];
    let r = diagnose(&record(&[(id, n, v)], 83));
    eprintln!("{}", r.human());
    check_found_within(&r, id, n, v, CLOSED_LOOP_BIAS);
}

#[test]
fn a_valve_dead_band_is_found_in_closed_loop() {
    // 5 % of the spool stroke (18.75 µm): the piston stops short of the
    // reference by the error whose command stays inside the dead zone
    let xd = 0.05 * declared().valve.stroke_m;
    let r = diagnose(&record(&[(EffectId::ValveDeadBand, "xd", xd)], 85));
    eprintln!("{}", r.human());
    check_found_within(&r, EffectId::ValveDeadBand, "xd", xd, CLOSED_LOOP_BIAS);
}

#[test]
fn a_closed_loop_record_needs_a_closed_loop_rig() {
    let rec = record(&[], 84);
    let e = diagnose_valve(
        &ValveRig::leaney_moog(),
        &rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("reference"), "{e}");
    let mut open = rec.clone();
    open.signals.remove(&Signal::Reference);
    let e = diagnose_valve(
        &declared(),
        &open,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap_err();
    assert!(e.to_string().contains("closed loop"), "{e}");
}

/// The preset with a PI controller (integral time 0.5 s).
fn declared_pi() -> ValveRig {
    let mut r = declared();
    if let Some(c) = r.controller.as_mut() {
        c.integral_time_s = 0.5;
    }
    r
}

#[test]
fn an_internal_leak_is_found_under_a_pi_controller() {
    let (id, n, v) = planted(EffectId::InternalLeakage)[0];
    let mut t = declared_pi();
    set(&mut t, id, n, v);
    let rec = valve_record_closed_loop(&t, 4000, 1e-3, 86, &valve_reference).unwrap();
    let r = diagnose_valve(
        &declared_pi(),
        &rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    eprintln!("{}", r.human());
    check_found_within(&r, id, n, v, CLOSED_LOOP_BIAS);
}

#[test]
fn a_record_that_starts_on_a_reference_step_fits_the_true_model_to_its_floor() {
    // the reference steps to 40 mm at the first sample: the controller's
    // first command is 0.4 while the piston, and so the spool, is at rest
    let step = |t: f64| {
        use std::f64::consts::PI;
        0.04 * (PI * t + 0.01).sin().signum() + 0.01 * (2.0 * PI * 1.3 * t).sin()
    };
    let rec = valve_record_closed_loop(&declared(), 4000, 1e-3, 87, &step).unwrap();
    assert!(rec.get(Signal::Command).unwrap()[0] > 0.3);
    let r = diagnose(&rec);
    assert!(r.effects_added.is_empty(), "{}", r.human());
    for (ch, after) in &r.nrmse_after {
        if let Some(floor) = r.noise_floor.get(ch).filter(|f| **f > 0.0) {
            assert!(
                after / floor < 1.1,
                "{ch}: {after} vs floor {floor}\n{}",
                r.human()
            );
        }
    }
}
