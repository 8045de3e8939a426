//! (to be written: see the module list in lib.rs)
