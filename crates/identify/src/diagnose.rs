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

mod bench_checks;
mod bench_loop;
mod bench_model;
mod rig;
pub use bench_loop::diagnose_bench;
pub use rig::{DiagnoseRig, RigKindError};

/// Fewer samples than this in a record: the report's ± intervals assume
/// many independent samples, so they are not to be trusted.
pub const SMALL_SAMPLE: usize = 100;

/// The warning for record `rec` when it has fewer than [`SMALL_SAMPLE`]
/// samples (`None` otherwise): in the report's `warnings`, and what the CLI
/// prints on stderr before the run.
pub fn small_sample_warning(rec: &Record) -> Option<String> {
    (rec.len() < SMALL_SAMPLE).then(|| {
        format!(
            "{}: {} samples, fewer than {SMALL_SAMPLE}: the ± intervals assume many independent samples and are not to be trusted",
            rec.source,
            rec.len()
        )
    })
}

/// `warnings` after the [`small_sample_warning`]s of `records`.
pub fn with_small_sample_warnings(warnings: Vec<String>, records: &[&Record]) -> Vec<String> {
    let small = records.iter().filter_map(|r| small_sample_warning(r));
    small.chain(warnings).collect()
}

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

impl DiagnoseOptions {
    /// Why a traced candidate fails the screen on its explained share of
    /// the residual, its held-out share and its ΔBIC; `None` when it passes.
    pub fn screen(&self, share: f64, held: f64, dbic: f64) -> Option<String> {
        if share < self.min_share {
            Some(format!(
                "explains {:.1} % < {:.1} %",
                100.0 * share,
                100.0 * self.min_share
            ))
        } else if held < 0.5 * self.min_share {
            Some(format!(
                "held-out share {:.1} %: does not generalise",
                100.0 * held
            ))
        } else if dbic >= 0.0 {
            Some(format!("BIC does not fall (ΔBIC = {dbic:.1})"))
        } else {
            None
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
    /// Several records given to a rig that is diagnosed on one at a time
    /// (a circuit: [`DiagnoseRig::Net`]); how many.
    #[error("a circuit rig is diagnosed on one record at a time ({0} given)")]
    OneRecordAtATime(usize),
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
    /// How it was added where that was not alone by the greedy forward
    /// step: added together with another effect by the pair step (each
    /// alone failed the acceptance rule), or in place of the greedy set
    /// (absent from the JSON otherwise).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub note: Option<String>,
}

impl EffectReport {
    /// A candidate's report once traced: its traced parameter values and its
    /// scores (share, held-out share, ΔBIC), no intervals yet, no note.
    pub fn traced(
        id: &str,
        params: BTreeMap<String, f64>,
        explained_share: f64,
        heldout_share: f64,
        delta_bic: f64,
    ) -> Self {
        Self {
            id: id.into(),
            params,
            ci95: BTreeMap::new(),
            explained_share,
            heldout_share,
            delta_bic,
            note: None,
        }
    }
}

/// An effect tried and rejected: its scores and, always, why (the type has
/// no rejected effect without a reason).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RejectedEffect {
    /// Its scores (the last round it was traced in).
    #[serde(flatten)]
    pub effect: EffectReport,
    /// Why it was rejected: which part of the screen or of the acceptance
    /// rule ([`crate::accept`]) it failed.
    pub reason: String,
}

impl RejectedEffect {
    /// `effect` rejected for `reason`.
    pub fn new(effect: EffectReport, reason: impl Into<String>) -> Self {
        Self {
            effect,
            reason: reason.into(),
        }
    }

    /// A candidate its round had no refit left for
    /// ([`MAX_REFITS_PER_ROUND`](crate::accept::MAX_REFITS_PER_ROUND)).
    pub fn not_refitted(effect: EffectReport) -> Self {
        Self::new(
            effect,
            format!(
                "not refitted: {} candidates explaining more were refitted first in its round",
                crate::accept::MAX_REFITS_PER_ROUND
            ),
        )
    }

    /// A candidate of the last round (0-based `round`) that was not
    /// refitted because `added`, explaining more, earned its place there.
    pub fn outranked(
        effect: EffectReport,
        added: EffectId,
        round: usize,
        max_effects: usize,
    ) -> Self {
        Self::new(
            effect,
            format!(
                "explains less than {}, added in round {} (the last round: at most {max_effects} effects are added)",
                added.id(),
                round + 1
            ),
        )
    }

    /// A candidate not traced at all (no scores), and why.
    pub fn untraced(id: EffectId, reason: impl Into<String>) -> Self {
        Self::new(
            EffectReport {
                id: id.id().into(),
                params: BTreeMap::new(),
                ci95: BTreeMap::new(),
                explained_share: 0.0,
                heldout_share: 0.0,
                delta_bic: 0.0,
                note: None,
            },
            reason,
        )
    }
}

/// The friction bench's effects the loop tried (added or rejected), in
/// catalog order, each with the `--set` paths of its parameters on the rig
/// diagnosed ([`FrictionBench::set_paths`]; none where the rig's friction
/// law has no such parameter, e.g. `stribeck` on a Coulomb + viscous law).
pub(crate) fn bench_applicable(
    rig: &FrictionBench,
    added: &[EffectReport],
    rejected: &[RejectedEffect],
) -> Vec<Applicable> {
    BENCH_EFFECTS
        .iter()
        .filter(|e| {
            added.iter().any(|a| a.id == e.id()) || rejected.iter().any(|r| r.effect.id == e.id())
        })
        .map(|e| Applicable {
            id: e.id().into(),
            paths: e
                .params()
                .iter()
                .flat_map(|p| rig.set_paths(&ParamRef::Effect(*e, p.name.to_string())))
                .collect(),
        })
        .collect()
}

/// An effect that applies to the rig, and where it acts.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Applicable {
    /// Effect id.
    pub id: String,
    /// The `<component>.<parameter>` paths it writes (`<friction> (law)` for
    /// an edit of the friction law; none for the sensor model).
    pub paths: Vec<String>,
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
    /// Its `--set` path on the rig diagnosed (`friction.coulomb`,
    /// `drive.mass`, `friction.extending.curve.coulomb`), so the fitted
    /// value goes back with `--set <name>=<fitted>`.
    pub name: String,
    /// The rig's other `--set` paths that hold the same parameter and take
    /// the same value (a law with one set per direction, `friction_lugre`:
    /// the retracting curve's); absent from the JSON when there are none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub also_set: Vec<String>,
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
    /// NRMSE the sensor noise alone would give, per channel: the noise's
    /// σ ([`noise_sigma`], at least a quantised channel's step/√12) over the
    /// channel's range. NaN (`null` in JSON, `n/a` in the table) where none
    /// is measured: a velocity derived from the position.
    pub noise_floor: BTreeMap<String, f64>,
    /// Declared parameters refitted, with their final values.
    pub declared_refit: Vec<ParamReport>,
    /// Effects added, in order.
    pub effects_added: Vec<EffectReport>,
    /// Effects tried and rejected (last round's scores), each with its reason.
    pub effects_rejected: Vec<RejectedEffect>,
    /// Catalog effects not tried on this rig, each with the reason.
    pub effects_not_applicable: Vec<NotApplicable>,
    /// The effects that apply to the rig, with the `<component>.<parameter>`
    /// paths each one writes (on the friction bench: the effects tried, with
    /// the `--set` paths of their parameters on the rig, none where its law
    /// has no such parameter).
    pub effects_applicable: Vec<Applicable>,
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
    /// Simulations of the rig the diagnosis ran (whole or part of the
    /// record; 0 for the friction bench, whose fit is its inverse model).
    pub simulations: usize,
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

/// An explanation of the residual that is *not* in the catalog, tried so that
/// a residual of foreign shape is not dressed up as the nearest catalog effect.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Probe {
    /// Short name: `delay`, `spring`, `force_gain`, `p1_gain` or `p2_gain`
    /// (friction bench: a transport delay of the force, a spring, a
    /// sensor's gain error); `delay`, `mass`, `coulomb`,
    /// `supply_pressure`, `p1_offset`, `p2_offset`, `p1_gain`, `p2_gain` or
    /// `position_gain` (netlist rigs: a transport delay of the command, a
    /// declared parameter other than declared, a pressure sensor's zero
    /// error, a sensor's gain error).
    pub kind: String,
    /// What it is, in words (`"time shift of the measured force"`, `"force
    /// proportional to position"`, ``"load mass other than declared
    /// (`load.mass` fits 40.0 kg, declared 20.0 kg)"``).
    pub what: String,
    /// Its fitted size, SI: delay \[s\], stiffness \[N·m⁻¹\], mass \[kg\],
    /// Coulomb level \[N\] (of the first Coulomb parameter, where the
    /// friction law has one per direction, all scaled by one factor),
    /// supply pressure \[Pa\], the offset \[Pa\] the pressure sensor
    /// reads above the pressure, or a sensor's gain error (a fraction:
    /// 0.03 reads 3 % high).
    pub value: f64,
    /// Share of the residual it explains.
    pub explained_share: f64,
}

impl Report {
    /// The compared channels whose NRMSE after is more than [`ABOVE_FLOOR`]
    /// times their noise floor (where one is measured), with that ratio,
    /// the highest first: what the share left (a share of the whole
    /// residual, which a large start makes small) does not show.
    pub fn above_noise_floor(&self) -> Vec<(String, f64)> {
        let mut v: Vec<(String, f64)> = self
            .nrmse_after
            .iter()
            .filter_map(|(ch, after)| {
                let floor = *self.noise_floor.get(ch)?;
                let r = after / floor;
                (floor > 0.0 && r.is_finite() && r > ABOVE_FLOOR).then(|| (ch.clone(), r))
            })
            .collect();
        v.sort_by(|a, b| b.1.total_cmp(&a.1));
        v
    }

    /// Where the report breaks "every catalog effect ends in exactly one of
    /// `effects_added`, `effects_rejected` and `effects_not_applicable`"
    /// (each of those with its reason): one line per effect listed in none or
    /// in several. Empty for every report the loops write.
    pub fn partition_errors(&self) -> Vec<String> {
        EffectId::ALL
            .iter()
            .filter_map(|e| {
                let id = e.id();
                let lists: Vec<&str> = [
                    (
                        "effects_added",
                        self.effects_added.iter().any(|a| a.id == id),
                    ),
                    (
                        "effects_rejected",
                        self.effects_rejected.iter().any(|r| r.effect.id == id),
                    ),
                    (
                        "effects_not_applicable",
                        self.effects_not_applicable.iter().any(|n| n.id == id),
                    ),
                ]
                .into_iter()
                .filter_map(|(name, hit)| hit.then_some(name))
                .collect();
                (lists.len() != 1).then(|| {
                    if lists.is_empty() {
                        format!("{id} is in none of the lists")
                    } else {
                        format!("{id} is in {}", lists.join(" and "))
                    }
                })
            })
            .collect()
    }

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
            let _ = writeln!(s, "\ndata problems:");
            let several = self.records.len() > 1;
            for p in &self.data_problems {
                let kind = serde_json::to_value(p.kind)
                    .ok()
                    .and_then(|v| v.as_str().map(str::to_string))
                    .unwrap_or_default();
                let done = if p.left_out { "left out" } else { "kept" };
                let file = if several {
                    format!("{}: ", p.file)
                } else {
                    String::new()
                };
                let _ = writeln!(
                    s,
                    "  {file}{:<10} {:<10} {:<8} {}",
                    p.channel, kind, done, p.message
                );
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
            let w = self
                .declared_refit
                .iter()
                .map(|p| p.name.chars().count())
                .max()
                .unwrap_or(0)
                .max(24);
            for p in &self.declared_refit {
                let _ = writeln!(
                    s,
                    "  {:<w$} {:>12.5e} -> {:>12.5e} ± {}",
                    p.name,
                    p.declared,
                    p.fitted,
                    fmt_ci(p.ci95)
                );
                if !p.also_set.is_empty() {
                    let _ = writeln!(s, "    (the same value at {})", p.also_set.join(", "));
                }
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
            if let Some(note) = &e.note {
                let _ = writeln!(s, "      ({note})");
            }
            for (k, v) in &e.params {
                let ci = e.ci95.get(k).copied().flatten();
                let _ = writeln!(s, "      {k} = {v:.5e} ± {}", fmt_ci(ci));
            }
        }
        let _ = writeln!(s, "\neffects tried and rejected:");
        for e in &self.effects_rejected {
            let _ = writeln!(s, "  {:<22} {}", e.effect.id, e.reason);
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
        let above = self.above_noise_floor();
        if !above.is_empty() {
            let listed: Vec<String> = above
                .iter()
                .map(|(ch, r)| format!("{ch} {r:.1}x"))
                .collect();
            let _ = writeln!(
                s,
                "left above the noise floor after (NRMSE over the floor's): {} — the share above is of the whole record's residual; these channels are not explained down to their noise",
                listed.join(", ")
            );
        }
        if let Some(p) = &self.unexplained_resembles {
            let _ = writeln!(
                s,
                "the unexplained residual resembles a {} (size {:.4e}, {:.1} % of the residual) — not a catalog effect",
                p.what,
                p.value,
                100.0 * p.explained_share
            );
        }
        // the warnings a data problem gave are listed above, under "data
        // problems" (the JSON keeps both lists whole)
        let restates = |w: &str| {
            self.data_problems
                .iter()
                .any(|p| w.starts_with(p.channel.as_str()) && w.ends_with(p.message.as_str()))
        };
        for w in self.warnings.iter().filter(|w| !restates(w)) {
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

/// A channel's NRMSE after over its noise floor beyond which the text
/// report lists it as not explained down to its noise.
pub const ABOVE_FLOOR: f64 = 1.5;

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
