//! Issue 17's stall with entrained air: the chapter-7 square and sine on the
//! `wang-hybrid` preset with the entrained-air fraction `α` (and index `n`)
//! in every volume, 0.1-ms samples; prints stall r / e and what moved.
//!
//! `cargo run --release -p hydrocyl-studies --example stall_air -- [alpha ...]`

use hydrocyl_actuator::EntrainedAir;
use hydrocyl_integrators::Method;
use hydrocyl_studies::chapter7::{Chapter7Test, Load, Shape};
use hydrocyl_system::hybrid::WangHybrid;

fn main() {
    let args: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|s| s.parse().ok())
        .collect();
    let alphas = if args.is_empty() {
        vec![0.0, 0.001, 0.005, 0.01]
    } else {
        args
    };
    println!("shape  alpha   n    stall r/e ms   charge r/e ms (travel mm)      lag e/r ms   drift mm  fric e/r N   min p1/p2 bar  min line bar  balance");
    for shape in [Shape::Square, Shape::Sine] {
        for &a in &alphas {
            for n in [1.0, 1.4] {
                if a == 0.0 && n != 1.0 {
                    continue;
                }
                let mut test = Chapter7Test::new(shape, Load::None);
                test.initial_position = -0.06;
                test.sample_interval = 1e-4;
                test.max_steps = 2_000_000;
                let mut rig = WangHybrid::preset();
                rig.entrained_air = EntrainedAir {
                    polytropic_index: n,
                    ..EntrainedAir::isothermal(a)
                };
                let r = match test.run_on(rig, Method::Rosenbrock) {
                    Ok(r) => r,
                    Err(e) => {
                        println!("{shape:?} {a} {n}: {e}");
                        continue;
                    }
                };
                if let Ok(dir) = std::env::var("STALL_DUMP") {
                    // the trace around the second period's reversals
                    let tr = &r.trace;
                    let mut out = String::from("t,command,pump_flow,pp1,pp2,p1,p2,x,v,spool\n");
                    for k in 0..tr.t.len() {
                        let t = tr.t[k];
                        if (7.45..7.62).contains(&t) || (9.95..10.12).contains(&t) {
                            out += &format!(
                                "{t:.4},{},{:e},{:.0},{:.0},{:.0},{:.0},{:.6},{:.5},{:e}\n",
                                tr.command[k],
                                tr.pump_flow[k],
                                tr.pp1[k],
                                tr.pp2[k],
                                tr.p1[k],
                                tr.p2[k],
                                tr.position[k],
                                tr.velocity[k],
                                tr.spool[k]
                            );
                        }
                    }
                    std::fs::write(format!("{dir}/{shape:?}-{a}-{n}.csv"), out).expect("write");
                }
                let p = &r.phenomena;
                let minp = |k: &str| {
                    r.min_pressures
                        .iter()
                        .filter(|(n, _)| n.contains(k))
                        .map(|(_, p)| *p)
                        .fold(f64::INFINITY, f64::min)
                        / 1e5
                };
                println!(
                    "{:6} {a:6.4} {n:3.1}  {:5.2} / {:5.2}  {:5.1} / {:5.1} ({:.3} / {:.3})  {:5.1} / {:5.1}  {:+6.3}  {:5.0} / {:5.0}  {:6.3} / {:6.3}  {:6.3}  {:.1e}",
                    format!("{shape:?}"),
                    p.stall_to_retract * 1e3,
                    p.stall_to_extend * 1e3,
                    p.charge_to_retract * 1e3,
                    p.charge_to_extend * 1e3,
                    p.charge_travel_retract * 1e3,
                    p.charge_travel_extend * 1e3,
                    p.lag_extend * 1e3,
                    p.lag_retract * 1e3,
                    p.drift_per_period * 1e3,
                    p.friction_extend,
                    p.friction_retract,
                    minp("chamber_1"),
                    minp("chamber_2"),
                    minp("line"),
                    r.worst_balance(),
                );
            }
        }
    }
}
