//! Chapter 9's further work on the hybrid drive (thesis section 9.2), done
//! in simulation on netlist rig files, each compared with the pilot-shifted
//! drive `wang-hybrid` on the same open-loop square wave:
//!
//! * `wang-hybrid-solenoid` — a command-switched (solenoid) four-way valve
//!   instead of the pilot-shifted DDDC valve, relief valves 1 and 2 removed;
//! * `wang-hybrid-needle` — the needle opening chosen per speed by an
//!   optimiser over simulations ([`needle`]): least energy in subject to an
//!   overrun limit;
//! * `wang-hybrid-servo-needle` — the solenoid drive with a servo needle
//!   valve whose opening follows the velocity command, its gains fitted to
//!   the optimiser's openings for that drive ([`servo`]);
//! * `wang-hybrid-improved` — the solenoid valve and the optimised needle;
//! * `wang-hybrid-closed-loop` — a position P controller on the servomotor,
//!   driven by the position reference of the same motion ([`closed_loop`]).
//!
//! [`compare()`] runs them all with the parameters the study sets; [`run_case`] runs one case and measures it (efficiency and ledger of eqs
//! 8.1–8.8, stall at reversal, drift per period, overrun); everything goes
//! through the public API (`rig::load`, `rig::apply_set`, `Simulation`).

pub mod closed_loop;
pub mod compare;
pub mod needle;
pub mod run;
pub mod servo;

pub use compare::{compare, Comparison, Row};
pub use run::{run_case, Case, Measured};

/// The rig files of the chapter-9 variants, with the pilot-shifted drive
/// first (`fixtures/rigs/<name>.json`).
pub const RIGS: [&str; 6] = [
    "wang-hybrid",
    "wang-hybrid-solenoid",
    "wang-hybrid-needle",
    "wang-hybrid-servo-needle",
    "wang-hybrid-improved",
    "wang-hybrid-closed-loop",
];

/// The speeds of the comparison \[mm/s\] (those of Tables 8-2 and 8-3).
pub const SPEEDS_MM_S: [f64; 2] = [50.0, 100.0];

/// The loads of the comparison \[kg\] (none and the 20 kg of Table 8-1).
pub const LOADS_KG: [f64; 2] = [0.0, 20.0];
