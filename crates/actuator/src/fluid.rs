//! Oil at low pressure: a liquid carrying entrained (undissolved) air.
//!
//! The thesis (eqs 2.10–2.15, 6.12–6.21) writes every volume with one
//! constant bulk modulus `B`, `dp/dt = B/V (ΣQ − dV/dt)`. Below atmospheric
//! pressure that law has no floor: a chamber that is stretched with its ports
//! shut goes to any negative pressure, including below absolute zero. Real
//! hydraulic oil carries a fraction of a per cent of undissolved air, whose
//! volume grows as the pressure falls; that is the textbook low-pressure
//! fluid model (the mixture of a liquid with a polytropic gas, as in the
//! entrained-air options of Simscape's isothermal liquid, Amesim's and
//! Hopsan's fluid models).
//!
//! **The mixture.** Per unit of fluid content (the volume it fills at
//! atmospheric pressure, gauge `p = 0`), the mixture fills
//!
//! ```text
//! v(p) = (1 − α) e^(−p/B) + α (p_a / P)^(1/n),     P = p + p_a  (absolute)
//! ```
//!
//! with `α` the air's volume fraction at atmospheric pressure, `n` its
//! polytropic index (1 isothermal, 1.4 adiabatic) and `p_a` the atmospheric
//! (absolute) pressure at gauge zero. The effective bulk modulus is
//! `B_eff = −v / (dv/dp)`:
//!
//! ```text
//! B_eff(p) = [(1 − α) e^(−p/B) + α (p_a/P)^(1/n)] / [(1 − α) e^(−p/B)/B + α (p_a/P)^(1/n)/(n P)]
//! ```
//!
//! and the mass balance of a volume `V` with a (local) volume inflow `Q`,
//! `d(V/v)/dt = Q/v`, is exactly `dp/dt = B_eff(p)/V (Q − dV/dt)`: the
//! fundamental form with `B` replaced by `B_eff(p)`. With `α = 0` every
//! function here returns the constant-`B` model bit for bit.
//!
//! **The floor.** As `P → 0` the air's volume grows without bound and
//! `B_eff → n P`: no finite outflow takes the pressure to absolute zero, so
//! with `α > 0` a volume cannot go below −`p_a` gauge. For the integrator's
//! trial states the absolute pressure in the gas law is the hyperbola
//! `P_eff = (P + √(P² + 4s²))/2` with `s` = [`ABSOLUTE_FLOOR_SCALE`] (1 Pa):
//! `P (1 + s²/P²)` above zero (a relative 1e-10 at 0.1 bar absolute) and
//! `s²/|P|` > 0 below, so the law stays defined, smooth and mass-conserving
//! for any state.
//!
//! **What it leaves out.** Air dissolving and coming out of solution (the
//! fraction is constant), the oil's vapour pressure (mineral oil's is of the
//! order of pascals, below the gas floor's range), and the heat exchange that
//! makes `n` vary with speed.

use serde::{Deserialize, Serialize};

use crate::ActuatorError;

/// Scale `s` of the hyperbola that keeps the gas law's absolute pressure
/// positive for any state (module docs) \[Pa\].
pub const ABSOLUTE_FLOOR_SCALE: f64 = 1.0;

/// Standard atmospheric pressure \[Pa\] (absolute), the default `p_a`.
pub const STANDARD_ATMOSPHERE: f64 = 101_325.0;

/// Entrained (undissolved) air in the oil of a volume (module docs).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EntrainedAir {
    /// `α`: volume fraction of undissolved air at atmospheric pressure \[-\];
    /// 0 is the pure liquid (the constant-`B` model).
    pub fraction: f64,
    /// `n`: polytropic index of the air \[-\] (1 isothermal, 1.4 adiabatic).
    pub polytropic_index: f64,
    /// `p_a`: the absolute pressure at gauge zero \[Pa\].
    pub atmospheric_pressure: f64,
}

impl Default for EntrainedAir {
    fn default() -> Self {
        Self::NONE
    }
}

impl EntrainedAir {
    /// No air: the constant-bulk-modulus liquid.
    pub const NONE: Self = Self {
        fraction: 0.0,
        polytropic_index: 1.0,
        atmospheric_pressure: STANDARD_ATMOSPHERE,
    };

    /// Isothermal air at volume fraction `fraction`, standard atmosphere.
    pub fn isothermal(fraction: f64) -> Self {
        Self {
            fraction,
            ..Self::NONE
        }
    }

    /// `true` when the fluid carries no air (the constant-`B` model).
    #[inline]
    pub fn is_none(&self) -> bool {
        self.fraction == 0.0
    }

    /// Checks `0 ≤ α < 1`, `1 ≤ n ≤ 1.4`, `p_a > 0`.
    pub fn validate(&self) -> Result<(), ActuatorError> {
        if !(self.fraction.is_finite() && (0.0..1.0).contains(&self.fraction)) {
            return Err(ActuatorError::OutOfRange {
                name: "air_fraction",
                value: self.fraction,
                range: "[0, 1)",
            });
        }
        if !(self.polytropic_index.is_finite() && (1.0..=1.4).contains(&self.polytropic_index)) {
            return Err(ActuatorError::OutOfRange {
                name: "polytropic_index",
                value: self.polytropic_index,
                range: "[1, 1.4]",
            });
        }
        crate::positive("atmospheric_pressure", self.atmospheric_pressure)
    }

    /// The gas law's absolute pressure `P_eff`, its slope `dP_eff/dp` and
    /// the slope's derivative (module docs).
    #[inline]
    fn absolute(&self, p: f64) -> (f64, f64, f64) {
        let s = ABSOLUTE_FLOOR_SCALE;
        let big = p + self.atmospheric_pressure;
        let r = big.hypot(2.0 * s);
        // (P + r)/2 loses every digit for P ≪ 0: 2 s² / (r − P) is the same value
        let soft = if big >= 0.0 {
            0.5 * (big + r)
        } else {
            2.0 * s * s / (r - big)
        };
        (soft, soft / r, 2.0 * s * s / (r * r * r))
    }

    /// `v(p)`, `dv/dp`, `d²v/dp²` for liquid bulk modulus `b` at gauge `p`.
    fn volume_terms(&self, b: f64, p: f64) -> (f64, f64, f64) {
        let a = self.fraction;
        let k = 1.0 / self.polytropic_index;
        let liquid = (1.0 - a) * (-p / b).exp();
        let (big, s, ds) = self.absolute(p);
        let gas = a * (self.atmospheric_pressure / big).powf(k);
        let v = liquid + gas;
        let dv = -liquid / b - k * gas / big * s;
        let ddv = liquid / (b * b) + k * (k + 1.0) * gas / (big * big) * s * s - k * gas / big * ds;
        (v, dv, ddv)
    }

    /// `v(p)`: the volume filled by one unit of fluid content (its volume at
    /// gauge 0) at gauge pressure `p` \[-\]; `b` is the liquid's bulk modulus.
    pub fn specific_volume(&self, b: f64, p: f64) -> f64 {
        if self.is_none() {
            return (-p / b).exp();
        }
        self.volume_terms(b, p).0
    }

    /// The effective bulk modulus `B_eff(p) = −v/(dv/dp)` \[Pa\]; `b` with no air.
    pub fn bulk_modulus(&self, b: f64, p: f64) -> f64 {
        if self.is_none() {
            return b;
        }
        let (v, dv, _) = self.volume_terms(b, p);
        -v / dv
    }

    /// `(B_eff(p), dB_eff/dp)` \[Pa, -\] (the slope for the analytic Jacobian).
    pub fn bulk_modulus_and_slope(&self, b: f64, p: f64) -> (f64, f64) {
        if self.is_none() {
            return (b, 0.0);
        }
        let (v, dv, ddv) = self.volume_terms(b, p);
        (-v / dv, -1.0 + v * ddv / (dv * dv))
    }

    /// `C(p) = ∫₀ᵖ dp'/B_eff(p') = −ln v(p)` \[-\]: the content a unit volume
    /// gains between gauge 0 and `p` (`p/B` with no air). A volume's mass
    /// balance over a window is `∫Q dt = Δ(V C) − ∫C dV/dt dt + ΔV`.
    pub fn compliance(&self, b: f64, p: f64) -> f64 {
        if self.is_none() {
            return p / b;
        }
        -self.volume_terms(b, p).0.ln()
    }

    /// The energy stored in a volume `volume` of this fluid at gauge `p`,
    /// counted from gauge 0 \[J\]: `V e(p)`, `e(p) = ∫₀ᵖ p'/B_eff(p') dp'`
    /// (`½ V p²/B` with no air). Its rate at constant `V` is the compression
    /// power `p V/B_eff dp/dt` the circuit books, so the ledger's storage
    /// check closes on it; with air, `e` is integrated numerically in
    /// `u = ln P_eff` (Gauss–Legendre, panels of 0.5 in `u`).
    pub fn stored_energy(&self, b: f64, p: f64, volume: f64) -> f64 {
        if self.is_none() {
            return 0.5 * volume * p * p / b;
        }
        let s2 = ABSOLUTE_FLOOR_SCALE * ABSOLUTE_FLOOR_SCALE;
        let pa = self.atmospheric_pressure;
        let (u0, u1) = (pa.ln(), self.absolute(p).0.ln());
        let panels = ((u1 - u0).abs() / 0.5).ceil().max(1.0);
        let h = (u1 - u0) / panels;
        // 4-point Gauss–Legendre nodes and weights on [−1, 1]
        const X: [f64; 4] = [
            -0.861_136_311_594_052_6,
            -0.339_981_043_584_856_3,
            0.339_981_043_584_856_3,
            0.861_136_311_594_052_6,
        ];
        const W: [f64; 4] = [
            0.347_854_845_137_453_9,
            0.652_145_154_862_546_1,
            0.652_145_154_862_546_1,
            0.347_854_845_137_453_9,
        ];
        let mut e = 0.0;
        for k in 0..panels as usize {
            let mid = u0 + (k as f64 + 0.5) * h;
            for (x, w) in X.iter().zip(W) {
                let pe = (mid + 0.5 * h * x).exp();
                // the gauge pressure whose P_eff is pe, and dp/du
                let gauge = pe - s2 / pe - pa;
                let dp_du = pe + s2 / pe;
                e += w * 0.5 * h * gauge / self.bulk_modulus(b, gauge) * dp_du;
            }
        }
        volume * e
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const B: f64 = 7.0e8;

    #[test]
    fn no_air_is_the_constant_bulk_modulus_model_exactly() {
        let f = EntrainedAir::NONE;
        for p in [-3e5, -1e5, 0.0, 1e5, 2e7] {
            assert_eq!(f.bulk_modulus(B, p), B);
            assert_eq!(f.bulk_modulus_and_slope(B, p), (B, 0.0));
            assert_eq!(f.compliance(B, p), p / B);
            assert_eq!(f.stored_energy(B, p, 1e-4), 0.5 * 1e-4 * p * p / B);
        }
    }

    /// The limit α → 0 is the constant-B model, continuously: `B/B_eff − 1`
    /// is first order in α, with the slope `(p_a/P)^(1/n) (B/(n P) − 1) e^(p/B)`.
    #[test]
    fn small_air_tends_to_the_liquid() {
        for p in [-5e4, 0.0, 1e6, 2e7] {
            let big = p + STANDARD_ATMOSPHERE;
            let slope = STANDARD_ATMOSPHERE / big * (B / big - 1.0) * (p / B).exp();
            for a in [1e-7, 1e-9, 1e-11] {
                let got = (B / EntrainedAir::isothermal(a).bulk_modulus(B, p) - 1.0) / a;
                assert!(
                    (got / slope - 1.0).abs() < 1e-3,
                    "{p} {a}: {got} vs {slope}"
                );
            }
        }
    }

    /// Pure gas (α → 1 with a rigid liquid): B_eff = n P, the polytropic gas.
    #[test]
    fn the_air_alone_is_a_polytropic_gas() {
        for n in [1.0, 1.4] {
            let f = EntrainedAir {
                fraction: 1.0 - 1e-12,
                polytropic_index: n,
                atmospheric_pressure: STANDARD_ATMOSPHERE,
            };
            for p in [-9e4, 0.0, 5e5] {
                let want = n * (p + STANDARD_ATMOSPHERE);
                let got = f.bulk_modulus(1e30, p);
                assert!((got / want - 1.0).abs() < 1e-7, "{n} {p}: {got} vs {want}");
            }
        }
    }

    /// At atmospheric pressure, the textbook mixture:
    /// 1/B_eff = (1 − α)/B + α/(n p_a).
    #[test]
    fn at_atmosphere_compliances_add() {
        let f = EntrainedAir::isothermal(0.005);
        let want = 1.0 / ((1.0 - 0.005) / B + 0.005 / STANDARD_ATMOSPHERE);
        assert!((f.bulk_modulus(B, 0.0) / want - 1.0).abs() < 1e-9);
    }

    /// The slope and the compliance against finite differences of B_eff and
    /// a quadrature of 1/B_eff.
    #[test]
    fn slope_and_compliance_agree_with_b_eff() {
        let f = EntrainedAir {
            fraction: 0.01,
            polytropic_index: 1.2,
            atmospheric_pressure: STANDARD_ATMOSPHERE,
        };
        for p in [-1.0e5, -9e4, -5e4, 0.0, 2e5, 1e7] {
            let h = 1e-3 * (p + STANDARD_ATMOSPHERE).abs().max(1.0);
            let fd = (f.bulk_modulus(B, p + h) - f.bulk_modulus(B, p - h)) / (2.0 * h);
            let (_, slope) = f.bulk_modulus_and_slope(B, p);
            assert!(
                (fd - slope).abs() < 1e-4 * slope.abs().max(1.0),
                "{p}: {fd} vs {slope}"
            );
            let dc = (f.compliance(B, p + h) - f.compliance(B, p - h)) / (2.0 * h);
            assert!((dc * f.bulk_modulus(B, p) - 1.0).abs() < 1e-5, "{p}");
        }
    }

    /// The stored energy's slope at constant volume is the compression
    /// power per unit pressure rate: d(V e)/dp = p V / B_eff; and with a rigid
    /// liquid and isothermal air, `e` has the closed form
    /// of Boyle's law (partial fractions).
    #[test]
    fn stored_energy_is_the_compression_work() {
        let f = EntrainedAir::isothermal(0.005);
        let v = 1e-4;
        for p in [-9.5e4, -8e4, -2e4, 1e5, 1e6, 2e7] {
            let h = 1e-3 * (p + STANDARD_ATMOSPHERE);
            let de = (f.stored_energy(B, p + h, v) - f.stored_energy(B, p - h, v)) / (2.0 * h);
            let want = p * v / f.bulk_modulus(B, p);
            assert!((de / want - 1.0).abs() < 1e-5, "{p}: {de} vs {want}");
        }
        // rigid liquid: e(p) = ∫ s dC, C = −ln((1 − α) + α p_a/P)
        let a = 0.2;
        let g = EntrainedAir::isothermal(a);
        let pa = STANDARD_ATMOSPHERE;
        for p in [-9e4, -5e4, 3e5] {
            // ∫₀ᵖ s · α p_a / (P ((1 − α) P + α p_a)) ds by the antiderivative
            // of the partial fractions, with k = α p_a/(1 − α)
            let k = a * pa / (1.0 - a);
            let prim = |s: f64| {
                let big = s + pa;
                // s/(P (P + k)) = [(P − p_a)/(P (P + k))]; α p_a/(1 − α) factor
                let c1 = -pa / k; // coefficient of 1/P
                let c2 = 1.0 + pa / k; // coefficient of 1/(P + k)
                k * (c1 * big.ln() + c2 * (big + k).ln())
            };
            let want = v * (prim(p) - prim(0.0));
            let got = g.stored_energy(1e30, p, v);
            assert!((got / want - 1.0).abs() < 1e-7, "{p}: {got} vs {want}");
        }
    }

    #[test]
    fn out_of_range_is_named() {
        let mut f = EntrainedAir::isothermal(1.0);
        assert!(f
            .validate()
            .unwrap_err()
            .to_string()
            .contains("air_fraction"));
        f.fraction = 0.01;
        f.polytropic_index = 2.0;
        assert!(f
            .validate()
            .unwrap_err()
            .to_string()
            .contains("polytropic_index"));
        f.polytropic_index = 1.0;
        f.atmospheric_pressure = 0.0;
        assert!(f.validate().is_err());
    }

    proptest! {
        /// With air the mixture is never stiffer than the liquid and never
        /// negative, B_eff in (0, B], for any state; at absolute pressures
        /// from zero up it stiffens monotonically with pressure. Below
        /// absolute zero (a state only a solver's trial step visits) the
        /// floor's gas law gives B_eff ≈ |P_abs|/n, which falls as the
        /// pressure rises back to zero: there it is bounded and positive,
        /// not rising.
        #[test]
        fn b_eff_is_positive_bounded_and_rising(
            a in 1e-5f64..0.05, n in 1.0f64..1.4, p in -2e5f64..3e7, dp in 1.0f64..1e6,
        ) {
            let f = EntrainedAir { fraction: a, polytropic_index: n, atmospheric_pressure: STANDARD_ATMOSPHERE };
            let b0 = f.bulk_modulus(B, p);
            prop_assert!(b0 > 0.0 && b0 <= B * (1.0 + 1e-12));
            let b1 = f.bulk_modulus(B, p + dp);
            prop_assert!(b1 > 0.0 && b1 <= B * (1.0 + 1e-12));
            if p + STANDARD_ATMOSPHERE >= 0.0 {
                prop_assert!(b1 >= b0 * (1.0 - 1e-12));
            }
        }
    }
}
