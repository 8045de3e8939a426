//! Classical fixed-step Runge–Kutta 4 with a cubic Hermite continuous
//! extension (third order, built from the end values and end derivatives).
// The stage loops index several vectors in step; iterators would hide that.
#![allow(clippy::needless_range_loop)]

use crate::api::{OdeSystem, Stats};
use crate::driver::{Attempt, Stepper};

/// RK4 stepper; `k[0]` carries `f(t, x)` from the end of the previous step.
pub(crate) struct Rk4 {
    k: [Vec<f64>; 4],
    y: Vec<f64>,
    k1_valid: bool,
    /// Hermite data of the last accepted step: x, f(x), x_new, f(x_new), h.
    hx0: Vec<f64>,
    hf0: Vec<f64>,
    hx1: Vec<f64>,
    hf1: Vec<f64>,
    hh: f64,
}

impl Rk4 {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            k: std::array::from_fn(|_| vec![0.0; n]),
            y: vec![0.0; n],
            k1_valid: false,
            hx0: vec![0.0; n],
            hf0: vec![0.0; n],
            hx1: vec![0.0; n],
            hf1: vec![0.0; n],
            hh: 0.0,
        }
    }
}

impl Stepper for Rk4 {
    fn adaptive(&self) -> bool {
        false
    }

    fn restart(&mut self) {
        self.k1_valid = false;
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
        let n = x.len();
        let [k1, k2, k3, k4] = &mut self.k;
        let y = &mut self.y;
        if !self.k1_valid {
            sys.rhs(t, x, k1);
            stats.rhs_evals += 1;
            self.k1_valid = true;
        }
        for i in 0..n {
            y[i] = x[i] + 0.5 * h * k1[i];
        }
        sys.rhs(t + 0.5 * h, y, k2);
        for i in 0..n {
            y[i] = x[i] + 0.5 * h * k2[i];
        }
        sys.rhs(t + 0.5 * h, y, k3);
        for i in 0..n {
            y[i] = x[i] + h * k3[i];
        }
        sys.rhs(t + h, y, k4);
        stats.rhs_evals += 3;
        for i in 0..n {
            x_new[i] = x[i] + h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            err[i] = 0.0;
        }
        Attempt::Done
    }

    fn f_start(&self) -> &[f64] {
        &self.k[0]
    }

    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        x: &[f64],
        h: f64,
        x_new: &[f64],
        stats: &mut Stats,
    ) {
        self.hx0.copy_from_slice(x);
        self.hf0.copy_from_slice(&self.k[0]);
        self.hx1.copy_from_slice(x_new);
        sys.rhs(t + h, x_new, &mut self.hf1);
        stats.rhs_evals += 1;
        self.hh = h;
        // f(t + h, x_new) is the first stage of the next step.
        self.k[0].copy_from_slice(&self.hf1);
    }

    fn dense(&self, theta: f64, out: &mut [f64]) {
        cubic_hermite(
            theta,
            self.hh,
            [&self.hx0, &self.hf0, &self.hx1, &self.hf1],
            out,
        );
    }
}

/// The cubic Hermite interpolant at `θ ∈ [0, 1]` of a step of size `h` from
/// its end values and end derivatives `[x0, f0, x1, f1]` (third order).
pub(crate) fn cubic_hermite(theta: f64, h: f64, [x0, f0, x1, f1]: [&[f64]; 4], out: &mut [f64]) {
    let s = theta;
    let s2 = s * s;
    let s3 = s2 * s;
    let h00 = 2.0 * s3 - 3.0 * s2 + 1.0;
    let h10 = s3 - 2.0 * s2 + s;
    let h01 = -2.0 * s3 + 3.0 * s2;
    let h11 = s3 - s2;
    let n = out.len();
    let (x0, f0, x1, f1) = (&x0[..n], &f0[..n], &x1[..n], &f1[..n]);
    for i in 0..n {
        out[i] = h00 * x0[i] + h10 * h * f0[i] + h01 * x1[i] + h11 * h * f1[i];
    }
}
