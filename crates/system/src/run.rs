//! Running an assembled circuit: solver choice, output sampling at given
//! times, probes turned into named channels, cavitation and stop reports.

use crate::circuit::{BuildError, Circuit};
use hydrocyl_integrators::{solve, Method, OdeSystem, Options, SolveError, Stats};
use std::time::{Duration, Instant};
use thiserror::Error;

/// Why a run failed.
#[derive(Debug, Error)]
pub enum SimError {
    /// The circuit could not be assembled.
    #[error(transparent)]
    Build(#[from] BuildError),
    /// The integrator failed (tolerance not met, non-finite state, ...).
    #[error("solver {method}: {source}")]
    Solve {
        /// The method used.
        method: &'static str,
        /// The solver's error.
        source: SolveError,
    },
    /// Bad run settings.
    #[error("run settings: {0}")]
    Settings(String),
}

/// The integration method, by the names the CLI accepts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Solver {
    /// Automatic (default): Dormand–Prince 5(4) while the problem is not
    /// stiff, Rosenbrock while it is, switched by the stiffness the run shows
    /// ([`Method::Auto`]; the choice is in [`Stats::stiff_steps`] and
    /// [`Stats::switches`]).
    Auto,
    /// Dormand–Prince 5(4) (Simulink's ode45, the thesis's solver).
    Dp45,
    /// Stiff Rosenbrock.
    Rosenbrock,
    /// Fixed-step RK4 (step `RunOptions::rk4_step`).
    Rk4,
}

impl Solver {
    /// The integrator crate's method.
    pub fn method(self) -> Method {
        match self {
            Solver::Auto => Method::Auto,
            Solver::Dp45 => Method::DormandPrince45,
            Solver::Rosenbrock => Method::Rosenbrock,
            Solver::Rk4 => Method::Rk4,
        }
    }
    /// The CLI name.
    pub fn name(self) -> &'static str {
        match self {
            Solver::Auto => "auto",
            Solver::Dp45 => "dp45",
            Solver::Rosenbrock => "rosenbrock",
            Solver::Rk4 => "rk4",
        }
    }
    /// Parses a CLI name (`auto`, `dp45`, `rosenbrock`, `rk4`).
    pub fn parse(s: &str) -> Option<Self> {
        match s {
            "auto" => Some(Solver::Auto),
            "dp45" => Some(Solver::Dp45),
            "rosenbrock" => Some(Solver::Rosenbrock),
            "rk4" => Some(Solver::Rk4),
            _ => None,
        }
    }
}

impl From<Method> for Solver {
    fn from(m: Method) -> Self {
        match m {
            Method::Auto => Solver::Auto,
            Method::DormandPrince45 => Solver::Dp45,
            Method::Rosenbrock => Solver::Rosenbrock,
            Method::Rk4 => Solver::Rk4,
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
    /// Fixed step of RK4 \[s\].
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
            h0: (self.solver == Solver::Rk4).then_some(self.rk4_step),
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
    /// Values at [`Run::time`].
    pub values: Vec<f64>,
}

/// The result of a run.
#[derive(Clone, Debug)]
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

    /// Number of cavitation entries of all chambers (0 = none).
    pub fn cavitation_entries(&self) -> usize {
        self.diagnostics
            .iter()
            .filter(|(n, _)| n.contains("cavitation_entries"))
            .map(|(_, v)| *v as usize)
            .sum()
    }

    /// Lowest value of the chamber pressure channels `p1`, `p2` \[Pa\].
    pub fn min_chamber_pressure(&self) -> f64 {
        ["p1", "p2"]
            .iter()
            .filter_map(|n| self.channel(n))
            .flat_map(|v| v.iter().copied())
            .fold(f64::INFINITY, f64::min)
    }
}

const ORDER: [&str; 5] = ["command", "position", "velocity", "p1", "p2"];

/// Integrates `circuit` from `x0` at `t_eval[0]` to the last of `t_eval`,
/// sampling at every `t_eval` time (sorted, strictly increasing, ≥ 2 points).
pub fn run(
    circuit: &mut Circuit,
    x0: &[f64],
    t_eval: &[f64],
    opts: &RunOptions,
) -> Result<Run, SimError> {
    if t_eval.len() < 2 {
        return Err(SimError::Settings("need at least two output times".into()));
    }
    if !t_eval[0].is_finite() {
        return Err(SimError::Settings(format!(
            "output time {} is not finite",
            t_eval[0]
        )));
    }
    if let Some(i) =
        (1..t_eval.len()).find(|&i| t_eval[i] <= t_eval[i - 1] || !t_eval[i].is_finite())
    {
        return Err(SimError::Settings(format!(
            "output time {} (sample {i}) does not increase",
            t_eval[i]
        )));
    }
    if !(opts.rtol > 0.0 && opts.rtol < 1.0) {
        return Err(SimError::Settings(format!(
            "rtol must be in (0, 1), got {}",
            opts.rtol
        )));
    }
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
    circuit.reset(t_eval[0], &x);
    solve_from(circuit, &x, t_eval, opts)
}

/// The solve of [`run`] from the full state `x` (quadratures included) at
/// `t_eval[0]`, without resetting the circuit, and its output channels.
fn solve_from(
    circuit: &mut Circuit,
    x: &[f64],
    t_eval: &[f64],
    opts: &RunOptions,
) -> Result<Run, SimError> {
    let (t0, t_end) = (t_eval[0], t_eval[t_eval.len() - 1]);
    let sopts = opts.solver_options(circuit, t_eval.to_vec());
    let start = Instant::now();
    let sol = solve(opts.solver.method(), circuit, t0, x, t_end, &sopts).map_err(|source| {
        SimError::Solve {
            method: opts.solver.name(),
            source,
        }
    })?;
    let wall = start.elapsed();
    // probes → channels
    let probes = if opts.channels {
        circuit.probes()
    } else {
        Vec::new()
    };
    let mut channels: Vec<Channel> = probes
        .iter()
        .map(|p| Channel {
            name: p.name.clone(),
            unit: p.unit,
            values: Vec::with_capacity(sol.t.len()),
        })
        .collect();
    let wires: Vec<_> = probes.iter().map(|p| p.wire).collect();
    let mut row = vec![0.0; wires.len()];
    for k in (0..sol.t.len()).filter(|_| !wires.is_empty()) {
        circuit.read_wires(sol.t[k], sol.state(k), &wires, &mut row);
        for (c, v) in channels.iter_mut().zip(&row) {
            c.values.push(*v);
        }
    }
    channels.sort_by_key(|c| {
        ORDER
            .iter()
            .position(|o| *o == c.name)
            .unwrap_or(ORDER.len())
    });
    Ok(Run {
        time: sol.t.clone(),
        channels,
        dim: sol.dim,
        states: sol.x,
        stats: sol.stats,
        diagnostics: circuit.diagnostics(),
        wall,
    })
}

/// [`run`] for long records: the output goes to `sink` in blocks of at most
/// `block` output times as soon as each is computed, so the memory grows
/// with the block, not the record. The integration restarts at each block's
/// first time from the state there (the circuit is not reset; the step
/// controller starts afresh, so a result differs from [`run`]'s within the
/// tolerance); with one block it is [`run`]'s. Returns the totals: stats
/// summed over the blocks, the diagnostics at the end, the wall time; its
/// `time`, `channels` and `states` are empty.
pub fn run_streaming(
    circuit: &mut Circuit,
    x0: &[f64],
    t_eval: &[f64],
    opts: &RunOptions,
    block: usize,
    sink: &mut dyn FnMut(&Run) -> Result<(), String>,
) -> Result<Run, SimError> {
    let block = block.max(2);
    let mut total: Option<Run> = None;
    let mut k0 = 0;
    let mut x = Vec::new();
    while k0 < t_eval.len() {
        let k1 = (k0 + block).min(t_eval.len());
        let mut r = if k0 == 0 {
            run(circuit, x0, &t_eval[..k1], opts)?
        } else {
            // from the previous block's last time, which is not repeated
            let mut r = solve_from(circuit, &x, &t_eval[k0 - 1..k1], opts)?;
            r.time.remove(0);
            r.channels.iter_mut().for_each(|c| {
                c.values.remove(0);
            });
            r.states.drain(..r.dim);
            r
        };
        x = r.state(r.time.len() - 1).to_vec();
        sink(&r).map_err(SimError::Settings)?;
        let t = total.get_or_insert_with(|| Run {
            time: Vec::new(),
            channels: Vec::new(),
            states: Vec::new(),
            dim: r.dim,
            stats: Stats::default(),
            diagnostics: Vec::new(),
            wall: Duration::ZERO,
        });
        let (a, b) = (&mut t.stats, &r.stats);
        a.steps += b.steps;
        a.rejected += b.rejected;
        a.rhs_evals += b.rhs_evals;
        a.jac_evals += b.jac_evals;
        a.lu_decomps += b.lu_decomps;
        a.events += b.events;
        a.stiff_steps += b.stiff_steps;
        a.switches += b.switches;
        t.wall += r.wall;
        t.diagnostics = std::mem::take(&mut r.diagnostics);
        k0 = k1;
    }
    total.ok_or_else(|| SimError::Settings("need at least two output times".into()))
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
