//! # hydrocyl-fit — bounded nonlinear least squares with confidence intervals
//!
//! hydrocyl identifies model parameters from measured data (the friction
//! curve of thesis Table 5-3, seal friction against pressure, refits of rig
//! models against records). This crate is the one fitting engine they share:
//!
//! ```text
//!   residual closure r(p) ──▶ ┌──────────────────────────┐ ──▶ estimates p̂, RMSE
//!   (optional ∂r/∂p)      ──▶ │ bounded Levenberg–Marquardt│ ──▶ std errors, 95 % intervals
//!   bounds lo ≤ p ≤ hi    ──▶ └──────────────────────────┘ ──▶ correlations, identifiability
//! ```
//!
//! It minimises `½ Σ r_i(p)²` subject to box bounds by Levenberg–Marquardt
//! with Marquardt's diagonal scaling and Nielsen's damping update; the
//! bounds are kept by projecting each trial point onto the box and holding
//! parameters whose gradient pushes them out of it (an active set). The
//! Jacobian is analytic when the model gives one ([`WithJacobian`] or
//! [`Residuals::jacobian`]), central finite differences otherwise (one-sided at
//! a bound). It implements no thesis equation; the thesis fitted its friction
//! curve with MATLAB's `cftool`, which this replaces.
//!
//! Statistics at the estimate p̂ (k free parameters, n residuals):
//! * residual variance `s² = Σ r² / (n − k)`; covariance `s² (JᵀJ)⁻¹`;
//! * confidence interval `p̂_j ± t_{(1+level)/2, n−k} · sqrt(C_jj)` with a
//!   hand-written Student-t quantile ([`student_t_two_sided`]);
//! * `RMSE = sqrt(Σ r² / n)` in the residuals' unit;
//! * singular values and condition number of the Jacobian with columns scaled
//!   by |p_j|, so that a near-singular direction (parameters the data cannot
//!   separate) shows as a huge condition number, and
//!   [`FitReport::unidentifiable`] lists parameters with no interval or an
//!   interval wider than ±100 %.
//!
//! Parameters and residuals carry whatever unit the caller gives them; the
//! standard errors and intervals are in each parameter's unit, the RMSE in the
//! residuals' unit.
//!
//! ```
//! use hydrocyl_fit::{Problem, Termination};
//!
//! // y = a exp(-b t) sampled without noise: the fit recovers a = 2, b = 0.5.
//! let t: Vec<f64> = (0..20).map(|i| i as f64 * 0.25).collect();
//! let y: Vec<f64> = t.iter().map(|t| 2.0 * (-0.5 * t).exp()).collect();
//! let model = |p: &[f64], r: &mut [f64]| {
//!     for i in 0..t.len() {
//!         r[i] = y[i] - p[0] * (-p[1] * t[i]).exp();
//!     }
//! };
//! let fit = Problem::new(model, t.len(), &["a", "b"])
//!     .bounds(&[0.0, 0.0], &[10.0, 10.0])
//!     .solve(&[1.0, 1.0])
//!     .unwrap();
//! assert!((fit.parameters[0].value - 2.0).abs() < 1e-8);
//! assert!((fit.parameters[1].value - 0.5).abs() < 1e-8);
//! assert!(fit.rmse < 1e-9);
//! assert_ne!(fit.termination, Termination::NoReduction);
//! ```
#![warn(missing_docs)]

mod error;
mod lm;
mod report;
mod stats;

pub use error::FitError;
pub use lm::{Options, Problem, Residuals, WithJacobian};
pub use report::{FitReport, Parameter, Termination};
pub use stats::{student_t_cdf, student_t_two_sided};
