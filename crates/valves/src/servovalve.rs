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
    /// A parameter outside its physical range.
    #[error("servovalve parameter `{name}` = {value} is out of range: {reason}")]
    OutOfRange {
        /// Parameter name.
        name: &'static str,
        /// The value given.
        value: f64,
        /// What it must satisfy.
        reason: &'static str,
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
        self.orifice
            .validate("servovalve")
            .map_err(|e| ServovalveError::OutOfRange {
                // the servovalve's names for the orifice's parameters
                name: match e.name {
                    "cd" => "discharge_coefficient",
                    "dp_transition" => "regularisation",
                    other => other,
                },
                value: e.value,
                reason: e.reason,
            })?;
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
        // the orifice coefficient once for the four edges
        let c = o.coefficient();
        // away from null one pair of edges is shut: no square roots for it
        let flow = |area: Area, up, down| {
            if area.si() == 0.0 {
                VolumeFlow::ZERO
            } else {
                o.flow_with_coefficient(c, area, up, down)
            }
        };
        let q_p1 = flow(a.av1, pp, pa);
        let q_1t = flow(a.av2, pa, pt);
        let q_2t = flow(a.av1, pb, pt);
        let q_p2 = flow(a.av2, pp, pb);
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

/// Supply droop (catalog `supply_droop`): the supply port sees
/// `Ps = Ps0 − Rs Q_P`, a source pressure `Ps0` behind a linear resistance
/// `Rs` (a pressure-compensated pump that sags with flow, hoses, a filter).
///
/// `Q_P` depends on `Ps` through the two metering edges P→A and P→B, so `Ps`
/// is the root of `g(Ps) = Ps + Rs Q_P(Ps) − Ps0`. `Q_P` is non-decreasing in
/// `Ps` (each edge's flow rises with its upstream pressure), so `g' ≥ 1`:
/// the root is unique, and `|Ps − root| ≤ |g(Ps)|` gives a guaranteed error
/// bound. It is bracketed by `[min(Ps0, pa, pb), max(Ps0, pa, pb)]` (at the
/// lower end no edge can draw from P, at the upper end none can push into
/// it). A Newton step on the analytic `g'` is taken when it stays inside the
/// current bracket, a bisection otherwise (a safeguarded Newton), so the
/// iteration cannot leave the bracket or stall.
///
/// The solution is Lipschitz in the chamber pressures and the spool
/// position: by the implicit function theorem `∂Ps/∂pa = Rs G_a / (1 + Rs
/// (G_a + G_b))` with `G` the edges' (finite, regularised) conductances, so
/// `0 ≤ ∂Ps/∂pa < 1`; the right-hand side of an integrator stays Lipschitz.
/// A negative `Q_P` (flow pushed back into the supply) raises `Ps` above
/// `Ps0`: the law is used as written, no check valve is assumed.
impl Metering {
    /// The supply pressure at port P: the root of `Ps = ps0 − rs Q_P(Ps)`
    /// (see the block above), to within `1e-12` of the pressure scale.
    /// `rs = 0` returns `ps0`; a non-finite input gives `NaN` (never a
    /// clamped value), which the integrator reports.
    pub fn drooped_supply(
        &self,
        xs: Position,
        ps0: Pressure,
        rs: f64,
        pa: Pressure,
        pb: Pressure,
    ) -> Pressure {
        let (p0, a, b) = (ps0.si(), pa.si(), pb.si());
        if rs == 0.0 {
            return ps0;
        }
        if !(rs.is_finite() && rs > 0.0 && p0.is_finite() && a.is_finite() && b.is_finite()) {
            return Pressure::new(f64::NAN);
        }
        let areas = self.areas(xs);
        let o = &self.orifice;
        let g = |ps: f64| -> (f64, f64) {
            let (pp, pa, pb) = (Pressure::new(ps), Pressure::new(a), Pressure::new(b));
            let q = o.flow(areas.av1, pp, pa).si() + o.flow(areas.av2, pp, pb).si();
            let dq = o.conductance(areas.av1, pp, pa) + o.conductance(areas.av2, pp, pb);
            (ps + rs * q - p0, 1.0 + rs * dq)
        };
        let (mut lo, mut hi) = (p0.min(a).min(b), p0.max(a).max(b));
        let tol = 1e-12 * (p0.abs() + a.abs() + b.abs()).max(1.0);
        let mut x = p0.clamp(lo, hi);
        for _ in 0..200 {
            let (gx, dg) = g(x);
            if gx.abs() <= tol {
                break;
            }
            if gx < 0.0 {
                lo = x;
            } else {
                hi = x;
            }
            if hi - lo <= tol {
                x = 0.5 * (lo + hi);
                break;
            }
            let newton = x - gx / dg;
            x = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
        }
        Pressure::new(x)
    }

    /// [`Metering::flows`] with the supply drooping behind resistance `rs`
    /// \[Pa·s·m⁻³\] from source pressure `ps0`: the flows at the drooped
    /// supply pressure (returned alongside), with the droop's loss
    /// `rs Q_P²` added to `dissipated`.
    #[inline]
    pub fn flows_drooped(
        &self,
        xs: Position,
        ps0: Pressure,
        rs: f64,
        pt: Pressure,
        pa: Pressure,
        pb: Pressure,
    ) -> (MeteringFlows, Pressure) {
        let ps = self.drooped_supply(xs, ps0, rs, pa, pb);
        let mut f = self.flows(xs, ps, pt, pa, pb);
        f.dissipated += rs * f.qp.si() * f.qp.si();
        (f, ps)
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
    fn drooped_supply_solves_the_implicit_law() {
        let v = valve();
        let ps0 = Pressure::new(7.0e6);
        let rs = 3.0e9;
        for &(xs, pa, pb) in &[
            (0.2e-3, 3.0e6, 1.0e6),
            (-0.3e-3, 2.0e6, 5.0e6),
            (0.0, 3.5e6, 3.5e6),
            (1e-6, 6.9995e6, 0.5e6),
            (0.375e-3, 7.5e6, 0.0),
        ] {
            let (xs, pa, pb) = (Position::new(xs), Pressure::new(pa), Pressure::new(pb));
            let (f, ps) = v.flows_drooped(xs, ps0, rs, Pressure::ZERO, pa, pb);
            // the law holds at the root, to the solver's tolerance
            let resid = ps.si() - (ps0.si() - rs * f.qp.si());
            assert!(resid.abs() < 1e-4, "{xs:?} {pa:?} {pb:?}: {resid}");
            // and the flows are those of the plain valve at that supply
            assert_eq!(f.qa, v.flows(xs, ps, Pressure::ZERO, pa, pb).qa);
        }
        // no resistance: the source pressure
        let p = v.drooped_supply(Position::ZERO, ps0, 0.0, ps0 * 0.5, ps0 * 0.5);
        assert_eq!(p, ps0);
        // more resistance, more droop, while the valve draws flow
        let at = |rs: f64| {
            v.drooped_supply(
                Position::new(0.2e-3),
                ps0,
                rs,
                Pressure::new(3e6),
                Pressure::new(1e6),
            )
            .si()
        };
        assert!(at(1e9) < ps0.si() && at(1e10) < at(1e9));
        // one edge open and outside the regularisation: the closed form
        // s² + k s − (Ps0 − pa) = 0 with s = √(Ps − pa), k = rs Cd √(2/ρ) Av1
        let xs = Position::new(0.375e-3);
        let a = v.areas(xs).av1.si();
        let k = 1e10 * v.orifice.coefficient() * a;
        let s = 0.5 * (-k + (k * k + 4.0 * (7.0e6 - 3.0e6)).sqrt());
        let want = 3.0e6 + s * s;
        let got = v.drooped_supply(xs, ps0, 1e10, Pressure::new(3e6), Pressure::new(1e6));
        assert!((got.si() - want).abs() < 1e-3, "{got:?} vs {want}");
        // non-finite input: NaN, not a clamped number
        let nan = v.drooped_supply(xs, ps0, rs, Pressure::new(f64::NAN), Pressure::ZERO);
        assert!(nan.si().is_nan());
    }

    #[test]
    fn drooped_supply_moves_less_than_the_chamber_pressure() {
        // the Lipschitz bound 0 <= dPs/dpa < 1 of the docs, by finite differences
        let v = valve();
        let ps0 = Pressure::new(7.0e6);
        for &xs in &[0.0, 0.1e-3, -0.1e-3, 0.375e-3] {
            for k in 0..20 {
                let pa = 0.35e6 * k as f64;
                let f = |pa: f64| {
                    v.drooped_supply(
                        Position::new(xs),
                        ps0,
                        5e9,
                        Pressure::new(pa),
                        Pressure::new(2e6),
                    )
                    .si()
                };
                let d = (f(pa + 10.0) - f(pa)) / 10.0;
                assert!((-1e-6..1.0).contains(&d), "xs {xs} pa {pa}: {d}");
            }
        }
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
        let mut m = valve();
        m.orifice.cd = 1.2;
        let e = m.validate().unwrap_err();
        assert!(e.to_string().contains("discharge_coefficient"), "{e}");
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
