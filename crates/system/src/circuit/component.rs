//! What a component of a [`Circuit`](super::Circuit) is: the [`Component`]
//! trait the assembler calls, the [`Probe`]s it publishes and the
//! [`PowerTerms`] it reports to the energy ledger.

use super::{AnyWire, BuildError, Netlist, Tangents, Wire, Wires};
use crate::series::OrificeInflow;
use hydrocyl_integrators::{Crossing, EventAction};
use hydrocyl_ports::Quantity;

/// Power bookkeeping of one component at one instant (the energy ledger's
/// input). Each component must balance on its own:
/// `power in at its ports + source = dissipated + storage + load + power out at its ports`,
/// so that summed over a circuit (port powers cancel pairwise at each node)
/// `Σ source = Σ dissipated + Σ storage + Σ load`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PowerTerms {
    /// Power brought into the circuit from outside: a fixed-pressure supply
    /// delivering flow, a pump's shaft \[W\].
    pub source: f64,
    /// Power turned into heat: orifices, leakage, friction \[W\].
    pub dissipated: f64,
    /// Rate of change of energy stored in the component: fluid compression
    /// `p V/B dp/dt`, kinetic `m v a`, bristle `σ0 z ż` \[W\].
    pub storage: f64,
    /// Power delivered as work to the outside (an external load force) \[W\].
    pub load: f64,
    /// Energy stored now (`½ V p²/B`, `½ (m + c) v²`, `½ σ0 z²`) \[J\] — for
    /// reports and the ledger's storage check; the ledger integrates
    /// `storage`, which is exact for the model used.
    pub stored: f64,
    /// Rate at which `stored` changes because a storage's volume moves, which
    /// `storage` does not contain \[W\]: a chamber's energy density times
    /// `dV/dt` (the linear fluid model `ṗ = B/V (Q − V̇)` stores `p V/B ṗ`;
    /// the state function `½ V p²/B` also changes by `½ p²/B V̇`). Not a
    /// power of the balance: only the storage check adds it.
    pub moved: f64,
}

/// A named output of a component, read from a wire after a solve.
#[derive(Clone, Debug, PartialEq)]
pub struct Probe {
    /// Column name, e.g. `p1`, `position`, `spool` (the measured-data names).
    pub name: String,
    /// SI unit, e.g. `Pa`.
    pub unit: &'static str,
    /// The wire it reads.
    pub wire: AnyWire,
    /// What it is, whatever its column is called: `<component>.<probe>`
    /// (`damper.p1`) as [`Circuit::probes`](super::Circuit::probes) lists
    /// it; the bare name from [`Probe::of`].
    pub path: String,
}

impl Probe {
    /// A probe named `name` on a typed wire, in the wire's SI unit.
    pub fn of<Q: Quantity>(name: impl Into<String>, wire: Wire<Q>) -> Self {
        let name = name.into();
        Self {
            path: name.clone(),
            name,
            unit: Q::UNIT,
            wire: wire.raw(),
        }
    }
}

/// A component of a circuit. Implement this to add a new component type: it
/// lives in its own file, and [`Circuit::build`](super::Circuit::build) joins it to the others
/// through named nodes — no change to the assembler.
///
/// The assembler calls, for each evaluation of `rhs(t, x)`:
/// 1. [`publish`](Component::publish) on every component (efforts from own state);
/// 2. [`evaluate`](Component::evaluate) in dependency order (flows, forces,
///    algebraic signals, accumulated into node wires);
/// 3. [`derivatives`](Component::derivatives) on every stateful component.
///
/// Each component sees only its own slice of the state vector.
///
/// For the stiff solver's Jacobian a component may also give its tangents
/// ([`has_tangents`](Component::has_tangents) and the `*_tangents` methods,
/// mirroring the three calls above; see [`Tangents`]); a circuit with one
/// component without them falls back to finite differences.
pub trait Component {
    /// Instance name (unique in a circuit), used in errors and reports.
    fn name(&self) -> &str;

    /// Declares the nodes and signals this component reads and owns, and
    /// stores the returned wire handles. What [`evaluate`](Component::evaluate)
    /// reads must be declared here: reading a run's probes evaluates only
    /// the components the probed wires depend on by these declarations
    /// (`Circuit::partial_for`; debug builds
    /// compare every such read with a full evaluation).
    fn bind(&mut self, net: &mut Netlist) -> Result<(), BuildError>;

    /// Number of states this component owns.
    fn n_states(&self) -> usize {
        0
    }

    /// Names of the states (for reports), `n_states` long.
    fn state_names(&self) -> Vec<String> {
        (0..self.n_states())
            .map(|i| format!("{}.x{i}", self.name()))
            .collect()
    }

    /// Typical magnitude of each state \[its SI unit\]; the absolute
    /// tolerance of state i is `rtol · scale_i`.
    fn state_scales(&self, scales: &mut [f64]) {
        scales.fill(1.0);
    }

    /// The component's default initial state.
    fn initial_state(&self, _x: &mut [f64]) {}

    /// Writes the efforts this component owns with
    /// [`Causality::Stored`](super::Causality::Stored), from its own state and
    /// the time; it may also add what depends on them alone into node
    /// accumulators (a chamber's pressure force on the rod, a pump's flow).
    /// The circuit zeroes the accumulators before the first `publish`.
    fn publish(&self, _t: f64, _x: &[f64], _w: &mut Wires) {}

    /// Whether the component is an actuator: it turns hydraulic power into
    /// the mechanical power on its rod (a cylinder, a bench's piston). The
    /// energy ledger's cylinder output is the work the other components on
    /// an actuator's rod take ([`Circuit::is_actuator`](super::Circuit::is_actuator)).
    fn is_actuator(&self) -> bool {
        false
    }

    /// Computes flows and forces from the efforts at its ports and adds them
    /// to the node accumulators; writes [`Causality::Algebraic`](super::Causality::Algebraic) wires.
    /// Every wire other than an accumulator that it writes here it writes on
    /// every call, never as a function of its previous value: the Newton
    /// solve of an algebraic node ([`crate::series`]) evaluates its members
    /// repeatedly and restores only the accumulators between trials.
    fn evaluate(&self, _t: f64, _x: &[f64], _w: &mut Wires) {}

    /// `∂Q/∂p` of the flow this component adds into hydraulic node `node`
    /// with respect to that node's pressure \[m³·s⁻¹·Pa⁻¹\] (negative for a
    /// resistive component), or `None` if it cannot say. The assembler's
    /// Newton solve of an algebraic node ([`crate::series`]) uses it. The
    /// default is the slope of the component's
    /// [`orifice_inflow`](Component::orifice_inflow) law where the node's
    /// pressure lies in it ([`OrificeInflow::slope`]), else `None`: a
    /// component whose law has another branch (a needle's check cracked)
    /// gives its slope itself.
    fn inflow_slope(
        &self,
        t: f64,
        x: &[f64],
        w: &Wires,
        node: Wire<hydrocyl_ports::Pressure>,
    ) -> Option<f64> {
        let p = w.get(node).si();
        let law = self.orifice_inflow(t, x, w, node)?;
        law.holds(p).then(|| law.slope(p))
    }

    /// The flow this component adds into hydraulic node `node` as an orifice
    /// law of that node's pressure ([`OrificeInflow`]: `k·√(other − p)`,
    /// regularised near zero), where it is one; `None` (the default) when it
    /// is not or cannot say. An algebraic node with two such members is
    /// solved in closed form ([`crate::series`]); the law must be the one
    /// [`evaluate`](Component::evaluate) computes, bit for bit in `k`.
    fn orifice_inflow(
        &self,
        _t: f64,
        _x: &[f64],
        _w: &Wires,
        _node: Wire<hydrocyl_ports::Pressure>,
    ) -> Option<OrificeInflow> {
        None
    }

    /// Whether what it publishes, evaluates or derives at `t` changes with
    /// the time itself over a short span after `t` (at fixed states and
    /// wires): a source of a time-varying signal. `true` (the default)
    /// unless it knows; a circuit whose components all say `false` has
    /// `∂f/∂t = 0` there ([`OdeSystem::constant_in_time`](hydrocyl_integrators::OdeSystem::constant_in_time)).
    fn reads_time(&self, _t: f64) -> bool {
        true
    }

    /// Time derivatives of its states (all accumulators are complete here).
    fn derivatives(&self, _t: f64, _x: &[f64], _w: &Wires, _dx: &mut [f64]) {}

    /// Whether this component gives the analytic Jacobian's tangents (the
    /// four `*_tangents` methods below; see [`Tangents`]). `false` (the
    /// default) makes the whole circuit fall back to finite differences, so
    /// a component without them keeps working.
    fn has_tangents(&self) -> bool {
        false
    }

    /// The gradient rows of the efforts [`publish`](Component::publish)
    /// sets, with respect to its own states ([`Tangents::state`]).
    fn publish_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, _d: &mut Tangents) {}

    /// The gradient rows of what [`evaluate`](Component::evaluate) writes:
    /// its local partials chained onto the rows of the wires it reads
    /// ([`Tangents::chain`]) and onto its own states ([`Tangents::state`]),
    /// for the branch (mode, regime) the evaluation at `w` took.
    fn evaluate_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, _d: &mut Tangents) {}

    /// The rows of `∂ẋ/∂x` of its states ([`Tangents::rate_chain`],
    /// [`Tangents::rate_state`]); every wire's row is complete here.
    fn derivative_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, _d: &mut Tangents) {}

    /// The rows of its quadratures' integrands ([`Tangents::quadrature_chain`],
    /// [`Tangents::quadrature_state`]).
    fn quadrature_tangents(&self, _t: f64, _x: &[f64], _w: &Wires, _d: &mut Tangents) {}

    /// Whether the circuit calls [`settle`](Component::settle) after every
    /// evaluation.
    fn settles(&self) -> bool {
        false
    }

    /// Called after every component has been evaluated (the accumulators
    /// complete), to set private wires that only probes read from them: a
    /// stuck friction's force is everything else acting on the rod. It may
    /// not change a wire another component reads.
    fn settle(&self, _t: f64, _x: &[f64], _w: &mut Wires) {}

    /// Whether [`evaluate`](Component::evaluate) must run after every other
    /// component's, to read complete accumulators (an imposed-motion source
    /// reporting the force it takes to impose its motion). Nothing may read
    /// its algebraic wires but probes.
    fn evaluates_last(&self) -> bool {
        false
    }

    /// The first time after `t` where an input of this component has a
    /// kink (see [`OdeSystem::next_breakpoint`](hydrocyl_integrators::OdeSystem::next_breakpoint)), or `+∞`.
    fn next_breakpoint(&self, _t: f64) -> f64 {
        f64::INFINITY
    }

    /// Number of switching functions.
    fn n_events(&self) -> usize {
        0
    }

    /// Switching functions (an event is a sign change of one).
    fn events(&self, _t: f64, _x: &[f64], _w: &Wires, _g: &mut [f64]) {}

    /// Handles a located event: change mode, edit own state.
    fn on_event(
        &mut self,
        _t: f64,
        _x: &mut [f64],
        _w: &Wires,
        _which: usize,
        _dir: Crossing,
    ) -> EventAction {
        EventAction::Continue
    }

    /// Whether [`on_event`](Component::on_event) or
    /// [`after_event`](Component::after_event) can change what
    /// [`publish`](Component::publish) and [`evaluate`](Component::evaluate)
    /// compute at a given `(t, x)` (a mode: stick/slip, at a stop). `true`
    /// for every component with events unless it says otherwise (one that
    /// only counts its events, e.g. cavitation entries); see
    /// [`Circuit::history_free`](super::Circuit::history_free).
    fn events_change_evaluation(&self) -> bool {
        self.n_events() > 0
    }

    /// Called on every component after any component handled an event, with
    /// the wires re-evaluated at the edited state: a chance to edit its own
    /// state in response (a mass sets v = 0 when a friction law starts to stick).
    fn after_event(&mut self, _t: f64, _x: &mut [f64], _w: &Wires) {}

    /// Power bookkeeping at this instant (see [`PowerTerms`]).
    fn power(&self, _t: f64, _x: &[f64], _w: &Wires, _dx: &[f64], _p: &mut PowerTerms) {}

    /// Whether the component's model conserves energy, so that its
    /// [`Component::power`] terms balance its port powers. `false` for a
    /// model form that does not (the generalised one-pressure cylinder of
    /// eqs 2.16–2.26): an energy ledger over it then does not close, and says
    /// which component is why.
    fn energy_consistent(&self) -> bool {
        true
    }

    /// Number of extra quadratures this component asks for (integrated
    /// alongside the states when [`Circuit::set_quadratures`](super::Circuit::set_quadratures) is on).
    fn n_quadratures(&self) -> usize {
        0
    }

    /// Names of the quadratures.
    fn quadrature_names(&self) -> Vec<String> {
        Vec::new()
    }

    /// Integrands of the quadratures.
    fn quadratures(&self, _t: f64, _x: &[f64], _w: &Wires, _dx: &[f64], _q: &mut [f64]) {}

    /// Named outputs.
    fn probes(&self) -> Vec<Probe> {
        Vec::new()
    }

    /// Counters and flags of the last run (cavitation entries, stop impacts).
    fn diagnostics(&self) -> Vec<(String, f64)> {
        Vec::new()
    }

    /// Called once before a run from a given state (reset counters, set modes).
    fn reset(&mut self, _t: f64, _x: &[f64], _w: &Wires) {}

    /// Changes parameter `name` (its netlist name, `seal.k_pressure`) of the
    /// built component to `value` (SI), for a caller that runs one circuit
    /// many times with different parameters (a fit) without assembling it
    /// again. A parameter the component cannot change in place (one that
    /// changes its states or ports) is an error saying so; the default
    /// refuses every parameter.
    fn set_parameter(&mut self, name: &str, _value: f64) -> Result<(), String> {
        Err(format!(
            "`{name}` cannot be changed on the built `{}`: set it in the netlist and assemble again",
            self.name()
        ))
    }
}
