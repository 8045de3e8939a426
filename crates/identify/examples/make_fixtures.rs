//! Writes the generated friction-bench fixtures of `fixtures/measured/`:
//! `cargo run -p hydrocyl-identify --example make_fixtures -- fixtures/measured`
//! (`-- --rigs-only fixtures/measured` writes the rig files alone and leaves
//! the records as they are).
//!
//! Each case is a record of [`synth::truth_with`] (the declared bench plus
//! the planted effects at realistic magnitude) on [`synth::motion`], 8 s at
//! 500 Hz, with the default sensor noise, and the declared rig (the truth
//! without the planted effects) as `<case>.rig.json`: the bench's netlist
//! with its identification section (`FrictionBench::netlist`).
//!
//! The valve-rig records `valve-<effect>.csv` ([`synth::valve_fixture_cases`])
//! are `leaney-moog` with one effect on at [`synth::valve_planted`]'s
//! magnitude, simulated by [`synth::valve_record`] (2 s at 1 kHz, seed
//! [`synth::VALVE_FIXTURE_SEED`]); their declared rig is the preset itself.

use std::path::PathBuf;

use hydrocyl_identify::data::{write_atomic, Signal};
use hydrocyl_identify::synth::{self, Noise};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let rigs_only = args.iter().any(|a| a == "--rigs-only");
    let dir = PathBuf::from(
        args.iter()
            .find(|a| !a.starts_with("--"))
            .cloned()
            .unwrap_or_else(|| "fixtures/measured".into()),
    );
    std::fs::create_dir_all(&dir)?;
    for case in synth::fixture_cases() {
        let mut declared = synth::declared_for(&case.planted);
        declared.name = case.name.clone();
        let json = serde_json::to_string_pretty(&declared.netlist()?)? + "\n";
        write_atomic(
            &dir.join(format!("{}.rig.json", case.name)),
            json.as_bytes(),
        )?;
        if rigs_only {
            println!("{}: rig file", case.name);
            continue;
        }
        let truth = synth::truth_with(&case.planted);
        let rec = synth::record(
            &truth,
            4000,
            2e-3,
            Noise::default(),
            case.foreign,
            case.seed,
        );
        let mut csv = String::from("time [s],position [mm],p2 [bar],force [N]\n");
        let x = &rec.signals[&Signal::Position];
        let p = &rec.signals[&Signal::P2];
        let f = &rec.signals[&Signal::Force];
        for i in 0..rec.time.len() {
            csv.push_str(&format!(
                "{:.3},{:.5},{:.5},{:.3}\n",
                rec.time[i],
                x[i] * 1e3,
                p[i] * 1e-5,
                f[i]
            ));
        }
        write_atomic(&dir.join(format!("{}.csv", case.name)), csv.as_bytes())?;
        println!(
            "{}: planted {:?}, foreign {:?}",
            case.name, case.planted, case.foreign
        );
    }
    if rigs_only {
        return Ok(());
    }
    // Valve rig (leaney-moog): nothing missing, and each valve-rig effect alone.
    for (name, planted) in synth::valve_fixture_cases() {
        let mut truth = hydrocyl_system::valve_rig::ValveRig::leaney_moog();
        if let Some(id) = planted {
            for (p, v) in synth::valve_planted_all(id) {
                hydrocyl_identify::valve::set(&mut truth, id, p, v);
            }
        }
        let rec = synth::valve_record(&truth, 2000, 1e-3, synth::VALVE_FIXTURE_SEED)?;
        let mut csv = String::from("time [s],command,position [mm],p1 [bar],p2 [bar]\n");
        let g = |s: Signal| &rec.signals[&s];
        for i in 0..rec.time.len() {
            csv.push_str(&format!(
                "{:.3},{:.6},{:.4},{:.4},{:.4}\n",
                rec.time[i],
                g(Signal::Command)[i],
                g(Signal::Position)[i] * 1e3,
                g(Signal::P1)[i] * 1e-5,
                g(Signal::P2)[i] * 1e-5
            ));
        }
        write_atomic(&dir.join(format!("{name}.csv")), csv.as_bytes())?;
        println!("{name}: planted {planted:?} on leaney-moog");
    }
    Ok(())
}
