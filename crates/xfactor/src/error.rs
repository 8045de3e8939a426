//! The error type of this crate.

use thiserror::Error;

/// Bad input to an X-factor or steady-pressure function, or a root finder that
/// could not meet its tolerance. Every variant names the offending argument
/// and its value.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum XFactorError {
    /// The area ratio gamma = A1/A2 is NaN, infinite or below 1.
    #[error("area ratio gamma = {gamma:?} is out of range: it must be finite and >= 1 (gamma = A1/A2, piston side over rod side)")]
    GammaOutOfRange {
        /// The value given.
        gamma: f64,
    },
    /// The normalised spool travel is NaN (an infinite travel is allowed: it is outside the underlap).
    #[error("spool travel = {travel:?} is not a number (travel = spool position / underlap)")]
    TravelNotANumber {
        /// The value given.
        travel: f64,
    },
    /// The tolerance of the numerical solver is not a positive finite number.
    #[error("tolerance = {tol:?} is out of range: it must be finite and > 0")]
    ToleranceOutOfRange {
        /// The value given.
        tol: f64,
    },
    /// Brent's method did not meet its tolerance within its iteration budget.
    #[error("Brent's method did not converge to tolerance {tol:?} within {iterations} iterations (last bracket width {width:?})")]
    NoConvergence {
        /// The tolerance asked for.
        tol: f64,
        /// Iterations spent.
        iterations: usize,
        /// Width of the last bracket.
        width: f64,
    },
    /// A physical argument (pressure, area, force, flow coefficient) is NaN,
    /// infinite, or has a sign it cannot have.
    #[error("{what} = {value:?} is out of range: {why}")]
    ParameterOutOfRange {
        /// Which argument.
        what: &'static str,
        /// The value given (SI units).
        value: f64,
        /// What it must be.
        why: &'static str,
    },
    /// No steady state exists with both chamber pressures in [0, Ps]: the load
    /// is more than the supply can hold at this spool travel.
    #[error("no steady state at travel {travel:?}: load force {force_n:?} N needs a chamber pressure outside [0, Ps] (Ps = {ps_pa:?} Pa)")]
    NoSteadyState {
        /// The normalised spool travel.
        travel: f64,
        /// The net load force \[N\].
        force_n: f64,
        /// The supply pressure \[Pa\].
        ps_pa: f64,
    },
    /// No X under this load keeps both chamber pressures in [0, Ps].
    #[error("no steady state at travel {travel:?}: load pressure P_LE / Ps = {p_le_over_ps:?} needs a chamber pressure outside [0, Ps]")]
    LoadBeyondSupply {
        /// The normalised spool travel.
        travel: f64,
        /// The effective load pressure over the supply pressure.
        p_le_over_ps: f64,
    },
}
