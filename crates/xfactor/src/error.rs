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
    #[error("no steady state at travel {travel:.4}: load force {force_n:.1} N needs a chamber pressure outside [0, Ps] (Ps = {ps_pa:.0} Pa)")]
    NoSteadyState {
        /// The normalised spool travel.
        travel: f64,
        /// The net load force \[N\].
        force_n: f64,
        /// The supply pressure \[Pa\].
        ps_pa: f64,
    },
    /// No X under this load keeps both chamber pressures in [0, Ps].
    #[error("no steady state at travel {travel:.4}: load pressure P_LE / Ps = {p_le_over_ps:.4} needs a chamber pressure outside [0, Ps]")]
    LoadBeyondSupply {
        /// The normalised spool travel.
        travel: f64,
        /// The effective load pressure over the supply pressure.
        p_le_over_ps: f64,
    },
}

#[cfg(test)]
mod tests {
    use super::XFactorError;

    /// A user reads these: the figures are rounded to what they mean.
    #[test]
    fn steady_state_failures_print_rounded_figures() {
        let e = XFactorError::NoSteadyState {
            travel: -1.973_916_666_666_666_8,
            force_n: 1234.5678,
            ps_pa: 7.0e6,
        };
        assert_eq!(
            e.to_string(),
            "no steady state at travel -1.9739: load force 1234.6 N needs a chamber pressure \
             outside [0, Ps] (Ps = 7000000 Pa)"
        );
        let e = XFactorError::LoadBeyondSupply {
            travel: 0.333_333_333_333_333_3,
            p_le_over_ps: 1.123_456_789,
        };
        assert!(e
            .to_string()
            .contains("travel 0.3333: load pressure P_LE / Ps = 1.1235 "));
    }
}
