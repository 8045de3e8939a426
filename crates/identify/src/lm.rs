//! Least-squares refits of effect parameters: hydrocyl-fit's bounded
//! Levenberg–Marquardt, driven in scaled parameters, with confidence
//! intervals corrected for correlated residuals.
//!
//! Minimises `Σ r_i(x)²` over `lower ≤ x ≤ upper`. Parameters are divided by
//! a typical magnitude before they reach the solver (so that a leakage
//! coefficient of 1e-12 and a mass of 100 are equally well conditioned). The
//! solver's interval is `s² (JᵀJ)⁻¹`-based, which assumes independent
//! residuals; samples of a measured record are not independent, so the
//! interval is widened by `√((1 + ρ)/(1 − ρ))` where ρ is the residual's
//! lag-1 autocorrelation (the AR(1) variance-inflation factor), taken per
//! channel block and the largest used.

use std::cell::RefCell;
use std::sync::Mutex;

use hydrocyl_fit::{FitError, Options, Problem, Residuals};
use rayon::prelude::*;
use thiserror::Error;

/// Options of a fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LmOptions {
    /// Most residual evaluations.
    pub max_evaluations: usize,
    /// Stop when an accepted step lowers the cost by less than this share.
    pub ftol: f64,
    /// Relative finite-difference step of the Jacobian, in scaled parameters.
    /// Models integrated by an adaptive solver need a step well above the
    /// solver's tolerance, or the Jacobian measures the solver's noise.
    pub fd_step: f64,
    /// The residual vector is this many equal-length blocks (channels); the
    /// interval is widened by the largest of the blocks' AR(1) factors.
    pub blocks: usize,
    /// The step is `fd_step × max(|x|, fd_floor)` in scaled parameters;
    /// `None` as `hydrocyl_fit::Options::fd_floor`. 1 makes it at least
    /// `fd_step` of the parameter's typical size.
    pub fd_floor: Option<f64>,
    /// Forward differences only (see
    /// `hydrocyl_fit::Options::forward_differences`).
    pub forward_differences: bool,
    /// Also converged when the Gauss–Newton step is below this many
    /// standard errors in every free parameter (0 = off; see
    /// `hydrocyl_fit::Options::step_se`).
    pub step_se: f64,
    /// The last this many parameters are nuisance parameters, left out of
    /// the `step_se` test (see `hydrocyl_fit::Options::step_se_nuisance`).
    pub step_se_nuisance: usize,
    /// Stop after this many rejected steps in a row (0 = no limit; see
    /// `hydrocyl_fit::Options::max_rejections`).
    pub max_rejections: usize,
}

impl Default for LmOptions {
    fn default() -> Self {
        Self {
            max_evaluations: 800,
            ftol: 1e-8,
            fd_step: 1e-7,
            blocks: 1,
            fd_floor: None,
            forward_differences: false,
            step_se: 0.0,
            step_se_nuisance: 0,
            max_rejections: 0,
        }
    }
}

/// The result of a fit.
#[derive(Clone, Debug, PartialEq)]
pub struct LmResult {
    /// Fitted parameters.
    pub x: Vec<f64>,
    /// Half-width of the 95 % confidence interval of each parameter
    /// (`NaN` when the parameter is on a bound or not identifiable).
    pub ci95: Vec<f64>,
    /// Final residual sum of squares.
    pub rss: f64,
    /// Number of residuals.
    pub m: usize,
    /// Iterations taken.
    pub iterations: usize,
    /// Residual evaluations taken.
    pub evaluations: usize,
    /// Which parameters ended on a bound.
    pub at_bound: Vec<bool>,
}

/// Why a fit failed.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum LmError {
    /// Inputs inconsistent (lengths, scales).
    #[error("fit set-up: {0}")]
    Setup(String),
    /// The model could not be evaluated at the start.
    #[error("model fails at the starting point: {0}")]
    Start(String),
    /// The solver failed (start outside the bounds, no convergence, ...).
    #[error(transparent)]
    Solver(#[from] FitError),
}

/// Fits `x` so that `resid(x)` is small in the least-squares sense.
///
/// `resid` fills its output vector (the same length every call) or returns
/// an error; a trial point whose evaluation fails counts as a worse point.
pub fn fit<F>(
    resid: F,
    x0: &[f64],
    lower: &[f64],
    upper: &[f64],
    typical: &[f64],
    opts: &LmOptions,
) -> Result<LmResult, LmError>
where
    F: FnMut(&[f64], &mut Vec<f64>) -> Result<(), String>,
{
    check_setup(x0, lower, upper, typical)?;
    let cell = RefCell::new((resid, Vec::new()));
    let m = {
        let mut c = cell.borrow_mut();
        let (f, buf) = &mut *c;
        f(x0, buf).map_err(LmError::Start)?;
        buf.len()
    };
    let model = |u: &[f64], r: &mut [f64]| {
        let mut c = cell.borrow_mut();
        let (f, buf) = &mut *c;
        match f(&unscaled(u, typical), buf) {
            Ok(()) if buf.len() == r.len() => r.copy_from_slice(buf),
            _ => r.iter_mut().for_each(|v| *v = f64::NAN),
        }
    };
    solve(model, m, x0, lower, upper, typical, opts)
}

/// [`fit`] for a residual that can be evaluated at several points at once:
/// the finite-difference Jacobian's points are evaluated on the available
/// cores (rayon's pool). The iteration, and so the result, is [`fit`]'s;
/// the residual at the start is evaluated once (where [`fit`] evaluates it
/// twice, once to learn the residual's length).
pub fn fit_parallel<F>(
    resid: F,
    x0: &[f64],
    lower: &[f64],
    upper: &[f64],
    typical: &[f64],
    opts: &LmOptions,
) -> Result<LmResult, LmError>
where
    F: Fn(&[f64], &mut Vec<f64>) -> Result<(), String> + Sync,
{
    fit_parallel_from(resid, x0, None, lower, upper, typical, opts)
}

/// [`fit_parallel`] given the residual at `x0` (`r0`; `None`: evaluated
/// there).
pub fn fit_parallel_from<F>(
    resid: F,
    x0: &[f64],
    r0: Option<Vec<f64>>,
    lower: &[f64],
    upper: &[f64],
    typical: &[f64],
    opts: &LmOptions,
) -> Result<LmResult, LmError>
where
    F: Fn(&[f64], &mut Vec<f64>) -> Result<(), String> + Sync,
{
    check_setup(x0, lower, upper, typical)?;
    let u0 = scaled(x0, typical);
    let r0 = match r0 {
        Some(r0) => r0,
        None => {
            let mut r0 = Vec::new();
            resid(&unscaled(&u0, typical), &mut r0).map_err(LmError::Start)?;
            r0
        }
    };
    let model = Parallel {
        resid,
        typical,
        start: Mutex::new(Some((u0, r0.clone()))),
    };
    solve(model, r0.len(), x0, lower, upper, typical, opts)
}

/// The residual of [`fit_parallel`], in scaled parameters.
struct Parallel<'a, F> {
    resid: F,
    typical: &'a [f64],
    /// The residual at the start, until the solver asks for it.
    start: Mutex<Option<(Vec<f64>, Vec<f64>)>>,
}

impl<F> Residuals for Parallel<'_, F>
where
    F: Fn(&[f64], &mut Vec<f64>) -> Result<(), String> + Sync,
{
    fn residuals(&self, u: &[f64], r: &mut [f64]) {
        if let Ok(mut start) = self.start.lock() {
            if start.as_ref().is_some_and(|(u0, _)| u0 == u) {
                if let Some((_, r0)) = start.take() {
                    if r0.len() == r.len() {
                        r.copy_from_slice(&r0);
                        return;
                    }
                }
            }
        }
        let mut buf = Vec::new();
        match (self.resid)(&unscaled(u, self.typical), &mut buf) {
            Ok(()) if buf.len() == r.len() => r.copy_from_slice(&buf),
            _ => r.iter_mut().for_each(|v| *v = f64::NAN),
        }
    }

    fn residuals_at(&self, points: &[Vec<f64>], out: &mut [Vec<f64>]) {
        points
            .par_iter()
            .zip(out.par_iter_mut())
            .for_each(|(u, r)| self.residuals(u, r));
    }
}

fn check_setup(x0: &[f64], lower: &[f64], upper: &[f64], typical: &[f64]) -> Result<(), LmError> {
    let p = x0.len();
    if lower.len() != p || upper.len() != p || typical.len() != p {
        return Err(LmError::Setup("bounds and scales must match x0".into()));
    }
    if let Some(j) = typical.iter().position(|t| !(*t > 0.0 && t.is_finite())) {
        return Err(LmError::Setup(format!(
            "typical scale of parameter {j} must be > 0"
        )));
    }
    Ok(())
}

/// Parameters divided by their typical sizes (what the solver works in).
fn scaled(x: &[f64], typical: &[f64]) -> Vec<f64> {
    x.iter().zip(typical).map(|(a, s)| a / s).collect()
}

/// Scaled parameters back in their units.
fn unscaled(u: &[f64], typical: &[f64]) -> Vec<f64> {
    u.iter().zip(typical).map(|(a, s)| a * s).collect()
}

/// The solve and its report, for a residual `model` in scaled parameters
/// with `m` residuals.
fn solve<M: Residuals>(
    model: M,
    m: usize,
    x0: &[f64],
    lower: &[f64],
    upper: &[f64],
    typical: &[f64],
    opts: &LmOptions,
) -> Result<LmResult, LmError> {
    let p = x0.len();
    let names: Vec<String> = (0..p).map(|j| format!("x{j}")).collect();
    let names: Vec<&str> = names.iter().map(String::as_str).collect();
    let report = Problem::new(model, m, &names)
        .bounds(&scaled(lower, typical), &scaled(upper, typical))
        .options(Options {
            max_evaluations: opts.max_evaluations,
            ftol: opts.ftol,
            xtol: 1e-10,
            gtol: 1e-8,
            fd_step: opts.fd_step,
            step_se: opts.step_se,
            step_se_nuisance: opts.step_se_nuisance,
            fd_floor: opts.fd_floor,
            forward_differences: opts.forward_differences,
            max_rejections: opts.max_rejections,
            ..Options::default()
        })
        .solve(&scaled(x0, typical))?;
    let nb = opts.blocks.max(1);
    let len = report.residuals.len() / nb;
    let widen = (0..nb)
        .map(|b| {
            let block = &report.residuals[b * len..((b + 1) * len).min(report.residuals.len())];
            let rho = lag1_autocorrelation(block).clamp(0.0, 0.999);
            ((1.0 + rho) / (1.0 - rho)).sqrt()
        })
        .fold(1.0, f64::max);
    let ci95 = report
        .parameters
        .iter()
        .zip(typical)
        .map(|(q, s)| match q.interval {
            Some((lo, hi)) if !q.at_bound => 0.5 * (hi - lo) * widen * s,
            _ => f64::NAN,
        })
        .collect();
    Ok(LmResult {
        x: unscaled(&report.values(), typical),
        ci95,
        rss: report.ssr,
        m,
        iterations: report.iterations,
        evaluations: report.evaluations,
        at_bound: report.parameters.iter().map(|q| q.at_bound).collect(),
    })
}

/// Lag-1 autocorrelation of a sequence (0 for fewer than 3 samples).
pub fn lag1_autocorrelation(r: &[f64]) -> f64 {
    if r.len() < 3 {
        return 0.0;
    }
    let mean = r.iter().sum::<f64>() / r.len() as f64;
    let var: f64 = r.iter().map(|v| (v - mean).powi(2)).sum();
    if var <= 0.0 {
        return 0.0;
    }
    let cov: f64 = r.windows(2).map(|w| (w[0] - mean) * (w[1] - mean)).sum();
    cov / var
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn intervals_cover_the_truth_at_their_level() {
        // y = a exp(-b t) + white noise, 200 noise draws: the 95 % intervals
        // contain the true parameters in about 95 % of the draws.
        let t: Vec<f64> = (0..200).map(|i| i as f64 * 0.02).collect();
        let mut covered = [0usize; 2];
        let draws = 200;
        for seed in 0..draws {
            let e = crate::smooth::gaussian_noise(200, seed);
            let y: Vec<f64> = t
                .iter()
                .zip(&e)
                .map(|(&t, e)| 2.0 * (-1.3 * t).exp() + 0.01 * e)
                .collect();
            let res = fit(
                |x, r| {
                    r.clear();
                    r.extend(
                        t.iter()
                            .zip(&y)
                            .map(|(&t, &y)| x[0] * (-x[1] * t).exp() - y),
                    );
                    Ok(())
                },
                &[1.0, 0.5],
                &[0.0, 0.0],
                &[10.0, 10.0],
                &[1.0, 1.0],
                &LmOptions::default(),
            )
            .unwrap();
            for (k, truth) in [2.0, 1.3].iter().enumerate() {
                if (res.x[k] - truth).abs() < res.ci95[k] {
                    covered[k] += 1;
                }
                assert!(res.ci95[k] < 0.03, "{res:?}");
            }
        }
        for c in covered {
            let share = c as f64 / draws as f64;
            assert!((0.88..=0.99).contains(&share), "coverage {share}");
        }
    }

    #[test]
    fn respects_bounds() {
        // Unconstrained optimum at x = -1; the bound holds it at 0.
        let res = fit(
            |x, r| {
                r.clear();
                r.push(x[0] + 1.0);
                r.push(0.1 * (x[0] + 1.0));
                Ok(())
            },
            &[2.0],
            &[0.0],
            &[5.0],
            &[1.0],
            &LmOptions::default(),
        )
        .unwrap();
        assert_eq!(res.x[0], 0.0);
        assert!(res.at_bound[0]);
        let e = fit(
            |_, r| {
                r.clear();
                r.push(1.0);
                Ok(())
            },
            &[7.0],
            &[0.0],
            &[5.0],
            &[1.0],
            &LmOptions::default(),
        );
        assert!(matches!(e, Err(LmError::Solver(_))), "{e:?}");
    }
}
