//! The LuGre model in its standard form (thesis eqs 2.34–2.36, 5.1):
//!
//! ```text
//! dz/dt = v − σ0 |v| z / g(v)                     (2.34)
//! F     = σ0 z + σ1 dz/dt + σ2 v                  (2.35)
//! g(v)  = Fc + (Fs − Fc) exp(−|v/vs|^δ)           (2.36)
//! ```
//!
//! z is the mean bristle deflection \[m\]. At constant velocity z settles to
//! `sgn(v) g(v)/σ0` (eq 2.37) and the force to the static curve eq 2.40.
//!
//! **Disagreement with the thesis.** The thesis's "original LuGre" of section
//! 5.3 and eq 5.13 writes `dz/dt = v − z |v| / g(v)`, without σ0. That is not
//! dimensionally consistent (z/g has units m/N) and is not the model of eq
//! 2.34 it cites; hydrocyl implements the standard form above for every
//! LuGre-type model, including the Table 5-11 comparison set.
//!
//! Table 5-11 prints the retracting exponent as "−1138"; that is a typo for
//! 0.1138 (Table 5-8, same rig, same curve), which hydrocyl uses. σ0 and σ1
//! are shared by both directions (they are equal in Tables 5-8 and 5-11, and a
//! σ0 that jumped at v = 0 would make the force σ0 z jump); the Stribeck curve
//! and σ2 have extending and retracting sets.

use hydrocyl_ports::{Energy, Force, Power};
use serde::{Deserialize, Serialize};

use crate::curve::StribeckCurve;
use crate::error::{non_negative, positive, FrictionError};
use crate::model::{FrictionInput, FrictionJacobian, FrictionModel};
use crate::stribeck::{sgn, SteadySet};

/// LuGre friction with directional Stribeck curves and viscous terms.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LuGre {
    /// Bristle stiffness σ0 \[N·m⁻¹\], > 0.
    pub sigma0: f64,
    /// Bristle (micro-)damping σ1 \[N·s·m⁻¹\], ≥ 0.
    pub sigma1: f64,
    /// Curve and σ2 while extending (v > 0).
    pub extending: SteadySet,
    /// Curve and σ2 while retracting (v < 0), magnitudes.
    pub retracting: SteadySet,
}

/// Table 5-11's extending and retracting steady sets.
pub(crate) fn table_5_11_sets() -> (SteadySet, SteadySet) {
    let curve = |fc: f64, fs: f64, delta: f64| StribeckCurve {
        coulomb: Force::new(fc),
        stiction: Force::new(fs),
        stribeck_velocity: hydrocyl_ports::Velocity::new(0.01),
        stribeck_exponent: delta,
    };
    (
        SteadySet {
            curve: curve(110.0, 180.0, 0.1087),
            sigma2: 1000.0,
        },
        SteadySet {
            curve: curve(80.0, 188.0, 0.1138),
            sigma2: 900.0,
        },
    )
}

/// The one-state bristle law shared by LuGre, Dahl and Wang's model:
/// `dz/dt = v − σ0 |v| z / g`, with `g` and `|v| dg/d|v|` given.
#[inline]
pub(crate) fn bristle_rate(sigma0: f64, v: f64, z: f64, g: f64) -> f64 {
    v - sigma0 * v.abs() * z / g
}

/// `(∂ż/∂z, ∂ż/∂v)` of [`bristle_rate`], with `vg = |v| dg/d|v|`.
#[inline]
pub(crate) fn bristle_partials(sigma0: f64, v: f64, z: f64, g: f64, vg: f64) -> (f64, f64) {
    let dz = -sigma0 * v.abs() / g;
    // d/dv (|v|/g(|v|)) = sgn(v) (1/g − |v| g'/g²)
    let dv = 1.0 - sigma0 * z * sgn(v) * (1.0 / g - vg / (g * g));
    (dz, dv)
}

impl LuGre {
    /// A symmetric LuGre model (same set both ways).
    pub fn symmetric(sigma0: f64, sigma1: f64, set: SteadySet) -> Result<Self, FrictionError> {
        let m = Self {
            sigma0,
            sigma1,
            extending: set,
            retracting: set,
        };
        m.validate()?;
        Ok(m)
    }

    /// The thesis's original-LuGre comparison set, Table 5-11: σ0 = 3e7 N/m,
    /// σ1 = 0.1 N s/m, Fc 110 / 80 N, Fs 180 / 188 N, vs 0.01 m/s,
    /// δ 0.1087 / 0.1138, σ2 1000 / 900 N s/m (extending / retracting).
    pub fn table_5_11() -> Self {
        let (e, r) = table_5_11_sets();
        Self {
            sigma0: 3.0e7,
            sigma1: 0.1,
            extending: e,
            retracting: r,
        }
    }

    /// The set for velocity `v` (extending for v ≥ 0; at v = 0 every
    /// directional term is zero).
    pub fn set(&self, v: f64) -> &SteadySet {
        if v >= 0.0 {
            &self.extending
        } else {
            &self.retracting
        }
    }

    /// The static curve, eq 2.40 \[N\].
    pub fn static_curve(&self, v: f64) -> f64 {
        self.set(v).curve_force(v)
    }
}

impl FrictionModel for LuGre {
    fn n_states(&self) -> usize {
        1
    }

    fn force(&self, input: &FrictionInput, state: &[f64]) -> Force {
        let v = input.velocity.si();
        let s = self.set(v);
        let z = state[0];
        let zdot = bristle_rate(self.sigma0, v, z, s.curve.g(v));
        Force::new(self.sigma0 * z + self.sigma1 * zdot + s.sigma2 * v)
    }

    fn state_derivative(&self, input: &FrictionInput, state: &[f64], dstate: &mut [f64]) {
        let v = input.velocity.si();
        dstate[0] = bristle_rate(self.sigma0, v, state[0], self.set(v).curve.g(v));
    }

    fn steady_state(&self, input: &FrictionInput, state: &mut [f64]) {
        let v = input.velocity.si();
        state[0] = sgn(v) * self.set(v).curve.g(v) / self.sigma0;
    }

    fn validate(&self) -> Result<(), FrictionError> {
        positive("lugre", "sigma0", self.sigma0)?;
        non_negative("lugre", "sigma1", self.sigma1)?;
        self.extending.validate("lugre (extending)")?;
        self.retracting.validate("lugre (retracting)")
    }

    fn jacobian(&self, input: &FrictionInput, state: &[f64]) -> FrictionJacobian {
        let v = input.velocity.si();
        let s = self.set(v);
        let (dz, dv) = bristle_partials(self.sigma0, v, state[0], s.curve.g(v), s.curve.v_dg_dv(v));
        FrictionJacobian {
            dzdot_dz: dz,
            dzdot_dv: dv,
            df_dz: self.sigma0 + self.sigma1 * dz,
            df_dv: self.sigma1 * dv + s.sigma2,
            df_dp1: 0.0,
            df_dp2: 0.0,
        }
    }

    /// The largest steady deflection, max(Fs)/σ0 \[m\].
    fn state_scales(&self, scales: &mut [f64]) {
        scales[0] = self
            .extending
            .curve
            .stiction
            .si()
            .max(self.retracting.curve.stiction.si())
            / self.sigma0;
    }

    fn stored_energy(&self, state: &[f64]) -> Energy {
        Energy::new(0.5 * self.sigma0 * state[0] * state[0])
    }

    fn dissipated_power(&self, input: &FrictionInput, state: &[f64]) -> Power {
        let mut zdot = [0.0];
        self.state_derivative(input, state, &mut zdot);
        Power::new(
            self.force(input, state).si() * input.velocity.si() - self.sigma0 * state[0] * zdot[0],
        )
    }
}
