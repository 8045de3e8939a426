//! What the README and `--help` promise about the command line itself:
//! progress where stderr is not a terminal, remedies, one-line argument
//! errors, `--set`'s blame, the benches' columns, help text and
//! `--print-rig`'s combinations.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn hydrocyl() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
}

/// A fresh scratch folder for one test.
fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hydrocyl-usability-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A command file of `n` samples `dt` apart (a gentle square wave).
fn command_file(dir: &Path, n: usize, dt: f64) -> PathBuf {
    let mut s = String::from("time,command\n");
    for k in 0..n {
        let t = k as f64 * dt;
        let u = if (t % 1.0) < 0.5 { 0.1 } else { -0.1 };
        s.push_str(&format!("{t},{u}\n"));
    }
    let p = dir.join("cmd.csv");
    std::fs::write(&p, s).unwrap();
    p
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn progress_shows_as_plain_lines_when_stderr_is_not_a_terminal() {
    let d = scratch("progress");
    let cmd = command_file(&d, 2001, 1e-3);
    let out = d.join("o.csv");
    let run = |progress: bool| {
        let mut c = hydrocyl();
        c.args(["simulate", "--rig", "leaney-moog", "--command"])
            .arg(&cmd)
            .arg("--out")
            .arg(&out)
            .env("HYDROCYL_PROGRESS_SECONDS", "0");
        if progress {
            c.arg("--progress");
        }
        let o = c.output().unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        stderr(&o)
    };
    let with = run(true);
    let lines: Vec<&str> = with
        .lines()
        .filter(|l| l.starts_with("hydrocyl: simulate: rows "))
        .collect();
    assert!(!lines.is_empty(), "no progress line in {with:?}");
    assert!(lines.iter().any(|l| l.contains("/2001")), "{with:?}");
    assert!(!with.contains('\r'), "a redrawn bar in a log: {with:?}");
    // without --progress a log gets only the summary
    let without = run(false);
    assert!(
        !without.contains("hydrocyl: simulate: rows "),
        "{without:?}"
    );
}
