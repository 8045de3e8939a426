//! Why a fit could not be done.

use thiserror::Error;

/// A fit that could not start or could not finish.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum FitError {
    /// The problem has no parameters or no residuals.
    #[error("empty problem: {n_params} parameters, {n_residuals} residuals")]
    Empty {
        /// Number of parameters.
        n_params: usize,
        /// Number of residuals.
        n_residuals: usize,
    },
    /// A vector given with the problem has the wrong length.
    #[error("{what} has length {got}, expected {expected}")]
    Dimension {
        /// Which vector.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The length it must have.
        expected: usize,
    },
    /// A bound pair is NaN or has lower > upper.
    #[error("bounds of parameter {index} ({name}) are invalid: [{lower}, {upper}]")]
    InvalidBounds {
        /// Parameter index.
        index: usize,
        /// Parameter name.
        name: String,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// The initial guess is NaN or outside its bounds.
    #[error("initial value {value} of parameter {index} ({name}) is outside [{lower}, {upper}] or not finite")]
    InitialOutsideBounds {
        /// Parameter index.
        index: usize,
        /// Parameter name.
        name: String,
        /// The initial value.
        value: f64,
        /// Lower bound.
        lower: f64,
        /// Upper bound.
        upper: f64,
    },
    /// The residual function returned NaN or infinity at the initial guess.
    #[error("residual {index} is not finite at the initial guess")]
    NonFiniteResidual {
        /// Index of the offending residual.
        index: usize,
    },
    /// The Jacobian has a NaN or infinite entry at an accepted point.
    #[error(
        "Jacobian entry (residual {row}, parameter {col}) is not finite at iteration {iteration}"
    )]
    NonFiniteJacobian {
        /// Residual index.
        row: usize,
        /// Parameter index.
        col: usize,
        /// Iteration reached.
        iteration: usize,
    },
    /// The iteration limit was reached before any convergence test passed.
    #[error("no convergence after {iterations} iterations: cost {cost:e}, projected gradient {gradient:e}, damping {lambda:e}")]
    NotConverged {
        /// Iterations done.
        iterations: usize,
        /// Half the sum of squared residuals reached.
        cost: f64,
        /// Infinity norm of the projected gradient reached.
        gradient: f64,
        /// Damping parameter reached.
        lambda: f64,
    },
}
