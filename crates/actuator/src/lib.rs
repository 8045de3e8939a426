//! # hydrocyl-actuator — the asymmetric (single-rod) cylinder
//!
//! Two ways to write the hydraulics of a single-rod cylinder (thesis §2.3.1.3,
//! chapter 3):
//!
//! * [`Cylinder`] — the **fundamental** two-chamber form (eqs 2.10–2.15, Fig 3-24):
//!   each chamber integrates its net inflow into a pressure with the exact mass
//!   balance `dp_i/dt = B/V_i (ΣQ_i − dV_i/dt)`, chamber volumes of vt.m
//!   `V1 = A1 (l1 + x)`, `V2 = A2 (l2 − x)`, optional internal leakage
//!   `Cl (p1 − p2)` and external leakage `Ce_i p_i`, and the piston force
//!   `p1 A1 − p2 A2` (eq 2.27).
//! * [`generalised`] — Leaney's **generalised one-pressure** form
//!   (eqs 2.16–2.26, 3.3): one effective load pressure `P_LE` with
//!   `dP_LE/dt = 4B/V_TE (Q_LE − Q_DE − Q_KE)`, the chamber pressures recovered
//!   from `P_LE` and the X factor (eqs 2.21, 2.22), X obtained numerically or
//!   analytically ([`generalised::XMethod`]). It needs the valve's port
//!   areas, so it merges valve and cylinder hydraulics into one subsystem.
//! * [`fluid`] — the oil at low pressure: an entrained-air fraction makes the
//!   effective bulk modulus `B_eff(p)` fall towards `n P` as the absolute
//!   pressure falls, so no volume goes below absolute zero
//!   ([`fluid::EntrainedAir`]; none = the constant `B` of eqs 2.10–2.15).
//! * [`StrokeEnds`] — the hard stroke-end stops (positions and the switching
//!   functions of the event-based stop used by the assembler).
//!
//! ```text
//!              Q1 (into 1) ─▶ ┌──────────────┬────────┐ ◀─ Q2 (out of 2)
//!   p1 [Pa] ◀──────────────── │  chamber 1   │ ch. 2  │ ───────────▶ p2 [Pa]
//!                             │  A1, V1(x)   │A2,V2(x)│════ rod ══▶ F = p1A1 − p2A2 [N]
//!                             └──────────────┴────────┘      x, v [m, m/s] (+ extending)
//! ```
//!
//! Units: SI everywhere (Pa, m, m², m³, m³·s⁻¹, N); `x` from mid-stroke, positive
//! extending; chamber 1 the cap side, γ = A1/A2.
//!
//! ```
//! use hydrocyl_actuator::Cylinder;
//! use hydrocyl_ports::{Position, Pressure, Velocity, VolumeFlow};
//!
//! let c = Cylinder::leaney_moog();
//! // 90 mm/s extension fed exactly by the displacement flow: pressures stay put
//! let v = Velocity::from_mm_per_s(90.0);
//! let q1 = c.area_1 * v;
//! let q2 = c.area_2 * v;
//! let (dp1, dp2) = c.pressure_rates(Position::ZERO, v, Pressure::from_bar(40.0),
//!                                   Pressure::from_bar(20.0), q1, q2);
//! assert!(dp1.abs() < 1e-6 && dp2.abs() < 1e-6);
//! assert!((c.gamma() - 1.9707).abs() < 1e-4);
//! ```
#![warn(missing_docs)]

pub mod fluid;
pub mod generalised;

pub use fluid::EntrainedAir;

use hydrocyl_ports::{Area, Force, Position, Pressure, Velocity, Volume, VolumeFlow};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// A cylinder parameter out of range; names the parameter and its value.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum ActuatorError {
    /// A parameter that must be positive and finite is not.
    #[error("cylinder parameter `{name}` must be positive and finite, got {value}")]
    NotPositive {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A parameter that must be non-negative and finite is not.
    #[error("cylinder parameter `{name}` must be non-negative and finite, got {value}")]
    Negative {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
    },
    /// A chamber would have no volume left at a stroke end.
    #[error("chamber {chamber} volume at the stroke end is {volume:e} m^3: chamber_length_{chamber} must exceed half the stroke")]
    EmptyChamber {
        /// 1 or 2.
        chamber: u8,
        /// The volume at the stroke end \[m³\].
        volume: f64,
    },
    /// A parameter outside its range.
    #[error("parameter `{name}` must be in {range}, got {value}")]
    OutOfRange {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// The range, e.g. `[0, 1)`.
        range: &'static str,
    },
    /// The rod side is larger than the cap side.
    #[error("area_2 ({a2} m^2) must not exceed area_1 ({a1} m^2) for a single-rod cylinder (gamma >= 1)")]
    AreaRatio {
        /// Cap-side area \[m²\].
        a1: f64,
        /// Rod-side area \[m²\].
        a2: f64,
    },
}

pub(crate) fn positive(name: &'static str, value: f64) -> Result<(), ActuatorError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ActuatorError::NotPositive { name, value })
    }
}

pub(crate) fn non_negative(name: &'static str, value: f64) -> Result<(), ActuatorError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ActuatorError::Negative { name, value })
    }
}

/// The two-chamber asymmetric cylinder (fundamental form).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Cylinder {
    /// Cap-side (piston) area A1 \[m²\].
    pub area_1: Area,
    /// Rod-side (annulus) area A2 \[m²\].
    pub area_2: Area,
    /// Full stroke; the piston moves in `[−stroke/2, +stroke/2]` \[m\].
    pub stroke: Position,
    /// Equivalent length of chamber 1 at mid-stroke, `V1 = A1 (l1 + x)` \[m\].
    pub chamber_length_1: Position,
    /// Equivalent length of chamber 2 at mid-stroke, `V2 = A2 (l2 − x)` \[m\].
    pub chamber_length_2: Position,
    /// Effective bulk modulus B of the fluid in the chambers \[Pa\].
    pub bulk_modulus: Pressure,
    /// Internal leakage coefficient Cl, flow `Cl (p1 − p2)` from 1 to 2 \[m³·s⁻¹·Pa⁻¹\].
    pub internal_leakage: f64,
    /// External leakage coefficient Ce1, flow `Ce1 p1` out of chamber 1 \[m³·s⁻¹·Pa⁻¹\].
    pub external_leakage_1: f64,
    /// External leakage coefficient Ce2, flow `Ce2 p2` out of chamber 2 \[m³·s⁻¹·Pa⁻¹\].
    pub external_leakage_2: f64,
}

impl Cylinder {
    /// The `leaney-moog` cylinder (88533-002): A1 = 11.43 cm², A2 = 5.8 cm²,
    /// stroke 0.52 m, `V = A (0.31 ± x)` (vt.m), B = 7000 bar, no leakage.
    pub fn leaney_moog() -> Self {
        Self {
            area_1: Area::new(11.43e-4),
            area_2: Area::new(5.8e-4),
            stroke: Position::new(0.52),
            chamber_length_1: Position::new(0.31),
            chamber_length_2: Position::new(0.31),
            bulk_modulus: Pressure::new(7.0e8),
            internal_leakage: 0.0,
            external_leakage_1: 0.0,
            external_leakage_2: 0.0,
        }
    }

    /// Checks the parameters: positive areas, stroke and bulk modulus,
    /// γ ≥ 1, non-negative leakage, and positive volumes at both stroke ends.
    pub fn validate(&self) -> Result<(), ActuatorError> {
        positive("area_1", self.area_1.si())?;
        positive("area_2", self.area_2.si())?;
        if self.area_2 > self.area_1 {
            return Err(ActuatorError::AreaRatio {
                a1: self.area_1.si(),
                a2: self.area_2.si(),
            });
        }
        positive("stroke", self.stroke.si())?;
        positive("chamber_length_1", self.chamber_length_1.si())?;
        positive("chamber_length_2", self.chamber_length_2.si())?;
        positive("bulk_modulus", self.bulk_modulus.si())?;
        non_negative("internal_leakage", self.internal_leakage)?;
        non_negative("external_leakage_1", self.external_leakage_1)?;
        non_negative("external_leakage_2", self.external_leakage_2)?;
        let half = self.stroke * 0.5;
        let (v1, _) = self.volumes(-half);
        let (_, v2) = self.volumes(half);
        if v1.si() <= 0.0 {
            return Err(ActuatorError::EmptyChamber {
                chamber: 1,
                volume: v1.si(),
            });
        }
        if v2.si() <= 0.0 {
            return Err(ActuatorError::EmptyChamber {
                chamber: 2,
                volume: v2.si(),
            });
        }
        Ok(())
    }

    /// Area ratio γ = A1/A2 \[-\].
    #[inline]
    pub fn gamma(&self) -> f64 {
        self.area_1 / self.area_2
    }

    /// Effective area `A_E = (A1 + A2)/2` (eq 2.16) \[m²\].
    #[inline]
    pub fn effective_area(&self) -> Area {
        (self.area_1 + self.area_2) * 0.5
    }

    /// The stroke ends of this cylinder.
    pub fn stroke_ends(&self) -> StrokeEnds {
        StrokeEnds {
            min: self.stroke * -0.5,
            max: self.stroke * 0.5,
        }
    }

    /// Chamber volumes `(V1, V2)` at piston position `x` (vt.m) \[m³\].
    #[inline]
    pub fn volumes(&self, x: Position) -> (Volume, Volume) {
        (
            self.area_1 * (self.chamber_length_1 + x),
            self.area_2 * (self.chamber_length_2 - x),
        )
    }

    /// Net force of the chamber pressures on the rod, `p1 A1 − p2 A2` (eq 2.27) \[N\].
    #[inline]
    pub fn force(&self, p1: Pressure, p2: Pressure) -> Force {
        p1 * self.area_1 - p2 * self.area_2
    }

    /// Leakage flows `(internal 1→2, external out of 1, external out of 2)` \[m³·s⁻¹\].
    #[inline]
    pub fn leakage(&self, p1: Pressure, p2: Pressure) -> (VolumeFlow, VolumeFlow, VolumeFlow) {
        (
            VolumeFlow::new(self.internal_leakage * (p1 - p2).si()),
            VolumeFlow::new(self.external_leakage_1 * p1.si()),
            VolumeFlow::new(self.external_leakage_2 * p2.si()),
        )
    }

    /// Pressure rates `(dp1/dt, dp2/dt)` \[Pa·s⁻¹\] for the flow `q1_in` **into**
    /// chamber 1 and the flow `q2_out` **out of** chamber 2 from outside (the
    /// valve), with the cylinder's own leakage added (eqs 2.10–2.15):
    /// `dp1/dt = B/V1 (q1_in − Ql − Qe1 − A1 v)`,
    /// `dp2/dt = B/V2 (A2 v + Ql − Qe2 − q2_out)`.
    #[inline]
    pub fn pressure_rates(
        &self,
        x: Position,
        v: Velocity,
        p1: Pressure,
        p2: Pressure,
        q1_in: VolumeFlow,
        q2_out: VolumeFlow,
    ) -> (f64, f64) {
        let (v1, v2) = self.volumes(x);
        let (ql, qe1, qe2) = self.leakage(p1, p2);
        let b = self.bulk_modulus.si();
        let n1 = q1_in - ql - qe1 - self.area_1 * v;
        let n2 = self.area_2 * v + ql - qe2 - q2_out;
        (b / v1.si() * n1.si(), b / v2.si() * n2.si())
    }
}

/// The hard stroke-end stops `[min, max]` of the piston \[m\].
///
/// hydrocyl models the stops as **events**, not as a stiff contact: when the
/// piston reaches an end moving outwards, its velocity is set to zero and it
/// is held there (dx/dt = dv/dt = 0) while the net force pushes it into the
/// stop; it is released when the net force turns inwards. The piston therefore
/// never leaves the stroke and the chamber volumes stay at least
/// `A1 (l1 − stroke/2)`, `A2 (l2 − stroke/2)`, which [`Cylinder::validate`]
/// requires to be positive. The impact is fully plastic (the kinetic energy is
/// lost at the stop, reported as such by the energy ledger).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct StrokeEnds {
    /// Retracted end \[m\].
    pub min: Position,
    /// Extended end \[m\].
    pub max: Position,
}

impl StrokeEnds {
    /// `true` when `x` is within the ends (inclusive).
    pub fn contains(&self, x: Position) -> bool {
        x >= self.min && x <= self.max
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn volumes_follow_vt_m() {
        let c = Cylinder::leaney_moog();
        let (v1, v2) = c.volumes(Position::new(0.1));
        assert!((v1.si() - 11.43e-4 * 0.41).abs() < 1e-15);
        assert!((v2.si() - 5.8e-4 * 0.21).abs() < 1e-15);
        c.validate().unwrap();
    }

    #[test]
    fn empty_chamber_at_stroke_end_is_rejected() {
        let mut c = Cylinder::leaney_moog();
        c.chamber_length_2 = Position::new(0.2);
        let e = c.validate().unwrap_err();
        assert!(
            matches!(e, ActuatorError::EmptyChamber { chamber: 2, .. }),
            "{e}"
        );
        let mut c = Cylinder::leaney_moog();
        c.area_2 = Area::new(2e-3);
        assert!(matches!(c.validate(), Err(ActuatorError::AreaRatio { .. })));
        let mut c = Cylinder::leaney_moog();
        c.bulk_modulus = Pressure::new(f64::NAN);
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .contains("bulk_modulus"));
    }

    #[test]
    fn blocked_chamber_stiffness() {
        // a blocked piston (v = 0) with inflow q: dp/dt = B q / V exactly
        let c = Cylinder::leaney_moog();
        let q = VolumeFlow::from_l_per_min(1.0);
        let (dp1, dp2) = c.pressure_rates(
            Position::ZERO,
            Velocity::ZERO,
            Pressure::ZERO,
            Pressure::ZERO,
            q,
            q,
        );
        let (v1, v2) = c.volumes(Position::ZERO);
        assert!((dp1 - 7e8 * q.si() / v1.si()).abs() < 1e-6);
        assert!((dp2 + 7e8 * q.si() / v2.si()).abs() < 1e-6);
    }

    proptest! {
        /// Leakage conserves volume: internal leakage leaves 1 what it adds to 2.
        #[test]
        fn internal_leakage_moves_volume_from_1_to_2(p1 in 0.0f64..1e7, p2 in 0.0f64..1e7, x in -0.26f64..0.26) {
            let mut c = Cylinder::leaney_moog();
            c.internal_leakage = 1e-12;
            let (dp1, dp2) = c.pressure_rates(Position::new(x), Velocity::ZERO,
                Pressure::new(p1), Pressure::new(p2), VolumeFlow::ZERO, VolumeFlow::ZERO);
            let (v1, v2) = c.volumes(Position::new(x));
            // V1 dp1/B + V2 dp2/B = 0 (what leaves 1 enters 2)
            let s = v1.si() * dp1 / 7e8 + v2.si() * dp2 / 7e8;
            prop_assert!(s.abs() <= 1e-12 * (1e-12 * (p1 - p2).abs()).max(1e-30));
            prop_assert!((dp1 > 0.0) == (p2 > p1) || p1 == p2);
        }
    }
}
