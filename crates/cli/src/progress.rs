//! Progress of long runs: an indicatif bar on stderr, drawn only on a
//! terminal or with `--progress`, never with `--quiet`, and only once the
//! run has taken more than a second; and the command's true wall time (from
//! the start of the process, reading and writing included).

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};
use std::io::IsTerminal as _;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

static START: OnceLock<Instant> = OnceLock::new();

/// Marks the start of the command (call first thing in `main`).
pub fn start() {
    let _ = START.set(Instant::now());
}

/// Phase marks of the process, kept when the environment variable
/// `HYDROCYL_PHASES` is set (to profile `hydrocyl simulate`): each a label,
/// the thread and the time since [`start`].
static MARKS: OnceLock<Option<std::sync::Mutex<Vec<Mark>>>> = OnceLock::new();

/// A phase mark: label, thread (0 = main) and time since [`start`].
type Mark = (&'static str, u64, Duration);

/// Records phase `label` (see [`MARKS`]); a no-op unless `HYDROCYL_PHASES`
/// is set.
pub fn mark(label: &'static str) {
    let marks = MARKS.get_or_init(|| {
        std::env::var_os("HYDROCYL_PHASES").map(|_| std::sync::Mutex::new(Vec::new()))
    });
    if let (Some(m), Some(s)) = (marks, START.get()) {
        let thread = if std::thread::current().name() == Some("main") {
            0
        } else {
            1
        };
        if let Ok(mut m) = m.lock() {
            m.push((label, thread, s.elapsed()));
        }
    }
}

/// Prints the phase marks to stderr (with `HYDROCYL_PHASES`), one line
/// each: milliseconds since the start, thread (0 = main), label.
pub fn print_marks() {
    if let Some(Some(m)) = MARKS.get() {
        if let Ok(m) = m.lock() {
            for (label, thread, t) in m.iter() {
                crate::console::note(format_args!(
                    "phase {:8.3} ms  [{thread}] {label}",
                    t.as_secs_f64() * 1e3
                ));
            }
        }
    }
}

/// Wall time since [`start`] \[s\].
pub fn wall() -> f64 {
    START.get().map_or(0.0, |s| s.elapsed().as_secs_f64())
}

/// A progress bar that shows itself after a second (see the module doc).
pub struct Progress {
    bar: Option<ProgressBar>,
    shown: bool,
    since: Instant,
}

impl Progress {
    /// A bar of `len` units of `what`; `force` = `--progress`, `quiet` = `--quiet`.
    pub fn new(what: &str, len: u64, force: bool, quiet: bool) -> Self {
        let on = !quiet && (force || std::io::stderr().is_terminal());
        let bar = on.then(|| {
            let b = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
            b.set_style(
                ProgressStyle::with_template(&format!(
                    "{{spinner}} {what} [{{bar:30}}] {{pos}}/{{len}} {{msg}} ({{elapsed}}, eta {{eta}})"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            b
        });
        Progress {
            bar,
            shown: false,
            since: Instant::now(),
        }
    }

    /// Sets the position (and total) with a stage message.
    pub fn set(&mut self, stage: &str, done: u64, total: u64) {
        let Some(b) = &self.bar else { return };
        if !self.shown && self.since.elapsed() > Duration::from_secs(1) {
            b.set_draw_target(ProgressDrawTarget::stderr());
            self.shown = true;
        }
        b.set_length(total);
        b.set_position(done);
        if !stage.is_empty() {
            b.set_message(stage.to_string());
        }
    }

    /// Removes the bar.
    pub fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish_and_clear();
        }
    }
}
