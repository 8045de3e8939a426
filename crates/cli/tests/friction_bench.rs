//! `hydrocyl simulate` on a friction-bench rig file (a netlist whose
//! `identify.model` is `friction-bench`, run on a record's motion): the run's
//! options are checked as on any rig, `--quiet` is honoured, and what the
//! bench cannot take is refused in one line, nothing written.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn hydrocyl() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
}

fn bench_rig() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/measured/bench-acceleration_friction.rig.json")
}

/// A `time,velocity` record of a slow sine.
fn velocity_record(dir: &Path) -> PathBuf {
    let mut s = String::from("time,velocity\n");
    for k in 0..200 {
        let t = k as f64 * 0.002;
        s.push_str(&format!("{t},{}\n", 0.05 * (6.0 * t).sin()));
    }
    let p = dir.join("velv.csv");
    std::fs::write(&p, s).unwrap();
    p
}

/// `hydrocyl simulate --rig <rig> --command <cmd> --out <out> <extra>`.
fn simulate(rig: &Path, cmd: &Path, out: &Path, extra: &[&str]) -> Output {
    hydrocyl()
        .args(["simulate", "--rig"])
        .arg(rig)
        .arg("--command")
        .arg(cmd)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap()
}

/// Exit 2, one line on stderr, no output: the line.
fn refused(st: &Output, out: &Path) -> String {
    let err = String::from_utf8_lossy(&st.stderr).into_owned();
    assert_eq!(st.status.code(), Some(2), "{err}");
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(!out.exists(), "{err}");
    err
}

/// A bad `--solver`, `--rtol` or `--rk4-step` is refused with the netlist
/// path's message (here the leaney-moog preset's), nothing written.
#[test]
fn bad_run_settings_are_refused_as_on_a_netlist() {
    let dir = tempfile::tempdir().unwrap();
    let vel = velocity_record(dir.path());
    let cmd = dir.path().join("cmd.csv");
    std::fs::write(&cmd, "time,command\n0,0\n0.1,0.1\n").unwrap();
    let out = dir.path().join("q.csv");
    for bad in [
        ["--solver", "nonsense"],
        ["--rtol", "0"],
        ["--rtol", "nan"],
        ["--rk4-step", "-1"],
    ] {
        let bench = refused(&simulate(&bench_rig(), &vel, &out, &bad), &out);
        let net = simulate(Path::new("leaney-moog"), &cmd, &out, &bad);
        let net = refused(&net, &out);
        assert_eq!(bench, net, "{bad:?}");
    }
}

/// A valid but non-default `--solver`, `--rtol` or `--rk4-step` is refused:
/// the bench fixes its own integration; the line names the netlist route.
#[test]
fn the_bench_refuses_solver_options_it_cannot_take() {
    let dir = tempfile::tempdir().unwrap();
    let vel = velocity_record(dir.path());
    let out = dir.path().join("q.csv");
    for extra in [
        &["--solver", "rk4"][..],
        &["--rtol", "1e-8"],
        &["--rk4-step", "1e-4"],
    ] {
        let err = refused(&simulate(&bench_rig(), &vel, &out, extra), &out);
        assert!(
            err.contains("fixes its own integration") && err.contains("tudelft-seal-25"),
            "{extra:?}: {err}"
        );
    }
    // the defaults spelled out are the defaults
    let st = simulate(
        &bench_rig(),
        &vel,
        &out,
        &["--solver", "auto", "--rtol", "1e-6", "--rk4-step", "2e-5"],
    );
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    assert!(out.exists());
}

/// `--quiet` prints nothing on a good run; without it the one note.
#[test]
fn quiet_is_quiet_on_a_bench() {
    let dir = tempfile::tempdir().unwrap();
    let vel = velocity_record(dir.path());
    let out = dir.path().join("q.csv");
    let st = simulate(&bench_rig(), &vel, &out, &["--quiet"]);
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    assert!(
        st.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    assert!(out.exists());
    let st = simulate(&bench_rig(), &vel, &out, &[]);
    assert!(st.status.success());
    assert!(String::from_utf8_lossy(&st.stderr).contains("simulated the friction bench"));
}

/// A `--set` value out of range is blamed on the `--set`, as on any rig
/// file, not on the file.
#[test]
fn a_bad_set_value_is_blamed_on_the_set() {
    let dir = tempfile::tempdir().unwrap();
    let vel = velocity_record(dir.path());
    let out = dir.path().join("q.csv");
    let rig = bench_rig();
    let st = simulate(&rig, &vel, &out, &["--set", "friction.coulomb=-5"]);
    let err = refused(&st, &out);
    assert_eq!(
        err.trim_end(),
        format!(
            "hydrocyl: error: rig `components.friction.coulomb`: -5 [N] is out of range: must be ≥ 0 (set by --set friction.coulomb=-5 on {})",
            rig.display()
        )
    );
}

/// A parameter of an effect that is off (the Stribeck shape without
/// `stiction`, σ1 with σ0 = 0) is refused with the condition that turns it
/// on; with that condition set, the same `--set` runs.
#[test]
fn a_parameter_of_an_effect_that_is_off_names_what_turns_it_on() {
    let dir = tempfile::tempdir().unwrap();
    let vel = velocity_record(dir.path());
    let out = dir.path().join("q.csv");
    let rig = bench_rig();
    let st = simulate(
        &rig,
        &vel,
        &out,
        &["--set", "friction.stribeck_velocity=0.02"],
    );
    let err = refused(&st, &out);
    assert!(
        err.contains("only where `friction.stiction` is set")
            && err.contains("--set friction.stiction=")
            && !err.contains("does not use this parameter"),
        "{err}"
    );
    let st = simulate(&rig, &vel, &out, &["--set", "friction.sigma1=100"]);
    let err = refused(&st, &out);
    assert!(
        err.contains("only where `friction.sigma0` is set off its default 0"),
        "{err}"
    );
    let st = simulate(
        &rig,
        &vel,
        &out,
        &[
            "--set",
            "friction.stiction=30",
            "--set",
            "friction.stribeck_velocity=0.02",
        ],
    );
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
}
