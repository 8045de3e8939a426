//! `cargo xtask bench --only record`: reading a measured record of ten
//! signals (`Record::parse`, what `hydrocyl diagnose` and the Python
//! package read a record with) against the record reader hydrocyl had when
//! issue 19 was filed (b2aea94^, `Record::parse` of that tree), kept here as
//! the reference: the `csv` crate's records (trimmed), per cell
//! `str::parse`, the finiteness check, the unit factor, the time's increase
//! and the signal's column found in a `BTreeMap`. The rows of
//! `--only csv` time the number conversion paths alone (the previous one as
//! the `csv` crate's records with `str::parse`, without that reader's checks
//! and look-ups); this row times the whole read a user waits for.

use crate::bench_csv::interleaved_ns;
use crate::bench_solve::square_case;
use hydrocyl_identify::data::{ColumnMap, Record, Signal};
use hydrocyl_identify::plaincsv::{run_columns, write_columns, PlainCsv};
use hydrocyl_system::run::Solver;
use std::collections::BTreeMap;

/// Rounds of the interleaved timing.
const ROUNDS: usize = 40;

/// The ten signals of the measured-data format with their SI units, as a
/// record's header names them.
const HEADERS: [&str; 10] = [
    "time [s]",
    "command [-]",
    "position [m]",
    "reference [m]",
    "velocity [m/s]",
    "p1 [Pa]",
    "p2 [Pa]",
    "ps [Pa]",
    "flow [m^3/s]",
    "force [N]",
];

/// A record's time and its other signals, as the previous reader returned
/// them.
type Read = (Vec<f64>, BTreeMap<Signal, Vec<f64>>);

/// The record reader of b2aea94^ (issue 19's "today"), its per-row work
/// unchanged: the header's columns mapped once (as there), then each record
/// of the `csv` crate checked for its length and each cell parsed, checked
/// finite, scaled, and put into its signal's vector through the map (the
/// time's cells checked increasing). `None` where that reader gave an error.
fn reader_before(text: &str) -> Option<Read> {
    let mut rdr = csv::ReaderBuilder::new()
        .has_headers(true)
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers = rdr.headers().ok()?.clone();
    let mut cols: Vec<Option<(Signal, f64)>> = vec![None; headers.len()];
    for (j, h) in headers.iter().enumerate() {
        let (name, unit) = h.split_once('[').unwrap_or((h, ""));
        let sig = Signal::from_name(name.trim())?;
        let unit = unit.trim_end_matches(']').trim();
        cols[j] = Some((sig, sig.unit_factor(unit)?));
    }
    let mut time: Vec<f64> = Vec::new();
    let mut signals: BTreeMap<Signal, Vec<f64>> = cols
        .iter()
        .flatten()
        .filter(|(s, _)| *s != Signal::Time)
        .map(|(s, _)| (*s, Vec::new()))
        .collect();
    for rec in rdr.records() {
        let rec = rec.ok()?;
        if rec.len() != headers.len() {
            return None;
        }
        for (j, col) in cols.iter().enumerate() {
            let Some((sig, factor)) = col else { continue };
            let v: f64 = rec[j].parse().ok()?;
            if !v.is_finite() {
                return None;
            }
            let v = v * factor;
            if *sig == Signal::Time {
                if time.last().is_some_and(|&prev| v <= prev) {
                    return None;
                }
                time.push(v);
            } else if let Some(s) = signals.get_mut(sig) {
                s.push(v);
            }
        }
    }
    Some((time, signals))
}

/// A record of the ten signals, 10 s at 1 kHz: the issue-19 case's ten
/// output columns (time and nine channels, full-precision values, some
/// held) under the ten signals' headers.
fn record_text() -> Result<String, String> {
    let run = square_case(10.0)?.run(Solver::Dp45, 1e-5)?;
    let (names, columns) = run_columns(&run);
    if columns.len() != HEADERS.len() {
        return Err(format!(
            "the case has {} columns, the record {}",
            names.len(),
            HEADERS.len()
        ));
    }
    String::from_utf8(write_columns(&HEADERS, &columns)).map_err(|e| e.to_string())
}

/// Reading a 10-signal record per row: `Record::parse` against the reader
/// of b2aea94^, interleaved, after checking both read the same values.
pub(crate) fn record_per_row() -> Result<(), String> {
    let text = record_text()?;
    let map = ColumnMap::default();
    let now = Record::parse("bench.csv", &text, &map).map_err(|e| e.to_string())?;
    let (time, signals) = reader_before(&text).ok_or("the previous reader refused the record")?;
    if now.time != time || now.signals != signals {
        return Err("the two readers read different values".into());
    }
    let rows = time.len() as f64;
    let all: Vec<usize> = (0..HEADERS.len()).collect();
    let threads = PlainCsv::new(&text).map_or(1, |p| p.threads(&all));
    let [new, old] = interleaved_ns(
        ROUNDS,
        [
            &mut || Record::parse("bench.csv", &text, &map).map_or(0, |r| r.time.len()),
            &mut || reader_before(&text).map_or(0, |r| r.0.len()),
        ],
    )
    .map(|t| t.per(rows));
    println!(
        "CSV, measured record of 10 signals ({} rows), read with Record::parse ({threads} threads): {} (the reader when issue 19 was filed, b2aea94^: {}), {}; goal >= 10x",
        time.len(),
        new.show(),
        old.show(),
        new.speedup(old),
    );
    Ok(())
}
