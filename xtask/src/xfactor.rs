//! `cargo xtask xfactor` (being written).

/// Runs the task; returns `true` on success.
pub fn run() -> bool {
    eprintln!("xtask xfactor: not in hydrocyl yet");
    false
}
