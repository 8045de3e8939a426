//! `cargo xtask energy`: the chapter-8 efficiency matrix of the valve and
//! hybrid drives (Tables 8-2, 8-3) and the thesis's improvements (sections
//! 8.2, 9.2), each with its energy ledger.
//!
//! Runs every scenario in parallel (rayon, both cores), prints the matrix with
//! the thesis's values beside and the ledger breakdown, writes
//! `target/energy/energy.json`, a power-in/out SVG per scenario and a stacked
//! bar of where the energy went, and reports its wall time.

use hydrocyl_studies::chapter8::{
    run_scenario, scenarios_for, Drive, FrictionCase, Outcome, Plan, Scenario, HYBRID_NOT_AHEAD,
};
use plotters::prelude::*;
use rayon::prelude::*;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// The ledger must close to this fraction of the energy in.
const CLOSURE: f64 = 1e-3;

/// The storage cross-check's limit for runs whose chambers cavitate (the
/// chattering solenoid variants): the pressures there swing through the
/// vapour pressure hundreds of times, and the integrated storage power and
/// the end states agree to ~1e-3 of the (small) energy in.
const CHATTER_STORAGE: f64 = 3e-3;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_else(|| PathBuf::from("."))
}

/// Runs the task; returns `true` on success.
pub fn run() -> bool {
    let start = Instant::now();
    let root = root();
    let mut drives: Vec<(String, Drive, Plan)> = Vec::new();
    match Drive::wang_valve_c10() {
        Ok(d) => drives.push(("valve".into(), d, Plan::default())),
        Err(e) => {
            eprintln!("xtask energy: {e}");
            return false;
        }
    }
    drives.push(("hybrid".into(), Drive::wang_hybrid(), Plan::default()));
    // the default rows run the presets' own friction (Table 5-8, the seal term
    // bounded to its identification range, K H a on); named variants: K = 0
    // (the matrix before issue 17) and the hybrid without K H a
    let k0 = Plan {
        friction: FrictionCase::WithoutSealTerm,
        ..Plan::default()
    };
    if let Some((_, valve, _)) = drives.first().cloned() {
        drives.push(("valve-k0".into(), valve, k0.clone()));
    }
    drives.push(("hybrid-k0".into(), Drive::wang_hybrid(), k0));
    let h0 = Plan {
        friction: FrictionCase::WithoutAccelerationTerm,
        ..Plan::default()
    };
    drives.push(("hybrid-h0".into(), Drive::wang_hybrid(), h0));
    // relief valves 1 and 2 read every way the text allows (issue 17 item 2)
    let readings = hydrocyl_studies::relief::readings();
    for (i, r) in readings.iter().enumerate() {
        drives.push((
            crate::energy_relief::system_name(i),
            r.drive(),
            Plan::default(),
        ));
    }
    // why the matrix runs without the seal term: the fold of eq 5.4's K term
    {
        use hydrocyl_studies::chapter7::{extend_fold_speed, extend_reserve_minimum};
        let rig = hydrocyl_system::hybrid::WangHybrid::preset();
        let w = hydrocyl_friction::Wang::table_5_8();
        let (v, r) = extend_reserve_minimum(&rig, &w);
        let fold = extend_fold_speed(&rig, &w).map_or("no fold".to_string(), |f| {
            format!("a fold at {:.1} mm/s", 1e3 * f)
        });
        println!(
            "with Table 5-8's seal gain K the hybrid drive's steady-extension force reserve falls to \
             {r:.2} N at {:.1} mm/s ({fold}; hydrocyl_studies::chapter7), so a transient \
             locks it; `valve`/`hybrid` run Table 5-8 with K bounded to 2.72 bar extending, 5.03 bar retracting and K H a on \
             (hydrocyl_friction::seal; docs/energy.md), `valve-k0`/`hybrid-k0` with K = 0, `hybrid-h0` without K H a",
            1e3 * v
        );
    }
    let jobs: Vec<(usize, Scenario)> = drives
        .iter()
        .enumerate()
        .flat_map(|(i, (name, _, _))| scenarios_for(name).into_iter().map(move |s| (i, s)))
        .collect();
    println!(
        "xtask energy: {} scenarios on {} threads (friction: {})",
        jobs.len(),
        rayon::current_num_threads(),
        Plan::default().friction.name()
    );
    let bar = crate::progress::bar("energy scenarios", jobs.len());
    let results: Vec<(Scenario, Result<Outcome, String>)> = jobs
        .par_iter()
        .map(|(i, sc)| {
            let (_, d, plan) = &drives[*i];
            let r = run_scenario(d, sc, plan).map_err(|e| e.to_string());
            bar.inc(1);
            (sc.clone(), r)
        })
        .collect();
    bar.finish_and_clear();
    let mut ok = true;
    let outcomes: Vec<&Outcome> = results
        .iter()
        .filter_map(|(sc, r)| match r {
            Ok(o) => Some(o),
            Err(e) => {
                println!("FAIL {}: {e}", sc.label());
                ok = false;
                None
            }
        })
        .collect();
    let (relief, outcomes): (Vec<&Outcome>, Vec<&Outcome>) = outcomes
        .into_iter()
        .partition(|o| crate::energy_relief::is_relief(&o.scenario.system));
    print_matrix(&outcomes);
    print_ledgers(&outcomes);
    ok &= checks(&outcomes);
    ok &= crate::energy_relief::closure(&relief, CLOSURE);
    let friction: Vec<(String, &'static str)> = drives
        .iter()
        .map(|(n, _, p)| (n.clone(), p.friction.name()))
        .collect();
    let relief_json = crate::energy_relief::report(&readings, &relief, &outcomes);
    let dir = root.join("target/energy");
    if let Err(e) = write_outputs(&dir, &outcomes, &relief_json, &friction) {
        println!("FAIL writing {}: {e}", dir.display());
        ok = false;
    } else {
        println!("wrote {}/energy.json and the SVG plots", dir.display());
    }
    ok &= crate::energy_ch9::run(&dir);
    println!(
        "xtask energy: wall time {:.1} s (goal < 30 s)",
        start.elapsed().as_secs_f64()
    );
    ok
}

fn pct(x: f64) -> String {
    format!("{:6.2} %", 100.0 * x)
}

fn print_matrix(outs: &[&Outcome]) {
    println!();
    println!(
        "{:<16} {:>6} {:<6} {:>5} | {:>9} {:>9} {:>6} | {:>9} {:>9} | {:>8} {:>8} {:>8} | biggest loss",
        "system", "mm/s", "wave", "kg", "hydrocyl", "thesis", "ratio", "ledger", "storage", "E_in J", "out J", "load J"
    );
    for o in outs {
        let s = &o.scenario;
        let l = &o.ledger;
        let big = l
            .losses
            .iter()
            .max_by(|a, b| a.energy_j.total_cmp(&b.energy_j))
            .map(|t| format!("{} {:.0} %", t.name, 100.0 * t.energy_j / l.energy_in_j))
            .unwrap_or_default();
        println!(
            "{:<16} {:>6} {:<6} {:>5} | {:>9} {:>9} {:>6} | {:>9.1e} {:>9.1e} | {:>8.1} {:>8.1} {:>8.1} | {big}",
            s.system,
            format!("±{}", s.speed_mm_s),
            s.wave.name(),
            s.load_kg,
            pct(o.efficiency),
            o.thesis_efficiency.map(pct).unwrap_or_else(|| "—".into()),
            o.thesis_efficiency
                .map(|t| format!("{:.2}", o.efficiency / t))
                .unwrap_or_else(|| "—".into()),
            l.error,
            l.storage_error,
            l.energy_in_j,
            l.cylinder_out_j,
            l.load_out_j
        );
    }
}

fn print_ledgers(outs: &[&Outcome]) {
    println!();
    println!("ledger breakdown (share of the energy in; storage and load signed):");
    for o in outs {
        let l = &o.ledger;
        let mut parts: Vec<String> = l
            .losses
            .iter()
            .map(|t| format!("{} {:.1}", t.name, 100.0 * t.energy_j / l.energy_in_j))
            .collect();
        parts.push(format!(
            "storage {:.2}",
            100.0 * l.total_storage_j() / l.energy_in_j
        ));
        parts.push(format!("load {:.2}", 100.0 * l.load_out_j / l.energy_in_j));
        println!(
            "  {:<42} E_in {:8.1} J | {} | peaks +{:.0}/-{:.0} mm/s | cavitation entries {}, stop impacts {}",
            o.scenario.label(),
            l.energy_in_j,
            parts.join(", "),
            o.peak_speeds_mm_s.0,
            o.peak_speeds_mm_s.1,
            o.cavitation_entries(),
            o.stop_impacts()
        );
    }
}

fn checks(outs: &[&Outcome]) -> bool {
    let mut ok = true;
    println!();
    for o in outs {
        let l = &o.ledger;
        let storage_limit = if o.cavitation_entries() > 0.0 {
            CHATTER_STORAGE
        } else {
            CLOSURE
        };
        if l.error.abs() > CLOSURE || l.storage_error.abs() > storage_limit {
            println!(
                "FAIL ledger of {}: balance {:.2e} (limit {CLOSURE:.0e}), storage {:.2e} (limit {storage_limit:.0e})",
                o.scenario.label(),
                l.error,
                l.storage_error
            );
            ok = false;
        }
    }
    let find = |sys: &str, sc: &Scenario| {
        outs.iter().find(|o| {
            o.scenario.system == sys
                && o.scenario.speed_mm_s == sc.speed_mm_s
                && o.scenario.wave == sc.wave
                && o.scenario.load_kg == sc.load_kg
        })
    };
    // the ordering of Tables 8-2/8-3 (hybrid ahead everywhere), except where
    // hydrocyl states its disagreement (chapter8::HYBRID_NOT_AHEAD): there the
    // valve must be ahead, as measured, or the list is stale
    let mut agree = 0;
    let base = scenarios_for("valve");
    for sc in &base {
        match (find("valve", sc), find("hybrid", sc)) {
            (Some(v), Some(h)) if (h.efficiency > v.efficiency) != sc.hybrid_not_ahead() => {
                agree += 1;
                if sc.hybrid_not_ahead() {
                    println!(
                        "NOTE hybrid below valve at {} ({} vs {}): hydrocyl disagrees with Tables 8-2/8-3 here \
                         (docs/energy.md, \"Where hydrocyl differs\")",
                        sc.label(),
                        pct(h.efficiency),
                        pct(v.efficiency)
                    );
                }
            }
            (Some(v), Some(h)) => {
                println!(
                    "FAIL at {}: hybrid {} vs valve {}, expected hybrid {}",
                    sc.label(),
                    pct(h.efficiency),
                    pct(v.efficiency),
                    if sc.hybrid_not_ahead() {
                        "below (HYBRID_NOT_AHEAD)"
                    } else {
                        "above"
                    }
                );
                ok = false;
            }
            _ => ok = false,
        }
    }
    println!(
        "{} the ledger closes to {CLOSURE:.0e} of E_in in every scenario run",
        if ok { "PASS" } else { "CHECK" }
    );
    println!(
        "{} hybrid vs valve ordering as expected in {agree} of {} base scenarios (hybrid ahead in {})",
        if agree == base.len() { "PASS" } else { "FAIL" },
        base.len(),
        base.len() - HYBRID_NOT_AHEAD.len()
    );
    ok && agree == base.len()
}

fn file_stem(s: &Scenario) -> String {
    format!(
        "{}-{}mms-{}-{}kg",
        s.system,
        s.speed_mm_s,
        s.wave.name(),
        s.load_kg
    )
    .replace(['+', ' '], "_")
}

pub(crate) fn row(o: &Outcome, friction: &[(String, &'static str)]) -> Value {
    let s = &o.scenario;
    let l = &o.ledger;
    let terms: serde_json::Map<String, Value> = l
        .named_terms()
        .into_iter()
        .map(|(k, v)| (k, json!(v)))
        .collect();
    json!({
        "system": s.system,
        "speed_mm_s": s.speed_mm_s,
        "wave": s.wave.name(),
        "load_kg": s.load_kg,
        "efficiency": o.efficiency,
        "thesis_efficiency": o.thesis_efficiency,
        "ledger_error": l.error,
        "storage_error": l.storage_error,
        "energy_in_j": l.energy_in_j,
        "cylinder_out_j": l.cylinder_out_j,
        "load_out_j": l.load_out_j,
        "window_s": [l.window_s.0, l.window_s.1],
        "friction": friction
            .iter()
            .find(|(n, _)| *n == s.system)
            .map_or(Plan::default().friction.name(), |(_, f)| *f),
        "pump_volume_m3": o.pump_volume_m3,
        "peak_speeds_mm_s": [o.peak_speeds_mm_s.0, o.peak_speeds_mm_s.1],
        "cavitation_entries": o.cavitation_entries(),
        "stop_impacts": o.stop_impacts(),
        "terms": terms,
        "plot": format!("{}.svg", file_stem(s)),
    })
}

/// Writes `text` to `path` through a temporary file, so no half-written
/// output is left behind.
fn write_atomic(path: &Path, text: &str) -> Result<(), String> {
    let tmp = path.with_extension("tmp");
    std::fs::write(&tmp, text).map_err(|e| format!("{}: {e}", tmp.display()))?;
    std::fs::rename(&tmp, path).map_err(|e| format!("{}: {e}", path.display()))
}

fn write_outputs(
    dir: &Path,
    outs: &[&Outcome],
    relief: &[Value],
    friction: &[(String, &'static str)],
) -> Result<(), String> {
    std::fs::create_dir_all(dir).map_err(|e| e.to_string())?;
    let mut rows: Vec<Value> = outs.iter().map(|o| row(o, friction)).collect();
    rows.extend(relief.iter().cloned());
    let text = serde_json::to_string_pretty(&rows).map_err(|e| e.to_string())?;
    write_atomic(&dir.join("energy.json"), &text)?;
    for o in outs {
        let path = dir.join(format!("{}.svg", file_stem(&o.scenario)));
        let tmp = path.with_extension("tmp.svg");
        power_plot(&tmp, o)?;
        std::fs::rename(&tmp, &path).map_err(|e| e.to_string())?;
    }
    let path = dir.join("where-the-energy-went.svg");
    let tmp = path.with_extension("tmp.svg");
    stacked_bar(&tmp, outs)?;
    std::fs::rename(&tmp, &path).map_err(|e| e.to_string())
}

fn power_plot(path: &Path, o: &Outcome) -> Result<(), String> {
    let tr = &o.trace;
    let t1 = tr.time_s.last().copied().unwrap_or(1.0);
    let (lo, hi) = tr
        .power_in_w
        .iter()
        .chain(&tr.power_out_w)
        .fold((0.0f64, 0.0f64), |(a, b), v| (a.min(*v), b.max(*v)));
    let pad = 0.05 * (hi - lo).max(1.0);
    let root = SVGBackend::new(path, (900, 420)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let title = format!(
        "{}: efficiency {:.2} % (thesis {})",
        o.scenario.label(),
        100.0 * o.efficiency,
        o.thesis_efficiency
            .map(|t| format!("{:.2} %", 100.0 * t))
            .unwrap_or_else(|| "—".into())
    );
    let mut chart = ChartBuilder::on(&root)
        .caption(title, ("sans-serif", 16))
        .margin(10)
        .x_label_area_size(35)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..t1, (lo - pad)..(hi + pad))
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .x_desc("time [s]")
        .y_desc("power [W]")
        .draw()
        .map_err(|e| e.to_string())?;
    for (name, ys, c) in [
        ("power in (eqs 8.1/8.5-8.6)", &tr.power_in_w, BLUE),
        ("power out v(p1A1 - p2A2) (eq 8.7)", &tr.power_out_w, RED),
    ] {
        chart
            .draw_series(LineSeries::new(
                tr.time_s.iter().zip(ys.iter()).map(|(t, y)| (*t, *y)),
                c.stroke_width(1),
            ))
            .map_err(|e| e.to_string())?
            .label(name)
            .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], c));
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.8))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}

/// Loss categories of the stacked bar, by ledger term name prefix.
fn category(name: &str) -> &'static str {
    match name {
        "valve" => "servovalve metering edges",
        "friction" => "friction",
        "relief_1" | "relief_2" => "relief valves 1, 2",
        "solenoid_1" | "solenoid_2" => "solenoid valves",
        "needle_valve" => "needle valve",
        "pilot_valve" => "pilot four-way valve",
        n if n.starts_with("relief_3") => "relief valve 3 (200 bar)",
        n if n.starts_with("check") => "check valves",
        _ => "other",
    }
}

const CATEGORIES: [&str; 9] = [
    "friction",
    "servovalve metering edges",
    "relief valves 1, 2",
    "solenoid valves",
    "pilot four-way valve",
    "needle valve",
    "relief valve 3 (200 bar)",
    "check valves",
    "other",
];

fn stacked_bar(path: &Path, outs: &[&Outcome]) -> Result<(), String> {
    let n = outs.len();
    let root = SVGBackend::new(path, (1400, 600)).into_drawing_area();
    root.fill(&WHITE).map_err(|e| e.to_string())?;
    let mut chart = ChartBuilder::on(&root)
        .caption(
            "Where the energy went (share of the energy in, over the ledger window)",
            ("sans-serif", 16),
        )
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(60)
        .build_cartesian_2d(0.0..(n as f64), 0.0..105.0)
        .map_err(|e| e.to_string())?;
    chart
        .configure_mesh()
        .disable_x_mesh()
        .x_labels(n.min(60))
        .x_label_formatter(&|x| {
            let i = *x as usize;
            outs.get(i)
                .map(|_| format!("{}", i + 1))
                .unwrap_or_default()
        })
        .x_desc("scenario (numbered as in energy.json)")
        .y_desc("share of energy in [%]")
        .draw()
        .map_err(|e| e.to_string())?;
    let colours = [
        RED,
        BLUE,
        GREEN,
        CYAN,
        MAGENTA,
        RGBColor(255, 140, 0),
        BLACK,
        RGBColor(128, 128, 128),
        YELLOW,
    ];
    for (ci, cat) in CATEGORIES.iter().enumerate() {
        let c = colours[ci % colours.len()];
        let bars: Vec<Rectangle<(f64, f64)>> = outs
            .iter()
            .enumerate()
            .map(|(i, o)| {
                let l = &o.ledger;
                let share = |pred: &dyn Fn(&str) -> bool| {
                    100.0
                        * l.losses
                            .iter()
                            .filter(|t| pred(category(&t.name)))
                            .map(|t| t.energy_j)
                            .sum::<f64>()
                        / l.energy_in_j
                };
                let below = share(&|k| CATEGORIES[..ci].contains(&k));
                let this = share(&|k| k == *cat);
                let x = i as f64;
                Rectangle::new([(x + 0.1, below), (x + 0.9, below + this)], c.filled())
            })
            .collect();
        chart
            .draw_series(bars)
            .map_err(|e| e.to_string())?
            .label(*cat)
            .legend(move |(x, y)| Rectangle::new([(x, y - 5), (x + 15, y + 5)], c.filled()));
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .draw()
        .map_err(|e| e.to_string())?;
    root.present().map_err(|e| e.to_string())
}
