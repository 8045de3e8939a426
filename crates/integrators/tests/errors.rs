//! Bad input and failing solves return clear errors, never panics.

use hydrocyl_integrators::problems::ExponentialDecay;
use hydrocyl_integrators::{solve, Method, OdeSystem, Options, SolveError};

/// `x' = 1` for state 0 and NaN for state 1 once `t > t_bad`.
struct GoesNan {
    t_bad: f64,
}

impl OdeSystem for GoesNan {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, _x: &[f64], dx: &mut [f64]) {
        dx[0] = 1.0;
        dx[1] = if t > self.t_bad { f64::NAN } else { 0.0 };
    }
}

/// `x' = x²`: blows up at `t = 1/x0`.
struct BlowUp;

impl OdeSystem for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = x[0] * x[0];
    }
}

const ALL: [Method; 3] = [Method::DormandPrince45, Method::Rosenbrock, Method::Rk4];

fn opts_for(method: Method) -> Options {
    Options {
        h0: if method == Method::Rk4 {
            Some(0.01)
        } else {
            None
        },
        ..Options::default()
    }
}

#[test]
fn nan_rhs_is_reported_with_state_index_and_time() {
    for method in ALL {
        let mut sys = GoesNan { t_bad: 0.5 };
        let e = solve(method, &mut sys, 0.0, &[0.0, 0.0], 1.0, &opts_for(method)).unwrap_err();
        match e {
            SolveError::NonFinite { t, index } => {
                assert_eq!(index, 1, "{method:?}");
                assert!((0.4..=0.52).contains(&t), "{method:?}: t = {t}");
            }
            other => panic!("{method:?}: expected NonFinite, got {other:?}"),
        }
        let msg = e.to_string();
        assert!(msg.contains("state 1"), "{msg}");
    }
}

#[test]
fn nan_at_the_start_is_reported_at_t0() {
    let mut sys = GoesNan { t_bad: -1.0 };
    let e = solve(
        Method::DormandPrince45,
        &mut sys,
        0.0,
        &[0.0, 0.0],
        1.0,
        &Options::default(),
    )
    .unwrap_err();
    assert_eq!(e, SolveError::NonFinite { t: 0.0, index: 1 });
}

#[test]
fn blow_up_hits_the_minimum_step() {
    for method in [Method::DormandPrince45, Method::Rosenbrock] {
        let opts = Options {
            h_min: 1e-8,
            ..Options::default()
        };
        let e = solve(method, &mut BlowUp, 0.0, &[1.0], 2.0, &opts).unwrap_err();
        match e {
            SolveError::StepTooSmall { t, h, .. } => {
                assert!(h < 1e-8, "{method:?}: h = {h}");
                assert!(t > 0.99 && t < 1.01, "{method:?}: t = {t}");
            }
            other => panic!("{method:?}: expected StepTooSmall, got {other:?}"),
        }
    }
}

#[test]
fn step_budget_is_enforced() {
    let opts = Options {
        max_steps: 5,
        ..Options::default()
    };
    let mut sys = ExponentialDecay { k: 1.0 };
    let e = solve(Method::DormandPrince45, &mut sys, 0.0, &[1.0], 100.0, &opts).unwrap_err();
    assert!(
        matches!(e, SolveError::TooManySteps { max: 5, .. }),
        "{e:?}"
    );
}

fn invalid(method: Method, x0: &[f64], t0: f64, t_end: f64, opts: &Options) -> String {
    let mut sys = ExponentialDecay { k: 1.0 };
    match solve(method, &mut sys, t0, x0, t_end, opts) {
        Err(SolveError::InvalidInput(msg)) => msg,
        other => panic!("expected InvalidInput, got {other:?}"),
    }
}

#[test]
fn invalid_inputs_are_named() {
    let d = Options::default();
    assert!(
        invalid(Method::DormandPrince45, &[1.0, 2.0], 0.0, 1.0, &d).contains("x0 has 2 entries")
    );
    assert!(invalid(Method::DormandPrince45, &[1.0], 1.0, 0.0, &d).contains("before t0"));
    assert!(invalid(Method::DormandPrince45, &[f64::NAN], 0.0, 1.0, &d).contains("x0[0]"));
    assert!(invalid(Method::Rk4, &[1.0], 0.0, 1.0, &d).contains("h0"));
    let bad_atol = Options {
        atol: vec![1e-6, 1e-6, 1e-6],
        ..Options::default()
    };
    assert!(invalid(Method::Rosenbrock, &[1.0], 0.0, 1.0, &bad_atol).contains("atol has 3 entries"));
    let neg_rtol = Options {
        rtol: -1.0,
        ..Options::default()
    };
    assert!(invalid(Method::Rosenbrock, &[1.0], 0.0, 1.0, &neg_rtol).contains("rtol"));
    let unsorted = Options {
        t_eval: Some(vec![0.0, 0.5, 0.2]),
        ..Options::default()
    };
    assert!(invalid(Method::DormandPrince45, &[1.0], 0.0, 1.0, &unsorted).contains("not sorted"));
    let outside = Options {
        t_eval: Some(vec![0.0, 2.0]),
        ..Options::default()
    };
    assert!(invalid(Method::DormandPrince45, &[1.0], 0.0, 1.0, &outside).contains("t_eval[1]"));
    let bad_tol = Options {
        event_tol: 0.0,
        ..Options::default()
    };
    assert!(invalid(Method::DormandPrince45, &[1.0], 0.0, 1.0, &bad_tol).contains("event_tol"));
}

#[test]
fn zero_length_interval_returns_the_initial_state() {
    let mut sys = ExponentialDecay { k: 1.0 };
    let sol = solve(
        Method::DormandPrince45,
        &mut sys,
        2.0,
        &[3.0],
        2.0,
        &Options::default(),
    )
    .unwrap();
    assert_eq!(sol.t, vec![2.0]);
    assert_eq!(sol.x, vec![3.0]);
    assert_eq!(sol.stats.steps, 0);
}

/// Three states of which the middle one is stiff: `x0' = −x0`,
/// `x1' = −λ (x1 − cos t)` with λ = 1e12 s⁻¹, `x2' = x0`. Named
/// `a.slow`, `b.stiff`, `c.sum` when `named`.
struct OneStiff {
    named: bool,
}

impl OdeSystem for OneStiff {
    fn dim(&self) -> usize {
        3
    }
    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        dx[0] = -x[0];
        dx[1] = -1e12 * (x[1] - t.cos());
        dx[2] = x[0];
    }
    fn state_name(&self, i: usize) -> Option<String> {
        self.named
            .then(|| ["a.slow", "b.stiff", "c.sum"][i].to_string())
    }
}

/// An explicit method on a stiff state needs a step below the stability
/// limit (≈ 3e-12 s here); with `h_min` above it the solve fails, and the
/// failure names the state whose error the steps could not control.
#[test]
fn a_step_below_the_minimum_names_the_state_that_dominates_the_error() {
    let opts = Options {
        h_min: 1e-9,
        ..Options::default()
    };
    for named in [false, true] {
        let mut sys = OneStiff { named };
        let e = solve(
            Method::DormandPrince45,
            &mut sys,
            0.0,
            &[1.0, 1.0, 0.0],
            1.0,
            &opts,
        )
        .unwrap_err();
        let SolveError::StepTooSmall { dominant, .. } = &e else {
            panic!("expected StepTooSmall, got {e:?}");
        };
        assert_eq!(dominant.len(), 1, "{dominant:?}");
        assert_eq!(dominant[0].index, 1);
        assert!(dominant[0].error > 1.0, "{dominant:?}");
        let m = e.to_string();
        assert!(!m.contains('\n'), "{m}");
        let who = if named { "`b.stiff` = " } else { "state 1 = " };
        assert!(
            m.contains(&format!("error estimate is dominated by {who}")),
            "{m}"
        );
        assert!(m.contains("× its tolerance"), "{m}");
    }
}
