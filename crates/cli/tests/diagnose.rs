//! `hydrocyl diagnose` end to end: a fixture diagnosed with a JSON report and
//! plots; malformed input gets a one-line error naming the place, exit code 2
//! and no report file.

use std::path::{Path, PathBuf};
use std::process::Command;

fn bin() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
}

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/measured")
}

#[test]
fn fixture_with_planted_pressure_friction_is_diagnosed() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("report.json");
    let plots = dir.path().join("plots");
    let out = bin()
        .args(["diagnose", "--rig"])
        .arg(fixtures().join("bench-pressure_viscous.rig.json"))
        .arg("--data")
        .arg(fixtures().join("bench-pressure_viscous.csv"))
        .arg("--report")
        .arg(&report)
        .arg("--plots")
        .arg(&plots)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let human = String::from_utf8_lossy(&out.stdout);
    assert!(human.contains("pressure_viscous"), "{human}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    for key in [
        "nrmse_before",
        "nrmse_after",
        "effects_added",
        "effects_rejected",
        "unexplained_share",
        "smoother",
        "samples",
    ] {
        assert!(json.get(key).is_some(), "report lacks {key}");
    }
    assert_eq!(json["samples"], 4000);
    let added = json["effects_added"].as_array().unwrap();
    assert_eq!(added[0]["id"], "pressure_viscous");
    let k = added[0]["params"]["K"].as_f64().unwrap();
    let ci = added[0]["ci95"]["K"].as_f64().unwrap();
    assert!((k - 1e-9).abs() <= ci, "K = {k} ± {ci}");
    assert!(added[0]["explained_share"].as_f64().unwrap() > 0.5);
    assert!(json["smoother"]["half_window"].as_u64().unwrap() >= 2);
    assert!(plots.join("bench-pressure_viscous-friction.svg").exists());
    assert!(plots.join("bench-pressure_viscous-residual.svg").exists());
}

/// Runs diagnose on `csv` text with the no-effect fixture's rig; returns
/// (exit code, stderr, whether a report file appeared).
fn run_bad(name: &str, csv: &str) -> (Option<i32>, String, bool) {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join(name);
    std::fs::write(&data, csv).unwrap();
    let report = dir.path().join("report.json");
    let out = bin()
        .args(["diagnose", "--rig"])
        .arg(fixtures().join("bench-none.rig.json"))
        .arg("--data")
        .arg(&data)
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).to_string(),
        report.exists(),
    )
}

fn good_csv() -> String {
    let text = std::fs::read_to_string(fixtures().join("bench-none.csv")).unwrap();
    text.lines().take(400).collect::<Vec<_>>().join("\n") + "\n"
}

fn replace_line(csv: &str, line: usize, f: impl Fn(&str) -> String) -> String {
    csv.lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == line { f(l) } else { l.to_string() })
        .collect::<Vec<_>>()
        .join("\n")
        + "\n"
}

fn assert_one_line_error(r: (Option<i32>, String, bool), must: &[&str]) {
    let (code, err, wrote) = r;
    assert_eq!(code, Some(2), "{err}");
    assert!(!wrote, "a report was written on error");
    assert_eq!(err.trim_end().lines().count(), 1, "not one line: {err}");
    for m in must {
        assert!(err.contains(m), "'{m}' not in: {err}");
    }
}

/// A smoother half-width wider than the record is refused, not clamped:
/// on a friction bench and on the valve rig.
#[test]
fn a_window_wider_than_the_record_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("short.csv");
    std::fs::write(&data, good_csv()).unwrap();
    let valve = fixtures().join("valve-internal_leakage.csv");
    for (rig, data, most) in [
        (fixtures().join("bench-none.rig.json"), data, "at most 199"),
        (PathBuf::from("leaney-moog"), valve, "at most 999"),
    ] {
        let report = dir.path().join("report.json");
        let out = bin()
            .args(["diagnose", "--rig"])
            .arg(&rig)
            .arg("--data")
            .arg(&data)
            .arg("--report")
            .arg(&report)
            .args(["--window", "100000"])
            .output()
            .unwrap();
        let r = (
            out.status.code(),
            String::from_utf8_lossy(&out.stderr).to_string(),
            report.exists(),
        );
        assert_one_line_error(r, &["half-width (window) of 100000", most]);
    }
    // a steady-state bench does not smooth: a window is refused, not ignored
    let report = dir.path().join("report.json");
    let out = bin()
        .args(["diagnose", "--rig"])
        .arg(fixtures().join("wang-table-5-3.steady.rig.json"))
        .arg("--data")
        .arg(fixtures().join("wang-table-5-3.steady.csv"))
        .arg("--report")
        .arg(&report)
        .args(["--window", "5"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(!report.exists());
    let last = err.trim_end().lines().last().unwrap_or_default();
    assert!(
        last.starts_with("hydrocyl: error: ") && last.contains("leave out the smoother half-width"),
        "{err}"
    );
}

/// Negative option values reach their range checks (one line, exit 2).
#[test]
fn negative_options_are_refused_by_their_range() {
    let valve = fixtures().join("valve-none.csv");
    for (args, words) in [
        (["--min-share", "-1"], "--min-share -1: must be in [0, 1)"),
        (
            ["--holdout", "-0.1"],
            "--holdout -0.1: must be in [0.05, 0.5]",
        ),
        (["--window", "-3"], "--window -3: must be at least 2"),
        // a window of 3 samples interpolates the cubic's 4 coefficients:
        // too narrow to smooth (it was accepted; tester t38d C7)
        (
            ["--window", "1"],
            "--window 1: must be at least 2: the order-3 smoother fits 4 coefficients",
        ),
    ] {
        let out = bin()
            .args(["diagnose", "--rig", "leaney-moog", "--data"])
            .arg(&valve)
            .args(args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(words), "{words}: {err}");
    }
}

#[test]
fn missing_force_column_is_named() {
    let csv = good_csv()
        .lines()
        .map(|l| l.rsplit_once(',').map_or(l, |(a, _)| a).to_string())
        .collect::<Vec<_>>()
        .join("\n");
    assert_one_line_error(run_bad("a.csv", &csv), &["a.csv", "missing column 'force'"]);
}

#[test]
fn text_in_a_number_is_named() {
    let csv = replace_line(&good_csv(), 17, |l| {
        let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
        cells.truncate(4);
        cells[2] = "abc".into();
        cells.join(",")
    });
    assert_one_line_error(
        run_bad("b.csv", &csv),
        &["b.csv", "row 17", "'p2 [bar]'", "'abc' is not a number"],
    );
}

#[test]
fn nan_is_named() {
    let csv = replace_line(&good_csv(), 30, |l| {
        let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
        cells[3] = "NaN".into();
        cells.join(",")
    });
    assert_one_line_error(
        run_bad("c.csv", &csv),
        &["c.csv", "row 30", "'force [N]'", "not finite"],
    );
}

#[test]
fn time_going_backwards_is_named() {
    let csv = replace_line(&good_csv(), 50, |l| {
        let mut cells: Vec<String> = l.split(',').map(str::to_string).collect();
        cells[0] = "0.001".into();
        cells.join(",")
    });
    assert_one_line_error(
        run_bad("d.csv", &csv),
        &["d.csv", "row 50", "does not increase"],
    );
}

#[test]
fn unknown_unit_is_named() {
    let csv = good_csv().replacen("p2 [bar]", "p2 [atm]", 1);
    assert_one_line_error(
        run_bad("e.csv", &csv),
        &["e.csv", "row 1", "'p2 [atm]'", "unknown unit 'atm'"],
    );
}

#[test]
fn unknown_rig_is_an_error() {
    let out = bin()
        .args(["diagnose", "--rig", "no-such-rig", "--data", "x.csv"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("no-such-rig"));
}

#[test]
fn valve_rig_finds_the_planted_leak() {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("r.json");
    let plots = dir.path().join("plots");
    let out = bin()
        .args(["diagnose", "--rig", "leaney-moog", "--quiet", "--data"])
        .arg(fixtures().join("valve-internal_leakage.csv"))
        .arg("--report")
        .arg(&report)
        .arg("--plots")
        .arg(&plots)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out.stdout.is_empty(), "--quiet printed");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    assert_eq!(json["rig_kind"], "netlist");
    // where each effect acts, as `<component>.<parameter>` paths
    let leak = listed(&json, "effects_applicable", "internal_leakage");
    assert_eq!(leak["paths"][0], "cylinder.internal_leakage");
    assert_eq!(json["effects_added"][0]["id"], "internal_leakage");
    for ch in ["position", "velocity", "p1", "p2"] {
        assert!(json["nrmse_before"][ch].is_number(), "{ch}");
        assert!(json["nrmse_after"][ch].is_number(), "{ch}");
        // one plot per channel: measured, before, after and the residuals
        let svg = std::fs::read_to_string(plots.join(format!("valve-internal_leakage-{ch}.svg")))
            .unwrap_or_else(|e| panic!("plot of {ch}: {e}"));
        assert!(svg.contains("<svg") && svg.contains("residual"), "{ch}");
    }
}

#[test]
fn a_valve_record_with_nothing_usable_exits_2_naming_the_problems() {
    // every measured channel constant (an all-zero record)
    let dir = tempfile::tempdir().unwrap();
    let data = dir.path().join("zeros.csv");
    let mut csv = String::from("time [s],command,position [mm],p1 [bar],p2 [bar]\n");
    for i in 0..200 {
        csv.push_str(&format!("{:.3},0,0,0,0\n", i as f64 * 1e-3));
    }
    std::fs::write(&data, csv).unwrap();
    let report = dir.path().join("report.json");
    let out = bin()
        .args(["diagnose", "--rig", "leaney-moog", "--data"])
        .arg(&data)
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(
        err.contains("nothing usable") && err.contains("position"),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!report.exists());
}

/// The report and the plots' folder at one path is refused before any fit:
/// one line, exit code 2, nothing written.
#[test]
fn report_and_plots_at_one_path_are_refused_up_front() {
    let dir = tempfile::tempdir().unwrap();
    let same = dir.path().join("same");
    let out = bin()
        .args(["diagnose", "--rig", "leaney-moog", "--data"])
        .arg(fixtures().join("valve-none.csv"))
        .arg("--report")
        .arg(&same)
        .arg("--plots")
        .arg(&same)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("--plots") && err.contains("another output"),
        "{err}"
    );
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

/// Every catalog effect ends in exactly one of `effects_added`,
/// `effects_rejected` and `effects_not_applicable`, each with a reason.
fn assert_partition(json: &serde_json::Value) {
    let ids = [
        "coulomb_asymmetry",
        "stribeck",
        "viscous",
        "pressure_viscous",
        "acceleration_friction",
        "lugre_dynamics",
        "external_force",
        "internal_leakage",
        "external_leakage",
        "valve_null_bias",
        "flow_gain_error",
        "bulk_modulus",
        "supply_droop",
        "sensor_lag",
        "valve_dead_band",
    ];
    let list = |k: &str| json[k].as_array().unwrap().clone();
    let (added, rejected, na) = (
        list("effects_added"),
        list("effects_rejected"),
        list("effects_not_applicable"),
    );
    for r in &rejected {
        let why = r["reason"].as_str().unwrap_or("");
        assert!(!why.is_empty(), "{} rejected without a reason", r["id"]);
    }
    for n in &na {
        assert!(!n["why"].as_str().unwrap_or("").is_empty(), "{}", n["id"]);
    }
    for id in ids {
        let n = [&added, &rejected, &na]
            .iter()
            .map(|l| l.iter().filter(|e| e["id"] == id).count())
            .sum::<usize>();
        assert_eq!(n, 1, "{id} is in {n} of the three lists");
    }
    assert_eq!(added.len() + rejected.len() + na.len(), ids.len());
}

/// The entry of effect `id` in the report's list `list`
/// (`effects_applicable`, `effects_not_applicable`, ...); panics when the
/// list does not hold it.
fn listed<'a>(json: &'a serde_json::Value, list: &str, id: &str) -> &'a serde_json::Value {
    json[list]
        .as_array()
        .unwrap_or_else(|| panic!("no list `{list}` in the report"))
        .iter()
        .find(|e| e["id"] == id)
        .unwrap_or_else(|| panic!("{id} is not listed in `{list}`"))
}

fn diagnose_json(args: &[&std::ffi::OsStr]) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("r.json");
    let out = bin()
        .args(["diagnose", "--quiet"])
        .args(args)
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap()
}

/// The valve rig declares `viscous` (friction.viscous = b): it was listed
/// as applicable and then in none of the lists.
#[test]
fn the_lists_partition_the_catalog_on_the_valve_rig() {
    let data = fixtures().join("valve-internal_leakage.csv");
    let json = diagnose_json(&[
        "--rig".as_ref(),
        "leaney-moog".as_ref(),
        "--data".as_ref(),
        data.as_os_str(),
    ]);
    assert_partition(&json);
    let why = listed(&json, "effects_not_applicable", "viscous")["why"].as_str();
    assert!(
        why.unwrap().contains("already on in the declared rig"),
        "{why:?}"
    );
}

/// The bench fixture declares `viscous` (friction.viscous = 300 N·s/m):
/// it was in none of the lists.
#[test]
fn the_lists_partition_the_catalog_on_a_bench_rig() {
    let rig_path = fixtures().join("bench-pressure_viscous.rig.json");
    let data = fixtures().join("bench-pressure_viscous.csv");
    let json = diagnose_json(&[
        "--rig".as_ref(),
        rig_path.as_os_str(),
        "--data".as_ref(),
        data.as_os_str(),
    ]);
    assert_partition(&json);
    let why = listed(&json, "effects_not_applicable", "viscous")["why"].as_str();
    assert!(
        why.unwrap().contains("already on in the declared rig"),
        "{why:?}"
    );
    // the tried effects' parameters by their `--set` paths on this rig
    let pv = listed(&json, "effects_applicable", "pressure_viscous");
    assert_eq!(pv["paths"], serde_json::json!(["friction.seal.k_pressure"]));
}

/// `--effects` naming an effect the loop cannot try says why.
#[test]
fn effects_asking_for_a_declared_effect_says_it_is_already_on() {
    let dir = tempfile::tempdir().unwrap();
    let out = bin()
        .args([
            "diagnose",
            "--quiet",
            "--rig",
            "leaney-moog",
            "--effects",
            "viscous",
            "--data",
        ])
        .arg(fixtures().join("valve-internal_leakage.csv"))
        .arg("--report")
        .arg(dir.path().join("r.json"))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("viscous: already on in the declared rig"),
        "{err}"
    );
}

/// A test user's record (Coulomb friction 150 N, declared 50 N). After two
/// effects were added, the rejected candidates were scored
/// against the round model fitted on the whole record while they were
/// traced (with the added effects) on the training part: `sensor_lag` at
/// τ = 0 "explained" −11.8 %, `internal_leakage` at Cl = 6e-14 −12.0 %.
/// An effect whose trace lands on its neutral value removes nothing.
#[test]
fn rejected_effects_at_their_neutral_value_explain_nothing() {
    let data = fixtures().join("valve-two-effects-neutral-shares.csv");
    let json = diagnose_json(&[
        "--rig".as_ref(),
        "leaney-moog".as_ref(),
        "--data".as_ref(),
        data.as_os_str(),
    ]);
    assert_partition(&json);
    // the record's friction is Coulomb 150 N against the preset's 50 N: the
    // loop once added `pressure_viscous` and `external_force` for it; the
    // declared-parameter probe now names it and nothing is added
    assert_eq!(
        json["effects_added"].as_array().unwrap().len(),
        0,
        "{}",
        json["effects_added"]
    );
    let probe = &json["unexplained_resembles"];
    assert_eq!(probe["kind"], "coulomb", "{probe}");
    assert!(
        (probe["value"].as_f64().unwrap() - 150.0).abs() < 5.0,
        "{probe}"
    );
    let mut checked = 0;
    for r in json["effects_rejected"].as_array().unwrap() {
        let p = &r["params"];
        let neutral = match r["id"].as_str().unwrap() {
            "sensor_lag" => p["tau"].as_f64().is_some_and(|t| t < 1e-5),
            "internal_leakage" => p["Cl"].as_f64().is_some_and(|c| c < 1e-13),
            _ => false,
        };
        if neutral {
            checked += 1;
            let share = r["explained_share"].as_f64().unwrap();
            assert!(
                share.abs() < 0.01,
                "{}: explains {share} at its neutral value",
                r["id"]
            );
        }
    }
    assert!(
        checked > 0,
        "no rejected effect at its neutral value: {}",
        json["effects_rejected"]
    );
}

/// A record without a p2 column ran silently: the report now says, in JSON
/// and in the table, that p2 is not compared; the exit code stays 0.
#[test]
fn a_record_without_p2_says_p2_is_not_compared() {
    let dir = tempfile::tempdir().unwrap();
    let full = std::fs::read_to_string(fixtures().join("valve-internal_leakage.csv")).unwrap();
    // drop the p2 column (the last one), keep 1.5 s
    let csv: String = full
        .lines()
        .take(1501)
        .map(|l| format!("{}\n", &l[..l.rfind(',').unwrap()]))
        .collect();
    assert!(csv.starts_with("time [s],command,position [mm],p1 [bar]\n"));
    let data = dir.path().join("no_p2.csv");
    std::fs::write(&data, csv).unwrap();
    let report = dir.path().join("r.json");
    let out = bin()
        .args(["diagnose", "--rig", "leaney-moog", "--data"])
        .arg(&data)
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        text.contains("no p2 column") && text.contains("not compared"),
        "{text}"
    );
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&report).unwrap()).unwrap();
    let p = &json["data_problems"][0];
    assert_eq!(p["channel"], "p2");
    assert_eq!(p["kind"], "missing");
    assert!(json["nrmse_after"].get("p2").is_none());
}

/// A bench preset's file (`fixtures/rigs/<name>.json`) and its printout
/// (`simulate --rig <name> --print-rig`) diagnose as its name does: the
/// identification section is in the file, so the three give one report
/// (JSON equal apart from the times taken), on a short record in the
/// preset's own column names. Each declared refit is named by a `--set`
/// path of the preset, which `simulate --set` takes.
#[test]
fn a_bench_presets_file_and_printout_diagnose_as_its_name() {
    let dir = tempfile::tempdir().unwrap();
    let rigs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/rigs");
    let (n, dt) = (400, 5e-3);
    let w = 2.0 * std::f64::consts::PI * 0.8;
    let motion = |i: usize| {
        let t = i as f64 * dt;
        let v = 0.08 * (w * t).sin();
        let x = -0.08 / w * (w * t).cos();
        let a = 0.08 * w * (w * t).cos();
        let wiggle = 0.3 * (37.0 * t).sin();
        (t, x, v, a, wiggle)
    };
    let emps = dir.path().join("emps.csv");
    let mut text = String::from("t_s,qm_motor_position_m,force_N(=gtau*vir)\n");
    for i in 0..n {
        let (t, x, v, a, e) = motion(i);
        let f = 60.0 * a + 12.0 * (v / 1e-3).tanh() + 130.0 * v + e;
        text.push_str(&format!("{t},{x},{f}\n"));
    }
    std::fs::write(&emps, text).unwrap();
    let seal = dir.path().join("seal.csv");
    let mut text =
        String::from("time_ms [ms],position_mm [mm],pressure_bar_gauge [bar],force_N [N]\n");
    let area = std::f64::consts::PI * 0.0125f64.powi(2);
    for i in 0..n {
        let (t, x, v, _, e) = motion(i);
        let f = 3e5 * area + 4.5 * (v / 1e-4).tanh() + 40.0 * v + 0.1 * e;
        text.push_str(&format!("{},{},3,{f}\n", 1e3 * t, 1e3 * x));
    }
    std::fs::write(&seal, text).unwrap();
    for (name, data) in [("emps", &emps), ("tudelft-seal-25", &seal)] {
        let printed = dir.path().join(format!("{name}.printed.json"));
        let out = bin()
            .args(["simulate", "--rig", name, "--print-rig"])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        std::fs::write(&printed, &out.stdout).unwrap();
        let file = rigs.join(format!("{name}.json"));
        let report = |rig: &std::ffi::OsStr| {
            let mut r = diagnose_json(&[
                "--rig".as_ref(),
                rig,
                "--data".as_ref(),
                data.as_os_str(),
                "--effects".as_ref(),
                "external_force".as_ref(),
            ]);
            let m = r.as_object_mut().unwrap();
            m.remove("wall_times_s");
            m.remove("elapsed_s");
            r
        };
        let by_name = report(name.as_ref());
        assert_eq!(report(file.as_os_str()), by_name, "{name}: file");
        assert_eq!(report(printed.as_os_str()), by_name, "{name}: --print-rig");
        let refits = by_name["declared_refit"].as_array().unwrap();
        assert_eq!(refits.len(), 3, "{name}: {refits:?}");
        for r in refits {
            let path = r["name"].as_str().unwrap();
            let set = format!("{path}={}", r["fitted"]);
            let out = bin()
                .args(["simulate", "--rig", name, "--print-rig", "--set", &set])
                .output()
                .unwrap();
            assert!(
                out.status.success(),
                "{name}: --set {set}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
    }
}

/// A record of fewer than 100 samples is warned of in the report's
/// `warnings`, not only on stderr (a script reading the report never saw
/// it; tester t38d C6), on the valve rig and on the bench, with `--quiet`.
#[test]
fn a_short_record_is_warned_of_in_the_report() {
    let dir = tempfile::tempdir().unwrap();
    for (rig, data) in [
        ("leaney-moog".to_string(), "valve-none.csv"),
        (
            fixtures().join("bench-none.rig.json").display().to_string(),
            "bench-none.csv",
        ),
    ] {
        let text = std::fs::read_to_string(fixtures().join(data)).unwrap();
        let short: String = text.lines().take(61).map(|l| format!("{l}\n")).collect();
        let path = dir.path().join(data);
        std::fs::write(&path, short).unwrap();
        let json = diagnose_json(&[
            "--rig".as_ref(),
            rig.as_ref(),
            "--data".as_ref(),
            path.as_os_str(),
        ]);
        let warnings = json["warnings"].as_array().unwrap();
        assert!(
            warnings.iter().any(|w| {
                let w = w.as_str().unwrap();
                w.contains(data) && w.contains("60 samples, fewer than 100")
            }),
            "{rig}: {warnings:?}"
        );
    }
}

/// A user's circuit whose netlist lists no `outputs` (every probe named
/// `component.probe`, as `docs/netlist.md` allows) has no `position`, `p1`,
/// `p2` for the record to be compared with: one line naming `outputs` and
/// the outputs to add, exit 2, no report. It failed in the declared run
/// ("rig: declared model does not simulate: … channel `position`: the
/// circuit has no such output"), naming no JSON path and no remedy.
#[test]
fn a_netlist_without_the_compared_outputs_is_named_at_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let p = bin()
        .args(["simulate", "--rig", "leaney-moog", "--print-rig"])
        .output()
        .unwrap();
    assert!(p.status.success());
    let mut v: serde_json::Value = serde_json::from_slice(&p.stdout).unwrap();
    v.as_object_mut().unwrap().remove("outputs");
    let rig = dir.path().join("no-outputs.json");
    std::fs::write(&rig, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    let report = dir.path().join("report.json");
    let out = bin()
        .args(["diagnose", "--rig"])
        .arg(&rig)
        .arg("--data")
        .arg(fixtures().join("valve-none.csv"))
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_one_line_error(
        (out.status.code(), err, report.exists()),
        &[
            "`outputs`",
            "\"position\": \"load.position\"",
            "\"velocity\": \"load.velocity\"",
            "\"p1\": \"cylinder.p1\"",
            "\"p2\": \"cylinder.p2\"",
        ],
    );
}

/// A record of the example pump-controlled closed circuit (no four-way
/// valve, no supply: `fixtures/rigs/examples/pump-closed-circuit.json`)
/// with Ce1 = 2e-12 m³/(s·Pa) planted, written by `simulate` with a
/// deterministic noise of ±20 µm and ±20 kPa; `keep_pressures` false drops
/// the p1/p2 columns. Returns the record's path.
fn pump_record(dir: &Path, keep_pressures: bool) -> PathBuf {
    let rig = fixtures().join("../rigs/examples/pump-closed-circuit.json");
    let cmd = dir.join("cmd.csv");
    let u = |t: f64| {
        1.5 * (2.0 * std::f64::consts::PI * 0.8 * t).sin()
            + 0.5 * (2.0 * std::f64::consts::PI * 2.1 * t).sin()
    };
    let mut s = String::from("time,command\n");
    for k in 0..=2000 {
        let t = k as f64 * 1e-3;
        s.push_str(&format!("{t},{}\n", u(t)));
    }
    std::fs::write(&cmd, s).unwrap();
    let sim = dir.join("sim.csv");
    let o = bin()
        .args(["simulate", "--rig"])
        .arg(&rig)
        .arg("--command")
        .arg(&cmd)
        .arg("--out")
        .arg(&sim)
        .args(["--rtol", "1e-8", "--quiet"])
        .args(["--set", "cylinder.external_leakage_1=2e-12"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let text = std::fs::read_to_string(&sim).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| h.starts_with(n)).unwrap();
    let (x, p1, p2) = (col("position "), col("p1 "), col("p2 "));
    // a fixed pseudo-random noise, uniform in ±1 (sd 0.577)
    let mut seed = 12345u64;
    let mut noise = || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    };
    let mut rec = String::from(if keep_pressures {
        "time [s],command,position [mm],p1 [bar],p2 [bar]\n"
    } else {
        "time [s],command,position [mm]\n"
    });
    for l in lines {
        let c: Vec<f64> = l.split(',').map(|v| v.parse().unwrap()).collect();
        let row = format!(
            "{},{},{:.4}",
            c[0],
            u(c[0]),
            (c[x] + 3.5e-5 * noise()) * 1e3
        );
        rec.push_str(&row);
        if keep_pressures {
            let (a, b) = (c[p1] + 3.5e4 * noise(), c[p2] + 3.5e4 * noise());
            rec.push_str(&format!(",{:.4},{:.4}", a / 1e5, b / 1e5));
        }
        rec.push('\n');
    }
    let path = dir.join(if keep_pressures {
        "pump.csv"
    } else {
        "pump-np.csv"
    });
    std::fs::write(&path, rec).unwrap();
    path
}

/// `diagnose` on a pump-controlled closed circuit (a user's circuit with no
/// four-way valve and no supply). Its pressures were left out as a unit
/// error ("p1 reaches 6.9e5 Pa, above the supply 0 Pa") — a circuit that
/// holds no pressure above tank has no supply to be above — and with no
/// measured pressure to start from, the declared model did not simulate:
/// the initial p1/p2 its file declares were cleared for a steady state at
/// rest the circuit does not have ("declared model does not simulate: …
/// no four-way valve feeds this cylinder's chambers"). Now the pressures are
/// compared and the planted leak is found; without pressure columns the
/// run starts from the file's pressures.
#[test]
fn a_pump_circuit_without_a_supply_is_diagnosed() {
    let dir = tempfile::tempdir().unwrap();
    let rig = fixtures().join("../rigs/examples/pump-closed-circuit.json");
    for keep in [true, false] {
        let data = pump_record(dir.path(), keep);
        let json = diagnose_json(&[
            "--rig".as_ref(),
            rig.as_os_str(),
            "--data".as_ref(),
            data.as_os_str(),
        ]);
        let problems = json["data_problems"].as_array().unwrap();
        assert!(
            problems.iter().all(|p| p["kind"] != "units"),
            "{problems:?}"
        );
        if keep {
            assert_eq!(json["effects_added"][0]["id"], "external_leakage", "{json}");
        }
    }
}

/// A record whose command is logged in per cent (`command [%]`, as
/// `simulate` takes a command file) diagnoses as the same record in `-`:
/// the record reader refused it ("unknown unit '%' (accepted: -, V)").
#[test]
fn a_command_in_per_cent_is_read_as_simulate_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(fixtures().join("valve-internal_leakage.csv")).unwrap();
    let mut lines = src.lines();
    let head = lines.next().unwrap();
    assert!(head.starts_with("time [s],command,"), "{head}");
    let mut pc = head.replacen(",command,", ",command [%],", 1) + "\n";
    for l in lines {
        let mut c: Vec<String> = l.split(',').map(str::to_string).collect();
        // the same digits, the decimal point two places on
        let v: f64 = c[1].parse().unwrap();
        c[1] = format!("{:.4}", v * 100.0);
        assert_eq!(
            format!("{:.6}", c[1].parse::<f64>().unwrap() / 100.0),
            l.split(',').nth(1).unwrap()
        );
        pc.push_str(&c.join(","));
        pc.push('\n');
    }
    let data = dir.path().join("pc.csv");
    std::fs::write(&data, pc).unwrap();
    let a = diagnose_json(&[
        "--rig".as_ref(),
        "leaney-moog".as_ref(),
        "--data".as_ref(),
        fixtures().join("valve-internal_leakage.csv").as_os_str(),
    ]);
    let b = diagnose_json(&[
        "--rig".as_ref(),
        "leaney-moog".as_ref(),
        "--data".as_ref(),
        data.as_os_str(),
    ]);
    // the same record but for the last bit of a command (0.01 × in
    // binary): the same effect, within the integration's noise
    let ids = |j: &serde_json::Value| -> Vec<String> {
        j["effects_added"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["id"].as_str().unwrap().to_string())
            .collect()
    };
    assert_eq!(ids(&a), ["internal_leakage"]);
    assert_eq!(ids(&a), ids(&b));
    let cl = |j: &serde_json::Value| j["effects_added"][0]["params"]["Cl"].as_f64().unwrap();
    assert!(
        (cl(&a) / cl(&b) - 1.0).abs() < 1e-4,
        "{} {}",
        cl(&a),
        cl(&b)
    );
    for ch in ["position", "p1", "p2"] {
        let (x, y) = (
            a["nrmse_after"][ch].as_f64().unwrap(),
            b["nrmse_after"][ch].as_f64().unwrap(),
        );
        assert!((x / y - 1.0).abs() < 1e-3, "{ch}: {x} {y}");
    }
}

/// A short record (fewer than 100 samples: warned of) that the rig refuses
/// (a closed-loop record's `reference` on an open-loop rig) gets its one
/// error line alone: the warning was printed first, before the record was
/// checked against the rig, making the error two lines.
#[test]
fn a_short_record_refused_by_the_rig_is_one_error_line() {
    let dir = tempfile::tempdir().unwrap();
    let mut s = String::from("time [s],reference [mm],command,position [mm],p1 [bar],p2 [bar]\n");
    for k in 0..30 {
        s.push_str(&format!("{},1.0,0.01,0.0,21.0,42.0\n", k as f64 * 1e-3));
    }
    let data = dir.path().join("short.csv");
    std::fs::write(&data, s).unwrap();
    let report = dir.path().join("r.json");
    let out = bin()
        .args(["diagnose", "--rig", "leaney-moog", "--data"])
        .arg(&data)
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr).to_string();
    assert_one_line_error(
        (out.status.code(), err, report.exists()),
        &["short.csv", "has no controller"],
    );
}

/// A header that names a signal but is not read as it — the unit in
/// parentheses, `p1 (bar)`, or the name in capitals, `Time [s]` — is named
/// where the signal is missing, with the header that would be read. The
/// record's pressures were dropped as "the record has no p1 column" (a
/// data problem; the diagnosis went on without them) and a time column as
/// "missing column 'time'", with nothing pointing at the header.
#[test]
fn a_signal_header_not_read_as_it_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let src = std::fs::read_to_string(fixtures().join("valve-internal_leakage.csv")).unwrap();
    let (head, body) = src.split_once('\n').unwrap();
    assert_eq!(head, "time [s],command,position [mm],p1 [bar],p2 [bar]");
    let data = dir.path().join("paren.csv");
    std::fs::write(
        &data,
        format!("time [s],command,position [mm],p1 (bar),p2 [bar]\n{body}"),
    )
    .unwrap();
    let json = diagnose_json(&[
        "--rig".as_ref(),
        "leaney-moog".as_ref(),
        "--data".as_ref(),
        data.as_os_str(),
    ]);
    let p1 = json["data_problems"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["channel"] == "p1")
        .unwrap()["message"]
        .as_str()
        .unwrap()
        .to_string();
    assert!(
        p1.contains("the header 'p1 (bar)' is not read as p1") && p1.contains("`p1 [bar]`"),
        "{p1}"
    );
    std::fs::write(
        &data,
        format!("Time [s],command,position [mm],p1 [bar],p2 [bar]\n{body}"),
    )
    .unwrap();
    let r = run_bad_rig("leaney-moog", &data);
    assert_one_line_error(
        r,
        &[
            "row 1: missing column 'time' (the header 'Time [s]' is not read as time",
            "`time [s]`",
        ],
    );
}

/// Runs diagnose with `rig` on `data`; (exit code, stderr, whether a
/// report file appeared).
fn run_bad_rig(rig: &str, data: &Path) -> (Option<i32>, String, bool) {
    let dir = tempfile::tempdir().unwrap();
    let report = dir.path().join("report.json");
    let out = bin()
        .args(["diagnose", "--rig", rig, "--data"])
        .arg(data)
        .arg("--report")
        .arg(&report)
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).to_string(),
        report.exists(),
    )
}
