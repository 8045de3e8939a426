//! Observed convergence order of each method on problems with closed-form
//! solutions, with constant steps: global error ∝ h^p.

use crate::common::{fixed_step, loglog_slope};
use hydrocyl_integrators::problems::{HarmonicOscillator, TimeVarying};
use hydrocyl_integrators::{solve, Method, OdeSystem, Options};

/// Global error at `t_end` of `method` with constant steps `t_end / n`.
fn global_error<S: OdeSystem>(
    method: Method,
    sys: &mut S,
    x0: &[f64],
    t_end: f64,
    n: usize,
    exact: &[f64],
) -> f64 {
    let h = t_end / n as f64;
    let opts = match method {
        Method::Rk4 => Options {
            h0: Some(h),
            ..Options::default()
        },
        _ => fixed_step(h),
    };
    let sol = solve(method, sys, 0.0, x0, t_end, &opts).expect("solve");
    assert_eq!(
        sol.stats.steps, n,
        "{method:?} took {} steps, expected {n}",
        sol.stats.steps
    );
    assert_eq!(sol.stats.rejected, 0);
    assert_eq!(*sol.t.last().unwrap(), t_end);
    sol.last()
        .unwrap()
        .iter()
        .zip(exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

fn order_on_oscillator(method: Method, ns: &[usize]) -> f64 {
    let osc = HarmonicOscillator { omega: 2.0 };
    let t_end = 3.0;
    let exact = osc.exact(t_end, [1.0, 0.5]);
    let mut hs = Vec::new();
    let mut errs = Vec::new();
    for &n in ns {
        let mut sys = osc;
        errs.push(global_error(
            method,
            &mut sys,
            &[1.0, 0.5],
            t_end,
            n,
            &exact,
        ));
        hs.push(t_end / n as f64);
    }
    loglog_slope(&hs, &errs)
}

#[test]
fn rk4_is_fourth_order() {
    let p = order_on_oscillator(Method::Rk4, &[20, 40, 80, 160, 320]);
    assert!((p - 4.0).abs() < 0.15, "RK4 observed order {p}");
}

#[test]
fn dormand_prince_is_fifth_order() {
    let p = order_on_oscillator(Method::DormandPrince45, &[20, 40, 80, 160]);
    assert!((p - 5.0).abs() < 0.25, "DP45 observed order {p}");
}

#[test]
fn rodas4_is_fourth_order_with_analytic_jacobian() {
    let p = order_on_oscillator(Method::Rosenbrock, &[20, 40, 80, 160]);
    assert!((p - 4.0).abs() < 0.25, "Rodas4 observed order {p}");
}

#[test]
fn rodas4_is_fourth_order_on_a_non_autonomous_problem_with_fd_jacobian() {
    let t_end = 2.0;
    let exact = [TimeVarying.exact(t_end, 1.0)];
    let mut hs = Vec::new();
    let mut errs = Vec::new();
    // Pre-asymptotic below n = 40 (the error changes sign between n = 10 and 20).
    for n in [40, 80, 160] {
        let mut sys = TimeVarying;
        errs.push(global_error(
            Method::Rosenbrock,
            &mut sys,
            &[1.0],
            t_end,
            n,
            &exact,
        ));
        hs.push(t_end / n as f64);
    }
    let p = loglog_slope(&hs, &errs);
    assert!(
        (p - 4.0).abs() < 0.3,
        "Rodas4 observed order {p} (errors {errs:?})"
    );
}

#[test]
fn adaptive_error_falls_with_tolerance() {
    // Tolerance proportionality: the global error follows the tolerance.
    let osc = HarmonicOscillator { omega: 1.0 };
    let exact = osc.exact(10.0, [1.0, 0.0]);
    for method in [Method::DormandPrince45, Method::Rosenbrock] {
        let mut last = f64::INFINITY;
        for tol in [1e-4, 1e-6, 1e-8] {
            let opts = Options {
                rtol: tol,
                atol: vec![tol],
                ..Options::default()
            };
            let mut sys = osc;
            let sol = solve(method, &mut sys, 0.0, &[1.0, 0.0], 10.0, &opts).unwrap();
            let e = sol
                .last()
                .unwrap()
                .iter()
                .zip(&exact)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            assert!(e < 300.0 * tol, "{method:?} tol {tol}: error {e}");
            assert!(
                e < last,
                "{method:?}: error did not fall with the tolerance"
            );
            last = e;
        }
    }
}

#[test]
fn auto_held_at_h_max_is_third_order_bogacki_shampine() {
    // a constant step with no error to speak of: after LOW_STEPS = 3 DP45
    // steps the automatic choice takes Bogacki–Shampine 3(2)
    let osc = HarmonicOscillator { omega: 2.0 };
    let t_end = 3.0;
    let exact = osc.exact(t_end, [1.0, 0.5]);
    let (mut hs, mut errs) = (Vec::new(), Vec::new());
    for n in [40, 80, 160, 320] {
        let h = t_end / n as f64;
        let mut sys = osc;
        let sol = solve(
            Method::Auto,
            &mut sys,
            0.0,
            &[1.0, 0.5],
            t_end,
            &fixed_step(h),
        )
        .unwrap();
        assert_eq!(sol.stats.steps, n);
        assert_eq!(sol.stats.low_order_steps, n - 3, "{:?}", sol.stats);
        assert_eq!(sol.stats.order_switches, 1);
        let err = sol
            .last()
            .unwrap()
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        hs.push(h);
        errs.push(err);
    }
    let p = loglog_slope(&hs, &errs);
    assert!(
        (p - 3.0).abs() < 0.2,
        "Bogacki–Shampine observed order {p} ({errs:?})"
    );
}
