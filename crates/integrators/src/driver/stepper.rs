//! The interface one integration method supplies to the driver
//! ([`Stepper`]): step attempts, dense output, and a change of method
//! ([`Switch`]).

use super::step_size::Controller;
use crate::api::{OdeSystem, Stats};

/// One integration method: attempts a step, and after acceptance offers a
/// continuous extension (dense output) over the accepted step.
pub(crate) trait Stepper {
    /// `true` for methods with an error estimate and step-size control.
    fn adaptive(&self) -> bool;

    /// `true` for a fixed-step method whose steps end on every output time
    /// (each interval between two output times split into the fewest equal
    /// steps no longer than `Options::h0`) instead of every `h0`.
    fn lands_on_outputs(&self) -> bool {
        false
    }

    /// Forgets everything carried over from the previous step (FSAL stage,
    /// Jacobian); called at the start and after every event.
    fn restart(&mut self);

    /// Attempts a step of size `h` from `(t, x)`; writes the candidate state
    /// into `x_new` and the local error estimate into `err`.
    #[allow(clippy::too_many_arguments)]
    fn attempt<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        x: &[f64],
        h: f64,
        x_new: &mut [f64],
        err: &mut [f64],
        stats: &mut Stats,
    ) -> Attempt;

    /// The derivative `f(t, x)` at the start of the last attempted step.
    fn f_start(&self) -> &[f64];

    /// Index of a state whose derivative was non-finite in the last attempt,
    /// when the method can tell (an implicit method mixes the states).
    fn nonfinite_hint(&self) -> Option<usize> {
        None
    }

    /// The error scale of the solve (validated absolute tolerances and the
    /// relative tolerance), for methods that need it (finite differences).
    fn set_scale(&mut self, _atol: &[f64], _rtol: f64) {}

    /// The last attempted step was accepted: builds the dense output over it
    /// and prepares the next step.
    fn accept<S: OdeSystem + ?Sized>(
        &mut self,
        sys: &S,
        t: f64,
        x: &[f64],
        h: f64,
        x_new: &[f64],
        stats: &mut Stats,
    );

    /// The dense output at `theta = (τ - t)/h ∈ [0, 1]` of the last accepted step.
    fn dense(&self, theta: f64, out: &mut [f64]);

    /// A stepper that changes its method between steps (the automatic
    /// choice) returns, once, after deciding to: the step-size controller of
    /// the method now in use and the largest step to continue with. Asked
    /// before every attempt.
    fn switch(&mut self) -> Option<Switch> {
        None
    }

    /// Told after each accepted step of an adaptive method, before
    /// [`Stepper::accept`]: its normed error and whether the step the
    /// controller proposes next is held at `Options::h_max`.
    fn observe(&mut self, _err: f64, _held_at_h_max: bool) {}

    /// Told after each step rejected for its error.
    fn rejected(&mut self) {}

    /// Asked of a step within the tolerance (normed error `err ≤ 1`) before
    /// it is accepted: `true` discards it and has the step taken again, at
    /// the same size, by the method the stepper switches to (counted as a
    /// rejected step). The automatic choice's low-order pair keeps only the
    /// steps far inside the tolerance.
    fn retake(&mut self, _err: f64) -> bool {
        false
    }
}

/// A change of method decided by a switching stepper ([`Stepper::switch`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Switch {
    /// The step-size controller of the method now in use.
    pub(crate) controller: Controller,
    /// The largest step to continue with \[s\].
    pub(crate) h_cap: f64,
    /// Between the explicit and the stiff method (counted in
    /// [`Stats::switches`]); otherwise between two explicit pairs (counted
    /// in [`Stats::order_switches`]).
    pub(crate) stiff: bool,
}

/// How a step attempt went.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Attempt {
    /// `x_new` and `err` hold the candidate and its error estimate.
    Done,
    /// The iteration matrix was singular at this step size.
    Singular,
}
