//! Fitting on the valve rig: the Levenberg–Marquardt refit with the initial
//! state as nuisance parameters, the cheap Gauss–Newton trace, the parallel
//! runner and the out-of-catalog delay probe.

use super::*;
pub(super) type ParamList = Vec<(EffectId, &'static str)>;

/// Fits `params` of `rig` in place on `part`, together with the initial
/// piston position and velocity (nuisance parameters: the rig integrates
/// flow into position, so a few micrometres of initial offset would
/// otherwise be absorbed by whichever effect shifts the position; and the
/// smoother's derivative at the record's first sample is one-sided and
/// noisy, and an initial velocity a few cm/s off rings the chambers for a
/// tenth of a second). The result's last two entries are the initial
/// position and velocity.
pub(super) fn fit(
    rig: &mut Model,
    params: &ParamList,
    p: &Prepared,
    holdout: f64,
    part: Part,
) -> Result<lm::LmResult, lm::LmError> {
    let mut x0: Vec<f64> = params
        .iter()
        .map(|(id, n)| get(rig, *id, n).unwrap_or(0.0))
        .collect();
    let (mut lo, mut hi): (Vec<f64>, Vec<f64>) =
        params.iter().map(|(id, n)| bounds(*id, n, rig)).unzip();
    let mut typ: Vec<f64> = params
        .iter()
        .zip(&x0)
        .map(|((id, n), x)| x.abs().max(typical(*id, n, rig)))
        .collect();
    // the initial position stays within the stroke (a record may start
    // with the piston on a stop)
    let xi = rig.x0();
    let half = 0.5 * rig.stroke();
    x0.push(xi);
    lo.push((xi - 0.01).max(-half));
    hi.push((xi + 0.01).min(half));
    typ.push(1e-3);
    let vi = rig.v0();
    x0.push(vi);
    lo.push(vi - 0.2);
    hi.push(vi + 0.2);
    typ.push(1e-2);
    let k = params.len();
    let mut work = rig.clone();
    let res = lm::fit(
        |x, r| {
            for ((id, n), v) in params.iter().zip(x) {
                set(&mut work, *id, n, *v);
            }
            work.set_x0(x[k]);
            work.set_v0(x[k + 1]);
            residual(&work, p, holdout, part, r)
        },
        &x0,
        &lo,
        &hi,
        &typ,
        &LmOptions {
            max_evaluations: 600,
            ftol: 1e-6,
            fd_step: 1e-3,
            blocks: p.weights.iter().filter(|w| **w > 0.0).count(),
        },
    )?;
    for ((id, n), v) in params.iter().zip(&res.x) {
        set(rig, *id, n, *v);
    }
    rig.set_x0(res.x[k]);
    rig.set_v0(res.x[k + 1]);
    Ok(res)
}

/// Traces a candidate cheaply: up to three backtracking Gauss–Newton steps on `part` from the
/// current values, with a finite-difference Jacobian (step 10 % of each
/// parameter's typical size) and the initial position and velocity as nuisance columns,
/// then clamped to the bounds. A handful of simulations per candidate instead
/// of a full Levenberg–Marquardt fit; the effect that is added is refitted
/// properly afterwards.
pub(super) fn gauss_newton_trace(
    rig: &mut Model,
    params: &ParamList,
    p: &Prepared,
    holdout: f64,
    part: Part,
) -> Result<(), String> {
    let k = params.len() + 2;
    for _ in 0..3 {
        let mut r0 = Vec::new();
        residual(rig, p, holdout, part, &mut r0)?;
        let m = r0.len();
        let mut jac = nalgebra::DMatrix::<f64>::zeros(m, k);
        for j in 0..k {
            let mut t = rig.clone();
            let h = if j < params.len() {
                let (id, n) = params[j];
                let h = 0.1 * typical(id, n, rig);
                set(&mut t, id, n, get(rig, id, n).unwrap_or(0.0) + h);
                h
            } else if j == params.len() {
                // step away from a stop the piston may start on
                let h = if t.x0() + 1e-5 > 0.5 * rig.stroke() {
                    -1e-5
                } else {
                    1e-5
                };
                t.set_x0(t.x0() + h);
                h
            } else {
                t.set_v0(t.v0() + 1e-4);
                1e-4
            };
            let mut r1 = Vec::new();
            residual(&t, p, holdout, part, &mut r1)?;
            for i in 0..m {
                jac[(i, j)] = (r1[i] - r0[i]) / h;
            }
        }
        let rhs = jac.transpose() * nalgebra::DVector::from_column_slice(&r0);
        let mut a = jac.transpose() * &jac;
        for j in 0..k {
            a[(j, j)] *= 1.0 + 1e-9;
        }
        let delta = a
            .cholesky()
            .ok_or("singular trace Jacobian")?
            .solve(&(-rhs));
        // Backtrack: take the largest of 1, 1/2, 1/4, 1/8 of the step that
        // lowers the sum of squares (keep the point if none does).
        let rss0: f64 = r0.iter().map(|v| v * v).sum();
        let mut accepted = None;
        for alpha in [1.0, 0.5, 0.25, 0.125] {
            let mut t = rig.clone();
            for (j, (id, n)) in params.iter().enumerate() {
                let (lo, hi) = bounds(*id, n, rig);
                let v = (get(rig, *id, n).unwrap_or(0.0) + alpha * delta[j]).clamp(lo, hi);
                set(&mut t, *id, n, v);
            }
            let half = 0.5 * rig.stroke();
            t.set_x0((t.x0() + alpha * delta[k - 2]).clamp(-half, half));
            t.set_v0(t.v0() + alpha * delta[k - 1]);
            if rss(&t, p, holdout, part) < rss0 {
                accepted = Some(t);
                break;
            }
        }
        match accepted {
            Some(t) => *rig = t,
            None => break,
        }
    }
    Ok(())
}

/// Runs `f` on every item, spread over the available cores (at most one
/// thread per item; each thread takes the next item not yet taken, so a
/// slow item does not hold up a queue), and returns the results in the
/// order of `items`.
pub(super) fn trace_parallel<I: Sync, T: Send>(
    items: &[I],
    f: &(dyn Fn(&I) -> T + Sync),
) -> Vec<T> {
    use std::sync::atomic::{AtomicUsize, Ordering};
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(items.len())
        .max(1);
    if threads == 1 {
        return items.iter().map(f).collect();
    }
    let next = AtomicUsize::new(0);
    let mut slots: Vec<Option<T>> = std::iter::repeat_with(|| None).take(items.len()).collect();
    std::thread::scope(|sc| {
        let handles: Vec<_> = (0..threads)
            .map(|_| {
                sc.spawn(|| {
                    let mut done = Vec::new();
                    loop {
                        let i = next.fetch_add(1, Ordering::Relaxed);
                        let Some(item) = items.get(i) else { break };
                        done.push((i, f(item)));
                    }
                    done
                })
            })
            .collect();
        for h in handles {
            // A panicking trace is a bug; re-raise it on this thread.
            match h.join() {
                Ok(v) => {
                    for (i, r) in v {
                        slots[i] = Some(r);
                    }
                }
                Err(e) => std::panic::resume_unwind(e),
            }
        }
    });
    slots.into_iter().flatten().collect()
}

/// Out-of-catalog probe: the command reaching the rig late by τ (a
/// transport delay), τ on a grid up to 60 ms, initial position refitted.
pub(super) fn delay_probe(rig: &Model, p: &Prepared, holdout: f64) -> Option<Probe> {
    if p.closed {
        // the input is the reference, not the command the valve receives
        return None;
    }
    let rss0 = rss(rig, p, holdout, Part::All);
    let mut best = (0.0, rss0);
    for tau in [0.002, 0.005, 0.01, 0.015, 0.02, 0.03, 0.045, 0.06] {
        let mut q = Prepared {
            rtol: p.rtol,
            input: p
                .t
                .iter()
                .map(|&t| crate::data::interp_linear(&p.t, &p.input, t - tau))
                .collect(),
            closed: p.closed,
            command0: p.command0,
            t: p.t.clone(),
            meas: p.meas.clone(),
            ranges: p.ranges.clone(),
            weights: p.weights.clone(),
            x0: p.x0,
            v0: p.v0,
            p10: p.p10,
            p20: p.p20,
            restarts: p.restarts.clone(),
            count: p.count.clone(),
        };
        q.input[0] = p.input[0];
        let r = rss(rig, &q, holdout, Part::All);
        if r < best.1 {
            best = (tau, r);
        }
    }
    (best.0 > 0.0).then(|| Probe {
        kind: "delay".into(),
        what: "transport delay of the command".into(),
        value: best.0,
        explained_share: 1.0 - best.1 / rss0.max(1e-300),
    })
}
