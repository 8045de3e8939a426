//! The contract between models and solvers. Models implement [`OdeSystem`];
//! callers pick a [`Method`] and [`Options`] and get a [`Solution`].

use thiserror::Error;

/// Direction of a switching function's zero crossing.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Crossing {
    /// g went from negative to positive.
    Rising,
    /// g went from positive to negative.
    Falling,
}

/// What the solver does after a located event.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EventAction {
    /// Restart the integration from the (possibly edited) state at the event time.
    Continue,
    /// End the integration at the event time.
    Stop,
}

/// A system of ordinary differential equations `dx/dt = f(t, x)` with
/// optional analytic Jacobian and switching functions.
pub trait OdeSystem {
    /// Number of states.
    fn dim(&self) -> usize;

    /// The right-hand side `dx = f(t, x)`. Must not allocate in hot loops.
    fn rhs(&self, t: f64, x: &[f64], dx: &mut [f64]);

    /// Analytic Jacobian `∂f/∂x`, written row-major into `jac` (`dim × dim`,
    /// `jac[i * dim + j] = ∂f_i/∂x_j`). Return `false` (the default) when the
    /// model has none; the stiff solver then uses finite differences.
    fn jacobian(&self, _t: f64, _x: &[f64], _jac: &mut [f64]) -> bool {
        false
    }

    /// Whether the right-hand side at `x` stays the same over a short time
    /// after `t` (`∂f/∂t = 0` there: no input that changes with time, or
    /// only piecewise-constant ones, whose jumps are events' business).
    /// The stiff solver then takes `∂f/∂t = 0` instead of differencing `f`
    /// in `t`, one right-hand side a step less. Return `false` (the
    /// default) unless the model knows: it is a promise.
    fn constant_in_time(&self, _t: f64) -> bool {
        false
    }

    /// How many of the **last** states are quadratures: integrals that no
    /// derivative depends on, not even their own (accumulated energies,
    /// pumped volumes). Their Jacobian columns are zero by construction, so
    /// the stiff solver neither differences them nor factorises them: it
    /// solves the other states' block and gets the quadratures by forward
    /// substitution. Default 0. A model that returns `k > 0` promises
    /// `∂f_i/∂x_j = 0` for every `i` and every `j ≥ dim − k`; an analytic
    /// [`jacobian`](OdeSystem::jacobian) may leave those columns unwritten.
    fn n_quadratures(&self) -> usize {
        0
    }

    /// The first time after `t` at which the right-hand side's smoothness
    /// breaks while its value stays continuous (a kink: the corner of a
    /// piecewise-linear input, the ends of a ramp), or `+∞` (the default)
    /// when there is none. The adaptive methods end a step exactly there
    /// instead of stepping across it, so that no step and no dense output
    /// spans the kink (a step across one has a low-order local error and is
    /// rejected or spoils the interpolated output near it). A jump of the
    /// right-hand side itself is an event's job, not a breakpoint's.
    fn next_breakpoint(&self, _t: f64) -> f64 {
        f64::INFINITY
    }

    /// The name of state `i` (`0 ≤ i < dim()`), for error messages: a
    /// failure that concerns a state ([`SolveError::StepTooSmall`]'s
    /// [`StateShare`]s) names it by it. `None` (the default): the state
    /// is known by its index alone.
    fn state_name(&self, _i: usize) -> Option<String> {
        None
    }

    /// Number of switching functions.
    fn n_events(&self) -> usize {
        0
    }

    /// Values of the switching functions `g_i(t, x)`; an event is a sign change
    /// of one of them between two accepted points.
    fn events(&self, _t: f64, _x: &[f64], _g: &mut [f64]) {}

    /// Called at a located event `which`, at time `t` with state `x`. The model
    /// may change its mode and edit `x` (e.g. clamp a velocity at an end stop).
    fn on_event(&mut self, _t: f64, _x: &mut [f64], _which: usize, _dir: Crossing) -> EventAction {
        EventAction::Continue
    }
}

/// The integration method.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Dormand–Prince 5(4), adaptive, with dense output.
    DormandPrince45,
    /// Stiff L-stable Rosenbrock method, adaptive.
    Rosenbrock,
    /// Classical Runge–Kutta 4 with a fixed step (`Options::h0`).
    Rk4,
    /// Exponential Rosenbrock–Euler at the step's mid time,
    /// `x₁ = x₀ + h φ₁(hJ) f(t + h/2, x₀)` (one right-hand side, one
    /// Jacobian, one small matrix function a step): fixed steps, each
    /// interval between two output times split into the fewest equal steps
    /// no longer than `Options::h0`; second order, exact for linear systems
    /// with constant coefficients at any step, no stability limit. For a
    /// stiff mode that is linear over a step (LuGre's bristle at a held
    /// velocity) and a simulated output that must be smooth in the model's
    /// parameters (a fit's finite differences).
    Exponential,
    /// Automatic choice: Dormand–Prince 5(4) while the problem is not stiff,
    /// Rodas4 while it is, switched by the stiffness the run shows (DP45's
    /// step held by its stability region; the Jacobian's spectral radius
    /// against the Rosenbrock step); Bogacki–Shampine 3(2) where the
    /// explicit step is held at `Options::h_max` far inside the tolerance,
    /// for the steps it takes within 5 % of the tolerance (its error
    /// stays of the order of DP45's).
    /// [`Stats::stiff_steps`], [`Stats::switches`],
    /// [`Stats::low_order_steps`] and [`Stats::order_switches`] say what it
    /// chose.
    Auto,
}

/// Solver settings.
#[derive(Clone, Debug)]
pub struct Options {
    /// Relative tolerance (dimensionless).
    pub rtol: f64,
    /// Absolute tolerance in the unit of each state (Pa, m, m/s, ...), one per
    /// state; a single entry applies to all states.
    pub atol: Vec<f64>,
    /// Initial step \[s\] (adaptive methods; `None` = estimated); the fixed step for RK4.
    pub h0: Option<f64>,
    /// Largest step allowed \[s\].
    pub h_max: f64,
    /// Step \[s\] below which the solver gives up with [`SolveError::StepTooSmall`].
    pub h_min: f64,
    /// Most steps (accepted + rejected) before [`SolveError::TooManySteps`].
    pub max_steps: usize,
    /// Time tolerance \[s\] to which event times are located.
    pub event_tol: f64,
    /// Output times \[s\] (sorted, within `[t0, t_end]`); `None` = every accepted step.
    pub t_eval: Option<Vec<f64>>,
}

impl Default for Options {
    fn default() -> Self {
        Self {
            rtol: 1e-6,
            atol: vec![1e-9],
            h0: None,
            h_max: f64::INFINITY,
            h_min: 1e-14,
            max_steps: 10_000_000,
            event_tol: 1e-12,
            t_eval: None,
        }
    }
}

/// Counters of the work a solve did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Accepted steps.
    pub steps: usize,
    /// Rejected steps.
    pub rejected: usize,
    /// Right-hand-side evaluations (including those for finite-difference Jacobians).
    pub rhs_evals: usize,
    /// Jacobian evaluations (analytic or finite-difference).
    pub jac_evals: usize,
    /// LU decompositions.
    pub lu_decomps: usize,
    /// Events located and handled.
    pub events: usize,
    /// Accepted steps taken by the stiff method (all of them for
    /// [`Method::Rosenbrock`], none for the explicit methods, the stiff share
    /// for [`Method::Auto`]).
    pub stiff_steps: usize,
    /// Switches between the explicit and the stiff method ([`Method::Auto`]).
    pub switches: usize,
    /// Accepted steps taken by the low-order explicit pair, Bogacki–Shampine
    /// 3(2) ([`Method::Auto`] where the step is held at `Options::h_max`
    /// far inside the tolerance).
    pub low_order_steps: usize,
    /// Switches between Dormand–Prince 5(4) and Bogacki–Shampine 3(2)
    /// ([`Method::Auto`]).
    pub order_switches: usize,
}

impl Stats {
    /// What the solve used: `explicit`, `stiff`, or `explicit+stiff` with
    /// the number of switches and the stiff share of the steps; the share
    /// of the steps taken by the low-order explicit pair after it, when
    /// there were any.
    pub fn choice(&self) -> String {
        let base = self.stiff_choice();
        if self.low_order_steps == 0 {
            base
        } else {
            format!(
                "{base}; {:.0} % of the steps Bogacki–Shampine 3(2) ({} switches)",
                100.0 * self.low_order_steps as f64 / self.steps.max(1) as f64,
                self.order_switches
            )
        }
    }

    fn stiff_choice(&self) -> String {
        if self.stiff_steps == 0 {
            "explicit".into()
        } else if self.stiff_steps == self.steps && self.switches == 0 {
            "stiff".into()
        } else {
            format!(
                "explicit+stiff ({} switches, {:.0} % of the steps stiff)",
                self.switches,
                100.0 * self.stiff_steps as f64 / self.steps.max(1) as f64
            )
        }
    }
}

/// One located event.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EventRecord {
    /// Time of the event \[s\].
    pub t: f64,
    /// Index of the switching function.
    pub which: usize,
    /// Direction of its crossing.
    pub dir: Crossing,
}

/// The result of a solve.
#[derive(Clone, Debug, Default)]
pub struct Solution {
    /// Output times \[s\].
    pub t: Vec<f64>,
    /// States at the output times, row-major: `x[k * dim + i]` is state `i` at `t[k]`.
    pub x: Vec<f64>,
    /// Number of states.
    pub dim: usize,
    /// Work counters.
    pub stats: Stats,
    /// Located events, in time order.
    pub events: Vec<EventRecord>,
}

impl Solution {
    /// The state at output index `k`.
    pub fn state(&self, k: usize) -> &[f64] {
        &self.x[k * self.dim..(k + 1) * self.dim]
    }
    /// The last state.
    pub fn last(&self) -> Option<&[f64]> {
        if self.t.is_empty() {
            None
        } else {
            Some(self.state(self.t.len() - 1))
        }
    }
}

/// A time in an error message \[s\]: as it is where it reads well
/// (0, or between 1 ms and 10⁷ s), in scientific notation where its
/// decimals would run on (`4.39e-14`, not `0.0000000000000439…`).
pub struct Seconds(pub f64);

impl std::fmt::Display for Seconds {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let t = self.0;
        if t == 0.0 || !t.is_finite() || (1e-3..1e7).contains(&t.abs()) {
            write!(f, "{t}")
        } else {
            write!(f, "{t:e}")
        }
    }
}

/// A state's part in the error estimate of a failing step: where a solve
/// gives up, the states whose error the step could not bring within the
/// tolerance, so that a model of many components says where to look.
#[derive(Clone, Debug, PartialEq)]
pub struct StateShare {
    /// Index of the state.
    pub index: usize,
    /// Its name ([`OdeSystem::state_name`]), when the model gives one.
    pub name: Option<String>,
    /// Its value at the start of the failing step (in its own unit).
    pub value: f64,
    /// Its error estimate over its tolerance,
    /// `|e_i| / (atol_i + rtol · max(|x_i|, |x̂_i|))` (the term of the
    /// error norm; a step is kept when the norm is at most 1).
    pub error: f64,
}

/// `; the error estimate of the last step tried is dominated by `a` = …
/// (… × its tolerance), …`, or nothing for no states.
struct Shares<'a>(&'a [StateShare]);

impl std::fmt::Display for Shares<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (k, s) in self.0.iter().enumerate() {
            if k == 0 {
                write!(f, "; the last step's error estimate is dominated by ")?;
            } else {
                write!(f, ", ")?;
            }
            match &s.name {
                Some(name) => write!(f, "`{name}`")?,
                None => write!(f, "state {}", s.index)?,
            }
            write!(f, " = {:.4e} ({:.1e} × its tolerance)", s.value, s.error)?;
        }
        Ok(())
    }
}

/// Why a solve failed. Each variant says where (time) and, where it can, which state.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum SolveError {
    /// The step size fell below `Options::h_min`.
    #[error("step size {h:e} s fell below the minimum at t = {} s: the solver cannot meet its tolerance{}", Seconds(*t), Shares(dominant))]
    StepTooSmall {
        /// Time reached.
        t: f64,
        /// Step size tried.
        h: f64,
        /// The states that dominate the error estimate of the last step
        /// rejected (largest share first; those within a tenth of the
        /// largest, at most three); empty when no step was rejected for its
        /// error just before (a step that fell to nothing at the start).
        dominant: Vec<StateShare>,
    },
    /// `Options::max_steps` was reached.
    #[error("the step budget ran out: more than {max} steps before t = {} s", Seconds(*t))]
    TooManySteps {
        /// Time reached.
        t: f64,
        /// The limit.
        max: usize,
    },
    /// A state or derivative became NaN or infinite.
    #[error("state {index} is not finite at t = {} s", Seconds(*t))]
    NonFinite {
        /// Time reached.
        t: f64,
        /// Index of the offending state.
        index: usize,
    },
    /// The stiff method's iteration matrix was singular.
    #[error("singular iteration matrix at t = {} s", Seconds(*t))]
    Singular {
        /// Time reached.
        t: f64,
    },
    /// The inputs to the solver were invalid.
    #[error("invalid solver input: {0}")]
    InvalidInput(String),
    /// Event after event without a step free of them
    /// ([`MAX_EVENTS_IN_A_ROW`](crate::MAX_EVENTS_IN_A_ROW)): the
    /// solution chatters, a step too long for a fixed-step method or a model
    /// that switches without end, and time stalls.
    #[error("{count} events in a row up to t = {} s, none with a step free of events between them (event function {which} the last): the solution chatters (a step too long for the rig, or a model that switches without end)", Seconds(*t))]
    EventStorm {
        /// Time reached.
        t: f64,
        /// The last event function that triggered.
        which: usize,
        /// Events in a row.
        count: usize,
    },
    /// Most of the last [`PACE_WINDOW`](crate::PACE_WINDOW) steps ended on
    /// an event, and at the pace they advanced time the run would need more
    /// steps to reach its end than its budget (`Options::max_steps`) has
    /// left: the solution chatters (a model that switches without end, a
    /// valve or stop whose switching is faster than the tolerance resolves).
    #[error("the solution chatters: {events} of the last {steps} steps ended on an event (event function {which} the last) and together advanced time by only {advanced:e} s up to t = {} s; at that pace the run needs ~{needed:.1e} more steps, more than the {left} its step budget has left", Seconds(*t))]
    Chattering {
        /// Time reached.
        t: f64,
        /// The last event function that triggered.
        which: usize,
        /// Steps of the window that ended on an event.
        events: usize,
        /// Steps in the window.
        steps: usize,
        /// Time the window's steps advanced \[s\].
        advanced: f64,
        /// Steps needed to reach the end at the window's pace.
        needed: f64,
        /// Steps left in the budget.
        left: usize,
    },
    /// The caller of a streamed solve ([`crate::solve_streaming`]) stopped
    /// it (its output could not be written, its input could not be read),
    /// or the `stop` of [`crate::solve_stoppable`] said so.
    #[error("stopped at t = {} s: {why}", Seconds(*t))]
    Interrupted {
        /// Time reached.
        t: f64,
        /// The caller's reason.
        why: String,
    },
}

impl SolveError {
    /// The time the solve failed at (the time each variant holds); `None`
    /// for [`SolveError::InvalidInput`], which fails before any step.
    pub fn time(&self) -> Option<f64> {
        match self {
            SolveError::StepTooSmall { t, .. }
            | SolveError::TooManySteps { t, .. }
            | SolveError::NonFinite { t, .. }
            | SolveError::Singular { t }
            | SolveError::EventStorm { t, .. }
            | SolveError::Chattering { t, .. }
            | SolveError::Interrupted { t, .. } => Some(*t),
            SolveError::InvalidInput(_) => None,
        }
    }
}
