//! The component types of the registry, one file per family.

use super::registry::{ComponentType, Domain, PortSpec, Role};
use crate::circuit::Component;
use std::sync::LazyLock;

mod friction;
mod hybrid;
mod hydraulic;
mod mechanical;
mod servo;

pub(super) const HYD: Domain = Domain::Hydraulic;
pub(super) const MECH: Domain = Domain::Mechanical;
pub(super) const SIG: Domain = Domain::Signal;

/// A [`PortSpec`] table entry.
pub(super) const fn port(
    name: &'static str,
    domain: Domain,
    role: Role,
    optional: bool,
    doc: &'static str,
) -> PortSpec {
    PortSpec {
        name,
        domain,
        role,
        optional,
        doc,
    }
}

/// Boxes a built component.
pub(super) fn built<C: Component + 'static>(c: C) -> Result<Box<dyn Component>, String> {
    Ok(Box::new(c))
}

pub(crate) use friction::law_of as friction_law_of;
pub(crate) use friction::terms_of as friction_terms_of;
pub(super) use mechanical::cylinder as cylinder_of;
pub(super) use servo::metering as metering_of;

static ALL: LazyLock<Vec<ComponentType>> = LazyLock::new(|| {
    [
        hydraulic::TYPES,
        servo::TYPES,
        mechanical::TYPES,
        friction::TYPES,
        hybrid::TYPES,
    ]
    .concat()
});

/// Every component type, in catalog order.
pub(super) fn all() -> &'static [ComponentType] {
    &ALL
}
