//! # hydrocyl-xfactor — Leaney's X factor (thesis chapter 3.2)
//!
//! A symmetric-ported four-way valve driving a single-rod cylinder, seen
//! through Leaney's *generalised* equations: one effective load pressure
//! `P_LE` instead of two chamber pressures, and a factor X that tells how the
//! supply pressure splits between the chambers. Outside the valve's underlap X
//! is 1 (extending) or `gamma^2` (retracting); inside it X is the root of the
//! implicit eq 2.25 / 3.4. This crate computes that root exactly and fast,
//! gives the Brent reference, the steady chamber pressures of section 3.3.4,
//! and the small algebra of the one-pressure actuator (eqs 2.16-2.26) that the
//! valve-rig model uses.
//!
//! ```text
//!             Ps [Pa]                 T (0 Pa)
//!               |                        |
//!        +------+------------------------+------+
//!        |  four-way valve, underlap u0 [m]     |   travel t = x_s / u0 [-]
//!        |  Av1 ~ (1+t): P->A, B->T            |   Av1, Av2 [m^2]
//!        |  Av2 ~ (1-t): P->B, A->T            |
//!        +------+------------------------+------+
//!           A   | Q1 [m^3/s]             | B  Q2 [m^3/s]
//!        +------+------------------------+-------------+
//!        |  p1 [Pa], A1 [m^2]  | piston |  p2 [Pa], A2 [m^2] ===> F [N], v [m/s]
//!        +---------------------------------------------+
//!          gamma = A1 / A2 >= 1 [-]
//!          X = (p1 + gamma^2 p2) / Ps [-]     P_LE = (p1 A1 - p2 A2) / A_E [Pa]
//! ```
//!
//! ## Equations implemented
//!
//! | thesis | here |
//! |---|---|
//! | 2.16 effective area and load pressure | [`effective_area`], [`load_pressure`] |
//! | 2.21, 2.22 chamber pressures from `P_LE` and X | [`chamber_pressures_from_load_pressure`], inverse [`load_pressure_and_x`] |
//! | 2.24 effective total volume | [`effective_total_volume`] |
//! | 2.25 = 3.4 the implicit equation for X | [`residual`] |
//! | 2.26 effective load flow | [`effective_load_flow`] |
//! | 3.5-3.19 the quartic | [`thesis_quartic`], factored exactly by [`quadratic_factors`]; all four roots stably: [`quartic_roots`] |
//! | 3.20-3.22 Ferrari's formula, root names X1..X4 | [`thesis::ferrari_roots`] |
//! | 3.29 X depends on gamma and travel only | every function takes `(gamma, travel)`; [`travel_from_port_areas`] |
//! | 3.30, Table 3-4 the fitted root split | [`branch_split`] (exact), [`thesis::fit_share_x1`] (the fit) |
//! | 3.3.4 steady pressures | [`steady_pressures`]; without the zero-load X: [`steady_pressures_two_chamber`], [`x_factor_loaded`] |
//!
//! Units: SI throughout; pressures, areas, forces, flows and volumes are the
//! typed quantities of `hydrocyl-ports`. X, gamma and travel are numbers.
//!
//! ## Example
//!
//! ```
//! use hydrocyl_xfactor::{x_factor, x_factor_numerical, branch_split};
//!
//! let gamma = 11.43 / 5.8; // Leaney's Moog rig
//! let x = x_factor(gamma, -0.2);
//! let reference = x_factor_numerical(gamma, -0.2, 1e-14);
//! assert!((x - reference).abs() <= 1e-12 * x);
//! assert!(x >= 1.0 && x <= gamma * gamma);
//! // where the thesis's root X4 hands over to X1 (Table 3-4: 41.67 % / 58.33 %)
//! let split = branch_split(gamma).unwrap();
//! assert!((split.share_x4 - 0.4160).abs() < 1e-4);
//! ```
//!
//! ## Using X in the generalised (one-pressure) actuator
//!
//! Leaney's generalised form (eqs 2.16-2.26, 3.3) integrates one state, the
//! effective load pressure `P_LE`, instead of p1 and p2. Per right-hand-side
//! evaluation:
//!
//! 1. `t = x_s / u0` for the symmetric underlap of eq 3.2, or in general
//!    [`travel_from_port_areas`]`(Av1, Av2)` (eq 3.4 is homogeneous in the areas);
//! 2. `X = `[`x_factor`]`(gamma, t)` (1 or `gamma^2` outside the underlap);
//! 3. `Q_LE = `[`effective_load_flow`] (eq 2.26), `Q_DE = A_E v`,
//!    `Q_CE = Q_LE - Q_DE - Q_KE` (eq 3.3, `Q_KE` leakage);
//! 4. `dP_LE/dt = 4 B / V_TE * Q_CE` (eq 2.23) with
//!    `V_TE = `[`effective_total_volume`]`(V1, V2, A1, A2)` (eq 2.24);
//! 5. p1, p2 for the force balance, the friction model and the outputs from
//!    [`chamber_pressures_from_load_pressure`] (eqs 2.21, 2.22); the force is
//!    `P_LE A_E` exactly. [`load_pressure_and_x`] is the inverse (initial
//!    conditions from chamber pressures: `X = (p1 + gamma^2 p2) / Ps`).
//!
//! Inside the underlap eq 3.4 is the zero-load condition: under a load the
//! two-chamber steady state has a different X ([`x_factor_loaded`],
//! [`steady_pressures_two_chamber`]); at 70 bar and 1 kN on Leaney's rig
//! p1 differs by about 0.8 bar at the null spool (`cargo xtask xfactor`).
//!
//! ## The exact solution
//!
//! Write `a = 1 + t`, `b = 1 - t` (port areas over the underlap, eq 3.29),
//! `K = 1 + gamma^3`, `u = sqrt(K - X)`, `v = sqrt(X)`, `z = sqrt(K - gamma X)`
//! and note `sqrt(gamma X) = sqrt(gamma) v`. Eq 3.4 is
//! `F(X) = a u - B v + C z = 0` with `B = b + gamma^(3/2) a`, `C = gamma b`.
//! The product of its four sign patterns `a u +- B v +- C z` is a polynomial
//! in X of degree **two**, `N(X)`; the thesis's quartic (3.15) treats
//! `sqrt(gamma X)` as a radical of its own and is `N(X) N''(X)` up to a
//! positive factor, where `N''` has `B'' = b - gamma^(3/2) a` and only
//! spurious roots ([`quadratic_factors`]). [`x_factor`] solves `N` with the
//! cancellation-free quadratic formula (both roots, Vieta for the small one),
//! so the thesis's degenerate cases never arise: `N`'s leading coefficient is
//! `f^2 + 4 a^2 B^2 > 0` inside the underlap, while `a4 -> 0` (gamma -> 1 at
//! the null spool, where the thesis's quartic even vanishes identically) lives
//! entirely in `N''`.
//!
//! ## Root selection, and why it picks exactly one root
//!
//! Rule: among the real roots of `N`, take the one at which every square-root
//! argument of eq 3.4 is non-negative (`0 <= X <= K / gamma`) and the
//! *unsquared* residual `|F(X)| / (a u + B v + C z)` is smallest; then polish
//! it with one Newton step on `F`. (Shortcut, same answer: a first candidate
//! with relative residual below 1e-9 is taken without evaluating the second;
//! only one root can pass unless the two have merged at an underlap edge.)
//!
//! * On `D = [0, K/gamma]` every term of `F` is monotone the same way (`a u`
//!   and `C z` fall, `B v` rises), so `F` is strictly decreasing: at most one
//!   zero.
//! * `F(1) = b (gamma sqrt(K - gamma) - 1) >= 0` and
//!   `F(gamma^2) = a (sqrt(1 + gamma^3 - gamma^2) - gamma^(5/2)) <= 0`, so that
//!   zero `X*` exists and lies in `[1, gamma^2]`.
//! * `X*` is a root of `N` (it zeroes one of `N`'s factors), and `N`'s two roots
//!   are distinct inside the underlap (its discriminant is
//!   `16 K^2 a^2 B^2 C^2 D` with `D = B^2 - (gamma - 1)(a^2 - C^2) > 0`). The other
//!   root is either outside `D` or has `F != 0`: exactly one root qualifies.
//!   Only at the underlap edges (`a -> 0` or `b -> 0`) do the two roots merge,
//!   and there either one is the answer.
//!
//! ## Branch split
//!
//! The thesis names the quartic's roots X1..X4 in the order of Ferrari's
//! formula 3.20 and finds that X is X4 on the retracting side and X1 on the
//! extending side. hydrocyl defines the **branch split** as the travel where
//! the selected root stops being the thesis's X4 and becomes X1. That happens
//! where a spurious root of the quartic crosses X* (a double root, the
//! thesis's own condition 3.23 `X4 = X1`): where both sides of eq 3.4 vanish,
//! i.e. no flow through the valve at zero load. Solving gives, exactly,
//! `t_s = (1 - sqrt(gamma)) / (1 + sqrt(gamma))`, `X(t_s) = 1 - gamma + gamma^2`,
//! share of X4 `= 1 / (1 + sqrt(gamma))` ([`branch_split`]). The thesis's
//! Table 3-4 and fit 3.30 approximate this to within ~1 percentage point.
//!
//! See `docs/xfactor.md` for the derivation, the comparison with the thesis
//! and the benchmark numbers.
#![warn(missing_docs)]

mod analytical;
mod error;
mod generalised;
mod numerical;
pub mod thesis;

pub use analytical::{
    branch_split, quadratic_factors, quartic_roots, residual, selection, thesis_quartic,
    travel_from_port_areas, x_factor, x_factor_checked, BranchSplit, Quadratic, Selection,
};
pub use error::XFactorError;
pub use generalised::{
    chamber_pressures_from_load_pressure, effective_area, effective_load_flow,
    effective_total_volume, load_pressure, load_pressure_and_x, steady_pressures,
    steady_pressures_two_chamber, x_factor_loaded, ChamberPressures, PortOrifices, SteadyPressures,
};
pub use numerical::{
    brent, x_factor_brent, x_factor_numerical, x_factor_numerical_checked, BrentSolution,
    MAX_ITERATIONS,
};
