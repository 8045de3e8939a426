//! `cargo xtask bench`: speed as **ratios** against a reference run on the same
//! machine in the same run, so the numbers mean something on any machine.
//! (Absolute times are printed too, for the record.) The criterion benches in
//! each crate (`cargo bench -p <crate>`) are the detailed measurements; this
//! task is the quick overview. It times the release build, the one users
//! run ([`in_release`]: `cargo xtask bench` builds it and runs itself again
//! in it; `--dev` times the dev build instead): both sides of every ratio
//! are built the same way.

use hydrocyl_ports::{Area, Density, Pressure};
use hydrocyl_valves::orifice::Orifice;
use hydrocyl_xfactor::{x_factor, x_factor_numerical};
use std::hint::black_box;
use std::time::Instant;

/// Median wall time per call \[ns\] of `f`, which performs `calls` calls.
fn ns_per_call(calls: usize, mut f: impl FnMut() -> f64) -> f64 {
    // warm up, then the median of 9 repetitions
    black_box(f());
    let mut samples: Vec<f64> = (0..9)
        .map(|_| {
            let t0 = Instant::now();
            black_box(f());
            t0.elapsed().as_secs_f64() * 1e9 / calls as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

fn orifice_typed_vs_raw() {
    let o = Orifice::new(0.625, Density::new(870.0));
    let coef = o.coefficient();
    let dpt = o.dp_transition.si();
    let n = 100_000;
    let ps: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let s = i as f64 / n as f64;
            (7.0e6 * s, 3.5e6 * (1.0 - s))
        })
        .collect();
    let raw = ns_per_call(n, || {
        ps.iter()
            .map(|&(u, d)| {
                let dp = black_box(u) - d;
                let r = if dp.abs() >= dpt {
                    dp.abs().sqrt() * dp.signum()
                } else {
                    let q = dp / dpt;
                    dp / dpt.sqrt() * (1.25 - 0.25 * q * q)
                };
                coef * 1.0e-5 * r
            })
            .sum()
    });
    let typed = ns_per_call(n, || {
        ps.iter()
            .map(|&(u, d)| {
                o.flow(
                    Area::new(1.0e-5),
                    Pressure::new(black_box(u)),
                    Pressure::new(d),
                )
                .si()
            })
            .sum()
    });
    println!(
        "orifice flow, typed ports vs raw f64:      typed {typed:8.2} ns  raw {raw:8.2} ns  ratio typed/raw {:.3}",
        typed / raw
    );
}

fn xfactor_analytical_vs_brent() {
    let n = 10_000;
    let pts: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let g = 1.01 + 4.99 * ((i * 7919) % n) as f64 / n as f64;
            let t = -0.999 + 1.998 * i as f64 / n as f64;
            (g, t)
        })
        .collect();
    let ana = ns_per_call(n, || {
        pts.iter().map(|&(g, t)| x_factor(black_box(g), t)).sum()
    });
    let num = ns_per_call(n, || {
        pts.iter()
            .map(|&(g, t)| x_factor_numerical(black_box(g), t, 1e-12))
            .sum()
    });
    println!(
        "X factor, analytical vs Brent (tol 1e-12): analytical {ana:8.2} ns  Brent {num:8.2} ns  speed-up {:.1}x",
        num / ana
    );
}

/// Best-of-`reps` wall time \[s\] of `f`, which returns its own measured
/// solve time (so that set-up is not counted), or the first error.
fn best_of(reps: usize, mut f: impl FnMut() -> Result<f64, String>) -> Result<f64, String> {
    let mut best = f64::INFINITY;
    for _ in 0..reps {
        best = best.min(f()?);
    }
    Ok(best)
}

/// The chapter-3 square wave (6 s simulated) on each actuator formulation:
/// simulated seconds per wall second, and each formulation's time as a ratio
/// to the fundamental model's in the same run.
fn valve_rig_real_time() -> Result<(), String> {
    use hydrocyl_studies::chapter3;
    use hydrocyl_system::run::RunOptions;
    use hydrocyl_system::valve_rig::Formulation;
    let case = chapter3::square_wave().map_err(|e| e.to_string())?;
    let span = case.times[case.times.len() - 1] - case.times[0];
    let mut walls = Vec::new();
    for f in Formulation::ALL {
        let mut rig = case.rig.clone();
        rig.cylinder.formulation = f;
        let wall = best_of(5, || {
            rig.simulate(case.command.clone(), &case.times, &RunOptions::dp45())
                .map(|r| r.wall.as_secs_f64())
                .map_err(|e| e.to_string())
        })?;
        walls.push((f, wall));
    }
    let reference = walls
        .iter()
        .find(|(f, _)| *f == Formulation::Fundamental)
        .map_or(f64::NAN, |w| w.1);
    for (f, wall) in walls {
        println!(
            "valve rig square wave, {:<23} DP45: {:7.1}x real time ({:.2} ms for {span} s)  time / fundamental {:.2}",
            f.name(),
            span / wall,
            wall * 1e3,
            wall / reference
        );
    }
    Ok(())
}

/// `hydrocyl diagnose` on a 12 s, 1 kHz `leaney-moog` record with a planted
/// internal leak (the speed case), against the reference of one
/// simulation of the same record (generating it): the ratio says how many
/// record simulations a diagnosis costs, the wall time is printed beside the
/// goal (<= 2 s on the development machine, issue 19).
fn valve_diagnose_time() -> Result<(), String> {
    use hydrocyl_identify::catalog::EffectId;
    use hydrocyl_identify::diagnose::DiagnoseOptions;
    use hydrocyl_identify::synth;
    use hydrocyl_identify::valve::{diagnose_valve, set};
    use hydrocyl_system::valve_rig::ValveRig;
    let mut truth = ValveRig::leaney_moog();
    let (p, v) = synth::valve_planted(EffectId::InternalLeakage)
        .ok_or("no planted internal_leakage value")?;
    set(&mut truth, EffectId::InternalLeakage, p, v);
    let mut rec = None;
    let simulate = best_of(3, || {
        let t0 = Instant::now();
        rec = Some(synth::valve_record(&truth, 12_000, 1e-3, 9)?);
        Ok(t0.elapsed().as_secs_f64())
    })?;
    let rec = rec.ok_or("no record")?;
    let t0 = Instant::now();
    let report = diagnose_valve(
        &ValveRig::leaney_moog(),
        &rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .map_err(|e| e.to_string())?;
    let diagnose = t0.elapsed().as_secs_f64();
    let found = report
        .effects_added
        .first()
        .map_or("nothing", |e| e.id.as_str())
        .to_string();
    println!(
        "diagnose, valve rig, 12 s at 1 kHz:                   {diagnose:7.2} s wall in-process ({}) = {:.0} record simulations ({:.0} ms each); found {found}",
        crate::bench_solve::profile(),
        diagnose / simulate,
        simulate * 1e3
    );
    diagnose_process(&rec)
}

/// Runs of `hydrocyl diagnose` per binary in [`diagnose_process`].
const DIAGNOSE_RUNS: usize = 5;

/// `hydrocyl diagnose` as a user runs it — the release binary
/// ([`crate::bench_solve::hydrocyl_binaries`]), the record read from a CSV
/// file, the report written — on `rec` with the `leaney-moog` preset:
/// median and fastest of [`DIAGNOSE_RUNS`] runs, beside the goal.
fn diagnose_process(rec: &hydrocyl_identify::data::Record) -> Result<(), String> {
    use hydrocyl_identify::data::{write_csv, Signal};
    let (bins, profile) = crate::bench_solve::hydrocyl_binaries()?;
    let dir = std::env::temp_dir().join(format!("hydrocyl-bench-diagnose-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let data = dir.join("record.csv");
    let columns: Vec<(Signal, &[f64])> = rec
        .signals
        .iter()
        .map(|(s, v)| (*s, v.as_slice()))
        .collect();
    write_csv(&data, &rec.time, &columns).map_err(|e| e.to_string())?;
    let report = dir.join("report.json");
    let (data_s, report_s) = (data.display().to_string(), report.display().to_string());
    let args = [
        "diagnose",
        "--rig",
        "leaney-moog",
        "--data",
        &data_s,
        "--report",
        &report_s,
        "--quiet",
    ];
    let walls = crate::bench_solve::time_processes(&bins, &args, DIAGNOSE_RUNS, None);
    let _ = std::fs::remove_dir_all(&dir);
    for (b, (median, fastest)) in walls?.into_iter().enumerate() {
        println!(
            "diagnose, whole process ({profile}{}): median {median:.2} s, fastest {fastest:.2} s of {DIAGNOSE_RUNS} (goal <= 2 s)",
            if bins.len() > 1 { format!(", {}", bins[b].display()) } else { String::new() },
        );
    }
    Ok(())
}

/// Runs this bench again in the release build (`cargo run --release -p
/// xtask -- bench` with this run's arguments): what users run is timed, not
/// the dev build with its debug assertions. `false` when it could not run
/// or failed.
pub fn in_release() -> bool {
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap_or_else(|| std::path::Path::new("."));
    // everything after `bench`
    let args: Vec<String> = std::env::args()
        .skip_while(|a| a != "bench")
        .skip(1)
        .collect();
    eprintln!("cargo xtask bench: timing the release build (`--dev` times the dev build)");
    match std::process::Command::new(cargo)
        .args([
            "run",
            "--release",
            "--quiet",
            "-p",
            "xtask",
            "--bin",
            "xtask",
            "--",
            "bench",
        ])
        .args(&args)
        .current_dir(root)
        .status()
    {
        Ok(s) => s.success(),
        Err(e) => {
            eprintln!("cargo xtask bench: cannot run the release build: {e}");
            false
        }
    }
}

/// Runs the benchmarks; returns `false` only when a benchmark could not run
/// (a benchmark has no pass/fail threshold).
/// A section of the bench: prints its rows, or says why it could not run.
pub type Section = fn() -> Result<(), String>;

/// `only`: run only the sections whose name contains it; `keep`: the
/// folder where the whole-process row writes and keeps its command files.
pub fn run(only: Option<&str>, keep: Option<&std::path::Path>) -> bool {
    println!("cargo xtask bench: ratios against a reference in the same run on this machine");
    let wanted = |name: &str| only.is_none_or(|o| name.contains(o));
    if wanted("orifice") {
        orifice_typed_vs_raw();
    }
    if wanted("xfactor") {
        xfactor_analytical_vs_brent();
    }
    let mut ok = true;
    let sections: [(&str, Section); 2] = [
        ("valve rig", valve_rig_real_time),
        ("diagnose", valve_diagnose_time),
    ];
    for (name, f) in sections {
        if !wanted(name) {
            continue;
        }
        if let Err(e) = f() {
            eprintln!("cargo xtask bench: {name}: {e}");
            ok = false;
        }
    }
    ok &= crate::bench_solve::run(&wanted, keep);
    ok
}
