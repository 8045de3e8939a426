//! Profiling aid for issue 13's "no slowdown": the criterion `hybrid` bench's
//! workload (the chapter-7 0.2 Hz square, 5 simulated s, Rosenbrock, 1 ms
//! output), run `reps` times; prints the best wall time, the solver
//! statistics and the algebraic node's solve counters.
//!
//! `cargo run --release -p hydrocyl-studies --example hybrid_square -- [reps]`

use hydrocyl_studies::chapter7::{Chapter7Test, Load, Shape};
use hydrocyl_system::run::{RunOptions, Solver};
use hydrocyl_system::simulation::Simulation;

fn main() {
    let reps: usize = std::env::args()
        .nth(1)
        .and_then(|s| s.parse().ok())
        .unwrap_or(20);
    let test = Chapter7Test::new(Shape::Square, Load::None);
    let rig = test.rig();
    let t: Vec<f64> = (0..=5000).map(|k| k as f64 * 1e-3).collect();
    let opts = RunOptions {
        solver: Solver::Rosenbrock,
        ..RunOptions::default()
    };
    let mut best = f64::INFINITY;
    let mut k = 0;
    let mut last_run = |reps: usize| {
        k += 1;
        k == reps
    };
    for _ in 0..reps {
        let start = std::time::Instant::now();
        let circ = rig.build(test.command(&rig)).expect("rig");
        let r = Simulation::of_circuit(circ)
            .options(opts.clone())
            .run(&t)
            .expect("run");
        best = best.min(start.elapsed().as_secs_f64());
        if last_run(reps) {
            let s = &r.stats;
            let solves: Vec<String> = r
                .diagnostics
                .iter()
                .filter(|(k, _)| k.contains("solve"))
                .map(|(k, v)| format!("{k} {v}"))
                .collect();
            println!(
                "steps {} rejected {} rhs {} jac {} lu {}; {}",
                s.steps,
                s.rejected,
                s.rhs_evals,
                s.jac_evals,
                s.lu_decomps,
                solves.join(", ")
            );
        }
    }
    println!("best {:.3} ms", best * 1e3);
}
