//! # hydrocyl-fmu — FMI 2.0 Co-Simulation export of any rig
//!
//! The FMU of a rig is a zip archive holding `modelDescription.xml`, the
//! rig (after its `--set` overrides) as `resources/rig.json`, and this
//! crate compiled as a `cdylib` as `binaries/linux64/<modelIdentifier>.so`.
//! The library is generic: `fmi2Instantiate` reads `resources/rig.json`
//! from `fmuResourceLocation`, rebuilds the variable table
//! ([`variables::Variables`]) and assembles the rig's own circuit
//! (`hydrocyl_system::rig::circuit`) driven by the FMU's input through a
//! [`Signal::External`](hydrocyl_system::signal::Signal::External);
//! `fmi2DoStep` integrates it with the rig's solvers
//! (`hydrocyl_integrators`), events located inside the step. `hydrocyl fmu`
//! only packages ([`package::fmu_archive`]).
//!
//! * [`variables`]: the variables (input `command`, one output per output
//!   channel, `solver.*` and every rig parameter by its `--set` path);
//! * [`units`]: units of parameters and the SI base units of every unit name;
//! * [`model_description`]: the XML and the GUID;
//! * [`slave`]: one instance, in safe Rust (the state machine, parameter
//!   checks through `rig::check`, the step);
//! * [`ffi`]: the C API, written by hand (with `instantiate`, where an
//!   instance's rig is read and its GUID checked, and the packager's check of
//!   a slave library's build: the only modules with `unsafe`);
//! * [`package`]: the `.fmu` archive and where the library is found.
//!
//! The variables and the model description of a preset's FMU:
//!
//! ```
//! use hydrocyl_fmu::model_description::{guid, model_description};
//! use hydrocyl_fmu::variables::{Role, Variables};
//! use hydrocyl_system::rig;
//!
//! let r = rig::preset("leaney-moog").unwrap();
//! let vars = Variables::of(&r).unwrap();
//! assert_eq!(vars.list[0].name, "command"); // the input, value reference 0
//! assert!(vars.outputs.iter().any(|(name, unit)| name == "p1" && *unit == "Pa"));
//! let n_par = vars.list.iter().filter(|v| matches!(v.role, Role::Parameter(_))).count();
//! assert_eq!(n_par, rig::parameters(&r).len()); // every rig parameter
//! let text = r.to_string();
//! let xml = model_description(&vars, "leaney-moog", "a valve rig", &text);
//! assert!(xml.contains(r#"<ScalarVariable name="load.mass""#));
//! // the GUID covers the rig's text and the variable list
//! assert!(xml.contains(&format!(r#"guid="{}""#, guid(&text, &vars))));
//! ```
//!
//! The crate implements no thesis equation: the physics is the rig's
//! (`hydrocyl-system`), the numerics the integrators'. The ABI is written by
//! hand: the FMI 2.0 C API is ~35 functions over `void*`, `int`, `double`
//! and one struct of callbacks; the crates.io FMI crates either target FMI 3
//! export only (`fmi-export`) or bind the API for importers (`fmi-sys`).

pub mod ffi;
mod instantiate;
pub mod model_description;
pub mod package;
pub mod slave;
#[doc(hidden)]
pub mod test_support;
pub mod units;
pub mod variables;
