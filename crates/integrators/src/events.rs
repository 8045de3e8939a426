//! Bracketing root finder for switching functions on the dense output.
//!
//! The Illinois variant of regula falsi (Dowell & Jarratt 1971): a secant
//! step between the bracket ends; when the same end is kept twice in a row,
//! its function value is halved, which restores superlinear convergence from
//! both sides. A bisection step is forced whenever two iterations have not
//! halved the bracket, so the bracket shrinks at least as fast as bisection
//! every second iteration. The invariant is that `g(a)` and `g(b)` have
//! opposite signs; the search ends when `b − a ≤ tol` or `g` is exactly zero.

/// A sign-change bracket `[a, b]` of a scalar function, with its end values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bracket {
    /// Left end (before the crossing).
    pub a: f64,
    /// `g(a)`, non-zero.
    pub ga: f64,
    /// Right end (at or after the crossing).
    pub b: f64,
    /// `g(b)`: zero or of the opposite sign to `ga`.
    pub gb: f64,
}

/// Most iterations of [`locate_root`]; bisection alone reaches any `tol ≥
/// 1e-300` of a finite bracket well within this.
const MAX_ITER: usize = 400;

/// Narrows a sign-change bracket of `g` to width `tol` (or to an exact zero,
/// which is returned as `a = b`). The returned `b` is at or just after the
/// root: `g(b)` is zero or has the sign of the original `gb`.
///
/// `g(a)` and `g(b)` of the input must have opposite signs (or `gb = 0`);
/// a NaN value of `g` is treated like a value of the sign of `gb`, which keeps
/// the bracket valid.
pub fn locate_root(br: Bracket, tol: f64, mut g: impl FnMut(f64) -> f64) -> Bracket {
    let Bracket {
        mut a,
        mut ga,
        mut b,
        mut gb,
    } = br;
    if gb == 0.0 {
        return Bracket {
            a: b,
            ga: gb,
            b,
            gb,
        };
    }
    // Illinois-modified values used in the secant step.
    let (mut fa, mut fb) = (ga, gb);
    let mut kept_side = 0i8; // -1: a was kept last time, +1: b was kept
                             // Bracket widths at the start of the previous two iterations.
    let mut width_two_ago = f64::INFINITY;
    let mut width_one_ago = f64::INFINITY;
    for _ in 0..MAX_ITER {
        let w = b - a;
        if w <= tol {
            break;
        }
        let mid = a + 0.5 * w;
        let mut c = if w > 0.5 * width_two_ago {
            mid
        } else {
            b - fb * (b - a) / (fb - fa)
        };
        if !(c > a && c < b) {
            c = mid;
        }
        if !(c > a && c < b) {
            // The bracket is down to adjacent floating-point numbers.
            break;
        }
        let gc = g(c);
        width_two_ago = width_one_ago;
        width_one_ago = w;
        if gc == 0.0 {
            return Bracket {
                a: c,
                ga: gc,
                b: c,
                gb: gc,
            };
        }
        if gc.is_nan() || (gc > 0.0) == (gb > 0.0) {
            b = c;
            gb = if gc.is_nan() { gb } else { gc };
            fb = gb;
            if kept_side == -1 {
                fa *= 0.5;
            }
            kept_side = -1;
        } else {
            a = c;
            ga = gc;
            fa = gc;
            if kept_side == 1 {
                fb *= 0.5;
            }
            kept_side = 1;
        }
    }
    Bracket { a, ga, b, gb }
}
