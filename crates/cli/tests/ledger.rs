//! `hydrocyl simulate --ledger`: the energy ledger written as JSON closes,
//! and is the library's (`hydrocyl_energy::ledger::ledger` on
//! `rig::simulate` with `RunOptions::ledger`, `Ledger::to_json`: what
//! Python's `run.ledger` is), on the hybrid preset with the shipped
//! chapter-7 square (its first second); a ledger path that cannot be
//! written is refused before the run, with nothing written.

use hydrocyl_energy::ledger::{ledger, RodSide};
use hydrocyl_system::rig;
use hydrocyl_system::run::RunOptions;
use hydrocyl_system::signal::Signal;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const START: &str = "cylinder.initial.position=-0.06";

/// The first `span` s of the shipped chapter-7 square, as a file in `dir`,
/// and its times and values.
fn square_head(span: f64, dir: &Path) -> (PathBuf, Vec<f64>, Vec<f64>) {
    let shipped =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures/commands/ch7-square.csv");
    let text = std::fs::read_to_string(shipped).unwrap();
    let mut lines = text.lines();
    let mut out = format!("{}\n", lines.next().unwrap());
    let (mut t, mut u) = (Vec::new(), Vec::new());
    for l in lines {
        let (a, b) = l.split_once(',').unwrap();
        let ta: f64 = a.parse().unwrap();
        if ta > span {
            break;
        }
        t.push(ta);
        u.push(b.parse().unwrap());
        out.push_str(l);
        out.push('\n');
    }
    let p = dir.join("square.csv");
    std::fs::write(&p, out).unwrap();
    (p, t, u)
}

fn simulate(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
        .args([
            "simulate",
            "--rig",
            "wang-hybrid",
            "--set",
            START,
            "--quiet",
        ])
        .args(args)
        .output()
        .unwrap()
}

/// The library's ledger JSON over output samples `k0..` of the run.
fn library(t: &[f64], u: &[f64], k0: usize) -> Value {
    let mut value = rig::load("wang-hybrid").unwrap();
    rig::apply_set(&mut value, START).unwrap();
    let signal = Signal::table(t.to_vec(), u.to_vec()).unwrap();
    let opts = RunOptions {
        ledger: true,
        ..RunOptions::default()
    };
    let run = rig::simulate(&value, signal.clone(), t, &opts).unwrap();
    let mut c = rig::circuit(&value, signal).unwrap();
    c.set_ledger(true);
    ledger(&c, &run, k0, t.len() - 1, &RodSide::of(&c))
        .unwrap()
        .to_json()
}

/// Every number of `a` equals `b`'s to `rel` (of the energy in), every
/// other value exactly, key for key.
fn same(a: &Value, b: &Value, scale: f64, rel: f64, at: &str) {
    match (a, b) {
        (Value::Object(x), Value::Object(y)) => {
            let kx: Vec<_> = x.keys().collect();
            let ky: Vec<_> = y.keys().collect();
            assert_eq!(kx, ky, "{at}");
            for (k, v) in x {
                same(v, &y[k], scale, rel, &format!("{at}.{k}"));
            }
        }
        (Value::Array(x), Value::Array(y)) => {
            assert_eq!(x.len(), y.len(), "{at}");
            for (i, (v, w)) in x.iter().zip(y).enumerate() {
                same(v, w, scale, rel, &format!("{at}[{i}]"));
            }
        }
        (Value::Number(x), Value::Number(y)) => {
            let (x, y) = (x.as_f64().unwrap(), y.as_f64().unwrap());
            assert!(
                (x - y).abs() <= rel * scale.max(x.abs()),
                "{at}: {x} vs {y}"
            );
        }
        _ => assert_eq!(a, b, "{at}"),
    }
}

#[test]
fn the_ledger_closes_and_is_the_librarys() {
    let dir = tempfile::tempdir().unwrap();
    let (cmd, t, u) = square_head(1.0, dir.path());
    let (out, led) = (dir.path().join("out.csv"), dir.path().join("ledger.json"));
    let st = simulate(&[
        "--command",
        cmd.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--ledger",
        led.to_str().unwrap(),
    ]);
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let cli: Value = serde_json::from_str(&std::fs::read_to_string(&led).unwrap()).unwrap();
    let e_in = cli["energy_in_j"].as_f64().unwrap();
    assert!(e_in > 0.0);
    let closure = cli["closure_relative"].as_f64().unwrap();
    assert!(closure.abs() < 1e-6, "closure {closure}");
    assert!(cli["storage_check_relative"].as_f64().unwrap().abs() < 1e-6);
    // the closure is the per-component terms' balance
    let totals = &cli["totals_j"];
    let by_terms = totals["source"].as_f64().unwrap()
        - totals["dissipated"].as_f64().unwrap()
        - totals["storage"].as_f64().unwrap()
        - totals["load"].as_f64().unwrap();
    assert!((by_terms - cli["closure_j"].as_f64().unwrap()).abs() < 1e-9 * e_in);
    assert_eq!(cli["window_s"], serde_json::json!([0.0, 1.0]));
    same(&cli, &library(&t, &u, 0), e_in, 1e-12, "ledger");

    // over a window after a start-up, as the chapter-8 matrix takes it
    let st = simulate(&[
        "--command",
        cmd.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--ledger",
        led.to_str().unwrap(),
        "--ledger-from",
        "0.5",
    ]);
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let cli: Value = serde_json::from_str(&std::fs::read_to_string(&led).unwrap()).unwrap();
    assert_eq!(cli["window_s"], serde_json::json!([0.5, 1.0]));
    let k0 = t.iter().position(|&x| x >= 0.5).unwrap();
    let e_in = cli["energy_in_j"].as_f64().unwrap();
    same(&cli, &library(&t, &u, k0), e_in, 1e-12, "window");

    // a command file read while the run goes (streamed): the same ledger
    let streamed = dir.path().join("streamed.json");
    let st = simulate(&[
        "--command",
        cmd.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--ledger",
        streamed.to_str().unwrap(),
        "--ledger-from",
        "0.5",
        "--stream-above",
        "1",
    ]);
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let s: Value = serde_json::from_str(&std::fs::read_to_string(&streamed).unwrap()).unwrap();
    same(&s, &cli, e_in, 1e-12, "streamed");
}

#[test]
fn a_ledger_path_that_cannot_be_written_is_refused_before_the_run() {
    let dir = tempfile::tempdir().unwrap();
    let (cmd, _, _) = square_head(0.05, dir.path());
    let out = dir.path().join("out.csv");
    let missing = dir.path().join("no-such-folder").join("ledger.json");
    for (ledger, extra) in [
        (missing.to_str().unwrap(), None),
        // the ledger over the CSV
        (out.to_str().unwrap(), None),
        // a window past the run's end
        (
            dir.path().join("l.json").to_str().unwrap(),
            Some(["--ledger-from", "1"]),
        ),
    ]
    .map(|(l, e)| (l.to_string(), e))
    {
        let mut args = vec![
            "--command",
            cmd.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
            "--ledger",
            &ledger,
        ];
        args.extend(extra.iter().flatten());
        let st = simulate(&args);
        let err = String::from_utf8_lossy(&st.stderr);
        assert_eq!(st.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains("--ledger"), "{err}");
        assert!(!out.exists(), "{args:?}: the CSV was written");
        assert!(!dir.path().join("l.json").exists());
        assert!(!missing.exists());
        // no temporary left behind
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.contains(".tmp"))
            .collect();
        assert!(left.is_empty(), "{left:?}");
    }
}
