//! Fitting on the valve rig: the Levenberg–Marquardt refit with the initial
//! state as nuisance parameters, the cheap Gauss–Newton trace, the parallel
//! runner (the out-of-catalog probes are in `probes.rs`).

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
    fit_with(rig, params, p, holdout, part, Stop::LOOSE, None)
}

/// Every valve-rig fit stops after this many rejected steps in a row: the
/// integration noise then hides any further gain (see
/// `hydrocyl_fit::Options::max_rejections`).
const MAX_REJECTIONS: usize = 4;

/// When a fit stops, and how its Jacobian is taken.
#[derive(Clone, Copy, Debug)]
struct Stop {
    /// Relative cost reduction of an accepted step below which it stops.
    ftol: f64,
    /// Gauss–Newton step in standard errors below which it stops (0 = off),
    /// in every effect parameter: the initial position and velocity are
    /// nuisance parameters, tested only in a fit of them alone.
    step_se: f64,
    /// Most residual evaluations.
    evaluations: usize,
    /// Forward differences (else central where the bounds allow).
    forward: bool,
    /// The least finite-difference step in typical sizes (`None`: the
    /// solver's default floor, relative to the value).
    fd_floor: Option<f64>,
    /// Stop after this many rejected steps in a row (0 = no limit).
    max_rejections: usize,
}

impl Stop {
    /// The initial-state fit and the refit's first stage: forward
    /// differences, stop where an accepted step gains less than 1e-6 of the
    /// cost or the Gauss–Newton step is within half a standard error (about
    /// as close as the integration noise at rtol 1e-6 lets it get).
    const LOOSE: Stop = Stop {
        ftol: 1e-6,
        step_se: 0.5,
        evaluations: 600,
        forward: true,
        fd_floor: Some(FD_FLOOR),
        max_rejections: MAX_REJECTIONS,
    };
}

/// Integration tolerance of the polish that ends every refit: at rtol
/// 1e-8 the weighted sum of squares of the 12 s valve record wobbles by
/// about 0.1 from one Cl to the next a millionth of a standard error away
/// (the adaptive steps change), which hides its minimum within about half
/// a standard error; at 1e-10 it is smooth to 0.01 there, and 1e-9 and
/// 1e-10 agree.
const POLISH_RTOL: f64 = 1e-9;

/// The finite-difference step of every fitted parameter is at least
/// `1e-3 × FD_FLOOR` of its typical size (10 µm of initial position, 0.1
/// mm/s of initial velocity, as the traces' steps): a step relative to a
/// value near zero measures the integrator's noise, not the model.
const FD_FLOOR: f64 = 10.0;

/// The polish stops when the Gauss–Newton step is below this many
/// standard errors in every effect parameter. The step is the joint one,
/// so it is how far each effect parameter is from the joint minimum, the
/// initial position and velocity moving with it; their own steps are left
/// out (they are not reported, and at rtol 1e-9 the initial velocity's
/// step wanders by a tenth of its standard error from one iteration to the
/// next, which held the polish two iterations longer on the 12 s record).
const POLISH_STEP_SE: f64 = 0.05;

/// A refit: [`fit`] on the whole record, then a polish from where it
/// stopped at [`POLISH_RTOL`] that stops only when the Gauss–Newton step is
/// below [`POLISH_STEP_SE`] standard errors. Where the refit starts (the
/// trace it comes from) then does not show in where it ends, and the
/// intervals come from a Jacobian at that end.
pub(super) fn refit_polished(
    rig: &mut Model,
    params: &ParamList,
    p: &Prepared,
    holdout: f64,
) -> Result<lm::LmResult, lm::LmError> {
    // first near the minimum, cheaply (as far as its integration noise lets it)
    let coarse = Prepared {
        rtol: 1e-6,
        ..p.clone()
    };
    // The trace fitted the initial position and velocity on the training
    // part, from the round model's (which the initial-state fit of a
    // declared model that cannot follow the record may have bent far off):
    // start from those or the smoother's, whichever is closer on the whole record.
    if let (Some(x0), Some(v0)) = (p.x0, p.v0) {
        let half = 0.5 * rig.stroke();
        let mut smoothed = rig.clone();
        smoothed.set_x0(x0.clamp(-half, half));
        smoothed.set_v0(v0);
        let (from_smoothed, from_trace) = rayon::join(
            || rss(&smoothed, &coarse, holdout, Part::All),
            || rss(rig, &coarse, holdout, Part::All),
        );
        if from_smoothed < from_trace {
            *rig = smoothed;
        }
    }
    fit_with(rig, params, &coarse, holdout, Part::All, Stop::LOOSE, None)?;
    let q = Prepared {
        rtol: POLISH_RTOL,
        ..p.clone()
    };
    let start = warm_step(rig, params, &q, holdout);
    fit_with(
        rig,
        params,
        &q,
        holdout,
        Part::All,
        Stop {
            ftol: 1e-12,
            step_se: POLISH_STEP_SE,
            evaluations: 200,
            forward: false,
            fd_floor: Some(FD_FLOOR),
            max_rejections: MAX_REJECTIONS,
        },
        start,
    )
}

/// The values a fit of `params` on `rig` starts from, with the initial
/// position and velocity last, their bounds and their typical sizes (the
/// solver's scales).
#[allow(clippy::type_complexity)]
fn start_of(rig: &Model, params: &ParamList) -> (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>) {
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
    (x0, lo, hi, typ)
}

/// `rig` with `params`, then the initial position and velocity, set to `x`.
fn at(rig: &Model, params: &ParamList, x: &[f64]) -> Model {
    let k = params.len();
    let mut work = rig.clone();
    for ((id, n), v) in params.iter().zip(x) {
        set(&mut work, *id, n, *v);
    }
    work.set_x0(x[k]);
    work.set_v0(x[k + 1]);
    work
}

/// The polish's first step, with a one-sided finite-difference Jacobian
/// (the polish's own is central: twice the simulations at its tight
/// tolerance `q`): the Gauss–Newton step from `rig`, projected on the fit's
/// bounds, where it lowers the sum of squares at `q` (else `rig` stays).
/// Returns the residual at `q` where `rig` ends, for the polish to start
/// from (`None` where a simulation fails: the polish then starts as
/// before). The polish's stop (its own Jacobian at its end point, the step
/// below [`POLISH_STEP_SE`] standard errors) and the intervals it gives
/// are unchanged; the step saves the polish's first central Jacobian where
/// it lands as close as the polish's own first step would.
fn warm_step(rig: &mut Model, params: &ParamList, q: &Prepared, holdout: f64) -> Option<Vec<f64>> {
    let (x, lo, hi, typ) = start_of(rig, params);
    let k = x.len();
    // the solver's steps (`fd_step` 1e-3 of max(|x|, FD_FLOOR typical sizes))
    let steps: Vec<f64> = (0..k)
        .map(|j| {
            let h = 1e-3 * (x[j] / typ[j]).abs().max(FD_FLOOR) * typ[j];
            if x[j] + h > hi[j] {
                -h
            } else {
                h
            }
        })
        .collect();
    // the residual at `rig` (the last) and at each stepped point, all at
    // once: none waits for another
    let mut runs: Vec<Option<Vec<f64>>> = (0..=k)
        .into_par_iter()
        .map(|j| {
            let mut xj = x.clone();
            if j < k {
                xj[j] += steps[j];
            }
            let mut r = Vec::new();
            residual(&at(rig, params, &xj), q, holdout, Part::All, &mut r).ok()?;
            Some(r)
        })
        .collect();
    let r0 = runs.pop().flatten()?;
    let cols: Option<Vec<Vec<f64>>> = runs
        .into_iter()
        .zip(&steps)
        .enumerate()
        .map(|(j, (r1, h))| {
            Some(
                r1?.iter()
                    .zip(&r0)
                    .map(|(a, b)| (a - b) / h * typ[j])
                    .collect(),
            )
        })
        .collect();
    let Some(cols) = cols else {
        return Some(r0);
    };
    // normal equations in scaled parameters
    let mut a = nalgebra::DMatrix::<f64>::zeros(k, k);
    let mut g = nalgebra::DVector::<f64>::zeros(k);
    for i in 0..k {
        g[i] = -cols[i].iter().zip(&r0).map(|(j, r)| j * r).sum::<f64>();
        for j in 0..=i {
            let v: f64 = cols[i].iter().zip(&cols[j]).map(|(a, b)| a * b).sum();
            a[(i, j)] = v;
            a[(j, i)] = v;
        }
    }
    let Some(d) = a.cholesky().map(|c| c.solve(&g)) else {
        return Some(r0);
    };
    let x1: Vec<f64> = (0..k)
        .map(|i| (x[i] + d[i] * typ[i]).clamp(lo[i], hi[i]))
        .collect();
    if x1.iter().any(|v| !v.is_finite()) {
        return Some(r0);
    }
    let t = at(rig, params, &x1);
    let mut r1 = Vec::new();
    if residual(&t, q, holdout, Part::All, &mut r1).is_ok() && sum_sq(&r1) < sum_sq(&r0) {
        *rig = t;
        return Some(r1);
    }
    Some(r0)
}

/// [`fit`] with its stopping rule `stop`, given the residual `start` at
/// `rig` where it is known.
fn fit_with(
    rig: &mut Model,
    params: &ParamList,
    p: &Prepared,
    holdout: f64,
    part: Part,
    stop: Stop,
    start: Option<Vec<f64>>,
) -> Result<lm::LmResult, lm::LmError> {
    let (x0, lo, hi, typ) = start_of(rig, params);
    let k = params.len();
    let res = lm::fit_parallel_from(
        |x, r| residual(&at(rig, params, x), p, holdout, part, r),
        &x0,
        start,
        &lo,
        &hi,
        &typ,
        &LmOptions {
            max_evaluations: stop.evaluations,
            ftol: stop.ftol,
            fd_step: 1e-3,
            fd_floor: stop.fd_floor,
            forward_differences: stop.forward,
            blocks: p.weights.iter().filter(|w| **w > 0.0).count(),
            step_se: stop.step_se,
            // the initial position and velocity (the last two, `start_of`)
            // are not the answer: the step test is on the effect
            // parameters (on them when they are all there is)
            step_se_nuisance: 2,
            max_rejections: stop.max_rejections,
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
pub(super) fn perturbed(rig: &Model, c: Column) -> (Model, f64) {
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
/// computed itself. The friction-law starts take the two nuisance columns
/// (see [`gauss_newton_trace`]).
pub(super) struct FirstStep {
    /// The round's model.
    model: Model,
    /// Its residual on the traced part.
    pub(super) r0: Vec<f64>,
    /// The columns computed, with their values.
    pub(super) cols: Vec<(Column, Vec<f64>)>,
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
    pub(super) fn applies_to(&self, rig: &Model) -> bool {
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
/// The first step takes what `first` has of it (see [`FirstStep`]; a
/// start of its own, a friction-law edit of `trace_starts`, only its
/// initial-position and -velocity columns); each later step starts from the
/// residual its backtracking accepted, with the Jacobian of the step before
/// updated by Broyden's rank-one formula from the step taken and the change
/// of the residual (in parameters scaled by their finite-difference steps),
/// not by new finite differences: those cost a simulation a column a step,
/// about a third of a round's traces, and every planted effect and
/// fixture is found the same without them.
///
/// Screening: where the first step's linearised sum of squares
/// `rss₀ + gᵀδ` (δ the Gauss–Newton step, g = Jᵀr) removes less than
/// `screen.share` of `screen.rss`, the round model's sum of squares on
/// `part`, the trace stops before simulating the step and `rig` is left
/// where it started ([`TraceEnd::Screened`]). (Ending a trace early where
/// a full step did what its linearisation predicted was tried and left
/// out: two candidates that explain nearly the same share, a Coulomb
/// asymmetry and a constant force on a record that never stops, then swap
/// places.)
///
/// The trace only ranks the candidates and starts the refit, whose polish
/// does not depend on where it starts ([`refit_polished`]).
pub(super) fn gauss_newton_trace(
    rig: &mut Model,
    params: &ParamList,
    p: &Prepared,
    holdout: f64,
    part: Part,
    first: Option<&FirstStep>,
    screen: Screen,
) -> Result<TraceEnd, String> {
    let cols = columns(params);
    let k = cols.len();
    // a start of its own (a friction-law edit) takes only the round
    // model's initial-position and -velocity columns
    let lent = first;
    let first = first.filter(|f| f.applies_to(rig));
    let mut r0 = match first {
        Some(f) => f.r0.clone(),
        None => {
            let mut r0 = Vec::new();
            residual(rig, p, holdout, part, &mut r0)?;
            r0
        }
    };
    let m = r0.len();
    let mut jac = nalgebra::DMatrix::<f64>::zeros(m, k);
    // each column's finite-difference step (the scale of the updates)
    let mut steps = vec![1.0; k];
    for (j, c) in cols.iter().enumerate() {
        let (t, h) = perturbed(rig, *c);
        steps[j] = h;
        let known = first
            .or(lent.filter(|_| matches!(c, Column::X0 | Column::V0)))
            .and_then(|f| f.cols.iter().find(|(fc, _)| fc == c));
        if let Some((_, col)) = known {
            jac.set_column(j, &nalgebra::DVector::from_column_slice(col));
            continue;
        }
        let mut r1 = Vec::new();
        residual(&t, p, holdout, part, &mut r1)?;
        for i in 0..m {
            jac[(i, j)] = (r1[i] - r0[i]) / h;
        }
    }
    for step in 0..3 {
        let rhs = jac.transpose() * nalgebra::DVector::from_column_slice(&r0);
        let mut a = jac.transpose() * &jac;
        for j in 0..k {
            a[(j, j)] *= 1.0 + 1e-9;
        }
        let delta = a
            .cholesky()
            .ok_or("singular trace Jacobian")?
            .solve(&(-&rhs));
        let rss0: f64 = r0.iter().map(|v| v * v).sum();
        let linear = rss0 + rhs.dot(&delta);
        if step == 0 && 1.0 - linear / screen.rss.max(1e-300) < screen.share {
            return Ok(TraceEnd::Screened {
                r: r0,
                share: 1.0 - linear / screen.rss.max(1e-300),
            });
        }
        // Backtrack: take the largest of 1, 1/2, 1/4, 1/8 of the step that
        // lowers the sum of squares (keep the point if none does).
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
            if residual(&t, p, holdout, part, &mut r1).is_ok() && sum_sq(&r1) < rss0 {
                accepted = Some((t, r1));
                break;
            }
        }
        match accepted {
            Some((t, r1)) => {
                broyden(&mut jac, &steps, &moved(rig, &t, params), &r0, &r1);
                *rig = t;
                r0 = r1;
            }
            None => break,
        }
    }
    Ok(TraceEnd::Traced(r0))
}

/// How far each column of a trace of `params` moved from `from` to `to`.
fn moved(from: &Model, to: &Model, params: &ParamList) -> Vec<f64> {
    params
        .iter()
        .map(|(id, n)| get(to, *id, n).unwrap_or(0.0) - get(from, *id, n).unwrap_or(0.0))
        .chain([to.x0() - from.x0(), to.v0() - from.v0()])
        .collect()
}

/// Broyden's rank-one update of a Jacobian `jac` after a step `s` that
/// took the residual from `r0` to `r1`, in parameters scaled by `scale`:
/// the least change of the scaled Jacobian that maps the step onto the
/// residual's change.
fn broyden(jac: &mut nalgebra::DMatrix<f64>, scale: &[f64], s: &[f64], r0: &[f64], r1: &[f64]) {
    let sigma: Vec<f64> = s.iter().zip(scale).map(|(a, w)| a / w).collect();
    let ss: f64 = sigma.iter().map(|v| v * v).sum();
    if !(ss > 0.0 && ss.is_finite()) {
        return;
    }
    let js = &*jac * nalgebra::DVector::from_column_slice(s);
    for (j, (sj, w)) in sigma.iter().zip(scale).enumerate() {
        let f = sj / (w * ss);
        if f == 0.0 {
            continue;
        }
        for i in 0..r0.len() {
            jac[(i, j)] += (r1[i] - r0[i] - js[i]) * f;
        }
    }
}

/// What a trace's shortcuts are judged against (see [`gauss_newton_trace`]).
#[derive(Clone, Copy, Debug)]
pub(super) struct Screen {
    /// The round model's sum of squares on the traced part.
    pub(super) rss: f64,
    /// Screened out below this linearised share of `rss`.
    pub(super) share: f64,
}

/// How a trace ended.
#[derive(Clone, Debug)]
pub(super) enum TraceEnd {
    /// Traced; the residual on the traced part at the point reached.
    Traced(Vec<f64>),
    /// Screened out by its first linearised step, which removes `share` of
    /// the round's sum of squares; the model is where it started, `r` its
    /// residual there.
    Screened {
        /// The residual at the start.
        r: Vec<f64>,
        /// The linearised share.
        share: f64,
    },
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
