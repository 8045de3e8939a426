//! Reduces the TU Delft pneumatic seal friction records (Zillen 2021, CC0;
//! `../shared/data/pneumatic_seal_friction_tudelft/csv_with_header/`) to one
//! row per steady stroke, the fixture
//! `fixtures/measured/tudelft-seal-strokes.csv` (see its PROVENANCE file).
//!
//! Per file (one seal, one chamber pressure, 10 back-and-forth strokes at
//! 100 Hz): the first 15 samples are dropped (as the authors do); velocity is
//! the central difference of the laser position over ±10 samples (0.2 s); a
//! stroke is a run of at least 100 samples with |v| > 2 mm/s of one sign; its
//! middle half (25 % trimmed at each end, away from the reversals) is
//! averaged: velocity, gauge pressure, and `F − p A` with the nominal piston
//! area (25 mm bore, 25.7 mm for the `*257` seals), which is friction plus
//! an area-calibration offset.
//!
//! ```sh
//! cargo run -p hydrocyl-friction --example reduce_tudelft_seals -- \
//!     ../shared/data/pneumatic_seal_friction_tudelft/csv_with_header \
//!     fixtures/measured/tudelft-seal-strokes.csv
//! ```
//!
//! The output is written to a temporary file and renamed into place, so a
//! failure never leaves a half-written fixture.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

const SEALS: [&str; 7] = [
    "KDN",
    "NAP310",
    "NAPN",
    "O-ring",
    "O-ring257",
    "PK",
    "X-ring257",
];
const PRESSURES: [u32; 4] = [1, 3, 5, 7];

struct Sample {
    t: f64,
    x: f64,
    p: f64,
    f: f64,
}

fn read(path: &Path) -> Result<Vec<Sample>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate().skip(1) {
        let cols: Vec<&str> = line.split(',').collect();
        if cols.len() != 7 {
            return Err(format!(
                "{}, line {}: {} columns, expected 7",
                path.display(),
                i + 1,
                cols.len()
            ));
        }
        let num = |k: usize| -> Result<f64, String> {
            cols[k]
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    format!(
                        "{}, line {}: column {} = {:?} is not a number",
                        path.display(),
                        i + 1,
                        k + 1,
                        cols[k]
                    )
                })
        };
        out.push(Sample {
            t: num(0)? * 1e-3,
            x: num(4)? * 1e-3,
            p: num(5)? * 1e5,
            f: num(6)?,
        });
    }
    Ok(out)
}

/// Per-stroke means: (direction, velocity m/s, pressure Pa, F − pA N, samples).
fn strokes(s: &[Sample], area: f64) -> Vec<(i8, f64, f64, f64, usize)> {
    let s = &s[15.min(s.len())..];
    let w = 10;
    let n = s.len();
    let v: Vec<f64> = (0..n)
        .map(|i| {
            if i < w || i + w >= n {
                0.0
            } else {
                (s[i + w].x - s[i - w].x) / (s[i + w].t - s[i - w].t)
            }
        })
        .collect();
    let dir = |vi: f64| -> i8 {
        if vi > 2e-3 {
            1
        } else if vi < -2e-3 {
            -1
        } else {
            0
        }
    };
    let mut out = Vec::new();
    let mut i = 0;
    while i < n {
        let d = dir(v[i]);
        let mut j = i;
        while j < n && dir(v[j]) == d {
            j += 1;
        }
        if d != 0 && j - i >= 100 {
            let (a, b) = (i + (j - i) / 4, j - (j - i) / 4);
            let m = (b - a) as f64;
            let vel = (s[b - 1].x - s[a].x) / (s[b - 1].t - s[a].t);
            let p = s[a..b].iter().map(|q| q.p).sum::<f64>() / m;
            let f = s[a..b].iter().map(|q| q.f - q.p * area).sum::<f64>() / m;
            out.push((d, vel, p, f, b - a));
        }
        i = j;
    }
    out
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let (src, dst) = match args.as_slice() {
        [_, a, b] => (PathBuf::from(a), PathBuf::from(b)),
        _ => {
            eprintln!("usage: reduce_tudelft_seals <csv_with_header dir> <output csv>");
            std::process::exit(2);
        }
    };
    let mut csv = String::from(
        "seal,bore_mm,nominal_bar,stroke,direction,velocity_mm_per_s,pressure_bar,force_minus_pa_n,samples\n",
    );
    for seal in SEALS {
        let bore = if seal.ends_with("257") { 25.7 } else { 25.0 };
        let area = std::f64::consts::PI * (bore * 1e-3 / 2.0_f64).powi(2);
        for bar in PRESSURES {
            let path = src.join(format!("{seal}_{bar}bar.csv"));
            let samples = match read(&path) {
                Ok(s) => s,
                Err(e) => {
                    eprintln!("error: {e}");
                    std::process::exit(2);
                }
            };
            for (k, (d, vel, p, f, m)) in strokes(&samples, area).into_iter().enumerate() {
                let _ = writeln!(
                    csv,
                    "{seal},{bore},{bar},{k},{d},{:.4},{:.5},{:.4},{m}",
                    vel * 1e3,
                    p * 1e-5,
                    f
                );
            }
        }
    }
    let tmp = dst.with_extension("csv.tmp");
    if let Err(e) = std::fs::write(&tmp, csv).and_then(|_| std::fs::rename(&tmp, &dst)) {
        let _ = std::fs::remove_file(&tmp);
        eprintln!("error: cannot write {}: {e}", dst.display());
        std::process::exit(2);
    }
    println!("wrote {}", dst.display());
}
