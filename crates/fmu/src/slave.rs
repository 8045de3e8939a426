//! The co-simulation slave in safe Rust: one instance of an FMU. It holds
//! the rig, the variable values, and (from initialisation on) the rig's
//! [`Simulation`], stepped between communication points
//! ([`Simulation::start`], [`Simulation::step_to`]); [`Slave::do_step`]
//! integrates it over one communication step with the rig's solver.
//!
//! The integrator is restarted at every communication point (its step-size
//! estimate and FSAL stage are not carried over): a step costs the
//! starting-step heuristic (two right-hand sides) more than one long solve
//! would, and no step of the solver straddles a communication point, where
//! the input's slope may change. The circuit itself (component modes:
//! friction stick/slip, stops, valve states) lives on between steps.

use crate::variables::{
    circuit_with_input, output_channels, Role, SolverParam, Variables, METHODS,
};
use hydrocyl_system::external::ExternalInput;
use hydrocyl_system::rig;
use hydrocyl_system::run::RunOptions;
use hydrocyl_system::simulation::Simulation;
use hydrocyl_system::AnyWire;
use serde_json::Value;

mod snapshot;
mod values;

pub use snapshot::Snapshot;

/// Where the slave is in the FMI 2.0 co-simulation state machine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Phase {
    /// After `fmi2Instantiate` / `fmi2Reset`: parameters may be set.
    Instantiated,
    /// Between `fmi2EnterInitializationMode` and `fmi2ExitInitializationMode`.
    Initializing,
    /// Stepping (`fmi2DoStep`).
    Stepping,
    /// After `fmi2Terminate`.
    Terminated,
    /// After an error: only reset and free are allowed.
    Failed,
}

/// The running circuit.
struct Sim {
    sim: Simulation,
    input: ExternalInput,
    wires: Vec<AnyWire>,
    t: f64,
}

/// One FMU instance.
pub struct Slave {
    base: Value,
    rig: Value,
    vars: Variables,
    values: Vec<f64>,
    slope: f64,
    t_start: f64,
    sim: Option<Sim>,
    phase: Phase,
    /// The communication steps taken since the circuit was assembled:
    /// `(t, h, input, slope)` each, what [`Slave::set_state`] replays.
    history: Vec<[f64; 4]>,
}

/// A rejected call: the message to log (names the variable, time, state).
pub type SlaveError = String;

impl Slave {
    /// A new instance of the FMU of `rig` (the rig is checked).
    pub fn new(rig: Value) -> Result<Self, SlaveError> {
        let vars =
            Variables::of(&rig).map_err(|e| format!("rig.json: {}", rig::set_form(e, &rig)))?;
        let values = vars.list.iter().map(|v| v.start).collect();
        Ok(Self {
            base: rig.clone(),
            rig,
            vars,
            values,
            slope: 0.0,
            t_start: 0.0,
            sim: None,
            phase: Phase::Instantiated,
            history: Vec::new(),
        })
    }

    /// The variable table.
    pub fn variables(&self) -> &Variables {
        &self.vars
    }

    /// The current phase.
    pub fn phase(&self) -> Phase {
        self.phase
    }

    /// The rig with the parameters set so far (each value checked on its
    /// own; the set as a whole is checked when the circuit is assembled).
    pub fn rig(&self) -> &Value {
        &self.rig
    }

    /// The communication time reached (the start time before the first step).
    pub fn time(&self) -> f64 {
        self.sim.as_ref().map_or(self.t_start, |s| s.t)
    }

    /// Back to the state right after instantiation (`fmi2Reset`).
    pub fn reset(&mut self) {
        self.rig = self.base.clone();
        self.values = self.vars.list.iter().map(|v| v.start).collect();
        self.slope = 0.0;
        self.t_start = 0.0;
        self.sim = None;
        self.phase = Phase::Instantiated;
        self.history.clear();
    }

    /// `fmi2SetupExperiment`: the start time.
    pub fn setup_experiment(&mut self, start: f64) -> Result<(), SlaveError> {
        self.expect(&[Phase::Instantiated], "fmi2SetupExperiment")?;
        if !start.is_finite() {
            return Err(format!("start time {start} is not finite"));
        }
        self.t_start = start;
        Ok(())
    }

    /// `fmi2EnterInitializationMode`.
    pub fn enter_initialization(&mut self) -> Result<(), SlaveError> {
        self.expect(&[Phase::Instantiated], "fmi2EnterInitializationMode")?;
        self.phase = Phase::Initializing;
        Ok(())
    }

    /// `fmi2ExitInitializationMode`: checks the parameters set together
    /// (the rig's rules that relate several of them) and assembles the
    /// circuit, at the rig's initial state. A rig the parameters make invalid
    /// is an error naming the parameters set; the instance stays in
    /// initialisation mode, where they can be corrected. What it returns
    /// are the warnings of the parameters far outside what real rigs have
    /// (`netlist::implausible`: a unit slip, which runs), as `hydrocyl
    /// simulate` warns of them.
    pub fn exit_initialization(&mut self) -> Result<Vec<String>, SlaveError> {
        self.expect(&[Phase::Initializing], "fmi2ExitInitializationMode")?;
        self.ensure_sim()?;
        self.phase = Phase::Stepping;
        Ok(hydrocyl_system::netlist::read(&self.rig)
            .map(|s| hydrocyl_system::netlist::implausible(&s))
            .unwrap_or_default())
    }

    /// `fmi2Terminate`.
    pub fn terminate(&mut self) -> Result<(), SlaveError> {
        self.expect(&[Phase::Stepping, Phase::Initializing], "fmi2Terminate")?;
        self.phase = Phase::Terminated;
        Ok(())
    }

    fn expect(&self, phases: &[Phase], what: &str) -> Result<(), SlaveError> {
        if phases.contains(&self.phase) {
            Ok(())
        } else {
            Err(format!("{what} is not allowed in phase {:?}", self.phase))
        }
    }

    fn var(&self, vr: u32) -> Result<&crate::variables::Variable, SlaveError> {
        self.vars
            .get(vr)
            .ok_or_else(|| format!("unknown value reference {vr}"))
    }

    /// The parameters whose values differ from their start values, as
    /// `name = value`, comma-separated (`none` if there are none).
    fn parameters_set(&self) -> String {
        let set: Vec<String> = self
            .vars
            .list
            .iter()
            .zip(&self.values)
            .filter(|(v, x)| {
                matches!(v.role, Role::Parameter(_) | Role::Solver(_))
                    && x.to_bits() != v.start.to_bits()
            })
            .map(|(v, x)| format!("{} = {x}", v.name))
            .collect();
        if set.is_empty() {
            "none".into()
        } else {
            set.join(", ")
        }
    }

    /// Assembles the circuit unless it is: the rig with the parameters set
    /// is checked as a whole first ([`rig::check`]: the rules relating
    /// several parameters, which `fmi2SetReal` leaves to this point).
    fn ensure_sim(&mut self) -> Result<(), SlaveError> {
        if self.sim.is_some() {
            return Ok(());
        }
        // the error's paths as `--set` and the variables name them
        let (circuit, input) = rig::check(&self.rig)
            .and_then(|_| circuit_with_input(&self.rig))
            .map_err(|e| {
                format!(
                    "the parameters set ({}) do not make a valid rig: {}",
                    self.parameters_set(),
                    rig::set_form(e, &self.rig)
                )
            })?;
        let probes = output_channels(&circuit, &crate::variables::input_name(&self.rig));
        let mut wires = Vec::with_capacity(self.vars.outputs.len());
        for (name, _) in &self.vars.outputs {
            let p = probes.iter().find(|p| &p.name == name).ok_or_else(|| {
                format!("output `{name}` does not exist with the parameters set (a parameter changed the rig's structure)")
            })?;
            wires.push(p.wire);
        }
        let t = self.t_start;
        self.history.clear();
        input.set(t, self.values[0], self.slope);
        // no quadratures, no ledger: the FMU's outputs are the probes
        let mut sim = Simulation::of_circuit(circuit).options(RunOptions::default());
        sim.start(t).map_err(|e| e.to_string())?;
        self.sim = Some(Sim {
            sim,
            input,
            wires,
            t,
        });
        Ok(())
    }

    /// `fmi2DoStep`: integrates from `t` (the time reached) to `t + h`. A
    /// time or step that is not a finite number, a non-positive step or a
    /// `t` other than the time reached is refused before any integration
    /// (the instance stays usable).
    pub fn do_step(&mut self, t: f64, h: f64) -> Result<(), SlaveError> {
        self.expect(&[Phase::Stepping], "fmi2DoStep")?;
        if !t.is_finite() {
            return Err(format!("communication point t = {t} s is not finite"));
        }
        if !(h > 0.0 && h.is_finite()) {
            return Err(format!(
                "communication step h = {h} s is not finite and positive"
            ));
        }
        if !(t + h).is_finite() {
            return Err(format!("t + h = {t} s + {h} s is not finite"));
        }
        let method = METHODS[self.values[self.index(SolverParam::Method)] as usize];
        let rtol = self.values[self.index(SolverParam::Rtol)];
        let h_max = self.values[self.index(SolverParam::HMax)];
        let rk4_step = self.values[self.index(SolverParam::Rk4Step)];
        let (u, slope) = (self.values[0], self.slope);
        let s = self.sim.as_mut().ok_or("no circuit")?;
        let tol = 1e-9 * s.t.abs().max(1.0);
        if (t - s.t).abs() > tol {
            return Err(format!(
                "fmi2DoStep from t = {t} s but the FMU is at t = {} s",
                s.t
            ));
        }
        let t_end = t + h;
        s.input.set(t, u, slope);
        s.sim.set_options(RunOptions {
            solver: method,
            rtol,
            h_max,
            rk4_step: rk4_step.min(h),
            ..RunOptions::default()
        });
        let failure = match s.sim.step_to(t_end) {
            Ok(()) => {
                s.t = t_end;
                self.history.push([t, h, u, slope]);
                // the input value at the new communication point
                self.values[0] = u + slope * h;
                s.input.set(t_end, self.values[0], slope);
                return Ok(());
            }
            Err(e) => e,
        };
        let state: Vec<String> = s
            .sim
            .circuit()
            .state_names()
            .iter()
            .zip(s.sim.state())
            .map(|(n, v)| format!("{n} = {v:e}"))
            .collect();
        self.phase = Phase::Failed;
        // the solver's error says when it failed; the state is the one it
        // started the step from
        let when = failure
            .failed_at()
            .map(|tf| format!(" at t = {tf} s"))
            .unwrap_or_default();
        Err(format!(
            "step from t = {t} s to {t_end} s failed{when}: {failure}; state at the step's start (t = {t} s): {}",
            state.join(", ")
        ))
    }

    fn index(&self, sp: SolverParam) -> usize {
        self.vars
            .list
            .iter()
            .position(|v| v.role == Role::Solver(sp))
            .unwrap_or(0)
    }

    /// Marks the instance failed (after a caught panic).
    pub fn fail(&mut self) {
        self.phase = Phase::Failed;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hydrocyl_system::signal::Signal;

    /// The value reference of the variable `name`.
    pub(super) fn vr(s: &Slave, name: &str) -> u32 {
        s.variables()
            .list
            .iter()
            .position(|v| v.name == name)
            .unwrap() as u32
    }

    #[test]
    fn solver_failure_is_an_error_with_time_and_state() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        // an initial chamber pressure of 1e30 Pa is finite (the rig takes
        // it) but no step size meets the tolerance from there (a tolerance
        // below what double precision meets is refused up front)
        s.set_real(vr(&s, "cylinder.initial.p1"), 1e30).unwrap();
        s.enter_initialization().unwrap();
        s.exit_initialization().unwrap();
        s.set_real(vr(&s, "command"), 0.5).unwrap();
        let e = s.do_step(0.0, 1.0).unwrap_err();
        assert!(
            e.contains("solver dp45") && e.contains("state at the step's start (t = 0 s)"),
            "{e}"
        );
        // the time of the failure is the solver's, inside the step: the
        // same run outside the FMU fails there
        let mut v = rig::preset("leaney-moog").unwrap();
        rig::apply_set(&mut v, "cylinder.initial.p1=1e30").unwrap();
        let tf = Simulation::new(&v, Signal::Constant { value: 0.5 })
            .unwrap()
            .options(RunOptions {
                solver: METHODS[0], // the FMU's default, dp45
                ..RunOptions::default()
            })
            .try_run(&[0.0, 1.0])
            .unwrap_err()
            .failed_at()
            .unwrap();
        assert!(
            e.contains(&format!("failed at t = {tf} s")) && (0.0..1.0).contains(&tf),
            "{e}"
        );
        assert!(e.contains("load.") && e.contains("cylinder."), "{e}");
        assert_eq!(s.phase(), Phase::Failed);
        assert!(s.do_step(0.0, 1e-3).is_err());
        s.reset();
        assert_eq!(s.phase(), Phase::Instantiated);
    }

    /// A communication point that is not a number is refused up front; the
    /// instance goes on stepping.
    #[test]
    fn a_nan_communication_point_is_refused_and_the_instance_goes_on() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        s.enter_initialization().unwrap();
        s.exit_initialization().unwrap();
        for (t, h) in [(f64::NAN, 1e-3), (f64::INFINITY, 1e-3), (0.0, f64::NAN)] {
            let e = s.do_step(t, h).unwrap_err();
            assert!(e.contains("not finite"), "{e}");
            assert_eq!(s.phase(), Phase::Stepping);
        }
        s.do_step(0.0, 1e-3).unwrap();
        assert_eq!(s.time(), 1e-3);
    }
}
