//! The analytical X factor: eq 3.4, its exact factorisation, root selection.
//!
//! Notation used throughout (normalised port areas, eq 3.29):
//!
//! ```text
//!   a = 1 + t = Av1 / u0w      b = 1 - t = Av2 / u0w      K = 1 + gamma^3
//!   u = sqrt(K - X)   v = sqrt(X)   z = sqrt(K - gamma X)    (sqrt(gamma X) = sqrt(gamma) v)
//!   B = b + gamma^(3/2) a        C = gamma b
//!   eq 3.4:  F(X) = a u - b v - gamma (a sqrt(gamma) v - b z) = a u - B v + C z = 0
//! ```

use crate::error::XFactorError;
use crate::thesis::Complex;

/// Checks `gamma` (finite, >= 1) and `travel` (not NaN).
pub(crate) fn check_inputs(gamma: f64, travel: f64) -> Result<(), XFactorError> {
    if !(gamma.is_finite() && gamma >= 1.0) {
        return Err(XFactorError::GammaOutOfRange { gamma });
    }
    if travel.is_nan() {
        return Err(XFactorError::TravelNotANumber { travel });
    }
    Ok(())
}

/// Residual of the **unsquared** eq 3.4 with normalised port areas
/// `Av1 = 1 + travel`, `Av2 = 1 - travel`:
///
/// `F(X) = (1+t) sqrt(1+g^3-X) - (1-t) sqrt(X) - g [ (1+t) sqrt(g X) - (1-t) sqrt(1+g^3-g X) ]`.
///
/// Every square-root argument is non-negative exactly for `X` in
/// `[0, (1 + gamma^3) / gamma]`; outside that interval the residual is `NaN`.
/// `F` is strictly decreasing in `X` there for `travel` in `(-1, 1)` (see the
/// crate documentation), so the X factor is its only zero.
pub fn residual(gamma: f64, travel: f64, x: f64) -> f64 {
    let a = 1.0 + travel;
    let b = 1.0 - travel;
    let k = 1.0 + gamma * gamma * gamma;
    a * (k - x).sqrt()
        - b * x.sqrt()
        - gamma * (a * (gamma * x).sqrt() - b * (k - gamma * x).sqrt())
}

/// Coefficients `[c0, c1, c2]` (constant first) of a quadratic factor
/// `c2 X^2 + c1 X + c0` of the thesis's quartic (see [`quadratic_factors`]).
pub type Quadratic = [f64; 3];

/// Intermediate quantities shared by both quadratic factors.
struct Terms {
    a: f64,
    c: f64,
    k: f64,
    /// `a^2 - C^2`.
    e: f64,
    /// `gamma C^2 - a^2 = gamma^3 b^2 - a^2`.
    w: f64,
    /// `B = b + gamma^(3/2) a` (consistent factor).
    b_n: f64,
    /// `B'' = b - gamma^(3/2) a` (spurious factor).
    b_s: f64,
}

/// The terms, with differences that would cancel near `gamma = 1`,
/// `travel = 0` (the thesis's `a4 = 0`) written as products of differences of
/// the inputs: `a - C = 2t - (gamma - 1) b`, `B'' = -2t - (gamma^(3/2) - 1) a`,
/// `gamma^(3/2) b - a = (gamma^(3/2) - 1) b - 2t`. `g32m1` is
/// `gamma^(3/2) - 1`, computed by the caller as accurately as it needs.
#[inline(always)]
fn terms(gamma: f64, travel: f64, g32m1: f64) -> Terms {
    let a = 1.0 + travel;
    let b = 1.0 - travel;
    let c = gamma * b;
    let two_t = 2.0 * travel;
    let g32 = 1.0 + g32m1;
    Terms {
        a,
        c,
        k: 1.0 + gamma * gamma * gamma,
        e: (two_t - (gamma - 1.0) * b) * (a + c),
        w: (g32m1 * b - two_t) * (g32 * b + a),
        b_n: b + g32 * a,
        b_s: -two_t - g32m1 * a,
    }
}

/// `gamma^(3/2) - 1` without cancellation as `gamma -> 1`:
/// `(gamma - 1)(gamma^2 + gamma + 1) / (gamma^(3/2) + 1)`.
#[inline(always)]
fn g32m1_accurate(gamma: f64) -> f64 {
    (gamma - 1.0) * (gamma * gamma + gamma + 1.0) / (gamma * gamma.sqrt() + 1.0)
}

/// The factor `N_B(X) = (f^2 + 4 a^2 B^2) X^2 + 2K (e f - 2 a^2 B^2) X + e^2 K^2`
/// (with `e = a^2 - C^2`, `f = B^2 - a^2 + gamma C^2`) and its discriminant
/// over `16 K^2 a^2 B^2 C^2`, `D = B^2 - (gamma - 1) e`.
#[inline(always)]
fn factor(t: &Terms, gamma: f64, big_b: f64) -> (Quadratic, f64) {
    let Terms { a, k, e, w, .. } = *t;
    let f = big_b * big_b + w;
    let ab = a * big_b;
    let c2 = f * f + 4.0 * ab * ab;
    let c1 = 2.0 * k * (e * f - 2.0 * ab * ab);
    let c0 = e * e * k * k;
    let d = big_b * big_b - (gamma - 1.0) * e;
    ([c0, c1, c2], d)
}

/// The two quadratic factors of the thesis's quartic (eqs 3.15-3.17), scaled
/// to polynomials in the normalised port areas:
///
/// `a4 X^4 + a3 X^3 + a2 X^2 + a1 X + a0 = lambda * N(X) * N''(X)`,
/// `lambda = 1 / (16 a^4 b^4)`.
///
/// * `N` (first) is the product of the four sign patterns `a u +- B v +- C z`
///   of eq 3.4 with `B = b + gamma^(3/2) a`: the *consistent* factor, which
///   has the X factor as a root for every travel.
/// * `N''` (second) is the same with `B'' = b - gamma^(3/2) a`: it comes from
///   the thesis treating `sqrt(gamma X)` and `sqrt(X)` as independent radicals
///   while squaring; all its roots are spurious for eq 3.4 (one of them equals
///   the X factor only at the branch split, see [`branch_split`]).
///
/// Returns `[N, N'']`, each as `[c0, c1, c2]`. Valid for `travel` in `(-1, 1)`.
pub fn quadratic_factors(gamma: f64, travel: f64) -> [Quadratic; 2] {
    let t = terms(gamma, travel, g32m1_accurate(gamma));
    let (n, _) = factor(&t, gamma, t.b_n);
    let (n2, _) = factor(&t, gamma, t.b_s);
    [n, n2]
}

/// The thesis's quartic coefficients `[a0, a1, a2, a3, a4]` of eq 3.16,
/// computed as written (through m, n, p, q, h of eqs 3.7-3.12, with
/// `Av1 = 1 + travel`, `Av2 = 1 - travel`). For comparison and tests only:
/// these cancel catastrophically near `travel = +-1`, which is why
/// [`x_factor`] works with [`quadratic_factors`] instead.
pub fn thesis_quartic(gamma: f64, travel: f64) -> [f64; 5] {
    let av1 = 1.0 + travel;
    let av2 = 1.0 - travel;
    let r = gamma;
    let k = 1.0 + r.powi(3);
    let m = k * (av1 / (2.0 * av2) - av2 * r * r / (2.0 * av1));
    let n = k * (av1 / (2.0 * av2) - av2 / (2.0 * av1));
    let p = n * n + 1.0 + r.powi(6);
    let q = 2.0 * m * n + (1.0 + r.powi(5)) * k;
    let h = m * m;
    [
        h * h,
        -2.0 * q * h,
        (2.0 * p * h + q * q) - 4.0 * r.powi(5) * k * k,
        4.0 * r.powi(5) * (1.0 + r) * k - 2.0 * p * q,
        p * p - 4.0 * r.powi(6),
    ]
}

/// All four roots of the thesis's quartic (eq 3.17), computed stably from
/// its two quadratic factors: `[N_1, N_2, N''_1, N''_2]`, each factor's
/// roots by the cancellation-free formula (`q / c2` first, `c0 / q` second)
/// with the discriminant in factored form, `16 K^2 a^2 B^2 C^2 D`,
/// `D = B^2 - (gamma - 1)(a^2 - C^2)` (and the same with `B''` for `N''`,
/// whose `D''` can be negative: a complex pair). For `travel` strictly
/// inside `(-1, 1)`.
///
/// Near gamma = 1, travel = 0, where the thesis's `a4 = p^2 - 4 gamma^6`
/// tends to 0, all three coefficients of `N''` shrink together (like
/// `(gamma - 1)^2 + travel^2`): its roots stay finite, and they are computed
/// from differences of the inputs, not from `p^2 - 4 gamma^6`, which loses
/// all its digits there. Exactly at gamma = 1, travel = 0 the thesis's
/// quartic and `N''` vanish identically; the `N''` roots are then NaN while
/// the roots of `N` (1 and 0) are exact.
///
/// ```
/// use hydrocyl_xfactor::{quartic_roots, x_factor};
/// let r = quartic_roots(2.0, 0.3).unwrap();
/// assert!((r[0].re - x_factor(2.0, 0.3)).abs() < 1e-12 && r[0].im == 0.0);
/// ```
pub fn quartic_roots(gamma: f64, travel: f64) -> Result<[Complex; 4], XFactorError> {
    check_inputs(gamma, travel)?;
    if !(travel > -1.0 && travel < 1.0) {
        return Err(XFactorError::ParameterOutOfRange {
            what: "travel",
            value: travel,
            why: "the quartic is defined only inside the underlap, -1 < travel < 1",
        });
    }
    let t = terms(gamma, travel, g32m1_accurate(gamma));
    let pair = |big_b: f64| -> [Complex; 2] {
        let (n, d) = factor(&t, gamma, big_b);
        let scale = 4.0 * t.k * t.a * big_b.abs() * t.c;
        if d >= 0.0 {
            let (r0, r1) = stable_roots(n, scale * d.sqrt());
            [Complex::new(r0, 0.0), Complex::new(r1, 0.0)]
        } else {
            let [_, c1, c2] = n;
            let (re, im) = (-c1 / (2.0 * c2), scale * (-d).sqrt() / (2.0 * c2));
            [Complex::new(re, im), Complex::new(re, -im)]
        }
    };
    let [x0, x1] = pair(t.b_n);
    let [y0, y1] = pair(t.b_s);
    Ok([x0, x1, y0, y1])
}

/// The real roots of `c2 X^2 + c1 X + c0` with `sqrt(disc)` given, computed
/// without cancellation: `q = -(c1 + sign(c1) sqrt(disc)) / 2`, roots `q / c2`
/// and `c0 / q` (Vieta). A vanishing `c2` sends the first root to infinity and
/// leaves the second exact.
#[inline(always)]
fn stable_roots(c: Quadratic, sqrt_disc: f64) -> (f64, f64) {
    let [c0, c1, c2] = c;
    let q = -0.5 * (c1 + sqrt_disc.copysign(c1));
    (q / c2, c0 / q)
}

/// Eq 3.4 at `x`: `(F, a u + B v + C z, u, v, z)`; `None` outside the domain.
#[inline(always)]
fn eval(a: f64, big_b: f64, c: f64, k: f64, gamma: f64, x: f64) -> Option<[f64; 5]> {
    let ru = k - x;
    let rz = k - gamma * x;
    if !(x > 0.0 && ru > 0.0 && rz > 0.0) {
        return None;
    }
    let (u, v, z) = (ru.sqrt(), x.sqrt(), rz.sqrt());
    let (au, bv, cz) = (a * u, big_b * v, c * z);
    Some([au - bv + cz, au + bv + cz, u, v, z])
}

/// The roots of the consistent factor `N` and the selected one, with the
/// relative residual of eq 3.4 at each (`f64::INFINITY` outside the domain).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Selection {
    /// The two roots of `N` (larger-magnitude formula root first).
    pub roots: [f64; 2],
    /// `|F(X)| / (a u + B v + C z)` at each root: the relative residual of eq 3.4.
    pub relative_residual: [f64; 2],
    /// Index into `roots` of the root chosen by the rule.
    pub chosen: usize,
    /// The chosen root after one Newton step on the unsquared eq 3.4.
    pub x: f64,
}

/// A candidate root whose relative residual in eq 3.4 is at most this is
/// accepted without evaluating the other candidate. Exactly one root of `N`
/// satisfies eq 3.4 (crate docs); a spurious root can pass this test only
/// where it has merged with the true one (underlap edges), within about
/// `1e-9 X`, and the Newton step then lands on the true root.
const ACCEPT: f64 = 1e-9;

/// The terms, `B`, and the two roots of `N` (`q/c2` first, then `c0/q`).
#[inline(always)]
fn roots_of_n(gamma: f64, travel: f64) -> (Terms, f64, f64, f64) {
    // the consistent factor needs no care near gamma = 1: plain gamma^(3/2) - 1
    let t = terms(gamma, travel, gamma * gamma.sqrt() - 1.0);
    let big_b = t.b_n;
    let (n, d) = factor(&t, gamma, big_b);
    // sqrt of the discriminant c1^2 - 4 c2 c0 = 16 K^2 a^2 B^2 C^2 D (D > 0 here).
    let sqrt_disc = 4.0 * t.k * t.a * big_b * t.c * d.sqrt();
    let (r0, r1) = stable_roots(n, sqrt_disc);
    (t, big_b, r0, r1)
}

/// One Newton step on the unsquared eq 3.4 from `root`, where `ev = eval(root)`:
/// `F' = -(a/u + B/v + gamma C/z)/2 < 0`, bounded away from zero on
/// `[1, gamma^2]`; written with a single division.
#[inline(always)]
fn newton(t: &Terms, big_b: f64, gamma: f64, root: f64, ev: [f64; 5]) -> f64 {
    let [f, _, u, v, z] = ev;
    let uv = u * v;
    let num = t.a * v * z + big_b * u * z + gamma * t.c * uv;
    root + 2.0 * f * uv * z / num
}

/// Index (0 or 1) of the candidate with the smaller relative residual;
/// `|F0| / S0` vs `|F1| / S1` compared without dividing.
#[inline(always)]
fn smaller_residual(e0: Option<[f64; 5]>, e1: Option<[f64; 5]>) -> usize {
    match (e0, e1) {
        (Some(p), Some(q)) => usize::from(q[0].abs() * p[1] < p[0].abs() * q[1]),
        (None, Some(_)) => 1,
        _ => 0,
    }
}

/// The X factor strictly inside the underlap, `gamma >= 1` (unchecked): the
/// selection rule with the early acceptance of [`ACCEPT`].
#[inline(always)]
pub(crate) fn x_inside(gamma: f64, travel: f64) -> f64 {
    let (t, big_b, r0, r1) = roots_of_n(gamma, travel);
    let e0 = eval(t.a, big_b, t.c, t.k, gamma, r0);
    if let Some(p) = e0 {
        if p[0].abs() <= ACCEPT * p[1] {
            return newton(&t, big_b, gamma, r0, p);
        }
    }
    let e1 = eval(t.a, big_b, t.c, t.k, gamma, r1);
    match (smaller_residual(e0, e1), e0, e1) {
        (0, Some(p), _) => newton(&t, big_b, gamma, r0, p),
        (1, _, Some(q)) => newton(&t, big_b, gamma, r1, q),
        // neither candidate is in the domain: cannot happen for gamma >= 1,
        // -1 < travel < 1 (X* is a root of N in [1, gamma^2]); NaN, not a guess
        _ => f64::NAN,
    }
}

/// Roots of `N` and the full selection rule (both residuals), for `travel`
/// strictly inside (-1, 1) and `gamma >= 1` (unchecked).
pub(crate) fn select(gamma: f64, travel: f64) -> Selection {
    let (t, big_b, r0, r1) = roots_of_n(gamma, travel);
    let e0 = eval(t.a, big_b, t.c, t.k, gamma, r0);
    let e1 = eval(t.a, big_b, t.c, t.k, gamma, r1);
    let chosen = smaller_residual(e0, e1);
    let (root, ev) = if chosen == 0 { (r0, e0) } else { (r1, e1) };
    let x = ev.map_or(f64::NAN, |p| newton(&t, big_b, gamma, root, p));
    let rel = |e: Option<[f64; 5]>| e.map_or(f64::INFINITY, |p| (p[0] / p[1]).abs());
    Selection {
        roots: [r0, r1],
        relative_residual: [rel(e0), rel(e1)],
        chosen,
        x,
    }
}

/// Leaney's X factor from the exact analytical root (thesis eqs 2.25 / 3.4, 3.29).
///
/// `travel` is the spool position over the underlap, `x_s / u0`: the valve is
/// inside its underlap for `travel` in `(-1, 1)`. `gamma = A1 / A2 >= 1` is the
/// cylinder area ratio.
///
/// * `travel >= 1` (extending, `Av2 = 0`): `X = 1`;
/// * `travel <= -1` (retracting, `Av1 = 0`): `X = gamma^2`;
/// * inside: the root of the consistent quadratic factor of the thesis's
///   quartic that satisfies the unsquared eq 3.4 (see the crate docs for the
///   rule and the proof that it picks exactly one root), polished by one
///   Newton step on eq 3.4.
///
/// Bad input (`gamma` NaN, infinite or `< 1`, `travel` NaN) gives `NaN`; use
/// [`x_factor_checked`] to get an error naming the argument instead.
///
/// ```
/// use hydrocyl_xfactor::x_factor;
/// let gamma = 11.43 / 5.8; // Leaney's Moog rig, Table 3-3
/// assert_eq!(x_factor(gamma, 1.0), 1.0);
/// assert!((x_factor(gamma, -1.0) - gamma * gamma).abs() < 1e-15);
/// // x_s = 0 (null spool): the thesis lists 2.637188916
/// assert!((x_factor(gamma, 0.0) / 2.637188916 - 1.0).abs() < 1e-6);
/// ```
#[inline]
pub fn x_factor(gamma: f64, travel: f64) -> f64 {
    if !(gamma.is_finite() && gamma >= 1.0) || travel.is_nan() {
        return f64::NAN;
    }
    if travel >= 1.0 {
        return 1.0;
    }
    if travel <= -1.0 {
        return gamma * gamma;
    }
    x_inside(gamma, travel)
}

/// [`x_factor`] with input checking: an error naming the argument for a
/// `gamma` that is NaN, infinite or below 1, or a NaN `travel`.
pub fn x_factor_checked(gamma: f64, travel: f64) -> Result<f64, XFactorError> {
    check_inputs(gamma, travel)?;
    Ok(x_factor(gamma, travel))
}

/// The roots of the consistent factor `N`, their residuals in the unsquared
/// eq 3.4 and the one the rule picks, for `travel` strictly inside `(-1, 1)`.
/// (For inspection and for the tests of the selection rule; [`x_factor`] is
/// the function to call.)
pub fn selection(gamma: f64, travel: f64) -> Result<Selection, XFactorError> {
    check_inputs(gamma, travel)?;
    if !(travel > -1.0 && travel < 1.0) {
        return Err(XFactorError::ParameterOutOfRange {
            what: "travel",
            value: travel,
            why: "the roots exist only inside the underlap, -1 < travel < 1",
        });
    }
    Ok(select(gamma, travel))
}

/// The normalised spool travel that gives the same X factor as the port
/// opening areas `av1` (supply to chamber 1, chamber 2 to tank) and `av2`
/// (supply to chamber 2, chamber 1 to tank) of a symmetric-ported valve:
/// eq 3.4 is homogeneous in `(Av1, Av2)`, so X depends on
/// `travel = (Av1 - Av2) / (Av1 + Av2)` only, whatever the port geometry.
///
/// `Av2 = 0 < Av1` gives 1, `Av1 = 0 < Av2` gives -1. Both zero (valve shut),
/// a negative or non-finite area is an error.
pub fn travel_from_port_areas(
    av1: hydrocyl_ports::Area,
    av2: hydrocyl_ports::Area,
) -> Result<f64, XFactorError> {
    let (a1, a2) = (av1.m2(), av2.m2());
    for (what, v) in [("av1", a1), ("av2", a2)] {
        if !(v.is_finite() && v >= 0.0) {
            return Err(XFactorError::ParameterOutOfRange {
                what,
                value: v,
                why: "a port opening area must be finite and >= 0 m^2",
            });
        }
    }
    if a1 + a2 <= 0.0 {
        return Err(XFactorError::ParameterOutOfRange {
            what: "av1 + av2",
            value: a1 + a2,
            why: "both ports are shut: X is undefined when no port is open",
        });
    }
    Ok((a1 - a2) / (a1 + a2))
}

/// Where the selected root changes algebraic branch (see the crate docs,
/// "Branch split").
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BranchSplit {
    /// The travel `t_s = (1 - sqrt(gamma)) / (1 + sqrt(gamma))` in `[-1, 0]`.
    pub travel: f64,
    /// The X factor there, `1 - gamma + gamma^2`.
    pub x: f64,
    /// Share of the underlap `[-1, 1]` on the retracting side of the split,
    /// `(t_s + 1) / 2 = 1 / (1 + sqrt(gamma))` (the thesis's "percentage of X4").
    pub share_x4: f64,
    /// `1 - share_x4 = sqrt(gamma) / (1 + sqrt(gamma))` (the thesis's "percentage of X1").
    pub share_x1: f64,
}

/// The exact branch split for area ratio `gamma`: the travel at which the
/// thesis's quartic has a double root at the X factor, i.e. where both sides
/// of eq 3.4 vanish (no flow through either chamber at zero load). There the
/// root that the thesis's formula 3.20 labels `X4` hands over to the one it
/// labels `X1`.
///
/// ```
/// use hydrocyl_xfactor::{branch_split, x_factor};
/// let s = branch_split(4.0).unwrap();
/// assert!((s.share_x1 - 2.0 / 3.0).abs() < 1e-15); // Table 3-4: 66.7 %
/// assert!((x_factor(4.0, s.travel) - s.x).abs() < 1e-12);
/// ```
pub fn branch_split(gamma: f64) -> Result<BranchSplit, XFactorError> {
    check_inputs(gamma, 0.0)?;
    let s = gamma.sqrt();
    let travel = (1.0 - s) / (1.0 + s);
    let share_x4 = 1.0 / (1.0 + s);
    Ok(BranchSplit {
        travel,
        x: 1.0 - gamma + gamma * gamma,
        share_x4,
        share_x1: s / (1.0 + s),
    })
}
