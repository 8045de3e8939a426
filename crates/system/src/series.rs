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
use crate::wires::{HydraulicNode, Wires};
use crate::Netlist;
use hydrocyl_ports::Pressure;
use std::cell::Cell;

mod orifice_law;
use orifice_law::orifice_pair_root;
pub use orifice_law::OrificeInflow;

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
    fn reads_time(&self, _t: f64) -> bool {
        false
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
            let start = closed.unwrap_or((guess, self.slope.get()));
            self.member_solve(&mut f, &slope, w, start, (lo, hi), tol)
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

impl SeriesGroup {
    /// The root by the members' own Newton solve from `(start, warm)`
    /// ([`newton`]), Brent's method where that fails: the path of a node
    /// whose members declare no orifice laws, or whose laws' root did not
    /// pass. Out of line, so that the law path's code in the circuit's
    /// evaluation stays small (on the hybrid rig this path is rare).
    #[inline(never)]
    fn member_solve(
        &self,
        f: &mut impl FnMut(f64, &mut Wires) -> f64,
        slope: &impl Fn(&Wires) -> Option<f64>,
        w: &mut Wires,
        (start, warm): (f64, f64),
        (lo, hi): (f64, f64),
        tol: f64,
    ) -> f64 {
        match newton(f, slope, w, start, (lo, hi), tol, warm) {
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
mod tests;
