//! # hydrocyl-system — the rig assembler
//!
//! A rig is built by joining **components** through **typed nodes**, not by
//! writing one right-hand side. The assembler ([`Circuit::build`]) binds each
//! component to named nodes, checks the causality, orders the algebraic
//! evaluations once, gives each stateful component its slice of one state
//! vector, and produces one [`OdeSystem`](hydrocyl_integrators::OdeSystem)
//! (`rhs`, switching functions, event handling) for the integrators.
//!
//! ```text
//!   supply P ──┐                    ┌── A ══ chamber 1 (p1) ┐
//!              ├─[ FourWayValve ]───┤                       ├─[ Cylinder ]══ rod ══[ Mass ]
//!   tank   T ──┘        ▲           └── B ══ chamber 2 (p2) ┘        ▲          ▲
//!                       │ spool [m]                                  └─[ Friction ]
//!   command u [-] ─▶[ ServoSpool ]
//! ```
//!
//! ## Causality (the rules a component follows)
//! * A **hydraulic node** has a pressure \[Pa\] and an inflow accumulator
//!   \[m³·s⁻¹\]. Exactly one component **owns** it and sets the pressure: a
//!   capacitive element ([`components::Volume`], the chambers of
//!   [`components::TwoChamberCylinder`]) from its state, or a fixed source
//!   ([`components::PressureSource`]). Every other component connected to it
//!   is resistive: it reads the pressures at its ports and **adds** flows
//!   (orifices, valves, leakage, relief and check valves).
//!   The owner integrates the accumulated flow with the exact mass balance
//!   `dp/dt = B/V (ΣQ_in − dV/dt)`.
//! * A **mechanical node** (a rigid body) has position \[m\] and velocity
//!   \[m·s⁻¹\] set by its owner ([`components::Mass`]) and a force accumulator
//!   \[N\] and an added-mass accumulator \[kg\] (acceleration-proportional
//!   friction terms moved to the mass side, `(m + Σc) a = ΣF − F_ext`).
//! * A **signal** (command, spool position, pilot travel) has one writer.
//! * An owner writes either from its state ([`Causality::Stored`], in
//!   [`Component::publish`]) or algebraically from other wires
//!   ([`Causality::Algebraic`], in [`Component::evaluate`]); readers of an
//!   algebraic wire are evaluated after its writer (an algebraic loop is a
//!   build error naming the components).
//!
//! * **Wires are typed** by the quantity they carry (`hydrocyl-ports`
//!   newtypes): a [`Wire<Q>`](Wire) is an effort or signal with one writer,
//!   an [`Acc<Q>`](Acc) an accumulator every other component adds to. A
//!   [`HydraulicNode`] is `Wire<Pressure>` + `Acc<VolumeFlow>`, a
//!   [`MechanicalNode`] `Wire<Position>`, `Wire<Velocity>`, `Acc<Force>`,
//!   `Acc<Mass>`; [`Wires::get`]/[`Wires::set`]/[`Wires::add`] take and
//!   return the quantity, so adding a pressure into a flow accumulator does
//!   not compile (see [`Acc`]). Signals are typed where their meaning is
//!   fixed (a spool travel is a `Position`, a relief flow a `VolumeFlow`); a
//!   command is a bare `f64`. Two components that use one signal name as
//!   different quantities are a build error ([`BuildError::UnitMismatch`]).
//!   Output columns read wires untyped ([`AnyWire`], [`Probe`]).
//!
//! Each evaluation of `rhs(t, x)`: zero the accumulators → `publish` all →
//! `evaluate` in the dependency order → `derivatives` of each stateful
//! component from its own state slice and the wires. Components never see the
//! whole vector.
//!
//! ## Extension points (for new components and rigs)
//! * **A new component type** (pump, relief valve, pilot-operated valve,
//!   bristle friction, ...): a struct in its own file implementing
//!   [`Component`]: `bind` (claim/declare nodes via [`Netlist`]), `n_states`,
//!   `publish`/`evaluate`/`derivatives`, and optionally `events`/`on_event`
//!   (switching functions: relief cracking, check opening, stops), `power`
//!   (the energy ledger), `quadratures`, `probes` (output columns) and
//!   `diagnostics` (counters). Placeholders for wire fields before `bind`:
//!   [`Wire::UNBOUND`], [`HydraulicNode::UNBOUND`], [`MechanicalNode::UNBOUND`]. No
//!   change to the assembler is needed. For the stiff solver's analytic
//!   Jacobian it may also give its tangents (`has_tangents` and the
//!   `*_tangents` twins of its calls, see [`Tangents`]); without them the
//!   circuit falls back to finite differences.
//! * **A new circuit or rig**: a netlist JSON file of registered component
//!   types (and an entry in [`rig::PRESETS`] for a preset). `hydrocyl
//!   simulate`, `--set` and `--print-rig` then work for it unchanged.
//! * **Swapping a component**: the `leaney-moog` rig swaps the spool order
//!   (`valve.dynamics`), the actuator formulation (`cylinder.formulation`:
//!   [`components::FourWayValve`] + [`components::TwoChamberCylinder`] or
//!   [`components::GeneralisedCylinder`], which merges valve metering and
//!   chambers because the generalised form needs the port areas) and the
//!   friction law, each without touching the other components.
//! * **The energy ledger**: every component reports [`PowerTerms`] (source,
//!   dissipated, storage rate, load, stored energy), balanced per component so
//!   that `Σ source = Σ dissipated + Σ storage + Σ load` over a circuit;
//!   [`Circuit::set_ledger`] appends five quadratures per component to the
//!   state vector (loosely weighted in the error norm by [`Circuit::atol`]).
//!
//! A circuit from components, by hand (what a rig kind's builder does), run as
//! every circuit is, by a [`simulation::Simulation`]:
//!
//! ```
//! use hydrocyl_ports::{Area, Density, Pressure};
//! use hydrocyl_system::components::{FixedOrifice, PressureSource, Volume};
//! use hydrocyl_system::run::{RunOptions, Solver};
//! use hydrocyl_system::simulation::Simulation;
//! use hydrocyl_system::{Circuit, Component};
//! use hydrocyl_valves::orifice::Orifice;
//!
//! // supply ──[orifice 0.1 mm²]── line volume 0.1 l (B = 7000 bar)
//! let parts: Vec<Box<dyn Component>> = vec![
//!     Box::new(PressureSource::new("supply", "P", Pressure::from_bar(70.0), None)),
//!     Box::new(FixedOrifice::new("restrictor", "P", "L", Area::from_mm2(0.1),
//!                                Orifice::new(0.65, Density::new(870.0)))),
//!     Box::new(Volume::new("line", "L", 1e-4, 7e8, 0.0, Some("pl"))),
//! ];
//! let c = Circuit::build(parts).unwrap();
//! let opts = RunOptions { rtol: 1e-8, solver: Solver::Dp45, ..RunOptions::default() };
//! let run = Simulation::of_circuit(c).options(opts).run(&[0.0, 2.0]).unwrap();
//! assert!((run.channel("pl").unwrap()[1] - 7.0e6).abs() < 1e3); // the line fills to supply pressure
//! ```
//!
//! ## Thesis equations
//! The components implement eqs 2.2, 2.3/3.1 (spool), 3.2, 2.8, 2.9 (metering),
//! 2.10–2.15 (chambers), 2.16–2.26 and 3.3 (generalised form), 2.27 (load),
//! and section 3.3.4 (steady initial pressures), 3.1.3 (open-loop bias). SI
//! units everywhere.
//!
//! ```
//! use hydrocyl_system::{run::RunOptions, signal::Signal, valve_rig::ValveRig};
//!
//! let rig = ValveRig::leaney_moog();
//! // the square-wave command giving ±90 mm/s (section 3.1.3)
//! let (bias, amplitude) = rig.open_loop_square(0.09).unwrap();
//! let cmd = Signal::Square { amplitude, period_s: 2.0, bias };
//! let t: Vec<f64> = (0..=100).map(|k| k as f64 * 0.01).collect();
//! let run = rig.simulate(cmd, &t, &RunOptions::default()).unwrap(); // automatic solver choice
//! let v = run.channel("velocity").unwrap();
//! assert!((v[90] - 0.09).abs() < 0.005); // extending at 90 mm/s after 0.9 s
//! ```
#![warn(missing_docs)]

mod binding;
pub mod circuit;
pub mod components;
pub mod external;
pub mod hybrid;
pub mod netlist;
pub mod rig;
pub mod run;
pub mod sensor;
pub mod series;
pub mod signal;
pub mod simulation;
pub mod valve_netlist;
pub mod valve_rig;
mod wires;

pub use circuit::{
    Acc, AnyWire, BuildError, Causality, Circuit, CircuitMemory, Component, HydraulicNode,
    MechanicalNode, Netlist, PowerTerms, Probe, ReadWire, Tangents, Wire, Wires,
};
