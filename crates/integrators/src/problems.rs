//! Reusable test problems with known answers, used by this crate's tests,
//! benches and `cargo xtask validate`, and available to other crates' tests.
//!
//! | problem | states | stiff | known answer |
//! |---|---|---|---|
//! | [`ExponentialDecay`] | 1 | for large `k` | `x(t) = x0·exp(−k t)` |
//! | [`HarmonicOscillator`] | 2 | no | `x = x0 cos ωt + v0/ω sin ωt` |
//! | [`TimeVarying`] | 1 | no | `x(t) = x0·exp(sin t)` (non-autonomous) |
//! | [`VanDerPol`] | 2 | for large `μ` | limit cycle, period ≈ (3 − 2 ln 2) μ for large μ |
//! | [`Robertson`] | 3 | yes | conservation `x1 + x2 + x3 = 1` |
//! | [`BouncingBall`] | 2 | no | bounce times in closed form ([`BouncingBall::bounce_times`]) |
//! | [`OrificeCharge`] | 1 | near its end | `p(t) = ps − (√ps − k t/2)²` until `p = ps` |
//!
//! All give analytic Jacobians except [`BouncingBall`] and [`TimeVarying`],
//! which exercise the finite-difference Jacobian.

use crate::api::{Crossing, EventAction, OdeSystem};

/// `dx/dt = −k x`.
#[derive(Clone, Copy, Debug)]
pub struct ExponentialDecay {
    /// Rate constant `k` \[1/s\].
    pub k: f64,
}

impl ExponentialDecay {
    /// The exact solution at `t` from `x0` at time 0.
    pub fn exact(&self, t: f64, x0: f64) -> f64 {
        x0 * (-self.k * t).exp()
    }
}

impl OdeSystem for ExponentialDecay {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = -self.k * x[0];
    }
    fn jacobian(&self, _t: f64, _x: &[f64], jac: &mut [f64]) -> bool {
        jac[0] = -self.k;
        true
    }
}

/// `x'' = −ω² x` as `[x, v]`.
#[derive(Clone, Copy, Debug)]
pub struct HarmonicOscillator {
    /// Angular frequency `ω` \[rad/s\].
    pub omega: f64,
}

impl HarmonicOscillator {
    /// The exact state `[x, v]` at `t` from `[x0, v0]` at time 0.
    pub fn exact(&self, t: f64, x0: [f64; 2]) -> [f64; 2] {
        let w = self.omega;
        let (s, c) = (w * t).sin_cos();
        [x0[0] * c + x0[1] / w * s, -x0[0] * w * s + x0[1] * c]
    }
}

impl OdeSystem for HarmonicOscillator {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = x[1];
        dx[1] = -self.omega * self.omega * x[0];
    }
    fn jacobian(&self, _t: f64, _x: &[f64], jac: &mut [f64]) -> bool {
        jac.copy_from_slice(&[0.0, 1.0, -self.omega * self.omega, 0.0]);
        true
    }
}

/// The non-autonomous `dx/dt = cos(t) · x`; checks the `∂f/∂t` terms of the
/// Rosenbrock method and the finite-difference Jacobian.
#[derive(Clone, Copy, Debug, Default)]
pub struct TimeVarying;

impl TimeVarying {
    /// The exact solution at `t` from `x0` at time 0.
    pub fn exact(&self, t: f64, x0: f64) -> f64 {
        x0 * t.sin().exp()
    }
}

impl OdeSystem for TimeVarying {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = t.cos() * x[0];
    }
}

/// Van der Pol's oscillator in its classical (unscaled) form
/// `x1' = x2`, `x2' = μ (1 − x1²) x2 − x1` (MATLAB's `vdp1000` for μ = 1000).
/// Stiff for large `μ`: the slow branches have `∂f2/∂x2 = μ(1 − x1²) ≈ −3μ`;
/// the usual start is `[2, 0]`, the period ≈ (3 − 2 ln 2) μ for large μ.
#[derive(Clone, Copy, Debug)]
pub struct VanDerPol {
    /// Damping parameter `μ`.
    pub mu: f64,
}

impl OdeSystem for VanDerPol {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = x[1];
        dx[1] = self.mu * (1.0 - x[0] * x[0]) * x[1] - x[0];
    }
    fn jacobian(&self, _t: f64, x: &[f64], jac: &mut [f64]) -> bool {
        jac[0] = 0.0;
        jac[1] = 1.0;
        jac[2] = -2.0 * self.mu * x[0] * x[1] - 1.0;
        jac[3] = self.mu * (1.0 - x[0] * x[0]);
        true
    }
}

/// Robertson's chemical kinetics (Hairer & Wanner II, §IV.1), start `[1, 0, 0]`:
/// `x1' = −0.04 x1 + 1e4 x2 x3`, `x2' = 0.04 x1 − 1e4 x2 x3 − 3e7 x2²`,
/// `x3' = 3e7 x2²`. The sum of the states is conserved.
#[derive(Clone, Copy, Debug, Default)]
pub struct Robertson;

impl OdeSystem for Robertson {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&self, _t: f64, x: &[f64], dx: &mut [f64]) {
        let r1 = 0.04 * x[0];
        let r2 = 1e4 * x[1] * x[2];
        let r3 = 3e7 * x[1] * x[1];
        dx[0] = -r1 + r2;
        dx[1] = r1 - r2 - r3;
        dx[2] = r3;
    }
    fn jacobian(&self, _t: f64, x: &[f64], jac: &mut [f64]) -> bool {
        jac.copy_from_slice(&[
            -0.04,
            1e4 * x[2],
            1e4 * x[1],
            0.04,
            -1e4 * x[2] - 6e7 * x[1],
            -1e4 * x[1],
            0.0,
            6e7 * x[1],
            0.0,
        ]);
        true
    }
}

/// A closed volume charged from a supply `ps` through a turbulent orifice,
/// `dp/dt = k √(ps − p)` with `k = (B/V) Cd a √(2/ρ)` (hydrocyl's `volume`
/// behind an `orifice`: a physics test's `vol.json`): from `p = 0` at time 0
/// the solution is the parabola `p(t) = ps − (√ps − k t/2)²` until it
/// reaches `ps` at `t* = 2√ps / k`, then `ps`. Its third derivative is zero:
/// the case where Bogacki–Shampine 3(2)'s error estimate (`h³ p‴ / 48` to
/// leading order) sees nothing of its step's error. Stiff near `t*`
/// (`∂f/∂p = −k / (2√(ps − p))` grows without bound).
#[derive(Clone, Copy, Debug)]
pub struct OrificeCharge {
    /// Supply pressure `ps` \[Pa\].
    pub supply: f64,
    /// Rate constant `k = (B/V) Cd a √(2/ρ)` \[Pa^½/s\].
    pub k: f64,
}

impl OrificeCharge {
    /// That test's circuit: 100 bar through `a = 1e-7 m²`, `Cd = 0.7`,
    /// `ρ = 870 kg/m³` into `V = 1e-4 m³` of `B = 1 GPa` (`t* ≈ 0.188 s`).
    pub fn hundred_bar() -> Self {
        Self {
            supply: 1e7,
            k: 1e9 / 1e-4 * 0.7 * 1e-7 * (2.0f64 / 870.0).sqrt(),
        }
    }

    /// When the volume reaches the supply pressure from `p = 0` at time 0 \[s\].
    pub fn t_full(&self) -> f64 {
        2.0 * self.supply.sqrt() / self.k
    }

    /// The exact pressure at `t` from `p = 0` at time 0 \[Pa\].
    pub fn exact(&self, t: f64) -> f64 {
        let r = (self.supply.sqrt() - 0.5 * self.k * t).max(0.0);
        self.supply - r * r
    }
}

impl OdeSystem for OrificeCharge {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = self.k * (self.supply - x[0]).max(0.0).sqrt();
    }
    fn jacobian(&self, _t: f64, x: &[f64], jac: &mut [f64]) -> bool {
        let r = (self.supply - x[0]).max(0.0).sqrt();
        jac[0] = if r > 0.0 { -0.5 * self.k / r } else { 0.0 };
        true
    }
}

/// A ball falling under gravity onto a floor at height 0, state `[y, v]`
/// (\[m\], \[m/s\]). Switching function `y`; at a falling crossing the velocity
/// is reversed and scaled by the restitution `e`. The solve stops after
/// `max_bounces` bounces (the bounce times accumulate: Zeno).
#[derive(Clone, Copy, Debug)]
pub struct BouncingBall {
    /// Gravitational acceleration `g` \[m/s²\].
    pub gravity: f64,
    /// Coefficient of restitution `e` (0..1).
    pub restitution: f64,
    /// Bounces handled so far.
    pub bounces: usize,
    /// The solve stops at this bounce.
    pub max_bounces: usize,
}

impl BouncingBall {
    /// A ball with gravity `g` \[m/s²\] and restitution `e`, stopping after `max_bounces`.
    pub fn new(gravity: f64, restitution: f64, max_bounces: usize) -> Self {
        Self {
            gravity,
            restitution,
            bounces: 0,
            max_bounces,
        }
    }

    /// The first `n` bounce times \[s\] for a drop from rest at height `h0` \[m\]
    /// at time 0: `t_1 = sqrt(2 h0 / g)`, `t_{k+1} = t_k + 2 e^k v_1 / g` with
    /// `v_1 = sqrt(2 g h0)`.
    pub fn bounce_times(&self, h0: f64, n: usize) -> Vec<f64> {
        let g = self.gravity;
        let v1 = (2.0 * g * h0).sqrt();
        let mut t = (2.0 * h0 / g).sqrt();
        let mut out = Vec::with_capacity(n);
        let mut v = v1;
        for _ in 0..n {
            out.push(t);
            v *= self.restitution;
            t += 2.0 * v / g;
        }
        out
    }
}

impl OdeSystem for BouncingBall {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = x[1];
        dx[1] = -self.gravity;
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&self, _t: f64, x: &[f64], g: &mut [f64]) {
        g[0] = x[0];
    }
    fn on_event(&mut self, _t: f64, x: &mut [f64], _which: usize, dir: Crossing) -> EventAction {
        if dir == Crossing::Falling {
            x[1] *= -self.restitution;
            self.bounces += 1;
        }
        if self.bounces >= self.max_bounces {
            EventAction::Stop
        } else {
            EventAction::Continue
        }
    }
}
