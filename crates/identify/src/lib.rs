//! # hydrocyl-identify — the measured-data loop
//!
//! Runs a rig model against a measured record, finds what the model gets
//! wrong, traces the residual to the effect of the catalog
//! (`spec/measured-data.md`) the model lacks, adds it, refits, and reports
//! before and after — the thesis's chapter-5 method made automatic. The
//! method, the report and the real-data results are in `docs/diagnose.md`.
//!
//! ```text
//!   record.csv ──▶ data ──▶ smooth (SG + GCV) ──▶ v, a
//!                                  │
//!   rig (declared) ──▶ simulate ──▶ residual per channel / balance
//!                                  │
//!        catalog effects ──▶ trace (share, held-out, ΔBIC; probes) ──▶ add best
//!                                  │                                    │
//!                                  └──────── LM refit (hydrocyl-fit) ◀──┘ ──▶ Report (JSON + human)
//! ```
//!
//! Modules:
//! * [`data`] — the CSV format: unit suffixes converted to SI (time \[s\],
//!   position \[m\], velocity \[m·s⁻¹\], pressures \[Pa\], flow \[m³·s⁻¹\],
//!   force \[N\]); errors name file, row and column; first-order hold.
//! * [`data_checks`] — data problems named before any fit (constant,
//!   clipped, quantised channels; units and signs that contradict the rig,
//!   pressures at a scale the declared model's contradicts; gaps in the
//!   time axis; compared channels the record lacks).
//! * [`smooth`] — Savitzky–Golay on uneven steps, window by GCV.
//! * [`catalog`] — the effect catalog as data (ids, balances, parameters).
//! * [`bench`](mod@bench) — the `friction-bench` rig: force balance
//!   `m a = s F + p1 A1 − p2 A2 − F_f − F0` (thesis eq 5.9 with the drive
//!   force), friction per eq 5.1 (LuGre, g(v) with Stribeck), eq 5.4
//!   (`K (p1 − p2)² v`) and eq 5.12 (`K H a`).
//! * [`valve`] — the valve rig of hydrocyl-system (`leaney-moog`):
//!   output-error tracing of the effects its rig file exposes.
//! * [`accept`] — the acceptance rule, one for every rig kind.
//! * [`diagnose`] — the loop and the report; [`lm`] — refits with
//!   confidence intervals; [`synth`] — generated records with planted effects.
//!
//! ```
//! use hydrocyl_identify::catalog::EffectId;
//! use hydrocyl_identify::diagnose::{diagnose_bench, DiagnoseOptions};
//! use hydrocyl_identify::synth::{declared_for, record, truth_with, Foreign, Noise};
//!
//! // A bench whose seal friction grows with pressure (K = 1e-9 m³·s/N),
//! // declared without the pressure term: the loop finds it.
//! let truth = truth_with(&[EffectId::PressureViscous]);
//! let rec = record(&truth, 3000, 1e-3, Noise::default(), Foreign::None, 1);
//! let declared = declared_for(&[EffectId::PressureViscous]);
//! let out = diagnose_bench(&declared, &[rec], &DiagnoseOptions::default(), &mut |_, _, _| {})
//!     .unwrap();
//! let first = &out.report.effects_added[0];
//! assert_eq!(first.id, "pressure_viscous");
//! assert!((first.params["K"] / 1e-9 - 1.0).abs() < 0.05);
//! ```
#![warn(missing_docs)]

pub mod accept;
pub mod bench;
pub mod catalog;
pub mod data;
pub mod data_checks;
pub mod diagnose;
pub mod lm;
pub mod plaincsv;
pub mod smooth;
pub mod synth;
pub mod valve;
