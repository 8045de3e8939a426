//! The netlist components bind to: node and signal names turned into typed
//! wires, with who owns (sets) and who reads each.

use crate::circuit::BuildError;
use crate::wires::{Acc, HydraulicNode, MechanicalNode, Wire};
use hydrocyl_ports::Quantity;
use std::collections::HashMap;
use std::marker::PhantomData;

/// When a component writes a wire it owns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Causality {
    /// From its own state and time only, in
    /// [`Component::publish`](crate::Component::publish) (volumes, masses,
    /// spools, command sources). Readers need no ordering.
    Stored,
    /// Algebraically from other wires, in
    /// [`Component::evaluate`](crate::Component::evaluate) (a pilot spool
    /// travel from line pressures; the generalised actuator's chamber
    /// pressures). Readers are evaluated after the writer.
    Algebraic,
}

#[derive(Clone, Debug)]
pub(crate) struct Owned {
    pub(crate) owner: usize,
    pub(crate) causality: Causality,
}

/// The registry components bind to: it turns node and signal names into
/// wires and records who owns (sets) and who reads each, and in which unit.
#[derive(Debug, Default)]
pub struct Netlist {
    pub(crate) names: Vec<String>,
    pub(crate) units: Vec<&'static str>,
    pub(crate) index: HashMap<String, usize>,
    pub(crate) owners: HashMap<usize, Owned>,
    pub(crate) accumulators: Vec<usize>,
    /// (component, wire) for every wire a component may write: the
    /// accumulators it binds and the wires it owns.
    pub(crate) writes: Vec<(usize, usize)>,
    pub(crate) reads: Vec<(usize, usize, &'static str, String)>,
    pub(crate) mismatch: Option<BuildError>,
    /// Algebraic nodes: (declaring component, node, name).
    pub(crate) solved: Vec<(usize, HydraulicNode, String)>,
    pub(crate) current: usize,
    pub(crate) component_names: Vec<String>,
}

impl Netlist {
    /// The index of wire `key` carrying `Q`; a second use of the key in
    /// another unit is recorded as a [`BuildError::UnitMismatch`].
    fn slot<Q: Quantity>(&mut self, key: String) -> usize {
        if let Some(&i) = self.index.get(&key) {
            if self.units[i] != Q::UNIT && self.mismatch.is_none() {
                self.mismatch = Some(BuildError::UnitMismatch {
                    wire: key,
                    first: self.units[i],
                    second: Q::UNIT,
                    component: self.component_names[self.current].clone(),
                });
            }
            return i;
        }
        let i = self.names.len();
        self.names.push(key.clone());
        self.units.push(Q::UNIT);
        self.index.insert(key, i);
        i
    }

    fn wire<Q: Quantity>(&mut self, key: String) -> Wire<Q> {
        Wire(self.slot::<Q>(key), PhantomData)
    }

    fn own(
        &mut self,
        w: usize,
        kind: &'static str,
        node: &str,
        c: Causality,
    ) -> Result<(), BuildError> {
        if let Some(o) = self.owners.get(&w) {
            return Err(BuildError::TwoOwners {
                kind,
                node: node.to_string(),
                first: self.component_names[o.owner].clone(),
                second: self.component_names[self.current].clone(),
            });
        }
        self.owners.insert(
            w,
            Owned {
                owner: self.current,
                causality: c,
            },
        );
        self.writes.push((self.current, w));
        Ok(())
    }

    fn read(&mut self, w: usize, kind: &'static str, node: &str) {
        self.reads.push((self.current, w, kind, node.to_string()));
    }

    fn accumulator<Q: Quantity>(&mut self, key: String) -> Acc<Q> {
        let i = self.slot::<Q>(key);
        if !self.accumulators.contains(&i) {
            self.accumulators.push(i);
        }
        self.writes.push((self.current, i));
        Acc(i, PhantomData)
    }

    fn hyd(&mut self, node: &str) -> HydraulicNode {
        let pressure = self.wire(format!("hyd:{node}:p"));
        let inflow = self.accumulator(format!("hyd:{node}:q"));
        HydraulicNode { pressure, inflow }
    }

    /// Connects to hydraulic node `node`: read its pressure, add flows into it.
    pub fn hydraulic(&mut self, node: &str) -> HydraulicNode {
        let h = self.hyd(node);
        self.read(h.pressure.0, "hydraulic node", node);
        h
    }

    /// Becomes the owner of hydraulic node `node` (sets its pressure); every
    /// hydraulic node has exactly one owner.
    pub fn own_hydraulic(&mut self, node: &str, c: Causality) -> Result<HydraulicNode, BuildError> {
        let h = self.hyd(node);
        self.own(h.pressure.0, "hydraulic node", node, c)?;
        Ok(h)
    }

    /// Declares hydraulic node `node` algebraic: its pressure is solved by
    /// the assembler so that the flows into it sum to zero
    /// ([`crate::series`]); it counts as the node's owner.
    pub fn solve_hydraulic(&mut self, node: &str) -> Result<HydraulicNode, BuildError> {
        let h = self.hyd(node);
        self.own(h.pressure.0, "hydraulic node", node, Causality::Algebraic)?;
        self.solved.push((self.current, h, node.to_string()));
        Ok(h)
    }

    fn mech(&mut self, node: &str) -> MechanicalNode {
        MechanicalNode {
            position: self.wire(format!("mech:{node}:x")),
            velocity: self.wire(format!("mech:{node}:v")),
            force: self.accumulator(format!("mech:{node}:f")),
            added_mass: self.accumulator(format!("mech:{node}:m")),
            hold: self.accumulator(format!("mech:{node}:hold")),
        }
    }

    /// Connects to mechanical node `node`: read position and velocity, add forces.
    pub fn mechanical(&mut self, node: &str) -> MechanicalNode {
        let m = self.mech(node);
        self.read(m.position.0, "mechanical node", node);
        self.read(m.velocity.0, "mechanical node", node);
        m
    }

    /// Becomes the owner of mechanical node `node` (sets position and velocity).
    pub fn own_mechanical(&mut self, node: &str) -> Result<MechanicalNode, BuildError> {
        let m = self.mech(node);
        self.own(m.position.0, "mechanical node", node, Causality::Stored)?;
        self.own(m.velocity.0, "mechanical node", node, Causality::Stored)?;
        Ok(m)
    }

    /// Reads signal `name` (a command, a spool position, a pilot travel) as
    /// a `Q`; every user of a signal must agree on its quantity.
    pub fn signal<Q: Quantity>(&mut self, name: &str) -> Wire<Q> {
        let w = self.wire(format!("sig:{name}"));
        self.read(w.0, "signal", name);
        w
    }

    /// Becomes the writer of signal `name`, a `Q`.
    pub fn own_signal<Q: Quantity>(
        &mut self,
        name: &str,
        c: Causality,
    ) -> Result<Wire<Q>, BuildError> {
        let w = self.wire(format!("sig:{name}"));
        self.own(w.0, "signal", name, c)?;
        Ok(w)
    }

    /// A wire private to the calling component (scratch values passed from
    /// `evaluate` to `derivatives`); `key` need only be unique per component.
    pub fn private<Q: Quantity>(&mut self, key: &str) -> Wire<Q> {
        let name = format!("priv:{}:{key}", self.component_names[self.current]);
        let w = self.wire(name);
        self.owners.insert(
            w.0,
            Owned {
                owner: self.current,
                causality: Causality::Algebraic,
            },
        );
        self.writes.push((self.current, w.0));
        w
    }
}
