//! A streamed solve: the same integration as [`crate::solve`] — the same
//! steps, the same outputs, bit for bit — with the output times supplied and
//! the outputs taken while it runs, so that a record of any length needs
//! memory for a block of it only, and the integrator's step size, controller
//! and stage carry over from one block to the next (nothing restarts).
//!
//! The caller's [`Stream`] is called before the first output, before every
//! step and once at the end. It appends output times ahead of the
//! integration ([`StreamIo::push_times`]) and takes the outputs written so
//! far ([`StreamIo::take`]). Between the calls it may also change what the
//! system reads ahead of the time reached (the next samples of a command
//! table): the system is handed to it mutably, and the solve evaluates it
//! only at or after the time of the call until the next call.

use crate::api::{Method, OdeSystem, Options, Solution, SolveError};
use crate::driver::{self, Between, Controller};
use crate::{auto, dopri, expo, rk4, rodas};
use std::borrow::Cow;

/// What a streamed solve's caller does between the steps.
pub trait Stream<S: ?Sized> {
    /// Called before the output at `t0`, before every step from time `t`
    /// (`t` does not decrease), and once after the last step
    /// ([`StreamIo::finished`]). Output times the solve reaches must have
    /// been pushed before: the step from `t` may reach `t + h_max` (the
    /// fixed step for RK4), and an output time pushed later than the
    /// integration has passed is an error. An `Err` stops the solve with
    /// [`SolveError::Interrupted`].
    fn between_steps(
        &mut self,
        sys: &mut S,
        t: f64,
        io: &mut StreamIo<'_, '_>,
    ) -> Result<(), String>;
}

/// The output side of a streamed solve, as one [`Stream::between_steps`]
/// call sees it.
pub struct StreamIo<'a, 'b> {
    times: &'a mut Cow<'b, [f64]>,
    next: &'a mut usize,
    sol: &'a mut Solution,
    t: f64,
    t_end: f64,
    finished: bool,
}

impl StreamIo<'_, '_> {
    /// Output times pushed and not yet reached.
    pub fn pending(&self) -> &[f64] {
        &self.times[*self.next..]
    }

    /// The last output time pushed (written or not), if any.
    pub fn last_time(&self) -> Option<f64> {
        self.times.last().copied()
    }

    /// Appends output times: finite, strictly increasing, after every time
    /// pushed before, not before the time reached and not after `t_end`.
    pub fn push_times(&mut self, t: &[f64]) -> Result<(), String> {
        if self.finished && !t.is_empty() {
            return Err("output times pushed after the end of the solve".into());
        }
        let mut prev = self.last_time().unwrap_or(f64::NEG_INFINITY);
        for &tk in t {
            if !(tk.is_finite() && tk > prev && tk >= self.t && tk <= self.t_end) {
                return Err(format!(
                    "output time {tk} s: not after {prev} s, or outside [{}, {}] s (the time reached, t_end)",
                    self.t, self.t_end
                ));
            }
            prev = tk;
        }
        let v = self.times.to_mut();
        // forget the times already written
        v.drain(..*self.next);
        *self.next = 0;
        v.extend_from_slice(t);
        Ok(())
    }

    /// Number of outputs written and not yet taken.
    pub fn written(&self) -> usize {
        self.sol.t.len()
    }

    /// Hands the outputs written since the last `take` to `f` as their
    /// times and their states (row-major, [`Solution::dim`] each), then
    /// forgets them.
    pub fn take<R>(&mut self, f: impl FnOnce(&[f64], &[f64]) -> R) -> R {
        let r = f(&self.sol.t, &self.sol.x);
        self.sol.t.clear();
        self.sol.x.clear();
        r
    }

    /// Whether this is the call after the last step (the solve is done; the
    /// outputs not yet taken are the last).
    pub fn finished(&self) -> bool {
        self.finished
    }
}

struct Adapter<'s, T: ?Sized> {
    stream: &'s mut T,
    t_end: f64,
}

impl<S: ?Sized, T: Stream<S> + ?Sized> Between<S> for Adapter<'_, T> {
    fn between(
        &mut self,
        sys: &mut S,
        t: f64,
        times: &mut Cow<'_, [f64]>,
        next: &mut usize,
        sol: &mut Solution,
    ) -> Result<(), SolveError> {
        let mut io = StreamIo {
            times,
            next,
            sol,
            t,
            t_end: self.t_end,
            finished: false,
        };
        self.stream
            .between_steps(sys, t, &mut io)
            .map_err(|why| SolveError::Interrupted { t, why })
    }
}

/// [`crate::solve`] with the output times given and the outputs taken by
/// `stream` while the solve runs (see the module doc). `opts.t_eval` is
/// ignored: the output times are the ones `stream` pushes. Returns the work
/// counters and the events; its `t` and `x` are empty (every output went to
/// `stream`).
///
/// # Errors
/// Those of [`crate::solve`], and [`SolveError::Interrupted`] when
/// `stream` returns an error.
pub fn solve_streaming<S: OdeSystem + ?Sized>(
    method: Method,
    sys: &mut S,
    t0: f64,
    x0: &[f64],
    t_end: f64,
    opts: &Options,
    stream: &mut dyn Stream<S>,
) -> Result<Solution, SolveError> {
    let opts = Options {
        t_eval: Some(Vec::new()),
        ..opts.clone()
    };
    let mut between = Adapter { stream, t_end };
    let mut sol = dispatch(method, sys, t0, x0, t_end, &opts, &mut between)?;
    let mut times = Cow::Owned(Vec::new());
    let mut next = 0;
    let mut io = StreamIo {
        times: &mut times,
        next: &mut next,
        sol: &mut sol,
        t: t_end,
        t_end,
        finished: true,
    };
    between
        .stream
        .between_steps(sys, t_end, &mut io)
        .map_err(|why| SolveError::Interrupted { t: t_end, why })?;
    sol.t.clear();
    sol.x.clear();
    Ok(sol)
}

/// The solve of `method` with `between` called between the steps (the one
/// place a method meets its stepper, controller and starting order).
pub(crate) fn dispatch<S: OdeSystem + ?Sized, B: Between<S>>(
    method: Method,
    sys: &mut S,
    t0: f64,
    x0: &[f64],
    t_end: f64,
    opts: &Options,
    between: &mut B,
) -> Result<Solution, SolveError> {
    let n = sys.dim();
    // the arms differ in the stepper (a type each), its controller and the
    // order of the starting-step estimate only
    macro_rules! run {
        ($stepper:expr, $controller:expr, $order:expr) => {
            driver::run_with(
                $stepper,
                $controller,
                $order,
                sys,
                t0,
                x0,
                t_end,
                opts,
                between,
            )
        };
    }
    let quadratures = sys.n_quadratures().min(n);
    match method {
        Method::DormandPrince45 => run!(dopri::DormandPrince::new(n), auto::DP_CONTROLLER, 5.0),
        Method::Rosenbrock => run!(
            rodas::Rodas4::new(n, quadratures),
            auto::RODAS_CONTROLLER,
            4.0
        ),
        Method::Auto => run!(auto::Auto::new(n, quadratures), auto::DP_CONTROLLER, 5.0),
        Method::Rk4 => run!(rk4::Rk4::new(n), Controller::Pi { q: 5.0, beta: 0.0 }, 4.0),
        Method::Exponential => run!(
            expo::Exponential::new(n, quadratures),
            Controller::Pi { q: 2.0, beta: 0.0 },
            2.0
        ),
    }
}
