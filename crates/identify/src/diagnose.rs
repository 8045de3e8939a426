//! The loop: simulate the declared model, trace the residual to catalog
//! effects, add the ones that earn their place, refit, report.
//!
//! 1. Every record is prepared (smoothed derivatives, [`crate::smooth`]) and
//!    the declared model is simulated on it; declared parameters listed in
//!    the rig's `refit` are fitted first (output error, [`crate::lm`]).
//! 2. For every catalog effect that is off and that the rig has a balance
//!    for, its parameters are fitted on the *training* part of each record
//!    (all but the last `holdout` share) with the rest of the model held,
//!    and scored: explained share of the residual sum of squares on the whole
//!    record, on the held-out part, and the change of the Bayesian
//!    information criterion `ΔBIC = n_eff ln(RSS₁/RSS₀) + k ln n_eff` with
//!    `n_eff = n (1 − ρ)/(1 + ρ)` (ρ the residual's lag-1 autocorrelation:
//!    neighbouring samples of a record are not independent evidence).
//! 3. An effect is added when it explains at least `min_share` of the
//!    residual, at least half that on the held-out part, and lowers the BIC.
//!    The best such effect is added and *all* free parameters (declared
//!    refits and effects added so far) are refitted against the output error.
//!    Repeat until no effect earns its place.
//! 4. What is left is reported as unexplained, with the share of it that the
//!    sensor noise accounts for.

use std::collections::BTreeMap;
use std::time::Instant;

use serde::Serialize;
use thiserror::Error;

use crate::bench::{bench_signals, BenchSignals, FrictionBench, ParamRef, BENCH_EFFECTS};
use crate::catalog::EffectId;
use crate::data::{DataError, Record};
use crate::data_checks::DataProblem;
use crate::lm::{self, LmOptions};
use crate::smooth::{noise_sigma, SmootherInfo};

/// Options of the loop.
#[derive(Clone, Debug, PartialEq)]
pub struct DiagnoseOptions {
    /// Least share of the residual an effect must explain to be added.
    pub min_share: f64,
    /// Share at the end of each record held out from the tracing fit.
    pub holdout: f64,
    /// Smoother half-width; `None` chooses it by GCV.
    pub half_window: Option<usize>,
    /// Most effects added.
    pub max_effects: usize,
    /// Effects the loop may add (`None`: every applicable catalog effect).
    pub candidates: Option<Vec<EffectId>>,
}

impl Default for DiagnoseOptions {
    fn default() -> Self {
        Self {
            min_share: 0.03,
            holdout: 0.3,
            half_window: None,
            max_effects: 4,
            candidates: None,
        }
    }
}

/// Why the loop could not run.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DiagnoseError {
    /// A record is unusable.
    #[error(transparent)]
    Data(#[from] DataError),
    /// The rig declaration is unusable.
    #[error("rig: {0}")]
    Rig(String),
    /// A fit could not start.
    #[error("fit of {what}: {reason}")]
    Fit {
        /// What was being fitted.
        what: String,
        /// Why it failed.
        reason: String,
    },
    /// No records given.
    #[error("no measured records given")]
    NoData,
    /// The data checks left nothing to fit.
    #[error("{file}: nothing usable to diagnose: {why}")]
    Unusable {
        /// The record.
        file: String,
        /// The data problems, one after the other.
        why: String,
    },
}

/// One effect in the report.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EffectReport {
    /// Catalog id.
    pub id: String,
    /// Parameter values (SI), by catalog name.
    pub params: BTreeMap<String, f64>,
    /// 95 % confidence half-widths, by catalog name (`null`: not identifiable).
    pub ci95: BTreeMap<String, Option<f64>>,
    /// Share of the balance residual it explains when traced (whole record).
    pub explained_share: f64,
    /// Share it explains on the held-out segments.
    pub heldout_share: f64,
    /// Change of BIC from adding it (negative: earns its place).
    pub delta_bic: f64,
    /// Why it was rejected (absent for an added effect).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub reason: Option<String>,
}

/// A catalog effect not tried on a rig, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct NotApplicable {
    /// Catalog id.
    pub id: String,
    /// Why it does not apply.
    pub why: String,
}

/// One fitted declared parameter.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ParamReport {
    /// `Fc`, `m` or `effect.param`.
    pub name: String,
    /// Declared value.
    pub declared: f64,
    /// Value after the final refit.
    pub fitted: f64,
    /// 95 % confidence half-width (`null`: not identifiable).
    pub ci95: Option<f64>,
}

/// The machine-readable report (`--report`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Report {
    /// Rig name.
    pub rig: String,
    /// Rig kind.
    pub rig_kind: String,
    /// Record files.
    pub records: Vec<String>,
    /// Samples used, all records.
    pub samples: usize,
    /// Problems of the data found before any fit (the channel named is
    /// left out of the fit).
    pub data_problems: Vec<DataProblem>,
    /// Smoother of the first record (window chosen per record; see `smoother_windows`).
    pub smoother: SmootherInfo,
    /// Half-width chosen for each record.
    pub smoother_windows: Vec<usize>,
    /// How the initial state was estimated.
    pub initial_state: String,
    /// NRMSE per channel of the model as declared (before any refit).
    pub nrmse_declared: BTreeMap<String, f64>,
    /// NRMSE per channel before effects are added (after the declared refit).
    pub nrmse_before: BTreeMap<String, f64>,
    /// NRMSE per channel after.
    pub nrmse_after: BTreeMap<String, f64>,
    /// NRMSE the sensor noise alone would give, per channel.
    pub noise_floor: BTreeMap<String, f64>,
    /// Declared parameters refitted, with their final values.
    pub declared_refit: Vec<ParamReport>,
    /// Effects added, in order.
    pub effects_added: Vec<EffectReport>,
    /// Effects tried and rejected (last round's scores).
    pub effects_rejected: Vec<EffectReport>,
    /// Catalog effects not tried on this rig, each with the reason.
    pub effects_not_applicable: Vec<NotApplicable>,
    /// Residual sum of squares after, as a share of before.
    pub unexplained_share: f64,
    /// An out-of-catalog shape the unexplained residual resembles, if a probe
    /// explains more of it than any catalog effect.
    pub unexplained_resembles: Option<Probe>,
    /// What did not go as planned (a refit that did not converge, ...).
    pub warnings: Vec<String>,
    /// Share of what is left that sensor noise accounts for (1 = all noise).
    pub noise_share: f64,
    /// The selection rule, in words.
    pub selection: String,
    /// Wall time of each stage of the loop \[s\] (summed over rounds).
    pub wall_times_s: BTreeMap<String, f64>,
    /// Wall time of the loop \[s\].
    pub elapsed_s: f64,
}

/// Wall time per stage of the loop, for the report.
#[derive(Debug)]
pub struct StageClock {
    last: Instant,
    times: BTreeMap<String, f64>,
}

impl StageClock {
    /// A clock starting now.
    pub fn new() -> Self {
        Self {
            last: Instant::now(),
            times: BTreeMap::new(),
        }
    }

    /// Books the time since the last lap to `stage`.
    pub fn lap(&mut self, stage: &str) {
        let now = Instant::now();
        *self.times.entry(stage.to_string()).or_insert(0.0) +=
            now.duration_since(self.last).as_secs_f64();
        self.last = now;
    }

    /// The times booked, the rest of the time as `report`.
    pub fn finish(mut self) -> BTreeMap<String, f64> {
        self.lap("report");
        self.times
    }
}

impl Default for StageClock {
    fn default() -> Self {
        Self::new()
    }
}

/// Time series for plots, one per record.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordTrace {
    /// Record name.
    pub source: String,
    /// Time \[s\].
    pub t: Vec<f64>,
    /// Velocity used by the model \[m·s⁻¹\].
    pub velocity: Vec<f64>,
    /// Channel name of `measured` (e.g. `force`).
    pub channel: String,
    /// Measured channel.
    pub measured: Vec<f64>,
    /// Simulated before.
    pub before: Vec<f64>,
    /// Simulated after.
    pub after: Vec<f64>,
    /// Regressor of the first added effect (its term with unit parameter),
    /// if any effect was added.
    pub regressor: Option<(String, Vec<f64>)>,
}

/// Everything the loop produces.
#[derive(Clone, Debug)]
pub struct Outcome {
    /// The report.
    pub report: Report,
    /// Series for plots.
    pub traces: Vec<RecordTrace>,
    /// The final model.
    pub rig: FrictionBench,
}

/// NRMSE = RMSE / (max − min of the measured channel).
pub fn nrmse(measured: &[f64], simulated: &[f64]) -> f64 {
    let n = measured.len().min(simulated.len());
    if n == 0 {
        return f64::NAN;
    }
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut ss = 0.0;
    for i in 0..n {
        lo = lo.min(measured[i]);
        hi = hi.max(measured[i]);
        ss += (measured[i] - simulated[i]).powi(2);
    }
    (ss / n as f64).sqrt() / (hi - lo).max(1e-300)
}

/// Which samples a residual uses.
#[derive(Clone, Copy, PartialEq)]
enum Part {
    All,
    Train,
    Held,
}

struct Bench<'a> {
    sigs: &'a [BenchSignals],
    holdout: f64,
}

impl Bench<'_> {
    fn range(&self, s: &BenchSignals, part: Part) -> std::ops::Range<usize> {
        let n = s.t.len();
        let cut = ((1.0 - self.holdout) * n as f64) as usize;
        match part {
            Part::All => 0..n,
            Part::Train => 0..cut,
            Part::Held => cut..n,
        }
    }

    fn residual(&self, rig: &FrictionBench, part: Part, out: &mut Vec<f64>) {
        out.clear();
        for s in self.sigs {
            let sim = rig.simulate(s);
            for i in self.range(s, part) {
                out.push(s.force[i] - sim[i]);
            }
        }
    }

    fn rss(&self, rig: &FrictionBench, part: Part) -> f64 {
        let mut r = Vec::new();
        self.residual(rig, part, &mut r);
        r.iter().map(|v| v * v).sum()
    }

    /// Fits `params` of `rig` in place on `part`; returns the LM result.
    fn fit(
        &self,
        rig: &mut FrictionBench,
        params: &[ParamRef],
        part: Part,
    ) -> Result<lm::LmResult, lm::LmError> {
        let x0: Vec<f64> = params.iter().map(|p| rig.get(p)).collect();
        let (lo, hi): (Vec<f64>, Vec<f64>) = params.iter().map(|p| p.bounds()).unzip();
        let x0: Vec<f64> = x0
            .iter()
            .zip(lo.iter().zip(&hi))
            .map(|(x, (l, h))| x.clamp(*l, *h))
            .collect();
        let typ: Vec<f64> = params
            .iter()
            .zip(&x0)
            .map(|(p, x)| x.abs().max(fallback_scale(p)))
            .collect();
        let mut work = rig.clone();
        let res = lm::fit(
            |x, r| {
                for (p, v) in params.iter().zip(x) {
                    work.set(p, *v);
                }
                self.residual(&work, part, r);
                Ok(())
            },
            &x0,
            &lo,
            &hi,
            &typ,
            &LmOptions::default(),
        )?;
        for (p, v) in params.iter().zip(&res.x) {
            rig.set(p, *v);
        }
        Ok(res)
    }
}

/// A scale for a parameter whose start value is zero.
fn fallback_scale(p: &ParamRef) -> f64 {
    match p {
        ParamRef::Coulomb | ParamRef::Mass => 1.0,
        ParamRef::Effect(_, name) => match name.as_str() {
            "K" => 1e-12,
            "H" => 1e6,
            "vs" => 1e-3,
            "sigma0" => 1e4,
            "tau" => 1e-3,
            _ => 1.0,
        },
    }
}

fn n_eff(r: &[f64]) -> f64 {
    let rho = lm::lag1_autocorrelation(r).clamp(0.0, 0.999);
    (r.len() as f64 * (1.0 - rho) / (1.0 + rho)).max(2.0)
}

/// Starting values of a candidate effect's parameters: linear terms by least
/// squares on the current residual, nonlinear ones from the data's scales.
fn initial_guess(id: EffectId, rig: &FrictionBench, b: &Bench<'_>) -> BTreeMap<String, f64> {
    let mut g = BTreeMap::new();
    let sg = rig.force_sign;
    let vt = rig.friction.smoothing_velocity;
    let k = rig.get(&ParamRef::Effect(EffectId::PressureViscous, "K".into()));
    let regressor = |s: &BenchSignals, i: usize| -> f64 {
        sg * match id {
            EffectId::CoulombAsymmetry => 0.5 * (s.v[i] / vt).tanh().abs(),
            EffectId::Viscous => s.v[i],
            EffectId::PressureViscous => (s.p1[i] - s.p2[i]).powi(2) * s.v[i],
            EffectId::AccelerationFriction => k * s.a[i],
            EffectId::ExternalForce => 1.0,
            _ => 0.0,
        }
    };
    let mut r = Vec::new();
    b.residual(rig, Part::Train, &mut r);
    let (mut num, mut den) = (0.0, 0.0);
    let mut j = 0;
    for s in b.sigs {
        for i in b.range(s, Part::Train) {
            let phi = regressor(s, i);
            num += phi * r[j];
            den += phi * phi;
            j += 1;
        }
    }
    let ls = if den > 0.0 { num / den } else { 0.0 };
    let fc = rig.friction.coulomb.max(1e-3);
    let mut speeds: Vec<f64> = b
        .sigs
        .iter()
        .flat_map(|s| s.v.iter().map(|v| v.abs()))
        .filter(|v| *v > 10.0 * vt)
        .collect();
    let vmed = if speeds.is_empty() {
        1e-2
    } else {
        let m = speeds.len() / 2;
        *speeds.select_nth_unstable_by(m, f64::total_cmp).1
    };
    match id {
        EffectId::CoulombAsymmetry => {
            g.insert("dFc".into(), ls);
        }
        EffectId::Viscous => {
            g.insert("b".into(), ls);
        }
        EffectId::PressureViscous => {
            g.insert("K".into(), ls);
        }
        EffectId::AccelerationFriction => {
            g.insert("H".into(), ls);
        }
        EffectId::ExternalForce => {
            g.insert("F0".into(), ls);
        }
        EffectId::Stribeck => {
            g.insert("Fs".into(), 1.5 * fc);
            g.insert("vs".into(), (0.3 * vmed).clamp(2e-5, 0.5));
            g.insert("alpha".into(), 1.0);
        }
        EffectId::LugreDynamics => {
            // Presliding range Fc/σ0 of about 50 µm; little micro-damping.
            let s0 = (fc / 5e-5).clamp(1e3, 1e9);
            g.insert("sigma0".into(), s0);
            g.insert("sigma1".into(), 0.01 * (s0 * rig.mass.max(1e-2)).sqrt());
        }
        _ => {}
    }
    g
}

/// An explanation of the residual that is *not* in the catalog, tried so that
/// a residual of foreign shape is not dressed up as the nearest catalog effect.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Probe {
    /// Short name: `delay` or `spring`.
    pub kind: String,
    /// What it is (`"time shift of the measured force"`, `"force proportional to position"`).
    pub what: String,
    /// Its fitted size (delay \[s\] or stiffness \[N·m⁻¹\]).
    pub value: f64,
    /// Share of the residual it explains.
    pub explained_share: f64,
}

/// Out-of-catalog probes on the current model: a time shift of the measured
/// force (transport delay, up to ±40 samples) and a force proportional to
/// the position (a spring the catalog lacks).
fn probes(rig: &FrictionBench, sigs: &[BenchSignals]) -> Vec<Probe> {
    let sims: Vec<Vec<f64>> = sigs.iter().map(|s| rig.simulate(s)).collect();
    let rss0: f64 = sigs
        .iter()
        .zip(&sims)
        .flat_map(|(s, f)| s.force.iter().zip(f).map(|(a, b)| (a - b).powi(2)))
        .sum::<f64>()
        .max(1e-300);
    let mut out = Vec::new();
    // Delay: the measurement lags the model by τ.
    let dt = crate::smooth::median_step(&sigs[0].t);
    let mut best = (0.0, rss0);
    for k in (-40i32..=40).filter(|k| *k != 0) {
        let tau = k as f64 * dt;
        let rss: f64 = sigs
            .iter()
            .zip(&sims)
            .map(|(s, f)| {
                s.t.iter()
                    .zip(&s.force)
                    .map(|(&t, &m)| (m - crate::data::interp_linear(&s.t, f, t - tau)).powi(2))
                    .sum::<f64>()
            })
            .sum();
        if rss < best.1 {
            best = (tau, rss);
        }
    }
    out.push(Probe {
        kind: "delay".into(),
        what: "time shift of the measured force (transport delay)".into(),
        value: best.0,
        explained_share: 1.0 - best.1 / rss0,
    });
    // Spring: residual ∝ position.
    let (mut num, mut den) = (0.0, 0.0);
    for (s, f) in sigs.iter().zip(&sims) {
        for ((x, m), f) in s.x.iter().zip(&s.force).zip(f) {
            let phi = rig.force_sign * x;
            num += phi * (m - f);
            den += phi * phi;
        }
    }
    let k = if den > 0.0 { num / den } else { 0.0 };
    out.push(Probe {
        kind: "spring".into(),
        what: "force proportional to position (spring)".into(),
        value: k,
        explained_share: num * k / rss0,
    });
    out
}

/// Runs the loop on a friction bench.
pub fn diagnose_bench(
    rig: &FrictionBench,
    records: &[Record],
    opts: &DiagnoseOptions,
    progress: &mut dyn FnMut(&str, usize, usize),
) -> Result<Outcome, DiagnoseError> {
    let start = Instant::now();
    rig.validate()
        .map_err(|e| DiagnoseError::Rig(e.to_string()))?;
    if records.is_empty() {
        return Err(DiagnoseError::NoData);
    }
    // Data problems that need no rig facts; the bench's output is the force,
    // so a constant force leaves nothing to fit.
    let mut data_problems = Vec::new();
    for r in records {
        let problems = crate::data_checks::check_record(r, None);
        if let Some(p) = problems
            .iter()
            .find(|p| p.channel == "force" && p.kind == crate::data_checks::ProblemKind::Constant)
        {
            return Err(DiagnoseError::Unusable {
                file: r.source.clone(),
                why: p.message.clone(),
            });
        }
        data_problems.extend(problems);
    }
    let mut sigs = Vec::new();
    let mut windows = Vec::new();
    let mut smoother = None;
    for r in records {
        let (s, info) = bench_signals(r, opts.half_window, rig.steady_state)?;
        windows.push(info.half_window);
        smoother.get_or_insert(info);
        sigs.push(s);
    }
    let b = Bench {
        sigs: &sigs,
        holdout: opts.holdout,
    };
    let measured: Vec<f64> = sigs.iter().flat_map(|s| s.force.iter().copied()).collect();
    let sim_all =
        |rig: &FrictionBench| -> Vec<f64> { sigs.iter().flat_map(|s| rig.simulate(s)).collect() };
    let channel = |rig: &FrictionBench| -> BTreeMap<String, f64> {
        let mut m = BTreeMap::new();
        m.insert("force".to_string(), nrmse(&measured, &sim_all(rig)));
        m
    };
    let nrmse_declared = channel(rig);
    // Declared refit.
    let mut model = rig.clone();
    let refit: Vec<ParamRef> = rig
        .refit
        .iter()
        .filter_map(|s| ParamRef::parse(s))
        .collect();
    let total_steps = 2 + opts.max_effects;
    progress("declared refit", 0, total_steps);
    if !refit.is_empty() {
        b.fit(&mut model, &refit, Part::All)
            .map_err(|e| DiagnoseError::Fit {
                what: "declared parameters".into(),
                reason: e.to_string(),
            })?;
    }
    let before = model.clone();
    let nrmse_before = channel(&model);
    let rss_before = b.rss(&model, Part::All);
    let candidates: Vec<EffectId> = opts
        .candidates
        .clone()
        .unwrap_or_else(|| EffectId::ALL.to_vec())
        .into_iter()
        .filter(|e| BENCH_EFFECTS.contains(e))
        // Steady-state tables have no time: no bristle dynamics, no acceleration.
        .filter(|e| {
            !(rig.steady_state
                && matches!(e, EffectId::LugreDynamics | EffectId::AccelerationFriction))
        })
        .collect();
    let mut added: Vec<EffectReport> = Vec::new();
    let mut last_scores: BTreeMap<EffectId, EffectReport> = BTreeMap::new();
    let mut free: Vec<ParamRef> = refit.clone();
    let mut first_added: Option<EffectId> = None;
    let mut resembles: Option<Probe> = None;
    for round in 0..opts.max_effects {
        progress("tracing", round + 1, total_steps);
        let mut r0 = Vec::new();
        b.residual(&model, Part::All, &mut r0);
        let rss0: f64 = r0.iter().map(|v| v * v).sum();
        let rss0_held = b.rss(&model, Part::Held);
        let neff = n_eff(&r0);
        let mut best: Option<(EffectId, FrictionBench, EffectReport)> = None;
        for &id in &candidates {
            if model.has(id) {
                continue;
            }
            if id == EffectId::AccelerationFriction
                && model.get(&ParamRef::Effect(EffectId::PressureViscous, "K".into())) == 0.0
            {
                last_scores.insert(
                    id,
                    EffectReport {
                        id: id.id().into(),
                        params: BTreeMap::new(),
                        ci95: BTreeMap::new(),
                        explained_share: 0.0,
                        heldout_share: 0.0,
                        delta_bic: 0.0,
                        reason: Some("needs pressure_viscous's K (term is K H a, eq 5.12)".into()),
                    },
                );
                continue;
            }
            let mut trial = model.clone();
            let guess = initial_guess(id, &model, &b);
            let params: Vec<ParamRef> = id
                .params()
                .iter()
                .map(|p| ParamRef::Effect(id, p.name.to_string()))
                .collect();
            for p in &params {
                let v = guess.get(param_name(p)).copied().unwrap_or(0.0);
                let (lo, hi) = p.bounds();
                trial.set(p, v.clamp(lo, hi));
            }
            let fit = b.fit(&mut trial, &params, Part::Train);
            let rss1 = b.rss(&trial, Part::All);
            let rss1_held = b.rss(&trial, Part::Held);
            let share = 1.0 - rss1 / rss0.max(1e-300);
            let held = 1.0 - rss1_held / rss0_held.max(1e-300);
            let k = params.len() as f64;
            let dbic = neff * (rss1 / rss0.max(1e-300)).ln() + k * neff.ln();
            let mut rep = EffectReport {
                id: id.id().into(),
                params: params
                    .iter()
                    .map(|p| (param_name(p).to_string(), trial.get(p)))
                    .collect(),
                ci95: BTreeMap::new(),
                explained_share: share,
                heldout_share: held,
                delta_bic: dbic,
                reason: None,
            };
            if let Err(e) = &fit {
                rep.reason = Some(format!("fit failed: {e}"));
            } else if share < opts.min_share {
                rep.reason = Some(format!(
                    "explains {:.1} % < {:.1} %",
                    100.0 * share,
                    100.0 * opts.min_share
                ));
            } else if held < 0.5 * opts.min_share {
                rep.reason = Some(format!(
                    "held-out share {:.1} %: does not generalise",
                    100.0 * held
                ));
            } else if dbic >= 0.0 {
                rep.reason = Some(format!("BIC does not fall (ΔBIC = {dbic:.1})"));
            }
            if rep.reason.is_none()
                && best
                    .as_ref()
                    .is_none_or(|(_, _, r)| share > r.explained_share)
            {
                best = Some((id, trial, rep.clone()));
            }
            last_scores.insert(id, rep);
        }
        let probe = if rig.steady_state {
            Vec::new()
        } else {
            probes(&model, &sigs)
        }
        .into_iter()
        .max_by(|a, b| a.explained_share.total_cmp(&b.explained_share));
        if let Some(p) = &probe {
            if p.explained_share >= opts.min_share
                && best
                    .as_ref()
                    .is_none_or(|(_, _, r)| p.explained_share > r.explained_share + opts.min_share)
            {
                if let Some((id, _, _)) = &best {
                    if let Some(r) = last_scores.get_mut(id) {
                        r.reason = Some(format!(
                            "the residual is better explained by a {} ({:.1} %), which is not in the catalog",
                            p.what,
                            100.0 * p.explained_share
                        ));
                    }
                }
                resembles = Some(p.clone());
                break;
            }
        }
        let Some((id, trial, mut rep)) = best else {
            break;
        };
        // Refit every free parameter against the output error.
        model = trial;
        for p in id.params() {
            free.push(ParamRef::Effect(id, p.name.to_string()));
        }
        progress("refit", round + 1, total_steps);
        let res = b
            .fit(&mut model, &free, Part::All)
            .map_err(|e| DiagnoseError::Fit {
                what: id.id().into(),
                reason: e.to_string(),
            })?;
        // Report the effect's refitted values and intervals.
        for (p, (x, ci)) in free.iter().zip(res.x.iter().zip(&res.ci95)) {
            if let ParamRef::Effect(e, name) = p {
                for a in added.iter_mut().chain(std::iter::once(&mut rep)) {
                    if a.id == e.id() {
                        a.params.insert(name.clone(), *x);
                        a.ci95.insert(name.clone(), ci.is_finite().then_some(*ci));
                    }
                }
            }
        }
        last_scores.remove(&id);
        first_added.get_or_insert(id);
        added.push(rep);
    }
    // Final intervals of the declared refits.
    let mut declared_refit = Vec::new();
    if !free.is_empty() {
        let mut m2 = model.clone();
        let res = b
            .fit(&mut m2, &free, Part::All)
            .map_err(|e| DiagnoseError::Fit {
                what: "final refit".into(),
                reason: e.to_string(),
            })?;
        model = m2;
        for (p, (x, ci)) in free.iter().zip(res.x.iter().zip(&res.ci95)) {
            match p {
                ParamRef::Effect(e, name) if !rig.has(*e) => {
                    for a in added.iter_mut() {
                        if a.id == e.id() {
                            a.params.insert(name.clone(), *x);
                            a.ci95.insert(name.clone(), ci.is_finite().then_some(*ci));
                        }
                    }
                }
                _ => declared_refit.push(ParamReport {
                    name: p.label(),
                    declared: rig.get(p),
                    fitted: *x,
                    ci95: ci.is_finite().then_some(*ci),
                }),
            }
        }
    }
    progress("report", total_steps, total_steps);
    let nrmse_after = channel(&model);
    let rss_after = b.rss(&model, Part::All);
    // The floor: load-cell noise plus the pressure sensors' noise carried
    // into the prediction by the areas (the balance is linear in both).
    let noise_ss: f64 = sigs
        .iter()
        .map(|s| {
            let var = noise_sigma(&s.force).powi(2)
                + (rig.area1 * noise_sigma(&s.p1)).powi(2)
                + (rig.area2 * noise_sigma(&s.p2)).powi(2);
            var * s.force.len() as f64
        })
        .sum();
    let range = {
        let lo = measured.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = measured.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (hi - lo).max(1e-300)
    };
    // A steady-state table is not a time series: no noise estimate from it.
    let noise_ss = if rig.steady_state { f64::NAN } else { noise_ss };
    let mut noise_floor = BTreeMap::new();
    noise_floor.insert(
        "force".to_string(),
        (noise_ss / measured.len() as f64).sqrt() / range,
    );
    let traces = sigs
        .iter()
        .map(|s| {
            // Show friction (the force minus the pressure force), not the
            // pressure-dominated load-cell force.
            let pf: Vec<f64> = (0..s.t.len())
                .map(|i| rig.force_sign * (rig.area2 * s.p2[i] - rig.area1 * s.p1[i]))
                .collect();
            let minus =
                |y: Vec<f64>| -> Vec<f64> { y.iter().zip(&pf).map(|(a, b)| a - b).collect() };
            RecordTrace {
                source: s.source.clone(),
                t: s.t.clone(),
                velocity: s.v.clone(),
                channel: "friction".into(),
                measured: minus(s.force.clone()),
                before: minus(before.simulate(s)),
                after: minus(model.simulate(s)),
                regressor: first_added.map(|id| {
                    let vt = model.friction.smoothing_velocity;
                    let k = model.get(&ParamRef::Effect(EffectId::PressureViscous, "K".into()));
                    let phi: Vec<f64> = (0..s.t.len())
                        .map(|i| match id {
                            EffectId::CoulombAsymmetry => 0.5 * (s.v[i] / vt).tanh().abs(),
                            EffectId::Viscous | EffectId::Stribeck | EffectId::LugreDynamics => {
                                s.v[i]
                            }
                            EffectId::PressureViscous => (s.p1[i] - s.p2[i]).powi(2) * s.v[i],
                            EffectId::AccelerationFriction => k * s.a[i],
                            _ => 1.0,
                        })
                        .collect();
                    (id.id().to_string(), phi)
                }),
            }
        })
        .collect();
    let rejected: Vec<EffectReport> = last_scores.into_values().collect();
    let report = Report {
        rig: rig.name.clone(),
        rig_kind: "friction-bench".into(),
        records: records.iter().map(|r| r.source.clone()).collect(),
        samples: measured.len(),
        data_problems,
        smoother: smoother.expect("at least one record"),
        smoother_windows: windows,
        initial_state: if rig.has(EffectId::LugreDynamics) || added.iter().any(|a| a.id == "lugre_dynamics") {
            "motion imposed by the drive (measured); bristle state z0 from the mean friction of the first 5 samples, limited to |z0| <= g(v0)/sigma0".into()
        } else {
            "motion imposed by the drive (measured); static friction law has no state".into()
        },
        nrmse_declared,
        nrmse_before,
        nrmse_after,
        noise_floor,
        declared_refit,
        effects_added: added,
        effects_rejected: rejected,
        effects_not_applicable: EffectId::ALL
            .iter()
            .filter(|e| !BENCH_EFFECTS.contains(e))
            .map(|e| NotApplicable {
                id: e.id().to_string(),
                why: format!(
                    "the friction bench has only the force balance; {} belongs to the {:?} balance",
                    e.id(),
                    e.balance()
                ),
            })
            .collect(),
        unexplained_share: rss_after / rss_before.max(1e-300),
        unexplained_resembles: resembles,
        warnings: Vec::new(),
        noise_share: if noise_ss.is_nan() {
            f64::NAN
        } else {
            (noise_ss / rss_after.max(1e-300)).min(1.0)
        },
        selection: format!(
            "add the effect explaining the largest share of the force-balance residual if share >= {:.0} %, held-out share >= {:.1} % (last {:.0} % of each record) and BIC falls (n_eff from lag-1 autocorrelation); refit all free parameters on the output error",
            100.0 * opts.min_share,
            50.0 * opts.min_share,
            100.0 * opts.holdout
        ),
        wall_times_s: BTreeMap::from([("total".to_string(), start.elapsed().as_secs_f64())]),
        elapsed_s: start.elapsed().as_secs_f64(),
    };
    Ok(Outcome {
        report,
        traces,
        rig: model,
    })
}

impl Report {
    /// The human report: a table of NRMSE before/after and the effects.
    pub fn human(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let _ = writeln!(
            s,
            "diagnose: rig '{}' ({}), {} samples in {} record(s)",
            self.rig,
            self.rig_kind,
            self.samples,
            self.records.len()
        );
        let _ = writeln!(
            s,
            "smoother: {} order {}, half-window {} ({:.3} s, {}); windows per record {:?}",
            self.smoother.method,
            self.smoother.order,
            self.smoother.half_window,
            self.smoother.window_s,
            self.smoother.criterion,
            self.smoother_windows
        );
        let _ = writeln!(s, "initial state: {}", self.initial_state);
        if !self.data_problems.is_empty() {
            let _ = writeln!(s, "\ndata problems (channel left out of the fit):");
            for p in &self.data_problems {
                let kind = serde_json::to_value(p.kind)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_string))
                    .unwrap_or_default();
                let _ = writeln!(s, "  {:<10} {:<10} {}", p.channel, kind, p.message);
            }
        }
        let _ = writeln!(
            s,
            "\n{:<10} {:>10} {:>10} {:>10} {:>12}",
            "channel", "declared", "before", "after", "noise floor"
        );
        let num = |v: Option<&f64>| match v {
            Some(v) if v.is_finite() => format!("{v:.3e}"),
            _ => "n/a".to_string(),
        };
        for (k, v) in &self.nrmse_after {
            let _ = writeln!(
                s,
                "{:<10} {:>10} {:>10} {:>10} {:>12}",
                k,
                num(self.nrmse_declared.get(k)),
                num(self.nrmse_before.get(k)),
                num(Some(v)),
                num(self.noise_floor.get(k))
            );
        }
        if !self.declared_refit.is_empty() {
            let _ = writeln!(s, "\ndeclared parameters refitted:");
            for p in &self.declared_refit {
                let _ = writeln!(
                    s,
                    "  {:<24} {:>12.5e} -> {:>12.5e} ± {}",
                    p.name,
                    p.declared,
                    p.fitted,
                    fmt_ci(p.ci95)
                );
            }
        }
        let _ = writeln!(s, "\neffects added (in order):");
        if self.effects_added.is_empty() {
            let _ = writeln!(s, "  none");
        }
        for e in &self.effects_added {
            let _ = writeln!(
                s,
                "  {:<22} explains {:5.1} % (held-out {:5.1} %, ΔBIC {:.0})",
                e.id,
                100.0 * e.explained_share,
                100.0 * e.heldout_share,
                e.delta_bic
            );
            for (k, v) in &e.params {
                let ci = e.ci95.get(k).copied().flatten();
                let _ = writeln!(s, "      {k} = {v:.5e} ± {}", fmt_ci(ci));
            }
        }
        let _ = writeln!(s, "\neffects tried and rejected:");
        for e in &self.effects_rejected {
            let _ = writeln!(s, "  {:<22} {}", e.id, e.reason.as_deref().unwrap_or(""));
        }
        if !self.effects_not_applicable.is_empty() {
            let _ = writeln!(s, "\neffects not applicable to this rig:");
            for e in &self.effects_not_applicable {
                let _ = writeln!(s, "  {:<22} {}", e.id, e.why);
            }
        }
        let noise = if self.noise_share.is_finite() {
            format!(
                "sensor noise accounts for {:.0} % of what is left",
                100.0 * self.noise_share
            )
        } else {
            "no noise estimate".to_string()
        };
        let _ = writeln!(
            s,
            "\nunexplained: {:.1} % of the residual before is left; {noise}{}",
            100.0 * self.unexplained_share,
            if self.noise_share < 0.5 {
                " — structured residual no catalog effect explains"
            } else {
                ""
            }
        );
        if let Some(p) = &self.unexplained_resembles {
            let _ = writeln!(
                s,
                "the unexplained residual resembles a {} (size {:.4e}, {:.1} % of the residual) — not a catalog effect",
                p.what,
                p.value,
                100.0 * p.explained_share
            );
        }
        for w in &self.warnings {
            let _ = writeln!(s, "warning: {w}");
        }
        let stages: Vec<String> = self
            .wall_times_s
            .iter()
            .map(|(k, v)| format!("{k} {v:.2} s"))
            .collect();
        let _ = writeln!(s, "time: {:.2} s ({})", self.elapsed_s, stages.join(", "));
        s
    }
}

/// The catalog name of a parameter (`K` of `pressure_viscous.K`).
fn param_name(p: &ParamRef) -> &str {
    match p {
        ParamRef::Coulomb => "Fc",
        ParamRef::Mass => "m",
        ParamRef::Effect(_, n) => n,
    }
}

fn fmt_ci(ci: Option<f64>) -> String {
    ci.map_or_else(|| "n/a".to_string(), |c| format!("{c:.2e} (95 %)"))
}
