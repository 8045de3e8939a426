//! Every bad input a tester tried (issue 18), as data: `bad_inputs.json`
//! lists per case the files (made in a temporary folder), the command line,
//! the exit code, the words stderr/stdout must (not) contain, and the files
//! that must be absent, present or unchanged afterwards. One test runs the
//! `hydrocyl` binary over every row; a failure names the case.

use serde_json::Value;
use std::path::Path;
use std::process::Command;

/// The workspace root (for `from` fixtures).
fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
}

/// Expands `@N template` lines: N rows, `{t}` = 0.01 k, `{k}` = k, `{sq}` a
/// square wave of ±0.1 with period 1 s.
fn lines(spec: &[Value]) -> String {
    let mut s = String::new();
    for l in spec {
        let l = l.as_str().expect("file lines are strings");
        if let Some(rest) = l.strip_prefix('@') {
            let (n, tpl) = rest.split_once(' ').expect("@N template");
            let n: usize = n.parse().expect("@N");
            for k in 0..n {
                let t = k as f64 * 0.01;
                let sq = if (t % 1.0) < 0.5 { "0.1" } else { "-0.1" };
                s.push_str(
                    &tpl.replace("{t}", &format!("{t}"))
                        .replace("{k}", &k.to_string())
                        .replace("{sq}", sq),
                );
                s.push('\n');
            }
        } else {
            s.push_str(l);
            s.push('\n');
        }
    }
    s
}

fn make_file(dir: &Path, name: &str, spec: &Value) {
    let text = match spec {
        Value::Array(a) => lines(a),
        Value::Object(o) => {
            let from = o["from"].as_str().expect("from");
            let mut t = std::fs::read_to_string(root().join(from)).expect("fixture");
            for r in o["replace"].as_array().expect("replace") {
                let (a, b) = (r[0].as_str().unwrap(), r[1].as_str().unwrap());
                assert!(t.contains(a), "{from} has no `{a}`");
                t = t.replacen(a, b, 1);
            }
            t
        }
        _ => panic!("file {name}: lines or {{from, replace}}"),
    };
    let p = dir.join(name);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(p, text).unwrap();
}

fn strs(row: &Value, key: &str) -> Vec<String> {
    row.get(key)
        .and_then(Value::as_array)
        .map(|a| a.iter().map(|v| v.as_str().unwrap().to_string()).collect())
        .unwrap_or_default()
}

fn hydrocyl(dir: &Path, args: &[String]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
        .current_dir(dir)
        .args(args)
        .env("NO_COLOR", "1")
        .output()
        .unwrap()
}

/// Runs one row; `Err` says what failed.
fn check(row: &Value) -> Result<(), String> {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    if let Some(files) = row["files"].as_object() {
        for (name, spec) in files {
            make_file(d, name, spec);
        }
    }
    for before in row
        .get("before")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        let args: Vec<String> = before
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_str().unwrap().to_string())
            .collect();
        let o = hydrocyl(d, &args);
        if !o.status.success() {
            return Err(format!(
                "setup {args:?} failed: {}",
                String::from_utf8_lossy(&o.stderr)
            ));
        }
    }
    let snapshot: Vec<(String, Vec<u8>)> = strs(row, "unchanged")
        .into_iter()
        .map(|f| {
            let b = std::fs::read(d.join(&f)).unwrap();
            (f, b)
        })
        .collect();
    let args = strs(row, "args");
    let o = hydrocyl(d, &args);
    let (out, err) = (
        String::from_utf8_lossy(&o.stdout).to_string(),
        String::from_utf8_lossy(&o.stderr).to_string(),
    );
    let code = row["code"].as_i64().unwrap() as i32;
    let ctx = || {
        format!(
            "\n  stderr: {err}\n  stdout: {}",
            out.chars().take(400).collect::<String>()
        )
    };
    if o.status.code() != Some(code) {
        return Err(format!(
            "exit {:?}, expected {code}{}",
            o.status.code(),
            ctx()
        ));
    }
    if code == 2 && err.trim().lines().count() != 1 {
        return Err(format!("the error is not one line{}", ctx()));
    }
    for (key, text, present) in [
        ("stderr", &err, true),
        ("stderr_not", &err, false),
        ("stdout", &out, true),
        ("stdout_not", &out, false),
    ] {
        for w in strs(row, key) {
            if text.contains(&w) != present {
                let has = if present { "lacks" } else { "has" };
                return Err(format!("{} {has} `{w}`{}", &key[..6], ctx()));
            }
        }
    }
    for f in strs(row, "absent") {
        if d.join(&f).exists() {
            return Err(format!("{f} exists afterwards{}", ctx()));
        }
    }
    for f in strs(row, "present") {
        if !d.join(&f).exists() {
            return Err(format!("{f} was not written{}", ctx()));
        }
    }
    for (f, before) in snapshot {
        if std::fs::read(d.join(&f)).ok().as_ref() != Some(&before) {
            return Err(format!("{f} changed{}", ctx()));
        }
    }
    if let Some(pairs) = row.get("same_files").and_then(Value::as_array) {
        for p in pairs {
            let (a, b) = (p[0].as_str().unwrap(), p[1].as_str().unwrap());
            if std::fs::read(d.join(a)).ok() != std::fs::read(d.join(b)).ok() {
                return Err(format!("{a} and {b} differ{}", ctx()));
            }
        }
    }
    let header = strs(row, "header");
    if !header.is_empty() {
        let text = std::fs::read_to_string(d.join("out.csv")).unwrap_or_default();
        let first = text.lines().next().unwrap_or("");
        let cols: Vec<&str> = first.split(',').collect();
        if cols.len() < header.len() || cols[..header.len()] != header[..] {
            return Err(format!(
                "out.csv header `{first}`, expected to start {header:?}"
            ));
        }
    }
    // no temporary file left anywhere in the folder
    let mut stack = vec![d.to_path_buf()];
    while let Some(p) = stack.pop() {
        for e in std::fs::read_dir(&p).unwrap() {
            let e = e.unwrap();
            if e.path().is_dir() {
                stack.push(e.path());
            } else if e.file_name().to_string_lossy().contains(".tmp") {
                return Err(format!("temporary file {} left", e.path().display()));
            }
        }
    }
    Ok(())
}

#[test]
fn every_bad_input_of_the_table() {
    let text = include_str!("bad_inputs.json");
    let rows: Vec<Value> = serde_json::from_str(text).unwrap();
    assert!(rows.len() >= 25, "the table lost rows");
    let failures: Vec<String> = rows
        .iter()
        .filter_map(|r| {
            check(r)
                .err()
                .map(|e| format!("- {}: {e}", r["case"].as_str().unwrap_or("?")))
        })
        .collect();
    assert!(
        failures.is_empty(),
        "{} of {} cases fail:\n{}",
        failures.len(),
        rows.len(),
        failures.join("\n")
    );
}

/// SIGTERM and SIGINT during a run: the temporary output is removed, no
/// output appears, exit code 130.
#[test]
fn a_signal_during_the_run_leaves_no_file() {
    for sig in ["-TERM", "-INT"] {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        // 2 s at an rk4 step of 1 µs: seconds of work, caught running
        let rows: String = (0..20_000)
            .map(|k| {
                format!(
                    "{},{}\n",
                    k as f64 * 1e-4,
                    if k % 10_000 < 5_000 { 0.1 } else { -0.1 }
                )
            })
            .collect();
        std::fs::write(d.join("cmd.csv"), format!("time,command\n{rows}")).unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
            .current_dir(d)
            .args([
                "simulate",
                "--rig",
                "leaney-moog",
                "--command",
                "cmd.csv",
                "--out",
                "out.csv",
            ])
            .args(["--solver", "rk4", "--rk4-step", "1e-6"])
            .stderr(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        // wait for the temporary file: the run has started
        let start = std::time::Instant::now();
        let tmp_exists = || {
            std::fs::read_dir(d)
                .unwrap()
                .any(|e| e.unwrap().file_name().to_string_lossy().contains(".tmp"))
        };
        while !tmp_exists() && start.elapsed().as_secs() < 30 {
            std::thread::sleep(std::time::Duration::from_millis(5));
        }
        assert!(tmp_exists(), "no temporary file appeared");
        Command::new("kill")
            .args([sig, &child.id().to_string()])
            .status()
            .unwrap();
        let st = child.wait().unwrap();
        assert_eq!(st.code(), Some(130), "{sig}: {st:?}");
        let left: Vec<_> = std::fs::read_dir(d)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
            .collect();
        assert_eq!(left, vec!["cmd.csv".to_string()], "{sig}");
    }
}

/// A CSV saved as UTF-16 (a spreadsheet's "Unicode text"; with a
/// byte-order mark or without) or UTF-32 is named so by both readers, row
/// 1, exit code 2, nothing written: read as UTF-8 its header had no
/// `time` ("missing column 'time'", though the column is there).
#[test]
fn a_utf16_file_is_named_so_by_both_readers() {
    let dir = std::env::temp_dir().join(format!("hydrocyl-utf16-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut cmd = String::from("time,command,position\n");
    for k in 0..50 {
        cmd.push_str(&format!(
            "{},{},0\n",
            k as f64 * 0.01,
            if k < 25 { 0.1 } else { -0.1 }
        ));
    }
    let le: Vec<u8> = cmd.encode_utf16().flat_map(u16::to_le_bytes).collect();
    let be: Vec<u8> = cmd.encode_utf16().flat_map(u16::to_be_bytes).collect();
    for (bytes, words) in [
        (
            [&[0xFF, 0xFE][..], &le].concat(),
            "the file is UTF-16 text (byte-order mark FF FE)",
        ),
        (
            [&[0xFE, 0xFF][..], &be].concat(),
            "the file is UTF-16 text (byte-order mark FE FF)",
        ),
        (le.clone(), "the file is UTF-16 text (no byte-order mark"),
    ] {
        let csv = dir.join("rec.csv");
        std::fs::write(&csv, &bytes).unwrap();
        for args in [
            &[
                "simulate",
                "--rig",
                "leaney-moog",
                "--command",
                "rec.csv",
                "--out",
                "out.csv",
            ][..],
            &[
                "diagnose",
                "--rig",
                "leaney-moog",
                "--data",
                "rec.csv",
                "--report",
                "out.csv",
            ][..],
        ] {
            let o = Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
                .args(args)
                .current_dir(&dir)
                .output()
                .unwrap();
            let err = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
            assert_eq!(err.lines().count(), 1, "{args:?}: {err}");
            assert!(
                err.starts_with(&format!("hydrocyl: error: rec.csv: row 1: {words}"))
                    && err.contains("save it as UTF-8 CSV"),
                "{args:?}: {err}"
            );
            assert!(!dir.join("out.csv").exists(), "{args:?}");
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
