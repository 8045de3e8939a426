//! Work counters agree with what each method must do per step.

use hydrocyl_integrators::problems::{HarmonicOscillator, VanDerPol};
use hydrocyl_integrators::{solve, Method, Options};

#[test]
fn dormand_prince_uses_six_evaluations_per_step_with_fsal() {
    let mut sys = VanDerPol { mu: 5.0 };
    let opts = Options {
        rtol: 1e-7,
        atol: vec![1e-9],
        h0: Some(1e-4),
        ..Options::default()
    };
    let s = solve(
        Method::DormandPrince45,
        &mut sys,
        0.0,
        &[2.0, 0.0],
        20.0,
        &opts,
    )
    .unwrap()
    .stats;
    assert!(s.steps > 100 && s.rejected > 0, "{s:?}");
    assert_eq!(s.rhs_evals, 1 + 6 * (s.steps + s.rejected), "{s:?}");
    assert_eq!((s.jac_evals, s.lu_decomps, s.events), (0, 0, 0));
    // Without h0 the starting-step heuristic costs two more evaluations.
    let s2 = solve(
        Method::DormandPrince45,
        &mut sys,
        0.0,
        &[2.0, 0.0],
        20.0,
        &Options { h0: None, ..opts },
    )
    .unwrap()
    .stats;
    assert_eq!(s2.rhs_evals, 3 + 6 * (s2.steps + s2.rejected), "{s2:?}");
}

#[test]
fn rk4_uses_four_evaluations_per_step() {
    let mut sys = HarmonicOscillator { omega: 1.0 };
    let opts = Options {
        h0: Some(0.01),
        ..Options::default()
    };
    let s = solve(Method::Rk4, &mut sys, 0.0, &[1.0, 0.0], 1.0, &opts)
        .unwrap()
        .stats;
    assert_eq!(s.steps, 100);
    assert_eq!(s.rhs_evals, 1 + 4 * s.steps);
}

#[test]
fn rodas4_counts_jacobians_and_factorisations() {
    let mut sys = VanDerPol { mu: 100.0 };
    let opts = Options {
        rtol: 1e-6,
        atol: vec![1e-8],
        ..Options::default()
    };
    let s = solve(Method::Rosenbrock, &mut sys, 0.0, &[2.0, 0.0], 200.0, &opts)
        .unwrap()
        .stats;
    // One Jacobian per accepted step (reused after a rejection), one LU per attempt.
    assert_eq!(s.jac_evals, s.steps, "{s:?}");
    assert_eq!(s.lu_decomps, s.steps + s.rejected, "{s:?}");
    // Analytic Jacobian: f and ∂f/∂t per Jacobian, five stages per attempt, two for the start.
    assert_eq!(
        s.rhs_evals,
        2 + 2 * s.jac_evals + 5 * (s.steps + s.rejected),
        "{s:?}"
    );
}

#[test]
fn each_event_restart_costs_a_fresh_start() {
    use hydrocyl_integrators::problems::BouncingBall;
    let mut ball = BouncingBall::new(9.81, 0.8, 5);
    let opts = Options {
        rtol: 1e-8,
        atol: vec![1e-10],
        ..Options::default()
    };
    let s = solve(
        Method::DormandPrince45,
        &mut ball,
        0.0,
        &[2.0, 0.0],
        10.0,
        &opts,
    )
    .unwrap()
    .stats;
    assert_eq!(s.events, 5);
    // Start: f(t0) and one probe for the step estimate, plus the first stage;
    // the same again after each of the four events that continue (the fifth stops).
    assert_eq!(
        s.rhs_evals,
        3 + 3 * (s.events - 1) + 6 * (s.steps + s.rejected),
        "{s:?}"
    );
}
