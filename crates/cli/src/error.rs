//! The CLI's error type: every failure is one line naming what and where.

use thiserror::Error;

/// A failure of a subcommand, printed as one line with exit code 2.
#[derive(Debug, Error)]
pub enum CliError {
    /// Bad user input (argument, file content); the message names what and where.
    #[error("{0}")]
    Input(String),
    /// A file could not be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The I/O error.
        source: std::io::Error,
    },
}
