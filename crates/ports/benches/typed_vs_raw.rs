//! Zero-cost check: the same sharp-edged orifice law (thesis eq 2.8, one
//! metering edge) written on bare `f64` and on the typed quantities, timed in
//! the same run. The ratio typed/raw should be 1 within noise.

use criterion::{criterion_group, criterion_main, Criterion};
use hydrocyl_ports::{Area, Density, Pressure, VolumeFlow};
use std::hint::black_box;

#[inline(never)]
fn orifice_raw(cd: f64, area: f64, rho: f64, p_up: f64, p_down: f64) -> f64 {
    let dp = p_up - p_down;
    cd * area * (2.0 / rho).sqrt() * dp.abs().sqrt() * dp.signum()
}

#[inline(never)]
fn orifice_typed(
    cd: f64,
    area: Area,
    rho: Density,
    p_up: Pressure,
    p_down: Pressure,
) -> VolumeFlow {
    let dp = p_up - p_down;
    VolumeFlow::new(cd * area.si() * (2.0 / rho.si()).sqrt() * dp.abs().si().sqrt() * dp.signum())
}

fn inputs() -> Vec<(f64, f64)> {
    (0..1024)
        .map(|i| {
            let s = i as f64 / 1024.0;
            (7.0e6 * s, 3.5e6 * (1.0 - s))
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let xs = inputs();
    let mut g = c.benchmark_group("orifice_flow_1024");
    g.bench_function("raw_f64", |b| {
        b.iter(|| {
            let mut acc = 0.0;
            for &(pu, pd) in &xs {
                acc += orifice_raw(black_box(0.625), 1.0e-5, 870.0, pu, pd);
            }
            acc
        })
    });
    g.bench_function("typed", |b| {
        b.iter(|| {
            let mut acc = VolumeFlow::ZERO;
            for &(pu, pd) in &xs {
                acc += orifice_typed(
                    black_box(0.625),
                    Area::new(1.0e-5),
                    Density::new(870.0),
                    Pressure::new(pu),
                    Pressure::new(pd),
                );
            }
            acc
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
