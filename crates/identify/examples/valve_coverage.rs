//! How often the valve rig's 95 % intervals cover the planted value: one
//! effect planted in a 2 s `leaney-moog` record, noise seeds 50–59 (as
//! docs/diagnose.md's coverage table). `cargo run -p hydrocyl-identify
//! --example valve_coverage [effect ...]`.

use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::diagnose::DiagnoseOptions;
use hydrocyl_identify::synth::{valve_planted, valve_planted_all, valve_record};
use hydrocyl_identify::valve::{diagnose_valve, set};
use hydrocyl_system::valve_rig::ValveRig;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let ids: Vec<EffectId> = if args.is_empty() {
        vec![
            EffectId::InternalLeakage,
            EffectId::ExternalForce,
            EffectId::FlowGainError,
            EffectId::ValveNullBias,
        ]
    } else {
        args.iter()
            .map(|a| EffectId::from_id(a).expect("an effect id"))
            .collect()
    };
    for id in ids {
        let (name, truth) = valve_planted(id).expect("a planted value");
        let mut rig = ValveRig::leaney_moog();
        for (n, v) in valve_planted_all(id) {
            set(&mut rig, id, n, v);
        }
        let mut misses = Vec::new();
        for seed in 50..60 {
            let rec = valve_record(&rig, 2000, 1e-3, seed).expect("record");
            let r = diagnose_valve(
                &ValveRig::leaney_moog(),
                &rec,
                &DiagnoseOptions::default(),
                &mut |_, _, _| {},
            )
            .expect("diagnosis");
            let Some(e) = r.effects_added.iter().find(|e| e.id == id.id()) else {
                misses.push(format!("seed {seed}: not added"));
                continue;
            };
            let (got, ci) = (e.params[name], e.ci95[name].unwrap_or(f64::NAN));
            let k = (got - truth).abs() / ci;
            if k.is_nan() || k > 1.0 {
                misses.push(format!("seed {seed}: {k:.2}x"));
            }
        }
        println!("{id}.{name}: {} misses of 10 {misses:?}", misses.len());
    }
}
