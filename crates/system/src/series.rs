//! Algebraic hydraulic nodes: two or more resistive components in series,
//! and the evaluation order of a circuit around them.
//!
//! A hydraulic node normally has an owner that sets its pressure from a
//! state (a volume, a chamber) or holds it fixed (a source). Between two
//! resistive components (a valve's return port and a needle valve, two
//! orifices in series) there is no volume worth a state: the node's pressure
//! is the one at which the flows into it sum to zero,
//!
//! ```text
//!   ΣQ_in(p) = 0,      p ∈ [min p_neighbour, max p_neighbour]
//!   chamber ══[ pilot valve ]══ T port (p solved) ══[ needle ]══ tank
//! ```
//!
//! Such a node is declared explicitly with an [`AlgebraicNode`] component (a
//! node without an owner stays a build error). The assembler gathers the
//! components that connect to the node (its *members*) and evaluates them as
//! one unit in the dependency order. Where the node has two members that
//! declare their flow into it as an orifice law
//! ([`Component::orifice_inflow`]: a valve's return edge and a needle, two
//! orifices), the root is found on those laws alone (closed form for the
//! square roots, a few Newton steps where a drop is in the regularisation's
//! transition) and the members are evaluated once, there; their residual
//! must pass the convergence test below, else the solve goes on from there.
//! Otherwise each evaluation solves `ΣQ_in(p) = 0`
//! by Newton's method on the members' analytic slopes
//! ([`Component::inflow_slope`]), then secants, then inverse quadratic
//! interpolation through the last three trials (which follows the bend of a
//! square-root law near a small pressure drop). It starts from the previous
//! solution, or from the line through the last two extended to its time when
//! it comes shortly after both, and is kept inside the bracket given by the
//! lowest and highest pressure the members read elsewhere (each resistive
//! flow into the node falls monotonically with `p`, so the root is bracketed
//! and unique): a step that leaves the bracket, or a member without a slope,
//! falls back to bisection and Brent's method. Converged when the step is
//! below [`SERIES_RTOL`] of the pressure scale; only a converged evaluation
//! is kept (every trial starts from the accumulators as they were before the
//! members added to them; the other wires a member writes in `evaluate` it
//! writes anew on every call, which debug builds check).
//! The result depends on the starting point only within that tolerance;
//! [`Circuit::reset`](crate::Circuit::reset) forgets it.

use crate::circuit::{BuildError, Component, Probe};
use crate::wires::{HydraulicNode, Wire, Wires};
use crate::Netlist;
use hydrocyl_ports::Pressure;
use hydrocyl_valves::needle::NeedleValve;
use hydrocyl_valves::orifice::{signed_sqrt_regularised, signed_sqrt_regularised_derivative};
use std::cell::Cell;

/// Relative tolerance of the series solve on the node pressure (of the
/// bracket's largest magnitude, floored at 1 bar).
pub const SERIES_RTOL: f64 = 1e-14;

/// Newton iterations (each safeguarded by bisection) before the solve falls
/// back to Brent's method; on the hybrid rig a solve takes ~2 evaluations.
const NEWTON_ITERATIONS: usize = 100;

/// Declares hydraulic node `node` algebraic: no component owns it, the
/// assembler solves its pressure so that the flows into it sum to zero.
/// Every component connected to it must be resistive (flows only, falling
/// with the node pressure).
#[derive(Debug)]
pub struct AlgebraicNode {
    name: String,
    node_name: String,
    probe: Option<String>,
    node: HydraulicNode,
}

impl AlgebraicNode {
    /// Node `node` solved by the assembler; `probe` names its pressure as
    /// an output column.
    pub fn new(name: &str, node: &str, probe: Option<&str>) -> Self {
        Self {
            name: name.into(),
            node_name: node.into(),
            probe: probe.map(str::to_string),
            node: HydraulicNode::UNBOUND,
        }
    }
}

impl Component for AlgebraicNode {
    fn name(&self) -> &str {
        &self.name
    }
    fn has_tangents(&self) -> bool {
        true
    }
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
        self.node = net.solve_hydraulic(&self.node_name)?;
        Ok(())
    }
    fn probes(&self) -> Vec<Probe> {
        self.probe
            .iter()
            .map(|n| Probe::of(n.clone(), self.node.pressure))
            .collect()
    }
}

/// A member's flow into an algebraic node as an orifice law of the node's
/// pressure `p` ([`Component::orifice_inflow`]):
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
fn orifice_pair_root(
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
    let slope = |p: f64| {
        -(a.k * signed_sqrt_regularised_derivative(a.other - p, a.transition)
            + b.k * signed_sqrt_regularised_derivative(b.other - p, b.transition))
    };
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
    let holds = |m: OrificeInflow| p >= m.valid.0 && p <= m.valid.1;
    let s = slope(p);
    (p >= lo && p <= hi && holds(a) && holds(b) && s < 0.0 && s.is_finite()).then_some((p, s))
}

/// One step of an evaluation, in dependency order.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Step {
    /// [`Component::evaluate`] of one component.
    Evaluate(usize),
    /// Solve an algebraic node with its members.
    Solve(usize),
}

/// One algebraic node and the components the assembler evaluates with it.
#[derive(Debug)]
pub(crate) struct SeriesGroup {
    /// The [`AlgebraicNode`] component.
    pub(crate) owner: usize,
    pub(crate) node: HydraulicNode,
    /// Members in evaluation order.
    pub(crate) members: Vec<usize>,
    /// Pressure wires (table indices) the members read elsewhere: the bracket.
    bracket: Vec<usize>,
    /// Every wire a member may write (their accumulators and owned wires,
    /// the node's pressure among them).
    writes: Vec<usize>,
    /// The accumulators among them: what a trial restores (a member writes
    /// the other wires anew whenever it is evaluated, so those need not be;
    /// debug builds check it).
    accumulators: Vec<usize>,
    /// `∂ΣQ_in/∂p` at the last solution: the first Newton step of the next
    /// solve uses it (NaN: ask the members).
    slope: Cell<f64>,
    pub(crate) solves: Cell<u64>,
    pub(crate) evaluations: Cell<u64>,
    pub(crate) fallbacks: Cell<u64>,
    /// `[t₀, p₀, t₁, p₁]`: the times and solutions of the last two solves.
    /// The next solve starts from the last solution `p₁`, or, later than
    /// both, which were in time order (an output row after the last, an
    /// integrator stage ahead of the last two), by at most twice their
    /// interval, from their straight line extended to its time.
    history: Cell<[f64; 4]>,
}

impl SeriesGroup {
    /// Every wire a member may write (the node's pressure among them).
    pub(crate) fn writes(&self) -> &[usize] {
        &self.writes
    }

    /// The last solutions and slope, where the next solve starts.
    pub(crate) fn memory(&self) -> ([f64; 4], f64) {
        (self.history.get(), self.slope.get())
    }

    /// Puts back what [`SeriesGroup::memory`] took.
    pub(crate) fn restore(&self, (history, slope): ([f64; 4], f64)) {
        self.history.set(history);
        self.slope.set(slope);
    }

    /// Forgets the last solution and slope (a run from a given state solves
    /// the same way whatever ran before).
    pub(crate) fn forget(&self) {
        self.slope.set(f64::NAN);
        self.history.set([f64::NAN; 4]);
    }

    /// Solves the node at time `t`: `eval(w)` runs the members on `w`,
    /// `slope(w)` sums their [`Component::inflow_slope`] (None if one has
    /// none); `snap` is scratch. Each trial restores only the accumulators
    /// the members add into.
    pub(crate) fn solve(
        &self,
        t: f64,
        w: &mut Wires,
        snap: &mut Vec<f64>,
        mut eval: impl FnMut(&mut Wires),
        slope: impl Fn(&Wires) -> Option<f64>,
        laws: impl Fn(&Wires) -> Option<[OrificeInflow; 2]>,
    ) {
        snap.clear();
        snap.extend(self.accumulators.iter().map(|&i| w.v[i]));
        #[cfg(debug_assertions)]
        let before = w.v.clone();
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for &i in &self.bracket {
            lo = lo.min(w.v[i]);
            hi = hi.max(w.v[i]);
        }
        let (last, n) = (Cell::new(f64::NAN), Cell::new(0u64));
        let mut f = |p: f64, w: &mut Wires| {
            for (&i, &v) in self.accumulators.iter().zip(snap.iter()) {
                w.v[i] = v;
            }
            w.set(self.node.pressure, Pressure::new(p));
            eval(w);
            last.set(p);
            n.set(n.get() + 1);
            w.get(self.node.inflow).si()
        };
        let scale = lo.abs().max(hi.abs()).max(1.0e5);
        let tol = SERIES_RTOL * scale;
        // where to start: the line through the last two solutions, extended
        // at most twice their interval ahead (no further than it says
        // anything), else the last solution, else the bracket's middle
        let [t0, p0, t1, p1] = self.history.get();
        let extended = if t > t1 && t1 > t0 && t - t1 <= 2.0 * (t1 - t0) {
            p1 + (p1 - p0) * ((t - t1) / (t1 - t0))
        } else {
            f64::NAN
        };
        let guess = [extended, p1]
            .into_iter()
            .find(|&p| p > lo && p < hi)
            .unwrap_or(0.5 * (lo + hi));
        // two orifice laws: the root found on them, kept when the members'
        // residual there passes the Newton test (else Newton starts there)
        let closed = if lo < hi {
            laws(w).and_then(|[a, b]| orifice_pair_root(a, b, (lo, hi), tol, guess))
        } else {
            None
        };
        let p = if lo >= hi {
            lo
        } else if let Some((p, s)) = closed.filter(|&(p, s)| (f(p, w) / s).abs() <= tol) {
            self.slope.set(s);
            p
        } else {
            let (start, warm) = closed.unwrap_or((guess, self.slope.get()));
            match newton(&mut f, &slope, w, start, (lo, hi), tol, warm) {
                Some((p, s)) => {
                    self.slope.set(s);
                    p
                }
                None => {
                    self.fallbacks.set(self.fallbacks.get() + 1);
                    self.slope.set(f64::NAN);
                    let (flo, fhi) = (f(lo, w), f(hi, w));
                    if flo <= 0.0 {
                        lo
                    } else if fhi >= 0.0 {
                        hi
                    } else {
                        // f(lo) > 0 > f(hi): a bracket, so Brent converges
                        hydrocyl_xfactor::brent(|p| f(p, w), lo, hi, tol)
                            .map_or(0.5 * (lo + hi), |s| s.x)
                    }
                }
            }
        };
        let [_, _, t1, p1] = self.history.get();
        self.history.set([t1, p1, t, p]);
        if last.get() != p {
            f(p, w);
        }
        #[cfg(debug_assertions)]
        {
            for (i, (a, b)) in before.iter().zip(&w.v).enumerate() {
                debug_assert!(
                    a.to_bits() == b.to_bits() || self.writes.contains(&i),
                    "a member of an algebraic node wrote wire {i}, which it did not bind"
                );
            }
            // the members' contract that lets a trial restore only the
            // accumulators: evaluated on the wire table as it was before the
            // solve, at the root, they write what the trials left, bit for bit
            let after: Vec<f64> = self.writes.iter().map(|&i| w.v[i]).collect();
            for &i in &self.writes {
                w.v[i] = before[i];
            }
            w.set(self.node.pressure, Pressure::new(p));
            eval(w);
            for (&i, a) in self.writes.iter().zip(&after) {
                debug_assert!(
                    a.to_bits() == w.v[i].to_bits(),
                    "a member of an algebraic node wrote wire {i} differently after other trials: \
                     it must write every wire it writes in `evaluate` on every call, \
                     never from its previous value"
                );
            }
        }
        self.solves.set(self.solves.get() + 1);
        self.evaluations.set(self.evaluations.get() + n.get());
    }
}

/// Newton's method for the root of the falling `f` in `(lo, hi)` from `p0`,
/// safeguarded by bisection of the bracket it narrows; `None` if a member has
/// no slope or it does not converge (the caller falls back to Brent).
///
/// The slope of a step is the secant through the last two trials when there
/// are two, the members' analytic slope otherwise, except that the first
/// step takes `warm` (the slope at the previous solve's root) when it is a
/// usable (negative) number: near the root the secant is as good as the
/// analytic slope, and a warm-started solve then costs the residual
/// evaluations alone. A first step that would end the solve on the warm
/// slope is checked again on the members' slope at that point (a stale,
/// steeper warm slope would otherwise accept an unconverged residual).
/// From the third trial on, the step is the inverse quadratic interpolation
/// through the last three trials instead whenever that lands inside the
/// bracket: it follows the bend of a square-root law near a small pressure
/// drop, which the secant takes several steps to cross. Returns the root and
/// the slope (of the step that found it) there.
fn newton(
    f: &mut impl FnMut(f64, &mut Wires) -> f64,
    slope: &impl Fn(&Wires) -> Option<f64>,
    w: &mut Wires,
    p0: f64,
    (mut a, mut b): (f64, f64),
    tol: f64,
    warm: f64,
) -> Option<(f64, f64)> {
    let mut p = p0;
    let mut last_step = f64::INFINITY;
    let mut prev: Option<(f64, f64)> = None;
    let mut prev2: Option<(f64, f64)> = None;
    let mut last_slope = warm;
    for k in 0..NEWTON_ITERATIONS {
        let r = f(p, w);
        if r == 0.0 {
            // the slope of the step that got here (not the last residual)
            return Some((p, last_slope));
        }
        // the inflow falls with p: a positive residual puts the root above p
        if r > 0.0 {
            a = p;
        } else {
            b = p;
        }
        let secant = prev.and_then(|(pp, rp): (f64, f64)| {
            let s = (r - rp) / (p - pp);
            (s < 0.0 && s.is_finite()).then_some(s)
        });
        let warm_step = secant.is_none() && k == 0 && warm < 0.0 && warm.is_finite();
        let mut s = match secant {
            Some(s) => s,
            None if warm_step => warm,
            None => slope(w)?,
        };
        let mut step = if s < 0.0 { -r / s } else { f64::NAN };
        // three trials: inverse quadratic interpolation (the bend of a
        // square-root law near a small pressure drop); NaN or infinite when
        // two residuals are equal, and then not inside the bracket
        if let (Some((p1, r1)), Some((p0, r0))) = (prev, prev2) {
            let x = p0 * r1 * r / ((r0 - r1) * (r0 - r))
                + p1 * r0 * r / ((r1 - r0) * (r1 - r))
                + p * r0 * r1 / ((r - r0) * (r - r1));
            if x > a && x < b {
                step = x - p;
            }
        }
        let mut confirmed = true;
        if warm_step && step.abs() <= tol {
            // the warm slope is the last solve's: a stale, steeper one would
            // shrink the step and accept a residual that is not converged, so
            // convergence is confirmed on the members' slope here (without
            // one, the step is taken and the secant decides)
            confirmed = match slope(w) {
                Some(fresh) => {
                    s = fresh;
                    step = if s < 0.0 { -r / s } else { f64::NAN };
                    true
                }
                None => false,
            };
        }
        // converged, or at the rounding floor (a step that stopped shrinking)
        if confirmed
            && (step.abs() <= tol || (step.abs() <= 1e3 * tol && step.abs() >= 0.5 * last_step))
        {
            return Some((p, s));
        }
        last_step = step.abs();
        last_slope = s;
        prev2 = prev;
        prev = Some((p, r));
        let next = p + step;
        p = if next > a && next < b {
            next
        } else {
            0.5 * (a + b)
        };
        if b - a <= tol {
            return Some((p, s));
        }
    }
    None
}

/// Groups the components around each algebraic node (see the module docs);
/// `deps[i]` are the algebraic writers component `i` reads. Returns the
/// groups and, per component, the group it belongs to.
fn groups(
    net: &Netlist,
    deps: &[Vec<usize>],
) -> Result<(Vec<SeriesGroup>, Vec<Option<usize>>), BuildError> {
    let n = net.component_names.len();
    let mut of: Vec<Option<usize>> = vec![None; n];
    let mut out = Vec::new();
    for (g, (owner, node, name)) in net.solved.iter().enumerate() {
        let p = node.pressure.raw();
        let mut members: Vec<usize> = Vec::new();
        for (reader, w, _, _) in &net.reads {
            if *w == p.0 && *reader != *owner && !members.contains(reader) {
                members.push(*reader);
            }
        }
        let err = |m: String| BuildError::Component {
            component: net.component_names[*owner].clone(),
            message: m,
        };
        if members.len() < 2 {
            return Err(err(format!(
                "algebraic node `{name}` needs at least two components connected to it"
            )));
        }
        for &m in &members {
            if let Some(h) = of[m] {
                return Err(err(format!(
                    "`{}` joins two algebraic nodes (`{}` and `{name}`): give one of them a volume",
                    net.component_names[m], net.solved[h].2
                )));
            }
            of[m] = Some(g);
        }
        of[*owner] = Some(g);
        // members in their dependency order
        let order = kahn(&members, |m| {
            deps[m].iter().filter(|d| members.contains(d)).copied()
        })
        .map_err(|left| loop_error(net, &left))?;
        let mut bracket: Vec<usize> = net
            .reads
            .iter()
            .filter(|(r, w, kind, _)| members.contains(r) && *kind == "hydraulic node" && *w != p.0)
            .map(|(_, w, _, _)| *w)
            .collect();
        bracket.sort_unstable();
        bracket.dedup();
        let mut writes: Vec<usize> = net
            .writes
            .iter()
            .filter(|(c, _)| members.contains(c))
            .map(|(_, wire)| *wire)
            .chain([p.0])
            .collect();
        writes.sort_unstable();
        writes.dedup();
        let accumulators: Vec<usize> = writes
            .iter()
            .copied()
            .filter(|wire| net.accumulators.contains(wire))
            .collect();
        if bracket.is_empty() {
            return Err(err(format!(
                "algebraic node `{name}` is connected to no other hydraulic node"
            )));
        }
        out.push(SeriesGroup {
            owner: *owner,
            node: *node,
            members: order,
            bracket,
            writes,
            accumulators,
            slope: Cell::new(f64::NAN),
            solves: Cell::new(0),
            evaluations: Cell::new(0),
            fallbacks: Cell::new(0),
            history: Cell::new([f64::NAN; 4]),
        });
    }
    Ok((out, of))
}

/// Kahn's order of `items`, stable in the order given; `Err` holds the
/// items on a cycle (and any between two cycles), without the items that
/// only depend on one.
fn kahn<I: Iterator<Item = usize>>(
    items: &[usize],
    deps: impl Fn(usize) -> I,
) -> Result<Vec<usize>, Vec<usize>> {
    let mut order = Vec::with_capacity(items.len());
    while order.len() < items.len() {
        let next = items
            .iter()
            .copied()
            .find(|&i| !order.contains(&i) && deps(i).all(|d| order.contains(&d)));
        match next {
            Some(i) => order.push(i),
            None => {
                let mut left: Vec<usize> = items
                    .iter()
                    .copied()
                    .filter(|i| !order.contains(i))
                    .collect();
                // drop what no item left depends on, until only the cycles
                // (each of whose items another one left depends on) remain
                loop {
                    let needed: Vec<usize> = left
                        .iter()
                        .copied()
                        .filter(|&i| left.iter().any(|&j| deps(j).any(|d| d == i)))
                        .collect();
                    if needed.len() == left.len() {
                        return Err(left);
                    }
                    left = needed;
                }
            }
        }
    }
    Ok(order)
}

fn loop_error(net: &Netlist, left: &[usize]) -> BuildError {
    let names: Vec<String> = left
        .iter()
        .map(|&i| net.component_names[i].clone())
        .collect();
    BuildError::AlgebraicLoop(names)
}

/// The evaluation order of a bound netlist: every read wire has an owner,
/// the components around each algebraic node form one unit, and the units
/// are ordered so that each runs after the algebraic writers it reads.
pub(crate) fn evaluation_order(net: &Netlist) -> Result<(Vec<Step>, Vec<SeriesGroup>), BuildError> {
    let n = net.component_names.len();
    let mut deps: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (reader, w, kind, node) in &net.reads {
        match net.owners.get(w) {
            None => {
                return Err(BuildError::NoOwner {
                    kind,
                    node: node.clone(),
                    user: net.component_names[*reader].clone(),
                })
            }
            Some(o) => {
                let solved = net.solved.iter().any(|(_, h, _)| h.pressure.0 == *w);
                // a component reading its own algebraic output (a signal
                // joined back to its own input) is a loop of one
                if o.causality == crate::Causality::Algebraic && !solved && o.owner == *reader {
                    return Err(loop_error(net, &[*reader]));
                }
                if o.causality == crate::Causality::Algebraic
                    && !solved
                    && o.owner != *reader
                    && !deps[*reader].contains(&o.owner)
                {
                    deps[*reader].push(o.owner);
                }
            }
        }
    }
    let (groups, group_of) = groups(net, &deps)?;
    let unit = |i: usize| group_of[i].map_or(i, |g| groups[g].owner);
    let mut unit_deps: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, d) in deps.iter().enumerate() {
        for &o in d {
            let (u, v) = (unit(i), unit(o));
            if u != v && !unit_deps[u].contains(&v) {
                unit_deps[u].push(v);
            }
        }
    }
    let units: Vec<usize> = (0..n).filter(|&i| unit(i) == i).collect();
    let order = kahn(&units, |u| unit_deps[u].iter().copied()).map_err(|l| loop_error(net, &l))?;
    let steps = order
        .into_iter()
        .map(|i| match group_of[i] {
            Some(g) => Step::Solve(g),
            None => Step::Evaluate(i),
        })
        .collect();
    Ok((steps, groups))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::components::{FixedOrifice, PressureSource, Volume};

    #[test]
    fn a_loop_error_names_the_cycle_and_not_what_hangs_off_it() {
        // 0 ⇄ 1 is the cycle; 2 reads 0, 3 reads 2: neither is on it
        let deps: [&[usize]; 4] = [&[1], &[0], &[0], &[2]];
        let left = kahn(&[0, 1, 2, 3], |i| deps[i].iter().copied()).unwrap_err();
        assert_eq!(left, vec![0, 1]);
        // a chain without a cycle orders
        let chain: [&[usize]; 3] = [&[], &[0], &[1]];
        assert_eq!(
            kahn(&[2, 1, 0], |i| chain[i].iter().copied()),
            Ok(vec![0, 1, 2])
        );
    }
    use crate::wires::Wire;
    use crate::Circuit;
    use hydrocyl_integrators::{solve, Method, Options};
    use hydrocyl_ports::{Area, Density};
    use hydrocyl_valves::orifice::Orifice;

    fn orifice() -> Orifice {
        Orifice::new(0.65, Density::new(870.0))
    }

    /// supply ──[A1]── m (algebraic) ──[A2]── `to`
    fn two_in_series(to: Box<dyn Component>) -> Vec<Box<dyn Component>> {
        vec![
            Box::new(PressureSource::new(
                "supply",
                "P",
                Pressure::from_bar(70.0),
                None,
            )),
            Box::new(FixedOrifice::new(
                "o1",
                "P",
                "M",
                Area::from_mm2(0.2),
                orifice(),
            )),
            Box::new(FixedOrifice::new(
                "o2",
                "M",
                "L",
                Area::from_mm2(0.1),
                orifice(),
            )),
            Box::new(AlgebraicNode::new("m", "M", Some("pm"))),
            to,
        ]
    }

    fn diag(c: &Circuit, k: &str) -> f64 {
        c.diagnostics().iter().find(|(n, _)| n == k).unwrap().1
    }

    #[test]
    fn two_orifices_in_series_pass_the_series_area_flow() {
        let c = Circuit::build(two_in_series(Box::new(PressureSource::new(
            "tank",
            "L",
            Pressure::ZERO,
            None,
        ))))
        .unwrap();
        let w = c.wires_at(0.0, &[]);
        // 1/A² = 1/A1² + 1/A2²: Q = Cd A √(2 Ps/ρ), p_m = Ps A²/A2²
        let (a1, a2) = (0.2e-6_f64, 0.1e-6_f64);
        let a = 1.0 / (1.0 / (a1 * a1) + 1.0 / (a2 * a2)).sqrt();
        let q = 0.65 * a * (2.0 * 7.0e6 / 870.0_f64).sqrt();
        let q_tank = w.get(c.find_wire("hyd:L:q").unwrap());
        assert!((q_tank - q).abs() < 1e-10 * q, "{q_tank} {q}");
        let pm = w.get(c.find_wire("hyd:M:p").unwrap());
        let pm_exact = 7.0e6 * (a * a) / (a2 * a2);
        assert!((pm - pm_exact).abs() < 1e-9 * pm_exact, "{pm} {pm_exact}");
        assert_eq!(c.probes().iter().filter(|p| p.name == "pm").count(), 1);
        // Newton on the orifices' slopes, no fallback
        assert_eq!(diag(&c, "m.solve_fallbacks"), 0.0);
    }

    #[test]
    fn a_volume_fills_through_two_orifices_in_series() {
        // the algebraic node inside an ODE: the volume reaches supply pressure
        let mut c = Circuit::build(two_in_series(Box::new(Volume::new(
            "vol", "L", 1e-5, 7e8, 0.0, None,
        ))))
        .unwrap();
        let x0 = c.initial_state();
        c.reset(0.0, &x0);
        let opts = Options {
            atol: c.atol(1e-8),
            rtol: 1e-8,
            ..Options::default()
        };
        let sol = solve(Method::DormandPrince45, &mut c, 0.0, &x0, 1.0, &opts).unwrap();
        let p = sol.last().unwrap()[0];
        assert!((p - 7.0e6).abs() < 1e3, "{p}");
        // two fixed orifices declare their laws: each solve evaluates the
        // members once, at the root found on the laws
        assert!(diag(&c, "m.solves") > 100.0);
        assert_eq!(diag(&c, "m.solve_evaluations"), diag(&c, "m.solves"));
        assert_eq!(diag(&c, "m.solve_fallbacks"), 0.0);
    }

    /// An orifice member that breaks the members' contract: it counts its
    /// evaluations in a wire of its own (a value written from its previous
    /// value).
    #[derive(Debug)]
    struct CountingOrifice {
        orifice: FixedOrifice,
        count: Wire<f64>,
    }

    impl Component for CountingOrifice {
        fn name(&self) -> &str {
            "counting"
        }
        fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError> {
            self.orifice.bind(net)?;
            self.count = net.private("count");
            Ok(())
        }
        fn evaluate(&self, t: f64, x: &[f64], w: &mut Wires) {
            self.orifice.evaluate(t, x, w);
            let n = w.get(self.count);
            w.set(self.count, n + 1.0);
        }
        fn inflow_slope(&self, t: f64, x: &[f64], w: &Wires, node: Wire<Pressure>) -> Option<f64> {
            self.orifice.inflow_slope(t, x, w, node)
        }
    }

    #[test]
    #[cfg(debug_assertions)]
    #[should_panic(expected = "differently after other trials")]
    fn debug_builds_catch_a_member_writing_from_its_previous_value() {
        let mut parts = two_in_series(Box::new(PressureSource::new(
            "tank",
            "L",
            Pressure::ZERO,
            None,
        )));
        parts[2] = Box::new(CountingOrifice {
            orifice: FixedOrifice::new("o2", "M", "L", Area::from_mm2(0.1), orifice()),
            count: Wire::UNBOUND,
        });
        let c = Circuit::build(parts).unwrap();
        c.wires_at(0.0, &[]);
    }

    #[test]
    fn a_node_without_an_owner_is_still_an_error() {
        let mut parts = two_in_series(Box::new(PressureSource::new(
            "tank",
            "L",
            Pressure::ZERO,
            None,
        )));
        parts.remove(3); // the AlgebraicNode
        let e = Circuit::build(parts).unwrap_err();
        assert!(matches!(e, BuildError::NoOwner { .. }), "{e}");
        assert!(e.to_string().contains("`M`"), "{e}");
    }

    #[test]
    fn a_stale_warm_slope_does_not_accept_an_unconverged_root() {
        // root at 1, slope −1e-3; the last solve's slope was 1e6 times
        // steeper: its step from 1 + 1e-9 looks converged, the true one not
        let mut f = |p: f64, _: &mut Wires| -1e-3 * (p - 1.0);
        let slope = |_: &Wires| Some(-1e-3);
        let mut w = Wires::default();
        let tol = 1e-12;
        let (p, s) = newton(&mut f, &slope, &mut w, 1.0 + 1e-9, (0.0, 2.0), tol, -1e3).unwrap();
        assert!((p - 1.0).abs() <= tol, "{p}");
        assert!((s + 1e-3).abs() < 1e-9, "{s}");
        // a usable warm slope still converges in one residual when it is right
        let mut calls = 0;
        let mut g = |p: f64, _: &mut Wires| {
            calls += 1;
            -1e-3 * (p - 1.0)
        };
        let (p, _) = newton(&mut g, &slope, &mut w, 1.0 + 1e-13, (0.0, 2.0), tol, -1e-3).unwrap();
        assert!((p - 1.0).abs() <= tol && calls == 1, "{p} {calls}");
    }

    #[test]
    fn the_bend_near_a_small_pressure_drop_takes_few_residuals() {
        // two square-root laws in series, the downstream one far more open:
        // the root p = (k1² p1 + k2² p2)/(k1² + k2²) lies ~2 Pa above p2,
        // where √(p − p2) bends sharply. The start is 40 % too high, the warm
        // slope the one at the root (stale where the solve starts), and there
        // is no analytic slope: secant steps, and from the third trial on
        // inverse quadratic interpolation, which crosses the bend (the secant
        // alone takes 6 residuals)
        let (k1, k2, p1, p2) = (1.0e-8_f64, 1.0e-6_f64, 2.0e4_f64, 0.0_f64);
        let root = (k1 * k1 * p1 + k2 * k2 * p2) / (k1 * k1 + k2 * k2);
        let calls = Cell::new(0);
        let mut f = |p: f64, _: &mut Wires| {
            calls.set(calls.get() + 1);
            k1 * (p1 - p).sqrt() - k2 * (p - p2).sqrt()
        };
        let slope = |_: &Wires| None;
        let warm = -0.5 * k1 / (p1 - root).sqrt() - 0.5 * k2 / (root - p2).sqrt();
        let tol = SERIES_RTOL * 1e5;
        let mut w = Wires::default();
        let (p, _) = newton(&mut f, &slope, &mut w, 1.4 * root, (p2, p1), tol, warm).unwrap();
        assert!((p - root).abs() <= tol, "{p} {root}");
        assert!(calls.get() <= 4, "{} residuals", calls.get());
    }

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

    #[test]
    fn brent_finds_the_root_of_a_falling_function() {
        let r = hydrocyl_xfactor::brent(|p| 2.0 - p * p, 0.0, 2.0, 1e-14)
            .unwrap()
            .x;
        assert!((r - 2.0_f64.sqrt()).abs() < 1e-13, "{r}");
    }
}
