//! The Dahl model (thesis section 2.4.2.2, refs [70], [71]) with exponent 1
//! and an optional viscous term:
//!
//! ```text
//! dz/dt = v − σ0 |v| z / Fc
//! F     = σ0 z + σ2 v
//! ```
//!
//! It is LuGre (eq 2.34) with g(v) ≡ Fc and σ1 = 0: pre-sliding stiffness σ0
//! and a smooth approach to Coulomb friction, but no stiction peak and no
//! Stribeck effect (as the thesis says of it). Its static curve is
//! `Fc sgn(v) + σ2 v`.

use hydrocyl_ports::{Energy, Force, Power};
use serde::{Deserialize, Serialize};

use crate::error::{non_negative, positive, FrictionError};
use crate::lugre::{bristle_partials, bristle_rate};
use crate::model::{FrictionInput, FrictionJacobian, FrictionModel};
use crate::stribeck::sgn;

/// Dahl friction.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Dahl {
    /// Coulomb level Fc \[N\], > 0.
    pub coulomb: Force,
    /// Rest stiffness σ0 \[N·m⁻¹\], > 0.
    pub sigma0: f64,
    /// Viscous coefficient σ2 \[N·s·m⁻¹\], ≥ 0.
    pub sigma2: f64,
}

impl Dahl {
    /// A validated Dahl model from Fc \[N\], σ0 \[N/m\], σ2 \[N s/m\].
    pub fn new(fc: f64, sigma0: f64, sigma2: f64) -> Result<Self, FrictionError> {
        let m = Self {
            coulomb: Force::new(fc),
            sigma0,
            sigma2,
        };
        m.validate()?;
        Ok(m)
    }

    /// The static curve `Fc sgn(v) + σ2 v` \[N\].
    pub fn static_curve(&self, v: f64) -> f64 {
        sgn(v) * self.coulomb.si() + self.sigma2 * v
    }
}

impl FrictionModel for Dahl {
    fn n_states(&self) -> usize {
        1
    }

    fn force(&self, input: &FrictionInput, state: &[f64]) -> Force {
        Force::new(self.sigma0 * state[0] + self.sigma2 * input.velocity.si())
    }

    fn state_derivative(&self, input: &FrictionInput, state: &[f64], dstate: &mut [f64]) {
        dstate[0] = bristle_rate(
            self.sigma0,
            input.velocity.si(),
            state[0],
            self.coulomb.si(),
        );
    }

    fn steady_state(&self, input: &FrictionInput, state: &mut [f64]) {
        state[0] = sgn(input.velocity.si()) * self.coulomb.si() / self.sigma0;
    }

    fn validate(&self) -> Result<(), FrictionError> {
        positive("dahl", "Fc (coulomb)", self.coulomb.si())?;
        positive("dahl", "sigma0", self.sigma0)?;
        non_negative("dahl", "sigma2", self.sigma2)
    }

    fn jacobian(&self, input: &FrictionInput, state: &[f64]) -> FrictionJacobian {
        let v = input.velocity.si();
        let (dz, dv) = bristle_partials(self.sigma0, v, state[0], self.coulomb.si(), 0.0);
        FrictionJacobian {
            dzdot_dz: dz,
            dzdot_dv: dv,
            df_dz: self.sigma0,
            df_dv: self.sigma2,
            df_dp1: 0.0,
            df_dp2: 0.0,
        }
    }

    /// The largest steady deflection, max(Fs)/σ0 \[m\].
    fn state_scales(&self, scales: &mut [f64]) {
        scales[0] = self.coulomb.si() / self.sigma0;
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
