//! `cargo xtask energy` (being written).

/// Runs the task; returns `true` on success.
pub fn run() -> bool {
    eprintln!("xtask energy: not in hydrocyl yet");
    false
}
