//! # hydrocyl-identify — the measured-data loop
//!
//! (Being written: see issue "Close the loop with measured data".)
#![warn(missing_docs)]
