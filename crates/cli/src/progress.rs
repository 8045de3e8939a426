//! Progress of long runs, on stderr, never with `--quiet`, and only once
//! the run has taken more than a second: on a terminal an indicatif bar
//! redrawn in place; elsewhere (a CI log, a file) with `--progress` only,
//! as plain lines, one every five seconds at most, e.g. `hydrocyl: simulate:
//! rows 51200/100001 (51%) after 2.0 s, eta 1.9 s` (indicatif draws nothing
//! where stderr is not a terminal, and a redrawn bar would litter a log with
//! carriage returns). The environment variable `HYDROCYL_PROGRESS_SECONDS`
//! sets both the delay and the least time between lines (tests set 0). And
//! the command's true wall time (from the start of the process, reading and
//! writing included).

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

/// The delay before progress shows, and (not on a terminal) between two
/// progress lines: `HYDROCYL_PROGRESS_SECONDS` when set (tests set 0: a
/// line at every update), else one second and five.
fn pacing() -> (Duration, Duration) {
    match std::env::var("HYDROCYL_PROGRESS_SECONDS")
        .ok()
        .and_then(|s| s.parse::<f64>().ok())
        .filter(|s| s.is_finite() && *s >= 0.0)
    {
        Some(s) => (Duration::from_secs_f64(s), Duration::from_secs_f64(s)),
        None => (Duration::from_secs(1), Duration::from_secs(5)),
    }
}

/// How progress is shown.
enum Shown {
    /// An indicatif bar redrawn in place (stderr is a terminal).
    Bar(ProgressBar),
    /// Plain lines, one per `every` at most (`--progress` with stderr not a
    /// terminal: a CI log, a file), each the stage, the position, the
    /// elapsed time and the estimate of the stage's remaining time.
    Lines {
        /// What runs (`simulate`, `diagnose`).
        what: String,
        /// The least time between two lines.
        every: Duration,
        /// When the last line was written.
        last: Option<Instant>,
        /// The current stage and when it started (the estimate is the stage's).
        stage: String,
        /// When the stage started.
        stage_since: Instant,
    },
}

/// Progress that shows itself after a second (see the module doc).
pub struct Progress {
    shown: Option<Shown>,
    drawn: bool,
    since: Instant,
    after: Duration,
}

impl Progress {
    /// Progress over `len` units of `what`; `force` = `--progress`, `quiet` = `--quiet`.
    pub fn new(what: &str, len: u64, force: bool, quiet: bool) -> Self {
        let (after, every) = pacing();
        let shown = if quiet {
            None
        } else if std::io::stderr().is_terminal() {
            let b = ProgressBar::with_draw_target(Some(len), ProgressDrawTarget::hidden());
            b.set_style(
                ProgressStyle::with_template(&format!(
                    "{{spinner}} {what} [{{bar:30}}] {{pos}}/{{len}} {{msg}} ({{elapsed}}, eta {{eta}})"
                ))
                .unwrap_or_else(|_| ProgressStyle::default_bar()),
            );
            Some(Shown::Bar(b))
        } else if force {
            Some(Shown::Lines {
                what: what.to_string(),
                every,
                last: None,
                stage: String::new(),
                stage_since: Instant::now(),
            })
        } else {
            None
        };
        Progress {
            shown,
            drawn: false,
            since: Instant::now(),
            after,
        }
    }

    /// Sets the position (and total) with a stage message.
    pub fn set(&mut self, stage: &str, done: u64, total: u64) {
        let late = self.since.elapsed() >= self.after;
        match &mut self.shown {
            None => {}
            Some(Shown::Bar(b)) => {
                if !self.drawn && late {
                    b.set_draw_target(ProgressDrawTarget::stderr());
                    self.drawn = true;
                }
                b.set_length(total);
                b.set_position(done);
                if !stage.is_empty() {
                    b.set_message(stage.to_string());
                }
            }
            Some(Shown::Lines {
                what,
                every,
                last,
                stage: current,
                stage_since,
            }) => {
                if !stage.is_empty() && stage != current {
                    // the first stage started with the progress
                    if !current.is_empty() {
                        *stage_since = Instant::now();
                    }
                    *current = stage.to_string();
                }
                let due = last.is_none_or(|l| l.elapsed() >= *every);
                if !(late && due) {
                    return;
                }
                *last = Some(Instant::now());
                let percent = if total > 0 {
                    format!(" ({:.0}%)", 100.0 * done as f64 / total as f64)
                } else {
                    String::new()
                };
                let eta = if done > 0 && done < total {
                    let s =
                        stage_since.elapsed().as_secs_f64() * (total - done) as f64 / done as f64;
                    format!(", eta {s:.1} s")
                } else {
                    String::new()
                };
                crate::console::note(format_args!(
                    "hydrocyl: {what}: {current} {done}/{total}{percent} after {:.1} s{eta}",
                    self.since.elapsed().as_secs_f64()
                ));
            }
        }
    }

    /// Removes the bar (the lines stay).
    pub fn finish(&self) {
        if let Some(Shown::Bar(b)) = &self.shown {
            b.finish_and_clear();
        }
    }
}
