//! Breakpoints ([`OdeSystem::next_breakpoint`]): the adaptive methods end a
//! step exactly at a kink of the right-hand side, which makes the solution
//! across it accurate with fewer rejected steps.

use hydrocyl_integrators::{solve, Method, OdeSystem, Options};

/// `dx/dt = v(t)`, with `v` the piecewise-linear trapezoid through
/// (0, 0), (`a`, 0), (`b`, 1), (1, 1): kinks at `a` and `b`. Exact:
/// `x(t) = 0` before `a`, `(t − a)²/(2(b − a))` on the ramp, then
/// `(b − a)/2 + (t − b)`.
struct Trapezoid {
    a: f64,
    b: f64,
    breakpoints: bool,
}

impl Trapezoid {
    fn v(&self, t: f64) -> f64 {
        ((t - self.a) / (self.b - self.a)).clamp(0.0, 1.0)
    }
    fn exact(&self, t: f64) -> f64 {
        let (a, b) = (self.a, self.b);
        if t <= a {
            0.0
        } else if t <= b {
            (t - a).powi(2) / (2.0 * (b - a))
        } else {
            0.5 * (b - a) + (t - b)
        }
    }
}

impl OdeSystem for Trapezoid {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]) {
        // a second, smooth state keeps the step size from growing unbounded
        dx[0] = self.v(t);
        dx[1] = -x[1];
    }
    fn next_breakpoint(&self, t: f64) -> f64 {
        match self.breakpoints {
            true if t < self.a => self.a,
            true if t < self.b => self.b,
            _ => f64::INFINITY,
        }
    }
}

fn run(method: Method, breakpoints: bool) -> (hydrocyl_integrators::Solution, Trapezoid) {
    let mut sys = Trapezoid {
        a: 0.3,
        b: 0.3 + 1e-3,
        breakpoints,
    };
    let opts = Options {
        rtol: 1e-6,
        atol: vec![1e-9],
        ..Options::default()
    };
    let sol = solve(method, &mut sys, 0.0, &[0.0, 1.0], 1.0, &opts).unwrap();
    (sol, sys)
}

#[test]
fn steps_end_exactly_at_the_breakpoints() {
    for method in [Method::DormandPrince45, Method::Rosenbrock, Method::Auto] {
        let (sol, sys) = run(method, true);
        for bp in [sys.a, sys.b] {
            assert!(sol.t.contains(&bp), "{method:?}: no step ends at {bp}");
        }
    }
}

#[test]
fn landing_on_the_kinks_needs_fewer_rejections_and_is_accurate() {
    for method in [Method::DormandPrince45, Method::Rosenbrock] {
        let (with, sys) = run(method, true);
        let (without, _) = run(method, false);
        assert!(
            with.stats.rejected < without.stats.rejected,
            "{method:?}: {} rejected with breakpoints, {} without",
            with.stats.rejected,
            without.stats.rejected
        );
        // every step is smooth: the solution stays within the tolerance
        for (k, &t) in with.t.iter().enumerate() {
            let e = (with.x[k * 2] - sys.exact(t)).abs();
            assert!(e < 1e-6, "{method:?}: error {e:e} at t = {t}");
        }
    }
}

#[test]
fn rk4_ignores_breakpoints() {
    let mut sys = Trapezoid {
        a: 0.305,
        b: 0.306,
        breakpoints: true,
    };
    let opts = Options {
        h0: Some(0.01),
        ..Options::default()
    };
    let sol = solve(Method::Rk4, &mut sys, 0.0, &[0.0, 1.0], 1.0, &opts).unwrap();
    assert!(!sol.t.contains(&sys.a));
    assert_eq!(sol.stats.steps, 100);
}
