//! The thesis's proposed improvements of the hybrid drive (sections 8.2 and
//! 9.2) as rig files of kind `hybrid-variant`: now a rig kind of
//! `hydrocyl-system` ([`hydrocyl_system::hybrid::variant`], so every
//! `rig::load` user — the CLI, the Python package, the FMU — runs them),
//! re-exported here.

pub use hydrocyl_system::hybrid::variant::*;
