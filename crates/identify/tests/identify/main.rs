//! hydrocyl-identify's integration tests, one binary (link time on 2 cores):
//! the loop on generated records with planted effects, on the friction bench
//! and on the valve rig.

mod checks;
mod closed_loop;
mod hybrid;
mod model;
mod pairs;
mod planted;
mod probes;
mod valve;

use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::diagnose::Report;

/// The ids of the effects added, in order.
fn ids(r: &Report) -> Vec<&str> {
    r.effects_added.iter().map(|e| e.id.as_str()).collect()
}

/// Only `id` is added, its parameter `name` within its 95 % interval of the
/// planted `value`, and every compared channel (a closed-loop record's
/// command among them) ends within 1.5 noise floors (a velocity derived from
/// the position has no floor: not compared).
fn check_found(r: &Report, id: EffectId, name: &str, value: f64) {
    check_found_within(r, id, name, value, 1.0);
}

/// As [`check_found`], with the planted value within `k` of the 95 %
/// intervals (`k` > 1 only where a test says which bias the interval leaves out).
fn check_found_within(r: &Report, id: EffectId, name: &str, value: f64, k: f64) {
    assert_eq!(ids(r), [id.id()], "{}", r.human());
    let e = &r.effects_added[0];
    assert!(
        (e.params[name] - value).abs() <= k * e.ci95[name].unwrap(),
        "{name} = {} ± {:?} (× {k}), planted {value}\n{}",
        e.params[name],
        e.ci95[name],
        r.human()
    );
    for (ch, floor) in r.noise_floor.iter().filter(|(_, f)| **f > 0.0) {
        let after = &r.nrmse_after[ch];
        assert!(
            *after <= 1.5 * floor,
            "{ch}: {after} vs floor {floor}\n{}",
            r.human()
        );
    }
}
