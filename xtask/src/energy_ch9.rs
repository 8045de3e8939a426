//! `cargo xtask energy`'s chapter-9 rows (thesis section 9.2, issue 17):
//! the needle optimiser's openings per speed, the servo needle's fitted law,
//! and every chapter-9 variant beside the pilot-shifted drive (efficiency,
//! energy in, stall at reversal, drift per period, ledger), appended to
//! `energy.json` as rows with `"study": "chapter9"`.

use hydrocyl_studies::chapter9::compare::compare;
use hydrocyl_studies::chapter9::needle::Optimum;
use hydrocyl_studies::chapter9::Comparison;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The ledger must close to this fraction of the energy in.
const CLOSURE: f64 = 1e-3;

fn rigs() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/rigs")
}

/// Runs the chapter-9 study, prints it, appends its rows to
/// `dir/energy.json`; returns `true` when every ledger closes.
pub fn run(dir: &Path) -> bool {
    let c = match compare(&rigs()) {
        Ok(c) => c,
        Err(e) => {
            println!("FAIL chapter 9: {e}");
            return false;
        }
    };
    print(&c);
    let mut ok = true;
    for r in &c.rows {
        if r.measured.ledger_error.abs() > CLOSURE {
            println!(
                "FAIL chapter-9 ledger of {} ±{} mm/s {} kg: {:.2e}",
                r.system, r.case.speed_mm_s, r.case.load_kg, r.measured.ledger_error
            );
            ok = false;
        }
    }
    println!(
        "{} chapter-9 ledgers close to {CLOSURE:.0e} of E_in ({} rows)",
        if ok { "PASS" } else { "FAIL" },
        c.rows.len()
    );
    match append(&dir.join("energy.json"), &c) {
        Ok(()) => println!(
            "appended the chapter-9 rows to {}/energy.json",
            dir.display()
        ),
        Err(e) => {
            println!("FAIL writing the chapter-9 rows: {e}");
            ok = false;
        }
    }
    ok
}

fn print_optimum(label: &str, o: &Optimum) {
    println!(
        "  {label} ±{} mm/s: {:.2} mm² (E_in {:.1} J over both loads, peak overrun {:.1} %, steady {:.1} %; {} simulations pairs)",
        o.speed_mm_s,
        1e6 * o.best.area_m2,
        o.best.objective_j,
        100.0 * o.best.overrun,
        100.0 * o.best.steady_overrun,
        o.evaluations.len()
    );
}

fn print(c: &Comparison) {
    println!();
    println!("chapter 9 (section 9.2): the needle opening of least energy in, peak overrun <= 20 %, steady <= 5 %");
    for o in &c.needle {
        print_optimum("pilot-shifted drive", o);
    }
    for o in &c.needle_solenoid {
        print_optimum("solenoid drive     ", o);
    }
    println!(
        "  servo needle: A = {:.2} mm² + {:.3} mm²/V u+ + {:.3} mm²/V u-",
        1e6 * c.servo.area_min,
        1e6 * c.servo.gain_positive,
        1e6 * c.servo.gain_negative
    );
    println!(
        "{:<26} {:>5} {:>4} | {:>8} {:>8} | {:>13} {:>9} {:>8} | {:>8}",
        "system", "mm/s", "kg", "eff", "E_in J", "stall r/e ms", "drift mm", "overrun", "ledger"
    );
    for r in &c.rows {
        let m = &r.measured;
        println!(
            "{:<26} {:>5} {:>4} | {:>6.2} % {:>8.1} | {:>6.0}/{:<6.0} {:>+9.2} {:>7.1} % | {:>8.1e}",
            r.system,
            r.case.speed_mm_s,
            r.case.load_kg,
            100.0 * m.efficiency,
            m.energy_in_j,
            1e3 * m.stall_s.0,
            1e3 * m.stall_s.1,
            1e3 * m.drift_m,
            100.0 * m.overrun,
            m.ledger_error
        );
    }
}

fn append(path: &Path, c: &Comparison) -> Result<(), String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let mut rows: Vec<Value> = serde_json::from_str(&text).map_err(|e| e.to_string())?;
    for r in &c.rows {
        let m = &r.measured;
        rows.push(json!({
            "study": "chapter9",
            "system": r.system,
            "speed_mm_s": r.case.speed_mm_s,
            "wave": "square",
            "load_kg": r.case.load_kg,
            "sets": r.sets,
            "efficiency": m.efficiency,
            "energy_in_j": m.energy_in_j,
            "ledger_error": m.ledger_error,
            "stall_s": [m.stall_s.0, m.stall_s.1],
            "drift_m_per_period": m.drift_m,
            "overrun": m.overrun,
            "steady_overrun": m.steady_overrun,
            "min_chamber_pa": m.min_chamber_pa,
            "losses_j": m.losses,
        }));
    }
    rows.push(json!({
        "study": "chapter9-choices",
        "needle_pilot_shifted": c.needle.iter().map(|o| json!({"speed_mm_s": o.speed_mm_s, "best": o.best, "evaluations": o.evaluations})).collect::<Vec<_>>(),
        "needle_solenoid": c.needle_solenoid.iter().map(|o| json!({"speed_mm_s": o.speed_mm_s, "best": o.best, "evaluations": o.evaluations})).collect::<Vec<_>>(),
        "servo_needle": c.servo,
    }));
    let out = serde_json::to_string_pretty(&rows).map_err(|e| e.to_string())?;
    let tmp = path.with_extension("json.tmp");
    std::fs::write(&tmp, out).map_err(|e| e.to_string())?;
    std::fs::rename(&tmp, path).map_err(|e| e.to_string())
}
