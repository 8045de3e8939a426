//! Fuzz targets of the two readers of user files: the command CSV reader
//! ([`crate::command::parse_command`]) and the rig reader (JSON text →
//! duplicate-key scan → rig check with path and line, [`crate::rigfile`]).
//! Input: arbitrary bytes, and valid files with bytes flipped, cut or
//! inserted (to get past the first parse). The property: no panic, and an
//! accepted command is a finite, strictly increasing record.
//!
//! A short run is an ordinary test (`HYDROCYL_FUZZ_CASES`, default 1000 per
//! target). The long run is `#[ignore]`d: `HYDROCYL_FUZZ_MINUTES=10 cargo
//! test -p hydrocyl-cli --bin hydrocyl fuzz_for_minutes -- --ignored
//! --nocapture` runs both targets until the time is up and prints the
//! number of executions. A crash proptest finds is kept as a regression seed
//! in `fuzz-corpus/` (committed; `the_corpus_passes` runs it) and fixed.
//! Found so far: the rig reader's line scanner (`netlist::locate::scan`)
//! allocates without bound on text that does not parse, its documented
//! precondition; `rig::load` only scans parsed text, as does this target.

use crate::command::{parse_command, CommandUnit};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};

const CSV_SEED: &str = "time [ms],command,comment\n0,0.1,x\n10,-0.2,y\n20,1e6,z\n30,0.5,\n";

/// The rig files the mutations start from.
fn rig_seeds() -> Vec<String> {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../../fixtures/");
    [
        "rigs/leaney-moog.json",
        "measured/festo-hanging-load.rig.json",
        "rigs/wang-hybrid-solenoid.json",
    ]
    .iter()
    .filter_map(|f| std::fs::read_to_string(format!("{root}{f}")).ok())
    .collect()
}

/// A mutation of `seed`: at byte `at` (mod length) replace, delete or
/// insert `with`.
fn mutate(seed: &[u8], op: u8, at: usize, with: &[u8]) -> Vec<u8> {
    let mut b = seed.to_vec();
    let i = at % (b.len() + 1);
    match op % 3 {
        0 => {
            for (k, &c) in with.iter().enumerate() {
                if let Some(x) = b.get_mut(i + k) {
                    *x = c;
                }
            }
        }
        1 => {
            let end = (i + with.len()).min(b.len());
            b.drain(i..end);
        }
        _ => {
            b.splice(i..i, with.iter().copied());
        }
    }
    b
}

fn bytes_or_mutation(seed: Vec<u8>) -> impl Strategy<Value = Vec<u8>> {
    prop_oneof![
        prop::collection::vec(any::<u8>(), 0..400),
        (
            any::<u8>(),
            any::<usize>(),
            prop::collection::vec(any::<u8>(), 1..8)
        )
            .prop_map(move |(op, at, with)| mutate(&seed, op, at, &with)),
    ]
}

/// The command reader on `bytes`.
fn command_target(bytes: &[u8]) -> Result<(), TestCaseError> {
    for unit in [CommandUnit::Normalised, CommandUnit::Volt] {
        if let Ok((t, u)) = parse_command("fuzz.csv", bytes, unit) {
            prop_assert!(t.len() >= 2 && t.len() == u.len());
            prop_assert!(t.windows(2).all(|w| w[1] > w[0]));
            prop_assert!(u.iter().chain(&t).all(|v| v.is_finite()));
        }
    }
    Ok(())
}

/// The rig reader on `bytes` (the steps of `rig::load` and the check).
fn rig_target(bytes: &[u8]) -> Result<(), TestCaseError> {
    // HYDROCYL_FUZZ_LAST=file keeps the input being tried (to catch a hang
    // or an abort, which no panic hook sees)
    if let Ok(f) = std::env::var("HYDROCYL_FUZZ_LAST") {
        let _ = std::fs::write(f, bytes);
    }
    let Ok(text) = std::str::from_utf8(bytes) else {
        return Ok(());
    };
    // as `rig::load`: the line scanner runs on text that parses (its
    // precondition; on other text it may allocate without bound)
    if let Ok(v) = serde_json::from_str::<serde_json::Value>(text) {
        let _ = hydrocyl_system::netlist::locate::scan(text);
        let _ = crate::rigfile::check(&v, "fuzz.json", &[]);
        let _ = hydrocyl_system::rig::parameters(&v);
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(
        std::env::var("HYDROCYL_FUZZ_CASES").ok().and_then(|s| s.parse().ok()).unwrap_or(1000)
    ))]
    #[test]
    fn command_reader_takes_any_bytes(b in bytes_or_mutation(CSV_SEED.as_bytes().to_vec())) {
        command_target(&b)?;
    }

    #[test]
    fn rig_reader_takes_any_bytes(k in 0usize..3, op in any::<u8>(), at in any::<usize>(),
                                  with in prop::collection::vec(any::<u8>(), 1..8),
                                  raw in prop::collection::vec(any::<u8>(), 0..400), use_raw in any::<bool>()) {
        let seeds = rig_seeds();
        let b = if use_raw || seeds.is_empty() { raw } else { mutate(seeds[k % seeds.len()].as_bytes(), op, at, &with) };
        rig_target(&b)?;
    }
}

/// Both targets for `HYDROCYL_FUZZ_MINUTES` minutes (default 1), printing
/// the executions per target.
#[test]
#[ignore = "long-running fuzz: HYDROCYL_FUZZ_MINUTES=10 ... -- --ignored"]
fn fuzz_for_minutes() {
    let minutes: f64 = std::env::var("HYDROCYL_FUZZ_MINUTES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1.0);
    let end = std::time::Instant::now() + std::time::Duration::from_secs_f64(60.0 * minutes);
    let seeds: Vec<Vec<u8>> = rig_seeds().into_iter().map(String::into_bytes).collect();
    let (n_cmd, n_rig) = (std::cell::Cell::new(0u64), std::cell::Cell::new(0u64));
    while std::time::Instant::now() < end {
        let config = Config {
            cases: 2000,
            failure_persistence: None,
            ..Config::default()
        };
        let mut runner = TestRunner::new(config.clone());
        runner
            .run(&bytes_or_mutation(CSV_SEED.as_bytes().to_vec()), |b| {
                n_cmd.set(n_cmd.get() + 1);
                command_target(&b)
            })
            .unwrap();
        for s in &seeds {
            let mut runner = TestRunner::new(config.clone());
            runner
                .run(&bytes_or_mutation(s.clone()), |b| {
                    n_rig.set(n_rig.get() + 1);
                    rig_target(&b)
                })
                .unwrap();
        }
    }
    println!(
        "fuzz: {} command-reader and {} rig-reader executions in {minutes} min, no failure",
        n_cmd.get(),
        n_rig.get()
    );
}

/// Every input in `fuzz-corpus/` (inputs that once failed a target or its
/// precondition) passes both targets.
#[test]
fn the_corpus_passes() {
    let dir = concat!(env!("CARGO_MANIFEST_DIR"), "/fuzz-corpus");
    let mut n = 0;
    for e in std::fs::read_dir(dir).unwrap() {
        let b = std::fs::read(e.unwrap().path()).unwrap();
        command_target(&b).unwrap();
        rig_target(&b).unwrap();
        n += 1;
    }
    assert!(n > 0, "empty corpus");
}
