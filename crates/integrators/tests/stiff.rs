//! Stiff problems: the Rosenbrock method needs few steps where the explicit
//! method exceeds a step budget.

use hydrocyl_integrators::problems::{Robertson, VanDerPol};
use hydrocyl_integrators::{solve, Method, OdeSystem, Options, SolveError};

#[test]
fn van_der_pol_mu_1000_rosenbrock_few_steps_dp45_over_budget() {
    let opts = Options {
        rtol: 1e-6,
        atol: vec![1e-6],
        max_steps: 50_000,
        ..Options::default()
    };
    let mut sys = VanDerPol { mu: 1000.0 };
    let sol = solve(
        Method::Rosenbrock,
        &mut sys,
        0.0,
        &[2.0, 0.0],
        3000.0,
        &opts,
    )
    .unwrap();
    let s = sol.stats;
    assert!(s.steps + s.rejected < 3000, "Rodas4 took {s:?}");
    // One period is about (3 − 2 ln 2) μ ≈ 1614 s: by 3000 s x1 has been through −2.
    let min_x1 = (0..sol.t.len())
        .map(|k| sol.state(k)[0])
        .fold(f64::INFINITY, f64::min);
    assert!(min_x1 < -1.9 && min_x1 > -2.1, "min x1 = {min_x1}");

    let e = solve(
        Method::DormandPrince45,
        &mut sys,
        0.0,
        &[2.0, 0.0],
        3000.0,
        &opts,
    )
    .unwrap_err();
    match e {
        SolveError::TooManySteps { t, max } => {
            assert_eq!(max, 50_000);
            assert!(t < 3000.0);
        }
        other => panic!("expected TooManySteps, got {other:?}"),
    }
}

#[test]
fn robertson_to_1e5_conserves_mass_in_few_steps() {
    let opts = Options {
        rtol: 1e-6,
        atol: vec![1e-10],
        max_steps: 20_000,
        ..Options::default()
    };
    let sol = solve(
        Method::Rosenbrock,
        &mut Robertson,
        0.0,
        &[1.0, 0.0, 0.0],
        1e5,
        &opts,
    )
    .unwrap();
    assert!(sol.stats.steps < 500, "{:?}", sol.stats);
    for k in 0..sol.t.len() {
        let x = sol.state(k);
        let sum: f64 = x.iter().sum();
        assert!((sum - 1.0).abs() < 1e-12, "mass {sum} at t = {}", sol.t[k]);
        assert!(
            x.iter().all(|v| *v > -1e-10),
            "negative concentration {x:?}"
        );
    }
    // Reference values at t = 1e5 (Hairer & Wanner's tables): x1 ≈ 0.0179, x3 ≈ 0.982.
    let x = sol.last().unwrap();
    assert!((x[0] - 1.7832e-2).abs() < 2e-4, "x1 = {}", x[0]);
    let e = solve(
        Method::DormandPrince45,
        &mut Robertson,
        0.0,
        &[1.0, 0.0, 0.0],
        1e5,
        &opts,
    )
    .unwrap_err();
    assert!(matches!(e, SolveError::TooManySteps { .. }), "{e:?}");
}

#[test]
fn fd_jacobian_matches_analytic_jacobian_results() {
    // The same stiff solve with the Jacobian from finite differences.
    use hydrocyl_integrators::OdeSystem;
    struct NoJac(VanDerPol);
    impl OdeSystem for NoJac {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
            self.0.rhs(t, x, dx)
        }
    }
    let opts = Options {
        rtol: 1e-8,
        atol: vec![1e-8],
        ..Options::default()
    };
    let a = solve(
        Method::Rosenbrock,
        &mut VanDerPol { mu: 50.0 },
        0.0,
        &[2.0, 0.0],
        100.0,
        &opts,
    )
    .unwrap();
    let b = solve(
        Method::Rosenbrock,
        &mut NoJac(VanDerPol { mu: 50.0 }),
        0.0,
        &[2.0, 0.0],
        100.0,
        &opts,
    )
    .unwrap();
    let (xa, xb) = (a.last().unwrap(), b.last().unwrap());
    assert!((xa[0] - xb[0]).abs() < 1e-4, "{xa:?} vs {xb:?}");
    assert_eq!(
        b.stats.rhs_evals,
        2 + 4 * b.stats.jac_evals + 5 * (b.stats.steps + b.stats.rejected)
    );
}

/// Van der Pol with two quadratures appended, `∫x₁ dt` and `∫x₁² dt`,
/// declared as quadratures or not.
struct VdpWithQuadratures {
    vdp: VanDerPol,
    declared: bool,
}

impl hydrocyl_integrators::OdeSystem for VdpWithQuadratures {
    fn dim(&self) -> usize {
        4
    }
    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        self.vdp.rhs(t, &x[..2], &mut dx[..2]);
        dx[2] = x[0];
        dx[3] = x[0] * x[0];
    }
    fn n_quadratures(&self) -> usize {
        if self.declared {
            2
        } else {
            0
        }
    }
}

#[test]
fn declared_quadratures_skip_their_jacobian_columns_and_change_nothing_else() {
    use hydrocyl_integrators::OdeSystem;
    let opts = Options {
        rtol: 1e-8,
        atol: vec![1e-8],
        max_steps: 100_000,
        ..Options::default()
    };
    let run = |declared: bool| {
        let mut sys = VdpWithQuadratures {
            vdp: VanDerPol { mu: 50.0 },
            declared,
        };
        assert_eq!(sys.n_quadratures(), if declared { 2 } else { 0 });
        solve(
            Method::Rosenbrock,
            &mut sys,
            0.0,
            &[2.0, 0.0, 0.0, 0.0],
            100.0,
            &opts,
        )
        .unwrap()
    };
    let (full, block) = (run(false), run(true));
    let (a, b) = (full.state(full.t.len() - 1), block.state(block.t.len() - 1));
    // the block solve is the same linear algebra; the declared quadratures
    // are normed apart from the states (each group's RMS, the larger taken),
    // so the steps differ a little and the answers agree to the tolerance's
    // global error
    for i in 0..4 {
        assert!(
            (a[i] - b[i]).abs() <= 1e-5 * a[i].abs().max(1.0),
            "state {i}: {} vs {}",
            a[i],
            b[i]
        );
    }
    // two fewer finite-difference columns per Jacobian
    // (a Jacobian: f, ∂f/∂t, and one difference per column; a step five
    // more stages; the start two)
    assert_eq!(
        block.stats.rhs_evals,
        2 + 4 * block.stats.jac_evals + 5 * (block.stats.steps + block.stats.rejected)
    );
    assert_eq!(
        full.stats.rhs_evals,
        2 + 6 * full.stats.jac_evals + 5 * (full.stats.steps + full.stats.rejected)
    );
    // ∫x₁² dt is positive and grows with the limit cycle's |x₁| ≈ 1..2
    assert!(b[3] > 50.0 && b[2].is_finite(), "∫x₁² dt = {}", b[3]);
}

/// Van der Pol that says it is autonomous ([`OdeSystem::constant_in_time`]).
struct SaysAutonomous(VanDerPol);

impl OdeSystem for SaysAutonomous {
    fn dim(&self) -> usize {
        self.0.dim()
    }
    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        self.0.rhs(t, x, dx)
    }
    fn jacobian(&self, t: f64, x: &[f64], jac: &mut [f64]) -> bool {
        self.0.jacobian(t, x, jac)
    }
    fn constant_in_time(&self, _t: f64) -> bool {
        true
    }
}

#[test]
fn an_autonomous_model_saves_the_time_difference_and_nothing_moves() {
    // f does not depend on t, so the forward difference in t is exactly 0:
    // taking ∂f/∂t = 0 must give the same solution bit for bit, one
    // right-hand side a Jacobian cheaper
    let opts = Options {
        rtol: 1e-6,
        atol: vec![1e-6],
        ..Options::default()
    };
    let (x0, t_end) = ([2.0, 0.0], 3000.0);
    let fd = solve(
        Method::Rosenbrock,
        &mut VanDerPol { mu: 1000.0 },
        0.0,
        &x0,
        t_end,
        &opts,
    )
    .unwrap();
    let zero = solve(
        Method::Rosenbrock,
        &mut SaysAutonomous(VanDerPol { mu: 1000.0 }),
        0.0,
        &x0,
        t_end,
        &opts,
    )
    .unwrap();
    assert_eq!(fd.t, zero.t);
    assert_eq!(fd.x, zero.x);
    let (a, b) = (fd.stats, zero.stats);
    assert_eq!(
        (a.steps, a.rejected, a.jac_evals),
        (b.steps, b.rejected, b.jac_evals)
    );
    assert_eq!(
        a.rhs_evals - b.rhs_evals,
        a.jac_evals,
        "{a:?} against {b:?}"
    );
}
