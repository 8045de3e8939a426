//! The RBAE relief valve with outlet-referred cracking (thesis section 6.2.2.2,
//! eqs 6.6–6.10; Appendix II `rlv_1.m`).
//!
//! ```text
//!   p_in ──▶ [ relief, p_c referred to p_out ] ──▶ p_out
//! ```
//!
//! ## Law (eq 6.10)
//! With `Δp = p_in − p_out` (the RBAE's back-pressure adds to its setting, so
//! every threshold is on the difference):
//!
//! ```text
//!   Q = 0                               Δp ≤ p_c
//!     = Q_m (Δp − p_c) / (P_m − p_c)    p_c < Δp ≤ P_m       (linear, eq 6.9)
//!     = K_v √Δp                         Δp > P_m              (orifice, eq 6.7)
//! ```
//!
//! with `Q_m = K_v √P_m` (eq 6.7), which makes the law continuous at `P_m`.
//!
//! ## Eq 6.8, corrected
//! The performance curve's linear part is `P = p_c + R_a Q` (eq 6.9) and the
//! fully-open part the orifice `Q = K_v √P`. They meet where
//! `P_m − p_c = R_a K_v √P_m`; squaring gives
//!
//! ```text
//!   P_m² − (2 p_c + R_a² K_v²) P_m + p_c² = 0
//! ```
//!
//! The thesis prints the last term as `P_m²` (which would cancel the first and
//! make the equation linear); it must be `p_c²`. Of the two roots the larger is
//! the intersection (`P_m > p_c`); the smaller is the spurious root of the
//! squaring (`√P_m = −(P_m − p_c)/(R_a K_v)`). [`ReliefValve::from_performance_curve`]
//! solves it; the tests check that the result satisfies eq 6.9 and the orifice law
//! at once and that the flow is continuous at `P_m`.
//!
//! ## Where hydrocyl differs from `rlv_1.m`
//! `rlv_1.m` uses `√(Δp − p_c)` above `P_m` (a jump in flow at `P_m`) and
//! compares the absolute inlet pressure, not `Δp`, with `P_m`. hydrocyl follows
//! eq 6.10 as printed: continuous, outlet-referred throughout. The relief is a
//! poppet: reverse pressure gives no flow.

use crate::check::{non_negative, positive, ParameterError};
use hydrocyl_ports::{Power, Pressure, VolumeFlow};
use serde::{Deserialize, Serialize};

/// `K_v` of the RBAE performance curve (`rlv_1.m`) \[m³·s⁻¹·Pa^-½\].
pub const RBAE_KV: f64 = 8.2864e-8;
/// `P_m` of the RBAE performance curve (`rlv_1.m`) \[Pa\].
pub const RBAE_PM: Pressure = Pressure::new(16.062_537_571_849_01e6);
/// The cracking pressure `rlv_1.m` computes its `P_m` for, `pc2 = 1e5` \[Pa\].
pub const RLV_1_CRACKING: Pressure = Pressure::new(1.0e5);
/// Slope `R_a` of the RBAE curve of `rlv_1.m` (eq 6.9): the line from
/// (`pc2` = 1 bar, 0) to (`P_m`, `K_v √P_m`), 4.81e10 Pa·s·m⁻³ (8.01 bar per
/// l/min). The valve's characteristic; `P_m` follows from it through eq 6.8
/// for any other cracking pressure.
pub fn rbae_ra() -> f64 {
    (RBAE_PM - RLV_1_CRACKING).si() / (RBAE_KV * RBAE_PM.si().sqrt())
}
/// Cracking pressure of relief valves 1 and 2 in `wang-hybrid`: the DDDC
/// valve's minimum pilot-shift pressure, 150 psi = 10.34 bar \[Pa\] (rigs.md,
/// assumed from Table 4-3 and `pcyl4_1.m`).
pub const RBAE_PILOT_CRACKING: Pressure = Pressure::new(10.34e5);
/// Setting of relief valve 3, the safety valve (section 4.1) \[Pa\].
pub const SAFETY_SETTING: Pressure = Pressure::new(200.0e5);

/// `P_m`: the larger root of the corrected eq 6.8,
/// `P_m² − (2 p_c + R_a² K_v²) P_m + p_c² = 0` (always `> p_c` for `R_a K_v > 0`).
pub fn full_open_from_curve(cracking: Pressure, ra: f64, kv: f64) -> Pressure {
    let pc = cracking.si();
    let rk2 = ra * ra * kv * kv;
    let b = 2.0 * pc + rk2;
    // b² − 4 pc² = rk2 (4 pc + rk2) ≥ 0, written without cancellation
    Pressure::new(0.5 * (b + (rk2 * (4.0 * pc + rk2)).sqrt()))
}

/// Which part of eq 6.10 the valve is on.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub enum ReliefRegime {
    /// `Δp ≤ p_c`: closed.
    Closed,
    /// `p_c < Δp ≤ P_m`: opening, linear in `Δp`.
    Opening,
    /// `Δp > P_m`: fully open, orifice law.
    FullyOpen,
}

/// A relief valve on the eq 6.10 law.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ReliefValve {
    /// Cracking pressure `p_c`, referred to the outlet \[Pa\].
    pub cracking: Pressure,
    /// Pressure difference `P_m` at which the valve is fully open \[Pa\].
    pub full_open: Pressure,
    /// Fully-open flow coefficient `K_v` \[m³·s⁻¹·Pa^-½\].
    pub kv: f64,
}

impl ReliefValve {
    /// A relief valve from `p_c`, `K_v` and `P_m` (validated: `0 ≤ p_c < P_m`,
    /// `K_v > 0`, all finite).
    pub fn new(cracking: Pressure, kv: f64, full_open: Pressure) -> Result<Self, ParameterError> {
        non_negative("relief valve", "cracking", cracking.si())?;
        positive("relief valve", "kv", kv)?;
        positive("relief valve", "full_open", full_open.si())?;
        if full_open.si() <= cracking.si() {
            return Err(ParameterError {
                component: "relief valve",
                name: "cracking",
                value: cracking.si(),
                reason: "must be below the full-open pressure difference `full_open` (P_m)",
            });
        }
        Ok(Self {
            cracking,
            full_open,
            kv,
        })
    }

    /// A relief valve from its performance-curve parameters: cracking `p_c`,
    /// pressure-flow ratio `R_a` of the linear part (eq 6.9) \[Pa·s·m⁻³\] and
    /// `K_v`; `P_m` is the larger root of the corrected eq 6.8 (module docs).
    pub fn from_performance_curve(
        cracking: Pressure,
        ra: f64,
        kv: f64,
    ) -> Result<Self, ParameterError> {
        non_negative("relief valve", "cracking", cracking.si())?;
        positive("relief valve", "ra", ra)?;
        positive("relief valve", "kv", kv)?;
        Self::new(cracking, kv, full_open_from_curve(cracking, ra, kv))
    }

    /// Relief valves 1 and 2 of `wang-hybrid`: the RBAE curve of `rlv_1.m`
    /// (`K_v` and the slope [`rbae_ra`]) at the pilot-shift cracking pressure
    /// (10.34 bar), `P_m` from eq 6.8: 178.7 bar (rigs.md: `rlv_1.m`'s 160.6
    /// bar belongs to its own 1-bar cracking pressure; reusing it at 10.34 bar
    /// would change the slope to 7.54 bar per l/min).
    pub fn rbae_pilot() -> Self {
        Self {
            cracking: RBAE_PILOT_CRACKING,
            full_open: full_open_from_curve(RBAE_PILOT_CRACKING, rbae_ra(), RBAE_KV),
            kv: RBAE_KV,
        }
    }

    /// Relief valve 3 of `wang-hybrid` (200 bar, "same law"): the RBAE's `K_v`
    /// and slope [`rbae_ra`], with `P_m` from eq 6.8 for the 200 bar setting.
    pub fn rbae_safety() -> Self {
        let ra = rbae_ra();
        Self {
            cracking: SAFETY_SETTING,
            full_open: full_open_from_curve(SAFETY_SETTING, ra, RBAE_KV),
            kv: RBAE_KV,
        }
    }

    /// Flow at full opening, `Q_m = K_v √P_m` (eq 6.7) \[m³·s⁻¹\].
    #[inline]
    pub fn q_max(&self) -> VolumeFlow {
        VolumeFlow::new(self.kv * self.full_open.si().sqrt())
    }

    /// Pressure-flow ratio of the linear part, `R_a = (P_m − p_c)/Q_m` (eq 6.9) \[Pa·s·m⁻³\].
    #[inline]
    pub fn ra(&self) -> f64 {
        (self.full_open - self.cracking).si() / self.q_max().si()
    }

    /// Which part of eq 6.10 applies at `Δp = p_in − p_out`.
    #[inline]
    pub fn regime(&self, p_in: Pressure, p_out: Pressure) -> ReliefRegime {
        let dp = p_in - p_out;
        if dp <= self.cracking {
            ReliefRegime::Closed
        } else if dp <= self.full_open {
            ReliefRegime::Opening
        } else {
            ReliefRegime::FullyOpen
        }
    }

    /// Flow from `p_in` to `p_out` (eq 6.10; never negative).
    #[inline]
    pub fn flow(&self, p_in: Pressure, p_out: Pressure) -> VolumeFlow {
        let dp = (p_in - p_out).si();
        let pc = self.cracking.si();
        let pm = self.full_open.si();
        if dp <= pc {
            VolumeFlow::ZERO
        } else if dp <= pm {
            VolumeFlow::new(self.q_max().si() * (dp - pc) / (pm - pc))
        } else {
            VolumeFlow::new(self.kv * dp.sqrt())
        }
    }

    /// `∂Q/∂p_in` \[m³·s⁻¹·Pa⁻¹\] (`∂Q/∂p_out` is its negative).
    #[inline]
    pub fn conductance(&self, p_in: Pressure, p_out: Pressure) -> f64 {
        let dp = (p_in - p_out).si();
        let pc = self.cracking.si();
        let pm = self.full_open.si();
        if dp <= pc {
            0.0
        } else if dp <= pm {
            self.q_max().si() / (pm - pc)
        } else {
            0.5 * self.kv / dp.sqrt()
        }
    }

    /// Switching function: `Δp − p_c` \[Pa\]; rising through zero when the valve cracks.
    #[inline]
    pub fn crack_margin(&self, p_in: Pressure, p_out: Pressure) -> f64 {
        (p_in - p_out - self.cracking).si()
    }

    /// Switching function: `Δp − P_m` \[Pa\]; rising through zero when the valve
    /// reaches full opening (the law's second kink).
    #[inline]
    pub fn full_open_margin(&self, p_in: Pressure, p_out: Pressure) -> f64 {
        (p_in - p_out - self.full_open).si()
    }

    /// Hydraulic power dissipated, `Q Δp` (never negative) \[W\].
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
    fn continuous_at_full_open() {
        let r = ReliefValve::rbae_pilot();
        let pm = r.full_open;
        let below = r.flow(pm * (1.0 - 1e-12), Pressure::ZERO).si();
        let above = r.flow(pm * (1.0 + 1e-12), Pressure::ZERO).si();
        assert!((below - above).abs() < 1e-9 * above, "{below} vs {above}");
        // and at cracking
        assert_eq!(r.flow(r.cracking, Pressure::ZERO), VolumeFlow::ZERO);
        assert!(r.flow(r.cracking * (1.0 + 1e-9), Pressure::ZERO).si() < 1e-12);
    }

    #[test]
    fn corrected_eq_6_8_meets_both_curves() {
        for &(pc_bar, ra, kv) in &[
            (10.34, 4.5e10, 8.2864e-8),
            (70.0, 2.0e10, 5.0e-8),
            (0.0, 1.0e10, 1.0e-7),
        ] {
            let r =
                ReliefValve::from_performance_curve(Pressure::from_bar(pc_bar), ra, kv).unwrap();
            let pm = r.full_open.si();
            let qm = r.q_max().si();
            // on the linear curve of eq 6.9 ...
            let p_lin = ra * qm + Pressure::from_bar(pc_bar).si();
            assert!((p_lin - pm).abs() < 1e-9 * pm, "eq 6.9: {p_lin} vs {pm}");
            // ... and on the orifice curve Q = Kv √P
            assert!((kv * pm.sqrt() - qm).abs() < 1e-12 * qm);
            assert!(pm > Pressure::from_bar(pc_bar).si());
            assert!((r.ra() - ra).abs() < 1e-9 * ra);
        }
    }

    #[test]
    fn as_printed_eq_6_8_cannot_be_right() {
        // printed: Pm² − (2pc + Ra²Kv²) Pm + Pm² = 0  →  Pm (2 Pm − b) = 0, i.e. Pm = b/2,
        // which does not lie on the orifice curve: its residual is large.
        let (pc, ra, kv): (f64, f64, f64) = (10.34e5, 4.5e10, 8.2864e-8);
        let b = 2.0 * pc + ra * ra * kv * kv;
        let pm_printed = b / 2.0;
        let resid = (pm_printed - pc - ra * kv * pm_printed.sqrt()).abs();
        assert!(resid > 0.1 * pm_printed, "{resid}");
    }

    #[test]
    fn rbae_curve_reproduces_rlv_1() {
        // at rlv_1.m's own 1 bar: Pm = 160.6 bar, Qm = Kv √Pm = 3.321e-4 m³/s (19.9 L/min)
        let at_1 = ReliefValve::from_performance_curve(RLV_1_CRACKING, rbae_ra(), RBAE_KV).unwrap();
        assert!((at_1.full_open.si() / RBAE_PM.si() - 1.0).abs() < 1e-12);
        assert!((at_1.q_max().si() - 8.2864e-8 * 16.062_537_571_849_01e6f64.sqrt()).abs() < 1e-15);
        // the preset's 10.34 bar keeps the slope: Pm = 178.7 bar
        let r = ReliefValve::rbae_pilot();
        assert!((r.ra() / rbae_ra() - 1.0).abs() < 1e-12);
        assert!(
            (r.full_open.si() - 178.7e5).abs() < 0.1e5,
            "{}",
            r.full_open.si()
        );
        // the same Ra through eq 6.8 gives back Pm
        let back = ReliefValve::from_performance_curve(r.cracking, r.ra(), r.kv).unwrap();
        assert!((back.full_open.si() - r.full_open.si()).abs() < 1e-6 * r.full_open.si());
    }

    #[test]
    fn outlet_referred_cracking() {
        let r = ReliefValve::rbae_pilot();
        let p_out = Pressure::from_bar(30.0);
        // 35 bar at the inlet would open a tank-referred 10.34 bar valve, not this one
        assert_eq!(r.flow(Pressure::from_bar(35.0), p_out), VolumeFlow::ZERO);
        let q = r.flow(Pressure::from_bar(50.0), p_out);
        let q0 = r.flow(Pressure::from_bar(20.0), Pressure::ZERO);
        assert!((q.si() - q0.si()).abs() < 1e-15);
        assert_eq!(
            r.regime(Pressure::from_bar(50.0), p_out),
            ReliefRegime::Opening
        );
    }

    #[test]
    fn safety_valve_is_closed_in_normal_operation_and_continuous() {
        let r = ReliefValve::rbae_safety();
        assert_eq!(r.cracking, SAFETY_SETTING);
        assert!(r.full_open > r.cracking);
        assert_eq!(
            r.flow(Pressure::from_bar(150.0), Pressure::ZERO),
            VolumeFlow::ZERO
        );
        let pm = r.full_open;
        let d = r.flow(pm * (1.0 + 1e-12), Pressure::ZERO).si()
            - r.flow(pm * (1.0 - 1e-12), Pressure::ZERO).si();
        assert!(d.abs() < 1e-9 * r.q_max().si());
    }

    #[test]
    fn rejects_bad_parameters() {
        let e = ReliefValve::new(Pressure::from_bar(100.0), RBAE_KV, Pressure::from_bar(50.0))
            .unwrap_err();
        // the relation is the cracking pressure's (below full_open)
        assert_eq!(e.name, "cracking");
        assert!(ReliefValve::new(Pressure::from_bar(-1.0), RBAE_KV, RBAE_PM).is_err());
        assert!(ReliefValve::new(Pressure::from_bar(1.0), 0.0, RBAE_PM).is_err());
        assert!(
            ReliefValve::from_performance_curve(Pressure::from_bar(1.0), f64::NAN, RBAE_KV)
                .is_err()
        );
        assert!(ReliefValve::from_performance_curve(Pressure::from_bar(1.0), 1e10, -1.0).is_err());
    }

    proptest! {
        #[test]
        fn monotone_nonnegative_and_conductance(a in -5.0e6f64..4.0e7, b in -5.0e6f64..4.0e7) {
            let r = ReliefValve::rbae_pilot();
            let qa = r.flow(Pressure::new(a), Pressure::ZERO).si();
            let qb = r.flow(Pressure::new(b), Pressure::ZERO).si();
            prop_assert!(qa >= 0.0);
            if a < b { prop_assert!(qa <= qb); }
            // Lipschitz with the linear part's slope as the bound
            let l = r.q_max().si() / (r.full_open - r.cracking).si();
            prop_assert!((qa - qb).abs() <= l * (a - b).abs() * (1.0 + 1e-9) + 1e-30);
            prop_assert!(r.power_dissipated(Pressure::new(a), Pressure::ZERO).si() >= 0.0);
        }

        #[test]
        fn conductance_is_the_derivative(dp in 1.2e6f64..3.0e7) {
            let r = ReliefValve::rbae_pilot();
            prop_assume!((dp - r.full_open.si()).abs() > 10.0);
            let h = 1.0;
            let fd = (r.flow(Pressure::new(dp + h), Pressure::ZERO).si()
                - r.flow(Pressure::new(dp - h), Pressure::ZERO).si()) / (2.0 * h);
            let an = r.conductance(Pressure::new(dp), Pressure::ZERO);
            prop_assert!((fd - an).abs() <= 1e-6 * an);
        }
    }
}
