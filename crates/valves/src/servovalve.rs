//! The servovalve: spool dynamics and the four-way metering of a symmetric
//! ported, underlapped spool (the Moog 76-102 of the `leaney-moog` rig).
//!
//! ```text
//!   command u [-] ─▶ [ spool dynamics ] ─▶ x_s [m] ─▶ [ metering ]
//!                     eq 2.3/3.1 (1st)                 eq 3.2 areas     P ──▶ A (Q_A)
//!                     eq 2.2     (2nd)                 eqs 2.8/2.9      B ──▶ T
//!                     saturation ±x_max                                 (and A ──▶ T, P ──▶ B in the underlap)
//! ```
//!
//! * **Spool dynamics** ([`SpoolDynamics`]): the demand is `x_ref = u · x_max`
//!   (`u` normalised to \[-1, 1\]); first order `τ ẋ_s = x_ref − x_s`
//!   (eqs 2.3, 3.1) or second order `ẍ_s = ω²(x_ref − x_s) − 2ζω ẋ_s`
//!   (eq 2.2). **Saturation** at the stroke `±x_max` is applied to the demand
//!   *and* to the output: for the first-order lag the state then never leaves
//!   the stroke (it is a convex average of in-stroke demands); the second-order
//!   spool can overshoot, and its output is clipped like Simulink's saturation
//!   block after the transfer function (Fig 3-4).
//! * **Port areas with underlap** ([`Metering::areas`], eq 3.2):
//!   `A_v1 = w max(0, u0 + x_s)`, `A_v2 = w max(0, u0 − x_s)` with the area
//!   gradient `w = π D` of fully annular ports.
//! * **Symmetric-ported flows** ([`Metering::flows`], eqs 2.8, 2.9):
//!   `Q_A = Cd√(2/ρ) [A_v1 √(p_P − p_A) − A_v2 √(p_A − p_T)]` into port A,
//!   `Q_B = Cd√(2/ρ) [A_v1 √(p_B − p_T) − A_v2 √(p_P − p_B)]` out of port B,
//!   each square root signed and regularised through
//!   [`Orifice`] (C¹, Lipschitz, error bounded by
//!   `0.2011 Cd A √(2Δp_t/ρ)` and vanishing as `√Δp_t`).
//!
//! Two effects of the measured-data catalog are parameters here, off by
//! default: `valve_null_bias` ([`Metering::null_bias`], a spool offset added
//! to `x_s`) and `flow_gain_error` ([`Metering::flow_gain`], a scale on `w`).

use crate::orifice::Orifice;
use hydrocyl_ports::{Area, Density, Position, Pressure, VolumeFlow};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// A servovalve parameter out of range; names the parameter and its value.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum ServovalveError {
    /// A parameter that must be positive and finite is not.
    #[error("servovalve parameter `{name}` must be positive and finite, got {value}")]
    NotPositive {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A parameter that must be finite (may be zero or negative) is not.
    #[error("servovalve parameter `{name}` must be finite, got {value}")]
    NotFinite {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
}

fn positive(name: &'static str, value: f64) -> Result<(), ServovalveError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ServovalveError::NotPositive { name, value })
    }
}

fn finite(name: &'static str, value: f64) -> Result<(), ServovalveError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ServovalveError::NotFinite { name, value })
    }
}

/// The spool's dynamics from demand to position.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "order", rename_all = "kebab-case", deny_unknown_fields)]
pub enum SpoolDynamics {
    /// First-order lag `τ ẋ_s = x_ref − x_s` (eqs 2.3, 3.1). One state: `x_s` \[m\].
    First {
        /// Time constant τ_s \[s\].
        time_constant_s: f64,
    },
    /// Second-order `ẍ_s = ω²(x_ref − x_s) − 2ζω ẋ_s` (eq 2.2). Two states:
    /// `x_s` \[m\], `ẋ_s` \[m·s⁻¹\].
    Second {
        /// Natural frequency ω_n \[rad·s⁻¹\].
        natural_frequency_rad_per_s: f64,
        /// Damping ratio ζ \[-\].
        damping_ratio: f64,
    },
}

impl SpoolDynamics {
    /// The `leaney-moog` preset: first order, τ_s = 4 ms (eq 3.1).
    pub const LEANEY_MOOG: Self = Self::First {
        time_constant_s: 0.004,
    };

    /// Number of states (1 or 2).
    pub fn n_states(&self) -> usize {
        match self {
            Self::First { .. } => 1,
            Self::Second { .. } => 2,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), ServovalveError> {
        match *self {
            Self::First { time_constant_s } => positive("time_constant_s", time_constant_s),
            Self::Second {
                natural_frequency_rad_per_s,
                damping_ratio,
            } => {
                positive("natural_frequency_rad_per_s", natural_frequency_rad_per_s)?;
                positive("damping_ratio", damping_ratio)
            }
        }
    }

    /// State derivatives for the (already saturated) demand `x_ref` \[m\].
    #[inline]
    pub fn derivatives(&self, x_ref: f64, state: &[f64], dstate: &mut [f64]) {
        match *self {
            Self::First { time_constant_s } => {
                dstate[0] = (x_ref - state[0]) / time_constant_s;
            }
            Self::Second {
                natural_frequency_rad_per_s: w,
                damping_ratio: z,
            } => {
                dstate[0] = state[1];
                dstate[1] = w * w * (x_ref - state[0]) - 2.0 * z * w * state[1];
            }
        }
    }

    /// The state at rest at spool position `xs` \[m\].
    pub fn rest_state(&self, xs: f64, state: &mut [f64]) {
        state[0] = xs;
        if state.len() > 1 {
            state[1] = 0.0;
        }
    }
}

/// A servovalve spool: stroke (saturation), demand normalisation and dynamics.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Spool {
    /// Spool stroke x_max (saturation at ±x_max); the demand is `u · x_max` \[m\].
    pub stroke: Position,
    /// Dynamics from demand to position.
    pub dynamics: SpoolDynamics,
}

impl Spool {
    /// The `leaney-moog` spool: ±0.375 mm, first order τ = 4 ms.
    pub fn leaney_moog() -> Self {
        Self {
            stroke: Position::new(0.375e-3),
            dynamics: SpoolDynamics::LEANEY_MOOG,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), ServovalveError> {
        positive("stroke", self.stroke.si())?;
        self.dynamics.validate()
    }

    /// The saturated demand `clamp(u · x_max, ±x_max)` for a normalised command `u` \[m\].
    #[inline]
    pub fn demand(&self, u: f64) -> f64 {
        let xm = self.stroke.si();
        (u * xm).clamp(-xm, xm)
    }

    /// The saturated spool position from the dynamic state \[m\].
    #[inline]
    pub fn position(&self, state: &[f64]) -> f64 {
        let xm = self.stroke.si();
        state[0].clamp(-xm, xm)
    }
}

/// Port areas of the four-way spool (eq 3.2).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PortAreas {
    /// A_v1: metering edges P→A and B→T \[m²\].
    pub av1: Area,
    /// A_v2: metering edges A→T and P→B \[m²\].
    pub av2: Area,
}

/// Flows of the four-way valve (eqs 2.8, 2.9 and the supply/return flows).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeteringFlows {
    /// Q_A = Q_P1 − Q_1T: flow **into** service port A (chamber 1) \[m³·s⁻¹\].
    pub qa: VolumeFlow,
    /// Q_B = Q_2T − Q_P2: flow **out of** service port B (chamber 2) \[m³·s⁻¹\].
    pub qb: VolumeFlow,
    /// Q_P = Q_P1 + Q_P2: flow drawn from the supply port P \[m³·s⁻¹\].
    pub qp: VolumeFlow,
    /// Q_T = Q_1T + Q_2T: flow returned to the tank port T \[m³·s⁻¹\].
    pub qt: VolumeFlow,
    /// Power dissipated at the four metering edges, Σ Δp Q \[W\].
    pub dissipated: f64,
}

/// The metering geometry of a symmetric-ported four-way spool valve with
/// (equivalent) underlap.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Metering {
    /// Equivalent underlap u0 (each edge open by u0 at null) \[m\].
    pub underlap: Position,
    /// Spool diameter D; area gradient w = π D (fully annular ports) \[m\].
    pub spool_diameter: Position,
    /// The orifice law of every metering edge (Cd, ρ, regularisation).
    pub orifice: Orifice,
    /// Spool null bias x_b added to the spool position \[m\] (catalog `valve_null_bias`).
    pub null_bias: Position,
    /// Scale k_w on the area gradient \[-\] (catalog `flow_gain_error`; 1 = nominal).
    pub flow_gain: f64,
}

impl Metering {
    /// The `leaney-moog` valve: u0 = 0.0045 mm, D = 7.938 mm, Cd = 0.625, ρ = 870 kg/m³.
    pub fn leaney_moog() -> Self {
        Self {
            underlap: Position::new(0.0045e-3),
            spool_diameter: Position::new(7.938e-3),
            orifice: Orifice::new(0.625, Density::new(870.0)),
            null_bias: Position::ZERO,
            flow_gain: 1.0,
        }
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), ServovalveError> {
        finite("underlap", self.underlap.si())?;
        if self.underlap.si() < 0.0 {
            return Err(ServovalveError::NotPositive {
                name: "underlap",
                value: self.underlap.si(),
            });
        }
        positive("spool_diameter", self.spool_diameter.si())?;
        positive("discharge_coefficient", self.orifice.cd)?;
        positive("density", self.orifice.density.si())?;
        positive("regularisation", self.orifice.dp_transition.si())?;
        finite("null_bias", self.null_bias.si())?;
        positive("flow_gain", self.flow_gain)
    }

    /// Area gradient `w = k_w π D` \[m\].
    #[inline]
    pub fn area_gradient(&self) -> f64 {
        self.flow_gain * std::f64::consts::PI * self.spool_diameter.si()
    }

    /// Port areas at spool position `xs` (eq 3.2; the null bias is added here).
    #[inline]
    pub fn areas(&self, xs: Position) -> PortAreas {
        let w = self.area_gradient();
        let x = xs.si() + self.null_bias.si();
        let u0 = self.underlap.si();
        PortAreas {
            av1: Area::new(w * (u0 + x).max(0.0)),
            av2: Area::new(w * (u0 - x).max(0.0)),
        }
    }

    /// All flows at spool position `xs` with supply `pp`, tank `pt` and
    /// service pressures `pa` (chamber 1), `pb` (chamber 2) (eqs 2.8, 2.9).
    #[inline]
    pub fn flows(
        &self,
        xs: Position,
        pp: Pressure,
        pt: Pressure,
        pa: Pressure,
        pb: Pressure,
    ) -> MeteringFlows {
        let a = self.areas(xs);
        let o = &self.orifice;
        let q_p1 = o.flow(a.av1, pp, pa);
        let q_1t = o.flow(a.av2, pa, pt);
        let q_2t = o.flow(a.av1, pb, pt);
        let q_p2 = o.flow(a.av2, pp, pb);
        let dissipated = (pp - pa) * q_p1 + (pa - pt) * q_1t + (pb - pt) * q_2t + (pp - pb) * q_p2;
        MeteringFlows {
            qa: q_p1 - q_1t,
            qb: q_2t - q_p2,
            qp: q_p1 + q_p2,
            qt: q_1t + q_2t,
            dissipated: dissipated.si(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn valve() -> Metering {
        Metering::leaney_moog()
    }

    #[test]
    fn areas_follow_eq_3_2() {
        let v = valve();
        let w = std::f64::consts::PI * 7.938e-3;
        let null = v.areas(Position::ZERO);
        assert!((null.av1.si() - w * 4.5e-6).abs() < 1e-18);
        assert_eq!(null.av1, null.av2);
        let ext = v.areas(Position::new(0.1e-3));
        assert_eq!(ext.av2.si(), 0.0);
        assert!((ext.av1.si() - w * 0.1045e-3).abs() < 1e-15);
        let ret = v.areas(Position::new(-0.1e-3));
        assert_eq!(ret.av1.si(), 0.0);
    }

    #[test]
    fn null_flows_balance_at_half_supply() {
        // at null with equal areas, Q_A = 0 exactly where p_A = Ps/2
        let v = valve();
        let ps = Pressure::from_bar(70.0);
        let f = v.flows(Position::ZERO, ps, Pressure::ZERO, ps * 0.5, ps * 0.5);
        assert!(f.qa.si().abs() < 1e-18 && f.qb.si().abs() < 1e-18);
        // leakage flow through the underlap: P→A→T and P→B→T
        assert!(f.qp.si() > 0.0);
        assert!((f.qp.si() - f.qt.si()).abs() < 1e-18);
    }

    #[test]
    fn extending_flow_matches_eq_2_8() {
        let v = valve();
        let ps = 7.0e6;
        let (p1, p2) = (3.0e6, 1.0e6);
        let xs = 0.2e-3;
        let f = v.flows(
            Position::new(xs),
            Pressure::new(ps),
            Pressure::ZERO,
            Pressure::new(p1),
            Pressure::new(p2),
        );
        let c = 0.625 * (2.0f64 / 870.0).sqrt();
        let av1 = std::f64::consts::PI * 7.938e-3 * (4.5e-6 + xs);
        assert!((f.qa.si() - c * av1 * (ps - p1).sqrt()).abs() < 1e-12);
        assert!((f.qb.si() - c * av1 * p2.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn first_order_spool_is_a_lag() {
        let s = Spool::leaney_moog();
        let mut d = [0.0];
        s.dynamics.derivatives(s.demand(1.0), &[0.0], &mut d);
        assert!((d[0] - 0.375e-3 / 0.004).abs() < 1e-12);
        // demand saturates
        assert_eq!(s.demand(3.0), 0.375e-3);
        assert_eq!(s.position(&[1.0]), 0.375e-3);
    }

    #[test]
    fn second_order_spool_is_at_rest_at_its_demand() {
        let d2 = SpoolDynamics::Second {
            natural_frequency_rad_per_s: 350.0,
            damping_ratio: 0.7,
        };
        let mut st = [0.0, 0.0];
        d2.rest_state(1e-4, &mut st);
        let mut d = [1.0, 1.0];
        d2.derivatives(1e-4, &st, &mut d);
        assert_eq!(d, [0.0, 0.0]);
    }

    #[test]
    fn bad_parameters_are_named() {
        let mut m = valve();
        m.spool_diameter = Position::new(-1.0);
        let e = m.validate().unwrap_err();
        assert!(e.to_string().contains("spool_diameter"));
        let d = SpoolDynamics::First {
            time_constant_s: f64::NAN,
        };
        assert!(d
            .validate()
            .unwrap_err()
            .to_string()
            .contains("time_constant_s"));
    }

    proptest! {
        /// Power conservation at the valve: P_in at P − P_out at T and at the
        /// service ports equals the dissipation at the metering edges.
        #[test]
        fn valve_power_balances(xs in -0.4e-3f64..0.4e-3, pa in -1e5f64..8e6, pb in -1e5f64..8e6) {
            let v = valve();
            let ps = Pressure::new(7.0e6);
            let f = v.flows(Position::new(xs), ps, Pressure::ZERO, Pressure::new(pa), Pressure::new(pb));
            let p_in = ps.si() * f.qp.si() + pb * f.qb.si();
            let p_out = pa * f.qa.si();
            prop_assert!((p_in - p_out - f.dissipated).abs() <= 1e-9 * p_in.abs().max(1.0));
            // mass balance of the valve body
            prop_assert!((f.qp.si() + f.qb.si() - f.qa.si() - f.qt.si()).abs() < 1e-15);
        }

        /// Flow into A decreases as p_A rises (the valve is a resistance).
        #[test]
        fn flow_is_monotone_in_load_pressure(xs in -0.4e-3f64..0.4e-3, pa in 0.0f64..7e6, dp in 1.0f64..1e5) {
            let v = valve();
            let ps = Pressure::new(7.0e6);
            let q = |p: f64| v.flows(Position::new(xs), ps, Pressure::ZERO, Pressure::new(p), Pressure::ZERO).qa.si();
            prop_assert!(q(pa + dp) <= q(pa));
        }
    }
}
