//! Writes the generated friction-bench fixtures of `fixtures/measured/`:
//! `cargo run -p hydrocyl-identify --example make_fixtures -- fixtures/measured`.
//!
//! Each case is a record of [`synth::truth_with`] (the declared bench plus
//! the planted effects at realistic magnitude) on [`synth::motion`], 8 s at
//! 500 Hz, with the default sensor noise, and the declared rig (the truth
//! without the planted effects) as `<case>.rig.json`.

use std::path::PathBuf;

use hydrocyl_identify::data::write_atomic;
use hydrocyl_identify::synth::{self, Noise};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = PathBuf::from(
        std::env::args()
            .nth(1)
            .unwrap_or_else(|| "fixtures/measured".into()),
    );
    std::fs::create_dir_all(&dir)?;
    for case in synth::fixture_cases() {
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
        let x = &rec.signals[&hydrocyl_identify::data::Signal::Position];
        let p = &rec.signals[&hydrocyl_identify::data::Signal::P2];
        let f = &rec.signals[&hydrocyl_identify::data::Signal::Force];
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
        let mut declared = synth::declared_for(&case.planted);
        declared.name = case.name.clone();
        let json = serde_json::to_string_pretty(&declared)?;
        write_atomic(
            &dir.join(format!("{}.rig.json", case.name)),
            json.as_bytes(),
        )?;
        println!(
            "{}: planted {:?}, foreign {:?}",
            case.name, case.planted, case.foreign
        );
    }
    Ok(())
}
