//! What the README and `--help` promise about the command line itself:
//! progress where stderr is not a terminal, remedies, one-line argument
//! errors, `--set`'s blame, the benches' columns, help text and
//! `--print-rig`'s combinations.

mod common;

use common::{hydrocyl, simulate_ok};
use std::path::{Path, PathBuf};
use std::process::Output;

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

/// The `leaney-moog` preset as `--print-rig` prints it, written to
/// `lm.json` in `dir` (a rig file whose lines errors name).
fn printed_rig(dir: &Path) -> PathBuf {
    let p = hydrocyl()
        .args(["simulate", "--rig", "leaney-moog", "--print-rig"])
        .output()
        .unwrap();
    assert!(p.status.success());
    let rig = dir.join("lm.json");
    std::fs::write(&rig, &p.stdout).unwrap();
    rig
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

/// `hydrocyl simulate` with `args`, expected to fail: its one stderr line
/// (exit code 2), the output `out` not written.
fn simulate_fails(args: &[&str], out: &Path) -> String {
    let o = hydrocyl().arg("simulate").args(args).output().unwrap();
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(!out.exists(), "{} written", out.display());
    let e = stderr(&o);
    assert_eq!(e.lines().count(), 1, "not one line: {e:?}");
    assert!(e.starts_with("hydrocyl: error: "), "{e:?}");
    e
}

#[test]
fn a_fixed_step_run_that_blows_up_names_the_remedy() {
    let d = scratch("rk4-blows-up");
    let out = d.join("o.csv");
    let e = simulate_fails(
        &[
            "--rig",
            "wang-hybrid",
            "--command",
            concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/../../fixtures/commands/ch7-square.csv"
            ),
            "--out",
            out.to_str().unwrap(),
            "--solver",
            "rk4",
            "--rk4-step",
            "0.0005",
        ],
        &out,
    );
    assert!(e.contains("is not finite"), "{e}");
    assert!(
        e.contains("--rk4-step 0.0005 is likely too large") && e.contains("--solver auto"),
        "{e}"
    );
}

#[test]
fn an_rtol_below_what_double_precision_meets_is_refused_up_front() {
    let d = scratch("tiny-rtol");
    let cmd = command_file(&d, 101, 1e-3);
    let out = d.join("o.csv");
    let e = simulate_fails(
        &[
            "--rig",
            "leaney-moog",
            "--command",
            cmd.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--rtol",
            "1e-300",
        ],
        &out,
    );
    assert!(e.contains("--rtol 1e-300: below 1e-14"), "{e}");
    assert!(e.contains("use a value in [1e-14, 1)"), "{e}");
    assert!(!e.contains("physical range"), "{e}");
}

#[test]
fn argument_errors_are_one_line_naming_the_option_and_the_help() {
    let d = scratch("clap");
    let out = d.join("o.csv");
    let o = out.to_str().unwrap();
    let cases: &[(&[&str], &[&str])] = &[
        (
            &[
                "simulate",
                "--rig",
                "leaney-moog",
                "--command",
                "c.csv",
                "--out",
                o,
                "--rtol",
                "abc",
            ],
            &[
                "--rtol: invalid value 'abc': ",
                "(see hydrocyl simulate --help)",
            ],
        ),
        (
            &[
                "diagnose",
                "--rig",
                "leaney-moog",
                "--data",
                "d.csv",
                "--holdout",
                "abc",
            ],
            &[
                "--holdout: invalid value 'abc'",
                "(see hydrocyl diagnose --help)",
            ],
        ),
        (
            &["simulate", "--rig", "leaney-moog", "--command", "c.csv"],
            &["missing required --out", "(see hydrocyl simulate --help)"],
        ),
        (
            &[
                "simulate",
                "--rig",
                "leaney-moog",
                "--command",
                "c.csv",
                "--ou",
                o,
            ],
            &["unexpected argument '--ou'; did you mean '--out'?"],
        ),
        (
            &["simulat"],
            &[
                "unknown subcommand 'simulat'; did you mean 'simulate'?",
                "(see hydrocyl --help)",
            ],
        ),
    ];
    for (args, wanted) in cases {
        let r = hydrocyl().args(*args).current_dir(&d).output().unwrap();
        let e = stderr(&r);
        assert_eq!(r.status.code(), Some(2), "{args:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{args:?}: not one line: {e:?}");
        assert!(e.starts_with("hydrocyl: error: "), "{args:?}: {e:?}");
        for w in *wanted {
            assert!(e.contains(w), "{args:?}: {w:?} not in {e:?}");
        }
        assert!(r.stdout.is_empty() && !out.exists(), "{args:?}");
    }
    // help and version still print as usual, on stdout, exit code 0
    for args in [&["simulate", "--help"][..], &["--version"], &["--help"]] {
        let r = hydrocyl().args(args).output().unwrap();
        assert_eq!(r.status.code(), Some(0), "{args:?}");
        assert!(!r.stdout.is_empty() && r.stderr.is_empty(), "{args:?}");
    }
}

#[test]
fn a_bad_value_from_set_names_the_set_not_a_line_of_the_rig_file() {
    let d = scratch("set-blame");
    let cmd = command_file(&d, 11, 1e-3);
    let rig = printed_rig(&d);
    let out = d.join("o.csv");
    let base = [
        "--rig",
        rig.to_str().unwrap(),
        "--command",
        cmd.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    let e = simulate_fails(&[&base[..], &["--set", "load.mass=-1"]].concat(), &out);
    assert!(
        e.contains("load.mass") && e.contains("(set by --set load.mass=-1 on "),
        "{e}"
    );
    assert!(!e.contains("line "), "{e}");
    // the same value in the file itself: its line
    let text =
        std::fs::read_to_string(&rig)
            .unwrap()
            .replacen("\"mass\": 100.0", "\"mass\": -1.0", 1);
    assert!(text.contains("\"mass\": -1.0"));
    std::fs::write(&rig, text).unwrap();
    let e = simulate_fails(&base, &out);
    assert!(e.contains("(line ") && !e.contains("--set"), "{e}");
}

/// An initial state a `--set` gave and a component refuses when it is built
/// (a spool position beyond its stroke, a mass's own position beyond its
/// end stops) is named at its path and blamed on the `--set`, as a
/// parameter's range error is: they were named at `components.<name>` with
/// the line of the file, which held the value the `--set` replaced.
#[test]
fn a_bad_initial_state_from_set_names_its_path_and_the_set() {
    let d = scratch("set-blame-initial");
    let cmd = command_file(&d, 11, 1e-3);
    let rig = printed_rig(&d);
    let out = d.join("o.csv");
    for (sets, path) in [
        (
            &["spool.initial.position=0.001"][..],
            "components.spool.initial.position",
        ),
        (
            &[
                "load.initial.position=0.3",
                "cylinder.initial.position=null",
            ],
            "components.load.initial.position",
        ),
    ] {
        let mut args = vec![
            "--rig",
            rig.to_str().unwrap(),
            "--command",
            cmd.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        for s in sets {
            args.extend(["--set", s]);
        }
        let e = simulate_fails(&args, &out);
        assert!(e.contains(&format!("rig `{path}`")), "{e}");
        assert!(e.contains(&format!("(set by --set {} on ", sets[0])), "{e}");
        assert!(!e.contains("(line "), "{e}");
    }
}

/// A relation between two parameters that a `--set` of the *other* one
/// breaks (the stroke against a chamber length, `full_open` against a
/// relief valve's `cracking`, the supply against the tank) is named at the
/// parameter the relation bounds, whose line in the file holds a value the
/// user did not change: the message names the `--set` too. It used to name
/// only that line, and the `--set` that broke the relation nowhere.
#[test]
fn a_relation_broken_by_a_set_of_the_other_parameter_names_the_set() {
    let d = scratch("set-blame-relation");
    let cmd = command_file(&d, 11, 1e-3);
    let rig = printed_rig(&d);
    let out = d.join("o.csv");
    // `simulate --rig <rig>` with `sets`, which must fail: its error line
    let fails = |rig: &str, sets: &[&str]| {
        let mut args = vec![
            "--rig",
            rig,
            "--command",
            cmd.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ];
        for s in sets {
            args.extend(["--set", s]);
        }
        simulate_fails(&args, &out)
    };
    let file = rig.to_str().unwrap();
    for (rig, set, path) in [
        (
            file,
            "cylinder.stroke=0.7",
            "components.cylinder.chamber_length_1",
        ),
        (file, "cylinder.area_1=0.0005", "components.cylinder.area_2"),
        (file, "supply.pressure=-1000", "components.tank.pressure"),
        ("leaney-moog", "supply.pressure=-1000", "tank.pressure"),
        (
            "leaney-moog",
            "cylinder.stroke=0.7",
            "cylinder.chamber_length_1",
        ),
    ] {
        let e = fails(rig, &[set]);
        assert!(e.contains(&format!("rig `{path}`")), "{e}");
        assert!(e.contains(&format!("(with --set {set})")), "{e}");
    }
    // a --set the message does not name is not blamed: the mass has
    // nothing to do with the stroke
    let e = fails(file, &["cylinder.stroke=0.7", "load.mass=50"]);
    assert!(e.contains("(with --set cylinder.stroke=0.7)"), "{e}");
    assert!(!e.contains("load.mass"), "{e}");
    // both the bounded parameter and the other one set: both named
    let e = fails(
        file,
        &["cylinder.chamber_length_1=0.3", "cylinder.stroke=0.7"],
    );
    assert!(
        e.contains("(set by --set cylinder.chamber_length_1=0.3 on ")
            && e.contains("with --set cylinder.stroke=0.7)"),
        "{e}"
    );
}

#[test]
fn a_friction_bench_writes_its_command_column_like_every_rig() {
    let d = scratch("bench-command");
    let mut s = String::from("time,command\n");
    for k in 0..201 {
        let t = k as f64 * 1e-3;
        s.push_str(&format!("{t},{}\n", if t < 0.1 { 0.01 } else { -0.02 }));
    }
    let cmd = d.join("velocity.csv");
    std::fs::write(&cmd, s).unwrap();
    for (rig, set) in [
        ("tudelft-seal-25", &["--set", "chamber.pressure=5e5"][..]),
        ("emps", &[][..]),
    ] {
        let out = d.join(format!("{rig}.csv"));
        let o = hydrocyl()
            .args(["simulate", "--rig", rig, "--command"])
            .arg(&cmd)
            .arg("--out")
            .arg(&out)
            .args(set)
            .output()
            .unwrap();
        assert!(o.status.success(), "{rig}: {}", stderr(&o));
        let text = std::fs::read_to_string(&out).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        assert_eq!(&header[..2], ["time [s]", "command [m/s]"], "{rig}");
        assert!(header.contains(&"force [N]"), "{rig}: {header:?}");
        // the command as read, at the command's times
        for (k, l) in lines.enumerate() {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            let want = if (k as f64) * 1e-3 < 0.1 { 0.01 } else { -0.02 };
            assert_eq!(v[1], want, "{rig} row {k}");
        }
    }
}

/// The help of `hydrocyl <sub> --help`.
fn help(sub: &str) -> String {
    let o = hydrocyl().args([sub, "--help"]).output().unwrap();
    assert!(o.status.success(), "{sub} --help");
    String::from_utf8(o.stdout).unwrap()
}

#[test]
fn help_shows_what_is_required_and_which_rigs_work() {
    // fmu's usage line names its two required options
    let fmu = help("fmu");
    let usage = fmu.lines().find(|l| l.starts_with("Usage:")).unwrap();
    assert!(
        usage.contains("--rig <RIG>") && usage.contains("--out <OUT>"),
        "{usage}"
    );
    // ... which --list-presets does without
    let o = hydrocyl().args(["fmu", "--list-presets"]).output().unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    // diagnose's --rig lists the presets it takes, the closed loop and the
    // hybrid rig among them
    let diagnose = help("diagnose");
    for p in [
        "leaney-moog-closed-loop",
        "wang-hybrid",
        "leaney-moog",
        "tudelft-seal-25",
        "emps",
    ] {
        assert!(diagnose.contains(p), "{p} not in diagnose --help");
    }
}

/// `fmu --help` says `--rig` and `--set` as `simulate --help` does: every
/// preset by name (it said `leaney-moog, ...`), and `--set` by the path
/// `--set` takes, `load.mass` (it said "by its JSON path", which is
/// refused: `components.load.mass`).
#[test]
fn fmu_help_names_the_presets_and_the_set_paths_as_simulate_does() {
    let (fmu, simulate) = (help("fmu"), help("simulate"));
    let line = |text: &str, opt: &str| {
        text.lines()
            .find(|l| l.trim_start().starts_with(opt))
            .unwrap_or_else(|| panic!("no {opt} in {text}"))
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ")
    };
    assert_eq!(line(&fmu, "--rig"), line(&simulate, "--rig"));
    let set = line(&fmu, "--set");
    assert!(
        !set.contains("JSON path") && set.contains("`--set load.mass=50`"),
        "{set}"
    );
}

#[test]
fn print_rig_refuses_the_output_options_it_would_not_write() {
    let d = scratch("print-rig");
    let out = d.join("o.csv");
    let ledger = d.join("l.json");
    for extra in [
        &["--out", out.to_str().unwrap()][..],
        &["--ledger", ledger.to_str().unwrap()],
    ] {
        let o = hydrocyl()
            .args(["simulate", "--rig", "leaney-moog", "--print-rig"])
            .args(extra)
            .output()
            .unwrap();
        let e = stderr(&o);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {e}");
        assert_eq!(e.lines().count(), 1, "{e:?}");
        assert!(
            e.starts_with("hydrocyl: error: --print-rig cannot be used with ")
                || e.contains("cannot be used with --print-rig"),
            "{e}"
        );
        assert!(o.stdout.is_empty() && !out.exists() && !ledger.exists());
    }
    // with --set only, it prints the rig
    let o = hydrocyl()
        .args([
            "simulate",
            "--rig",
            "leaney-moog",
            "--print-rig",
            "--set",
            "load.mass=50",
        ])
        .output()
        .unwrap();
    assert!(o.status.success() && String::from_utf8_lossy(&o.stdout).contains("50"));
}

/// A command file with a column the run does not read written in
/// Windows-1252 by a logger (`Öl [°C]`) runs as the same file without it;
/// a `command` cell with such a byte is refused at its row and column. The
/// file was refused whole, at a byte offset ("not UTF-8 text (byte 27)").
#[test]
fn bytes_that_are_not_utf8_are_named_only_where_the_run_reads_them() {
    let d = scratch("latin1");
    let mut plain = String::from("time [s],command\n");
    let mut s = b"time [s],command,\xd6l [\xb0C]\r\n".to_vec();
    for k in 0..21 {
        let t = k as f64 * 1e-3;
        plain.push_str(&format!("{t},0.2\n"));
        s.extend(format!("{t},0.2,41.5\r\n").bytes());
    }
    let (a, b) = (d.join("plain.csv"), d.join("latin1.csv"));
    std::fs::write(&a, plain).unwrap();
    std::fs::write(&b, &s).unwrap();
    let (oa, ob) = (d.join("a.csv"), d.join("b.csv"));
    simulate_ok("leaney-moog", &a, &oa, &[]);
    simulate_ok("leaney-moog", &b, &ob, &[]);
    assert_eq!(std::fs::read(&oa).unwrap(), std::fs::read(&ob).unwrap());
    let at = s.windows(5).position(|w| w == b"0.2,4").unwrap();
    s[at + 1] = 0xb7;
    std::fs::write(&b, &s).unwrap();
    let out = d.join("c.csv");
    let e = simulate_fails(
        &[
            "--rig",
            "leaney-moog",
            "--command",
            b.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        &out,
    );
    assert!(e.contains("row 2, column 'command'"), "{e}");
}

/// A line of spaces or tabs in a command file (a logger's padded blank
/// line, between rows or at the end) is blank: the run is the one without
/// it. It was refused as a row of one cell ("1 cell, the header has 2").
#[test]
fn a_line_of_spaces_in_a_command_file_is_blank() {
    let d = scratch("blank-spaces");
    let (mut plain, mut padded) = (
        String::from("time,command\n"),
        String::from("time,command\r\n"),
    );
    for k in 0..21 {
        let row = format!("{},0.2", k as f64 * 1e-3);
        plain.push_str(&format!("{row}\n"));
        padded.push_str(&format!("{row}\r\n"));
        if k == 7 {
            padded.push_str(" \t \r\n");
        }
    }
    padded.push_str("  \r\n\t\r\n");
    let (a, b) = (d.join("plain.csv"), d.join("padded.csv"));
    std::fs::write(&a, plain).unwrap();
    std::fs::write(&b, padded).unwrap();
    let (oa, ob) = (d.join("a.csv"), d.join("b.csv"));
    simulate_ok("leaney-moog", &a, &oa, &[]);
    simulate_ok("leaney-moog", &b, &ob, &[]);
    assert_eq!(std::fs::read(&oa).unwrap(), std::fs::read(&ob).unwrap());
}

/// The command reader (`simulate`) and the record reader (`diagnose`) say
/// the same fault the same way (README): a missing `time` or `command`
/// column and an unknown time unit. `simulate` said "no `time` column" and
/// "unknown time unit `min` (use s or ms)" where `diagnose` said "missing
/// column 'time'" and "unknown unit 'min' (accepted: s, ms)".
#[test]
fn both_readers_word_a_missing_column_and_a_time_unit_alike() {
    let d = scratch("same-words");
    let rows: String = (0..150)
        .map(|k| format!("{},0.1,0.0,21.0,42.0\n", k as f64 * 1e-3))
        .collect();
    for header in [
        "Time [s],command,position [mm],p1 [bar],p2 [bar]",
        "time [s],cmd,position [mm],p1 [bar],p2 [bar]",
        "time [min],command,position [mm],p1 [bar],p2 [bar]",
    ] {
        let f = d.join("rec.csv");
        std::fs::write(&f, format!("{header}\n{rows}")).unwrap();
        let f = f.to_str().unwrap();
        let out = d.join("o.csv");
        let s = simulate_fails(
            &[
                "--rig",
                "leaney-moog",
                "--command",
                f,
                "--out",
                out.to_str().unwrap(),
            ],
            &out,
        );
        let report = d.join("r.json");
        let o = hydrocyl()
            .args(["diagnose", "--rig", "leaney-moog", "--data", f, "--report"])
            .arg(&report)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2));
        assert!(!report.exists());
        assert_eq!(s, stderr(&o), "{header}");
    }
}

/// A `--set` path copied from an error about a rig file, which names the
/// JSON path (`components.load.mass`), is refused with the path `--set`
/// takes: it said only "no component `components`".
#[test]
fn a_set_with_the_json_path_names_the_parameter_path() {
    let d = scratch("set-json-path");
    let cmd = command_file(&d, 11, 1e-3);
    let out = d.join("o.csv");
    let e = simulate_fails(
        &[
            "--rig",
            "leaney-moog",
            "--command",
            cmd.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--set",
            "components.load.mass=50",
        ],
        &out,
    );
    assert!(
        e.contains("without the JSON path's `components.`: `load.mass`"),
        "{e}"
    );
}

/// A parameter inside its range but far outside what real rigs have (a
/// bulk modulus written in bar) runs, with a warning that names it and the
/// unit it was likely meant in; `--quiet` silences it, a preset as shipped
/// has none, and `fmu` warns of it too.
#[test]
fn a_unit_slip_in_a_parameter_is_warned_of_and_still_runs() {
    let d = scratch("slip");
    let cmd = command_file(&d, 201, 1e-3);
    let out = d.join("o.csv");
    let run = |extra: &[&str]| {
        let o = hydrocyl()
            .args(["simulate", "--rig", "leaney-moog", "--command"])
            .arg(&cmd)
            .arg("--out")
            .arg(&out)
            .args(extra)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", stderr(&o));
        assert!(out.exists());
        stderr(&o)
    };
    let slip = ["--set", "cylinder.bulk_modulus=7000"];
    let e = run(&slip);
    let warned: Vec<&str> = e.lines().filter(|l| l.contains("warning")).collect();
    assert_eq!(
        warned,
        ["hydrocyl: warning: rig `cylinder.bulk_modulus`: 7000 [Pa] is far outside the usual 5e7 to 5e9 [Pa] of effective bulk modulus B of the chambers: a value in bar? (7000 bar = 7e8 Pa)"],
        "{e}"
    );
    assert!(!run(&[]).contains("warning"));
    assert!(run(&[&slip[..], &["--quiet"]].concat()).is_empty());
    // a command that fails after the rig is read keeps its one error line,
    // the warning after it (it may explain the failure): fmu without its
    // library, simulate on a command file that is not there
    let o = hydrocyl()
        .args([
            "fmu",
            "--rig",
            "leaney-moog",
            "--set",
            "cylinder.area_1=1963",
            "--out",
        ])
        .arg(d.join("r.fmu"))
        .args(["--library", "/nonexistent/libhydrocyl_fmu.so"])
        .output()
        .unwrap();
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2));
    assert_eq!(e.lines().count(), 1, "{e}");
    assert!(e.starts_with("hydrocyl: error: "), "{e}");
    assert!(
        e.contains(" (and a warning: rig `cylinder.area_1`: 1963 [m^2] is far outside"),
        "{e}"
    );
    let o = hydrocyl()
        .args([
            "simulate",
            "--rig",
            "leaney-moog",
            "--command",
            "/nonexistent.csv",
            "--out",
        ])
        .arg(&out)
        .args(slip)
        .output()
        .unwrap();
    let e = stderr(&o);
    assert_eq!((o.status.code(), e.lines().count()), (Some(2), 1), "{e}");
    assert!(
        e.contains("(and a warning: rig `cylinder.bulk_modulus`"),
        "{e}"
    );
}
