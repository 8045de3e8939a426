//! # hydrocyl-pump-motor — servomotor and bidirectional gear pump
//!
//! The power source of the `wang-hybrid` drive (thesis sections 4.2.1–4.2.3,
//! 6.2.1): a DC servomotor under a speed-controlled drive, coupled to a
//! bidirectional gear pump whose ports A and B feed the two pump lines.
//!
//! ```text
//!   command u [V] ──▶ ┌─────────────────┐  Q_A ──▶ pump line 1 (p_A)
//!                     │ motor ══ pump   │
//!   voltage V [V] ──▶ └─────────────────┘  ◀── Q_A  pump line 2 (p_B)
//!                      i [A], ω [rad/s]       (Q_A > 0: clockwise, extending)
//! ```
//!
//! Two models:
//! * [`IdentifiedPump`] — the thesis's identified command → flow model: gain
//!   1.07e-5 m³·s⁻¹/V and a second-order lag with ω_n = 47.62 rad/s, ζ = 0.64
//!   (section 6.2.1, Fig 6-5). States `[Q, Q̇]`.
//! * [`PhysicalPump`] — the motor from Table 4-1 (torque constant, armature
//!   resistance and inductance, inertia from the mechanical time constant)
//!   and the pump from Table 4-2 (2.05 cc/rev, 8000 rpm) with volumetric and
//!   mechanical losses as parameters. States `[i, ω]`; it reports electrical
//!   power `V i`, shaft power `T ω` and hydraulic power `Δp Q` for the energy
//!   ledger ([`PowerBreakdown`]).
//!
//! Units are SI throughout; every field says its unit.
//!
//! ```
//! use hydrocyl_ports::{Voltage, VolumeFlow};
//! use hydrocyl_pump_motor::IdentifiedPump;
//!
//! let pump = IdentifiedPump::wang();
//! // the command for 50 mm/s extending on the 8.042 cm² piston
//! let u = pump.command_for_flow(VolumeFlow::new(8.042e-4 * 0.05));
//! assert!((u.si() - 3.758).abs() < 1e-3);
//! // 7.3 % overshoot at the first peak of the step response
//! let wd = 47.62 * (1.0f64 - 0.64 * 0.64).sqrt();
//! let peak = pump.step_response(u, std::f64::consts::PI / wd);
//! assert!((peak.si() / (8.042e-4 * 0.05) - 1.073).abs() < 1e-3);
//! ```
#![warn(missing_docs)]

pub mod identified;
pub mod physical;

pub use identified::IdentifiedPump;
pub use physical::{DcMotor, GearPump, PhysicalPump, PowerBreakdown};

use thiserror::Error;

/// What can go wrong with a pump-motor model.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum PumpError {
    /// A parameter is outside its valid range.
    #[error("{component}: parameter `{name}` = {value} is invalid: {reason}")]
    Parameter {
        /// The component (`"motor"`, `"pump"`, `"identified pump"`).
        component: &'static str,
        /// The parameter's name.
        name: &'static str,
        /// The offending value (SI).
        value: f64,
        /// What it must satisfy.
        reason: &'static str,
    },
    /// Newton's method found no steady state.
    #[error("no steady state of the motor and pump at {voltage} V and a pressure rise of {dp} Pa")]
    NoSteadyState {
        /// Armature voltage \[V\].
        voltage: f64,
        /// Pressure rise \[Pa\].
        dp: f64,
    },
}

impl PumpError {
    pub(crate) fn parameter(
        component: &'static str,
        name: &'static str,
        value: f64,
        reason: &'static str,
    ) -> Self {
        Self::Parameter {
            component,
            name,
            value,
            reason,
        }
    }
}
