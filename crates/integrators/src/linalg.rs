//! Small dense LU factorisations for the Rosenbrock method's iteration matrix
//! `E = I/(hγ) − J` (n ≤ 16 in hydrocyl's models).
//!
//! Two implementations of the same [`DenseLu`] contract are kept so that the
//! choice can be measured (`cargo bench -p hydrocyl-integrators -- lu`):
//!
//! * [`NalgebraLu`] — nalgebra's partial-pivoting `LU` on a `DMatrix`;
//! * [`InPlaceLu`] — partial-pivoting Doolittle elimination in a buffer
//!   allocated once, with no allocation per factorisation.
//!
//! The bench also runs faer's `PartialPivLu` (as a dev-dependency only).
//! The solver uses [`SolverLu`], the faster of the two on this crate's sizes.

use nalgebra::{DMatrix, DVectorViewMut, Dyn, LU};

/// A dense LU factorisation with partial pivoting, reusable across steps.
pub trait DenseLu {
    /// A factoriser for `n × n` matrices; allocates its buffers once.
    fn new(n: usize) -> Self;
    /// The matrix to be factorised, row-major (`a[i * n + j]` = row i, column j);
    /// write it before [`DenseLu::factor`].
    fn matrix_mut(&mut self) -> &mut [f64];
    /// Factorises the matrix written through [`DenseLu::matrix_mut`]; `false`
    /// when it is singular (a zero or non-finite pivot).
    fn factor(&mut self) -> bool;
    /// Overwrites `b` with the solution of `A y = b` for the last factorised `A`.
    fn solve(&self, b: &mut [f64]);
}

/// nalgebra's LU with partial pivoting (copies the matrix per factorisation).
pub struct NalgebraLu {
    n: usize,
    a: Vec<f64>,
    lu: Option<LU<f64, Dyn, Dyn>>,
}

impl DenseLu for NalgebraLu {
    fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            lu: None,
        }
    }

    fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.a
    }

    fn factor(&mut self) -> bool {
        let m = DMatrix::from_row_slice(self.n, self.n, &self.a);
        let lu = m.lu();
        let u = lu.u();
        let ok = (0..self.n).all(|i| {
            let d = u[(i, i)];
            d != 0.0 && d.is_finite()
        });
        self.lu = if ok { Some(lu) } else { None };
        ok
    }

    fn solve(&self, b: &mut [f64]) {
        if let Some(lu) = &self.lu {
            let n = self.n;
            let mut v = DVectorViewMut::from_slice(b, n);
            lu.solve_mut(&mut v);
        }
    }
}

/// Partial-pivoting LU in a preallocated row-major buffer.
pub struct InPlaceLu {
    n: usize,
    a: Vec<f64>,
    piv: Vec<usize>,
}

impl DenseLu for InPlaceLu {
    fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            piv: vec![0; n],
        }
    }

    fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.a
    }

    fn factor(&mut self) -> bool {
        let n = self.n;
        let a = &mut self.a;
        for k in 0..n {
            // Pivot: the largest magnitude in column k at or below the diagonal.
            let mut p = k;
            let mut amax = a[k * n + k].abs();
            for i in k + 1..n {
                let v = a[i * n + k].abs();
                if v > amax {
                    amax = v;
                    p = i;
                }
            }
            self.piv[k] = p;
            if amax == 0.0 || !amax.is_finite() {
                return false;
            }
            if p != k {
                for j in 0..n {
                    a.swap(k * n + j, p * n + j);
                }
            }
            let inv = 1.0 / a[k * n + k];
            for i in k + 1..n {
                let l = a[i * n + k] * inv;
                a[i * n + k] = l;
                if l != 0.0 {
                    for j in k + 1..n {
                        a[i * n + j] -= l * a[k * n + j];
                    }
                }
            }
        }
        true
    }

    fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        let a = &self.a;
        for k in 0..n {
            b.swap(k, self.piv[k]);
        }
        for i in 1..n {
            let mut s = b[i];
            for j in 0..i {
                s -= a[i * n + j] * b[j];
            }
            b[i] = s;
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for j in i + 1..n {
                s -= a[i * n + j] * b[j];
            }
            b[i] = s / a[i * n + i];
        }
    }
}

/// The LU the Rosenbrock solver uses.
pub type SolverLu = InPlaceLu;
