//! The assembler core: components, the netlist they bind to, and the
//! [`Circuit`] that flattens them into one [`OdeSystem`].
//!
//! See the crate docs for the causality rules and how to add a component.

use hydrocyl_integrators::{Crossing, EventAction, OdeSystem};
use std::cell::RefCell;
use thiserror::Error;

use crate::series::{SeriesGroup, Step};

mod attachments;
mod component;
mod dependencies;
mod jacobian;
mod naming;
pub use component::{Component, PowerTerms, Probe};
pub(crate) use dependencies::Partial;
pub use jacobian::Tangents;

pub use crate::binding::{Causality, Netlist};
pub use crate::wires::{Acc, AnyWire, HydraulicNode, MechanicalNode, ReadWire, Wire, Wires};

/// A failure to assemble a circuit; names the component and the node.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum BuildError {
    /// Two components claim to set the same effort.
    #[error(
        "{kind} `{node}` is set by both `{first}` and `{second}`: a node has exactly one owner"
    )]
    TwoOwners {
        /// "hydraulic node", "mechanical node" or "signal".
        kind: &'static str,
        /// The node name.
        node: String,
        /// The first owner.
        first: String,
        /// The second claimant.
        second: String,
    },
    /// A node is used but nothing sets its effort.
    #[error("{kind} `{node}` is used by `{user}` but no component sets it (add a volume, chamber, pressure source, mass or signal source; or an algebraic node between resistive components)")]
    NoOwner {
        /// "hydraulic node", "mechanical node" or "signal".
        kind: &'static str,
        /// The node name.
        node: String,
        /// A component that uses it.
        user: String,
    },
    /// Algebraic components depend on each other in a cycle: the components
    /// on the cycle (and any between two cycles), in circuit order.
    #[error("algebraic loop between components: {}", .0.join(", "))]
    AlgebraicLoop(Vec<String>),
    /// Two components use one wire (a signal) as different quantities.
    #[error("`{component}` uses wire `{wire}` in {second}, but it was declared in {first}")]
    UnitMismatch {
        /// The wire (`sig:<name>`, ...).
        wire: String,
        /// The unit it was first declared in.
        first: &'static str,
        /// The unit the second use asks for.
        second: &'static str,
        /// The component of the second use.
        component: String,
    },
    /// A component rejected its parameters or connections.
    #[error("component `{component}`: {message}")]
    Component {
        /// The component.
        component: String,
        /// What is wrong.
        message: String,
    },
}

/// The assembled circuit: one ODE system over all component states, plus
/// optional quadratures (component quadratures, the energy ledger).
pub struct Circuit {
    comps: Vec<Box<dyn Component>>,
    offsets: Vec<usize>,
    ev_offsets: Vec<usize>,
    order: Vec<Step>,
    groups: Vec<SeriesGroup>,
    scratch: RefCell<Vec<f64>>,
    accumulators: Vec<usize>,
    /// The components that [`Component::settle`] after each evaluation.
    settlers: Vec<usize>,
    wires: RefCell<Wires>,
    n_states: usize,
    n_events: usize,
    quad: bool,
    ledger: bool,
    q_offsets: Vec<usize>,
    n_quad: usize,
    wire_names: Vec<String>,
    /// The component whose `publish` sets each wire (a stored effort), by
    /// wire index.
    publisher: Vec<Option<usize>>,
    probe_names: Option<Vec<Option<String>>>,
    /// The states' names in messages ([`Circuit::name_states`]).
    state_labels: Option<Vec<Option<String>>>,
    /// Units given to probes by [`Circuit::set_probe_unit`]:
    /// `(component, probe, unit)`.
    probe_units: Vec<(String, String, &'static str)>,
    /// The nodes each component is attached to.
    attachments: attachments::Attachments,
    /// What each component reads and who writes each wire.
    dependencies: dependencies::Dependencies,
    /// Every component has tangents and the analytic Jacobian is wanted.
    analytic: bool,
    tangents: RefCell<Tangents>,
    /// The point of the last [`Circuit::fill`], while no mode changed since.
    filled: RefCell<FillKey>,
}

/// What a circuit's evaluations leave behind ([`Circuit::memory`]).
#[derive(Clone, Debug)]
pub struct CircuitMemory {
    wires: Vec<f64>,
    filled: FillKey,
    series: Vec<([f64; 4], f64)>,
}

impl CircuitMemory {
    /// The same with every algebraic node's last solutions forgotten (its
    /// next solve starts as in a fresh run).
    pub fn forgetting_solutions(mut self) -> Self {
        for s in &mut self.series {
            *s = ([f64::NAN; 4], f64::NAN);
        }
        self
    }
}

/// Where the wire table was last evaluated (see [`Circuit::filled_at`]).
#[derive(Clone, Debug, Default)]
struct FillKey {
    valid: bool,
    t: f64,
    x: Vec<f64>,
}

impl std::fmt::Debug for Circuit {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Circuit")
            .field(
                "components",
                &self
                    .comps
                    .iter()
                    .map(|c| c.name().to_string())
                    .collect::<Vec<_>>(),
            )
            .field("n_states", &self.n_states)
            .finish()
    }
}

/// Number of ledger quadratures per component: ∫source, ∫dissipated,
/// ∫storage, ∫load, ∫moved ([`PowerTerms::moved`]).
pub const LEDGER_TERMS: usize = LEDGER_TERM_NAMES.len();

/// The ledger quadratures of a component, in their order in the state
/// vector (named `<component>.energy_<term>`).
pub const LEDGER_TERM_NAMES: [&str; 5] = ["source", "dissipated", "storage", "load", "moved"];

impl Circuit {
    /// Assembles components: binds each to the netlist, checks that every
    /// node has one owner, orders the algebraic evaluations, and lays out one
    /// state vector (each component's slice in the order given).
    pub fn build(mut comps: Vec<Box<dyn Component>>) -> Result<Self, BuildError> {
        let mut net = Netlist {
            component_names: comps.iter().map(|c| c.name().to_string()).collect(),
            ..Netlist::default()
        };
        for (i, n) in net.component_names.iter().enumerate() {
            if net.component_names[..i].contains(n) {
                return Err(BuildError::Component {
                    component: n.clone(),
                    message: "two components have this name".into(),
                });
            }
        }
        for (i, c) in comps.iter_mut().enumerate() {
            net.current = i;
            c.bind(&mut net)?;
        }
        if let Some(e) = net.mismatch.take() {
            return Err(e);
        }
        let (order, groups) = crate::series::evaluation_order(&net)?;
        let n = comps.len();
        let attachments = attachments::Attachments::of(&net, n);
        let dependencies = dependencies::Dependencies::of(&net, n);
        // components that read complete accumulators go last, in order
        let (mut order, last): (Vec<Step>, Vec<Step>) = order
            .into_iter()
            .partition(|s| !matches!(s, Step::Evaluate(i) if comps[*i].evaluates_last()));
        order.extend(last);
        let mut offsets = Vec::with_capacity(n + 1);
        let mut ev_offsets = Vec::with_capacity(n + 1);
        let mut q_offsets = Vec::with_capacity(n + 1);
        let (mut s, mut e, mut q) = (0, 0, 0);
        for c in &comps {
            offsets.push(s);
            ev_offsets.push(e);
            q_offsets.push(q);
            s += c.n_states();
            e += c.n_events();
            q += c.n_quadratures();
        }
        offsets.push(s);
        ev_offsets.push(e);
        q_offsets.push(q);
        let analytic = comps.iter().all(|c| c.has_tangents());
        let settlers = (0..n).filter(|&i| comps[i].settles()).collect();
        let mut publisher = vec![None; net.names.len()];
        for (&w, o) in &net.owners {
            if o.causality == crate::Causality::Stored {
                publisher[w] = Some(o.owner);
            }
        }
        Ok(Self {
            comps,
            offsets,
            ev_offsets,
            order,
            groups,
            scratch: RefCell::new(Vec::new()),
            accumulators: net.accumulators,
            settlers,
            wires: RefCell::new(Wires {
                v: vec![0.0; net.names.len()],
            }),
            n_states: s,
            n_events: e,
            quad: false,
            ledger: false,
            q_offsets,
            n_quad: q,
            wire_names: net.names,
            publisher,
            probe_names: None,
            state_labels: None,
            probe_units: Vec::new(),
            attachments,
            dependencies,
            analytic,
            tangents: RefCell::new(Tangents::default()),
            filled: RefCell::new(FillKey::default()),
        })
    }

    /// Number of component states (without quadratures).
    pub fn n_states(&self) -> usize {
        self.n_states
    }

    /// Turns the component quadratures on or off (appended after the states).
    pub fn set_quadratures(&mut self, on: bool) {
        self.quad = on;
    }

    /// Turns the energy ledger on or off: [`LEDGER_TERMS`] quadratures per
    /// component (∫source, ∫dissipated, ∫storage, ∫load, ∫moved dt \[J\])
    /// appended after the component quadratures.
    pub fn set_ledger(&mut self, on: bool) {
        self.ledger = on;
    }

    fn quad_len(&self) -> usize {
        if self.quad {
            self.n_quad
        } else {
            0
        }
    }

    /// Index of the first component quadrature in the full state vector.
    pub fn quadrature_offset(&self) -> usize {
        self.n_states
    }

    /// Index of the first ledger quadrature in the full state vector.
    pub fn ledger_offset(&self) -> usize {
        self.n_states + self.quad_len()
    }

    /// The components, in the order given to [`Circuit::build`].
    pub fn components(&self) -> impl Iterator<Item = &dyn Component> {
        self.comps.iter().map(|c| c.as_ref())
    }

    /// Index of the component named `name`.
    pub fn component_index(&self, name: &str) -> Option<usize> {
        self.comps.iter().position(|c| c.name() == name)
    }

    /// Sets parameter `path` (`<component>.<parameter>`, the netlist's
    /// scheme) of the built circuit to `value` (SI) without assembling it
    /// again ([`Component::set_parameter`]; errors name the path). The wire
    /// table is evaluated afresh at the next call.
    pub fn set_parameter(&mut self, path: &str, value: f64) -> Result<(), String> {
        let (comp, name) = path
            .split_once('.')
            .ok_or_else(|| format!("`{path}` is not `<component>.<parameter>`"))?;
        let i = self
            .component_index(comp)
            .ok_or_else(|| format!("`{path}`: no component `{comp}` in the circuit"))?;
        self.comps[i]
            .set_parameter(name, value)
            .map_err(|why| format!("`{path}`: {why}"))?;
        self.filled.borrow_mut().valid = false;
        Ok(())
    }

    /// The state range of component `i`.
    pub fn state_range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i]..self.offsets[i + 1]
    }

    /// The quadrature range of component `i` in the full vector (when on).
    pub fn quadrature_range(&self, i: usize) -> std::ops::Range<usize> {
        let o = self.quadrature_offset();
        o + self.q_offsets[i]..o + self.q_offsets[i + 1]
    }

    /// Names of all entries of the full state vector.
    pub fn state_names(&self) -> Vec<String> {
        let mut v: Vec<String> = self.comps.iter().flat_map(|c| c.state_names()).collect();
        if self.quad {
            v.extend(self.comps.iter().flat_map(|c| c.quadrature_names()));
        }
        if self.ledger {
            for c in &self.comps {
                for t in LEDGER_TERM_NAMES {
                    v.push(format!("{}.energy_{t}", c.name()));
                }
            }
        }
        v
    }

    /// The component whose event function `which` (an index of
    /// [`OdeSystem::events`]) is.
    pub fn event_owner(&self, which: usize) -> Option<&str> {
        (0..self.comps.len())
            .find(|&i| which >= self.ev_offsets[i] && which < self.ev_offsets[i + 1])
            .map(|i| self.comps[i].name())
    }

    /// The default initial state of every component (quadratures zero).
    pub fn initial_state(&self) -> Vec<f64> {
        let mut x = vec![0.0; self.dim()];
        for (i, c) in self.comps.iter().enumerate() {
            c.initial_state(&mut x[self.offsets[i]..self.offsets[i + 1]]);
        }
        x
    }

    /// Absolute tolerances, `rtol · scale` per state; quadratures are
    /// loosely weighted (scale 1e6 of their unit) so they never limit the step.
    pub fn atol(&self, rtol: f64) -> Vec<f64> {
        let mut a = vec![1.0e6; self.dim()];
        for (i, c) in self.comps.iter().enumerate() {
            c.state_scales(&mut a[self.offsets[i]..self.offsets[i + 1]]);
        }
        a.iter().map(|s| rtol * s).collect()
    }

    /// The probes of every component, in component order, under the names
    /// given by [`Circuit::name_probes`] (if it was called), in the units
    /// given by [`Circuit::set_probe_unit`].
    pub fn probes(&self) -> Vec<Probe> {
        let all = self.comps.iter().flat_map(|c| {
            c.probes().into_iter().map(move |mut p| {
                if let Some((_, _, u)) = self
                    .probe_units
                    .iter()
                    .find(|(comp, probe, _)| comp == c.name() && *probe == p.name)
                {
                    p.unit = u;
                }
                p.path = format!("{}.{}", c.name(), p.name);
                p
            })
        });
        match &self.probe_names {
            None => all.collect(),
            Some(names) => all
                .zip(names)
                .filter_map(|(mut p, n)| {
                    n.clone().map(|n| {
                        p.name = n;
                        p
                    })
                })
                .collect(),
        }
    }

    /// Renames the probes (the run's output columns): `name(component,
    /// probe)` gives the column of each probe, `None` leaves it out.
    pub fn name_probes(&mut self, name: impl Fn(&str, &str) -> Option<String>) {
        let names = self
            .comps
            .iter()
            .flat_map(|c| {
                c.probes()
                    .into_iter()
                    .map(|p| name(c.name(), &p.name))
                    .collect::<Vec<_>>()
            })
            .collect();
        self.probe_names = Some(names);
    }

    /// Gives probe `probe` of component `component` the unit `unit`: a
    /// signal's probe is read in the unit of what the signal means where it
    /// is used (a command input feeding a position controller's set-point
    /// is in m), which its wire (a bare signal) cannot say.
    pub fn set_probe_unit(&mut self, component: &str, probe: &str, unit: &'static str) {
        self.probe_units
            .retain(|(c, p, _)| !(c == component && p == probe));
        self.probe_units
            .push((component.to_string(), probe.to_string(), unit));
    }

    /// Diagnostics of every component, names prefixed by the component's;
    /// an algebraic node's report its solves, the member evaluations they
    /// took and how many fell back to Brent (`<node>.solves`,
    /// `<node>.solve_evaluations`, `<node>.solve_fallbacks`).
    pub fn diagnostics(&self) -> Vec<(String, f64)> {
        let mut d: Vec<(String, f64)> = self
            .comps
            .iter()
            .flat_map(|c| {
                let n = c.name().to_string();
                c.diagnostics()
                    .into_iter()
                    .map(move |(k, v)| (format!("{n}.{k}"), v))
            })
            .collect();
        for g in &self.groups {
            let n = self.comps[g.owner].name();
            d.push((format!("{n}.solves"), g.solves.get() as f64));
            d.push((format!("{n}.solve_evaluations"), g.evaluations.get() as f64));
            d.push((format!("{n}.solve_fallbacks"), g.fallbacks.get() as f64));
        }
        d
    }

    /// Whether the wires at `(t, x)` are the same whatever was evaluated
    /// before and whichever events were handled: no algebraic node (its
    /// Newton solve starts from the last solution, which moves the last
    /// bits) and no component whose events change its evaluation
    /// ([`Component::events_change_evaluation`]). Then a second circuit built
    /// and reset like this one reads the same probes at the same points, on
    /// another thread ([`crate::run::ProbeReader`]).
    pub fn history_free(&self) -> bool {
        self.groups.is_empty() && !self.comps.iter().any(|c| c.events_change_evaluation())
    }

    /// Evaluates every wire at `(t, x)` and returns a copy of the table.
    pub fn wires_at(&self, t: f64, x: &[f64]) -> Wires {
        self.fill(t, x);
        self.wires.borrow().clone()
    }

    /// What an evaluation leaves for the next to start from: the wire table,
    /// where it was evaluated, and each algebraic node's last solutions
    /// (where its next solve starts). Reading outputs between a solve's
    /// steps takes it before and puts it back after
    /// ([`Circuit::restore_memory`]), so that the steps evaluate as if
    /// nothing had been read: a run is the same whenever its outputs are
    /// read.
    pub fn memory(&self) -> CircuitMemory {
        CircuitMemory {
            wires: self.wires.borrow().v.clone(),
            filled: self.filled.borrow().clone(),
            series: self.groups.iter().map(SeriesGroup::memory).collect(),
        }
    }

    /// Puts back what [`Circuit::memory`] took (of this circuit, or of one
    /// built alike: a memory of another shape is ignored).
    pub fn restore_memory(&self, m: CircuitMemory) {
        if m.wires.len() != self.wires.borrow().v.len() || m.series.len() != self.groups.len() {
            return;
        }
        self.wires.borrow_mut().v = m.wires;
        *self.filled.borrow_mut() = m.filled;
        for (g, s) in self.groups.iter().zip(m.series) {
            g.restore(s);
        }
    }

    /// Evaluates every wire at `(t, x)` and copies the values of `wires` into `out`.
    pub fn read_wires(&self, t: f64, x: &[f64], wires: &[AnyWire], out: &mut [f64]) {
        self.fill(t, x);
        let w = self.wires.borrow();
        for (o, wire) in out.iter_mut().zip(wires) {
            *o = w.get(*wire);
        }
    }

    /// The component whose [`Component::publish`] sets wire `w` from its
    /// own state and the time (an effort it owns with
    /// [`Causality::Stored`]), if one does.
    pub fn publisher_of(&self, w: AnyWire) -> Option<usize> {
        self.publisher.get(w.0).copied().flatten()
    }

    /// Name of a wire (`hyd:<node>:p`, `mech:<node>:v`, `sig:<name>`, ...).
    pub fn wire_name(&self, w: impl Into<AnyWire>) -> &str {
        let w = w.into();
        &self.wire_names[w.0]
    }

    /// Finds a wire by its name.
    pub fn find_wire(&self, name: &str) -> Option<AnyWire> {
        self.wire_names.iter().position(|n| n == name).map(AnyWire)
    }

    /// Per-component power terms at `(t, x)` (the ledger's integrands), in component order.
    pub fn power_terms(&self, t: f64, x: &[f64]) -> Vec<PowerTerms> {
        let mut dx = vec![0.0; self.dim()];
        self.rhs(t, x, &mut dx);
        let w = self.wires.borrow();
        self.comps
            .iter()
            .enumerate()
            .map(|(i, c)| {
                let r = self.offsets[i]..self.offsets[i + 1];
                let mut p = PowerTerms::default();
                c.power(t, &x[r.clone()], &w, &dx[r], &mut p);
                p
            })
            .collect()
    }

    /// Calls [`Component::reset`] on every component at `(t, x)`.
    pub fn reset(&mut self, t: f64, x: &[f64]) {
        // a run from a given state solves its algebraic nodes the same way
        // whatever ran before
        for g in &self.groups {
            g.forget();
        }
        self.fill(t, x);
        for g in &self.groups {
            g.solves.set(0);
            g.evaluations.set(0);
            g.fallbacks.set(0);
        }
        let w = self.wires.borrow().clone();
        for (i, c) in self.comps.iter_mut().enumerate() {
            c.reset(t, &x[self.offsets[i]..self.offsets[i + 1]], &w);
        }
        // the components' modes may have changed: the table is stale
        self.filled.borrow_mut().valid = false;
    }

    /// Forgets where the wire table was last evaluated, so that the next
    /// evaluation at any point fills it afresh: an input from outside the
    /// circuit (an [`ExternalInput`](crate::external::ExternalInput)) may
    /// have changed since, at the same time and state.
    pub(crate) fn forget_evaluation(&self) {
        self.filled.borrow_mut().valid = false;
    }

    /// Whether the wire table holds the evaluation at exactly `(t, x)` with
    /// the components' modes as they are now (the stiff solver asks for the
    /// Jacobian right after `f(t, x)`; its tangent pass reuses that table).
    fn filled_at(&self, t: f64, x: &[f64]) -> bool {
        let k = self.filled.borrow();
        k.valid
            && k.t.to_bits() == t.to_bits()
            && k.x.len() == x.len()
            && k.x.iter().zip(x).all(|(a, b)| a.to_bits() == b.to_bits())
    }

    /// Publish + evaluate: every wire is current for `(t, x)`.
    fn fill(&self, t: f64, x: &[f64]) {
        {
            let mut k = self.filled.borrow_mut();
            k.valid = true;
            k.t = t;
            k.x.clear();
            k.x.extend_from_slice(x);
        }
        let mut w = self.wires.borrow_mut();
        self.publish_and_evaluate(None, &self.order, t, x, &mut w);
        if !self.settlers.is_empty() {
            self.settle(t, x, &mut w);
        }
    }

    /// Zeroes the accumulators, publishes the components `publishers`
    /// (every one for `None`) and runs `steps`: all of them for
    /// [`Circuit::fill`], or what some wires depend on
    /// ([`Circuit::partial_for`]).
    #[inline]
    fn publish_and_evaluate(
        &self,
        publishers: Option<&[usize]>,
        steps: &[Step],
        t: f64,
        x: &[f64],
        w: &mut Wires,
    ) {
        for &a in &self.accumulators {
            w.zero(a);
        }
        let xs = |i: usize| &x[self.offsets[i]..self.offsets[i + 1]];
        match publishers {
            None => {
                for (c, o) in self.comps.iter().zip(self.offsets.windows(2)) {
                    c.publish(t, &x[o[0]..o[1]], w);
                }
            }
            Some(p) => {
                for &i in p {
                    self.comps[i].publish(t, xs(i), w);
                }
            }
        }
        for step in steps {
            match *step {
                Step::Evaluate(i) => self.comps[i].evaluate(t, xs(i), w),
                Step::Solve(g) => {
                    let g = &self.groups[g];
                    let eval = |w: &mut Wires| {
                        for &i in &g.members {
                            self.comps[i].evaluate(t, xs(i), w);
                        }
                    };
                    let slope = |w: &Wires| {
                        g.members.iter().try_fold(0.0, |s, &i| {
                            Some(s + self.comps[i].inflow_slope(t, xs(i), w, g.node.pressure)?)
                        })
                    };
                    let laws = |w: &Wires| match g.members[..] {
                        [a, b] => Some([
                            self.comps[a].orifice_inflow(t, xs(a), w, g.node.pressure)?,
                            self.comps[b].orifice_inflow(t, xs(b), w, g.node.pressure)?,
                        ]),
                        _ => None,
                    };
                    g.solve(t, w, &mut self.scratch.borrow_mut(), eval, slope, laws);
                }
            }
        }
    }

    /// [`Component::settle`] on the components that ask for it (out of
    /// line: most circuits have none, and their evaluation stays as it was).
    #[inline(never)]
    fn settle(&self, t: f64, x: &[f64], w: &mut Wires) {
        for &i in &self.settlers {
            self.comps[i].settle(t, &x[self.offsets[i]..self.offsets[i + 1]], w);
        }
    }
}

impl Circuit {
    /// The energy an event took out of the states it edited (a plastic
    /// impact's kinetic energy), moved in the ledger from the component's
    /// storage to its losses: the integrated storage then still equals the
    /// stored energy of the states, and the balance still closes.
    fn book_event_loss(&self, t: f64, x: &mut [f64], states: &[f64], before: &[PowerTerms]) {
        let after = self.power_terms(t, x);
        let o = self.ledger_offset();
        for (i, r) in self.offsets.windows(2).enumerate() {
            if x[r[0]..r[1]] != states[r[0]..r[1]] {
                let lost = before[i].stored - after[i].stored;
                let k = o + LEDGER_TERMS * i;
                x[k + 1] += lost;
                x[k + 2] -= lost;
            }
        }
        self.filled.borrow_mut().valid = false;
    }
}

impl OdeSystem for Circuit {
    fn dim(&self) -> usize {
        self.n_states
            + self.quad_len()
            + if self.ledger {
                LEDGER_TERMS * self.comps.len()
            } else {
                0
            }
    }

    /// The component quadratures and the energy ledger: integrals of
    /// flows and powers that no component reads back.
    fn n_quadratures(&self) -> usize {
        self.dim() - self.n_states
    }

    fn state_name(&self, i: usize) -> Option<String> {
        self.state_label(i)
    }

    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        // the table may already hold (t, x): the switching functions at the
        // end of an accepted step evaluated it, and the stiff solver's next
        // step starts with f there
        if !self.filled_at(t, x) {
            self.fill(t, x);
        }
        let w = self.wires.borrow();
        for (c, o) in self.comps.iter().zip(self.offsets.windows(2)) {
            let r = o[0]..o[1];
            // a component without states has no derivatives to write
            if !r.is_empty() {
                c.derivatives(t, &x[r.clone()], &w, &mut dx[r]);
            }
        }
        if self.quad {
            let o = self.quadrature_offset();
            for (i, c) in self.comps.iter().enumerate() {
                let r = self.offsets[i]..self.offsets[i + 1];
                let (ds, dq) = dx.split_at_mut(o);
                c.quadratures(
                    t,
                    &x[r.clone()],
                    &w,
                    &ds[r],
                    &mut dq[self.q_offsets[i]..self.q_offsets[i + 1]],
                );
            }
        }
        if self.ledger {
            let o = self.ledger_offset();
            for (i, c) in self.comps.iter().enumerate() {
                let r = self.offsets[i]..self.offsets[i + 1];
                let mut p = PowerTerms::default();
                c.power(t, &x[r.clone()], &w, &dx[r], &mut p);
                let k = o + LEDGER_TERMS * i;
                dx[k] = p.source;
                dx[k + 1] = p.dissipated;
                dx[k + 2] = p.storage;
                dx[k + 3] = p.load;
                dx[k + 4] = p.moved;
            }
        }
    }

    /// The analytic Jacobian (see [`Tangents`]) where every component has
    /// one and the ledger is off; finite differences otherwise.
    fn jacobian(&self, t: f64, x: &[f64], jac: &mut [f64]) -> bool {
        self.analytic_jacobian(t, x, jac)
    }

    fn constant_in_time(&self, t: f64) -> bool {
        !self.comps.iter().any(|c| c.reads_time(t))
    }

    fn next_breakpoint(&self, t: f64) -> f64 {
        self.comps
            .iter()
            .map(|c| c.next_breakpoint(t))
            .fold(f64::INFINITY, f64::min)
    }

    fn n_events(&self) -> usize {
        self.n_events
    }

    fn events(&self, t: f64, x: &[f64], g: &mut [f64]) {
        // after an accepted step the last stage has just filled the table at
        // exactly (t, x) (first same as last): no second evaluation
        if !self.filled_at(t, x) {
            self.fill(t, x);
        }
        let w = self.wires.borrow();
        let spans = self.offsets.windows(2).zip(self.ev_offsets.windows(2));
        for (c, (o, e)) in self.comps.iter().zip(spans) {
            // a component without event functions has nothing to write
            if e[0] < e[1] {
                c.events(t, &x[o[0]..o[1]], &w, &mut g[e[0]..e[1]]);
            }
        }
    }

    fn on_event(&mut self, t: f64, x: &mut [f64], which: usize, dir: Crossing) -> EventAction {
        self.fill(t, x);
        let w = self.wires.borrow().clone();
        let Some(i) = (0..self.comps.len())
            .find(|&i| which >= self.ev_offsets[i] && which < self.ev_offsets[i + 1])
        else {
            return EventAction::Continue;
        };
        let r = self.offsets[i]..self.offsets[i + 1];
        let before = self
            .ledger
            .then(|| (x[..self.n_states].to_vec(), self.power_terms(t, x)));
        let action = self.comps[i].on_event(t, &mut x[r], &w, which - self.ev_offsets[i], dir);
        self.fill(t, x);
        let w = self.wires.borrow().clone();
        for (i, c) in self.comps.iter_mut().enumerate() {
            c.after_event(t, &mut x[self.offsets[i]..self.offsets[i + 1]], &w);
        }
        // modes and states changed after the last evaluation
        self.filled.borrow_mut().valid = false;
        if let Some((states, terms)) = before {
            self.book_event_loss(t, x, &states, &terms);
        }
        action
    }
}

#[cfg(test)]
mod tests;
