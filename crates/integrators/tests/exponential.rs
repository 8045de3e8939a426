//! The exponential Rosenbrock–Euler method ([`Method::Exponential`]):
//! exact on linear constant-coefficient systems, second order on smooth
//! ones (closed forms and a tight reference), LuGre's bristle however stiff,
//! and its steps landing on the output times.

use crate::common::loglog_slope;
use hydrocyl_integrators::problems::{HarmonicOscillator, TimeVarying, VanDerPol};
use hydrocyl_integrators::{solve, Method, OdeSystem, Options};

fn expo(h: f64, t_eval: Option<Vec<f64>>) -> Options {
    Options {
        h0: Some(h),
        t_eval,
        ..Options::default()
    }
}

fn last_error<S: OdeSystem>(sys: &mut S, x0: &[f64], t_end: f64, n: usize, exact: &[f64]) -> f64 {
    let sol = solve(
        Method::Exponential,
        sys,
        0.0,
        x0,
        t_end,
        &expo(t_end / n as f64, None),
    )
    .unwrap();
    assert_eq!(sol.stats.steps, n);
    assert_eq!(*sol.t.last().unwrap(), t_end);
    sol.last()
        .unwrap()
        .iter()
        .zip(exact)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max)
}

/// A linear constant-coefficient system is solved exactly (to rounding) at
/// any step: the harmonic oscillator over 3 s in 3 steps or 300.
#[test]
fn exact_on_a_linear_system() {
    let osc = HarmonicOscillator { omega: 2.0 };
    let exact = osc.exact(3.0, [1.0, 0.5]);
    for n in [3, 30, 300] {
        let e = last_error(&mut { osc }, &[1.0, 0.5], 3.0, n, &exact);
        assert!(e < 1e-13 * n as f64, "{n} steps: error {e}");
    }
}

/// Second order on the non-autonomous `x' = cos(t) x` (closed form
/// `x0 e^{sin t}`), with a finite-difference Jacobian (the problem gives
/// none).
#[test]
fn second_order_on_a_time_varying_problem() {
    let exact = [TimeVarying.exact(2.0, 1.0)];
    let ns = [20, 40, 80, 160, 320];
    let errs: Vec<f64> = ns
        .iter()
        .map(|&n| last_error(&mut TimeVarying, &[1.0], 2.0, n, &exact))
        .collect();
    let hs: Vec<f64> = ns.iter().map(|&n| 2.0 / n as f64).collect();
    let p = loglog_slope(&hs, &errs);
    assert!((p - 2.0).abs() < 0.1, "observed order {p}, errors {errs:?}");
}

/// Second order on the nonlinear Van der Pol oscillator (μ = 2, analytic
/// Jacobian) against DP45 at rtol 1e-13.
#[test]
fn second_order_against_a_tight_reference() {
    let mut vdp = VanDerPol { mu: 2.0 };
    let t_end = 1.5;
    let tight = Options {
        rtol: 1e-13,
        atol: vec![1e-14],
        ..Options::default()
    };
    let reference = solve(
        Method::DormandPrince45,
        &mut vdp,
        0.0,
        &[2.0, 0.0],
        t_end,
        &tight,
    )
    .unwrap();
    let exact = reference.last().unwrap().to_vec();
    let ns = [40, 80, 160, 320, 640];
    let errs: Vec<f64> = ns
        .iter()
        .map(|&n| last_error(&mut vdp, &[2.0, 0.0], t_end, n, &exact))
        .collect();
    let hs: Vec<f64> = ns.iter().map(|&n| t_end / n as f64).collect();
    let p = loglog_slope(&hs, &errs);
    assert!((p - 2.0).abs() < 0.1, "observed order {p}, errors {errs:?}");
}

/// LuGre's bristle under the velocity `v(t) = V sin(ωt) ≥ 0` on a half
/// period: `ż = v − (σ0/Fc) v z`, so `z = (1 − e^{−k x(t)})/k` from rest,
/// `k = σ0/Fc`, `x(t) = V (1 − cos ωt)/ω` (the pre-sliding closed form).
struct Bristle {
    k: f64,
    v: f64,
    w: f64,
}

impl Bristle {
    fn vel(&self, t: f64) -> f64 {
        self.v * (self.w * t).sin()
    }
    fn exact(&self, t: f64) -> f64 {
        let x = self.v * (1.0 - (self.w * t).cos()) / self.w;
        -(-self.k * x).exp_m1() / self.k
    }
}

impl OdeSystem for Bristle {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, t: f64, z: &[f64], dz: &mut [f64]) {
        let v = self.vel(t);
        dz[0] = v - self.k * v.abs() * z[0];
    }
    fn jacobian(&self, t: f64, _z: &[f64], jac: &mut [f64]) -> bool {
        jac[0] = -self.k * self.vel(t).abs();
        true
    }
}

/// On the bristle's closed form the method is second order whether the
/// relaxation is mild or stiff (rate·h from 0.03 to 300 at the coarsest
/// step), and stays within 1e-3 of the steady deflection `1/k` where RK4 at
/// the same step is unstable.
#[test]
fn lugre_bristle_closed_form_mild_and_stiff() {
    let t_end = 0.9 * std::f64::consts::PI; // v ≥ 0 all the way
    for sigma0 in [1e3, 1e5, 1e7] {
        let mut b = Bristle {
            k: sigma0 / 5.0,
            v: 0.05,
            w: 1.0,
        };
        let exact = [b.exact(t_end)];
        let ns = [50, 100, 200, 400];
        let errs: Vec<f64> = ns
            .iter()
            .map(|&n| last_error(&mut b, &[0.0], t_end, n, &exact) * b.k)
            .collect();
        let hs: Vec<f64> = ns.iter().map(|&n| t_end / n as f64).collect();
        let p = loglog_slope(&hs, &errs);
        assert!(errs[0] < 1e-3, "σ0 {sigma0}: relative error {}", errs[0]);
        if errs[0] > 1e-12 {
            assert!((p - 2.0).abs() < 0.2, "σ0 {sigma0}: order {p}, {errs:?}");
        }
        // RK4 at the coarsest step on the stiff case blows up or is far off
        if sigma0 >= 1e5 {
            let h = t_end / ns[0] as f64;
            let rk = solve(
                Method::Rk4,
                &mut b,
                0.0,
                &[0.0],
                t_end,
                &Options {
                    h0: Some(h),
                    ..Options::default()
                },
            );
            let bad = rk.map_or(true, |s| {
                (s.last().unwrap()[0] - exact[0]).abs() * b.k > 1.0
            });
            assert!(
                bad,
                "RK4 was expected to fail at rate·h = {}",
                b.k * 0.05 * h
            );
        }
    }
}

/// The steps land on every output time: unevenly spaced outputs, each
/// interval split into the fewest equal steps of at most `h0`; the outputs
/// are the step ends (no interpolation), equal to a solve to that time.
#[test]
fn steps_land_on_the_output_times() {
    let t_eval = vec![0.0, 0.1, 0.25, 0.26, 0.7, 1.0];
    let h0 = 0.1;
    let osc = HarmonicOscillator { omega: 2.0 };
    let sol = solve(
        Method::Exponential,
        &mut { osc },
        0.0,
        &[1.0, 0.5],
        1.0,
        &expo(h0, Some(t_eval.clone())),
    )
    .unwrap();
    assert_eq!(sol.t, t_eval);
    // 1 + 2 + 1 + 5 + 3 steps
    assert_eq!(sol.stats.steps, 12);
    for (k, &t) in t_eval.iter().enumerate() {
        let e = osc.exact(t, [1.0, 0.5]);
        for (got, want) in sol.state(k).iter().zip(e) {
            assert!((got - want).abs() < 1e-14, "t {t}");
        }
    }
    // one rhs and one Jacobian a step
    assert_eq!(sol.stats.rhs_evals, 12);
    assert_eq!(sol.stats.jac_evals, 12);
}
