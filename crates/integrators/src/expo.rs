//! The exponential Rosenbrock–Euler step at the step's mid time: a
//! fixed-step, one-stage method for stiff systems whose stiff part is
//! (nearly) linear over a step,
//!
//! ```text
//! x₁ = x₀ + h φ₁(h J) f(t + h/2, x₀),   J = ∂f/∂x (t + h/2, x₀),
//! φ₁(z) = (eᶻ − 1) / z,
//! ```
//!
//! one right-hand side, one Jacobian and one matrix function a step.
//!
//! * **Exact** for `x' = A x + b` with constant `A`, `b` (the matrix
//!   exponential is the solution operator), at any `h`: no stability limit,
//!   and a decaying mode decays by exactly `e^{−λh}` however stiff.
//! * **Second order** for a smooth `f(t, x)` with the exact Jacobian:
//!   `x₁ = x₀ + h f + (h²/2)(f_t + J f) + O(h³)` (the mid time supplies
//!   `f_t`, `J` the `J f` term), which is the exact solution's expansion.
//!   A finite-difference Jacobian (a system without [`OdeSystem::jacobian`])
//!   keeps the order but no longer makes the step exact on linear systems
//!   to rounding.
//! * **Smooth in the model's parameters**: no error control, no rejected
//!   step, the step sequence fixed by the output times. A fit that
//!   differences a simulated output with respect to a parameter sees a
//!   smooth map (an adaptive method's step choices are not smooth in it).
//!
//! The step: the driver lands a step on every output time, dividing each
//! interval between two output times into the fewest equal steps no longer
//! than `Options::h0` ([`crate::Method::Exponential`]).
//!
//! LuGre's bristle with the velocity held over a step,
//! `ż = v − (σ0 |v| / g(v)) z`, is linear in `z`: the step relaxes `z`
//! exactly towards `v / rate` at the rate the mid-step velocity gives, the
//! exponential midpoint rule of the bristle. An implicit (Rosenbrock) Euler
//! step would damp it by `1/(1 + rate h)` instead of `e^{−rate h}`: first
//! order, and wrong by up to the whole relaxation when `rate h ≈ 1`.
//!
//! `φ₁(hJ) f` is the last column of `exp([[hJ, f], [0, 0]])` (the augmented
//! matrix), computed by scaling and squaring of the diagonal [6/6] Padé
//! approximant (Moler & Van Loan 2003, "Nineteen dubious ways…", method 3;
//! relative error below 4e-16 at `‖·‖ ≤ 1/2`). A diagonal `J` (decoupled
//! states, the friction bench) is done elementwise.
//!
//! Dense output between the step ends is linear (first order): the outputs
//! are the step ends themselves, and an event is located to first order.
// The matrix loops index several buffers in step; iterators would hide that.
#![allow(clippy::needless_range_loop)]

use crate::api::{OdeSystem, Stats};
use crate::driver::{Attempt, Stepper};
use crate::linalg::{DenseLu, InPlaceLu};

/// `φ₁(z) = (eᶻ − 1)/z`, with `φ₁(0) = 1`, accurate near 0.
pub fn phi1(z: f64) -> f64 {
    if z.abs() < 1e-5 {
        1.0 + z * (0.5 + z / 6.0)
    } else if z < -700.0 {
        -1.0 / z
    } else {
        z.exp_m1() / z
    }
}

/// The matrix exponential of the `m × m` row-major `a`, in place, with
/// `work` buffers allocated by the caller (scaling and squaring of the
/// [6/6] Padé approximant).
struct Expm {
    m: usize,
    lu: InPlaceLu,
    a2: Vec<f64>,
    pw: Vec<f64>,
    num: Vec<f64>,
    den: Vec<f64>,
    tmp: Vec<f64>,
    col: Vec<f64>,
}

impl Expm {
    fn new(m: usize) -> Self {
        let z = || vec![0.0; m * m];
        Expm {
            m,
            lu: InPlaceLu::new(m),
            a2: z(),
            pw: z(),
            num: z(),
            den: z(),
            tmp: z(),
            col: vec![0.0; m],
        }
    }

    fn matmul(m: usize, a: &[f64], b: &[f64], out: &mut [f64]) {
        for i in 0..m {
            for j in 0..m {
                let mut s = 0.0;
                for k in 0..m {
                    s += a[i * m + k] * b[k * m + j];
                }
                out[i * m + j] = s;
            }
        }
    }

    /// Overwrites `a` with `exp(a)`; `false` if not finite or singular.
    fn exp(&mut self, a: &mut [f64]) -> bool {
        let m = self.m;
        // ‖a‖∞ and the scaling 2^-s that brings it to ≤ 1/2
        let norm = (0..m)
            .map(|i| a[i * m..(i + 1) * m].iter().map(|v| v.abs()).sum::<f64>())
            .fold(0.0, f64::max);
        if !norm.is_finite() {
            return false;
        }
        let s = if norm > 0.5 {
            (norm / 0.5).log2().ceil() as i32
        } else {
            0
        };
        let scale = 0.5f64.powi(s);
        a.iter_mut().for_each(|v| *v *= scale);
        // Padé [6/6]: c_k = c_{k−1} (q − k + 1) / (k (2q − k + 1))
        const Q: usize = 6;
        let mut c = [1.0; Q + 1];
        for k in 1..=Q {
            c[k] = c[k - 1] * (Q - k + 1) as f64 / (k * (2 * Q - k + 1)) as f64;
        }
        self.num.fill(0.0);
        self.den.fill(0.0);
        for i in 0..m {
            self.num[i * m + i] = 1.0;
            self.den[i * m + i] = 1.0;
        }
        self.pw.copy_from_slice(a);
        for (k, ck) in c.iter().enumerate().skip(1) {
            let sign = if k % 2 == 0 { 1.0 } else { -1.0 };
            for i in 0..m * m {
                self.num[i] += ck * self.pw[i];
                self.den[i] += sign * ck * self.pw[i];
            }
            if k < Q {
                Self::matmul(m, &self.pw, a, &mut self.tmp);
                std::mem::swap(&mut self.pw, &mut self.tmp);
            }
        }
        // E = den⁻¹ num, column by column
        self.lu.matrix_mut().copy_from_slice(&self.den);
        if !self.lu.factor() {
            return false;
        }
        for j in 0..m {
            for i in 0..m {
                self.col[i] = self.num[i * m + j];
            }
            self.lu.solve(&mut self.col);
            for i in 0..m {
                a[i * m + j] = self.col[i];
            }
        }
        for _ in 0..s {
            Self::matmul(m, a, a, &mut self.a2);
            a.copy_from_slice(&self.a2);
        }
        a.iter().all(|v| v.is_finite())
    }
}

/// `φ₂(z) = (eᶻ − 1 − z)/z²`, with `φ₂(0) = 1/2`: its series where the
/// closed form cancels.
pub fn phi2(z: f64) -> f64 {
    if z.abs() < 0.1 {
        // Σ z^k/(k+2)!, to below an ulp at |z| < 0.1
        let mut term = 0.5;
        let mut sum = 0.5;
        for k in 1..14 {
            term *= z / (k + 2) as f64;
            sum += term;
        }
        sum
    } else if z < -700.0 {
        (-1.0 - z) / (z * z)
    } else {
        (z.exp_m1() - z) / (z * z)
    }
}

/// `out = h φ₁(h J) f` for the `n × n` row-major `jac` (see the module doc),
/// the last `q` states quadratures: nothing depends on them (their columns
/// of `J` are zero), so with `J = [[J_a, 0], [J_q, 0]]`
///
/// ```text
/// h φ₁(hJ) f = [ h φ₁(hJ_a) f_a ;  h f_q + h J_q · h φ₂(hJ_a) f_a ]
/// ```
///
/// and the matrix function is taken of the active block alone: `φ₁` and
/// `φ₂` of it on `h f_a` as the last two columns of
/// `exp([[hJ_a, h f_a, 0], [0, 0, 1], [0, 0, 0]])` (the exponential of the
/// augmented matrix, Sidje's Expokit form). A ledger's five quadratures per
/// component then cost a matrix product, not a cubed dimension.
pub(crate) struct PhiStep {
    n: usize,
    /// Active (non-quadrature) states: the first `na` of `n`.
    na: usize,
    aug: Vec<f64>,
    /// `h φ₂(hJ_a) f_a`.
    phi2f: Vec<f64>,
    expm: Expm,
}

impl PhiStep {
    pub(crate) fn new(n: usize, quadratures: usize) -> Self {
        let na = n - quadratures.min(n);
        let m = Self::augmented(na, n);
        PhiStep {
            n,
            na,
            aug: vec![0.0; m * m],
            phi2f: vec![0.0; na],
            expm: Expm::new(m),
        }
    }

    /// The augmented matrix's dimension: one column for `φ₁ f`, and one
    /// more for `φ₂ f` where there are quadratures.
    fn augmented(na: usize, n: usize) -> usize {
        if na < n {
            na + 2
        } else {
            na + 1
        }
    }

    /// Writes `h φ₁(h J) f` into `out`; `false` when the matrix function
    /// failed (not finite).
    pub(crate) fn apply(&mut self, h: f64, jac: &[f64], f: &[f64], out: &mut [f64]) -> bool {
        let (n, na) = (self.n, self.na);
        let diagonal = (0..na).all(|i| (0..na).all(|j| i == j || jac[i * n + j] == 0.0));
        if diagonal {
            for i in 0..na {
                let z = h * jac[i * n + i];
                out[i] = h * phi1(z) * f[i];
                self.phi2f[i] = h * phi2(z) * f[i];
            }
        } else {
            let m = Self::augmented(na, n);
            self.aug.fill(0.0);
            for i in 0..na {
                for j in 0..na {
                    self.aug[i * m + j] = h * jac[i * n + j];
                }
                self.aug[i * m + na] = h * f[i];
            }
            if na < n {
                self.aug[na * m + na + 1] = 1.0;
            }
            if !self.expm.exp(&mut self.aug) {
                return false;
            }
            for i in 0..na {
                out[i] = self.aug[i * m + na];
                if na < n {
                    self.phi2f[i] = self.aug[i * m + na + 1];
                }
            }
        }
        for i in na..n {
            let row = &jac[i * n..i * n + na];
            let coupled: f64 = row.iter().zip(&self.phi2f).map(|(j, p)| j * p).sum();
            out[i] = h * (f[i] + coupled);
        }
        out.iter().all(|v| v.is_finite())
    }
}

/// The exponential Rosenbrock–Euler stepper (module doc).
pub(crate) struct Exponential {
    n: usize,
    f: Vec<f64>,
    jac: Vec<f64>,
    y: Vec<f64>,
    fy: Vec<f64>,
    phi: PhiStep,
    /// The last accepted step's ends, for the linear dense output.
    x0: Vec<f64>,
    x1: Vec<f64>,
    quadratures: usize,
}

impl Exponential {
    pub(crate) fn new(n: usize, quadratures: usize) -> Self {
        let z = || vec![0.0; n];
        Exponential {
            n,
            f: z(),
            jac: vec![0.0; n * n],
            y: z(),
            fy: z(),
            phi: PhiStep::new(n, quadratures),
            x0: z(),
            x1: z(),
            quadratures,
        }
    }

    /// `∂f/∂x` at `(t, x)` (after `f` there): the model's, or forward
    /// differences of the non-quadrature columns.
    fn jacobian<S: OdeSystem + ?Sized>(&mut self, sys: &S, t: f64, x: &[f64], stats: &mut Stats) {
        let n = self.n;
        stats.jac_evals += 1;
        if sys.jacobian(t, x, &mut self.jac) {
            return;
        }
        crate::fdjac::ForwardDifference {
            f0: &self.f,
            differenced: n - self.quadratures,
            y: &mut self.y,
            fy: &mut self.fy,
            jac: &mut self.jac,
        }
        .fill(sys, t, x, |_| 1e-8, stats, |_| {});
    }
}

impl Stepper for Exponential {
    fn adaptive(&self) -> bool {
        false
    }

    fn lands_on_outputs(&self) -> bool {
        true
    }

    fn restart(&mut self) {}

    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        x: &[f64],
        h: f64,
        x_new: &mut [f64],
        err: &mut [f64],
        stats: &mut Stats,
    ) -> Attempt {
        let tm = t + 0.5 * h;
        sys.rhs(tm, x, &mut self.f);
        stats.rhs_evals += 1;
        self.jacobian(sys, tm, x, stats);
        err.fill(0.0);
        if !self.phi.apply(h, &self.jac, &self.f, x_new) {
            x_new.fill(f64::NAN);
            return Attempt::Done;
        }
        for (xn, x0) in x_new.iter_mut().zip(x) {
            *xn += x0;
        }
        Attempt::Done
    }

    fn f_start(&self) -> &[f64] {
        &self.f
    }

    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        _sys: &S,
        _t: f64,
        x: &[f64],
        _h: f64,
        x_new: &[f64],
        _stats: &mut Stats,
    ) {
        self.x0.copy_from_slice(x);
        self.x1.copy_from_slice(x_new);
    }

    fn dense(&self, theta: f64, out: &mut [f64]) {
        for i in 0..out.len() {
            out[i] = self.x0[i] + theta * (self.x1[i] - self.x0[i]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Padé exponential against closed forms: a rotation-with-decay
    /// block `exp([[a, b], [−b, a]] t)` and a Jordan block (non-normal),
    /// from tiny to stiff norms.
    #[test]
    fn expm_matches_closed_forms() {
        for &(a, b, t) in &[
            (-0.3, 2.0, 0.1),
            (-1.0, 0.5, 3.0),
            (-50.0, 40.0, 1.0),
            (0.2, 0.0, 1e-9),
        ] {
            let mut e = Expm::new(2);
            let mut m = vec![a * t, b * t, -b * t, a * t];
            assert!(e.exp(&mut m));
            let (ea, c, s) = ((a * t).exp(), (b * t).cos(), (b * t).sin());
            let want = [ea * c, ea * s, -ea * s, ea * c];
            for (g, w) in m.iter().zip(want) {
                assert!((g - w).abs() <= 1e-14 * (1.0 + w.abs()), "{g} vs {w}");
            }
        }
        // Jordan block: exp([[λ, 1], [0, λ]] t) = e^{λt} [[1, t], [0, 1]]
        let (l, t) = (-7.0, 2.5);
        let mut e = Expm::new(2);
        let mut m = vec![l * t, t, 0.0, l * t];
        assert!(e.exp(&mut m));
        let el = (l * t).exp();
        for (g, w) in m.iter().zip([el, t * el, 0.0, el]) {
            assert!((g - w).abs() <= 1e-13 * el.max(w.abs()), "{g} vs {w}");
        }
    }

    /// `h φ₁(hJ) f` from the augmented exponential equals the elementwise
    /// formula on a diagonal `J` (the fast path), stiff and mild.
    #[test]
    fn augmented_phi_equals_elementwise() {
        let jac = [-3e4, 0.0, 0.0, -0.7];
        let f = [2.0, -1.5];
        let h = 1e-3;
        let mut p = PhiStep::new(2, 0);
        let mut fast = [0.0; 2];
        assert!(p.apply(h, &jac, &f, &mut fast));
        // the general path: the same matrix with an off-diagonal 0 made a
        // negligible coupling
        let mut slow = [0.0; 2];
        let jac2 = [-3e4, 1e-300, 0.0, -0.7];
        assert!(p.apply(h, &jac2, &f, &mut slow));
        for (a, b) in fast.iter().zip(slow) {
            assert!((a - b).abs() <= 1e-14 * a.abs(), "{a} vs {b}");
        }
        assert!((fast[0] - h * phi1(-30.0) * 2.0).abs() < 1e-18);
    }

    /// `φ₂` against its closed form, across the switch to the series.
    #[test]
    fn phi2_matches_its_closed_form() {
        for z in [
            -800.0f64, -30.0, -1.0, -0.1000001, -0.0999999, -1e-3, 0.0, 1e-8, 0.05, 2.0,
        ] {
            // the series, summed long, where the closed form cancels
            let want = if z.abs() <= 1.0 {
                let (mut term, mut sum) = (0.5, 0.5);
                for k in 1..40 {
                    term *= z / (k + 2) as f64;
                    sum += term;
                }
                sum
            } else {
                (z.exp_m1() - z) / (z * z)
            };
            let tol = 1e-14;
            assert!(
                (phi2(z) - want).abs() <= tol * want.abs(),
                "{z}: {} vs {want}",
                phi2(z)
            );
        }
    }

    /// Quadratures (zero columns, the last `q` states) taken by `φ₂` of the
    /// active block give what the whole matrix's exponential gives, with a
    /// coupled and with a diagonal active block.
    #[test]
    fn quadratures_by_phi2_equal_the_whole_exponential() {
        // 3 active states, 2 quadratures fed by them
        let coupled = [
            -40.0, 3.0, 0.5, 0.0, 0.0, //
            2.0, -7.0, 1.0, 0.0, 0.0, //
            0.0, -1.5, -0.2, 0.0, 0.0, //
            0.3, -2.0, 4.0, 0.0, 0.0, //
            1.0, 0.0, -0.5, 0.0, 0.0,
        ];
        let mut diagonal = coupled;
        for i in 0..3 {
            for j in 0..3 {
                if i != j {
                    diagonal[i * 5 + j] = 0.0;
                }
            }
        }
        let f = [1.0, -2.0, 0.5, 3.0, -0.7];
        for jac in [coupled, diagonal] {
            for h in [1e-4, 1e-2, 0.3] {
                let (mut split, mut whole) = ([0.0; 5], [0.0; 5]);
                assert!(PhiStep::new(5, 2).apply(h, &jac, &f, &mut split));
                // the whole matrix, every state active
                let mut general = jac;
                general[3 * 5 + 3] = 1e-300; // not diagonal: the Padé path
                assert!(PhiStep::new(5, 0).apply(h, &general, &f, &mut whole));
                for (a, b) in split.iter().zip(whole) {
                    assert!(
                        (a - b).abs() <= 1e-13 * b.abs().max(1e-3 * h),
                        "h {h}: {split:?} vs {whole:?}"
                    );
                }
            }
        }
    }
}
