//! Small dense LU factorisations for the Rosenbrock method's iteration matrix
//! `E = I/(hγ) − J` (n ≤ 16 in hydrocyl's models).
//!
//! The solver uses [`InPlaceLu`]: partial-pivoting Doolittle elimination in
//! a row-major buffer allocated once per solve, so a factorisation allocates
//! nothing. `cargo bench -p hydrocyl-integrators -- lu` measures it against
//! nalgebra's `LU` on a `DMatrix` and faer's `PartialPivLu` behind the same
//! [`DenseLu`] contract (both as dev-dependencies only) for n = 2..16; the
//! in-place version was the fastest at every size measured, so the library
//! itself depends on neither.

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

/// The LU the Rosenbrock solver uses (the fastest in `benches/solvers.rs`).
pub type SolverLu = InPlaceLu;
