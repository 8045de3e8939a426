//! # hydrocyl-xfactor — Leaney's X factor (thesis chapter 3.2)
//!
//! (Being written: see issue "The X factor".)
#![warn(missing_docs)]
