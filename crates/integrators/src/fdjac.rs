//! The forward-difference Jacobian the linearly implicit steppers fall back
//! on when the model gives none (Rosenbrock, exponential Euler).

use crate::api::{OdeSystem, Stats};

/// Work vectors and the rule for one forward-difference Jacobian.
pub(crate) struct ForwardDifference<'a> {
    /// `f(t, x)`, already evaluated.
    pub f0: &'a [f64],
    /// States below this index are differenced; the rest (quadratures, on
    /// which nothing depends) get zero columns.
    pub differenced: usize,
    /// A perturbed copy of `x` (length n).
    pub y: &'a mut [f64],
    /// `f` at the perturbed state (length n).
    pub fy: &'a mut [f64],
    /// The Jacobian, row-major n×n.
    pub jac: &'a mut [f64],
}

impl ForwardDifference<'_> {
    /// Fills `jac` with `(f(x + δ_j e_j) − f0) / δ_j`,
    /// `δ_j = √ε · max(|x_j|, floor(j))`; `seen` is called with every
    /// perturbed evaluation (for a caller that checks it is finite).
    pub(crate) fn fill<S: OdeSystem + ?Sized>(
        self,
        sys: &S,
        t: f64,
        x: &[f64],
        floor: impl Fn(usize) -> f64,
        stats: &mut Stats,
        mut seen: impl FnMut(&[f64]),
    ) {
        let n = self.f0.len();
        let jac = self.jac;
        let sqrt_eps = f64::EPSILON.sqrt();
        self.y.copy_from_slice(x);
        for j in 0..n {
            if j >= self.differenced {
                for i in 0..n {
                    jac[i * n + j] = 0.0;
                }
                continue;
            }
            let xj = x[j];
            self.y[j] = xj + sqrt_eps * xj.abs().max(floor(j));
            sys.rhs(t, self.y, self.fy);
            stats.rhs_evals += 1;
            seen(self.fy);
            let dx = self.y[j] - xj;
            for i in 0..n {
                jac[i * n + j] = (self.fy[i] - self.f0[i]) / dx;
            }
            self.y[j] = xj;
        }
    }
}
