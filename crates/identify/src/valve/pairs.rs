//! The pair step on the valve rig: two catalog effects traced and refitted
//! together where the greedy forward step cannot add either alone.
//!
//! With two effects in the record, each alone may explain most of the
//! residual and still be refused: the one channel the other effect acts on
//! gets worse when the first stands in for both (an internal leak and an
//! external force: each alone explains about 90 %, and each raises p1).
//! The forward step then adds nothing, or adds the nearest effect that does
//! not trade channels, and the true pair is never refitted together.
//!
//! The pair step takes the round's best candidates by traced share
//! ([`pool`], at most [`PAIR_POOL`]: at most six pairs) and the best
//! [`LINEAR_PAIRS`] other pairs by a linearised joint step
//! ([`linear_pairs`]: two effects that cancel in part explain little alone),
//! traces every pair jointly with the effects already added (the same
//! Gauss–Newton trace as a single candidate), screens each pair's scores as a single
//! candidate's (share, held-out share, ΔBIC with both effects' parameters)
//! and refits the best of them (at most
//! [`MAX_REFITS_PER_ROUND`](crate::accept::MAX_REFITS_PER_ROUND)) with every
//! free parameter. The first whose refit passes the acceptance rule for
//! *both* effects ([`accept::verdict_pair`]) is returned. The loop runs it
//! only where a round adds no single effect (and, from the declared model,
//! once after the forward step where the residual left is well above the
//! noise, to compare the greedy set with the best pair), so a record whose
//! effects the forward step adds one at a time down to the noise costs
//! nothing more.

use super::*;

/// Most candidates the pair step combines (the best by traced share): at
/// most `4 · 3 / 2 = 6` pairs of them are traced.
pub(super) const PAIR_POOL: usize = 4;

/// The round a pair is traced in: the round model, the effects already
/// added, and what the round's candidates were scored against.
pub(super) struct Round<'a> {
    /// The round model.
    pub model: &'a Model,
    /// The parameters already added (refitted jointly with the pair).
    pub free: &'a ParamList,
    /// The prepared record at the tracing tolerance.
    pub pt: &'a Prepared,
    /// The prepared record at the refits' tolerance.
    pub p: &'a Prepared,
    /// The loop's options (screen, held-out share).
    pub opts: &'a DiagnoseOptions,
    /// The declared rig (neutral values, negligible sizes).
    pub declared: &'a Model,
    /// Noise floor per compared channel (NRMSE).
    pub floors: &'a BTreeMap<String, f64>,
    /// Whole-record and held-out sums of squares the round's shares are of.
    pub null: (f64, f64),
    /// Effective number of independent residuals (the BIC's `n`).
    pub neff: f64,
    /// The round's shared first-step simulations, where there are any.
    pub first: Option<&'a FirstStep>,
}

/// What the compare after the forward step needs of the first round
/// (its model is the declared one from the initial state "before" uses).
pub(super) struct FirstRound {
    /// Whole-record and held-out sums of squares its shares are of.
    pub null: (f64, f64),
    /// Effective number of independent residuals.
    pub neff: f64,
    /// Every candidate traced, and its traced share.
    pub singles: Vec<(EffectId, f64)>,
}

/// A pair that passed the acceptance rule.
pub(super) struct Pair {
    /// The two effects, the better single candidate first.
    pub ids: [EffectId; 2],
    /// The refitted model.
    pub model: Model,
    /// Every parameter refitted (the effects already added, then the pair's).
    pub joint: ParamList,
    /// The refit.
    pub res: lm::LmResult,
    /// One report per effect: its traced values, and the pair's scores.
    pub reps: [EffectReport; 2],
}

/// What the pair step did: the pair accepted, if any, and why each pair
/// refitted before it was refused.
pub(super) struct PairOutcome {
    /// The accepted pair.
    pub accepted: Option<Pair>,
    /// The pairs refitted and refused, with the reason.
    pub refused: Vec<([EffectId; 2], String)>,
}

/// The candidates the pair step combines: those whose single trace
/// explains at least `min_share` (`singles`: id and traced share, in any
/// order), the best [`PAIR_POOL`] of them by share.
pub(super) fn pool(singles: &[(EffectId, f64)], min_share: f64) -> Vec<EffectId> {
    let mut v: Vec<(EffectId, f64)> = singles
        .iter()
        .copied()
        .filter(|(_, s)| s.is_finite() && *s >= min_share)
        .collect();
    v.sort_by(|a, b| b.1.total_cmp(&a.1));
    v.into_iter().take(PAIR_POOL).map(|(id, _)| id).collect()
}

/// A traced pair: its model, its scores and, if it fails the screen, why.
type TracedPair = ([EffectId; 2], Model, [EffectReport; 2], Option<String>);

/// Traces pair `ids` from the round model (both effects' trace starts,
/// the first of each) jointly with the effects already added.
fn trace_pair(r: &Round<'_>, ids: [EffectId; 2]) -> TracedPair {
    let [a, b] = ids;
    let start_a = trace_starts(r.model, a).swap_remove(0);
    let mut trial = trace_starts(&start_a, b).swap_remove(0);
    let own: ParamList = ids
        .iter()
        .flat_map(|id| id.params().iter().map(move |q| (*id, q.name)))
        .collect();
    let joint: ParamList = r.free.iter().chain(own.iter()).copied().collect();
    let no_screen = Screen {
        rss: f64::INFINITY,
        share: f64::NEG_INFINITY,
    };
    let holdout = r.opts.holdout;
    let traced = gauss_newton_trace(
        &mut trial,
        &joint,
        r.pt,
        holdout,
        Part::Train,
        r.first,
        no_screen,
    );
    let (rss1, held1) = match &traced {
        Ok(_) => rss_all_held(&trial, r.pt, holdout),
        Err(_) => (f64::INFINITY, f64::INFINITY),
    };
    let (null, held_null) = r.null;
    let failed = !(rss1.is_finite() && held1.is_finite());
    let (share, held, dbic) = if failed {
        (0.0, 0.0, 0.0)
    } else {
        (
            1.0 - rss1 / null.max(1e-300),
            1.0 - held1 / held_null.max(1e-300),
            r.neff * (rss1 / null.max(1e-300)).max(1e-300).ln() + own.len() as f64 * r.neff.ln(),
        )
    };
    let rep = |id: EffectId| {
        let params = id
            .params()
            .iter()
            .filter_map(|q| get(&trial, id, q.name).map(|v| (q.name.to_string(), v)))
            .collect();
        EffectReport::traced(id.id(), params, share, held, dbic)
    };
    let why = match &traced {
        Err(e) => Some(format!("trace failed: {e}")),
        Ok(_) if failed => Some("the rig does not simulate at the traced values".into()),
        Ok(_) => r.opts.screen(share, held, dbic).or_else(|| {
            ids.iter()
                .find(|id| negligible(**id, &trial, r.declared))
                .map(|id| format!("{}'s fitted size is negligible", id.id()))
        }),
    };
    let reps = [rep(a), rep(b)];
    (ids, trial, reps, why)
}

/// Most pairs the linearised ranking ([`linear_pairs`]) adds to those of
/// the pool.
pub(super) const LINEAR_PAIRS: usize = 3;

/// The pairs worth tracing in round `r` (`singles`: every candidate traced
/// and its share): every pair of the [`pool`], and the best
/// [`LINEAR_PAIRS`] others by [`linear_pairs`] — two effects that cancel in
/// part (a leak and a null bias of opposite drift) each explain little or
/// nothing alone, and only a joint step shows them.
fn pairs_to_trace(r: &Round<'_>, singles: &[(EffectId, f64)]) -> Vec<[EffectId; 2]> {
    let pool = pool(singles, r.opts.min_share);
    let mut jobs: Vec<[EffectId; 2]> = pool
        .iter()
        .enumerate()
        .flat_map(|(i, &a)| pool[i + 1..].iter().map(move |&b| [a, b]))
        .collect();
    let ids: Vec<EffectId> = singles.iter().map(|(id, _)| *id).collect();
    let extra: Vec<[EffectId; 2]> = linear_pairs(r, &ids)
        .into_iter()
        .filter(|x| !jobs.iter().any(|y| same(*x, *y)))
        .take(LINEAR_PAIRS)
        .collect();
    jobs.extend(extra);
    jobs
}

/// Whether two pairs are the same (in either order).
fn same(x: [EffectId; 2], y: [EffectId; 2]) -> bool {
    (x[0] == y[0] && x[1] == y[1]) || (x[0] == y[1] && x[1] == y[0])
}

/// Every pair of `ids` (those whose trace starts from the round model
/// itself: not the friction-law edits, which start from a law of their own),
/// best first by the sum of squares left on the training part by one
/// linearised Gauss–Newton step of both effects, the effects already added
/// and the initial position and velocity: one finite-difference column per
/// candidate parameter (one simulation each), then a small least-squares
/// solve per pair. Empty where the round model does not simulate.
fn linear_pairs(r: &Round<'_>, ids: &[EffectId]) -> Vec<[EffectId; 2]> {
    use rayon::prelude::*;
    let holdout = r.opts.holdout;
    let own;
    let first = match r.first {
        Some(f) => f,
        None => match FirstStep::new(r.model, r.free, r.pt, holdout, Part::Train) {
            Some(f) => {
                own = f;
                &own
            }
            None => return Vec::new(),
        },
    };
    let cands: Vec<EffectId> = ids
        .iter()
        .copied()
        .filter(|id| {
            let starts = trace_starts(r.model, *id);
            starts.len() == 1 && first.applies_to(&starts[0])
        })
        .collect();
    let params: Vec<(EffectId, &'static str)> = cands
        .iter()
        .flat_map(|id| id.params().iter().map(move |q| (*id, q.name)))
        .collect();
    let r0 = &first.r0;
    let own_cols: Vec<Option<Vec<f64>>> = params
        .par_iter()
        .map(|&(id, n)| {
            let (t, h) = perturbed(r.model, Column::Param(id, n));
            let mut r1 = Vec::new();
            residual(&t, r.pt, holdout, Part::Train, &mut r1).ok()?;
            let col: Vec<f64> = r1.iter().zip(r0).map(|(a, b)| (a - b) / h).collect();
            col.iter().all(|v| v.is_finite()).then_some(col)
        })
        .collect();
    // columns: the shared ones (added effects, x0, v0), then each parameter's
    let base: Vec<&[f64]> = first.cols.iter().map(|(_, c)| c.as_slice()).collect();
    let nb = base.len();
    let all: Vec<&[f64]> = base
        .iter()
        .copied()
        .chain(own_cols.iter().flatten().map(Vec::as_slice))
        .collect();
    // where each candidate's columns sit in `all` (None: one did not simulate)
    let mut at: Vec<(EffectId, Option<Vec<usize>>)> = Vec::new();
    let mut k = nb;
    for id in &cands {
        let mut idx = Some(Vec::new());
        for (j, (pid, _)) in params.iter().enumerate() {
            if pid != id {
                continue;
            }
            match (&own_cols[j], idx.as_mut()) {
                (Some(_), Some(v)) => {
                    v.push(k);
                    k += 1;
                }
                _ => idx = None,
            }
        }
        at.push((*id, idx));
    }
    let dot = |a: &[f64], b: &[f64]| -> f64 { a.iter().zip(b).map(|(x, y)| x * y).sum() };
    let n = all.len();
    let gram = nalgebra::DMatrix::from_fn(n, n, |i, j| dot(all[i], all[j]));
    let g = nalgebra::DVector::from_fn(n, |i, _| dot(all[i], r0));
    let mut ranked: Vec<([EffectId; 2], f64)> = Vec::new();
    for (i, (a, ia)) in at.iter().enumerate() {
        for (b, ib) in &at[i + 1..] {
            let (Some(ia), Some(ib)) = (ia, ib) else {
                continue;
            };
            let cols: Vec<usize> = (0..nb)
                .chain(ia.iter().copied())
                .chain(ib.iter().copied())
                .collect();
            let m = cols.len();
            let mut a_m = nalgebra::DMatrix::from_fn(m, m, |p, q| gram[(cols[p], cols[q])]);
            for j in 0..m {
                a_m[(j, j)] *= 1.0 + 1e-9;
            }
            let rhs = nalgebra::DVector::from_fn(m, |p, _| g[cols[p]]);
            let Some(ch) = a_m.cholesky() else {
                continue;
            };
            // the sum of squares the step removes: gᵀ A⁻¹ g
            let removed = rhs.dot(&ch.solve(&rhs));
            if removed.is_finite() {
                ranked.push(([*a, *b], removed));
            }
        }
    }
    ranked.sort_by(|x, y| y.1.total_cmp(&x.1));
    ranked.into_iter().map(|(ids, _)| ids).collect()
}

/// Traces the pairs worth tracing in round `r` (`singles`: every candidate
/// traced and its share; see [`pairs_to_trace`]), but `exclude` (in either
/// order), and refits the best by traced share that pass the screen and
/// reach `need`, at most [`crate::accept::MAX_REFITS_PER_ROUND`], until one
/// passes the acceptance rule for both its effects.
pub(super) fn try_pairs(
    r: &Round<'_>,
    singles: &[(EffectId, f64)],
    exclude: Option<[EffectId; 2]>,
    need: f64,
    progress: &mut dyn FnMut(&str),
) -> PairOutcome {
    let mut jobs = pairs_to_trace(r, singles);
    jobs.retain(|ids| exclude.is_none_or(|x| !same(x, *ids)));
    let mut outcome = PairOutcome {
        accepted: None,
        refused: Vec::new(),
    };
    if jobs.is_empty() {
        return outcome;
    }
    progress("tracing pairs");
    let mut traced: Vec<TracedPair> = trace_parallel(&jobs, &|ids| trace_pair(r, *ids));
    traced.retain(|t| t.3.is_none() && t.2[0].explained_share >= need);
    traced.sort_by(|x, y| y.2[0].explained_share.total_cmp(&x.2[0].explained_share));
    let holdout = r.opts.holdout;
    let (nrmse, held) = nrmse_and_held(r.model, r.p, holdout);
    let base = accept::Baseline {
        declared: r.declared,
        nrmse,
        held,
        floors: r.floors.clone(),
        p: r.p,
        holdout,
    };
    for (ids, trial, reps, _) in traced.into_iter().take(crate::accept::MAX_REFITS_PER_ROUND) {
        progress(&format!("refit the pair {} + {}", ids[0].id(), ids[1].id()));
        let joint: ParamList = r
            .free
            .iter()
            .copied()
            .chain(
                ids.iter()
                    .flat_map(|id| id.params().iter().map(move |q| (*id, q.name))),
            )
            .collect();
        let mut refit = trial;
        let verdict = match refit_polished(&mut refit, &joint, r.p, holdout) {
            Ok(res) => {
                accept::verdict_pair(ids, &joint, &res, &refit, r.model, &base).map(|()| res)
            }
            Err(e) => Err(format!("refit failed: {e}")),
        };
        match verdict {
            Ok(res) => {
                outcome.accepted = Some(Pair {
                    ids,
                    model: refit,
                    joint,
                    res,
                    reps,
                });
                break;
            }
            Err(why) => outcome.refused.push((ids, why)),
        }
    }
    outcome
}

/// Copies the refit's values and 95 % half-widths (`res` over `free`)
/// into the reports of `added`.
pub(super) fn book(added: &mut [EffectReport], free: &ParamList, res: &lm::LmResult) {
    for ((eid, n), (x, ci)) in free.iter().zip(res.x.iter().zip(&res.ci95)) {
        if let Some(a) = added.iter_mut().find(|a| a.id == eid.id()) {
            a.params.insert(n.to_string(), *x);
            a.ci95.insert(n.to_string(), ci.is_finite().then_some(*ci));
        }
    }
}

/// The forward step's set is compared with the best pair from the declared
/// model ([`compare`]) where the sensor noise accounts for less than this
/// share of the weighted sum of squares left (what is left is more than
/// twice the noise).
pub(super) const COMPARE_NOISE_SHARE: f64 = 0.5;

/// The pair step of a round `r` that added no single effect (`singles`:
/// the round's candidates and their traced shares; `last`: their
/// rejections); only pairs whose traced share reaches `need` are refitted
/// (`--min-share`, or the share of an out-of-catalog probe that outranked
/// every single candidate). A pair that passes is added to `added` with a note saying
/// why (each alone was refused, and for what), taken out of `last`, and
/// returned as the new model, its free parameters and the refit; a pair
/// refitted and refused is named in its effects' rejections.
pub(super) fn step(
    r: &Round<'_>,
    singles: &[(EffectId, f64)],
    need: f64,
    last: &mut BTreeMap<EffectId, RejectedEffect>,
    added: &mut Vec<EffectReport>,
    progress: &mut dyn FnMut(&str),
) -> Option<(Model, ParamList, lm::LmResult)> {
    if pool(singles, r.opts.min_share).is_empty() {
        return None;
    }
    let out = try_pairs(r, singles, None, need, progress);
    note_refused(&out.refused, last);
    let pair = out.accepted?;
    let [a, b] = pair.ids;
    let alone = |id: EffectId, last: &BTreeMap<EffectId, RejectedEffect>| {
        last.get(&id)
            .map_or_else(|| "not refitted".to_string(), |e| e.reason.clone())
    };
    let share = pair.reps[0].explained_share;
    let notes = [
        format!(
            "added together with {} by the pair step: the pair explains {:.1} %; alone it was refused: {}",
            b.id(),
            100.0 * share,
            alone(a, last)
        ),
        format!(
            "added together with {} by the pair step: the pair explains {:.1} %; alone it was refused: {}",
            a.id(),
            100.0 * share,
            alone(b, last)
        ),
    ];
    for (mut rep, note) in pair.reps.into_iter().zip(notes) {
        rep.note = Some(note);
        added.push(rep);
    }
    last.remove(&a);
    last.remove(&b);
    book(added, &pair.joint, &pair.res);
    Some((pair.model, pair.joint, pair.res))
}

/// Names each refused pair in the rejections of its two effects (the
/// first pair each one was refused in).
fn note_refused(
    refused: &[([EffectId; 2], String)],
    last: &mut BTreeMap<EffectId, RejectedEffect>,
) {
    let mut seen: Vec<EffectId> = Vec::new();
    for (ids, why) in refused {
        for (k, id) in ids.iter().enumerate() {
            if seen.contains(id) {
                continue;
            }
            seen.push(*id);
            if let Some(e) = last.get_mut(id) {
                e.reason = format!(
                    "{}; refitted together with {} in the pair step, refused too: {why}",
                    e.reason,
                    ids[1 - k].id()
                );
            }
        }
    }
}

/// After the forward step (and its backward step): the effects it added
/// (`added`, refitted as `model` over `free`, leaving the weighted sum of
/// squares `rss`) compared with the best pair of the first round's `pool`
/// traced and refitted from the declared model (`r0`, the first round; the
/// forward step's own pair left out). Where a pair passes the acceptance
/// rule, leaves less than the set and its ΔBIC against the set is negative
/// (with more parameters than the set, it must leave less by more than they
/// cost), it replaces the set, whose effects are rejected saying so;
/// returns whether it did. (A pair that leaves more than a larger set but
/// wins on ΔBIC does not replace it: the set's extra effect passed the
/// acceptance rule when it was added.)
pub(super) fn compare(
    r0: &Round<'_>,
    singles: &[(EffectId, f64)],
    rss: f64,
    state: (&mut Model, &mut ParamList),
    added: &mut Vec<EffectReport>,
    last: &mut BTreeMap<EffectId, RejectedEffect>,
    progress: &mut dyn FnMut(&str),
) -> bool {
    let (model, free) = state;
    let greedy: Vec<EffectId> = added
        .iter()
        .filter_map(|a| EffectId::from_id(&a.id))
        .collect();
    let exclude = match greedy[..] {
        [a, b] => Some([a, b]),
        _ => None,
    };
    let out = try_pairs(r0, singles, exclude, r0.opts.min_share, progress);
    let Some(pair) = out.accepted else {
        return false;
    };
    let rss_pair =
        simulate(&pair.model, r0.p).map_or(f64::INFINITY, |s| rss_of(r0.p, &s, r0.opts.holdout));
    let dbic = r0.neff * (rss_pair / rss.max(1e-300)).max(1e-300).ln()
        + (pair.joint.len() as f64 - free.len() as f64) * r0.neff.ln();
    if !(rss_pair < rss && dbic < 0.0) {
        return false;
    }
    let names: Vec<&str> = greedy.iter().map(|id| id.id()).collect();
    let [a, b] = pair.ids;
    let why = format!("weighted sum of squares {rss_pair:.4e} against {rss:.4e}, ΔBIC {dbic:.1}");
    for rep in added.drain(..) {
        if let Some(id) = EffectId::from_id(&rep.id) {
            last.insert(
                id,
                RejectedEffect::new(
                    rep,
                    format!(
                        "added by the forward step, then replaced: the pair {} + {}, traced and refitted together from the declared model, passes the acceptance rule and explains more ({why})",
                        a.id(),
                        b.id()
                    ),
                ),
            );
        }
    }
    for (mut rep, other) in pair.reps.into_iter().zip([b, a]) {
        rep.note = Some(format!(
            "added together with {} in place of the forward step's {} ({why})",
            other.id(),
            names.join(" + ")
        ));
        added.push(rep);
    }
    last.remove(&a);
    last.remove(&b);
    book(added, &pair.joint, &pair.res);
    *model = pair.model;
    *free = pair.joint;
    true
}
