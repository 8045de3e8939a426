//! Progress of the long tasks (`energy`, `validate`): an indicatif bar on
//! stderr, drawn only when stderr is a terminal or with `--progress`, and
//! the task's true wall time as its last line.

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal as _;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

static FORCED: AtomicBool = AtomicBool::new(false);

/// `--progress`: draw the bars even when stderr is not a terminal.
pub fn force(on: bool) {
    FORCED.store(on, Ordering::Relaxed);
}

/// A bar of `len` steps of `what` (hidden unless on a terminal or forced).
/// Clones share it; it is safe to advance from several threads.
pub fn bar(what: &str, len: usize) -> ProgressBar {
    let on = FORCED.load(Ordering::Relaxed) || std::io::stderr().is_terminal();
    let target = if on {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let b = ProgressBar::with_draw_target(Some(len as u64), target);
    b.set_style(
        ProgressStyle::with_template(&format!(
            "{{spinner}} {what} [{{bar:30}}] {{pos}}/{{len}} {{msg}} ({{elapsed}}, eta {{eta}})"
        ))
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    if on {
        // the elapsed time moves while one long item runs
        b.enable_steady_tick(std::time::Duration::from_millis(250));
    }
    b
}

/// Prints the task's wall time since `start` (its last line).
pub fn wall(task: &str, start: Instant) {
    println!(
        "xtask {task}: wall time {:.1} s",
        start.elapsed().as_secs_f64()
    );
}
