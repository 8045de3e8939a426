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

/// The command line's definition, `--rig`'s help listing every preset.
fn definition() -> clap::Command {
    let names = presets::names();
    let rig_help = |sub: clap::Command| {
        let help = format!(
            "A preset name ({names}; `hydrocyl presets` says what each is) or a rig JSON file"
        );
        sub.mut_arg("rig", move |a| a.help(help))
    };
    Cli::command().mut_subcommand("simulate", rig_help)
}

fn main() {
    progress::start();
    progress::mark("main");
    let cli = match Cli::from_arg_matches(&definition().get_matches()) {
        Ok(c) => c,
        Err(e) => e.exit(),
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
            console::note(format_args!("hydrocyl: error: {e}"));
            std::process::exit(2);
        }
        Ok(()) => {}
    }
}
