//! hydrocyl-energy's tests, one binary: the ledger against closed forms and
//! bad input (the chapter-8 matrix is tested in `hydrocyl-studies`).

use hydrocyl_energy::ledger::{ledger, RodSide};
use hydrocyl_ports::{Area, Density, Pressure};
use hydrocyl_system::components::{FixedOrifice, PressureSource, Volume};
use hydrocyl_system::run::RunOptions;
use hydrocyl_system::simulation::Simulation;
use hydrocyl_system::{Circuit, Component};
use hydrocyl_valves::orifice::Orifice;
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../fixtures/rigs")
        .join(name)
}

fn oil() -> Orifice {
    Orifice {
        cd: 0.65,
        density: Density::new(900.0),
        dp_transition: Pressure::new(1000.0),
    }
}

/// Supply → orifice → closed volume, filled from 0 Pa for `t_end`.
fn charging_circuit(ps: f64, volume: f64, b: f64, via: Box<dyn Component>) -> Circuit {
    Circuit::build(vec![
        Box::new(PressureSource::new("supply", "P", Pressure::new(ps), None)),
        via,
        Box::new(Volume::new("volume", "V", volume, b, 0.0, Some("pv"))),
    ])
    .unwrap()
}

/// `c` run at the outputs `t` with the ledger on (DP45, rtol 1e-8).
fn run_with_ledger(c: Circuit, t: &[f64]) -> (Simulation, hydrocyl_system::run::Run) {
    let opts = RunOptions {
        ledger: true,
        rtol: 1e-8,
        ..RunOptions::dp45()
    };
    let mut sim = Simulation::of_circuit(c).options(opts);
    let r = sim.run(t).unwrap();
    (sim, r)
}

/// The ledger of rig `v` over 0.3 s of a half-open spool (rtol 1e-9), with
/// the rod side it was taken on.
fn half_open_ledger(v: &serde_json::Value) -> (RodSide, hydrocyl_energy::ledger::Ledger) {
    use hydrocyl_system::signal::Signal;
    let t: Vec<f64> = (0..=300).map(|k| k as f64 * 1e-3).collect();
    let u = Signal::Constant { value: 0.5 };
    let opts = RunOptions {
        rtol: 1e-9,
        ledger: true,
        ..RunOptions::dp45()
    };
    let run = hydrocyl_system::rig::simulate(v, u.clone(), &t, &opts).unwrap();
    let mut c = hydrocyl_system::rig::circuit(v, u).unwrap();
    c.set_ledger(true);
    let rod = RodSide::of(&c);
    let l = ledger(&c, &run, 0, t.len() - 1, &rod).unwrap();
    (rod, l)
}

mod closed_forms {
    use super::*;

    /// Charging a volume from a constant-pressure source through any
    /// resistance dissipates exactly half the energy drawn: E_in = V Ps²/B,
    /// stored ½ V Ps²/B, lost ½ V Ps²/B — whatever the orifice.
    #[test]
    fn charging_a_volume_loses_half_the_energy_drawn() {
        let (ps, v, b) = (7.0e6, 1.0e-4, 7.0e8);
        for area in [1e-7, 1e-6] {
            let orifice = FixedOrifice::new("orifice", "P", "V", Area::new(area), oil());
            let c = charging_circuit(ps, v, b, Box::new(orifice));
            let t: Vec<f64> = (0..=200).map(|k| k as f64 * 5e-3).collect();
            let (sim, r) = run_with_ledger(c, &t);
            let c = sim.circuit();
            let pv = *r.channel("pv").unwrap().last().unwrap();
            assert!((pv - ps).abs() < 1e-6 * ps, "not charged: {pv}");
            let rod = RodSide {
                node: "none".into(),
                components: vec![],
            };
            let l = ledger(c, &r, 0, t.len() - 1, &rod).unwrap();
            let e_in = v * ps * ps / b;
            assert!((l.energy_in_j - e_in).abs() < 1e-5 * e_in, "{l:?}");
            assert!(
                (l.loss("orifice") - 0.5 * e_in).abs() < 1e-5 * e_in,
                "{l:?}"
            );
            assert!((l.stored_change_from_states_j - 0.5 * e_in).abs() < 1e-6 * e_in);
            assert!(
                l.error.abs() < 1e-9 && l.storage_error.abs() < 1e-5,
                "{l:?}"
            );
            assert_eq!(l.reference_j, l.energy_in_j);
        }
    }

    /// A charged volume discharging to tank (a source at 0 Pa) takes no
    /// energy in: the ledger still closes, as a fraction of the energy the
    /// orifice dissipates, `½ V (p0² − p(t)²)/B`, the storage lost; there
    /// is no efficiency (`null` in the JSON).
    #[test]
    fn a_volume_discharging_to_tank_closes_without_energy_in() {
        let (p0, v, b) = (5.0e6, 1.0e-4, 7.0e8);
        let c = Circuit::build(vec![
            Box::new(PressureSource::new("tank", "T", Pressure::new(0.0), None)),
            Box::new(FixedOrifice::new(
                "orifice",
                "V",
                "T",
                Area::new(1e-7),
                oil(),
            )),
            Box::new(Volume::new("volume", "V", v, b, p0, Some("pv"))),
        ])
        .unwrap();
        let t: Vec<f64> = (0..=100).map(|k| k as f64 * 1e-3).collect();
        let (sim, r) = run_with_ledger(c, &t);
        let pv = *r.channel("pv").unwrap().last().unwrap();
        assert!(pv > 0.0 && pv < 0.5 * p0, "not discharged: {pv}");
        let rod = RodSide::of(sim.circuit());
        let l = ledger(sim.circuit(), &r, 0, t.len() - 1, &rod).unwrap();
        let lost = 0.5 * v * (p0 * p0 - pv * pv) / b;
        assert_eq!(l.energy_in_j, 0.0);
        assert!((l.loss("orifice") - lost).abs() < 1e-6 * lost, "{l:?}");
        assert!((l.reference_j - lost).abs() < 1e-6 * lost, "{l:?}");
        assert!(
            l.error.abs() < 1e-9 && l.storage_error.abs() < 1e-5,
            "{l:?}"
        );
        assert!(l.efficiency().is_nan());
        let j = l.to_json();
        assert!(j["efficiency"].is_null(), "{j}");
        assert_eq!(j["reference_j"], serde_json::json!(l.reference_j));
    }
}

mod model_forms {
    use super::*;

    /// The ledger of `preset` over 0.3 s of a half-open spool, at rtol 1e-9.
    fn preset_ledger(preset: &str) -> hydrocyl_energy::ledger::Ledger {
        half_open_ledger(&hydrocyl_system::rig::preset(preset).unwrap()).1
    }

    #[test]
    fn a_ledger_over_the_generalised_form_names_it_and_the_fundamental_closes() {
        // the fundamental form closes to rounding and names no component
        let fundamental = preset_ledger("leaney-moog");
        assert!(fundamental.error.abs() < 1e-12, "{}", fundamental.error);
        assert!(fundamental.not_energy_consistent.is_empty());
        // the one-pressure form does not conserve energy (docs/models.md,
        // section 3): its residual is the form's, and the ledger says whose
        let generalised = preset_ledger("leaney-moog-generalised");
        assert_eq!(
            generalised.not_energy_consistent,
            vec!["cylinder".to_string()]
        );
        assert!(generalised.error.abs() > 1e-6, "{}", generalised.error);
    }
}

mod events_and_moving_walls {
    use super::*;
    use hydrocyl_energy::ledger::Ledger;
    use hydrocyl_system::run::Run;
    use hydrocyl_system::signal::Signal;

    /// `preset` with `sets`, on a constant command, at `rtol`, with its ledger.
    fn ledger_of(preset: &str, sets: &[&str], u: f64, t_end: f64, rtol: f64) -> (Run, Ledger) {
        let mut v = hydrocyl_system::rig::preset(preset).unwrap();
        for s in sets {
            hydrocyl_system::rig::apply_set(&mut v, s).unwrap();
        }
        let t: Vec<f64> = (0..=(t_end * 1e3) as usize)
            .map(|k| k as f64 * 1e-3)
            .collect();
        let mut sim = Simulation::new(&v, Signal::Constant { value: u })
            .unwrap()
            .options(RunOptions {
                rtol,
                ledger: true,
                ..RunOptions::dp45()
            });
        let run = sim.run(&t).unwrap();
        let l = ledger(
            sim.circuit(),
            &run,
            0,
            t.len() - 1,
            &RodSide::of(sim.circuit()),
        )
        .unwrap();
        (run, l)
    }

    /// A plastic impact at the stroke end: the kinetic energy it destroys is
    /// a loss of the mass (the impact energy the mass reports), the load
    /// stores nothing once at rest, and the storage check stays at the
    /// integration's error.
    #[test]
    fn a_plastic_impact_is_booked_as_the_mass_loss() {
        let (run, l) = ledger_of(
            "leaney-moog",
            &["cylinder.initial.position=0.1"],
            1.0,
            1.0,
            1e-9,
        );
        let diag = |k: &str| run.diagnostics.iter().find(|d| d.0 == k).unwrap().1;
        let impact = diag("load.stop_impact_energy_j");
        // ½ m v² at the full-spool speed (0.6036 m/s, 100 kg)
        assert!(impact > 18.0 && impact < 18.5, "{impact}");
        assert!(
            (l.loss("load") - impact).abs() < 1e-9 * impact,
            "{} vs {impact}",
            l.loss("load")
        );
        let at_rest: f64 = l
            .storage
            .iter()
            .filter(|t| t.name == "load")
            .map(|t| t.energy_j)
            .sum();
        assert!(at_rest.abs() < 1e-6, "{:?}", l.storage);
        assert!(l.error.abs() < 1e-12, "{}", l.error);
        assert!(l.storage_error.abs() < 1e-9, "{}", l.storage_error);
    }

    /// A chamber whose wall moves: the stored energy `½ V p²/B` changes by
    /// `∫ ½ p²/B dV` besides the storage power; the ledger's moving-walls
    /// term equals that integral (trapezoids over the output), and the
    /// storage check is then the integration's error: it falls with the
    /// tolerance, whatever the bulk modulus.
    #[test]
    fn the_storage_check_measures_the_integration_on_moving_chambers() {
        for b in [7e8, 1e8] {
            let mut errors = Vec::new();
            for rtol in [1e-6, 1e-9] {
                let set = format!("cylinder.bulk_modulus={b}");
                let (run, l) = ledger_of("leaney-moog", &[&set], 0.3, 0.4, rtol);
                let ch = |k: &str| run.channel(k).unwrap();
                let (p1, p2, v) = (ch("p1"), ch("p2"), ch("velocity"));
                let (a1, a2) = (1.143e-3, 5.8e-4);
                let y: Vec<f64> = (0..v.len())
                    .map(|k| 0.5 / b * (p1[k] * p1[k] * a1 - p2[k] * p2[k] * a2) * v[k])
                    .collect();
                let by_hand = hydrocyl_energy::ledger::trapezoid(&run.time, &y, 0, v.len() - 1);
                assert!(
                    (l.moving_walls_j - by_hand).abs() < 1e-4 * l.moving_walls_j.abs(),
                    "B = {b}: {} vs {by_hand}",
                    l.moving_walls_j
                );
                errors.push(l.storage_error.abs());
            }
            assert!(errors[0] < 1e-6 && errors[1] < 1e-9, "B = {b}: {errors:?}");
        }
    }
}

/// The rod side is found by the connections, not by the names.
mod rod_side {
    use super::*;
    use hydrocyl_system::signal::Signal;

    /// The ledger of the rig in `text` (a netlist) over 0.3 s of a half-open
    /// spool.
    fn ledger_of(text: &str) -> (RodSide, hydrocyl_energy::ledger::Ledger) {
        half_open_ledger(&serde_json::from_str(text).unwrap())
    }

    /// `name` renamed `to` in a netlist's text: the component's key and
    /// every `name.port` that refers to it.
    fn renamed(text: &str, name: &str, to: &str) -> String {
        text.replace(&format!("\"{name}\""), &format!("\"{to}\""))
            .replace(&format!("\"{name}."), &format!("\"{to}."))
    }

    #[test]
    fn the_presets_rod_side_is_their_load_and_friction() {
        for (preset, node) in [("leaney-moog", "load.rod"), ("wang-hybrid", "rod")] {
            let v = hydrocyl_system::rig::preset(preset).unwrap();
            let c = hydrocyl_system::rig::circuit(&v, Signal::Constant { value: 0.0 }).unwrap();
            let mut rod = RodSide::of(&c);
            rod.components.sort();
            assert_eq!(rod.components, ["friction", "load"], "{preset}");
            assert_eq!(rod.node, node, "{preset}");
        }
    }

    #[test]
    fn renaming_the_mass_and_the_friction_leaves_the_cylinders_output() {
        let text = std::fs::read_to_string(fixture("examples/meter-out-needle.json")).unwrap();
        let (_, before) = ledger_of(&text);
        assert!(before.cylinder_out_j > 0.0, "{before:?}");
        let other = renamed(&renamed(&text, "friction", "fr"), "load", "mass1");
        let (rod, after) = ledger_of(&other);
        assert!(rod.components.contains(&"fr".to_string()), "{rod:?}");
        assert!(rod.components.contains(&"mass1".to_string()), "{rod:?}");
        assert_eq!(after.cylinder_out_j, before.cylinder_out_j);
        assert_eq!(after.efficiency(), before.efficiency());
    }

    #[test]
    fn two_cylinders_give_their_output_together() {
        let text =
            std::fs::read_to_string(fixture("examples/two-cylinders-parallel.json")).unwrap();
        let (rod, l) = ledger_of(&text);
        let mut on_rods = rod.components.clone();
        on_rods.sort();
        assert_eq!(on_rods, ["friction_1", "friction_2", "load_1", "load_2"]);
        // the two rods' components, term by term
        let part = |name: &str| {
            l.components
                .iter()
                .find(|c| c.name == name)
                .map(|c| c.energy_j[1] + c.energy_j[2] + c.energy_j[3])
                .unwrap()
        };
        let sum: f64 = on_rods.iter().map(|n| part(n)).sum();
        assert!(l.cylinder_out_j > 0.0, "{l:?}");
        assert!((l.cylinder_out_j - sum).abs() <= 1e-12 * sum.abs(), "{l:?}");
    }
}

mod with_and_without {
    use super::*;
    use hydrocyl_system::signal::Signal;

    /// The ledger's quadratures are normed apart from the states: a run
    /// with the ledger takes the steps of the run without it, and its
    /// channels are the same, bit for bit (DP45; the stiff methods use the
    /// circuit's analytic Jacobian only without the ledger).
    #[test]
    fn the_ledger_leaves_the_channels_as_they_were() {
        let t: Vec<f64> = (0..=100).map(|k| k as f64 * 1e-3).collect();
        for preset in ["leaney-moog", "wang-hybrid"] {
            let v = hydrocyl_system::rig::preset(preset).unwrap();
            let run = |ledger: bool| {
                let opts = RunOptions {
                    ledger,
                    ..RunOptions::dp45()
                };
                hydrocyl_system::rig::simulate(&v, Signal::Constant { value: 0.5 }, &t, &opts)
                    .unwrap()
            };
            let (plain, with) = (run(false), run(true));
            assert_eq!(with.stats.steps, plain.stats.steps, "{preset}");
            assert_eq!(with.stats.rejected, plain.stats.rejected, "{preset}");
            for (a, b) in plain.channels.iter().zip(&with.channels) {
                assert_eq!(a.name, b.name);
                assert!(
                    a.values
                        .iter()
                        .zip(&b.values)
                        .all(|(x, y)| x.to_bits() == y.to_bits()),
                    "{preset}: channel {} differs with the ledger",
                    a.name
                );
            }
        }
    }
}

mod imposed_motion {
    use super::*;
    use hydrocyl_system::run::Solver;
    use hydrocyl_system::signal::Signal;

    /// A 50 kg mass, friction off, driven from rest along a velocity ramp
    /// to 0.1 m/s over 1 s and held: the drive brings in exactly
    /// `½ m v²` = 0.25 J. The exponential method's steps land on the
    /// outputs (the ramp's end among them) and take the drive's power at
    /// each step's middle: exact. An adaptive method steps across the
    /// corner where the acceleration (the drive force) jumps, and the
    /// energy in carries about `h·m·Δa·v` for it (docs/energy.md): within
    /// 1 % here, not exact.
    #[test]
    fn a_ramp_brings_in_the_kinetic_energy() {
        let mut v = hydrocyl_system::rig::preset("emps").unwrap();
        v["components"]["friction"]["coulomb"] = serde_json::json!(0.0);
        v["components"]["friction"]["viscous"] = serde_json::json!(0.0);
        let command = Signal::Table {
            time_s: vec![0.0, 1.0, 2.0].into(),
            value: vec![0.0, 0.1, 0.1].into(),
        };
        let t: Vec<f64> = (0..=200).map(|k| k as f64 * 1e-2).collect();
        for (solver, tol) in [(Solver::Exponential, 1e-9), (Solver::Dp45, 1e-2)] {
            let opts = RunOptions {
                solver,
                rk4_step: 1e-3,
                ledger: true,
                ..RunOptions::default()
            };
            let run = hydrocyl_system::rig::simulate(&v, command.clone(), &t, &opts).unwrap();
            let mut c = hydrocyl_system::rig::circuit(&v, command.clone()).unwrap();
            c.set_ledger(true);
            let l = ledger(&c, &run, 0, t.len() - 1, &RodSide::of(&c)).unwrap();
            assert!(
                (l.energy_in_j - 0.25).abs() < tol * 0.25,
                "{solver:?}: {l:?}"
            );
            assert!(l.storage_error.abs() < tol, "{solver:?}: {l:?}");
        }
    }
}

mod bad_input {
    use super::*;

    #[test]
    fn a_run_without_the_ledger_is_refused() {
        let orifice = FixedOrifice::new("orifice", "P", "V", Area::new(1e-7), oil());
        let c = charging_circuit(1e6, 1e-4, 7e8, Box::new(orifice));
        let t = [0.0, 0.01, 0.02];
        let mut sim = Simulation::of_circuit(c).options(RunOptions::dp45());
        let r = sim.run(&t).unwrap();
        let e = ledger(sim.circuit(), &r, 0, 2, &RodSide::of(sim.circuit())).unwrap_err();
        assert!(e.to_string().contains("ledger: true"), "{e}");
    }

    #[test]
    fn the_valve_preset_file_is_the_preset() {
        let text = std::fs::read_to_string(fixture("wang-valve-c10.json")).unwrap();
        let v: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(
            Some(v.clone()),
            hydrocyl_system::rig::preset("wang-valve-c10")
        );
        let r = hydrocyl_system::rig::valve_rig_from(&v).unwrap();
        assert_eq!(r.cylinder.area_1_m2, 8.042e-4);
        assert_eq!(r.cylinder.area_2_m2, 5.50e-4);
        assert_eq!(r.cylinder.stroke_m, 0.3);
        assert_eq!(r.load.mass_kg, 20.0);
        assert_eq!(r.supply.pressure_pa, 7.0e6);
        assert_eq!(r.friction.name(), "wang");
    }
}
