//! `cargo xtask bench` (being written).

/// Runs the task; returns `true` on success.
pub fn run() -> bool {
    eprintln!("xtask bench: not in hydrocyl yet");
    false
}
