//! Rodas4: the stiffly accurate, L-stable, six-stage Rosenbrock method of
//! order 4 with an embedded order-3 solution and an order-3 continuous
//! extension (Hairer & Wanner II, §IV.7, the coefficients of `RODAS`,
//! method 1).
//!
//! One step from `(t, x)` with step `h`, `E = I/(hγ) − J`, `J = ∂f/∂x(t, x)`,
//! `f_t = ∂f/∂t(t, x)`:
//!
//! ```text
//! E k_i = f(t + c_i h, x + Σ_{j<i} a_ij k_j) + Σ_{j<i} (c_ij / h) k_j + h d_i f_t ,  i = 1..6
//! x_new = x + Σ_{j≤4} a_5j k_j + k_5 + k_6 ,   error estimate = k_6
//! ```
//!
//! The Jacobian is the model's ([`OdeSystem::jacobian`]) or a column-wise
//! forward difference with increments `δ_j = sqrt(ε) · max(|x_j|, atol_j/rtol)`
//! (`atol_j/rtol` is the magnitude below which the error norm treats state j
//! as absolute, a natural scale for it); `f_t` is zero where the model says
//! so ([`OdeSystem::constant_in_time`]), else a forward difference in `t`
//! with `δ_t = sqrt(ε) · max(|t|, h)`. After a rejected step the
//! Jacobian is reused and only `E` is refactorised.
//!
//! Quadrature states ([`OdeSystem::n_quadratures`], the last `q` states) have
//! zero Jacobian columns, so `E` is block lower-triangular,
//! `[[E_aa, 0], [−J_qa, I/(hγ)]]`: only the `n − q` active states are
//! differenced and factorised, and each stage's quadrature part follows by
//! forward substitution, `k_q = hγ (b_q + J_qa k_a)`. This is the same
//! linear algebra, not an approximation; it keeps an energy ledger of dozens
//! of integrals from turning a 9-state LU into a 70-state one.
// The stage loops index several vectors in step; iterators would hide that.
#![allow(clippy::needless_range_loop)]

use crate::api::{OdeSystem, Stats};
use crate::driver::{Attempt, Stepper};
use crate::linalg::{DenseLu, SolverLu};

const GAMMA: f64 = 0.25;
const C2: f64 = 0.386;
const C3: f64 = 0.21;
const C4: f64 = 0.63;
const D1: f64 = 0.25;
const D2: f64 = -0.1043;
const D3: f64 = 0.1035;
const D4: f64 = -0.362e-1;
const A21: f64 = 0.1544e+01;
const A31: f64 = 0.946_678_528_081_582_6;
const A32: f64 = 0.255_701_169_898_328_4;
const A41: f64 = 0.331_482_518_706_852_1e+01;
const A42: f64 = 0.289_612_401_597_220_1e+01;
const A43: f64 = 0.998_641_913_997_781_7;
const A51: f64 = 0.122_122_450_922_664_1e+01;
const A52: f64 = 0.601_913_448_128_862_9e+01;
const A53: f64 = 0.125_370_833_293_208_7e+02;
const A54: f64 = -0.687_886_036_105_895;
const C21: f64 = -0.56688e+01;
const C31: f64 = -0.243_009_335_683_387_5e+01;
const C32: f64 = -0.206_359_915_709_191_5;
const C41: f64 = -0.107_352_905_815_137_5;
const C42: f64 = -0.959_456_225_102_335_5e+01;
const C43: f64 = -0.204_702_861_480_961_6e+02;
const C51: f64 = 0.749_644_331_396_764_7e+01;
const C52: f64 = -0.102_468_043_146_435_2e+02;
const C53: f64 = -0.339_999_035_281_990_5e+02;
const C54: f64 = 0.117_089_089_320_616e+02;
const C61: f64 = 0.808_324_679_592_152_2e+01;
const C62: f64 = -0.798_113_298_806_489_3e+01;
const C63: f64 = -0.315_215_943_287_437_1e+02;
const C64: f64 = 0.163_193_054_312_313_6e+02;
const C65: f64 = -0.605_881_823_883_405_4e+01;
// Dense output.
const DD21: f64 = 0.101_262_350_834_458_6e+02;
const DD22: f64 = -0.748_799_587_761_016_7e+01;
const DD23: f64 = -0.348_009_186_155_574_7e+02;
const DD24: f64 = -0.799_277_170_756_882_3e+01;
const DD25: f64 = 0.102_513_772_329_566_2e+01;
const DD31: f64 = -0.676_280_339_280_125_3;
const DD32: f64 = 0.608_771_465_168_001_5e+01;
const DD33: f64 = 0.164_308_432_089_247_8e+02;
const DD34: f64 = 0.247_672_251_141_838_6e+02;
const DD35: f64 = -0.659_438_912_571_687_2e+01;

/// Rodas4 stepper; all work vectors and the LU buffer allocated once.
pub(crate) struct Rodas4 {
    n: usize,
    /// Active (non-quadrature) states: the first `na` of `n`.
    na: usize,
    k: [Vec<f64>; 6],
    f0: Vec<f64>,
    ft: Vec<f64>,
    y: Vec<f64>,
    fy: Vec<f64>,
    jac: Vec<f64>,
    /// `f0`, `ft` and `jac` belong to the current step start.
    jac_valid: bool,
    lu: SolverLu,
    cont: [Vec<f64>; 4],
    /// Magnitude scale of each state for finite-difference increments.
    scale: Vec<f64>,
    /// A state whose derivative was non-finite in the last attempt.
    bad: Option<usize>,
    /// A state whose derivative was non-finite while linearising.
    lin_bad: Option<usize>,
}

/// The stage solve `E k = b` with the quadratures substituted.
struct BlockSolve<'a> {
    lu: &'a SolverLu,
    jac: &'a [f64],
    n: usize,
    na: usize,
    h_gamma: f64,
}

impl BlockSolve<'_> {
    /// Overwrites `b` with `k`.
    #[inline]
    fn solve(&self, b: &mut [f64]) {
        let (n, na) = (self.n, self.na);
        self.lu.solve(&mut b[..na]);
        for i in na..n {
            let row = &self.jac[i * n..i * n + na];
            let s: f64 = row.iter().zip(&b[..na]).map(|(j, k)| j * k).sum();
            b[i] = self.h_gamma * (b[i] + s);
        }
    }
}

/// `out = Σ c_j v_j`, the terms added in their order (a coefficient 1 is
/// exact): the stages' sums as one loop, not one copy per sum (the step's
/// code is what the instruction cache has to hold).
#[inline(never)]
fn combine(out: &mut [f64], terms: &[(f64, &[f64])]) {
    let Some((&(c0, v0), rest)) = terms.split_first() else {
        return;
    };
    for (o, &v) in out.iter_mut().zip(v0) {
        *o = c0 * v;
    }
    for &(c, v) in rest {
        for (o, &v) in out.iter_mut().zip(v) {
            *o += c * v;
        }
    }
}

/// `k = f + k / h + hd · f_t`: a stage's right-hand side from the sum of
/// the earlier stages `Σ c_ij k_j` held in `k`.
#[inline(never)]
fn stage(k: &mut [f64], f: &[f64], inv_h: f64, hd: f64, ft: &[f64]) {
    for ((k, &f), &ft) in k.iter_mut().zip(f).zip(ft) {
        *k = f + inv_h * *k + hd * ft;
    }
}

/// `out += v`.
#[inline(never)]
fn add(out: &mut [f64], v: &[f64]) {
    for (o, &v) in out.iter_mut().zip(v) {
        *o += v;
    }
}

/// First index of a non-finite entry.
fn first_nonfinite(v: &[f64]) -> Option<usize> {
    v.iter().position(|x| !x.is_finite())
}

impl Rodas4 {
    /// A stepper for `n` states, the last `quadratures` of them quadratures.
    pub(crate) fn new(n: usize, quadratures: usize) -> Self {
        let na = n - quadratures.min(n);
        Self {
            n,
            na,
            k: std::array::from_fn(|_| vec![0.0; n]),
            f0: vec![0.0; n],
            ft: vec![0.0; n],
            y: vec![0.0; n],
            fy: vec![0.0; n],
            jac: vec![0.0; n * n],
            jac_valid: false,
            lu: SolverLu::new(na),
            cont: std::array::from_fn(|_| vec![0.0; n]),
            scale: vec![1e-5; n],
            bad: None,
            lin_bad: None,
        }
    }

    /// Number of states.
    pub(crate) fn dim(&self) -> usize {
        self.n
    }

    /// The Jacobian at the start of the last attempted step, row-major
    /// (`dim × dim`; the quadrature columns are zero).
    pub(crate) fn jacobian(&self) -> &[f64] {
        &self.jac
    }

    /// `f(t, x)`, `∂f/∂t` and `∂f/∂x` at the step start.
    fn linearise<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        x: &[f64],
        h: f64,
        stats: &mut Stats,
    ) {
        let n = self.n;
        let sqrt_eps = f64::EPSILON.sqrt();
        sys.rhs(t, x, &mut self.f0);
        stats.rhs_evals += 1;
        self.lin_bad = first_nonfinite(&self.f0);
        // the model's Jacobian right after f(t, x), so that a model can reuse
        // that evaluation for it (the circuit's tangent pass does)
        stats.jac_evals += 1;
        let analytic = sys.jacobian(t, x, &mut self.jac);
        if sys.constant_in_time(t) {
            self.ft.fill(0.0);
        } else {
            // ∂f/∂t by a forward difference.
            let t_plus = t + sqrt_eps * t.abs().max(h);
            let dt = t_plus - t;
            sys.rhs(t_plus, x, &mut self.fy);
            stats.rhs_evals += 1;
            self.lin_bad = self.lin_bad.or(first_nonfinite(&self.fy));
            for i in 0..n {
                self.ft[i] = (self.fy[i] - self.f0[i]) / dt;
            }
        }
        if !analytic {
            let scale = &self.scale;
            let lin_bad = &mut self.lin_bad;
            crate::fdjac::ForwardDifference {
                f0: &self.f0,
                differenced: self.na,
                y: &mut self.y,
                fy: &mut self.fy,
                jac: &mut self.jac,
            }
            .fill(
                sys,
                t,
                x,
                |j| scale[j],
                stats,
                |fy| {
                    *lin_bad = lin_bad.or(first_nonfinite(fy));
                },
            );
        }
    }
}

impl Stepper for Rodas4 {
    fn adaptive(&self) -> bool {
        true
    }

    fn restart(&mut self) {
        self.jac_valid = false;
    }

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
        let n = self.n;
        if !self.jac_valid {
            self.linearise(sys, t, x, h, stats);
            self.jac_valid = true;
        }
        self.bad = self.lin_bad;
        if self.f0.iter().any(|v| !v.is_finite()) {
            // The driver reports the offending state from f_start().
            return Attempt::Done;
        }
        // E = I/(hγ) − J on the active block (the quadratures are
        // substituted, see the module docs).
        let fac = 1.0 / (h * GAMMA);
        let na = self.na;
        {
            let e = self.lu.matrix_mut();
            for i in 0..na {
                for j in 0..na {
                    e[i * na + j] = -self.jac[i * n + j];
                }
                e[i * na + i] += fac;
            }
        }
        stats.lu_decomps += 1;
        if !self.lu.factor() {
            return Attempt::Singular;
        }
        let [k1, k2, k3, k4, k5, k6] = &mut self.k;
        let (y, fy, f0, ft) = (&mut self.y, &mut self.fy, &self.f0, &self.ft);
        let solver = BlockSolve {
            lu: &self.lu,
            jac: &self.jac,
            n,
            na,
            h_gamma: h * GAMMA,
        };
        let inv_h = 1.0 / h;

        combine(k1, &[(1.0, f0), (h * D1, ft)]);
        solver.solve(k1);

        combine(y, &[(1.0, x), (A21, k1)]);
        sys.rhs(t + C2 * h, y, fy);
        let mut bad = first_nonfinite(fy);
        combine(k2, &[(C21, k1)]);
        stage(k2, fy, inv_h, h * D2, ft);
        solver.solve(k2);

        combine(y, &[(1.0, x), (A31, k1), (A32, k2)]);
        sys.rhs(t + C3 * h, y, fy);
        bad = bad.or(first_nonfinite(fy));
        combine(k3, &[(C31, k1), (C32, k2)]);
        stage(k3, fy, inv_h, h * D3, ft);
        solver.solve(k3);

        combine(y, &[(1.0, x), (A41, k1), (A42, k2), (A43, k3)]);
        sys.rhs(t + C4 * h, y, fy);
        bad = bad.or(first_nonfinite(fy));
        combine(k4, &[(C41, k1), (C42, k2), (C43, k3)]);
        stage(k4, fy, inv_h, h * D4, ft);
        solver.solve(k4);

        combine(y, &[(1.0, x), (A51, k1), (A52, k2), (A53, k3), (A54, k4)]);
        sys.rhs(t + h, y, fy);
        bad = bad.or(first_nonfinite(fy));
        combine(k5, &[(C51, k1), (C52, k2), (C53, k3), (C54, k4)]);
        stage(k5, fy, inv_h, 0.0, ft);
        solver.solve(k5);

        add(y, k5);
        sys.rhs(t + h, y, fy);
        bad = bad.or(first_nonfinite(fy));
        combine(k6, &[(C61, k1), (C62, k2), (C63, k3), (C64, k4), (C65, k5)]);
        stage(k6, fy, inv_h, 0.0, ft);
        solver.solve(k6);
        stats.rhs_evals += 5;
        self.bad = self.bad.or(bad);

        x_new.copy_from_slice(y);
        add(x_new, k6);
        err.copy_from_slice(k6);
        Attempt::Done
    }

    fn f_start(&self) -> &[f64] {
        &self.f0
    }

    fn nonfinite_hint(&self) -> Option<usize> {
        self.bad
    }

    fn set_scale(&mut self, atol: &[f64], rtol: f64) {
        for (s, &a) in self.scale.iter_mut().zip(atol) {
            *s = if rtol > 0.0 { a / rtol } else { a }.max(f64::MIN_POSITIVE);
        }
    }

    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        _sys: &S,
        _t: f64,
        x: &[f64],
        _h: f64,
        x_new: &[f64],
        stats: &mut Stats,
    ) {
        stats.stiff_steps += 1;
        let [k1, k2, k3, k4, k5, _] = &self.k;
        let [c1, c2, c3, c4] = &mut self.cont;
        c1.copy_from_slice(x);
        combine(c2, &[(1.0, x_new), (-1.0, x)]);
        combine(
            c3,
            &[(DD21, k1), (DD22, k2), (DD23, k3), (DD24, k4), (DD25, k5)],
        );
        combine(
            c4,
            &[(DD31, k1), (DD32, k2), (DD33, k3), (DD34, k4), (DD35, k5)],
        );
        self.jac_valid = false;
    }

    fn dense(&self, theta: f64, out: &mut [f64]) {
        let s1 = 1.0 - theta;
        let [c1, c2, c3, c4] = &self.cont;
        for i in 0..out.len() {
            out[i] = c1[i] + theta * (c2[i] + s1 * (c3[i] + theta * c4[i]));
        }
    }
}
