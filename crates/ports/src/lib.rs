//! # hydrocyl-ports — typed power-bond quantities
//!
//! Every physical quantity that crosses a component boundary in hydrocyl is a
//! `#[repr(transparent)]` newtype over `f64` holding the **SI** value. Only the
//! products that mean something physically are defined, so that a unit slip
//! (bar where pascal is meant, l/min where m³/s is meant) or a wrong product
//! (pressure × velocity) does not compile:
//!
//! ```text
//!   Pressure   × VolumeFlow      = Power        (hydraulic bond, effort × flow)
//!   Force      × Velocity        = Power        (mechanical bond)
//!   Torque     × AngularVelocity = Power        (rotational bond)
//!   Voltage    × Current         = Power        (electrical bond)
//!   Pressure   × Area            = Force        (piston)
//!   Area       × Velocity        = VolumeFlow   (displacement flow)
//!   Area       × Position        = Volume       (chamber volume)
//!   Mass       × Acceleration    = Force        (Newton)
//!   Power      × Time            = Energy
//!   Pressure   × Volume          = Energy
//! ```
//!
//! A [`HydraulicPort`] carries (pressure, flow), a [`MechanicalPort`] carries
//! (force, velocity); both know their [`Power`]. The sign convention is the
//! bond-graph one: flow (velocity) is positive **into** the component through
//! the port, so `port.power()` is the power delivered *to* the component.
//!
//! The thesis (Wang 2019) writes every equation in SI units; this crate
//! implements no equation of its own, it is the vocabulary the component
//! crates speak (eqs 2.8–2.27, 6.1–6.21, 8.1–8.12 take and return these types).
//!
//! Conversions from the units engineers type are explicit, named constructors
//! and accessors; there is no implicit conversion anywhere:
//!
//! ```
//! use hydrocyl_ports::{Area, Pressure, VolumeFlow, Velocity};
//!
//! let ps = Pressure::from_bar(70.0);
//! assert_eq!(ps.pa(), 7.0e6);
//! let q = VolumeFlow::from_l_per_min(6.0);
//! assert!((q.m3_per_s() - 1.0e-4).abs() < 1e-18);
//! // hydraulic power of 70 bar at 6 l/min, typed as Power:
//! let p = ps * q;
//! assert!((p.watts() - 700.0).abs() < 1e-9);
//! // a piston of 11.43 cm² moving at 50 mm/s displaces a flow:
//! let a1 = Area::from_cm2(11.43);
//! let flow: VolumeFlow = a1 * Velocity::from_mm_per_s(50.0);
//! assert!((flow.l_per_min() - 3.429).abs() < 1e-9);
//! ```
//!
//! All operations are `#[inline]` and compile to the raw `f64` arithmetic; the
//! `typed_vs_raw` criterion benchmark checks that an orifice-flow function
//! written with these types runs as fast as the same function on bare `f64`.
#![warn(missing_docs)]

mod ports;
mod quantity;

pub use ports::{HydraulicPort, MechanicalPort};
pub use quantity::*;
