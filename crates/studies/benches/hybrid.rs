//! Criterion bench of the `wang-hybrid` rig: simulated seconds per wall
//! second for the chapter-7 square-wave test (±50 mm/s, 0.2 Hz, no added
//! load, one 5 s period, Rosenbrock, rtol 1e-6), output every 1 ms, with
//! and without the mass-balance quadratures, and with the finite-difference
//! Jacobian in place of the circuit's analytic one. The goal is 500× real time.

use criterion::{criterion_group, criterion_main, BatchSize, Criterion, Throughput};
use hydrocyl_studies::chapter7::{Chapter7Test, Load, Shape};
use hydrocyl_system::run::{RunOptions, Solver};
use hydrocyl_system::simulation::Simulation;
use std::hint::black_box;

fn square_period(c: &mut Criterion) {
    let test = Chapter7Test::new(Shape::Square, Load::None);
    let rig = test.rig();
    let t: Vec<f64> = (0..=5000).map(|k| k as f64 * 1e-3).collect();
    let mut g = c.benchmark_group("wang-hybrid square 0.2 Hz, 5 simulated s");
    // throughput in simulated milliseconds: criterion's "elements/s" reads as
    // simulated ms per wall second, i.e. 1000 x the real-time factor
    g.throughput(Throughput::Elements(5000));
    g.sample_size(10);
    // the circuit's analytic Jacobian (issue 13 item 9), and the same run
    // with the finite-difference Jacobian it replaced, as an in-run reference
    for (name, quadratures, analytic) in [
        ("plain", false, true),
        ("with mass balance", true, true),
        ("plain, finite-difference Jacobian", false, false),
    ] {
        let opts = RunOptions {
            solver: Solver::Rosenbrock,
            quadratures,
            ..RunOptions::default()
        };
        g.bench_function(name, |b| {
            b.iter(|| {
                let mut sim = Simulation::of_circuit(rig.build(test.command(&rig)).expect("rig"))
                    .options(opts.clone());
                sim.circuit_mut().set_analytic_jacobian(analytic);
                black_box(sim.run(&t).expect("run").stats.steps)
            })
        });
    }
    // the run alone: the rig built (netlist read, circuit assembled) in
    // criterion's untimed setup, so that the solve is timed without the
    // one-off build a sweep or an FMU pays once
    let opts = RunOptions {
        solver: Solver::Rosenbrock,
        ..RunOptions::default()
    };
    g.bench_function("plain, run only", |b| {
        b.iter_batched(
            || {
                Simulation::of_circuit(rig.build(test.command(&rig)).expect("rig"))
                    .options(opts.clone())
            },
            |mut sim| black_box(sim.run(&t).expect("run").stats.steps),
            BatchSize::SmallInput,
        )
    });
    g.finish();
}

criterion_group!(benches, square_period);
criterion_main!(benches);
