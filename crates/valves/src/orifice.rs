//! The generic sharp-edged orifice (thesis eqs 2.6–2.9, 6.1, 6.13, 6.14): the turbulent
//! orifice law `Q = Cd A sqrt(2 |Δp| / ρ) sgn(Δp)`, regularised near `Δp = 0`.
//!
//! ## Regularisation
//! `sqrt(|Δp|)` has an infinite slope at `Δp = 0`, which makes the right-hand
//! side non-Lipschitz and stalls step-size control. Below a transition
//! pressure `Δp_t` the signed square root is replaced by the odd cubic
//! `f(x) = x/√Δp_t · (5/4 − x²/(4 Δp_t²))`, the unique odd cubic that matches
//! the value **and** slope of `sgn(x)√|x|` at `|x| = Δp_t`. The law is then C¹
//! with finite slope `5/(4√Δp_t)` at zero. The error is confined to
//! `|Δp| < Δp_t` and bounded by `max |f(x) − √x| = 0.2011 √Δp_t` (attained at
//! `x ≈ 0.1655 Δp_t`, where `1 − 2.5 s + 1.5 s⁵ = 0` for `s = √(x/Δp_t)`), so
//! the absolute flow error is at most `0.2011 Cd A √(2 Δp_t / ρ)` and vanishes
//! as `√Δp_t` when `Δp_t → 0` (tested below).

use crate::check::{positive, ParameterError};
use hydrocyl_ports::{Area, Density, Pressure, VolumeFlow};
use serde::{Deserialize, Serialize};

/// Default transition pressure of the regularised square root \[Pa\] (0.01 bar).
pub const DEFAULT_DP_TRANSITION: Pressure = Pressure::new(1.0e3);

/// `sgn(x) √|x|`, regularised for `|x| < x_t` by the C¹ odd cubic described in
/// the module docs. `x_t = 0` gives the exact signed square root.
#[inline]
pub fn signed_sqrt_regularised(x: f64, x_t: f64) -> f64 {
    let ax = x.abs();
    if ax >= x_t {
        ax.sqrt() * x.signum()
    } else {
        let r = x / x_t;
        x / x_t.sqrt() * (1.25 - 0.25 * r * r)
    }
}

/// Derivative of [`signed_sqrt_regularised`] with respect to `x`.
#[inline]
pub fn signed_sqrt_regularised_derivative(x: f64, x_t: f64) -> f64 {
    let ax = x.abs();
    if ax >= x_t {
        0.5 / ax.sqrt()
    } else {
        let r = x / x_t;
        (1.25 - 0.75 * r * r) / x_t.sqrt()
    }
}

/// A sharp-edged orifice: discharge coefficient, fluid density and the
/// regularisation's transition pressure.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Orifice {
    /// Discharge coefficient Cd \[-\].
    pub cd: f64,
    /// Fluid density ρ \[kg·m⁻³\].
    pub density: Density,
    /// Transition pressure Δp_t of the regularised square root \[Pa\].
    pub dp_transition: Pressure,
}

impl Orifice {
    /// An orifice with the default regularisation ([`DEFAULT_DP_TRANSITION`]).
    pub fn new(cd: f64, density: Density) -> Self {
        Self {
            cd,
            density,
            dp_transition: DEFAULT_DP_TRANSITION,
        }
    }

    /// Checks the parameters on behalf of `component` (named in the error):
    /// Cd in `(0, 1]` (a sharp edge cannot pass more than the ideal jet),
    /// ρ > 0 and Δp_t > 0, all finite.
    pub fn validate(&self, component: &'static str) -> Result<(), ParameterError> {
        positive(component, "cd", self.cd)?;
        if self.cd > 1.0 {
            return Err(ParameterError {
                component,
                name: "cd",
                value: self.cd,
                reason: "a discharge coefficient must be at most 1",
            });
        }
        positive(component, "density", self.density.si())?;
        positive(component, "dp_transition", self.dp_transition.si())
    }

    /// Flow coefficient `Cd √(2/ρ)` \[m^1.5·kg^-0.5\]: flow per unit area per √Pa.
    #[inline]
    pub fn coefficient(&self) -> f64 {
        self.cd * (2.0 / self.density.si()).sqrt()
    }

    /// Flow from `p_up` to `p_down` through opening `area` (negative when the
    /// pressure difference reverses).
    #[inline]
    pub fn flow(&self, area: Area, p_up: Pressure, p_down: Pressure) -> VolumeFlow {
        self.flow_with_coefficient(self.coefficient(), area, p_up, p_down)
    }

    /// [`Orifice::flow`] with its [`Orifice::coefficient`] given: a valve
    /// with several edges of one orifice computes the coefficient (a
    /// division and a square root) once for all of them. The same value,
    /// bit for bit, when `coefficient` is `self.coefficient()`.
    #[inline]
    pub fn flow_with_coefficient(
        &self,
        coefficient: f64,
        area: Area,
        p_up: Pressure,
        p_down: Pressure,
    ) -> VolumeFlow {
        let dp = (p_up - p_down).si();
        VolumeFlow::new(
            coefficient * area.si() * signed_sqrt_regularised(dp, self.dp_transition.si()),
        )
    }

    /// `∂Q/∂p_up` of [`Orifice::flow`] (`∂Q/∂p_down` is its negative) \[m³·s⁻¹·Pa⁻¹\].
    #[inline]
    pub fn conductance(&self, area: Area, p_up: Pressure, p_down: Pressure) -> f64 {
        let dp = (p_up - p_down).si();
        self.coefficient()
            * area.si()
            * signed_sqrt_regularised_derivative(dp, self.dp_transition.si())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn flow_with_its_own_coefficient_is_flow_bit_for_bit() {
        let o = Orifice::new(0.625, Density::new(870.0));
        let a = Area::new(3.7e-6);
        for (up, down) in [
            (7.0e6, 2.1e6),
            (1.0e5, 3.0e6),
            (2.0e5, 2.0e5 + 400.0),
            (0.0, 0.0),
        ] {
            let (up, down) = (Pressure::new(up), Pressure::new(down));
            let q = o.flow(a, up, down).si();
            let qc = o.flow_with_coefficient(o.coefficient(), a, up, down).si();
            assert_eq!(q.to_bits(), qc.to_bits());
        }
    }

    #[test]
    fn exact_outside_transition() {
        assert_eq!(signed_sqrt_regularised(4.0e6, 1.0e3), 2000.0);
        assert_eq!(signed_sqrt_regularised(-9.0e4, 1.0e3), -300.0);
    }

    #[test]
    fn continuous_value_and_slope_at_transition() {
        let xt = 1.0e3;
        let below = signed_sqrt_regularised(xt * (1.0 - 1e-12), xt);
        let above = signed_sqrt_regularised(xt * (1.0 + 1e-12), xt);
        assert!((below - above).abs() < 1e-9);
        let s_below = signed_sqrt_regularised_derivative(xt * (1.0 - 1e-12), xt);
        let s_above = signed_sqrt_regularised_derivative(xt * (1.0 + 1e-12), xt);
        assert!((s_below - s_above).abs() < 1e-9);
    }

    #[test]
    fn error_bound_and_convergence() {
        // max error over |x| < x_t is 0.2011 sqrt(x_t) and shrinks as sqrt(x_t)
        let mut prev = f64::INFINITY;
        for &xt in &[1.0e4, 1.0e3, 1.0e2, 1.0e1] {
            let mut emax: f64 = 0.0;
            for i in 0..=10_000 {
                let x = xt * i as f64 / 10_000.0;
                emax = emax.max((signed_sqrt_regularised(x, xt) - x.sqrt()).abs());
            }
            assert!(emax <= 0.2011 * xt.sqrt(), "xt={xt} emax={emax}");
            assert!(
                emax >= 0.2010 * xt.sqrt(),
                "the bound is attained: xt={xt} emax={emax}"
            );
            assert!(emax < prev / 3.0 || prev.is_infinite());
            prev = emax;
        }
    }

    proptest! {
        #[test]
        fn odd_and_monotone(x in -1.0e7f64..1.0e7, y in -1.0e7f64..1.0e7) {
            let xt = 1.0e3;
            prop_assert_eq!(signed_sqrt_regularised(-x, xt), -signed_sqrt_regularised(x, xt));
            if x < y {
                prop_assert!(signed_sqrt_regularised(x, xt) <= signed_sqrt_regularised(y, xt));
            }
        }

        #[test]
        fn derivative_matches_finite_difference(x in -1.0e5f64..1.0e5) {
            let xt = 1.0e3;
            let h = 1e-3;
            let fd = (signed_sqrt_regularised(x + h, xt) - signed_sqrt_regularised(x - h, xt)) / (2.0 * h);
            let an = signed_sqrt_regularised_derivative(x, xt);
            prop_assume!((x.abs() - xt).abs() > 2.0 * h && x.abs() > 2.0 * h);
            prop_assert!((fd - an).abs() <= 1e-5 * an.abs().max(1e-3));
        }
    }

    #[test]
    fn validate_names_the_component_and_the_parameter() {
        let ok = Orifice::new(0.625, Density::new(870.0));
        assert!(ok.validate("test").is_ok());
        assert!(Orifice::new(1.0, Density::new(870.0)).validate("t").is_ok());
        for (o, name) in [
            (Orifice::new(1.5, Density::new(870.0)), "cd"),
            (Orifice::new(0.0, Density::new(870.0)), "cd"),
            (Orifice::new(f64::NAN, Density::new(870.0)), "cd"),
            (Orifice::new(0.6, Density::new(-1.0)), "density"),
            (
                Orifice {
                    dp_transition: Pressure::ZERO,
                    ..ok
                },
                "dp_transition",
            ),
        ] {
            let e = o.validate("needle valve").unwrap_err();
            assert_eq!((e.component, e.name), ("needle valve", name));
            assert!(e.to_string().contains(name), "{e}");
        }
    }

    #[test]
    fn orifice_flow_matches_textbook_value() {
        let o = Orifice::new(0.625, Density::new(870.0));
        let q = o.flow(Area::new(1.0e-6), Pressure::from_bar(70.0), Pressure::ZERO);
        let expect = 0.625 * 1.0e-6 * (2.0 * 7.0e6 / 870.0f64).sqrt();
        assert!((q.si() - expect).abs() < 1e-15);
        assert_eq!(
            o.flow(Area::new(1.0e-6), Pressure::ZERO, Pressure::from_bar(70.0))
                .si(),
            -q.si()
        );
    }
}
