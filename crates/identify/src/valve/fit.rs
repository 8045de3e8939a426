//! Fitting on the valve rig: the Levenberg–Marquardt refit with the initial
//! state as nuisance parameters, the cheap Gauss–Newton trace, the parallel
//! runner and the out-of-catalog delay probe.

use super::*;
use rayon::prelude::*;
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
    let res = lm::fit_parallel(
        |x, r| {
            let mut work = rig.clone();
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

/// One column of a trace's finite-difference Jacobian: an effect parameter
/// or one of the two nuisance parameters (initial position and velocity).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Column {
    /// Catalog parameter `name` of effect `id`.
    Param(EffectId, &'static str),
    /// The initial piston position.
    X0,
    /// The initial piston velocity.
    V0,
}

/// The columns of a trace of `params`, in the order of its Jacobian.
fn columns(params: &ParamList) -> Vec<Column> {
    params
        .iter()
        .map(|&(id, n)| Column::Param(id, n))
        .chain([Column::X0, Column::V0])
        .collect()
}

/// `rig` with column `c` stepped by its finite-difference step, and the step:
/// 10 % of a parameter's typical size, 10 µm of initial position (away from
/// a stop the piston may start on), 0.1 mm/s of initial velocity.
fn perturbed(rig: &Model, c: Column) -> (Model, f64) {
    let mut t = rig.clone();
    let h = match c {
        Column::Param(id, n) => {
            let h = 0.1 * typical(id, n, rig);
            set(&mut t, id, n, get(rig, id, n).unwrap_or(0.0) + h);
            h
        }
        Column::X0 => {
            let h = if t.x0() + 1e-5 > 0.5 * rig.stroke() {
                -1e-5
            } else {
                1e-5
            };
            t.set_x0(t.x0() + h);
            h
        }
        Column::V0 => {
            t.set_v0(t.v0() + 1e-4);
            1e-4
        }
    };
    (t, h)
}

/// The part of a trace's first Gauss–Newton step that every candidate of a
/// round shares: the residual of the round's model on the traced part and
/// its finite-difference columns for the effects already added and the two
/// nuisance parameters. A candidate that starts from this model (every one
/// but the friction-law starts of `trace_starts`) reuses them and simulates
/// only its own parameters' columns; the numbers are the ones it would have
/// computed itself.
pub(super) struct FirstStep {
    /// The round's model.
    model: Model,
    /// Its residual on the traced part.
    r0: Vec<f64>,
    /// The columns computed, with their values.
    cols: Vec<(Column, Vec<f64>)>,
}

impl FirstStep {
    /// Simulates the shared part of the first step of tracing with `free`
    /// (the effects already added) on `model`, on the available cores.
    /// `None` when the model does not simulate (each trace then fails on
    /// its own, saying why); a column that does not simulate is left out.
    pub(super) fn new(
        model: &Model,
        free: &ParamList,
        p: &Prepared,
        holdout: f64,
        part: Part,
    ) -> Option<Self> {
        let mut r0 = Vec::new();
        residual(model, p, holdout, part, &mut r0).ok()?;
        let cols: Vec<(Column, Vec<f64>)> = columns(free)
            .par_iter()
            .filter_map(|&c| {
                let (t, h) = perturbed(model, c);
                let mut r1 = Vec::new();
                residual(&t, p, holdout, part, &mut r1).ok()?;
                Some((c, r1.iter().zip(&r0).map(|(a, b)| (a - b) / h).collect()))
            })
            .collect();
        Some(Self {
            model: model.clone(),
            r0,
            cols,
        })
    }

    /// Whether a trace starting from `rig` may use these simulations.
    fn applies_to(&self, rig: &Model) -> bool {
        rig.lag == self.model.lag && rig.net == self.model.net
    }
}

/// Traces a candidate cheaply: up to three backtracking Gauss–Newton steps on `part` from the
/// current values, with a finite-difference Jacobian (step 10 % of each
/// parameter's typical size) and the initial position and velocity as nuisance columns,
/// then clamped to the bounds. A handful of simulations per candidate instead
/// of a full Levenberg–Marquardt fit; the effect that is added is refitted
/// properly afterwards.
///
/// The first step takes what `first` has of it (see [`FirstStep`]); each
/// later step starts from the residual its backtracking accepted. Returns
/// the residual on `part` at the point reached.
pub(super) fn gauss_newton_trace(
    rig: &mut Model,
    params: &ParamList,
    p: &Prepared,
    holdout: f64,
    part: Part,
    first: Option<&FirstStep>,
) -> Result<Vec<f64>, String> {
    let cols = columns(params);
    let k = cols.len();
    let first = first.filter(|f| f.applies_to(rig));
    let mut r0 = match first {
        Some(f) => f.r0.clone(),
        None => {
            let mut r0 = Vec::new();
            residual(rig, p, holdout, part, &mut r0)?;
            r0
        }
    };
    for step in 0..3 {
        let m = r0.len();
        let mut jac = nalgebra::DMatrix::<f64>::zeros(m, k);
        for (j, c) in cols.iter().enumerate() {
            let shared = first
                .filter(|_| step == 0)
                .and_then(|f| f.cols.iter().find(|(fc, _)| fc == c));
            if let Some((_, col)) = shared {
                jac.set_column(j, &nalgebra::DVector::from_column_slice(col));
                continue;
            }
            let (t, h) = perturbed(rig, *c);
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
            let mut r1 = Vec::new();
            if residual(&t, p, holdout, part, &mut r1).is_ok()
                && r1.iter().map(|v| v * v).sum::<f64>() < rss0
            {
                accepted = Some((t, r1));
                break;
            }
        }
        match accepted {
            Some((t, r1)) => {
                *rig = t;
                r0 = r1;
            }
            None => break,
        }
    }
    Ok(r0)
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
/// transport delay), τ on a grid up to 60 ms, scored against `rss0`, the
/// weighted sum of squares of `rig` on the whole record.
pub(super) fn delay_probe(rig: &Model, p: &Prepared, holdout: f64, rss0: f64) -> Option<Probe> {
    if p.closed {
        // the input is the reference, not the command the valve receives
        return None;
    }
    const TAUS: [f64; 8] = [0.002, 0.005, 0.01, 0.015, 0.02, 0.03, 0.045, 0.06];
    let shifted = |tau: &f64| {
        let mut q = p.clone();
        q.input =
            p.t.iter()
                .map(|&t| crate::data::interp_linear(&p.t, &p.input, t - tau))
                .collect();
        q.input[0] = p.input[0];
        rss(rig, &q, holdout, Part::All)
    };
    let scores = trace_parallel(&TAUS, &shifted);
    let mut best = (0.0, rss0);
    for (tau, r) in TAUS.iter().zip(scores) {
        if r < best.1 {
            best = (*tau, r);
        }
    }
    (best.0 > 0.0).then(|| Probe {
        kind: "delay".into(),
        what: "transport delay of the command".into(),
        value: best.0,
        explained_share: 1.0 - best.1 / rss0.max(1e-300),
    })
}
