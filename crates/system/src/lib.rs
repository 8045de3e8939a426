//! # hydrocyl-system — the rig assembler
//!
//! (Being written: see issue "The valve-controlled drive".)
#![warn(missing_docs)]
