//! `hydrocyl presets`: the built-in rigs `--rig` takes by name, one line
//! each: name, kind and what it is.

use crate::error::CliError;
use hydrocyl_system::rig;

/// Arguments of `hydrocyl presets` (none).
#[derive(clap::Args)]
pub struct Args {}

/// The first sentence of `text`, at most ~100 characters.
fn one_line(text: &str) -> String {
    let first = text.trim_end_matches('.');
    if first.chars().count() > 100 {
        let cut: String = first.chars().take(97).collect();
        format!("{cut}...")
    } else {
        first.to_string()
    }
}

/// Every preset as `(name, kind, one-line description)`.
pub fn all() -> Vec<(&'static str, String, String)> {
    let describe = |v: &serde_json::Value| {
        let kind = v
            .get("kind")
            .and_then(|k| k.as_str())
            .unwrap_or("?")
            .to_string();
        let what = v
            .get("description")
            .and_then(|d| d.as_str())
            .map(one_line)
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
pub fn run(_: Args) -> Result<(), CliError> {
    let list = all();
    let w = list.iter().map(|p| p.0.len()).max().unwrap_or(0);
    let k = list.iter().map(|p| p.1.len()).max().unwrap_or(0);
    let lines: String = list
        .into_iter()
        .map(|(name, kind, what)| format!("{name:w$}  {kind:k$}  {what}\n"))
        .collect();
    crate::console::print(&lines)
}
