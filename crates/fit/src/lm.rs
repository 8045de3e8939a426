//! The bounded Levenberg–Marquardt iteration.

use nalgebra::{DMatrix, DVector};

use crate::error::FitError;
use crate::report::{FitReport, Termination};

/// A least-squares model: residuals `r(p)` (measured − model, or any vector
/// whose squared norm is to be minimised) and optionally their Jacobian.
///
/// Any closure `Fn(&[f64], &mut [f64])` is a `Residuals`; wrap a closure pair
/// in [`WithJacobian`] to supply an analytic Jacobian.
pub trait Residuals {
    /// Writes the residuals at parameters `p` into `r`.
    fn residuals(&self, p: &[f64], r: &mut [f64]);

    /// Writes the Jacobian `∂r_i/∂p_j` row-major into `jac`
    /// (`jac[i * n_params + j]`) and returns `true`; the default returns
    /// `false` and the solver uses finite differences.
    fn jacobian(&self, _p: &[f64], _jac: &mut [f64]) -> bool {
        false
    }

    /// Writes the residuals at each of `points` into the matching entry of
    /// `out` (each as long as the residual vector). The finite-difference
    /// Jacobian asks for all its points in one call; the default evaluates
    /// them in turn, and a model that can evaluate several points at once
    /// (on several cores) overrides it.
    fn residuals_at(&self, points: &[Vec<f64>], out: &mut [Vec<f64>]) {
        for (p, r) in points.iter().zip(out.iter_mut()) {
            self.residuals(p, r);
        }
    }
}

impl<F: Fn(&[f64], &mut [f64])> Residuals for F {
    fn residuals(&self, p: &[f64], r: &mut [f64]) {
        self(p, r)
    }
}

/// A residual closure with its analytic Jacobian closure (row-major, see
/// [`Residuals::jacobian`]).
pub struct WithJacobian<R, J> {
    /// The residuals `r(p)`.
    pub residuals: R,
    /// The Jacobian `∂r/∂p`, row-major.
    pub jacobian: J,
}

impl<R, J> Residuals for WithJacobian<R, J>
where
    R: Fn(&[f64], &mut [f64]),
    J: Fn(&[f64], &mut [f64]),
{
    fn residuals(&self, p: &[f64], r: &mut [f64]) {
        (self.residuals)(p, r)
    }
    fn jacobian(&self, p: &[f64], jac: &mut [f64]) -> bool {
        (self.jacobian)(p, jac);
        true
    }
}

/// Solver settings.
#[derive(Clone, Debug, PartialEq)]
pub struct Options {
    /// Most residual evaluations (trial points and finite-difference columns)
    /// before [`FitError::NotConverged`].
    pub max_evaluations: usize,
    /// Converged when an accepted step lowers the cost by less than `ftol` × cost.
    pub ftol: f64,
    /// Converged when the step is below `xtol` × (‖p‖ + `xtol`).
    pub xtol: f64,
    /// Converged when every free parameter's gradient cosine
    /// `|g_j| / (‖J_j‖ ‖r‖)` is below `gtol`.
    pub gtol: f64,
    /// Initial damping λ (relative to the diagonal of JᵀJ, Marquardt scaling).
    pub initial_lambda: f64,
    /// Relative finite-difference step (absolute where a parameter is zero).
    pub fd_step: f64,
    /// The finite-difference step is `fd_step × max(|p|, fd_floor)`; `None`
    /// takes `1e-3 √fd_step`. A parameter that wanders near zero (an
    /// initial offset) gets a step of `fd_step × |p|` that is far too small
    /// for a model with integration noise unless the floor is raised: its
    /// Jacobian column is then the integrator's noise, and the iteration
    /// wanders with it.
    pub fd_floor: Option<f64>,
    /// Forward differences only (one model evaluation per parameter instead
    /// of two). Their O(h) error is smooth in the parameters, so it moves
    /// the point where `Jᵀr = 0` by a small share of a standard error when
    /// the residual at the minimum is noise; it halves a Jacobian's cost.
    pub forward_differences: bool,
    /// Confidence level of the reported intervals (0.95 = 95 %).
    pub confidence_level: f64,
    /// Converged when the undamped Gauss–Newton step of every free
    /// parameter is below `step_se` × its standard error, both from the
    /// Jacobian at the current point (0 = off). Unlike `ftol`, this says
    /// how far the point is from the minimum in the units of the answer's
    /// own uncertainty, so where the iteration started does not show in
    /// where it stops (in a flat valley a damped step may lower the cost by
    /// less than `ftol` while still several standard errors away).
    pub step_se: f64,
    /// The last this many parameters are nuisance parameters (an initial
    /// state the fit needs but whose value is not the answer): the
    /// `step_se` test leaves them out, so it says how far the answer's
    /// parameters are from the joint minimum — the Gauss–Newton step is the
    /// joint one, so a nuisance parameter still far from its own optimum
    /// moves the others' steps by what it takes with it. A fit whose free
    /// parameters are all nuisance tests them all. 0 (the default): every
    /// parameter is tested.
    pub step_se_nuisance: usize,
    /// Stop ([`Termination::NoReduction`]) after this many trial steps in a
    /// row fail to lower the cost (0 = no limit: until λ overflows or the
    /// step falls below `xtol`). With integration noise in the residual a
    /// point near the minimum rejects every step the noise hides, and the
    /// damping then shrinks the step over a dozen evaluations to nothing.
    pub max_rejections: usize,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            max_evaluations: 5000,
            ftol: 1e-12,
            xtol: 1e-12,
            gtol: 1e-10,
            initial_lambda: 1e-3,
            fd_step: 1e-7,
            fd_floor: None,
            forward_differences: false,
            confidence_level: 0.95,
            step_se: 0.0,
            step_se_nuisance: 0,
            max_rejections: 0,
        }
    }
}

/// A bounded nonlinear least-squares problem: minimise ½‖r(p)‖² subject to
/// `lower ≤ p ≤ upper`.
pub struct Problem<R> {
    model: R,
    n_residuals: usize,
    names: Vec<String>,
    lower: Vec<f64>,
    upper: Vec<f64>,
    options: Options,
}

impl<R: Residuals> Problem<R> {
    /// A problem with `n_residuals` residuals and one parameter per name,
    /// unbounded until [`Problem::bounds`] is called.
    pub fn new(model: R, n_residuals: usize, names: &[&str]) -> Self {
        Self {
            model,
            n_residuals,
            names: names.iter().map(|s| s.to_string()).collect(),
            lower: vec![f64::NEG_INFINITY; names.len()],
            upper: vec![f64::INFINITY; names.len()],
            options: Options::default(),
        }
    }

    /// Sets the parameter bounds (checked by [`Problem::solve`]); use
    /// infinities for an open side.
    pub fn bounds(mut self, lower: &[f64], upper: &[f64]) -> Self {
        self.lower = lower.to_vec();
        self.upper = upper.to_vec();
        self
    }

    /// Replaces the solver settings.
    pub fn options(mut self, options: Options) -> Self {
        self.options = options;
        self
    }

    /// Number of parameters.
    pub fn n_params(&self) -> usize {
        self.names.len()
    }

    fn validate(&self, p0: &[f64]) -> Result<(), FitError> {
        let m = self.n_params();
        if m == 0 || self.n_residuals == 0 {
            return Err(FitError::Empty {
                n_params: m,
                n_residuals: self.n_residuals,
            });
        }
        for (what, got) in [
            ("initial guess", p0.len()),
            ("lower bounds", self.lower.len()),
            ("upper bounds", self.upper.len()),
        ] {
            if got != m {
                return Err(FitError::Dimension {
                    what,
                    got,
                    expected: m,
                });
            }
        }
        for (j, &value) in p0.iter().enumerate() {
            let (lo, hi) = (self.lower[j], self.upper[j]);
            if lo.is_nan() || hi.is_nan() || lo > hi {
                return Err(FitError::InvalidBounds {
                    index: j,
                    name: self.names[j].clone(),
                    lower: lo,
                    upper: hi,
                });
            }
            if !value.is_finite() || value < lo || value > hi {
                return Err(FitError::InitialOutsideBounds {
                    index: j,
                    name: self.names[j].clone(),
                    value,
                    lower: lo,
                    upper: hi,
                });
            }
        }
        Ok(())
    }

    fn eval(&self, p: &[f64], r: &mut DVector<f64>) -> bool {
        self.model.residuals(p, r.as_mut_slice());
        r.iter().all(|x| x.is_finite())
    }

    /// Jacobian at `p` (analytic or finite differences), column-major matrix.
    fn jacobian(
        &self,
        p: &[f64],
        r: &DVector<f64>,
        buf: &mut Vec<f64>,
        evaluations: &mut usize,
    ) -> DMatrix<f64> {
        let (n, m) = (self.n_residuals, self.n_params());
        buf.resize(n * m, 0.0);
        if self.model.jacobian(p, buf) {
            return DMatrix::from_row_slice(n, m, buf);
        }
        // Central differences where both sides are within the bounds, else
        // one-sided; every point first, then the columns.
        let mut points = Vec::with_capacity(2 * m);
        let mut plan = Vec::with_capacity(m);
        for j in 0..m {
            let floor = self
                .options
                .fd_floor
                .unwrap_or(1e-3 * self.options.fd_step.sqrt());
            let h = self.options.fd_step * p[j].abs().max(floor);
            let up_ok = p[j] + h <= self.upper[j];
            let down_ok = p[j] - h >= self.lower[j] && !(self.options.forward_differences && up_ok);
            let mut at = |x: f64| {
                let mut pp = p.to_vec();
                pp[j] = x;
                points.push(pp);
            };
            if up_ok {
                at(p[j] + h);
            }
            if !up_ok || down_ok {
                at(p[j] - h);
            }
            plan.push((h, up_ok, down_ok));
        }
        let mut out = vec![vec![0.0; n]; points.len()];
        self.model.residuals_at(&points, &mut out);
        let out: Vec<DVector<f64>> = out.into_iter().map(DVector::from_vec).collect();
        let mut jac = DMatrix::zeros(n, m);
        let mut k = 0;
        for (j, (h, up_ok, down_ok)) in plan.into_iter().enumerate() {
            if up_ok && down_ok {
                jac.set_column(j, &((&out[k] - &out[k + 1]) / (2.0 * h)));
                k += 2;
            } else if up_ok {
                jac.set_column(j, &((&out[k] - r) / h));
                k += 1;
            } else {
                jac.set_column(j, &((r - &out[k]) / h));
                k += 1;
            }
        }
        *evaluations += k;
        jac
    }

    /// Runs the bounded Levenberg–Marquardt iteration from `p0` and returns the
    /// fitted parameters with their statistics.
    ///
    /// Bounds are kept by projection: each trial point is the damped
    /// Gauss–Newton point projected onto the box, and parameters sitting on a
    /// bound with the gradient pushing outward are held fixed for that
    /// iteration (an active set). Such parameters are flagged
    /// [`crate::Parameter::at_bound`] and get no confidence interval.
    pub fn solve(&self, p0: &[f64]) -> Result<FitReport, FitError> {
        self.validate(p0)?;
        let (n, m) = (self.n_residuals, self.n_params());
        let o = &self.options;
        let mut p = p0.to_vec();
        let mut r = DVector::zeros(n);
        if !self.eval(&p, &mut r) {
            let index = r.iter().position(|x| !x.is_finite()).unwrap_or(0);
            return Err(FitError::NonFiniteResidual { index });
        }
        let mut cost = 0.5 * r.norm_squared();
        let mut buf = Vec::new();
        let mut evaluations = 1usize;
        let mut jac = self.jacobian(&p, &r, &mut buf, &mut evaluations);
        let mut lambda = o.initial_lambda;
        let mut nu = 2.0;
        let mut iterations = 0usize;
        let mut r_new = DVector::zeros(n);
        let termination;
        'outer: loop {
            check_finite(&jac, iterations)?;
            let a = jac.transpose() * &jac;
            let g = jac.transpose() * &r;
            let free: Vec<usize> = (0..m)
                .filter(|&j| {
                    !((p[j] <= self.lower[j] && g[j] > 0.0)
                        || (p[j] >= self.upper[j] && g[j] < 0.0))
                })
                .collect();
            // Gradient test (MINPACK's cosine form) on the free parameters.
            let rnorm = r.norm();
            if rnorm == 0.0 {
                termination = Termination::ZeroResidual;
                break;
            }
            let gmax = free
                .iter()
                .map(|&j| {
                    let cn = a[(j, j)].sqrt();
                    if cn > 0.0 {
                        g[j].abs() / (cn * rnorm)
                    } else {
                        0.0
                    }
                })
                .fold(0.0, f64::max);
            if free.is_empty() || gmax <= o.gtol {
                termination = Termination::Gradient;
                break;
            }
            let k = free.len();
            let answer = m.saturating_sub(o.step_se_nuisance);
            if o.step_se > 0.0 && gauss_newton_within_se(&a, &g, &free, answer, cost, n, o.step_se)
            {
                termination = Termination::StandardError;
                break;
            }
            let max_diag = free.iter().map(|&j| a[(j, j)]).fold(0.0, f64::max);
            let floor = (max_diag * 1e-12).max(f64::MIN_POSITIVE);
            let mut rejected = 0usize;
            // a trial the bounds project onto the point rejected last is
            // rejected again without evaluating it
            let mut last_rejected: Option<Vec<f64>> = None;
            loop {
                if evaluations >= o.max_evaluations {
                    return Err(FitError::NotConverged {
                        iterations,
                        cost,
                        gradient: gmax,
                        lambda,
                    });
                }
                let mut sys = DMatrix::zeros(k, k);
                let mut rhs = DVector::zeros(k);
                for (ii, &i) in free.iter().enumerate() {
                    rhs[ii] = -g[i];
                    for (jj, &j) in free.iter().enumerate() {
                        sys[(ii, jj)] = a[(i, j)];
                    }
                    sys[(ii, ii)] += lambda * a[(i, i)].max(floor);
                }
                let Some(chol) = sys.cholesky() else {
                    lambda *= nu;
                    nu *= 2.0;
                    continue;
                };
                let d = chol.solve(&rhs);
                let mut trial = p.clone();
                for (ii, &j) in free.iter().enumerate() {
                    trial[j] = (p[j] + d[ii]).clamp(self.lower[j], self.upper[j]);
                }
                let step = DVector::from_iterator(m, (0..m).map(|j| trial[j] - p[j]));
                let pnorm = p.iter().map(|x| x * x).sum::<f64>().sqrt();
                if step.norm() <= o.xtol * (pnorm + o.xtol) {
                    termination = Termination::Step;
                    break 'outer;
                }
                let repeat = last_rejected.as_ref() == Some(&trial);
                let (finite, cost_new) = if repeat {
                    (false, f64::INFINITY)
                } else {
                    evaluations += 1;
                    let finite = self.eval(&trial, &mut r_new);
                    (finite, 0.5 * r_new.norm_squared())
                };
                let predicted = -(g.dot(&step) + 0.5 * step.dot(&(&a * &step)));
                let rho = if finite && predicted > 0.0 {
                    (cost - cost_new) / predicted
                } else {
                    -1.0
                };
                if rho > 1e-4 {
                    let reduction = cost - cost_new;
                    p = trial;
                    std::mem::swap(&mut r, &mut r_new);
                    cost = cost_new;
                    iterations += 1;
                    lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                    nu = 2.0;
                    jac = self.jacobian(&p, &r, &mut buf, &mut evaluations);
                    if reduction <= o.ftol * cost {
                        termination = Termination::Cost;
                        break 'outer;
                    }
                    break;
                }
                last_rejected = Some(trial);
                rejected += 1;
                lambda *= nu;
                nu *= 2.0;
                if lambda > 1e30 || (o.max_rejections > 0 && rejected >= o.max_rejections) {
                    termination = Termination::NoReduction;
                    break 'outer;
                }
            }
        }
        check_finite(&jac, iterations)?;
        Ok(FitReport::build(
            &self.names,
            p,
            r,
            &jac,
            &self.lower,
            &self.upper,
            o.confidence_level,
            iterations,
            evaluations,
            termination,
        ))
    }
}

/// Whether the undamped Gauss–Newton step `−A⁻¹g` on the `free` parameters
/// (`A = JᵀJ`, `g = Jᵀr`) is below `tol` standard errors in every free one
/// below index `answer` (in every free one where none is):
/// `|d_j| ≤ tol √(s² (A⁻¹)_jj)` with `s² = 2 cost / (n − k)`. `false` where
/// the free block is singular or there are no degrees of freedom left.
fn gauss_newton_within_se(
    a: &DMatrix<f64>,
    g: &DVector<f64>,
    free: &[usize],
    answer: usize,
    cost: f64,
    n: usize,
    tol: f64,
) -> bool {
    let k = free.len();
    if n <= k {
        return false;
    }
    let sub = DMatrix::from_fn(k, k, |i, j| a[(free[i], free[j])]);
    let rhs = DVector::from_fn(k, |i, _| -g[free[i]]);
    let Some(chol) = sub.cholesky() else {
        return false;
    };
    let d = chol.solve(&rhs);
    let inv = chol.inverse();
    let s2 = 2.0 * cost / (n - k) as f64;
    let all = !free.iter().any(|&j| j < answer);
    (0..k).filter(|&i| all || free[i] < answer).all(|i| {
        let se = (s2 * inv[(i, i)]).sqrt();
        se.is_finite() && d[i].abs() <= tol * se
    })
}

fn check_finite(jac: &DMatrix<f64>, iteration: usize) -> Result<(), FitError> {
    for col in 0..jac.ncols() {
        for row in 0..jac.nrows() {
            if !jac[(row, col)].is_finite() {
                return Err(FitError::NonFiniteJacobian {
                    row,
                    col,
                    iteration,
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_step_test_leaves_the_nuisance_parameters_out_unless_they_are_all_there_is() {
        // Uncorrelated parameters, unit standard errors (A = I·(n−k)/(2
        // cost) makes s²(A⁻¹)_jj = 1): the Gauss–Newton step is −g, 0.01
        // standard errors in the answer, 0.5 in the nuisance.
        let (n, cost) = (12, 5.0);
        let a = DMatrix::<f64>::identity(2, 2) * ((n - 2) as f64 / (2.0 * cost));
        let g = DVector::from_vec(vec![0.01, -0.5]).component_mul(&a.diagonal());
        let within =
            |free: &[usize], answer| gauss_newton_within_se(&a, &g, free, answer, cost, n, 0.05);
        // every parameter tested: the nuisance's step is too long
        assert!(!within(&[0, 1], 2));
        // the answer alone: within
        assert!(within(&[0, 1], 1));
        // all nuisance (or no free answer parameter): all are tested
        assert!(!within(&[0, 1], 0));
        assert!(!within(&[1], 1));
    }
}
