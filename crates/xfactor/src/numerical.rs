//! The numerical reference: Brent's method on the unsquared eq 3.4 in `[1, gamma^2]`.

use crate::analytical::{check_inputs, residual};
use crate::error::XFactorError;

/// Iteration budget of [`x_factor_brent`]; bisection alone on `[1, 36]` meets
/// `tol = 1e-15` in about 55 halvings, so the budget is only hit by a bug or a
/// tolerance below what `f64` can resolve.
pub const MAX_ITERATIONS: usize = 200;

/// A Brent solution and its cost.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BrentSolution {
    /// The root (the X factor, for [`x_factor_brent`]).
    pub x: f64,
    /// Evaluations of the function spent (the two bracket ends included).
    pub evaluations: usize,
}

/// Brent's method (inverse quadratic interpolation, secant, bisection) on
/// `F(X)` of eq 3.4 over the bracket `[1, gamma^2]`, which always contains
/// exactly one root (`F(1) >= 0 >= F(gamma^2)`, `F` strictly decreasing; see
/// the crate docs). Stops when the bracket half-width is below
/// `tol + 2 eps |X|` (`tol` absolute, in units of X).
///
/// Outside the underlap (`|travel| >= 1`) it returns 1 or `gamma^2` with no
/// evaluation, as [`crate::x_factor`] does.
pub fn x_factor_brent(gamma: f64, travel: f64, tol: f64) -> Result<BrentSolution, XFactorError> {
    check_inputs(gamma, travel)?;
    if !(tol.is_finite() && tol > 0.0) {
        return Err(XFactorError::ToleranceOutOfRange { tol });
    }
    if travel >= 1.0 {
        return Ok(BrentSolution {
            x: 1.0,
            evaluations: 0,
        });
    }
    if travel <= -1.0 {
        return Ok(BrentSolution {
            x: gamma * gamma,
            evaluations: 0,
        });
    }
    let f = |x: f64| residual(gamma, travel, x);
    let (lo, hi) = (1.0, gamma * gamma);
    // In exact arithmetic F(1) >= 0 >= F(gamma^2). A computed end value of the
    // wrong sign is rounding (gamma -> 1, travel -> +-1): the root is that end.
    if f(lo) <= 0.0 {
        return Ok(BrentSolution {
            x: lo,
            evaluations: 1,
        });
    }
    if f(hi) >= 0.0 {
        return Ok(BrentSolution {
            x: hi,
            evaluations: 2,
        });
    }
    brent(f, lo, hi, tol)
}

/// Brent's method on `f` over `[a, b]`, which must bracket a sign change
/// (checked: an error otherwise is a bug in the caller's bracket, reported as
/// [`XFactorError::NoConvergence`] with zero iterations). The workspace's one
/// bracketed root finder: the X factor's reference and the assembler's
/// algebraic nodes (`hydrocyl_system::series`) both call it.
pub fn brent<F: FnMut(f64) -> f64>(
    mut f: F,
    a: f64,
    b: f64,
    tol: f64,
) -> Result<BrentSolution, XFactorError> {
    let (mut a, mut b) = (a, b);
    let (mut fa, mut fb) = (f(a), f(b));
    let evaluations = 2;
    if fa == 0.0 {
        return Ok(BrentSolution { x: a, evaluations });
    }
    if fb == 0.0 {
        return Ok(BrentSolution { x: b, evaluations });
    }
    if !(fa.is_finite() && fb.is_finite()) || (fa > 0.0) == (fb > 0.0) {
        return Err(XFactorError::NoConvergence {
            tol,
            iterations: 0,
            width: (b - a).abs(),
        });
    }
    // `b` is the best estimate, `a` the previous one, `c` the contrapoint.
    let (mut c, mut fc) = (a, fa);
    let mut d = b - a;
    let mut e = d;
    for iteration in 0..MAX_ITERATIONS {
        let evaluations = 2 + iteration;
        if (fb > 0.0) == (fc > 0.0) {
            c = a;
            fc = fa;
            d = b - a;
            e = d;
        }
        if fc.abs() < fb.abs() {
            a = b;
            b = c;
            c = a;
            fa = fb;
            fb = fc;
            fc = fa;
        }
        let tol1 = 2.0 * f64::EPSILON * b.abs() + 0.5 * tol;
        let xm = 0.5 * (c - b);
        if xm.abs() <= tol1 || fb == 0.0 {
            return Ok(BrentSolution { x: b, evaluations });
        }
        if e.abs() >= tol1 && fa.abs() > fb.abs() {
            // Interpolate: secant when a == c, inverse quadratic otherwise.
            let s = fb / fa;
            let (mut p, mut q) = if a == c {
                (2.0 * xm * s, 1.0 - s)
            } else {
                let qa = fa / fc;
                let r = fb / fc;
                (
                    s * (2.0 * xm * qa * (qa - r) - (b - a) * (r - 1.0)),
                    (qa - 1.0) * (r - 1.0) * (s - 1.0),
                )
            };
            if p > 0.0 {
                q = -q;
            }
            p = p.abs();
            let min1 = 3.0 * xm * q - (tol1 * q).abs();
            let min2 = (e * q).abs();
            if 2.0 * p < min1.min(min2) {
                e = d;
                d = p / q;
            } else {
                d = xm;
                e = d;
            }
        } else {
            d = xm;
            e = d;
        }
        a = b;
        fa = fb;
        b += if d.abs() > tol1 { d } else { tol1.copysign(xm) };
        fb = f(b);
    }
    Err(XFactorError::NoConvergence {
        tol,
        iterations: MAX_ITERATIONS,
        width: (c - b).abs(),
    })
}

/// The X factor from eq 3.4 by Brent's method on `[1, gamma^2]` to absolute
/// tolerance `tol` (the numerical reference for [`crate::x_factor`]).
///
/// Bad input (see [`x_factor_numerical_checked`]) gives `NaN`.
///
/// ```
/// use hydrocyl_xfactor::{x_factor, x_factor_numerical};
/// let (g, t) = (1.9707, -0.3);
/// assert!((x_factor_numerical(g, t, 1e-13) - x_factor(g, t)).abs() < 1e-12);
/// ```
pub fn x_factor_numerical(gamma: f64, travel: f64, tol: f64) -> f64 {
    x_factor_brent(gamma, travel, tol).map_or(f64::NAN, |s| s.x)
}

/// [`x_factor_numerical`] with an error naming the argument for a bad
/// `gamma`, `travel` or `tol`, or when Brent's method cannot meet `tol`.
pub fn x_factor_numerical_checked(gamma: f64, travel: f64, tol: f64) -> Result<f64, XFactorError> {
    x_factor_brent(gamma, travel, tol).map(|s| s.x)
}
