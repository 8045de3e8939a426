//! Speed of the integrators and of the small dense LU behind the Rosenbrock
//! method.
//!
//! * `solve/*`: one solve per iteration; throughput is reported in accepted
//!   steps, so criterion's "elem/s" is steps per second. Van der Pol with
//!   μ = 10 (mildly stiff: DP45 still finishes) for every method, Robertson
//!   (stiff) for Rodas4 only.
//! * `lu/*`: factorise and solve one right-hand side of an `n × n` matrix,
//!   n = 2..16: the in-place LU the solver uses, nalgebra's `LU` and faer's
//!   `PartialPivLu`.
//!
//! Quick run: `cargo bench -p hydrocyl-integrators -- --warm-up-time 1 --measurement-time 2`.

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use faer::linalg::solvers::Solve;
use hydrocyl_integrators::linalg::{DenseLu, InPlaceLu};
use hydrocyl_integrators::problems::{Robertson, VanDerPol};
use hydrocyl_integrators::{solve, Method, OdeSystem, Options};
use nalgebra::{DMatrix, DVectorViewMut, Dyn, LU};
use std::hint::black_box;

/// nalgebra's LU with partial pivoting (copies the matrix per factorisation).
pub struct NalgebraLu {
    n: usize,
    a: Vec<f64>,
    lu: Option<LU<f64, Dyn, Dyn>>,
}

impl DenseLu for NalgebraLu {
    fn new(n: usize) -> Self {
        Self {
            n,
            a: vec![0.0; n * n],
            lu: None,
        }
    }

    fn matrix_mut(&mut self) -> &mut [f64] {
        &mut self.a
    }

    fn factor(&mut self) -> bool {
        let m = DMatrix::from_row_slice(self.n, self.n, &self.a);
        let lu = m.lu();
        let u = lu.u();
        let ok = (0..self.n).all(|i| {
            let d = u[(i, i)];
            d != 0.0 && d.is_finite()
        });
        self.lu = if ok { Some(lu) } else { None };
        ok
    }

    fn solve(&self, b: &mut [f64]) {
        if let Some(lu) = &self.lu {
            let n = self.n;
            let mut v = DVectorViewMut::from_slice(b, n);
            lu.solve_mut(&mut v);
        }
    }
}

fn run(method: Method, sys: &mut dyn OdeSystem, x0: &[f64], t_end: f64, opts: &Options) -> usize {
    solve(method, sys, 0.0, x0, t_end, opts)
        .expect("benchmark solve")
        .stats
        .steps
}

fn bench_solvers(c: &mut Criterion) {
    let mut g = c.benchmark_group("solve");
    let adaptive = Options {
        rtol: 1e-6,
        atol: vec![1e-8],
        ..Options::default()
    };
    let rk4 = Options {
        h0: Some(2e-3),
        ..Options::default()
    };
    let t_end = 20.0;
    for (name, method, opts) in [
        ("vdp10/dp45", Method::DormandPrince45, &adaptive),
        ("vdp10/rodas4", Method::Rosenbrock, &adaptive),
        ("vdp10/rk4", Method::Rk4, &rk4),
    ] {
        let steps = run(
            method,
            &mut VanDerPol { mu: 10.0 },
            &[2.0, 0.0],
            t_end,
            opts,
        );
        g.throughput(Throughput::Elements(steps as u64));
        g.bench_function(name, |b| {
            b.iter(|| {
                run(
                    method,
                    &mut VanDerPol { mu: 10.0 },
                    black_box(&[2.0, 0.0]),
                    t_end,
                    opts,
                )
            })
        });
    }
    let rob = Options {
        rtol: 1e-6,
        atol: vec![1e-10],
        ..Options::default()
    };
    let steps = run(
        Method::Rosenbrock,
        &mut Robertson,
        &[1.0, 0.0, 0.0],
        1e5,
        &rob,
    );
    g.throughput(Throughput::Elements(steps as u64));
    g.bench_function("robertson/rodas4", |b| {
        b.iter(|| {
            run(
                Method::Rosenbrock,
                &mut Robertson,
                black_box(&[1.0, 0.0, 0.0]),
                1e5,
                &rob,
            )
        })
    });
    g.finish();
}

/// A deterministic, well-conditioned test matrix (diagonally dominant), row-major.
fn test_matrix(n: usize) -> Vec<f64> {
    let mut s: u64 = 0x9E37_79B9_7F4A_7C15;
    let mut a = vec![0.0; n * n];
    for i in 0..n {
        for j in 0..n {
            s = s
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1_442_695_040_888_963_407);
            a[i * n + j] = ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5;
        }
        a[i * n + i] += n as f64;
    }
    a
}

fn bench_lu(c: &mut Criterion) {
    let mut g = c.benchmark_group("lu");
    for n in [2usize, 4, 8, 12, 16] {
        let a = test_matrix(n);
        let rhs: Vec<f64> = (0..n).map(|i| i as f64 + 1.0).collect();

        let mut inplace = InPlaceLu::new(n);
        let mut b = rhs.clone();
        g.bench_with_input(BenchmarkId::new("in-place", n), &n, |bch, _| {
            bch.iter(|| {
                inplace.matrix_mut().copy_from_slice(black_box(&a));
                assert!(inplace.factor());
                b.copy_from_slice(&rhs);
                inplace.solve(&mut b);
                black_box(b[0])
            })
        });

        let mut nal = NalgebraLu::new(n);
        g.bench_with_input(BenchmarkId::new("nalgebra", n), &n, |bch, _| {
            bch.iter(|| {
                nal.matrix_mut().copy_from_slice(black_box(&a));
                assert!(nal.factor());
                b.copy_from_slice(&rhs);
                nal.solve(&mut b);
                black_box(b[0])
            })
        });

        let mut fm = faer::Mat::<f64>::zeros(n, n);
        let mut fb = faer::Mat::<f64>::zeros(n, 1);
        g.bench_with_input(BenchmarkId::new("faer", n), &n, |bch, _| {
            bch.iter(|| {
                let a = black_box(&a);
                for i in 0..n {
                    for j in 0..n {
                        fm[(i, j)] = a[i * n + j];
                    }
                }
                let lu = fm.partial_piv_lu();
                for i in 0..n {
                    fb[(i, 0)] = rhs[i];
                }
                lu.solve_in_place(fb.as_mut());
                black_box(fb[(0, 0)])
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench_solvers, bench_lu);
criterion_main!(benches);
