//! Errors: a parameter out of its range, a malformed friction data file, a
//! fit that failed.

use thiserror::Error;

/// What went wrong, naming the model, parameter, file or line.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum FrictionError {
    /// A parameter is NaN, infinite or outside its physical range.
    #[error("{model}: parameter {name} = {value} is invalid ({requirement})")]
    Parameter {
        /// The model (and direction) the parameter belongs to.
        model: &'static str,
        /// The parameter.
        name: &'static str,
        /// Its value in SI units.
        value: f64,
        /// The range it must be in.
        requirement: &'static str,
    },
    /// A data file could not be read.
    #[error("cannot read {path}: {message}")]
    Io {
        /// The file.
        path: String,
        /// The operating system's message.
        message: String,
    },
    /// A data file has a malformed line.
    #[error("{path}, line {line}: {message}")]
    Malformed {
        /// The file.
        path: String,
        /// 1-based line number (the header is line 1).
        line: usize,
        /// What is wrong.
        message: String,
    },
    /// Too few data points for the requested fit.
    #[error("{what}: {got} points, at least {needed} needed")]
    TooFewPoints {
        /// Which fit.
        what: String,
        /// Points available.
        got: usize,
        /// Points needed.
        needed: usize,
    },
    /// The least-squares fit failed.
    #[error("fit of {what} failed: {source}")]
    Fit {
        /// Which fit.
        what: String,
        /// The solver's reason.
        source: hydrocyl_fit::FitError,
    },
}

/// Checks that `value` is finite and `> 0`.
pub(crate) fn positive(
    model: &'static str,
    name: &'static str,
    value: f64,
) -> Result<(), FrictionError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(FrictionError::Parameter {
            model,
            name,
            value,
            requirement: "finite and > 0",
        })
    }
}

/// Checks that `value` is finite and `>= 0`.
pub(crate) fn non_negative(
    model: &'static str,
    name: &'static str,
    value: f64,
) -> Result<(), FrictionError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(FrictionError::Parameter {
            model,
            name,
            value,
            requirement: "finite and >= 0",
        })
    }
}
