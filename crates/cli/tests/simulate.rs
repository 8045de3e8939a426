//! `hydrocyl simulate` end to end: output format, sampling, overrides,
//! solvers, and one-line errors with no output file.

mod common;

use common::{hydrocyl, simulate_ok};
use std::path::{Path, PathBuf};

fn write_command(dir: &Path, name: &str, rows: &[(f64, f64)]) -> PathBuf {
    let mut s = String::from("time,command,comment\n");
    for (t, u) in rows {
        s.push_str(&format!("{t},{u},x\n"));
    }
    let p = dir.join(name);
    std::fs::write(&p, s).unwrap();
    p
}

/// `hydrocyl simulate --rig leaney-moog` on `cmd` into `out`, which must
/// succeed.
fn simulate_leaney_moog(cmd: &Path, out: &Path) -> std::process::Output {
    simulate_ok("leaney-moog", cmd, out, &[])
}

fn square(n: usize, dt: f64) -> Vec<(f64, f64)> {
    (0..n)
        .map(|k| {
            let t = k as f64 * dt;
            (t, if (t % 1.0) < 0.5 { 0.15 } else { -0.2 })
        })
        .collect()
}

fn read_csv(p: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines();
    let header: Vec<String> = lines
        .next()
        .unwrap()
        .split(',')
        // the header carries units (`position [m]`): compare by name
        .map(|h| h.split(" [").next().unwrap_or(h).to_string())
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|c| c.parse::<f64>().unwrap()).collect())
        .collect();
    (header, rows)
}

#[test]
fn writes_the_measured_data_format_at_the_command_times() {
    let dir = tempfile::tempdir().unwrap();
    // uneven sampling: the output must follow it
    let mut rows = square(400, 0.005);
    rows.push((2.0013, 0.1));
    let cmd = write_command(dir.path(), "cmd.csv", &rows);
    let out = dir.path().join("out.csv");
    let st = simulate_leaney_moog(&cmd, &out);
    let header = std::fs::read_to_string(&out).unwrap();
    assert!(
        header.starts_with("time [s],command [-],position [m],velocity [m/s],p1 [Pa],p2 [Pa],"),
        "{}",
        header.lines().next().unwrap_or("")
    );
    let (h, data) = read_csv(&out);
    assert_eq!(
        &h[..6],
        ["time", "command", "position", "velocity", "p1", "p2"]
    );
    assert!(h.contains(&"spool".to_string()) && h.contains(&"ps".to_string()));
    assert_eq!(data.len(), rows.len());
    for (r, (t, u)) in data.iter().zip(&rows) {
        assert_eq!(r[0], *t);
        assert_eq!(r[1], *u);
        // an abrupt reversal may push a chamber briefly above Ps (the load's
        // momentum compresses it); it may not go below tank without a report
        assert!(r[4].is_finite() && r[5].is_finite() && r[4] <= 1.5e7 && r[5] <= 1.5e7);
        assert!(r[2].abs() <= 0.26);
    }
    // the piston moves out in the first half second
    assert!(data[99][3] > 0.05, "velocity {}", data[99][3]);
    let min_p = data
        .iter()
        .map(|r| r[4].min(r[5]))
        .fold(f64::INFINITY, f64::min);
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(min_p >= 0.0 || err.contains("CAVITATION"), "{min_p}: {err}");
}

#[test]
fn overrides_and_solvers_change_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = write_command(dir.path(), "cmd.csv", &square(200, 0.005));
    let run_on = |rig: &str, extra: &[&str], name: &str| {
        let out = dir.path().join(name);
        simulate_ok(rig, &cmd, &out, extra);
        read_csv(&out).1
    };
    let run = |extra: &[&str], name: &str| run_on("leaney-moog", extra, name);
    let base = run(&[], "a.csv");
    let start = run(
        &[
            "--set",
            "cylinder.initial.position=0.1",
            "--set",
            "cylinder.initial.p1=2e6",
            "--set",
            "cylinder.initial.p2=4e6",
        ],
        "b.csv",
    );
    assert_eq!(start[0][2], 0.1);
    assert_eq!((start[0][4], start[0][5]), (2e6, 4e6));
    let heavy = run(&["--set", "load.mass=1000"], "c.csv");
    assert!((heavy[20][3] - base[20][3]).abs() > 1e-3);
    for solver in ["rosenbrock", "rk4"] {
        let other = run(&["--solver", solver], &format!("{solver}.csv"));
        let k = other.len() - 1;
        assert!((other[k][3] - base[k][3]).abs() < 1e-4, "{solver}");
    }
    let gen = run_on("leaney-moog-generalised", &[], "g.csv");
    assert!((gen[90][3] - base[90][3]).abs() < 5e-3);
}

#[test]
fn errors_are_one_line_with_exit_code_2_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let good = write_command(dir.path(), "cmd.csv", &square(50, 0.01));
    let bad_time = write_command(dir.path(), "bad.csv", &[(0.0, 0.0), (0.1, 0.1), (0.1, 0.2)]);
    let text = dir.path().join("text.csv");
    std::fs::write(&text, "time,command\n0,0\n0.1,abc\n").unwrap();
    let nocol = dir.path().join("nocol.csv");
    std::fs::write(&nocol, "time,u\n0,0\n0.1,1\n").unwrap();
    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["--set".into(), "cylinder.area_1=-1".into()],
            "cylinder.area_1",
        ),
        (
            vec!["--set".into(), "cylinder.colour=red".into()],
            "cylinder.colour",
        ),
        (
            vec!["--set".into(), "cylinder.initial.position=1".into()],
            "initial position 1 m is outside the end stops",
        ),
        (vec!["--solver".into(), "euler".into()], "euler"),
        (vec!["--rig".into(), "no-such-rig".into()], "no-such-rig"),
    ];
    let out = dir.path().join("out.csv");
    for (extra, needle) in cases {
        let mut c = hydrocyl();
        c.args(["simulate", "--command"])
            .arg(&good)
            .arg("--out")
            .arg(&out);
        if !extra.contains(&"--rig".to_string()) {
            c.args(["--rig", "leaney-moog"]);
        }
        let st = c.args(&extra).output().unwrap();
        let err = String::from_utf8_lossy(&st.stderr);
        assert_eq!(st.status.code(), Some(2), "{extra:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains(needle), "{needle}: {err}");
        assert!(!out.exists(), "{extra:?} left an output file");
    }
    for (file, needle) in [(&bad_time, "row 4"), (&text, "row 3"), (&nocol, "command")] {
        let st = hydrocyl()
            .args(["simulate", "--rig", "leaney-moog", "--command"])
            .arg(file)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&st.stderr);
        assert_eq!(st.status.code(), Some(2), "{err}");
        assert!(err.contains(needle), "{needle}: {err}");
        assert!(!out.exists());
    }
    // an unwritable output: error, no stray temporary file
    let st = hydrocyl()
        .args(["simulate", "--rig", "leaney-moog", "--command"])
        .arg(&good)
        .arg("--out")
        .arg(dir.path().join("missing-dir").join("out.csv"))
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(2));
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert!(
        left.iter().all(|n| !n.to_string_lossy().contains(".tmp")),
        "{left:?}"
    );
}

#[test]
fn rig_files_and_print_rig_round_trip() {
    let dir = tempfile::tempdir().unwrap();
    let st = hydrocyl()
        .args([
            "simulate",
            "--rig",
            "leaney-moog",
            "--print-rig",
            "--set",
            "load.mass=42",
        ])
        .output()
        .unwrap();
    assert!(st.status.success());
    let rig = dir.path().join("rig.json");
    std::fs::write(&rig, &st.stdout).unwrap();
    let v: serde_json::Value = serde_json::from_slice(&st.stdout).unwrap();
    assert_eq!(v["components"]["load"]["mass"], 42.0);
    // every parameter is written out, defaults included
    assert_eq!(v["components"]["valve"]["null_bias"], 0.0);
    let cmd = write_command(dir.path(), "cmd.csv", &square(20, 0.01));
    let out = dir.path().join("out.csv");
    let st = hydrocyl()
        .args(["simulate", "--rig"])
        .arg(&rig)
        .arg("--command")
        .arg(&cmd)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    // the fixture file itself is a valid rig
    let fixture =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/rigs/leaney-moog.json");
    let st = hydrocyl()
        .args(["simulate", "--print-rig", "--rig"])
        .arg(&fixture)
        .output()
        .unwrap();
    assert!(st.status.success());
}

/// A rig file of an older kind (`valve-cylinder`, closed loop) is read as
/// its netlist: `--print-rig` shows the netlist under the
/// `<component>.<parameter>` scheme, `--set cylinder.initial.position=...`
/// reaches it, and it runs on a `reference` column (its controller's input).
#[test]
fn an_older_rig_kind_runs_and_prints_as_its_netlist() {
    let dir = tempfile::tempdir().unwrap();
    let old = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/legacy/festo-hanging-load.rig.json");
    let st = hydrocyl()
        .args([
            "simulate",
            "--print-rig",
            "--set",
            "cylinder.initial.position=-0.05",
            "--rig",
        ])
        .arg(&old)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&st.stdout).unwrap();
    assert_eq!(v["kind"], "netlist");
    assert_eq!(v["components"]["cylinder"]["initial"]["position"], -0.05);
    assert_eq!(v["components"]["controller"]["type"], "position_controller");
    // the old paths are gone, and the error lists the components
    let st = hydrocyl()
        .args([
            "simulate",
            "--print-rig",
            "--set",
            "initial.position=0",
            "--rig",
        ])
        .arg(&old)
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&st.stderr).contains("cylinder"));
    let reference: Vec<(f64, f64)> = (0..=200).map(|k| (k as f64 * 1e-3, -0.05)).collect();
    let cmd = dir.path().join("ref.csv");
    let mut text = String::from("time,reference\n");
    for (t, r) in &reference {
        text.push_str(&format!("{t},{r}\n"));
    }
    std::fs::write(&cmd, text).unwrap();
    let out = dir.path().join("out.csv");
    let st = hydrocyl()
        .args(["simulate", "--rig"])
        .arg(&old)
        .arg("--command")
        .arg(&cmd)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let (h, rows) = read_csv(&out);
    let pos = h.iter().position(|c| c == "position").unwrap();
    // the controller pulls the rod from -0.09 m towards the set-point
    assert!(
        rows[200][pos] > rows[0][pos] + 1e-3,
        "{} -> {}",
        rows[0][pos],
        rows[200][pos]
    );
}

/// A friction bench is driven by its motion: simulated on the generated
/// record whose truth is its declared model, the predicted load-cell force
/// matches the measured one to the record's sensor noise (σ = 0.5 N on the
/// force, plus what the pressure noise carries through the piston area);
/// the same record under a rig that lacks a planted effect does not.
#[test]
fn friction_bench_is_simulated_from_its_motion() {
    let dir = tempfile::tempdir().unwrap();
    let fx = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/measured");
    let rms = |rig: &str, rec: &str| {
        let out = dir.path().join(format!("{rec}.out.csv"));
        let st = hydrocyl()
            .args(["simulate", "--rig"])
            .arg(fx.join(rig))
            .arg("--command")
            .arg(fx.join(rec))
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{}",
            String::from_utf8_lossy(&st.stderr)
        );
        let (h, sim) = read_csv(&out);
        assert_eq!(
            h,
            [
                "time",
                "position",
                "velocity",
                "p1",
                "p2",
                "force",
                "friction_force"
            ]
        );
        let text = std::fs::read_to_string(fx.join(rec)).unwrap();
        let col = text
            .lines()
            .next()
            .unwrap()
            .split(',')
            .position(|c| c.starts_with("force"))
            .unwrap();
        let measured: Vec<f64> = text
            .lines()
            .skip(1)
            .map(|l| l.split(',').nth(col).unwrap().parse().unwrap())
            .collect();
        assert_eq!(measured.len(), sim.len());
        let ss: f64 = measured
            .iter()
            .zip(&sim)
            .map(|(m, r)| (m - r[5]).powi(2))
            .sum();
        (ss / sim.len() as f64).sqrt()
    };
    // the prediction uses the measured (noisy) pressure, so its error floor is
    // √(σ_F² + (σ_p A2)²) with the noise of fixtures/measured/README.md
    let rig: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fx.join("bench-none.rig.json")).unwrap())
            .unwrap();
    let area = rig["components"]["cylinder"]["area_2"].as_f64().unwrap();
    let floor = (0.5f64.powi(2) + (2e3 * area).powi(2)).sqrt();
    let truth = rms("bench-none.rig.json", "bench-none.csv");
    assert!(
        truth > 0.8 * floor && truth < 1.2 * floor,
        "declared = truth: rms {truth} N, noise floor {floor} N"
    );
    let lacking = rms("bench-viscous.rig.json", "bench-viscous.csv");
    assert!(lacking > 4.0 * floor, "viscous missing: rms {lacking} N");
}

#[test]
fn friction_bench_needs_motion_and_writes_nothing_without_it() {
    let dir = tempfile::tempdir().unwrap();
    let fx = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/measured");
    let input = dir.path().join("p.csv");
    let mut s = String::from("time,p2\n");
    for k in 0..20 {
        s.push_str(&format!("{},{}\n", k as f64 * 0.01, 3e5));
    }
    std::fs::write(&input, s).unwrap();
    let out = dir.path().join("o.csv");
    let st = hydrocyl()
        .args(["simulate", "--rig"])
        .arg(fx.join("bench-none.rig.json"))
        .arg("--command")
        .arg(&input)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(2));
    let err = String::from_utf8_lossy(&st.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("position") && err.contains("p.csv"), "{err}");
    assert!(!out.exists());
}

/// The chapter-9 rig files (netlists) simulate through `hydrocyl simulate`:
/// the needle file at the base opening is the base rig to the digit, the
/// solenoid four-way valve removes the relief valves' cracking drop between
/// pump line and chamber, the servo needle and the closed loop run; a
/// retired `hybrid-variant` file is refused in one line naming its
/// replacement, nothing written.
#[test]
fn chapter9_rig_files_simulate() {
    let dir = tempfile::tempdir().unwrap();
    let rigs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/rigs");
    let rows: Vec<(f64, f64)> = (0..=300)
        .map(|k| {
            let t = k as f64 * 0.005;
            (t, if t > 0.2 { 2.0 } else { 0.0 })
        })
        .collect();
    let cmd = write_command(dir.path(), "cmd.csv", &rows);
    let sim_with = |rig: &Path, cmd: &Path, sets: &[&str], name: &str| {
        let out = dir.path().join(name);
        let mut c = hydrocyl();
        c.args(["simulate", "--solver", "rosenbrock", "--rig"])
            .arg(rig)
            .arg("--command")
            .arg(cmd)
            .arg("--out")
            .arg(&out);
        for s in sets {
            c.args(["--set", s]);
        }
        let st = c.output().unwrap();
        assert!(
            st.status.success(),
            "{}",
            String::from_utf8_lossy(&st.stderr)
        );
        read_csv(&out)
    };
    let sim = |rig: &Path, sets: &[&str], name: &str| sim_with(rig, &cmd, sets, name);
    let (h, base) = sim(&rigs.join("wang-hybrid.json"), &[], "base.csv");
    let (h2, same) = sim(
        &rigs.join("wang-hybrid-needle.json"),
        &["needle_valve.area=4.0e-6"],
        "needle.csv",
    );
    assert_eq!(h, h2);
    assert_eq!(
        base, same,
        "the needle file at the base opening is the base rig"
    );
    let (h3, sol) = sim(&rigs.join("wang-hybrid-solenoid.json"), &[], "sol.csv");
    // the relief valves' flow channels are gone with the relief valves
    assert!(h3.contains(&"pp1".to_string()) && !h3.contains(&"relief_1_flow".to_string()));
    let col = |h: &[String], n: &str| h.iter().position(|c| c == n).unwrap();
    // one second into the extending command
    let k = rows.iter().position(|r| r.0 >= 1.2).unwrap();
    let drop = |h: &[String], d: &[Vec<f64>]| d[k][col(h, "pp1")] - d[k][col(h, "p1")];
    assert!(
        drop(&h, &base) > 10.34e5,
        "relief 1 cracking: {}",
        drop(&h, &base)
    );
    assert!(
        drop(&h3, &sol) < 1e5,
        "solenoid valve open: {}",
        drop(&h3, &sol)
    );
    let (h4, imp) = sim(&rigs.join("wang-hybrid-improved.json"), &[], "imp.csv");
    assert!(imp[k][col(&h4, "velocity")] > 0.02, "improved extends");
    let (h5, servo) = sim(
        &rigs.join("wang-hybrid-servo-needle.json"),
        &[],
        "servo.csv",
    );
    // the opening follows the 2 V command: A_0 + g+ 2 V
    let rig: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string(rigs.join("wang-hybrid-servo-needle.json")).unwrap(),
    )
    .unwrap();
    let n = &rig["components"]["needle_valve"];
    let want = n["area_min"].as_f64().unwrap() + 2.0 * n["gain_positive"].as_f64().unwrap();
    let got = servo[k][col(&h5, "needle_opening")];
    assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    // the closed loop follows a position step of 10 mm from -60 mm
    let refs: Vec<(f64, f64)> = rows
        .iter()
        .map(|r| (r.0, if r.0 > 0.2 { -0.05 } else { -0.06 }))
        .collect();
    let refs_file = dir.path().join("ref.csv");
    let mut text = String::from("time,reference\n");
    for (t, r) in &refs {
        text.push_str(&format!("{t},{r}\n"));
    }
    std::fs::write(&refs_file, text).unwrap();
    let (h6, cl) = sim_with(
        &rigs.join("wang-hybrid-closed-loop.json"),
        &refs_file,
        &["cylinder.initial.position=-0.06"],
        "cl.csv",
    );
    let x_end = cl.last().unwrap()[col(&h6, "position")];
    assert!((x_end + 0.05).abs() < 1e-3, "closed loop ends at {x_end} m");
    // a retired variant file: one line, exit 2, nothing written
    let old = dir.path().join("old.json");
    std::fs::write(
        &old,
        r#"{"kind": "hybrid-variant", "name": "x", "description": "", "base": "wang-hybrid"}"#,
    )
    .unwrap();
    let out = dir.path().join("old.csv");
    let st = hydrocyl()
        .args(["simulate", "--rig"])
        .arg(&old)
        .arg("--command")
        .arg(&cmd)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(2));
    let err = String::from_utf8_lossy(&st.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("retired") && err.contains("needle_valve.area"),
        "{err}"
    );
    assert!(!out.exists());
}

/// A netlist error names the JSON path and its line in the file; nothing
/// is written.
#[test]
fn netlist_errors_name_the_path_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/rigs/leaney-moog.json"),
    )
    .unwrap();
    let line = text.lines().position(|l| l.contains("\"cd\"")).unwrap() + 1;
    let rig = dir.path().join("bad.json");
    std::fs::write(&rig, text.replace("\"cd\": 0.625", "\"cd\": 1.5")).unwrap();
    let cmd = write_command(dir.path(), "cmd.csv", &[(0.0, 0.0), (0.1, 0.2)]);
    let out = dir.path().join("out.csv");
    let st = hydrocyl()
        .args(["simulate", "--rig"])
        .arg(&rig)
        .arg("--command")
        .arg(&cmd)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(st.status.code(), Some(2));
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("components.valve.orifice.cd") && err.contains(&format!("line {line} of")),
        "{err}"
    );
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!out.exists());
}

/// The output written block by block (several blocks here) is, byte for
/// byte, the in-process run of the same command written in one piece,
/// whichever thread made each block's text: the writer thread (on a second
/// circuit), the solve's thread during the solve (`--probes-behind 0`:
/// every block, on a third circuit; `2`: while the writer is two behind),
/// or both after the solve (the default and `1000`: the solve's thread on
/// the solving circuit).
#[test]
fn the_written_rows_are_the_in_process_run_byte_for_byte() {
    use hydrocyl_identify::plaincsv::{run_columns, write_columns};
    use hydrocyl_system::{rig, run::RunOptions, signal::Signal};
    let dir = tempfile::tempdir().unwrap();
    let rows = square(3500, 1e-3);
    let cmd = write_command(dir.path(), "cmd.csv", &rows);
    let (t, u): (Vec<f64>, Vec<f64>) = rows.iter().copied().unzip();
    let run = rig::simulate(
        &rig::load("leaney-moog").unwrap(),
        Signal::table(t.clone(), u).unwrap(),
        &t,
        &RunOptions::default(),
    )
    .unwrap();
    let (names, columns) = run_columns(&run);
    let whole = String::from_utf8(write_columns(&names, &columns)).unwrap();
    let body = |s: &str| s.split_once('\n').map(|(_, b)| b.to_string()).unwrap();
    for extra in [
        &[][..],
        &["--probes-behind", "0"],
        &["--probes-behind", "2"],
        &["--probes-behind", "1000"],
    ] {
        let out = dir.path().join("out.csv");
        simulate_ok("leaney-moog", &cmd, &out, extra);
        let written = std::fs::read_to_string(&out).unwrap();
        assert_eq!(written.lines().count(), rows.len() + 1, "{extra:?}");
        assert_eq!(
            written.lines().next().unwrap().split(',').count(),
            names.len(),
            "{extra:?}"
        );
        assert!(body(&written) == body(&whole), "{extra:?}: the rows differ");
    }
}

/// The hybrid rig (an algebraic node, whose solves start from the last
/// solution: its wires depend on what ran before) reads its outputs on the
/// solving circuit between blocks of steps; the reads leave the circuit as
/// they found it, so the written rows are the in-process run's (which reads
/// them after the solve), byte for byte, with either solver (once its zeros
/// are flushed as `simulate` writes them: `flush_to_zero`).
#[test]
fn the_hybrid_rig_written_is_its_in_process_run() {
    use hydrocyl_identify::plaincsv::{run_columns, write_columns};
    use hydrocyl_system::{rig, run::RunOptions, run::Solver, signal::Signal};
    let dir = tempfile::tempdir().unwrap();
    let rows: Vec<(f64, f64)> = (0..=500)
        .map(|k| {
            let t = k as f64 * 1e-3;
            (t, 2.0 * (std::f64::consts::TAU * 2.0 * t).sin())
        })
        .collect();
    let cmd = write_command(dir.path(), "cmd.csv", &rows);
    let (t, u): (Vec<f64>, Vec<f64>) = rows.iter().copied().unzip();
    for solver in [Solver::Rosenbrock, Solver::Auto] {
        let run = rig::simulate(
            &rig::load("wang-hybrid").unwrap(),
            Signal::table(t.clone(), u.clone()).unwrap(),
            &t,
            &RunOptions {
                solver,
                ..RunOptions::default()
            },
        )
        .unwrap();
        let (names, columns) = run_columns(&run);
        // as `simulate` writes a value: a subnormal or -0.0 as 0.0
        let flushed: Vec<Vec<f64>> = columns
            .iter()
            .map(|c| {
                c.iter()
                    .map(|&v| if v.is_subnormal() || v == 0.0 { 0.0 } else { v })
                    .collect()
            })
            .collect();
        let columns: Vec<&[f64]> = flushed.iter().map(Vec::as_slice).collect();
        let whole = String::from_utf8(write_columns(&names, &columns)).unwrap();
        let out = dir.path().join("out.csv");
        simulate_ok("wang-hybrid", &cmd, &out, &["--solver", solver.name()]);
        let written = std::fs::read_to_string(&out).unwrap();
        let body = |s: &str| s.split_once('\n').map(|(_, b)| b.to_string()).unwrap();
        assert!(
            body(&written) == body(&whole),
            "{}: the rows differ",
            solver.name()
        );
    }
}

/// The temporaries left in `dir` (none after any run, good or failed).
fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().to_string())
        .filter(|n| n.contains(".tmp"))
        .collect()
}

/// An output that exists is replaced by a run that succeeds (swapped into
/// place, its old content removed) and kept as it was by one that fails —
/// on a bad command cell in the second half of a long file (read by the
/// other thread), and on an unstable solution found while writing.
#[test]
fn an_existing_output_is_replaced_by_a_good_run_and_kept_by_a_failed_one() {
    let dir = tempfile::tempdir().unwrap();
    let rows = square(4000, 1e-3);
    let cmd = write_command(dir.path(), "cmd.csv", &rows);
    let out = dir.path().join("out.csv");
    std::fs::write(&out, "old content\n").unwrap();
    simulate_ok("leaney-moog", &cmd, &out, &[]);
    let written = std::fs::read_to_string(&out).unwrap();
    assert_eq!(written.lines().count(), rows.len() + 1);
    assert!(
        temporaries(dir.path()).is_empty(),
        "{:?}",
        temporaries(dir.path())
    );
    // a bad cell at row 3501 (the second half of the body)
    let mut text = std::fs::read_to_string(&cmd).unwrap();
    let line = text.lines().nth(3500).unwrap().to_string();
    text = text.replacen(&line, &line.replacen(",x", "z,x", 1), 1);
    let bad = dir.path().join("bad.csv");
    std::fs::write(&bad, &text).unwrap();
    std::fs::write(&out, "old content\n").unwrap();
    for (command, extra, needle) in [
        (&bad, &[][..], "row 3501, column 'command'"),
        (
            &cmd,
            &["--solver", "rk4", "--rk4-step", "2e-2"][..],
            "unstable",
        ),
    ] {
        let st = hydrocyl()
            .args(["simulate", "--rig", "leaney-moog", "--command"])
            .arg(command)
            .arg("--out")
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&st.stderr);
        assert_eq!(st.status.code(), Some(2), "{err}");
        assert!(err.contains(needle), "{needle}: {err}");
        assert_eq!(std::fs::read_to_string(&out).unwrap(), "old content\n");
        assert!(
            temporaries(dir.path()).is_empty(),
            "{:?}",
            temporaries(dir.path())
        );
    }
}

/// A long command file is parsed in two halves on two threads; blank lines
/// inside it (which the full reader skips) or only at its end give the run
/// of the same samples without them.
#[test]
fn a_long_command_file_read_in_halves_is_the_same_samples() {
    let dir = tempfile::tempdir().unwrap();
    let rows = square(4000, 1e-3);
    let cmd = write_command(dir.path(), "cmd.csv", &rows);
    let out = dir.path().join("out.csv");
    simulate_ok("leaney-moog", &cmd, &out, &[]);
    let reference = std::fs::read_to_string(&out).unwrap();
    let text = std::fs::read_to_string(&cmd).unwrap();
    let lines: Vec<&str> = text.lines().collect();
    let blank_at = |ks: &[usize], end: bool| {
        let mut s = String::new();
        for (k, l) in lines.iter().enumerate() {
            if ks.contains(&k) {
                s.push('\n');
            }
            s.push_str(l);
            s.push('\n');
        }
        if end {
            s.push_str("\n\r\n");
        }
        s
    };
    // around the middle, where the body is cut, and at the end
    for (ks, end) in [
        (&[1990, 2010][..], false),
        (&[2001][..], false),
        (&[][..], true),
    ] {
        let other = dir.path().join("blank.csv");
        std::fs::write(&other, blank_at(ks, end)).unwrap();
        simulate_ok("leaney-moog", &other, &out, &[]);
        assert!(
            std::fs::read_to_string(&out).unwrap() == reference,
            "{ks:?} {end}: the rows differ"
        );
    }
}

/// A long command file's halves are parsed before the rig is read, on the
/// columns its header suggests (`time`, and `command`, else `reference`);
/// a rig whose input is another column gets that column, as from a file
/// holding it alone: a closed-loop rig's `reference` beside a `command`,
/// in either order.
#[test]
fn a_long_command_file_parsed_early_reads_the_rigs_column() {
    let dir = tempfile::tempdir().unwrap();
    let rows = square(6000, 1e-3);
    let file = |name: &str, header: &str, row: &dyn Fn(f64, f64) -> String| {
        let mut s = format!("{header}\n");
        for (t, u) in &rows {
            s.push_str(&row(*t, *u));
        }
        let p = dir.path().join(name);
        std::fs::write(&p, s).unwrap();
        p
    };
    // a set-point of a few millimetres; a `command` of nonsense beside it
    let alone = file("alone.csv", "time,reference [mm]", &|t, u| {
        format!("{t},{}\n", 20.0 * u)
    });
    let after = file("after.csv", "time,command,reference [mm]", &|t, u| {
        format!("{t},{},{}\n", 7.0 - u, 20.0 * u)
    });
    let before = file("before.csv", "reference [mm],time,command", &|t, u| {
        format!("{},{t},{}\n", 20.0 * u, 7.0 - u)
    });
    let out = dir.path().join("out.csv");
    let rig = "leaney-moog-closed-loop";
    simulate_ok(rig, &alone, &out, &["--quiet"]);
    let expected = std::fs::read_to_string(&out).unwrap();
    for cmd in [&after, &before] {
        simulate_ok(rig, cmd, &out, &["--quiet"]);
        assert!(
            std::fs::read_to_string(&out).unwrap() == expected,
            "{}: the rows differ",
            cmd.display()
        );
    }
    // and a valve rig reads the `command` of the same files
    let command = file("command.csv", "time,command", &|t, u| {
        format!("{t},{}\n", 7.0 - u)
    });
    simulate_ok("leaney-moog", &command, &out, &["--quiet"]);
    let expected = std::fs::read_to_string(&out).unwrap();
    for cmd in [&after, &before] {
        simulate_ok("leaney-moog", cmd, &out, &["--quiet"]);
        assert!(
            std::fs::read_to_string(&out).unwrap() == expected,
            "{}: the rows differ",
            cmd.display()
        );
    }
}

/// An output path that is a symbolic link is written through it, as a
/// shell's `>` does: the file it points to gets the run, the link stays a
/// link (also one that points to a file not there yet); a stream
/// (`/dev/stdout`) is written to directly.
#[test]
#[cfg(unix)]
fn an_output_link_is_written_through_and_a_stream_is_written_to() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = write_command(dir.path(), "cmd.csv", &square(50, 1e-3));
    let target = dir.path().join("target.csv");
    std::fs::write(&target, "old content\n").unwrap();
    let link = dir.path().join("out.csv");
    std::os::unix::fs::symlink("target.csv", &link).unwrap();
    simulate_ok("leaney-moog", &cmd, &link, &[]);
    assert!(link.symlink_metadata().unwrap().file_type().is_symlink());
    let written = std::fs::read_to_string(&target).unwrap();
    assert!(written.starts_with("time [s],command"), "{written}");
    assert_eq!(written.lines().count(), 51);
    // a link to a file that does not exist yet creates it
    let dangling = dir.path().join("later.csv");
    std::os::unix::fs::symlink("new.csv", &dangling).unwrap();
    simulate_ok("leaney-moog", &cmd, &dangling, &[]);
    assert!(dangling
        .symlink_metadata()
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(
        std::fs::read_to_string(dir.path().join("new.csv")).unwrap(),
        written
    );
    assert!(temporaries(dir.path()).is_empty());
    // the run's rows on standard output (a stream has no disk to flush to)
    for extra in [&["--quiet"][..], &["--quiet", "--fsync"][..]] {
        let st = simulate_ok("leaney-moog", &cmd, Path::new("/dev/stdout"), extra);
        assert_eq!(String::from_utf8_lossy(&st.stdout), written);
    }
}

/// A closed standard output (`hydrocyl presets | true`, a `| head` that has
/// read enough) ends the run quietly with the status of a tool that SIGPIPE
/// killed (141), as `cat` and `git log` do: never a panic, and no error
/// message for what is not an error. The simulation's rows to `/dev/stdout`
/// likewise.
#[test]
fn a_closed_standard_output_ends_quietly_not_with_a_panic() {
    let dir = tempfile::tempdir().unwrap();
    let cmd = dir.path().join("cmd.csv");
    let rows: String = (0..=2000)
        .map(|k| format!("{},0.1\n", k as f64 * 1e-3))
        .collect();
    std::fs::write(&cmd, format!("time,command\n{rows}")).unwrap();
    let cmd = cmd.to_str().unwrap();
    for args in [
        &["components"][..],
        &["presets"][..],
        &["simulate", "--rig", "leaney-moog", "--print-rig"][..],
        &[
            "simulate",
            "--rig",
            "leaney-moog",
            "--command",
            cmd,
            "--out",
            "/dev/stdout",
        ][..],
    ] {
        // the reading end is closed before the child starts
        let (reader, writer) = std::io::pipe().unwrap();
        drop(reader);
        let st = hydrocyl()
            .args(args)
            .stdout(writer)
            .stderr(std::process::Stdio::piped())
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&st.stderr);
        assert_eq!(st.status.code(), Some(141), "{args:?}: {err}");
        assert!(err.is_empty(), "{args:?}: {err}");
    }
}

/// The input column is read and written in the unit its rig takes it in: a
/// bench drive's imposed velocity in m/s or mm/s (a spool demand's % is
/// refused), a closed-loop rig's set-point in m, so that its output reads
/// back as a command file.
#[test]
fn the_input_column_is_in_the_unit_of_its_rig() {
    let dir = tempfile::tempdir().unwrap();
    let write = |name: &str, text: &str| {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    };
    let out = dir.path().join("out.csv");
    let m_s = write("m_s.csv", "time,command [m/s]\n0,0\n0.1,0.05\n");
    let mm_s = write("mm_s.csv", "time,command [mm/s]\n0,0\n0.1,50\n");
    simulate_ok("emps", &m_s, &out, &["--quiet"]);
    let in_m_s = std::fs::read_to_string(&out).unwrap();
    simulate_ok("emps", &mm_s, &out, &["--quiet"]);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), in_m_s);
    let percent = write("percent.csv", "time,command [%]\n0,0\n0.1,50\n");
    let st = hydrocyl()
        .args(["simulate", "--rig", "emps", "--command"])
        .arg(&percent)
        .arg("--out")
        .arg(dir.path().join("none.csv"))
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert_eq!(st.status.code(), Some(2), "{err}");
    assert!(
        err.contains("row 1, column 'command [%]'") && err.contains("m/s"),
        "{err}"
    );
    assert!(!dir.path().join("none.csv").exists());
    // the closed-loop set-point: written in m, read back as the same run
    let mm = write("mm.csv", "time,reference [mm]\n0,0\n0.1,20\n");
    let first = dir.path().join("first.csv");
    simulate_ok("leaney-moog-closed-loop", &mm, &first, &["--quiet"]);
    let text = std::fs::read_to_string(&first).unwrap();
    assert!(
        text.lines().next().unwrap().contains("reference [m]"),
        "{text}"
    );
    simulate_ok("leaney-moog-closed-loop", &first, &out, &["--quiet"]);
    assert_eq!(std::fs::read_to_string(&out).unwrap(), text);
}

/// A number a rig or a command cannot hold (`1e400` overflows, `inf`,
/// `NaN`) is named as such, in a command cell and in a `--set`.
#[test]
fn a_number_that_is_not_finite_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let good = write_command(dir.path(), "good.csv", &square(20, 1e-3));
    let big = dir.path().join("big.csv");
    std::fs::write(&big, "time,command\n0,1e400\n0.01,1\n").unwrap();
    let out = dir.path().join("out.csv");
    let run = |cmd: &Path, extra: &[&str]| {
        let st = hydrocyl()
            .args(["simulate", "--rig", "leaney-moog", "--command"])
            .arg(cmd)
            .arg("--out")
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        (
            st.status.code(),
            String::from_utf8_lossy(&st.stderr).to_string(),
        )
    };
    let (code, err) = run(&big, &[]);
    assert_eq!(code, Some(2), "{err}");
    assert!(
        err.contains("row 2, column 'command': '1e400' is not finite"),
        "{err}"
    );
    for v in ["1e400", "inf", "NaN"] {
        let (code, err) = run(&good, &["--set", &format!("load.mass={v}")]);
        assert_eq!(code, Some(2), "{err}");
        assert!(
            err.contains(&format!("`{v}` is not a finite number")),
            "{err}"
        );
    }
    assert!(!out.exists());
}

/// A ±0.3 square wave of 1 s half-periods sampled every millisecond for
/// `seconds` (the tester's `sq.csv`).
fn square_03(seconds: usize) -> Vec<(f64, f64)> {
    (0..=seconds * 1000)
        .map(|k| {
            let t = k as f64 * 1e-3;
            (t, if (k / 1000) % 2 == 0 { 0.3 } else { -0.3 })
        })
        .collect()
}

#[test]
fn cavitation_on_a_generalised_cylinder_proposes_no_parameter_it_lacks() {
    // the generalised one-pressure actuator has no entrained-air
    // parameter: the warning's remedy must not tell the user to set one
    let dir = tempfile::tempdir().unwrap();
    let cmd = write_command(dir.path(), "sq.csv", &square_03(3));
    let out = dir.path().join("g.csv");
    let st = hydrocyl()
        .args(["simulate", "--rig", "leaney-moog-generalised", "--command"])
        .arg(&cmd)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert_eq!(st.status.code(), Some(0), "{err}");
    assert!(out.exists());
    assert!(err.contains("hydrocyl: warning:"), "{err}");
    assert!(err.contains("cavitates"), "{err}");
    assert!(!err.contains("--set cylinder.air_fraction"), "{err}");
    assert!(
        err.contains("`cylinder` (a `generalised_cylinder`) has no entrained-air parameter"),
        "{err}"
    );
}

/// The chapter-3 sawtooth (section 3.3.3, `crates/studies/src/chapter3.rs`):
/// u from −0.52 to +0.52, period 1.5 s, 6 s; samples `step` × 0.1 ms apart
/// (10: the thesis's 1 ms), their times written as decimals (`1.507`).
fn chapter3_sawtooth(dir: &Path, step: usize) -> PathBuf {
    let mut s = String::from("time,command\n");
    for m in (0..=60_000).step_by(step) {
        let t = m as f64 * 1e-4;
        let phase = (t / 1.5).rem_euclid(1.0);
        s.push_str(&format!(
            "{}.{:04},{}\n",
            m / 10_000,
            m % 10_000,
            0.52 * (2.0 * phase - 1.0)
        ));
    }
    let p = dir.join("c3saw.csv");
    std::fs::write(&p, s).unwrap();
    p
}

/// The warning of a chamber far below vacuum, as the CLI words it.
const CAVITATION_WARNING: &str = "hydrocyl: warning: a chamber pressure fell far below absolute vacuum (p1 of `cylinder` fell below";

#[test]
fn the_chapter3_sawtooth_cavitates_with_one_warning_and_is_written() {
    // the drop at the end of each ramp reverses a 100 kg load moving at
    // ~0.3 m/s: chamber 1 of the constant-B oil goes to −14.9 bar with any
    // method and step (docs/models.md §3): the model's limit, not an
    // error; the run is written and warned of once, whichever thread made
    // the rows (the writer's, the solve's, or the streamed command's path)
    let dir = tempfile::tempdir().unwrap();
    let cmd = chapter3_sawtooth(dir.path(), 10);
    let out = dir.path().join("f.csv");
    for extra in [
        &[][..],
        &["--solver", "rosenbrock"],
        &["--solver", "dp45", "--rtol", "1e-8"],
        &["--solver", "rk4"],
        &["--probes-behind", "0"],
        &["--stream-above", "1"],
    ] {
        let _ = std::fs::remove_file(&out);
        let st = simulate_ok("leaney-moog", &cmd, &out, extra);
        let err = String::from_utf8_lossy(&st.stderr);
        assert_eq!(err.matches("warning").count(), 1, "{extra:?}: {err}");
        for needle in [
            CAVITATION_WARNING,
            "-1.4885e6 Pa at t = 1.507 s",
            "has left its range from then on",
            "--set cylinder.air_fraction=0.005",
            "CAVITATION:",
            // the summary names the chambers, with their counts
            "cylinder.cavitation_entries_",
        ] {
            assert!(err.contains(needle), "{extra:?}: {needle}: {err}");
        }
        // a fixed step is told how to find whether it is to blame
        assert_eq!(
            err.contains(
                "a smaller --rk4-step than 0.00002 tells whether the rk4 step is to blame"
            ),
            extra.contains(&"rk4"),
            "{extra:?}: {err}"
        );
        let (header, rows) = read_csv(&out);
        assert_eq!(rows.len(), 6001, "{extra:?}");
        let p1 = header.iter().position(|h| h == "p1").unwrap();
        let lowest = rows.iter().map(|r| r[p1]).fold(f64::INFINITY, f64::min);
        assert!((-1.49e6..-1.48e6).contains(&lowest), "{extra:?}: {lowest}");
    }
    // --quiet says nothing
    let st = simulate_ok("leaney-moog", &cmd, &out, &["--quiet"]);
    assert_eq!(String::from_utf8_lossy(&st.stderr), "");
}

#[test]
fn an_rk4_blow_up_after_a_moderate_tension_is_an_error_with_no_warning() {
    // rk4 at 12.5 ms on the sawtooth sampled every 0.5 ms: the chambers
    // fall to finite tensions from t = 0.8195 s (p2 to −389 bar, earlier
    // blocks of rows), then the step blows up (p1 = −1633 bar, beyond the
    // liquid's tension limit, at t = 1.026 s, a later block): an error, the
    // file not written, and no warning of the tension before it, whichever
    // thread found it
    let dir = tempfile::tempdir().unwrap();
    let cmd = chapter3_sawtooth(dir.path(), 5);
    let out = dir.path().join("f.csv");
    for extra in [&[][..], &["--probes-behind", "0"], &["--stream-above", "1"]] {
        let st = hydrocyl()
            .args(["simulate", "--rig", "leaney-moog", "--command"])
            .arg(&cmd)
            .arg("--out")
            .arg(&out)
            .args(["--solver", "rk4", "--rk4-step", "1.25e-2"])
            .args(extra)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&st.stderr);
        assert_eq!(st.status.code(), Some(2), "{extra:?}: {err}");
        assert_eq!(err.trim().lines().count(), 1, "{extra:?}: {err}");
        assert!(
            err.contains("the rk4 solution is unstable (p1 = "),
            "{extra:?}: {err}"
        );
        assert!(err.contains("at t = 1.026 s"), "{extra:?}: {err}");
        assert!(
            err.contains("--rk4-step 0.0125 is too large"),
            "{extra:?}: {err}"
        );
        assert!(!err.contains("warning"), "{extra:?}: {err}");
        assert!(!out.exists(), "{extra:?}");
    }
}

/// `hydrocyl simulate --rig <rig> --command <rows> <extra>`: its stderr,
/// which must report success.
fn summary(rig: &str, rows: &[(f64, f64)], extra: &[&str]) -> String {
    let dir = tempfile::tempdir().unwrap();
    let cmd = write_command(dir.path(), "cmd.csv", rows);
    let st = simulate_ok(rig, &cmd, &dir.path().join("out.csv"), extra);
    String::from_utf8_lossy(&st.stderr).to_string()
}

#[test]
fn sub_pascal_solver_noise_below_the_cavitation_pressure_is_not_cavitation() {
    // a closed chamber at tank pressure (0 Pa, the cavitation pressure)
    // dithers at −8e-4 Pa: not an entry, and never a `-0 Pa` minimum
    let err = summary("wang-valve-c10", &square_03(3), &[]);
    assert!(err.contains("no cavitation"), "{err}");
    assert!(!err.contains("-0 Pa"), "{err}");
    // −7e-68 Pa from rosenbrock on a chamber at rest at tank pressure
    let step: Vec<(f64, f64)> = (0..=2000).map(|k| (k as f64 * 1e-3, 1.0)).collect();
    let err = summary(
        "leaney-moog",
        &step,
        &[
            "--solver",
            "rosenbrock",
            "--set",
            "cylinder.initial.position=0.2",
        ],
    );
    assert!(err.contains("no cavitation"), "{err}");
}

#[test]
fn a_line_volume_exactly_at_absolute_vacuum_is_not_below_it() {
    let dir = tempfile::tempdir().unwrap();
    let rig = dir.path().join("relief.json");
    std::fs::write(
        &rig,
        r#"{"kind":"netlist","name":"relief-test",
 "components":{
  "supply":{"type":"pressure_source","pressure":1.0e7},
  "tank":{"type":"pressure_source","pressure":0.0},
  "o1":{"type":"orifice","area":1.0e-6,"cd":0.6,"density":870.0},
  "line":{"type":"volume","volume":1e-5,"bulk_modulus":7e8},
  "rv":{"type":"relief_valve","cracking":2e6,"full_open":8e6,"kv":3e-8}
 },
 "connections":[["supply.port","o1.a"],["o1.b","line.port","rv.inlet"],["rv.outlet","tank.port"]]
}"#,
    )
    .unwrap();
    let step: Vec<(f64, f64)> = (0..=2000).map(|k| (k as f64 * 1e-3, 1.0)).collect();
    let err = summary(
        rig.to_str().unwrap(),
        &step,
        &["--set", "supply.pressure=-101325"],
    );
    assert!(err.contains("no cavitation"), "{err}");
}
