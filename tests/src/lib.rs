//! # hydrocyl-tests — end-to-end tests of the whole workspace
//!
//! This package holds no code of its own: its integration tests
//! (`tests/workspace/`) exercise the crates together through their public
//! surfaces, where no single crate's tests can:
//!
//! * every rig file in `fixtures/rigs/` loads, checks, and equals the built-in
//!   preset of the same name;
//! * every preset runs through the assembler and keeps its chambers' mass
//!   balance closed;
//! * a run written in the measured-data format (`spec/measured-data.md`) reads
//!   back through `hydrocyl-identify` to the same numbers, and every measured
//!   record in `fixtures/measured/` reads and has a rig that loads;
//! * the README's layout table names exactly the folders that exist.
//!
//! Run with `cargo test -p hydrocyl-tests` (part of `cargo test --workspace`).
