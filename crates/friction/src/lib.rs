//! # hydrocyl-friction — friction models for hydraulic cylinders
//!
//! Every model implements [`FrictionModel`]: velocity, acceleration and the
//! chamber pressures in ([`FrictionInput`]), internal state where the model
//! has one (the LuGre bristle deflection z), force out.
//!
//! ```text
//!   piston velocity v ──▶ ┌──────────────┐
//!   chamber p1, p2    ──▶ │   friction   │──▶ force F opposing motion [N]
//!   acceleration a    ──▶ └──────────────┘
//! ```
//!
//! Models (thesis section 2.4 and chapter 5):
//! * [`CoulombViscous`] — `F = Fc tanh(v/v_t) + b v`, the `leaney-moog` preset's law.
//!
//! ```
//! use hydrocyl_friction::{CoulombViscous, FrictionInput, FrictionModel};
//! use hydrocyl_ports::{Force, Velocity};
//!
//! let f = CoulombViscous::leaney_moog();
//! let input = FrictionInput::at_velocity(Velocity::from_mm_per_s(100.0));
//! let force = f.force(&input, &[]);
//! assert!((force.n() - (50.0 * (100.0f64).tanh() + 500.0 * 0.1)).abs() < 1e-9);
//! ```
#![warn(missing_docs)]

use hydrocyl_ports::{Acceleration, Force, Mass, Pressure, Velocity};
use serde::{Deserialize, Serialize};

/// The signals a friction model may read.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrictionInput {
    /// Piston velocity, + extending \[m·s⁻¹\].
    pub velocity: Velocity,
    /// Piston acceleration \[m·s⁻²\].
    pub acceleration: Acceleration,
    /// Cap-side chamber pressure p1 \[Pa\].
    pub p1: Pressure,
    /// Rod-side chamber pressure p2 \[Pa\].
    pub p2: Pressure,
}

impl FrictionInput {
    /// Input at velocity `v` with zero acceleration and zero pressures.
    pub fn at_velocity(v: Velocity) -> Self {
        Self {
            velocity: v,
            ..Self::default()
        }
    }
}

/// A friction law. The force is the friction force on the piston, positive
/// when it opposes extension (so the load balance is
/// `m a = p1 A1 − p2 A2 − F_friction − F_ext`, thesis eq 2.27).
///
/// Terms linear in acceleration (the thesis's `K H a`, eq 5.12) are **not**
/// in [`FrictionModel::force`]; they are reported by
/// [`FrictionModel::acceleration_coefficient`] so that the assembler can move
/// them to the mass side of the balance and solve it explicitly:
/// `(m + c) a = p1 A1 − p2 A2 − force(..) − F_ext`.
pub trait FrictionModel {
    /// Number of internal states (0 for static laws, 1 for LuGre/Dahl's z).
    fn n_states(&self) -> usize {
        0
    }

    /// Friction force without the acceleration-proportional term \[N\].
    fn force(&self, input: &FrictionInput, state: &[f64]) -> Force;

    /// Coefficient `c` of a friction term `c a` \[kg\] (zero by default).
    fn acceleration_coefficient(&self, _input: &FrictionInput) -> Mass {
        Mass::ZERO
    }

    /// Time derivative of the internal states.
    fn state_derivative(&self, _input: &FrictionInput, _state: &[f64], _dstate: &mut [f64]) {}

    /// The internal state that is steady at this input (for initial conditions).
    fn steady_state(&self, _input: &FrictionInput, _state: &mut [f64]) {}

    /// Steady-state force at constant velocity (the static friction curve).
    fn steady_force(&self, input: &FrictionInput) -> Force {
        let mut z = vec![0.0; self.n_states()];
        self.steady_state(input, &mut z);
        self.force(input, &z)
    }
}

/// Coulomb + viscous friction, `F = Fc tanh(v / v_t) + b v` (the `leaney-moog`
/// preset's law, rigs.md; tanh smoothing instead of a discontinuous sign).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CoulombViscous {
    /// Coulomb level Fc \[N\].
    pub coulomb: Force,
    /// Viscous coefficient b \[N·s·m⁻¹\].
    pub viscous: f64,
    /// Smoothing velocity v_t of the tanh \[m·s⁻¹\].
    pub smoothing_velocity: Velocity,
}

impl CoulombViscous {
    /// The `leaney-moog` preset: Fc = 50 N, b = 500 N s/m, v_t = 1 mm/s.
    pub fn leaney_moog() -> Self {
        Self {
            coulomb: Force::new(50.0),
            viscous: 500.0,
            smoothing_velocity: Velocity::new(1.0e-3),
        }
    }
}

impl FrictionModel for CoulombViscous {
    fn force(&self, input: &FrictionInput, _state: &[f64]) -> Force {
        let v = input.velocity.si();
        Force::new(self.coulomb.si() * (v / self.smoothing_velocity.si()).tanh() + self.viscous * v)
    }
}
