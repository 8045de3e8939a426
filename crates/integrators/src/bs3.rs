//! Bogacki–Shampine 3(2) (Bogacki & Shampine 1989, the method of MATLAB's
//! `ode23`): four stages of which the last is the first of the next step
//! (FSAL), so three right-hand sides a step; third-order solution, embedded
//! second-order error estimate, cubic Hermite dense output from the end
//! values and end derivatives (third order).
//!
//! [`Method::Auto`](crate::Method::Auto) takes it where the explicit step is
//! held at `Options::h_max` with an error far below the tolerance (the
//! steady phases of a drive): there it does the same step for half the
//! right-hand sides of Dormand–Prince.
// The stage loops index several vectors in step; iterators would hide that.
#![allow(clippy::needless_range_loop)]

use crate::api::{OdeSystem, Stats};
use crate::driver::{Attempt, Stepper};
use crate::hermite::Hermite;

const A32: f64 = 3.0 / 4.0;
const B1: f64 = 2.0 / 9.0;
const B2: f64 = 1.0 / 3.0;
const B3: f64 = 4.0 / 9.0;
// Error coefficients: third-order weights minus the embedded second-order
// ones (7/24, 1/4, 1/3, 1/8).
const E1: f64 = -5.0 / 72.0;
const E2: f64 = 1.0 / 12.0;
const E3: f64 = 1.0 / 9.0;
const E4: f64 = -1.0 / 8.0;

/// Bogacki–Shampine 3(2) stepper; all work vectors allocated once.
pub(crate) struct BogackiShampine {
    k: [Vec<f64>; 4],
    y: Vec<f64>,
    /// `k[0]` holds `f(t, x)` for the next attempt (FSAL).
    k1_valid: bool,
    /// The last accepted step, for the dense output.
    last: Hermite,
}

impl BogackiShampine {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            k: std::array::from_fn(|_| vec![0.0; n]),
            y: vec![0.0; n],
            k1_valid: false,
            last: Hermite::new(n),
        }
    }

    /// Takes `f(t, x)` of the step about to start from another stepper
    /// (the first stage it would otherwise compute).
    pub(crate) fn set_f_start(&mut self, f: &[f64]) {
        self.k[0].copy_from_slice(f);
        self.k1_valid = true;
    }
}

impl Stepper for BogackiShampine {
    fn adaptive(&self) -> bool {
        true
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
        // every vector cut to n: the stage loops need no bounds checks
        let (k1, k2, k3, k4) = (&mut k1[..n], &mut k2[..n], &mut k3[..n], &mut k4[..n]);
        let (y, x_new, err) = (&mut self.y[..n], &mut x_new[..n], &mut err[..n]);
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
            y[i] = x[i] + h * A32 * k2[i];
        }
        sys.rhs(t + 0.75 * h, y, k3);
        for i in 0..n {
            x_new[i] = x[i] + h * (B1 * k1[i] + B2 * k2[i] + B3 * k3[i]);
        }
        sys.rhs(t + h, x_new, k4);
        stats.rhs_evals += 3;
        for i in 0..n {
            err[i] = h * (E1 * k1[i] + E2 * k2[i] + E3 * k3[i] + E4 * k4[i]);
        }
        Attempt::Done
    }

    fn f_start(&self) -> &[f64] {
        &self.k[0]
    }

    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        _sys: &S,
        _t: f64,
        x: &[f64],
        h: f64,
        x_new: &[f64],
        _stats: &mut Stats,
    ) {
        self.last.keep_step(x, &self.k[0], x_new, h);
        self.last.f1.copy_from_slice(&self.k[3]);
        // FSAL: f(t + h, x_new) is the first stage of the next step.
        self.k.swap(0, 3);
    }

    fn dense(&self, theta: f64, out: &mut [f64]) {
        self.last.dense(theta, out);
    }
}
