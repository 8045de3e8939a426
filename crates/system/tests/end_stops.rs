//! Stroke-end stops hold: a drive running at constant speed (no friction, so
//! the net force is ~0 when the mass meets the stop) stays on the stop under
//! every method, the piston never leaves the stroke, and a stop that the force
//! pulls away from still releases the mass.

use hydrocyl_system::rig;
use hydrocyl_system::run::{Run, RunOptions, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::simulation::Simulation;
use serde_json::{json, Value};

/// Supply → orifice → cap side, rod side → orifice → tank: the piston runs
/// at the orifices' constant speed into its stop at +0.26 m, from steady
/// pressures (so the net force is zero up to rounding at the impact).
fn two_orifices(external_force: f64, p1: f64, p2: f64) -> Value {
    json!({
        "kind": "netlist",
        "name": "two-orifices",
        "components": {
            "supply": { "type": "pressure_source", "pressure": 7.0e6 },
            "tank": { "type": "pressure_source", "pressure": 0.0 },
            "o1": { "type": "orifice", "area": 1.0e-6, "cd": 0.6, "density": 870.0 },
            "o2": { "type": "orifice", "area": 1.0e-6, "cd": 0.6, "density": 870.0 },
            "cylinder": { "type": "cylinder", "area_1": 0.001143, "area_2": 0.00058, "stroke": 0.52,
                          "chamber_length_1": 0.31, "chamber_length_2": 0.31, "bulk_modulus": 7e8,
                          "initial": { "p1": p1, "p2": p2, "position": 0.2, "velocity": 0.0 } },
            "load": { "type": "mass", "mass": 100.0, "external_force": external_force }
        },
        "connections": [["supply.port", "o1.a"], ["o1.b", "cylinder.A"], ["cylinder.B", "o2.a"],
                        ["o2.b", "tank.port"], ["cylinder.rod", "load.rod"]]
    })
}

fn run(rig: &Value, command: f64, solver: Solver, t_end: f64) -> Run {
    let t: Vec<f64> = (0..=(t_end * 1e3) as usize)
        .map(|k| k as f64 * 1e-3)
        .collect();
    Simulation::new(rig, Signal::Constant { value: command })
        .expect("circuit")
        .options(RunOptions {
            solver,
            ..RunOptions::default()
        })
        .run(&t)
        .unwrap_or_else(|e| panic!("{}: {e}", solver.name()))
}

fn position(r: &Run) -> &[f64] {
    r.channel("position")
        .or_else(|| r.channel("load.position"))
        .expect("position")
}

const METHODS: [Solver; 4] = [Solver::Auto, Solver::Dp45, Solver::Rosenbrock, Solver::Rk4];

#[test]
fn a_drive_at_constant_speed_stays_on_its_stop_under_every_method() {
    // steady pressures of the orifice drive: with F = 2000 N and with none
    for (force, p1, p2) in [(2000.0, 2.3565e6, 1.19566e6), (0.0, 2.3565e6, 1.19566e6)] {
        let rig = two_orifices(force, p1, p2);
        for m in METHODS {
            let r = run(&rig, 0.0, m, 2.0);
            let x = position(&r);
            let top = x.iter().cloned().fold(f64::MIN, f64::max);
            assert!(
                top <= 0.26 + 1e-12,
                "{} F = {force}: x reached {top}",
                m.name()
            );
            assert!((x[x.len() - 1] - 0.26).abs() < 1e-12, "{}", m.name());
        }
    }
}

#[test]
fn the_valve_rig_without_friction_stays_on_both_stops() {
    for (u, x0, end) in [(1.0, 0.2, 0.26), (-1.0, -0.2, -0.26)] {
        let mut rig = rig::preset("leaney-moog").unwrap();
        for s in [
            "friction.coulomb=0".to_string(),
            "friction.viscous=0".to_string(),
            format!("cylinder.initial.position={x0}"),
        ] {
            rig::apply_set(&mut rig, &s).unwrap();
        }
        for m in METHODS {
            let r = run(&rig, u, m, 1.0);
            let x = position(&r);
            let beyond = x.iter().map(|v| v.abs()).fold(0.0, f64::max);
            assert!(
                beyond <= 0.26 + 1e-12,
                "{} u = {u}: |x| reached {beyond}",
                m.name()
            );
            assert!((x[x.len() - 1] - end).abs() < 1e-12, "{} u = {u}", m.name());
            for p in ["p1", "p2"] {
                let low = r
                    .channel(p)
                    .unwrap()
                    .iter()
                    .cloned()
                    .fold(f64::MAX, f64::min);
                assert!(low > -1e5, "{} u = {u}: {p} fell to {low} Pa", m.name());
            }
        }
    }
}

#[test]
fn a_stop_releases_the_mass_when_the_drive_reverses() {
    // run into the +stop, then reverse the command: the piston must leave it
    let rig = rig::preset("leaney-moog").unwrap();
    let t: Vec<f64> = (0..=1500).map(|k| k as f64 * 1e-3).collect();
    let command = Signal::table(vec![0.0, 0.6, 0.6001, 1.5], vec![1.0, 1.0, -1.0, -1.0]).unwrap();
    let mut rig = rig;
    rig::apply_set(&mut rig, "cylinder.initial.position=0.1").unwrap();
    for m in METHODS {
        let r = Simulation::new(&rig, command.clone())
            .unwrap()
            .options(RunOptions {
                solver: m,
                ..RunOptions::default()
            })
            .run(&t)
            .unwrap();
        let x = position(&r);
        assert!(
            (x[600] - 0.26).abs() < 1e-12,
            "{}: {} at 0.6 s",
            m.name(),
            x[600]
        );
        assert!(x[1500] < 0.0, "{}: {} at 1.5 s", m.name(), x[1500]);
    }
}
