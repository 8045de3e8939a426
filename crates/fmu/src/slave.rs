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
    circuit_with_input, nullable, output_channels, Role, SolverParam, Variables, METHODS,
};
use hydrocyl_system::external::ExternalInput;
use hydrocyl_system::netlist::{self, registry};
use hydrocyl_system::rig;
use hydrocyl_system::run::{RunOptions, Setting};
use hydrocyl_system::simulation::Simulation;
use hydrocyl_system::AnyWire;
use serde_json::Value;

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

/// A saved instance state (`fmi2FMUstate`): the rig and variable values, and
/// the communication steps taken since initialisation. Restoring it
/// re-assembles the circuit and replays those steps, so the component modes
/// (stick/slip, stops, valve states) come back with the continuous state,
/// bit for bit; it costs a re-run from the start time.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    rig: Value,
    values: Vec<f64>,
    slope: f64,
    t_start: f64,
    phase: Phase,
    assembled: bool,
    history: Vec<[f64; 4]>,
}

impl Snapshot {
    /// The state as bytes (JSON, every number as its IEEE-754 bits).
    pub fn serialize(&self) -> Vec<u8> {
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<u64>>();
        serde_json::json!({
            "rig": self.rig,
            "values": bits(&self.values),
            "slope": self.slope.to_bits(),
            "t_start": self.t_start.to_bits(),
            "phase": self.phase as u8,
            "assembled": self.assembled,
            "history": self.history.iter().map(|h| bits(h)).collect::<Vec<_>>(),
        })
        .to_string()
        .into_bytes()
    }

    /// A state from [`Snapshot::serialize`]'s bytes.
    pub fn deserialize(bytes: &[u8]) -> Result<Snapshot, SlaveError> {
        let bad = |what: &str| format!("serialized FMU state: {what}");
        let v: Value = serde_json::from_slice(bytes).map_err(|e| bad(&e.to_string()))?;
        let f = |x: &Value| {
            x.as_u64()
                .map(f64::from_bits)
                .ok_or_else(|| bad("a number"))
        };
        let list = |x: &Value| -> Result<Vec<f64>, SlaveError> {
            x.as_array()
                .ok_or_else(|| bad("a list"))?
                .iter()
                .map(f)
                .collect()
        };
        let phase = match v["phase"].as_u64() {
            Some(0) => Phase::Instantiated,
            Some(1) => Phase::Initializing,
            Some(2) => Phase::Stepping,
            Some(3) => Phase::Terminated,
            _ => return Err(bad("phase")),
        };
        let history = v["history"]
            .as_array()
            .ok_or_else(|| bad("history"))?
            .iter()
            .map(|h| list(h)?.try_into().map_err(|_| bad("a history entry")))
            .collect::<Result<Vec<[f64; 4]>, _>>()?;
        Ok(Snapshot {
            rig: v["rig"].clone(),
            values: list(&v["values"])?,
            slope: f(&v["slope"])?,
            t_start: f(&v["t_start"])?,
            phase,
            assembled: v["assembled"].as_bool().ok_or_else(|| bad("assembled"))?,
            history,
        })
    }
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

    /// `fmi2GetFMUstate`: the instance's state.
    pub fn get_state(&self) -> Result<Snapshot, SlaveError> {
        if self.phase == Phase::Failed {
            return Err("fmi2GetFMUstate after an error: reset the instance first".into());
        }
        Ok(Snapshot {
            rig: self.rig.clone(),
            values: self.values.clone(),
            slope: self.slope,
            t_start: self.t_start,
            phase: self.phase,
            assembled: self.sim.is_some(),
            history: self.history.clone(),
        })
    }

    /// `fmi2SetFMUstate`: back to a saved state (of an instance of the same
    /// FMU): the circuit is re-assembled and the saved steps replayed.
    pub fn set_state(&mut self, snap: &Snapshot) -> Result<(), SlaveError> {
        if snap.values.len() != self.values.len() {
            return Err("fmi2SetFMUstate: the state is of another FMU".into());
        }
        self.rig = snap.rig.clone();
        self.values = snap.values.clone();
        self.t_start = snap.t_start;
        self.sim = None;
        self.history.clear();
        if snap.assembled {
            self.ensure_sim()?;
            self.phase = Phase::Stepping;
            for &[t, h, u, slope] in &snap.history {
                self.values[0] = u;
                self.slope = slope;
                if let Err(e) = self.do_step(t, h) {
                    self.phase = Phase::Failed;
                    return Err(format!("fmi2SetFMUstate: replaying the saved steps: {e}"));
                }
            }
        }
        self.values = snap.values.clone();
        self.slope = snap.slope;
        if let Some(s) = &self.sim {
            s.input.set(s.t, self.values[0], self.slope);
        }
        self.phase = snap.phase;
        Ok(())
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
    /// initialisation mode, where they can be corrected.
    pub fn exit_initialization(&mut self) -> Result<(), SlaveError> {
        self.expect(&[Phase::Initializing], "fmi2ExitInitializationMode")?;
        self.ensure_sim()?;
        self.phase = Phase::Stepping;
        Ok(())
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

    /// `fmi2GetReal` of one variable.
    pub fn get_real(&mut self, vr: u32) -> Result<f64, SlaveError> {
        let v = self.var(vr)?;
        match v.role {
            Role::Output(i) => {
                if self.phase == Phase::Instantiated {
                    return Err(format!(
                        "output `{}` is not known before fmi2EnterInitializationMode",
                        v.name
                    ));
                }
                self.ensure_sim()?;
                let s = self.sim.as_ref().ok_or("no circuit")?;
                let mut out = [0.0];
                s.sim
                    .circuit()
                    .read_wires(s.t, s.sim.state(), &s.wires[i..i + 1], &mut out);
                Ok(out[0])
            }
            _ if v.integer => Err(format!("`{}` is an Integer", v.name)),
            _ => Ok(self.values[vr as usize]),
        }
    }

    /// `fmi2GetInteger` of one variable.
    pub fn get_integer(&self, vr: u32) -> Result<i32, SlaveError> {
        let v = self.var(vr)?;
        if !v.integer {
            return Err(format!("`{}` is not an Integer", v.name));
        }
        Ok(self.values[vr as usize] as i32)
    }

    /// `fmi2SetInteger` of one variable (`solver.method`).
    pub fn set_integer(&mut self, vr: u32, value: i32) -> Result<(), SlaveError> {
        let v = self.var(vr)?;
        if !v.integer {
            return Err(format!("`{}` is not an Integer", v.name));
        }
        self.set(vr, value as f64)
    }

    /// `fmi2SetReal` of one variable: the input at any time; a parameter
    /// before the end of initialisation. A parameter's value is checked on
    /// its own here (finite, inside the range its component declares; the
    /// message names the parameter and the rule it breaks); the rules that
    /// relate several parameters are checked once on the whole set, when the
    /// circuit is next assembled (`fmi2ExitInitializationMode`, or an output
    /// read in initialisation mode), so parameters can be set in any order.
    pub fn set_real(&mut self, vr: u32, value: f64) -> Result<(), SlaveError> {
        let v = self.var(vr)?;
        if v.integer {
            return Err(format!("`{}` is an Integer", v.name));
        }
        self.set(vr, value)
    }

    fn set(&mut self, vr: u32, value: f64) -> Result<(), SlaveError> {
        let v = self.var(vr)?.clone();
        let name = &v.name;
        match &v.role {
            Role::Output(_) => return Err(format!("`{name}` is an output: it cannot be set")),
            Role::Input => {
                if !value.is_finite() {
                    return Err(format!("input `{name}` = {value} is not finite"));
                }
                if self.phase == Phase::Failed || self.phase == Phase::Terminated {
                    return Err(format!("setting `{name}` in phase {:?}", self.phase));
                }
                self.values[vr as usize] = value;
                // a new value starts a step without slope until
                // fmi2SetRealInputDerivatives says otherwise
                self.slope = 0.0;
                if let Some(s) = &self.sim {
                    s.input.set(s.t, value, 0.0);
                }
                return Ok(());
            }
            Role::Solver(sp) => {
                self.expect(
                    &[Phase::Instantiated, Phase::Initializing],
                    &format!("setting fixed parameter `{name}`"),
                )?;
                let (ok, rule) = match sp {
                    SolverParam::Method => (
                        value >= 0.0 && value < METHODS.len() as f64 && value.fract() == 0.0,
                        format!(
                            "must be {}",
                            METHODS
                                .iter()
                                .enumerate()
                                .map(|(i, m)| format!("{i} ({})", m.name()))
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                    ),
                    SolverParam::Rtol => setting_rule(Setting::Rtol, value),
                    SolverParam::HMax => setting_rule(Setting::HMax, value),
                    SolverParam::Rk4Step => setting_rule(Setting::Rk4Step, value),
                };
                if !ok {
                    return Err(format!("parameter `{name}` = {value} rejected: {rule}"));
                }
            }
            Role::Parameter(path) => {
                self.expect(
                    &[Phase::Instantiated, Phase::Initializing],
                    &format!("setting fixed parameter `{name}`"),
                )?;
                // NaN: back to "computed by the rig" / "none", for every
                // parameter the rig may leave null
                let text = if value.is_nan() && (v.start.is_nan() || nullable(&self.rig, path)) {
                    "null".to_string()
                } else if value.is_finite() {
                    format!("{value:?}")
                } else {
                    return Err(format!(
                        "parameter `{name}` = {value} rejected: must be finite"
                    ));
                };
                let rejected =
                    |why: String| format!("parameter `{name}` = {value} rejected: {why}");
                if value.is_finite() {
                    own_rule(&self.rig, path, value).map_err(rejected)?;
                }
                let mut r = self.rig.clone();
                rig::apply_set(&mut r, &format!("{path}={text}"))
                    .map_err(|e| rejected(e.to_string()))?;
                self.rig = r;
            }
        }
        self.values[vr as usize] = value;
        self.sim = None;
        Ok(())
    }

    /// `fmi2SetRealInputDerivatives` of order 1: the input's slope over the
    /// next step (the input is linear inside it).
    pub fn set_input_derivative(
        &mut self,
        vr: u32,
        order: i32,
        value: f64,
    ) -> Result<(), SlaveError> {
        let v = self.var(vr)?;
        if v.role != Role::Input {
            return Err(format!("`{}` is not an input", v.name));
        }
        if order != 1 {
            return Err(format!(
                "input derivative of order {order} for `{}`: only order 1 is supported",
                v.name
            ));
        }
        if !value.is_finite() {
            return Err(format!("input derivative of `{}` = {value}", v.name));
        }
        self.slope = value;
        if let Some(s) = &self.sim {
            s.input.set(s.t, self.values[0], value);
        }
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

/// Whether a solver parameter's `value` meets `setting`'s rule, and the rule.
fn setting_rule(setting: Setting, value: f64) -> (bool, String) {
    (setting.holds(value), setting.rule().into())
}

/// The rules a rig parameter's value must meet on its own, whatever the
/// other parameters are: for a netlist, the range its component type
/// declares ([`registry::ParamSpec::range`]) or an initial state's own rule
/// ([`registry::StateSpec::check`]). The rules relating several parameters
/// (a chamber longer than half the stroke, ...) are [`rig::check`]'s.
fn own_rule(rig: &Value, path: &str, value: f64) -> Result<(), String> {
    if rig.get("kind").and_then(Value::as_str) != Some(netlist::KIND) {
        return Ok(());
    }
    let Some((component, name)) = path.split_once('.') else {
        return Ok(());
    };
    let Some(ty) = rig
        .pointer(&format!("/components/{component}/type"))
        .and_then(Value::as_str)
        .and_then(registry::lookup)
    else {
        return Ok(());
    };
    match name.strip_prefix("initial.") {
        Some(state) => ty.state(state).map_or(Ok(()), |s| s.check(value)),
        None => ty.param(name).map_or(Ok(()), |p| p.check(value)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hydrocyl_system::signal::Signal;

    fn vr(s: &Slave, name: &str) -> u32 {
        s.variables()
            .list
            .iter()
            .position(|v| v.name == name)
            .unwrap() as u32
    }

    #[test]
    fn solver_failure_is_an_error_with_time_and_state() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        // a tolerance no step can meet: the step size falls below its minimum
        s.set_real(vr(&s, "solver.rtol"), 1e-300).unwrap();
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
        let rtol = RunOptions {
            rtol: 1e-300,
            ..RunOptions::default()
        };
        let tf = Simulation::new(
            &rig::preset("leaney-moog").unwrap(),
            Signal::Constant { value: 0.5 },
        )
        .unwrap()
        .options(rtol)
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

    /// A state saved in mid-run, restored (directly and through its bytes),
    /// continues exactly as the uninterrupted run.
    #[test]
    fn a_restored_state_continues_the_run_bit_for_bit() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        let (cmd, pos) = (vr(&s, "command"), vr(&s, "position"));
        s.enter_initialization().unwrap();
        s.exit_initialization().unwrap();
        let go = |s: &mut Slave, from: usize, n: usize| -> Vec<f64> {
            (from..from + n)
                .map(|k| {
                    s.set_real(cmd, if k % 80 < 40 { 0.4 } else { -0.4 })
                        .unwrap();
                    s.do_step(k as f64 * 1e-3, 1e-3).unwrap();
                    s.get_real(pos).unwrap()
                })
                .collect()
        };
        go(&mut s, 0, 100);
        let snap = s.get_state().unwrap();
        let first = go(&mut s, 100, 150);
        s.set_state(&snap).unwrap();
        assert_eq!(go(&mut s, 100, 150), first);
        let back = Snapshot::deserialize(&snap.serialize()).unwrap();
        assert_eq!(back.serialize(), snap.serialize()); // NaN-safe equality
        let mut other = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        other.set_state(&back).unwrap();
        assert_eq!(other.time(), 0.1);
        assert_eq!(go(&mut other, 100, 150), first);
        assert!(Snapshot::deserialize(b"{}").is_err());
    }

    /// Lengthening the stroke past twice the chamber lengths, then the
    /// chambers: the stroke alone breaks the rig's rule relating it to the
    /// chambers, the whole set does not. The set is checked as a whole at
    /// initialisation, which names the parameters set when it is invalid.
    #[test]
    fn related_parameters_can_be_set_in_any_order() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        let start = |s: &Slave, name: &str| s.variables().list[vr(s, name) as usize].start;
        let stroke = 2.0
            * start(&s, "cylinder.chamber_length_1").max(start(&s, "cylinder.chamber_length_2"))
            + start(&s, "cylinder.stroke");
        s.set_real(vr(&s, "cylinder.stroke"), stroke).unwrap();
        s.enter_initialization().unwrap();
        // the stroke alone breaks the chambers' rule: refused at exit, named
        let e = s.exit_initialization().unwrap_err();
        assert!(
            e.contains(&format!("cylinder.stroke = {stroke}"))
                && e.contains("chamber_length_1 must exceed half the stroke"),
            "{e}"
        );
        assert_eq!(s.phase(), Phase::Initializing);
        let e = s.get_real(vr(&s, "position")).unwrap_err();
        assert!(e.contains("cylinder.stroke"), "{e}");
        // the chambers follow: the whole set is valid
        for c in ["cylinder.chamber_length_1", "cylinder.chamber_length_2"] {
            s.set_real(vr(&s, c), 0.6 * stroke).unwrap();
        }
        s.exit_initialization().unwrap();
        s.set_real(vr(&s, "command"), 0.2).unwrap();
        s.do_step(0.0, 1e-2).unwrap();
        assert!(s.get_real(vr(&s, "position")).unwrap() > 0.0);
    }

    /// A value wrong on its own is still refused at once, naming the rule.
    #[test]
    fn a_value_out_of_its_own_range_is_refused_when_set() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        let e = s.set_real(vr(&s, "cylinder.stroke"), -0.1).unwrap_err();
        assert!(
            e.contains("cylinder.stroke") && e.contains("-0.1 [m] is out of range: must be > 0"),
            "{e}"
        );
        let e = s.set_real(vr(&s, "cylinder.stroke"), f64::NAN).unwrap_err();
        assert!(e.contains("must be finite"), "{e}");
        let e = s.set_real(vr(&s, "cylinder.initial.p1"), -2e5).unwrap_err();
        assert!(e.contains("below absolute vacuum"), "{e}");
        assert_eq!(s.rig(), &rig::preset("leaney-moog").unwrap());
        // solver parameters: the message is the rule, not the description
        for (name, bad, rule) in [
            ("solver.rtol", 0.0, "must be in (0, 1)"),
            ("solver.h_max", -1.0, "must be > 0 [s]"),
            (
                "solver.rk4_step",
                f64::INFINITY,
                "must be finite and > 0 [s]",
            ),
        ] {
            let e = s.set_real(vr(&s, name), bad).unwrap_err();
            assert!(e.contains(rule) && !e.contains("tolerance of"), "{e}");
        }
        let e = s.set_integer(vr(&s, "solver.method"), 7).unwrap_err();
        assert!(
            e.contains("must be 0 (dp45), 1 (rosenbrock), 2 (rk4)"),
            "{e}"
        );
        s.enter_initialization().unwrap();
        s.exit_initialization().unwrap();
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

    /// Every parameter the rig may leave null (an initial pressure computed
    /// from the steady state, an absent end stop) takes NaN as "back to
    /// computed/none", whatever its start value; the others refuse NaN.
    #[test]
    fn nan_is_computed_for_every_nullable_parameter() {
        let mut n_null = 0;
        for preset in ["leaney-moog", "wang-hybrid", "tudelft-seal-25"] {
            let r = rig::preset(preset).unwrap();
            let mut s = Slave::new(r.clone()).unwrap();
            for (i, v) in s.variables().list.clone().iter().enumerate() {
                let Role::Parameter(path) = &v.role else {
                    continue;
                };
                let result = s.set_real(i as u32, f64::NAN);
                if nullable(&r, path) {
                    n_null += 1;
                    assert!(result.is_ok(), "{preset} {path}: {result:?}");
                    assert!(s.get_real(i as u32).unwrap().is_nan());
                } else {
                    let e = result.unwrap_err();
                    assert!(e.contains(path) && e.contains("must be finite"), "{e}");
                }
            }
            // all back to the rig's own choice: a rig that cannot compute
            // one of them (no steady state to start from) says which
            s.enter_initialization().unwrap();
            if let Err(e) = s.exit_initialization() {
                assert!(e.contains("= NaN") && e.contains("give it"), "{e}");
            }
        }
        assert!(n_null > 4, "{n_null}");
        // an initial pressure set, then set back: the computed one again
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        let p1 = vr(&s, "cylinder.initial.p1");
        s.enter_initialization().unwrap();
        let computed = s.get_real(vr(&s, "p1")).unwrap();
        s.set_real(p1, computed + 1e6).unwrap();
        assert_eq!(s.get_real(vr(&s, "p1")).unwrap(), computed + 1e6);
        s.set_real(p1, f64::NAN).unwrap();
        assert_eq!(s.get_real(vr(&s, "p1")).unwrap(), computed);
    }

    #[test]
    fn parameters_are_checked_by_the_rig_and_outputs_follow_them() {
        let mut s = Slave::new(rig::preset("leaney-moog").unwrap()).unwrap();
        let e = s.set_real(vr(&s, "cylinder.area_1"), 0.0).unwrap_err();
        assert!(e.contains("cylinder.area_1"), "{e}");
        // an initial state is a parameter; the output at the start follows it
        s.set_real(vr(&s, "cylinder.initial.p1"), 2e6).unwrap();
        s.enter_initialization().unwrap();
        assert_eq!(s.get_real(vr(&s, "p1")).unwrap(), 2e6);
        s.set_real(vr(&s, "cylinder.initial.p1"), 3e6).unwrap();
        assert_eq!(s.get_real(vr(&s, "p1")).unwrap(), 3e6);
        assert!(s.set_real(vr(&s, "load.mass"), f64::NAN).is_err());
    }
}
