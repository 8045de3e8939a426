//! # hydrocyl-energy — where the energy of a drive goes
//!
//! The energy ledger of a run and the thesis's chapter-8 comparison of the
//! valve-controlled and the hybrid pump-controlled drive.
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
//! Tables 8-2 and 8-3 are in [`scenario::thesis_efficiency`]; the scenario
//! matrix in [`scenario::base_matrix`]; the improvements of sections 8.2 and
//! 9.2 in [`variant`]. Units: SI (J, W, s) everywhere, speeds in mm/s only in
//! scenario labels.
//!
//! ```
//! use hydrocyl_energy::scenario::{run_scenario, Drive, Plan, Scenario, Wave};
//!
//! let drive = Drive::wang_valve_c10().unwrap();
//! let sc = Scenario { system: "valve".into(), speed_mm_s: 100.0, wave: Wave::Square, load_kg: 0.0 };
//! let plan = Plan { measured_periods: 1, sample_s: 5e-3, ..Plan::default() };
//! let out = run_scenario(&drive, &sc, &plan).unwrap();
//! assert!(out.ledger.error.abs() < 1e-3);        // the ledger closes
//! assert!(out.efficiency > 0.0 && out.efficiency < 0.5);
//! ```
#![warn(missing_docs)]

pub mod error;
pub mod ledger;
pub mod scenario;
pub mod switched;
pub mod variant;

pub use error::EnergyError;
pub use ledger::{Ledger, RodSide, Term};
pub use scenario::{run_scenario, Drive, Outcome, Plan, Scenario, Trace, Wave};
pub use variant::HybridVariant;
