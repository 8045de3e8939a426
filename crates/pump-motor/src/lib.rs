//! # hydrocyl-pump-motor — servomotor and bidirectional gear pump
//!
//! (Being written: see issue "The hybrid pump-controlled drive".)
#![warn(missing_docs)]
