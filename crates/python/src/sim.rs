//! One run of a rig on a sampled command, as `hydrocyl simulate` makes it:
//! run settings checked with the CLI's messages, the command a
//! piecewise-linear table over the output times, the energy ledger when
//! asked for, and a solver failure located (time and state).

use crate::errors::{stopped, Failure, Outcome, RunWarning, Stop};
use hydrocyl_energy::ledger::{ledger, Ledger, RodSide};
use hydrocyl_system::rig::{self, RigError};
use hydrocyl_system::run::{
    Cause, DeepCavitation, Run, RunOptions, Setting, SettingWords, SimError, Solver,
};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;
use serde_json::Value;
use std::sync::Arc;

/// The run settings `simulate` and `simulate_batch` take, checked with the
/// CLI's rules and messages (named by the Python argument).
pub fn options(
    solver: &str,
    rtol: f64,
    rk4_step: f64,
    h_max: Option<f64>,
    ledger: bool,
) -> Outcome<RunOptions> {
    let solver =
        Solver::parse_or_why(solver).map_err(|why| Failure::Input(format!("solver: {why}")))?;
    let defaults = RunOptions::default();
    let h_max = h_max.unwrap_or(defaults.h_max);
    for (name, setting, value) in [
        ("rtol", Setting::Rtol, rtol),
        ("rk4_step", Setting::Rk4Step, rk4_step),
        ("h_max", Setting::HMax, h_max),
    ] {
        setting.check_named(name, value).map_err(Failure::Input)?;
    }
    Ok(RunOptions {
        solver,
        rtol,
        rk4_step,
        h_max,
        ledger,
        ..defaults
    })
}

/// The command: a first-order-hold table of `u` over `t` (the CLI's command
/// CSV), at least two samples, one value of `u` per time of `t` (else the
/// lengths are named, not a sample). The run is sampled at the same `t`.
pub fn command(t: &[f64], u: &[f64]) -> Outcome<Signal> {
    if t.len() != u.len() {
        return Err(Failure::Input(format!(
            "command (t, u): t has {} samples but u has {} (one command value per time)",
            t.len(),
            u.len()
        )));
    }
    if t.len() < 2 {
        return Err(Failure::Input(format!(
            "command (t, u): needs at least two samples, found {}",
            t.len()
        )));
    }
    Signal::shared_table(t.into(), u.into())
        .map_err(|e| Failure::Input(format!("command (t, u): {e}")))
}

/// A run and, when the options ask for it, its energy ledger over the whole
/// run (or why there is none).
pub struct Simulated {
    /// The run (channels as `hydrocyl simulate` writes them).
    pub run: Run,
    /// The ledger (`None` unless `RunOptions::ledger`).
    pub ledger: Option<Result<Ledger, String>>,
    /// The warnings of the run, in the CLI's order: the command beyond
    /// the spool's stroke or the rating of the pump the input drives
    /// ([`Simulation::command_limit`], as `hydrocyl simulate` warns of it), a
    /// chamber far below vacuum
    /// ([`Run::deep_cavitation`]).
    pub warnings: Vec<RunWarning>,
}

/// Simulates the rig value (checked or not) on `command` sampled at `t`
/// ([`rig::simulate`]), stopped by `stop` ([`Failure::Interrupted`]); the
/// command is checked against the limit of the rig's command
/// ([`Simulation::command_limit`]: read with the rig's netlist, the run's
/// own, a batch set's parameters and all).
pub fn simulate(
    value: &Value,
    command: &Signal,
    t: &[f64],
    opts: &RunOptions,
    stop: &Stop,
) -> Outcome<Simulated> {
    if stopped(stop) {
        return Err(Failure::Interrupted);
    }
    let mut limit = None;
    let mut implausible = Vec::new();
    let run = Simulation::new(value, command.clone())
        .and_then(|s| {
            limit = s.command_limit().cloned();
            implausible = s.implausible().to_vec();
            s.options(opts.clone()).stop_on(Arc::clone(stop)).run(t)
        })
        .map_err(|e| match e {
            _ if stopped(stop) => Failure::Interrupted,
            RigError::Sim(_) => locate_failure(value, command, t, opts, stop, e.to_string()),
            // the rig's parameters named as `--set`, `Rig.set` and the
            // batch's `params` name them (`load.mass`, not the JSON path
            // `components.load.mass`): a batch set's value is checked here
            other => Failure::Input(rig::set_form(other, value).to_string()),
        })?;
    let cavitation = match run.physical() {
        Err(u) => return Err(unphysical(value, command, opts, &run, u)),
        Ok(deep) => deep.map(|d| cavitation_warning(value, opts, &d)),
    };
    let ledger = opts.ledger.then(|| whole_run_ledger(value, command, &run));
    let rating = match command {
        Signal::Table { time_s, value: u } => limit
            .and_then(|l| l.check(time_s, u))
            .map(|w| RunWarning::Rating(format!("command (t, u): {w}"))),
        _ => None,
    };
    Ok(Simulated {
        run,
        ledger,
        warnings: implausible
            .into_iter()
            .map(RunWarning::Parameter)
            .chain(rating)
            .chain(cavitation.map(RunWarning::Cavitation))
            .collect(),
    })
}

/// The warning of a run whose chamber fell far below vacuum without
/// blowing up ([`DeepCavitation::warning`] in Python's names; a parameter
/// proposed to set is one the component's type has).
fn cavitation_warning(value: &Value, opts: &RunOptions, d: &DeepCavitation) -> String {
    let words = SettingWords {
        set: |p| format!("rig.set('{p}', 0.005)"),
        rk4_step: "rk4_step",
        rtol: "rtol",
        stiff_solver: "solver='rosenbrock'",
        quote: '\'',
    };
    d.warning(
        |c| rig::component_type(value, c),
        opts.solver,
        opts.rk4_step,
        &words,
    )
}

/// A run that finished but is not physical ([`Run::unphysical`]: a blow-up)
/// as a [`Failure::Solver`]: the CLI's diagnosis and remedy in Python's
/// words, the time and the state of the first such sample.
fn unphysical(
    value: &Value,
    command: &Signal,
    opts: &RunOptions,
    run: &Run,
    u: hydrocyl_system::run::Unphysical,
) -> Failure {
    let solver = opts.solver;
    let message = match u.cause(solver) {
        Cause::StepTooLong => format!(
            "the {} solution is unstable ({}): rk4_step {} is too large for this rig: use a smaller step or solver='auto'",
            solver.name(),
            u.what,
            opts.rk4_step
        ),
        Cause::Unstable => format!(
            "the {} solution is unstable ({}); try solver='rosenbrock' or a smaller rtol",
            solver.name(),
            u.what
        ),
    };
    let names = Simulation::new(value, command.clone())
        .map(|s| s.circuit().state_names())
        .unwrap_or_default();
    let state: Vec<(String, f64)> = names
        .into_iter()
        .zip(run.state(u.sample).iter().copied())
        .collect();
    let time = run.time[u.sample];
    let listed = state
        .iter()
        .map(|(k, v)| format!("{k} = {v:e}"))
        .collect::<Vec<_>>()
        .join(", ");
    Failure::Solver {
        message: format!("{message}; state at t = {time} s: {listed}"),
        time,
        state,
    }
}

/// The ledger of `run` over all its samples, on a fresh circuit of the same
/// rig (the ledger reads only the circuit's structure and the run's states).
fn whole_run_ledger(value: &Value, command: &Signal, run: &Run) -> Result<Ledger, String> {
    let mut c = rig::circuit(value, command.clone()).map_err(|e| e.to_string())?;
    c.set_ledger(true);
    ledger(&c, run, 0, run.time.len() - 1, &RodSide::of(&c)).map_err(|e| e.to_string())
}

/// Turns a failed run into a [`Failure::Solver`]: the rig's run is repeated
/// (a fresh [`Simulation`], [`Simulation::try_run`] for the solver's own
/// error) to get the solver's time, then integrated up to that time for the
/// state there (or up to the last point before it a run reaches, when the
/// failing step ends at that time). The message is the CLI's, with the state
/// appended.
fn locate_failure(
    value: &Value,
    command: &Signal,
    t: &[f64],
    opts: &RunOptions,
    stop: &Stop,
    message: String,
) -> Failure {
    let located = (|| {
        let sim = || {
            Simulation::new(value, command.clone())
                .ok()
                .map(|s| s.options(opts.clone()).stop_on(Arc::clone(stop)))
        };
        let mut first = sim()?;
        let x0 = first.initial().to_vec();
        let n = first.circuit().n_states();
        let names = first.circuit().state_names();
        let time = match first.try_run(t) {
            Err(SimError::Solve { source, .. }) => source.time()?,
            _ => return None,
        };
        // the state at the failure time, or — where the solver failed on a
        // step that ends there (a non-finite fixed step) — at the last point
        // before it that a run reaches: one fixed step back, else the last
        // output sample before it
        let mut candidates = vec![time];
        if opts.solver == Solver::Rk4 {
            candidates.push(time - opts.rk4_step);
        }
        candidates.extend(t.iter().rev().find(|&&s| s < time));
        let mut reached = None;
        for at in candidates.into_iter().filter(|&at| at >= t[0]) {
            if at == t[0] {
                reached = Some((at, x0[..n].to_vec()));
                break;
            }
            if let Ok(r) = sim()?.try_run(&[t[0], at]) {
                reached = Some((at, r.state(1)[..n].to_vec()));
                break;
            }
        }
        let (time, state) = reached?;
        Some((
            time,
            names.into_iter().take(n).zip(state).collect::<Vec<_>>(),
        ))
    })();
    if stopped(stop) {
        return Failure::Interrupted;
    }
    let (time, state) = located.unwrap_or((f64::NAN, Vec::new()));
    let listed = state
        .iter()
        .map(|(k, v)| format!("{k} = {v:e}"))
        .collect::<Vec<_>>()
        .join(", ");
    let message = if state.is_empty() {
        message
    } else {
        format!("{message}; state at t = {time} s: {listed}")
    };
    Failure::Solver {
        message,
        time,
        state,
    }
}
