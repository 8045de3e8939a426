//! `hydrocyl` — the command-line tool.
//!
//! Subcommands live one per module; each returns `Result<(), CliError>` and
//! `main` turns an error into one line on stderr and exit code 2.

mod bench_sim;
mod command;
mod command_stream;
mod components;
mod console;
mod diagnose;
mod error;
mod fmu;
#[cfg(test)]
mod fuzz;
mod heap;
mod ledger;
mod output;
mod presets;
mod progress;
mod rating;
mod rigfile;
mod simulate;
mod writer;
mod xfactor;

use clap::{CommandFactory as _, FromArgMatches as _, Parser, Subcommand};
use error::CliError;

/// hydrocyl: simulate asymmetric hydraulic cylinder drives, compute X factors,
/// diagnose measured data, export FMUs.
#[derive(Parser)]
#[command(name = "hydrocyl", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print Leaney's X factor for a cylinder area ratio and spool travels.
    Xfactor(xfactor::Args),
    /// Simulate a rig on a command signal and write the measured-data CSV format.
    #[command(
        override_usage = "hydrocyl simulate --rig <RIG> --command <COMMAND> --out <OUT> [--ledger <FILE.json>] [OPTIONS]\n       hydrocyl simulate --rig <RIG> --print-rig [--set <PATH=VALUE>]...",
        after_help = simulate::COLUMNS_HELP
    )]
    Simulate(simulate::Args),
    /// Diagnose a rig against a measured record: residuals, missing effects, refits.
    Diagnose(diagnose::Args),
    /// List the component types a netlist can use: ports, parameters (unit,
    /// default, range), initial states and outputs.
    Components(components::Args),
    /// Export a rig as an FMI 2.0 Co-Simulation FMU (linux64).
    Fmu(fmu::Args),
    /// List the built-in rigs `--rig` takes by name, with what each is.
    Presets(presets::Args),
}

fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Xfactor(a) => xfactor::run(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Diagnose(a) => diagnose::run(a),
        Command::Components(a) => components::run(a),
        Command::Fmu(a) => fmu::run(a),
        Command::Presets(a) => presets::run(a),
    }
}

/// The command line's definition, `--rig`'s help listing every preset
/// (`simulate`, `fmu`; `diagnose`: those it takes, [`diagnose::presets`]).
fn definition() -> clap::Command {
    let names = presets::names();
    let rig_help = |sub: clap::Command| {
        let help = format!(
            "A preset name ({names}; `hydrocyl presets` says what each is) or a rig JSON file"
        );
        sub.mut_arg("rig", move |a| a.help(help))
    };
    // the presets diagnose takes are found by reading each (a few
    // milliseconds): only when help may be shown
    let help = std::env::args_os().any(|a| a == "--help" || a == "-h" || a == "help");
    let diagnosable = if help {
        diagnose::presets().join(", ")
    } else {
        "see hydrocyl presets".to_string()
    };
    Cli::command()
        .mut_subcommand("simulate", rig_help)
        .mut_subcommand("fmu", rig_help)
        .mut_subcommand("diagnose", move |sub| {
            sub.mut_arg("rig", move |a| {
                a.help(format!(
                    "A preset name ({diagnosable}: a friction bench or a netlist with a cylinder on a mass) or a rig JSON file (a netlist, its `identify` section naming the model, columns and refits; or an older valve-cylinder or friction-bench file)"
                ))
            })
        })
}

/// `hydrocyl simulate ...` parsed by the `simulate` subcommand's own
/// definition: the whole command line's (every subcommand's arguments and
/// help) takes ~0.2 ms to build, a few per cent of a short run. `None` when
/// the command is not `simulate` or its arguments do not parse as it: the
/// whole definition then parses them, so that help, usage and every error
/// read as always.
fn simulate_alone() -> Option<Cli> {
    use clap::Args as _;
    let mut args = std::env::args_os();
    if args.nth(1)? != "simulate" {
        return None;
    }
    let m = simulate::Args::augment_args(clap::Command::new("simulate"))
        .try_get_matches_from(std::env::args_os().skip(1))
        .ok()?;
    let a = simulate::Args::from_arg_matches(&m).ok()?;
    Some(Cli {
        command: Command::Simulate(a),
    })
}

/// Ends the process on an error of the command line's parser: help and
/// the version as clap prints them (exit code 0; a bare `hydrocyl`, the
/// help with exit code 2), anything else as one line like every other
/// error, exit code 2: `hydrocyl: error: --rtol: invalid value 'abc':
/// invalid float literal (see hydrocyl simulate --help)`.
fn argument_error(e: &clap::Error) -> ! {
    use clap::error::ErrorKind;
    if matches!(
        e.kind(),
        ErrorKind::DisplayHelp
            | ErrorKind::DisplayVersion
            | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand
    ) {
        e.exit()
    }
    // the subcommand, the first word that is not an option
    let sub = std::env::args_os()
        .skip(1)
        .find(|a| !a.to_string_lossy().starts_with('-'))
        .and_then(|a| {
            let a = a.to_string_lossy().into_owned();
            definition()
                .get_subcommands()
                .any(|s| s.get_name() == a)
                .then_some(a)
        });
    let help = match &sub {
        Some(s) => format!("hydrocyl {s} --help"),
        None => "hydrocyl --help".to_string(),
    };
    console::note(format_args!(
        "hydrocyl: error: {} (see {help})",
        argument_message(e)
    ));
    std::process::exit(2)
}

/// What is wrong with the command line, in one line, from the parser's
/// error context: the option (as `--rtol`, without its value's name), the
/// value and why.
fn argument_message(e: &clap::Error) -> String {
    use clap::error::{ContextKind, ContextValue, ErrorKind};
    let strings = |k: ContextKind| -> Vec<String> {
        match e.get(k) {
            Some(ContextValue::String(s)) => vec![s.clone()],
            Some(ContextValue::Strings(v)) => v.clone(),
            Some(ContextValue::StyledStr(s)) => vec![s.to_string()],
            Some(ContextValue::StyledStrs(v)) => v.iter().map(ToString::to_string).collect(),
            _ => Vec::new(),
        }
    };
    // `--rtol <RTOL>` -> `--rtol`
    let flag = |s: &str| s.split_whitespace().next().unwrap_or(s).to_string();
    let first = |k: ContextKind| strings(k).into_iter().next();
    let arg = first(ContextKind::InvalidArg).map(|a| flag(&a));
    let value = first(ContextKind::InvalidValue);
    let did_you_mean = |k: ContextKind| {
        let s = strings(k);
        if s.is_empty() {
            String::new()
        } else {
            format!("; did you mean '{}'?", s.join("' or '"))
        }
    };
    let why = std::error::Error::source(e).map(ToString::to_string);
    match (e.kind(), arg, value) {
        (ErrorKind::InvalidValue, Some(a), Some(v)) if v.is_empty() => {
            format!("{a}: a value is required but none was given")
        }
        (ErrorKind::InvalidValue | ErrorKind::ValueValidation, Some(a), Some(v)) => {
            let valid = strings(ContextKind::ValidValue);
            let why = match (why, valid.is_empty()) {
                (Some(w), _) => format!(": {w}"),
                (None, false) => format!(": use one of {}", valid.join(", ")),
                (None, true) => String::new(),
            };
            format!("{a}: invalid value '{v}'{why}")
        }
        (ErrorKind::UnknownArgument, Some(a), _) => format!(
            "unexpected argument '{a}'{}",
            did_you_mean(ContextKind::SuggestedArg)
        ),
        (ErrorKind::InvalidSubcommand, ..) if first(ContextKind::InvalidSubcommand).is_some() => {
            format!(
                "unknown subcommand '{}'{}",
                first(ContextKind::InvalidSubcommand).unwrap_or_default(),
                did_you_mean(ContextKind::SuggestedSubcommand)
            )
        }
        (ErrorKind::MissingRequiredArgument, _, _) => {
            let missing: Vec<String> = strings(ContextKind::InvalidArg)
                .iter()
                .map(|a| flag(a))
                .collect();
            format!("missing required {}", missing.join(", "))
        }
        (ErrorKind::ArgumentConflict, Some(a), _)
            if first(ContextKind::PriorArg).is_some_and(|p| flag(&p) != a) =>
        {
            let p = first(ContextKind::PriorArg).unwrap_or_default();
            format!("{a} cannot be used with {}", flag(&p))
        }
        (ErrorKind::ArgumentConflict, Some(a), _) if first(ContextKind::PriorArg).is_some() => {
            format!("{a} cannot be given more than once")
        }
        (ErrorKind::MissingSubcommand, _, _) => "a subcommand is required".to_string(),
        // anything else: clap's own message, its first line
        _ => {
            let text = e.to_string();
            let line = text.lines().next().unwrap_or("invalid arguments");
            line.strip_prefix("error: ").unwrap_or(line).to_string()
        }
    }
}

fn main() {
    progress::start();
    progress::mark("main");
    let cli = match simulate_alone().map_or_else(
        || {
            definition()
                .try_get_matches()
                .and_then(|m| Cli::from_arg_matches(&m))
        },
        Ok,
    ) {
        Ok(c) => c,
        Err(e) => argument_error(&e),
    };
    progress::mark("arguments parsed");
    let r = run(cli);
    progress::mark("end");
    progress::print_marks();
    match r {
        // the reader of a pipe stopped reading (`--out /dev/stdout | head`):
        // end quietly, with the status a tool killed by SIGPIPE has
        Err(error::CliError::Io { source, .. })
            if source.kind() == std::io::ErrorKind::BrokenPipe =>
        {
            std::process::exit(141)
        }
        Err(e) => {
            console::note(format_args!("{}", console::error_line(&e)));
            std::process::exit(2);
        }
        Ok(()) => {}
    }
}
