//! A rod held by Karnopp's stiction reports the force that holds it: the
//! friction probe is everything else acting on the rod while it sticks (it
//! read 0 N while the chambers pushed with 20 kN), and the law's own force
//! once the rod slips.

use hydrocyl_system::run::{Run, RunOptions, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;
use serde_json::{json, Value};

const A1: f64 = 0.002;
const A2: f64 = 0.001;

/// Supply → orifice → cap side, rod side → orifice → tank, a 50 kg load and
/// Karnopp friction with a stiction of `stiction` N (Coulomb 18 kN).
fn rig(stiction: f64) -> Value {
    json!({
        "kind": "netlist",
        "name": "stuck",
        "components": {
            "supply": { "type": "pressure_source", "pressure": 1.0e7 },
            "tank": { "type": "pressure_source", "pressure": 0.0 },
            "o1": { "type": "orifice", "area": 2.0e-6, "cd": 0.7, "density": 870.0 },
            "o2": { "type": "orifice", "area": 1.0e-6, "cd": 0.7, "density": 870.0 },
            "cylinder": { "type": "cylinder", "area_1": A1, "area_2": A2, "stroke": 0.5,
                          "chamber_length_1": 0.3, "chamber_length_2": 0.3, "bulk_modulus": 1e9,
                          "initial": { "p1": 0.0, "p2": 0.0, "position": -0.2, "velocity": 0.0 } },
            "load": { "type": "mass", "mass": 50.0, "external_force": 0.0 },
            "fric": { "type": "friction_karnopp", "sigma2": 1000.0,
                      "curve": { "coulomb": 18000.0, "stiction": stiction,
                                 "stribeck_velocity": 0.01, "stribeck_exponent": 2.0 } }
        },
        "connections": [["supply.port", "o1.a"], ["o1.b", "cylinder.A"], ["cylinder.B", "o2.a"],
                        ["o2.b", "tank.port"], ["cylinder.rod", "load.rod", "fric.rod"]]
    })
}

fn run(rig: &Value, solver: Solver) -> Run {
    let t: Vec<f64> = (0..=500).map(|k| k as f64 * 1e-3).collect();
    Simulation::new(rig, Signal::Constant { value: 0.0 })
        .expect("circuit")
        .options(RunOptions {
            solver,
            ..RunOptions::default()
        })
        .run(&t)
        .unwrap_or_else(|e| panic!("{}: {e}", solver.name()))
}

fn channel<'a>(r: &'a Run, name: &str) -> &'a [f64] {
    r.channel(name).unwrap_or_else(|| {
        panic!(
            "no {name} in {:?}",
            r.channels.iter().map(|c| &c.name).collect::<Vec<_>>()
        )
    })
}

#[test]
fn a_stuck_rod_reports_the_force_that_holds_it() {
    for solver in [Solver::Auto, Solver::Dp45, Solver::Rosenbrock] {
        let r = run(&rig(25_000.0), solver);
        let (v, p1, p2, f) = (
            channel(&r, "load.velocity"),
            channel(&r, "cylinder.p1"),
            channel(&r, "cylinder.p2"),
            channel(&r, "fric.force"),
        );
        let last = v.len() - 1;
        // stuck throughout: the chambers reach the supply and the tank
        assert!(
            v.iter().all(|&v| v == 0.0),
            "{}: the rod moved",
            solver.name()
        );
        let drive = p1[last] * A1 - p2[last] * A2;
        assert!(drive > 19_000.0, "{}: drive {drive}", solver.name());
        for k in 0..=last {
            let drive = p1[k] * A1 - p2[k] * A2;
            assert!(
                (f[k] - drive).abs() <= 1e-9 * drive.abs().max(1.0),
                "{} at row {k}: friction {} N against a drive of {drive} N",
                solver.name(),
                f[k]
            );
        }
    }
}

#[test]
fn a_slipping_rod_reports_the_laws_force() {
    // stiction below the drive: the rod breaks away and slides
    let r = run(&rig(19_000.0), Solver::Auto);
    let (v, f) = (channel(&r, "load.velocity"), channel(&r, "fric.force"));
    let last = v.len() - 1;
    assert!(v[last] > 1e-3, "the rod did not slide: v = {}", v[last]);
    // Karnopp's slip force: g(v) + σ2 v, g between Fc and Fs
    let law = f[last] - 1000.0 * v[last];
    assert!(
        (18_000.0..=19_000.0).contains(&law),
        "slip force {}",
        f[last]
    );
}
