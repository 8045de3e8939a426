//! `hydrocyl simulate` on a friction-bench rig file (`spec/measured-data.md`:
//! a netlist whose `identify` section names the `friction-bench` model, or an
//! older `friction-bench` file read as that netlist): the drive imposes the motion, so the
//! bench's input is not a command but the motion itself. The `--command` file
//! is a record in the measured-data format (through the rig's column map) with
//! `time`, `position` or `velocity`, and `p1`/`p2` where the bench has
//! pressures (a chamber of area over zero needs its pressure column, as in
//! `diagnose`: [`FrictionBench::require_inputs`]); the output adds the predicted load-cell `force` and the
//! friction on the rod: `time, position, velocity, p1, p2, force,
//! friction_force`, or those of them the rig's `outputs` names, as a
//! netlist's run is chosen (a name that is none of them is refused before
//! the run); SI, each header with its unit (`force [N]`) and each value its
//! shortest round-trip text, as every `simulate` output. Velocity and acceleration
//! come from the same smoother `diagnose` uses; the bristle starts from the
//! record's measured force when it has one, else at rest. The bench runs as
//! its netlist through the one run path (`FrictionBench::simulate`:
//! the record's velocity, acceleration and pressures are the netlist's inputs).

use crate::error::CliError;
use crate::output::Outputs;
use crate::progress::Progress;
use crate::simulate::{run_settings, Args};
use hydrocyl_identify::bench::{self, bench_signals, BenchInputs, FrictionBench};
use hydrocyl_identify::data::{Record, Signal};
use hydrocyl_system::rig;
use hydrocyl_system::run::RunOptions;
use std::path::Path;

/// A friction-bench rig file read for the CLI ([`bench::is_bench_rig`]),
/// or `None` for any other `--rig`: the bench (the circuit and the
/// identification section of its netlist after `sets`) and its netlist
/// (what `--print-rig` shows; `--set` takes its `<component>.<parameter>`
/// paths). Errors name the JSON path and line.
pub fn load(
    spec: &str,
    sets: &[String],
) -> Result<Option<(FrictionBench, serde_json::Value)>, CliError> {
    if rig::is_preset(spec) {
        return Ok(None);
    }
    // read as every rig file is (a byte-order mark, an older kind)
    let is_bench = rig::load(spec).is_ok_and(|v| bench::is_bench_rig(&v));
    if !is_bench {
        return Ok(None);
    }
    let err = |e: rig::RigError| CliError::Input(e.to_string());
    let mut net = rig::load(spec).map_err(err)?;
    let read = |net: &serde_json::Value| {
        FrictionBench::from_rig(net).map_err(|e| CliError::Input(format!("{spec}: {e}")))
    };
    let as_json = |b: &FrictionBench| serde_json::to_value(b).ok();
    // a value out of range blames the `--set` that gave it, not the file
    let check = |net: &serde_json::Value| {
        rig::check(net).map_err(|e| err(crate::rigfile::at_line_or_set(e, spec, sets)))
    };
    rig::each_path_once(sets).map_err(err)?;
    for s in sets {
        let before = as_json(&read(&net)?);
        let old = net.clone();
        rig::apply_set(&mut net, s).map_err(err)?;
        if net == old {
            continue;
        }
        check(&net)?;
        // the bench runs as its standard circuit, read into `FrictionBench`:
        // a set that changes the file but not the bench would be dropped
        if as_json(&read(&net)?) == before {
            return Err(CliError::Input(match switched_off_by(&old, s) {
                Some(why) => format!("--set {s}: {why}"),
                None => format!(
                    "--set {s}: the friction-bench model does not use this parameter (a bench runs as its standard circuit: the drive's mass and load-cell sign, the piston's areas, the friction law; `--print-rig` lists the rest)"
                ),
            }));
        }
    }
    check(&net)?;
    let bench = read(&net)?;
    Ok(Some((bench, net)))
}

/// `hydrocyl simulate` on a friction bench: the `--command` file carries the
/// imposed motion ([`simulate`]). The bench fixes its own
/// integration (one exponential Rosenbrock–Euler step per sample, as its fit
/// runs it), so `--solver`, `--rtol` and `--rk4-step` are checked as for any
/// rig and then refused unless they are the defaults. The rig's `outputs`
/// choose the columns as on a netlist, the header carries the units
/// ([`column_headers`](crate::simulate::column_headers)) and `--progress` shows the run's stages (reading,
/// smoothing, simulating, writing) as the netlist run shows its rows.
pub(crate) fn run(
    args: &Args,
    bench: &FrictionBench,
    value: &serde_json::Value,
) -> Result<(), CliError> {
    if args.print_rig {
        let text = rig::printed(value).map_err(|e| CliError::Input(e.to_string()))?;
        return crate::console::print(&format!("{text}\n"));
    }
    let solver = run_settings(args)?;
    let default = RunOptions::default();
    if solver != default.solver
        || args.rtol != default.rtol
        || args.rk4_step != default.rk4_step
        || args.max_step.is_some()
    {
        return Err(CliError::Input(
            "--solver, --rtol, --rk4-step, --max-step: the friction-bench model fixes its own integration (one step per sample of the imposed motion); to choose them, simulate a netlist of the bench (e.g. the tudelft-seal-25 preset)".into(),
        ));
    }
    let (Some(input), Some(out)) = (&args.command, &args.out) else {
        return Err(CliError::Input("--command and --out are required".into()));
    };
    if args.ledger.is_some() {
        return Err(CliError::Input(
            "--ledger: a friction-bench rig file imposes its motion and has no energy ledger; use a netlist of the bench (e.g. the tudelft-seal-25 preset)".into(),
        ));
    }
    // the channels the rig's `outputs` names, as on a netlist (all without)
    let only = selection(bench, value)?;
    let mut outputs = Outputs::new(&[("--command", input.as_path())]);
    let id = outputs.file("--out", out)?;
    let mut bar = Progress::new("simulate", 1, args.progress, args.quiet);
    let (text, rows) = simulate(bench, input, only.as_deref(), &mut |stage, done, total| {
        bar.set(stage, done, total)
    })?;
    outputs.write(id, &text)?;
    outputs.commit(args.fsync)?;
    bar.finish();
    if !args.quiet {
        crate::console::note(format_args!(
            "hydrocyl: simulated the friction bench on {rows} samples of {}",
            input.display()
        ));
    }
    Ok(())
}

/// Why a `--set` of a friction law's parameter (`friction.stribeck_velocity`)
/// left the bench unchanged where the parameter belongs to an effect that is
/// off in `net` (the netlist before the set): the bench reads an effect as
/// on by its switch ([`FrictionBench::effect_switch_of`], the rule
/// [`FrictionBench::from_rig`] reads it by: its first parameter, `stiction`
/// or `sigma0`, given off its default), so the others are unused until it
/// is. `None` for any other parameter.
fn switched_off_by(net: &serde_json::Value, set: &str) -> Option<String> {
    let path = set.split_once('=')?.0.trim();
    let path = path.strip_prefix("components.").unwrap_or(path);
    let (comp, param) = path.split_once('.')?;
    let ty = net.get("components")?.get(comp)?.get("type")?.as_str()?;
    let switch = FrictionBench::effect_switch_of(ty, param).filter(|s| s.on != param)?;
    let on = switch.on;
    let unit = if switch.unit.is_empty() || switch.unit == "-" {
        String::new()
    } else {
        format!(", in {}", switch.unit)
    };
    let given = match switch.default {
        Some(d) => format!("set off its default {d}"),
        None => "set".to_string(),
    };
    let coulomb = if switch.not_at_coulomb {
        " and differs from the Coulomb level"
    } else {
        ""
    };
    Some(format!(
        "the friction-bench model uses `{comp}.{param}` only where `{comp}.{on}` is {given}{coulomb} (the `{}` effect is off without it, as in this file): set it too (--set {comp}.{on}=VALUE{unit})",
        switch.effect.id()
    ))
}

/// `true` when `simulate` runs the rig `spec` on a record's motion
/// ([`load`], [`simulate`]): a friction-bench rig file whose netlist takes
/// the record's acceleration or pressures as inputs of their own
/// (`command_input` components: an older `friction-bench` file, the
/// netlists of `fixtures/measured/`). A bench preset's netlist (`emps`,
/// `tudelft-seal-25`), whose one input is the drive's velocity, is
/// simulated on a command as the preset is, by name, as a file or printed
/// by `--print-rig`; `diagnose` reads each of them as the same bench.
pub fn runs_on_motion(spec: &str) -> bool {
    !rig::is_preset(spec)
        && rig::load(spec).is_ok_and(|v| {
            bench::is_bench_rig(&v)
                && v.get("components")
                    .and_then(|c| c.as_object())
                    .is_some_and(|c| {
                        c.values().any(|i| {
                            i.get("type").and_then(|t| t.as_str()) == Some("command_input")
                        })
                    })
        })
}

/// The channels the rig's netlist `net` selects with its `outputs` (their
/// column names), as a netlist run's are chosen: `None` (every channel)
/// where it lists none. A name that is not one of the bench's channels is
/// refused here, before any record is read, with the error of a run's
/// selection ([`FrictionBench::check_channels`]).
pub fn selection(
    bench: &FrictionBench,
    net: &serde_json::Value,
) -> Result<Option<Vec<String>>, CliError> {
    let s = hydrocyl_system::netlist::read(net)
        .map_err(|e| CliError::Input(hydrocyl_system::rig::RigError::from(e).to_string()))?;
    let only: Option<Vec<String>> =
        (!s.outputs.is_empty()).then(|| s.outputs.into_iter().map(|(col, _)| col).collect());
    bench
        .check_channels(only.as_deref())
        .map_err(|e| CliError::Input(format!("rig `outputs`: {e}")))?;
    Ok(only)
}

/// Simulates `bench` on the motion in `input`: the output CSV text and its
/// rows. The columns are the bench's channels named in `only` (every one
/// for `None`; an unknown name is refused as on any run,
/// [`hydrocyl_system::run::ProbeSet::selected`]), the header and the values
/// written as every `simulate` output is ([`crate::simulate::column_headers`],
/// shortest round-trip floats by [`hydrocyl_identify::plaincsv`]).
/// `progress(stage, done, total)` is told of each stage as it starts.
pub fn simulate(
    bench: &FrictionBench,
    input: &Path,
    only: Option<&[String]>,
    progress: &mut dyn FnMut(&str, u64, u64),
) -> Result<(Vec<u8>, usize), CliError> {
    const STAGES: u64 = 4;
    progress("reading the record", 0, STAGES);
    let mut rec =
        Record::read_mapped(input, &bench.columns).map_err(|e| CliError::Input(e.to_string()))?;
    if rec.get(Signal::Position).is_none() && rec.get(Signal::Velocity).is_none() {
        return Err(CliError::Input(format!(
            "{}: a friction bench is driven by its motion: the file needs a `position` or `velocity` column",
            input.display()
        )));
    }
    // a pressure the rig's areas make an input is needed, not taken as 0 Pa
    bench
        .require_inputs(&rec)
        .map_err(|e| CliError::Input(e.to_string()))?;
    let measured_force = rec.get(Signal::Force).is_some();
    if !measured_force {
        rec.signals.insert(Signal::Force, vec![0.0; rec.len()]);
    }
    progress("smoothing the motion", 1, STAGES);
    let (s, _) = bench_signals(&rec, None, bench.steady_state)
        .map_err(|e| CliError::Input(e.to_string()))?;
    let inputs = BenchInputs::of(&s).map_err(CliError::Input)?;
    progress("simulating", 2, STAGES);
    let mut run = bench
        .simulate_channels(&s, &inputs, !measured_force, only)
        .map_err(|e| CliError::Input(format!("{}: {e}", input.display())))?;
    for c in &run.channels {
        if let Some(i) = c.values.iter().position(|f| !f.is_finite()) {
            return Err(CliError::Input(format!(
                "{}: the bench model gave a non-finite {} at row {} (t = {} s)",
                input.display(),
                c.name,
                i + 2,
                s.t[i]
            )));
        }
    }
    progress("writing", 3, STAGES);
    for c in &mut run.channels {
        crate::simulate::flush_to_zero(&mut c.values);
    }
    let header = crate::simulate::column_headers(&run.channels);
    let names: Vec<&str> = header.iter().map(String::as_str).collect();
    let columns: Vec<&[f64]> = std::iter::once(run.time.as_slice())
        .chain(run.channels.iter().map(|c| c.values.as_slice()))
        .collect();
    let text = hydrocyl_identify::plaincsv::write_columns(&names, &columns);
    progress("written", STAGES, STAGES);
    Ok((text, run.time.len()))
}
