//! The acceptance rule of the valve rig (`spec/measured-data.md`): a traced
//! candidate that explains a share of the residual is refitted with every
//! effect already added, and it earns its place only if
//!
//! 1. none of its parameters ends on a fit bound, except on its neutral
//!    ("off") value while another parameter carries the effect (Ce2 = 0
//!    beside a found Ce1): a parameter on a bound means the catalog form
//!    does not fit the residual;
//! 2. its fitted size's 95 % interval excludes zero (the neutral value), and
//!    the size is not negligible;
//! 3. no compared channel gets worse by more than its noise floor (NRMSE);
//! 4. the held-out part of the record improves.
//!
//! Otherwise it is rejected with the reason, and the next candidate is tried.

use std::collections::BTreeMap;

use super::Model;

use super::{get, mean_coulomb, negligible, nrmse_and_held, ParamList, Prepared};
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

/// The parameter whose distance from "off" is the effect's size, and that
/// distance: the first parameter's, except the larger leak of
/// `external_leakage` and the hump `Fs − Fc` of `stribeck`.
fn size(id: EffectId, rig: &Model, declared: &Model) -> (&'static str, f64) {
    let v = |n: &str| get(rig, id, n).unwrap_or(0.0);
    match id {
        EffectId::ExternalLeakage => {
            if v("Ce1") >= v("Ce2") {
                ("Ce1", v("Ce1"))
            } else {
                ("Ce2", v("Ce2"))
            }
        }
        EffectId::Stribeck => ("Fs", v("Fs") - mean_coulomb(rig)),
        _ => {
            let n = id.params()[0].name;
            (n, v(n) - neutral(id, n, declared))
        }
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
/// candidate's parameters among them), earns its place; else the reason.
pub(super) fn verdict(
    id: EffectId,
    free: &ParamList,
    res: &LmResult,
    refit: &Model,
    base: &Baseline<'_>,
) -> Result<(), String> {
    for (k, (eid, n)) in free.iter().enumerate() {
        if *eid != id || !res.at_bound.get(k).copied().unwrap_or(false) {
            continue;
        }
        let x = res.x[k];
        let off = neutral(id, n, base.declared);
        if (x - off).abs() > 1e-12 * off.abs().max(1.0) || id.params().len() == 1 {
            return Err(format!(
                "{n} = {x:.4e} ends on its fit bound: the catalog form does not fit the residual"
            ));
        }
    }
    let (name, d) = size(id, refit, base.declared);
    let ci = free
        .iter()
        .position(|(e, n)| *e == id && *n == name)
        .and_then(|k| res.ci95.get(k).copied())
        .unwrap_or(f64::NAN);
    if !ci.is_finite() {
        return Err(format!(
            "{name} has no confidence interval (not identifiable from this record)"
        ));
    }
    if d.abs() <= ci {
        return Err(format!(
            "{name}: the 95 % interval (size {d:.3e} ± {ci:.3e}) includes zero"
        ));
    }
    if negligible(id, refit, base.declared) {
        return Err("fitted size negligible (indistinguishable from the declared rig)".into());
    }
    let (after, h1) = nrmse_and_held(refit, base.p, base.holdout);
    for (ch, before) in &base.nrmse {
        let (Some(a), Some(floor)) = (after.get(ch), base.floors.get(ch)) else {
            continue;
        };
        if !a.is_finite() || a - before > *floor {
            return Err(format!(
                "{ch} gets worse: NRMSE {before:.4} -> {a:.4}, more than its noise floor {floor:.4}"
            ));
        }
    }
    let h0 = base.held;
    if h1.partial_cmp(&h0) != Some(std::cmp::Ordering::Less) {
        return Err(format!(
            "the held-out part does not improve (weighted SS {h0:.4e} -> {h1:.4e})"
        ));
    }
    Ok(())
}
