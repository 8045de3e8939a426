//! Simulating the valve rig against a record: the prepared record (input,
//! compared channels, weights, initial state, stop restarts), the simulated
//! channels, the weighted output error and the NRMSE per channel.

use super::*;
use hydrocyl_system::rig;
use hydrocyl_system::simulation::Simulation;
use serde_json::Value;
use std::sync::Arc;
/// The channels compared, in report order.
pub(super) const CHANNELS: [Signal; 4] =
    [Signal::Position, Signal::Velocity, Signal::P1, Signal::P2];

#[derive(Clone)]
pub(super) struct Prepared {
    /// Relative tolerance of the simulations (looser while tracing).
    pub(super) rtol: f64,
    pub(super) t: Arc<[f64]>,
    /// The run's input: the measured command (open loop) or the position
    /// reference (a closed-loop record, whose rig's controller computes the
    /// command).
    pub(super) input: Arc<[f64]>,
    /// Whether the record is closed loop (it has a `reference` column).
    pub(super) closed: bool,
    /// The measured command at the first sample (the initial spool demand;
    /// `None` in a closed-loop record without a `command` column: the
    /// controller's output at the first sample is taken).
    pub(super) command0: Option<f64>,
    /// Measured channels present (velocity: measured, else smoothed derivative).
    pub(super) meas: Vec<(Signal, Vec<f64>)>,
    pub(super) ranges: Vec<f64>,
    /// Weight of each channel in the output error: 1/σ (its noise, floored at
    /// 1e-4 of its range); 0 for a velocity derived from position (it would
    /// count the position twice).
    pub(super) weights: Vec<f64>,
    /// Initial state estimates: smoothed position, velocity, p1, p2 at t0.
    pub(super) x0: Option<f64>,
    pub(super) v0: Option<f64>,
    pub(super) p10: Option<f64>,
    pub(super) p20: Option<f64>,
    /// Restarts of the simulation from the measured state: where the
    /// measured piston leaves a stop, and after each gap in the time axis
    /// ([`restart`]).
    pub(super) restarts: Vec<restart::Restart>,
    /// Simulations run so far (shared by every copy).
    pub(super) count: Arc<std::sync::atomic::AtomicUsize>,
    /// The latest simulations, to answer a repeated one (shared by every
    /// copy; a copy may change `rtol` and `input`, which the runs are kept
    /// by, but anything else it changes needs a fresh one).
    pub(super) recent: Arc<Recent>,
}

/// How many simulated samples [`Recent`] keeps, all runs and channels
/// together (64 MB; ~160 runs of four channels of a 12 s, 1 kHz record).
const RECENT_SAMPLES: usize = 8 << 20;

/// The latest simulations of a prepared record, each by what determines it
/// (the netlist and the roles of its components, the tolerance, the input
/// and the samples simulated), with
/// the simulated channels before the sensor lag (which acts on the samples,
/// see [`simulate`]). A repeated simulation — the diagnosis asks for some
/// twice: the round model's, a trace that ends where it started, a
/// `sensor_lag` column that changes only the lag — is answered from here
/// with the numbers a new run would give (a run is a deterministic function
/// of these).
#[derive(Default)]
pub(super) struct Recent {
    runs: std::sync::Mutex<std::collections::VecDeque<Kept>>,
}

/// One simulation kept by [`Recent`].
struct Kept {
    /// A hash of `net`'s text (compared first).
    hash: u64,
    net: Value,
    roles: Arc<model::Roles>,
    rtol: u64,
    input: Arc<[f64]>,
    n: usize,
    out: Arc<Vec<Vec<f64>>>,
}

/// A hash of a netlist's text.
fn net_hash(net: &Value) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    net.to_string().hash(&mut h);
    h.finish()
}

impl Recent {
    fn find(&self, hash: u64, rig: &Model, p: &Prepared, n: usize) -> Option<Arc<Vec<Vec<f64>>>> {
        let runs = self.runs.lock().ok()?;
        runs.iter()
            .rev()
            .find(|k| {
                k.hash == hash
                    && k.n == n
                    && k.rtol == p.rtol.to_bits()
                    && Arc::ptr_eq(&k.input, &p.input)
                    && Arc::ptr_eq(&k.roles, &rig.roles)
                    && k.net == rig.net
            })
            .map(|k| Arc::clone(&k.out))
    }

    fn keep(&self, hash: u64, rig: &Model, p: &Prepared, n: usize, out: Arc<Vec<Vec<f64>>>) {
        let size = |k: &Kept| k.out.iter().map(Vec::len).sum::<usize>();
        if let Ok(mut runs) = self.runs.lock() {
            let mut kept: usize = runs.iter().map(size).sum();
            kept += out.iter().map(Vec::len).sum::<usize>();
            while kept > RECENT_SAMPLES {
                match runs.pop_front() {
                    Some(k) => kept -= size(&k),
                    None => return,
                }
            }
            runs.push_back(Kept {
                hash,
                net: rig.net.clone(),
                roles: Arc::clone(&rig.roles),
                rtol: p.rtol.to_bits(),
                input: Arc::clone(&p.input),
                n,
                out,
            });
        }
    }
}

pub(super) fn prepare(
    rec: &Record,
    half: Option<usize>,
    excluded: &[Signal],
    stroke: f64,
) -> Result<(Prepared, crate::smooth::SmootherInfo), DiagnoseError> {
    let t = rec.time.clone();
    let closed = rec.get(Signal::Reference).is_some();
    let input = if closed {
        rec.require(Signal::Reference)?.to_vec()
    } else {
        rec.require(Signal::Command)?.to_vec()
    };
    let command0 = rec.get(Signal::Command).map(|u| u[0]);
    let x = rec.require(Signal::Position)?;
    let s = match half {
        Some(h) => smooth_with(rec, x, h, crate::smooth::ORDER)?,
        None => smooth_gcv(&t, x, crate::smooth::ORDER, 400),
    };
    let position_ok = !excluded.contains(&Signal::Position);
    let mut meas = Vec::new();
    // In closed loop the measured command is an output: compared like the others.
    let compared = CHANNELS
        .into_iter()
        .chain(closed.then_some(Signal::Command));
    for ch in compared {
        if excluded.contains(&ch) {
            continue;
        }
        match (ch, rec.get(ch)) {
            (_, Some(v)) => meas.push((ch, v.to_vec())),
            (Signal::Velocity, None) if position_ok => meas.push((ch, s.d1.clone())),
            _ => {}
        }
    }
    let ranges = meas
        .iter()
        .map(|(_, v)| {
            let lo = v.iter().copied().fold(f64::INFINITY, f64::min);
            let hi = v.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            (hi - lo).max(1e-300)
        })
        .collect();
    let weights = meas
        .iter()
        .zip(&ranges)
        .map(|((ch, y), r)| {
            if *ch == Signal::Velocity && rec.get(Signal::Velocity).is_none() {
                0.0
            } else {
                1.0 / noise_sigma(&rec.time, y).max(1e-4 * r)
            }
        })
        .collect();
    // A position left out of the fit (a data problem) gives no initial
    // state: the rig's declared one is kept.
    let v0 = match rec.get(Signal::Velocity) {
        Some(v) if !excluded.contains(&Signal::Velocity) => Some(v[0]),
        _ => position_ok.then(|| s.d1[0]),
    };
    // The first sample's noise would start the simulation off the record:
    // take the smoothed values at t0 (local cubic fit over the GCV window).
    let p0 = |sig: Signal| {
        (!excluded.contains(&sig))
            .then(|| {
                rec.get(sig)
                    .map(|y| smooth_gcv(&t, y, crate::smooth::ORDER, 100).value[0])
            })
            .flatten()
    };
    let (p10, p20) = (p0(Signal::P1), p0(Signal::P2));
    let restarts = if position_ok {
        let kept = |sig: Signal| rec.get(sig).filter(|_| !excluded.contains(&sig));
        let measured = restart::Measured {
            position: x,
            velocity: kept(Signal::Velocity),
            p1: kept(Signal::P1),
            p2: kept(Signal::P2),
        };
        restart::merged(
            stops::restarts(
                x,
                stroke,
                (5.0 * noise_sigma(&rec.time, x)).max(1e-4 * stroke),
            ),
            restart::after_gaps(&t, measured, 0.5 * stroke),
        )
    } else {
        Vec::new()
    };
    Ok((
        Prepared {
            rtol: 1e-8,
            x0: position_ok.then(|| s.value[0]),
            p10,
            p20,
            restarts,
            count: Default::default(),
            recent: Default::default(),
            t: t.into(),
            input: input.into(),
            closed,
            command0,
            meas,
            ranges,
            weights,
            v0,
        },
        s.info,
    ))
}

/// Sets the rig's initial state from the record: measured position, velocity
/// and chamber pressures at the first sample (the steady pressures of the
/// rig when p1/p2 are not measured), spool at the first command (or the
/// controller's output at the first sample).
pub(super) fn with_initial(rig: &Model, p: &Prepared) -> Model {
    let mut r = rig.clone();
    if let Some(x0) = p.x0 {
        let half = 0.5 * r.stroke();
        r.set_x0(x0.clamp(-half, half));
    }
    if let Some(v0) = p.v0 {
        r.set_v0(v0);
    }
    let ctrl = r.roles.controller.clone();
    let u0 = match (p.command0, &ctrl) {
        (Some(u), _) => u,
        (None, Some(c)) => {
            // the controller's own law, with its initial integral
            let q = |k: &str, d: f64| r.param(c, k).unwrap_or(d);
            let law = hydrocyl_system::components::PositionLaw {
                gain: q("gain", 0.0),
                integral_time: q("integral_time", 0.0),
                bias: q("bias", 0.0),
                output_min: q("output_min", -1.0),
                output_max: q("output_max", 1.0),
            };
            law.output(p.input[0] - r.x0(), q("initial.integral", 0.0))
        }
        (None, None) => 0.0,
    };
    if let Some(s) = r.roles.spool.clone() {
        let xm = r.spool_stroke();
        r.set_param(
            &s,
            "initial.position",
            Value::from((u0 * xm).clamp(-xm, xm)),
        );
        // A record that starts on a command step (a closed-loop record whose
        // reference steps at its first sample) finds the spool where the
        // motion before it left it, not at the new command: a piston at rest
        // under a first command of 0.4 has a closed spool. Where the first
        // samples' velocity is far from the steady velocity of the first
        // command (by more than half of it and 5 % of full demand's, beyond
        // the smoother's one-sided error at the first sample), the spool
        // starts at the opening that velocity needs, and follows the initial
        // velocity as it is fitted.
        let gain = super::effects::rig_facts(&r).velocity_gain;
        if let (Some(v0), Some(g)) = (p.v0, gain) {
            let v_cmd = g * u0;
            if (v0 - v_cmd).abs() > 0.5 * v_cmd.abs() + 0.05 * g {
                r.spool_per_velocity = Some(xm / g);
                r.set_v0(r.v0());
            }
        }
    }
    if r.roles.cylinder_type == "cylinder" {
        let c = r.roles.cylinder.clone();
        let declared = [r.param(&c, "initial.p1"), r.param(&c, "initial.p2")];
        let measured = [p.p10, p.p20];
        for (k, m) in ["initial.p1", "initial.p2"].into_iter().zip(measured) {
            r.set_param(&c, k, m.map_or(Value::Null, Value::from));
        }
        // Where the record gives no pressure (none measured, or left out as
        // a data problem), the rig's steady state at rest starts it; a rig
        // that has none (no four-way valve feeds the chambers: a pump's
        // closed circuit) starts from the pressures its file declares. They
        // were cleared, and the declared model did not simulate ("not
        // given, and no four-way valve feeds this cylinder's chambers").
        if measured.iter().any(Option::is_none) && rig::check(&r.net).is_err() {
            for ((k, m), d) in ["initial.p1", "initial.p2"]
                .into_iter()
                .zip(measured)
                .zip(declared)
            {
                if let (None, Some(d)) = (m, d) {
                    r.set_param(&c, k, Value::from(d));
                }
            }
        }
    }
    r
}

/// Simulates and returns, per measured channel, the simulated series.
///
/// `sensor_lag` is applied here as a measurement model on the simulated
/// samples ([`lag_samples`]) rather than by sensor states: the rig is run
/// with ideal sensors. A lag state with τ far below the integrator's
/// step makes the system stiff (the fit's first finite-difference steps
/// start from τ = 0), and the sampled filter is smooth in τ down to 0. On
/// 1 kHz records of this rig the two agree to well under the sensor noise
/// (the planted `sensor_lag` test generates its record with the states).
pub(super) fn simulate(rig: &Model, p: &Prepared) -> Result<Vec<Vec<f64>>, String> {
    simulate_prefix(rig, p, p.t.len())
}

/// [`simulate`] over the first `n` samples only (the training part needs no
/// more; at least two samples are simulated).
///
/// The circuit is assembled once. At a restart ([`restart`]) the next
/// segment starts from the last state of the one before with the piston put
/// where the record says (on the stop at rest; after a gap, at the measured
/// position, with the velocity and chamber pressures where they are
/// measured): every other state — spool, chambers, lines, pump, bristles,
/// the controller's integral — carries on. A rig whose load has no position
/// and velocity states (`<load>.x`, `<load>.v`) cannot be restarted: an
/// error, where the record has a restart.
pub(super) fn simulate_prefix(
    rig: &Model,
    p: &Prepared,
    n: usize,
) -> Result<Vec<Vec<f64>>, String> {
    let n = n.clamp(2.min(p.t.len()), p.t.len());
    let tau = rig.lag;
    if !(tau.is_finite() && tau >= 0.0) {
        return Err(format!(
            "the sensor lag must be finite and non-negative, got {tau}"
        ));
    }
    let hash = net_hash(&rig.net);
    let out = match p.recent.find(hash, rig, p, n) {
        Some(out) => out,
        None => {
            let out = Arc::new(run_prefix(rig, p, n)?);
            p.recent.keep(hash, rig, p, n, Arc::clone(&out));
            out
        }
    };
    let t = &p.t[..n];
    Ok(out
        .iter()
        .zip(&p.meas)
        .map(|(o, (ch, _))| {
            if tau > 0.0 && matches!(ch, Signal::P1 | Signal::P2) {
                lag_samples(t, o, tau)
            } else {
                o.clone()
            }
        })
        .collect())
}

/// The run behind [`simulate_prefix`]: the compared channels of `rig` over
/// the first `n` samples, before the sensor lag.
fn run_prefix(rig: &Model, p: &Prepared, n: usize) -> Result<Vec<Vec<f64>>, String> {
    let t = &p.t[..n];
    let cmd = CmdSignal::shared_table(p.t.clone(), p.input.clone()).map_err(|e| e.to_string())?;
    // only the compared channels: position and pressures are states,
    // read without evaluating the circuit at each sample
    let opts = RunOptions {
        rtol: p.rtol,
        only_channels: Some(p.meas.iter().map(|(ch, _)| ch.name().to_string()).collect()),
        ..RunOptions::default()
    };
    p.count.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let circuit = rig::circuit(&rig.net, cmd).map_err(|e| e.to_string())?;
    let names = circuit.state_names();
    let load = &rig.roles.load;
    let at = |s: &str| names.iter().position(|n| *n == format!("{load}.{s}"));
    let (kx, kv) = (at("x"), at("v"));
    let cyl = &rig.roles.cylinder;
    let chambers =
        [format!("{cyl}.p1"), format!("{cyl}.p2")].map(|c| names.iter().position(|n| *n == c));
    let mut sim = Simulation::of_circuit(circuit).options(opts);
    let mut out: Vec<Vec<f64>> = vec![Vec::with_capacity(n); p.meas.len()];
    // One segment per stretch between restarts (stop exits, gap ends).
    let mut cuts = p
        .restarts
        .iter()
        .filter(|r| r.index > 0 && r.index + 1 < n)
        .peekable();
    let on_stop = match (kx, kv) {
        (Some(kx), Some(kv)) => Some((kx, kv)),
        _ => None,
    };
    if let (Some(r), None) = (cuts.peek(), on_stop) {
        return Err(format!(
            "the record {} (restart at t = {} s), but the load `{load}` has no states `{load}.x` and `{load}.v` to put the piston there",
            r.cause.what(),
            t[r.index]
        ));
    }
    let mut a = 0;
    loop {
        let next = cuts.next();
        let b = next.map_or(n - 1, |r| r.index);
        let run = sim.run(&t[a..=b]).map_err(|e| e.to_string())?;
        // the restart sample belongs to the next segment
        let keep = if next.is_some() { b - a } else { b - a + 1 };
        for (o, (ch, _)) in out.iter_mut().zip(&p.meas) {
            let v = run
                .channel(ch.name())
                .ok_or_else(|| format!("simulation has no channel '{}'", ch.name()))?;
            o.extend_from_slice(&v[..keep]);
        }
        let Some(r) = next else { break };
        let mut x = run.state(run.time.len() - 1).to_vec();
        if let Some((kx, kv)) = on_stop {
            x[kx] = r.position;
            if let Some(v) = r.velocity {
                x[kv] = v;
            }
        }
        for (k, p) in chambers.iter().zip(r.pressures) {
            if let (Some(k), Some(p)) = (k, p) {
                x[*k] = p;
            }
        }
        sim = sim.initial_state(x);
        a = b;
    }
    Ok(out)
}

/// A first-order lag `τ dy/dt = u − y` applied to samples `u` at times `t`,
/// exact when `u` is linear between samples (first-order hold): over a step
/// `h` with `a = exp(−h/τ)` and slope `s = Δu/h`,
/// `y ← a y + (1 − a) u_k + s (h − τ (1 − a))`. It starts at rest
/// (`y_0 = u_0`), as the rig's sensor states do; `τ = 0` returns `u`.
pub fn lag_samples(t: &[f64], u: &[f64], tau: f64) -> Vec<f64> {
    let mut y = Vec::with_capacity(u.len());
    let Some(&u0) = u.first() else {
        return y;
    };
    y.push(u0);
    for k in 1..u.len().min(t.len()) {
        let h = t[k] - t[k - 1];
        let (a, tau_1a) = if tau > 0.0 {
            let a = (-h / tau).exp();
            (a, tau * (1.0 - a))
        } else {
            (0.0, 0.0)
        };
        let s = (u[k] - u[k - 1]) / h;
        let prev = y[k - 1];
        y.push(a * prev + (1.0 - a) * u[k - 1] + s * (h - tau_1a));
    }
    y
}

#[derive(Clone, Copy, PartialEq)]
pub(super) enum Part {
    All,
    Train,
    Held,
}

pub(super) fn residual(
    rig: &Model,
    p: &Prepared,
    holdout: f64,
    part: Part,
    out: &mut Vec<f64>,
) -> Result<(), String> {
    let n = p.t.len();
    let cut = ((1.0 - holdout) * n as f64) as usize;
    let sims = if part == Part::Train {
        simulate_prefix(rig, p, cut)?
    } else {
        simulate(rig, p)?
    };
    weighted(p, &sims, holdout, part, out);
    Ok(())
}

/// The weighted residual of simulated channels `sims` on `part`, channel
/// after channel (channels of weight 0 left out).
fn weighted(p: &Prepared, sims: &[Vec<f64>], holdout: f64, part: Part, out: &mut Vec<f64>) {
    let n = p.t.len();
    let cut = ((1.0 - holdout) * n as f64) as usize;
    let range = match part {
        Part::All => 0..n,
        Part::Train => 0..cut,
        Part::Held => cut..n,
    };
    out.clear();
    for ((_, m), (s, w)) in p.meas.iter().zip(sims.iter().zip(&p.weights)) {
        if *w == 0.0 {
            continue;
        }
        for i in range.clone() {
            out.push((s[i] - m[i]) * w);
        }
    }
}

/// The weighted sum of squares on the whole record of simulated channels
/// `sims` ([`rss`] on `Part::All` without simulating again; infinite where
/// the simulation failed and `sims` is empty).
pub(super) fn rss_of(p: &Prepared, sims: &[Vec<f64>], holdout: f64) -> f64 {
    if sims.len() < p.meas.len() {
        return f64::INFINITY;
    }
    let mut r = Vec::new();
    weighted(p, sims, holdout, Part::All, &mut r);
    sum_sq(&r)
}

/// The NRMSE per channel ([`nrmse_of`]) and the held-out part's
/// weighted sum of squares ([`rss`] on `Part::Held`), from one simulation.
pub(super) fn nrmse_and_held(
    rig: &Model,
    p: &Prepared,
    holdout: f64,
) -> (BTreeMap<String, f64>, f64) {
    match simulate(rig, p) {
        Ok(sims) => {
            let mut r = Vec::new();
            weighted(p, &sims, holdout, Part::Held, &mut r);
            (nrmse_of(p, &sims), sum_sq(&r))
        }
        Err(_) => (BTreeMap::new(), f64::INFINITY),
    }
}

pub(super) fn rss(rig: &Model, p: &Prepared, holdout: f64, part: Part) -> f64 {
    let mut r = Vec::new();
    match residual(rig, p, holdout, part, &mut r) {
        Ok(()) => r.iter().map(|v| v * v).sum(),
        Err(_) => f64::INFINITY,
    }
}

/// The sums of squares of the weighted residual on the whole record and on
/// its held-out part, from one simulation (the same numbers as [`rss`] on
/// `Part::All` and `Part::Held`).
pub(super) fn rss_all_held(rig: &Model, p: &Prepared, holdout: f64) -> (f64, f64) {
    let mut r = Vec::new();
    if residual(rig, p, holdout, Part::All, &mut r).is_err() {
        return (f64::INFINITY, f64::INFINITY);
    }
    (sum_sq(&r), held_sum_sq(&r, p, holdout))
}

/// The sum of squares of a residual.
pub(super) fn sum_sq(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// The sum of squares of the held-out part of a whole-record residual
/// (`residual` on `Part::All`: one block of the record's length per
/// compared channel), in the order `residual` on `Part::Held` sums it.
pub(super) fn held_sum_sq(r: &[f64], p: &Prepared, holdout: f64) -> f64 {
    let n = p.t.len();
    let cut = ((1.0 - holdout) * n as f64) as usize;
    r.chunks(n.max(1))
        .flat_map(|block| &block[cut.min(block.len())..])
        .map(|v| v * v)
        .sum()
}

/// NRMSE per measured channel of the simulated series `sims`.
pub(super) fn nrmse_of(p: &Prepared, sims: &[Vec<f64>]) -> BTreeMap<String, f64> {
    p.meas
        .iter()
        .zip(sims)
        .map(|((ch, meas), s)| (ch.name().to_string(), nrmse(meas, s)))
        .collect()
}

/// The noise floor of every channel of `p` as an NRMSE (the noise's σ over
/// the channel's range; NaN where none is measured: a velocity derived
/// from position), and the weighted sum of squares pure noise would leave
/// (weighted residuals of pure noise have unit variance).
pub(super) fn noise_floors(p: &Prepared) -> (BTreeMap<String, f64>, f64) {
    let mut floors = BTreeMap::new();
    let mut ss = 0.0;
    for (((ch, m), r), w) in p.meas.iter().zip(&p.ranges).zip(&p.weights) {
        let sig = if *w == 0.0 {
            f64::NAN
        } else {
            crate::smooth::noise_sigma(&p.t, m)
        };
        floors.insert(ch.name().to_string(), sig / r);
        if *w > 0.0 {
            ss += (sig * w).powi(2) * m.len() as f64;
        }
    }
    (floors, ss)
}

/// Noise floor of each compared channel of `p` as an NRMSE (the weights'
/// floor of 1e-4 of the range for noise-free records).
pub(super) fn compared_floors(p: &Prepared) -> BTreeMap<String, f64> {
    p.meas
        .iter()
        .zip(p.ranges.iter().zip(&p.weights))
        .filter(|(_, (_, w))| **w > 0.0)
        .map(|((ch, _), (r, w))| (ch.name().to_string(), 1.0 / (w * r)))
        .collect()
}

/// The initial state "before" starts from: `rig0` (the declared model from
/// the smoother's initial state, whose runs are `declared`) takes the
/// initial-state fit's position and velocity (`fitted`) only where no
/// compared channel's NRMSE rises by more than the acceptance rule lets an
/// effect raise it (rule 3, [`crate::accept::worsened`], against the
/// smoother's). The fit lowers the noise-weighted sum of squares, which the
/// position dominates, and on a record the declared model cannot follow (a
/// leak the position drifts with) it bought position with both pressures:
/// "before" read worse than "declared", and every effect was scored
/// against that worse start. Returns the runs "before" and, in words,
/// which initial state they start from; a failed fit is a warning.
pub(super) fn initial_state(
    rig0: &mut Model,
    fitted: Result<Model, lm::LmError>,
    declared: Vec<Vec<f64>>,
    p: &Prepared,
    floors: &BTreeMap<String, f64>,
    warnings: &mut Vec<String>,
) -> (Vec<Vec<f64>>, String) {
    let r = match fitted {
        Ok(r) => r,
        Err(e) => {
            warnings.push(format!(
                "initial-state fit: {e}; the smoother's initial position and velocity are kept"
            ));
            return (declared, "the smoother's (the fit failed)".into());
        }
    };
    let sims = simulate(&r, p).unwrap_or_default();
    match crate::accept::worsened(&nrmse_of(p, &declared), &nrmse_of(p, &sims), floors) {
        None => {
            *rig0 = r;
            (sims, "fitted on the declared model".into())
        }
        Some(why) => (
            declared,
            format!("the smoother's, kept: with the fitted ones {why}"),
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Record;
    use std::collections::BTreeMap;

    /// A record that rests on a stop needs the load's position and velocity
    /// states to restart the simulation there: a rig whose load role has
    /// none is an error naming them, not a restart that leaves the piston
    /// where the last segment ended.
    #[test]
    fn a_restart_on_a_stop_needs_the_loads_states() {
        let v = hydrocyl_system::rig::preset("leaney-moog").unwrap();
        let m = Model::new(&v).unwrap();
        let t: Vec<f64> = (0..200).map(|k| k as f64 * 1e-3).collect();
        let half = 0.5 * m.stroke();
        let p = Prepared {
            rtol: 1e-6,
            input: vec![0.0; t.len()].into(),
            closed: false,
            command0: Some(0.0),
            meas: vec![(Signal::Position, vec![0.0; t.len()])],
            ranges: vec![1.0],
            weights: vec![1.0],
            x0: None,
            v0: None,
            p10: None,
            p20: None,
            restarts: vec![restart::Restart {
                index: 100,
                cause: restart::Cause::Stop,
                position: half,
                velocity: Some(0.0),
                pressures: [None; 2],
            }],
            count: Default::default(),
            recent: Default::default(),
            t: t.into(),
        };
        assert!(simulate(&m, &p).is_ok(), "the mass has x and v");
        let mut roles = (*m.roles).clone();
        roles.load = roles.cylinder.clone();
        let no_states = Model {
            roles: std::sync::Arc::new(roles),
            ..m
        };
        let e = simulate(&no_states, &p).unwrap_err();
        assert!(
            e.contains("has no states `cylinder.x` and `cylinder.v`"),
            "{e}"
        );
    }

    /// A PI-controlled piston driven onto its extending stop (reference
    /// beyond it) rests there while the integral winds up to the output
    /// limit; when the reference comes back, the integral holds the piston
    /// on the stop until it unwinds. The loop restarts the simulation in the
    /// middle of the rest: with every state carried on (the integral among
    /// them) the restarted run is the uninterrupted one; with the integral
    /// reset (as before) the restarted controller leaves the stop at once.
    #[test]
    fn a_stop_restart_carries_the_pi_integral() {
        let v = hydrocyl_system::rig::preset("leaney-moog-closed-loop").unwrap();
        let mut m = Model::new(&v).unwrap();
        let c = m.roles.controller.clone().unwrap();
        m.set_param(&c, "integral_time", Value::from(0.5));
        let half = 0.5 * m.stroke();
        m.set_x0(half - 0.02);
        let t: Vec<f64> = (0..3000).map(|k| k as f64 * 1e-3).collect();
        let r: Vec<f64> = t
            .iter()
            .map(|&t| if t < 1.5 { half + 0.04 } else { half - 0.06 })
            .collect();
        let cmd = CmdSignal::table(t.clone(), r.clone()).unwrap();
        let opts = RunOptions {
            rtol: 1e-8,
            ..RunOptions::default()
        };
        let truth = rig::simulate(&m.net, cmd, &t, &opts).unwrap();
        let ch = |n: &str| truth.channel(n).unwrap().to_vec();
        let mut signals = BTreeMap::new();
        for (s, n) in [
            (Signal::Position, "position"),
            (Signal::P1, "p1"),
            (Signal::P2, "p2"),
            (Signal::Command, "command"),
        ] {
            signals.insert(s, ch(n));
        }
        signals.insert(Signal::Reference, r);
        let rec = Record {
            source: "pi".into(),
            time: t.clone(),
            signals,
            ignored: vec![],
            units: Default::default(),
            lines: Vec::new(),
        };
        let (mut p, _) = prepare(&rec, None, &[], m.stroke()).unwrap();
        p.rtol = 1e-8;
        assert_eq!(p.restarts.len(), 1, "one rest on the stop");
        let k = p.restarts[0].index;
        let x = ch("position");
        let u = ch("command");
        // the integral at the restart is what holds the piston there
        let names = rig::circuit(&m.net, CmdSignal::Constant { value: 0.0 })
            .unwrap()
            .state_names();
        let ki = names
            .iter()
            .position(|n| *n == format!("{c}.integral"))
            .unwrap();
        let i_rest = truth.state(k)[ki];
        assert!(i_rest > 0.02, "integral at the restart {i_rest} m s");
        let sims = simulate(&m, &p).unwrap();
        let (sx, su) = (&sims[0], &sims[4]);
        assert_eq!(p.meas[0].0, Signal::Position);
        assert_eq!(p.meas[4].0, Signal::Command);
        let dx = (k..x.len())
            .map(|i| (sx[i] - x[i]).abs())
            .fold(0.0, f64::max);
        let du = (k..u.len())
            .map(|i| (su[i] - u[i]).abs())
            .fold(0.0, f64::max);
        assert!(
            dx < 1e-5 && du < 1e-3,
            "after the restart: |dx| {dx} m, |du| {du}"
        );
        // the same restart with the integral zeroed leaves the stop early
        let from = truth.state(k).to_vec();
        let mut x0 = from.clone();
        x0[ki] = 0.0;
        let circuit = rig::circuit(
            &m.net,
            CmdSignal::table(t.clone(), p.input.to_vec()).unwrap(),
        )
        .unwrap();
        let run = Simulation::of_circuit(circuit)
            .options(opts)
            .initial_state(x0)
            .run(&t[k..])
            .unwrap();
        let xr = run.channel("position").unwrap();
        let d0 = xr
            .iter()
            .zip(&x[k..])
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        assert!(d0 > 1e-3, "a reset integral departs by {d0} m");
    }
}
