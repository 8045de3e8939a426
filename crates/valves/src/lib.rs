//! # hydrocyl-valves — hydraulic valve models
//!
//! Constitutive laws (algebraic: efforts in, flows out) of the valves in the
//! thesis's two drives:
//!
//! * [`orifice`] — the generic sharp-edged orifice, eqs 2.4–2.9, regularised
//!   near zero pressure drop; every other valve reuses it.
//! * [`servovalve`] — the Moog 76-102 servovalve with underlap: spool dynamics
//!   (eqs 2.2, 2.3/3.1), port areas (eq 3.2), symmetric-ported flows (eqs 2.8, 2.9).
//! * [`relief`] — the RBAE relief valve with outlet-referred cracking (eqs 6.6–6.10).
//! * [`pilot_valve`] — the DDDC pilot-shifted spring-centred four-way valve (eqs 6.2–6.5).
//! * [`needle`] — the NCCC needle valve with its reverse-flow check (Table 6-1).
//! * [`check`] — anti-cavitation check valves.
//!
//! ```text
//!            p_up ──▶ [ orifice, area A ] ──▶ p_down        Q = Cd A √(2|Δp|/ρ) sgn Δp
//! ```
//!
//! ```
//! use hydrocyl_ports::{Area, Density, Pressure};
//! use hydrocyl_valves::orifice::Orifice;
//!
//! let o = Orifice::new(0.625, Density::new(870.0));
//! let q = o.flow(Area::from_mm2(1.0), Pressure::from_bar(70.0), Pressure::ZERO);
//! // Cd A √(2Δp/ρ) = 0.625 · 1 mm² · √(2 · 7 MPa / 870 kg/m³) = 4.757 l/min
//! assert!((q.l_per_min() - 4.757).abs() < 1e-3);
//! ```
#![warn(missing_docs)]

pub mod check;
pub mod needle;
pub mod orifice;
pub mod pilot_valve;
pub mod relief;
pub mod servovalve;
