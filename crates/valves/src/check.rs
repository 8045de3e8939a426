//! Anti-cavitation check valves (thesis section 4.1: "two check valves that
//! connected to the oil tank are introduced into the system to avoid
//! cavitation"), and the parameter error shared by the hybrid drive's valves.
//!
//! ```text
//!   p_in ──▶|── p_out          flow only from p_in to p_out, once
//!                              Δp = p_in − p_out exceeds the cracking pressure
//! ```
//!
//! ## Law
//! With `Δp = p_in − p_out`, cracking pressure `p_c`, opening range `Δp_o` and
//! full-open flow coefficient `K_c`:
//!
//! ```text
//!   x(Δp) = clamp((Δp − p_c) / Δp_o, 0, 1)          poppet opening [-]
//!   Q     = K_c · x(Δp) · √Δp                        [m³·s⁻¹], Q = 0 for Δp ≤ p_c
//! ```
//!
//! The poppet opens linearly over `Δp_o` (a spring-loaded poppet whose lift
//! grows with the pressure above cracking), then acts as a fixed orifice.
//! The law is continuous, with a bounded slope everywhere
//! ([`CheckValve::lipschitz_bound`]), so explicit and implicit solvers can step
//! across it; the only kink is at `Δp = p_c`, which [`CheckValve::crack_margin`]
//! exposes as a switching function so the integrator can end a step exactly
//! there. The thesis gives no data for these valves: the defaults of
//! [`CheckValve::anti_cavitation`] are **assumed** (see there).

use hydrocyl_ports::{Power, Pressure, VolumeFlow};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// A component parameter outside its valid range (shared by the relief,
/// pilot four-way, needle and check valve models).
#[derive(Clone, Debug, Error, PartialEq)]
#[error("{component}: parameter `{name}` = {value} is invalid: {reason}")]
pub struct ParameterError {
    /// The component whose parameter is wrong, e.g. `"relief valve"`.
    pub component: &'static str,
    /// The parameter's name.
    pub name: &'static str,
    /// The offending value (SI).
    pub value: f64,
    /// What it must satisfy.
    pub reason: &'static str,
}

/// Returns an error unless `value` is finite and `> 0`.
pub(crate) fn positive(
    component: &'static str,
    name: &'static str,
    value: f64,
) -> Result<(), ParameterError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ParameterError {
            component,
            name,
            value,
            reason: "must be finite and > 0",
        })
    }
}

/// Returns an error unless `value` is finite and `>= 0`.
pub(crate) fn non_negative(
    component: &'static str,
    name: &'static str,
    value: f64,
) -> Result<(), ParameterError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ParameterError {
            component,
            name,
            value,
            reason: "must be finite and >= 0",
        })
    }
}

/// A spring-loaded poppet check valve with a smooth opening characteristic.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CheckValve {
    /// Cracking pressure `p_c` \[Pa\]: the poppet lifts above it.
    pub cracking: Pressure,
    /// Opening range `Δp_o` \[Pa\]: the poppet is fully open at `p_c + Δp_o`.
    pub opening_range: Pressure,
    /// Full-open flow coefficient `K_c = Cd A √(2/ρ)` \[m³·s⁻¹·Pa^-½\].
    pub k_open: f64,
}

impl CheckValve {
    /// A check valve from its parameters, validated: `cracking ≥ 0`,
    /// `opening_range > 0`, `k_open > 0`, all finite.
    pub fn new(
        cracking: Pressure,
        opening_range: Pressure,
        k_open: f64,
    ) -> Result<Self, ParameterError> {
        non_negative("check valve", "cracking", cracking.si())?;
        positive("check valve", "opening_range", opening_range.si())?;
        positive("check valve", "k_open", k_open)?;
        Ok(Self {
            cracking,
            opening_range,
            k_open,
        })
    }

    /// The `wang-hybrid` anti-cavitation check valve, **assumed** (the thesis
    /// gives no data): cracking 0.35 bar (5 psi, a usual suction check
    /// spring), fully open 0.5 bar above cracking, and a full-open coefficient
    /// of a 30 mm² port with Cd 0.65 in a 900 kg/m³ oil
    /// (`K_c = 0.65 · 30e-6 · √(2/900) = 9.19e-7` m³·s⁻¹·Pa^-½, about 16 L/min
    /// at 0.85 bar — the pump's full flow).
    pub fn anti_cavitation() -> Self {
        Self {
            cracking: Pressure::from_bar(0.35),
            opening_range: Pressure::from_bar(0.5),
            k_open: 0.65 * 30.0e-6 * (2.0f64 / 900.0).sqrt(),
        }
    }

    /// Poppet opening `x ∈ [0, 1]` at pressure difference `dp = p_in − p_out` \[Pa\].
    #[inline]
    pub fn opening(&self, dp: Pressure) -> f64 {
        ((dp - self.cracking).si() / self.opening_range.si()).clamp(0.0, 1.0)
    }

    /// Flow from `p_in` to `p_out` (never negative).
    #[inline]
    pub fn flow(&self, p_in: Pressure, p_out: Pressure) -> VolumeFlow {
        let dp = p_in - p_out;
        let x = self.opening(dp);
        if x <= 0.0 {
            VolumeFlow::ZERO
        } else {
            VolumeFlow::new(self.k_open * x * dp.si().sqrt())
        }
    }

    /// `∂Q/∂p_in` \[m³·s⁻¹·Pa⁻¹\] (`∂Q/∂p_out` is its negative).
    #[inline]
    pub fn conductance(&self, p_in: Pressure, p_out: Pressure) -> f64 {
        let dp = (p_in - p_out).si();
        let x = self.opening(Pressure::new(dp));
        if x <= 0.0 {
            return 0.0;
        }
        let s = dp.sqrt();
        let dx = if x < 1.0 {
            1.0 / self.opening_range.si()
        } else {
            0.0
        };
        self.k_open * (dx * s + x * 0.5 / s)
    }

    /// An upper bound of `|∂Q/∂Δp|` over all `Δp`: the law's Lipschitz constant
    /// \[m³·s⁻¹·Pa⁻¹\].
    pub fn lipschitz_bound(&self) -> f64 {
        let pc = self.cracking.si();
        let po = self.opening_range.si();
        // on the ramp: K (√Δp/Δp_o + x/(2√Δp)) with x/(2√Δp) = (Δp−p_c)/(2 Δp_o √Δp) ≤ √Δp/(2Δp_o);
        // beyond it K/(2√(p_c+Δp_o)) ≤ K √(p_c+Δp_o)/(2 Δp_o).
        self.k_open * 1.5 * (pc + po).sqrt() / po
    }

    /// Switching function for the integrator: `Δp − p_c`, rising through zero
    /// when the valve cracks open, falling when it closes \[Pa\].
    #[inline]
    pub fn crack_margin(&self, p_in: Pressure, p_out: Pressure) -> f64 {
        (p_in - p_out - self.cracking).si()
    }

    /// Hydraulic power dissipated in the valve, `Q Δp` (never negative).
    #[inline]
    pub fn power_dissipated(&self, p_in: Pressure, p_out: Pressure) -> Power {
        self.flow(p_in, p_out) * (p_in - p_out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn closed_below_cracking_and_for_reverse_pressure() {
        let c = CheckValve::anti_cavitation();
        assert_eq!(
            c.flow(Pressure::from_bar(0.3), Pressure::ZERO),
            VolumeFlow::ZERO
        );
        assert_eq!(
            c.flow(Pressure::ZERO, Pressure::from_bar(50.0)),
            VolumeFlow::ZERO
        );
        assert!(c.flow(Pressure::from_bar(0.4), Pressure::ZERO).si() > 0.0);
    }

    #[test]
    fn fully_open_is_an_orifice() {
        let c = CheckValve::anti_cavitation();
        let dp = Pressure::from_bar(2.0);
        let q = c.flow(dp, Pressure::ZERO).si();
        assert!((q - c.k_open * dp.si().sqrt()).abs() < 1e-18);
        // about the pump's full flow (16.4 L/min) near full opening
        let q_full = c.flow(Pressure::from_bar(0.85), Pressure::ZERO);
        assert!(
            (q_full.l_per_min() - 16.0).abs() < 1.0,
            "{}",
            q_full.l_per_min()
        );
    }

    #[test]
    fn rejects_bad_parameters() {
        let e = CheckValve::new(Pressure::new(-1.0), Pressure::from_bar(1.0), 1e-6).unwrap_err();
        assert_eq!(e.name, "cracking");
        assert!(CheckValve::new(Pressure::ZERO, Pressure::ZERO, 1e-6).is_err());
        assert!(CheckValve::new(Pressure::ZERO, Pressure::from_bar(1.0), f64::NAN).is_err());
        assert!(CheckValve::new(Pressure::ZERO, Pressure::from_bar(1.0), 1e-6).is_ok());
    }

    proptest! {
        #[test]
        fn lipschitz_and_monotone(a in -2.0e5f64..5.0e5, b in -2.0e5f64..5.0e5) {
            let c = CheckValve::anti_cavitation();
            let qa = c.flow(Pressure::new(a), Pressure::ZERO).si();
            let qb = c.flow(Pressure::new(b), Pressure::ZERO).si();
            prop_assert!(qa >= 0.0 && qb >= 0.0);
            prop_assert!((qa - qb).abs() <= c.lipschitz_bound() * (a - b).abs() * (1.0 + 1e-9) + 1e-30);
            if a < b { prop_assert!(qa <= qb); }
        }

        #[test]
        fn conductance_matches_finite_difference(dp in 0.36e5f64..3.0e5) {
            let c = CheckValve::anti_cavitation();
            let h = 1.0;
            prop_assume!((dp - 0.35e5).abs() > 2.0 && (dp - 0.85e5).abs() > 2.0);
            let fd = (c.flow(Pressure::new(dp + h), Pressure::ZERO).si()
                - c.flow(Pressure::new(dp - h), Pressure::ZERO).si()) / (2.0 * h);
            let an = c.conductance(Pressure::new(dp), Pressure::ZERO);
            prop_assert!((fd - an).abs() <= 1e-6 * an.abs() + 1e-20);
        }

        #[test]
        fn dissipates_power(dp in -1.0e6f64..1.0e6) {
            let c = CheckValve::anti_cavitation();
            prop_assert!(c.power_dissipated(Pressure::new(dp), Pressure::ZERO).si() >= 0.0);
        }
    }

    #[test]
    fn crack_margin_changes_sign_at_cracking() {
        let c = CheckValve::anti_cavitation();
        assert!(c.crack_margin(Pressure::from_bar(0.34), Pressure::ZERO) < 0.0);
        assert!(c.crack_margin(Pressure::from_bar(0.36), Pressure::ZERO) > 0.0);
        // referred to the outlet
        assert!(c.crack_margin(Pressure::from_bar(10.36), Pressure::from_bar(10.0)) > 0.0);
    }
}
