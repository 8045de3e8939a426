//! `hydrocyl simulate` on a friction-bench rig file (a netlist whose
//! `identify.model` is `friction-bench`, run on a record's motion): the run's
//! options are checked as on any rig, `--quiet` and `--progress` are
//! honoured, the rig's `outputs` choose the columns, the output is written as
//! a netlist run's (units in the header, shortest round-trip values), and
//! what the bench cannot take is refused in one line, nothing written.

mod common;

use common::hydrocyl;
use std::path::{Path, PathBuf};
use std::process::Output;

fn bench_rig() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/measured/bench-acceleration_friction.rig.json")
}

/// A `time,velocity,p2` record of a slow sine at 5 bar (the bench's
/// chamber 2 has an area: its pressure is an input the record must carry).
fn velocity_record(dir: &Path) -> PathBuf {
    let mut s = String::from("time,velocity,p2 [bar]\n");
    for k in 0..200 {
        let t = k as f64 * 0.002;
        s.push_str(&format!("{t},{},5\n", 0.05 * (6.0 * t).sin()));
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

/// The bench rig with its `outputs` replaced by `outputs` (JSON), written
/// into `dir`.
fn rig_with_outputs(dir: &Path, outputs: serde_json::Value) -> PathBuf {
    let mut v: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(bench_rig()).unwrap()).unwrap();
    v["outputs"] = outputs;
    let p = dir.join("bench-outputs.rig.json");
    std::fs::write(&p, serde_json::to_string_pretty(&v).unwrap()).unwrap();
    p
}

/// A good run's output text.
fn ran(st: &Output, out: &Path) -> String {
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    std::fs::read_to_string(out).unwrap()
}

/// The rig's `outputs` choose the columns as on a netlist (in the run's
/// channel order, whatever the file's); a name that is none of the bench's
/// channels is refused before the run with a run's selection error, nothing
/// written.
#[test]
fn the_rigs_outputs_choose_the_columns() {
    let dir = tempfile::tempdir().unwrap();
    let vel = velocity_record(dir.path());
    let out = dir.path().join("q.csv");
    let rig = rig_with_outputs(
        dir.path(),
        serde_json::json!({ "force": "drive.force", "position": "cylinder.position" }),
    );
    let text = ran(&simulate(&rig, &vel, &out, &[]), &out);
    assert_eq!(text.lines().next(), Some("time [s],position [m],force [N]"));
    assert!(text.lines().skip(1).all(|l| l.split(',').count() == 3));
    // the file's own outputs: every channel, friction included
    let text = ran(&simulate(&bench_rig(), &vel, &out, &[]), &out);
    assert_eq!(
        text.lines().next(),
        Some("time [s],position [m],velocity [m/s],p1 [Pa],p2 [Pa],force [N],friction_force [N]")
    );
    std::fs::remove_file(&out).unwrap();
    // a probe of the rig's netlist that the bench does not write
    let rig = rig_with_outputs(
        dir.path(),
        serde_json::json!({ "force": "drive.force", "imposed": "drive.command" }),
    );
    let err = refused(&simulate(&rig, &vel, &out, &[]), &out);
    assert_eq!(
        err.trim_end(),
        "hydrocyl: error: rig `outputs`: channel `imposed`: the circuit has no such output (it has velocity, force, p1, p2, position, friction_force)"
    );
}

/// The header is the netlist path's (`name [unit]`, one formatter): the
/// columns the bench shares with the tudelft-seal-25 preset's netlist run
/// are headed alike.
#[test]
fn the_header_carries_units_as_a_netlist_run() {
    let dir = tempfile::tempdir().unwrap();
    let vel = velocity_record(dir.path());
    let out = dir.path().join("q.csv");
    let text = ran(&simulate(&bench_rig(), &vel, &out, &["--quiet"]), &out);
    let bench: Vec<String> = text
        .lines()
        .next()
        .unwrap()
        .split(',')
        .map(String::from)
        .collect();
    let cmd = dir.path().join("cmd.csv");
    std::fs::write(&cmd, "time,command\n0,0\n0.01,0.001\n").unwrap();
    let seal = dir.path().join("seal.csv");
    let text = ran(
        &simulate(Path::new("tudelft-seal-25"), &cmd, &seal, &["--quiet"]),
        &seal,
    );
    let net: Vec<&str> = text.lines().next().unwrap().split(',').collect();
    let shared: Vec<&String> = bench.iter().filter(|h| net.contains(&h.as_str())).collect();
    for h in [
        "time [s]",
        "position [m]",
        "velocity [m/s]",
        "force [N]",
        "friction_force [N]",
    ] {
        assert!(shared.iter().any(|s| *s == h), "{h}: {bench:?} vs {net:?}");
    }
    assert!(bench[1..].iter().all(|h| h.ends_with(']')), "{bench:?}");
}

/// Values are written as every `simulate` output's: each its shortest
/// round-trip text, so the text is what the CSV writer makes of the values
/// it reads back (10 significant digits in exponent form were not).
#[test]
fn values_are_shortest_round_trip_as_on_a_netlist() {
    use hydrocyl_identify::plaincsv::write_columns;
    let dir = tempfile::tempdir().unwrap();
    let vel = velocity_record(dir.path());
    let out = dir.path().join("q.csv");
    let text = ran(&simulate(&bench_rig(), &vel, &out, &["--quiet"]), &out);
    let mut lines = text.lines();
    let names: Vec<&str> = lines.next().unwrap().split(',').collect();
    let mut columns = vec![Vec::new(); names.len()];
    for l in lines {
        for (c, cell) in columns.iter_mut().zip(l.split(',')) {
            c.push(cell.parse::<f64>().unwrap());
        }
    }
    let cols: Vec<&[f64]> = columns.iter().map(Vec::as_slice).collect();
    let again = String::from_utf8(write_columns(&names, &cols)).unwrap();
    assert_eq!(again, text);
    assert!(columns[0].len() == 200 && columns.iter().flatten().any(|v| *v != 0.0));
}

/// `--progress` shows the bench's stages as plain lines where stderr is not
/// a terminal (as a netlist run shows its rows); without it, or with
/// `--quiet`, none.
#[test]
fn progress_shows_the_stages_of_a_bench_run() {
    let dir = tempfile::tempdir().unwrap();
    let vel = velocity_record(dir.path());
    let out = dir.path().join("q.csv");
    let run = |extra: &[&str]| {
        let st = hydrocyl()
            .env("HYDROCYL_PROGRESS_SECONDS", "0")
            .args(["simulate", "--rig"])
            .arg(bench_rig())
            .arg("--command")
            .arg(&vel)
            .arg("--out")
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{}",
            String::from_utf8_lossy(&st.stderr)
        );
        String::from_utf8_lossy(&st.stderr).into_owned()
    };
    let err = run(&["--progress"]);
    for stage in [
        "hydrocyl: simulate: reading the record 0/4",
        "hydrocyl: simulate: smoothing the motion 1/4",
        "hydrocyl: simulate: simulating 2/4",
        "hydrocyl: simulate: writing 3/4",
    ] {
        assert!(err.contains(stage), "{stage}: {err}");
    }
    assert!(!run(&[]).contains("hydrocyl: simulate:"));
    assert!(run(&["--progress", "--quiet"]).is_empty());
}
