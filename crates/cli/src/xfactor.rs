//! `hydrocyl xfactor` (being written).

use crate::error::CliError;

/// Arguments of this subcommand.
#[derive(clap::Args)]
pub struct Args {}

/// Runs the subcommand.
pub fn run(_args: Args) -> Result<(), CliError> {
    Err(CliError::Input(
        "this subcommand is not in hydrocyl yet".into(),
    ))
}
