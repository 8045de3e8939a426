//! The one run path: a rig (or an assembled circuit) + its command + solver
//! options → a [`Run`] (channels, statistics, diagnostics and, when asked,
//! the energy ledger's quadratures).
//!
//! Every caller that simulates a rig or a circuit goes through
//! [`Simulation`]: [`rig::simulate`] (and so the typed rigs' `simulate`),
//! `hydrocyl simulate`, `diagnose` and identification, the energy matrix and
//! the studies (chapter 3, 7, 8 and 9), the Python package, xtask and the
//! benches. A rig value is read, checked and assembled once, in
//! [`Simulation::new`] (a circuit assembled by hand enters by
//! [`Simulation::of_circuit`]); then one of its run methods integrates it
//! from its initial state, each delegating to the crate's run machinery
//! ([`crate::run`], whose integrating functions are private to this crate):
//!
//! - [`Simulation::run`]: every output time kept, a failure mapped to one
//!   [`RigError`]; [`Simulation::try_run`] the same with the run's own
//!   [`SimError`] (a solver failure's time, for a caller that locates it);
//! - [`Simulation::run_streaming`]: the channels handed to a sink in blocks
//!   (one solve, bit for bit [`Simulation::run`]'s outputs);
//! - [`Simulation::run_streaming_states`]: the raw states handed to a
//!   [`StateSink`] in blocks, the probes read by the sink (the CLI's writer
//!   thread, a [`crate::run::ProbeReader`]);
//! - [`Simulation::run_command_stream`]: the command read from a
//!   [`CommandSource`] into a [`StreamedTable`] while the run goes (a
//!   command file too long to hold);
//! - [`Simulation::run_wires`] and [`Simulation::sample_state_free`]: chosen
//!   wires only (a fit's residuals).
//!
//! A co-simulation slave (the FMU) steps the same simulation between
//! communication points instead: [`Simulation::start`], then
//! [`Simulation::step_to`] as often as the host asks, reading
//! [`Simulation::time`] and [`Simulation::state`] in between.
//!
//! ```
//! use hydrocyl_system::{rig, signal::Signal, simulation::Simulation, run::RunOptions};
//!
//! let rig = rig::load("leaney-moog").unwrap();
//! let t: Vec<f64> = (0..=50).map(|k| k as f64 * 0.01).collect();
//! let run = Simulation::new(&rig, Signal::Constant { value: 0.1 })
//!     .unwrap()
//!     .options(RunOptions::default())
//!     .run(&t)
//!     .unwrap();
//! assert!(run.channel("velocity").unwrap()[50] > 0.0); // a positive command extends
//! ```

use crate::circuit::Circuit;
use crate::rig::{self, CommandLimit, RigError};
use crate::run::{self as runner, CommandSource, Run, RunOptions, SimError, StateSink};
use crate::signal::{Signal, StreamedTable};
use crate::wires::AnyWire;
use hydrocyl_integrators::{solve, OdeSystem};
use serde_json::Value;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// One simulation: an assembled circuit, its initial state and the solver
/// options. Build it from a rig value ([`Simulation::new`]) or from a circuit
/// assembled by hand ([`Simulation::of_circuit`]); run it with
/// [`Simulation::run`] (as many times as wanted: each run starts from the
/// initial state).
pub struct Simulation {
    circuit: Circuit,
    initial: Vec<f64>,
    options: RunOptions,
    /// The time reached and the state there, while stepping.
    now: Option<(f64, Vec<f64>)>,
    /// Set from outside to stop [`Simulation::run`] and
    /// [`Simulation::try_run`] ([`Simulation::stop_on`]).
    stop: Option<Arc<AtomicBool>>,
    /// The limit of the rig's command, from the netlist read in
    /// [`Simulation::new`] ([`Simulation::command_limit`]).
    command_limit: Option<CommandLimit>,
    /// The warnings of the rig's parameters far outside what real rigs
    /// have, from the same reading ([`Simulation::implausible`]).
    implausible: Vec<String>,
}

impl Simulation {
    /// Reads, checks and assembles `rig` (a preset's or file's JSON value of
    /// any rig kind, after any `--set`) driven by `command`. Errors name the
    /// JSON path. The rig's netlist is read once: the circuit and the
    /// limit its command is checked against ([`Simulation::command_limit`])
    /// both come from that reading.
    pub fn new(rig: &Value, command: Signal) -> Result<Self, RigError> {
        let (circuit, limit, implausible) = rig::assembled(rig, command)?;
        let mut s = Self::of_circuit(circuit);
        s.command_limit = limit;
        s.implausible = implausible;
        Ok(s)
    }

    /// A simulation of an assembled circuit, from the circuit's own initial
    /// state ([`Circuit::initial_state`]) with the default options.
    pub fn of_circuit(circuit: Circuit) -> Self {
        let initial = circuit.initial_state();
        Simulation {
            circuit,
            initial,
            options: RunOptions::default(),
            now: None,
            stop: None,
            command_limit: None,
            implausible: Vec::new(),
        }
    }

    /// Sets the solver options.
    pub fn options(mut self, options: RunOptions) -> Self {
        self.options = options;
        self
    }

    /// Lets another thread stop [`Simulation::run`] and
    /// [`Simulation::try_run`]: once `flag` is set, the run ends at its next
    /// step with [`SimError::Solve`] holding
    /// [`hydrocyl_integrators::SolveError::Interrupted`] (an interactive
    /// interrupt of a long run: the Python package's KeyboardInterrupt).
    /// The flag is read once a step; until it is set the run is the same, bit
    /// for bit.
    pub fn stop_on(mut self, flag: Arc<AtomicBool>) -> Self {
        self.stop = Some(flag);
        self
    }

    /// Starts from `x0` instead of the circuit's initial state (one value per
    /// state, in [`Circuit::state_names`] order; checked by [`Simulation::run`]).
    pub fn initial_state(mut self, x0: Vec<f64>) -> Self {
        self.initial = x0;
        self
    }

    /// What the command is checked against before a run, as `hydrocyl
    /// simulate` and the Python package check it (warned of, not refused):
    /// the spool's stroke (±1) of a normalised spool demand, the rating of
    /// a pump driven in volts, `None` for a position, a velocity or a
    /// set-point, or a pump with no rating ([`CommandLimit::of`]). It is
    /// the rig's as given to [`Simulation::new`], `--set`s and all, read
    /// with its netlist (not once more); a simulation of a circuit
    /// assembled by hand ([`Simulation::of_circuit`]) has none.
    pub fn command_limit(&self) -> Option<&CommandLimit> {
        self.command_limit.as_ref()
    }

    /// The warnings of the rig's parameters that lie far outside what real
    /// rigs have (a unit slip, which runs: [`crate::netlist::implausible`]),
    /// as `hydrocyl simulate` warns of them; from the netlist read by
    /// [`Simulation::new`] (not once more); none for a simulation of a
    /// circuit assembled by hand.
    pub fn implausible(&self) -> &[String] {
        &self.implausible
    }

    /// The assembled circuit (its components, probes, state names; the energy
    /// ledger's power terms after a run).
    pub fn circuit(&self) -> &Circuit {
        &self.circuit
    }

    /// The assembled circuit, mutable (e.g. to step it by hand).
    pub fn circuit_mut(&mut self) -> &mut Circuit {
        &mut self.circuit
    }

    /// Changes the solver options between steps or runs.
    pub fn set_options(&mut self, options: RunOptions) {
        self.options = options;
    }

    /// The solver options the runs use.
    pub fn run_options(&self) -> &RunOptions {
        &self.options
    }

    /// Integrates from the initial state at `t_eval[0]` to the last of
    /// `t_eval`, sampling every `t_eval` time (sorted, strictly increasing,
    /// at least two). A solver failure is [`RigError::Sim`] with the method,
    /// time and reason; bad settings name the setting.
    pub fn run(&mut self, t_eval: &[f64]) -> Result<Run, RigError> {
        self.try_run(t_eval).map_err(rig_error)
    }

    /// [`Simulation::run`] with the run's own error, not mapped to a
    /// [`RigError`]: a solver failure stays [`SimError::Solve`], whose
    /// [`hydrocyl_integrators::SolveError`] holds the time it failed at (what
    /// a caller that locates the failure reads).
    pub fn try_run(&mut self, t_eval: &[f64]) -> Result<Run, SimError> {
        match &self.stop {
            None => runner::run(&mut self.circuit, &self.initial, t_eval, &self.options),
            Some(flag) => runner::run_until(
                &mut self.circuit,
                &self.initial,
                t_eval,
                &self.options,
                Some(&|| flag.load(Ordering::Relaxed)),
            ),
        }
    }

    /// [`Simulation::run`] for long records: the outputs go to `sink` in
    /// blocks of about `block` output times (a block ends at a step's end,
    /// so it may hold a few more) as soon as each is computed, so the memory
    /// grows with the block, not the record. It is one solve: the
    /// integrator's step size, controller and stages carry over from block
    /// to block, and the outputs are [`Simulation::run`]'s, bit for bit. An
    /// `Err` from the sink stops the run (its message in the error).
    /// Returns the totals: the stats, the diagnostics at the end, the wall
    /// time of the solve (the sink's excluded); its `time`, `channels` and
    /// `states` are empty.
    pub fn run_streaming(
        &mut self,
        t_eval: &[f64],
        block: usize,
        sink: &mut dyn FnMut(&Run) -> Result<(), String>,
    ) -> Result<Run, RigError> {
        runner::run_streaming(
            &mut self.circuit,
            &self.initial,
            t_eval,
            &self.options,
            block,
            sink,
        )
        .map_err(rig_error)
    }

    /// [`Simulation::run_streaming`] without the channels: `sink` receives
    /// each block's output times and full states (row-major,
    /// `x.len() / t.len()` each) as the integrator wrote them, and reads the
    /// probes itself where it likes, e.g. a [`crate::run::ProbeReader`] on
    /// another thread (the solve's thread then only solves). The buffers
    /// are the solve's, reused block after block: copy what is kept.
    pub fn run_streaming_states(
        &mut self,
        t_eval: &[f64],
        block: usize,
        sink: &mut StateSink<'_>,
    ) -> Result<Run, RigError> {
        runner::run_streaming_states(
            &mut self.circuit,
            &self.initial,
            t_eval,
            &self.options,
            block,
            sink,
        )
        .map_err(rig_error)
    }

    /// [`Simulation::run_streaming`] on a command record too long to hold:
    /// the circuit reads its command from `table` (the simulation built with
    /// [`Signal::Streamed`] of a clone of it), which is filled from `source`
    /// ahead of the integration and emptied behind it; the output times are
    /// the record's sample times, from the first (the initial state's time)
    /// to `t_end`, the last. Memory grows with `block` and the window, not
    /// the record; the outputs are those of [`Simulation::run`] on the whole
    /// record as a [`Signal::Table`].
    pub fn run_command_stream(
        &mut self,
        table: &StreamedTable,
        source: &mut dyn CommandSource,
        t_end: f64,
        block: usize,
        sink: &mut dyn FnMut(&Run) -> Result<(), String>,
    ) -> Result<Run, RigError> {
        runner::run_command_stream(
            &mut self.circuit,
            &self.initial,
            table,
            source,
            t_end,
            &self.options,
            block,
            sink,
        )
        .map_err(rig_error)
    }

    /// The initial state of the runs ([`Circuit::state_names`] order).
    pub fn initial(&self) -> &[f64] {
        &self.initial
    }

    /// Sets parameter `path` (`<component>.<parameter>`) of the assembled
    /// circuit to `value` (SI) for the next runs, without assembling or
    /// checking the netlist again ([`Circuit::set_parameter`]): what a fit
    /// that runs one circuit many times does. A parameter the component
    /// cannot change in place is an error naming the path.
    pub fn set_parameter(&mut self, path: &str, value: f64) -> Result<(), RigError> {
        self.circuit
            .set_parameter(path, value)
            .map_err(|why| RigError::Invalid {
                path: path.to_string(),
                why,
            })
    }

    /// Replaces the initial state of the next runs (as
    /// [`Simulation::initial_state`], on a simulation kept between runs).
    pub fn set_initial_state(&mut self, x0: Vec<f64>) {
        self.initial = x0;
    }

    /// Runs as [`Simulation::run`] but reads only `wires` (e.g. one probe's,
    /// [`Circuit::find_wire`]) at every output time, from the states the
    /// solver reached there: `out[k][i]` is wire `k` at `t_eval[i]`. For a
    /// circuit without events (whose components have no modes that a later
    /// time could have switched); one with events is an error.
    pub fn run_wires(
        &mut self,
        t_eval: &[f64],
        wires: &[AnyWire],
    ) -> Result<Vec<Vec<f64>>, RigError> {
        if self.circuit.n_events() > 0 {
            return Err(RigError::Sim(
                "run_wires: the circuit has events; read its probes from Simulation::run".into(),
            ));
        }
        let channels = std::mem::replace(&mut self.options.channels, false);
        let run = self.run(t_eval);
        self.options.channels = channels;
        let run = run?;
        let mut out = vec![Vec::with_capacity(t_eval.len()); wires.len()];
        let mut row = vec![0.0; wires.len()];
        for (i, &t) in run.time.iter().enumerate() {
            self.circuit.read_wires(t, run.state(i), wires, &mut row);
            for (o, v) in out.iter_mut().zip(&row) {
                o.push(*v);
            }
        }
        Ok(out)
    }

    /// Reads `wires` at every time of `t_eval` with the state held at the
    /// initial state, integrating nothing: for outputs that no state reaches,
    /// e.g. the load cell of a bench whose drive imposes the motion and whose
    /// friction law is static (the only state, the drive's position, feeds no
    /// force), which are then algebraic in the inputs. Checked at the first
    /// time: moving each state by its scale must leave every wire unchanged,
    /// else an error (integrate with [`Simulation::run_wires`]).
    pub fn sample_state_free(
        &mut self,
        t_eval: &[f64],
        wires: &[AnyWire],
    ) -> Result<Vec<Vec<f64>>, RigError> {
        let Some(&t0) = t_eval.first() else {
            return Ok(vec![Vec::new(); wires.len()]);
        };
        let n = self.circuit.n_states();
        if self.initial.len() != n || self.circuit.n_events() > 0 {
            return Err(RigError::Sim(format!(
                "sample_state_free: {} initial values for {n} states{}",
                self.initial.len(),
                if self.circuit.n_events() > 0 {
                    ", and the circuit has events"
                } else {
                    ""
                }
            )));
        }
        let x0 = self.initial.clone();
        self.circuit.reset(t0, &x0);
        let mut at0 = vec![0.0; wires.len()];
        self.circuit.read_wires(t0, &x0, wires, &mut at0);
        let scales = self.circuit.atol(1.0);
        let mut moved = vec![0.0; wires.len()];
        for k in 0..n {
            let mut x = x0.clone();
            x[k] += scales[k].max(1e-6);
            self.circuit.read_wires(t0, &x, wires, &mut moved);
            if let Some(j) = (0..wires.len()).find(|&j| moved[j].to_bits() != at0[j].to_bits()) {
                return Err(RigError::Sim(format!(
                    "sample_state_free: `{}` depends on the state `{}`",
                    self.circuit.wire_name(wires[j]),
                    self.circuit.state_names()[k]
                )));
            }
        }
        let mut out = vec![Vec::with_capacity(t_eval.len()); wires.len()];
        let mut row = vec![0.0; wires.len()];
        for &t in t_eval {
            self.circuit.read_wires(t, &x0, wires, &mut row);
            for (o, v) in out.iter_mut().zip(&row) {
                o.push(*v);
            }
        }
        Ok(out)
    }

    /// Starts stepping at `t0` from the initial state (the circuit reset
    /// there; the options' quadratures and ledger switches applied). Checks
    /// the initial state as [`Simulation::run`] does.
    pub fn start(&mut self, t0: f64) -> Result<(), RigError> {
        let n = self.circuit.n_states();
        let bad = |why: String| RigError::Sim(SimError::Settings(why).to_string());
        if self.initial.len() != n {
            return Err(bad(format!(
                "initial state has {} entries, the circuit {n}",
                self.initial.len()
            )));
        }
        if !t0.is_finite() {
            return Err(bad(format!("start time {t0} is not finite")));
        }
        if let Some(i) = self.initial.iter().position(|v| !v.is_finite()) {
            return Err(bad(format!(
                "initial state {} is not finite",
                self.circuit.state_names()[i]
            )));
        }
        self.circuit.set_quadratures(self.options.quadratures);
        self.circuit.set_ledger(self.options.ledger);
        let mut x = vec![0.0; self.circuit.dim()];
        x[..n].copy_from_slice(&self.initial);
        self.circuit.reset(t0, &x);
        self.now = Some((t0, x));
        Ok(())
    }

    /// Integrates from the time reached to `t_end` (after [`Simulation::start`]).
    /// The circuit is not reset, so its components' modes (stick/slip,
    /// stops, valve states) carry over; the integrator restarts, so no step
    /// straddles the time reached. On failure the time and state stay where
    /// they were: the [`SimError`] says why (the solver's error,
    /// [`SimError::Solve`], or the circuit stopping the run early,
    /// [`SimError::Stopped`]) and when ([`SimError::failed_at`]); stepping
    /// before the start or not forward is [`SimError::Settings`].
    pub fn step_to(&mut self, t_end: f64) -> Result<(), SimError> {
        let (t, x) = self
            .now
            .as_ref()
            .ok_or_else(|| SimError::Settings("not started (Simulation::start)".into()))?;
        let t = *t;
        if !(t_end > t && t_end.is_finite()) {
            return Err(SimError::Settings(format!(
                "step to t = {t_end} s from t = {t} s"
            )));
        }
        let opts = self.options.solver_options(&self.circuit, vec![t, t_end]);
        let method = self.options.solver;
        // the host may have set the inputs anew since the last step ended
        self.circuit.forget_evaluation();
        let sol = solve(method.method(), &mut self.circuit, t, x, t_end, &opts)
            .map_err(|source| SimError::solve(method.name(), source, &self.circuit, t, x))?;
        match (sol.t.last(), sol.last()) {
            (Some(&te), Some(last)) if te == t_end => {
                self.now = Some((t_end, last.to_vec()));
                Ok(())
            }
            (reached, _) => Err(SimError::Stopped {
                t: reached.copied().unwrap_or(t),
            }),
        }
    }

    /// The time reached by stepping (`None` before [`Simulation::start`]).
    pub fn time(&self) -> Option<f64> {
        self.now.as_ref().map(|(t, _)| *t)
    }

    /// The state at the time reached, [`Circuit::state_names`] order, then
    /// any quadratures (empty before [`Simulation::start`]).
    pub fn state(&self) -> &[f64] {
        self.now.as_ref().map_or(&[], |(_, x)| x.as_slice())
    }

    /// The circuit, consumed (for callers that keep it after the runs).
    pub fn into_circuit(self) -> Circuit {
        self.circuit
    }
}

/// A run's error as a rig's: an assembly error as such, any other (the
/// solver's, bad settings, a sink's) as [`RigError::Sim`] with its message.
fn rig_error(e: SimError) -> RigError {
    match e {
        SimError::Build(b) => RigError::from(b),
        other => RigError::Sim(other.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig;

    /// Stepping through communication points ends where one run ends, to
    /// the tolerance (the integrator restarts at each point).
    #[test]
    fn steps_end_where_a_run_ends() {
        let rig = rig::load("leaney-moog").unwrap();
        let cmd = || Signal::Constant { value: 0.2 };
        let mut opts = RunOptions::dp45();
        opts.rtol = 1e-9;
        let t: Vec<f64> = (0..=40).map(|k| k as f64 * 5e-3).collect();
        let run = Simulation::new(&rig, cmd())
            .unwrap()
            .options(opts.clone())
            .run(&t)
            .unwrap();
        let mut sim = Simulation::new(&rig, cmd()).unwrap().options(opts);
        assert!(sim.step_to(0.1).is_err(), "stepping needs a start");
        sim.start(0.0).unwrap();
        for &tk in &t[1..] {
            sim.step_to(tk).unwrap();
        }
        assert_eq!(sim.time(), Some(0.2));
        let n = sim.circuit().n_states();
        let end = run.state(40);
        for (i, (a, b)) in sim.state()[..n].iter().zip(end).enumerate() {
            let scale = a.abs().max(b.abs()).max(1e-9);
            assert!((a - b).abs() < 1e-6 * scale, "state {i}: {a} vs {b}");
        }
        assert!(sim.step_to(0.1).is_err(), "no step backwards");
    }

    /// The streamed entry points give [`Simulation::run`]'s outputs bit for
    /// bit (states and channels, in blocks), and [`Simulation::try_run`]
    /// keeps the solver's error where [`Simulation::run`] maps it.
    #[test]
    fn the_streamed_runs_are_the_run() {
        let rig = rig::load("leaney-moog").unwrap();
        let t: Vec<f64> = (0..=300).map(|k| k as f64 * 1e-3).collect();
        let u: Vec<f64> = t
            .iter()
            .map(|&t| if t < 0.15 { 0.2 } else { -0.2 })
            .collect();
        let cmd = Signal::table(t.clone(), u).unwrap();
        let mut sim = Simulation::new(&rig, cmd).unwrap();
        let whole = sim.run(&t).unwrap();
        let (mut times, mut states) = (Vec::new(), Vec::new());
        let total = sim
            .run_streaming_states(&t, 64, &mut |tb, xb| {
                times.extend_from_slice(tb);
                states.extend_from_slice(xb);
                Ok(())
            })
            .unwrap();
        assert_eq!(times, whole.time);
        assert_eq!(states, whole.states);
        assert_eq!(total.stats, whole.stats);
        let mut velocity = Vec::new();
        sim.run_streaming(&t, 64, &mut |b| {
            velocity.extend_from_slice(b.channel("velocity").unwrap());
            Ok(())
        })
        .unwrap();
        assert_eq!(velocity, whole.channel("velocity").unwrap());
        let e = sim.run_streaming(&t, 64, &mut |_| Err("sink full".into()));
        assert!(e.unwrap_err().to_string().contains("sink full"));
        let mut opts = RunOptions::dp45();
        opts.max_steps = 5;
        sim.set_options(opts);
        assert!(matches!(sim.try_run(&t), Err(SimError::Solve { .. })));
    }

    /// The step budget is the options': a run that needs more steps fails.
    #[test]
    fn the_step_budget_is_kept() {
        let rig = rig::load("leaney-moog").unwrap();
        let mut opts = RunOptions::dp45();
        opts.max_steps = 5;
        let e = Simulation::new(&rig, Signal::Constant { value: 0.2 })
            .unwrap()
            .options(opts)
            .run(&[0.0, 0.5])
            .unwrap_err();
        assert!(e.to_string().contains("steps"), "{e}");
    }
}
