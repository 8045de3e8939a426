//! Which evaluations a set of wires depends on, as the components' bindings
//! declared them: what reading a run's probes needs at each output point
//! (the valve's orifices are not evaluated to read a friction force).

use super::Circuit;
use crate::binding::Netlist;
use crate::series::Step;
use crate::wires::AnyWire;

/// The wires each component reads and the components that write each wire,
/// as the components bound them.
#[derive(Clone, Debug, Default)]
pub(super) struct Dependencies {
    /// By component: the wires it reads (efforts and signals).
    reads: Vec<Vec<usize>>,
    /// By component: the accumulators it is bound to.
    accumulators: Vec<Vec<usize>>,
    /// By wire: the components that may write it (its owner, or every
    /// component adding into an accumulator).
    writers: Vec<Vec<usize>>,
}

impl Dependencies {
    /// From a netlist every component has bound.
    pub(super) fn of(net: &Netlist, n_components: usize) -> Self {
        let mut reads = vec![Vec::new(); n_components];
        for &(c, w, _, _) in &net.reads {
            reads[c].push(w);
        }
        let mut accumulators = vec![Vec::new(); n_components];
        let mut writers = vec![Vec::new(); net.names.len()];
        for &(c, w) in &net.writes {
            if !writers[w].contains(&c) {
                writers[w].push(c);
            }
            if net.accumulators.contains(&w) && !accumulators[c].contains(&w) {
                accumulators[c].push(w);
            }
        }
        Self {
            reads,
            accumulators,
            writers,
        }
    }
}

/// What sets some wires at a point when it is less than the whole
/// evaluation ([`Circuit::partial_for`]): the components that publish and
/// the evaluation steps that run.
#[derive(Clone, Debug)]
pub(crate) struct Partial {
    /// In component order.
    publishers: Vec<usize>,
    /// In evaluation order.
    steps: Vec<Step>,
}

#[cfg(test)]
impl Partial {
    /// The evaluation steps, in evaluation order.
    pub(crate) fn steps(&self) -> &[Step] {
        &self.steps
    }
}

impl Circuit {
    /// What sets `wires` at a point, when it is less than the whole
    /// evaluation: a wire a component publishes needs that component's
    /// publish; an algebraic one its writers' evaluations, and each of those
    /// what the writer reads (its own published states among them), a
    /// component that evaluates last
    /// ([`Component::evaluates_last`](super::Component::evaluates_last)) the
    /// writers of its accumulators, a member of an algebraic node its whole
    /// node and the writers of the node's inflow. `None` when everything is
    /// needed, or when a component settles after the evaluation
    /// ([`Component::settles`](super::Component::settles): it reads the
    /// complete accumulators).
    pub(crate) fn partial_for(&self, wires: &[AnyWire]) -> Option<Partial> {
        if !self.settlers.is_empty() {
            return None;
        }
        let deps = &self.dependencies;
        // the algebraic node a component solves or is evaluated with
        let group_of = |c: usize| {
            self.groups
                .iter()
                .position(|g| g.owner == c || g.members.contains(&c))
        };
        let n = self.comps.len();
        let (mut evaluated, mut published) = (vec![false; n], vec![false; n]);
        let mut pending: Vec<usize> = wires.iter().map(|w| w.0).collect();
        while let Some(w) = pending.pop() {
            if let Some(owner) = self.publisher.get(w).copied().flatten() {
                published[owner] = true;
                continue;
            }
            let mut queue: Vec<usize> = deps.writers.get(w).cloned().unwrap_or_default();
            while let Some(c) = queue.pop() {
                if std::mem::replace(&mut evaluated[c], true) {
                    continue;
                }
                published[c] = true;
                pending.extend(&deps.reads[c]);
                if self.comps[c].evaluates_last() {
                    pending.extend(&deps.accumulators[c]);
                }
                if let Some(g) = group_of(c) {
                    queue.push(self.groups[g].owner);
                    queue.extend(&self.groups[g].members);
                    pending.push(self.groups[g].node.inflow.0);
                }
            }
        }
        if evaluated.iter().chain(&published).all(|&n| n) {
            return None;
        }
        Some(Partial {
            publishers: (0..n).filter(|&i| published[i]).collect(),
            steps: self
                .order
                .iter()
                .copied()
                .filter(|s| match *s {
                    Step::Evaluate(i) => evaluated[i],
                    Step::Solve(g) => evaluated[self.groups[g].owner],
                })
                .collect(),
        })
    }

    /// Copies `wires` at `(t, x)` into `out` with only what `partial`
    /// ([`Circuit::partial_for`] of those wires) says published and
    /// evaluated: the values a full evaluation gives them.
    pub(crate) fn read_partial(
        &self,
        partial: &Partial,
        t: f64,
        x: &[f64],
        wires: &[AnyWire],
        out: &mut [f64],
    ) {
        // the table is no full evaluation at any point now
        self.filled.borrow_mut().valid = false;
        let mut w = self.wires.borrow_mut();
        self.publish_and_evaluate(Some(&partial.publishers), &partial.steps, t, x, &mut w);
        for (o, wire) in out.iter_mut().zip(wires) {
            *o = w.get(*wire);
        }
    }
}
