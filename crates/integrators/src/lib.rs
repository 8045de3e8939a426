//! # hydrocyl-integrators — ODE solvers for small stiff systems with switching
//!
//! Hydraulic drives are small (n ≤ 16), stiff (bulk modulus over a small
//! chamber volume, bristle stiffness σ0 = 3e7 N/m) and discontinuous (orifice
//! square roots at zero pressure drop, valves and check valves that switch,
//! friction that sticks and slips, end stops). This crate integrates an
//! [`OdeSystem`] with:
//!
//! * [`Method::DormandPrince45`] — explicit Dormand–Prince 5(4), adaptive step,
//!   dense output (Simulink's `ode45`, the thesis's solver);
//! * [`Method::Rosenbrock`] — a stiff, L-stable linearly implicit Rosenbrock
//!   method with adaptive step, analytic Jacobian when the model gives one,
//!   finite differences otherwise;
//! * [`Method::Rk4`] — classical fixed-step Runge–Kutta 4, for cross-checks.
//!
//! and **event location**: the model declares switching functions
//! ([`OdeSystem::events`]); the solver finds each sign change to a tolerance,
//! ends the step there, calls [`OdeSystem::on_event`] so the model can change
//! mode (and edit its state), and restarts. No step straddles a discontinuity
//! the model declared.
//!
//! Every solution carries [`Stats`] (steps, rejected steps, function and
//! Jacobian evaluations, LU decompositions, events).
//!
//! The crate implements no thesis equation; it is the numerical engine under
//! all of them.
#![warn(missing_docs)]

mod api;

pub use api::*;
