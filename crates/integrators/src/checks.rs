//! The checks of a solve's inputs: each inconsistent input is named with
//! its value in a [`SolveError::InvalidInput`].

use crate::api::{Options, SolveError};

/// Per-state absolute tolerances, expanded from `Options::atol`.
fn expand_atol(opts: &Options, n: usize) -> Result<Vec<f64>, SolveError> {
    let atol = match opts.atol.len() {
        1 => vec![opts.atol[0]; n],
        m if m == n => opts.atol.clone(),
        m => {
            return Err(SolveError::InvalidInput(format!(
                "Options::atol has {m} entries; expected 1 or the system dimension {n}"
            )))
        }
    };
    for (i, &a) in atol.iter().enumerate() {
        if !(a.is_finite() && a >= 0.0) {
            return Err(SolveError::InvalidInput(format!(
                "Options::atol[{i}] = {a} must be finite and >= 0"
            )));
        }
        if a == 0.0 && opts.rtol == 0.0 {
            return Err(SolveError::InvalidInput(format!(
                "Options::atol[{i}] and Options::rtol are both zero: no error scale for state {i}"
            )));
        }
    }
    Ok(atol)
}

/// Checks the solver inputs; returns the expanded absolute tolerances.
pub(crate) fn check_inputs(
    n: usize,
    t0: f64,
    x0: &[f64],
    t_end: f64,
    opts: &Options,
    fixed_step: bool,
) -> Result<Vec<f64>, SolveError> {
    let bad = |s: String| Err(SolveError::InvalidInput(s));
    if x0.len() != n {
        return bad(format!(
            "x0 has {} entries but the system has {n} states",
            x0.len()
        ));
    }
    if let Some(i) = x0.iter().position(|v| !v.is_finite()) {
        return bad(format!("x0[{i}] = {} is not finite", x0[i]));
    }
    if !t0.is_finite() || !t_end.is_finite() {
        return bad(format!("t0 = {t0} and t_end = {t_end} must be finite"));
    }
    if t_end < t0 {
        return bad(format!(
            "t_end = {t_end} s is before t0 = {t0} s (only forward integration is supported)"
        ));
    }
    if !(opts.rtol.is_finite() && opts.rtol >= 0.0) {
        return bad(format!(
            "Options::rtol = {} must be finite and >= 0",
            opts.rtol
        ));
    }
    let atol = expand_atol(opts, n)?;
    if let Some(h0) = opts.h0 {
        if !(h0.is_finite() && h0 > 0.0) {
            return bad(format!("Options::h0 = {h0} must be finite and > 0"));
        }
    } else if fixed_step {
        return bad(
            "RK4 and the exponential method are fixed-step methods: set Options::h0 to the step size"
                .into(),
        );
    }
    if opts.h_max.is_nan() || opts.h_max <= 0.0 {
        return bad(format!("Options::h_max = {} must be > 0", opts.h_max));
    }
    if !(opts.h_min.is_finite() && opts.h_min >= 0.0 && opts.h_min <= opts.h_max) {
        return bad(format!(
            "Options::h_min = {} must be finite, >= 0 and <= h_max = {}",
            opts.h_min, opts.h_max
        ));
    }
    if opts.max_steps == 0 {
        return bad("Options::max_steps must be at least 1".into());
    }
    if !(opts.event_tol.is_finite() && opts.event_tol > 0.0) {
        return bad(format!(
            "Options::event_tol = {} must be finite and > 0",
            opts.event_tol
        ));
    }
    if let Some(te) = &opts.t_eval {
        for (k, &tk) in te.iter().enumerate() {
            if !tk.is_finite() || tk < t0 || tk > t_end {
                return bad(format!(
                    "Options::t_eval[{k}] = {tk} is not within [t0, t_end] = [{t0}, {t_end}]"
                ));
            }
            if k > 0 && tk < te[k - 1] {
                return bad(format!(
                    "Options::t_eval is not sorted: t_eval[{k}] = {tk} < t_eval[{}] = {}",
                    k - 1,
                    te[k - 1]
                ));
            }
        }
    }
    Ok(atol)
}
