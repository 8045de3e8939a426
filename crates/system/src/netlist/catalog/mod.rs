//! The component types of the registry, one file per family.

use super::registry::{ComponentType, Domain, ParamSpec, PortSpec, Role};
use crate::circuit::Component;
use std::sync::LazyLock;

mod bench;
mod bench_friction;
mod control;
mod friction;
mod hybrid;
mod hydraulic;
mod mechanical;
mod servo;
mod switched;

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

/// The parameter table `a` followed by `b` (`N = A + B`), for tables that
/// share rows (a metering's, a cylinder's, the seal terms).
pub(super) const fn join<const A: usize, const B: usize, const N: usize>(
    a: [ParamSpec; A],
    b: [ParamSpec; B],
) -> [ParamSpec; N] {
    assert!(A + B == N && A > 0, "N = A + B, A > 0");
    let mut out = [a[0]; N];
    let mut i = 0;
    while i < A {
        out[i] = a[i];
        i += 1;
    }
    while i < N {
        out[i] = b[i - A];
        i += 1;
    }
    out
}

/// Boxes a built component.
pub(super) fn built<C: Component + 'static>(c: C) -> Result<Box<dyn Component>, String> {
    Ok(Box::new(c))
}

pub(crate) use friction::law_of as friction_law_of;
pub(crate) use friction::terms_of as friction_terms_of;
pub(crate) use friction::typed_view_law as typed_view_friction_law;
pub(super) use mechanical::cylinder as cylinder_of;
pub(super) use servo::metering as metering_of;

static ALL: LazyLock<Vec<ComponentType>> = LazyLock::new(|| {
    [
        hydraulic::TYPES,
        servo::TYPES,
        mechanical::TYPES,
        friction::TYPES,
        hybrid::TYPES,
        control::TYPES,
        bench::TYPES,
        bench_friction::TYPES,
        switched::TYPES,
    ]
    .concat()
});

/// Every component type, in catalog order.
pub(super) fn all() -> &'static [ComponentType] {
    &ALL
}

#[cfg(test)]
mod tests {
    use super::super::registry::lookup;

    /// The summary of component type `ty`.
    fn summary(ty: &str) -> &'static str {
        lookup(ty).unwrap().summary
    }

    /// The catalog cites the thesis equations each type implements: eqs
    /// 6.12–6.15 are the hybrid drive's chamber equations and 6.16–6.19 its
    /// force balance and integrators, not valve laws; the thesis gives no
    /// check-valve law; the needle's area is eq 6.11 and its flow eq 6.1;
    /// LuGre's bristle state is eq 2.34; eqs 2.4–2.5 are the servovalve's
    /// amplifier, not an orifice.
    #[test]
    fn the_catalog_cites_the_thesis_equations_each_type_implements() {
        let check = summary("check_valve");
        assert!(check.contains("gives no check-valve law"), "{check}");
        assert!(!check.contains("eq"), "{check}");
        for needle in ["needle_valve", "servo_needle_valve"] {
            let s = summary(needle);
            assert!(s.contains("eq 6.1 ") && s.contains("eq 6.11"), "{s}");
            assert!(!s.contains("6.14") && !s.contains("6.19"), "{s}");
        }
        assert!(summary("friction_lugre").contains("eqs 2.34–2.36"));
        assert!(summary("orifice").contains("eq 6.1;"));
        assert!(!summary("orifice").contains("2.4"));
        assert!(!summary("friction_karnopp").contains("eq 2.39"));
        assert!(summary("friction_dahl").contains("section 2.4.2.2"));
    }
}
