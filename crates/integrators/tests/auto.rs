//! The automatic method choice: stays explicit (and identical to DP45) where
//! nothing is stiff, goes stiff where DP45 is held by stability, and comes
//! back when the stiffness is gone.

use hydrocyl_integrators::problems::{HarmonicOscillator, VanDerPol};
use hydrocyl_integrators::{solve, Method, OdeSystem, Options};

#[test]
fn a_problem_that_is_never_stiff_is_solved_exactly_as_dp45() {
    let opts = Options {
        rtol: 1e-8,
        atol: vec![1e-10],
        ..Options::default()
    };
    let mut sys = HarmonicOscillator { omega: 3.0 };
    let dp = solve(
        Method::DormandPrince45,
        &mut sys,
        0.0,
        &[1.0, 0.0],
        20.0,
        &opts,
    )
    .unwrap();
    let auto = solve(Method::Auto, &mut sys, 0.0, &[1.0, 0.0], 20.0, &opts).unwrap();
    assert_eq!(auto.stats.switches, 0);
    assert_eq!(auto.stats.stiff_steps, 0);
    assert_eq!(auto.stats.choice(), "explicit");
    assert_eq!(auto.t, dp.t);
    assert_eq!(auto.x, dp.x);
    assert_eq!(auto.stats, dp.stats);
}

#[test]
fn van_der_pol_goes_stiff_and_costs_what_rosenbrock_costs() {
    let opts = Options {
        rtol: 1e-6,
        atol: vec![1e-6],
        max_steps: 200_000,
        ..Options::default()
    };
    let mut sys = VanDerPol { mu: 1000.0 };
    let ros = solve(
        Method::Rosenbrock,
        &mut sys,
        0.0,
        &[2.0, 0.0],
        3000.0,
        &opts,
    )
    .unwrap();
    // DP45 alone runs out of its 200,000 steps before t = 300 s
    let dp = solve(
        Method::DormandPrince45,
        &mut sys,
        0.0,
        &[2.0, 0.0],
        3000.0,
        &opts,
    );
    assert!(dp.is_err());
    let auto = solve(Method::Auto, &mut sys, 0.0, &[2.0, 0.0], 3000.0, &opts).unwrap();
    let s = auto.stats;
    assert!(s.switches >= 1 && s.stiff_steps > 0, "{s:?}");
    // not many more right-hand sides than Rodas4 alone
    assert!(
        s.rhs_evals < 2 * ros.stats.rhs_evals,
        "auto {s:?}, ros {:?}",
        ros.stats
    );
    // and the same answer
    let (a, r) = (auto.last().unwrap(), ros.last().unwrap());
    assert!((a[0] - r[0]).abs() < 1e-3, "{a:?} vs {r:?}");
}

/// `x' = −k(t) (x − cos t)` with `k` falling from 1e5 to 1 over a few
/// seconds: stiff at the start, not at the end.
struct FadingStiffness;

impl FadingStiffness {
    fn k(t: f64) -> f64 {
        1.0 + 1e5 * (-3.0 * t).exp()
    }
}

impl OdeSystem for FadingStiffness {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = -Self::k(t) * (x[0] - t.cos());
    }
    fn jacobian(&self, t: f64, _x: &[f64], jac: &mut [f64]) -> bool {
        jac[0] = -Self::k(t);
        true
    }
}

#[test]
fn fading_stiffness_switches_back_to_the_explicit_method() {
    let opts = Options {
        rtol: 1e-7,
        atol: vec![1e-9],
        ..Options::default()
    };
    let mut sys = FadingStiffness;
    let auto = solve(Method::Auto, &mut sys, 0.0, &[0.0], 20.0, &opts).unwrap();
    let s = auto.stats;
    assert!(s.switches >= 2, "stiff and back: {s:?}");
    assert!(s.stiff_steps > 0 && s.stiff_steps < s.steps, "{s:?}");
    let tight = Options {
        rtol: 1e-11,
        atol: vec![1e-13],
        ..Options::default()
    };
    let r = solve(Method::Rosenbrock, &mut sys, 0.0, &[0.0], 20.0, &tight).unwrap();
    let (a, b) = (auto.last().unwrap()[0], r.last().unwrap()[0]);
    assert!((a - b).abs() < 1e-5, "{a} vs {b}");
    assert!(
        auto.stats.choice().contains("switches"),
        "{}",
        auto.stats.choice()
    );
}
