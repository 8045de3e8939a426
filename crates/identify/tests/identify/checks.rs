//! Data problems named before any fit, the acceptance rule and end stops,
//! on generated `leaney-moog` records with the mistakes real data carries.

use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::data::{Record, Signal};
use hydrocyl_identify::data_checks::ProblemKind;
use hydrocyl_identify::diagnose::{DiagnoseError, DiagnoseOptions, Report};
use hydrocyl_identify::synth::{valve_planted_all, valve_record, valve_record_with};
use hydrocyl_identify::valve::{diagnose_valve, set};
use hydrocyl_system::valve_rig::ValveRig;

fn truth(planted: &[EffectId]) -> ValveRig {
    let mut t = ValveRig::leaney_moog();
    for id in planted {
        for (name, v) in valve_planted_all(*id) {
            set(&mut t, *id, name, v);
        }
    }
    t
}

fn diagnose(rec: &Record) -> Result<Report, DiagnoseError> {
    diagnose_valve(
        &ValveRig::leaney_moog(),
        rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
}

/// Every number of the JSON report is finite (NaN and infinities would be
/// written as `null`); `null` is allowed only where the report says "none"
/// (no probe, no interval of a rejected candidate).
fn assert_finite(r: &Report) {
    fn walk(v: &serde_json::Value, path: &str) {
        match v {
            // a velocity derived from the position has no noise floor
            serde_json::Value::Null => assert!(
                path.ends_with("unexplained_resembles")
                    || path.contains("effects_rejected")
                    || path == "report.noise_floor.velocity",
                "null at {path}"
            ),
            serde_json::Value::Number(n) => {
                assert!(n.as_f64().is_some_and(f64::is_finite), "{path}: {n}")
            }
            serde_json::Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    walk(x, &format!("{path}[{i}]"));
                }
            }
            serde_json::Value::Object(o) => {
                for (k, x) in o {
                    walk(x, &format!("{path}.{k}"));
                }
            }
            _ => {}
        }
    }
    walk(&serde_json::to_value(r).unwrap(), "report");
    let text = r.human();
    for bad in ["NaN", "inf"] {
        assert!(!text.contains(bad), "{bad} in\n{text}");
    }
}

fn with(rec: &Record, sig: Signal, f: impl Fn(f64) -> f64) -> Record {
    let mut r = rec.clone();
    if let Some(v) = r.signals.get_mut(&sig) {
        v.iter_mut().for_each(|x| *x = f(*x));
    }
    r
}

fn problems(r: &Report) -> Vec<(String, ProblemKind)> {
    r.data_problems
        .iter()
        .map(|p| (p.channel.clone(), p.kind))
        .collect()
}

#[test]
fn a_stuck_pressure_sensor_is_named_and_the_leak_still_found() {
    let rec = valve_record(&truth(&[EffectId::InternalLeakage]), 2000, 1e-3, 61).unwrap();
    let rec = with(&rec, Signal::P1, |_| 2e6);
    let r = diagnose(&rec).unwrap();
    assert_finite(&r);
    assert_eq!(problems(&r), [("p1".to_string(), ProblemKind::Constant)]);
    assert!(!r.nrmse_after.contains_key("p1"), "{}", r.human());
    let first = r
        .effects_added
        .first()
        .unwrap_or_else(|| panic!("{}", r.human()));
    assert_eq!(first.id, "internal_leakage", "{}", r.human());
    let ci = first.ci95["Cl"].unwrap();
    assert!((first.params["Cl"] - 1e-11).abs() <= ci, "{}", r.human());
}

#[test]
fn a_position_in_metres_under_a_millimetre_header_is_named() {
    // the column says [mm], the numbers are metres: 1000 times too small
    let rec = valve_record(&truth(&[]), 2000, 1e-3, 62).unwrap();
    let rec = with(&rec, Signal::Position, |x| x * 1e-3);
    let r = diagnose(&rec).unwrap();
    assert_finite(&r);
    assert_eq!(problems(&r), [("position".to_string(), ProblemKind::Units)]);
    assert!(r.effects_added.is_empty(), "{}", r.human());
}

#[test]
fn pressures_in_pascal_under_a_bar_header_are_named() {
    let rec = valve_record(&truth(&[]), 2000, 1e-3, 63).unwrap();
    let rec = with(&rec, Signal::P1, |p| p * 1e5);
    let rec = with(&rec, Signal::P2, |p| p * 1e5);
    let r = diagnose(&rec).unwrap();
    assert_finite(&r);
    assert_eq!(
        problems(&r),
        [
            ("p1".to_string(), ProblemKind::Units),
            ("p2".to_string(), ProblemKind::Units)
        ]
    );
    assert!(r.effects_added.is_empty(), "{}", r.human());
}

#[test]
fn pressures_in_bar_under_a_kilopascal_header_are_named() {
    // 100 times too low: above a thousandth of the supply, so only the
    // declared model's pressures on the same command can tell
    let rec = valve_record(&truth(&[]), 2000, 1e-3, 65).unwrap();
    let rec = with(&rec, Signal::P1, |p| p * 1e-2);
    let rec = with(&rec, Signal::P2, |p| p * 1e-2);
    let r = diagnose(&rec).unwrap();
    assert_finite(&r);
    assert_eq!(
        problems(&r),
        [
            ("p1".to_string(), ProblemKind::Units),
            ("p2".to_string(), ProblemKind::Units)
        ],
        "{}",
        r.human()
    );
    assert!(!r.nrmse_after.contains_key("p1"), "{}", r.human());
    assert!(r.effects_added.is_empty(), "{}", r.human());
    // the honest record has none, and its derived velocity no noise floor
    let r = diagnose(&valve_record(&truth(&[]), 2000, 1e-3, 65).unwrap()).unwrap();
    assert_eq!(problems(&r), [], "{}", r.human());
    assert!(r.noise_floor["velocity"].is_nan(), "{}", r.human());
    assert!(r
        .human()
        .lines()
        .any(|l| l.starts_with("velocity") && l.ends_with("n/a")));
}

#[test]
fn a_dropout_in_the_record_is_named_and_the_channels_kept() {
    // a 1 kHz record with the rows from 1.2 s to 1.5 s removed
    let rec = valve_record(&truth(&[]), 2000, 1e-3, 66).unwrap();
    let keep: Vec<bool> = rec
        .time
        .iter()
        .map(|t| !(*t > 1.2005 && *t < 1.4995))
        .collect();
    let mut cut = rec.clone();
    let pick = |y: &[f64]| -> Vec<f64> {
        y.iter()
            .zip(&keep)
            .filter(|(_, k)| **k)
            .map(|(v, _)| *v)
            .collect()
    };
    cut.time = pick(&rec.time);
    for v in cut.signals.values_mut() {
        *v = pick(v);
    }
    let r = diagnose(&cut).unwrap();
    assert_finite(&r);
    assert_eq!(problems(&r), [("time".to_string(), ProblemKind::Gap)]);
    let gap = &r.data_problems[0];
    assert!(!gap.left_out, "{gap:?}");
    assert!(
        gap.message.contains("from 1.2000 s to 1.5000 s") && gap.message.contains("interpolated")
    );
    for ch in ["position", "p1", "p2"] {
        assert!(r.nrmse_after.contains_key(ch), "{ch}\n{}", r.human());
    }
}

#[test]
fn a_record_without_p2_says_p2_is_not_compared() {
    let mut rec = valve_record(&truth(&[]), 2000, 1e-3, 67).unwrap();
    rec.signals.remove(&Signal::P2);
    let r = diagnose(&rec).unwrap();
    assert_finite(&r);
    assert_eq!(problems(&r), [("p2".to_string(), ProblemKind::Missing)]);
    assert!(!r.nrmse_after.contains_key("p2"));
    let text = r.human();
    assert!(
        text.contains("no p2 column") && text.contains("not compared"),
        "{text}"
    );
}

#[test]
fn a_flipped_command_sign_is_named_and_nothing_is_dressed_up() {
    let rec = valve_record(&truth(&[EffectId::ExternalLeakage]), 2000, 1e-3, 64).unwrap();
    let rec = with(&rec, Signal::Command, |u| -u);
    let r = diagnose(&rec).unwrap();
    assert_finite(&r);
    assert_eq!(problems(&r), [("position".to_string(), ProblemKind::Sign)]);
    // whatever is added carries an interval that excludes zero
    for e in &r.effects_added {
        for k in e.params.keys() {
            assert!(e.ci95[k].is_some(), "{}", r.human());
        }
    }
}

#[test]
fn a_record_with_nothing_usable_is_an_error() {
    let rec = valve_record(&truth(&[]), 500, 1e-3, 65).unwrap();
    let zero = with(
        &with(&with(&rec, Signal::Position, |_| 0.0), Signal::P1, |_| 0.0),
        Signal::P2,
        |_| 0.0,
    );
    match diagnose(&zero) {
        Err(DiagnoseError::Unusable { why, .. }) => {
            assert!(why.contains("position") && why.contains("p1"), "{why}")
        }
        other => panic!("expected Unusable, got {other:?}"),
    }
}

#[test]
fn a_record_resting_on_an_end_stop_is_diagnosed() {
    // The command's mean pushes the piston onto the extending stop, where it
    // rests for part of every second before the sine pulls it off again.
    let cmd = |t: f64| hydrocyl_identify::synth::valve_command(t) + 0.1;
    let rec = valve_record_with(
        &truth(&[EffectId::InternalLeakage]),
        4000,
        1e-3,
        66,
        0.0,
        &cmd,
    )
    .unwrap();
    let x = rec.get(Signal::Position).unwrap();
    let at_stop = x.iter().filter(|v| **v > 0.26 - 1e-4).count();
    assert!(at_stop > 400, "{at_stop} samples at the stop");
    let r = diagnose(&rec).unwrap();
    assert_finite(&r);
    eprintln!("{}", r.human());
    let ids: Vec<&str> = r.effects_added.iter().map(|e| e.id.as_str()).collect();
    assert_eq!(ids, ["internal_leakage"], "{}", r.human());
    let e = &r.effects_added[0];
    assert!(
        (e.params["Cl"] - 1e-11).abs() <= e.ci95["Cl"].unwrap(),
        "{}",
        r.human()
    );
    for ch in ["position", "p1", "p2"] {
        assert!(
            r.nrmse_after[ch] <= 1.5 * r.noise_floor[ch],
            "{ch}\n{}",
            r.human()
        );
    }
}

#[test]
fn pressure_viscous_is_found_on_the_valve_rig() {
    // K (p1 - p2)^2 v as an additive term on the coulomb-viscous law:
    // about 100 N at 2.5 MPa across the piston and 50 mm/s.
    let mut t = truth(&[]);
    set(&mut t, EffectId::PressureViscous, "K", 3e-10);
    let rec = valve_record(&t, 2000, 1e-3, 67).unwrap();
    let r = diagnose(&rec).unwrap();
    assert_finite(&r);
    let first = r
        .effects_added
        .first()
        .unwrap_or_else(|| panic!("{}", r.human()));
    assert_eq!(first.id, "pressure_viscous", "{}", r.human());
    let ci = first.ci95["K"].unwrap();
    assert!((first.params["K"] - 3e-10).abs() <= ci, "{}", r.human());
    // K H a is offered once K is there, and every effect not tried says why
    assert!(r
        .effects_not_applicable
        .iter()
        .all(|e| !e.why.is_empty() && e.id != "pressure_viscous"));
}

#[test]
fn bar_under_a_psi_header_is_named_by_the_force_balance() {
    // p2 [psi] holding bar: 14.5 times too low, but within the supply
    let rec = valve_record(&truth(&[]), 2000, 1e-3, 65).unwrap();
    let rec = with(&rec, Signal::P2, |p| p / 1e5 * hydrocyl_ports::PSI_IN_PA);
    let r = diagnose(&rec).unwrap();
    assert_finite(&r);
    assert_eq!(
        problems(&r),
        [
            ("p1".to_string(), ProblemKind::Units),
            ("p2".to_string(), ProblemKind::Units)
        ]
    );
    assert!(r.data_problems.iter().all(|p| p.left_out));
    assert!(r.effects_added.is_empty(), "{}", r.human());
    // the human report lists each problem once, under "data problems" (the
    // JSON's warnings keep them too, for a reader of that list alone)
    let text = r.human();
    assert_eq!(
        text.matches("do not balance the piston").count(),
        2,
        "{text}"
    );
    assert!(!text.contains("warning: p1 left out of the fit"), "{text}");
    assert!(r
        .warnings
        .iter()
        .any(|w| w.starts_with("p1 left out of the fit")));
    // the position fit is what it is without the pressures
    assert!(
        r.nrmse_after["position"] < 1.1 * r.noise_floor["position"],
        "{}",
        r.human()
    );
}

#[test]
fn a_quantised_position_whose_peak_dwells_on_a_level_is_not_clipped() {
    // 0.5 mm steps: a sine peak sits on its top level for a few % of the record
    let rec = valve_record(&truth(&[]), 2000, 1e-3, 66).unwrap();
    let rec = with(&rec, Signal::Position, |x| (x / 5e-4).round() * 5e-4);
    let r = diagnose(&rec).unwrap();
    assert!(
        !problems(&r)
            .iter()
            .any(|(c, k)| c == "position" && *k == ProblemKind::Clipped),
        "{}",
        r.human()
    );
    assert!(r.nrmse_after.contains_key("position"), "{}", r.human());
}

#[test]
fn seconds_under_a_millisecond_header_are_an_error_naming_the_time_column() {
    // the header says [ms], the numbers are seconds: the record lasts 2 ms
    let mut rec = valve_record(&truth(&[]), 2000, 1e-3, 67).unwrap();
    rec.time.iter_mut().for_each(|t| *t *= 1e-3);
    rec.units.insert(Signal::Time, "ms".into());
    let e = diagnose(&rec).unwrap_err().to_string();
    assert!(
        e.contains("row 1, column 'time [ms]'") && e.contains("unit of the time column"),
        "{e}"
    );
}

#[test]
fn a_command_in_volts_on_a_valve_rig_is_an_error_naming_the_column() {
    let mut rec = valve_record(&truth(&[]), 2000, 1e-3, 68).unwrap();
    rec.units.insert(Signal::Command, "V".into());
    let e = diagnose(&rec).unwrap_err();
    assert!(matches!(e, DiagnoseError::Data(_)), "{e}");
    let e = e.to_string();
    assert!(
        e.contains("row 1, column 'command [V]'") && e.contains("normalised spool demand"),
        "{e}"
    );
    // `-` (or `1`) is the valve rig's own
    rec.units.insert(Signal::Command, "1".into());
    assert!(diagnose(&rec).is_ok());
}
