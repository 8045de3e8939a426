//! The machinery under [`Simulation`](crate::simulation::Simulation):
//! running an assembled circuit, with the solver chosen ([`Solver`],
//! [`RunOptions`]), the outputs sampled at given times, the probes turned
//! into named channels ([`ProbeSet`], or [`ProbeReader`] on a circuit of its
//! own), cavitation and stop reports ([`Run`]).
//!
//! The functions that integrate are this crate's own: `run` (one solve,
//! every output kept), `run_streaming` (the outputs' channels handed to a
//! sink in blocks), `run_streaming_states` (the raw states handed to a
//! [`StateSink`]) and `run_command_stream` (the command read from a
//! [`CommandSource`] while the run goes), the last three one streamed solve
//! ([`hydrocyl_integrators::solve_streaming`]). Outside this crate a circuit
//! is run only through [`Simulation`](crate::simulation::Simulation), whose
//! methods of the same names delegate to them; what is public here is what
//! those methods take and give: the options, the run and its channels, the
//! errors, the sink and source types, the probe readers, and [`nrmse`].

use crate::circuit::{BuildError, Circuit};
use crate::signal::StreamedTable;
use hydrocyl_integrators::{
    solve, solve_stoppable, solve_streaming, OdeSystem as _, Options, SolveError, Stats, Stream,
    StreamIo,
};
use std::time::{Duration, Instant};
use thiserror::Error;

mod physical;
mod probes;
mod settings;
pub use physical::{
    chamber_of, chamber_types_with_air, AirRemedy, Cause, DeepCavitation, SettingWords, Tension,
    Unphysical, ABSURD_PRESSURE_PA, AIR_PARAMETER, LIQUID_TENSION_LIMIT_PA,
};
pub use probes::{ProbeReader, ProbeSet};
pub use settings::{Setting, Solver, RTOL_FLOOR};

/// Why a run failed.
#[derive(Debug, Error)]
pub enum SimError {
    /// The circuit could not be assembled.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The integrator failed (tolerance not met, non-finite state, ...).
    #[error("solver {method}: {source}{state}")]
    Solve {
        /// The method used.
        method: &'static str,
        /// The solver's error.
        source: SolveError,
        /// The state it is about, by name ([`SimError::solve`]): `
        /// (state 1 is `valve.spool`)`, or at the start the fastest state;
        /// empty when the error names no state.
        state: String,
    },
    /// Bad run settings.
    #[error("run settings: {0}")]
    Settings(String),
    /// The circuit ended a step early
    /// ([`crate::simulation::Simulation::step_to`]): an event stopped it.
    #[error("the rig stopped the run at t = {t} s")]
    Stopped {
        /// The time the run stopped at \[s\].
        t: f64,
    },
}

impl SimError {
    /// The time the run failed at: the solver's ([`SolveError::time`]) or
    /// the one the circuit stopped it at; `None` for a failure before any
    /// step (assembly, settings, an invalid solver input).
    pub fn failed_at(&self) -> Option<f64> {
        match self {
            SimError::Solve { source, .. } => source.time(),
            SimError::Stopped { t } => Some(*t),
            SimError::Build(_) | SimError::Settings(_) => None,
        }
    }

    /// A solver failure of `circuit` started at `(t0, x0)`, with the state
    /// it is about named ([`Circuit::state_label`]; a step that fell below
    /// the minimum names the states that dominate its error itself,
    /// [`SolveError::StepTooSmall`]): a non-finite state by its name, a failure at the
    /// start (a step that fell to nothing, a non-finite value at `t0`) by
    /// the state whose rate, relative to its scale, is the largest there —
    /// the one a parameter out of its physical range (a vanishing mass, an
    /// absurd bias) sets.
    pub fn solve(
        method: &'static str,
        source: SolveError,
        circuit: &Circuit,
        t0: f64,
        x0: &[f64],
    ) -> Self {
        // the netlist's names (`v.pressure`, what `v.initial.pressure` sets)
        let name = |i: usize| circuit.state_label(i).unwrap_or_else(|| "?".into());
        let at_start = |t: f64| t <= t0 && x0.len() == circuit.n_states();
        let fastest = || {
            let mut dx = vec![0.0; x0.len()];
            circuit.rhs(t0, x0, &mut dx);
            let scale = circuit.atol(1.0);
            let rate = |i: usize| {
                let r = (dx[i] / scale[i]).abs();
                if r.is_nan() {
                    f64::INFINITY
                } else {
                    r
                }
            };
            (0..dx.len())
                .max_by(|&a, &b| rate(a).total_cmp(&rate(b)))
                .map(|i| (i, dx[i]))
        };
        let hint = "; a parameter that sets its rate is out of its physical range";
        let state = match &source {
            SolveError::NonFinite { index, t } if at_start(*t) => {
                format!(" (state {index} is `{}`{hint})", name(*index))
            }
            SolveError::NonFinite { index, .. } => {
                format!(" (state {index} is `{}`)", name(*index))
            }
            SolveError::EventStorm { which, .. } | SolveError::Chattering { which, .. } => circuit
                .event_owner(*which)
                .map(|c| format!(" (the events are `{c}`'s)"))
                .unwrap_or_default(),
            SolveError::StepTooSmall { t, .. } if at_start(*t) => match fastest() {
                Some((i, d)) => format!(
                    " (the fastest state at the start is `{}`, d/dt = {d:e}{hint})",
                    name(i)
                ),
                None => String::new(),
            },
            _ => String::new(),
        };
        SimError::Solve {
            method,
            source,
            state,
        }
    }
}

/// Settings of a run.
#[derive(Clone, Debug)]
pub struct RunOptions {
    /// The integration method.
    pub solver: Solver,
    /// Relative tolerance (absolute tolerances are `rtol ·` each state's scale).
    pub rtol: f64,
    /// Largest step \[s\] (adaptive methods).
    pub h_max: f64,
    /// Fixed step of RK4, the longest step of [`Solver::Exponential`] \[s\].
    pub rk4_step: f64,
    /// Integrate the component quadratures (mass balance).
    pub quadratures: bool,
    /// Integrate the energy ledger.
    pub ledger: bool,
    /// Step budget: a run that needs more steps fails with the time reached.
    pub max_steps: usize,
    /// Read the probes into [`Run::channels`] at every output time; off, a
    /// run keeps only its raw [`Run::states`] (for a caller that reads the
    /// circuit itself, e.g. the chapter-7 measurements).
    pub channels: bool,
    /// Read only the channels named here (e.g. `["position", "p1",
    /// "p2"]`: what a fit compares with a record), in the order of the
    /// full set; `None` (the default): every probe. When each named
    /// channel is a stored effort (a state's: a position, a chamber
    /// pressure), they are read without evaluating the circuit.
    pub only_channels: Option<Vec<String>>,
}

impl Default for RunOptions {
    fn default() -> Self {
        Self {
            solver: Solver::Auto,
            rtol: 1e-6,
            h_max: 1e-2,
            rk4_step: 2e-5,
            quadratures: false,
            ledger: false,
            max_steps: Options::default().max_steps,
            channels: true,
            only_channels: None,
        }
    }
}

impl RunOptions {
    /// The integrator's options for `circuit` with output at `t_eval`
    /// (absolute tolerances from the circuit's state scales).
    pub fn solver_options(&self, circuit: &Circuit, t_eval: Vec<f64>) -> Options {
        Options {
            rtol: self.rtol,
            atol: circuit.atol(self.rtol),
            h0: self.solver.fixed_step().then_some(self.rk4_step),
            h_max: self.h_max,
            max_steps: self.max_steps,
            t_eval: Some(t_eval),
            ..Options::default()
        }
    }

    /// The defaults with Dormand–Prince 5(4) named: for results that must
    /// stay those of the thesis's solver whatever the default choice is.
    pub fn dp45() -> Self {
        Self {
            solver: Solver::Dp45,
            ..Self::default()
        }
    }
}

/// One output column.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// Name (measured-data signal names: `position`, `velocity`, `p1`, ...).
    pub name: String,
    /// SI unit.
    pub unit: &'static str,
    /// The probe it reads, `<component>.<probe>` ([`Probe::path`](crate::Probe::path)):
    /// what the channel is, whatever its column is called.
    pub probe: String,
    /// Values at [`Run::time`].
    pub values: Vec<f64>,
}

/// The result of a run.
#[derive(Clone, Debug, Default)]
pub struct Run {
    /// Output times \[s\].
    pub time: Vec<f64>,
    /// Output channels, in the measured-data order (command, position,
    /// velocity, p1, p2, then the rig's others).
    pub channels: Vec<Channel>,
    /// Full state vectors at the output times, row-major (`dim` each).
    pub states: Vec<f64>,
    /// Length of one state vector.
    pub dim: usize,
    /// Integrator work counters.
    pub stats: Stats,
    /// Component counters (`<component>.<counter>`): cavitation entries,
    /// stop impacts, X-factor evaluations.
    pub diagnostics: Vec<(String, f64)>,
    /// Wall-clock time of the solve.
    pub wall: Duration,
}

impl Run {
    /// A channel's values by name.
    pub fn channel(&self, name: &str) -> Option<&[f64]> {
        self.channels
            .iter()
            .find(|c| c.name == name)
            .map(|c| c.values.as_slice())
    }

    /// A diagnostic counter by its full name.
    pub fn diagnostic(&self, name: &str) -> Option<f64> {
        self.diagnostics
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| *v)
    }

    /// The state vector at output `k`.
    pub fn state(&self, k: usize) -> &[f64] {
        &self.states[k * self.dim..(k + 1) * self.dim]
    }

    /// Lowest value of the chamber pressure channels \[Pa\]: every
    /// cylinder's `p1`, `p2` probes, whatever their columns are called
    /// ([`chamber_of`]); infinite when the outputs hold none.
    pub fn min_chamber_pressure(&self) -> f64 {
        self.channels
            .iter()
            .filter(|c| c.unit == "Pa" && chamber_of(&c.probe).is_some())
            .flat_map(|c| c.values.iter().copied())
            .fold(f64::INFINITY, f64::min)
    }
}

const ORDER: [&str; 5] = ["command", "position", "velocity", "p1", "p2"];

/// Integrates `circuit` from `x0` at `t_eval[0]` to the last of `t_eval`,
/// sampling at every `t_eval` time (sorted, strictly increasing, ≥ 2 points):
/// [`crate::simulation::Simulation::run`].
pub(crate) fn run(
    circuit: &mut Circuit,
    x0: &[f64],
    t_eval: &[f64],
    opts: &RunOptions,
) -> Result<Run, SimError> {
    run_until(circuit, x0, t_eval, opts, None)
}

/// [`run`], and with `stop` the solve asks it before every step and ends
/// with [`SolveError::Interrupted`] once it says so
/// ([`hydrocyl_integrators::solve_stoppable`]); until then the outputs are
/// the same.
pub(crate) fn run_until(
    circuit: &mut Circuit,
    x0: &[f64],
    t_eval: &[f64],
    opts: &RunOptions,
    stop: Option<&dyn Fn() -> bool>,
) -> Result<Run, SimError> {
    check_times(t_eval)?;
    check_options(opts)?;
    let x = initial(circuit, x0, t_eval[0], opts)?;
    let mut probes = ProbeSet::selected(circuit, opts.only_channels.as_deref())?;
    let (t0, t_end) = (t_eval[0], t_eval[t_eval.len() - 1]);
    let sopts = opts.solver_options(circuit, t_eval.to_vec());
    let start = Instant::now();
    let method = opts.solver.method();
    let sol = match stop {
        None => solve(method, circuit, t0, &x, t_end, &sopts),
        Some(stop) => solve_stoppable(method, circuit, t0, &x, t_end, &sopts, stop),
    }
    .map_err(|source| SimError::solve(opts.solver.name(), source, circuit, t0, &x))?;
    let wall = start.elapsed();
    // probes → channels
    let mut channels = Vec::new();
    if opts.channels {
        probes.read_channels(circuit, &sol.t, &sol.x, &mut channels);
    }
    Ok(Run {
        time: sol.t,
        channels,
        dim: sol.dim,
        states: sol.x,
        stats: sol.stats,
        diagnostics: circuit.diagnostics(),
        wall,
    })
}

/// Each setting meets its rule ([`Setting`]).
fn check_options(opts: &RunOptions) -> Result<(), SimError> {
    for (name, setting, value) in [
        ("rtol", Setting::Rtol, opts.rtol),
        ("h_max", Setting::HMax, opts.h_max),
        ("rk4_step", Setting::Rk4Step, opts.rk4_step),
    ] {
        setting
            .check_named(name, value)
            .map_err(SimError::Settings)?;
    }
    Ok(())
}

/// Sets the circuit up for a run from `x0` at `t0` (quadratures and ledger
/// as asked, reset there) and returns the full state (quadratures at 0).
fn initial(
    circuit: &mut Circuit,
    x0: &[f64],
    t0: f64,
    opts: &RunOptions,
) -> Result<Vec<f64>, SimError> {
    circuit.set_quadratures(opts.quadratures);
    circuit.set_ledger(opts.ledger);
    let n = circuit.n_states();
    if x0.len() != n {
        return Err(SimError::Settings(format!(
            "initial state has {} entries, the circuit {n}",
            x0.len()
        )));
    }
    let mut x = vec![0.0; circuit.dim()];
    x[..n].copy_from_slice(x0);
    if let Some(i) = x.iter().position(|v| !v.is_finite()) {
        return Err(SimError::Settings(format!(
            "initial state {} is not finite",
            circuit.state_names()[i]
        )));
    }
    circuit.reset(t0, &x);
    Ok(x)
}

/// The integrator's options of a run (no output times: a streamed run
/// pushes them as it goes).
fn solver_options(circuit: &Circuit, opts: &RunOptions) -> Options {
    Options {
        t_eval: None,
        ..opts.solver_options(circuit, Vec::new())
    }
}

/// [`run`] for long records: the output goes to `sink` in blocks of about
/// `block` output times (a block ends at a step's end, so it may hold a few
/// more) as soon as each is computed, so the memory grows with the block,
/// not the record. It is one solve ([`hydrocyl_integrators::solve_streaming`]):
/// the integrator's step size, controller and stages carry over from block
/// to block, and the outputs are [`run`]'s, bit for bit. Returns the totals:
/// the stats, the diagnostics at the end, the wall time of the solve (the
/// sink's excluded); its `time`, `channels` and `states` are empty.
pub(crate) fn run_streaming(
    circuit: &mut Circuit,
    x0: &[f64],
    t_eval: &[f64],
    opts: &RunOptions,
    block: usize,
    sink: &mut dyn FnMut(&Run) -> Result<(), String>,
) -> Result<Run, SimError> {
    stream_slice(circuit, x0, t_eval, opts, block, Output::Channels(sink))
}

/// The sink of [`Simulation::run_streaming_states`]: a block's output times
/// and states (row-major); an `Err` stops the run.
///
/// [`Simulation::run_streaming_states`]: crate::simulation::Simulation::run_streaming_states
pub type StateSink<'a> = dyn FnMut(&[f64], &[f64]) -> Result<(), String> + 'a;

/// [`run_streaming`] without the channels: `sink` receives each block's
/// output times and full states (row-major, `x.len() / t.len()` each) as
/// the integrator wrote them, and reads the probes itself where it likes,
/// e.g. a [`ProbeReader`] on another thread (the solve's thread then only
/// solves). The buffers are the solve's, reused block after block: copy
/// what is kept.
pub(crate) fn run_streaming_states(
    circuit: &mut Circuit,
    x0: &[f64],
    t_eval: &[f64],
    opts: &RunOptions,
    block: usize,
    sink: &mut StateSink<'_>,
) -> Result<Run, SimError> {
    stream_slice(circuit, x0, t_eval, opts, block, Output::States(sink))
}

/// [`stream`] at the output times `t_eval`, all given.
fn stream_slice(
    circuit: &mut Circuit,
    x0: &[f64],
    t_eval: &[f64],
    opts: &RunOptions,
    block: usize,
    out: Output<'_>,
) -> Result<Run, SimError> {
    check_times(t_eval)?;
    let mut times = Times::Slice {
        t: t_eval,
        pushed: 0,
    };
    let t_end = t_eval[t_eval.len() - 1];
    stream(circuit, x0, &mut times, t_end, opts, block, out)
}

/// The samples of a command record, read while the run goes (a source for
/// [`Simulation::run_command_stream`]).
///
/// [`Simulation::run_command_stream`]: crate::simulation::Simulation::run_command_stream
pub trait CommandSource {
    /// Appends the next samples' times \[s\] and values to `t` and `u`
    /// (both the same length; times strictly increasing across calls);
    /// `Ok(false)` once the record has no more.
    fn read(&mut self, t: &mut Vec<f64>, u: &mut Vec<f64>) -> Result<bool, String>;
}

/// [`run_streaming`] on a command record too long to hold: the circuit reads
/// its command from `table` (built with [`crate::signal::Signal::Streamed`]
/// of a clone of it), which is filled from `source` ahead of the
/// integration and emptied behind it; the output times are the record's
/// sample times, from the first (`x0`'s time) to `t_end`, the last. Memory
/// grows with `block` and the window, not the record; the outputs are those
/// of [`run`] on the whole record as a [`crate::signal::Signal::Table`].
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_command_stream(
    circuit: &mut Circuit,
    x0: &[f64],
    table: &StreamedTable,
    source: &mut dyn CommandSource,
    t_end: f64,
    opts: &RunOptions,
    block: usize,
    sink: &mut dyn FnMut(&Run) -> Result<(), String>,
) -> Result<Run, SimError> {
    let mut times = Times::Command {
        table,
        source,
        t: Vec::new(),
        u: Vec::new(),
        eof: false,
    };
    // the first samples give the start time
    times
        .refill(f64::NEG_INFINITY, f64::NEG_INFINITY)
        .map_err(SimError::Settings)?;
    stream(
        circuit,
        x0,
        &mut times,
        t_end,
        opts,
        block,
        Output::Channels(sink),
    )
}

/// Output times must be at least two, finite and strictly increasing.
fn check_times(t_eval: &[f64]) -> Result<(), SimError> {
    if t_eval.len() < 2 {
        return Err(SimError::Settings("need at least two output times".into()));
    }
    if let Some(i) = t_eval.iter().position(|t| !t.is_finite()) {
        return Err(SimError::Settings(format!(
            "output time {} (sample {i}) is not finite",
            t_eval[i]
        )));
    }
    if let Some(i) = (1..t_eval.len()).find(|&i| t_eval[i] <= t_eval[i - 1]) {
        return Err(SimError::Settings(format!(
            "output time {} (sample {i}) does not increase",
            t_eval[i]
        )));
    }
    Ok(())
}

/// Where a streamed run's output times come from.
enum Times<'a> {
    /// All given.
    Slice { t: &'a [f64], pushed: usize },
    /// A command record's sample times, its values going to `table`.
    Command {
        table: &'a StreamedTable,
        source: &'a mut dyn CommandSource,
        /// Samples read and not yet pushed.
        t: Vec<f64>,
        u: Vec<f64>,
        eof: bool,
    },
}

impl Times<'_> {
    /// The first output time.
    fn first(&self) -> Option<f64> {
        match self {
            Times::Slice { t, .. } => t.first().copied(),
            Times::Command { table, .. } => table.first_time(),
        }
    }

    /// Reads samples until the window reaches past `until` (or the record
    /// ends); `behind`: the window may drop what is before it.
    fn refill(&mut self, until: f64, behind: f64) -> Result<(), String> {
        let Times::Command {
            table,
            source,
            t,
            u,
            eof,
        } = self
        else {
            return Ok(());
        };
        table.drop_before(behind);
        loop {
            if table.last_time().is_some_and(|l| l > until) || table.finished() {
                return Ok(());
            }
            if t.is_empty() {
                if *eof {
                    table.finish();
                    return Ok(());
                }
                *eof = !source.read(t, u)?;
                if t.len() != u.len() {
                    return Err("command source: times and values differ in length".into());
                }
                t.reverse();
                u.reverse();
                continue;
            }
            if table.free() == 0 {
                return Err(format!(
                    "the command is sampled too densely to stream ({} samples before t = {until} s)",
                    table.len()
                ));
            }
            while let (Some(&tk), Some(&uk)) = (t.last(), u.last()) {
                if !table.push(tk, uk) {
                    break;
                }
                t.pop();
                u.pop();
                if tk > until {
                    break;
                }
            }
        }
    }
}

/// Where a streamed run's blocks go.
enum Output<'a> {
    /// The channels read on the solving circuit, as a [`Run`].
    Channels(&'a mut dyn FnMut(&Run) -> Result<(), String>),
    /// The raw times and states.
    States(&'a mut StateSink<'a>),
}

/// The [`Stream`] of [`run_streaming`] and [`run_command_stream`].
struct Streamer<'a, 'b, 's> {
    times: &'a mut Times<'b>,
    /// How far past the time reached the next step may go \[s\].
    ahead: f64,
    block: usize,
    sink: Output<'s>,
    probes: ProbeSet,
    /// The block handed to a channel sink, its buffers reused.
    out: Run,
    /// Time spent in `sink` (not the solve's).
    in_sink: Duration,
    /// The last output time pushed (∞ once all are).
    covered: f64,
    new_times: Vec<f64>,
}

impl Stream<Circuit> for Streamer<'_, '_, '_> {
    fn between_steps(
        &mut self,
        c: &mut Circuit,
        t: f64,
        io: &mut StreamIo<'_, '_>,
    ) -> Result<(), String> {
        if io.written() >= self.block || io.finished() {
            self.flush(c, io)?;
        }
        if let Times::Command { table, .. } = self.times {
            if table.underrun() {
                return Err(format!(
                    "the command window did not cover t = {t} s (the streamed run read ahead too little)"
                ));
            }
        }
        if io.finished() {
            return Ok(());
        }
        // the window keeps the samples the outputs not yet taken need
        let behind = if io.written() == 0 {
            t
        } else {
            f64::NEG_INFINITY
        };
        let until = t + self.ahead;
        self.times.refill(until, behind)?;
        if self.covered > until {
            return Ok(());
        }
        match self.times {
            Times::Slice { t: all, pushed } => {
                let mut end = *pushed;
                while end < all.len() && all[end] <= until {
                    end += 1;
                }
                let end = (end + 1).min(all.len());
                io.push_times(&all[*pushed..end])?;
                *pushed = end;
                self.covered = if end == all.len() {
                    f64::INFINITY
                } else {
                    all[end - 1]
                };
            }
            Times::Command { table, .. } => {
                self.new_times.clear();
                table.times_after(self.covered, &mut self.new_times);
                io.push_times(&self.new_times)?;
                if let Some(&l) = self.new_times.last() {
                    self.covered = l;
                }
                if table.finished() {
                    self.covered = f64::INFINITY;
                }
            }
        }
        Ok(())
    }
}

impl Streamer<'_, '_, '_> {
    /// Hands the outputs written so far to the sink: their channels read
    /// on `c` (into the reused block), or the raw times and states.
    fn flush(&mut self, c: &mut Circuit, io: &mut StreamIo<'_, '_>) -> Result<(), String> {
        let (probes, out, sink, in_sink) = (
            &mut self.probes,
            &mut self.out,
            &mut self.sink,
            &mut self.in_sink,
        );
        io.take(|t, x| {
            if t.is_empty() {
                return Ok(());
            }
            // the channels are read on the solve's time, the sink's is not
            if let Output::Channels(_) = sink {
                probes.read(c, t, x, out);
            }
            let start = Instant::now();
            let r = match sink {
                Output::States(f) => f(t, x),
                Output::Channels(f) => f(out),
            };
            *in_sink += start.elapsed();
            r
        })
    }
}

/// The streamed solve of [`run_streaming`] and [`run_command_stream`].
fn stream(
    circuit: &mut Circuit,
    x0: &[f64],
    times: &mut Times<'_>,
    t_end: f64,
    opts: &RunOptions,
    block: usize,
    sink: Output<'_>,
) -> Result<Run, SimError> {
    let t0 = times
        .first()
        .ok_or_else(|| SimError::Settings("need at least two output times".into()))?;
    if !(t0.is_finite() && t_end.is_finite() && t_end > t0) {
        return Err(SimError::Settings(format!(
            "the run goes from {t0} s to {t_end} s: needs at least two increasing output times"
        )));
    }
    check_options(opts)?;
    let x = initial(circuit, x0, t0, opts)?;
    let mut streamer = Streamer {
        times,
        ahead: opts.h_max.max(if opts.solver.fixed_step() {
            opts.rk4_step
        } else {
            0.0
        }) * 1.05,
        block: block.max(2),
        sink,
        probes: ProbeSet::selected(circuit, opts.only_channels.as_deref())?,
        out: Run::default(),
        in_sink: Duration::ZERO,
        covered: f64::NEG_INFINITY,
        new_times: Vec::new(),
    };
    let sopts = solver_options(circuit, opts);
    let start = Instant::now();
    let sol = solve_streaming(
        opts.solver.method(),
        circuit,
        t0,
        &x,
        t_end,
        &sopts,
        &mut streamer,
    )
    .map_err(|source| match source {
        SolveError::Interrupted { why, .. } => SimError::Settings(why),
        source => SimError::solve(opts.solver.name(), source, circuit, t0, &x),
    })?;
    Ok(Run {
        time: Vec::new(),
        channels: Vec::new(),
        states: Vec::new(),
        dim: sol.dim,
        stats: sol.stats,
        diagnostics: circuit.diagnostics(),
        wall: start.elapsed().saturating_sub(streamer.in_sink),
    })
}

/// Normalised RMS error `RMSE(a − b) / (max b − min b)` (the measured-data
/// spec's NRMSE, `b` the reference). `NaN` when lengths differ or `b` is flat.
pub fn nrmse(a: &[f64], b: &[f64]) -> f64 {
    if a.len() != b.len() || a.is_empty() {
        return f64::NAN;
    }
    let (lo, hi) = b
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
            (l.min(*v), h.max(*v))
        });
    let mse = a.iter().zip(b).map(|(x, y)| (x - y) * (x - y)).sum::<f64>() / a.len() as f64;
    if hi > lo {
        mse.sqrt() / (hi - lo)
    } else {
        f64::NAN
    }
}

#[cfg(test)]
mod tests;
