//! The solenoid-operated on/off valve of the hybrid drive's variant (a):
//! now a component of `hydrocyl-system`
//! ([`hydrocyl_system::components::SwitchedOrifice`]), re-exported here.

pub use hydrocyl_system::components::SwitchedOrifice;
