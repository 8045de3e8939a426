//! The thesis's seal terms as additive terms on **any** friction law: the
//! pressure term `K (p1 − p2)² v` (eq 5.4) and the acceleration term
//! `K H a` (eq 5.12). Wang's law (eq 5.14) has them inside a LuGre law;
//! [`WithSealTerms`] puts them on top of a Coulomb-viscous, Stribeck,
//! Karnopp, Dahl or LuGre law without switching bristle dynamics on, so the
//! measured-data loop can offer `pressure_viscous` and
//! `acceleration_friction` on every rig.
//!
//! `K H a` is linear in the acceleration: as in [`crate::Wang`] it is not
//! part of [`FrictionModel::force`] but reported as
//! [`FrictionModel::acceleration_coefficient`] `c = K H` \[kg\] (added mass).

use hydrocyl_ports::{Energy, Force, Mass, Power};
use serde::{Deserialize, Serialize};

use crate::error::{non_negative, FrictionError};
use crate::model::{FrictionInput, FrictionJacobian, FrictionMode, FrictionModel};

/// The additive seal terms (both 0 = off).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SealTerms {
    /// Seal gain K of `K (p1 − p2)² v` \[m³·s·N⁻¹\], ≥ 0.
    #[serde(default)]
    pub k_pressure: f64,
    /// Acceleration gain H of `K H a` \[N²·s·m⁻⁴\], ≥ 0.
    #[serde(default)]
    pub h_acceleration: f64,
    /// Bound Δp_max of the pressure difference in `K min(|p1 − p2|, Δp_max)² v`
    /// \[Pa\] (module [`crate::seal`]); 0 = unbounded, the thesis's eq 5.4.
    #[serde(default)]
    pub dp_max: f64,
    /// Bound while extending (v > 0) \[Pa\]; 0 = `dp_max`
    /// ([`crate::seal::bound_for`]).
    #[serde(default, skip_serializing_if = "crate::seal::is_unbounded")]
    pub dp_max_extend: f64,
    /// Bound while retracting (v < 0) \[Pa\]; 0 = `dp_max`.
    #[serde(default, skip_serializing_if = "crate::seal::is_unbounded")]
    pub dp_max_retract: f64,
}

impl SealTerms {
    /// `true` when both terms are zero.
    pub fn is_off(&self) -> bool {
        self.k_pressure == 0.0 && self.h_acceleration == 0.0
    }

    /// Checks the parameters (finite, non-negative).
    pub fn validate(&self) -> Result<(), FrictionError> {
        const M: &str = "seal terms";
        non_negative(M, "K (k_pressure)", self.k_pressure)?;
        non_negative(M, "H (h_acceleration)", self.h_acceleration)?;
        non_negative(M, "dp_max", self.dp_max)?;
        non_negative(M, "dp_max_extend", self.dp_max_extend)?;
        non_negative(M, "dp_max_retract", self.dp_max_retract)
    }

    /// The bounded pressure difference and its slope at this input.
    fn seal_dp(&self, input: &FrictionInput) -> (f64, f64) {
        let bound = crate::seal::bound_for(
            input.velocity.si() > 0.0,
            self.dp_max,
            self.dp_max_extend,
            self.dp_max_retract,
        );
        crate::seal::bounded(input.p1.si() - input.p2.si(), bound)
    }

    /// `K min(|p1 − p2|, Δp_max)² v` \[N\].
    fn pressure_force(&self, input: &FrictionInput) -> f64 {
        let (dp, _) = self.seal_dp(input);
        self.k_pressure * dp * dp * input.velocity.si()
    }
}

/// A friction law with the [`SealTerms`] added.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WithSealTerms<M> {
    /// The law the terms are added to.
    pub inner: M,
    /// The terms.
    pub terms: SealTerms,
}

impl<M: FrictionModel> FrictionModel for WithSealTerms<M> {
    fn n_states(&self) -> usize {
        self.inner.n_states()
    }
    fn force(&self, input: &FrictionInput, state: &[f64]) -> Force {
        self.inner.force(input, state) + Force::new(self.terms.pressure_force(input))
    }
    fn acceleration_coefficient(&self, input: &FrictionInput) -> Mass {
        self.inner.acceleration_coefficient(input)
            + Mass::new(self.terms.k_pressure * self.terms.h_acceleration)
    }
    fn acceleration_coefficient_slope(&self, input: &FrictionInput) -> f64 {
        self.inner.acceleration_coefficient_slope(input)
    }
    fn state_derivative(&self, input: &FrictionInput, state: &[f64], dstate: &mut [f64]) {
        self.inner.state_derivative(input, state, dstate)
    }
    fn steady_state(&self, input: &FrictionInput, state: &mut [f64]) {
        self.inner.steady_state(input, state)
    }
    fn steady_force(&self, input: &FrictionInput) -> Force {
        self.inner.steady_force(input) + Force::new(self.terms.pressure_force(input))
    }
    fn state_scales(&self, scales: &mut [f64]) {
        self.inner.state_scales(scales)
    }
    fn validate(&self) -> Result<(), FrictionError> {
        self.inner.validate()?;
        self.terms.validate()
    }
    fn jacobian(&self, input: &FrictionInput, state: &[f64]) -> FrictionJacobian {
        let mut j = self.inner.jacobian(input, state);
        let k = self.terms.k_pressure;
        let (dp, slope) = self.terms.seal_dp(input);
        let v = input.velocity.si();
        j.df_dv += k * dp * dp;
        j.df_dp1 += 2.0 * k * dp * slope * v;
        j.df_dp2 -= 2.0 * k * dp * slope * v;
        j
    }
    fn stored_energy(&self, state: &[f64]) -> Energy {
        self.inner.stored_energy(state)
    }
    fn dissipated_power(&self, input: &FrictionInput, state: &[f64]) -> Power {
        self.inner.dissipated_power(input, state)
            + Power::new(self.terms.pressure_force(input) * input.velocity.si())
    }
    fn n_events(&self) -> usize {
        self.inner.n_events()
    }
    fn events(&self, input: &FrictionInput, drive: Force, state: &[f64], g: &mut [f64]) {
        self.inner.events(input, drive, state, g)
    }
    fn on_event(
        &mut self,
        which: usize,
        input: &FrictionInput,
        drive: Force,
        state: &mut [f64],
    ) -> FrictionMode {
        self.inner.on_event(which, input, drive, state)
    }
    fn initialise_mode(&mut self, input: &FrictionInput, drive: Force) -> FrictionMode {
        self.inner.initialise_mode(input, drive)
    }
    fn mode(&self) -> FrictionMode {
        self.inner.mode()
    }
    fn can_stick(&self) -> bool {
        self.inner.can_stick()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{finite_difference_jacobian, CoulombViscous, FrictionLaw};
    use hydrocyl_ports::{Pressure, Velocity};

    /// The analytic Jacobian against finite differences.
    fn assert_jacobian(m: &impl FrictionModel, input: &FrictionInput) {
        let (a, b) = (
            m.jacobian(input, &[]),
            finite_difference_jacobian(m, input, &[]),
        );
        for (x, y) in [
            (a.df_dv, b.df_dv),
            (a.df_dp1, b.df_dp1),
            (a.df_dp2, b.df_dp2),
        ] {
            assert!((x - y).abs() <= 1e-5 * y.abs().max(1.0), "{x} vs {y}");
        }
    }

    #[test]
    fn the_terms_add_to_any_law_and_their_jacobian_is_right() {
        let inner = FrictionLaw::CoulombViscous(CoulombViscous::leaney_moog());
        let terms = SealTerms {
            k_pressure: 1e-9,
            h_acceleration: 3e9,
            ..SealTerms::default()
        };
        let m = WithSealTerms { inner, terms };
        let input = FrictionInput {
            velocity: Velocity::new(0.05),
            p1: Pressure::new(5e6),
            p2: Pressure::new(2e6),
            ..FrictionInput::default()
        };
        let extra = 1e-9 * 9e12 * 0.05;
        let f = m.force(&input, &[]).si();
        assert!((f - inner.force(&input, &[]).si() - extra).abs() < 1e-9);
        assert!((m.acceleration_coefficient(&input).si() - 3.0).abs() < 1e-12);
        assert_jacobian(&m, &input);
        assert!(SealTerms::default().is_off());
        let bad = SealTerms {
            k_pressure: -1.0,
            ..SealTerms::default()
        };
        assert!(bad.validate().is_err());
        // bounded to 2 MPa: the 3 MPa difference counts as 2 MPa, and the
        // Jacobian follows (no pressure slope beyond the bound)
        let bounded = WithSealTerms {
            inner,
            terms: SealTerms {
                dp_max: 2e6,
                ..terms
            },
        };
        let f = bounded.force(&input, &[]).si() - inner.force(&input, &[]).si();
        assert!((f - 1e-9 * 4e12 * 0.05).abs() < 1e-9, "{f}");
        assert_jacobian(&bounded, &input);
        // per direction: extending takes 1 MPa, retracting falls back to 2 MPa
        let per = WithSealTerms {
            inner,
            terms: SealTerms {
                dp_max: 2e6,
                dp_max_extend: 1e6,
                ..terms
            },
        };
        let f = per.force(&input, &[]).si() - inner.force(&input, &[]).si();
        assert!((f - 1e-9 * 1e12 * 0.05).abs() < 1e-9, "{f}");
        let back = FrictionInput {
            velocity: Velocity::new(-0.05),
            ..input
        };
        let f = per.force(&back, &[]).si() - inner.force(&back, &[]).si();
        assert!((f + 1e-9 * 4e12 * 0.05).abs() < 1e-9, "{f}");
        assert_jacobian(&per, &back);
    }
}
