//! # hydrocyl-studies — the thesis's experiments, as a user's study
//!
//! The experiments of the thesis, built only on the public API of
//! `hydrocyl-system` (rigs, circuits, runs) and `hydrocyl-energy` (the
//! ledger), like any user's study: the library crates hold models, this
//! crate holds what the thesis did with them. Used by `cargo xtask validate`,
//! `cargo xtask energy`, the benches and the tests.
//!
//! * [`chapter3`] — the `leaney-moog` valve-rig tests of section 3.3 (square
//!   wave, underlap sine, sawtooth, underlap sweep, end stop; Figs 3-11,
//!   3-13, 3-21 to 3-26, Table 3-5) and the comparison of the numerical and
//!   analytical X-factor formulations with the fundamental one.
//! * [`chapter7`] — the open-loop tests of the hybrid drive (sections
//!   7.1–7.3) and the measurement of the phenomena the thesis reports (stall
//!   at reversal, slower retraction, drift, friction asymmetry by eq 7.4);
//!   the fold of the pressure-energised seal term of eq 5.4.
//! * [`chapter8`] — the efficiency matrix of Tables 8-2 and 8-3 (eqs
//!   8.1–8.8): valve-controlled against hybrid, ±50/±100 mm/s, sine/square,
//!   no load/20 kg.
//! * [`relief`] — the readings of relief valves 1 and 2 (eqs 6.6–6.10,
//!   `rlv_1.m`: cracking pressure and slope, `P_m` by eq 6.8) and the cap the
//!   pilot valve's shift pressure puts on the hybrid's efficiency.
//! * [`commands`] — the command files of the chapter-3, 7 and 8 experiments
//!   as `hydrocyl simulate` reads them (`fixtures/commands/`, `cargo xtask
//!   commands`), with the command lines that run them.
//! * [`chapter9`] — the further work of section 9.2 in simulation: the
//!   solenoid four-way valve, the needle opening optimised per speed, a servo
//!   needle valve and a closed position loop, each against the pilot-shifted
//!   drive (stall, efficiency, drift).
//!
//! ```
//! use hydrocyl_studies::chapter8::{run_scenario, Drive, Plan, Scenario, Wave};
//!
//! let drive = Drive::wang_valve_c10().unwrap();
//! let sc = Scenario { system: "valve".into(), speed_mm_s: 100.0, wave: Wave::Square, load_kg: 0.0 };
//! let plan = Plan { measured_periods: 1, sample_s: 5e-3, ..Plan::default() };
//! let out = run_scenario(&drive, &sc, &plan).unwrap();
//! assert!(out.ledger.error.abs() < 1e-3);        // the ledger closes
//! assert!(out.efficiency > 0.0 && out.efficiency < 0.5);
//! ```
#![warn(missing_docs)]

pub mod chapter3;
pub mod chapter7;
pub mod chapter8;
pub mod chapter9;
pub mod commands;
pub mod relief;
