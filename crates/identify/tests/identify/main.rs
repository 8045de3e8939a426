//! hydrocyl-identify's integration tests, one binary (link time on 2 cores):
//! the loop on generated records with planted effects, on the friction bench
//! and on the valve rig.

mod checks;
mod closed_loop;
mod hybrid;
mod planted;
mod valve;
