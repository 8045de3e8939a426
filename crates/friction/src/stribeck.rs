//! Static Stribeck friction, the steady-state curve of the LuGre family
//! (thesis eq 2.40, with separate extending and retracting sets):
//!
//! `F = sgn(v) [Fc + (Fs − Fc) exp(−|v/vs|^δ)] + σ2 v`
//!
//! As a force law inside an ODE the sign is smoothed, `sgn(v) → tanh(v/v_t)`;
//! [`Stribeck::static_curve`] is the unsmoothed eq 2.40.

use hydrocyl_ports::{Force, Velocity};
use serde::{Deserialize, Serialize};

use crate::curve::StribeckCurve;
use crate::error::{non_negative, positive, FrictionError};
use crate::model::{FrictionInput, FrictionJacobian, FrictionModel};

/// One direction's steady-curve parameters: the Stribeck curve and the viscous
/// coefficient σ2.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SteadySet {
    /// Stribeck curve g(v) (eq 2.36).
    pub curve: StribeckCurve,
    /// Viscous coefficient σ2 \[N·s·m⁻¹\], ≥ 0.
    pub sigma2: f64,
}

impl SteadySet {
    /// Eq 2.40: `sgn(v) g(v) + σ2 v` \[N\] (zero at v = 0, eq 2.38).
    pub fn curve_force(&self, v: f64) -> f64 {
        sgn(v) * self.curve.g(v) + self.sigma2 * v
    }

    pub(crate) fn validate(&self, model: &'static str) -> Result<(), FrictionError> {
        self.curve.validate(model)?;
        non_negative(model, "sigma2", self.sigma2)
    }
}

/// The thesis's sign function (eq 2.38): 0 at 0.
#[inline]
pub(crate) fn sgn(v: f64) -> f64 {
    if v > 0.0 {
        1.0
    } else if v < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// Static Stribeck friction with extending / retracting sets and tanh
/// smoothing of the sign.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Stribeck {
    /// Parameters while extending (v > 0).
    pub extending: SteadySet,
    /// Parameters while retracting (v < 0), magnitudes.
    pub retracting: SteadySet,
    /// Smoothing velocity v_t of `tanh(v/v_t)` \[m·s⁻¹\], > 0.
    pub smoothing_velocity: Velocity,
}

impl Stribeck {
    /// The steady curve of the thesis's original-LuGre comparison set
    /// (Table 5-11: Fc 110 / 80 N, Fs 180 / 188 N, vs 0.01 m/s,
    /// δ 0.1087 / 0.1138, σ2 1000 / 900 N s/m), smoothed over v_t = 0.1 mm/s.
    pub fn table_5_11() -> Self {
        let (e, r) = crate::lugre::table_5_11_sets();
        Self {
            extending: e,
            retracting: r,
            smoothing_velocity: Velocity::new(1e-4),
        }
    }

    /// The set for velocity `v` (extending for v ≥ 0).
    pub fn set(&self, v: f64) -> &SteadySet {
        if v >= 0.0 {
            &self.extending
        } else {
            &self.retracting
        }
    }

    /// The unsmoothed static curve, eq 2.40 \[N\].
    pub fn static_curve(&self, v: Velocity) -> Force {
        Force::new(self.set(v.si()).curve_force(v.si()))
    }
}

impl FrictionModel for Stribeck {
    fn force(&self, input: &FrictionInput, _state: &[f64]) -> Force {
        let v = input.velocity.si();
        let s = self.set(v);
        Force::new((v / self.smoothing_velocity.si()).tanh() * s.curve.g(v) + s.sigma2 * v)
    }

    fn validate(&self) -> Result<(), FrictionError> {
        self.extending.validate("stribeck (extending)")?;
        self.retracting.validate("stribeck (retracting)")?;
        positive(
            "stribeck",
            "v_t (smoothing_velocity)",
            self.smoothing_velocity.si(),
        )
    }

    fn jacobian(&self, input: &FrictionInput, _state: &[f64]) -> FrictionJacobian {
        let v = input.velocity.si();
        let s = self.set(v);
        let vt = self.smoothing_velocity.si();
        let th = (v / vt).tanh();
        // d/dv [th g] = g (1 − th²)/vt + th sgn(v) g'(|v|); th·sgn(v) = |th|.
        let g_term = if v != 0.0 {
            th.abs() * s.curve.v_dg_dv(v) / v.abs()
        } else {
            0.0
        };
        FrictionJacobian {
            df_dv: s.curve.g(v) * (1.0 - th * th) / vt + g_term + s.sigma2,
            ..FrictionJacobian::default()
        }
    }
}
