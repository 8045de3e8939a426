//! What a fit reports: estimates, standard errors, confidence intervals,
//! correlations, RMSE and an identifiability verdict.

use nalgebra::{DMatrix, DVector};
use std::fmt::Write as _;

use crate::stats::student_t_two_sided;

/// Which convergence test ended the iteration.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Termination {
    /// Every free parameter's gradient cosine fell below `gtol`.
    Gradient,
    /// The step fell below `xtol`.
    Step,
    /// An accepted step lowered the cost by less than `ftol` × cost.
    Cost,
    /// The residuals are exactly zero.
    ZeroResidual,
    /// No trial step lowered the cost even at very large damping: the point is
    /// a minimum to machine precision.
    NoReduction,
    /// The Gauss–Newton step fell below `step_se` standard errors in every
    /// free parameter.
    StandardError,
}

/// One fitted parameter.
#[derive(Clone, Debug, PartialEq)]
pub struct Parameter {
    /// Name given with the problem.
    pub name: String,
    /// Estimate.
    pub value: f64,
    /// Standard error (square root of the covariance diagonal); `None` when the
    /// parameter is on a bound, there are no degrees of freedom, or the
    /// parameter lies in a near-null direction of the scaled Jacobian (the
    /// data cannot move it).
    pub std_error: Option<f64>,
    /// Confidence interval `value ± t · std_error` at the report's level.
    pub interval: Option<(f64, f64)>,
    /// The estimate sits on a bound (held there by the bound, not the data).
    pub at_bound: bool,
}

impl Parameter {
    /// Half-width of the confidence interval relative to |value| (∞ when unknown).
    pub fn relative_uncertainty(&self) -> f64 {
        match self.interval {
            Some((lo, hi)) if self.value != 0.0 => 0.5 * (hi - lo) / self.value.abs(),
            _ => f64::INFINITY,
        }
    }
}

/// The result of a fit.
#[derive(Clone, Debug)]
pub struct FitReport {
    /// The parameters, in problem order.
    pub parameters: Vec<Parameter>,
    /// Residuals at the estimate.
    pub residuals: Vec<f64>,
    /// Sum of squared residuals.
    pub ssr: f64,
    /// Root-mean-square residual `sqrt(ssr / n)`.
    pub rmse: f64,
    /// Degrees of freedom `n − k` (k = parameters not on a bound).
    pub dof: usize,
    /// Residual variance `ssr / dof` (`None` without degrees of freedom).
    pub residual_variance: Option<f64>,
    /// Covariance `s² (JᵀJ)⁻¹` over all parameters (rows and columns of
    /// parameters on a bound are zero); `None` without degrees of freedom or
    /// when JᵀJ is singular (then only the parameters outside its near-null
    /// space get standard errors, from the pseudo-inverse).
    pub covariance: Option<DMatrix<f64>>,
    /// Correlation matrix derived from the covariance.
    pub correlation: Option<DMatrix<f64>>,
    /// Singular values of the Jacobian of the free parameters, each column
    /// scaled by its parameter's magnitude, largest first.
    pub singular_values: Vec<f64>,
    /// Ratio of the largest to the smallest scaled singular value.
    pub condition_number: f64,
    /// Confidence level of the intervals.
    pub confidence_level: f64,
    /// Accepted iterations.
    pub iterations: usize,
    /// Residual evaluations (including finite-difference columns).
    pub evaluations: usize,
    /// The convergence test that ended the iteration.
    pub termination: Termination,
}

/// Scaled condition number above which JᵀJ is treated as singular.
const SINGULAR_CONDITION: f64 = 1e10;

impl FitReport {
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn build(
        names: &[String],
        p: Vec<f64>,
        r: DVector<f64>,
        jac: &DMatrix<f64>,
        lower: &[f64],
        upper: &[f64],
        level: f64,
        iterations: usize,
        evaluations: usize,
        termination: Termination,
    ) -> Self {
        let (n, m) = jac.shape();
        let g = jac.transpose() * &r;
        let at_bound: Vec<bool> = (0..m)
            .map(|j| (p[j] <= lower[j] && g[j] >= 0.0) || (p[j] >= upper[j] && g[j] <= 0.0))
            .collect();
        let free: Vec<usize> = (0..m).filter(|&j| !at_bound[j]).collect();
        let k = free.len();
        let ssr = r.norm_squared();
        let rmse = (ssr / n as f64).sqrt();
        let dof = n.saturating_sub(k);
        let residual_variance = (dof > 0).then(|| ssr / dof as f64);

        // Scaled Jacobian of the free parameters: columns × |p_j| (or 1).
        let scale: Vec<f64> = free
            .iter()
            .map(|&j| if p[j] != 0.0 { p[j].abs() } else { 1.0 })
            .collect();
        let mut js = DMatrix::zeros(n, k);
        for (c, &j) in free.iter().enumerate() {
            js.set_column(c, &(jac.column(j) * scale[c]));
        }
        // Covariance of the free parameters from the SVD of the scaled
        // Jacobian: (JsᵀJs)⁺ = V Σ⁻² Vᵀ over the singular values above
        // smax / SINGULAR_CONDITION. A parameter with a component in the
        // discarded (near-null) directions is undetermined; the others keep
        // their intervals even when the problem as a whole is rank deficient.
        let mut determined = vec![false; k];
        let (singular_values, condition_number, cov_free) = if k == 0 {
            (Vec::new(), 1.0, None)
        } else {
            let svd = js.clone().svd(false, true);
            let mut sv: Vec<f64> = svd.singular_values.iter().copied().collect();
            sv.sort_by(|a, b| b.total_cmp(a));
            let smax = sv.first().copied().unwrap_or(0.0);
            let smin = if n >= k {
                sv.last().copied().unwrap_or(0.0)
            } else {
                0.0
            };
            let cond = if smin > 0.0 {
                smax / smin
            } else {
                f64::INFINITY
            };
            let cov = match (residual_variance, svd.v_t) {
                (Some(s2), Some(vt)) if n >= k && smax > 0.0 => {
                    let keep = smax / SINGULAR_CONDITION;
                    determined = (0..k)
                        .map(|a| {
                            svd.singular_values
                                .iter()
                                .enumerate()
                                .all(|(idx, s)| *s > keep || vt[(idx, a)].abs() <= 1e-6)
                        })
                        .collect();
                    let mut inv = DMatrix::zeros(k, k);
                    for (idx, s) in svd.singular_values.iter().enumerate() {
                        if *s > keep {
                            let v = vt.row(idx).transpose();
                            inv += (&v * v.transpose()) / (s * s);
                        }
                    }
                    for a in 0..k {
                        for b in 0..k {
                            inv[(a, b)] *= s2 * scale[a] * scale[b];
                        }
                    }
                    Some(inv)
                }
                _ => None,
            };
            (sv, cond, cov)
        };
        let full_rank = condition_number < SINGULAR_CONDITION;

        let t = student_t_two_sided(level, dof);
        let mut covariance = None;
        let mut correlation = None;
        let mut parameters: Vec<Parameter> = (0..m)
            .map(|j| Parameter {
                name: names[j].clone(),
                value: p[j],
                std_error: None,
                interval: None,
                at_bound: at_bound[j],
            })
            .collect();
        if let Some(cf) = cov_free {
            let mut cov = DMatrix::zeros(m, m);
            for (a, &i) in free.iter().enumerate() {
                for (b, &j) in free.iter().enumerate() {
                    cov[(i, j)] = cf[(a, b)];
                }
            }
            let mut corr = DMatrix::zeros(m, m);
            for &i in &free {
                for &j in &free {
                    corr[(i, j)] = cov[(i, j)] / (cov[(i, i)] * cov[(j, j)]).sqrt();
                }
            }
            for (a, &j) in free.iter().enumerate() {
                if determined[a] {
                    let se = cov[(j, j)].sqrt();
                    parameters[j].std_error = Some(se);
                    parameters[j].interval = t.map(|t| (p[j] - t * se, p[j] + t * se));
                }
            }
            if full_rank {
                covariance = Some(cov);
                correlation = Some(corr);
            }
        }
        Self {
            parameters,
            residuals: r.iter().copied().collect(),
            ssr,
            rmse,
            dof,
            residual_variance,
            covariance,
            correlation,
            singular_values,
            condition_number,
            confidence_level: level,
            iterations,
            evaluations,
            termination,
        }
    }

    /// The estimates, in problem order.
    pub fn values(&self) -> Vec<f64> {
        self.parameters.iter().map(|p| p.value).collect()
    }

    /// The parameter called `name`, if any.
    pub fn get(&self, name: &str) -> Option<&Parameter> {
        self.parameters.iter().find(|p| p.name == name)
    }

    /// Indices of the parameters the data do not determine: no confidence
    /// interval (no degrees of freedom, singular JᵀJ), or an interval whose
    /// half-width exceeds |value|. Parameters on a bound are not listed here
    /// (see [`Parameter::at_bound`]).
    pub fn unidentifiable(&self) -> Vec<usize> {
        (0..self.parameters.len())
            .filter(|&j| {
                let p = &self.parameters[j];
                !p.at_bound && p.relative_uncertainty() > 1.0
            })
            .collect()
    }

    /// Pairs of free parameters with |correlation| above `threshold`.
    pub fn strong_correlations(&self, threshold: f64) -> Vec<(usize, usize, f64)> {
        let mut out = Vec::new();
        if let Some(c) = &self.correlation {
            for i in 0..c.nrows() {
                for j in (i + 1)..c.ncols() {
                    if c[(i, j)].abs() > threshold {
                        out.push((i, j, c[(i, j)]));
                    }
                }
            }
        }
        out
    }

    /// A plain-text table of the estimates, intervals and fit statistics.
    pub fn summary(&self) -> String {
        let mut s = String::new();
        let pct = 100.0 * self.confidence_level;
        let _ = writeln!(
            s,
            "{:<10} {:>14} {:>14} {:>30}",
            "parameter",
            "estimate",
            "std error",
            format!("{pct:.0} % interval")
        );
        for p in &self.parameters {
            let se = p
                .std_error
                .map_or_else(|| "-".to_string(), |v| format!("{v:.4e}"));
            let ci = match (p.at_bound, p.interval) {
                (true, _) => "at bound".to_string(),
                (false, Some((lo, hi))) => format!("[{lo:.4e}, {hi:.4e}]"),
                (false, None) => "undetermined".to_string(),
            };
            let _ = writeln!(s, "{:<10} {:>14.6e} {:>14} {:>30}", p.name, p.value, se, ci);
        }
        let _ = writeln!(
            s,
            "RMSE {:.4e}, dof {}, condition {:.3e}, {} iterations, {:?}",
            self.rmse, self.dof, self.condition_number, self.iterations, self.termination
        );
        s
    }
}
