//! Times `diagnose` on the issue-19 case: a 12 s, 1 kHz `leaney-moog`
//! record with a planted internal leak (noise seed 9, as `cargo xtask
//! bench`). `cargo run --release -p hydrocyl-identify --example diagnose_time`
//! (add `hybrid` for the hybrid rig's 4 s planted-leak record).

use std::time::Instant;

use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::diagnose::DiagnoseOptions;
use hydrocyl_identify::synth;
use hydrocyl_identify::valve::{diagnose_valve, set};
use hydrocyl_system::valve_rig::ValveRig;

fn main() {
    let mut truth = ValveRig::leaney_moog();
    let (p, v) = synth::valve_planted(EffectId::InternalLeakage).expect("planted value");
    set(&mut truth, EffectId::InternalLeakage, p, v);
    let t0 = Instant::now();
    let rec = synth::valve_record(&truth, 12_000, 1e-3, 9).expect("record");
    let sim = t0.elapsed().as_secs_f64();
    let t0 = Instant::now();
    let r = diagnose_valve(
        &ValveRig::leaney_moog(),
        &rec,
        &DiagnoseOptions::default(),
        &mut |_, _, _| {},
    )
    .expect("diagnosis");
    let el = t0.elapsed().as_secs_f64();
    let found: Vec<String> = r
        .effects_added
        .iter()
        .map(|e| format!("{} {:?} ± {:?}", e.id, e.params, e.ci95))
        .collect();
    println!(
        "record simulated in {:.1} ms; diagnosed in {el:.2} s wall, {} record simulations; found {found:?}",
        sim * 1e3,
        r.simulations
    );
    println!("stages: {:?}", r.wall_times_s);
}
