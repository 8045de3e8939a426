//! # hydrocyl-identify — the measured-data loop
//!
//! (Being written: see issue "Close the loop with measured data".)
#![warn(missing_docs)]

pub mod bench;
pub mod catalog;
pub mod data;
pub mod diagnose;
pub mod lm;
pub mod smooth;
pub mod synth;
pub mod valve;
