//! # hydrocyl-actuator — the asymmetric (single-rod) cylinder
//!
//! (Being written: see issue "The valve-controlled drive".)
#![warn(missing_docs)]
