//! Profiling aid for issue 19: the `leaney-moog` 10 s open-loop square
//! (±90 mm/s, period 2 s) as a 1 kHz command table with 1 kHz output, run
//! `reps` times with DP45 at the given rtol (as `cargo xtask bench` does).
//!
//! `cargo run --release -p hydrocyl-studies --example valve_square -- [rtol] [reps] [solver]`
//!
//! `VALVE_RHS=1` times the right-hand side alone, `VALVE_STEPS=1|2` prints
//! the step sizes, `VALVE_ERR=1` where in time the velocity error lies.

use hydrocyl_system::run::{nrmse, RunOptions, Solver};
use hydrocyl_system::signal::Signal;
use hydrocyl_system::valve_rig::ValveRig;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let rtol: f64 = args.get(1).and_then(|s| s.parse().ok()).unwrap_or(1e-5);
    let reps: usize = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(200);
    let solver = match args.get(3).map(String::as_str) {
        Some("rosenbrock") => Solver::Rosenbrock,
        Some("auto") => Solver::Auto,
        _ => Solver::Dp45,
    };
    let rig = ValveRig::leaney_moog();
    let (bias, amplitude) = rig.open_loop_square(0.09).expect("square");
    let times: Vec<f64> = (0..=10_000).map(|k| k as f64 * 1e-3).collect();
    let values = times
        .iter()
        .map(|t| {
            if (t / 2.0).rem_euclid(1.0) < 0.5 {
                bias + amplitude
            } else {
                bias - amplitude
            }
        })
        .collect();
    let command = Signal::table(times.clone(), values).expect("table");
    if std::env::var("VALVE_RHS").is_ok() {
        use hydrocyl_integrators::OdeSystem;
        let mut c = rig.circuit(command.clone()).expect("circuit");
        let x0 = c.initial_state();
        c.reset(0.0, &x0);
        let mut dx = vec![0.0; x0.len()];
        let mut x = x0.clone();
        x[0] += 1e-3;
        let n = 2_000_000;
        let start = std::time::Instant::now();
        let mut acc = 0.0;
        for k in 0..n {
            let t = (k % 10_000) as f64 * 1e-3;
            c.rhs(t, &x, &mut dx);
            acc += dx[1];
        }
        println!(
            "rhs: {:.1} ns per call ({acc:e})",
            start.elapsed().as_secs_f64() * 1e9 / n as f64
        );
        return;
    }
    if std::env::var("VALVE_STEPS").is_ok() {
        steps(&rig, command.clone(), rtol);
        return;
    }
    let opts = |solver, rtol| RunOptions {
        solver,
        rtol,
        ..RunOptions::default()
    };
    let reference = rig
        .simulate(command.clone(), &times, &opts(Solver::Dp45, 1e-11))
        .expect("reference");
    let mut best = f64::INFINITY;
    let mut last = None;
    for _ in 0..reps {
        let r = rig
            .simulate(command.clone(), &times, &opts(solver, rtol))
            .expect("run");
        best = best.min(r.wall.as_secs_f64());
        last = Some(r);
    }
    let r = last.expect("at least one rep");
    let v = nrmse(
        r.channel("velocity").unwrap_or(&[]),
        reference.channel("velocity").unwrap_or(&[]),
    );
    if std::env::var("VALVE_ERR").is_ok() {
        let a = r.channel("velocity").unwrap_or(&[]);
        let b = reference.channel("velocity").unwrap_or(&[]);
        // squared error per 50 ms window
        let mut win = vec![0.0; 200];
        for k in 0..a.len().min(b.len()) {
            win[(k / 50).min(199)] += (a[k] - b[k]).powi(2);
        }
        let tot: f64 = win.iter().sum();
        let mut idx: Vec<usize> = (0..200).collect();
        idx.sort_by(|&i, &j| win[j].total_cmp(&win[i]));
        for &i in &idx[..12] {
            println!(
                "  window {:.2} s: {:.1} % of the squared error",
                i as f64 * 0.05,
                100.0 * win[i] / tot
            );
        }
    }
    println!(
        "{} rtol {rtol:.0e}: best {:.3} ms, steps {}, rejected {}, rhs {}, velocity NRMSE {v:.2e} (reference {} steps)",
        solver.name(),
        best * 1e3,
        r.stats.steps,
        r.stats.rejected,
        r.stats.rhs_evals,
        reference.stats.steps
    );
}

/// Step sizes over time (`VALVE_STEPS=1` a histogram, `=2` every step).
fn steps(rig: &ValveRig, command: Signal, rtol: f64) {
    use hydrocyl_integrators::{solve, Method, Options};
    let mut c = rig.circuit(command).expect("circuit");
    let x0 = c.initial_state();
    c.reset(0.0, &x0);
    let o = Options {
        rtol,
        atol: c.atol(rtol),
        ..Options::default()
    };
    let s = solve(Method::DormandPrince45, &mut c, 0.0, &x0, 10.0, &o).expect("solve");
    let mut hist = [0usize; 12];
    for k in 1..s.t.len() {
        let h = s.t[k] - s.t[k - 1];
        let b = ((-h.log10()).floor() as usize).min(11);
        hist[b] += 1;
        if std::env::var("VALVE_STEPS").as_deref() == Ok("2") {
            println!("{:.6} {:.3e}", s.t[k], h);
        }
    }
    println!(
        "h histogram by decade (1e-0..1e-11): {hist:?}; rejected {}",
        s.stats.rejected
    );
}
