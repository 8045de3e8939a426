//! [`Method::Auto`](crate::Method::Auto): Dormand–Prince 5(4) while the
//! problem is not stiff, Rodas4 while it is, switched by stiffness detected
//! from the run itself.
//!
//! * **DP45 → Rodas4** (Hairer, Nørsett & Wanner I, §II.10, the test of
//!   `DOPRI5`): after each accepted explicit step the last two stages, both at
//!   `t + h`, give `ρ = ‖f(y₇) − f(y₆)‖ / ‖y₇ − y₆‖`, an estimate of the
//!   Jacobian's dominant eigenvalue magnitude along the step. `h ρ` beyond
//!   3.25 means the step sits on the boundary of DP45's stability region
//!   (which crosses the negative real axis at −3.3): the step-size
//!   controller is held there by stability, not accuracy. [`STIFF_STEPS`]
//!   such steps in a row (interrupted by fewer than [`CALM_STEPS`] others)
//!   switch to Rodas4.
//! * **Rodas4 → DP45**: Rodas4 computes the Jacobian `J` every step; a
//!   power iteration gives its spectral radius `ρ(J)`. When the stiff method's
//!   own accepted step is at most `BACK_HRHO / ρ(J)` for [`BACK_STEPS`] steps
//!   in a row, DP45 would be stable at that step while costing a fraction of a
//!   Rosenbrock step (no Jacobian, no LU): switch back, the first explicit step
//!   no larger than the stable one.
//!
//! * **DP45 ⇄ Bogacki–Shampine 3(2)**: DP45 steps held at `Options::h_max`
//!   with a normed error at most [`LOW_ERR`] for [`LOW_STEPS`] steps go to
//!   the third-order pair (half the right-hand sides a step). It keeps a
//!   step only when its normed error is at most [`LOW_KEEP`]: a step
//!   between that and the tolerance is taken again by DP45, which goes on
//!   (so does a rejected step, or one after which the controller wants less
//!   than `h_max`). Its error estimate, `h³ x‴ / 48` to leading order, does
//!   not see the error of a step along a parabola (a volume charged through
//!   an orifice, [`crate::problems::OrificeCharge`]), where the step's error
//!   is ~4× the estimate; kept at every step up to the tolerance, such steps
//!   added up to 3–30× rtol over a run where DP45 stays under rtol.
//!
//! Norms are weighted by the error scale (`1/(atol_i + rtol |x_i|)`), a
//! similarity transform that keeps the eigenvalues but makes a pressure in Pa
//! and a position in m comparable; quadrature states (which no derivative
//! reads) are left out. The detection never changes a step's result: a run
//! that never switches is the DP45 run, bit for bit.
#![allow(clippy::needless_range_loop)]

use crate::api::{OdeSystem, Stats};
use crate::bs3::BogackiShampine;
use crate::dopri::DormandPrince;
use crate::driver::{Attempt, Controller, Stepper, Switch};
use crate::rodas::Rodas4;

/// `h ρ` above which a DP45 step counts as held by stability.
const STIFF_HRHO: f64 = 3.25;
/// Consecutive stability-held DP45 steps that switch to Rodas4.
pub(crate) const STIFF_STEPS: usize = 15;
/// Steps not held by stability that clear the stiff count.
pub(crate) const CALM_STEPS: usize = 6;
/// `h ρ(J)` below which a Rodas4 step would be stable for DP45.
const BACK_HRHO: f64 = 2.0;
/// Consecutive such Rodas4 steps that switch back to DP45.
pub(crate) const BACK_STEPS: usize = 25;
/// Power iterations for the spectral radius.
const POWER_ITERATIONS: usize = 12;
/// DP45 normed error at or below which a step held at `h_max` counts as
/// far inside the tolerance (a third-order step of the same size would be
/// too).
const LOW_ERR: f64 = 1e-2;
/// Consecutive such DP45 steps that switch to Bogacki–Shampine 3(2).
pub(crate) const LOW_STEPS: usize = 3;
/// Bogacki–Shampine 3(2)'s normed error above which its step is not kept
/// but taken again by DP45 (which then goes on): the low-order pair is for
/// steps far inside the tolerance only. Its error estimate is
/// `h³ x‴ / 48` to leading order, blind to the error of a step along a
/// parabola (a volume charged through an orifice: the estimate there is
/// 4× below the step's error, [`crate::problems::OrificeCharge`]); kept
/// steps at most `LOW_KEEP` of the tolerance leave the global error of the
/// order of DP45's.
pub(crate) const LOW_KEEP: f64 = 0.05;

/// The controller of each method (the ones [`crate::solve`] uses for them).
pub(crate) const DP_CONTROLLER: Controller = Controller::Pi { q: 5.0, beta: 0.04 };
/// The controller of Rodas4.
pub(crate) const RODAS_CONTROLLER: Controller = Controller::Predictive { q: 4.0 };
/// The controller of Bogacki–Shampine 3(2).
pub(crate) const BS_CONTROLLER: Controller = Controller::Pi { q: 3.0, beta: 0.04 };

/// Which method takes the next step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Mode {
    Explicit,
    Stiff,
    /// Bogacki–Shampine 3(2) while the step is held at `h_max`.
    Low,
}

/// The switching stepper.
pub(crate) struct Auto {
    dp: DormandPrince,
    rodas: Rodas4,
    bs: BogackiShampine,
    /// Consecutive DP45 steps held at `h_max` far inside the tolerance.
    capped: usize,
    mode: Mode,
    /// Active (non-quadrature) states.
    na: usize,
    /// Error weights `1/(atol_i + rtol |x_i|)` of the current step.
    weight: Vec<f64>,
    atol: Vec<f64>,
    rtol: f64,
    /// Consecutive stability-held explicit steps, and steps since the last one.
    held: usize,
    calm: usize,
    /// Consecutive stiff steps at which DP45 would be stable.
    easy: usize,
    /// The stable explicit step at the last check \[s\].
    h_stable: f64,
    /// A switch decided after the last accepted step, not yet taken.
    pending: Option<Mode>,
    /// Power-iteration vectors.
    v: Vec<f64>,
    w: Vec<f64>,
}

impl Auto {
    /// A stepper for `n` states, the last `quadratures` of them quadratures.
    pub(crate) fn new(n: usize, quadratures: usize) -> Self {
        let na = n - quadratures.min(n);
        Self {
            dp: DormandPrince::new(n),
            rodas: Rodas4::new(n, quadratures),
            bs: BogackiShampine::new(n),
            capped: 0,
            mode: Mode::Explicit,
            na,
            weight: vec![1.0; n],
            atol: vec![0.0; n],
            rtol: 0.0,
            held: 0,
            calm: 0,
            easy: 0,
            h_stable: f64::INFINITY,
            pending: None,
            v: vec![0.0; na],
            w: vec![0.0; na],
        }
    }

    fn set_weights(&mut self, x: &[f64]) {
        for i in 0..self.na {
            self.weight[i] = 1.0 / (self.atol[i] + self.rtol * x[i].abs()).max(f64::MIN_POSITIVE);
        }
    }

    /// After an accepted DP45 step: counts stability-held steps.
    fn check_explicit(&mut self, h: f64, x_new: &[f64]) {
        self.set_weights(x_new);
        let rho = self.dp.stiffness_ratio(x_new, &self.weight[..self.na]);
        if !rho.is_finite() {
            return;
        }
        if h * rho > STIFF_HRHO {
            self.held += 1;
            self.calm = 0;
            if self.held >= STIFF_STEPS {
                self.pending = Some(Mode::Stiff);
            }
        } else {
            self.calm += 1;
            if self.calm >= CALM_STEPS {
                self.held = 0;
            }
        }
    }

    /// After an accepted Rodas4 step: counts steps DP45 could take as stably.
    fn check_stiff(&mut self, h: f64, x: &[f64]) {
        self.set_weights(x);
        let rho = self.spectral_radius();
        if !rho.is_finite() {
            return;
        }
        self.h_stable = if rho > 0.0 {
            BACK_HRHO / rho
        } else {
            f64::INFINITY
        };
        if h <= self.h_stable {
            self.easy += 1;
            if self.easy >= BACK_STEPS {
                self.pending = Some(Mode::Explicit);
            }
        } else {
            self.easy = 0;
        }
    }

    /// Spectral radius of the weighted active Jacobian `W J W⁻¹` of the last
    /// Rodas4 step, by power iteration: `(‖A^k v‖ / ‖v‖)^(1/k)`, which tends
    /// to `ρ(A)` for complex dominant pairs too.
    fn spectral_radius(&mut self) -> f64 {
        let (na, n) = (self.na, self.rodas.dim());
        if na == 0 {
            return 0.0;
        }
        let jac = self.rodas.jacobian();
        let wt = &self.weight;
        // a start vector with every component, not symmetric in sign
        for i in 0..na {
            self.v[i] = 1.0 + 0.37 * (i % 3) as f64 - 0.5 * (i % 2) as f64;
        }
        let norm = |v: &[f64]| v.iter().map(|a| a * a).sum::<f64>().sqrt();
        let mut log_growth = 0.0;
        let mut nv = norm(&self.v);
        for _ in 0..POWER_ITERATIONS {
            for i in 0..na {
                let row = &jac[i * n..i * n + na];
                let mut s = 0.0;
                for j in 0..na {
                    s += row[j] * self.v[j] / wt[j];
                }
                self.w[i] = wt[i] * s;
            }
            let nw = norm(&self.w);
            if !(nw > 0.0 && nw.is_finite()) {
                return if nw == 0.0 { 0.0 } else { f64::NAN };
            }
            log_growth += (nw / nv).ln();
            for i in 0..na {
                self.v[i] = self.w[i] / nw;
            }
            nv = 1.0;
        }
        (log_growth / POWER_ITERATIONS as f64).exp()
    }

    /// The switch decided after the last accepted step, taken now: the
    /// controller of the method that takes the next step and the largest
    /// step it should start with.
    pub(crate) fn take_switch(&mut self) -> Option<Switch> {
        let to = self.pending.take()?;
        let from = self.mode;
        self.mode = to;
        self.held = 0;
        self.calm = 0;
        self.easy = 0;
        self.capped = 0;
        Some(match (from, to) {
            (_, Mode::Stiff) => {
                self.rodas.restart();
                Switch {
                    controller: RODAS_CONTROLLER,
                    h_cap: f64::INFINITY,
                    stiff: true,
                }
            }
            (Mode::Stiff, Mode::Explicit) => {
                self.dp.restart();
                Switch {
                    controller: DP_CONTROLLER,
                    h_cap: self.h_stable,
                    stiff: true,
                }
            }
            (_, Mode::Low) => {
                // the explicit pairs share the first stage
                self.bs.set_f_start(self.dp.f_start());
                Switch {
                    controller: BS_CONTROLLER,
                    h_cap: f64::INFINITY,
                    stiff: false,
                }
            }
            (_, Mode::Explicit) => {
                self.dp.set_f_start(self.bs.f_start());
                Switch {
                    controller: DP_CONTROLLER,
                    h_cap: f64::INFINITY,
                    stiff: false,
                }
            }
        })
    }
}

impl Stepper for Auto {
    fn adaptive(&self) -> bool {
        true
    }

    fn restart(&mut self) {
        self.dp.restart();
        self.rodas.restart();
        self.bs.restart();
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
        match self.mode {
            Mode::Explicit => self.dp.attempt(sys, t, x, h, x_new, err, stats),
            Mode::Stiff => self.rodas.attempt(sys, t, x, h, x_new, err, stats),
            Mode::Low => self.bs.attempt(sys, t, x, h, x_new, err, stats),
        }
    }

    fn f_start(&self) -> &[f64] {
        match self.mode {
            Mode::Explicit => self.dp.f_start(),
            Mode::Stiff => self.rodas.f_start(),
            Mode::Low => self.bs.f_start(),
        }
    }

    fn nonfinite_hint(&self) -> Option<usize> {
        match self.mode {
            Mode::Explicit => self.dp.nonfinite_hint(),
            Mode::Stiff => self.rodas.nonfinite_hint(),
            Mode::Low => self.bs.nonfinite_hint(),
        }
    }

    fn set_scale(&mut self, atol: &[f64], rtol: f64) {
        self.atol.copy_from_slice(atol);
        self.rtol = rtol;
        self.dp.set_scale(atol, rtol);
        self.rodas.set_scale(atol, rtol);
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
        match self.mode {
            Mode::Explicit => {
                self.check_explicit(h, x_new);
                self.dp.accept(sys, t, x, h, x_new, stats);
            }
            Mode::Stiff => {
                self.check_stiff(h, x);
                self.rodas.accept(sys, t, x, h, x_new, stats);
            }
            Mode::Low => {
                stats.low_order_steps += 1;
                self.bs.accept(sys, t, x, h, x_new, stats);
            }
        }
    }

    fn observe(&mut self, err: f64, held_at_h_max: bool) {
        match self.mode {
            Mode::Explicit => {
                if held_at_h_max && err <= LOW_ERR {
                    self.capped += 1;
                    if self.capped >= LOW_STEPS && self.pending.is_none() {
                        self.pending = Some(Mode::Low);
                    }
                } else {
                    self.capped = 0;
                }
            }
            // the step is no longer held at h_max: accuracy sets it again
            Mode::Low if !held_at_h_max => self.pending = Some(Mode::Explicit),
            _ => {}
        }
    }

    fn rejected(&mut self) {
        if self.mode == Mode::Low {
            self.pending = Some(Mode::Explicit);
        }
    }

    fn retake(&mut self, err: f64) -> bool {
        if self.mode == Mode::Low && err > LOW_KEEP {
            self.pending = Some(Mode::Explicit);
            true
        } else {
            false
        }
    }

    fn dense(&self, theta: f64, out: &mut [f64]) {
        match self.mode {
            Mode::Explicit => self.dp.dense(theta, out),
            Mode::Stiff => self.rodas.dense(theta, out),
            Mode::Low => self.bs.dense(theta, out),
        }
    }

    fn switch(&mut self) -> Option<Switch> {
        self.take_switch()
    }
}
