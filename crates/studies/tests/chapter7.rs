//! The chapter-7 phenomena on the `wang-hybrid` rig (sections 7.1–7.3), the
//! fold of the seal term and the biased command.

use hydrocyl_studies::chapter7::*;
use hydrocyl_system::hybrid::WangHybrid;
use hydrocyl_system::signal::Signal;

fn run(shape: Shape, load: Load) -> Chapter7Run {
    Chapter7Test::new(shape, load).run().expect("chapter-7 run")
}

fn common_invariants(r: &Chapter7Run) {
    // mass balance of every volume to 1e-6 of the volume pumped
    assert!(r.worst_balance() < 1e-6, "{:?}", r.balances);
    assert_eq!(r.balances.len(), 4);
    // no chamber below vapour pressure, and the model says so when it is
    for (name, p) in &r.min_pressures {
        assert!(*p > r.vapour_pressure, "{name} fell to {p} Pa");
    }
    assert_eq!(
        r.count("cylinder.cavitation_entries_1") + r.count("cylinder.cavitation_entries_2"),
        0.0
    );
    // the valve-state events are located by the integrator: each reversal shifts the
    // pilot valve, cracks the relief valve of the fed line and opens the suction check
    for name in [
        "pilot_valve.shifted_extend",
        "pilot_valve.shifted_retract",
        "relief_1.cracked",
        "relief_2.cracked",
        "check_1.opened",
        "check_2.opened",
    ] {
        assert!(r.count(name) >= 2.0, "{name}: {}", r.count(name));
    }
}

#[test]
fn square_no_load_shows_the_chapter_7_phenomena() {
    let r = run(Shape::Square, Load::None);
    let p = r.phenomena;
    common_invariants(&r);
    assert!(!p.locked);
    assert_eq!(p.reversals, 4);
    // a stall at each reversal
    assert!(
        p.stall_to_retract > 1e-3 && p.stall_to_extend > 1e-3,
        "{p:?}"
    );
    // slower response when retracting
    assert!(p.lag_retract > p.lag_extend, "{p:?}");
    // drift towards the extended end
    assert!(p.drift_per_period > 0.0, "{p:?}");
    // friction larger in magnitude extending than retracting at the same speed
    assert!(
        p.friction_extend > -p.friction_retract && p.friction_retract < 0.0,
        "{p:?}"
    );
    // steady speeds reach the target (the bias makes them symmetric)
    assert!((p.steady_extend.velocity - 0.05).abs() < 1e-3);
    assert!((p.steady_retract.velocity + 0.05).abs() < 1e-3);
    // eq 7.3: the return line passes A2 v extending and A1 v retracting through the same
    // needle, so √(p2_ext / p1_ret) = A2/A1 (the four-way valve adds < 1 %)
    let ratio = (p.steady_extend.p2 / p.steady_retract.p1).sqrt();
    assert!((ratio / (5.50 / 8.042) - 1.0).abs() < 0.02, "{ratio}");
    // section 7.1: P1 retracting > P2 extending, and P2 retracting > P1 extending
    assert!(p.steady_retract.p1 > p.steady_extend.p2);
    assert!(p.steady_retract.p2 > p.steady_extend.p1);
    // the fed pump line sits above its chamber by at least the relief's cracking
    // pressure, below the safety valve, and the other line at suction pressure
    let pc = WangHybrid::preset().relief_pilot.cracking.si();
    assert!(p.steady_extend.pp1 - p.steady_extend.p1 > pc && p.steady_extend.pp1 < 200e5);
    assert!(p.steady_retract.pp2 - p.steady_retract.p2 > pc && p.steady_retract.pp2 < 200e5);
    assert!(p.steady_extend.pp2 < 0.0 && p.steady_extend.pp2 > -1.0e5);
}

#[test]
fn sine_stall_is_longer_than_square_stall() {
    let sq = run(Shape::Square, Load::None);
    let si = run(Shape::Sine, Load::None);
    common_invariants(&si);
    let (a, b) = (sq.phenomena, si.phenomena);
    assert!(!b.locked);
    assert!(b.stall_to_retract > 3.0 * a.stall_to_retract, "{a:?} {b:?}");
    assert!(b.stall_to_extend > 3.0 * a.stall_to_extend, "{a:?} {b:?}");
    assert!(b.drift_per_period > 0.0);
    assert!(b.friction_extend > -b.friction_retract);
    assert!(b.lag_retract >= b.lag_extend, "{b:?}");
}

#[test]
fn loaded_sines_keep_the_phenomena() {
    for load in [Load::Kg25, Load::Kg38] {
        let r = run(Shape::Sine, load);
        common_invariants(&r);
        let p = r.phenomena;
        assert!(!p.locked, "{load:?}");
        assert!(p.stall() > 0.01 && p.drift_per_period > 0.0, "{p:?}");
        assert!(p.friction_extend > -p.friction_retract, "{p:?}");
    }
    // more load (higher Coulomb level, Tables 5-9, 5-10) → more friction extending
    let f = |l| run(Shape::Sine, l).phenomena.friction_extend;
    assert!(f(Load::Kg38) > f(Load::Kg25));
}

#[test]
fn fold_reserve_shrinks_with_load_and_the_25_kg_square_locks() {
    let rig = WangHybrid::preset();
    let r: Vec<f64> = [Load::None, Load::Kg25, Load::Kg38]
        .iter()
        .map(|l| extend_force_reserve(&rig, &l.friction(), 0.05))
        .collect();
    assert!(r[0] > r[1] && r[1] > r[2] && r[2] > 0.0, "{r:?}");
    let (ps, pu) = extend_pressure_roots(&rig, &Load::None.friction(), 0.05).unwrap();
    assert!(ps < pu);
    // at the stable root the balance holds: Δp A1 + p2 (A1 − A2) = g + K v Δp²
    let w = Load::None.friction();
    let k_ret = hydrocyl_valves::pilot_valve::series_coefficient(
        rig.four_way.k_t,
        rig.needle.coefficient(),
    );
    let p2 = (5.5e-4 * 0.05 / k_ret).powi(2);
    let lhs = ps * 8.042e-4 + p2 * (8.042e-4 - 5.5e-4);
    let rhs = w.extending.curve.g(0.05) + w.extending.k_pressure * 0.05 * ps * ps;
    assert!((lhs - rhs).abs() < 1e-9 * lhs);
    let sq = run(Shape::Square, Load::Kg25);
    assert!(sq.phenomena.locked);
    // locked at the safety valve: the closed form v = A1 / (K p1)
    let pmax = sq.phenomena.max_chamber_pressure;
    assert!(pmax > 150e5 && pmax < 250e5, "{pmax}");
    assert!(sq.worst_balance() < 1e-6);
}

#[test]
fn acceleration_term_locks_even_the_unloaded_square() {
    let mut t = Chapter7Test::new(Shape::Square, Load::None);
    t.acceleration_term = true;
    t.periods = 2;
    let r = t.run().expect("run");
    assert!(r.phenomena.locked);
    // the locked speed is the closed form A1 / (K p1) at the locked pressure
    let k = Load::None.friction().extending.k_pressure;
    let i = r.trace.t.iter().position(|&t| t > 2.0).unwrap();
    let (p1, p2, v) = (r.trace.p1[i], r.trace.p2[i], r.trace.velocity[i]);
    let v_lock = (p1 * 8.042e-4 - p2 * 5.5e-4) / (k * (p1 - p2).powi(2));
    assert!((v / v_lock - 1.0).abs() < 0.2, "{v} vs {v_lock}");
}

#[test]
fn bias_makes_the_command_implied_velocity_symmetric() {
    let t = Chapter7Test::new(Shape::Square, Load::None);
    let rig = t.rig();
    let Signal::Square {
        amplitude, bias, ..
    } = t.command(&rig)
    else {
        panic!("square expected")
    };
    let k = rig.pump.gain;
    assert!((k * (bias + amplitude) / 8.042e-4 - 0.05).abs() < 1e-12);
    assert!((k * (bias - amplitude) / 5.50e-4 + 0.05).abs() < 1e-12);
}

/// On the rig the T port between the pilot valve and the needle (two
/// orifice laws) is solved on the laws: one member evaluation a solve, at
/// the root, whose residual passes; never a fall back to Brent.
#[test]
fn the_return_port_solve_is_cheap_on_the_rig() {
    use hydrocyl_system::run::{RunOptions, Solver};
    use hydrocyl_system::simulation::Simulation;
    let test = Chapter7Test::new(Shape::Square, Load::None);
    let rig = test.rig();
    let t: Vec<f64> = (0..=300).map(|k| k as f64 * 1e-2).collect();
    let opts = RunOptions {
        solver: Solver::Rosenbrock,
        ..RunOptions::default()
    };
    let d = Simulation::of_circuit(rig.build(test.command(&rig)).unwrap())
        .options(opts)
        .run(&t)
        .unwrap()
        .diagnostics;
    let get = |k: &str| d.iter().find(|(n, _)| n == k).unwrap().1;
    let (solves, evals) = (
        get("return_port.solves"),
        get("return_port.solve_evaluations"),
    );
    assert!(solves > 1000.0);
    assert_eq!(evals, solves, "{} evaluations a solve", evals / solves);
    assert_eq!(get("return_port.solve_fallbacks"), 0.0);
}

/// Section 7.1's pressure charging on the preset as shipped: after each
/// reversal the four-way valve stays centred while the pump charges the new
/// line to the pilot shift pressure, for the time `V ∫dp/B_eff / Q` the
/// lines take (docs/hybrid.md item 9). Entrained air (0.5 %, assumed) makes
/// the lines softer, so the charging takes longer, and keeps every volume
/// above absolute zero where the constant-B oil goes below it.
#[test]
fn the_valve_is_centred_for_the_line_charging_and_air_lengthens_it() {
    let mut test = Chapter7Test::new(Shape::Square, Load::None);
    test.initial_position = -0.06;
    let run = |air: f64| {
        let mut rig = WangHybrid::preset();
        rig.entrained_air = hydrocyl_actuator::EntrainedAir::isothermal(air);
        test.run_on(rig, hydrocyl_integrators::Method::Rosenbrock)
            .expect("chapter-7 run")
    };
    let (liquid, aerated) = (run(0.0), run(0.005));
    let (a, b) = (liquid.phenomena, aerated.phenomena);
    for p in [&a, &b] {
        assert!(
            p.charge_to_retract > 3e-3 && p.charge_to_extend > 3e-3,
            "{p:?}"
        );
        // the piston rings on the shut chambers but stays within 0.5 mm
        assert!(
            p.charge_travel_retract < 5e-4 && p.charge_travel_extend < 5e-4,
            "{p:?}"
        );
    }
    assert!(
        b.charge_to_retract > 1.5 * a.charge_to_retract,
        "{a:?} {b:?}"
    );
    assert!(b.charge_to_extend > 1.5 * a.charge_to_extend, "{a:?} {b:?}");
    let lowest = |r: &Chapter7Run| {
        r.min_pressures
            .iter()
            .map(|m| m.1)
            .fold(f64::INFINITY, f64::min)
    };
    assert!(lowest(&liquid) < -101_325.0, "{}", lowest(&liquid));
    assert!(lowest(&aerated) > -101_325.0, "{}", lowest(&aerated));
    assert!(aerated.worst_balance() < 1e-6, "{:?}", aerated.balances);
}
