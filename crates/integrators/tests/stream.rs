//! A streamed solve is the plain solve: the same outputs, bit for bit, with
//! the output times pushed a little ahead of the integration and the
//! outputs taken in small blocks.

use hydrocyl_integrators::problems::{BouncingBall, VanDerPol};
use hydrocyl_integrators::{
    solve, solve_streaming, Method, OdeSystem, Options, Solution, Stream, StreamIo,
};

/// Pushes `times` as the integration needs them (up to `ahead` past the
/// time reached) and collects the outputs in blocks of at least `block`.
struct Collect {
    times: Vec<f64>,
    pushed: usize,
    ahead: f64,
    block: usize,
    t: Vec<f64>,
    x: Vec<f64>,
    calls: usize,
    takes: usize,
}

impl<S: OdeSystem + ?Sized> Stream<S> for Collect {
    fn between_steps(
        &mut self,
        _: &mut S,
        t: f64,
        io: &mut StreamIo<'_, '_>,
    ) -> Result<(), String> {
        self.calls += 1;
        if io.finished() {
            // a solve a stopping event ended early takes no more times
            self.takes += 1;
            io.take(|t, x| {
                self.t.extend_from_slice(t);
                self.x.extend_from_slice(x);
            });
            return Ok(());
        }
        let mut end = self.pushed;
        while end < self.times.len() && self.times[end] <= t + self.ahead {
            end += 1;
        }
        // one more, so the pushed times reach past t + ahead
        let end = (end + 1).min(self.times.len());
        io.push_times(&self.times[self.pushed..end])?;
        self.pushed = end;
        if io.written() >= self.block {
            self.takes += 1;
            io.take(|t, x| {
                self.t.extend_from_slice(t);
                self.x.extend_from_slice(x);
            });
        }
        Ok(())
    }
}

fn both<S: OdeSystem + Clone>(
    sys: &S,
    method: Method,
    x0: &[f64],
    t_end: f64,
    times: &[f64],
    opts: &Options,
) -> (Solution, Collect, Solution) {
    let opts = Options {
        t_eval: Some(times.to_vec()),
        ..opts.clone()
    };
    let plain = solve(method, &mut sys.clone(), 0.0, x0, t_end, &opts).unwrap();
    let mut c = Collect {
        times: times.to_vec(),
        pushed: 0,
        ahead: opts.h_max.min(t_end),
        block: 37,
        t: Vec::new(),
        x: Vec::new(),
        calls: 0,
        takes: 0,
    };
    let streamed =
        solve_streaming(method, &mut sys.clone(), 0.0, x0, t_end, &opts, &mut c).unwrap();
    (plain, c, streamed)
}

#[test]
fn streamed_equals_plain_for_every_method() {
    let vdp = VanDerPol { mu: 5.0 };
    let t_end = 20.0;
    let times: Vec<f64> = (0..=2000).map(|k| k as f64 * 1e-2).collect();
    for method in [
        Method::DormandPrince45,
        Method::Rosenbrock,
        Method::Auto,
        Method::Rk4,
    ] {
        let opts = Options {
            rtol: 1e-7,
            atol: vec![1e-9],
            h_max: 0.05,
            h0: (method == Method::Rk4).then_some(1e-3),
            ..Options::default()
        };
        let (plain, c, streamed) = both(&vdp, method, &[2.0, 0.0], t_end, &times, &opts);
        assert_eq!(c.t, plain.t, "{method:?}");
        assert_eq!(c.x, plain.x, "{method:?}: streamed states differ");
        assert_eq!(streamed.stats, plain.stats, "{method:?}");
        assert!(streamed.t.is_empty() && streamed.x.is_empty());
        assert!(
            c.takes > 20,
            "{method:?}: outputs taken in blocks ({})",
            c.takes
        );
        assert!(c.calls > plain.stats.steps, "{method:?}: a call per step");
    }
}

#[test]
fn streamed_equals_plain_across_events() {
    let ball = BouncingBall::new(9.81, 0.8, 12);
    let t_end = 6.0;
    let times: Vec<f64> = (0..=600).map(|k| k as f64 * 1e-2).collect();
    let opts = Options {
        rtol: 1e-9,
        atol: vec![1e-12],
        h_max: 0.1,
        ..Options::default()
    };
    let (plain, c, streamed) = both(
        &ball,
        Method::DormandPrince45,
        &[1.0, 0.0],
        t_end,
        &times,
        &opts,
    );
    assert!(plain.stats.events >= 5);
    assert_eq!(c.t, plain.t);
    assert_eq!(c.x, plain.x);
    assert_eq!(streamed.events, plain.events);
}

/// An output time pushed after the integration passed it is refused.
struct Late;

impl<S: OdeSystem + ?Sized> Stream<S> for Late {
    fn between_steps(
        &mut self,
        _: &mut S,
        t: f64,
        io: &mut StreamIo<'_, '_>,
    ) -> Result<(), String> {
        if t > 0.5 {
            io.push_times(&[0.25])?;
        }
        Ok(())
    }
}

#[test]
fn a_late_output_time_stops_the_solve() {
    let e = solve_streaming(
        Method::DormandPrince45,
        &mut VanDerPol { mu: 1.0 },
        0.0,
        &[2.0, 0.0],
        2.0,
        &Options::default(),
        &mut Late,
    )
    .unwrap_err();
    assert!(e.to_string().contains("output time 0.25"), "{e}");
}

#[test]
fn a_stoppable_solve_equals_the_plain_one_until_it_is_stopped() {
    use hydrocyl_integrators::{solve_stoppable, SolveError};
    use std::cell::Cell;
    let vdp = VanDerPol { mu: 5.0 };
    let times: Vec<f64> = (0..=2000).map(|k| k as f64 * 1e-2).collect();
    for method in [Method::DormandPrince45, Method::Rosenbrock, Method::Auto] {
        let opts = Options {
            rtol: 1e-7,
            atol: vec![1e-9],
            h_max: 0.05,
            t_eval: Some(times.clone()),
            ..Options::default()
        };
        let plain = solve(method, &mut vdp.clone(), 0.0, &[2.0, 0.0], 20.0, &opts).unwrap();
        let asked = Cell::new(0usize);
        let never = || {
            asked.set(asked.get() + 1);
            false
        };
        let same = solve_stoppable(
            method,
            &mut vdp.clone(),
            0.0,
            &[2.0, 0.0],
            20.0,
            &opts,
            &never,
        )
        .unwrap();
        assert_eq!(same.t, plain.t, "{method:?}");
        assert_eq!(same.x, plain.x, "{method:?}");
        assert_eq!(same.stats, plain.stats, "{method:?}");
        // asked before the first output, before every step and at the end
        assert!(asked.get() >= plain.stats.steps, "{method:?}");
        let calls = Cell::new(0usize);
        let after_ten = || {
            calls.set(calls.get() + 1);
            calls.get() > 10
        };
        let e = solve_stoppable(
            method,
            &mut vdp.clone(),
            0.0,
            &[2.0, 0.0],
            20.0,
            &opts,
            &after_ten,
        )
        .unwrap_err();
        match e {
            SolveError::Interrupted { t, .. } => assert!(t > 0.0 && t < 20.0, "{method:?}: {t}"),
            other => panic!("{method:?}: {other}"),
        }
    }
}

/// A system without states (resistances between sources, its wires
/// functions of time alone).
#[derive(Clone)]
struct Stateless;

impl OdeSystem for Stateless {
    fn dim(&self) -> usize {
        0
    }
    fn rhs(&self, _t: f64, _x: &[f64], _dx: &mut [f64]) {}
}

#[test]
fn a_system_without_states_gives_its_output_times_streamed_or_not() {
    let t_end = 2.0;
    let times: Vec<f64> = (0..=200).map(|k| k as f64 * 1e-2).collect();
    for method in [
        Method::DormandPrince45,
        Method::Rosenbrock,
        Method::Auto,
        Method::Rk4,
        Method::Exponential,
    ] {
        let opts = Options {
            h_max: 0.05,
            h0: (method == Method::Rk4 || method == Method::Exponential).then_some(1e-3),
            ..Options::default()
        };
        let (plain, c, _) = both(&Stateless, method, &[], t_end, &times, &opts);
        assert_eq!(plain.t, times, "{method:?}");
        assert!(plain.x.is_empty() && plain.dim == 0, "{method:?}");
        assert_eq!(c.t, times, "{method:?}: streamed");
        // steps of at most h_max between the outputs, to t_end
        assert_eq!(plain.stats.steps, 200, "{method:?}");
        // no output times: one per step, the last at t_end
        let free = solve(method, &mut Stateless, 0.0, &[], t_end, &opts).unwrap();
        assert_eq!(free.t.len(), 41, "{method:?}");
        assert_eq!(*free.t.last().unwrap(), t_end, "{method:?}");
        assert!(free.t.windows(2).all(|w| w[1] > w[0]), "{method:?}");
    }
}
