//! The terminal's two streams. Standard output is an output like a file: a
//! write that fails (a closed pipe, `hydrocyl components | head -1`) is an
//! error naming `<stdout>`, exit code 2, never a panic. Standard error
//! carries notes and the error line itself, best effort: when it is closed
//! too there is nobody left to tell, and the exit code still says it.

use crate::error::CliError;
use std::io::Write as _;
use std::sync::Mutex;

/// Warnings held until the command ends ([`hold_warning`]).
static HELD: Mutex<Vec<String>> = Mutex::new(Vec::new());

/// Holds a warning (one line, without the `hydrocyl: warning: ` prefix)
/// until the command ends: printed after its output when it succeeds
/// ([`print_held`]), added to its error line when it fails
/// ([`error_line`]), which the warning may explain (a solver that fails on
/// a bulk modulus meant in bar) while the error stays one line.
pub fn hold_warning(w: String) {
    if let Ok(mut h) = HELD.lock() {
        h.push(w);
    }
}

/// The warnings held so far, taken.
fn take_held() -> Vec<String> {
    HELD.lock()
        .map(|mut h| std::mem::take(&mut *h))
        .unwrap_or_default()
}

/// Prints the warnings held so far, one `hydrocyl: warning: …` line each
/// (none with `quiet`, which drops them).
pub fn print_held(quiet: bool) {
    for w in take_held() {
        if !quiet {
            note(format_args!("hydrocyl: warning: {w}"));
        }
    }
}

/// The one line of a failed command's error `e`, with the warnings held
/// so far after it.
pub fn error_line(e: &CliError) -> String {
    let held = take_held();
    if held.is_empty() {
        format!("hydrocyl: error: {e}")
    } else {
        format!("hydrocyl: error: {e} (and a warning: {})", held.join("; "))
    }
}

/// Writes `text` to standard output and flushes it.
pub fn print(text: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(|source| CliError::Io {
            path: "<stdout>".into(),
            source,
        })
}

/// Writes one line to standard error, ignoring a closed stream.
pub fn note(line: std::fmt::Arguments<'_>) {
    let _ = writeln!(std::io::stderr().lock(), "{line}");
}
