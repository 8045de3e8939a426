//! `cargo xtask bench`: speed as **ratios** against a reference run on the same
//! machine in the same run, so the numbers mean something on any machine.
//! (Absolute times are printed too, for the record.) The criterion benches in
//! each crate (`cargo bench -p <crate>`) are the detailed measurements; this
//! task is the quick overview. It runs in the profile `cargo xtask` is built
//! with (dev, `opt-level = 2`, dependencies at 3): both sides of every ratio
//! are built the same way.

use hydrocyl_ports::{Area, Density, Pressure};
use hydrocyl_valves::orifice::Orifice;
use hydrocyl_xfactor::{x_factor, x_factor_numerical};
use std::hint::black_box;
use std::time::Instant;

/// Median wall time per call \[ns\] of `f`, which performs `calls` calls.
fn ns_per_call(calls: usize, mut f: impl FnMut() -> f64) -> f64 {
    // warm up, then the median of 9 repetitions
    black_box(f());
    let mut samples: Vec<f64> = (0..9)
        .map(|_| {
            let t0 = Instant::now();
            black_box(f());
            t0.elapsed().as_secs_f64() * 1e9 / calls as f64
        })
        .collect();
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

fn orifice_typed_vs_raw() {
    let o = Orifice::new(0.625, Density::new(870.0));
    let coef = o.coefficient();
    let dpt = o.dp_transition.si();
    let n = 100_000;
    let ps: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let s = i as f64 / n as f64;
            (7.0e6 * s, 3.5e6 * (1.0 - s))
        })
        .collect();
    let raw = ns_per_call(n, || {
        ps.iter()
            .map(|&(u, d)| {
                let dp = black_box(u) - d;
                let r = if dp.abs() >= dpt {
                    dp.abs().sqrt() * dp.signum()
                } else {
                    let q = dp / dpt;
                    dp / dpt.sqrt() * (1.25 - 0.25 * q * q)
                };
                coef * 1.0e-5 * r
            })
            .sum()
    });
    let typed = ns_per_call(n, || {
        ps.iter()
            .map(|&(u, d)| {
                o.flow(
                    Area::new(1.0e-5),
                    Pressure::new(black_box(u)),
                    Pressure::new(d),
                )
                .si()
            })
            .sum()
    });
    println!(
        "orifice flow, typed ports vs raw f64:      typed {typed:8.2} ns  raw {raw:8.2} ns  ratio typed/raw {:.3}",
        typed / raw
    );
}

fn xfactor_analytical_vs_brent() {
    let n = 10_000;
    let pts: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let g = 1.01 + 4.99 * ((i * 7919) % n) as f64 / n as f64;
            let t = -0.999 + 1.998 * i as f64 / n as f64;
            (g, t)
        })
        .collect();
    let ana = ns_per_call(n, || {
        pts.iter().map(|&(g, t)| x_factor(black_box(g), t)).sum()
    });
    let num = ns_per_call(n, || {
        pts.iter()
            .map(|&(g, t)| x_factor_numerical(black_box(g), t, 1e-12))
            .sum()
    });
    println!(
        "X factor, analytical vs Brent (tol 1e-12): analytical {ana:8.2} ns  Brent {num:8.2} ns  speed-up {:.1}x",
        num / ana
    );
}

/// Runs the benchmarks; returns `true` (a benchmark has no pass/fail).
pub fn run() -> bool {
    println!("cargo xtask bench: ratios against a reference in the same run on this machine");
    orifice_typed_vs_raw();
    xfactor_analytical_vs_brent();
    true
}
