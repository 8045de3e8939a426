//! Validation section: integrators.
//!
//! Measured in this run, against closed forms and textbook behaviour (no
//! thesis numbers are involved):
//!
//! * observed convergence order with constant steps on the harmonic
//!   oscillator `x'' = −4x`, `x(0) = 1`, `x'(0) = 0.5`, over `[0, 3]` (least-squares
//!   slope of log error against log step); pass when within 0.3 of the
//!   method's order (RK4: 4, Dormand–Prince: 5, Rodas4: 4);
//! * bounce times of a ball dropped from 10 m (g = 9.81 m/s², e = 0.8),
//!   twelve bounces, against the closed form; pass when the worst error is
//!   below 1e-9 s;
//! * Van der Pol μ = 1000 over [0, 3000] s (rtol = atol = 1e-6): Rodas4 must
//!   finish in fewer than 3000 steps; Dormand–Prince must exceed a budget of
//!   50 000 steps (it is stability-limited to h ≈ 1e-3 s on the slow branches);
//! * Robertson over [0, 1e5] s: Rodas4 steps (pass below 500) and the drift
//!   of the conserved sum x1 + x2 + x3 (pass below 1e-12).

use crate::report::Section;
use hydrocyl_integrators::problems::{BouncingBall, HarmonicOscillator, Robertson, VanDerPol};
use hydrocyl_integrators::{solve, Method, Options, SolveError};

/// Least-squares slope of `ln e` against `ln h`.
fn slope(h: &[f64], e: &[f64]) -> f64 {
    let n = h.len() as f64;
    let xs: Vec<f64> = h.iter().map(|v| v.ln()).collect();
    let ys: Vec<f64> = e.iter().map(|v| v.ln()).collect();
    let mx = xs.iter().sum::<f64>() / n;
    let my = ys.iter().sum::<f64>() / n;
    let num: f64 = xs.iter().zip(&ys).map(|(x, y)| (x - mx) * (y - my)).sum();
    let den: f64 = xs.iter().map(|x| (x - mx) * (x - mx)).sum();
    num / den
}

/// Observed order of `method` with constant steps `3/n`, n in `ns`.
fn observed_order(method: Method, ns: &[usize]) -> Result<(f64, f64), SolveError> {
    let osc = HarmonicOscillator { omega: 2.0 };
    let x0 = [1.0, 0.5];
    let t_end = 3.0;
    let exact = osc.exact(t_end, x0);
    let (mut hs, mut errs) = (Vec::new(), Vec::new());
    for &n in ns {
        let h = t_end / n as f64;
        let opts = match method {
            Method::Rk4 => Options {
                h0: Some(h),
                ..Options::default()
            },
            // Constant steps for an adaptive method: h0 = h_max = h and
            // tolerances that never reject.
            _ => Options {
                rtol: 1e12,
                atol: vec![1e12],
                h0: Some(h),
                h_max: h,
                h_min: 0.0,
                ..Options::default()
            },
        };
        let mut sys = osc;
        let sol = solve(method, &mut sys, 0.0, &x0, t_end, &opts)?;
        let last = sol.last().unwrap_or(&x0);
        let e = last
            .iter()
            .zip(&exact)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        hs.push(h);
        errs.push(e);
    }
    Ok((slope(&hs, &errs), *errs.last().unwrap_or(&f64::NAN)))
}

fn worst_bounce_error(method: Method) -> Result<(f64, usize), SolveError> {
    let h0 = 10.0;
    let mut ball = BouncingBall::new(9.81, 0.8, 12);
    let expected = ball.bounce_times(h0, 12);
    let opts = Options {
        rtol: 1e-10,
        atol: vec![1e-12],
        h0: if method == Method::Rk4 {
            Some(0.01)
        } else {
            None
        },
        event_tol: 1e-12,
        ..Options::default()
    };
    let sol = solve(method, &mut ball, 0.0, &[h0, 0.0], 100.0, &opts)?;
    let worst = if sol.events.len() == expected.len() {
        sol.events
            .iter()
            .zip(&expected)
            .map(|(ev, te)| (ev.t - te).abs())
            .fold(0.0, f64::max)
    } else {
        f64::INFINITY
    };
    Ok((worst, sol.events.len()))
}

fn name(method: Method) -> &'static str {
    match method {
        Method::DormandPrince45 => "Dormand-Prince 5(4)",
        Method::Rosenbrock => "Rodas4",
        Method::Rk4 => "RK4",
        Method::Auto => "automatic (DP45/Rodas4)",
        Method::Exponential => "exponential Rosenbrock-Euler",
    }
}

/// Runs this section and returns what it measured.
pub fn section() -> Section {
    let mut s = Section::new("integrators");

    for (method, order, ns) in [
        (Method::Rk4, 4.0, &[20usize, 40, 80, 160, 320][..]),
        (Method::DormandPrince45, 5.0, &[20, 40, 80, 160][..]),
        (Method::Rosenbrock, 4.0, &[20, 40, 80, 160][..]),
    ] {
        let check = format!("{} order, constant steps", name(method));
        match observed_order(method, ns) {
            Ok((p, e_last)) => s.check(
                &check,
                format!(
                    "{p:.2} (error {e_last:.1e} at h = {:.4})",
                    3.0 / ns[ns.len() - 1] as f64
                ),
                format!("{order} (theory), pass within 0.3"),
                (p - order).abs() < 0.3,
            ),
            Err(e) => s.check(&check, format!("failed: {e}"), format!("{order}"), false),
        }
    }

    for method in [Method::DormandPrince45, Method::Rosenbrock, Method::Rk4] {
        let check = format!("bouncing ball, 12 bounce times, {}", name(method));
        match worst_bounce_error(method) {
            Ok((worst, n)) => s.check(
                &check,
                format!("max |Δt| = {worst:.1e} s ({n} events)"),
                "closed form, pass < 1e-9 s".into(),
                worst < 1e-9,
            ),
            Err(e) => s.check(&check, format!("failed: {e}"), "closed form".into(), false),
        }
    }

    let vdp_opts = Options {
        rtol: 1e-6,
        atol: vec![1e-6],
        max_steps: 50_000,
        ..Options::default()
    };
    match solve(
        Method::Rosenbrock,
        &mut VanDerPol { mu: 1000.0 },
        0.0,
        &[2.0, 0.0],
        3000.0,
        &vdp_opts,
    ) {
        Ok(sol) => {
            let st = sol.stats;
            s.check(
                "Van der Pol mu=1000, [0, 3000] s, Rodas4",
                format!(
                    "{} steps, {} rejected, {} f-evals, {} LU",
                    st.steps, st.rejected, st.rhs_evals, st.lu_decomps
                ),
                "few steps: pass < 3000".into(),
                st.steps + st.rejected < 3000,
            );
        }
        Err(e) => s.check(
            "Van der Pol mu=1000, [0, 3000] s, Rodas4",
            format!("failed: {e}"),
            "few steps".into(),
            false,
        ),
    }
    let dp = solve(
        Method::DormandPrince45,
        &mut VanDerPol { mu: 1000.0 },
        0.0,
        &[2.0, 0.0],
        3000.0,
        &vdp_opts,
    );
    let (measured, pass) = match dp {
        Err(SolveError::TooManySteps { t, max }) => {
            (format!("budget of {max} steps spent by t = {t:.1} s"), true)
        }
        Ok(sol) => (format!("finished in {} steps", sol.stats.steps), false),
        Err(e) => (format!("failed otherwise: {e}"), false),
    };
    s.check(
        "Van der Pol mu=1000, [0, 3000] s, Dormand-Prince",
        measured,
        "explicit method cannot: pass = exceeds 50000 steps".into(),
        pass,
    );

    let rob_opts = Options {
        rtol: 1e-6,
        atol: vec![1e-10],
        max_steps: 20_000,
        ..Options::default()
    };
    match solve(
        Method::Rosenbrock,
        &mut Robertson,
        0.0,
        &[1.0, 0.0, 0.0],
        1e5,
        &rob_opts,
    ) {
        Ok(sol) => {
            let drift = (0..sol.t.len())
                .map(|k| (sol.state(k).iter().sum::<f64>() - 1.0).abs())
                .fold(0.0, f64::max);
            s.check(
                "Robertson, [0, 1e5] s, Rodas4 steps",
                format!("{} steps, {} rejected", sol.stats.steps, sol.stats.rejected),
                "pass < 500".into(),
                sol.stats.steps < 500,
            );
            s.check(
                "Robertson, conservation of x1+x2+x3",
                format!("max drift {drift:.1e}"),
                "exact invariant, pass < 1e-12".into(),
                drift < 1e-12,
            );
        }
        Err(e) => s.check(
            "Robertson, [0, 1e5] s, Rodas4",
            format!("failed: {e}"),
            "few steps".into(),
            false,
        ),
    }
    s.note("speed (steps/s) and the LU choice: cargo bench -p hydrocyl-integrators");
    s
}
