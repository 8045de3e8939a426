//! `cargo xtask bench`, the user-facing speed of issue 19: the valve rig's
//! work-precision table, the cost per step against the simulated time, the
//! automatic solver choice on the hybrid rig and the whole `hydrocyl
//! simulate` process (CSV reading and writing: [`crate::bench_csv`]). Every ratio is against a reference run in the same run.

use hydrocyl_identify::plaincsv::write_columns;
use hydrocyl_integrators::Method;
use hydrocyl_studies::chapter7::{Chapter7Test, Load, Shape};
use hydrocyl_system::run::{nrmse, Run, RunOptions, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;
use hydrocyl_system::valve_rig::ValveRig;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

/// The case: `leaney-moog`, open-loop square ±90 mm/s (period 2 s)
/// as a 1 kHz command table, output at the same 1 kHz times.
pub(crate) struct SquareCase {
    rig: ValveRig,
    times: Vec<f64>,
    pub(crate) command: Signal,
}

pub(crate) fn square_case(t_end: f64) -> Result<SquareCase, String> {
    let rig = ValveRig::leaney_moog();
    let (bias, amplitude) = rig.open_loop_square(0.09).map_err(|e| e.to_string())?;
    let n = (t_end * 1e3).round() as usize;
    let times: Vec<f64> = (0..=n).map(|k| k as f64 * 1e-3).collect();
    let values = times
        .iter()
        .map(|t| {
            if (t / 2.0).rem_euclid(1.0) < 0.5 {
                bias + amplitude
            } else {
                bias - amplitude
            }
        })
        .collect();
    let command = Signal::table(times.clone(), values).map_err(|e| e.to_string())?;
    Ok(SquareCase {
        rig,
        times,
        command,
    })
}

impl SquareCase {
    pub(crate) fn run(&self, solver: Solver, rtol: f64) -> Result<Run, String> {
        let opts = RunOptions {
            solver,
            rtol,
            ..RunOptions::default()
        };
        self.rig
            .simulate(self.command.clone(), &self.times, &opts)
            .map_err(|e| e.to_string())
    }

    /// The fastest of `reps` runs (the solve's own wall time).
    fn best(&self, solver: Solver, rtol: f64, reps: usize) -> Result<Run, String> {
        let mut best: Option<Run> = None;
        for _ in 0..reps {
            let r = self.run(solver, rtol)?;
            if best.as_ref().is_none_or(|b| r.wall < b.wall) {
                best = Some(r);
            }
        }
        best.ok_or_else(|| "no run".into())
    }
}

/// The build profile this binary was compiled in, for the bench headers
/// (`cargo xtask bench` runs the release build, the one users run;
/// `cargo xtask bench --dev` this dev build).
pub(crate) fn profile() -> &'static str {
    if cfg!(debug_assertions) {
        "dev profile"
    } else {
        "release profile"
    }
}

/// The tolerances of the work-precision table: decades from 1e-3 to 1e-9,
/// with the half decades between 1e-3 and 1e-6 where the velocity target
/// NRMSE 1e-4 falls.
const WORK_PRECISION_RTOLS: [f64; 10] =
    [1e-3, 3e-4, 1e-4, 3e-5, 1e-5, 3e-6, 1e-6, 1e-7, 1e-8, 1e-9];

/// Work-precision table of the valve rig, 10 s: wall time, steps and the
/// NRMSE of every channel against a DP45 run at rtol 1e-11 in this run.
fn work_precision() -> Result<(), String> {
    let case = square_case(10.0)?;
    let reference = case.run(Solver::Dp45, 1e-11)?;
    let names: Vec<&str> = reference
        .channels
        .iter()
        .map(|c| c.name.as_str())
        .filter(|n| *n != "command" && *n != "ps")
        .collect();
    println!(
        "valve rig work-precision ({}), leaney-moog 10 s open-loop square, 1 kHz command and output; ms = the solve in-process; NRMSE against DP45 at rtol 1e-11 ({} steps):",
        profile(),
        reference.stats.steps
    );
    let mut head = format!(
        "  {:<10} {:>6} {:>8} {:>7} {:>6} {:>6} {:>6}",
        "solver", "rtol", "ms", "steps", "rhs", "stiff", "bs32"
    );
    for n in &names {
        head.push_str(&format!(" {:>9}", truncate(n, 9)));
    }
    println!("{head}");
    // every run's (solver, rtol, ms, velocity NRMSE), in table order
    let mut rows: Vec<(Solver, f64, f64, f64)> = Vec::new();
    for solver in [Solver::Auto, Solver::Dp45, Solver::Rosenbrock] {
        for rtol in WORK_PRECISION_RTOLS {
            let reps = if rtol >= 1e-7 { 15 } else { 3 };
            let r = case.best(solver, rtol, reps)?;
            let ms = r.wall.as_secs_f64() * 1e3;
            let mut line = format!(
                "  {:<10} {:>6.0e} {:>8.3} {:>7} {:>6} {:>6} {:>6}",
                solver.name(),
                rtol,
                ms,
                r.stats.steps,
                r.stats.rhs_evals,
                r.stats.stiff_steps,
                r.stats.low_order_steps
            );
            for n in &names {
                let e = match (r.channel(n), reference.channel(n)) {
                    (Some(a), Some(b)) => nrmse(a, b),
                    _ => f64::NAN,
                };
                line.push_str(&format!(" {e:>9.1e}"));
            }
            println!("{line}");
            let v = nrmse(
                r.channel("velocity").unwrap_or(&[]),
                reference.channel("velocity").unwrap_or(&[]),
            );
            rows.push((solver, rtol, ms, v));
        }
    }
    print_goal(&rows);
    Ok(())
}

/// The velocity NRMSE goal of the work-precision table.
const NRMSE_GOAL: f64 = 1e-4;

/// For each solver, the fastest run at velocity NRMSE ≤ [`NRMSE_GOAL`], with
/// its margin (NRMSE / goal) and how its neighbouring tolerances in the table
/// fare: a run that meets the goal between two that miss it met it by luck
/// of the step sequence (the error at the valve's corners is not smooth in
/// rtol), not by its tolerance.
fn print_goal(rows: &[(Solver, f64, f64, f64)]) {
    let mut any = false;
    for solver in [Solver::Auto, Solver::Dp45, Solver::Rosenbrock] {
        let runs: Vec<_> = rows.iter().filter(|r| r.0 == solver).collect();
        let best = (0..runs.len())
            .filter(|&i| runs[i].3 <= NRMSE_GOAL)
            .min_by(|&a, &b| runs[a].2.total_cmp(&runs[b].2));
        let Some(i) = best else { continue };
        any = true;
        let (_, rtol, ms, v) = *runs[i];
        let side = |j: Option<usize>, what: &str| match j.and_then(|j| runs.get(j)) {
            Some(r) => format!(
                "{what} rtol {:.0e} {:.1e} {}",
                r.1,
                r.3,
                if r.3 <= NRMSE_GOAL {
                    "meets it"
                } else {
                    "misses"
                }
            ),
            None => format!("no {what} rtol"),
        };
        println!(
            "  fastest {} run at velocity NRMSE <= 1e-4: {ms:.3} ms (rtol {rtol:.0e}, NRMSE {v:.2e} = {:.2} of the goal; {}, {}; goal <= 1 ms; {})",
            solver.name(),
            v / NRMSE_GOAL,
            side(i.checked_sub(1), "looser"),
            side(Some(i + 1), "tighter"),
            profile()
        );
    }
    if !any {
        println!("  no run reached velocity NRMSE <= 1e-4");
    }
}

fn truncate(s: &str, n: usize) -> &str {
    &s[..s.len().min(n)]
}

/// Minor page faults of this process so far (`/proc/self/stat`, field 10),
/// `None` where there is no procfs.
fn minor_faults() -> Option<u64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // the command name may hold spaces: count fields after its closing ')'
    let rest = &stat[stat.rfind(')')? + 2..];
    rest.split(' ').nth(7)?.parse().ok()
}

/// The cost of first touching fresh memory on this machine \[µs per 4 KiB
/// page\]: the fastest of 3 writes of one byte per page into 64 MiB just
/// allocated (the kernel maps and zeroes each page at its first write).
fn first_touch_us() -> f64 {
    const BYTES: usize = 64 << 20;
    let mut best = f64::INFINITY;
    for _ in 0..3 {
        let t0 = Instant::now();
        let mut v = vec![0u8; BYTES];
        for k in (0..BYTES).step_by(4096) {
            v[k] = 1;
        }
        std::hint::black_box(&v);
        best = best.min(t0.elapsed().as_secs_f64() * 1e6 / (BYTES / 4096) as f64);
    }
    best
}

/// Cost per step (solve wall / attempted steps) in records of 1, 10, 100
/// and 1000 s, DP45 at rtol 1e-5 on the 1 kHz square with 1 kHz output. Each
/// length runs 1000 simulated seconds in all (1000 runs of 1 s, ..., one of
/// 1000 s), so every row does the same work; the ratio to the 1 s cost says
/// whether anything grows with the record. Two paths, each its own 1 s
/// reference:
/// - **streamed** (`Simulation::run_streaming_states` in 256-row blocks, the path of
///   `hydrocyl simulate`'s solve thread): the outputs go to a sink block by
///   block in reused buffers (here one reused copy, as the CLI's writer
///   queue), so the memory does not grow with the record; this is the row
///   the goal (<= 1.10) is for;
/// - **in memory** (`run`: every output state kept, 72 MB at 1000 s): the
///   page faults per step show the kernel's first touch of that memory,
///   which a long record cannot reuse from an earlier run (the faults of
///   the whole run, the channels built after the solve included; beside
///   them, what they cost at most at this machine's [`first_touch_us`]).
///   They are inside the timed solve, as they are for a caller of `run`.
///   The streamed rows count the faults of the solve alone.
fn cost_per_step() -> Result<(), String> {
    println!("valve rig cost per step, DP45 rtol 1e-5, 1 kHz command and output, 1000 s simulated per row (wall of the solve / attempted steps; the fastest of 3 rounds, the lengths interleaved):");
    let fault = first_touch_us();
    let opts = RunOptions {
        solver: Solver::Dp45,
        rtol: 1e-5,
        ..RunOptions::default()
    };
    let lengths = [1.0, 10.0, 100.0, 1000.0];
    let cases = lengths
        .iter()
        .map(|&t| square_case(t))
        .collect::<Result<Vec<_>, _>>()?;
    let mut kept = Vec::new();
    // one run: its solve's wall, attempted steps and page faults (streamed:
    // the solve's alone, the circuit's copy of the command table is made
    // before; in memory: the whole run's)
    let mut one =
        |case: &SquareCase, streamed: bool| -> Result<(f64, usize, Option<u64>), String> {
            let f0;
            let r = if streamed {
                let c = case
                    .rig
                    .circuit(case.command.clone())
                    .map_err(|e| e.to_string())?;
                let mut sim = Simulation::of_circuit(c).options(opts.clone());
                f0 = minor_faults();
                sim.run_streaming_states(&case.times, 256, &mut |t, x| {
                    kept.clear();
                    kept.extend_from_slice(t);
                    kept.extend_from_slice(x);
                    Ok(())
                })
                .map_err(|e| e.to_string())?
            } else {
                f0 = minor_faults();
                case.run(Solver::Dp45, 1e-5)?
            };
            let faults = minor_faults().zip(f0).map(|(b, a)| b - a);
            Ok((
                r.wall.as_secs_f64(),
                r.stats.steps + r.stats.rejected,
                faults,
            ))
        };
    for streamed in [true, false] {
        println!(
            "  {}",
            if streamed {
                "streamed (Simulation::run_streaming_states, 256-row blocks in reused buffers: hydrocyl simulate's solve thread):"
            } else {
                "in memory (run: all outputs kept, the states grow with the record):"
            }
        );
        // per length: (fastest wall, steps, faults of that round)
        let mut rows = vec![(f64::INFINITY, 0usize, Some(0u64)); lengths.len()];
        for _ in 0..3 {
            for (case, row) in cases.iter().zip(rows.iter_mut()) {
                let t_end = case.times[case.times.len() - 1];
                let runs = (1000.0 / t_end).round() as usize;
                one(case, streamed)?; // warm-up
                let (mut wall, mut steps, mut faulted) = (0.0, 0usize, Some(0u64));
                for _ in 0..runs {
                    let (w, n, f) = one(case, streamed)?;
                    wall += w;
                    steps += n;
                    faulted = faulted.zip(f).map(|(a, b)| a + b);
                }
                if wall < row.0 {
                    *row = (wall, steps, faulted);
                }
            }
        }
        let base = rows[0].0 / rows[0].1 as f64;
        for (t_end, (wall, steps, faulted)) in lengths.iter().zip(rows) {
            let runs = (1000.0 / t_end) as usize;
            let faults = match faulted {
                Some(n) => {
                    let per_step = n as f64 / steps as f64;
                    format!(
                        "{per_step:.3} (at most {:.3} µs/step at {fault:.2} µs each)",
                        per_step * fault
                    )
                }
                None => "?".into(),
            };
            let us = wall * 1e6 / steps as f64;
            println!(
                "    {t_end:>6.0} s x {runs:>4}: {:>8.1} ms, {steps:>7} steps, {us:.3} µs/step, / 1 s {:.2}{}; page faults/step {faults}",
                wall * 1e3,
                us / (base * 1e6),
                if streamed { " (goal <= 1.10)" } else { "" }
            );
        }
    }
    Ok(())
}

/// The chapter-7 0.2 Hz square of the hybrid rig (15 s) with each method:
/// the automatic choice against the best fixed one.
fn hybrid_solver_choice() -> Result<(), String> {
    let test = Chapter7Test::new(Shape::Square, Load::None);
    let mut rows = Vec::new();
    for (name, method, reps) in [
        ("auto", Method::Auto, 3),
        ("rosenbrock", Method::Rosenbrock, 3),
        ("dp45", Method::DormandPrince45, 1),
    ] {
        let mut best = f64::INFINITY;
        let mut outcome = Err(String::new());
        for _ in 0..reps {
            let t0 = Instant::now();
            outcome = test
                .run_with(method)
                .map(|r| r.stats)
                .map_err(|e| e.to_string());
            best = best.min(t0.elapsed().as_secs_f64());
        }
        rows.push((name, best, outcome));
    }
    let fixed = rows[1..]
        .iter()
        .filter(|r| r.2.is_ok())
        .map(|r| r.1)
        .fold(f64::INFINITY, f64::min);
    println!("hybrid rig chapter-7 square (15 s), each method (incl. measuring the phenomena):");
    for (name, wall, outcome) in &rows {
        match outcome {
            Ok(s) => println!(
                "  {name:<10} {:>8.1} ms  {:>7} steps  {:<45}  / best fixed {:.2}{}",
                wall * 1e3,
                s.steps,
                s.choice(),
                wall / fixed,
                if *name == "auto" {
                    " (goal <= 1.5)"
                } else {
                    ""
                }
            ),
            Err(e) => println!("  {name:<10} {:>8.1} ms  fails: {e}", wall * 1e3),
        }
    }
    Ok(())
}

/// The `hydrocyl` binaries to time and the profile they were built with:
/// `$HYDROCYL_BIN` ("given"; several paths separated by `:` are timed
/// interleaved, run by run, to compare builds in one run), else the release
/// build, brought up to date now (`cargo build --release -p hydrocyl-cli`; a
/// no-op when it is): a user runs a release build (`cargo install`), so the
/// whole process is timed on one.
pub(crate) fn hydrocyl_binaries() -> Result<(Vec<PathBuf>, &'static str), String> {
    if let Ok(p) = std::env::var("HYDROCYL_BIN") {
        let bins: Vec<PathBuf> = p
            .split(':')
            .filter(|s| !s.is_empty())
            .map(PathBuf::from)
            .collect();
        if bins.is_empty() {
            return Err("HYDROCYL_BIN names no binary".into());
        }
        return Ok((bins, "given by HYDROCYL_BIN"));
    }
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .ok_or("no workspace root")?;
    let cargo = std::env::var("CARGO").unwrap_or_else(|_| "cargo".into());
    let st = Command::new(cargo)
        .args([
            "build",
            "--release",
            "--quiet",
            "-p",
            "hydrocyl-cli",
            "--bin",
            "hydrocyl",
        ])
        .current_dir(root)
        .status()
        .map_err(|e| e.to_string())?;
    if !st.success() {
        return Err("cargo build --release -p hydrocyl-cli failed".into());
    }
    let target = std::env::var("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|_| root.join("target"));
    Ok((
        vec![target.join("release").join("hydrocyl")],
        "release profile",
    ))
}

/// Wall times of `runs` runs of each of `bins` with `args` \[s\], the
/// binaries interleaved run by run (each run's order rotated, so that the
/// machine's load falls on each alike): per binary, (median, fastest).
/// `synced`: a file flushed to the disk before each run (the output a run
/// replaces, as a rerun long after the last finds it: deleting it then
/// frees its blocks), not only in the page cache as after the run before.
pub(crate) fn time_processes(
    bins: &[PathBuf],
    args: &[&str],
    runs: usize,
    synced: Option<&Path>,
) -> Result<Vec<(f64, f64)>, String> {
    let mut v = vec![Vec::with_capacity(runs); bins.len()];
    for r in 0..runs {
        for i in 0..bins.len() {
            let b = (i + r) % bins.len();
            if let Some(p) = synced {
                if let Ok(f) = std::fs::File::open(p) {
                    f.sync_all().map_err(|e| e.to_string())?;
                }
            }
            let t0 = Instant::now();
            let out = Command::new(&bins[b])
                .args(args)
                .output()
                .map_err(|e| e.to_string())?;
            v[b].push(t0.elapsed().as_secs_f64());
            if !out.status.success() {
                return Err(String::from_utf8_lossy(&out.stderr).into_owned());
            }
        }
    }
    Ok(v.into_iter()
        .map(|mut v| {
            v.sort_by(f64::total_cmp);
            (v[v.len() / 2], v[0])
        })
        .collect())
}

/// Runs of each binary per row of [`whole_process`].
const PROCESS_RUNS: usize = 21;

/// The whole `hydrocyl simulate` process on the 1 kHz 10 s and 100 s
/// command files (1 kHz output), against the process doing nothing
/// (`hydrocyl --version`): median and fastest of [`PROCESS_RUNS`] runs.
/// Several binaries ([`hydrocyl_binaries`]) are timed interleaved, run by
/// run (each run's order rotated), so that the machine's load falls on each
/// alike. Each run replaces
/// the output of the one before (still in the page cache); the 10 s default
/// is also timed over an output already on the disk (synced before each
/// run), as a rerun long after the last finds it: replacing it then frees
/// its blocks. The command files
/// go to `keep` and stay there when it is given (to profile the process on
/// them), else to a temporary folder removed at the end.
fn whole_process(keep: Option<&Path>) -> Result<(), String> {
    let (bins, profile) = hydrocyl_binaries()?;
    let dir = keep.map_or_else(
        || std::env::temp_dir().join(format!("hydrocyl-bench-{}", std::process::id())),
        Path::to_path_buf,
    );
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    // `synced`: see `time_processes`
    let time_with = |args: &[&str], synced: Option<&Path>| {
        time_processes(&bins, args, PROCESS_RUNS, synced).map(|v| {
            v.into_iter()
                .map(|(m, f)| (m * 1e3, f * 1e3))
                .collect::<Vec<_>>()
        })
    };
    let time = |args: &[&str]| time_with(args, None);
    // the binary's label on its rows when several are compared
    let label = |b: usize| {
        if bins.len() > 1 {
            format!(" [{}]", bins[b].display())
        } else {
            String::new()
        }
    };
    println!("hydrocyl simulate, whole process ({profile}):");
    for (b, (idle, idle_min)) in time(&["--version"])?.into_iter().enumerate() {
        println!(
            "  {}: process start {idle:.2} ms (fastest {idle_min:.2})",
            bins[b].display()
        );
    }
    for t_end in [10.0, 100.0] {
        let case = square_case(t_end)?;
        let Signal::Table { time_s, value } = &case.command else {
            return Err("not a table".into());
        };
        let cmd = dir.join(format!("cmd{t_end}.csv"));
        std::fs::write(&cmd, write_columns(&["time", "command"], &[time_s, value]))
            .map_err(|e| e.to_string())?;
        let out = dir.join("out.csv");
        let (cmd_s, out_s) = (cmd.display().to_string(), out.display().to_string());
        for (name, extra) in [
            ("default (auto, rtol 1e-6)", None),
            (
                "dp45 rtol 1e-5",
                Some(["--solver", "dp45", "--rtol", "1e-5"]),
            ),
        ] {
            let mut args = vec![
                "simulate",
                "--rig",
                "leaney-moog",
                "--command",
                &cmd_s,
                "--out",
                &out_s,
            ];
            if let Some(e) = extra {
                args.extend(e);
            }
            for (b, (med, min)) in time(&args)?.into_iter().enumerate() {
                println!(
                    "  {t_end:>4.0} s, 1 kHz in and out, {name:<26}: median {med:7.2} ms, fastest {min:7.2} ms{}{}",
                    if t_end == 10.0 { " (goal < 6 ms)" } else { "" },
                    label(b)
                );
            }
            if t_end == 10.0 && extra.is_none() {
                for (b, (med, min)) in time_with(&args, Some(&out))?.into_iter().enumerate() {
                    println!(
                        "  {t_end:>4.0} s, 1 kHz in and out, {:<26}: median {med:7.2} ms, fastest {min:7.2} ms{}",
                        "default, output on disk",
                        label(b)
                    );
                }
            }
        }
    }
    if keep.is_none() {
        let _ = std::fs::remove_dir_all(&dir);
    }
    Ok(())
}

/// Runs the issue-19 benchmarks whose name is `wanted`; `false` when one
/// could not run. `keep`: see [`whole_process`].
pub fn run(wanted: &dyn Fn(&str) -> bool, keep: Option<&Path>) -> bool {
    let mut ok = true;
    let sections: [(&str, crate::bench::Section); 5] = [
        ("csv", crate::bench_csv::csv_per_row),
        ("csv record", crate::bench_record::record_per_row),
        ("cost per step", cost_per_step),
        ("work-precision", work_precision),
        ("hybrid solver choice", hybrid_solver_choice),
    ];
    // lazily, in this order: each section prints as it runs
    let process = wanted("whole process")
        .then_some("whole process")
        .into_iter()
        .map(|name| (name, whole_process(keep)));
    let ran = sections
        .into_iter()
        .filter(|(name, _)| wanted(name))
        .map(|(name, f)| (name, f()))
        .chain(process);
    for (name, r) in ran {
        if let Err(e) = r {
            eprintln!("cargo xtask bench: {name}: {e}");
            ok = false;
        }
    }
    ok
}
