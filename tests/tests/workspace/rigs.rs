//! Rig files against presets, and every preset through the assembler.

use super::{files, root};
use hydrocyl_system::rig;
use hydrocyl_system::run::RunOptions;
use hydrocyl_system::signal::Signal;

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Every built-in preset has its file in `fixtures/rigs/`, and the two are
/// equal; every rig file of a kind the assembler knows checks.
#[test]
fn presets_equal_their_rig_files() {
    let dir = root().join("fixtures/rigs");
    for p in rig::PRESETS {
        let file = dir.join(format!("{}.json", p.name));
        assert!(file.exists(), "preset `{}` has no rig file", p.name);
        let preset = rig::preset(p.name).unwrap();
        assert_ne!(preset, serde_json::Value::Null, "preset `{}`", p.name);
        assert_eq!(
            preset,
            json(&file),
            "preset `{}` differs from its file",
            p.name
        );
        rig::check(&preset).unwrap_or_else(|e| panic!("preset `{}`: {e}", p.name));
    }
    for f in files(&dir, ".json") {
        let v = json(&f);
        let kind = v["kind"].as_str().unwrap_or_default().to_string();
        if rig::RIG_KINDS.iter().any(|k| k.kind == kind) {
            rig::check(&v).unwrap_or_else(|e| panic!("{}: {e}", f.display()));
        }
    }
}

/// A rig file with one parameter broken is refused with the parameter's name.
#[test]
fn a_broken_rig_file_is_refused_by_name() {
    for p in rig::PRESETS {
        let mut v = rig::preset(p.name).unwrap();
        // a friction bench has no cylinder: its drive's mass instead
        let path = if v["cylinder"]["area_1_m2"].is_number() {
            "cylinder.area_1_m2"
        } else if v["components"]["cylinder"].is_object() {
            "cylinder.area_1"
        } else {
            "drive.mass"
        };
        rig::apply_set(&mut v, &format!("{path}=-1.0"))
            .unwrap_or_else(|e| panic!("preset `{}`: {e}", p.name));
        let err = rig::check(&v).expect_err(p.name).to_string();
        let name = path.split('.').nth(1).unwrap();
        assert!(err.contains(name), "preset `{}`: {err}", p.name);
    }
}

/// Every preset runs 0.6 s of a command step through the assembler with the
/// stiff solver, and its output stays finite with the piston inside the
/// stroke. (The valve rigs take a normalised spool command, the pump rig a
/// drive voltage: a step to 20 % of each rig's range, extending.)
#[test]
fn every_preset_runs_a_step() {
    let t: Vec<f64> = (0..=60).map(|k| k as f64 * 0.01).collect();
    for p in rig::PRESETS {
        let v = rig::preset(p.name).unwrap();
        let after = if v["components"]["pump"].is_object() {
            2.0
        } else {
            0.2
        };
        let cmd = Signal::Step {
            time_s: 0.1,
            before: 0.0,
            after,
        };
        let opts = RunOptions {
            solver: hydrocyl_system::run::Solver::Rosenbrock,
            ..RunOptions::default()
        };
        let run = rig::simulate(&v, cmd, &t, &opts)
            .unwrap_or_else(|e| panic!("preset `{}`: {e}", p.name));
        assert_eq!(run.time.len(), t.len());
        for c in &run.channels {
            assert!(
                c.values.iter().all(|x| x.is_finite()),
                "preset `{}`: channel `{}` not finite",
                p.name,
                c.name
            );
        }
        let x = run.channel("position").unwrap();
        let cyl = &v["components"]["cylinder"];
        // a friction bench's drive imposes the motion: no stroke to leave
        let stroke = cyl["stroke"].as_f64().or(v["components"]["drive"]
            .is_object()
            .then_some(f64::INFINITY));
        let half_stroke = stroke.expect("every rig states its stroke") / 2.0;
        assert!(
            x.iter().all(|x| x.abs() <= half_stroke + 1e-12),
            "preset `{}` left the stroke",
            p.name
        );
        // a positive command extends every rig
        assert!(
            x[x.len() - 1] > x[0],
            "preset `{}`: x {} -> {}",
            p.name,
            x[0],
            x[x.len() - 1]
        );
    }
}
