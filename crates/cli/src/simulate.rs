//! `hydrocyl simulate`: simulate a rig on a command signal and write the
//! measured-data CSV format.
//!
//! ```text
//! hydrocyl simulate --rig leaney-moog --command cmd.csv --out run.csv \
//!     [--set load.mass=50] [--set cylinder.initial.p1=2e6] \
//!     [--solver auto|dp45|rosenbrock|rk4] [--rtol 1e-6] [--print-rig] [--fsync]
//! ```
//!
//! The command file is CSV with a `time` column (`time`, `time [s]` or
//! `time [ms]`) and a `command` column (the normalised spool demand of a
//! valve rig, the drive voltage of a pump rig); other columns are ignored.
//! The output has one row per command sample: `time, command, position,
//! velocity, p1, p2`, then the rig's other outputs (`ps`, `spool`, `p_le`,
//! ...), all SI without unit suffixes. The friction-bench presets
//! (`tudelft-seal-25`, `tudelft-seal-257`, `emps`) are netlists whose drive
//! imposes the rod's velocity: their `command` column is that velocity
//! \[m·s⁻¹\] and their output has the load-cell `force`. A `friction-bench`
//! rig *file* (the identification format of `diagnose`) is driven by a
//! measured record's motion instead: see [`crate::bench_sim`]. A `hybrid-variant` rig file
//! (chapter 8's circuit improvements) runs on its base rig with the variant's
//! components swapped in. It is written to a temporary file in
//! the output's folder and renamed into place, so a failed run leaves no file
//! (`--fsync` also flushes it to the disk first; without it the operating
//! system writes it back when it likes, as for any ordinary file).

use crate::error::CliError;
use hydrocyl_energy::variant::{self, HybridVariant};
use hydrocyl_identify::bench::{self, FrictionBench};
use hydrocyl_identify::plaincsv::{run_columns, write_columns_in_parts, PlainCsv};
use hydrocyl_system::hybrid::WangHybrid;
use hydrocyl_system::rig;
use hydrocyl_system::run::{self as runner, Run, RunOptions, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::Circuit;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Arguments of `hydrocyl simulate`.
#[derive(clap::Args)]
pub struct Args {
    /// A preset name (leaney-moog, ...) or a rig JSON file.
    #[arg(long)]
    rig: String,
    /// CSV with `time` and `command` columns; the output is sampled at its times.
    #[arg(long, required_unless_present = "print_rig")]
    command: Option<PathBuf>,
    /// Output CSV (measured-data format).
    #[arg(long, required_unless_present = "print_rig")]
    out: Option<PathBuf>,
    /// Override a rig parameter by its JSON path, e.g. `--set load.mass_kg=50`
    /// or `--set initial.p1=2.5e6` (repeatable).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    set: Vec<String>,
    /// Integration method: auto (default: dp45 while the run is not stiff,
    /// rosenbrock while it is), dp45, rosenbrock or rk4.
    #[arg(long, default_value = "auto")]
    solver: String,
    /// Relative tolerance of the adaptive methods.
    #[arg(long, default_value_t = 1e-6)]
    rtol: f64,
    /// Fixed step of rk4 \[s\].
    #[arg(long, default_value_t = 2e-5)]
    rk4_step: f64,
    /// Print the rig (after --set) as JSON and exit.
    #[arg(long)]
    print_rig: bool,
    /// Flush the output to the disk (fsync) before it is renamed into place.
    #[arg(long)]
    fsync: bool,
}

/// The `time` column (index, factor to seconds) and the `command` column
/// among `headers`.
fn command_columns<'a>(
    file: &str,
    headers: impl Iterator<Item = &'a str>,
) -> Result<(usize, f64, usize), CliError> {
    let mut time_col = None;
    let mut cmd_col = None;
    for (i, h) in headers.enumerate() {
        let (name, unit) = match h.find('[') {
            Some(o) if h.ends_with(']') => (h[..o].trim(), Some(h[o + 1..h.len() - 1].trim())),
            _ => (h.trim(), None),
        };
        match name {
            "time" => {
                let f = match unit {
                    None | Some("s") => 1.0,
                    Some("ms") => 1e-3,
                    Some(u) => {
                        return Err(CliError::Input(format!(
                            "{file}: column `{h}`: unknown time unit `{u}` (use s or ms)"
                        )))
                    }
                };
                time_col = Some((i, f));
            }
            "command" => cmd_col = Some(i),
            _ => {}
        }
    }
    let (ti, tf) = time_col.ok_or_else(|| CliError::Input(format!("{file}: no `time` column")))?;
    let ci = cmd_col.ok_or_else(|| CliError::Input(format!("{file}: no `command` column")))?;
    Ok((ti, tf, ci))
}

/// The fast path of [`read_command`] for plain numeric CSV
/// ([`hydrocyl_identify::plaincsv`]); `None` sends the text to the full
/// reader, which also reports every error.
fn read_command_plain(file: &str, text: &str) -> Option<(Vec<f64>, Vec<f64>)> {
    let csv = PlainCsv::new(text)?;
    let (ti, tf, ci) = command_columns(file, csv.headers()).ok()?;
    let mut cols = csv.columns(&[ti, ci])?;
    let u = cols.pop()?;
    let mut t = cols.pop()?;
    if tf != 1.0 {
        t.iter_mut().for_each(|v| *v *= tf);
    }
    if t.len() < 2 || t.windows(2).any(|w| w[1] <= w[0]) {
        return None;
    }
    Some((t, u))
}

/// Reads the command CSV: `(time [s], command)`; errors name file, row and column.
pub fn read_command(path: &Path) -> Result<(Vec<f64>, Vec<f64>), CliError> {
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| CliError::Io {
        path: file.clone(),
        source,
    })?;
    if let Some(r) = read_command_plain(&file, &text) {
        return Ok(r);
    }
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers = rdr
        .headers()
        .map_err(|e| CliError::Input(format!("{file}: row 1: {e}")))?
        .clone();
    let (ti, tf, ci) = command_columns(&file, headers.iter())?;
    let (mut t, mut u) = (Vec::new(), Vec::new());
    for (k, rec) in rdr.records().enumerate() {
        let row = k + 2;
        let rec = rec.map_err(|e| CliError::Input(format!("{file}: row {row}: {e}")))?;
        let cell = |i: usize, col: &str| -> Result<f64, CliError> {
            let s = rec.get(i).unwrap_or("");
            let v: f64 = s.parse().map_err(|_| {
                CliError::Input(format!(
                    "{file}: row {row}, column `{col}`: `{s}` is not a number"
                ))
            })?;
            if !v.is_finite() {
                return Err(CliError::Input(format!(
                    "{file}: row {row}, column `{col}`: {v} is not finite"
                )));
            }
            Ok(v)
        };
        let tv = cell(ti, "time")? * tf;
        if let Some(&prev) = t.last() {
            if tv <= prev {
                return Err(CliError::Input(format!(
                    "{file}: row {row}, column `time`: {tv} s does not increase (previous {prev} s)"
                )));
            }
        }
        t.push(tv);
        u.push(cell(ci, "command")?);
    }
    if t.len() < 2 {
        return Err(CliError::Input(format!(
            "{file}: needs at least two samples, found {}",
            t.len()
        )));
    }
    Ok((t, u))
}

/// The run as CSV text in the measured-data format (shortest round-trip
/// numbers, [`hydrocyl_identify::plaincsv::write_columns`]), in consecutive
/// parts formatted in parallel on the machine's cores.
pub fn to_csv(run: &Run) -> Vec<Vec<u8>> {
    let (names, columns) = run_columns(run);
    // threads pay for themselves from a few thousand rows on
    let parts = if run.time.len() < 4096 {
        1
    } else {
        std::thread::available_parallelism().map_or(1, |n| n.get().min(8))
    };
    write_columns_in_parts(&names, &columns, parts)
}

/// Writes `parts` (one after the other) to `path` through a temporary file in
/// the same folder (renamed into place, so a failure leaves no half-written
/// file); with `fsync` the data is flushed to the disk before the rename.
fn write_atomic(path: &Path, parts: &[&[u8]], fsync: bool) -> Result<(), CliError> {
    let io = |source| CliError::Io {
        path: path.display().to_string(),
        source,
    };
    let name = path
        .file_name()
        .ok_or_else(|| CliError::Input(format!("{}: not a file name", path.display())))?;
    let tmp = path.with_file_name(format!(
        ".{}.tmp{}",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = std::fs::File::create(&tmp)
        .and_then(|mut f| {
            for p in parts {
                f.write_all(p)?;
            }
            if fsync {
                f.sync_all()?;
            }
            Ok(())
        })
        .and_then(|_| std::fs::rename(&tmp, path));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        return Err(io(e));
    }
    Ok(())
}

/// A `hybrid-variant` rig (`hydrocyl-energy`): the variant (after `--set`)
/// and its base rig, resolved relative to the variant file.
fn load_variant(
    spec: &str,
    value: &serde_json::Value,
) -> Result<(WangHybrid, HybridVariant), CliError> {
    let input = |e: hydrocyl_energy::EnergyError| CliError::Input(e.to_string());
    let v = HybridVariant::from_json(&value.to_string(), spec).map_err(input)?;
    let base = v.base_rig(Path::new(spec).parent()).map_err(input)?;
    Ok((base, v))
}

/// Simulates a circuit variant of the hybrid drive on `command` \[V\]. A
/// variant that sets the needle opening per speed gets the entry for the
/// command's peak speed, `K max(u_max / A1, −u_min / A2)` (K the pump's
/// flow gain), the speed the chapter-8 scenarios command.
fn simulate_variant(
    base: &WangHybrid,
    v: &HybridVariant,
    command: Signal,
    t: &[f64],
    opts: &RunOptions,
) -> Result<Run, CliError> {
    let mut r = base.clone();
    let (u_max, u_min) = match &command {
        Signal::Table { value, .. } => value
            .iter()
            .fold((0.0f64, 0.0f64), |(hi, lo), &u| (hi.max(u), lo.min(u))),
        _ => (0.0, 0.0),
    };
    let speed = r.pump.gain * (u_max / r.cylinder.area_1.si()).max(-u_min / r.cylinder.area_2.si());
    v.apply_to_rig(&mut r, Some(1e3 * speed));
    let build = |e: hydrocyl_system::BuildError| CliError::Input(format!("rig {}: {e}", v.name));
    let mut comps = r.components(command).map_err(build)?;
    v.swap_components(&mut comps);
    let mut c = Circuit::build(comps).map_err(build)?;
    let x0 = c.initial_state();
    c.reset(t.first().copied().unwrap_or(0.0), &x0);
    runner::run(&mut c, &x0, t, opts).map_err(|e| CliError::Input(format!("rig {}: {e}", v.name)))
}

/// `hydrocyl simulate` on a friction bench: the `--command` file carries the
/// imposed motion (see [`crate::bench_sim`]).
fn run_bench(args: &Args, value: &serde_json::Value) -> Result<(), CliError> {
    let bench = FrictionBench::from_json(&value.to_string())
        .map_err(|e| CliError::Input(format!("rig {}: {e}", args.rig)))?;
    if args.print_rig {
        let text = serde_json::to_string_pretty(value)
            .map_err(|e| CliError::Input(format!("rig: {e}")))?;
        println!("{text}");
        return Ok(());
    }
    let (Some(input), Some(out)) = (&args.command, &args.out) else {
        return Err(CliError::Input("--command and --out are required".into()));
    };
    let text = crate::bench_sim::simulate(&bench, input)?;
    write_atomic(out, &[text.as_bytes()], args.fsync)?;
    eprintln!(
        "hydrocyl: simulated the friction bench on {} samples of {}",
        text.lines().count() - 1,
        input.display()
    );
    Ok(())
}

/// Runs `hydrocyl simulate`.
pub fn run(args: Args) -> Result<(), CliError> {
    let rig_err = |e: rig::RigError| CliError::Input(e.to_string());
    let mut value = rig::load(&args.rig).map_err(rig_err)?;
    for s in &args.set {
        rig::apply_set(&mut value, s).map_err(rig_err)?;
    }
    let kind = value.get("kind").and_then(|k| k.as_str());
    if kind == Some(bench::KIND) {
        return run_bench(&args, &value);
    }
    let variant = if kind == Some(variant::KIND) {
        Some(load_variant(&args.rig, &value)?)
    } else {
        rig::check(&value).map_err(|e| rig_err(rig::at_line(e, &args.rig)))?;
        None
    };
    if args.print_rig {
        // a netlist is printed with every parameter written out (defaults
        // filled in), under the paths `--set` takes
        let shown = if kind == Some(hydrocyl_system::netlist::KIND) {
            hydrocyl_system::netlist::expanded(&value).map_err(rig_err)?
        } else {
            value.clone()
        };
        let text = serde_json::to_string_pretty(&shown)
            .map_err(|e| CliError::Input(format!("rig: {e}")))?;
        println!("{text}");
        return Ok(());
    }
    let solver = Solver::parse(&args.solver).ok_or_else(|| {
        CliError::Input(format!(
            "--solver: unknown method `{}` (use auto, dp45, rosenbrock or rk4)",
            args.solver
        ))
    })?;
    if !(args.rtol > 0.0 && args.rtol < 1.0) {
        return Err(CliError::Input(format!(
            "--rtol: {} is not in (0, 1)",
            args.rtol
        )));
    }
    if !(args.rk4_step > 0.0 && args.rk4_step.is_finite()) {
        return Err(CliError::Input(format!(
            "--rk4-step: {} is not positive",
            args.rk4_step
        )));
    }
    let (Some(cmd_path), Some(out)) = (args.command, args.out) else {
        return Err(CliError::Input("--command and --out are required".into()));
    };
    let (t, u) = read_command(&cmd_path)?;
    let signal = Signal::table(t.clone(), u)
        .map_err(|e| CliError::Input(format!("{}: {e}", cmd_path.display())))?;
    let opts = RunOptions {
        solver,
        rtol: args.rtol,
        rk4_step: args.rk4_step,
        ..RunOptions::default()
    };
    let run = match variant {
        None => rig::simulate(&value, signal, &t, &opts).map_err(rig_err)?,
        Some((base, v)) => simulate_variant(&base, &v, signal, &t, &opts)?,
    };
    let parts = to_csv(&run);
    let parts: Vec<&[u8]> = parts.iter().map(Vec::as_slice).collect();
    write_atomic(&out, &parts, args.fsync)?;
    let cav = run.cavitation_entries();
    eprintln!(
        "hydrocyl: simulated {:.4} s in {:.3} s ({} {}: {} steps, {} rejected, {} rhs); {}",
        t[t.len() - 1] - t[0],
        run.wall.as_secs_f64(),
        solver.name(),
        run.stats.choice(),
        run.stats.steps,
        run.stats.rejected,
        run.stats.rhs_evals,
        if cav > 0 {
            format!(
                "CAVITATION: {cav} entries below the cavitation pressure (min chamber pressure {:.0} Pa)",
                run.min_chamber_pressure()
            )
        } else {
            "no cavitation".to_string()
        }
    );
    Ok(())
}
