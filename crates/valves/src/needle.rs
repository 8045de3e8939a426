//! The NCCC needle valve with its reverse-flow check (thesis section 6.2.2.3,
//! eq 6.11, Table 6-1; Appendix II `pcyl4_1.m`).
//!
//! ```text
//!            ┌──[ needle, 0.8 Avn ]──┐
//!   p_in ────┤                       ├──── p_out      metered: p_in → p_out (both signs)
//!            └────────◀|─────────────┘                free reverse flow p_out → p_in
//! ```
//!
//! ## Law
//! * Opening area from the adjusting screw's turns by linear interpolation of
//!   Table 6-1 (0 turns = closed; 1, 2, 3, 4 turns = 4.51e-7, 1.80e-6, 3.61e-6,
//!   5.58e-6 m²); the valve adjusts over 5 turns (Table 4-5), so 4–5 turns
//!   extend the 3–4 segment linearly (an assumption: the table stops at 4).
//! * Metered flow `Q = Cd (0.8 Avn) √(2/ρ) √Δp` (eq 6.1 with the 0.8 factor of
//!   `pcyl4_1.m`'s `Avne = Avnr = 0.8 Avn`, used for both the extending and the
//!   retracting return flow), regularised near `Δp = 0` as in [`crate::orifice`].
//! * The reverse-flow check: a [`CheckValve`] from outlet to inlet in parallel
//!   with the needle. In `wang-hybrid` the needle's outlet is the tank, so this
//!   check lets a return-connected chamber draw oil from the tank rather than
//!   cavitate.

use crate::check::{non_negative, positive, CheckValve, ParameterError};
use crate::orifice::Orifice;
use hydrocyl_ports::{Area, Density, Power, Pressure, VolumeFlow};
use serde::{Deserialize, Serialize};

/// Table 6-1: screw turns and the opening area they give \[m²\] (0 turns added: closed).
pub const TABLE_6_1: [(f64, f64); 5] = [
    (0.0, 0.0),
    (1.0, 4.51e-7),
    (2.0, 1.80e-6),
    (3.0, 3.61e-6),
    (4.0, 5.58e-6),
];
/// Screw adjustment range (Table 4-5) \[turns\].
pub const MAX_TURNS: f64 = 5.0;
/// Effective-area factor of `pcyl4_1.m` (`Avne = Avnr = 0.8 Avn`) \[-\].
pub const EFFECTIVE_AREA_FACTOR: f64 = 0.8;

/// Opening area `Avn` for `turns` of the screw by linear interpolation of
/// Table 6-1 (extrapolated linearly over 4–5 turns). Errors outside `[0, 5]`
/// or for NaN.
pub fn area_from_turns(turns: f64) -> Result<Area, ParameterError> {
    if !(turns.is_finite() && (0.0..=MAX_TURNS).contains(&turns)) {
        return Err(ParameterError {
            component: "needle valve",
            name: "turns",
            value: turns,
            reason: "must be within the screw's 0..=5 turns (Table 4-5)",
        });
    }
    let i = (turns.floor() as usize).min(TABLE_6_1.len() - 2);
    let (t0, a0) = TABLE_6_1[i];
    let (t1, a1) = TABLE_6_1[i + 1];
    Ok(Area::new(a0 + (a1 - a0) * (turns - t0) / (t1 - t0)))
}

/// The needle valve: opening area, orifice law and reverse-flow check.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct NeedleValve {
    /// Opening area `Avn` \[m²\].
    pub area: Area,
    /// Effective-area factor applied to `Avn` \[-\].
    pub effective_factor: f64,
    /// Orifice law (Cd, ρ, regularisation).
    pub orifice: Orifice,
    /// Reverse-flow check (outlet → inlet).
    pub reverse_check: CheckValve,
}

impl NeedleValve {
    /// A needle valve with opening `area`, validated (`area ≥ 0`, factor in
    /// `(0, 1]`, Cd in `(0, 1]`, ρ > 0).
    pub fn new(
        area: Area,
        effective_factor: f64,
        orifice: Orifice,
        reverse_check: CheckValve,
    ) -> Result<Self, ParameterError> {
        const C: &str = "needle valve";
        non_negative(C, "area", area.si())?;
        positive(C, "effective_factor", effective_factor)?;
        if effective_factor > 1.0 {
            return Err(ParameterError {
                component: C,
                name: "effective_factor",
                value: effective_factor,
                reason: "must be at most 1",
            });
        }
        orifice.validate(C)?;
        Ok(Self {
            area,
            effective_factor,
            orifice,
            reverse_check,
        })
    }

    /// The `wang-hybrid` needle valve: `Avn` = 4.0e-6 m² (`pcyl4_1.m`), factor
    /// 0.8, Cd 0.65, ρ 900 kg/m³, the assumed anti-cavitation check as its
    /// reverse-flow check.
    pub fn nccc() -> Self {
        Self {
            area: Area::new(4.0e-6),
            effective_factor: EFFECTIVE_AREA_FACTOR,
            orifice: Orifice::new(0.65, Density::new(900.0)),
            reverse_check: CheckValve::anti_cavitation(),
        }
    }

    /// The `wang-hybrid` needle valve set to `turns` of the screw (Table 6-1).
    pub fn nccc_at_turns(turns: f64) -> Result<Self, ParameterError> {
        Ok(Self {
            area: area_from_turns(turns)?,
            ..Self::nccc()
        })
    }

    /// Metering coefficient `Cd (0.8 Avn) √(2/ρ)` \[m³·s⁻¹·Pa^-½\]: the
    /// one [`NeedleValve::metered_flow`] multiplies the signed square root
    /// by, bit for bit.
    #[inline]
    pub fn coefficient(&self) -> f64 {
        self.orifice.coefficient() * (self.area * self.effective_factor).si()
    }

    /// Metered flow `p_in → p_out` (either sign) \[m³·s⁻¹\].
    #[inline]
    pub fn metered_flow(&self, p_in: Pressure, p_out: Pressure) -> VolumeFlow {
        self.orifice
            .flow(self.area * self.effective_factor, p_in, p_out)
    }

    /// Total flow `p_in → p_out`: metered flow minus the reverse check's flow \[m³·s⁻¹\].
    #[inline]
    pub fn flow(&self, p_in: Pressure, p_out: Pressure) -> VolumeFlow {
        self.metered_flow(p_in, p_out) - self.reverse_check.flow(p_out, p_in)
    }

    /// `∂Q/∂p_in` of [`NeedleValve::flow`] \[m³·s⁻¹·Pa⁻¹\].
    #[inline]
    pub fn conductance(&self, p_in: Pressure, p_out: Pressure) -> f64 {
        self.orifice
            .conductance(self.area * self.effective_factor, p_in, p_out)
            + self.reverse_check.conductance(p_out, p_in)
    }

    /// Switching function of the reverse check: rising through zero when it cracks \[Pa\].
    #[inline]
    pub fn reverse_check_margin(&self, p_in: Pressure, p_out: Pressure) -> f64 {
        self.reverse_check.crack_margin(p_out, p_in)
    }

    /// Hydraulic power dissipated \[W\] (never negative).
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
    fn interpolates_table_6_1_exactly_at_its_points() {
        for &(t, a) in &TABLE_6_1 {
            assert!((area_from_turns(t).unwrap().si() - a).abs() < 1e-18, "{t}");
        }
        let mid = area_from_turns(2.5).unwrap().si();
        assert!((mid - 0.5 * (1.80e-6 + 3.61e-6)).abs() < 1e-18);
        let five = area_from_turns(5.0).unwrap().si();
        assert!((five - (5.58e-6 + (5.58e-6 - 3.61e-6))).abs() < 1e-18);
    }

    #[test]
    fn rejects_turns_outside_the_screw_range() {
        assert_eq!(area_from_turns(-0.1).unwrap_err().name, "turns");
        assert!(area_from_turns(5.01).is_err());
        assert!(area_from_turns(f64::NAN).is_err());
        assert!(NeedleValve::nccc_at_turns(3.0).is_ok());
    }

    #[test]
    fn table_6_1_areas_reproduce_its_flows() {
        // Table 6-1 was computed back from the datasheet flows with eq 6.11; the flows per
        // area are consistent with one pressure drop: Q/A is the same for each row.
        let q = [0.67, 2.67, 5.33, 8.25];
        let ratios: Vec<f64> = TABLE_6_1[1..]
            .iter()
            .zip(q)
            .map(|(&(_, a), q)| q / 60_000.0 / a)
            .collect();
        for r in &ratios {
            assert!((r / ratios[0] - 1.0).abs() < 0.02, "{ratios:?}");
        }
    }

    #[test]
    fn metered_flow_is_the_orifice_law_with_0_8_avn() {
        let n = NeedleValve::nccc();
        let q = n.flow(Pressure::from_bar(5.0), Pressure::ZERO).si();
        let expect = 0.65 * 0.8 * 4.0e-6 * (2.0f64 / 900.0).sqrt() * 5.0e5f64.sqrt();
        assert!((q - expect).abs() < 1e-15);
        assert!((n.coefficient() * 5.0e5f64.sqrt() - expect).abs() < 1e-15);
    }

    #[test]
    fn reverse_check_adds_free_flow_backwards() {
        let n = NeedleValve::nccc();
        let back = n.flow(Pressure::ZERO, Pressure::from_bar(2.0)).si();
        let metered_only = n.metered_flow(Pressure::ZERO, Pressure::from_bar(2.0)).si();
        assert!(back < metered_only && metered_only < 0.0);
        // below the check's cracking, only the needle passes reverse flow
        let small = Pressure::from_bar(0.2);
        assert_eq!(
            n.flow(Pressure::ZERO, small),
            n.metered_flow(Pressure::ZERO, small)
        );
        assert!(n.reverse_check_margin(Pressure::ZERO, Pressure::from_bar(0.5)) > 0.0);
    }

    #[test]
    fn rejects_bad_parameters() {
        let n = NeedleValve::nccc();
        assert!(NeedleValve::new(Area::new(-1e-6), 0.8, n.orifice, n.reverse_check).is_err());
        assert!(NeedleValve::new(n.area, 1.2, n.orifice, n.reverse_check).is_err());
        let mut o = n.orifice;
        o.cd = f64::NAN;
        assert!(NeedleValve::new(n.area, 0.8, o, n.reverse_check).is_err());
        o.cd = 1.5;
        let e = NeedleValve::new(n.area, 0.8, o, n.reverse_check).unwrap_err();
        assert_eq!(e.name, "cd");
    }

    proptest! {
        #[test]
        fn area_monotone_in_turns(a in 0.0f64..5.0, b in 0.0f64..5.0) {
            let (x, y) = (area_from_turns(a).unwrap(), area_from_turns(b).unwrap());
            if a < b { prop_assert!(x <= y); }
        }

        #[test]
        fn flow_monotone_and_dissipative(a in -3.0e5f64..3.0e6, b in -3.0e5f64..3.0e6) {
            let n = NeedleValve::nccc();
            let qa = n.flow(Pressure::new(a), Pressure::ZERO).si();
            let qb = n.flow(Pressure::new(b), Pressure::ZERO).si();
            if a < b { prop_assert!(qa <= qb); }
            prop_assert!(n.power_dissipated(Pressure::new(a), Pressure::ZERO).si() >= 0.0);
        }

        #[test]
        fn the_coefficient_is_the_metered_flows_bit_for_bit(
            turns in 0.0f64..5.0, factor in 0.1f64..1.0, dp in -3.0e6f64..3.0e6,
        ) {
            // an algebraic node solved on the needle's law (hydrocyl-system's
            // series solve) needs the very k that metered_flow multiplies by
            let n = NeedleValve { effective_factor: factor, ..NeedleValve::nccc_at_turns(turns).unwrap() };
            let law = n.coefficient()
                * crate::orifice::signed_sqrt_regularised(dp, n.orifice.dp_transition.si());
            prop_assert_eq!(n.metered_flow(Pressure::new(dp), Pressure::ZERO).si(), law);
        }
    }
}
