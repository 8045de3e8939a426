//! The acceptance rule on the valve rig: [`crate::accept::verdict`] (the
//! one rule of `spec/measured-data.md` for every rig kind) on a candidate
//! refitted with every effect already added, with the valve rig's neutral
//! values, fit bounds, negligible sizes and noise-weighted held-out part.

use std::collections::BTreeMap;

use super::Model;

use super::{bounds, get, mean_coulomb, negligible, nrmse_and_held, ParamList, Prepared};
use crate::accept::{self, FittedParam, Refitted, Scores};
use crate::catalog::EffectId;
use crate::lm::LmResult;

/// The neutral ("off") value of parameter `name` of effect `id`.
pub(super) fn neutral(id: EffectId, name: &str, declared: &Model) -> f64 {
    match (id, name) {
        (EffectId::FlowGainError, _) => 1.0,
        (EffectId::BulkModulus, _) => get(declared, id, name).unwrap_or(0.0),
        _ => 0.0,
    }
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
    let params: Vec<FittedParam> = free
        .iter()
        .enumerate()
        .map(|(k, (eid, n))| FittedParam {
            effect: Some(*eid),
            name: n.to_string(),
            value: res.x[k],
            ci95: res.ci95.get(k).copied().unwrap_or(f64::NAN),
            bounds: bounds(*eid, n, refit),
            at_bound: res.at_bound.get(k).copied().unwrap_or(false),
            neutral: neutral(*eid, n, base.declared),
            before: (*eid != id).then(|| get(round, *eid, n)).flatten(),
        })
        .collect();
    let size = accept::size(
        id,
        |n| get(refit, id, n).unwrap_or(0.0),
        |n| neutral(id, n, base.declared),
        mean_coulomb(refit),
    );
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
        || {
            let (nrmse, held) = nrmse_and_held(refit, base.p, base.holdout);
            Scores { nrmse, held }
        },
    )
}
