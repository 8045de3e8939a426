//! `hydrocyl presets`: the built-in rigs `--rig` takes by name, one line
//! each: name, kind and what it is — on a terminal the description cut to
//! fit a line (`--long`: whole), elsewhere (a pipe, a file) whole.

use crate::error::CliError;
use hydrocyl_system::rig;
use std::io::IsTerminal as _;

/// Arguments of `hydrocyl presets`.
#[derive(clap::Args)]
pub struct Args {
    /// Print each description whole on a terminal too (piped or redirected
    /// output always has it whole; a terminal gets one short line per preset).
    #[arg(long)]
    long: bool,
}

/// `text` without its closing full stop, at most ~100 characters (cut
/// with `...`).
fn one_line(text: &str) -> String {
    let first = text.trim_end_matches('.');
    if first.chars().count() > 100 {
        let cut: String = first.chars().take(97).collect();
        format!("{cut}...")
    } else {
        first.to_string()
    }
}

/// Every preset as `(name, kind, description)`: the description whole, or
/// cut to one short line ([`one_line`]) when `short`.
pub fn all(short: bool) -> Vec<(&'static str, String, String)> {
    let describe = |v: &serde_json::Value| {
        let kind = v
            .get("kind")
            .and_then(|k| k.as_str())
            .unwrap_or("?")
            .to_string();
        let what = v
            .get("description")
            .and_then(|d| d.as_str())
            .map(|d| if short { one_line(d) } else { d.to_string() })
            .unwrap_or_default();
        (kind, what)
    };
    // the friction-bench presets are netlists of `rig::PRESETS` too
    // (`bench::PRESETS` is their identification view, not more rigs)
    rig::PRESETS
        .iter()
        .map(|p| {
            let (k, d) = describe(&(p.json)());
            (p.name, k, d)
        })
        .collect()
}

/// The preset names, comma-separated (for `--rig`'s help).
pub fn names() -> String {
    // names only: reading every preset here would cost each start-up
    rig::PRESETS
        .iter()
        .map(|p| p.name)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Runs `hydrocyl presets`.
pub fn run(args: Args) -> Result<(), CliError> {
    let short = !args.long && std::io::stdout().is_terminal();
    let list = all(short);
    let w = list.iter().map(|p| p.0.len()).max().unwrap_or(0);
    let k = list.iter().map(|p| p.1.len()).max().unwrap_or(0);
    let lines: String = list
        .into_iter()
        .map(|(name, kind, what)| format!("{name:w$}  {kind:k$}  {what}\n"))
        .collect();
    crate::console::print(&lines)
}
