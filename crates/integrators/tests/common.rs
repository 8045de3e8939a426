//! Helpers shared by the test modules.

use hydrocyl_integrators::Options;

/// Least-squares slope of `log(err)` against `log(h)`.
pub fn loglog_slope(h: &[f64], err: &[f64]) -> f64 {
    let n = h.len() as f64;
    let xs: Vec<f64> = h.iter().map(|v| v.ln()).collect();
    let ys: Vec<f64> = err.iter().map(|v| v.ln()).collect();
    let mx = xs.iter().sum::<f64>() / n;
    let my = ys.iter().sum::<f64>() / n;
    let num: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let den: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    num / den
}

/// Options that make an adaptive method take constant steps `h`: the first
/// step and the largest step are `h`, and the tolerances never reject.
pub fn fixed_step(h: f64) -> Options {
    Options {
        rtol: 1e12,
        atol: vec![1e12],
        h0: Some(h),
        h_max: h,
        h_min: 0.0,
        ..Options::default()
    }
}
