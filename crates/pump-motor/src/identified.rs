//! The identified command → flow model of the servomotor, its drive and the
//! gear pump (thesis section 6.2.1, Figs 6-4, 6-5): a gain and a second-order
//! lag,
//!
//! ```text
//!   Q̈ + 2 ζ ω_n Q̇ + ω_n² Q = ω_n² K u        K = 1.07e-5 m³·s⁻¹/V, ω_n = 47.62 rad/s, ζ = 0.64
//! ```
//!
//! States `[Q, Q̇]` (\[m³·s⁻¹\], \[m³·s⁻²\]); input `u` the drive command \[V\].
//! Positive flow leaves pump port A into pump line 1 (the pump turning
//! clockwise, extending the cylinder, Fig 4-3).

use crate::PumpError;
use hydrocyl_ports::{AngularVelocity, Voltage, VolumeFlow};
use serde::{Deserialize, Serialize};

/// The identified pump-and-motor model.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct IdentifiedPump {
    /// Steady-state flow per volt of command, `K` \[m³·s⁻¹·V⁻¹\].
    pub gain: f64,
    /// Natural frequency `ω_n` \[rad·s⁻¹\].
    pub natural_frequency: f64,
    /// Damping ratio `ζ` \[-\].
    pub damping: f64,
}

impl Default for IdentifiedPump {
    fn default() -> Self {
        Self::wang()
    }
}

impl IdentifiedPump {
    /// Number of states, `[Q, Q̇]`.
    pub const N_STATES: usize = 2;

    /// The thesis's identified values (section 6.2.1).
    pub fn wang() -> Self {
        Self {
            gain: 1.07e-5,
            natural_frequency: 47.62,
            damping: 0.64,
        }
    }

    /// A model from its three parameters, validated (all finite; gain ≠ 0,
    /// `ω_n > 0`, `ζ > 0`).
    pub fn new(gain: f64, natural_frequency: f64, damping: f64) -> Result<Self, PumpError> {
        if !(gain.is_finite() && gain != 0.0) {
            return Err(PumpError::parameter(
                "identified pump",
                "gain",
                gain,
                "must be finite and non-zero",
            ));
        }
        if !(natural_frequency.is_finite() && natural_frequency > 0.0) {
            return Err(PumpError::parameter(
                "identified pump",
                "natural_frequency",
                natural_frequency,
                "must be finite and > 0",
            ));
        }
        if !(damping.is_finite() && damping > 0.0) {
            return Err(PumpError::parameter(
                "identified pump",
                "damping",
                damping,
                "must be finite and > 0",
            ));
        }
        Ok(Self {
            gain,
            natural_frequency,
            damping,
        })
    }

    /// Pump flow out of port A from the state \[m³·s⁻¹\].
    #[inline]
    pub fn flow(&self, x: &[f64]) -> VolumeFlow {
        VolumeFlow::new(x[0])
    }

    /// Time derivatives of `[Q, Q̇]` at command `u`.
    #[inline]
    pub fn derivatives(&self, x: &[f64], u: Voltage, dx: &mut [f64]) {
        let wn = self.natural_frequency;
        dx[0] = x[1];
        dx[1] = wn * wn * (self.gain * u.si() - x[0]) - 2.0 * self.damping * wn * x[1];
    }

    /// Jacobian `∂ẋ/∂x`, row-major 2×2 (the model is linear, so constant).
    pub fn jacobian(&self) -> [f64; 4] {
        let wn = self.natural_frequency;
        [0.0, 1.0, -wn * wn, -2.0 * self.damping * wn]
    }

    /// The state at rest under a constant command `u`.
    pub fn steady_state(&self, u: Voltage) -> [f64; 2] {
        [self.gain * u.si(), 0.0]
    }

    /// The command whose steady flow is `q` \[V\].
    pub fn command_for_flow(&self, q: VolumeFlow) -> Voltage {
        Voltage::new(q.si() / self.gain)
    }

    /// Closed-form flow `t` seconds after a command step from rest to `u`
    /// (under-damped `ζ < 1`, critically or over-damped otherwise).
    pub fn step_response(&self, u: Voltage, t: f64) -> VolumeFlow {
        let (wn, z) = (self.natural_frequency, self.damping);
        let q_inf = self.gain * u.si();
        if t <= 0.0 {
            return VolumeFlow::ZERO;
        }
        let frac = if z < 1.0 {
            let wd = wn * (1.0 - z * z).sqrt();
            1.0 - (-z * wn * t).exp() * ((wd * t).cos() + z * wn / wd * (wd * t).sin())
        } else if z == 1.0 {
            1.0 - (-wn * t).exp() * (1.0 + wn * t)
        } else {
            let s = (z * z - 1.0).sqrt();
            let (r1, r2) = (-wn * (z - s), -wn * (z + s));
            1.0 - (r2 * (r1 * t).exp() - r1 * (r2 * t).exp()) / (r2 - r1)
        };
        VolumeFlow::new(q_inf * frac)
    }

    /// Shaft speed that the flow implies for a pump of `displacement` \[m³ per
    /// radian\] with no leakage, `ω = Q / D` (for reporting speed against
    /// Table 4-2's 8000 rpm).
    pub fn implied_speed(&self, x: &[f64], displacement: f64) -> AngularVelocity {
        AngularVelocity::new(x[0] / displacement)
    }

    /// Switching function: the pump flow \[m³·s⁻¹\]; it changes sign when the
    /// pump reverses.
    #[inline]
    pub fn reversal_margin(&self, x: &[f64]) -> f64 {
        x[0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rk4(p: &IdentifiedPump, u: Voltage, t_end: f64, h: f64) -> [f64; 2] {
        let mut x = [0.0; 2];
        let n = (t_end / h).round() as usize;
        let f = |x: &[f64; 2]| {
            let mut d = [0.0; 2];
            p.derivatives(x, u, &mut d);
            d
        };
        for _ in 0..n {
            let k1 = f(&x);
            let k2 = f(&[x[0] + 0.5 * h * k1[0], x[1] + 0.5 * h * k1[1]]);
            let k3 = f(&[x[0] + 0.5 * h * k2[0], x[1] + 0.5 * h * k2[1]]);
            let k4 = f(&[x[0] + h * k3[0], x[1] + h * k3[1]]);
            for i in 0..2 {
                x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
        x
    }

    #[test]
    fn integrated_step_matches_closed_form_with_fourth_order_convergence() {
        let p = IdentifiedPump::wang();
        let u = Voltage::new(3.0);
        let t = 0.05;
        let exact = p.step_response(u, t).si();
        let e1 = (rk4(&p, u, t, 1e-3)[0] - exact).abs();
        let e2 = (rk4(&p, u, t, 5e-4)[0] - exact).abs();
        assert!(e1 < 1e-6 * exact.abs(), "{e1}");
        let order = (e1 / e2).log2();
        assert!((order - 4.0).abs() < 0.5, "order {order}");
    }

    #[test]
    fn overshoot_is_that_of_zeta_0_64() {
        let p = IdentifiedPump::wang();
        let u = Voltage::new(1.0);
        let wd = p.natural_frequency * (1.0 - p.damping * p.damping).sqrt();
        let t_peak = std::f64::consts::PI / wd;
        let peak = p.step_response(u, t_peak).si() / p.gain - 1.0;
        let expect =
            (-p.damping * std::f64::consts::PI / (1.0 - p.damping * p.damping).sqrt()).exp();
        assert!((peak - expect).abs() < 1e-12);
        assert!((peak - 0.0730).abs() < 1e-3); // 7.3 % overshoot
    }

    #[test]
    fn steady_state_is_a_fixed_point_and_inverts() {
        let p = IdentifiedPump::wang();
        let u = Voltage::new(-2.5);
        let x = p.steady_state(u);
        let mut d = [1.0; 2];
        p.derivatives(&x, u, &mut d);
        assert_eq!(d, [0.0, 0.0]);
        assert!((p.command_for_flow(p.flow(&x)).si() - u.si()).abs() < 1e-12);
        // 50 mm/s on the 8.042 cm² piston needs 3.76 V
        let v = p.command_for_flow(VolumeFlow::new(8.042e-4 * 0.05));
        assert!((v.si() - 3.758).abs() < 1e-3);
    }

    #[test]
    fn other_damping_regimes_are_continuous() {
        let u = Voltage::new(1.0);
        let t = 0.03;
        let q = |z: f64| {
            IdentifiedPump::new(1.0, 47.62, z)
                .unwrap()
                .step_response(u, t)
                .si()
        };
        assert!((q(1.0 - 1e-7) - q(1.0)).abs() < 1e-6);
        assert!((q(1.0 + 1e-7) - q(1.0)).abs() < 1e-6);
    }

    #[test]
    fn rejects_bad_parameters() {
        assert!(IdentifiedPump::new(0.0, 47.62, 0.64).is_err());
        assert!(IdentifiedPump::new(1e-5, -1.0, 0.64).is_err());
        let e = IdentifiedPump::new(1e-5, 47.62, f64::NAN).unwrap_err();
        assert!(e.to_string().contains("damping"));
    }

    #[test]
    fn jacobian_matches_derivatives() {
        let p = IdentifiedPump::wang();
        let j = p.jacobian();
        let x = [1e-5, 2e-4];
        let mut d0 = [0.0; 2];
        p.derivatives(&x, Voltage::ZERO, &mut d0);
        assert!((d0[0] - (j[0] * x[0] + j[1] * x[1])).abs() < 1e-15);
        assert!((d0[1] - (j[2] * x[0] + j[3] * x[1])).abs() < 1e-12);
    }
}
