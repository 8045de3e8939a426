//! The component library: the building blocks of the `leaney-moog` rig and
//! generic pieces (fixed-pressure sources, volumes, orifices) other rigs reuse.
//!
//! | component | owns (effort) | states | reads | adds |
//! |---|---|---|---|---|
//! | [`PressureSource`] | node pressure | – | – | – |
//! | [`Volume`] | node pressure | p | node inflow | – |
//! | [`FixedOrifice`] | – | – | 2 node pressures | flow a→b |
//! | [`CommandInput`] | signal | – | – | – |
//! | [`ServoSpool`] | spool signal | x_s (, ẋ_s) | command | – |
//! | [`FourWayValve`] | – | – | spool, P, T, A, B | flows at P, T, A, B |
//! | [`TwoChamberCylinder`] | A, B pressures | p1, p2 | rod x, v; inflows | force on rod |
//! | [`GeneralisedCylinder`] | A, B pressures (algebraic) | P_LE | spool, P, T, rod | flows at P, T; force |
//! | [`Mass`] | rod x, v | x, v | forces on rod | – |
//! | [`Friction`] | – | model's (z) | rod v; A, B pressures | −F, added mass |
//! | [`SolenoidFourWay`] | – | s | command; P1, P2, A, B, T | flows at P1, P2, A, B, T |
//! | [`ServoNeedle`] | – | – | command; inlet, outlet | flow inlet→outlet |
//! | [`PositionController`] | command signal (algebraic) | (∫e) | reference, rod x | – |

mod controller;
mod cylinder;
mod four_way;
mod friction;
mod generalised;
mod mass;
mod orifice;
mod servo_needle;
mod solenoid_four_way;
mod sources;
mod spool;
mod volume;

pub use controller::{PositionController, PositionLaw};
pub use cylinder::{CylinderNodes, TwoChamberCylinder, CAVITATION_MARGIN_PA};
pub use four_way::{FourWayNodes, FourWayValve};
pub use friction::Friction;
pub use generalised::{GeneralisedCylinder, XMethod};
pub use mass::Mass;
pub use orifice::FixedOrifice;
pub use servo_needle::{OpeningLaw, ServoNeedle};
pub use solenoid_four_way::{SolenoidFourWay, SolenoidLaw, SolenoidNodes};
pub use sources::{CommandInput, PressureSource};
pub use spool::ServoSpool;
pub use volume::Volume;
