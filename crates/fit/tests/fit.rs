//! Integration tests of the bounded Levenberg–Marquardt fit.

use hydrocyl_fit::{FitError, Options, Problem, Termination, WithJacobian};
use proptest::prelude::*;

/// Deterministic zero-mean pseudo-noise in [-1, 1].
fn noise(i: usize) -> f64 {
    ((i as f64 * 12.9898).sin() * 43_758.545_3).fract() * 2.0 - 1.0
}

#[test]
fn straight_line_matches_ordinary_least_squares_closed_form() {
    let n = 25;
    let x: Vec<f64> = (0..n).map(|i| i as f64 * 0.4).collect();
    let y: Vec<f64> = (0..n).map(|i| 1.5 + 0.8 * x[i] + 0.3 * noise(i)).collect();
    let model = |p: &[f64], r: &mut [f64]| {
        for i in 0..n {
            r[i] = y[i] - (p[0] + p[1] * x[i]);
        }
    };
    let fit = Problem::new(model, n, &["a", "b"])
        .solve(&[0.0, 0.0])
        .unwrap();
    // Closed form.
    let nf = n as f64;
    let sx: f64 = x.iter().sum();
    let sy: f64 = y.iter().sum();
    let sxx: f64 = x.iter().map(|v| v * v).sum();
    let sxy: f64 = x.iter().zip(&y).map(|(a, b)| a * b).sum();
    let det = nf * sxx - sx * sx;
    let b = (nf * sxy - sx * sy) / det;
    let a = (sy - b * sx) / nf;
    let ssr: f64 = (0..n).map(|i| (y[i] - a - b * x[i]).powi(2)).sum();
    let s2 = ssr / (nf - 2.0);
    let se_a = (s2 * sxx / det).sqrt();
    let se_b = (s2 * nf / det).sqrt();
    assert!((fit.parameters[0].value - a).abs() < 1e-9);
    assert!((fit.parameters[1].value - b).abs() < 1e-9);
    assert!((fit.parameters[0].std_error.unwrap() / se_a - 1.0).abs() < 1e-6);
    assert!((fit.parameters[1].std_error.unwrap() / se_b - 1.0).abs() < 1e-6);
    assert_eq!(fit.dof, n - 2);
    assert!((fit.rmse - (ssr / nf).sqrt()).abs() < 1e-12);
    // 95 % interval with t(0.975, 23) = 2.0687.
    let (lo, hi) = fit.parameters[1].interval.unwrap();
    assert!(((hi - lo) / (2.0 * se_b) - 2.0687).abs() < 1e-3);
    // Intercept and slope of a line through positive x are negatively correlated.
    let corr = fit.correlation.as_ref().unwrap();
    assert!(corr[(0, 1)] < -0.5 && (corr[(0, 0)] - 1.0).abs() < 1e-12);
    assert!(fit.unidentifiable().is_empty());
}

#[test]
fn rosenbrock_valley_converges_from_the_classical_start() {
    let model = |p: &[f64], r: &mut [f64]| {
        r[0] = 10.0 * (p[1] - p[0] * p[0]);
        r[1] = 1.0 - p[0];
    };
    let fit = Problem::new(model, 2, &["x", "y"])
        .solve(&[-1.2, 1.0])
        .unwrap();
    assert!((fit.parameters[0].value - 1.0).abs() < 1e-8);
    assert!((fit.parameters[1].value - 1.0).abs() < 1e-8);
    // Zero degrees of freedom: no intervals, and both parameters are flagged.
    assert_eq!(fit.dof, 0);
    assert!(fit.parameters.iter().all(|p| p.interval.is_none()));
    assert_eq!(fit.unidentifiable(), vec![0, 1]);
}

#[test]
fn analytic_and_finite_difference_jacobians_agree() {
    let t: Vec<f64> = (0..30).map(|i| i as f64 * 0.1).collect();
    let y: Vec<f64> = t
        .iter()
        .enumerate()
        .map(|(i, t)| 3.0 * (-1.3 * t).exp() + 0.5 + 0.01 * noise(i))
        .collect();
    let n = t.len();
    let res = |p: &[f64], r: &mut [f64]| {
        for i in 0..n {
            r[i] = y[i] - (p[0] * (-p[1] * t[i]).exp() + p[2]);
        }
    };
    let jac = |p: &[f64], j: &mut [f64]| {
        for i in 0..n {
            let e = (-p[1] * t[i]).exp();
            j[i * 3] = -e;
            j[i * 3 + 1] = p[0] * t[i] * e;
            j[i * 3 + 2] = -1.0;
        }
    };
    let names = ["a", "k", "c"];
    let fd = Problem::new(res, n, &names)
        .solve(&[1.0, 1.0, 0.0])
        .unwrap();
    let an = Problem::new(
        WithJacobian {
            residuals: res,
            jacobian: jac,
        },
        n,
        &names,
    )
    .solve(&[1.0, 1.0, 0.0])
    .unwrap();
    for j in 0..3 {
        let (a, b) = (&fd.parameters[j], &an.parameters[j]);
        assert!((a.value - b.value).abs() < 1e-7 * b.value.abs().max(1.0));
        assert!((a.std_error.unwrap() / b.std_error.unwrap() - 1.0).abs() < 1e-4);
    }
    assert!(an.evaluations < fd.evaluations);
}

#[test]
fn an_active_bound_holds_the_parameter_and_drops_its_interval() {
    // Data with slope 2, slope bounded above by 1.
    let x: Vec<f64> = (1..=10).map(f64::from).collect();
    let model = |p: &[f64], r: &mut [f64]| {
        for (i, xi) in x.iter().enumerate() {
            r[i] = 2.0 * xi + 1.0 - (p[0] * xi + p[1]);
        }
    };
    let fit = Problem::new(model, x.len(), &["slope", "offset"])
        .bounds(&[0.0, -100.0], &[1.0, 100.0])
        .solve(&[0.5, 0.0])
        .unwrap();
    let s = &fit.parameters[0];
    assert_eq!(s.value, 1.0);
    assert!(s.at_bound && s.interval.is_none());
    // The free offset takes the best value given the held slope: mean(x) + 1.
    assert!((fit.parameters[1].value - 6.5).abs() < 1e-8);
    assert!(fit.parameters[1].interval.is_some());
    assert_eq!(fit.dof, x.len() - 1);
}

#[test]
fn a_product_of_parameters_is_reported_unidentifiable() {
    // y = a b x: only the product a b is determined.
    let x: Vec<f64> = (1..=8).map(f64::from).collect();
    let model = |p: &[f64], r: &mut [f64]| {
        for (i, xi) in x.iter().enumerate() {
            r[i] = 6.0 * xi + 0.1 * noise(i) - p[0] * p[1] * xi;
        }
    };
    let fit = Problem::new(model, x.len(), &["a", "b"])
        .solve(&[1.0, 2.0])
        .unwrap();
    assert!((fit.parameters[0].value * fit.parameters[1].value - 6.0).abs() < 0.05);
    assert!(fit.condition_number > 1e10);
    assert!(fit.covariance.is_none());
    assert_eq!(fit.unidentifiable(), vec![0, 1]);
}

#[test]
fn bad_inputs_are_clear_errors() {
    let ok = |p: &[f64], r: &mut [f64]| r[0] = p[0];
    let e = Problem::new(ok, 1, &["a"]).solve(&[f64::NAN]).unwrap_err();
    assert!(matches!(e, FitError::InitialOutsideBounds { index: 0, .. }));
    let e = Problem::new(ok, 1, &["a"])
        .bounds(&[1.0], &[0.0])
        .solve(&[0.5])
        .unwrap_err();
    assert!(matches!(e, FitError::InvalidBounds { index: 0, .. }));
    assert!(e.to_string().contains("parameter 0 (a)"));
    let e = Problem::new(ok, 1, &["a"]).solve(&[1.0, 2.0]).unwrap_err();
    assert!(matches!(e, FitError::Dimension { .. }));
    let e = Problem::new(ok, 0, &["a"]).solve(&[1.0]).unwrap_err();
    assert!(matches!(e, FitError::Empty { .. }));
    let nan = |_: &[f64], r: &mut [f64]| {
        r[0] = 1.0;
        r[1] = f64::NAN;
    };
    let e = Problem::new(nan, 2, &["a"]).solve(&[1.0]).unwrap_err();
    assert_eq!(e, FitError::NonFiniteResidual { index: 1 });
}

#[test]
fn an_evaluation_budget_too_small_is_not_converged() {
    let model = |p: &[f64], r: &mut [f64]| {
        r[0] = 10.0 * (p[1] - p[0] * p[0]);
        r[1] = 1.0 - p[0];
    };
    let e = Problem::new(model, 2, &["x", "y"])
        .options(Options {
            max_evaluations: 8,
            ..Options::default()
        })
        .solve(&[-1.2, 1.0])
        .unwrap_err();
    assert!(matches!(e, FitError::NotConverged { .. }), "{e}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]
    /// Noise-free data from any parameters in range are fitted back exactly,
    /// from a start inside the bounds.
    #[test]
    fn noise_free_exponentials_are_recovered(a in 0.5f64..5.0, k in 0.2f64..3.0, c in -1.0f64..1.0) {
        let t: Vec<f64> = (0..40).map(|i| i as f64 * 0.1).collect();
        let y: Vec<f64> = t.iter().map(|t| a * (-k * t).exp() + c).collect();
        let model = |p: &[f64], r: &mut [f64]| {
            for i in 0..t.len() {
                r[i] = y[i] - (p[0] * (-p[1] * t[i]).exp() + p[2]);
            }
        };
        let fit = Problem::new(model, t.len(), &["a", "k", "c"])
            .bounds(&[0.0, 0.01, -10.0], &[10.0, 10.0, 10.0])
            .solve(&[1.0, 1.0, 0.0])
            .unwrap();
        prop_assert!((fit.parameters[0].value - a).abs() < 1e-6);
        prop_assert!((fit.parameters[1].value - k).abs() < 1e-6);
        prop_assert!((fit.parameters[2].value - c).abs() < 1e-6);
    }
}

#[test]
fn determined_parameters_keep_intervals_when_others_are_not() {
    // y = c + d x + a b x²: a and b are not separable, c and d are.
    let x: Vec<f64> = (0..15).map(|i| i as f64 * 0.5).collect();
    let y: Vec<f64> = (0..15)
        .map(|i| 1.0 + 2.0 * x[i] + 0.3 * x[i] * x[i] + 0.05 * noise(i))
        .collect();
    let model = |p: &[f64], r: &mut [f64]| {
        for i in 0..x.len() {
            r[i] = y[i] - (p[0] + p[1] * x[i] + p[2] * p[3] * x[i] * x[i]);
        }
    };
    let fit = Problem::new(model, x.len(), &["c", "d", "a", "b"])
        .solve(&[0.0, 0.0, 1.0, 1.0])
        .unwrap();
    assert!(fit.covariance.is_none());
    assert_eq!(fit.unidentifiable(), vec![2, 3]);
    let (lo, hi) = fit.parameters[1].interval.unwrap();
    assert!(lo < 2.0 && 2.0 < hi && hi - lo < 0.2, "[{lo}, {hi}]");
    assert!(fit.parameters[0].interval.is_some());
}

/// `y = a exp(−b t)` with pseudo-noise: the residual of the tests below.
fn decay(n: usize) -> impl Fn(&[f64], &mut [f64]) {
    move |p: &[f64], r: &mut [f64]| {
        for (i, ri) in r.iter_mut().enumerate().take(n) {
            let t = i as f64 * 0.05;
            let y = 2.0 * (-1.3 * t).exp() + 0.02 * noise(i);
            *ri = y - p[0] * (-p[1] * t).exp();
        }
    }
}

#[test]
fn the_standard_error_stop_ends_near_the_minimum_whatever_the_start() {
    // Stopped when the Gauss–Newton step is below 0.05 standard errors,
    // with the cost test off: from two starts, both ends are within 0.05
    // standard errors of the fully converged fit.
    let n = 120;
    let full = Problem::new(decay(n), n, &["a", "b"])
        .solve(&[1.0, 1.0])
        .unwrap();
    for start in [[1.0, 1.0], [4.0, 0.3]] {
        let fit = Problem::new(decay(n), n, &["a", "b"])
            .options(Options {
                ftol: 0.0,
                xtol: 0.0,
                gtol: 0.0,
                step_se: 0.05,
                ..Options::default()
            })
            .solve(&start)
            .unwrap();
        assert_eq!(fit.termination, Termination::StandardError);
        for (q, f) in fit.parameters.iter().zip(&full.parameters) {
            let se = f.std_error.unwrap();
            assert!((q.value - f.value).abs() < 0.05 * se, "{q:?} vs {f:?}");
        }
    }
}

#[test]
fn forward_differences_take_one_evaluation_per_parameter() {
    // A straight line: one Jacobian is exact either way; forward differences
    // evaluate it at one point per parameter, central ones at two.
    let n = 20;
    let model = |p: &[f64], r: &mut [f64]| {
        for (i, ri) in r.iter_mut().enumerate() {
            *ri = (1.0 + 0.5 * i as f64 + 0.1 * noise(i)) - (p[0] + p[1] * i as f64);
        }
    };
    let solve = |forward_differences| {
        Problem::new(model, n, &["a", "b"])
            .options(Options {
                forward_differences,
                ..Options::default()
            })
            .solve(&[0.0, 0.0])
            .unwrap()
    };
    let (c, f) = (solve(false), solve(true));
    for (a, b) in c.parameters.iter().zip(&f.parameters) {
        assert!((a.value - b.value).abs() < 1e-6, "{a:?} vs {b:?}");
    }
    assert!(
        f.evaluations < c.evaluations,
        "{} vs {}",
        f.evaluations,
        c.evaluations
    );
    assert_eq!(
        c.evaluations - f.evaluations,
        2 * (c.iterations + 1),
        "central {c:?}\nforward {f:?}"
    );
}

#[test]
fn the_difference_step_has_the_floor_it_is_given() {
    // At p = 0 the step is fd_step × fd_floor.
    let seen = std::sync::Mutex::new(Vec::new());
    let model = |p: &[f64], r: &mut [f64]| {
        seen.lock().unwrap().push(p[0]);
        for (i, ri) in r.iter_mut().enumerate() {
            *ri = p[0] - 0.1 * noise(i);
        }
    };
    let _ = Problem::new(model, 5, &["a"])
        .options(Options {
            fd_step: 1e-3,
            fd_floor: Some(10.0),
            forward_differences: true,
            ..Options::default()
        })
        .solve(&[0.0]);
    let points = seen.lock().unwrap().clone();
    assert!((points[1] - 1e-2).abs() < 1e-15, "{points:?}");
}

#[test]
fn a_noisy_residual_stops_after_the_rejections_it_is_allowed() {
    // A residual with a fine staircase (as an adaptive integrator's noise):
    // near the minimum no step lowers the cost; with `max_rejections` 4 the
    // fit ends after four rejected trials in a row, with its interval.
    let n = 60;
    let stair = |p: &[f64], r: &mut [f64]| {
        for (i, ri) in r.iter_mut().enumerate() {
            let q = (p[0] * 1e4).round() / 1e4 + 1e-5 * ((p[0] * 1e7).sin());
            *ri = q - 0.3 - 0.05 * noise(i);
        }
    };
    let solve = |max_rejections| {
        Problem::new(stair, n, &["a"])
            .options(Options {
                fd_step: 1e-2,
                ftol: 0.0,
                xtol: 0.0,
                gtol: 0.0,
                max_rejections,
                ..Options::default()
            })
            .solve(&[1.0])
            .unwrap()
    };
    let (fit, unlimited) = (solve(4), solve(0));
    assert_eq!(fit.termination, Termination::NoReduction);
    assert!(
        fit.evaluations + 10 < unlimited.evaluations,
        "{} vs {}",
        fit.evaluations,
        unlimited.evaluations
    );
    assert!((fit.parameters[0].value - 0.3).abs() < 0.05, "{fit:?}");
    assert!(fit.parameters[0].interval.is_some());
}
