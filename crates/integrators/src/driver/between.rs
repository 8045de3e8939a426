//! What a solve does between its steps ([`Between`]): nothing for the plain
//! solve, a check of the caller's stop for a stoppable one.

use crate::api::{Solution, SolveError};
use std::borrow::Cow;

/// What a solve does between its steps: nothing for [`crate::solve`]; a
/// streamed solve ([`crate::solve_streaming`]) hands the outputs written so
/// far to its caller and takes more output times.
pub(crate) trait Between<S: ?Sized> {
    /// `true` when [`Between::between`] never changes the system, so that
    /// what the system said of the times ahead (its next breakpoint) holds
    /// until an event.
    const LEAVES_SYSTEM: bool = false;

    /// Called before the output at `t0`, before every step from `t`, and
    /// once after the last step. `times[*next..]` are the output times not
    /// yet written; `sol` holds the outputs written since the last call.
    fn between(
        &mut self,
        sys: &mut S,
        t: f64,
        times: &mut Cow<'_, [f64]>,
        next: &mut usize,
        sol: &mut Solution,
    ) -> Result<(), SolveError>;
}

/// The plain solve: every output stays in the [`Solution`].
pub(crate) struct Nothing;

impl<S: ?Sized> Between<S> for Nothing {
    const LEAVES_SYSTEM: bool = true;

    #[inline(always)]
    fn between(
        &mut self,
        _: &mut S,
        _: f64,
        _: &mut Cow<'_, [f64]>,
        _: &mut usize,
        _: &mut Solution,
    ) -> Result<(), SolveError> {
        Ok(())
    }
}

/// The plain solve, stopped when the caller's `stop` says so
/// ([`crate::solve_stoppable`]); it never changes the system.
pub(crate) struct Stop<'a>(pub &'a dyn Fn() -> bool);

impl<S: ?Sized> Between<S> for Stop<'_> {
    const LEAVES_SYSTEM: bool = true;

    #[inline]
    fn between(
        &mut self,
        _: &mut S,
        t: f64,
        _: &mut Cow<'_, [f64]>,
        _: &mut usize,
        _: &mut Solution,
    ) -> Result<(), SolveError> {
        if (self.0)() {
            Err(SolveError::Interrupted {
                t,
                why: "stopped by the caller".into(),
            })
        } else {
            Ok(())
        }
    }
}
