//! Validation section: chapter 9's further work on the hybrid drive (thesis
//! section 9.2), on the rig files as shipped at ±50 mm/s (the full study,
//! both speeds and the optimiser at each, is `cargo xtask energy`):
//!
//! * every chapter-9 rig runs and its ledger closes;
//! * the solenoid four-way valve: the efficiency and the stall at reversal
//!   beside the pilot-shifted drive's;
//! * the needle optimiser: the opening the needle file ships is the one the
//!   optimiser finds at ±50 mm/s, and that opening meets the overrun limits;
//! * the closed position loop: the drift per period under the symmetric
//!   reference against the open-loop drive's.

use crate::report::Section;
use hydrocyl_studies::chapter9::compare::load;
use hydrocyl_studies::chapter9::needle::{optimise, OVERRUN_LIMIT, STEADY_OVERRUN_LIMIT};
use hydrocyl_studies::chapter9::{run_case, Case, Measured, RIGS};
use std::collections::HashMap;
use std::path::Path;

fn ms(x: f64) -> String {
    format!("{:.0} ms", 1e3 * x)
}

/// Runs this section and returns what it measured.
pub fn section() -> Section {
    let mut s = Section::new("chapter9");
    let rigs = Path::new(env!("CARGO_MANIFEST_DIR")).join("../fixtures/rigs");
    let mut m: HashMap<(&str, u32), Measured> = HashMap::new();
    for name in RIGS {
        let v = match load(&rigs, name) {
            Ok(v) => v,
            Err(e) => {
                s.check(name, e.to_string(), "loads".into(), false);
                continue;
            }
        };
        for load_kg in [0.0, 20.0] {
            match run_case(
                &v,
                &Case {
                    speed_mm_s: 50.0,
                    load_kg,
                },
            ) {
                Ok(r) => {
                    s.check(
                        &format!("{name} ±50 mm/s {load_kg} kg: ledger"),
                        format!("{:.1e}", r.ledger_error),
                        "< 1e-3 of E_in".into(),
                        r.ledger_error.abs() < 1e-3,
                    );
                    m.insert((name, load_kg as u32), r);
                }
                Err(e) => s.check(name, e.to_string(), "runs".into(), false),
            }
        }
    }
    let get = |n: &'static str, kg: u32| m.get(&(n, kg));
    for kg in [0, 20] {
        if let (Some(p), Some(sol)) = (get("wang-hybrid", kg), get("wang-hybrid-solenoid", kg)) {
            s.check(
                &format!("solenoid four-way vs pilot-shifted, {kg} kg: efficiency"),
                format!(
                    "{:.1} % vs {:.1} %",
                    100.0 * sol.efficiency,
                    100.0 * p.efficiency
                ),
                "higher (no relief 1/2 cracking drop)".into(),
                sol.efficiency > p.efficiency,
            );
            s.check(
                &format!(
                    "solenoid four-way vs pilot-shifted, {kg} kg: stall to retract / to extend"
                ),
                format!(
                    "{} / {} vs {} / {}",
                    ms(sol.stall_s.0),
                    ms(sol.stall_s.1),
                    ms(p.stall_s.0),
                    ms(p.stall_s.1)
                ),
                "measured (both < 50 ms)".into(),
                sol.stall_s.0.max(sol.stall_s.1) < 0.05 && p.stall_s.0.max(p.stall_s.1) < 0.05,
            );
        }
        if let (Some(p), Some(cl)) = (get("wang-hybrid", kg), get("wang-hybrid-closed-loop", kg)) {
            s.check(
                &format!("closed position loop, {kg} kg: drift per period"),
                format!(
                    "{:+.3} mm vs open loop {:+.2} mm",
                    1e3 * cl.drift_m,
                    1e3 * p.drift_m
                ),
                "|closed| < 0.05 mm and < |open| / 5".into(),
                cl.drift_m.abs() < 5e-5 && cl.drift_m.abs() < p.drift_m.abs() / 5.0,
            );
        }
    }
    match (
        load(&rigs, "wang-hybrid-needle"),
        get("wang-hybrid-needle", 0),
    ) {
        (Ok(v), Some(_)) => {
            let shipped = v["components"]["needle_valve"]["area"]
                .as_f64()
                .unwrap_or(f64::NAN);
            match optimise(&v, 50.0) {
                Ok(o) => {
                    s.check(
                        "needle optimiser ±50 mm/s (pilot-shifted): opening",
                        format!(
                            "{:.3} mm², file ships {:.3} mm²",
                            1e6 * o.best.area_m2,
                            1e6 * shipped
                        ),
                        "the file ships the optimum (2 %)".into(),
                        (o.best.area_m2 / shipped - 1.0).abs() < 0.02,
                    );
                    s.check(
                        "needle optimum meets the damping limits",
                        format!(
                            "peak {:.1} %, steady {:.1} %",
                            100.0 * o.best.overrun,
                            100.0 * o.best.steady_overrun
                        ),
                        format!(
                            "<= {:.0} %, <= {:.0} %",
                            100.0 * OVERRUN_LIMIT,
                            100.0 * STEADY_OVERRUN_LIMIT
                        ),
                        o.best.objective_j.is_finite(),
                    );
                }
                Err(e) => s.check("needle optimiser", e.to_string(), "runs".into(), false),
            }
        }
        _ => s.check("needle file", "missing".into(), "loads".into(), false),
    }
    s
}
