//! Typed wires: the handles components hold to the circuit's wire table,
//! and the table itself.
//!
//! A wire is an index into one `Vec<f64>`; its type parameter is the
//! quantity it carries (a `hydrocyl-ports` newtype, or `f64` for a
//! dimensionless signal), so a component reads and writes quantities, never
//! bare numbers, and a unit or domain slip inside a component does not
//! compile. See the crate docs for the causality rules.

use hydrocyl_ports::{Force, Mass, Position, Pressure, Quantity, Velocity, VolumeFlow};
use std::marker::PhantomData;

/// An effort or signal wire carrying a quantity `Q` (a pressure, a position,
/// a velocity, a spool travel, a normalised command as `f64`): written by its
/// one owner, read by the others. The type parameter makes a unit or domain
/// slip inside a component a compile error; the wire itself is an index into
/// the circuit's table of `f64` (the quantities are `#[repr(transparent)]`
/// newtypes, so typed access costs nothing).
pub struct Wire<Q>(pub(crate) usize, pub(crate) PhantomData<fn() -> Q>);

/// An accumulator wire carrying a quantity `Q`: every component but the
/// node's owner **adds** to it (flows into a hydraulic node, forces and added
/// masses on a body); zeroed at the start of each evaluation.
///
/// A pressure cannot be added into a flow accumulator:
///
/// ```compile_fail,E0308
/// use hydrocyl_ports::{Pressure, VolumeFlow};
/// use hydrocyl_system::{Acc, Wires};
///
/// let mut w = Wires::default();
/// let inflow: Acc<VolumeFlow> = Acc::UNBOUND;
/// w.add(inflow, Pressure::from_bar(1.0)); // error: expected `VolumeFlow`
/// ```
///
/// while a flow can (the same code with the right quantity compiles):
///
/// ```no_run
/// use hydrocyl_ports::{Pressure, VolumeFlow};
/// use hydrocyl_system::{Acc, Wires};
///
/// let mut w = Wires::default();
/// let inflow: Acc<VolumeFlow> = Acc::UNBOUND;
/// w.add(inflow, VolumeFlow::from_l_per_min(1.0));
/// ```
pub struct Acc<Q>(pub(crate) usize, pub(crate) PhantomData<fn() -> Q>);

/// An untyped wire index, for readers that want every wire as a column of
/// `f64` (probes, output sampling, [`Circuit::find_wire`](crate::Circuit::find_wire)).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct AnyWire(pub(crate) usize);

macro_rules! typed_wire {
    ($t:ident) => {
        impl<Q> $t<Q> {
            /// A placeholder for a component's wire fields before
            /// [`Component::bind`](crate::Component::bind) sets them (never
            /// read: [`Circuit::build`](crate::Circuit::build) binds every
            /// component before anything is evaluated).
            pub const UNBOUND: Self = Self(usize::MAX, PhantomData);

            /// The untyped index (for probes and output columns).
            #[inline(always)]
            pub const fn raw(self) -> AnyWire {
                AnyWire(self.0)
            }
        }
        impl<Q> Clone for $t<Q> {
            fn clone(&self) -> Self {
                *self
            }
        }
        impl<Q> Copy for $t<Q> {}
        impl<Q> PartialEq for $t<Q> {
            fn eq(&self, o: &Self) -> bool {
                self.0 == o.0
            }
        }
        impl<Q> Eq for $t<Q> {}
        impl<Q> std::hash::Hash for $t<Q> {
            fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
                self.0.hash(h)
            }
        }
        impl<Q: Quantity> std::fmt::Debug for $t<Q> {
            fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                write!(f, "{}<{}>({})", stringify!($t), Q::UNIT, self.0)
            }
        }
        impl<Q> From<$t<Q>> for AnyWire {
            fn from(w: $t<Q>) -> AnyWire {
                w.raw()
            }
        }
    };
}
typed_wire!(Wire);
typed_wire!(Acc);

/// A wire handle [`Wires::get`] can read: a typed [`Wire`] or [`Acc`] gives
/// its quantity, an [`AnyWire`] gives the bare SI `f64`.
pub trait ReadWire: Copy {
    /// What reading it gives.
    type Value;
    /// The table index.
    fn index(self) -> usize;
    /// The value from its SI `f64`.
    fn value(si: f64) -> Self::Value;
}

impl<Q: Quantity> ReadWire for Wire<Q> {
    type Value = Q;
    #[inline(always)]
    fn index(self) -> usize {
        self.0
    }
    #[inline(always)]
    fn value(si: f64) -> Q {
        Q::from_si(si)
    }
}

impl<Q: Quantity> ReadWire for Acc<Q> {
    type Value = Q;
    #[inline(always)]
    fn index(self) -> usize {
        self.0
    }
    #[inline(always)]
    fn value(si: f64) -> Q {
        Q::from_si(si)
    }
}

impl ReadWire for AnyWire {
    type Value = f64;
    #[inline(always)]
    fn index(self) -> usize {
        self.0
    }
    #[inline(always)]
    fn value(si: f64) -> f64 {
        si
    }
}

/// The wires of a hydraulic node.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct HydraulicNode {
    /// The node pressure (the effort), written by the node's one owner.
    pub pressure: Wire<Pressure>,
    /// Accumulator of the volume flow **into** the node from every component
    /// except its owner; zeroed at the start of each evaluation.
    pub inflow: Acc<VolumeFlow>,
}

impl HydraulicNode {
    /// A placeholder before [`Component::bind`](crate::Component::bind)
    /// (see [`Wire::UNBOUND`]).
    pub const UNBOUND: Self = Self {
        pressure: Wire::UNBOUND,
        inflow: Acc::UNBOUND,
    };
}

/// The wires of a mechanical (translational) node: a rigid body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct MechanicalNode {
    /// Position, + extending (written by the owner, a mass).
    pub position: Wire<Position>,
    /// Velocity (written by the owner).
    pub velocity: Wire<Velocity>,
    /// Accumulator of the forces on the body from every component except its
    /// owner, + in the + direction; zeroed at each evaluation.
    pub force: Acc<Force>,
    /// Accumulator of masses added by acceleration-proportional terms
    /// (`c a` friction terms moved to the mass side).
    pub added_mass: Acc<Mass>,
    /// Accumulator of hold requests (a count): a component that sticks the
    /// body (a friction law in its stick mode) adds 1; while it is positive
    /// the owner holds the body at rest (`dv/dt = 0`, and `v = 0` after the event).
    pub hold: Acc<f64>,
}

impl MechanicalNode {
    /// A placeholder before [`Component::bind`](crate::Component::bind)
    /// (see [`Wire::UNBOUND`]).
    pub const UNBOUND: Self = Self {
        position: Wire::UNBOUND,
        velocity: Wire::UNBOUND,
        force: Acc::UNBOUND,
        added_mass: Acc::UNBOUND,
        hold: Acc::UNBOUND,
    };
}

/// The wire table, read and written by components during one evaluation.
#[derive(Clone, Debug, Default)]
pub struct Wires {
    pub(crate) v: Vec<f64>,
}

impl Wires {
    /// Value of a wire: the quantity of a [`Wire`] or [`Acc`], the SI `f64`
    /// of an [`AnyWire`].
    #[inline(always)]
    pub fn get<W: ReadWire>(&self, w: W) -> W::Value {
        W::value(self.v[w.index()])
    }
    /// Sets a wire (only its owner should).
    #[inline(always)]
    pub fn set<Q: Quantity>(&mut self, w: Wire<Q>, value: Q) {
        self.v[w.0] = value.si();
    }
    /// Adds to an accumulator (flows into a node, forces on a body).
    #[inline(always)]
    pub fn add<Q: Quantity>(&mut self, w: Acc<Q>, value: Q) {
        self.v[w.0] += value.si();
    }
    #[inline(always)]
    pub(crate) fn zero(&mut self, i: usize) {
        self.v[i] = 0.0;
    }
}
