//! The measured-data contract across crates: what `simulate` writes,
//! `identify` reads back; every shipped record reads and has a rig.

use super::{files, root};
use hydrocyl_identify::data::{write_csv, Record, Signal as DataSignal};
use hydrocyl_system::rig;
use hydrocyl_system::run::RunOptions;
use hydrocyl_system::signal::Signal;
use proptest::prelude::*;

/// Every record in `fixtures/measured/` that `diagnose` reads (a
/// `<name>.csv` with its `<name>.rig.json`, and the generated `valve-*`
/// records) is in the measured-data format: it reads without error, with
/// strictly increasing time, and its rig file is a netlist that checks (older
/// rig kinds are kept in `fixtures/legacy/` only). (The other
/// CSVs there are reduced tables of real data sets, read by the friction crate
/// in their own documented layouts.)
#[test]
fn every_diagnose_record_reads() {
    let dir = root().join("fixtures/measured");
    let csvs: Vec<_> = files(&dir, ".csv")
        .into_iter()
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            p.with_extension("rig.json").exists() || name.starts_with("valve-")
        })
        .collect();
    assert!(csvs.len() >= 10, "{} records", csvs.len());
    for f in csvs {
        let rec = Record::read(&f).unwrap_or_else(|e| panic!("{e}"));
        assert!(rec.len() > 1, "{}", f.display());
        assert!(rec.time.windows(2).all(|w| w[1] > w[0]), "{}", f.display());
        let rig_file = f.with_extension("rig.json");
        if rig_file.exists() {
            let v: serde_json::Value =
                serde_json::from_str(&std::fs::read_to_string(&rig_file).unwrap()).unwrap();
            assert_eq!(v["kind"], "netlist", "{}", rig_file.display());
            rig::check(&v).unwrap_or_else(|e| panic!("{}: {e}", rig_file.display()));
        }
    }
}

/// Real records carry their provenance beside them.
#[test]
fn real_records_have_provenance() {
    let dir = root().join("fixtures/measured");
    for name in [
        "wang-table-5-3",
        "emps-inverse-model",
        "tudelft-seal-strokes",
    ] {
        assert!(
            dir.join(format!("{name}.PROVENANCE.md")).exists(),
            "{name} has no provenance"
        );
        assert!(dir.join(format!("{name}.csv")).exists(), "{name}.csv");
    }
}

fn simulate_leaney_moog(amplitude: f64, period_s: f64, bias: f64) -> hydrocyl_system::run::Run {
    let v = rig::preset("leaney-moog").unwrap();
    let t: Vec<f64> = (0..=400).map(|k| k as f64 * 2.5e-3).collect();
    let cmd = Signal::Sine {
        amplitude,
        period_s,
        bias,
        phase_rad: 0.0,
    };
    rig::simulate(&v, cmd, &t, &RunOptions::dp45()).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(8))]

    /// A run of the valve rig written in the measured-data format reads back
    /// through `hydrocyl-identify` to the same signals (to the 10 significant
    /// digits the writer keeps), with the command first-order held between
    /// samples as the spec says.
    #[test]
    fn simulate_output_reads_back_through_identify(
        amplitude in 0.02f64..0.6,
        period_s in 0.3f64..2.0,
        bias in -0.1f64..0.1,
    ) {
        let run = simulate_leaney_moog(amplitude, period_s, bias);
        let names = [
            (DataSignal::Command, "command"),
            (DataSignal::Position, "position"),
            (DataSignal::Velocity, "velocity"),
            (DataSignal::P1, "p1"),
            (DataSignal::P2, "p2"),
        ];
        let cols: Vec<(DataSignal, &[f64])> = names
            .iter()
            .map(|&(s, n)| (s, run.channel(n).unwrap()))
            .collect();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.csv");
        write_csv(&path, &run.time, &cols).unwrap();
        let rec = Record::read(&path).unwrap();
        prop_assert_eq!(rec.len(), run.time.len());
        for (s, n) in names {
            let a = run.channel(n).unwrap();
            let b = rec.require(s).unwrap();
            let scale = a.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
            for (x, y) in a.iter().zip(b) {
                prop_assert!((x - y).abs() <= 1e-8 * scale, "{}: {} vs {}", n, x, y);
            }
        }
        // first-order hold between samples
        let k = 100;
        let tm = 0.5 * (rec.time[k] + rec.time[k + 1]);
        let c = rec.require(DataSignal::Command).unwrap();
        let mid = rec.interpolate(DataSignal::Command, tm).unwrap();
        prop_assert!((mid - 0.5 * (c[k] + c[k + 1])).abs() <= 1e-12);
    }
}
