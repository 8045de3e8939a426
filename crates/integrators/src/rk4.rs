//! Classical fixed-step Runge–Kutta 4 with a cubic Hermite continuous
//! extension (third order, built from the end values and end derivatives).
// The stage loops index several vectors in step; iterators would hide that.
#![allow(clippy::needless_range_loop)]

use crate::api::{OdeSystem, Stats};
use crate::driver::{Attempt, Stepper};
use crate::hermite::Hermite;

/// RK4 stepper; `k[0]` carries `f(t, x)` from the end of the previous step.
pub(crate) struct Rk4 {
    k: [Vec<f64>; 4],
    y: Vec<f64>,
    k1_valid: bool,
    /// The last accepted step, for the dense output.
    last: Hermite,
}

impl Rk4 {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            k: std::array::from_fn(|_| vec![0.0; n]),
            y: vec![0.0; n],
            k1_valid: false,
            last: Hermite::new(n),
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
        self.last.keep_step(x, &self.k[0], x_new, h);
        sys.rhs(t + h, x_new, &mut self.last.f1);
        stats.rhs_evals += 1;
        // f(t + h, x_new) is the first stage of the next step.
        self.k[0].copy_from_slice(&self.last.f1);
    }

    fn dense(&self, theta: f64, out: &mut [f64]) {
        self.last.dense(theta, out);
    }
}
