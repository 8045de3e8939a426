//! Dormand–Prince 5(4) (Dormand & Prince 1980) with FSAL and Dormand &
//! Prince's continuous extension of order 4 (Hairer, Nørsett & Wanner I,
//! §II.6, the coefficients of `DOPRI5`).
// The stage loops index several vectors in step; iterators would hide that.
#![allow(clippy::needless_range_loop)]

use crate::api::{OdeSystem, Stats};
use crate::driver::{Attempt, Stepper};

const C2: f64 = 1.0 / 5.0;
const C3: f64 = 3.0 / 10.0;
const C4: f64 = 4.0 / 5.0;
const C5: f64 = 8.0 / 9.0;
const A21: f64 = 1.0 / 5.0;
const A31: f64 = 3.0 / 40.0;
const A32: f64 = 9.0 / 40.0;
const A41: f64 = 44.0 / 45.0;
const A42: f64 = -56.0 / 15.0;
const A43: f64 = 32.0 / 9.0;
const A51: f64 = 19372.0 / 6561.0;
const A52: f64 = -25360.0 / 2187.0;
const A53: f64 = 64448.0 / 6561.0;
const A54: f64 = -212.0 / 729.0;
const A61: f64 = 9017.0 / 3168.0;
const A62: f64 = -355.0 / 33.0;
const A63: f64 = 46732.0 / 5247.0;
const A64: f64 = 49.0 / 176.0;
const A65: f64 = -5103.0 / 18656.0;
const A71: f64 = 35.0 / 384.0;
const A73: f64 = 500.0 / 1113.0;
const A74: f64 = 125.0 / 192.0;
const A75: f64 = -2187.0 / 6784.0;
const A76: f64 = 11.0 / 84.0;
// Error coefficients: 5th-order weights minus the embedded 4th-order ones.
const E1: f64 = 71.0 / 57600.0;
const E3: f64 = -71.0 / 16695.0;
const E4: f64 = 71.0 / 1920.0;
const E5: f64 = -17253.0 / 339200.0;
const E6: f64 = 22.0 / 525.0;
const E7: f64 = -1.0 / 40.0;
// Dense-output coefficients.
const D1: f64 = -12715105075.0 / 11282082432.0;
const D3: f64 = 87487479700.0 / 32700410799.0;
const D4: f64 = -10690763975.0 / 1880347072.0;
const D5: f64 = 701980252875.0 / 199316789632.0;
const D6: f64 = -1453857185.0 / 822651844.0;
const D7: f64 = 69997945.0 / 29380423.0;

/// Dormand–Prince 5(4) stepper; all work vectors allocated once.
pub(crate) struct DormandPrince {
    k: [Vec<f64>; 7],
    y: Vec<f64>,
    /// `k[0]` holds `f(t, x)` for the next attempt (FSAL).
    k1_valid: bool,
    rcont: [Vec<f64>; 5],
}

impl DormandPrince {
    pub(crate) fn new(n: usize) -> Self {
        Self {
            k: std::array::from_fn(|_| vec![0.0; n]),
            y: vec![0.0; n],
            k1_valid: false,
            rcont: std::array::from_fn(|_| vec![0.0; n]),
        }
    }
}

impl DormandPrince {
    /// Takes `f(t, x)` of the step about to start from another stepper
    /// (the first stage it would otherwise compute).
    pub(crate) fn set_f_start(&mut self, f: &[f64]) {
        self.k[0].copy_from_slice(f);
        self.k1_valid = true;
    }

    /// `‖f(y₇) − f(y₆)‖ / ‖y₇ − y₆‖` of the last attempted step, over the
    /// first `w.len()` states weighted by `w`: both stages sit at `t + h`, so
    /// the ratio estimates the Jacobian's dominant eigenvalue magnitude
    /// (Hairer, Nørsett & Wanner I, §II.10). Call before [`Stepper::accept`]
    /// (which moves the last stage to the first for FSAL). 0 when `y₇ = y₆`.
    pub(crate) fn stiffness_ratio(&self, x_new: &[f64], w: &[f64]) -> f64 {
        let (k6, k7, y6) = (&self.k[5], &self.k[6], &self.y);
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..w.len() {
            let df = (k7[i] - k6[i]) * w[i];
            let dy = (x_new[i] - y6[i]) * w[i];
            num += df * df;
            den += dy * dy;
        }
        if den > 0.0 {
            (num / den).sqrt()
        } else {
            0.0
        }
    }
}

impl Stepper for DormandPrince {
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
        let [k1, k2, k3, k4, k5, k6, k7] = &mut self.k;
        // every vector cut to n: the stage loops need no bounds checks
        let (k1, k2, k3, k4) = (&mut k1[..n], &mut k2[..n], &mut k3[..n], &mut k4[..n]);
        let (k5, k6, k7) = (&mut k5[..n], &mut k6[..n], &mut k7[..n]);
        let (y, x_new, err) = (&mut self.y[..n], &mut x_new[..n], &mut err[..n]);
        if !self.k1_valid {
            sys.rhs(t, x, k1);
            stats.rhs_evals += 1;
            self.k1_valid = true;
        }
        for i in 0..n {
            y[i] = x[i] + h * A21 * k1[i];
        }
        sys.rhs(t + C2 * h, y, k2);
        for i in 0..n {
            y[i] = x[i] + h * (A31 * k1[i] + A32 * k2[i]);
        }
        sys.rhs(t + C3 * h, y, k3);
        for i in 0..n {
            y[i] = x[i] + h * (A41 * k1[i] + A42 * k2[i] + A43 * k3[i]);
        }
        sys.rhs(t + C4 * h, y, k4);
        for i in 0..n {
            y[i] = x[i] + h * (A51 * k1[i] + A52 * k2[i] + A53 * k3[i] + A54 * k4[i]);
        }
        sys.rhs(t + C5 * h, y, k5);
        for i in 0..n {
            y[i] = x[i] + h * (A61 * k1[i] + A62 * k2[i] + A63 * k3[i] + A64 * k4[i] + A65 * k5[i]);
        }
        sys.rhs(t + h, y, k6);
        for i in 0..n {
            x_new[i] =
                x[i] + h * (A71 * k1[i] + A73 * k3[i] + A74 * k4[i] + A75 * k5[i] + A76 * k6[i]);
        }
        sys.rhs(t + h, x_new, k7);
        stats.rhs_evals += 6;
        for i in 0..n {
            err[i] =
                h * (E1 * k1[i] + E3 * k3[i] + E4 * k4[i] + E5 * k5[i] + E6 * k6[i] + E7 * k7[i]);
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
        let n = x.len();
        let [k1, _k2, k3, k4, k5, k6, k7] = &self.k;
        let [r1, r2, r3, r4, r5] = &mut self.rcont;
        let (k1, k3, k4, k5, k6, k7) = (&k1[..n], &k3[..n], &k4[..n], &k5[..n], &k6[..n], &k7[..n]);
        let (r1, r2, r3, r4, r5) = (
            &mut r1[..n],
            &mut r2[..n],
            &mut r3[..n],
            &mut r4[..n],
            &mut r5[..n],
        );
        let x_new = &x_new[..n];
        for i in 0..n {
            let dy = x_new[i] - x[i];
            let bspl = h * k1[i] - dy;
            r1[i] = x[i];
            r2[i] = dy;
            r3[i] = bspl;
            r4[i] = dy - h * k7[i] - bspl;
            r5[i] =
                h * (D1 * k1[i] + D3 * k3[i] + D4 * k4[i] + D5 * k5[i] + D6 * k6[i] + D7 * k7[i]);
        }
        // FSAL: f(t + h, x_new) is the first stage of the next step.
        self.k.swap(0, 6);
    }

    fn dense(&self, theta: f64, out: &mut [f64]) {
        let s1 = 1.0 - theta;
        let n = out.len();
        let [r1, r2, r3, r4, r5] = &self.rcont;
        let (r1, r2, r3, r4, r5) = (&r1[..n], &r2[..n], &r3[..n], &r4[..n], &r5[..n]);
        for i in 0..n {
            out[i] = r1[i] + theta * (r2[i] + s1 * (r3[i] + theta * (r4[i] + s1 * r5[i])));
        }
    }
}
