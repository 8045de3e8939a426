//! `hydrocyl components`: the component catalog of netlists, from the
//! registry (the same text as `docs/components.md`).

use crate::error::CliError;
use hydrocyl_system::netlist::registry;

/// Arguments of `hydrocyl components`.
#[derive(clap::Args)]
pub struct Args {
    /// Show one type only (e.g. `four_way_valve`).
    #[arg(long = "type")]
    pub type_name: Option<String>,
}

/// Runs `hydrocyl components`.
pub fn run(args: Args) -> Result<(), CliError> {
    match args.type_name {
        None => crate::console::print(&registry::catalog_markdown()),
        Some(name) => {
            let t = registry::lookup(&name).ok_or_else(|| {
                CliError::Input(format!(
                    "--type: unknown component type `{name}` (known: {})",
                    registry::types()
                        .iter()
                        .map(|t| t.name)
                        .collect::<Vec<_>>()
                        .join(", ")
                ))
            })?;
            crate::console::print(&registry::type_markdown(t))
        }
    }
}
