//! Joining connection endpoints into nodes: a union–find over the
//! endpoints, and what each joined set holds, checked as each endpoint joins.

use super::{err, NetlistError};
use crate::netlist::registry::{Domain, Instance, Role};

/// Union–find over connection endpoints.
pub(super) struct Sets {
    pub(super) parent: Vec<usize>,
}

impl Sets {
    pub(super) fn find(&mut self, i: usize) -> usize {
        let mut r = i;
        while self.parent[r] != r {
            r = self.parent[r];
        }
        let mut j = i;
        while self.parent[j] != r {
            let n = self.parent[j];
            self.parent[j] = r;
            j = n;
        }
        r
    }
    fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[rb.max(ra)] = ra.min(rb);
        }
    }
}

/// An endpoint: a component port, or a named node.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) enum End {
    Port(usize, &'static str),
    Named(String),
}

/// What the endpoints joined so far into one set hold: checked as each
/// endpoint joins, so that a conflict is named at the connection element
/// that brings it in (not where the node was first used).
#[derive(Clone, Debug, Default)]
pub(super) struct Part {
    /// The set's domain and the first port that gave it.
    pub(super) domain: Option<(Domain, String)>,
    /// The owning ports in the set.
    pub(super) owners: Vec<String>,
    /// The set's node name, when a named node is in it.
    pub(super) named: Option<String>,
}

impl Part {
    pub(super) fn of(e: &End, instances: &[Instance]) -> Self {
        match e {
            End::Named(n) => Part {
                named: Some(n.clone()),
                ..Part::default()
            },
            End::Port(ci, p) => {
                let inst = &instances[*ci];
                let spec = inst.ty.port(p).expect("checked when read");
                let label = format!("{}.{p}", inst.name);
                Part {
                    owners: if spec.role == Role::Owns {
                        vec![label.clone()]
                    } else {
                        Vec::new()
                    },
                    domain: Some((spec.domain, label)),
                    named: None,
                }
            }
        }
    }
}

/// Joins `item` (the element `item_label` at JSON path `at`, its endpoint
/// `e`) to the set
/// of `to`: a domain, owner or name conflict between the two sets is an
/// error at `at`, naming the ports (or nodes) on both sides.
pub(super) fn join(
    sets: &mut Sets,
    parts: &mut [Part],
    to: usize,
    item: usize,
    e: &End,
    item_label: &str,
    at: &str,
) -> Result<(), NetlistError> {
    let (ra, rb) = (sets.find(to), sets.find(item));
    if ra == rb {
        return Ok(());
    }
    let (a, b) = (&parts[ra], &parts[rb]);
    if let (Some(da), Some(db)) = (&a.domain, &b.domain) {
        if da.0 != db.0 {
            // the element itself where it is a port, else a port on its node
            let port = match e {
                End::Port(..) => format!("`{item_label}`"),
                End::Named(n) => format!("`{}` (on node `{n}`)", db.1),
            };
            return err(
                at,
                format!(
                    "{port} is {} but `{}` is {}: connected ports share a domain",
                    db.0.name(),
                    da.1,
                    da.0.name()
                ),
            );
        }
    }
    if let (Some(na), Some(nb)) = (&a.named, &b.named) {
        if na != nb {
            return err(
                at,
                format!("nodes `{na}` and `{nb}` are joined: a node has one name"),
            );
        }
    }
    if !a.owners.is_empty() && !b.owners.is_empty() {
        let domain = a
            .domain
            .as_ref()
            .or(b.domain.as_ref())
            .expect("owners have ports");
        return err(
            at,
            format!(
                "the {} node is owned by both {} and {}: a node has exactly one owner",
                domain.0.name(),
                a.owners.join(" and "),
                b.owners.join(" and ")
            ),
        );
    }
    let b = std::mem::take(&mut parts[rb]);
    let a = &mut parts[ra];
    a.domain = a.domain.take().or(b.domain);
    a.owners.extend(b.owners);
    a.named = a.named.take().or(b.named);
    sets.union(ra, rb);
    let root = sets.find(ra);
    if root != ra {
        parts.swap(root, ra);
    }
    Ok(())
}
