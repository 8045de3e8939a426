//! Which mechanical nodes each component of a circuit is attached to, as
//! its binding declared them: what a study needs to find the parts of a
//! circuit by their connections rather than by their names (the energy
//! ledger's rod side: the components on a cylinder's rod).

use super::Circuit;
use crate::binding::Netlist;

/// The mechanical nodes each component binds, by component index.
#[derive(Clone, Debug, Default)]
pub(super) struct Attachments {
    mechanical: Vec<Vec<String>>,
}

impl Attachments {
    /// From a netlist every component has bound: a node is the part of a
    /// wire's name (`mech:<node>:v`) between its domain and its quantity,
    /// for every wire a component reads or writes.
    pub(super) fn of(net: &Netlist, n_components: usize) -> Self {
        let mut mechanical = vec![Vec::<String>::new(); n_components];
        let touched = net
            .reads
            .iter()
            .map(|(c, w, _, _)| (*c, *w))
            .chain(net.writes.iter().copied());
        for (c, w) in touched {
            let Some(rest) = net.names[w].strip_prefix("mech:") else {
                continue;
            };
            let node = rest.rsplit_once(':').map_or(rest, |(n, _)| n);
            if !mechanical[c].iter().any(|m| m == node) {
                mechanical[c].push(node.to_string());
            }
        }
        Self { mechanical }
    }
}

impl Circuit {
    /// The mechanical nodes component `i` is attached to (a cylinder's rod,
    /// a mass's), in the order it bound them; empty for a component index
    /// out of range.
    pub fn mechanical_nodes(&self, i: usize) -> &[String] {
        self.attachments
            .mechanical
            .get(i)
            .map_or(&[], Vec::as_slice)
    }

    /// Whether component `i` is an actuator
    /// ([`Component::is_actuator`](super::Component::is_actuator): a
    /// cylinder, a bench's piston); `false` for an index out of range.
    pub fn is_actuator(&self, i: usize) -> bool {
        self.comps.get(i).is_some_and(|c| c.is_actuator())
    }
}
