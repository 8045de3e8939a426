//! Watching whether a run gets anywhere: event after event with no step free
//! of them ([`SolveError::EventStorm`]), and events so frequent that, at the
//! pace time advances, the step budget cannot reach the end
//! ([`SolveError::Chattering`]). Both stop a run that would otherwise end
//! only on its step budget, after minutes, with a message that does not say
//! why.

use crate::api::SolveError;

/// Events in a row, each ending its step before the step's end, with no
/// step free of events between them, after which a run stops with
/// [`SolveError::EventStorm`]: time then advances by less and less (a fixed
/// step far too long for the rig puts an event into every step's first few
/// microseconds, for ever). No run that advances does this: between two
/// events of a chattering valve there are steps free of them.
pub const MAX_EVENTS_IN_A_ROW: usize = 10_000;

/// Accepted steps over which the pace of a run is measured
/// ([`SolveError::Chattering`]).
pub const PACE_WINDOW: usize = 10_000;

/// The share of a window's steps that end on an event from which on the
/// window's pace is checked against the budget: a run whose events are rare
/// is slow for other reasons (stiffness, a tight tolerance), which the step
/// budget itself reports.
pub const CHATTER_SHARE: f64 = 0.25;

/// Events in a row and the pace over the current window.
pub(crate) struct Pace {
    in_a_row: usize,
    window_t0: f64,
    window_steps: usize,
    window_events: usize,
    last_which: usize,
}

impl Pace {
    /// A run starting at `t0`.
    pub(crate) fn new(t0: f64) -> Self {
        Self {
            in_a_row: 0,
            window_t0: t0,
            window_steps: 0,
            window_events: 0,
            last_which: 0,
        }
    }

    /// A step that ended at its own end, free of events.
    pub(crate) fn free_step(&mut self) {
        self.in_a_row = 0;
        self.window_steps += 1;
    }

    /// A step that ended on an event of function `which` at `t`.
    pub(crate) fn event_step(&mut self, t: f64, which: usize) -> Result<(), SolveError> {
        self.in_a_row += 1;
        self.window_steps += 1;
        self.window_events += 1;
        self.last_which = which;
        if self.in_a_row >= MAX_EVENTS_IN_A_ROW {
            return Err(SolveError::EventStorm {
                t,
                which,
                count: self.in_a_row,
            });
        }
        Ok(())
    }

    /// After a step that reached `t`: at the end of a window, whether the
    /// window's pace can reach `t_end` within the `left` steps of the budget
    /// (only where at least [`CHATTER_SHARE`] of its steps ended on events).
    pub(crate) fn check(&mut self, t: f64, t_end: f64, left: usize) -> Result<(), SolveError> {
        if self.window_steps < PACE_WINDOW {
            return Ok(());
        }
        let (steps, events) = (self.window_steps, self.window_events);
        let advanced = t - self.window_t0;
        self.window_t0 = t;
        self.window_steps = 0;
        self.window_events = 0;
        if (events as f64) < CHATTER_SHARE * steps as f64 {
            return Ok(());
        }
        let needed = if advanced > 0.0 {
            (t_end - t) / advanced * steps as f64
        } else {
            f64::INFINITY
        };
        if needed > left as f64 {
            return Err(SolveError::Chattering {
                t,
                which: self.last_which,
                events,
                steps,
                advanced,
                needed,
                left,
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn window(p: &mut Pace, t0: f64, dt: f64, every: usize) -> f64 {
        let mut t = t0;
        for k in 0..PACE_WINDOW {
            t += dt;
            if every > 0 && k % every == 0 {
                p.event_step(t, 1).unwrap();
            } else {
                p.free_step();
            }
        }
        t
    }

    #[test]
    fn frequent_events_at_a_pace_the_budget_cannot_cover_stop_the_run() {
        let mut p = Pace::new(0.0);
        // every other step an event, 1 ns a step: 1e-5 s a window
        let t = window(&mut p, 0.0, 1e-9, 2);
        match p.check(t, 10.0, 1_000_000) {
            Err(SolveError::Chattering {
                events,
                steps,
                needed,
                which,
                ..
            }) => {
                assert_eq!((events, steps, which), (PACE_WINDOW / 2, PACE_WINDOW, 1));
                // (10 − 1e-5) / 1e-5 windows of 1e4 steps
                assert!((needed / 1e10 - 1.0).abs() < 1e-5, "{needed:e}");
            }
            other => panic!("expected chattering, got {other:?}"),
        }
    }

    #[test]
    fn the_same_pace_within_the_budget_or_rare_events_go_on() {
        // the budget covers it
        let mut p = Pace::new(0.0);
        let t = window(&mut p, 0.0, 1e-9, 2);
        assert!(p.check(t, 1e-3, 10_000_000).is_ok());
        // events on fewer than a quarter of the steps
        let mut p = Pace::new(0.0);
        let t = window(&mut p, 0.0, 1e-9, 5);
        assert!(p.check(t, 10.0, 1_000).is_ok());
        // before the window is full nothing is checked
        let mut p = Pace::new(0.0);
        p.event_step(1e-9, 0).unwrap();
        assert!(p.check(1e-9, 10.0, 0).is_ok());
    }

    #[test]
    fn events_with_no_free_step_between_them_are_a_storm() {
        let mut p = Pace::new(0.0);
        for k in 1..MAX_EVENTS_IN_A_ROW {
            p.event_step(k as f64 * 1e-12, 0).unwrap();
        }
        assert!(matches!(
            p.event_step(1.0, 3),
            Err(SolveError::EventStorm {
                which: 3,
                count: MAX_EVENTS_IN_A_ROW,
                ..
            })
        ));
        // a free step starts the count again
        let mut p = Pace::new(0.0);
        for _ in 0..MAX_EVENTS_IN_A_ROW - 1 {
            p.event_step(0.0, 0).unwrap();
        }
        p.free_step();
        assert!(p.event_step(0.0, 0).is_ok());
    }
}
