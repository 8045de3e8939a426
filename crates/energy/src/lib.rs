//! # hydrocyl-energy — where the energy of a drive goes
//!
//! The energy ledger of a run (thesis chapter 8, eqs 8.1–8.8).
//!
//! ```text
//!        source power                         load power
//!   supply Ps·Q / pump (pA−pB)·Qp ──▶ [ circuit ] ──▶ F_ext·v (gravity)
//!                                        │  │
//!              losses by component ◀─────┘  └────▶ storage: ½V p²/B, ½(m+c)v², ½σ0 z²
//!   (metering edges, relief, pilot and needle valves, friction, leakage)
//! ```
//!
//! Every component of `hydrocyl-system` reports its power terms (source,
//! dissipated, storage rate, load) balanced on its own, and the assembler
//! integrates them alongside the states. [`ledger::ledger`] turns those
//! integrals into the run's ledger over a window:
//! `E_in = E_load + Σ E_loss + ΔE_stored`, with the residual as a fraction of
//! `E_in` (it must close to 0.1 %) and an independent check of the storage
//! from the end states.
//!
//! ## Thesis equations
//! * eq 8.1 (with 8.2, 8.3): valve drive input `Ps Q_in` \[W\] — here the
//!   supply's delivered flow, i.e. every metering edge fed from P;
//! * eqs 8.5, 8.6: hybrid input `P_s1 Q_p` / `P_s2 Q_p` \[W\] — here the pump's
//!   hydraulic power `(p_A − p_B) Q_p`, equal to them with the suction line at
//!   tank pressure;
//! * eqs 8.4, 8.7, 8.8: output `v (p1 A1 − p2 A2)` \[W\], the cylinder's
//!   mechanical power (friction, load and kinetic energy);
//! * efficiency = ∫output dt / ∫input dt over whole periods (signed
//!   integrals: "the area between the power curves and time axis").
//!
//! The chapter-8 scenario matrix (Tables 8-2 and 8-3) is a study on this
//! ledger and lives in `hydrocyl-studies` (`chapter8`), and so do the
//! improvements of sections 8.2 and 9.2 (`chapter9`). Units: SI (J, W, s) everywhere.
//! Charging a closed volume from a 70-bar source through an orifice loses
//! half the energy drawn, whatever the orifice:
//!
//! ```
//! use hydrocyl_energy::ledger::{ledger, RodSide};
//! use hydrocyl_ports::{Area, Density, Pressure};
//! use hydrocyl_system::components::{FixedOrifice, PressureSource, Volume};
//! use hydrocyl_system::run::RunOptions;
//! use hydrocyl_system::simulation::Simulation;
//! use hydrocyl_system::Circuit;
//! use hydrocyl_valves::orifice::Orifice;
//!
//! let (ps, v, b) = (7.0e6, 1.0e-4, 7.0e8);
//! let oil = Orifice { cd: 0.65, density: Density::new(900.0), dp_transition: Pressure::new(1000.0) };
//! let c = Circuit::build(vec![
//!     Box::new(PressureSource::new("supply", "P", Pressure::new(ps), None)),
//!     Box::new(FixedOrifice::new("orifice", "P", "V", Area::new(1e-6), oil)),
//!     Box::new(Volume::new("volume", "V", v, b, 0.0, Some("pv"))),
//! ])
//! .unwrap();
//! let t: Vec<f64> = (0..=100).map(|k| k as f64 * 1e-2).collect();
//! let opts = RunOptions { ledger: true, rtol: 1e-8, ..RunOptions::dp45() };
//! let mut sim = Simulation::of_circuit(c).options(opts);
//! let r = sim.run(&t).unwrap();
//! let rod = RodSide { node: "none".into(), components: vec![] };
//! let l = ledger(sim.circuit(), &r, 0, t.len() - 1, &rod).unwrap();
//! let e_in = v * ps * ps / b; // V Ps² / B
//! assert!((l.loss("orifice") / e_in - 0.5).abs() < 1e-4);
//! assert!(l.error.abs() < 1e-3); // the ledger closes
//! ```
#![warn(missing_docs)]

pub mod error;
pub mod ledger;

pub use error::EnergyError;
pub use ledger::{Ledger, RodSide, Term};
