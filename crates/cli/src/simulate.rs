//! `hydrocyl simulate`: simulate a rig on a command signal and write the
//! measured-data CSV format.
//!
//! ```text
//! hydrocyl simulate --rig leaney-moog --command cmd.csv --out run.csv \
//!     [--set load.mass=50] [--set cylinder.initial.p1=2e6] \
//!     [--solver auto|dp45|rosenbrock|rk4|exponential] [--rtol 1e-6] [--print-rig] [--fsync]
//! ```
//!
//! The command file is CSV with a `time` column (`time`, `time [s]` or
//! `time [ms]`) and one `command` column in the unit of the rig's command
//! (see [`crate::command`]); other columns are ignored. A closed-loop rig
//! (one with a `position_controller`, e.g. the `leaney-moog-closed-loop`
//! preset) is driven by a `reference` column instead (`reference [m]` /
//! `reference [mm]`: the position set-point), and its controller computes the
//! command.
//! The output has one row per command sample: `time, command, position,
//! velocity, p1, p2`, then the rig's other outputs (`ps`, `spool`, `p_le`,
//! ...), all SI, each header with its unit (`position [m]`; the readers take
//! both forms; [`COLUMNS_HELP`] says what each is). The friction-bench presets
//! (`tudelft-seal-25`, `tudelft-seal-257`, `emps`) are netlists whose drive
//! imposes the rod's velocity: their `command` column is that velocity
//! \[m·s⁻¹\] and their output has the load-cell `force`. A `friction-bench`
//! rig *file* (the identification format of `diagnose`) is driven by a
//! measured record's motion instead, its output chosen, headed and written
//! as every rig's: see [`crate::bench_sim`].
//! A rig file of an older kind (`valve-cylinder`, `hybrid-pump`) is read as
//! its netlist ([`rig::load`]): `--set` and `--print-rig` use the
//! netlist's `<component>.<parameter>` paths on it as on every preset.
//! The rig is read and checked once ([`crate::rigfile::check`]); the input's
//! column and unit come from the netlist (the port that reads the input).
//!
//! Every input is checked and the output's temporary file created before the
//! run ([`crate::output`]); the command file is read meanwhile on a thread of
//! its own ([`crate::command::Ahead`]). The run is one
//! [`Simulation`] of the checked rig's circuit, streamed in blocks
//! ([`Simulation::run_streaming`]; a command file too long to hold is read
//! while the run goes, [`Simulation::run_command_stream`]); each block's
//! text is made by the writer thread while the solve computes the next, and
//! by both threads once the solve has ended, and written in order
//! ([`crate::writer`]); a history-free rig's probes are read there too, on a
//! circuit of each thread's own ([`Simulation::run_streaming_states`],
//! [`hydrocyl_system::run::ProbeReader`]). The temporary is put in place at
//! the end, so a failed or interrupted run leaves no file and the old one as
//! it was (`--fsync` also flushes it to the disk first; without it the
//! operating system writes it back when it likes, as for any ordinary file).

use crate::command::{read_bytes, read_table, Ahead, CommandUnit};
use crate::command_stream;
use crate::error::CliError;
use crate::ledger::Ends;
use crate::output::Outputs;
use crate::progress::Progress;
use crate::writer::{Block, Lows, Maker, Rows, Writer};
use hydrocyl_system::netlist::registry::ComponentType;
use hydrocyl_system::rig;
use hydrocyl_system::run::{
    Cause, Channel, DeepCavitation, ProbeReader, Run, RunOptions, Setting, SettingWords, Solver,
};
use hydrocyl_system::signal::{Signal, StreamedTable};
use hydrocyl_system::simulation::Simulation;
use std::path::{Path, PathBuf};

/// The output columns, for `hydrocyl simulate --help`.
pub const COLUMNS_HELP: &str = "\
Output columns (one row per command sample; the header gives each unit, e.g. `position [m]`):
  time [s]            the command file's times
  command [-] or [V]  the command as read (normalised spool demand; pump drive voltage)
  reference [m]       a closed-loop rig's position set-point (its `command` is the controller's output)
  position [m]        rod position from mid-stroke       velocity [m/s]  rod velocity (+ extends)
  p1, p2 [Pa]         cap-side and rod-side chamber pressures, gauge
  spool [m]           valve spool position               ps [Pa]   supply pressure at the valve
  p_le [Pa]           load pressure: the chambers' net force over the effective area (A1 + A2)/2 (eq 2.16)
  friction_force [N]  friction on the rod
  pump rigs:  pump_flow [m^3/s] pump flow; pp1, pp2 [Pa] pressures at the pump's ports (lines 1 and 2);
              relief_*_flow, check_*_flow, return_flow_* [m^3/s] flows through those valves;
              pilot_spool [m] the pilot-operated return valve's spool
  benches:    the input is the imposed `command` velocity [m/s]; force [N] the load cell's
  netlists:   any other column is a component's probe, `<component>.<probe>` (see `hydrocyl components`)";

/// Arguments of `hydrocyl simulate`.
#[derive(clap::Args)]
pub struct Args {
    /// A preset name (`hydrocyl presets`) or a rig JSON file.
    #[arg(long)]
    pub(crate) rig: String,
    /// (required) CSV with `time` and `command` columns (a closed-loop rig:
    /// `time` and `reference` [m or mm], the position set-point); the output
    /// is sampled at its times.
    #[arg(long, required_unless_present = "print_rig")]
    pub(crate) command: Option<PathBuf>,
    /// (required) Output CSV (measured-data format, units in the header).
    #[arg(long, required_unless_present = "print_rig")]
    pub(crate) out: Option<PathBuf>,
    /// Override a rig parameter by its path, e.g. `--set load.mass=50` or
    /// `--set cylinder.initial.p1=2.5e6` (repeatable; `hydrocyl simulate
    /// --print-rig` lists every path).
    #[arg(long = "set", value_name = "PATH=VALUE")]
    pub(crate) set: Vec<String>,
    /// Integration method: auto (default: dp45 while the run is not stiff,
    /// rosenbrock while it is), dp45, rosenbrock, rk4 (fixed step, --rk4-step)
    /// or exponential (exponential Rosenbrock–Euler, fixed steps landing on
    /// the output times: for a mode stiff but linear over a step, e.g. a
    /// friction bench's LuGre bristle).
    #[arg(long, default_value = "auto")]
    pub(crate) solver: String,
    /// Relative tolerance of the adaptive methods, in [1e-14, 1) (a smaller
    /// one asks for more digits than double precision carries).
    #[arg(long, default_value_t = 1e-6, allow_negative_numbers = true)]
    pub(crate) rtol: f64,
    /// Fixed step of rk4, and the longest step of exponential \[s\].
    #[arg(
        long,
        default_value_t = 2e-5,
        allow_negative_numbers = true,
        help = "Fixed step of rk4, and the longest step of exponential [s]"
    )]
    pub(crate) rk4_step: f64,
    /// Longest step of the adaptive methods \[s\] (default 0.01; `inf`: no
    /// bound): a larger one lets a circuit at rest, or a long slow run,
    /// take fewer steps; outputs and events are where they are whatever it
    /// is.
    #[arg(
        long,
        value_name = "S",
        allow_negative_numbers = true,
        help = "Longest step of the adaptive methods [s] (default 0.01; inf: no bound): a larger one lets a circuit at rest, or a long slow run, take fewer steps; outputs and events are where they are whatever it is"
    )]
    pub(crate) max_step: Option<f64>,
    /// Also integrate the energy ledger and write it to this JSON file (put
    /// in place with the CSV, checked before the run as --out is): per
    /// component the integrated source, dissipated, storage, load and moved
    /// energies in J (`components_j`), their totals, the energy in, the load's
    /// work, the losses and storage by component, and the closure
    /// `energy_in - load - losses - storage` in J and as a fraction of the
    /// energy in (`closure_j`, `closure_relative`; where none comes in, of
    /// the largest term, `reference_j`, and no efficiency), with the storage check
    /// against the stored energy recomputed from the states (docs/energy.md;
    /// the keys are those of Python's `run.ledger`). The ledger's
    /// quadratures are normed apart from the states: with dp45 the CSV is
    /// the one a run without it writes; the stiff methods difference the
    /// circuit while the ledger is on, so theirs may differ in the last
    /// digits.
    #[arg(long, value_name = "FILE.json")]
    pub(crate) ledger: Option<PathBuf>,
    /// The ledger's window starts at the first output time at or after this
    /// time in s (default: the run's first; e.g. after a warm-up period, as
    /// `cargo xtask energy` does).
    #[arg(
        long,
        value_name = "SECONDS",
        requires = "ledger",
        allow_negative_numbers = true
    )]
    pub(crate) ledger_from: Option<f64>,
    /// Print the rig (after --set) as JSON and exit: nothing is run or
    /// written, so --out and --ledger are refused with it; --command and the
    /// run's options (--solver, --rtol, ...) are not read.
    #[arg(long, conflicts_with_all = ["out", "ledger"])]
    pub(crate) print_rig: bool,
    /// Flush the output to the disk (fsync) before it is renamed into place.
    #[arg(long)]
    pub(crate) fsync: bool,
    /// Show progress when stderr is not a terminal too (a CI log, a file):
    /// there as plain lines, one every 5 s at most after the first second,
    /// not a redrawn bar (on a terminal a bar shows without this flag).
    #[arg(long)]
    pub(crate) progress: bool,
    /// Print nothing but errors (no progress, no warnings, no summary).
    #[arg(long)]
    pub(crate) quiet: bool,
    /// Command files larger than this many bytes are read a buffer at a time
    /// during the run instead of whole (tests set it low).
    #[arg(long, hide = true, default_value_t = 16 << 20)]
    pub(crate) stream_above: u64,
    /// While this many blocks wait for the writer thread, the solve's thread
    /// makes the next block's text itself (reading its probes on a circuit
    /// of its own) rather than queue it (default: the queue's bound; tests
    /// set 0: always).
    #[arg(long, hide = true, default_value_t = crate::writer::QUEUE)]
    pub(crate) probes_behind: usize,
}

/// Output times per block of a streamed run: the memory a run needs grows
/// with this, not with the record. Blocks this small let the writer thread
/// read the probes of, format and write one block while the solve computes
/// the next, and the two threads share what is left when the solve ends
/// finely ([`crate::writer`]).
const BLOCK: usize = 1 << 8;

/// Samples of the command window of a streamed command file.
const WINDOW: usize = 1 << 18;

/// Writes `values` of a `simulate` output as zero where they are zero to
/// double precision: a subnormal (below `f64::MIN_POSITIVE`, 2.2e-308, in
/// magnitude: a pressure decaying onto the tank's 0 Pa, `-1.3e-316`) and
/// `-0.0` become `0.0`. A subnormal has lost its precision and is no
/// physical value; every normal double is written as the solver gave it.
pub fn flush_to_zero(values: &mut [f64]) {
    for v in values {
        if v.is_subnormal() || *v == 0.0 {
            *v = 0.0;
        }
    }
}

/// The CSV header of a run's `channels`: `time [s]`, then each channel as
/// `name [unit]` (the in-memory channel names stay bare; the readers take
/// both forms): every `simulate` output's, a netlist's or a friction
/// bench's ([`crate::bench_sim`]). The run's input is in the unit its
/// readers take it in ([`hydrocyl_system::Circuit::set_probe_unit`]).
pub fn column_headers(channels: &[Channel]) -> Vec<String> {
    std::iter::once("time [s]".to_string())
        .chain(channels.iter().map(|c| {
            if c.unit.is_empty() {
                c.name.clone()
            } else {
                format!("{} [{}]", c.name, c.unit)
            }
        }))
        .collect()
}

/// The run's `--solver`, `--rtol`, `--rk4-step` and `--max-step`, checked
/// (the same messages on every kind of rig): the solver.
pub(crate) fn run_settings(args: &Args) -> Result<Solver, CliError> {
    let solver = Solver::parse_or_why(&args.solver)
        .map_err(|why| CliError::Input(format!("--solver: {why}")))?;
    for (flag, setting, value) in [
        ("--rtol", Setting::Rtol, Some(args.rtol)),
        ("--rk4-step", Setting::Rk4Step, Some(args.rk4_step)),
        ("--max-step", Setting::HMax, args.max_step),
    ] {
        if let Some(value) = value {
            setting.check_named(flag, value).map_err(CliError::Input)?;
        }
    }
    Ok(solver)
}

/// The unit of a rig's input, from the netlist (the port that reads it,
/// [`crate::rigfile::Checked::input_unit`]): the position set-point of a
/// closed-loop rig, a position another port reads directly (a valve's
/// spool), a pump drive's voltage, a bench drive's imposed velocity, else a
/// normalised spool demand.
fn command_unit(rig: &crate::rigfile::Checked) -> CommandUnit {
    match rig.input_unit() {
        Some("m") if rig.input_is_set_point() => CommandUnit::Reference,
        Some("m") => CommandUnit::Position,
        Some("V") => CommandUnit::Volt,
        Some("m/s") => CommandUnit::Velocity,
        _ => CommandUnit::Normalised,
    }
}

/// Rejects an initial chamber pressure below absolute vacuum (gauge
/// pressures below −101 325 Pa do not exist).
fn check_initial_pressures(rig: &crate::rigfile::Checked) -> Result<(), CliError> {
    for p in rig.parameters() {
        let pressure = p.unit == Some("Pa")
            || (p.unit.is_none()
                && p.path
                    .rsplit('.')
                    .next()
                    .is_some_and(|l| l.starts_with('p')));
        let initial = p.path.starts_with("initial.") || p.path.contains(".initial.");
        match p.value {
            Some(v) if initial && pressure && v < rig::ABSOLUTE_VACUUM_GAUGE_PA => {
                return Err(CliError::Input(format!(
                    "rig parameter `{}` = {v} Pa: below absolute vacuum ({} Pa gauge)",
                    p.path,
                    rig::ABSOLUTE_VACUUM_GAUGE_PA
                )));
            }
            _ => {}
        }
    }
    Ok(())
}

/// The registry type of each component of the rig, by instance name: what
/// a remedy may propose to `--set` on a component is looked up in it.
pub(crate) type Types = std::sync::Arc<[(String, &'static ComponentType)]>;

/// Checks the solution (a run or a block of one) for the signs of an
/// unstable integration (a non-finite value, a chamber pressure below the
/// liquid's tension limit: [`Run::physical`]) and names the fix; otherwise
/// where its constant-B liquid left its range (a chamber far below vacuum,
/// [`Run::deep_cavitation`]), which the blocks of a run merge
/// ([`DeepCavitation::merged`]) and [`cavitation_warning`] words once the
/// whole run has passed.
pub(crate) fn check_solution(
    run: &Run,
    solver: Solver,
    rk4_step: f64,
) -> Result<Option<DeepCavitation>, CliError> {
    let u = match run.physical() {
        Ok(deep) => return Ok(deep),
        Err(u) => u,
    };
    let what = &u.what;
    let message = match u.cause(solver) {
        Cause::StepTooLong => format!(
            "the {} solution is unstable ({what}); --rk4-step {rk4_step} is too large for this rig: use a smaller step or --solver auto",
            solver.name()
        ),
        Cause::Unstable => format!(
            "the {} solution is unstable ({what}); try --solver rosenbrock or a smaller --rtol",
            solver.name()
        ),
    };
    Err(CliError::Input(message))
}

/// The one-line warning of a run whose chamber fell far below vacuum
/// without blowing up ([`DeepCavitation::warning`] in the CLI's flags); a
/// parameter it proposes to `--set` is one the component's type has
/// (`types`).
pub(crate) fn cavitation_warning(
    d: &DeepCavitation,
    solver: Solver,
    rk4_step: f64,
    types: &[(String, &'static ComponentType)],
) -> String {
    let type_of = |c: &str| types.iter().find(|(n, _)| n == c).map(|(_, t)| *t);
    let words = SettingWords {
        set: |p| format!("--set {p}=0.005, docs/hybrid.md"),
        rk4_step: "--rk4-step",
        rtol: "--rtol",
        stiff_solver: "--solver rosenbrock",
        quote: '`',
    };
    format!(
        "hydrocyl: warning: {}",
        d.warning(type_of, solver, rk4_step, &words)
    )
}

/// A pressure to the nearest pascal, for messages: a value that rounds to
/// zero is `0` (never `-0`, which `{:.0}` makes of −0.4 Pa).
fn whole_pascals(p: f64) -> String {
    let r = p.round();
    format!("{:.0}", if r == 0.0 { 0.0 } else { r })
}

/// The command of a run: a table read whole (and its times, the output
/// times), or a long file streamed into a window.
enum Input {
    Table(std::sync::Arc<[f64]>),
    Stream(StreamedTable, command_stream::Chunks),
}

/// Adds the remedy to a step-budget failure (the integrator says "the step
/// budget ran out"): a fixed step is told how many steps it needs over the
/// run's `span` \[s\]; an explicit method is told to use rosenbrock; `auto`
/// (which switches to it itself) and rosenbrock are told that the run is too
/// long or too stiff for the budget.
fn solver_hint(e: rig::RigError, solver: Solver, rk4_step: f64, span: f64) -> CliError {
    let m = e.to_string();
    // SolveError::EventStorm's and ::Chattering's messages, and a state
    // that blew up (SolveError::NonFinite's, not at the start, where the
    // message names the parameter's range): a fixed step is the likely cause
    let blew_up = m.contains("is not finite at") && !m.contains("physical range");
    if blew_up && solver.fixed_step() {
        return CliError::Input(format!(
            "{m}; --rk4-step {rk4_step} is likely too large for this rig: use a smaller step, or --solver auto (or rosenbrock for a stiff rig)"
        ));
    }
    if blew_up {
        return CliError::Input(format!(
            "{m}; the {} solution is unstable: try --solver rosenbrock or a smaller --rtol",
            solver.name()
        ));
    }
    if (m.contains("events in a row") || m.contains("the solution chatters")) && solver.fixed_step()
    {
        return CliError::Input(format!(
            "{m}; --rk4-step {rk4_step} is likely too large for this rig: use a smaller step or --solver auto"
        ));
    }
    if !m.contains("the step budget ran out") {
        return CliError::Input(m);
    }
    CliError::Input(if solver.fixed_step() {
        format!("{m}: {}", steps_needed(rk4_step, span))
    } else if matches!(solver, Solver::Auto | Solver::Rosenbrock) {
        format!(
            "{m}: the run is too long or too stiff for the step budget (--solver {}); shorten the command file, or check that its time column is in seconds",
            solver.name()
        )
    } else {
        format!("{m}: the run is stiff for an explicit method; use --solver rosenbrock")
    })
}

/// How many steps `--rk4-step` takes over a run of `span` \[s\], and the
/// remedy.
fn steps_needed(rk4_step: f64, span: f64) -> String {
    format!(
        "--rk4-step {rk4_step:e} s over the run's {span} s takes at least {:.3e} steps; use a larger --rk4-step or --solver auto",
        span / rk4_step
    )
}

/// A fixed step that the step budget (`max` steps) cannot cover the run
/// with, refused before the run.
fn budget_message(rk4_step: f64, span: f64, max: usize) -> String {
    format!(
        "the step budget is {max} steps: {}",
        steps_needed(rk4_step, span)
    )
}

/// Runs `hydrocyl simulate`.
pub fn run(args: Args) -> Result<(), CliError> {
    crate::heap::keep_freed_memory();
    let rig_err = |e: rig::RigError| CliError::Input(e.to_string());
    if crate::bench_sim::runs_on_motion(&args.rig) {
        if let Some((bench, net)) = crate::bench_sim::load(&args.rig, &args.set)? {
            return crate::bench_sim::run(&args, &bench, &net);
        }
    }
    // the command file is read (and parsed once the rig's unit is known) on
    // a thread of its own while the rig is read and checked
    let ahead = match &args.command {
        Some(path) if !args.print_rig => Some(Ahead::start(path.clone(), args.stream_above)),
        _ => None,
    };
    // meanwhile (the command is the longer task): the signal handler's thread
    crate::output::remove_temporaries_on_signal();
    let mut value = rig::load(&args.rig).map_err(rig_err)?;
    rig::apply_sets(&mut value, &args.set).map_err(rig_err)?;
    crate::progress::mark("rig loaded");
    let checked = crate::rigfile::check(&value, &args.rig, &args.set)?;
    check_initial_pressures(&checked)?;
    checked.hold_implausible();
    crate::progress::mark("rig checked");
    if args.print_rig {
        // what `simulate` would refuse is refused here too: the components
        // are built (on a held command), which runs their own checks
        checked
            .circuit(Signal::Constant { value: 0.0 })
            .map_err(|e| CliError::Input(e.to_string()))?;
        // a netlist is printed with every parameter written out (defaults
        // filled in), under the paths `--set` takes
        let text = rig::printed(&value).map_err(rig_err)?;
        crate::console::print(&format!("{text}\n"))?;
        crate::console::print_held(args.quiet);
        return Ok(());
    }
    let solver = run_settings(&args)?;
    let (Some(cmd_path), Some(out)) = (args.command, args.out) else {
        return Err(CliError::Input("--command and --out are required".into()));
    };
    let rig_path = Path::new(&args.rig);
    let mut inputs = vec![("--command", cmd_path.as_path())];
    if !rig::is_preset(&args.rig) {
        inputs.push(("--rig", rig_path));
    }
    let unit = command_unit(&checked);
    if let Some(a) = &ahead {
        a.parse(unit);
    }
    let mut outputs = Outputs::new(&inputs);
    let id = outputs.file("--out", &out)?;
    let ledger_id = match &args.ledger {
        Some(p) => Some(outputs.file("--ledger", p)?),
        None => None,
    };
    crate::progress::mark("output created");
    let opts = RunOptions {
        solver,
        rtol: args.rtol,
        rk4_step: args.rk4_step,
        h_max: args.max_step.unwrap_or(RunOptions::default().h_max),
        ledger: ledger_id.is_some(),
        ..RunOptions::default()
    };
    // a long file is checked in a first pass and read during the run a
    // buffer at a time; a short one (or one that is not plain CSV) is read whole
    let table = match ahead {
        Some(a) => a.table(unit)?,
        None => None,
    };
    // the command's limit, from the rig's one reading (the library's, as
    // Python's): a spool demand beyond the spool's stroke (the valve clamps
    // it), a pump's voltage beyond its rating (not limited), warned of
    let limit = checked.command_limit();
    let bound = limit.as_ref().map_or(1.0, rig::CommandLimit::bound);
    let long = match table {
        Some(_) => None,
        None => command_stream::scan(&cmd_path, unit, bound)?,
    };
    let (rows, t0, t1, signal, mut input) = match (long, table) {
        (Some((scan, chunks)), _) => {
            if let Some(l) = limit.as_ref().filter(|_| !args.quiet) {
                crate::rating::warn(&cmd_path, l, scan.outside, scan.peak);
            }
            let table = StreamedTable::new(WINDOW);
            table.set_range(scan.min, scan.max);
            let signal = Signal::Streamed(table.clone());
            (
                scan.rows,
                scan.t0,
                scan.t1,
                signal,
                Input::Stream(table, chunks),
            )
        }
        (None, table) => {
            let table = match table {
                Some(t) => t,
                // not plain enough to stream: read whole
                None => read_table(&cmd_path, &read_bytes(&cmd_path)?, unit)?,
            };
            if let Some(l) = limit.as_ref().filter(|_| !args.quiet) {
                // a spool demand's samples beyond ±1 are counted as it is read
                let (outside, peak) = match l {
                    rig::CommandLimit::Stroke => (table.outside, table.peak),
                    rig::CommandLimit::Rating(r) => crate::rating::beyond(&table.signal, r.limit),
                };
                crate::rating::warn(&cmd_path, l, outside, peak);
            }
            let t = &table.times;
            let (rows, t0, t1) = (t.len(), t[0], t[t.len() - 1]);
            (rows, t0, t1, table.signal, Input::Table(table.times))
        }
    };
    crate::progress::mark("command read");
    // the ledger's window: its two ends are kept from the streamed blocks
    if let Some(from) = args.ledger_from {
        if !(from.is_finite() && from < t1) {
            return Err(CliError::Input(format!(
                "--ledger-from {from}: must be a time before the command's last, {t1} s"
            )));
        }
    }
    let mut ends = ledger_id.map(|_| Ends::new(args.ledger_from.unwrap_or(f64::NEG_INFINITY)));
    let ledger_signal = ends.as_ref().map(|_| signal.clone());
    // a fixed step that cannot cover the run within the step budget is
    // refused before the run, not after the budget's worth of steps
    if solver.fixed_step() && (t1 - t0) / opts.rk4_step > opts.max_steps as f64 {
        return Err(CliError::Input(budget_message(
            opts.rk4_step,
            t1 - t0,
            opts.max_steps,
        )));
    }
    // the writer thread starts now: on a table, it builds a circuit of its
    // own to read the probes on while this thread builds the solving one
    let types = checked.component_types();
    let checked = std::sync::Arc::new(checked);
    let o = outputs;
    let (c, w, table) = match &input {
        Input::Table(times) => {
            let t0 = times[0];
            let signal = std::sync::Arc::new(signal);
            // a circuit of the rig to read the probes on: `None` when they
            // depend on the circuit's history (read on the solving one)
            let reader = {
                let (checked, signal, opts) = (checked.clone(), signal.clone(), opts.clone());
                move || -> Result<Option<Maker>, CliError> {
                    let c = checked
                        .circuit(Signal::clone(&signal))
                        .map_err(|e| CliError::Input(e.to_string()))?;
                    if !c.history_free() {
                        return Ok(None);
                    }
                    // the solving circuit's initial state (built alike)
                    let x0 = c.initial_state();
                    let r = ProbeReader::new(c, &x0, t0, &opts)
                        .map_err(|e| CliError::Input(e.to_string()))?;
                    Ok(Some(Maker::states(r)))
                }
            };
            let on_writer = {
                let reader = reader.clone();
                Box::new(move || reader().map(Option::unwrap_or_default))
            };
            let w = Writer::start(o, id, on_writer);
            let c = checked
                .circuit(Signal::clone(&signal))
                .map_err(|e| CliError::Input(e.to_string()))?;
            (c, w, Some((reader, t0)))
        }
        Input::Stream(..) => {
            let w = Writer::start(o, id, Box::new(|| Ok(Maker::default())));
            let c = checked
                .circuit(signal)
                .map_err(|e| CliError::Input(e.to_string()))?;
            (c, w, None)
        }
    };
    // the run: the circuit from its own initial state, with the options
    let mut sim = Simulation::of_circuit(c).options(opts.clone());
    let x0 = sim.initial().to_vec();
    crate::progress::mark("circuit built");
    let mut bar = Progress::new("simulate", rows as u64, args.progress, args.quiet);
    let mut failed: Option<CliError> = None;
    let mut done = 0usize;
    // the chamber pressures read on this thread (the channels' blocks)
    let mut lows = Lows::default();
    // the solve's thread's maker, made when first needed: during the solve
    // (the writer far behind) on a third circuit, after it on the solving one
    let mut own: Option<Maker> = None;
    let (streamed, written) = match (table, &input) {
        (Some((reader, t0)), Input::Table(times)) if sim.circuit().history_free() => {
            w.rows(Rows::States {
                solver,
                rk4_step: args.rk4_step,
            });
            let build = || -> Result<Maker, CliError> {
                reader()?.ok_or_else(|| CliError::Input("no probe reader".into()))
            };
            let streamed = {
                let mut sink = |t: &[f64], x: &[f64]| -> Result<(), String> {
                    if let Some(e) = ends.as_mut() {
                        e.see(t, x);
                    }
                    done += t.len();
                    bar.set("rows", done as u64, rows as u64);
                    let fill = |b: &mut Block| {
                        b.time.extend_from_slice(t);
                        b.values.extend_from_slice(x);
                    };
                    if w.behind() < args.probes_behind {
                        return w.push(fill).map_err(|e| e.to_string());
                    }
                    if own.is_none() {
                        own = Some(build().map_err(|e| e.to_string())?);
                    }
                    let m = own.as_mut().ok_or("no maker")?;
                    w.make_here(m, fill).map_err(|e| e.to_string())
                };
                sim.run_streaming_states(times, BLOCK, &mut sink)
            };
            crate::progress::mark("solve done");
            // the solving circuit is free now: it reads the probes of the
            // solve's share of what is left (history-free: the same values)
            let mut solving = Some(sim.into_circuit());
            let mut after = || match solving.take() {
                Some(c) => ProbeReader::new(c, &x0, t0, &opts)
                    .map(Maker::states)
                    .map_err(|e| CliError::Input(e.to_string())),
                None => build(),
            };
            let written = w.finish(&mut own, &mut after);
            (streamed, written)
        }
        _ => {
            let streamed = {
                let mut sink = |block: &Run| -> Result<(), String> {
                    if let Some(e) = ends.as_mut() {
                        e.see(&block.time, &block.states);
                    }
                    let r = check_solution(block, solver, args.rk4_step).and_then(|deep| {
                        lows.add(Lows {
                            min_p: block.min_chamber_pressure(),
                            deep,
                        });
                        if !w.has_rows() {
                            let mut header = column_headers(&block.channels).join(",").into_bytes();
                            header.push(b'\n');
                            w.rows(Rows::Channels(header));
                        }
                        let fill = |b: &mut Block| {
                            b.time.extend_from_slice(&block.time);
                            b.values.reserve(block.channels.len() * block.time.len());
                            let start = b.values.len();
                            for c in &block.channels {
                                b.values.extend_from_slice(&c.values);
                            }
                            flush_to_zero(&mut b.values[start..]);
                        };
                        if w.behind() < args.probes_behind {
                            w.push(fill)
                        } else {
                            w.make_here(own.get_or_insert_with(Maker::default), fill)
                        }
                    });
                    done += block.time.len();
                    bar.set("rows", done as u64, rows as u64);
                    r.map_err(|e| {
                        let m = e.to_string();
                        failed = Some(e);
                        m
                    })
                };
                match &mut input {
                    Input::Table(times) => sim.run_streaming(times, BLOCK, &mut sink),
                    Input::Stream(table, chunks) => {
                        sim.run_command_stream(table, chunks, t1, BLOCK, &mut sink)
                    }
                }
            };
            crate::progress::mark("solve done");
            let written = w.finish(&mut own, &mut || Ok(Maker::default()));
            (streamed, written)
        }
    };
    bar.finish();
    // the writer's error (a failed write, a bad solution) first: the
    // solve's is its echo
    let (mut outputs, run) = match (streamed, failed, written) {
        (_, _, Err(e)) | (_, Some(e), _) => return Err(e),
        (Err(e), None, _) => return Err(solver_hint(e, solver, args.rk4_step, t1 - t0)),
        (Ok(r), None, Ok((o, written_lows))) => {
            lows.add(written_lows);
            (o, r)
        }
    };
    crate::progress::mark("writer finished");
    // the ledger, on a circuit of the rig (it reads the structure and the
    // two states): written with the CSV, or neither
    let ledger_note = match (ledger_id, &ends, ledger_signal) {
        (Some(lid), Some(e), Some(signal)) => {
            let c = checked
                .circuit(signal)
                .map_err(|e| CliError::Input(e.to_string()))?;
            let (text, note) = e.json(c)?;
            outputs.write(lid, &text)?;
            Some(note)
        }
        _ => None,
    };
    outputs.commit(args.fsync)?;
    crate::progress::mark("output committed");
    crate::console::print_held(args.quiet);
    if args.quiet {
        return Ok(());
    }
    // the whole run has passed its checks (a run that fails later is an
    // error and warns of nothing): once per run
    if let Some(d) = &lows.deep {
        crate::console::note(format_args!(
            "{}",
            cavitation_warning(d, solver, args.rk4_step, &types)
        ));
    }
    let min_p = lows.min_p;
    let cav = run.cavitation_entries();
    // one write: stderr is not buffered
    let line = format!(
        "hydrocyl: simulated {:.4} s ({rows} rows) in {:.3} s, {:.3} s of it solving ({} {}: {} steps, {} rejected, {} rhs); {}\n",
        t1 - t0,
        crate::progress::wall(),
        run.wall.as_secs_f64(),
        solver.name(),
        run.stats.choice(),
        run.stats.steps,
        run.stats.rejected,
        run.stats.rhs_evals,
        if cav > 0 {
            // the entries are the solver's events, found between the
            // samples; the samples' lowest pressure need not show the dip
            let lowest = if min_p.is_finite() {
                format!(
                    "the output samples need not show it: their lowest cylinder chamber pressure is {} Pa; sample more finely to see the dip",
                    whole_pascals(min_p)
                )
            } else {
                "no chamber pressure among the outputs".to_string()
            };
            let which: Vec<String> = run
                .cavitation_by_chamber()
                .iter()
                .map(|(n, k)| format!("{n} {k}"))
                .collect();
            format!("CAVITATION: a cylinder chamber fell below its cavitation pressure, or a line volume below absolute vacuum, {cav} times ({}), found by the solver between the output samples ({lowest})", which.join(", "))
        } else {
            "no cavitation".to_string()
        }
    );
    let _ = std::io::Write::write_all(&mut std::io::stderr(), line.as_bytes());
    if let (Some(note), Some(path)) = (ledger_note, &args.ledger) {
        crate::console::note(format_args!("hydrocyl: {}: {note}", path.display()));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::whole_pascals;

    #[test]
    fn a_pressure_that_rounds_to_zero_is_never_minus_zero() {
        assert_eq!(whole_pascals(-0.00082), "0");
        assert_eq!(whole_pascals(-0.0), "0");
        assert_eq!(whole_pascals(-215_000.4), "-215000");
        assert_eq!(whole_pascals(1.6), "2");
    }
}
