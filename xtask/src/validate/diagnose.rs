//! Validation section: diagnose — the measured-data loop on the generated
//! fixtures (effect planted vs effect found, NRMSE before/after vs the noise
//! floor), the speed goal, and the real EMPS and TU Delft records when
//! `../shared/data` is present.

use std::path::{Path, PathBuf};
use std::time::Instant;

use hydrocyl_identify::bench::{self, FrictionBench};
use hydrocyl_identify::catalog::EffectId;
use hydrocyl_identify::data::Record;
use hydrocyl_identify::diagnose::{diagnose_bench, DiagnoseOptions, Outcome};
use hydrocyl_identify::synth::{self, Foreign, Noise};

use super::doc_table::DocTable;
use crate::report::Section;

/// The document whose tables of diagnose results are checked here.
const DOC: &str = "docs/diagnose.md";

/// The table of [`DOC`] whose header row starts with `header`, or a failed
/// check saying it is not there.
fn doc_table(s: &mut Section, header: &str) -> Option<DocTable> {
    let table = std::fs::read_to_string(root().join(DOC))
        .ok()
        .and_then(|text| DocTable::find(DOC, &text, header));
    if table.is_none() {
        s.check(
            &format!("{DOC}: the table `{header} ...`"),
            "not found".into(),
            "a table".into(),
            false,
        );
    }
    table
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from("."), Path::to_path_buf)
}

fn run(rig: &FrictionBench, recs: &[Record]) -> Result<Outcome, String> {
    diagnose_bench(rig, recs, &DiagnoseOptions::default(), &mut |_, _, _| {})
        .map_err(|e| e.to_string())
}

fn ids(o: &Outcome) -> String {
    let v: Vec<&str> = o
        .report
        .effects_added
        .iter()
        .map(|e| e.id.as_str())
        .collect();
    if v.is_empty() {
        "none".into()
    } else {
        v.join("+")
    }
}

/// Runs this section and returns what it measured.
pub fn section() -> Section {
    let mut s = Section::new("diagnose");
    let dir = root().join("fixtures/measured");
    let doc = doc_table(&mut s, "| fixture | planted | found | force NRMSE");
    s.note(&format!(
        "{:<40} {:<38} {:<38} {:>9} {:>9} {:>9}",
        "fixture", "planted", "found", "nrmse0", "nrmse1", "floor"
    ));
    for case in synth::fixture_cases() {
        let csv = dir.join(format!("{}.csv", case.name));
        let rigf = dir.join(format!("{}.rig.json", case.name));
        let loaded = std::fs::read_to_string(&rigf)
            .map_err(|e| format!("{}: {e}", rigf.display()))
            .and_then(|t| serde_json::from_str(&t).map_err(|e| e.to_string()))
            .and_then(|v| FrictionBench::from_rig(&v))
            .and_then(|rig| {
                Record::read(&csv)
                    .map(|r| (rig, r))
                    .map_err(|e| e.to_string())
            });
        let (rig, rec) = match loaded {
            Ok(x) => x,
            Err(e) => {
                s.check(&case.name, e, "readable fixture".into(), false);
                continue;
            }
        };
        let o = match run(&rig, &[rec]) {
            Ok(o) => o,
            Err(e) => {
                s.check(&case.name, e, "diagnosed".into(), false);
                continue;
            }
        };
        let r = &o.report;
        let planted = match case.foreign {
            Foreign::None if case.planted.is_empty() => "none".to_string(),
            Foreign::None => case
                .planted
                .iter()
                .map(|e| e.id())
                .collect::<Vec<_>>()
                .join("+"),
            Foreign::Spring(_) => "spring (not in catalog)".into(),
            Foreign::ForceDelay(_) => "force delay (not in catalog)".into(),
        };
        let found = ids(&o);
        let found_text = match (&r.unexplained_resembles, case.foreign) {
            (Some(p), Foreign::Spring(_) | Foreign::ForceDelay(_)) => {
                format!("{found}; unexplained ~ {}", p.kind)
            }
            _ => found.clone(),
        };
        let (n0, n1, fl) = (
            r.nrmse_before["force"],
            r.nrmse_after["force"],
            r.noise_floor["force"],
        );
        s.note(&format!(
            "{:<40} {:<38} {:<38} {:>9.5} {:>9.5} {:>9.5}",
            case.name, planted, found_text, n0, n1, fl
        ));
        if let Some(doc) = &doc {
            doc.check_row(&mut s, &case.name, &[(3, vec![n0, n1]), (4, vec![fl])], &[]);
        }
        let pass = match case.foreign {
            Foreign::None => {
                let mut want: Vec<&str> = case.planted.iter().map(|e| e.id()).collect();
                let mut got: Vec<&str> = r.effects_added.iter().map(|e| e.id.as_str()).collect();
                want.sort();
                got.sort();
                want == got && n1 <= 1.5 * fl
            }
            _ => r.effects_added.is_empty() && r.unexplained_resembles.is_some(),
        };
        s.check(
            &format!("{}: found / NRMSE", case.name),
            format!("{found}, {n1:.5}"),
            format!("{planted}, <= 1.5 x {fl:.5}"),
            pass,
        );
    }
    // Speed: a 12 s record at 1 kHz with one planted effect.
    let truth = synth::truth_with(&[EffectId::PressureViscous]);
    let rec = synth::record(&truth, 12_000, 1e-3, Noise::default(), Foreign::None, 7);
    let t0 = Instant::now();
    let ok = run(&synth::declared_for(&[EffectId::PressureViscous]), &[rec]).is_ok();
    let el = t0.elapsed().as_secs_f64();
    s.check(
        "friction bench: 12 s at 1 kHz record diagnosed",
        if ok { "a report" } else { "an error" }.into(),
        "a report".into(),
        ok,
    );
    timing_note(&mut s, "friction bench", el);
    valve(&mut s, &dir);
    real_data(&mut s);
    s
}

/// The valve rig (`leaney-moog`): the generated fixtures and the speed goal.
fn valve(s: &mut Section, dir: &Path) {
    use hydrocyl_identify::valve::{diagnose_valve, set};
    use hydrocyl_system::valve_rig::ValveRig;
    let doc = doc_table(s, "| fixture | planted | found | fitted");
    for (name, planted_id) in synth::valve_fixture_cases() {
        let planted = planted_id.map_or("none", |id| id.id());
        let res = Record::read(&dir.join(format!("{name}.csv")))
            .map_err(|e| e.to_string())
            .and_then(|r| {
                diagnose_valve(
                    &ValveRig::leaney_moog(),
                    &r,
                    &DiagnoseOptions::default(),
                    &mut |_, _, _| {},
                )
                .map_err(|e| e.to_string())
            });
        match res {
            Ok(r) => {
                let found: Vec<&str> = r.effects_added.iter().map(|e| e.id.as_str()).collect();
                let found = if found.is_empty() {
                    "none".to_string()
                } else {
                    found.join("+")
                };
                let within = ["position", "p1", "p2"]
                    .iter()
                    .all(|c| r.nrmse_after[*c] <= 1.5 * r.noise_floor[*c]);
                // the planted parameter: fitted ± 95 % interval vs planted
                let param = planted_id
                    .and_then(|id| synth::valve_planted(id).map(|(n, v)| (id, n, v)))
                    .and_then(|(id, n, v)| {
                        let e = r.effects_added.iter().find(|e| e.id == id.id())?;
                        let got = e.params.get(n).copied()?;
                        let ci = e.ci95.get(n).copied().flatten().unwrap_or(f64::NAN);
                        Some(format!("; {n} {got:.4e} ± {ci:.1e} (planted {v:.4e})"))
                    })
                    .unwrap_or_default();
                s.note(&format!(
                    "{name:<40} {planted:<38} {found:<38} NRMSE before -> after (floor): position {:.2e}->{:.2e} ({:.2e}), p1 {:.5}->{:.5} ({:.5}), p2 {:.5}->{:.5} ({:.5}){param}",
                    r.nrmse_before["position"], r.nrmse_after["position"], r.noise_floor["position"],
                    r.nrmse_before["p1"], r.nrmse_after["p1"], r.noise_floor["p1"],
                    r.nrmse_before["p2"], r.nrmse_after["p2"], r.noise_floor["p2"],
                ));
                if let Some(doc) = &doc {
                    check_valve_row(s, doc, &name, &r);
                }
                s.check(
                    &format!("{name}: found / NRMSE"),
                    format!("{found}, {}", if within { "within" } else { "above" }),
                    format!("{planted}, every channel <= 1.5 x floor"),
                    found == planted && within,
                );
            }
            Err(e) => s.check(&format!("{name}: diagnosed"), e, "a report".into(), false),
        }
    }
    // Speed: 12 s at 1 kHz on the valve rig, one planted leak.
    let mut truth = ValveRig::leaney_moog();
    if let Some((p, v)) = synth::valve_planted(EffectId::InternalLeakage) {
        set(&mut truth, EffectId::InternalLeakage, p, v);
    }
    match synth::valve_record(&truth, 12_000, 1e-3, 9) {
        Ok(rec) => {
            let t0 = Instant::now();
            let ok = diagnose_valve(
                &ValveRig::leaney_moog(),
                &rec,
                &DiagnoseOptions::default(),
                &mut |_, _, _| {},
            )
            .is_ok_and(|r| {
                r.effects_added
                    .first()
                    .is_some_and(|e| e.id == "internal_leakage")
            });
            let el = t0.elapsed().as_secs_f64();
            s.check(
                "valve rig: 12 s at 1 kHz record, internal_leakage found first",
                if ok { "found" } else { "not found" }.into(),
                "found".into(),
                ok,
            );
            timing_note(s, "valve rig", el);
        }
        Err(e) => s.check(
            "valve rig: 12 s record generated",
            e,
            "a record".into(),
            false,
        ),
    }
}

/// The row of a valve fixture in [`DOC`]'s table: the effects found, the
/// fitted parameter with its 95 % half-width (the first effect's, named in
/// the cell), and the NRMSE of p1, p2 and position before → after (floor).
fn check_valve_row(
    s: &mut Section,
    doc: &DocTable,
    name: &str,
    r: &hydrocyl_identify::diagnose::Report,
) {
    let found: Vec<&str> = r.effects_added.iter().map(|e| e.id.as_str()).collect();
    let found = if found.is_empty() {
        "nothing".to_string()
    } else {
        found.join(" + ")
    };
    let mut numbers: Vec<(usize, Vec<f64>)> = ["p1", "p2", "position"]
        .iter()
        .enumerate()
        .map(|(k, c)| {
            (
                4 + k,
                vec![r.nrmse_before[*c], r.nrmse_after[*c], r.noise_floor[*c]],
            )
        })
        .collect();
    // the fitted cell names its parameter first: `Cl 1e-11 ± 1e-15`
    let fitted = doc.cell(name, 3).unwrap_or_default();
    if let (Some(param), Some(e)) = (fitted.split_whitespace().next(), r.effects_added.first()) {
        if let Some(&v) = e.params.get(param) {
            let ci = e.ci95.get(param).copied().flatten().unwrap_or(f64::NAN);
            numbers.push((3, vec![v, ci]));
        }
    }
    doc.check_row(s, name, &numbers, &[(2, found)]);
}

/// Reports a diagnose wall time against the goal. Wall time depends on
/// the machine and on what else runs on it, so it is reported here and
/// measured as a ratio in `cargo xtask bench`, never asserted.
fn timing_note(s: &mut Section, what: &str, seconds: f64) {
    s.note(&format!(
        "{what}: 12 s at 1 kHz diagnosed in {seconds:.2} s wall (goal < 10 s on the development machine; {}; not a pass/fail check)",
        if seconds < 10.0 { "met here" } else { "NOT met here" }
    ));
}

/// The acceptance rule on a real-data report: every added effect has an
/// interval for each parameter (a parameter on a bound has none) and its
/// size's interval excludes zero; the effects that break it, or "none".
fn unaccepted(o: &Outcome) -> String {
    let r = &o.report;
    let fc = r
        .declared_refit
        .iter()
        .find(|p| o.rig.param(&p.name) == Some(hydrocyl_identify::bench::ParamRef::Coulomb))
        .map_or(o.rig.friction.coulomb, |p| p.fitted);
    let bad: Vec<String> = r
        .effects_added
        .iter()
        .filter(|e| {
            let Some(id) = EffectId::from_id(&e.id) else {
                return true;
            };
            let v = |n: &str| e.params.get(n).copied().unwrap_or(0.0);
            let size = hydrocyl_identify::accept::size(id, v, |_| 0.0, fc);
            let ci = e.ci95.get(size.name).copied().flatten();
            e.ci95.values().any(Option::is_none) || ci.is_none_or(|c| size.value.abs() <= c)
        })
        .map(|e| e.id.clone())
        .collect();
    if bad.is_empty() {
        "none".into()
    } else {
        bad.join(", ")
    }
}

fn real_data(s: &mut Section) {
    let data = root().join("../shared/data");
    let emps = data.join("emps_friction_benchmark/DATA_EMPS.csv");
    if let (true, Some(rig)) = (emps.exists(), bench::preset("emps")) {
        match Record::read_mapped(&emps, &rig.columns)
            .map_err(|e| e.to_string())
            .and_then(|r| run(&rig, &[r]))
        {
            Ok(o) => {
                let r = &o.report;
                let get = |n: &str| {
                    r.declared_refit
                        .iter()
                        .find(|p| p.name == n)
                        .map_or(f64::NAN, |p| p.fitted)
                };
                // Reference IDIM-LS model of the benchmark (Janot et al. 2019):
                // M = 95.1089 kg, Fv = 203.5034 N s/m, Fc = 20.3935 N, offset -3.1648 N.
                let rel = |a: f64, b: f64| (a / b - 1.0).abs();
                s.check(
                    "EMPS mass m [kg]",
                    format!("{:.2}", get("drive.mass")),
                    "95.11 (IDIM-LS), within 3 %".into(),
                    rel(get("drive.mass"), 95.1089) < 0.03,
                );
                s.check(
                    "EMPS viscous b [N s/m]",
                    format!("{:.1}", get("friction.viscous")),
                    "203.5 (IDIM-LS), within 5 %".into(),
                    rel(get("friction.viscous"), 203.5034) < 0.05,
                );
                s.check(
                    "EMPS Coulomb Fc [N]",
                    format!("{:.2}", get("friction.coulomb")),
                    "20.39 (IDIM-LS), within 5 %".into(),
                    rel(get("friction.coulomb"), 20.3935) < 0.05,
                );
                let off = r
                    .effects_added
                    .iter()
                    .find(|e| e.id == "coulomb_asymmetry")
                    .map_or(f64::NAN, |e| 0.5 * e.params["dFc"]);
                s.check(
                    "EMPS offset while moving dFc/2 [N]",
                    format!("{off:.2}"),
                    "-3.16 (IDIM-LS offset), within 0.5 N".into(),
                    (off + 3.1648).abs() < 0.5,
                );
                let bad = unaccepted(&o);
                s.check(
                    "EMPS: added effects pass the acceptance rule",
                    bad.clone(),
                    "none (every parameter with an interval, size's excludes zero)".into(),
                    bad == "none",
                );
                s.note(&format!(
                    "EMPS: added {}; force NRMSE declared {:.4} -> refit {:.4} -> after {:.4}",
                    ids(&o),
                    r.nrmse_declared["force"],
                    r.nrmse_before["force"],
                    r.nrmse_after["force"]
                ));
            }
            Err(e) => s.check("EMPS diagnosed", e, "a report".into(), false),
        }
    } else {
        s.note("EMPS: ../shared/data/emps_friction_benchmark not present, skipped");
    }
    let tud = data.join("pneumatic_seal_friction_tudelft/csv_with_header");
    if tud.exists() {
        let Some(rig) = bench::preset("tudelft-seal-25") else {
            return;
        };
        let recs: Result<Vec<Record>, String> = [1, 3, 5, 7]
            .iter()
            .map(|p| {
                Record::read_mapped(&tud.join(format!("NAPN_{p}bar.csv")), &rig.columns)
                    .map_err(|e| e.to_string())
            })
            .collect();
        match recs.and_then(|r| run(&rig, &r)) {
            Ok(o) => {
                let r = &o.report;
                let found = r.effects_added.iter().any(|e| e.id == "pressure_viscous");
                s.check(
                    "TU Delft NAPN 1-7 bar: pressure dependence found",
                    ids(&o),
                    "pressure_viscous among the added".into(),
                    found,
                );
                let bad = unaccepted(&o);
                s.check(
                    "TU Delft NAPN: added effects pass the acceptance rule",
                    bad.clone(),
                    "none (every parameter with an interval, size's excludes zero)".into(),
                    bad == "none",
                );
                s.note(&format!(
                    "TU Delft NAPN: added {}; force NRMSE declared {:.4} -> refit {:.4} -> after {:.4}; unexplained {:.0} %",
                    ids(&o),
                    r.nrmse_declared["force"],
                    r.nrmse_before["force"],
                    r.nrmse_after["force"],
                    100.0 * r.unexplained_share
                ));
            }
            Err(e) => s.check("TU Delft NAPN diagnosed", e, "a report".into(), false),
        }
    } else {
        s.note("TU Delft: ../shared/data/pneumatic_seal_friction_tudelft not present, skipped");
    }
}
