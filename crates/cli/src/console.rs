//! The terminal's two streams. Standard output is an output like a file: a
//! write that fails (a closed pipe, `hydrocyl components | head -1`) is an
//! error naming `<stdout>`, exit code 2, never a panic. Standard error
//! carries notes and the error line itself, best effort: when it is closed
//! too there is nobody left to tell, and the exit code still says it.

use crate::error::CliError;
use std::io::Write as _;

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
