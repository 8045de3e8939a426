//! Event location: known bounce times, the root finder, and proptests on
//! switching functions with known roots.

use hydrocyl_integrators::events::{locate_root, Bracket};
use hydrocyl_integrators::problems::BouncingBall;
use hydrocyl_integrators::{solve, Crossing, EventAction, Method, OdeSystem, Options};
use proptest::prelude::*;

const ALL: [Method; 3] = [Method::DormandPrince45, Method::Rosenbrock, Method::Rk4];

fn opts_for(method: Method) -> Options {
    Options {
        rtol: 1e-10,
        atol: vec![1e-12],
        h0: if method == Method::Rk4 {
            Some(0.01)
        } else {
            None
        },
        event_tol: 1e-12,
        ..Options::default()
    }
}

#[test]
fn bouncing_ball_bounce_times_match_closed_form() {
    let h0 = 10.0;
    for method in ALL {
        let mut ball = BouncingBall::new(9.81, 0.8, 12);
        let expected = ball.bounce_times(h0, 12);
        let sol = solve(method, &mut ball, 0.0, &[h0, 0.0], 100.0, &opts_for(method)).unwrap();
        assert_eq!(sol.events.len(), 12, "{method:?}");
        assert_eq!(sol.stats.events, 12);
        for (ev, te) in sol.events.iter().zip(&expected) {
            assert_eq!(ev.which, 0);
            assert_eq!(ev.dir, Crossing::Falling);
            assert!(
                (ev.t - te).abs() < 1e-9,
                "{method:?}: bounce at {} expected {te}",
                ev.t
            );
        }
        // Stopped at the last bounce, after the velocity was reflected.
        assert_eq!(*sol.t.last().unwrap(), sol.events[11].t);
        let x = sol.last().unwrap();
        assert!(x[0].abs() < 1e-9 && x[1] > 0.0, "{method:?}: {x:?}");
        // Output holds the state before and after each bounce at the same time.
        let n_at_last = sol.t.iter().filter(|&&t| t == sol.events[11].t).count();
        assert_eq!(n_at_last, 2);
        // No step straddles a bounce: every output time sits between bounces or on one.
        assert!(sol.t.windows(2).all(|w| w[1] >= w[0]));
    }
}

#[test]
fn bouncing_ball_energy_after_each_bounce() {
    // Between bounces the mechanical energy is conserved; each bounce scales it by e².
    let mut ball = BouncingBall::new(9.81, 0.7, 6);
    let sol = solve(
        Method::DormandPrince45,
        &mut ball,
        0.0,
        &[5.0, 0.0],
        50.0,
        &opts_for(Method::DormandPrince45),
    )
    .unwrap();
    let energy = |x: &[f64]| 9.81 * x[0] + 0.5 * x[1] * x[1];
    let e0 = energy(sol.state(0));
    let last = sol.last().unwrap();
    let expected = e0 * 0.7f64.powi(12);
    assert!(
        (energy(last) - expected).abs() < 1e-8 * e0,
        "{} vs {expected}",
        energy(last)
    );
}

/// `x' = 1` (so `x = t`) with switching functions that are polynomials of `x`.
struct Clock {
    /// Each switching function is `Π (x − r)` over its roots, times a sign.
    funcs: Vec<(f64, Vec<f64>)>,
    seen: Vec<(f64, usize, Crossing)>,
}

impl OdeSystem for Clock {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, _x: &[f64], dx: &mut [f64]) {
        dx[0] = 1.0;
    }
    fn n_events(&self) -> usize {
        self.funcs.len()
    }
    fn events(&self, _t: f64, x: &[f64], g: &mut [f64]) {
        for (gi, (sign, roots)) in g.iter_mut().zip(&self.funcs) {
            *gi = roots.iter().fold(*sign, |acc, r| acc * (x[0] - r));
        }
    }
    fn on_event(&mut self, t: f64, _x: &mut [f64], which: usize, dir: Crossing) -> EventAction {
        self.seen.push((t, which, dir));
        EventAction::Continue
    }
}

#[test]
fn simultaneous_events_are_all_reported_once() {
    let mut clock = Clock {
        funcs: vec![(1.0, vec![0.5]), (-1.0, vec![0.5]), (1.0, vec![0.25, 0.75])],
        seen: Vec::new(),
    };
    let opts = Options {
        h_max: 0.1,
        ..Options::default()
    };
    let sol = solve(Method::DormandPrince45, &mut clock, 0.0, &[0.0], 1.0, &opts).unwrap();
    let got: Vec<(usize, Crossing)> = sol.events.iter().map(|e| (e.which, e.dir)).collect();
    assert_eq!(
        got,
        vec![
            (2, Crossing::Falling),
            (0, Crossing::Rising),
            (1, Crossing::Falling),
            (2, Crossing::Rising)
        ]
    );
    assert!((sol.events[1].t - 0.5).abs() < 1e-12 && sol.events[1].t == sol.events[2].t);
    assert_eq!(clock.seen.len(), 4);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// The root finder on its own: a cubic with one root in the bracket.
    #[test]
    fn locator_brackets_the_root_to_tolerance(
        r in 0.01f64..0.99, c2 in -3.0f64..3.0, scale in 1e-6f64..1e6, tol_exp in -14i32..-4,
        falling in any::<bool>()
    ) {
        let tol = 10f64.powi(tol_exp);
        let s = if falling { -scale } else { scale };
        // g(t) = s (t − r)(1 + c2 (t − r)² ) has only the root r in [0, 1] when 1 + c2 (t−r)² > 0.
        let g = |t: f64| s * (t - r) * (1.0 + c2.abs() * (t - r) * (t - r));
        let br = locate_root(Bracket { a: 0.0, ga: g(0.0), b: 1.0, gb: g(1.0) }, tol, g);
        prop_assert!(br.b - br.a <= tol);
        prop_assert!(br.a <= r + 1e-15 && br.b >= r - 1e-15, "bracket [{}, {}] root {r}", br.a, br.b);
        prop_assert!(br.gb == 0.0 || (br.gb > 0.0) == (g(1.0) > 0.0));
    }

    /// Through the solver: random linear and quadratic switching functions of
    /// time with known roots (separated by more than a step) are each found
    /// once, to the event tolerance, in time order, with the right direction.
    #[test]
    fn solver_finds_every_root_once(
        lin_roots in proptest::collection::vec(0.02f64..0.98, 1..4),
        quad in (0.05f64..0.45, 0.05f64..0.45),
        sign in prop_oneof![Just(1.0f64), Just(-1.0f64)],
        method_ix in 0usize..3,
    ) {
        let method = ALL[method_ix];
        let (q1, q2) = (quad.0, 0.5 + quad.1);
        let mut funcs: Vec<(f64, Vec<f64>)> = lin_roots.iter().map(|&r| (sign, vec![r])).collect();
        funcs.push((sign, vec![q1, q2]));
        let mut clock = Clock { funcs, seen: Vec::new() };
        let event_tol = 1e-10;
        let opts = Options {
            h0: Some(if method == Method::Rk4 { 0.003 } else { 0.01 }),
            h_max: 0.04,
            event_tol,
            ..Options::default()
        };
        let sol = solve(method, &mut clock, 0.0, &[0.0], 1.0, &opts).unwrap();
        // Expected (time, which, direction).
        let mut expected: Vec<(f64, usize, Crossing)> = Vec::new();
        for (i, &r) in lin_roots.iter().enumerate() {
            let dir = if sign > 0.0 { Crossing::Rising } else { Crossing::Falling };
            expected.push((r, i, dir));
        }
        let iq = lin_roots.len();
        let (d1, d2) = if sign > 0.0 { (Crossing::Falling, Crossing::Rising) } else { (Crossing::Rising, Crossing::Falling) };
        expected.push((q1, iq, d1));
        expected.push((q2, iq, d2));
        prop_assert_eq!(sol.events.len(), expected.len(), "events {:?}", sol.events);
        for (i, (r, which, dir)) in expected.iter().enumerate() {
            let found: Vec<_> = sol.events.iter().filter(|e| e.which == *which && (e.t - r).abs() <= 2.0 * event_tol).collect();
            prop_assert_eq!(found.len(), 1, "root {} of function {} (case {})", r, which, i);
            prop_assert_eq!(found[0].dir, *dir);
        }
        prop_assert!(sol.events.windows(2).all(|w| w[1].t >= w[0].t));
    }
}

/// A mass pushed by a constant acceleration into an end stop at `x = 1`; at
/// the stop the model clamps the state onto the root and switches mode.
struct EndStop {
    accel: f64,
    stopped: bool,
}

impl OdeSystem for EndStop {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, _t: f64, x: &[f64], dx: &mut [f64]) {
        if self.stopped {
            dx[0] = 0.0;
            dx[1] = 0.0;
        } else {
            dx[0] = x[1];
            dx[1] = self.accel;
        }
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&self, _t: f64, x: &[f64], g: &mut [f64]) {
        g[0] = x[0] - 1.0;
    }
    fn on_event(&mut self, _t: f64, x: &mut [f64], _which: usize, dir: Crossing) -> EventAction {
        assert_eq!(dir, Crossing::Rising);
        self.stopped = true;
        x[0] = 1.0;
        x[1] = 0.0;
        EventAction::Continue
    }
}

#[test]
fn clamping_onto_the_root_and_switching_mode_gives_one_event() {
    for method in ALL {
        let mut sys = EndStop {
            accel: 2.0,
            stopped: false,
        };
        let sol = solve(method, &mut sys, 0.0, &[0.0, 0.0], 3.0, &opts_for(method)).unwrap();
        assert_eq!(sol.events.len(), 1, "{method:?}: {:?}", sol.events);
        assert!((sol.events[0].t - 1.0).abs() < 1e-10, "{method:?}");
        assert_eq!(sol.last().unwrap(), &[1.0, 0.0]);
        assert_eq!(*sol.t.last().unwrap(), 3.0);
    }
}

/// `x' = −1` with an event at `x = 0` whose handler puts the state back a
/// nanometre above it: a model that switches without end, one event every
/// nanosecond, so that time all but stalls.
struct Sticky;

impl OdeSystem for Sticky {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, _x: &[f64], dx: &mut [f64]) {
        dx[0] = -1.0;
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&self, _t: f64, x: &[f64], g: &mut [f64]) {
        g[0] = x[0];
    }
    fn on_event(&mut self, _t: f64, x: &mut [f64], _which: usize, _dir: Crossing) -> EventAction {
        x[0] = 1e-9;
        EventAction::Continue
    }
}

/// Events that come without end, with no step free of them between (a
/// fixed step far too long puts one at the start of every step), stop the
/// run with `EventStorm` after `MAX_EVENTS_IN_A_ROW` of them instead of
/// locating them for ever. The adaptive methods take free steps between the
/// events here; the pace of the first window of steps stops them with
/// `Chattering` long before their step budget would.
#[test]
fn events_without_end_stop_the_run() {
    use hydrocyl_integrators::{SolveError, CHATTER_SHARE, MAX_EVENTS_IN_A_ROW, PACE_WINDOW};
    for method in ALL {
        let opts = Options {
            max_steps: 200_000,
            ..opts_for(method)
        };
        match solve(method, &mut Sticky, 0.0, &[0.5], 10.0, &opts) {
            Err(SolveError::EventStorm { t, which, count }) => {
                assert_eq!(method, Method::Rk4);
                assert_eq!(which, 0);
                assert_eq!(count, MAX_EVENTS_IN_A_ROW);
                // the first event at t = 0.5, then one a nanosecond
                assert!((0.5..0.5 + 1e-4).contains(&t), "stopped at {t}");
            }
            Err(SolveError::Chattering {
                t,
                which,
                events,
                steps,
                needed,
                left,
                ..
            }) => {
                assert_ne!(method, Method::Rk4);
                assert_eq!((which, steps), (0, PACE_WINDOW), "{method:?}");
                assert!(events as f64 >= CHATTER_SHARE * steps as f64, "{method:?}");
                assert!(needed > left as f64 && left < 200_000, "{method:?}");
                assert!(t < 0.6, "{method:?}: stopped at {t}");
            }
            other => panic!("{method:?}: expected the run to stop, got {other:?}"),
        }
    }
}

/// A relay: `x' = s` with `s` flipped each time `x` reaches `±a`, beside a
/// state `y' = cos(ω t)` that sets the step size. Events come every 4 ms
/// for 60 s, a good share of the steps end on one, and time advances at a
/// pace the step budget covers: the run ends normally.
struct Relay {
    s: f64,
}

const RELAY_A: f64 = 0.002;

impl OdeSystem for Relay {
    fn dim(&self) -> usize {
        2
    }
    fn rhs(&self, t: f64, _x: &[f64], dx: &mut [f64]) {
        dx[0] = self.s;
        dx[1] = (300.0 * t).cos();
    }
    fn n_events(&self) -> usize {
        1
    }
    fn events(&self, _t: f64, x: &[f64], g: &mut [f64]) {
        g[0] = RELAY_A - self.s * x[0];
    }
    fn on_event(&mut self, _t: f64, _x: &mut [f64], _which: usize, _dir: Crossing) -> EventAction {
        self.s = -self.s;
        EventAction::Continue
    }
}

#[test]
fn frequent_events_at_a_pace_the_budget_covers_do_not_stop_the_run() {
    use hydrocyl_integrators::CHATTER_SHARE;
    for method in [Method::DormandPrince45, Method::Rosenbrock] {
        let opts = Options {
            rtol: 1e-6,
            atol: vec![1e-9, 1e-9],
            ..opts_for(method)
        };
        let mut sys = Relay { s: 1.0 };
        let sol = solve(method, &mut sys, 0.0, &[0.0, 0.0], 60.0, &opts)
            .unwrap_or_else(|e| panic!("{method:?}: {e}"));
        // the first flip at 2 ms, then one every 4 ms
        let flips = sol.events.len() as f64;
        assert!((flips - 15_000.0).abs() <= 2.0, "{method:?}: {flips}");
        // DP45's steps are long enough that a third of them end on a flip:
        // its pace is checked against the budget (Rosenbrock's, ~8 %, is not)
        let share = flips / sol.stats.steps as f64;
        if method == Method::DormandPrince45 {
            assert!(share > CHATTER_SHARE, "events on {share} of the steps");
        }
        assert_eq!(*sol.t.last().unwrap(), 60.0);
    }
}
