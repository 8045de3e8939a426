//! A member's flow into an algebraic node as an orifice law
//! ([`OrificeInflow`]), and the root of two such laws in series found on the
//! laws alone ([`orifice_pair_root`]): the series solve's fast path
//! ([`crate::series`]).

use super::NEWTON_ITERATIONS;
use crate::wires::{HydraulicNode, Wire, Wires};
use hydrocyl_ports::Pressure;
use hydrocyl_valves::needle::NeedleValve;
use hydrocyl_valves::orifice::{signed_sqrt_regularised, signed_sqrt_regularised_derivative};

/// A member's flow into an algebraic node as an orifice law of the node's
/// pressure `p` ([`Component::orifice_inflow`](crate::circuit::Component::orifice_inflow)):
/// `Q_in(p) = k · s(other − p)`, with `s` the signed square root
/// regularised below `transition` (`hydrocyl_valves::orifice::signed_sqrt_regularised`),
/// for `p` in `valid` (outside it, another branch of the member's law holds:
/// a check valve beside it that cracks).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrificeInflow {
    /// Flow coefficient `k` \[m³·s⁻¹·Pa^-½\].
    pub k: f64,
    /// The pressure on the member's other side \[Pa\].
    pub other: f64,
    /// The regularisation's transition pressure drop \[Pa\].
    pub transition: f64,
    /// The node pressures for which the law holds, `(low, high)` \[Pa\].
    pub valid: (f64, f64),
}

impl OrificeInflow {
    /// The inflow into `node` of an orifice flow `Q = k·s(p_a − p_b)` from
    /// port `a` to port `b` (`Q_in = k·s(p_b − p)` at `a`, `k·s(p_a − p)` at
    /// `b`), holding for every node pressure; `None` when `node` is neither
    /// port or both.
    pub fn between(
        k: f64,
        transition: f64,
        (a, b): (HydraulicNode, HydraulicNode),
        w: &Wires,
        node: Wire<Pressure>,
    ) -> Option<Self> {
        let other = match (node == a.pressure, node == b.pressure) {
            (true, false) => b.pressure,
            (false, true) => a.pressure,
            _ => return None,
        };
        Some(Self {
            k,
            other: w.get(other).si(),
            transition,
            valid: (f64::NEG_INFINITY, f64::INFINITY),
        })
    }

    /// `∂Q_in/∂p` of the law at node pressure `p` \[m³·s⁻¹·Pa⁻¹\]:
    /// `−k·s′(other − p)`.
    pub fn slope(&self, p: f64) -> f64 {
        -(self.k * signed_sqrt_regularised_derivative(self.other - p, self.transition))
    }

    /// Whether the law holds at node pressure `p` (`p` in `valid`).
    pub fn holds(&self, p: f64) -> bool {
        p >= self.valid.0 && p <= self.valid.1
    }

    /// The inflow into `node` of needle valve `v` from `i` to `o`: its
    /// metered orifice, where its reverse check (`o → i`) stays shut (the
    /// drop `p_o − p_i` at most the check's cracking pressure).
    pub fn needle(
        v: &NeedleValve,
        (i, o): (HydraulicNode, HydraulicNode),
        w: &Wires,
        node: Wire<Pressure>,
    ) -> Option<Self> {
        let mut law = Self::between(
            v.coefficient(),
            v.orifice.dp_transition.si(),
            (i, o),
            w,
            node,
        )?;
        let crack = v.reverse_check.cracking.si();
        law.valid = if node == i.pressure {
            (law.other - crack, f64::INFINITY)
        } else {
            (f64::NEG_INFINITY, law.other + crack)
        };
        Some(law)
    }
}

/// The root of two [`OrificeInflow`]s in series, `Σ k·s(other − p) = 0`,
/// and `∂ΣQ_in/∂p` there, found on the laws alone (no member evaluated):
/// Newton's method on their analytic slope, kept inside the bracket by
/// bisection, from the root of the plain square roots,
/// `p = (k_a² p_a + k_b² p_b) / (k_a² + k_b²)` (exact where neither drop is
/// in its transition; a shut member, `k = 0`, leaves the other's own
/// pressure), or from `guess` (the last solution) where a drop there is in
/// its transition. `None` when the root is outside `[lo, hi]` or where a
/// member's law holds, the coefficients are not usable, or it does not
/// converge to `tol`.
pub(super) fn orifice_pair_root(
    a: OrificeInflow,
    b: OrificeInflow,
    (lo, hi): (f64, f64),
    tol: f64,
    guess: f64,
) -> Option<(f64, f64)> {
    let (ka, kb) = (a.k * a.k, b.k * b.k);
    if !(a.k >= 0.0 && b.k >= 0.0 && ka + kb > 0.0 && (ka + kb).is_finite()) {
        return None;
    }
    let inflow = |p: f64| {
        a.k * signed_sqrt_regularised(a.other - p, a.transition)
            + b.k * signed_sqrt_regularised(b.other - p, b.transition)
    };
    let slope = |p: f64| a.slope(p) + b.slope(p);
    // the inflow falls with p from positive below both sides to negative
    // above them: the root lies between them
    let (mut x0, mut x1) = (a.other.min(b.other), a.other.max(b.other));
    let plain = if a.k == 0.0 || a.other == b.other {
        b.other
    } else if b.k == 0.0 {
        a.other
    } else {
        ((ka * a.other + kb * b.other) / (ka + kb)).clamp(x0, x1)
    };
    // the plain root is the root where neither drop is in its transition,
    // or no flow passes (a shut member, or both sides at one pressure);
    // else a guess near it (the last solve's) saves iterations
    let still = a.k == 0.0 || b.k == 0.0 || a.other == b.other;
    let in_transition = |m: OrificeInflow| (m.other - plain).abs() < m.transition;
    let exact = still || !(in_transition(a) || in_transition(b));
    let mut p = if !exact && guess > x0 && guess < x1 {
        guess
    } else {
        plain
    };
    let mut root = exact.then_some(plain);
    for _ in 0..if exact { 0 } else { NEWTON_ITERATIONS } {
        let r = inflow(p);
        if r == 0.0 {
            root = Some(p);
            break;
        }
        if r > 0.0 {
            x0 = p;
        } else {
            x1 = p;
        }
        let step = -r / slope(p);
        if step.abs() <= tol || x1 - x0 <= tol {
            root = Some(p);
            break;
        }
        let next = p + step;
        p = if next > x0 && next < x1 {
            next
        } else {
            0.5 * (x0 + x1)
        };
    }
    let p = root?;
    let s = slope(p);
    (p >= lo && p <= hi && a.holds(p) && b.holds(p) && s < 0.0 && s.is_finite()).then_some((p, s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::series::SERIES_RTOL;

    /// The root of `Σ k·s(other − p)` by bisection to the last bit.
    fn bisected(laws: [OrificeInflow; 2]) -> f64 {
        let q = |p: f64| {
            laws.iter()
                .map(|m| m.k * signed_sqrt_regularised(m.other - p, m.transition))
                .sum::<f64>()
        };
        let (mut a, mut b) = (
            laws[0].other.min(laws[1].other),
            laws[0].other.max(laws[1].other),
        );
        while b - a > 0.0 {
            let m = 0.5 * (a + b);
            if m <= a || m >= b {
                break;
            }
            if q(m) > 0.0 {
                a = m;
            } else {
                b = m;
            }
        }
        0.5 * (a + b)
    }

    fn law(k: f64, other: f64) -> OrificeInflow {
        OrificeInflow {
            k,
            other,
            transition: 1e3,
            valid: (f64::NEG_INFINITY, f64::INFINITY),
        }
    }

    proptest::proptest! {
        /// The pair's root found on the laws is the bisected root, within
        /// the solve's tolerance, in either regime (drops far above their
        /// transition, or inside it) and from any guess.
        #[test]
        fn the_orifice_pair_root_is_the_bisected_root(
            ka in 1e-10f64..1e-6,
            kb in 1e-10f64..1e-6,
            pa in -1e5f64..3e7,
            drop in proptest::prop_oneof![0.0f64..2e3, 0.0f64..3e7],
            at in 0.0f64..1.0,
        ) {
            let (a, b) = (law(ka, pa), law(kb, pa - drop));
            let (lo, hi) = (pa - drop, pa);
            let tol = SERIES_RTOL * lo.abs().max(hi.abs()).max(1e5);
            let guess = lo + at * (hi - lo);
            let (p, s) = orifice_pair_root(a, b, (lo, hi), tol, guess).unwrap();
            let exact = bisected([a, b]);
            // a step of the residual over the slope below tol: the root to
            // a few tol (the slope changes little over it)
            proptest::prop_assert!((p - exact).abs() <= 4.0 * tol + 4.0 * f64::EPSILON * exact.abs(), "{} {} {}", p, exact, tol);
            proptest::prop_assert!(s < 0.0);
        }
    }

    proptest::proptest! {
        /// The law's slope (the default `Component::inflow_slope` of a
        /// member that declares a law) is the derivative of its inflow: a
        /// central difference agrees, inside the transition and outside.
        #[test]
        fn the_slope_is_the_inflows_derivative(
            k in 1e-10f64..1e-6,
            drop in proptest::prop_oneof![-2e3f64..2e3, -3e7f64..3e7],
        ) {
            let m = law(k, 1e6);
            let p = 1e6 - drop;
            // h small against the drop and the transition: a difference
            // across the transition's edge (a jump in the second
            // derivative) errs by ~h/transition; and large against p's
            // last bits (p ± h is rounded at p's ulp, ~1e-10 at 1 MPa: a
            // step of 1e-6 Pa would carry a 1e-4 error)
            let h = (1e-6 * drop.abs().max(1.0).min(m.transition)).max(1e-9 * p.abs());
            let q = |p: f64| m.k * signed_sqrt_regularised(m.other - p, m.transition);
            let fd = (q(p + h) - q(p - h)) / (2.0 * h);
            proptest::prop_assert!(m.slope(p) < 0.0);
            proptest::prop_assert!((m.slope(p) - fd).abs() <= 1e-5 * fd.abs(), "{} {}", m.slope(p), fd);
        }
    }

    #[test]
    fn a_shut_member_or_equal_sides_leave_no_flow() {
        let tol = SERIES_RTOL * 1e5;
        // a shut member: the other's own pressure, where it passes nothing
        let (p, _) =
            orifice_pair_root(law(0.0, 5e6), law(1e-7, 2e5), (2e5, 5e6), tol, 3e6).unwrap();
        assert_eq!(p, 2e5);
        let (p, _) =
            orifice_pair_root(law(1e-8, 7e5), law(1e-7, 7e5), (6e5, 8e5), tol, 7.5e5).unwrap();
        assert_eq!(p, 7e5);
        // both shut: nothing to solve on
        assert!(orifice_pair_root(law(0.0, 5e6), law(0.0, 2e5), (2e5, 5e6), tol, 3e6).is_none());
        // a root where one member's law does not hold (its check cracks)
        let mut cracked = law(1e-7, 2e5);
        cracked.valid = (3e6, f64::INFINITY);
        assert!(orifice_pair_root(law(1e-7, 5e6), cracked, (2e5, 5e6), tol, 3e6).is_none());
    }
}
