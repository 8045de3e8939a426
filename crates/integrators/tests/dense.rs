//! Output at requested times from the dense output.

use hydrocyl_integrators::problems::HarmonicOscillator;
use hydrocyl_integrators::{solve, Method, Options};

fn t_eval_grid(n: usize, t_end: f64) -> Vec<f64> {
    (0..=n).map(|k| t_end * k as f64 / n as f64).collect()
}

#[test]
fn t_eval_is_exact_at_requested_times_including_ends() {
    let osc = HarmonicOscillator { omega: 1.3 };
    let t_end = 7.0;
    let grid = t_eval_grid(333, t_end);
    for method in [Method::DormandPrince45, Method::Rosenbrock, Method::Rk4] {
        let opts = Options {
            rtol: 1e-9,
            atol: vec![1e-12],
            h0: if method == Method::Rk4 {
                Some(1e-3)
            } else {
                None
            },
            t_eval: Some(grid.clone()),
            ..Options::default()
        };
        let mut sys = osc;
        let sol = solve(method, &mut sys, 0.0, &[1.0, 0.0], t_end, &opts).unwrap();
        assert_eq!(sol.t, grid, "{method:?}: output times differ from t_eval");
        assert_eq!(sol.state(0), &[1.0, 0.0]);
        let mut worst = 0.0f64;
        for (k, &t) in sol.t.iter().enumerate() {
            let ex = osc.exact(t, [1.0, 0.0]);
            for (a, b) in sol.state(k).iter().zip(ex) {
                worst = worst.max((a - b).abs());
            }
        }
        // Dense output keeps the accuracy of the steps (order 4 / 3 / 3 interpolants).
        assert!(worst < 1e-6, "{method:?}: dense-output error {worst}");
    }
}

#[test]
fn dense_output_converges_between_steps() {
    // Constant steps h; interpolated values at 37 % of each step converge like
    // h^4 at least for DP45 (order-4 continuous extension) and like h^4 for
    // Rodas4 and RK4 too (order-3 interpolants: local error O(h^4)).
    let osc = HarmonicOscillator { omega: 1.0 };
    for (method, min_order) in [
        (Method::DormandPrince45, 3.7),
        (Method::Rosenbrock, 3.7),
        (Method::Rk4, 3.7),
    ] {
        let mut errs = Vec::new();
        let mut hs = Vec::new();
        for n in [16usize, 32, 64] {
            let h = 4.0 / n as f64;
            let mids: Vec<f64> = (0..n).map(|k| (k as f64 + 0.37) * h).collect();
            let mut opts = crate::common::fixed_step(h);
            opts.t_eval = Some(mids.clone());
            let mut sys = osc;
            let sol = solve(method, &mut sys, 0.0, &[1.0, 0.0], 4.0, &opts).unwrap();
            let e = mids
                .iter()
                .enumerate()
                .map(|(k, &t)| (sol.state(k)[0] - osc.exact(t, [1.0, 0.0])[0]).abs())
                .fold(0.0, f64::max);
            errs.push(e);
            hs.push(h);
        }
        let p = crate::common::loglog_slope(&hs, &errs);
        assert!(
            p > min_order,
            "{method:?}: dense output order {p}, errors {errs:?}"
        );
    }
}

#[test]
fn every_step_output_starts_at_t0_and_ends_at_t_end() {
    let mut sys = HarmonicOscillator { omega: 1.0 };
    let sol = solve(
        Method::DormandPrince45,
        &mut sys,
        0.5,
        &[1.0, 0.0],
        3.25,
        &Options::default(),
    )
    .unwrap();
    assert_eq!(sol.t[0], 0.5);
    assert_eq!(*sol.t.last().unwrap(), 3.25);
    assert_eq!(sol.t.len(), sol.stats.steps + 1);
    assert!(sol.t.windows(2).all(|w| w[1] > w[0]));
}
