//! The loop on generated friction-bench records with planted effects.

use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::diagnose::{diagnose_bench, DiagnoseOptions, Outcome};
use hydrocyl_identify::synth::{declared_for, record, truth_with, Foreign, Noise};

fn run(planted: &[EffectId], foreign: Foreign, seed: u64) -> Outcome {
    let truth = truth_with(planted);
    let rec = record(&truth, 8000, 1e-3, Noise::default(), foreign, seed);
    let declared = declared_for(planted);
    diagnose_bench(
        &declared,
        &[rec],
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap()
}

fn show(o: &Outcome) -> String {
    o.report.human()
}

fn check_single(id: EffectId, seed: u64) {
    let o = run(&[id], Foreign::None, seed);
    let r = &o.report;
    assert!(
        !r.effects_added.is_empty(),
        "{id}: nothing added\n{}",
        show(&o)
    );
    let first = &r.effects_added[0];
    assert_eq!(first.id, id.id(), "{}", show(&o));
    let truth = hydrocyl_identify::synth::planted(id);
    for (name, value) in &truth {
        let got = first.params[name];
        let ci = first.ci95[name].expect("interval");
        assert!(
            (got - value).abs() <= ci,
            "{id}.{name}: {got} ± {ci} vs {value}\n{}",
            show(&o)
        );
    }
    let after = r.nrmse_after["force"];
    let floor = r.noise_floor["force"];
    assert!(
        after <= 1.5 * floor,
        "{id}: nrmse {after} vs floor {floor}\n{}",
        show(&o)
    );
}

#[test]
fn viscous_is_found() {
    check_single(EffectId::Viscous, 11);
}

#[test]
fn pressure_viscous_is_found() {
    check_single(EffectId::PressureViscous, 12);
}

#[test]
fn coulomb_asymmetry_is_found() {
    check_single(EffectId::CoulombAsymmetry, 13);
}

#[test]
fn external_force_is_found() {
    check_single(EffectId::ExternalForce, 14);
}

#[test]
fn stribeck_is_found() {
    check_single(EffectId::Stribeck, 15);
}

#[test]
fn acceleration_friction_is_found() {
    check_single(EffectId::AccelerationFriction, 16);
}

#[test]
fn lugre_dynamics_is_found() {
    check_single(EffectId::LugreDynamics, 17);
}

#[test]
fn nothing_missing_adds_nothing() {
    let o = run(&[], Foreign::None, 21);
    assert!(o.report.effects_added.is_empty(), "{}", show(&o));
    assert!(o.report.nrmse_after["force"] <= 1.5 * o.report.noise_floor["force"]);
}

#[test]
fn out_of_catalog_spring_is_unexplained() {
    let o = run(&[], Foreign::Spring(400.0), 22);
    let r = &o.report;
    assert!(r.effects_added.is_empty(), "{}", show(&o));
    assert!(r.noise_share < 0.5, "{}", show(&o));
    assert!(r.unexplained_share > 0.9, "{}", show(&o));
    let p = r
        .unexplained_resembles
        .as_ref()
        .expect("a probe names the shape");
    assert!(p.what.contains("spring"), "{}", show(&o));
    assert!((p.value / 400.0 - 1.0).abs() < 0.05, "{}", show(&o));
}

#[test]
fn two_effects_are_both_found() {
    let o = run(
        &[EffectId::PressureViscous, EffectId::ExternalForce],
        Foreign::None,
        23,
    );
    let ids: Vec<&str> = o
        .report
        .effects_added
        .iter()
        .map(|e| e.id.as_str())
        .collect();
    assert_eq!(ids.len(), 2, "{}", show(&o));
    assert!(
        ids.contains(&"pressure_viscous") && ids.contains(&"external_force"),
        "{}",
        show(&o)
    );
    assert!(
        o.report.nrmse_after["force"] <= 1.5 * o.report.noise_floor["force"],
        "{}",
        show(&o)
    );
}

#[test]
fn out_of_catalog_delay_is_unexplained() {
    // A 10 ms transport delay of the load-cell signal: no catalog effect is
    // a delay, so the residual must stay unexplained, not be dressed up.
    let o = run(&[], Foreign::ForceDelay(0.01), 24);
    let r = &o.report;
    assert!(r.effects_added.is_empty(), "{}", show(&o));
    let p = r
        .unexplained_resembles
        .as_ref()
        .expect("a probe names the shape");
    assert!(p.what.contains("delay"), "{}", show(&o));
    assert!((p.value - 0.01).abs() < 1.5e-3, "{}", show(&o));
}

/// The loop on a record without missing effects whose `signal` column
/// reads `gain` times its value (a sensor's calibration error).
fn run_with_gain(signal: hydrocyl_identify::data::Signal, gain: f64, seed: u64) -> Outcome {
    let truth = truth_with(&[]);
    let mut rec = record(&truth, 8000, 1e-3, Noise::default(), Foreign::None, seed);
    rec.signals
        .get_mut(&signal)
        .expect("the column")
        .iter_mut()
        .for_each(|v| *v *= gain);
    diagnose_bench(
        &declared_for(&[]),
        &[rec],
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap()
}

/// A sensor's gain error is not a catalog effect: nothing is added (a
/// constant `external_force` stood in for it before the gain probes), and
/// the probe names the sensor and its gain.
fn check_gain(signal: hydrocyl_identify::data::Signal, gain: f64, kind: &str, seed: u64) {
    let o = run_with_gain(signal, gain, seed);
    let r = &o.report;
    assert!(r.effects_added.is_empty(), "{}", show(&o));
    assert!(r.unexplained_share > 0.9, "{}", show(&o));
    let p = r
        .unexplained_resembles
        .as_ref()
        .expect("a probe names the shape");
    assert_eq!(p.kind, kind, "{}", show(&o));
    assert!(
        (p.value - (gain - 1.0)).abs() < 0.1 * (gain - 1.0).abs(),
        "{}",
        show(&o)
    );
}

#[test]
fn a_load_cell_gain_error_is_unexplained_and_named() {
    check_gain(
        hydrocyl_identify::data::Signal::Force,
        1.03,
        "force_gain",
        25,
    );
}

#[test]
fn a_pressure_sensor_gain_error_is_unexplained_and_named() {
    check_gain(hydrocyl_identify::data::Signal::P2, 1.05, "p2_gain", 26);
}

#[test]
fn a_pressure_twice_what_the_force_balance_implies_is_an_error_naming_the_file() {
    // the bench's pressure is its model's input: doubled, the friction the
    // record implies no longer opposes the motion
    let truth = truth_with(&[]);
    let mut rec = record(&truth, 4000, 1e-3, Noise::default(), Foreign::None, 71);
    rec.source = "doubled.csv".into();
    if let Some(p) = rec.signals.get_mut(&hydrocyl_identify::data::Signal::P2) {
        p.iter_mut().for_each(|v| *v *= 2.0);
    }
    let e = diagnose_bench(
        &declared_for(&[]),
        &[rec],
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.starts_with("doubled.csv: ") && e.contains("pressure force does not balance"),
        "{e}"
    );
}

#[test]
fn bench_data_problems_name_their_record_and_say_the_pressure_is_kept() {
    // p2 in 0.1 bar steps on two records: a quantised input, kept
    let truth = truth_with(&[]);
    let recs: Vec<_> = (0..2)
        .map(|k| {
            let mut r = record(&truth, 4000, 1e-3, Noise::default(), Foreign::None, 72 + k);
            r.source = format!("rec{k}.csv");
            if let Some(p) = r.signals.get_mut(&hydrocyl_identify::data::Signal::P2) {
                p.iter_mut().for_each(|v| *v = (*v / 1e4).round() * 1e4);
            }
            r
        })
        .collect();
    let o = diagnose_bench(
        &declared_for(&[]),
        &recs,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap();
    let ps = &o.report.data_problems;
    let files: Vec<&str> = ps.iter().map(|p| p.file.as_str()).collect();
    assert_eq!(files, ["rec0.csv", "rec1.csv"], "{}", o.report.human());
    assert!(ps.iter().all(|p| p.channel == "p2" && !p.left_out));
    let text = o.report.human();
    assert!(!text.contains("left out"), "{text}");
    assert!(
        text.contains("rec1.csv: p2") && text.contains("kept"),
        "{text}"
    );
}
