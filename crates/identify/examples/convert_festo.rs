//! Converts the Festo didactic bench's hanging-load record (Mårtensson,
//! MataveID data; `../shared/data/festo_hydraulic_bench_mataveid/hanging_load.csv`,
//! 50 Hz, signals in volts) to the measured-data format for
//! `fixtures/measured/festo-hanging-load.rig.json`.
//!
//! The provenance states no units; the scales are assumptions, recorded in
//! `fixtures/measured/festo-hanging-load.PROVENANCE.md`:
//! * `command` = controller output u / 10 V (a ±10 V proportional-valve input
//!   read as the normalised spool demand);
//! * `position [mm]` = (position_V − 5 V) × 20 mm/V (a 0–10 V transducer over
//!   a 200 mm stroke, 0 at mid-stroke);
//! * `reference [mm]` = (reference_V − 5 V) × 20 mm/V, the same scale: the
//!   record is closed loop, and its reference drives the rig's controller.
//!
//! ```sh
//! cargo run -p hydrocyl-identify --example convert_festo -- \
//!     ../shared/data/festo_hydraulic_bench_mataveid/hanging_load.csv fixtures/measured/festo-hanging-load.csv
//! ```
//!
//! Written to a temporary file and renamed into place.

use std::fmt::Write as _;

/// Volts of controller output per unit of normalised spool demand.
const COMMAND_FULL_SCALE_V: f64 = 10.0;
/// Transducer voltage at mid-stroke.
const POSITION_MID_V: f64 = 5.0;
/// Millimetres of stroke per volt of transducer output.
const POSITION_MM_PER_V: f64 = 20.0;

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(2);
    }
}

fn run() -> Result<(), String> {
    let args: Vec<String> = std::env::args().collect();
    let [_, src, dst] = args.as_slice() else {
        return Err("usage: convert_festo <hanging_load.csv> <output csv>".into());
    };
    let text = std::fs::read_to_string(src).map_err(|e| format!("cannot read {src}: {e}"))?;
    let mut out = String::from("time [s],command,position [mm],reference [mm]\n");
    for (i, line) in text.lines().enumerate().skip(1) {
        let cols: Vec<f64> = line
            .split(',')
            .map(|c| c.trim().parse::<f64>().unwrap_or(f64::NAN))
            .collect();
        if cols.len() != 4 || cols.iter().any(|c| !c.is_finite()) {
            return Err(format!(
                "{src}, line {}: expected 4 numbers (t, reference, position, u)",
                i + 1
            ));
        }
        let (t, r, y, u) = (cols[0], cols[1], cols[2], cols[3]);
        let _ = writeln!(
            out,
            "{t:.2},{:.6},{:.4},{:.4}",
            u / COMMAND_FULL_SCALE_V,
            (y - POSITION_MID_V) * POSITION_MM_PER_V,
            (r - POSITION_MID_V) * POSITION_MM_PER_V
        );
    }
    let tmp = format!("{dst}.tmp");
    std::fs::write(&tmp, out).map_err(|e| format!("cannot write {tmp}: {e}"))?;
    std::fs::rename(&tmp, dst).map_err(|e| format!("cannot rename {tmp} to {dst}: {e}"))
}
