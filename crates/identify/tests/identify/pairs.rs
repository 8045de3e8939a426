//! The pair step and the initial state "before" starts from, on short
//! generated `leaney-moog` records (2.5 s at 2 ms).

use hydrocyl_identify::accept::WORSEN_TOL;
use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::diagnose::{DiagnoseOptions, Report};
use hydrocyl_identify::synth::{valve_command, valve_record_with};
use hydrocyl_identify::valve::{diagnose_valve, set};
use hydrocyl_system::valve_rig::ValveRig;

/// `leaney-moog` with `planted` (effect, parameter, value) simulated for
/// 2.5 s at 2 ms (noise 20 µm, 20 kPa) and diagnosed against the preset.
fn diagnose_planted(planted: &[(EffectId, &str, f64)], seed: u64) -> Report {
    let mut truth = ValveRig::leaney_moog();
    for (id, name, v) in planted {
        set(&mut truth, *id, name, *v);
    }
    let rec = valve_record_with(&truth, 1250, 2e-3, seed, 0.0, &valve_command).unwrap();
    diagnose_valve(
        &ValveRig::leaney_moog(),
        &rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .unwrap()
}

/// Every planted parameter is found within its 95 % interval.
fn check_covered(r: &Report, planted: &[(EffectId, &str, f64)]) {
    for (id, name, v) in planted {
        let e = r
            .effects_added
            .iter()
            .find(|e| e.id == id.id())
            .unwrap_or_else(|| panic!("{} not added\n{}", id.id(), r.human()));
        let (got, ci) = (e.params[*name], e.ci95[*name].expect("interval"));
        assert!(
            (got - v).abs() <= ci,
            "{name} = {got} ± {ci}, planted {v}\n{}",
            r.human()
        );
    }
}

/// A leak and a null bias of opposite drift: each alone explains little of
/// what the pair does (they cancel in part), and the greedy forward step
/// added a flow-gain error in their place (t34 rec_leakbias; on this short
/// record the old loop added `flow_gain_error` kw ≈ 0.93 alone). The pair
/// step finds the true pair, both within their intervals, and says the two
/// were added together.
#[test]
fn a_leak_and_a_null_bias_that_cancel_in_part_are_found_as_a_pair() {
    let planted = [
        (EffectId::InternalLeakage, "Cl", 5e-12),
        (EffectId::ValveNullBias, "xb", -8e-6),
    ];
    let r = diagnose_planted(&planted, 61);
    let mut ids: Vec<&str> = r.effects_added.iter().map(|e| e.id.as_str()).collect();
    ids.sort();
    assert_eq!(
        ids,
        ["internal_leakage", "valve_null_bias"],
        "{}",
        r.human()
    );
    check_covered(&r, &planted);
    for e in &r.effects_added {
        let note = e.note.as_deref().unwrap_or_default();
        assert!(
            note.starts_with("added together with") && note.contains("pair step"),
            "{}: {note:?}\n{}",
            e.id,
            r.human()
        );
    }
    for (ch, floor) in r.noise_floor.iter().filter(|(_, f)| **f > 0.0) {
        let after = r.nrmse_after[ch];
        assert!(
            after <= 1.5 * floor,
            "{ch}: {after} vs {floor}\n{}",
            r.human()
        );
    }
}

/// t34 defect 3: on a leak record the initial-state fit of the declared
/// model bought position with both pressures (p1 0.063 -> 0.076 on this
/// short record), so "before" read worse than "declared". The fitted
/// initial state is kept only where no compared channel gets worse beyond
/// the acceptance rule's tolerance; the report says which one "before"
/// starts from, and the leak is still found.
#[test]
fn before_is_never_worse_than_declared() {
    let planted = [(EffectId::InternalLeakage, "Cl", 5e-12)];
    let r = diagnose_planted(&planted, 62);
    for (ch, floor) in r.noise_floor.iter().filter(|(_, f)| **f > 0.0) {
        let (decl, before) = (r.nrmse_declared[ch], r.nrmse_before[ch]);
        assert!(
            before <= decl + WORSEN_TOL * floor,
            "{ch}: before {before} vs declared {decl}\n{}",
            r.human()
        );
    }
    assert!(
        r.initial_state
            .contains("\"before\" starts from initial position and velocity the smoother's, kept"),
        "{}",
        r.initial_state
    );
    check_covered(&r, &planted);
}
