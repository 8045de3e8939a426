//! The method-independent part of a solve: input checks, the error norm, the
//! step-size controller, event location, output at `t_eval`, and the
//! accept/reject loop. Each method only supplies a [`Stepper`].

mod between;
mod step_size;
mod stepper;

pub(crate) use between::{Between, Nothing, Stop};
pub(crate) use step_size::Controller;
pub(crate) use stepper::{Attempt, Stepper, Switch};

use crate::api::{
    Crossing, EventAction, EventRecord, OdeSystem, Options, Solution, SolveError, StateShare, Stats,
};
use crate::checks::check_inputs;
use crate::events::{locate_root, Bracket};
use crate::pace::Pace;
use std::borrow::Cow;
use step_size::{dominant_states, initial_step, split_error_norm, ControlState};

/// Largest number of consecutive singular-matrix retries before giving up.
const MAX_SINGULAR_RETRIES: usize = 8;

/// Sign of a switching-function value: -1, 0 or +1.
#[inline]
fn sgn(v: f64) -> i8 {
    if v > 0.0 {
        1
    } else if v < 0.0 {
        -1
    } else {
        0
    }
}

/// Event bookkeeping: values at the start of the current step and whether
/// each function is armed (its last value was a trustworthy non-zero sign).
///
/// A function that sits exactly on zero is not armed, so that the restart
/// after its event cannot find the same crossing again. The one exception is
/// a function that triggered an event whose handler *edited the state* and
/// sits exactly on zero after the edit (a mass clamped onto its stop): its
/// zero is the handler's, not the crossing's, and it is armed to *leave*
/// zero (`from_zero`): the first time it takes a sign, that is a crossing in
/// that direction, located where it leaves zero (or where it crosses back
/// after a detour to the other side). Without it, a mass released from its
/// stop at a tie of forces that drifts back through the stop within the
/// restart's first step would pass the stop unseen.
struct EventState {
    g_prev: Vec<f64>,
    g_new: Vec<f64>,
    g_tmp: Vec<f64>,
    armed: Vec<bool>,
    from_zero: Vec<bool>,
    /// Whether the handler of this function's event (at the last event
    /// time) edited the state.
    edited_by: Vec<bool>,
    /// `|g|` at the ends of the final bracket of each triggered function.
    bracket_mag: Vec<f64>,
    triggered: Vec<bool>,
    x_tmp: Vec<f64>,
}

/// Why the last step attempt was rejected.
#[derive(Clone, Copy)]
enum Rejection {
    /// It was not (or it was for another reason: a singular matrix).
    None,
    /// For its error.
    Error,
    /// For a non-finite state, this one.
    NonFinite(usize),
}

/// Writes the states at the output times in `(t_from, t_to]` (all of them
/// when `include_start`) from the stepper's dense output.
#[allow(clippy::too_many_arguments)]
fn emit_t_eval<St: Stepper>(
    stepper: &St,
    t_eval: &[f64],
    next_out: &mut usize,
    t_step: f64,
    h: f64,
    t_to: f64,
    x_to: &[f64],
    sol: &mut Solution,
) {
    let n = x_to.len();
    while *next_out < t_eval.len() && t_eval[*next_out] <= t_to {
        let tk = t_eval[*next_out];
        if tk == t_to {
            sol.x.extend_from_slice(x_to);
        } else {
            // interpolated straight into the output (no copy through a buffer)
            let theta = ((tk - t_step) / h).clamp(0.0, 1.0);
            let at = sol.x.len();
            sol.x.resize(at + n, 0.0);
            stepper.dense(theta, &mut sol.x[at..]);
        }
        sol.t.push(tk);
        *next_out += 1;
    }
}

/// The solve of a system without states (`dim() = 0`: resistances between
/// sources, its wires functions of time alone): nothing to integrate, so
/// each step goes to the next output time, at most `h_max` ahead (as far
/// as an adaptive step may, so that a streamed caller sees the time advance
/// as in any solve), calling `between` before each step and once after the
/// last, as [`run_with`] does.
#[cold]
#[inline(never)]
#[allow(clippy::too_many_arguments)]
fn stateless<S: OdeSystem + ?Sized, B: Between<S>>(
    sys: &mut S,
    t0: f64,
    t_end: f64,
    opts: &Options,
    t_eval: &mut Cow<'_, [f64]>,
    next_out: &mut usize,
    between: &mut B,
    mut sol: Solution,
) -> Result<Solution, SolveError> {
    let mut stats = Stats::default();
    let mut t = t0;
    loop {
        between.between(sys, t, t_eval, next_out, &mut sol)?;
        // times a streamed caller added at or before t
        while *next_out < t_eval.len() && t_eval[*next_out] <= t {
            sol.t.push(t_eval[*next_out]);
            *next_out += 1;
        }
        if t >= t_end {
            break;
        }
        // no sliver of a last step (as `run_with`)
        let ahead = if t + 1.01 * opts.h_max >= t_end {
            t_end
        } else {
            t + opts.h_max
        };
        let t_new = match t_eval.get(*next_out) {
            Some(&tk) if opts.t_eval.is_some() => tk.min(ahead),
            _ => ahead,
        };
        if opts.t_eval.is_some() {
            while *next_out < t_eval.len() && t_eval[*next_out] <= t_new {
                sol.t.push(t_eval[*next_out]);
                *next_out += 1;
            }
        } else {
            sol.t.push(t_new);
        }
        stats.steps += 1;
        t = t_new;
    }
    sol.stats = stats;
    Ok(sol)
}

/// Runs one solve with the given stepper, calling `between` between the
/// steps (see [`Between`]).
#[allow(clippy::too_many_arguments)]
pub(crate) fn run_with<S: OdeSystem + ?Sized, St: Stepper, B: Between<S>>(
    mut stepper: St,
    controller: Controller,
    start_order: f64,
    sys: &mut S,
    t0: f64,
    x0: &[f64],
    t_end: f64,
    opts: &Options,
    between: &mut B,
) -> Result<Solution, SolveError> {
    let n = sys.dim();
    let adaptive = stepper.adaptive();
    let atol = check_inputs(n, t0, x0, t_end, opts, !adaptive)?;
    let rtol = opts.rtol;
    stepper.set_scale(&atol, rtol);
    let n_ev = sys.n_events();
    // the states a step's error is normed over apart from the quadratures
    let n_active = n - sys.n_quadratures().min(n);

    let mut sol = Solution {
        dim: n,
        ..Solution::default()
    };
    let mut stats = Stats::default();
    if let Some(te) = &opts.t_eval {
        sol.t.reserve(te.len());
        sol.x.reserve(te.len() * n);
    }

    let mut t = t0;
    let mut x = x0.to_vec();
    let mut x_new = vec![0.0; n];
    let mut err = vec![0.0; n];
    let mut buf = vec![0.0; n];
    let mut work_f = vec![0.0; n];
    let mut work_f0 = vec![0.0; n];
    let mut x_ev = vec![0.0; n];
    let mut ev = EventState {
        g_prev: vec![0.0; n_ev],
        g_new: vec![0.0; n_ev],
        g_tmp: vec![0.0; n_ev],
        armed: vec![false; n_ev],
        from_zero: vec![false; n_ev],
        edited_by: vec![false; n_ev],
        bracket_mag: vec![0.0; n_ev],
        triggered: vec![false; n_ev],
        x_tmp: vec![0.0; n],
    };
    if n_ev > 0 {
        sys.events(t, &x, &mut ev.g_prev);
        for i in 0..n_ev {
            ev.armed[i] = ev.g_prev[i] != 0.0 && ev.g_prev[i].is_finite();
        }
    }

    // Output at t0.
    let mut t_eval: Cow<'_, [f64]> = Cow::Borrowed(opts.t_eval.as_deref().unwrap_or(&[]));
    let mut next_out = 0usize;
    between.between(sys, t, &mut t_eval, &mut next_out, &mut sol)?;
    if opts.t_eval.is_some() {
        while next_out < t_eval.len() && t_eval[next_out] <= t0 {
            sol.t.push(t_eval[next_out]);
            sol.x.extend_from_slice(&x);
            next_out += 1;
        }
    } else {
        sol.t.push(t0);
        sol.x.extend_from_slice(&x);
    }

    if n == 0 {
        return stateless(
            sys,
            t,
            t_end,
            opts,
            &mut t_eval,
            &mut next_out,
            between,
            sol,
        );
    }

    let mut ctrl = ControlState::new(controller);
    let mut fresh = true; // a fresh step-size estimate is needed
    let mut h = opts.h0.unwrap_or(0.0);
    let mut singular_retries = 0usize;
    // What the last attempt was rejected for: its error (`err`, `x_new`
    // hold its estimate) or a non-finite state; what a step that falls
    // below `h_min` reports.
    let mut last_rejection = Rejection::None;
    let mut pace = Pace::new(t0);
    // The system's next breakpoint after `bp_from`: while nothing changes
    // the system (no event, no streamed input) it is still the next one
    // after any time before it, and is asked again only once passed.
    let (mut bp_from, mut bp_next) = (f64::INFINITY, f64::INFINITY);

    // Times closer than this to t_end count as t_end.
    let t_close = |t: f64| 4.0 * f64::EPSILON * t.abs().max(t_end.abs()).max(1e-300);

    while t_end - t > t_close(t) {
        between.between(sys, t, &mut t_eval, &mut next_out, &mut sol)?;
        if stats.steps + stats.rejected >= opts.max_steps {
            sol.stats = stats;
            return Err(SolveError::TooManySteps {
                t,
                max: opts.max_steps,
            });
        }
        if let Err(e) = pace.check(t, t_end, opts.max_steps - (stats.steps + stats.rejected)) {
            sol.stats = stats;
            return Err(e);
        }
        if let Some(sw) = stepper.switch() {
            ctrl = ControlState::new(sw.controller);
            if sw.stiff {
                stats.switches += 1;
            } else {
                stats.order_switches += 1;
            }
            h = h.min(sw.h_cap);
        }
        if fresh {
            stepper.restart();
            ctrl.reset();
            if adaptive && (opts.h0.is_none() || stats.steps + stats.rejected > 0) {
                // f(t, x) for the estimate; the stepper recomputes its own.
                sys.rhs(t, &x, &mut work_f);
                stats.rhs_evals += 1;
                if let Some(i) = work_f.iter().position(|v| !v.is_finite()) {
                    return Err(SolveError::NonFinite { t, index: i });
                }
                work_f0.copy_from_slice(&work_f);
                h = initial_step(
                    sys,
                    t,
                    &x,
                    &work_f0,
                    start_order,
                    &atol,
                    rtol,
                    opts.h_max,
                    &mut buf,
                    &mut work_f,
                    &mut stats,
                );
            } else if let Some(h0) = opts.h0 {
                h = if adaptive { h0.min(opts.h_max) } else { h0 };
            }
            fresh = false;
        }
        if adaptive {
            h = h.min(opts.h_max);
            // A step that does not move t in floating point is as bad as h < h_min.
            if h < opts.h_min || t + h <= t {
                sol.stats = stats;
                let dominant = match last_rejection {
                    Rejection::Error => dominant_states(&*sys, &err, &x, &x_new, &atol, rtol),
                    Rejection::NonFinite(i) => vec![StateShare {
                        index: i,
                        name: sys.state_name(i),
                        value: x[i],
                        error: f64::INFINITY,
                    }],
                    Rejection::None => Vec::new(),
                };
                return Err(SolveError::StepTooSmall { t, h, dominant });
            }
        }
        // Land exactly on t_end; avoid a sliver of a last step.
        let mut last = false;
        let remaining = t_end - t;
        let stretch = if adaptive { 1.01 } else { 1.0 + 1e-9 };
        // Land exactly on the next breakpoint (adaptive methods); the step the
        // controller wanted is kept for after it.
        let mut breakpoint = None;
        // A method that lands on the output times: the next one (or t_end)
        // in the fewest equal steps of at most h0.
        let mut land = None;
        if !adaptive && stepper.lands_on_outputs() {
            let h0 = opts.h0.unwrap_or(remaining);
            let target = t_eval
                .get(next_out)
                .copied()
                .filter(|&tk| tk - t > t_close(t) && tk < t_end)
                .unwrap_or(t_end);
            let gap = target - t;
            let k = (gap / h0 * (1.0 - 1e-9)).ceil().max(1.0);
            h = gap / k;
            if k == 1.0 && target < t_end {
                land = Some(target);
            }
        }
        if h * stretch >= remaining {
            h = remaining;
            last = true;
        } else if adaptive {
            if !(B::LEAVES_SYSTEM && bp_from <= t && t < bp_next) {
                (bp_from, bp_next) = (t, sys.next_breakpoint(t));
            }
            let bp = bp_next;
            if bp - t <= h * stretch && t_end - bp > t_close(bp) && bp - t > t_close(t) {
                breakpoint = Some((bp, h));
                h = bp - t;
            }
        }

        if stepper.attempt(&*sys, t, &x, h, &mut x_new, &mut err, &mut stats) == Attempt::Singular {
            singular_retries += 1;
            stats.rejected += 1;
            if singular_retries > MAX_SINGULAR_RETRIES || h * 0.5 < opts.h_min {
                sol.stats = stats;
                return Err(SolveError::Singular { t });
            }
            h *= 0.5;
            ctrl.last_rejected = true;
            last_rejection = Rejection::None;
            continue;
        }
        if let Some(i) = stepper.f_start().iter().position(|v| !v.is_finite()) {
            sol.stats = stats;
            return Err(SolveError::NonFinite { t, index: i });
        }
        if let Some(i) = x_new.iter().position(|v| !v.is_finite()) {
            let i = stepper.nonfinite_hint().unwrap_or(i);
            // A too-large step can overflow; shrink and retry, give up at h_min.
            stats.rejected += 1;
            let h_try = h * 0.25;
            if !adaptive || h_try < opts.h_min.max(f64::EPSILON * t.abs()) {
                sol.stats = stats;
                return Err(SolveError::NonFinite { t: t + h, index: i });
            }
            h = h_try;
            ctrl.last_rejected = true;
            last_rejection = Rejection::NonFinite(i);
            continue;
        }
        let err_norm = if adaptive {
            split_error_norm(&err, &x, &x_new, &atol, rtol, n_active)
        } else {
            0.0
        };
        // A NaN norm counts as a failed step.
        if err_norm.is_nan() || err_norm > 1.0 {
            stats.rejected += 1;
            h = ctrl.rejected(h, err_norm);
            stepper.rejected();
            last_rejection = Rejection::Error;
            continue;
        }
        if adaptive && stepper.retake(err_norm) {
            stats.rejected += 1;
            continue;
        }
        singular_retries = 0;
        last_rejection = Rejection::None;

        // Accepted.
        stats.steps += 1;
        let t_new = match (last, breakpoint, land) {
            (true, _, _) => t_end,
            (false, Some((bp, _)), _) => bp,
            (false, None, Some(tk)) => tk,
            (false, None, None) => t + h,
        };
        let h_next = match (adaptive, breakpoint) {
            (false, _) => h,
            (true, None) => ctrl.accepted(h, err_norm),
            // a step shortened to land on a breakpoint says little about the
            // step to take next: no smaller than the one wanted before it
            (true, Some((_, wanted))) => ctrl.accepted(h, err_norm).max(wanted),
        };
        if adaptive {
            stepper.observe(err_norm, h_next >= opts.h_max);
        }
        stepper.accept(&*sys, t, &x, h, &x_new, &mut stats);

        // Event detection over [t, t_new].
        let mut event_at: Option<f64> = None;
        if n_ev > 0 {
            sys.events(t_new, &x_new, &mut ev.g_new);
            let mut t_stop = f64::INFINITY;
            let tol = opts.event_tol.max(4.0 * f64::EPSILON * t_new.abs());
            for i in 0..n_ev {
                ev.triggered[i] = false;
                let (gp, gn) = (ev.g_prev[i], ev.g_new[i]);
                let leaves_zero = ev.from_zero[i] && gp == 0.0 && sgn(gn) != 0;
                if !(leaves_zero || (ev.armed[i] && sgn(gp) != 0 && sgn(gn) != sgn(gp))) {
                    continue;
                }
                // leaving zero: zero counts as the side it leaves
                let side = if gn > 0.0 { -1.0 } else { 1.0 };
                let off_zero = move |g: f64| {
                    if leaves_zero && g == 0.0 {
                        side * f64::MIN_POSITIVE
                    } else {
                        g
                    }
                };
                let br = if gn == 0.0 {
                    Bracket {
                        a: t_new,
                        ga: 0.0,
                        b: t_new,
                        gb: 0.0,
                    }
                } else {
                    let stepper_ref = &stepper;
                    let sys_ref = &*sys;
                    let (x_tmp, g_tmp) = (&mut ev.x_tmp, &mut ev.g_tmp);
                    locate_root(
                        Bracket {
                            a: t,
                            ga: off_zero(gp),
                            b: t_new,
                            gb: gn,
                        },
                        tol,
                        |tau| {
                            let theta = ((tau - t) / h).clamp(0.0, 1.0);
                            stepper_ref.dense(theta, x_tmp);
                            sys_ref.events(tau, x_tmp, g_tmp);
                            off_zero(g_tmp[i])
                        },
                    )
                };
                ev.bracket_mag[i] = br.ga.abs().max(br.gb.abs());
                t_stop = t_stop.min(br.b);
            }
            if t_stop.is_finite() {
                event_at = Some(t_stop);
            }
        }

        match event_at {
            None => {
                pace.free_step();
                if opts.t_eval.is_some() {
                    emit_t_eval(
                        &stepper,
                        &t_eval,
                        &mut next_out,
                        t,
                        h,
                        t_new,
                        &x_new,
                        &mut sol,
                    );
                } else {
                    sol.t.push(t_new);
                    sol.x.extend_from_slice(&x_new);
                }
                t = t_new;
                std::mem::swap(&mut x, &mut x_new);
                if n_ev > 0 {
                    std::mem::swap(&mut ev.g_prev, &mut ev.g_new);
                    for i in 0..n_ev {
                        ev.armed[i] = ev.g_prev[i] != 0.0;
                        ev.from_zero[i] &= ev.g_prev[i] == 0.0;
                    }
                }
                h = h_next;
            }
            Some(t_ev) => {
                // State at the event from the dense output (exact step end if t_ev = t_new).
                if t_ev >= t_new {
                    x_ev.copy_from_slice(&x_new);
                } else {
                    stepper.dense(((t_ev - t) / h).clamp(0.0, 1.0), &mut x_ev);
                }
                if opts.t_eval.is_some() {
                    emit_t_eval(
                        &stepper,
                        &t_eval,
                        &mut next_out,
                        t,
                        h,
                        t_ev,
                        &x_ev,
                        &mut sol,
                    );
                } else {
                    sol.t.push(t_ev);
                    sol.x.extend_from_slice(&x_ev);
                }
                // Which functions have crossed by t_ev.
                sys.events(t_ev, &x_ev, &mut ev.g_tmp);
                let mut stop = false;
                x.copy_from_slice(&x_ev);
                for i in 0..n_ev {
                    let gp = ev.g_prev[i];
                    let (gn, gt) = (ev.g_new[i], ev.g_tmp[i]);
                    let left_zero =
                        ev.from_zero[i] && gp == 0.0 && sgn(gn) != 0 && sgn(gt) == sgn(gn);
                    let crossed = left_zero
                        || (ev.armed[i]
                            && sgn(gp) != 0
                            && sgn(gn) != sgn(gp)
                            && sgn(gt) != sgn(gp));
                    ev.triggered[i] = crossed;
                    if crossed {
                        let rising = if left_zero { gn > 0.0 } else { gp < 0.0 };
                        let dir = if rising {
                            Crossing::Rising
                        } else {
                            Crossing::Falling
                        };
                        sol.events.push(EventRecord {
                            t: t_ev,
                            which: i,
                            dir,
                        });
                        stats.events += 1;
                        ev.x_tmp.copy_from_slice(&x);
                        if sys.on_event(t_ev, &mut x, i, dir) == EventAction::Stop {
                            stop = true;
                        }
                        ev.edited_by[i] = x != ev.x_tmp;
                    }
                }
                if let Some(i) = x.iter().position(|v| !v.is_finite()) {
                    sol.stats = stats;
                    return Err(SolveError::NonFinite { t: t_ev, index: i });
                }
                let which = ev.triggered.iter().rposition(|&b| b).unwrap_or(0);
                if let Err(e) = pace.event_step(t_ev, which) {
                    sol.stats = stats;
                    return Err(e);
                }
                let edited = x.iter().zip(x_ev.iter()).any(|(a, b)| a != b);
                if edited && opts.t_eval.is_none() {
                    sol.t.push(t_ev);
                    sol.x.extend_from_slice(&x);
                }
                t = t_ev;
                if stop {
                    break;
                }
                // Re-arm: a triggered function still within its bracket's
                // magnitude sits on its root; it is armed again once it has
                // left zero, so the restart cannot re-detect the same event.
                sys.events(t, &x, &mut ev.g_prev);
                for i in 0..n_ev {
                    let g = ev.g_prev[i];
                    ev.armed[i] = g != 0.0 && !(ev.triggered[i] && g.abs() <= ev.bracket_mag[i]);
                    ev.from_zero[i] =
                        g == 0.0 && (ev.from_zero[i] || (ev.triggered[i] && ev.edited_by[i]));
                    ev.edited_by[i] = false;
                }
                fresh = true;
                // the handler may have changed the system's inputs
                bp_from = f64::INFINITY;
            }
        }
    }
    // Output times at t_end not yet written (t reached t_end within rounding).
    between.between(sys, t, &mut t_eval, &mut next_out, &mut sol)?;
    if opts.t_eval.is_some() {
        while next_out < t_eval.len() && t_eval[next_out] <= t_end && t >= t_end - t_close(t) {
            sol.t.push(t_eval[next_out]);
            sol.x.extend_from_slice(&x);
            next_out += 1;
        }
    }
    sol.stats = stats;
    Ok(sol)
}
