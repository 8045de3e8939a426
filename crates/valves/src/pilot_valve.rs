//! The DDDC pilot-shifted, spring-centred, normally closed four-way valve
//! (thesis section 6.2.2.1, eqs 6.1–6.5; Appendix II `pcyl4_1.m`).
//!
//! ```text
//!            pilot 1 (Pp1) ─┐        ┌─ pilot 6 (Pp2)
//!                           ▼        ▼
//!        A ◀──┐   ┌───────────────────────────┐   ┌──▶ B
//!             └───│  s < 0 │ centre │  s > 0  │───┘
//!        P ──────▶│ P→B A→T│ closed │ P→A B→T │◀────── T
//!                 └───────────────────────────┘
//! ```
//!
//! ## Spool travel (`pcyl4_1.m`)
//! The pilot pressure difference works against a centring spring of rate
//! `k_s` (1.379e6 Pa per mm) across an overlap `x_o` (0.75 mm), after which the
//! ports open over a travel `x_max` (2.15 mm):
//!
//! ```text
//!   s = sgn(Pp1 − Pp2) · clamp(|Pp1 − Pp2| / k_s − x_o, 0, x_max)      [m]
//! ```
//!
//! so the valve starts to open at `k_s x_o` = 10.34 bar (the datasheet's
//! minimum pilot-shift pressure, 150 psi) and is fully shifted at
//! `k_s (x_o + x_max)` = 40 bar. The spool is quasi-static (no spool mass or
//! damping), as in the thesis.
//!
//! ## Port flows (eqs 6.2–6.5)
//! At full shift the datasheet curves give `Q = K √Δp` with `K_P` for P→A, P→B
//! and `K_T` for A→T, B→T (eqs 6.4, 6.5). For a partial shift the coefficients
//! are scaled by the open fraction of the drilled ports: six holes of radius
//! 2.3855 mm each uncovered as a circular segment of height `|s|`
//! (the commented-out area line of `pcyl4_1.m`), normalised to 1 at `x_max`.
//! The segment area grows as `|s|^{3/2}`, so the flows are C¹ in the pilot
//! pressures — no jump when the valve starts to open. Square roots are the
//! regularised ones of [`crate::orifice`].
//!
//! The thesis uses the spool travel "only when the valve opening area is smaller
//! than that of the needle valve" (Fig 6-10); hydrocyl always uses it, which
//! is the same thing when the valve is wide open (its `K_T` is 14 times the
//! needle valve's coefficient) and the right thing while it opens.

use crate::check::{non_negative, positive, ParameterError};
use crate::orifice::{signed_sqrt_regularised, DEFAULT_DP_TRANSITION};
use hydrocyl_ports::{Position, Power, Pressure, VolumeFlow};
use serde::{Deserialize, Serialize};

/// The port flows of the four-way valve, each positive in the direction named.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FourWayFlows {
    /// P → A \[m³·s⁻¹\].
    pub p_to_a: VolumeFlow,
    /// P → B \[m³·s⁻¹\].
    pub p_to_b: VolumeFlow,
    /// A → T \[m³·s⁻¹\].
    pub a_to_t: VolumeFlow,
    /// B → T \[m³·s⁻¹\].
    pub b_to_t: VolumeFlow,
}

impl FourWayFlows {
    /// Net flow into the valve through port P \[m³·s⁻¹\].
    pub fn into_p(&self) -> VolumeFlow {
        self.p_to_a + self.p_to_b
    }
    /// Net flow out of the valve through port A \[m³·s⁻¹\].
    pub fn out_of_a(&self) -> VolumeFlow {
        self.p_to_a - self.a_to_t
    }
    /// Net flow out of the valve through port B \[m³·s⁻¹\].
    pub fn out_of_b(&self) -> VolumeFlow {
        self.p_to_b - self.b_to_t
    }
    /// Net flow out of the valve through port T \[m³·s⁻¹\].
    pub fn out_of_t(&self) -> VolumeFlow {
        self.a_to_t + self.b_to_t
    }
}

/// The port pressures of the four-way valve.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FourWayPressures {
    /// Supply port P \[Pa\].
    pub p: Pressure,
    /// Tank port T \[Pa\].
    pub t: Pressure,
    /// Work port A (cylinder cap side) \[Pa\].
    pub a: Pressure,
    /// Work port B (cylinder rod side) \[Pa\].
    pub b: Pressure,
}

/// The DDDC pilot-shifted four-way valve.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PilotFourWay {
    /// Centring spring rate `k_s`, pilot pressure per spool travel \[Pa·m⁻¹\].
    pub spring_rate: f64,
    /// Overlap `x_o` \[m\]: travel before any port opens.
    pub overlap: Position,
    /// Opening travel `x_max` \[m\] beyond the overlap to full shift.
    pub stroke: Position,
    /// Radius of each drilled port hole \[m\].
    pub hole_radius: Position,
    /// Full-shift flow coefficient P→A and P→B, `K_P` (eq 6.4) \[m³·s⁻¹·Pa^-½\].
    pub k_p: f64,
    /// Full-shift flow coefficient A→T and B→T, `K_T` (eq 6.5) \[m³·s⁻¹·Pa^-½\].
    pub k_t: f64,
    /// Transition pressure of the regularised square root \[Pa\].
    pub dp_transition: Pressure,
}

impl Default for PilotFourWay {
    fn default() -> Self {
        Self::dddc()
    }
}

/// Area of a circular segment of height `h` in a circle of radius `r` \[m²\].
fn segment_area(h: f64, r: f64) -> f64 {
    let h = h.clamp(0.0, 2.0 * r);
    r * r * ((r - h) / r).clamp(-1.0, 1.0).acos() - (r - h) * (2.0 * r * h - h * h).max(0.0).sqrt()
}

impl PilotFourWay {
    /// The `wang-hybrid` DDDC valve: spring 1.379e6 Pa/mm, overlap 0.75 mm,
    /// stroke 2.15 mm, hole radius 2.3855 mm (`pcyl4_1.m`), `K_P` = 1.0644e-6,
    /// `K_T` = 1.3730e-6 m³·s⁻¹·Pa^-½ (eqs 6.4, 6.5).
    pub fn dddc() -> Self {
        Self {
            spring_rate: 1.379e9,
            overlap: Position::from_mm(0.75),
            stroke: Position::from_mm(2.15),
            hole_radius: Position::from_mm(2.3855),
            k_p: 1.0644e-6,
            k_t: 1.3730e-6,
            dp_transition: DEFAULT_DP_TRANSITION,
        }
    }

    /// Checks every parameter is finite and positive (the overlap may be
    /// zero: a critically lapped spool that opens at any pilot difference).
    pub fn validate(&self) -> Result<(), ParameterError> {
        const C: &str = "pilot four-way valve";
        positive(C, "spring_rate", self.spring_rate)?;
        non_negative(C, "overlap", self.overlap.si())?;
        positive(C, "stroke", self.stroke.si())?;
        positive(C, "hole_radius", self.hole_radius.si())?;
        positive(C, "k_p", self.k_p)?;
        positive(C, "k_t", self.k_t)?;
        positive(C, "dp_transition", self.dp_transition.si())
    }

    /// Pilot pressure difference at which the ports start to open, `k_s x_o` \[Pa\].
    pub fn shift_pressure(&self) -> Pressure {
        Pressure::new(self.spring_rate * self.overlap.si())
    }

    /// Pilot pressure difference at full shift, `k_s (x_o + x_max)` \[Pa\].
    pub fn full_shift_pressure(&self) -> Pressure {
        Pressure::new(self.spring_rate * (self.overlap + self.stroke).si())
    }

    /// Signed spool travel past the overlap, + towards P→A/B→T (when
    /// `Pp1 > Pp2`) \[m\].
    #[inline]
    pub fn spool_travel(&self, pp1: Pressure, pp2: Pressure) -> Position {
        let d = (pp1 - pp2).si();
        let s = (d.abs() / self.spring_rate - self.overlap.si()).clamp(0.0, self.stroke.si());
        Position::new(s * d.signum())
    }

    /// `∂s/∂(pp1 − pp2)` of [`PilotFourWay::spool_travel`] \[m·Pa⁻¹\]:
    /// `1/spring_rate` while the spool moves, zero on the overlap and at the
    /// end of its stroke (the one-sided slope of the branch it is on).
    #[inline]
    pub fn spool_travel_slope(&self, pp1: Pressure, pp2: Pressure) -> f64 {
        let u = (pp1 - pp2).si().abs() / self.spring_rate - self.overlap.si();
        if u > 0.0 && u < self.stroke.si() {
            1.0 / self.spring_rate
        } else {
            0.0
        }
    }

    /// `∂y/∂(pp1 − pp2)` of [`PilotFourWay::opening`] \[Pa⁻¹\]: the hole's
    /// chord `2√(2rh − h²)` at travel `h` over the full segment area, times
    /// [`PilotFourWay::spool_travel_slope`].
    #[inline]
    pub fn opening_slope(&self, pp1: Pressure, pp2: Pressure) -> f64 {
        let ds = self.spool_travel_slope(pp1, pp2);
        if ds == 0.0 {
            return 0.0;
        }
        let h = self.spool_travel(pp1, pp2).si().abs();
        let r = self.hole_radius.si();
        let chord = 2.0 * (2.0 * r * h - h * h).max(0.0).sqrt();
        chord / segment_area(self.stroke.si(), r) * ds
    }

    /// Open fraction of the ports in `[0, 1]` at spool travel `s` (sign ignored).
    #[inline]
    pub fn open_fraction(&self, s: Position) -> f64 {
        let r = self.hole_radius.si();
        segment_area(s.si().abs(), r) / self.full_open_area()
    }

    /// The ports' open area at full stroke (the circle segment the fraction
    /// is taken of) \[m²\].
    #[inline]
    pub fn full_open_area(&self) -> f64 {
        segment_area(self.stroke.si(), self.hole_radius.si())
    }

    /// Signed opening in `[-1, 1]` from the pilot pressures: + extending state
    /// (P→A, B→T), − retracting state (P→B, A→T), 0 centred.
    #[inline]
    pub fn opening(&self, pp1: Pressure, pp2: Pressure) -> f64 {
        self.opening_given_full_area(pp1, pp2, self.full_open_area())
    }

    /// [`PilotFourWay::opening`] with [`PilotFourWay::full_open_area`]
    /// given (a caller that asks often computes it once): the same value, bit
    /// for bit, when `full` is `self.full_open_area()`.
    #[inline]
    pub fn opening_given_full_area(&self, pp1: Pressure, pp2: Pressure, full: f64) -> f64 {
        let s = self.spool_travel(pp1, pp2).si();
        if s == 0.0 {
            // centred: no segment to compute (the signed zero as below)
            return 0.0 * s.signum();
        }
        segment_area(s.abs(), self.hole_radius.si()) / full * s.signum()
    }

    /// The four port flows at pilot pressures `pp1`, `pp2` and port pressures `p`.
    #[inline]
    pub fn flows(&self, pp1: Pressure, pp2: Pressure, p: &FourWayPressures) -> FourWayFlows {
        let y = self.opening(pp1, pp2);
        let xt = self.dp_transition.si();
        let q = |k: f64, up: Pressure, down: Pressure| {
            VolumeFlow::new(k * y.abs() * signed_sqrt_regularised((up - down).si(), xt))
        };
        if y > 0.0 {
            FourWayFlows {
                p_to_a: q(self.k_p, p.p, p.a),
                b_to_t: q(self.k_t, p.b, p.t),
                ..FourWayFlows::default()
            }
        } else if y < 0.0 {
            FourWayFlows {
                p_to_b: q(self.k_p, p.p, p.b),
                a_to_t: q(self.k_t, p.a, p.t),
                ..FourWayFlows::default()
            }
        } else {
            FourWayFlows::default()
        }
    }

    /// The return-path coefficient A→T (`y < 0`) or B→T (`y > 0`) at signed
    /// opening `y`, `K_T |y|` \[m³·s⁻¹·Pa^-½\].
    #[inline]
    pub fn return_coefficient(&self, y: f64) -> f64 {
        self.k_t * y.abs()
    }

    /// Hydraulic power dissipated in the valve \[W\] (never negative).
    pub fn power_dissipated(&self, pp1: Pressure, pp2: Pressure, p: &FourWayPressures) -> Power {
        let f = self.flows(pp1, pp2, p);
        f.p_to_a * (p.p - p.a)
            + f.p_to_b * (p.p - p.b)
            + f.a_to_t * (p.a - p.t)
            + f.b_to_t * (p.b - p.t)
    }

    /// Switching function: `(Pp1 − Pp2) − k_s x_o` \[Pa\]; rising through zero
    /// when the valve starts to shift into the extending state.
    #[inline]
    pub fn extend_shift_margin(&self, pp1: Pressure, pp2: Pressure) -> f64 {
        (pp1 - pp2 - self.shift_pressure()).si()
    }

    /// Switching function: `(Pp2 − Pp1) − k_s x_o` \[Pa\]; rising through zero
    /// when the valve starts to shift into the retracting state.
    #[inline]
    pub fn retract_shift_margin(&self, pp1: Pressure, pp2: Pressure) -> f64 {
        (pp2 - pp1 - self.shift_pressure()).si()
    }

    /// Switching function: `|Pp1 − Pp2| − k_s (x_o + x_max)` \[Pa\]; rising
    /// through zero when the spool reaches its end.
    #[inline]
    pub fn full_shift_margin(&self, pp1: Pressure, pp2: Pressure) -> f64 {
        ((pp1 - pp2).abs() - self.full_shift_pressure()).si()
    }
}

/// Coefficient of two turbulent orifices in series, `K₁K₂/√(K₁² + K₂²)`
/// \[m³·s⁻¹·Pa^-½\]: exact for `Q = K √Δp` through both (the same `Q` drops
/// `Q²/K₁²` and `Q²/K₂²`), used for the four-way valve's return port and the
/// needle valve joined by a short pipe (section 6.2.2.3). Zero when either is.
#[inline]
pub fn series_coefficient(k1: f64, k2: f64) -> f64 {
    if k1 <= 0.0 || k2 <= 0.0 {
        0.0
    } else {
        k1 * k2 / k1.hypot(k2)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn ports(p: f64, t: f64, a: f64, b: f64) -> FourWayPressures {
        FourWayPressures {
            p: Pressure::from_bar(p),
            t: Pressure::from_bar(t),
            a: Pressure::from_bar(a),
            b: Pressure::from_bar(b),
        }
    }

    #[test]
    fn shift_pressures_match_datasheet() {
        let v = PilotFourWay::dddc();
        assert!((v.shift_pressure().psi() - 150.0).abs() < 0.1);
        assert!((v.full_shift_pressure().bar() - 39.99).abs() < 0.01);
        assert!(v.validate().is_ok());
    }

    #[test]
    fn centred_below_minimum_pilot_pressure() {
        let v = PilotFourWay::dddc();
        let f = v.flows(
            Pressure::from_bar(10.0),
            Pressure::ZERO,
            &ports(50.0, 0.0, 20.0, 20.0),
        );
        assert_eq!(f, FourWayFlows::default());
        assert_eq!(v.opening(Pressure::from_bar(10.0), Pressure::ZERO), 0.0);
    }

    #[test]
    fn full_shift_reproduces_eqs_6_4_and_6_5() {
        let v = PilotFourWay::dddc();
        let p = ports(30.0, 0.0, 10.0, 20.0);
        let f = v.flows(Pressure::from_bar(60.0), Pressure::ZERO, &p);
        assert!((f.p_to_a.si() - 1.0644e-6 * 20.0e5f64.sqrt()).abs() < 1e-15);
        assert!((f.b_to_t.si() - 1.3730e-6 * 20.0e5f64.sqrt()).abs() < 1e-15);
        assert_eq!(f.p_to_b, VolumeFlow::ZERO);
        assert_eq!(f.a_to_t, VolumeFlow::ZERO);
        let r = v.flows(Pressure::ZERO, Pressure::from_bar(60.0), &p);
        assert!((r.p_to_b.si() - 1.0644e-6 * 10.0e5f64.sqrt()).abs() < 1e-15);
        assert!((r.a_to_t.si() - 1.3730e-6 * 10.0e5f64.sqrt()).abs() < 1e-15);
        // mass balance across the valve body: in through P and T = out through A and B
        let net = r.into_p() - r.out_of_t() - r.out_of_a() - r.out_of_b();
        assert!(net.si().abs() < 1e-18);
    }

    #[test]
    fn segment_area_closed_forms() {
        let r: f64 = 2.0;
        assert!(segment_area(0.0, r).abs() < 1e-15);
        assert!((segment_area(r, r) - std::f64::consts::PI * r * r / 2.0).abs() < 1e-12);
        assert!((segment_area(2.0 * r, r) - std::f64::consts::PI * r * r).abs() < 1e-12);
        // small h: A ≈ (4/3) √(2r) h^{3/2}
        let h: f64 = 1e-6;
        let approx = 4.0 / 3.0 * (2.0 * r).sqrt() * h.powf(1.5);
        assert!((segment_area(h, r) / approx - 1.0).abs() < 1e-3);
    }

    #[test]
    fn series_coefficient_is_exact_for_square_root_law() {
        let (k1, k2) = (1.3730e-6, 9.8e-8);
        let k = series_coefficient(k1, k2);
        let q = k * 3.0e5f64.sqrt();
        let dp1 = (q / k1).powi(2);
        let dp2 = (q / k2).powi(2);
        assert!((dp1 + dp2 - 3.0e5).abs() < 1e-6);
        assert_eq!(series_coefficient(0.0, k2), 0.0);
    }

    proptest! {
        #[test]
        fn opening_is_the_signed_open_fraction_bit_for_bit(d in -6.0e6f64..6.0e6, centred in any::<bool>(), neg in any::<bool>()) {
            // the centred spool (no segment computed) keeps the zero's sign
            let v = PilotFourWay::dddc();
            let d = if centred { if neg { -1.0 } else { 1.0 } } else { d };
            let s = v.spool_travel(Pressure::new(d), Pressure::ZERO);
            let by_fraction = v.open_fraction(s) * s.signum() * f64::from(s.si() != 0.0);
            let y = v.opening(Pressure::new(d), Pressure::ZERO);
            prop_assert_eq!(y.to_bits(), by_fraction.to_bits());
            let given = v.opening_given_full_area(Pressure::new(d), Pressure::ZERO, v.full_open_area());
            prop_assert_eq!(given.to_bits(), y.to_bits());
        }

        #[test]
        fn opening_is_continuous_odd_and_bounded(d in -6.0e6f64..6.0e6) {
            let v = PilotFourWay::dddc();
            let y = v.opening(Pressure::new(d), Pressure::ZERO);
            let y2 = v.opening(Pressure::ZERO, Pressure::new(d));
            prop_assert!((-1.0..=1.0).contains(&y));
            prop_assert!((y + y2).abs() < 1e-15);
            let yh = v.opening(Pressure::new(d + 10.0), Pressure::ZERO);
            prop_assert!((yh - y).abs() < 1e-4);
            if d.abs() > v.full_shift_pressure().si() { prop_assert!((y.abs() - 1.0).abs() < 1e-12); }
        }

        #[test]
        fn dissipates_and_flows_downhill(pp in -1.0e7f64..1.0e7, a in 0.0f64..1.0e7, b in 0.0f64..1.0e7) {
            let v = PilotFourWay::dddc();
            let p = FourWayPressures { p: Pressure::new(8.0e6), t: Pressure::ZERO, a: Pressure::new(a), b: Pressure::new(b) };
            prop_assert!(v.power_dissipated(Pressure::new(pp), Pressure::ZERO, &p).si() >= 0.0);
        }
    }

    #[test]
    fn switching_functions_bracket_the_shift() {
        let v = PilotFourWay::dddc();
        let lo = Pressure::from_bar(10.0);
        let hi = Pressure::from_bar(10.7);
        assert!(v.extend_shift_margin(lo, Pressure::ZERO) < 0.0);
        assert!(v.extend_shift_margin(hi, Pressure::ZERO) > 0.0);
        assert!(v.retract_shift_margin(Pressure::ZERO, hi) > 0.0);
        assert!(v.retract_shift_margin(hi, Pressure::ZERO) < 0.0);
        assert!(v.full_shift_margin(Pressure::from_bar(41.0), Pressure::ZERO) > 0.0);
        assert!(v.opening(hi, Pressure::ZERO) > 0.0);
    }
}
