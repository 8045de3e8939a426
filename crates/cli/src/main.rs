//! `hydrocyl` — the command-line tool.
//!
//! Subcommands live one per module; each returns `Result<(), CliError>` and
//! `main` turns an error into one line on stderr and exit code 2.

mod bench_sim;
mod components;
mod diagnose;
mod error;
mod fmu;
mod simulate;
mod xfactor;

use clap::{Parser, Subcommand};
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
    Simulate(simulate::Args),
    /// Diagnose a rig against a measured record: residuals, missing effects, refits.
    Diagnose(diagnose::Args),
    /// List the component types a netlist can use: ports, parameters (unit,
    /// default, range), initial states and outputs.
    Components(components::Args),
    /// Export a rig as an FMI 2.0 Co-Simulation FMU (linux64).
    Fmu(fmu::Args),
}

fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Xfactor(a) => xfactor::run(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Diagnose(a) => diagnose::run(a),
        Command::Components(a) => components::run(a),
        Command::Fmu(a) => fmu::run(a),
    }
}

fn main() {
    let cli = Cli::parse();
    if let Err(e) = run(cli) {
        eprintln!("hydrocyl: error: {e}");
        std::process::exit(2);
    }
}
