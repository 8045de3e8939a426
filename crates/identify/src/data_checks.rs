//! Data problems named before any fit (`spec/measured-data.md`): a channel
//! that is constant, clipped or quantised far coarser than the others; a
//! unit that contradicts the rig (a position range beyond the stroke,
//! pressures above the supply or below vacuum, or far below the supply, a
//! command-to-velocity gain far from the rig's, p1 and p2 that do not
//! balance the piston or look swapped); a sign that contradicts the rig
//! (command up, piston down) or the record (a velocity against its own
//! position's derivative); gaps in the time axis. After the declared
//! model's first run, [`pressure_scale_problems`] compares the pressures'
//! scale with the model's, and [`missing_channels`] names the compared
//! channels a record lacks.
//!
//! What leaves nothing to diagnose is an error naming the file, row and
//! column instead: [`position_outliers`] (a handful of position samples
//! beyond the stroke), [`unit_errors`], [`input_errors`] (a constant
//! command under a piston moving both ways) and, after the first run,
//! [`travel_error`] (a command the declared rig does not move the piston
//! on as the record's).
//!
//! The checks read the record and a few facts about the rig ([`RigFacts`]),
//! not the rig itself, so they do not depend on how a rig is declared. Each
//! problem names its channel, a kind and a one-line message that says what
//! to check; the loop leaves the channel out of the fit
//! ([`DataProblem::channel`]) and goes on with the others.

use serde::Serialize;

use crate::data::{Record, Signal};
use crate::smooth::noise_sigma;

mod balance;
mod coverage;
mod input;
mod outliers;
mod travel;
mod unit_errors;
mod velocity_sign;
pub use coverage::{gap_ends, missing_channels, pressure_scale_problems, GAP_FACTOR, SCALE_FACTOR};
pub use input::input_errors;
pub use outliers::position_outliers;
pub use travel::travel_error;
pub use unit_errors::unit_errors;

/// What the checks need to know about the rig (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigFacts {
    /// Piston stroke \[m\]: the position stays within ±stroke/2.
    pub stroke: f64,
    /// Supply pressure, gauge \[Pa\].
    pub supply: f64,
    /// Steady piston velocity per unit command near full demand
    /// \[m·s⁻¹ per unit command\] (the mean of the extending and retracting
    /// gains), if the rig has one.
    pub velocity_gain: Option<f64>,
    /// Cap- and rod-side piston areas \[m²\], if the rig has a cylinder
    /// whose areas it declares.
    pub areas: Option<(f64, f64)>,
    /// Moving mass on the rod \[kg\].
    pub mass: f64,
    /// The unit of the rig's `command`: `-` for a normalised spool demand
    /// (valve rigs, and the controller's output of a closed-loop rig), `V`
    /// for a drive voltage (pump rigs); `None` if the rig does not say.
    pub command_unit: Option<&'static str>,
}

/// The kind of a data problem.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ProblemKind {
    /// The channel never changes (a stuck or disconnected sensor).
    Constant,
    /// The channel sits at its extreme value for many samples (saturated
    /// transducer or acquisition range).
    Clipped,
    /// The channel has few distinct levels, far coarser than the others.
    Quantised,
    /// The values contradict the rig's units or ranges.
    Units,
    /// The sign contradicts the rig.
    Sign,
    /// The time axis has gaps (steps far longer than the record's typical
    /// step) that the input is interpolated across; the channels are kept.
    Gap,
    /// A channel the loop compares is not in the record: it is not compared.
    Missing,
}

/// One data problem (`data_problems` in the JSON report).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct DataProblem {
    /// The record it was found in (the file, as given).
    pub file: String,
    /// The channel (`position`, `p1`, ...).
    pub channel: String,
    /// What is wrong.
    pub kind: ProblemKind,
    /// One line: what was seen and what to check.
    pub message: String,
    /// `true` when the channel is left out of the fit; `false` when it is
    /// kept, and [`DataProblem::message`] says why (a friction bench's
    /// pressure is an input of its model, not a compared channel).
    pub left_out: bool,
}

/// Channels the checks look at (the measured ones; the command is the
/// input and may legitimately hold few levels).
const MEASURED: [Signal; 7] = [
    Signal::Position,
    Signal::Velocity,
    Signal::P1,
    Signal::P2,
    Signal::Ps,
    Signal::Flow,
    Signal::Force,
];

/// Least share of the samples at one extreme that counts as clipping.
const CLIP_SHARE: f64 = 0.02;
/// Fewer distinct levels than this over the channel's range is coarse.
const COARSE_LEVELS: f64 = 100.0;
/// A coarse channel is flagged when its resolution is this many times
/// coarser than the finest other measured channel's.
const COARSER_THAN_NEIGHBOURS: f64 = 20.0;
/// A measured command-to-velocity gain this many times off the rig's (either
/// way) contradicts the units of the position.
const GAIN_FACTOR: f64 = 20.0;
/// The chamber pressures' force-balance coefficient this many times off 1
/// (either way) contradicts their units (psi/bar 14.5, MPa/bar 10, kPa/psi
/// 6.9).
const BALANCE_FACTOR: f64 = 3.0;
/// A channel at its extreme this many times longer than on any of the
/// levels next to it is clipped (a quantised peak dwells at most 2.4 times
/// as long on its top level).
const CLIP_DWELL: f64 = 5.0;
/// How many distinct levels next to an extreme [`inward_dwell`] looks at.
const INWARD_LEVELS: usize = 3;

fn range(y: &[f64]) -> (f64, f64) {
    y.iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), v| {
            (lo.min(*v), hi.max(*v))
        })
}

/// Resolution of a channel: its smallest step between distinct values that
/// is not a rounding artefact (the 5th percentile of the steps between
/// sorted distinct values), as a share of its range; with its level count.
/// The range is the one between the 0.5th and 99.5th percentiles (the full
/// range if that is zero), so that one outlier (1e300 in a pressure column)
/// neither merges every other value into one level nor makes the steps
/// look fine.
fn resolution(y: &[f64]) -> Option<(f64, usize)> {
    let (lo, hi) = range(y);
    if hi - lo <= 0.0 {
        return None;
    }
    let mut v = y.to_vec();
    v.sort_by(f64::total_cmp);
    let r = robust_range(&v, hi - lo);
    v.dedup_by(|a, b| (*a - *b).abs() <= 1e-12 * r);
    if v.len() < 2 {
        return None;
    }
    let mut steps: Vec<f64> = v.windows(2).map(|w| w[1] - w[0]).collect();
    let k = steps.len() / 20;
    let q = *steps.select_nth_unstable_by(k, f64::total_cmp).1;
    Some((q / r, v.len()))
}

/// The range between the 0.5th and 99.5th percentiles of the sorted
/// values `v` (`full` if that is zero): a few outliers do not count.
fn robust_range(v: &[f64], full: f64) -> f64 {
    let tail = v.len() / 200;
    let r = v[v.len() - 1 - tail] - v[tail];
    if r > 0.0 {
        r
    } else {
        full
    }
}

/// The 0.5th and 99.5th percentiles of `y` (its extremes below 200
/// samples): the bulk of the channel, without a handful of outliers.
fn bulk(y: &[f64]) -> (f64, f64) {
    let mut v = y.to_vec();
    v.sort_by(f64::total_cmp);
    let tail = v.len() / 200;
    match (
        v.get(tail),
        v.len().checked_sub(1 + tail).and_then(|k| v.get(k)),
    ) {
        (Some(lo), Some(hi)) => (*lo, *hi),
        _ => (0.0, 0.0),
    }
}

/// A value for a message: `0.5200` below 1e6 in magnitude, else `1.0000e305`
/// (not a 300-digit number).
fn num(v: f64) -> String {
    if v.abs() < 1e6 {
        format!("{v:.4}")
    } else {
        format!("{v:.4e}")
    }
}

/// SI unit of a channel for messages.
fn unit(s: Signal) -> &'static str {
    match s {
        Signal::Position | Signal::Reference => "m",
        Signal::Velocity => "m/s",
        Signal::P1 | Signal::P2 | Signal::Ps => "Pa",
        Signal::Flow => "m^3/s",
        Signal::Force => "N",
        _ => "",
    }
}

fn problem(ch: Signal, kind: ProblemKind, message: String) -> DataProblem {
    DataProblem {
        file: String::new(),
        channel: ch.name().into(),
        kind,
        message,
        left_out: true,
    }
}

/// Checks the record against the rig; one entry per problem (a channel at
/// most once, its first problem). `facts` `None`: only the checks that need
/// no rig (constant, clipped, quantised).
pub fn check_record(rec: &Record, facts: Option<&RigFacts>) -> Vec<DataProblem> {
    let mut out: Vec<DataProblem> = Vec::new();
    let present: Vec<(Signal, &[f64])> = MEASURED
        .iter()
        .filter_map(|&s| rec.get(s).map(|y| (s, y)))
        .collect();
    let resolutions: Vec<(Signal, Option<(f64, usize)>)> =
        present.iter().map(|(s, y)| (*s, resolution(y))).collect();
    for (s, y) in &present {
        if let Some(p) = channel_problem(*s, &rec.time, y, facts, &resolutions) {
            out.push(p);
        }
    }
    out.extend(coverage::gap_problem(rec));
    if let Some(f) = facts {
        let bad = |out: &[DataProblem], s: Signal| out.iter().any(|p| p.channel == s.name());
        if !bad(&out, Signal::Position) {
            if let Some(p) = gain_problem(rec, f) {
                out.push(p);
            }
        }
        if !bad(&out, Signal::Position) && !bad(&out, Signal::Velocity) {
            out.extend(velocity_sign::velocity_sign_problem(rec));
        }
        if !bad(&out, Signal::P1) && !bad(&out, Signal::P2) {
            out.extend(balance::balance_problems(rec, f));
        }
    }
    for p in &mut out {
        p.file.clone_from(&rec.source);
    }
    out
}

/// The first problem of one channel, if any.
fn channel_problem(
    s: Signal,
    t: &[f64],
    y: &[f64],
    facts: Option<&RigFacts>,
    resolutions: &[(Signal, Option<(f64, usize)>)],
) -> Option<DataProblem> {
    let name = s.name();
    let u = unit(s);
    let (lo, hi) = range(y);
    let r = hi - lo;
    // a supply pressure logged as the constant set-point is a stiff supply
    let stiff_supply =
        s == Signal::Ps && facts.is_some_and(|f| (lo - f.supply).abs() <= 0.05 * f.supply);
    if y.len() >= 2 && r <= 1e-12 * lo.abs().max(hi.abs()) && !stiff_supply {
        return Some(problem(
            s,
            ProblemKind::Constant,
            format!("{name} reads {lo:.6e} {u} in every sample: a stuck or disconnected sensor? check the transducer, its wiring and the logged column"),
        ));
    }
    // the range without outliers (see `robust_range`): one 1e305 in the
    // column would make the noise sigma, and each margin built on it, huge
    let rr = {
        let mut v = y.to_vec();
        v.sort_by(f64::total_cmp);
        robust_range(&v, r)
    };
    let sigma = noise_sigma(t, y).min(rr);
    // Unit and range checks against the rig.
    if let Some(f) = facts {
        match s {
            Signal::Position => {
                // the bulk of the channel (its 0.5th to 99.5th percentiles):
                // a few samples beyond the stroke are outliers
                // (`outliers::position_outliers`, an error naming their
                // rows), not a unit
                let (blo, bhi) = bulk(y);
                let allowed = f.stroke + 10.0 * sigma;
                if bhi - blo > 1.05 * allowed {
                    return Some(problem(
                        s,
                        ProblemKind::Units,
                        format!("position spans {} m but the rig's stroke is {:.4} m: check the unit of the position column (mm written as m?) and the rig", num(bhi - blo), f.stroke),
                    ));
                }
                let half = outliers::half_stroke_allowed(f, sigma);
                if blo < -half || bhi > half {
                    return Some(problem(
                        s,
                        ProblemKind::Units,
                        format!("position reaches [{}, {}] m, outside the stroke ±{:.4} m: position must be measured from mid-stroke; check the transducer's zero and unit", num(blo), num(bhi), 0.5 * f.stroke),
                    ));
                }
            }
            Signal::P1 | Signal::P2 | Signal::Ps => {
                // a pressure at the supply or tank reads a little past it in
                // a real record: allow 5 % of the supply and 5 noise sigmas
                let margin = 0.05 * f.supply + 5.0 * sigma;
                // a circuit that holds no pressure above tank (a pump's
                // closed circuit without relief valves: its pressures are
                // the load's) has no supply to be above: the check needs one
                if f.supply > 0.0 && hi > f.supply + margin {
                    return Some(problem(
                        s,
                        ProblemKind::Units,
                        format!("{name} reaches {:.4e} Pa, above the supply {:.4e} Pa: check the unit of the column (Pa written as bar?) and the rig's supply pressure", hi, f.supply),
                    ));
                }
                if lo < -1.0e5 - margin {
                    return Some(problem(
                        s,
                        ProblemKind::Units,
                        format!("{name} falls to {lo:.4e} Pa, below vacuum (-1e5 Pa gauge): check the unit and that the pressure is gauge, not absolute with an offset"),
                    ));
                }
                if hi.abs().max(lo.abs()) < 1e-3 * f.supply {
                    return Some(problem(
                        s,
                        ProblemKind::Units,
                        format!("{name} never exceeds {:.3e} Pa, a thousandth of the {:.3e} Pa supply: check the unit of the column (bar written as Pa?)", hi.abs().max(lo.abs()), f.supply),
                    ));
                }
            }
            _ => {}
        }
    }
    // Clipping: many samples exactly at an extreme that is not a physical
    // limit of the rig (an end stop, the supply, the tank).
    // (the tolerance on the range without outliers: one 1e305 would put
    // every other sample "at the extreme")
    let tol = 1e-9 * rr;
    let n = y.len() as f64;
    let at_hi = y.iter().filter(|v| (hi - **v).abs() <= tol).count() as f64;
    let at_lo = y.iter().filter(|v| (**v - lo).abs() <= tol).count() as f64;
    let physical = |v: f64| -> bool {
        facts.is_some_and(|f| match s {
            Signal::Position => (v.abs() - 0.5 * f.stroke).abs() <= 0.01 * f.stroke,
            Signal::P1 | Signal::P2 | Signal::Ps => {
                (v - f.supply).abs() <= 0.05 * f.supply || v.abs() <= 0.05 * f.supply
            }
            Signal::Velocity => v.abs() <= 1e-9,
            _ => false,
        })
    };
    let coarse = resolutions
        .iter()
        .find(|(c, _)| *c == s)
        .and_then(|(_, r)| *r);
    let many_levels = coarse.is_some_and(|(_, levels)| levels as f64 >= COARSE_LEVELS);
    // a run at the extreme from the record's first sample is the piston (or
    // a pressure) at rest before anything moves, not a saturated sensor:
    // only the samples at the extreme after the channel first leaves it count
    let lead = |v: f64| y.iter().take_while(|x| (**x - v).abs() <= tol).count() as f64;
    for (count, v, which) in [
        (at_hi - lead(hi), hi, "maximum"),
        (at_lo - lead(lo), lo, "minimum"),
    ] {
        if many_levels
            && count >= (CLIP_SHARE * n).max(5.0)
            && !physical(v)
            && count > CLIP_DWELL * inward_dwell(y, v, r)
        {
            return Some(problem(
                s,
                ProblemKind::Clipped,
                format!("{name} sits at its {which} {v:.6e} {u} in {:.0} % of the samples: a saturated transducer or acquisition range? check the sensor's range and the logger's scaling", 100.0 * count / n),
            ));
        }
    }
    // Quantisation far coarser than the other measured channels.
    if let Some((q, levels)) = coarse {
        let finest_other = resolutions
            .iter()
            .filter(|(c, _)| *c != s)
            .filter_map(|(_, r)| r.map(|(q, _)| q))
            .fold(f64::INFINITY, f64::min);
        if (levels as f64) < COARSE_LEVELS
            && q > COARSER_THAN_NEIGHBOURS * finest_other
            && finest_other.is_finite()
        {
            return Some(problem(
                s,
                ProblemKind::Quantised,
                format!("{name} has {levels} distinct levels ({:.2} % of its range per step, the other channels {:.4} %): check the sensor's resolution and the logged column's precision", 100.0 * q, 100.0 * finest_other),
            ));
        }
    }
    None
}

/// The most samples at one of the [`INWARD_LEVELS`] distinct levels next
/// to the extreme `v` (towards the inside of the range `r`): how long the
/// signal dwells on a level near its extreme when nothing clips it (at
/// least 1). A quantised sine dwells on its top level about as long as on
/// the next ones (at most 2.4 times as long, for a peak just below a level's
/// upper edge); a clipped signal sits on its extreme far longer than it
/// takes to cross the levels below it.
fn inward_dwell(y: &[f64], v: f64, r: f64) -> f64 {
    let tol = 1e-9 * r;
    let mut d: Vec<f64> = y
        .iter()
        .map(|x| (x - v).abs())
        .filter(|d| *d > tol)
        .collect();
    d.sort_by(f64::total_cmp);
    let mut counts: Vec<usize> = Vec::new();
    let mut level = f64::NAN;
    for x in d {
        if counts.is_empty() || x - level > tol {
            if counts.len() == INWARD_LEVELS {
                break;
            }
            counts.push(0);
            level = x;
        }
        if let Some(c) = counts.last_mut() {
            *c += 1;
        }
    }
    counts.into_iter().max().unwrap_or(0).max(1) as f64
}

/// The command-to-velocity gain of the record against the rig's: the sign
/// (command up, piston down) and the magnitude (a position logged in the
/// wrong unit moves the piston 1000 times too little per unit command).
fn gain_problem(rec: &Record, f: &RigFacts) -> Option<DataProblem> {
    let g_rig = f.velocity_gain?;
    let (u, x) = (rec.get(Signal::Command)?, rec.get(Signal::Position)?);
    let t = &rec.time;
    let n = t.len();
    if n < 10 || !(g_rig.is_finite() && g_rig > 0.0) {
        return None;
    }
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    // central differences over about 50 ms (at least one sample each side)
    let k = ((0.025 / dt).round() as usize).clamp(1, n / 4);
    let (mut suv, mut suu, mut svv, mut su, mut sv, mut m) = (0.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    for i in k..n - k {
        // away from the stops, where the command does not move the piston
        if x[i].abs() > 0.45 * f.stroke {
            continue;
        }
        let v = (x[i + k] - x[i - k]) / (t[i + k] - t[i - k]);
        let ui = u[i];
        suv += ui * v;
        suu += ui * ui;
        svv += v * v;
        su += ui;
        sv += v;
        m += 1.0;
    }
    if m < 10.0 || suu <= 0.0 || svv <= 0.0 {
        return None;
    }
    let cov = suv / m - su * sv / (m * m);
    let var_u = suu / m - (su / m).powi(2);
    let var_v = svv / m - (sv / m).powi(2);
    if var_u <= 0.0 || var_v <= 0.0 {
        return None;
    }
    let corr = cov / (var_u * var_v).sqrt();
    let gain = cov / var_u;
    if corr < -0.3 {
        return Some(problem(
            Signal::Position,
            ProblemKind::Sign,
            format!("the piston moves against the command (correlation {corr:.2} of command and velocity; command up, piston down): check the sign of the command and of the position transducer"),
        ));
    }
    let ratio = gain / g_rig;
    if corr > 0.3 && !(1.0 / GAIN_FACTOR..=GAIN_FACTOR).contains(&ratio) {
        return Some(problem(
            Signal::Position,
            ProblemKind::Units,
            format!("the piston moves {ratio:.3e} times as fast per unit command as the rig predicts ({gain:.3e} vs {g_rig:.3e} m/s): check the unit of the position column (m written under [mm]?) and the rig's valve size"),
        ));
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    pub(super) fn rec(cols: &[(Signal, Vec<f64>)]) -> Record {
        let n = cols[0].1.len();
        Record {
            source: "test".into(),
            time: (0..n).map(|i| i as f64 * 1e-3).collect(),
            signals: cols.iter().cloned().collect::<BTreeMap<_, _>>(),
            ignored: vec![],
            units: Default::default(),
            lines: Vec::new(),
        }
    }

    pub(super) fn facts() -> RigFacts {
        RigFacts {
            stroke: 0.5,
            supply: 7e6,
            velocity_gain: Some(0.2),
            areas: None,
            mass: 100.0,
            command_unit: Some("-"),
        }
    }

    pub(super) fn moving(n: usize) -> (Vec<f64>, Vec<f64>) {
        // command a sine, position its integral at gain 0.2 m/s
        let u: Vec<f64> = (0..n)
            .map(|i| (i as f64 * 1e-3 * 2.0 * std::f64::consts::PI).sin())
            .collect();
        let x: Vec<f64> = (0..n)
            .map(|i| {
                let t = i as f64 * 1e-3;
                -0.2 * (2.0 * std::f64::consts::PI * t).cos() / (2.0 * std::f64::consts::PI)
            })
            .collect();
        (u, x)
    }

    pub(super) fn pressure(n: usize, mean: f64) -> Vec<f64> {
        let e = crate::smooth::gaussian_noise(n, 3);
        (0..n)
            .map(|i| mean + 5e5 * (i as f64 * 3e-3).sin() + 2e4 * e[i])
            .collect()
    }

    #[test]
    fn a_clean_record_has_no_problems() {
        let (u, x) = moving(2000);
        let r = rec(&[
            (Signal::Command, u),
            (Signal::Position, x),
            (Signal::P1, pressure(2000, 3e6)),
            (Signal::P2, pressure(2000, 4e6)),
        ]);
        assert_eq!(check_record(&r, Some(&facts())), vec![]);
    }

    #[test]
    fn each_problem_is_named() {
        let (u, x) = moving(2000);
        let kinds = |cols: &[(Signal, Vec<f64>)]| -> Vec<(String, ProblemKind)> {
            check_record(&rec(cols), Some(&facts()))
                .into_iter()
                .map(|p| (p.channel, p.kind))
                .collect()
        };
        // stuck p1
        let k = kinds(&[
            (Signal::Command, u.clone()),
            (Signal::Position, x.clone()),
            (Signal::P1, vec![2e6; 2000]),
        ]);
        assert_eq!(k, [("p1".to_string(), ProblemKind::Constant)]);
        // pressures in Pa under [bar]: 1e5 times too large
        let big: Vec<f64> = pressure(2000, 3e6).iter().map(|p| p * 1e5).collect();
        let k = kinds(&[
            (Signal::Command, u.clone()),
            (Signal::Position, x.clone()),
            (Signal::P1, big),
        ]);
        assert_eq!(k, [("p1".to_string(), ProblemKind::Units)]);
        // bar under [Pa]: 1e5 times too small
        let small: Vec<f64> = pressure(2000, 3e6).iter().map(|p| p * 1e-5).collect();
        let k = kinds(&[(Signal::Command, u.clone()), (Signal::P2, small)]);
        assert_eq!(k, [("p2".to_string(), ProblemKind::Units)]);
        // position in m under [mm]: 1000 times too small
        let xs: Vec<f64> = x.iter().map(|v| v * 1e-3).collect();
        let k = kinds(&[(Signal::Command, u.clone()), (Signal::Position, xs)]);
        assert_eq!(k, [("position".to_string(), ProblemKind::Units)]);
        // position in mm under [m]: beyond the stroke
        let xl: Vec<f64> = x.iter().map(|v| v * 1e3).collect();
        let k = kinds(&[(Signal::Command, u.clone()), (Signal::Position, xl)]);
        assert_eq!(k, [("position".to_string(), ProblemKind::Units)]);
        // command sign flipped
        let un: Vec<f64> = u.iter().map(|v| -v).collect();
        let k = kinds(&[(Signal::Command, un), (Signal::Position, x.clone())]);
        assert_eq!(k, [("position".to_string(), ProblemKind::Sign)]);
        // a pressure clipped at 5 MPa (the supply is 7 MPa)
        let clipped: Vec<f64> = pressure(2000, 4.8e6).iter().map(|p| p.min(5e6)).collect();
        let k = kinds(&[
            (Signal::Command, u.clone()),
            (Signal::Position, x.clone()),
            (Signal::P1, clipped),
        ]);
        assert_eq!(k, [("p1".to_string(), ProblemKind::Clipped)]);
        // p2 in 1 bar steps while p1 resolves pascals
        let coarse: Vec<f64> = pressure(2000, 3e6)
            .iter()
            .map(|p| (p / 2e5).round() * 2e5)
            .collect();
        let k = kinds(&[
            (Signal::Command, u.clone()),
            (Signal::Position, x.clone()),
            (Signal::P1, pressure(2000, 3e6)),
            (Signal::P2, coarse),
        ]);
        assert_eq!(k, [("p2".to_string(), ProblemKind::Quantised)]);
    }

    /// A noise-free record whose piston rests at its lowest position for
    /// the first 5 % of the samples before it moves is not clipped; the same
    /// record clipped after it has moved (at the top, or at the bottom on
    /// each cycle) still is.
    #[test]
    fn a_rest_at_the_records_start_is_not_clipping() {
        let n = 2000;
        let w = 2.0 * std::f64::consts::PI * 0.7;
        let x: Vec<f64> = (0..n)
            .map(|i| {
                let t = (i as f64 * 1e-3 - 0.1).max(0.0);
                0.05 * (1.0 - (w * t).cos()) + 0.01 * t
            })
            .collect();
        let kinds = |x: Vec<f64>| -> Vec<(String, ProblemKind)> {
            check_record(&rec(&[(Signal::Position, x)]), None)
                .into_iter()
                .map(|p| (p.channel, p.kind))
                .collect()
        };
        assert_eq!(kinds(x.clone()), vec![]);
        let top: Vec<f64> = x.iter().map(|v| v.min(0.08)).collect();
        assert_eq!(kinds(top), [("position".to_string(), ProblemKind::Clipped)]);
        let bottom: Vec<f64> = x.iter().map(|v| (v - 0.03).max(0.0)).collect();
        assert_eq!(
            kinds(bottom),
            [("position".to_string(), ProblemKind::Clipped)]
        );
    }

    #[test]
    fn a_piston_resting_on_its_stop_is_not_clipping() {
        let n = 2000;
        let u = vec![1.0; n];
        let x: Vec<f64> = (0..n).map(|i| (i as f64 * 1e-3 * 0.2).min(0.25)).collect();
        let r = rec(&[(Signal::Command, u), (Signal::Position, x)]);
        assert_eq!(check_record(&r, Some(&facts())), vec![]);
    }

    /// One huge value in a pressure column (1e300 bar, row 502) is not a
    /// stuck or quantised sensor (it used to merge every other value into
    /// one level: "2 distinct levels"); it is a value above the supply.
    #[test]
    fn one_outlier_is_neither_constant_nor_quantised() {
        let (u, x) = moving(2000);
        let mut p1 = pressure(2000, 3e6);
        p1[500] = 1e305;
        let probs = check_record(
            &rec(&[
                (Signal::Command, u),
                (Signal::Position, x),
                (Signal::P1, p1),
                (Signal::P2, pressure(2000, 2e6)),
            ]),
            Some(&facts()),
        );
        let p1: Vec<_> = probs.iter().filter(|p| p.channel == "p1").collect();
        assert_eq!(p1.len(), 1, "{probs:?}");
        assert_eq!(p1[0].kind, ProblemKind::Units, "{probs:?}");
    }

    /// One position far off (1e305 m at row 502) is named at its row and
    /// column, not blamed on the time column's unit at row 1, and its
    /// ratio is written compactly (it was a 300-digit number).
    #[test]
    fn a_position_outlier_is_named_at_its_row() {
        let (u, mut x) = moving(2000);
        x[500] = 1e305;
        let r = rec(&[(Signal::Command, u.clone()), (Signal::Position, x)]);
        // the range checks judge the bulk of the channel: no unit problem
        // (no message holds the 300-digit number); the outlier is named
        let probs = check_record(&r, Some(&facts()));
        assert_eq!(probs, vec![]);
        assert!(probs.iter().all(|p| p.message.len() < 300), "{probs:?}");
        let e = unit_errors(&r, &facts(), &probs).unwrap_err().to_string();
        assert!(
            e.contains("row 502, column 'position'") && e.len() < 400,
            "{e}"
        );
        // a whole record in ms under [s] is still the time unit
        let (_, x) = moving(2000);
        let mut r = rec(&[(Signal::Command, u), (Signal::Position, x)]);
        r.time.iter_mut().for_each(|t| *t *= 1e-3);
        let e = unit_errors(&r, &facts(), &[]).unwrap_err().to_string();
        assert!(e.contains("row 1, column 'time'"), "{e}");
    }
}
