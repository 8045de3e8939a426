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
        (["--window", "-3"], "--window -3: must be at least 1"),
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
    let leak = json["effects_applicable"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["id"] == "internal_leakage")
        .unwrap();
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
