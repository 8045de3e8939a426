//! Analytical vs numerical X factor over the same 10,000 points.
//!
//! The points: 100 area ratios evenly in [1.01, 6] times 100 travels evenly
//! inside the underlap (-0.99 .. 0.99). Each benchmark evaluates all 10,000
//! points; the throughput is per call. After the runs, the ratio of the mean
//! times (Brent at 1e-12 over analytical) is printed from criterion's
//! estimates.
//!
//! `cargo bench -p hydrocyl-xfactor --bench xfactor -- --warm-up-time 1 --measurement-time 2`

use std::hint::black_box;
use std::path::PathBuf;

use criterion::{criterion_group, Criterion, Throughput};
use hydrocyl_xfactor::{x_factor, x_factor_numerical};

const N_GAMMA: usize = 100;
const N_TRAVEL: usize = 100;
const GROUP: &str = "xfactor_10k_points";

fn points() -> Vec<(f64, f64)> {
    let mut p = Vec::with_capacity(N_GAMMA * N_TRAVEL);
    for i in 0..N_GAMMA {
        let g = 1.01 + (6.0 - 1.01) * i as f64 / (N_GAMMA - 1) as f64;
        for j in 0..N_TRAVEL {
            let t = -0.99 + 1.98 * j as f64 / (N_TRAVEL - 1) as f64;
            p.push((g, t));
        }
    }
    p
}

fn bench(c: &mut Criterion) {
    let pts = points();
    let mut group = c.benchmark_group(GROUP);
    group.throughput(Throughput::Elements(pts.len() as u64));
    group.bench_function("analytical", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &(g, t) in &pts {
                s += x_factor(black_box(g), black_box(t));
            }
            s
        })
    });
    group.bench_function("brent_1e-12", |b| {
        b.iter(|| {
            let mut s = 0.0;
            for &(g, t) in &pts {
                s += x_factor_numerical(black_box(g), black_box(t), 1e-12);
            }
            s
        })
    });
    group.finish();
}

/// Criterion's output directory: `$CRITERION_HOME`, else `<target>/criterion`.
fn criterion_dir() -> PathBuf {
    if let Some(h) = std::env::var_os("CRITERION_HOME") {
        return PathBuf::from(h);
    }
    let target = std::env::var_os("CARGO_TARGET_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../target"));
    target.join("criterion")
}

/// The mean time \[ns\] of one benchmark from criterion's estimates, if present.
fn mean_ns(id: &str) -> Option<f64> {
    let path = criterion_dir()
        .join(GROUP)
        .join(id)
        .join("new/estimates.json");
    let text = std::fs::read_to_string(path).ok()?;
    let v: serde_json::Value = serde_json::from_str(&text).ok()?;
    v["mean"]["point_estimate"].as_f64()
}

fn report() {
    let n = (N_GAMMA * N_TRAVEL) as f64;
    match (mean_ns("analytical"), mean_ns("brent_1e-12")) {
        (Some(a), Some(b)) => {
            println!(
                "\nper call: analytical {:.1} ns, Brent (tol 1e-12) {:.1} ns; Brent / analytical = {:.1}x",
                a / n,
                b / n,
                b / a
            );
        }
        _ => println!(
            "\n(ratio not printed: criterion estimates not found under {})",
            criterion_dir().display()
        ),
    }
}

criterion_group!(benches, bench);

fn main() {
    benches();
    Criterion::default().configure_from_args().final_summary();
    report();
}
