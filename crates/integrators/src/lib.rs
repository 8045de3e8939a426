//! # hydrocyl-integrators — ODE solvers for small stiff systems with switching
//!
//! Hydraulic drives are small (n ≤ 16), stiff (bulk modulus over a small
//! chamber volume, bristle stiffness σ0 = 3e7 N/m) and discontinuous (orifice
//! square roots at zero pressure drop, valves and check valves that switch,
//! friction that sticks and slips, end stops). This crate integrates an
//! [`OdeSystem`] `dx/dt = f(t, x)` with:
//!
//! * [`Method::DormandPrince45`] — explicit Dormand–Prince 5(4), adaptive
//!   step, FSAL, order-4 dense output. It is the method of Simulink's `ode45`,
//!   which the thesis uses for its models (Wang 2019, §3.2: "the
//!   Dormand-Prince method is utilised for integration operation in
//!   Simulink");
//! * [`Method::Rosenbrock`] — Rodas4 (Hairer & Wanner), a stiffly accurate,
//!   L-stable, linearly implicit Rosenbrock method of order 4(3) with an
//!   order-3 dense output; the model's analytic Jacobian
//!   ([`OdeSystem::jacobian`]) when it gives one, column-wise finite
//!   differences otherwise;
//! * [`Method::Rk4`] — classical fixed-step Runge–Kutta 4 (`Options::h0` is
//!   the step), with a cubic Hermite interpolant, for cross-checks;
//! * [`Method::Exponential`] — the exponential Rosenbrock–Euler step
//!   `x₁ = x₀ + h φ₁(hJ) f(t + h/2, x₀)`, fixed steps landing on every
//!   output time (at most `Options::h0` long), second order, exact on linear
//!   constant-coefficient systems however stiff: a simulated output smooth
//!   in the model's parameters, at one right-hand side and one Jacobian a
//!   step (the friction bench's LuGre fits; [`expo`]);
//! * [`Method::Auto`] — DP45 while the problem is not stiff, Rodas4 while it
//!   is: DP45's step held on its stability boundary (Hairer's test,
//!   `h ‖f(y₇) − f(y₆)‖ / ‖y₇ − y₆‖ > 3.25` for 15 steps) switches to
//!   Rodas4; a Rosenbrock step at which DP45 would be stable (power-iteration
//!   spectral radius of the Jacobian, `h ρ(J) ≤ 2` for 25 steps) switches
//!   back. Where DP45's step is held at `Options::h_max` with a normed
//!   error ≤ 1e-2 for 3 steps (a drive at rest between command edges), it
//!   takes Bogacki–Shampine 3(2) (`ode23`'s pair: 3 right-hand sides a step
//!   instead of 6) until that pair's controller wants a step below `h_max`
//!   or rejects one, then DP45 again; a BS3 step is kept only with a normed
//!   error ≤ 0.05, one between that and 1 is taken again by DP45 (BS3's
//!   estimate can be 4× below its step's error: auto's error stays of the
//!   order of DP45's, see docs/speed.md). [`Stats::stiff_steps`],
//!   [`Stats::switches`], [`Stats::low_order_steps`] and
//!   [`Stats::order_switches`] report the choice; a run that never switches
//!   is the DP45 run exactly;
//!
//! and **event location**: the model declares switching functions
//! ([`OdeSystem::events`]); the solver finds each sign change to
//! `Options::event_tol`, ends the step there, calls [`OdeSystem::on_event`]
//! so the model can change mode (and edit its state), and restarts. Every
//! [`Solution`] carries [`Stats`] (steps, rejected steps, function and
//! Jacobian evaluations, LU decompositions, events).
//!
//! ```text
//!            x, t                      dx/dt, J = ∂f/∂x (optional)
//!  solver ─────────────▶  OdeSystem  ─────────────────────────────▶ solver
//!    ▲                     │  events(t, x) → g_i   (switching functions)
//!    │  on_event(t, x, i)  │  a sign change of g_i between two accepted
//!    └─────────────────────┘  points is located, the model switches mode
//! ```
//!
//! The crate implements no thesis equation itself; it is the numerical engine
//! under all of them. Units: time in seconds; states in whatever SI unit the
//! model uses (the tolerances are in the same units, per state).
//!
//! ## Error norm
//!
//! A step's local error estimate `e` is measured in Hairer's mixed RMS norm
//!
//! ```text
//! ‖e‖ = sqrt( (1/n) Σ_i ( e_i / (atol_i + rtol · max(|x_i|, |x̂_i|)) )² )
//! ```
//!
//! over the states at both ends of the step; a step is accepted when
//! `‖e‖ ≤ 1`. `atol` is per state (one entry applies to all) — give
//! pressures (1e7 Pa) and positions (1e-3 m) their own.
//!
//! ## Step-size control
//!
//! * DP45 (and Bogacki–Shampine 3(2), with `q = 3`): proportional–integral controller (Hairer, Nørsett & Wanner I,
//!   §II.4; Gustafsson 1991): `h_new = h · 0.9 · ‖e‖^(−α) · ‖e_prev‖^(β)`
//!   with `β = 0.04`, `α = 1/5 − 0.75 β`.
//! * Rodas4: Gustafsson's predictive controller (Hairer & Wanner II, §IV.8),
//!   `h_new = h · 0.9 · min(‖e‖^(−1/4), (h/h_prev)(‖e_prev‖/‖e‖)^(1/4)‖e‖^(−1/4))`.
//!
//! Both limit the change to a factor 0.2…10 per step and do not grow the step
//! right after a rejection. A rejected step is retried with
//! `h · max(0.2, 0.9 ‖e‖^(−1/q))`. A step whose result is not finite is
//! retried with `h/4`. The first step (and the first after every event) comes
//! from Hairer's starting-step heuristic unless `Options::h0` is given. The
//! last step is stretched by up to 1 % to land exactly on `t_end`.
//!
//! ## Event location
//!
//! After each accepted step `[t, t + h]` the switching functions are evaluated
//! at the new point. A function that changed sign is located on the method's
//! dense output by the Illinois variant of regula falsi with a forced
//! bisection whenever two iterations have not halved the bracket
//! ([`events::locate_root`]), to a bracket `[a, b]` of width
//! `≤ Options::event_tol`. The step is cut at the earliest `b` (where `g` has
//! already changed sign); every function that has changed sign by then is
//! reported at that time ([`EventRecord`], in index order) and handed to
//! [`OdeSystem::on_event`]. The integration restarts from the (possibly
//! edited) state with a fresh step-size estimate and no carried-over stage
//! (FSAL and Jacobian are invalidated), so no step straddles a declared
//! discontinuity. A function that sits on its root after the event (|g| no
//! larger than at the ends of its final bracket) is disarmed until it has left
//! zero, so the restart cannot detect the same crossing twice.
//!
//! Contract for models: the right-hand side must be smooth inside a step —
//! keep discontinuous behaviour behind a mode that only
//! [`OdeSystem::on_event`] changes, and declare the switching function that
//! triggers it. Known limits: two sign changes of one function inside one
//! step cancel and are not seen (bound `Options::h_max` if switching
//! functions can oscillate faster than the dynamics); `n_events()` must not
//! change during a solve.
//!
//! ## Output
//!
//! Without `Options::t_eval`, the solution holds `t0` and every accepted step;
//! at an event it holds the state at the event and, if the model edited it,
//! the edited state at the same time (a vertical segment in a plot). With
//! `t_eval`, it holds exactly the requested times, interpolated from the
//! dense output (values at `t0` and at step ends are exact). An event that
//! returns [`EventAction::Stop`] ends the solution at the event time.
//! [`solve_streaming`] is the same solve with the output times given and the
//! outputs taken while it runs (a record of any length in the memory of a
//! block; the same steps and outputs as [`solve`]).
//!
//! ## Example: a ball dropped from 1 m onto a floor
//!
//! ```
//! use hydrocyl_integrators::{solve, Crossing, EventAction, Method, OdeSystem, Options};
//!
//! /// State [height (m), velocity (m/s)]; bounces with restitution 0.5.
//! struct Ball;
//!
//! impl OdeSystem for Ball {
//!     fn dim(&self) -> usize { 2 }
//!     fn rhs(&self, _t: f64, x: &[f64], dx: &mut [f64]) {
//!         dx[0] = x[1];
//!         dx[1] = -9.81;
//!     }
//!     fn n_events(&self) -> usize { 1 }
//!     fn events(&self, _t: f64, x: &[f64], g: &mut [f64]) { g[0] = x[0]; }
//!     fn on_event(&mut self, _t: f64, x: &mut [f64], _i: usize, dir: Crossing) -> EventAction {
//!         assert_eq!(dir, Crossing::Falling);
//!         x[1] *= -0.5;
//!         EventAction::Continue
//!     }
//! }
//!
//! let opts = Options { rtol: 1e-9, atol: vec![1e-12], ..Options::default() };
//! let sol = solve(Method::DormandPrince45, &mut Ball, 0.0, &[1.0, 0.0], 1.0, &opts).unwrap();
//! let t1 = (2.0 * 1.0 / 9.81f64).sqrt(); // first impact, closed form
//! assert!((sol.events[0].t - t1).abs() < 1e-10);
//! assert!((sol.events[1].t - 2.0 * t1).abs() < 1e-9); // up and down at half the speed
//! assert_eq!(*sol.t.last().unwrap(), 1.0);
//! println!("{} steps, {} events", sol.stats.steps, sol.stats.events);
//! ```
#![warn(missing_docs)]

mod api;
mod auto;
mod bs3;
mod checks;

pub use api::*;
mod dopri;
mod driver;
pub mod events;
pub mod expo;
mod fdjac;
mod hermite;
pub mod linalg;
mod pace;
pub mod problems;
mod rk4;
mod rodas;
mod stream;

pub use pace::{CHATTER_SHARE, MAX_EVENTS_IN_A_ROW, PACE_WINDOW};
pub use stream::{solve_streaming, Stream, StreamIo};

/// Integrates `sys` from `(t0, x0)` to `t_end` with `method`.
///
/// Output: every accepted step (and, at an event, the state before and after
/// [`OdeSystem::on_event`] edited it) when `opts.t_eval` is `None`; otherwise
/// exactly the requested times, from the method's dense output. An event
/// whose handler returns [`EventAction::Stop`] ends the solution at the event.
///
/// # Errors
/// [`SolveError::InvalidInput`] for inconsistent inputs (length of `x0`,
/// `t_end < t0`, non-finite values, bad tolerances, unsorted `t_eval`, RK4
/// without `h0`); [`SolveError::NonFinite`] when a state or derivative becomes
/// NaN or infinite; [`SolveError::StepTooSmall`] when the controller needs a
/// step below `h_min`; [`SolveError::TooManySteps`] beyond `max_steps`
/// (accepted + rejected); [`SolveError::Singular`] when the Rosenbrock
/// iteration matrix stays singular after halving the step;
/// [`SolveError::EventStorm`] after [`MAX_EVENTS_IN_A_ROW`] events with no
/// step free of them; [`SolveError::Chattering`] when most of the last
/// [`PACE_WINDOW`] steps ended on events and their pace cannot reach `t_end`
/// within what is left of `max_steps`.
pub fn solve<S: OdeSystem + ?Sized>(
    method: Method,
    sys: &mut S,
    t0: f64,
    x0: &[f64],
    t_end: f64,
    opts: &Options,
) -> Result<Solution, SolveError> {
    stream::dispatch(method, sys, t0, x0, t_end, opts, &mut driver::Nothing)
}

/// [`solve`] that asks `stop` before every step (and before the first
/// output) whether to go on: the same steps and outputs as [`solve`], bit
/// for bit, until `stop` returns `true`, when the solve ends with
/// [`SolveError::Interrupted`] at the time reached. For a caller that must
/// be able to cancel a long solve (an interactive interrupt); `stop` should
/// be cheap (an atomic flag's load), being called once a step.
///
/// # Errors
/// Those of [`solve`], and [`SolveError::Interrupted`] once `stop` says so.
pub fn solve_stoppable<S: OdeSystem + ?Sized>(
    method: Method,
    sys: &mut S,
    t0: f64,
    x0: &[f64],
    t_end: f64,
    opts: &Options,
    stop: &dyn Fn() -> bool,
) -> Result<Solution, SolveError> {
    stream::dispatch(method, sys, t0, x0, t_end, opts, &mut driver::Stop(stop))
}
