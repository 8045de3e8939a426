//! Leaney's generalised one-pressure form of a valve-controlled asymmetric
//! cylinder (thesis eqs 2.16–2.26, 3.3; Appendix II qload.m, vt.m, pressure.m).
//!
//! One state, the effective load pressure `P_LE = (p1 A1 − p2 A2)/A_E` with
//! `A_E = (A1 + A2)/2`, replaces the two chamber pressures. With `k = (1+γ)/2`
//! and `D = 1 + γ³`, and pressures measured from the tank pressure:
//!
//! * chamber pressures (eqs 2.21, 2.22):
//!   `p1 = (X Ps + γ² k P_LE)/D`, `p2 = (X γ Ps − k P_LE)/D`;
//! * effective volume (eq 2.24 = vt.m): `V_TE = (1+γ)(V2 + γ² V1)/D`;
//! * effective load flow (eq 2.26 = qload.m):
//!   `Q_LE = Cd/√(2ρ) · √((1+γ)²/D) · [A_v1 √(XγPs − k P_LE) − A_v2 √((D − Xγ)Ps + k P_LE)]`,
//!   which is `k · Q2` with `Q2` of eq 2.9 evaluated at `p2` above — that is how
//!   it is computed here, through the same regularised orifice law as the
//!   fundamental form (the regularised root is scale-homogeneous, so the two
//!   writings agree exactly);
//! * dynamics (eqs 2.23, 3.3): `dP_LE/dt = 4B/V_TE (Q_LE − Q_DE − Q_KE)`,
//!   `Q_DE = A_E v`, `Q_KE = Ql + (Qe1 − Qe2)/2`.
//!
//! X is Leaney's factor (eq 3.4), 1 when extending, γ² when retracting and the
//! root of eq 3.4 in the underlap; [`evaluate`] takes it as an input, and
//! [`XMethod`] obtains it from `hydrocyl-xfactor` numerically (Brent) or
//! analytically (the exact quartic root).
//!
//! ## What the form assumes (why it differs from the fundamental form)
//! 1. The pressure pair is constrained to the line of eqs 2.21/2.22 for the
//!    current X: the fast "pressure level" mode of the two chambers is
//!    removed (its compressibility is folded into `V_TE`, derived with X
//!    constant, so `dX/dt` in the underlap is neglected).
//! 2. X solves eq 3.4, which is the flow ratio `Q1 = γ Q2` at `P_LE = 0`; under
//!    load in the underlap the pressures of eqs 2.21/2.22 do not satisfy
//!    `Q1 = γ Q2` exactly. Outside the underlap (X = 1 or γ²) they do, for any
//!    `P_LE` (tested below).
//! 3. Only `Q2` enters `Q_LE`; chamber 1's flow is implied, not integrated, so
//!    the form does not conserve each chamber's mass separately.

use crate::Cylinder;
use hydrocyl_ports::{Area, Pressure, Velocity, VolumeFlow};

/// How the generalised form obtains Leaney's X factor (eq 3.4) from the
/// normalised spool travel `x_s/u0` (`hydrocyl-xfactor`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum XMethod {
    /// The exact analytical quartic root (root picked by the unsquared eq 3.4).
    Analytical,
    /// A bracketing (Brent) solve of eq 3.4 in `[1, γ²]`.
    Numerical {
        /// Absolute tolerance on X \[-\].
        tol: f64,
    },
}

impl XMethod {
    /// X at area ratio `gamma` and travel `travel` (1 for travel ≥ 1, γ² for ≤ −1).
    #[inline]
    pub fn x_factor(self, gamma: f64, travel: f64) -> f64 {
        match self {
            XMethod::Analytical => hydrocyl_xfactor::x_factor(gamma, travel),
            XMethod::Numerical { tol } => hydrocyl_xfactor::x_factor_numerical(gamma, travel, tol),
        }
    }
}

/// Chamber pressures `(p1, p2)` above tank from `P_LE`, X and the supply
/// pressure `ps` above tank (eqs 2.21, 2.22) \[Pa\].
#[inline]
pub fn chamber_pressures(gamma: f64, x: f64, ps: f64, p_le: f64) -> (f64, f64) {
    let k = 0.5 * (1.0 + gamma);
    let d = 1.0 + gamma * gamma * gamma;
    (
        (x * ps + gamma * gamma * k * p_le) / d,
        (x * gamma * ps - k * p_le) / d,
    )
}

/// Effective load pressure `P_LE = (p1 A1 − p2 A2)/A_E` (eq 2.16) \[Pa\].
#[inline]
pub fn load_pressure(cyl: &Cylinder, p1: Pressure, p2: Pressure) -> Pressure {
    Pressure::new(cyl.force(p1, p2).si() / cyl.effective_area().si())
}

/// Effective total volume `V_TE` (eq 2.24, vt.m) at piston position `x` \[m³\].
#[inline]
pub fn effective_volume(cyl: &Cylinder, x: f64) -> f64 {
    let g = cyl.gamma();
    let (v1, v2) = cyl.volumes(hydrocyl_ports::Position::new(x));
    (1.0 + g) * (v2.si() + g * g * v1.si()) / (1.0 + g * g * g)
}

/// Everything the generalised form computes at one instant.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GeneralisedState {
    /// Chamber 1 pressure (absolute, tank added back) \[Pa\].
    pub p1: Pressure,
    /// Chamber 2 pressure \[Pa\].
    pub p2: Pressure,
    /// `dP_LE/dt` \[Pa·s⁻¹\].
    pub dp_le: f64,
    /// Effective load flow Q_LE \[m³·s⁻¹\].
    pub q_le: VolumeFlow,
    /// Flow drawn from the supply `Q_P1 + Q_P2` \[m³·s⁻¹\].
    pub q_supply: VolumeFlow,
    /// Flow returned to the tank `Q_1T + Q_2T` \[m³·s⁻¹\].
    pub q_tank: VolumeFlow,
    /// Power dissipated at the four metering edges \[W\].
    pub dissipated: f64,
}

/// Evaluates the generalised form (eqs 2.21–2.26, 3.3).
///
/// `orifice(area, p_up, p_down)` is the metering edges' flow law (the
/// valves crate's regularised `Orifice::flow`; passed in so that this crate
/// does not depend sideways on the valves crate), `av1`/`av2` the port areas (eq 3.2),
/// `ps`/`pt` supply and tank pressures, `x_factor` Leaney's X, `p_le` the
/// state, `x`/`v` the piston position and velocity.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn evaluate(
    cyl: &Cylinder,
    orifice: impl Fn(Area, Pressure, Pressure) -> VolumeFlow,
    av1: Area,
    av2: Area,
    ps: Pressure,
    pt: Pressure,
    x_factor: f64,
    p_le: f64,
    x: f64,
    v: Velocity,
) -> GeneralisedState {
    let g = cyl.gamma();
    let k = 0.5 * (1.0 + g);
    let (r1, r2) = chamber_pressures(g, x_factor, (ps - pt).si(), p_le);
    let p1 = pt + Pressure::new(r1);
    let p2 = pt + Pressure::new(r2);
    // Q2 of eq 2.9 at these pressures; Q_LE = k Q2 (eq 2.26)
    let q_2t = orifice(av1, p2, pt);
    let q_p2 = orifice(av2, ps, p2);
    let q_p1 = orifice(av1, ps, p1);
    let q_1t = orifice(av2, p1, pt);
    let q_le = (q_2t - q_p2) * k;
    let q_de = cyl.effective_area() * v;
    let (ql, qe1, qe2) = cyl.leakage(p1, p2);
    let q_ke = ql + (qe1 - qe2) * 0.5;
    let vte = effective_volume(cyl, x);
    let dp_le = 4.0 * cyl.bulk_modulus.si() / vte * (q_le - q_de - q_ke).si();
    let dissipated =
        ((ps - p1) * q_p1 + (p1 - pt) * q_1t + (p2 - pt) * q_2t + (ps - p2) * q_p2).si();
    GeneralisedState {
        p1,
        p2,
        dp_le,
        q_le,
        q_supply: q_p1 + q_p2,
        q_tank: q_1t + q_2t,
        dissipated,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The sharp-edged orifice law, exact root (Cd = 0.625, ρ = 870).
    fn orifice(a: Area, up: Pressure, down: Pressure) -> VolumeFlow {
        let dp = (up - down).si();
        VolumeFlow::new(0.625 * (2.0f64 / 870.0).sqrt() * a.si() * dp.abs().sqrt() * dp.signum())
    }

    #[test]
    fn pressures_reproduce_load_pressure() {
        let c = Cylinder::leaney_moog();
        let g = c.gamma();
        for &(x, ple) in &[(1.0, 3e5), (g * g, -2e6), (2.6, 0.0)] {
            let (p1, p2) = chamber_pressures(g, x, 7e6, ple);
            let back = load_pressure(&c, Pressure::new(p1), Pressure::new(p2));
            assert!((back.si() - ple).abs() < 1e-6, "{x} {ple}");
        }
    }

    #[test]
    fn effective_volume_matches_eq_2_24() {
        let c = Cylinder::leaney_moog();
        let (a1, a2) = (c.area_1.si(), c.area_2.si());
        let ae = c.effective_area().si();
        for &x in &[-0.2, 0.0, 0.13] {
            let (v1, v2) = c.volumes(hydrocyl_ports::Position::new(x));
            let r = a2 / a1;
            let eq224 = 2.0 * ae / a1 * (v1.si() + r * r * v2.si()) / (1.0 + r * r * r);
            assert!((effective_volume(&c, x) - eq224).abs() < 1e-15);
        }
    }

    #[test]
    fn load_flow_matches_eq_2_26_as_printed() {
        // Q_LE = Cd/sqrt(2 rho) sqrt((1+g)^2/(1+g^3)) [Av1 sqrt(X g Ps - k P) - Av2 sqrt((D - X g) Ps + k P)]
        let c = Cylinder::leaney_moog();
        let g = c.gamma();
        let (k, d) = (0.5 * (1.0 + g), 1.0 + g * g * g);
        let (av1, av2) = (Area::new(2e-7), Area::new(5e-8));
        let (xf, ple, ps) = (2.1, 4e5, 7e6);
        let s = evaluate(
            &c,
            orifice,
            av1,
            av2,
            Pressure::new(ps),
            Pressure::ZERO,
            xf,
            ple,
            0.0,
            Velocity::ZERO,
        );
        let printed = 0.625 / (2.0f64 * 870.0).sqrt()
            * ((1.0 + g).powi(2) / d).sqrt()
            * (av1.si() * (xf * g * ps - k * ple).sqrt()
                - av2.si() * ((d - xf * g) * ps + k * ple).sqrt());
        assert!(
            (s.q_le.si() - printed).abs() < 1e-12 * printed.abs(),
            "{} {}",
            s.q_le.si(),
            printed
        );
    }

    #[test]
    fn both_x_methods_give_table_3_3() {
        let g = 11.43 / 5.8;
        for m in [XMethod::Analytical, XMethod::Numerical { tol: 1e-13 }] {
            assert!((m.x_factor(g, 0.0) / 2.637188916 - 1.0).abs() < 1e-6);
            assert_eq!(m.x_factor(g, 1.5), 1.0);
            assert!((m.x_factor(g, -1.0) - g * g).abs() < 1e-12);
        }
    }

    proptest! {
        /// Outside the underlap the generalised pressures satisfy the flow
        /// ratio Q1 = γ Q2 exactly for any load (the form's premise).
        #[test]
        fn flow_ratio_holds_outside_underlap(s in 0.001f64..0.999, a in 1e-8f64..1e-6, extending in proptest::bool::ANY) {
            let c = Cylinder::leaney_moog();
            let g = c.gamma();
            let o = orifice;
            let ps = Pressure::new(7e6);
            let (xf, av1, av2) = if extending { (1.0, Area::new(a), Area::ZERO) } else { (g * g, Area::ZERO, Area::new(a)) };
            // the loads that keep both chambers 10 kPa inside (0, ps): p1
            // rises with P_LE and p2 falls (eqs 2.21, 2.22), so they are
            // an interval, drawn from by `s` (no case is rejected)
            let (lo, hi) = (1e4, ps.si() - 1e4);
            let (p1_0, p2_0) = chamber_pressures(g, xf, ps.si(), 0.0);
            let (p1_1, p2_1) = chamber_pressures(g, xf, ps.si(), 1.0);
            let (d1, d2) = (p1_1 - p1_0, p2_1 - p2_0);
            let from = ((lo - p1_0) / d1).max((hi - p2_0) / d2);
            let to = ((hi - p1_0) / d1).min((lo - p2_0) / d2);
            prop_assume!(from < to);
            let ple = from + s * (to - from);
            let (p1, p2) = chamber_pressures(g, xf, ps.si(), ple);
            let (p1, p2) = (Pressure::new(p1), Pressure::new(p2));
            let q1 = o(av1, ps, p1) - o(av2, p1, Pressure::ZERO);
            let q2 = o(av1, p2, Pressure::ZERO) - o(av2, ps, p2);
            prop_assert!((q1.si() - g * q2.si()).abs() <= 1e-9 * q1.si().abs());
        }
    }
}
