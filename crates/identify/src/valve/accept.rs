//! The acceptance rule on the valve rig: [`crate::accept::verdict`] (the
//! one rule of `spec/measured-data.md` for every rig kind) on a candidate
//! refitted with every effect already added, with the valve rig's neutral
//! values, fit bounds, negligible sizes and noise-weighted held-out part.

use std::collections::BTreeMap;

use super::Model;

use super::{
    bounds, get, mean_coulomb, negligible, nrmse_and_held, refit_polished, set, ParamList, Prepared,
};
use crate::accept::{self, FittedParam, Refitted, Scores};
use crate::catalog::EffectId;
use crate::diagnose::{EffectReport, RejectedEffect};
use crate::lm::LmResult;

/// The neutral ("off") value of parameter `name` of effect `id`.
pub(super) fn neutral(id: EffectId, name: &str, declared: &Model) -> f64 {
    match (id, name) {
        (EffectId::FlowGainError, _) => 1.0,
        (EffectId::BulkModulus, _) => get(declared, id, name).unwrap_or(0.0),
        _ => 0.0,
    }
}

/// The refit's parameters as the rule sees them: `res` over `free` in
/// `refit`; `candidate`: the effect being added and the model before it
/// (the other effects' values before), `None` after the loop.
fn fitted_params(
    free: &ParamList,
    res: &LmResult,
    refit: &Model,
    candidate: Option<(EffectId, &Model)>,
    declared: &Model,
) -> Vec<FittedParam> {
    free.iter()
        .enumerate()
        .map(|(k, (eid, n))| FittedParam {
            effect: Some(*eid),
            name: n.to_string(),
            value: res.x[k],
            ci95: res.ci95.get(k).copied().unwrap_or(f64::NAN),
            bounds: bounds(*eid, n, refit),
            at_bound: res.at_bound.get(k).copied().unwrap_or(false),
            neutral: neutral(*eid, n, declared),
            before: candidate
                .filter(|(id, _)| eid != id)
                .and_then(|(_, round)| get(round, *eid, n)),
        })
        .collect()
}

/// The fitted size of effect `id` in `rig` ([`accept::size`]).
fn size_of(id: EffectId, rig: &Model, declared: &Model) -> accept::Size {
    accept::size(
        id,
        |n| get(rig, id, n).unwrap_or(0.0),
        |n| neutral(id, n, declared),
        mean_coulomb(rig),
    )
}

/// The backward step after the loop's last joint refit (`res` over `free`
/// in `model`, `p` the prepared record with `holdout` its held-out share):
/// every added effect must still pass the rule's interval
/// test ([`accept::unresolved`], the one made at acceptance) and not be
/// negligible; a later effect may have taken over what an earlier one
/// carried, and the joint refit widened its interval. Of those that fail,
/// the least resolved (the smallest size in half-widths) is dropped: set
/// to its neutral value and taken out of `free` and `added`, and the rest
/// refitted; then checked again, until every one passes. Returns the
/// dropped effects with the reason. A refit that fails ends the step: the
/// effects left keep their values from the refit before it, and `warnings`
/// says so (the diagnosis goes on with what it has).
pub(super) fn backward(
    (model, free): (&mut Model, &mut ParamList),
    mut res: Option<LmResult>,
    added: &mut Vec<EffectReport>,
    declared: &Model,
    p: &Prepared,
    holdout: f64,
    warnings: &mut Vec<String>,
) -> Vec<RejectedEffect> {
    let mut dropped = Vec::new();
    while let Some(r) = res.take() {
        let params = fitted_params(free, &r, model, None, declared);
        // (failing effect, reason, size in half-widths)
        let worst = added
            .iter()
            .filter_map(|a| EffectId::from_id(&a.id))
            .filter_map(|id| {
                let size = size_of(id, model, declared);
                let why = if negligible(id, model, declared) {
                    "its size became negligible (indistinguishable from the declared rig)".into()
                } else {
                    accept::unresolved(id, &params, &size)?
                };
                let ci = params
                    .iter()
                    .find(|q| q.effect == Some(id) && q.name == size.name)
                    .map_or(f64::NAN, |q| q.ci95);
                let z = (size.value / ci).abs();
                Some((id, why, if z.is_finite() { z } else { 0.0 }))
            })
            .min_by(|a, b| a.2.total_cmp(&b.2));
        let Some((id, why, _)) = worst else {
            break;
        };
        for q in id.params() {
            set(model, id, q.name, neutral(id, q.name, declared));
        }
        free.retain(|(e, _)| *e != id);
        if let Some(pos) = added.iter().position(|a| a.id == id.id()) {
            let rep = added.remove(pos);
            dropped.push(RejectedEffect::new(
                rep,
                format!("added, then dropped after the last joint refit with the effects added after it: {why}"),
            ));
        }
        if free.is_empty() {
            break;
        }
        let mut refit = model.clone();
        let r = match refit_polished(&mut refit, free, p, holdout) {
            Ok(r) => r,
            Err(e) => {
                warnings.push(format!(
                    "the refit after dropping {id} failed ({e}); the effects left keep their values from the refit before it"
                ));
                break;
            }
        };
        *model = refit;
        for ((eid, n), (x, ci)) in free.iter().zip(r.x.iter().zip(&r.ci95)) {
            if let Some(a) = added.iter_mut().find(|a| a.id == eid.id()) {
                a.params.insert(n.to_string(), *x);
                a.ci95.insert(n.to_string(), ci.is_finite().then_some(*ci));
            }
        }
        res = Some(r);
    }
    dropped
}

/// What the rule compares a candidate with: the model before it, its
/// channels' NRMSE and their noise floors.
pub(super) struct Baseline<'a> {
    /// The declared rig (neutral values, negligible sizes).
    pub declared: &'a Model,
    /// NRMSE per channel of `model`.
    pub nrmse: BTreeMap<String, f64>,
    /// The held-out part's weighted sum of squares of `model`.
    pub held: f64,
    /// Noise floor per compared channel (NRMSE of the sensor noise, at least
    /// 1e-4: the weights' floor).
    pub floors: BTreeMap<String, f64>,
    /// The prepared record (tight tolerance).
    pub p: &'a Prepared,
    /// Held-out share.
    pub holdout: f64,
}

/// `Ok` if candidate `id`, refitted as `refit` (`res` over `free`, the
/// candidate's parameters among them; `round` the model before it), earns
/// its place; else the reason.
pub(super) fn verdict(
    id: EffectId,
    free: &ParamList,
    res: &LmResult,
    refit: &Model,
    round: &Model,
    base: &Baseline<'_>,
) -> Result<(), String> {
    verdict_with(id, free, res, refit, round, base, || {
        let (nrmse, held) = nrmse_and_held(refit, base.p, base.holdout);
        Scores { nrmse, held }
    })
}

/// `Ok` if both effects of a pair (`ids`), refitted together as `refit`
/// (`res` over `free`, both effects' parameters among them; `round` the
/// model before them), earn their place: the rule made on each as if it
/// were the candidate (the other one's parameters then count as already
/// there), rules 3 and 4 on the one refitted model (simulated once). Else
/// the reason, naming the effect that fails rule 1 or 2.
pub(super) fn verdict_pair(
    ids: [EffectId; 2],
    free: &ParamList,
    res: &LmResult,
    refit: &Model,
    round: &Model,
    base: &Baseline<'_>,
) -> Result<(), String> {
    let scores = std::cell::OnceCell::new();
    let after = || {
        scores
            .get_or_init(|| {
                let (nrmse, held) = nrmse_and_held(refit, base.p, base.holdout);
                Scores { nrmse, held }
            })
            .clone()
    };
    for id in ids {
        verdict_with(id, free, res, refit, round, base, after)
            .map_err(|why| format!("{}: {why}", id.id()))?;
    }
    Ok(())
}

/// [`verdict`] with the refitted model's scores from `after`.
fn verdict_with(
    id: EffectId,
    free: &ParamList,
    res: &LmResult,
    refit: &Model,
    round: &Model,
    base: &Baseline<'_>,
    after: impl FnOnce() -> Scores,
) -> Result<(), String> {
    let params = fitted_params(free, res, refit, Some((id, round)), base.declared);
    let size = size_of(id, refit, base.declared);
    let negligible = negligible(id, refit, base.declared)
        .then(|| "fitted size negligible (indistinguishable from the declared rig)".to_string());
    accept::verdict(
        &Refitted {
            id,
            params: &params,
            size,
            negligible,
            before: &Scores {
                nrmse: base.nrmse.clone(),
                held: base.held,
            },
            floors: &base.floors,
        },
        after,
    )
}
