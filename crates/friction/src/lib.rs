//! # hydrocyl-friction — friction models for hydraulic cylinders
//!
//! Every model implements [`FrictionModel`]: velocity, acceleration and the
//! chamber pressures in ([`FrictionInput`]), internal state where the model
//! has one (the bristle deflection z), force out; plus its Jacobian for the
//! stiff integrator, its switching functions and modes for event location,
//! and its stored energy and dissipated power for the energy ledger.
//!
//! ```text
//!   piston velocity v   [m/s] ──▶ ┌───────────────────┐
//!   acceleration a    [m/s²]  ──▶ │  friction law     │──▶ force F [N] (opposes extension when > 0)
//!   chamber p1, p2     [Pa]   ──▶ │  state z [m]      │──▶ acceleration coefficient c [kg]
//!   drive force (events) [N]  ──▶ │  mode Slip/Stick  │──▶ dz/dt [m/s], ∂/∂(z, v, p1, p2)
//!                                 └───────────────────┘──▶ stored ½σ0z² [J], dissipated [W]
//! ```
//!
//! Models (thesis section 2.4 and chapter 5), each module citing its equations:
//! * [`CoulombViscous`] — `F = Fc tanh(v/v_t) + b v`, the `leaney-moog` preset's law;
//! * [`Stribeck`] — static Stribeck curve, eq 2.40, extending/retracting sets;
//! * [`Karnopp`] — stick as a mode with located stick/break-away events;
//! * [`Dahl`] — pre-sliding bristle without stiction;
//! * [`LuGre`] — eqs 2.34–2.36 / 5.1 in the **standard form** (eq 5.13 of the
//!   thesis drops σ0 from dz/dt; hydrocyl does not), Table 5-11 set;
//! * [`Wang`] — the thesis's new model, eq 5.4 pressure term `K (p1 − p2)² v`
//!   and eq 5.12/5.14 acceleration term `K H a`, Tables 5-8, 5-9, 5-10.
//!
//! [`WithSealTerms`] adds the eq 5.4 and 5.12 seal terms to any of them.
//!
//! [`FrictionLaw`] holds any of them and (de)serialises with a `"model"` tag,
//! so a rig file picks its friction by name. [`ident`] fits steady friction
//! curves (eq 2.40 / 5.8) to measured points with [`hydrocyl_fit`].
//!
//! The thesis writes α for both the Stribeck exponent and the acceleration;
//! hydrocyl calls the exponent δ ([`StribeckCurve::stribeck_exponent`]) and the
//! acceleration a. Units are SI throughout: N, m, s, Pa, kg.
//!
//! ```
//! use hydrocyl_friction::{CoulombViscous, FrictionInput, FrictionModel, Wang};
//! use hydrocyl_ports::{Pressure, Velocity};
//!
//! let f = CoulombViscous::leaney_moog();
//! let input = FrictionInput::at_velocity(Velocity::from_mm_per_s(100.0));
//! let force = f.force(&input, &[]);
//! assert!((force.n() - (50.0 * (100.0f64).tanh() + 500.0 * 0.1)).abs() < 1e-9);
//!
//! // Wang's model at 50 mm/s with 10 bar across the piston, in steady state.
//! let wang = Wang::table_5_8();
//! let input = FrictionInput {
//!     velocity: Velocity::from_mm_per_s(50.0),
//!     p1: Pressure::from_bar(12.0),
//!     p2: Pressure::from_bar(2.0),
//!     ..FrictionInput::default()
//! };
//! let mut z = [0.0];
//! wang.steady_state(&input, &mut z);
//! let f = wang.force(&input, &z).n();
//! assert!((f - wang.static_curve(&input)).abs() < 1e-9);
//! // K (p1 − p2)² v = 2.5e-8 × (1e6)² × 0.05 = 1250 N on top of g(v) ≈ 150 N.
//! assert!(f > 1250.0 && f < 1250.0 + 180.0);
//! ```
#![warn(missing_docs)]

mod additive;
mod coulomb;
mod curve;
mod dahl;
mod error;
pub mod ident;
mod karnopp;
mod law;
mod lugre;
mod model;
pub mod seal;
mod stribeck;
mod wang;

pub use additive::{SealTerms, WithSealTerms};
pub use coulomb::CoulombViscous;
pub use curve::StribeckCurve;
pub use dahl::Dahl;
pub use error::FrictionError;
pub use karnopp::Karnopp;
pub use law::FrictionLaw;
pub use lugre::LuGre;
pub use model::{
    finite_difference_jacobian, FrictionInput, FrictionJacobian, FrictionMode, FrictionModel,
};
pub use stribeck::{SteadySet, Stribeck};
pub use wang::{Wang, WangSet, ACCELERATION_BLEND_VELOCITY};
