//! The cubic Hermite continuous extension of a one-step method (third
//! order): the interpolant of the last accepted step from its end values
//! and end derivatives. RK4 and Bogacki–Shampine 3(2) give their dense
//! output with it.
// The loop indexes four vectors in step; iterators would hide that.
#![allow(clippy::needless_range_loop)]

/// The last accepted step's end values and derivatives: `x0 = x(t)`,
/// `f0 = f(t, x0)`, `x1 = x(t + h)`, `f1 = f(t + h, x1)`, and `h`.
pub(crate) struct Hermite {
    pub(crate) x0: Vec<f64>,
    pub(crate) f0: Vec<f64>,
    pub(crate) x1: Vec<f64>,
    pub(crate) f1: Vec<f64>,
    pub(crate) h: f64,
}

impl Hermite {
    /// Room for `n` states.
    pub(crate) fn new(n: usize) -> Self {
        Self {
            x0: vec![0.0; n],
            f0: vec![0.0; n],
            x1: vec![0.0; n],
            f1: vec![0.0; n],
            h: 0.0,
        }
    }

    /// Keeps the start of an accepted step of size `h`: its state `x0` and
    /// derivative `f0`, and its end state `x1` (the caller puts `f1`).
    pub(crate) fn keep_step(&mut self, x0: &[f64], f0: &[f64], x1: &[f64], h: f64) {
        self.x0.copy_from_slice(x0);
        self.f0.copy_from_slice(f0);
        self.x1.copy_from_slice(x1);
        self.h = h;
    }

    /// The interpolant at `θ ∈ [0, 1]` of the step into `out`.
    pub(crate) fn dense(&self, theta: f64, out: &mut [f64]) {
        let s = theta;
        let s2 = s * s;
        let s3 = s2 * s;
        let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
        let h10 = s3 - 2.0 * s2 + s;
        let h01 = -2.0 * s3 + 3.0 * s2;
        let h11 = s3 - s2;
        let (h, n) = (self.h, out.len());
        let (x0, f0, x1, f1) = (&self.x0[..n], &self.f0[..n], &self.x1[..n], &self.f1[..n]);
        for i in 0..n {
            out[i] = h00 * x0[i] + h10 * h * f0[i] + h01 * x1[i] + h11 * h * f1[i];
        }
    }
}
