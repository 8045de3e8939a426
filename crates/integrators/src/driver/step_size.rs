//! Step-size control: the controller ([`Controller`]) and its state across
//! steps, the error norm it reads, and the starting step.

use crate::api::{OdeSystem, StateShare, Stats};

/// Step-size controller of an adaptive method.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Controller {
    /// Proportional–integral controller (Hairer, Nørsett & Wanner I, §II.4):
    /// `h_new = h · safe · err^(-α) · err_prev^(β)`, `α = 1/q − 0.75 β`,
    /// where `q` is the order of the error estimate plus one.
    Pi {
        /// `q`: the local error estimate behaves like `h^q`.
        q: f64,
        /// The integral gain `β`.
        beta: f64,
    },
    /// Gustafsson's predictive controller (Hairer & Wanner II, §IV.8), the
    /// one Rodas uses: `h_new = h · min(h/h_prev · (err_prev/err)^(1/q), err^(-1/q))`.
    Predictive {
        /// `q`: the local error estimate behaves like `h^q`.
        q: f64,
    },
}

/// Safety factor on the step-size proposal.
const SAFE: f64 = 0.9;
/// Largest shrink factor per step.
const FAC_MIN: f64 = 0.2;
/// Largest growth factor per step.
const FAC_MAX: f64 = 10.0;

pub(super) struct ControlState {
    controller: Controller,
    err_prev: f64,
    h_prev: f64,
    first: bool,
    pub(super) last_rejected: bool,
}

impl ControlState {
    pub(super) fn new(controller: Controller) -> Self {
        Self {
            controller,
            err_prev: 1e-4,
            h_prev: 0.0,
            first: true,
            last_rejected: false,
        }
    }

    pub(super) fn reset(&mut self) {
        self.err_prev = 1e-4;
        self.first = true;
        self.last_rejected = false;
    }

    /// The next step size after an accepted step with normed error `err ≤ 1`.
    pub(super) fn accepted(&mut self, h: f64, err: f64) -> f64 {
        let err = err.max(1e-10);
        let mut fac = match self.controller {
            Controller::Pi { q, beta } => {
                let alpha = 1.0 / q - 0.75 * beta;
                SAFE * err.powf(-alpha) * self.err_prev.powf(beta)
            }
            Controller::Predictive { q } => {
                let plain = SAFE * err.powf(-1.0 / q);
                if self.first {
                    plain
                } else {
                    let pred = SAFE * (h / self.h_prev) * (self.err_prev / err).powf(1.0 / q)
                        / err.powf(1.0 / q);
                    plain.min(pred)
                }
            }
        };
        fac = fac.clamp(FAC_MIN, FAC_MAX);
        if self.last_rejected {
            fac = fac.min(1.0);
        }
        self.err_prev = match self.controller {
            Controller::Pi { .. } => err.max(1e-4),
            Controller::Predictive { .. } => err.max(1e-2),
        };
        self.h_prev = h;
        self.first = false;
        self.last_rejected = false;
        h * fac
    }

    /// The retry step size after a rejected step with normed error `err > 1`.
    pub(super) fn rejected(&mut self, h: f64, err: f64) -> f64 {
        let q = match self.controller {
            Controller::Pi { q, .. } | Controller::Predictive { q } => q,
        };
        let fac = if err.is_finite() {
            (SAFE * err.powf(-1.0 / q)).clamp(FAC_MIN, 1.0)
        } else {
            FAC_MIN
        };
        self.last_rejected = true;
        h * fac
    }
}

/// The mixed absolute/relative RMS error norm (Hairer's):
/// `‖e‖ = sqrt( (1/n) Σ (e_i / (atol_i + rtol·max(|x_i|, |x̂_i|)))² )`.
pub(crate) fn error_norm(err: &[f64], x: &[f64], x_new: &[f64], atol: &[f64], rtol: f64) -> f64 {
    let n = err.len();
    if n == 0 {
        return 0.0;
    }
    let (x, x_new, atol) = (&x[..n], &x_new[..n], &atol[..n]);
    let mut sum = 0.0;
    for i in 0..n {
        let sc = (atol[i] + rtol * x[i].abs().max(x_new[i].abs())).max(f64::MIN_POSITIVE);
        let r = err[i] / sc;
        sum += r * r;
    }
    (sum / n as f64).sqrt()
}

/// The error of a step whose last `n − active` states are quadratures
/// ([`OdeSystem::n_quadratures`]): the [`error_norm`] of the states and that
/// of the quadratures, each over its own, and the larger of the two (NaN if
/// either is). Quadratures added to a system (a mass balance, an energy
/// ledger) then never loosen the control of its states, as one RMS over
/// both would (by `√(n/active)` where the quadratures' errors are small
/// against their tolerances); they are controlled by their own.
pub(crate) fn split_error_norm(
    err: &[f64],
    x: &[f64],
    x_new: &[f64],
    atol: &[f64],
    rtol: f64,
    active: usize,
) -> f64 {
    let states = error_norm(&err[..active], x, x_new, atol, rtol);
    if active == err.len() {
        return states;
    }
    let a = active;
    let quadratures = error_norm(&err[a..], &x[a..], &x_new[a..], &atol[a..], rtol);
    if states.is_nan() || quadratures.is_nan() {
        f64::NAN
    } else {
        states.max(quadratures)
    }
}

/// Hairer's starting-step heuristic (Hairer, Nørsett & Wanner I, §II.4):
/// a step such that an explicit Euler step has a local error of about the
/// tolerance, refined with one extra right-hand-side evaluation.
#[allow(clippy::too_many_arguments)]
pub(super) fn initial_step<S: OdeSystem + ?Sized>(
    sys: &S,
    t: f64,
    x: &[f64],
    f0: &[f64],
    order: f64,
    atol: &[f64],
    rtol: f64,
    h_max: f64,
    work_x: &mut [f64],
    work_f: &mut [f64],
    stats: &mut Stats,
) -> f64 {
    let n = x.len();
    // the states' norms alone, as the steps' errors (`split_error_norm`):
    // quadratures added to a system leave its first step as it was
    let active = match n - sys.n_quadratures().min(n) {
        0 => n,
        a => a,
    };
    let sc = |i: usize| (atol[i] + rtol * x[i].abs()).max(f64::MIN_POSITIVE);
    let (mut d0, mut d1) = (0.0, 0.0);
    for i in 0..active {
        d0 += (x[i] / sc(i)).powi(2);
        d1 += (f0[i] / sc(i)).powi(2);
    }
    let d0 = (d0 / active as f64).sqrt();
    let d1 = (d1 / active as f64).sqrt();
    let mut h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    h0 = h0.min(h_max);
    for i in 0..n {
        work_x[i] = x[i] + h0 * f0[i];
    }
    sys.rhs(t + h0, work_x, work_f);
    stats.rhs_evals += 1;
    let mut d2 = 0.0;
    for i in 0..active {
        d2 += ((work_f[i] - f0[i]) / sc(i)).powi(2);
    }
    let d2 = (d2 / active as f64).sqrt() / h0;
    let dmax = d1.max(d2);
    let h1 = if !dmax.is_finite() {
        h0
    } else if dmax <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / dmax).powf(1.0 / order)
    };
    (100.0 * h0).min(h1).min(h_max)
}

/// The states that dominate a rejected step's error estimate `err` (from
/// `x` towards `x_new`): each state's term of [`error_norm`], the largest
/// first, those within a tenth of the largest, at most three; NaN terms
/// count as the largest. Empty when every term is zero.
pub(crate) fn dominant_states<S: OdeSystem + ?Sized>(
    sys: &S,
    err: &[f64],
    x: &[f64],
    x_new: &[f64],
    atol: &[f64],
    rtol: f64,
) -> Vec<StateShare> {
    let term = |i: usize| {
        let sc = (atol[i] + rtol * x[i].abs().max(x_new[i].abs())).max(f64::MIN_POSITIVE);
        let r = (err[i] / sc).abs();
        if r.is_nan() {
            f64::INFINITY
        } else {
            r
        }
    };
    let mut order: Vec<usize> = (0..err.len()).filter(|&i| term(i) > 0.0).collect();
    order.sort_by(|&a, &b| term(b).total_cmp(&term(a)));
    let Some(&top) = order.first() else {
        return Vec::new();
    };
    let floor = 0.1 * term(top);
    order
        .into_iter()
        .take_while(|&i| term(i) >= floor)
        .take(3)
        .map(|i| StateShare {
            index: i,
            name: sys.state_name(i),
            value: x[i],
            error: term(i),
        })
        .collect()
}
