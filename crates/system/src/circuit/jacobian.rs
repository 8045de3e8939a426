//! The analytic circuit Jacobian: forward-mode tangents through the wires.
//!
//! One pass propagates the gradients of every wire with respect to all `n`
//! states at once, in the order of an evaluation:
//!
//! 1. [`Component::publish_tangents`](crate::Component::publish_tangents): the rows of the efforts a component
//!    sets from its own states (`∂p/∂x_k = 1` for a volume's pressure);
//! 2. [`Component::evaluate_tangents`](crate::Component::evaluate_tangents) in dependency order: the component's
//!    local partials (an orifice's `∂Q/∂p_a`, a friction law's `∂F/∂v`)
//!    chained onto the rows of the wires it reads, added into the rows of the
//!    wires it writes;
//! 3. [`Component::derivative_tangents`](crate::Component::derivative_tangents): the rows of `∂ẋ/∂x` (and
//!    [`Component::quadrature_tangents`](crate::Component::quadrature_tangents) for the quadratures).
//!
//! An algebraic node's pressure ([`crate::series`]) is implicit: its members
//! run with the node pressure's row set to a unit vector in an extra column,
//! so the node's inflow row holds `∂r/∂x` and `∂r/∂p`; the implicit function
//! theorem gives `∂p/∂x = −(∂r/∂x)/(∂r/∂p)`, and every row the members wrote
//! has its extra column folded into the state columns with it.
//!
//! A circuit has an analytic Jacobian when every component says it has
//! ([`Component::has_tangents`](crate::Component::has_tangents)); otherwise, and while the energy ledger is
//! on, the stiff solver differences the right-hand side as before. At a
//! non-smooth point (a valve's cracking pressure, a stick/slip switch) each
//! component gives the one-sided derivative of the branch its evaluation
//! took, which is the branch its event/mode state selects.

use super::{Circuit, Step};
use crate::wires::{AnyWire, HydraulicNode, Wire};
use hydrocyl_ports::VolumeFlow;

/// Gradient rows `∂wire/∂x` of every wire of a circuit, and the rows of the
/// circuit Jacobian being assembled; what a component's `*_tangents` methods
/// write into. Row entries are the states of the whole circuit; a component
/// refers to its own states by their index in its slice (`k` below).
#[derive(Clone, Debug, Default)]
pub struct Tangents {
    /// Columns: the states, then one per algebraic node.
    width: usize,
    /// `n_wires × width`.
    rows: Vec<f64>,
    /// `∂ẋ/∂x` and the quadrature rows, `(n + n_quad) × width`.
    rates: Vec<f64>,
    /// The current component's first state and first quadrature.
    offset: usize,
    q_offset: usize,
    /// Scratch: an algebraic node's `∂p/∂x` row (kept, so that a Jacobian
    /// allocates nothing once the first has sized it).
    node_row: Vec<f64>,
}

impl Tangents {
    #[inline(always)]
    fn add_row(dst: &mut [f64], c: f64, src: &[f64]) {
        for (d, s) in dst.iter_mut().zip(src) {
            *d += c * s;
        }
    }

    /// `∂target/∂x_k += c` for the component's own state `k`.
    #[inline]
    pub fn state(&mut self, target: impl Into<AnyWire>, k: usize, c: f64) {
        let t = target.into().0;
        self.rows[t * self.width + self.offset + k] += c;
    }

    /// `∂target += c · ∂source` (the chain rule through a wire read).
    #[inline]
    pub fn chain(&mut self, target: impl Into<AnyWire>, c: f64, source: impl Into<AnyWire>) {
        self.chain_rows(target.into().0, c, source.into().0);
    }

    /// [`Tangents::chain`] on wire indices. Out of line on purpose: every
    /// component's `evaluate_tangents` calls it many times, and one copy of
    /// the row loop keeps the Jacobian's code small enough to stay in the
    /// instruction cache beside the right-hand side's (inlined, the copies
    /// pushed ~35 KB of code out of it on every step of the hybrid rig).
    #[inline(never)]
    fn chain_rows(&mut self, t: usize, c: f64, s: usize) {
        if c == 0.0 || t == s {
            // a wire never depends on itself in one evaluation
            return;
        }
        let m = self.width;
        let (dst, src) = if t < s {
            let (a, b) = self.rows.split_at_mut(s * m);
            (&mut a[t * m..(t + 1) * m], &b[..m])
        } else {
            let (a, b) = self.rows.split_at_mut(t * m);
            (&mut b[..m], &a[s * m..(s + 1) * m])
        };
        Self::add_row(dst, c, src);
    }

    /// `∂ẋ_k/∂x_l += c` for the component's own states `k` (its derivative)
    /// and `l`.
    #[inline]
    pub fn rate_state(&mut self, k: usize, l: usize, c: f64) {
        self.rates[(self.offset + k) * self.width + self.offset + l] += c;
    }

    /// `∂ẋ_k += c · ∂source` for the component's own state `k`.
    #[inline]
    pub fn rate_chain(&mut self, k: usize, c: f64, source: impl Into<AnyWire>) {
        self.rates_chain(self.offset + k, c, source.into());
    }

    /// `rates[r] += c · ∂source` (out of line, as [`Tangents::chain_rows`]).
    #[inline(never)]
    fn rates_chain(&mut self, r: usize, c: f64, source: AnyWire) {
        if c == 0.0 {
            return;
        }
        let (s, m) = (source.0, self.width);
        Self::add_row(
            &mut self.rates[r * m..(r + 1) * m],
            c,
            &self.rows[s * m..(s + 1) * m],
        );
    }

    /// `∂q_k/∂x_l += c` for the component's own quadrature `k` and state `l`.
    #[inline]
    pub fn quadrature_state(&mut self, k: usize, l: usize, c: f64) {
        self.rates[(self.q_offset + k) * self.width + self.offset + l] += c;
    }

    /// `∂q_k += c · ∂source` for the component's own quadrature `k`.
    #[inline]
    pub fn quadrature_chain(&mut self, k: usize, c: f64, source: impl Into<AnyWire>) {
        self.rates_chain(self.q_offset + k, c, source.into());
    }

    /// A resistive two-port: a flow `q` with `∂q/∂p_from = g` and
    /// `∂q/∂p_to = −g` (`g` the law's conductance) leaves node `from` and
    /// enters node `to`; `flow`, if given, is a wire the component sets to `q`.
    pub fn resistive(
        &mut self,
        from: HydraulicNode,
        to: HydraulicNode,
        g: f64,
        flow: Option<Wire<VolumeFlow>>,
    ) {
        for (pressure, s) in [(from.pressure, g), (to.pressure, -g)] {
            self.chain(from.inflow, -s, pressure);
            self.chain(to.inflow, s, pressure);
            if let Some(f) = flow {
                self.chain(f, s, pressure);
            }
        }
    }

    fn row(&self, w: usize) -> &[f64] {
        &self.rows[w * self.width..(w + 1) * self.width]
    }
}

impl Circuit {
    /// Whether the circuit gives the stiff solver an analytic Jacobian:
    /// every component has tangents ([`Component::has_tangents`](crate::Component::has_tangents)) and the
    /// energy ledger is off.
    pub fn has_jacobian(&self) -> bool {
        self.analytic && !self.ledger
    }

    /// Turns the analytic Jacobian off (finite differences) or back on (where
    /// every component has one) — for comparisons.
    pub fn set_analytic_jacobian(&mut self, on: bool) {
        self.analytic = on && self.comps.iter().all(|c| c.has_tangents());
    }

    /// The analytic Jacobian at `(t, x)` into `jac` (row-major, `dim × dim`,
    /// quadrature columns left as they are); `false` if the circuit has none
    /// ([`Circuit::has_jacobian`]) or an algebraic node is degenerate there.
    pub(super) fn analytic_jacobian(&self, t: f64, x: &[f64], jac: &mut [f64]) -> bool {
        if !self.has_jacobian() {
            return false;
        }
        if !self.filled_at(t, x) {
            self.fill(t, x);
        }
        let w = self.wires.borrow();
        let mut tg = self.tangents.borrow_mut();
        let (n, dim) = (self.n_states, hydrocyl_integrators::OdeSystem::dim(self));
        let n_rows = n + self.quad_len(); // states then quadratures
        let m = n + self.groups.len();
        tg.width = m;
        tg.rows.clear();
        tg.rows.resize(w.v.len() * m, 0.0);
        tg.rates.clear();
        tg.rates.resize(n_rows * m, 0.0);
        let xs = |i: usize| &x[self.offsets[i]..self.offsets[i + 1]];
        for (i, c) in self.comps.iter().enumerate() {
            tg.offset = self.offsets[i];
            c.publish_tangents(t, xs(i), &w, &mut tg);
        }
        for step in &self.order {
            match *step {
                Step::Evaluate(i) => {
                    tg.offset = self.offsets[i];
                    self.comps[i].evaluate_tangents(t, xs(i), &w, &mut tg);
                }
                Step::Solve(g) => {
                    let grp = &self.groups[g];
                    let col = n + g;
                    let p = grp.node.pressure.raw().0;
                    tg.rows[p * m..(p + 1) * m].fill(0.0);
                    tg.rows[p * m + col] = 1.0;
                    for &i in &grp.members {
                        tg.offset = self.offsets[i];
                        self.comps[i].evaluate_tangents(t, xs(i), &w, &mut tg);
                    }
                    // implicit function theorem on r(p, x) = ΣQ_in = 0
                    let r = grp.node.inflow.raw().0;
                    let drdp = tg.rows[r * m + col];
                    if !(drdp < 0.0 && drdp.is_finite()) {
                        return false;
                    }
                    let mut dpdx = std::mem::take(&mut tg.node_row);
                    dpdx.clear();
                    dpdx.extend(tg.row(r)[..n].iter().map(|d| -d / drdp));
                    for &wi in grp.writes() {
                        let row = &mut tg.rows[wi * m..(wi + 1) * m];
                        let c = row[col];
                        if c != 0.0 {
                            Tangents::add_row(&mut row[..n], c, &dpdx);
                            row[col] = 0.0;
                        }
                    }
                    tg.node_row = dpdx;
                }
            }
        }
        for (i, c) in self.comps.iter().enumerate() {
            if self.offsets[i] < self.offsets[i + 1] {
                tg.offset = self.offsets[i];
                c.derivative_tangents(t, xs(i), &w, &mut tg);
            }
        }
        if self.quad {
            for (i, c) in self.comps.iter().enumerate() {
                if self.q_offsets[i] < self.q_offsets[i + 1] {
                    tg.offset = self.offsets[i];
                    tg.q_offset = n + self.q_offsets[i];
                    c.quadrature_tangents(t, xs(i), &w, &mut tg);
                }
            }
        }
        for i in 0..n_rows {
            jac[i * dim..i * dim + n].copy_from_slice(&tg.rates[i * m..i * m + n]);
        }
        true
    }
}

#[cfg(test)]
mod tests;
