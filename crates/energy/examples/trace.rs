//! Scratch: prints a hybrid trace.
use hydrocyl_system::hybrid::WangHybrid;
use hydrocyl_system::run::{RunOptions, Solver};
use hydrocyl_system::signal::Signal;
fn main() {
    let mut r = WangHybrid::preset();
    r.initial_position = -0.0625;
    let v = 0.05; let (a1, a2, k) = (r.cylinder.area_1.si(), r.cylinder.area_2.si(), r.pump.gain);
    let cmd = Signal::Square { amplitude: v*(a1+a2)/(2.0*k), period_s: 5.0, bias: v*(a1-a2)/(2.0*k) };
    let t: Vec<f64> = (0..=400).map(|i| i as f64 * 0.025).collect();
    let o = r.simulate(cmd, &t, &RunOptions { solver: Solver::Rosenbrock, ..Default::default() }).unwrap();
    let c = |n: &str| o.channel(n).unwrap().to_vec();
    let (x, vv, p1, p2, pp1, pp2, fr) = (c("position"), c("velocity"), c("p1"), c("p2"), c("pp1"), c("pp2"), c("friction_force"));
    for i in (0..t.len()).step_by(4) {
        println!("{:5.2} x {:7.4} v {:7.4} p1 {:6.2} p2 {:6.2} pp1 {:6.2} pp2 {:6.2} bar F {:8.1}", t[i], x[i], vv[i], p1[i]/1e5, p2[i]/1e5, pp1[i]/1e5, pp2[i]/1e5, fr[i]);
    }
}
