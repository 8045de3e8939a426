//! One chapter-9 case: a rig value driven by the chapter-8 square wave (or,
//! for a closed-loop rig, the position reference of the same motion), run
//! with its energy ledger and measured.
//!
//! Conventions are chapter 8's (`crate::chapter8`): period `0.25 m / v`,
//! start half a stroke's travel below mid-stroke, 20 kg as a gravity force
//! opposing extension, the first period start-up and the next two measured;
//! the open-loop command is the biased square `v (A1 ± A2)/(2K)` that gives
//! ±v in steady state. Output every millisecond.

use crate::chapter8::G;
use hydrocyl_energy::ledger::{ledger, RodSide};
use hydrocyl_energy::EnergyError;
use hydrocyl_system::rig::{self, RigError};
use hydrocyl_system::run::{Run, RunOptions, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;
use serde::Serialize;
use serde_json::Value;

/// Output sample interval \[s\].
pub const SAMPLE_S: f64 = 1e-3;

/// A speed and a load.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Case {
    /// Speed amplitude \[mm/s\].
    pub speed_mm_s: f64,
    /// Gravity load \[kg\].
    pub load_kg: f64,
}

impl Case {
    /// Speed \[m/s\].
    pub fn speed(&self) -> f64 {
        1e-3 * self.speed_mm_s
    }
    /// Command period \[s\].
    pub fn period(&self) -> f64 {
        0.25 / self.speed()
    }
    /// Start position \[m\] (half the 125 mm travel below mid-stroke).
    pub fn start(&self) -> f64 {
        -0.0625
    }
}

/// What a run measured.
#[derive(Clone, Debug, Serialize)]
pub struct Measured {
    /// Efficiency of eqs 8.1–8.7 over the measured periods \[-\].
    pub efficiency: f64,
    /// Energy in over the measured periods \[J\].
    pub energy_in_j: f64,
    /// The ledger's closing error (fraction of the energy in).
    pub ledger_error: f64,
    /// Mean stall at the reversals to retraction / to extension \[s\].
    pub stall_s: (f64, f64),
    /// Position change per measured period (+ towards extension) \[m\].
    pub drift_m: f64,
    /// Largest speed over the commanded one, as a fraction (0.1 = 10 %).
    pub overrun: f64,
    /// Largest steady speed over the commanded one, as a fraction: the mean
    /// speed over the last 40 % of each half period (the load running ahead
    /// of the pump shows here, the pump's own step overshoot does not).
    pub steady_overrun: f64,
    /// Lowest chamber pressure in the measured periods \[Pa\].
    pub min_chamber_pa: f64,
    /// The ledger's losses `(component, J)`, largest first.
    pub losses: Vec<(String, f64)>,
}

/// A value of the rig `v` by its parameter path (`rig::parameters`).
pub fn parameter(v: &Value, path: &str) -> Result<f64, RigError> {
    rig::parameters(v)
        .into_iter()
        .find(|p| p.path == path)
        .and_then(|p| p.value)
        .ok_or_else(|| RigError::Invalid {
            path: path.into(),
            why: "the chapter-9 study needs this parameter".into(),
        })
}

/// Whether the rig is driven by a position reference (has a
/// `position_controller`).
pub fn is_closed_loop(v: &Value) -> bool {
    v.get("components")
        .and_then(Value::as_object)
        .is_some_and(|c| c.values().any(|i| i["type"] == "position_controller"))
}

/// The rig's input for `case`: the biased square \[V\] (open loop) or the
/// triangle position reference \[m\] of the same motion (closed loop).
pub fn input(v: &Value, case: &Case, t: &[f64]) -> Result<Signal, RigError> {
    let period = case.period();
    if is_closed_loop(v) {
        let x0 = case.start();
        let value: std::sync::Arc<[f64]> = t
            .iter()
            .map(|&ti| {
                let ph = ti.rem_euclid(period) / period;
                let up = if ph < 0.5 { ph } else { 1.0 - ph };
                x0 + case.speed() * period * up
            })
            .collect();
        return Signal::shared_table(t.into(), value).map_err(|e| RigError::Invalid {
            path: "reference".into(),
            why: e.to_string(),
        });
    }
    let (a1, a2) = (
        parameter(v, "cylinder.area_1")?,
        parameter(v, "cylinder.area_2")?,
    );
    let k = parameter(v, "pump.gain")?;
    Ok(Signal::Square {
        amplitude: case.speed() * (a1 + a2) / (2.0 * k),
        period_s: period,
        bias: case.speed() * (a1 - a2) / (2.0 * k),
    })
}

/// Runs `rig` (a rig value, its `--set`s applied) on `case`: three periods,
/// the last two measured.
pub fn run_case(rig: &Value, case: &Case) -> Result<Measured, EnergyError> {
    let err = |source: RigError| EnergyError::Rig {
        rig: rig["name"].as_str().unwrap_or("rig").into(),
        source,
    };
    let mut v = rig.clone();
    for s in [
        format!("load.external_force={}", case.load_kg * G),
        format!("cylinder.initial.position={}", case.start()),
    ] {
        rig::apply_set(&mut v, &s).map_err(err)?;
    }
    let period = case.period();
    let n_per = (period / SAMPLE_S).round() as usize;
    let t: Vec<f64> = (0..=3 * n_per).map(|k| k as f64 * SAMPLE_S).collect();
    let cmd = input(&v, case, &t).map_err(err)?;
    let opts = RunOptions {
        solver: Solver::Rosenbrock,
        rtol: 1e-6,
        ledger: true,
        ..RunOptions::default()
    };
    let mut sim = Simulation::new(&v, cmd).map_err(err)?.options(opts);
    let out = sim.run(&t).map_err(err)?;
    let (k0, k1) = (n_per, 3 * n_per);
    let led = ledger(sim.circuit(), &out, k0, k1, &RodSide::of(sim.circuit()))?;
    let mut losses: Vec<(String, f64)> = led
        .losses
        .iter()
        .map(|l| (l.name.clone(), l.energy_j))
        .collect();
    losses.sort_by(|a, b| b.1.total_cmp(&a.1));
    let m = measure(&out, case, k0, k1).map_err(err)?;
    Ok(Measured {
        efficiency: led.efficiency(),
        energy_in_j: led.energy_in_j,
        ledger_error: led.error,
        losses,
        ..m
    })
}

/// Stall, drift, overrun and lowest chamber pressure over samples `k0..=k1`.
fn measure(out: &Run, case: &Case, k0: usize, k1: usize) -> Result<Measured, RigError> {
    let ch = |n: &str| {
        out.channel(n).ok_or_else(|| RigError::Invalid {
            path: format!("outputs.{n}"),
            why: "the chapter-9 study needs this output".into(),
        })
    };
    let (x, v, p1, p2) = (ch("position")?, ch("velocity")?, ch("p1")?, ch("p2")?);
    let n_half = (k1 - k0) / 4;
    // reversals at every half period: to extension at each period's start,
    // to retraction half a period later
    let mut stalls = (Vec::new(), Vec::new());
    for r in 0..4 {
        let k = k0 + r * n_half;
        let dir = if r % 2 == 0 { 1.0 } else { -1.0 };
        let end = (k + n_half).min(k1);
        let d = crate::chapter7::stall::stall_at(&out.time, v, k, dir, 0.5 * case.speed(), end)
            .unwrap_or(f64::NAN);
        if dir < 0.0 {
            stalls.0.push(d);
        } else {
            stalls.1.push(d);
        }
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let steady = (0..4)
        .map(|r| {
            let end = k0 + (r + 1) * n_half;
            let s: Vec<f64> = (end - 2 * n_half / 5..end).map(|k| v[k].abs()).collect();
            mean(&s)
        })
        .fold(0.0, f64::max);
    let peak = (k0..=k1).map(|k| v[k].abs()).fold(0.0, f64::max);
    Ok(Measured {
        efficiency: f64::NAN,
        energy_in_j: f64::NAN,
        ledger_error: f64::NAN,
        stall_s: (mean(&stalls.0), mean(&stalls.1)),
        drift_m: (x[k1] - x[k0]) / 2.0,
        overrun: peak / case.speed() - 1.0,
        steady_overrun: steady / case.speed() - 1.0,
        min_chamber_pa: (k0..=k1)
            .map(|k| p1[k].min(p2[k]))
            .fold(f64::INFINITY, f64::min),
        losses: Vec::new(),
    })
}
