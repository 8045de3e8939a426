//! The physical servomotor + gear pump (Tables 4-1, 4-2): a permanent-magnet
//! DC motor driving a fixed-displacement gear pump on one shaft.
//!
//! ```text
//!   L di/dt = V − R i − K_e ω
//!   J dω/dt = K_t i − b_m ω − T_p
//!   T_p     = D (p_A − p_B) + b_p ω + T_c tanh(ω/ω_c)        pump torque
//!   Q_A     = D ω − C_l (p_A − p_B)                           flow out of port A
//! ```
//!
//! States `[i, ω]` (\[A\], \[rad·s⁻¹\]); inputs the armature voltage `V` \[V\] and
//! the port pressures `p_A`, `p_B` \[Pa\]. The same flow `Q_A` enters the pump
//! through port B (no external leakage).
//!
//! ## Power ledger
//! `V i = R i² + d/dt(½ L i²) + d/dt(½ J ω²) + b_m ω² + T_p ω` and
//! `T_p ω = (p_A − p_B) Q_A + C_l (p_A − p_B)² + b_p ω² + T_c ω tanh(ω/ω_c)`:
//! electrical power in, copper loss, stored energy, motor friction, shaft
//! power, hydraulic power out, leakage loss and pump friction; every term is
//! in [`PowerBreakdown`], and the test integrates them to show the ledger closes.
//!
//! ## Values (Tables 4-1, 4-2 and assumptions)
//! `K_t` = 0.24 N·m/A, `K_e` = 0.24 V·s/rad, `R` = 0.4 Ω, `L` = 2.2 mH; the
//! rotor inertia is not listed, so it is taken from the mechanical time
//! constant `τ_m = J R/(K_t K_e)` = 14 ms: `J` = 2.016e-3 kg·m² (pump rotor and
//! coupling neglected). `D` = 2.05 cc/rev = 3.263e-7 m³/rad. **Assumed** (the
//! datasheets give none): no motor viscous friction (`b_m` = 0, it is inside
//! `τ_m`), pump leakage `C_l` = 1.28e-13 m³·s⁻¹·Pa⁻¹ (95 % volumetric
//! efficiency at 200 bar and 1500 rpm), pump viscous torque `b_p` = 1e-4
//! N·m·s/rad and Coulomb torque `T_c` = 0.1 N·m (`ω_c` = 1 rad/s).
//!
//! Note: with these values the bare motor's voltage → speed response has
//! `ω_n = √(K_t K_e/(L J))` ≈ 114 rad/s, ζ ≈ 0.8 — faster than the identified
//! 47.62 rad/s of section 6.2.1, which therefore describes the speed-controlled
//! drive (AXOR Microspeed loop, section 4.2.3) rather than the bare motor.

use crate::PumpError;
use hydrocyl_ports::{AngularVelocity, Current, Power, Pressure, Torque, Voltage, VolumeFlow};
use serde::{Deserialize, Serialize};

/// A permanent-magnet DC motor.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct DcMotor {
    /// Torque constant `K_t` \[N·m·A⁻¹\].
    pub torque_constant: f64,
    /// Back-EMF constant `K_e` \[V·s·rad⁻¹\].
    pub emf_constant: f64,
    /// Armature resistance `R` \[Ω\].
    pub resistance: f64,
    /// Armature inductance `L` \[H\].
    pub inductance: f64,
    /// Rotor inertia `J` (motor + pump) \[kg·m²\].
    pub inertia: f64,
    /// Viscous friction `b_m` \[N·m·s·rad⁻¹\].
    pub viscous: f64,
    /// Maximum terminal voltage \[V\] (Table 4-1; for checking commands).
    pub max_voltage: Voltage,
}

impl DcMotor {
    /// The SEM MT30R4-25 of Table 4-1 (inertia from the 14 ms mechanical time constant).
    pub fn mt30r4_25() -> Self {
        let (kt, ke, r) = (0.24, 0.24, 0.4);
        Self {
            torque_constant: kt,
            emf_constant: ke,
            resistance: r,
            inductance: 2.2e-3,
            inertia: 0.014 * kt * ke / r,
            viscous: 0.0,
            max_voltage: Voltage::new(100.0),
        }
    }
}

/// A fixed-displacement gear pump with laminar leakage and friction torque.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GearPump {
    /// Displacement per radian `D` \[m³·rad⁻¹\].
    pub displacement: f64,
    /// Laminar internal leakage coefficient `C_l` (A ↔ B) \[m³·s⁻¹·Pa⁻¹\].
    pub leakage: f64,
    /// Viscous friction torque coefficient `b_p` \[N·m·s·rad⁻¹\].
    pub viscous_torque: f64,
    /// Coulomb friction torque `T_c` \[N·m\].
    pub coulomb_torque: Torque,
    /// Speed scale `ω_c` of the smoothed Coulomb torque \[rad·s⁻¹\].
    pub coulomb_speed: f64,
    /// Maximum speed (Table 4-2) \[rad·s⁻¹\].
    pub max_speed: AngularVelocity,
}

impl GearPump {
    /// The HPI M3AAN1002L20C01 of Table 4-2 (2.05 cc/rev, 8000 rpm) with the
    /// assumed losses of the module docs.
    pub fn hpi_2_05cc() -> Self {
        Self {
            displacement: 2.05e-6 / (2.0 * std::f64::consts::PI),
            leakage: 1.28e-13,
            viscous_torque: 1.0e-4,
            coulomb_torque: Torque::new(0.1),
            coulomb_speed: 1.0,
            max_speed: AngularVelocity::from_rpm(8000.0),
        }
    }

    /// Volumetric efficiency `Q_A/(D ω)` at speed `omega` and pressure rise `dp` \[-\].
    pub fn volumetric_efficiency(&self, omega: AngularVelocity, dp: Pressure) -> f64 {
        1.0 - self.leakage * dp.si() / (self.displacement * omega.si())
    }
}

/// Where the power goes in the motor and pump, at one instant \[W\].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PowerBreakdown {
    /// Electrical power into the armature, `V i`.
    pub electrical: Power,
    /// Copper loss `R i²`.
    pub copper_loss: Power,
    /// Rate of change of magnetic energy, `L i di/dt`.
    pub magnetic_storage: Power,
    /// Rate of change of kinetic energy, `J ω dω/dt`.
    pub kinetic_storage: Power,
    /// Motor friction `b_m ω²`.
    pub motor_friction: Power,
    /// Shaft power into the pump, `T_p ω`.
    pub shaft: Power,
    /// Pump friction `b_p ω² + T_c ω tanh(ω/ω_c)`.
    pub pump_friction: Power,
    /// Leakage loss `C_l Δp²`.
    pub leakage_loss: Power,
    /// Hydraulic power out, `(p_A − p_B) Q_A`.
    pub hydraulic: Power,
}

/// The motor and pump on one shaft.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct PhysicalPump {
    /// The motor.
    pub motor: DcMotor,
    /// The pump.
    pub pump: GearPump,
}

impl Default for PhysicalPump {
    fn default() -> Self {
        Self::wang()
    }
}

impl PhysicalPump {
    /// Number of states, `[i, ω]`.
    pub const N_STATES: usize = 2;

    /// The `wang-hybrid` motor and pump (Tables 4-1, 4-2).
    pub fn wang() -> Self {
        Self {
            motor: DcMotor::mt30r4_25(),
            pump: GearPump::hpi_2_05cc(),
        }
    }

    /// Checks every parameter (finite; positive where it must be, non-negative losses).
    pub fn validate(&self) -> Result<(), PumpError> {
        let m = &self.motor;
        let p = &self.pump;
        let pos = [
            ("motor", "torque_constant", m.torque_constant),
            ("motor", "emf_constant", m.emf_constant),
            ("motor", "resistance", m.resistance),
            ("motor", "inductance", m.inductance),
            ("motor", "inertia", m.inertia),
            ("motor", "max_voltage", m.max_voltage.si()),
            ("pump", "displacement", p.displacement),
            ("pump", "coulomb_speed", p.coulomb_speed),
            ("pump", "max_speed", p.max_speed.si()),
        ];
        for (c, n, v) in pos {
            if !(v.is_finite() && v > 0.0) {
                return Err(PumpError::parameter(c, n, v, "must be finite and > 0"));
            }
        }
        let nonneg = [
            ("motor", "viscous", m.viscous),
            ("pump", "leakage", p.leakage),
            ("pump", "viscous_torque", p.viscous_torque),
            ("pump", "coulomb_torque", p.coulomb_torque.si()),
        ];
        for (c, n, v) in nonneg {
            if !(v.is_finite() && v >= 0.0) {
                return Err(PumpError::parameter(c, n, v, "must be finite and >= 0"));
            }
        }
        Ok(())
    }

    /// Pump torque `T_p` at speed `ω` and pressure rise `p_A − p_B` \[N·m\].
    #[inline]
    pub fn pump_torque(&self, omega: f64, dp: Pressure) -> Torque {
        let p = &self.pump;
        Torque::new(
            p.displacement * dp.si()
                + p.viscous_torque * omega
                + p.coulomb_torque.si() * (omega / p.coulomb_speed).tanh(),
        )
    }

    /// Flow out of port A (and into port B) \[m³·s⁻¹\].
    #[inline]
    pub fn flow(&self, x: &[f64], p_a: Pressure, p_b: Pressure) -> VolumeFlow {
        VolumeFlow::new(self.pump.displacement * x[1] - self.pump.leakage * (p_a - p_b).si())
    }

    /// Armature current from the state.
    #[inline]
    pub fn current(&self, x: &[f64]) -> Current {
        Current::new(x[0])
    }

    /// Shaft speed from the state.
    #[inline]
    pub fn speed(&self, x: &[f64]) -> AngularVelocity {
        AngularVelocity::new(x[1])
    }

    /// Time derivatives of `[i, ω]`.
    #[inline]
    pub fn derivatives(&self, x: &[f64], v: Voltage, p_a: Pressure, p_b: Pressure, dx: &mut [f64]) {
        let m = &self.motor;
        let (i, w) = (x[0], x[1]);
        dx[0] = (v.si() - m.resistance * i - m.emf_constant * w) / m.inductance;
        dx[1] = (m.torque_constant * i - m.viscous * w - self.pump_torque(w, p_a - p_b).si())
            / m.inertia;
    }

    /// The power ledger at state `x` (see the module docs).
    pub fn powers(&self, x: &[f64], v: Voltage, p_a: Pressure, p_b: Pressure) -> PowerBreakdown {
        let m = &self.motor;
        let p = &self.pump;
        let mut dx = [0.0; 2];
        self.derivatives(x, v, p_a, p_b, &mut dx);
        let (i, w) = (x[0], x[1]);
        let dp = (p_a - p_b).si();
        PowerBreakdown {
            electrical: v * Current::new(i),
            copper_loss: Power::new(m.resistance * i * i),
            magnetic_storage: Power::new(m.inductance * i * dx[0]),
            kinetic_storage: Power::new(m.inertia * w * dx[1]),
            motor_friction: Power::new(m.viscous * w * w),
            shaft: self.pump_torque(w, p_a - p_b) * AngularVelocity::new(w),
            pump_friction: Power::new(
                p.viscous_torque * w * w + p.coulomb_torque.si() * w * (w / p.coulomb_speed).tanh(),
            ),
            leakage_loss: Power::new(p.leakage * dp * dp),
            hydraulic: (p_a - p_b) * self.flow(x, p_a, p_b),
        }
    }

    /// The steady state `[i, ω]` under constant voltage `v` and pressure rise
    /// `dp`, by Newton's method on the speed (the Coulomb term makes it
    /// nonlinear). Errors if it does not converge.
    pub fn steady_state(&self, v: Voltage, dp: Pressure) -> Result<[f64; 2], PumpError> {
        let m = &self.motor;
        // i = (V − K_e ω)/R;  K_t i − b_m ω − T_p(ω) = 0
        let f = |w: f64| {
            m.torque_constant * (v.si() - m.emf_constant * w) / m.resistance
                - m.viscous * w
                - self.pump_torque(w, dp).si()
        };
        let mut w = v.si() / m.emf_constant;
        for _ in 0..100 {
            let h = 1e-6 * (1.0 + w.abs());
            let d = (f(w + h) - f(w - h)) / (2.0 * h);
            let step = f(w) / d;
            w -= step;
            if step.abs() < 1e-12 * (1.0 + w.abs()) {
                return Ok([(v.si() - m.emf_constant * w) / m.resistance, w]);
            }
        }
        Err(PumpError::NoSteadyState {
            voltage: v.si(),
            dp: dp.si(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn table_values_and_derived_inertia() {
        let p = PhysicalPump::wang();
        assert!(p.validate().is_ok());
        let tau =
            p.motor.inertia * p.motor.resistance / (p.motor.torque_constant * p.motor.emf_constant);
        assert!((tau - 0.014).abs() < 1e-12);
        // nominal flow at 1500 rpm is 3.07 L/min (Table 4-2) without leakage
        let q = p.pump.displacement * AngularVelocity::from_rpm(1500.0).si();
        assert!((VolumeFlow::new(q).l_per_min() - 3.075).abs() < 1e-3);
        // and the assumed leakage gives 95 % at 200 bar, 1500 rpm
        let eta = p
            .pump
            .volumetric_efficiency(AngularVelocity::from_rpm(1500.0), Pressure::from_bar(200.0));
        assert!((eta - 0.95).abs() < 0.002);
    }

    #[test]
    fn steady_state_is_a_fixed_point() {
        let p = PhysicalPump::wang();
        let (v, dp) = (Voltage::new(40.0), Pressure::from_bar(30.0));
        let x = p.steady_state(v, dp).unwrap();
        let mut d = [1.0; 2];
        p.derivatives(&x, v, dp, Pressure::ZERO, &mut d);
        assert!(d[0].abs() < 1e-6 && d[1].abs() < 1e-6, "{d:?}");
        // torque balance: K_t i = D dp + losses
        assert!(x[0] * 0.24 > p.pump.displacement * dp.si());
    }

    #[test]
    fn power_ledger_closes_over_a_transient() {
        // integrate states and energies with RK4; the energy identity must hold to
        // the integration error.
        let p = PhysicalPump::wang();
        let (pa, pb) = (Pressure::from_bar(50.0), Pressure::from_bar(-0.3));
        let v = |t: f64| Voltage::new(if t < 0.05 { 60.0 } else { -30.0 });
        let f = |t: f64, y: &[f64; 4]| {
            let mut d = [0.0; 2];
            p.derivatives(&y[..2], v(t), pa, pb, &mut d);
            let pw = p.powers(&y[..2], v(t), pa, pb);
            [
                d[0],
                d[1],
                pw.electrical.si(),
                (pw.copper_loss + pw.motor_friction + pw.shaft).si(),
            ]
        };
        let h = 1e-5;
        let mut y = [0.0f64; 4];
        let mut t = 0.0;
        while t < 0.1 - 1e-12 {
            let k1 = f(t, &y);
            let a = |k: &[f64; 4], s: f64| std::array::from_fn::<f64, 4, _>(|i| y[i] + s * k[i]);
            let k2 = f(t + 0.5 * h, &a(&k1, 0.5 * h));
            let k3 = f(t + 0.5 * h, &a(&k2, 0.5 * h));
            let k4 = f(t + h, &a(&k3, h));
            for i in 0..4 {
                y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
            t += h;
        }
        let stored = 0.5 * p.motor.inductance * y[0] * y[0] + 0.5 * p.motor.inertia * y[1] * y[1];
        let e_in = y[2];
        let e_out = y[3] + stored;
        assert!(
            (e_in - e_out).abs() < 1e-6 * e_in.abs(),
            "{e_in} vs {e_out}"
        );
        // and the shaft power splits exactly into hydraulic, leakage and friction
        let pw = p.powers(&y[..2], v(t), pa, pb);
        let split = pw.hydraulic + pw.leakage_loss + pw.pump_friction;
        assert!((pw.shaft - split).si().abs() < 1e-9 * pw.shaft.si().abs());
    }

    #[test]
    fn rejects_bad_parameters() {
        let mut p = PhysicalPump::wang();
        p.motor.inductance = 0.0;
        assert!(p.validate().unwrap_err().to_string().contains("inductance"));
        let mut p = PhysicalPump::wang();
        p.pump.leakage = -1.0;
        assert!(p.validate().is_err());
    }

    #[test]
    fn flow_falls_with_pressure_by_the_leakage() {
        let p = PhysicalPump::wang();
        let x = [0.0, 300.0];
        let q0 = p.flow(&x, Pressure::ZERO, Pressure::ZERO).si();
        let q1 = p.flow(&x, Pressure::from_bar(100.0), Pressure::ZERO).si();
        assert!((q0 - q1 - 1.28e-13 * 1.0e7).abs() < 1e-18);
    }
}
