//! hydrocyl-integrators' integration tests, in one binary to save link time.

mod auto;
mod breakpoints;
mod common;
mod convergence;
mod dense;
mod errors;
mod events;
mod exponential;
mod linalg;
mod stats;
mod stiff;
mod stream;
