//! The loop on the friction bench: output-error traces of the catalog's
//! friction effects on imposed motion, LM refits and the out-of-catalog
//! probes (delay, spring, sensor gains).

use super::bench_checks::{kept_on_bench, pressure_force_contradiction};
use super::bench_model::{initial_guess, n_eff, probes, Bench, Part};
use super::*;
use crate::accept::{self, FittedParam, Refitted, Scores};

/// A sensor-gain probe stands in for the catalog only where what it leaves
/// of the force residual is within this factor of the noise floor (NRMSE):
/// the tolerance the loop's own tests hold an explained record to.
const GAIN_PROBE_FLOOR: f64 = 1.5;

/// Why an effect the declared rig already has is not traced.
fn declared_on_why(rig: &FrictionBench, e: EffectId) -> String {
    let values: Vec<String> = e
        .params()
        .iter()
        .map(|p| {
            let r = ParamRef::Effect(e, p.name.to_string());
            format!("{} = {:.4e}", rig.name_of(&r), rig.get(&r))
        })
        .collect();
    let refitted = e.params().iter().any(|p| {
        let r = ParamRef::Effect(e, p.name.to_string());
        rig.refit_params().contains(&r)
    });
    format!(
        "already on in the declared rig ({}): the loop adds only effects that are off ({})",
        values.join(", "),
        if refitted {
            "it is refitted with the declared parameters: declared_refit"
        } else {
            "list its parameters in the rig's refit to fit them"
        }
    )
}

/// The parameters of a candidate's refit as the acceptance rule sees them
/// (`model`: the model before the candidate).
fn fitted_params(
    id: EffectId,
    joint: &[ParamRef],
    res: &lm::LmResult,
    model: &FrictionBench,
) -> Vec<FittedParam> {
    joint
        .iter()
        .enumerate()
        .map(|(k, p)| {
            let effect = match p {
                ParamRef::Effect(e, _) => Some(*e),
                _ => None,
            };
            FittedParam {
                effect,
                name: match p {
                    ParamRef::Effect(_, n) => n.clone(),
                    _ => model.name_of(p),
                },
                value: res.x[k],
                ci95: res.ci95.get(k).copied().unwrap_or(f64::NAN),
                bounds: p.bounds(),
                at_bound: res.at_bound.get(k).copied().unwrap_or(false),
                neutral: if effect.is_some() { 0.0 } else { f64::NAN },
                before: (effect != Some(id)).then(|| model.get(p)),
            }
        })
        .collect()
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
    // a pressure the model is driven by must be measured
    for r in records {
        rig.require_inputs(r)?;
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
        // a problem already kept (a gap) keeps its own reason
        data_problems.extend(problems.into_iter().map(|p| {
            if p.left_out {
                kept_on_bench(p)
            } else {
                p
            }
        }));
    }
    let mut sigs = Vec::new();
    let mut windows = Vec::new();
    let mut smoother = None;
    for r in records {
        let (s, info) = bench_signals(r, opts.half_window, rig.steady_state)?;
        if let Some(why) = pressure_force_contradiction(rig, &s, &r.units) {
            return Err(DiagnoseError::Unusable {
                file: r.source.clone(),
                why,
            });
        }
        windows.push(info.half_window);
        smoother.get_or_insert(info);
        sigs.push(s);
    }
    let b = Bench::new(rig, &sigs, opts.holdout).map_err(DiagnoseError::Rig)?;
    let measured: Vec<f64> = sigs.iter().flat_map(|s| s.force.iter().copied()).collect();
    let sim_all = |rig: &FrictionBench| -> Vec<f64> { b.simulate_all(rig).concat() };
    let channel = |rig: &FrictionBench| -> BTreeMap<String, f64> {
        let mut m = BTreeMap::new();
        m.insert("force".to_string(), nrmse(&measured, &sim_all(rig)));
        m
    };
    let nrmse_declared = channel(rig);
    // Declared refit.
    let mut model = rig.clone();
    let refit: Vec<ParamRef> = rig.refit_params();
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
    // Every catalog effect is a candidate or, with the reason, not applicable.
    let asked = opts
        .candidates
        .clone()
        .unwrap_or_else(|| EffectId::ALL.to_vec());
    let mut candidates: Vec<EffectId> = Vec::new();
    let mut not_applicable: Vec<NotApplicable> = Vec::new();
    for &e in EffectId::ALL.iter() {
        let why = if !BENCH_EFFECTS.contains(&e) {
            format!(
                "the friction bench has only the force balance; {} belongs to the {:?} balance",
                e.id(),
                e.balance()
            )
        } else if !asked.contains(&e) {
            "left out by --effects".into()
        } else if rig.steady_state
            && matches!(e, EffectId::LugreDynamics | EffectId::AccelerationFriction)
        {
            // Steady-state tables have no time: no bristle dynamics, no acceleration.
            "a steady-state table has no time: no bristle dynamics and no acceleration".into()
        } else if rig.has(e) {
            declared_on_why(rig, e)
        } else {
            candidates.push(e);
            continue;
        };
        not_applicable.push(NotApplicable {
            id: e.id().to_string(),
            why,
        });
    }
    // The floor: load-cell noise plus the pressure sensors' noise carried
    // into the prediction by the areas (the balance is linear in both).
    let noise_ss: f64 = sigs
        .iter()
        .map(|s| {
            let var = noise_sigma(&s.t, &s.force).powi(2)
                + (rig.area1 * noise_sigma(&s.t, &s.p1)).powi(2)
                + (rig.area2 * noise_sigma(&s.t, &s.p2)).powi(2);
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
    let floors: BTreeMap<String, f64> = noise_floor
        .iter()
        .filter(|(_, v)| v.is_finite())
        .map(|(k, v)| (k.clone(), *v))
        .collect();
    let mut added: Vec<EffectReport> = Vec::new();
    let mut rejected: BTreeMap<EffectId, RejectedEffect> = BTreeMap::new();
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
        // Candidates that pass the screen, each with its traced model.
        let mut eligible: Vec<(EffectId, FrictionBench, EffectReport)> = Vec::new();
        for &id in &candidates {
            if model.has(id) {
                continue;
            }
            if id == EffectId::AccelerationFriction
                && model.get(&ParamRef::Effect(EffectId::PressureViscous, "K".into())) == 0.0
            {
                rejected.insert(
                    id,
                    RejectedEffect::untraced(
                        id,
                        "needs pressure_viscous's K (term is K H a, eq 5.12)",
                    ),
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
            let traced = params
                .iter()
                .map(|p| (param_name(p).to_string(), trial.get(p)))
                .collect();
            let rep = EffectReport::traced(id.id(), traced, share, held, dbic);
            let why = match &fit {
                Err(e) => Some(format!("fit failed: {e}")),
                Ok(_) => opts.screen(share, held, dbic),
            };
            match why {
                Some(why) => {
                    rejected.insert(id, RejectedEffect::new(rep, why));
                }
                None => eligible.push((id, trial, rep)),
            }
        }
        // best first (ties in catalog order)
        eligible.sort_by(|a, b| b.2.explained_share.total_cmp(&a.2.explained_share));
        let top = eligible.first().map(|(_, _, r)| r.explained_share);
        // A probe that explains more than the best candidate stands in for
        // it. A sensor's gain error also resembles catalog effects in part
        // (an offset that grows with the pressure looks like a Coulomb
        // asymmetry or a pressure term), so it stands in only where it
        // leaves no more than the noise (GAIN_PROBE_FLOOR × the floor).
        let probe = if rig.steady_state {
            Vec::new()
        } else {
            let found = probes(&model, &b);
            let complete =
                |p: &Probe| rss0 * (1.0 - p.explained_share) <= GAIN_PROBE_FLOOR.powi(2) * noise_ss;
            found
                .shapes
                .into_iter()
                .chain(found.gains.into_iter().filter(complete))
                .collect()
        }
        .into_iter()
        .max_by(|a, b| a.explained_share.total_cmp(&b.explained_share));
        if let Some(p) = &probe {
            if p.explained_share >= opts.min_share
                && top.is_none_or(|share| p.explained_share > share + opts.min_share)
            {
                for (id, _, rep) in eligible {
                    rejected.insert(
                        id,
                        RejectedEffect::new(
                            rep,
                            format!(
                                "the residual is better explained by a {} ({:.1} %), which is not in the catalog",
                                p.what,
                                100.0 * p.explained_share
                            ),
                        ),
                    );
                }
                resembles = Some(p.clone());
                break;
            }
        }
        // The acceptance rule (`crate::accept`): refit each candidate in
        // turn with every free parameter; the first that earns its place is
        // added.
        let before_scores = Scores {
            nrmse: channel(&model),
            held: rss0_held,
        };
        let mut accepted: Option<(EffectId, FrictionBench, EffectReport, lm::LmResult)> = None;
        let mut pending = eligible.into_iter();
        let mut refits = 0;
        for (id, trial, rep) in pending.by_ref() {
            if refits == accept::MAX_REFITS_PER_ROUND {
                rejected.insert(id, RejectedEffect::not_refitted(rep));
                continue;
            }
            refits += 1;
            progress("refit", round + 1, total_steps);
            let joint: Vec<ParamRef> = free
                .iter()
                .cloned()
                .chain(
                    id.params()
                        .iter()
                        .map(|p| ParamRef::Effect(id, p.name.to_string())),
                )
                .collect();
            let mut refitted = trial;
            let verdict = match b.fit(&mut refitted, &joint, Part::All) {
                Err(e) => Err(format!("refit failed: {e}")),
                Ok(res) => {
                    let params = fitted_params(id, &joint, &res, &model);
                    let size = accept::size(
                        id,
                        |n| refitted.get(&ParamRef::Effect(id, n.to_string())),
                        |_| 0.0,
                        refitted.friction.coulomb,
                    );
                    accept::verdict(
                        &Refitted {
                            id,
                            params: &params,
                            size,
                            negligible: None,
                            before: &before_scores,
                            floors: &floors,
                        },
                        || Scores {
                            nrmse: channel(&refitted),
                            held: b.rss(&refitted, Part::Held),
                        },
                    )
                    .map(|()| res)
                }
            };
            match verdict {
                Ok(res) => {
                    accepted = Some((id, refitted, rep, res));
                    break;
                }
                Err(why) => {
                    rejected.insert(id, RejectedEffect::new(rep, why));
                }
            }
        }
        let Some((id, refitted, mut rep, res)) = accepted else {
            break;
        };
        // The candidates after it were not refitted: one explaining more
        // earned its place (they are traced again next round, if any).
        for (other, _, r) in pending {
            rejected.insert(
                other,
                RejectedEffect::outranked(r, id, round, opts.max_effects),
            );
        }
        model = refitted;
        for p in id.params() {
            free.push(ParamRef::Effect(id, p.name.to_string()));
        }
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
        rejected.remove(&id);
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
                    name: rig.name_of(p),
                    also_set: rig.set_paths(p).into_iter().skip(1).collect(),
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
    let (before_f, after_f) = (b.simulate_all(&before), b.simulate_all(&model));
    let traces = sigs
        .iter()
        .zip(before_f.into_iter().zip(after_f))
        .map(|(s, (before_f, after_f))| {
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
                before: minus(before_f),
                after: minus(after_f),
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
    let rejected: Vec<RejectedEffect> = rejected.into_values().collect();
    let applicable = bench_applicable(rig, &added, &rejected);
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
        effects_applicable: applicable,
        simulations: 0,
        effects_not_applicable: not_applicable,
        unexplained_share: rss_after / rss_before.max(1e-300),
        unexplained_resembles: resembles,
        warnings: super::with_small_sample_warnings(Vec::new(), &records.iter().collect::<Vec<_>>()),
        noise_share: if noise_ss.is_nan() {
            f64::NAN
        } else {
            (noise_ss / rss_after.max(1e-300)).min(1.0)
        },
        selection: format!(
            "add the effect explaining the largest share of the force-balance residual if share >= {:.0} %, held-out share >= {:.1} % (last {:.0} % of each record) and BIC falls (n_eff from lag-1 autocorrelation); refit all free parameters on the output error; keep it only if no parameter ends on a bound, its size's 95 % interval excludes zero, the force NRMSE does not rise by more than {:.0} % of its noise floor and the held-out part improves",
            100.0 * opts.min_share,
            50.0 * opts.min_share,
            100.0 * opts.holdout,
            100.0 * accept::WORSEN_TOL
        ),
        wall_times_s: BTreeMap::from([("total".to_string(), start.elapsed().as_secs_f64())]),
        elapsed_s: start.elapsed().as_secs_f64(),
    };
    // every catalog effect in exactly one list, with its reason
    debug_assert!(
        report.partition_errors().is_empty(),
        "{:?}",
        report.partition_errors()
    );
    Ok(Outcome {
        report,
        traces,
        rig: model,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::synth::{declared_for, record, truth_with, Foreign, Noise};

    /// Two effects planted, one allowed: the one that explains less passed
    /// the screen but was never decided, and had no reason (DATA_EMPS_PULSES'
    /// `external_force`, 19.8 %, ΔBIC −2106, printed with an empty reason).
    #[test]
    fn a_candidate_that_passed_the_screen_but_was_not_added_says_why() {
        let both = [EffectId::PressureViscous, EffectId::ExternalForce];
        let truth = truth_with(&both);
        let rec = record(&truth, 3000, 1e-3, Noise::default(), Foreign::None, 1);
        let opts = DiagnoseOptions {
            max_effects: 1,
            ..DiagnoseOptions::default()
        };
        let out = diagnose_bench(&declared_for(&[]), &[rec], &opts, &mut |_, _, _| {}).unwrap();
        let r = &out.report;
        assert_eq!(r.effects_added.len(), 1, "{:?}", r.effects_added);
        let added = &r.effects_added[0].id;
        let other = r
            .effects_rejected
            .iter()
            .find(|e| e.effect.explained_share >= opts.min_share && e.effect.delta_bic < 0.0)
            .expect("a candidate that passed the screen");
        assert!(
            other
                .reason
                .contains(&format!("explains less than {added}")),
            "{}: {}",
            other.effect.id,
            other.reason
        );
        assert!(
            r.partition_errors().is_empty(),
            "{:?}",
            r.partition_errors()
        );
    }
}
