//! The loop on the valve-controlled rig (`valve-cylinder`, preset
//! `leaney-moog`, assembled by hydrocyl-system): output-error simulation on
//! the measured command from the measured initial state, effect tracing by
//! output error, LM refits.
//!
//! ```text
//!   command u ─▶ servovalve (xb, kw) ─▶ chambers p1, p2 (Cl, Ce1, Ce2, B) ─▶ piston x, v (F0, b)
//!                                          measured: position, [velocity], p1, p2
//! ```
//!
//! Catalog effects that the rig file already has as parameters are switched
//! by those parameters: `valve_null_bias` (valve.null_bias_m), `flow_gain_error`
//! (valve.flow_gain), `internal_leakage` and `external_leakage`
//! (cylinder.*_leakage), `bulk_modulus` (fluid.bulk_modulus_pa),
//! `external_force` (load.external_force_n, + opposing extension),
//! `viscous` (the coulomb-viscous law's b), `supply_droop`
//! (supply.droop_resistance_pa_s_per_m3) and `sensor_lag`
//! (sensors.pressure_lag_s: the simulated p1/p2 are then the lagged sensor
//! readings the record is compared with) and `valve_dead_band`
//! (valve.dead_band_m). An effect is "off" at its neutral
//! value (0, or kw = 1); `bulk_modulus` is always declared, so tracing it
//! means refitting B away from the declared value.
//!
//! Tracing here is by output error, not equation error: each candidate's
//! parameters are estimated on the training part of the record by two
//! Gauss–Newton steps of the simulated whole rig, and scored by the share of the output-error sum of squares they
//! remove, each channel weighted by the inverse of its noise level (the
//! maximum-likelihood weighting for Gaussian sensor noise) (whole record, held-out part, ΔBIC). The valve rig
//! simulates 3 s in about 20 ms, so this is affordable and avoids the
//! chamber-volume and spool-state reconstruction an equation-error flow
//! residual needs.

use std::collections::BTreeMap;
use std::time::Instant;

use hydrocyl_system::run::RunOptions;
use hydrocyl_system::signal::Signal as CmdSignal;
use hydrocyl_system::valve_rig::ValveRig;

use crate::catalog::EffectId;
use crate::data::{Record, Signal};
use crate::data_checks::{
    check_record, input_errors, missing_channels, position_outliers, pressure_scale_problems,
    travel_error, unit_errors, ProblemKind, RigFacts,
};
use crate::diagnose::{
    nrmse, Applicable, DiagnoseError, DiagnoseOptions, EffectReport, NotApplicable, Probe,
    RecordTrace, RejectedEffect, Report,
};
use crate::lm::{self, LmOptions};
use crate::smooth::{noise_sigma, smooth_gcv, smooth_with};

mod accept;
mod effects;
mod fit;
pub mod model;
mod pairs;
mod probes;
mod report;
mod restart;
mod sim;
mod stops;

use effects::*;
pub use effects::{is_on, rig_facts};
use fit::*;
pub use model::Model;
use probes::{best_probe, gain_probe};
use report::{not_applicable_why, traces};
pub use sim::lag_samples;
use sim::*;

/// A rig whose catalog effects can be read and set: a [`Model`] (any
/// netlist), or a `valve-cylinder` rig value (through its netlist).
pub trait Effects {
    /// Value of catalog parameter `name` of effect `id` (SI); `None` where
    /// the rig has no component the effect acts on.
    fn effect(&self, id: EffectId, name: &str) -> Option<f64>;
    /// Sets catalog parameter `name` of effect `id` (nothing where the rig
    /// has no component it acts on).
    fn set_effect(&mut self, id: EffectId, name: &str, v: f64);
}

impl Effects for Model {
    fn effect(&self, id: EffectId, name: &str) -> Option<f64> {
        effects::read_effect(self, id, name)
    }
    fn set_effect(&mut self, id: EffectId, name: &str, v: f64) {
        effects::write_effect(self, id, name, v);
    }
}

impl Effects for ValveRig {
    fn effect(&self, id: EffectId, name: &str) -> Option<f64> {
        Model::from_valve_rig(self)
            .ok()
            .and_then(|m| m.effect(id, name))
    }
    /// Through the rig's netlist and back; a rig that does not convert
    /// (it does not validate) is left as it is.
    fn set_effect(&mut self, id: EffectId, name: &str, v: f64) {
        if let Ok(mut m) = Model::from_valve_rig(self) {
            m.set_effect(id, name, v);
            if let Ok(r) = m.to_valve_rig() {
                *self = r;
            }
        }
    }
}

/// Value of catalog parameter `name` of effect `id` in `rig` (SI).
pub fn get<R: Effects + ?Sized>(rig: &R, id: EffectId, name: &str) -> Option<f64> {
    rig.effect(id, name)
}

/// Sets catalog parameter `name` of effect `id` in `rig`.
pub fn set<R: Effects + ?Sized>(rig: &mut R, id: EffectId, name: &str, v: f64) {
    rig.set_effect(id, name, v);
}

/// A candidate whose first linearised trace step explains less than this
/// share of `--min-share` is not traced further (see `gauss_newton_trace`).
const SCREEN_SHARE: f64 = 1.0 / 3.0;

/// Everything the loop on the valve rig produces: the report, the series for
/// plots (one [`RecordTrace`] per compared channel: measured, the declared
/// model after its initial-state fit, and the final model) and the final rig.
#[derive(Clone, Debug)]
pub struct ValveOutcome {
    /// The report.
    pub report: Report,
    /// Measured vs simulated before and after, per channel (SI units).
    pub traces: Vec<RecordTrace>,
    /// The final model: the declared rig with the added effects, refitted.
    pub rig: Model,
}

/// Runs the loop on a valve-controlled rig and one record (command,
/// position, optionally velocity, p1, p2).
pub fn diagnose_valve(
    declared: &ValveRig,
    rec: &Record,
    opts: &DiagnoseOptions,
    progress: &mut dyn FnMut(&str, usize, usize),
) -> Result<Report, DiagnoseError> {
    diagnose_valve_traced(declared, rec, opts, progress).map(|o| o.report)
}

/// [`diagnose_rig_traced`] on a `valve-cylinder` rig value (its netlist).
pub fn diagnose_valve_traced(
    declared: &ValveRig,
    rec: &Record,
    opts: &DiagnoseOptions,
    progress: &mut dyn FnMut(&str, usize, usize),
) -> Result<ValveOutcome, DiagnoseError> {
    let m = Model::from_valve_rig(declared).map_err(DiagnoseError::Rig)?;
    diagnose_rig_traced(&m, rec, opts, progress)
}

/// Runs the loop on any netlist rig with a cylinder on a mass (the valve
/// rig, the hybrid rig, a user's circuit) and one record.
pub fn diagnose_rig(
    declared: &Model,
    rec: &Record,
    opts: &DiagnoseOptions,
    progress: &mut dyn FnMut(&str, usize, usize),
) -> Result<Report, DiagnoseError> {
    diagnose_rig_traced(declared, rec, opts, progress).map(|o| o.report)
}

/// [`diagnose_rig`], also returning the measured and simulated series
/// before and after (the runs the report's NRMSEs come from) and the final rig.
pub fn diagnose_rig_traced(
    declared: &Model,
    rec: &Record,
    opts: &DiagnoseOptions,
    progress: &mut dyn FnMut(&str, usize, usize),
) -> Result<ValveOutcome, DiagnoseError> {
    let start = Instant::now();
    let mut clock = crate::diagnose::StageClock::new();
    match (
        rec.get(Signal::Reference).is_some(),
        declared.roles.controller.is_some(),
    ) {
        (true, false) => {
            return Err(DiagnoseError::Rig(format!(
                "{}: the record has a `reference` column (closed loop), but rig `{}` has no controller: use a closed-loop rig (e.g. the `leaney-moog-closed-loop` preset)",
                rec.source, declared.roles.name
            )))
        }
        (false, true) => {
            return Err(DiagnoseError::Rig(format!(
                "{}: rig `{}` is closed loop (it has a controller), but the record has no `reference` column to drive it",
                rec.source, declared.roles.name
            )))
        }
        _ => {}
    }
    // The record's channels are compared with the circuit's outputs of
    // their names: a netlist without them (no `outputs`, so that every
    // probe is named `component.probe`) is named here, with the outputs to
    // add (it failed in the declared run, "channel `position`: the circuit
    // has no such output", naming no JSON path)
    let mut wanted = vec!["position", "velocity"];
    wanted.extend(
        [
            (Signal::P1, "p1"),
            (Signal::P2, "p2"),
            (Signal::Reference, "command"),
        ]
        .into_iter()
        .filter(|(s, _)| rec.get(*s).is_some())
        .map(|(_, n)| n),
    );
    let missing = declared.missing_outputs(&wanted);
    if !missing.is_empty() {
        return Err(DiagnoseError::Rig(format!(
            "`outputs`: the record's {} compared with the circuit's outputs of those names, which rig `{}` lacks: name them, `\"outputs\": {{{}}}` (docs/netlist.md, the identification section)",
            missing
                .iter()
                .map(|(n, _)| format!("`{n}`"))
                .collect::<Vec<_>>()
                .join(", ")
                + if missing.len() == 1 { " is" } else { " are" },
            declared.roles.name,
            missing
                .iter()
                .map(|(n, p)| format!("\"{n}\": \"{p}\""))
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    // Data problems first: each channel named and left out is not fitted.
    let facts = rig_facts(declared);
    let mut data_problems = check_record(rec, Some(&facts));
    position_outliers(rec, &facts, &data_problems)?;
    unit_errors(rec, &facts, &data_problems)?;
    input_errors(rec, &facts)?;
    // the compared channels the record lacks (a position is required)
    let compared: &[Signal] = match rec.get(Signal::Reference) {
        Some(_) => &[Signal::P1, Signal::P2, Signal::Command],
        None => &[Signal::P1, Signal::P2],
    };
    data_problems.extend(missing_channels(rec, compared));
    // Twice at most: pressures whose scale contradicts the declared model's
    // first run on this command are left out, and the record prepared again.
    let mut scale_checked = false;
    let (p, info, pt, mut rig0, sims_declared, initial_fit) = loop {
        let mut excluded: Vec<Signal> = data_problems
            .iter()
            .filter(|p| p.left_out)
            .filter_map(|p| Signal::from_name(&p.channel))
            .collect();
        if data_problems.iter().any(|p| p.kind == ProblemKind::Sign) {
            excluded.push(Signal::Velocity);
        }
        let (p, info) = prepare(rec, opts.half_window, &excluded, declared.stroke())?;
        if p.weights.iter().all(|w| *w == 0.0) {
            let why = if data_problems.is_empty() {
                "no measured channel to compare (position, velocity, p1, p2)".to_string()
            } else {
                data_problems
                    .iter()
                    .map(|p| p.message.as_str())
                    .collect::<Vec<_>>()
                    .join("; ")
            };
            return Err(DiagnoseError::Unusable {
                file: rec.source.clone(),
                why,
            });
        }
        let rig0 = with_initial(declared, &p);
        // Tracing compares candidates with each other, and the initial-state
        // fit below only starts the refits: a looser integration tolerance is
        // enough there. The refits use the tight one (a loose one puts
        // integration noise into the finite-difference Jacobian, which narrows
        // the confidence intervals below their coverage).
        let pt = Prepared {
            rtol: 1e-6,
            ..p.clone()
        };
        // The declared model's own refit: the initial position and velocity
        // only (the nuisance parameters of every later fit), so that what the
        // effects are scored against is not an initial transient.
        // (the declared model's own run alongside: it waits for nothing)
        let (sims_declared, initial_fit) = {
            let mut r = rig0.clone();
            let (declared_run, fitted) = rayon::join(
                || simulate(&rig0, &p),
                || fit(&mut r, &Vec::new(), &pt, opts.holdout, Part::All),
            );
            (declared_run, fitted.map(|_| r))
        };
        let sims_declared = sims_declared
            .map_err(|e| DiagnoseError::Rig(format!("declared model does not simulate: {e}")))?;
        if !scale_checked {
            scale_checked = true;
            let sim: Vec<(Signal, &[f64])> = p
                .meas
                .iter()
                .map(|(c, _)| *c)
                .zip(sims_declared.iter().map(Vec::as_slice))
                .collect();
            // the command moves the declared piston as the record's (any
            // netlist rig, not only the valve circuit's steady gain)
            if let Some((_, x)) = sim.iter().find(|(s, _)| *s == Signal::Position) {
                travel_error(rec, x, &facts, &data_problems)?;
            }
            let scale = pressure_scale_problems(rec, &sim);
            if !scale.is_empty() {
                data_problems.extend(scale);
                continue;
            }
        }
        break (p, info, pt, rig0, sims_declared, initial_fit);
    };
    let mut warnings: Vec<String> = data_problems
        .iter()
        .map(|p| match p.left_out {
            true => format!("{} left out of the fit: {}", p.channel, p.message),
            false => format!("{}: {}", p.channel, p.message),
        })
        .collect();
    let floors = compared_floors(&p);
    let nrmse_declared = nrmse_of(&p, &sims_declared);
    // the fitted initial state, where it costs no channel (`initial_state`)
    let (sims_before, initial_used) = initial_state(
        &mut rig0,
        initial_fit,
        sims_declared,
        &p,
        &floors,
        &mut warnings,
    );
    clock.lap("checks, smoothing and initial-state fit");
    let nrmse_before = nrmse_of(&p, &sims_before);
    let rss_before = rss_of(&p, &sims_before, opts.holdout);
    let candidates: Vec<EffectId> = opts
        .candidates
        .clone()
        .unwrap_or_else(|| EffectId::ALL.to_vec())
        .into_iter()
        .filter(|e| declared.applies(*e).is_ok())
        .filter(|e| e.params().iter().all(|q| get(&rig0, *e, q.name).is_some()))
        // on in the declared rig: not a missing effect (bulk_modulus is
        // always declared: tracing it refits B)
        .filter(|e| *e == EffectId::BulkModulus || !is_on(&rig0, *e))
        .collect();
    let mut model = rig0.clone();
    let mut free: ParamList = Vec::new();
    let mut added: Vec<EffectReport> = Vec::new();
    let mut last: BTreeMap<EffectId, RejectedEffect> = BTreeMap::new();
    let mut resembles: Option<Probe> = None;
    // the last joint refit of the added effects (the backward step's start)
    let mut joint_res: Option<lm::LmResult> = None;
    // the first round's scores and pair pool (the compare after the forward
    // step), unless that round already ran the pair step
    let mut round0: Option<pairs::FirstRound> = None;
    let total = opts.max_effects + 1;
    for round in 0..opts.max_effects {
        progress(&format!("tracing, round {}", round + 1), round, total);
        let mut r0 = Vec::new();
        residual(&model, &pt, opts.holdout, Part::All, &mut r0)
            .map_err(|e| DiagnoseError::Rig(e.to_string()))?;
        let rss0 = sum_sq(&r0);
        let rss0_held = held_sum_sq(&r0, &pt, opts.holdout);
        let rho = lm::lag1_autocorrelation(&r0).clamp(0.0, 0.999);
        let neff = (r0.len() as f64 * (1.0 - rho) / (1.0 + rho)).max(2.0);
        let mut todo: Vec<EffectId> = candidates
            .iter()
            .copied()
            .filter(|&id| id == EffectId::BulkModulus || !is_on(&model, id))
            .filter(|id| !added.iter().any(|a| a.id == id.id()))
            .collect();
        // `K H a` needs the pressure term's K (eq 5.12)
        if k_pressure(&model) == 0.0 {
            let id = EffectId::AccelerationFriction;
            if let Some(k) = todo.iter().position(|e| *e == id) {
                todo.remove(k);
                last.insert(
                    id,
                    RejectedEffect::untraced(
                        id,
                        "not traced: needs pressure_viscous's K (the term is K H a, eq 5.12)",
                    ),
                );
            }
        }
        // One job per candidate and start (see `trace_starts`).
        let jobs: Vec<(EffectId, Model)> = todo
            .iter()
            .flat_map(|&id| trace_starts(&model, id).into_iter().map(move |r| (id, r)))
            .collect();
        // The first step's simulations every candidate shares.
        let first = FirstStep::new(&model, &free, &pt, opts.holdout, Part::Train);
        // What the candidates are scored against: the round model traced
        // like a candidate with nothing added (the effects already added and
        // the initial position and velocity stepped on the training part
        // alone). Each candidate is traced jointly with those, so against
        // the round model itself (fitted on the whole record) every
        // candidate was charged with what fitting on the training part alone
        // costs on the rest: after two effects, one whose trace landed on
        // its neutral value (τ = 0, Cl ≈ 0) "explained" −12 %.
        let (rss_null, held_null) = {
            let mut null = model.clone();
            let no_screen = Screen {
                rss: f64::INFINITY,
                share: f64::NEG_INFINITY,
            };
            let traced = gauss_newton_trace(
                &mut null,
                &free,
                &pt,
                opts.holdout,
                Part::Train,
                first.as_ref(),
                no_screen,
            );
            let (a, h) = match traced {
                Ok(_) => rss_all_held(&null, &pt, opts.holdout),
                Err(_) => (f64::INFINITY, f64::INFINITY),
            };
            if a.is_finite() && h.is_finite() {
                (a, h)
            } else {
                (rss0, rss0_held)
            }
        };
        let trace_one = |job: &(EffectId, Model)| -> (Model, EffectReport, Option<String>, f64) {
            let id = job.0;
            let params: ParamList = id.params().iter().map(|q| (id, q.name)).collect();
            // The candidate is traced together with the effects already added
            // (refitted jointly), so that an earlier effect that was standing
            // in for this one can give way.
            let joint: ParamList = free.iter().chain(params.iter()).copied().collect();
            let mut trial = job.1.clone();
            let screen = Screen {
                rss: first.as_ref().map_or(f64::INFINITY, |f| sum_sq(&f.r0)),
                share: SCREEN_SHARE * opts.min_share,
            };
            let res = gauss_newton_trace(
                &mut trial,
                &joint,
                &pt,
                opts.holdout,
                Part::Train,
                first.as_ref(),
                screen,
            );
            let (res, screened) = match res {
                Ok(TraceEnd::Traced(r)) => (Ok(r), None),
                Ok(TraceEnd::Screened { r, share }) => (Ok(r), Some(share)),
                Err(e) => (Err(e), None),
            };
            let rss_train = match &res {
                Ok(r) => sum_sq(r),
                Err(_) => rss(&trial, &pt, opts.holdout, Part::Train),
            };
            // A candidate screened out where the round model is its start
            // scores what nothing added scores (nothing to simulate).
            let unchanged =
                screened.is_some() && first.as_ref().is_some_and(|f| f.applies_to(&trial));
            let (rss1, rss1_held) = if unchanged {
                (rss_null, held_null)
            } else {
                rss_all_held(&trial, &pt, opts.holdout)
            };
            // A trace whose simulation fails scores nothing (finite numbers
            // only reach the report) and says why below.
            let sim_failed = !(rss1.is_finite() && rss1_held.is_finite() && rss_train.is_finite());
            let (share, held, dbic) = if sim_failed {
                (0.0, 0.0, 0.0)
            } else {
                (
                    1.0 - rss1 / rss_null.max(1e-300),
                    1.0 - rss1_held / held_null.max(1e-300),
                    neff * (rss1 / rss_null.max(1e-300)).max(1e-300).ln()
                        + params.len() as f64 * neff.ln(),
                )
            };
            let traced = params
                .iter()
                .filter_map(|(eid, n)| get(&trial, *eid, n).map(|v| (n.to_string(), v)))
                .collect();
            let rep = EffectReport::traced(id.id(), traced, share, held, dbic);
            let why = if let Err(e) = &res {
                Some(format!("fit failed: {e}"))
            } else if let Some(lin) = screened {
                Some(format!(
                    "screened out: a linearised Gauss–Newton step explains {:.2} % of the training part (< {:.1} %), not traced further",
                    100.0 * lin,
                    100.0 * screen.share
                ))
            } else if sim_failed {
                Some("the rig does not simulate at the traced values".into())
            } else if let Some(why) = opts.screen(share, held, dbic) {
                Some(why)
            } else if negligible(id, &trial, declared) {
                Some("fitted size negligible (indistinguishable from the declared rig)".into())
            } else {
                None
            };
            (trial, rep, why, rss_train)
        };
        // The jobs are independent: trace them on the available cores
        // (results taken in catalog order, so the outcome does not depend on
        // the number of threads). Of a candidate's starts, the one ending
        // lowest on the training part is kept.
        // The slowest first (the friction-law edits, then by parameter
        // count), so that no core is left alone with one at the end.
        let mut order: Vec<usize> = (0..jobs.len()).collect();
        order.sort_by_key(|&i| {
            let id = jobs[i].0;
            std::cmp::Reverse((model::is_law_edit(id), id.params().len()))
        });
        let queued: Vec<&(EffectId, Model)> = order.iter().map(|&i| &jobs[i]).collect();
        type Traced = (Model, EffectReport, Option<String>, f64);
        let mut done: Vec<Option<Traced>> = jobs.iter().map(|_| None).collect();
        for (i, r) in order
            .into_iter()
            .zip(trace_parallel(&queued, &|j| trace_one(j)))
        {
            done[i] = Some(r);
        }
        let mut traced: Vec<Option<(EffectId, Traced)>> = done
            .into_iter()
            .zip(&jobs)
            .map(|(d, (id, _))| d.map(|t| (*id, t)))
            .collect();
        // Candidates that explain a share worth having (best first); the
        // others rejected with the reason.
        let mut eligible: Vec<(EffectId, Model, EffectReport)> = Vec::new();
        let mut singles: Vec<(EffectId, f64)> = Vec::new();
        for &id in &todo {
            let mut pick: Option<Traced> = None;
            for slot in traced.iter_mut() {
                if slot.as_ref().is_some_and(|s| s.0 == id) {
                    if let Some((_, t)) = slot.take() {
                        if pick.as_ref().is_none_or(|p| t.3 < p.3) {
                            pick = Some(t);
                        }
                    }
                }
            }
            if let Some(t) = &pick {
                singles.push((id, t.1.explained_share));
            }
            match pick {
                Some((trial, rep, None, _)) => eligible.push((id, trial, rep)),
                Some((_, rep, Some(why), _)) => {
                    last.insert(id, RejectedEffect::new(rep, why));
                }
                None => {}
            }
        }
        eligible.sort_by(|a, b| b.2.explained_share.total_cmp(&a.2.explained_share));
        let top = eligible.first().map(|(id, _, r)| (*id, r.explained_share));
        // The probe's share is at most 1 (a sum of squares is not negative):
        // it is not run where it could not win.
        let probe_can_win =
            opts.min_share <= 1.0 && top.is_none_or(|(_, share)| share + opts.min_share < 1.0);
        // what a probe must explain to outrank the top candidate
        let need = top.map_or(opts.min_share, |(_, share)| {
            (share + opts.min_share).max(opts.min_share)
        });
        let probe = if probe_can_win {
            best_probe(&model, &pt, opts.holdout, &r0, rss0, need)
        } else {
            None
        };
        // A probe that outranks every candidate ends the loop, unless a pair
        // of candidates explains more (the pair step below).
        let mut probe_won: Option<Probe> = None;
        if let Some(pr) = probe {
            if pr.explained_share >= opts.min_share
                && top.is_none_or(|(_, share)| pr.explained_share > share + opts.min_share)
            {
                for (id, _, rep) in eligible.drain(..) {
                    last.insert(
                        id,
                        RejectedEffect::new(
                            rep,
                            format!(
                                "the residual is better explained by a {} ({:.1} %), which is not in the catalog",
                                pr.what,
                                100.0 * pr.explained_share
                            ),
                        ),
                    );
                }
                probe_won = Some(pr);
            }
        }
        // The acceptance rule (`accept`): refit each candidate in turn with
        // the effects already added; the first that earns its place is added.
        clock.lap("tracing");
        // The round model's scores the verdicts compare with: simulated
        // (only where a candidate is to be refitted) alongside the first
        // refit, which does not need them.
        let mut scores: Option<(BTreeMap<String, f64>, f64)> = None;
        let mut accepted: Option<(EffectId, Model, EffectReport, ParamList, lm::LmResult)> = None;
        let mut pending = eligible.into_iter();
        let mut refits = 0;
        for (id, trial, rep) in pending.by_ref() {
            if refits == crate::accept::MAX_REFITS_PER_ROUND {
                last.insert(id, RejectedEffect::not_refitted(rep));
                continue;
            }
            refits += 1;
            progress(&format!("refit {}", id.id()), round + 1, total);
            let joint: ParamList = free
                .iter()
                .copied()
                .chain(id.params().iter().map(|q| (id, q.name)))
                .collect();
            let mut refit = trial;
            let polished = match scores {
                Some(_) => refit_polished(&mut refit, &joint, &p, opts.holdout),
                None => {
                    let (polished, round_scores) = rayon::join(
                        || refit_polished(&mut refit, &joint, &p, opts.holdout),
                        || nrmse_and_held(&model, &p, opts.holdout),
                    );
                    scores = Some(round_scores);
                    polished
                }
            };
            let (nrmse, held) = scores.clone().unwrap_or((BTreeMap::new(), f64::INFINITY));
            let base = accept::Baseline {
                declared,
                nrmse,
                held,
                floors: floors.clone(),
                p: &p,
                holdout: opts.holdout,
            };
            let verdict = match polished {
                Ok(res) => accept::verdict(id, &joint, &res, &refit, &model, &base).map(|()| res),
                Err(e) => Err(format!("refit failed: {e}")),
            };
            match verdict {
                Ok(res) => {
                    accepted = Some((id, refit, rep, joint, res));
                    break;
                }
                Err(why) => {
                    last.insert(id, RejectedEffect::new(rep, why));
                }
            }
        }
        // (booked here: the next lap is the next round's tracing)
        clock.lap("refits");
        if round == 0 {
            round0 = Some(pairs::FirstRound {
                null: (rss_null, held_null),
                neff,
                singles: singles.clone(),
            });
        }
        let Some((id, refit, rep, joint, res)) = accepted else {
            // No single effect: the best candidates in pairs (`pairs.rs`),
            // which must explain more than a probe that outranked them all,
            // and more than a sensor's gain error (closed-form, so tried
            // even where no probe ran) by `--min-share` (`gain_probe`).
            let mut need = probe_won
                .as_ref()
                .map_or(opts.min_share, |pr| pr.explained_share);
            resembles = probe_won;
            if let Some(g) = gain_probe(&pt, &r0, rss0) {
                if g.explained_share >= opts.min_share && g.explained_share + opts.min_share > need
                {
                    need = g.explained_share + opts.min_share;
                    resembles = Some(g);
                }
            }
            if added.len() + 2 > opts.max_effects {
                break;
            }
            let r = pairs::Round {
                model: &model,
                free: &free,
                pt: &pt,
                p: &p,
                opts,
                declared,
                floors: &floors,
                null: (rss_null, held_null),
                neff,
                first: first.as_ref(),
            };
            let stepped = pairs::step(&r, &singles, need, &mut last, &mut added, &mut |s| {
                progress(s, round + 1, total)
            });
            clock.lap("pair step");
            let Some((m, f, res)) = stepped else {
                break;
            };
            (model, free, joint_res) = (m, f, Some(res));
            (round0, resembles) = (None, None);
            continue;
        };
        // The candidates after it were not refitted: one explaining more
        // earned its place (they are traced again next round, if any).
        for (other, _, r) in pending {
            last.insert(
                other,
                RejectedEffect::outranked(r, id, round, opts.max_effects),
            );
        }
        model = refit;
        free = joint;
        last.remove(&id);
        added.push(rep);
        pairs::book(&mut added, &free, &res);
        joint_res = Some(res);
    }
    clock.lap("refits");
    // Backward step: every added effect must still pass the rule's interval
    // test after the last joint refit (a later effect may have taken over
    // what it carried); the least resolved that fails is dropped and the
    // rest refitted, until all pass.
    let dropped = accept::backward(
        (&mut model, &mut free),
        joint_res,
        &mut added,
        declared,
        &p,
        opts.holdout,
        &mut warnings,
    );
    for d in dropped {
        if let Some(id) = EffectId::from_id(&d.effect.id) {
            last.insert(id, d);
        }
    }
    clock.lap("backward step");
    let mut sims_after = simulate(&model, &p).unwrap_or_default();
    let mut rss_after = rss_of(&p, &sims_after, opts.holdout);
    let (noise_floor, noise_ss) = noise_floors(&p);
    // The forward step's set against the best pair from the declared model,
    // where what is left is well above the noise (`pairs::compare`).
    if let Some(first0) =
        round0.filter(|_| !added.is_empty() && noise_ss < pairs::COMPARE_NOISE_SHARE * rss_after)
    {
        let r = pairs::Round {
            model: &rig0,
            free: &Vec::new(),
            pt: &pt,
            p: &p,
            opts,
            declared,
            floors: &floors,
            null: first0.null,
            neff: first0.neff,
            first: None,
        };
        let swapped = pairs::compare(
            &r,
            &first0.singles,
            rss_after,
            (&mut model, &mut free),
            &mut added,
            &mut last,
            &mut |s| progress(s, total, total),
        );
        if swapped {
            sims_after = simulate(&model, &p).unwrap_or_default();
            rss_after = rss_of(&p, &sims_after, opts.holdout);
        }
        clock.lap("pair compare");
    }
    progress("report", total, total);
    let nrmse_after = nrmse_of(&p, &sims_after);
    let traces = traces(rec, &p, &sims_before, &sims_after);
    let report = Report {
        rig: declared.roles.name.clone(),
        rig_kind: "netlist".into(),
        records: vec![rec.source.clone()],
        samples: rec.len(),
        data_problems,
        smoother: info.clone(),
        smoother_windows: vec![info.half_window],
        initial_state: format!("velocity and chamber pressures at the first sample from the smoother's local cubic fit (not the raw noisy sample), initial position and velocity fitted first on the declared model (kept only if no compared channel gets worse than from the smoother's, by the acceptance rule's tolerance) and again with every refit (the rig integrates flow into position; the smoother's one-sided derivative at the first sample is noisy); spool at the first command; the rig's steady pressures where p1/p2 are not measured. \"before\" starts from initial position and velocity {initial_used}"),
        nrmse_declared,
        nrmse_before,
        nrmse_after,
        noise_floor,
        declared_refit: vec![],
        effects_added: added,
        effects_rejected: last.into_values().collect(),
        effects_applicable: candidates
            .iter()
            .map(|e| Applicable {
                id: e.id().to_string(),
                paths: declared.paths_of(*e),
            })
            .collect(),
        effects_not_applicable: EffectId::ALL
            .iter()
            .filter(|e| !candidates.contains(e))
            .map(|e| NotApplicable {
                id: e.id().to_string(),
                why: not_applicable_why(*e, declared, opts),
            })
            .collect(),
        unexplained_share: rss_after / rss_before.max(1e-300),
        unexplained_resembles: resembles,
        warnings: crate::diagnose::with_small_sample_warnings(warnings, &[rec]),
        noise_share: (noise_ss / rss_after.max(1e-300)).min(1.0),
        selection: format!(
            "output-error tracing: add the effect removing the largest share of the noise-weighted output-error SS if share >= {:.0} %, held-out share >= {:.1} % and BIC falls; refit all added parameters on the output error; keep it only if its size's 95 % interval excludes zero and stays in the parameter's valid range, no parameter sits at a bound, no compared channel's NRMSE rises by more than {:.0} % of its noise floor and the held-out part improves; after the last joint refit, drop the least resolved added effect whose interval no longer passes and refit the rest, until all pass; where a round adds no single effect, pairs of its best candidates are traced and refitted together, and a pair is added when both effects pass the same rule; after the forward step, where what is left is more than twice the noise, the best pair from the declared model replaces the added set when it passes the rule, leaves less and its ΔBIC against the set is negative",
            100.0 * opts.min_share,
            50.0 * opts.min_share,
            100.0 * crate::accept::WORSEN_TOL
        ),
        wall_times_s: clock.finish(),
        elapsed_s: start.elapsed().as_secs_f64(),
        simulations: p.count.load(std::sync::atomic::Ordering::Relaxed),
    };
    // every catalog effect in exactly one list, with its reason
    debug_assert!(
        report.partition_errors().is_empty(),
        "{:?}",
        report.partition_errors()
    );
    Ok(ValveOutcome {
        report,
        traces,
        rig: model,
    })
}

#[cfg(test)]
mod tests;
