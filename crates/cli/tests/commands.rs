//! The shipped command files of the thesis's experiments
//! (`fixtures/commands/`): they are what `cargo xtask commands` writes from
//! the studies' signal definitions (so they cannot drift from them), and
//! each runs through `hydrocyl simulate` on its preset by the command line
//! its README gives (on its first 0.3 s, to keep the test fast).

use hydrocyl_studies::commands::{all, readme, CommandFile, FOLDER};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn folder() -> PathBuf {
    root().join(FOLDER)
}

#[test]
fn the_shipped_files_are_what_the_generator_writes() {
    let files = all().unwrap();
    let dir = folder();
    for f in &files {
        let shipped = std::fs::read_to_string(dir.join(&f.name))
            .unwrap_or_else(|e| panic!("{}: {e} (run `cargo xtask commands`)", f.name));
        assert!(
            shipped == f.csv(),
            "{}: not what the generator writes; run `cargo xtask commands`",
            f.name
        );
    }
    let shipped = std::fs::read_to_string(dir.join("README.md")).unwrap();
    assert!(
        shipped == readme(&files),
        "README.md: not what the generator writes; run `cargo xtask commands`"
    );
    // nothing else: every CSV there is one the generator makes
    for e in std::fs::read_dir(&dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            name == "README.md" || files.iter().any(|f| f.name == name),
            "{name}: not written by the generator"
        );
    }
}

/// The first `span` seconds of `f` as a command file in `dir`.
fn head(f: &CommandFile, span: f64, dir: &Path) -> PathBuf {
    let mut text = String::new();
    for (i, line) in f.csv().lines().enumerate() {
        if i > 0 && f.time[i - 1] > span {
            break;
        }
        text.push_str(line);
        text.push('\n');
    }
    let p = dir.join(&f.name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn each_runs_on_its_preset_by_the_readmes_command_line() {
    let dir = tempfile::tempdir().unwrap();
    for f in all().unwrap() {
        let cmd = head(&f, 0.3, dir.path());
        // the README's line, its files swapped for the test's
        let line = f.command_line();
        let words: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(words[..2], ["hydrocyl", "simulate"], "{line}");
        let mut args: Vec<String> = vec!["simulate".into()];
        let mut it = words[2..].iter();
        while let Some(&w) = it.next() {
            args.push(w.to_string());
            let value = match w {
                "--command" => {
                    let shipped = it.next().unwrap();
                    assert!(root().join(shipped).exists(), "{line}");
                    cmd.to_string_lossy().into_owned()
                }
                "--out" | "--ledger" => dir
                    .path()
                    .join(it.next().unwrap())
                    .to_string_lossy()
                    .into_owned(),
                // the short run has no warm-up period
                "--ledger-from" => {
                    it.next();
                    "0".into()
                }
                _ if w.starts_with("--") && w != "--quiet" => it.next().unwrap().to_string(),
                _ => continue,
            };
            args.push(value);
        }
        let st = Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
            .args(&args)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{line}: {}",
            String::from_utf8_lossy(&st.stderr)
        );
        let stem = f.name.trim_end_matches(".csv");
        let out = std::fs::read_to_string(dir.path().join(format!("{stem}.out.csv"))).unwrap();
        assert_eq!(
            out.lines().count(),
            std::fs::read_to_string(&cmd).unwrap().lines().count(),
            "{line}"
        );
        if f.ledger_from.is_some() {
            let l: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(dir.path().join(format!("{stem}.ledger.json"))).unwrap(),
            )
            .unwrap();
            let closure = l["closure_relative"].as_f64().unwrap();
            assert!(closure.abs() < 1e-6, "{line}: closure {closure}");
        }
    }
}

/// One run of `hydrocyl simulate` on a whole shipped chapter-3 file with its
/// README's `--set`s: the output's columns by name, and stderr.
fn whole_run(name: &str, dir: &Path) -> (std::collections::HashMap<String, Vec<f64>>, String) {
    let f = all().unwrap().into_iter().find(|f| f.name == name).unwrap();
    let out = dir.join(format!("{name}.out"));
    let mut args = vec![
        "simulate".to_string(),
        "--rig".into(),
        f.rig.into(),
        "--command".into(),
        folder().join(&f.name).to_string_lossy().into_owned(),
        "--out".into(),
        out.to_string_lossy().into_owned(),
    ];
    for s in &f.sets {
        args.extend(["--set".to_string(), s.clone()]);
    }
    let st = Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
        .args(&args)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&st.stderr).into_owned();
    assert!(st.status.success(), "{name}: {stderr}");
    let text = std::fs::read_to_string(&out).unwrap();
    let mut lines = text.lines();
    let names: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        .map(|h| h.split(' ').next().unwrap().to_string())
        .collect();
    let mut cols: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
    for l in lines {
        for (c, v) in cols.iter_mut().zip(l.split(',')) {
            c.push(v.parse().unwrap());
        }
    }
    (names.into_iter().zip(cols).collect(), stderr)
}

fn min_max(v: &[f64]) -> (f64, f64) {
    v.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        })
}

/// What the README says the chapter-3 files show, to its printed digits
/// (the whole 6-s runs).
#[test]
fn the_chapter3_files_show_what_the_readme_says() {
    let dir = tempfile::tempdir().unwrap();
    let near = |what: &str, got: f64, want: f64, tol: f64| {
        assert!((got - want).abs() <= tol, "{what}: {got} (README: {want})");
    };
    // the underlap sine: spool inside the underlap, velocity, swing and creep
    let (c, _) = whole_run("ch3-underlap-sine.csv", dir.path());
    let (s0, s1) = min_max(&c["spool"]);
    near("spool min [mm]", 1e3 * s0, -0.058, 5e-4);
    near("spool max [mm]", 1e3 * s1, 0.032, 5e-4);
    let (v0, v1) = min_max(&c["velocity"]);
    near("velocity min [mm/s]", 1e3 * v0, -124.5, 0.05);
    near("velocity max [mm/s]", 1e3 * v1, 127.9, 0.05);
    let t = &c["time"];
    let x = &c["position"];
    let period = |k: f64| -> Vec<f64> {
        t.iter()
            .zip(x)
            .filter(|(&tt, _)| tt >= 2.0 * k && tt < 2.0 * k + 2.0)
            .map(|(_, &p)| p)
            .collect()
    };
    for k in 0..3 {
        let p = period(k as f64);
        let (a, b) = min_max(&p);
        near("swing per period [mm]", 1e3 * (b - a), 81.2, 0.05);
    }
    let creep = (x[x.len() - 1] - x[0]) / 3.0;
    near("creep per period [mm]", 1e3 * creep, 1.67, 0.005);
    near("highest position [mm]", 1e3 * min_max(x).1, 84.5, 0.05);
    // the sawtooth: written, warned, p1 down to −14.9 bar, 3 entries
    let (c, stderr) = whole_run("ch3-sawtooth.csv", dir.path());
    near(
        "sawtooth p1 min [bar]",
        min_max(&c["p1"]).0 / 1e5,
        -14.9,
        0.05,
    );
    assert!(stderr.contains("far below absolute vacuum"), "{stderr}");
    assert!(stderr.contains("3 times"), "{stderr}");
    // the square: ±90.0 mm/s plateaus, position −0.8 .. +90.4 mm
    let (c, _) = whole_run("ch3-square.csv", dir.path());
    let plateau = |lo: f64, hi: f64| {
        let mut v: Vec<f64> = c["time"]
            .iter()
            .zip(&c["velocity"])
            .filter(|(&tt, _)| tt % 2.0 > lo && tt % 2.0 < hi)
            .map(|(_, &v)| v)
            .collect();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    near(
        "extending plateau [mm/s]",
        1e3 * plateau(0.5, 0.95),
        90.0,
        0.05,
    );
    near(
        "retracting plateau [mm/s]",
        1e3 * plateau(1.5, 1.95),
        -90.0,
        0.05,
    );
    let (p0, p1) = min_max(&c["position"]);
    near("position min [mm]", 1e3 * p0, -0.8, 0.05);
    near("position max [mm]", 1e3 * p1, 90.4, 0.05);
}
