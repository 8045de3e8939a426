//! Integration tests of hydrocyl-friction (one binary, one module per topic).

mod common;
mod dynamics;
mod energy;
mod ident;
mod jacobian;
mod karnopp;
mod serde_law;
mod steady;
mod stiff;
