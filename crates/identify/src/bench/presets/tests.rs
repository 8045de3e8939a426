//! Tests of the bench presets: legacy files read as their netlists, and
//! what every bench rig under `fixtures/` reads as, recorded.

use super::*;

fn fixtures() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures")
}

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Each older `friction-bench` file kept in `fixtures/legacy/` reads as
/// the same bench, field for field, as the file's own declaration: its
/// netlist in `fixtures/measured/`, that netlist with every default
/// written out (`--print-rig`), and the older file itself (migrated). So
/// `diagnose` fits the same model from the same start whichever file it
/// is given; and a `--set` on the netlist reaches the bench.
#[test]
fn legacy_bench_files_read_as_their_netlists() {
    let mut seen = 0;
    for entry in std::fs::read_dir(fixtures().join("legacy")).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            continue; // `circuits/`: what the older kinds become
        }
        let old = json(&path);
        if old.get("kind").and_then(|k| k.as_str()) != Some(KIND) {
            continue;
        }
        let mut declared = FrictionBench::from_json(&old.to_string()).unwrap();
        // the older file's catalog names (`Fc`, `viscous.b`) as netlist paths
        for r in declared.refit.iter_mut() {
            *r = super::super::ParamRef::parse(r).unwrap().path();
        }
        let new = json(&fixtures().join("measured").join(path.file_name().unwrap()));
        assert_eq!(new["kind"], "netlist");
        assert!(is_bench_rig(&new) && is_bench_rig(&old));
        let printed = hydrocyl_system::netlist::expanded(&new).unwrap();
        for v in [&new, &printed, &old] {
            assert_eq!(
                FrictionBench::from_rig(v).unwrap(),
                declared,
                "{}",
                path.display()
            );
        }
        let mut set = new.clone();
        hydrocyl_system::rig::apply_set(&mut set, "friction.viscous=123").unwrap();
        let set = FrictionBench::from_rig(&set).unwrap();
        assert_eq!(set.friction.effects[&EffectId::Viscous]["b"], 123.0);
        seen += 1;
    }
    assert!(seen >= 3, "{seen}");
}

/// Every generated bench fixture's rig file is what `make_fixtures`
/// writes for its case (the declared bench's netlist), so the files are
/// generated, not edited.
#[test]
fn generated_bench_rig_files_are_the_generators() {
    for case in crate::synth::fixture_cases() {
        let mut declared = crate::synth::declared_for(&case.planted);
        declared.name = case.name.clone();
        let file = json(
            &fixtures()
                .join("measured")
                .join(format!("{}.rig.json", case.name)),
        );
        assert_eq!(file, declared.netlist().unwrap(), "{}", case.name);
        assert_eq!(FrictionBench::from_rig(&file).unwrap(), declared);
    }
}

/// Every declared refit the report names is a `--set` path of the rig
/// it was run on (with the rig's other paths of the same parameter), so
/// the fitted value goes back with `--set <name>=<fitted>`: on the
/// `emps` preset (Coulomb + viscous law), `tudelft-seal-25` (LuGre, one
/// set per direction) and a `friction_bench` rig file. Each path is one
/// `rig::parameters` lists, setting it gives the bench the fitted value
/// and changes the run.
#[test]
fn declared_refits_are_named_by_their_set_paths() {
    use crate::diagnose::{diagnose_bench, DiagnoseOptions};
    let table = json(&fixtures().join("measured/wang-table-5-3.steady.rig.json"));
    let rigs = [
        ("emps", hydrocyl_system::rig::preset("emps").unwrap()),
        (
            "tudelft-seal-25",
            hydrocyl_system::rig::preset("tudelft-seal-25").unwrap(),
        ),
        ("wang-table-5-3", table),
    ];
    for (name, net) in rigs {
        let rig = match preset(name) {
            Some(r) => r,
            None => FrictionBench::from_rig(&net).unwrap(),
        };
        // a record of the rig with its refitted parameters moved
        let mut truth = rig.clone();
        for p in rig.refit_params() {
            truth.set(&p, 1.3 * rig.get(&p) + 1.0);
        }
        truth.steady_state = false;
        let mut declared = rig.clone();
        declared.steady_state = false;
        let rec = crate::synth::record(
            &truth,
            400,
            5e-3,
            crate::synth::Noise::default(),
            crate::synth::Foreign::None,
            7,
        );
        let opts = DiagnoseOptions {
            candidates: Some(vec![]),
            ..DiagnoseOptions::default()
        };
        let out = diagnose_bench(
            &declared,
            std::slice::from_ref(&rec),
            &opts,
            &mut |_, _, _| {},
        )
        .unwrap();
        let refits = &out.report.declared_refit;
        assert_eq!(refits.len(), rig.refit_params().len(), "{name}");
        let listed: Vec<String> = hydrocyl_system::rig::parameters(&net)
            .into_iter()
            .map(|p| p.path)
            .collect();
        let (sigs, _) = crate::bench::bench_signals(&rec, None, false).unwrap();
        let inputs = crate::bench::BenchInputs::of(&sigs).unwrap();
        let before = declared.simulate(&sigs, &inputs).unwrap();
        for r in refits {
            let p = rig
                .param(&r.name)
                .unwrap_or_else(|| panic!("{name}: {}", r.name));
            let mut set = net.clone();
            for path in std::iter::once(&r.name).chain(&r.also_set) {
                assert!(listed.contains(path), "{name}: {path} not in {listed:?}");
                hydrocyl_system::rig::apply_set(&mut set, &format!("{path}={}", r.fitted))
                    .unwrap_or_else(|e| panic!("{name}: --set {path}: {e}"));
            }
            let mut b = FrictionBench::from_netlist(&set, rig.friction.smoothing_velocity).unwrap();
            // to the last digit serde_json's reading of the number keeps
            let x = b.get(&p);
            assert!(
                (x - r.fitted).abs() <= 1e-12 * r.fitted.abs(),
                "{name}: {}: {x} != {}",
                r.name,
                r.fitted
            );
            assert_eq!(
                b.friction.effects.keys().collect::<Vec<_>>(),
                rig.friction.effects.keys().collect::<Vec<_>>(),
                "{name}: {}",
                r.name
            );
            b.steady_state = false;
            let after = b.simulate(&sigs, &inputs).unwrap();
            assert_ne!(after, before, "{name}: --set {} changes nothing", r.name);
        }
    }
}

/// The bench rigs the recording tests read: `tudelft-seal-25` with a
/// Stribeck hump set (its stiction level no longer the Coulomb level),
/// then every bench rig file under `fixtures/` (the presets' files in
/// `rigs/`, the generated and kept rig files), by path.
fn bench_rigs() -> Vec<(String, serde_json::Value)> {
    let mut rigs: Vec<(String, serde_json::Value)> = vec![];
    let mut hump = hydrocyl_system::rig::preset("tudelft-seal-25").unwrap();
    for d in ["extending", "retracting"] {
        let set = format!("friction.{d}.curve.stiction=6");
        hydrocyl_system::rig::apply_set(&mut hump, &set).unwrap();
    }
    rigs.push(("tudelft-seal-25 with a Stribeck hump".into(), hump));
    let mut files = vec![];
    let mut dirs = vec![fixtures()];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).unwrap() {
            let p = e.unwrap().path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "json") {
                files.push(p);
            }
        }
    }
    files.sort();
    for f in files {
        let Ok(v) = hydrocyl_system::rig::load(f.to_str().unwrap()) else {
            continue; // not a rig file
        };
        if is_bench_rig(&v) {
            let name = f.strip_prefix(fixtures()).unwrap().display().to_string();
            rigs.push((name, v));
        }
    }
    rigs
}

/// The `--set` paths each bench rig under `fixtures/` keeps for its
/// parameters (`FrictionBench::paths`, where a parameter is not at its
/// bench-circuit path), recorded: the presets' files in `rigs/` (a LuGre
/// law with one set per direction, a Coulomb + viscous law), every other
/// bench rig file (a `friction_bench` law, which keeps none), and
/// `tudelft-seal-25` with a Stribeck hump set (its stiction level no
/// longer the Coulomb level).
#[test]
fn the_set_paths_of_every_bench_rig_are_as_recorded() {
    let rigs = bench_rigs();
    let mut got = String::new();
    for (name, v) in &rigs {
        let b = FrictionBench::from_rig(v).unwrap_or_else(|e| panic!("{name}: {e}"));
        got += &format!("{name}:\n");
        for (p, paths) in &b.paths {
            got += &format!("  {} -> {}\n", p.path(), paths.join(" "));
        }
    }
    assert_eq!(got, RECORDED_PATHS, "{got}");
}

const RECORDED_PATHS: &str = concat!(
    "tudelft-seal-25 with a Stribeck hump:\n",
    "  friction.coulomb -> friction.extending.curve.coulomb friction.retracting.curve.coulomb\n",
    "  friction.asymmetry -> \n",
    "  friction.stiction -> friction.extending.curve.stiction friction.retracting.curve.stiction\n",
    "  friction.stribeck_exponent -> friction.extending.curve.stribeck_exponent friction.retracting.curve.stribeck_exponent\n",
    "  friction.stribeck_velocity -> friction.extending.curve.stribeck_velocity friction.retracting.curve.stribeck_velocity\n",
    "  friction.viscous -> friction.extending.sigma2 friction.retracting.sigma2\n",
    "  friction.external_force -> \n",
    "legacy/bench-acceleration_friction.rig.json:\n",
    "legacy/mr-damper.rig.json:\n",
    "legacy/wang-table-5-3.steady.rig.json:\n",
    "measured/bench-acceleration_friction.rig.json:\n",
    "measured/bench-coulomb_asymmetry.rig.json:\n",
    "measured/bench-external_force.rig.json:\n",
    "measured/bench-foreign-delay.rig.json:\n",
    "measured/bench-foreign-spring.rig.json:\n",
    "measured/bench-lugre_dynamics.rig.json:\n",
    "measured/bench-none.rig.json:\n",
    "measured/bench-pressure_viscous+external_force.rig.json:\n",
    "measured/bench-pressure_viscous.rig.json:\n",
    "measured/bench-stribeck.rig.json:\n",
    "measured/bench-viscous.rig.json:\n",
    "measured/mr-damper.rig.json:\n",
    "measured/wang-table-5-3.steady.rig.json:\n",
    "rigs/emps.json:\n",
    "  friction.asymmetry -> \n",
    "  friction.stiction -> \n",
    "  friction.stribeck_exponent -> \n",
    "  friction.stribeck_velocity -> \n",
    "  friction.sigma0 -> \n",
    "  friction.sigma1 -> \n",
    "  friction.external_force -> \n",
    "rigs/tudelft-seal-25.json:\n",
    "  friction.coulomb -> friction.extending.curve.coulomb friction.retracting.curve.coulomb friction.extending.curve.stiction friction.retracting.curve.stiction\n",
    "  friction.asymmetry -> \n",
    "  friction.stiction -> friction.extending.curve.stiction friction.retracting.curve.stiction\n",
    "  friction.stribeck_exponent -> friction.extending.curve.stribeck_exponent friction.retracting.curve.stribeck_exponent\n",
    "  friction.stribeck_velocity -> friction.extending.curve.stribeck_velocity friction.retracting.curve.stribeck_velocity\n",
    "  friction.viscous -> friction.extending.sigma2 friction.retracting.sigma2\n",
    "  friction.external_force -> \n",
    "rigs/tudelft-seal-257.json:\n",
    "  friction.coulomb -> friction.extending.curve.coulomb friction.retracting.curve.coulomb friction.extending.curve.stiction friction.retracting.curve.stiction\n",
    "  friction.asymmetry -> \n",
    "  friction.stiction -> friction.extending.curve.stiction friction.retracting.curve.stiction\n",
    "  friction.stribeck_exponent -> friction.extending.curve.stribeck_exponent friction.retracting.curve.stribeck_exponent\n",
    "  friction.stribeck_velocity -> friction.extending.curve.stribeck_velocity friction.retracting.curve.stribeck_velocity\n",
    "  friction.viscous -> friction.extending.sigma2 friction.retracting.sigma2\n",
    "  friction.external_force -> \n"
);

/// What `FrictionBench::from_rig` reads of each bench rig under
/// `fixtures/` (areas, mass, load-cell sign, the friction law's Coulomb
/// level, smoothing velocity and declared effects), and of the preset
/// netlists with a law value changed by `--set` (a seal term on each
/// law, a direction's value apart from the other's, a `friction_bench`
/// law's effects given), recorded: so the
/// friction law's view is read the same way whatever table says it.
#[test]
fn what_every_bench_rig_reads_as_is_recorded() {
    let mut rigs = bench_rigs();
    for (preset, sets) in [
        ("emps", &["friction.seal.k_pressure=2e-9"][..]),
        ("emps", &["friction.seal.h_acceleration=3"][..]),
        ("tudelft-seal-25", &["friction.seal.k_pressure=2e-9"][..]),
        ("tudelft-seal-25", &["friction.seal.h_acceleration=3"][..]),
        (
            "tudelft-seal-25",
            &["friction.retracting.curve.coulomb=4"][..],
        ),
        ("tudelft-seal-25", &["friction.retracting.sigma2=7"][..]),
        (
            "tudelft-seal-25",
            &[
                "friction.extending.curve.stribeck_velocity=0.02",
                "friction.retracting.curve.stiction=6",
            ][..],
        ),
        (
            "measured/bench-none.rig.json",
            &[
                "friction.stiction=30",
                "friction.sigma0=1e4",
                "friction.asymmetry=1",
                "friction.external_force=2",
                "friction.seal.h_acceleration=-2",
            ][..],
        ),
        (
            "measured/bench-none.rig.json",
            &["friction.sigma1=5", "friction.seal.h_acceleration=4"][..],
        ),
    ] {
        let mut v = match hydrocyl_system::rig::preset(preset) {
            Some(v) => v,
            None => hydrocyl_system::rig::load(fixtures().join(preset).to_str().unwrap()).unwrap(),
        };
        for s in sets {
            hydrocyl_system::rig::apply_set(&mut v, s).unwrap();
        }
        rigs.push((format!("{preset} --set {}", sets.join(" --set ")), v));
    }
    let mut got = String::new();
    for (name, v) in &rigs {
        got += &format!("{name}:\n");
        match FrictionBench::from_rig(v) {
            Ok(b) => {
                got += &format!(
                    "  area1 {:?} area2 {:?} mass {:?} force_sign {:?}\n",
                    b.area1, b.area2, b.mass, b.force_sign
                );
                got += &format!(
                    "  coulomb {:?} smoothing_velocity {:?}\n",
                    b.friction.coulomb, b.friction.smoothing_velocity
                );
                for (id, ps) in &b.friction.effects {
                    got += &format!("  {id:?} {ps:?}\n");
                }
            }
            Err(e) => got += &format!("  error: {e}\n"),
        }
    }
    assert_eq!(got, RECORDED_READS, "{got}");
}

const RECORDED_READS: &str = concat!(
    "tudelft-seal-25 with a Stribeck hump:\n",
    "  area1 0.0 area2 0.0004908738521234052 mass 0.1 force_sign 1.0\n",
    "  coulomb 5.0 smoothing_velocity 0.0001\n",
    "  Stribeck {\"Fs\": 6.0, \"alpha\": 1.0, \"vs\": 0.001}\n",
    "  Viscous {\"b\": 0.0}\n",
    "  LugreDynamics {\"sigma0\": 100000.0, \"sigma1\": 0.0}\n",
    "legacy/bench-acceleration_friction.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "  PressureViscous {\"K\": 1e-9}\n",
    "legacy/mr-damper.rig.json:\n",
    "  area1 0.0 area2 0.0 mass 0.0 force_sign -1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "legacy/wang-table-5-3.steady.rig.json:\n",
    "  area1 0.0 area2 0.0 mass 0.0 force_sign 1.0\n",
    "  coulomb 100.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 1000.0}\n",
    "measured/bench-acceleration_friction.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "  PressureViscous {\"K\": 1e-9}\n",
    "measured/bench-coulomb_asymmetry.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "measured/bench-external_force.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "measured/bench-foreign-delay.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "measured/bench-foreign-spring.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "measured/bench-lugre_dynamics.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "measured/bench-none.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "measured/bench-pressure_viscous+external_force.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "measured/bench-pressure_viscous.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "measured/bench-stribeck.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "measured/bench-viscous.rig.json:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "measured/mr-damper.rig.json:\n",
    "  area1 0.0 area2 0.0 mass 0.0 force_sign -1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "measured/wang-table-5-3.steady.rig.json:\n",
    "  area1 0.0 area2 0.0 mass 0.0 force_sign 1.0\n",
    "  coulomb 100.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 1000.0}\n",
    "rigs/emps.json:\n",
    "  area1 0.0 area2 0.0 mass 50.0 force_sign 1.0\n",
    "  coulomb 10.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 100.0}\n",
    "rigs/tudelft-seal-25.json:\n",
    "  area1 0.0 area2 0.0004908738521234052 mass 0.1 force_sign 1.0\n",
    "  coulomb 5.0 smoothing_velocity 0.0001\n",
    "  Viscous {\"b\": 0.0}\n",
    "  LugreDynamics {\"sigma0\": 100000.0, \"sigma1\": 0.0}\n",
    "rigs/tudelft-seal-257.json:\n",
    "  area1 0.0 area2 0.0005187476329423806 mass 0.1 force_sign 1.0\n",
    "  coulomb 5.0 smoothing_velocity 0.0001\n",
    "  Viscous {\"b\": 0.0}\n",
    "  LugreDynamics {\"sigma0\": 100000.0, \"sigma1\": 0.0}\n",
    "emps --set friction.seal.k_pressure=2e-9:\n",
    "  area1 0.0 area2 0.0 mass 50.0 force_sign 1.0\n",
    "  coulomb 10.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 100.0}\n",
    "  PressureViscous {\"K\": 2e-9}\n",
    "emps --set friction.seal.h_acceleration=3:\n",
    "  area1 0.0 area2 0.0 mass 50.0 force_sign 1.0\n",
    "  coulomb 10.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 100.0}\n",
    "  AccelerationFriction {\"H\": 3.0}\n",
    "tudelft-seal-25 --set friction.seal.k_pressure=2e-9:\n",
    "  area1 0.0 area2 0.0004908738521234052 mass 0.1 force_sign 1.0\n",
    "  coulomb 5.0 smoothing_velocity 0.0001\n",
    "  Viscous {\"b\": 0.0}\n",
    "  PressureViscous {\"K\": 2e-9}\n",
    "  LugreDynamics {\"sigma0\": 100000.0, \"sigma1\": 0.0}\n",
    "tudelft-seal-25 --set friction.seal.h_acceleration=3:\n",
    "  area1 0.0 area2 0.0004908738521234052 mass 0.1 force_sign 1.0\n",
    "  coulomb 5.0 smoothing_velocity 0.0001\n",
    "  Viscous {\"b\": 0.0}\n",
    "  AccelerationFriction {\"H\": 3.0}\n",
    "  LugreDynamics {\"sigma0\": 100000.0, \"sigma1\": 0.0}\n",
    "tudelft-seal-25 --set friction.retracting.curve.coulomb=4:\n",
    "  error: components.friction.extending.curve.coulomb: the bench's law has one set for both directions (5 ≠ 4)\n",
    "tudelft-seal-25 --set friction.retracting.sigma2=7:\n",
    "  error: components.friction.extending.sigma2: the bench's law has one set for both directions (0 ≠ 7)\n",
    "tudelft-seal-25 --set friction.extending.curve.stribeck_velocity=0.02 --set friction.retracting.curve.stiction=6:\n",
    "  error: components.friction.extending.curve.stiction: the bench's law has one set for both directions (5 ≠ 6)\n",
    "measured/bench-none.rig.json --set friction.stiction=30 --set friction.sigma0=1e4 --set friction.asymmetry=1 --set friction.external_force=2 --set friction.seal.h_acceleration=-2:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  CoulombAsymmetry {\"dFc\": 1.0}\n",
    "  Stribeck {\"Fs\": 30.0, \"alpha\": 1.0, \"vs\": 0.01}\n",
    "  Viscous {\"b\": 300.0}\n",
    "  AccelerationFriction {\"H\": -2.0}\n",
    "  LugreDynamics {\"sigma0\": 10000.0, \"sigma1\": 0.0}\n",
    "  ExternalForce {\"F0\": 2.0}\n",
    "measured/bench-none.rig.json --set friction.sigma1=5 --set friction.seal.h_acceleration=4:\n",
    "  area1 0.0 area2 0.001963495408493621 mass 2.0 force_sign 1.0\n",
    "  coulomb 20.0 smoothing_velocity 0.001\n",
    "  Viscous {\"b\": 300.0}\n",
    "  AccelerationFriction {\"H\": 4.0}\n"
);

/// A netlist that is not a friction bench is refused by path.
#[test]
fn a_cylinder_netlist_is_not_a_bench() {
    let v = hydrocyl_system::rig::preset("leaney-moog").unwrap();
    assert!(!is_bench_rig(&v));
    let e = FrictionBench::from_rig(&v).unwrap_err();
    assert!(e.contains("identify.model"), "{e}");
}

/// The identification section's column roles are the measured-data
/// format's signals.
#[test]
fn column_roles_are_the_formats_signals() {
    let names: Vec<&str> = Signal::ALL.iter().map(|s| s.name()).collect();
    assert_eq!(names, hydrocyl_system::netlist::identify::COLUMN_ROLES);
}

/// The presets' identification view is the declaration the bench had
/// before its circuit became a netlist, field for field (so `diagnose`
/// and `cargo xtask validate` fit the same model from the same start).
#[test]
fn presets_are_the_netlists_seen_as_benches() {
    let effects = |e: &[(EffectId, &[(&str, f64)])]| -> BTreeMap<_, _> {
        e.iter()
            .map(|(id, p)| (*id, p.iter().map(|(k, v)| (k.to_string(), *v)).collect()))
            .collect()
    };
    for (name, bore) in [("tudelft-seal-25", 0.025f64), ("tudelft-seal-257", 0.0257)] {
        let r = preset(name).unwrap();
        assert_eq!(r.area1, 0.0);
        assert_eq!(r.area2, std::f64::consts::PI * (0.5 * bore).powi(2));
        assert_eq!((r.mass, r.force_sign), (0.1, 1.0));
        assert_eq!(r.friction.coulomb, 5.0);
        assert_eq!(r.friction.smoothing_velocity, 1e-4);
        assert_eq!(
            r.friction.effects,
            effects(&[
                (EffectId::LugreDynamics, &[("sigma0", 1e5), ("sigma1", 0.0)]),
                (EffectId::Viscous, &[("b", 0.0)]),
            ])
        );
        assert_eq!(
            r.refit,
            [
                "friction.extending.curve.coulomb",
                "friction.sigma0",
                "friction.extending.sigma2"
            ]
        );
        assert_eq!(
            r.refit_params(),
            [
                ParamRef::Coulomb,
                ParamRef::Effect(EffectId::LugreDynamics, "sigma0".into()),
                ParamRef::Effect(EffectId::Viscous, "b".into())
            ]
        );
        assert_eq!(r.columns.0[&Signal::Time], "time_ms [ms]");
    }
    let r = preset("emps").unwrap();
    assert_eq!(
        (r.area1, r.area2, r.mass, r.force_sign),
        (0.0, 0.0, 50.0, 1.0)
    );
    assert_eq!(
        (r.friction.coulomb, r.friction.smoothing_velocity),
        (10.0, 1e-3)
    );
    assert_eq!(
        r.friction.effects,
        effects(&[(EffectId::Viscous, &[("b", 100.0)])])
    );
    assert_eq!(
        r.refit,
        ["friction.coulomb", "drive.mass", "friction.viscous"]
    );
    assert!(preset("leaney-moog").is_none());
}

/// A bench record without the pressure of a chamber whose area is over
/// zero is refused, naming the file and the column (it was run at 0 Pa,
/// and the missing pressure force "found" as an `external_force`).
#[test]
fn a_bench_record_without_its_chamber_pressure_is_refused() {
    let dir = fixtures().join("measured");
    let rig = FrictionBench::from_rig(&json(&dir.join("bench-none.rig.json"))).unwrap();
    let text = std::fs::read_to_string(dir.join("bench-none.csv")).unwrap();
    let rec = crate::data::Record::parse("b.csv", &text, &rig.columns).unwrap();
    assert!(rig.require_inputs(&rec).is_ok());
    let without: String = text
        .lines()
        .map(|l| {
            let c: Vec<&str> = l.split(',').collect();
            format!("{},{},{}\n", c[0], c[1], c[3])
        })
        .collect();
    let rec = crate::data::Record::parse("b.csv", &without, &rig.columns).unwrap();
    let e = rig.require_inputs(&rec).unwrap_err().to_string();
    assert!(
        e.starts_with("b.csv: row 1: missing column 'p2'") && e.contains("area2"),
        "{e}"
    );
}
