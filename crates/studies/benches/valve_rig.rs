//! Speed of the `leaney-moog` square-wave test (±90 mm/s, 6 s simulated) per
//! actuator formulation and integrator.
//!
//! Throughput is reported in elements = simulated **milliseconds**, so
//! criterion's `Kelem/s` reads directly as simulated seconds per wall second
//! (the goal for the fundamental model is ≥ 1000, i.e. ≥ 1 Melem/s).

use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use hydrocyl_studies::chapter3;
use hydrocyl_system::run::{RunOptions, Solver};
use hydrocyl_system::valve_rig::Formulation;
use std::hint::black_box;

fn square_wave(c: &mut Criterion) {
    let case = chapter3::square_wave().expect("square-wave case");
    let span_ms = (case.times[case.times.len() - 1] - case.times[0]) * 1e3;
    for solver in [Solver::Dp45, Solver::Rosenbrock, Solver::Rk4] {
        let mut g = c.benchmark_group(format!("square-wave/{}", solver.name()));
        g.throughput(Throughput::Elements(span_ms as u64));
        g.sample_size(10);
        for f in Formulation::ALL {
            let mut rig = case.rig.clone();
            rig.cylinder.formulation = f;
            let opts = RunOptions {
                solver,
                ..RunOptions::default()
            };
            g.bench_function(f.name(), |b| {
                b.iter(|| {
                    let r = rig
                        .simulate(case.command.clone(), &case.times, &opts)
                        .expect("square-wave run");
                    black_box(r.stats.steps)
                })
            });
        }
        g.finish();
    }
}

criterion_group!(benches, square_wave);
criterion_main!(benches);
