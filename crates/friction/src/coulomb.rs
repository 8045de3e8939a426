//! Coulomb + viscous friction (thesis Fig 2-33 (a)+(b); the `leaney-moog`
//! preset's law in rigs.md):
//!
//! `F = Fc tanh(v / v_t) + b v`
//!
//! with a tanh of smoothing velocity v_t in place of the discontinuous sign.

use hydrocyl_ports::{Force, Velocity};
use serde::{Deserialize, Serialize};

use crate::error::{non_negative, positive, FrictionError};
use crate::model::{FrictionInput, FrictionJacobian, FrictionModel};

/// Coulomb + viscous friction, `F = Fc tanh(v / v_t) + b v` (the `leaney-moog`
/// preset's law, rigs.md; tanh smoothing instead of a discontinuous sign).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CoulombViscous {
    /// Coulomb level Fc \[N\].
    pub coulomb: Force,
    /// Viscous coefficient b \[N·s·m⁻¹\].
    pub viscous: f64,
    /// Smoothing velocity v_t of the tanh \[m·s⁻¹\].
    pub smoothing_velocity: Velocity,
}

impl CoulombViscous {
    /// The `leaney-moog` preset: Fc = 50 N, b = 500 N s/m, v_t = 1 mm/s.
    pub fn leaney_moog() -> Self {
        Self {
            coulomb: Force::new(50.0),
            viscous: 500.0,
            smoothing_velocity: Velocity::new(1.0e-3),
        }
    }
}

impl CoulombViscous {
    /// The unsmoothed static curve `Fc sgn(v) + b v` \[N\] (its limit
    /// `±Fc` as v → 0± is the break-away level this law can represent).
    pub fn static_curve(&self, v: Velocity) -> Force {
        let v = v.si();
        let s = if v > 0.0 {
            1.0
        } else if v < 0.0 {
            -1.0
        } else {
            0.0
        };
        Force::new(self.coulomb.si() * s + self.viscous * v)
    }
}

impl FrictionModel for CoulombViscous {
    fn force(&self, input: &FrictionInput, _state: &[f64]) -> Force {
        let v = input.velocity.si();
        Force::new(self.coulomb.si() * (v / self.smoothing_velocity.si()).tanh() + self.viscous * v)
    }

    fn validate(&self) -> Result<(), FrictionError> {
        const M: &str = "coulomb-viscous";
        non_negative(M, "Fc (coulomb)", self.coulomb.si())?;
        non_negative(M, "b (viscous)", self.viscous)?;
        positive(M, "v_t (smoothing_velocity)", self.smoothing_velocity.si())
    }

    fn jacobian(&self, input: &FrictionInput, _state: &[f64]) -> FrictionJacobian {
        let vt = self.smoothing_velocity.si();
        let th = (input.velocity.si() / vt).tanh();
        FrictionJacobian {
            df_dv: self.coulomb.si() * (1.0 - th * th) / vt + self.viscous,
            ..FrictionJacobian::default()
        }
    }
}
