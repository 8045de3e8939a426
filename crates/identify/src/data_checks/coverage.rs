//! What the record covers: gaps in its time axis, compared channels it
//! lacks, and pressures whose scale contradicts the declared rig's on the
//! same command.

use super::{problem, range, DataProblem, ProblemKind};
use crate::data::{Record, Signal};
use crate::smooth::noise_sigma;

/// A step longer than this many times the record's median step is a gap.
pub const GAP_FACTOR: f64 = 5.0;
/// Most gaps a message lists (the count says how many more there are).
const GAPS_LISTED: usize = 5;
/// A pressure whose level is this many times off the declared model's
/// (either way) contradicts its unit: bar under `[kPa]` is 100 times too
/// low, psi under `[kPa]` 6.9 times; a supply other than declared by the
/// 4 times the probes search is not flagged.
pub const SCALE_FACTOR: f64 = 5.0;
/// A simulated chamber's level below this share of the largest simulated
/// pressure level is a tank-side chamber: its own level says nothing about
/// units, the largest level is compared instead.
const TANK_SIDE: f64 = 0.2;

/// The gaps of a time axis: the median step and the index of the first
/// sample after each step longer than [`GAP_FACTOR`] times it (none for
/// fewer than 3 samples or a median step that is not positive). The data
/// check names them (the `gap` data problem); the valve loop restarts its
/// simulation after each from the measured state.
pub fn gap_ends(t: &[f64]) -> (f64, Vec<usize>) {
    if t.len() < 3 {
        return (f64::NAN, Vec::new());
    }
    let mut dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = dt.len() / 2;
    let median = *dt.select_nth_unstable_by(mid, f64::total_cmp).1;
    if median.is_nan() || median <= 0.0 {
        return (median, Vec::new());
    }
    let ends = (1..t.len())
        .filter(|&k| t[k] - t[k - 1] > GAP_FACTOR * median)
        .collect();
    (median, ends)
}

/// Gaps in the time axis ([`gap_ends`]). One problem on `time`, kept (not
/// left out): every sample either side is a real measurement, but the input
/// (the command, or a closed-loop record's reference) is interpolated
/// linearly across each gap, so the model there runs on an input nobody
/// measured; a circuit rig's simulation restarts after each gap from the
/// measured state.
pub(super) fn gap_problem(rec: &Record) -> Option<DataProblem> {
    let t = &rec.time;
    let (median, ends) = gap_ends(t);
    let gaps: Vec<(f64, f64)> = ends.iter().map(|&k| (t[k - 1], t[k])).collect();
    if gaps.is_empty() {
        return None;
    }
    let input = if rec.get(Signal::Reference).is_some() {
        "reference"
    } else {
        "command"
    };
    let listed: Vec<String> = gaps
        .iter()
        .take(GAPS_LISTED)
        .map(|(a, b)| format!("{:.4} s from {a:.4} s to {b:.4} s", b - a))
        .collect();
    let more = if gaps.len() > GAPS_LISTED {
        format!(" and {} more", gaps.len() - GAPS_LISTED)
    } else {
        String::new()
    };
    let total: f64 = gaps.iter().map(|(a, b)| b - a).sum();
    let mut p = problem(
        Signal::Time,
        ProblemKind::Gap,
        format!(
            "{} gap(s) in the record, steps over {GAP_FACTOR} times its median step ({median:.3e} s), {total:.4} s in all: {}{more}; the {input} (the model's input) is interpolated linearly across each, so the model runs there on an input nobody measured: a dropped logger buffer? the channels stay in the fit (their samples are measured); a circuit rig's simulation restarts after each gap from the measured position (and velocity and chamber pressures, where measured), so what it drifted across the gap does not count as the model's",
            gaps.len(),
            listed.join(", ")
        ),
    );
    p.left_out = false;
    Some(p)
}

/// The channels of `compared` that the record lacks: one problem each
/// (kind `missing`), the channel not compared, so no effect is judged on it.
pub fn missing_channels(rec: &Record, compared: &[Signal]) -> Vec<DataProblem> {
    let mut out: Vec<DataProblem> = compared
        .iter()
        .filter(|s| rec.get(**s).is_none())
        .map(|&s| {
            let name = s.name();
            problem(
                s,
                ProblemKind::Missing,
                format!("the record has no {name} column{}: {name} is not compared (the model's {name} is simulated, but nothing checks it and no effect is judged on it)", crate::data::unread_header_hint(&rec.ignored, name)),
            )
        })
        .collect();
    for p in &mut out {
        p.file.clone_from(&rec.source);
    }
    out
}

/// The level of a pressure: the larger magnitude of its 2nd and 98th
/// percentiles (gauge; a few spikes do not count).
fn level(y: &[f64]) -> f64 {
    let mut v: Vec<f64> = y.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    let at = |q: f64| v[((v.len() - 1) as f64 * q).round() as usize];
    at(0.02).abs().max(at(0.98).abs())
}

/// Pressures whose scale contradicts the declared model's on the same
/// command: `simulated` holds the declared model's channels (any; the
/// pressures `p1`, `p2`, `ps` among them are judged). A measured pressure
/// whose level (the larger magnitude of its 2nd and 98th percentiles) is over [`SCALE_FACTOR`] times below the
/// simulated one, or above it by more than that and five noise sigmas, is
/// in another unit than its header says (bar under `[kPa]`). Whatever the
/// rig, its pressures are set by its supply, relief and load, which the
/// declared model has; a wrong supply or leak moves them by far less. A
/// tank-side chamber (simulated level under a fifth of the largest) is
/// compared with the largest simulated level, not its own.
pub fn pressure_scale_problems(rec: &Record, simulated: &[(Signal, &[f64])]) -> Vec<DataProblem> {
    let pressures: Vec<(Signal, &[f64], f64)> = simulated
        .iter()
        .filter(|(s, _)| matches!(s, Signal::P1 | Signal::P2 | Signal::Ps))
        .map(|(s, y)| (*s, *y, level(y)))
        .collect();
    let top = pressures.iter().map(|p| p.2).fold(0.0, f64::max);
    if !(top.is_finite() && top > 0.0) {
        return vec![];
    }
    let mut out = Vec::new();
    for (s, _, sim) in pressures {
        let Some(y) = rec.get(s) else { continue };
        let meas = level(y);
        let sigma = noise_sigma(&rec.time, y);
        let (lo, hi) = range(y);
        let name = s.name();
        let unit = rec.units.get(&s).map_or("Pa", String::as_str);
        let said = format!("{name} reaches [{lo:.4e}, {hi:.4e}] Pa ({unit} in the header)");
        let msg = if sim >= TANK_SIDE * top && meas * SCALE_FACTOR < sim {
            Some(format!(
                "{said}, {:.3e} times the declared model's level on this command ({sim:.3e} Pa): check the unit of the column (bar written under [kPa]?), or whether the rig's supply pressure and load are this drive's",
                meas / sim
            ))
        } else if meas - 5.0 * sigma > SCALE_FACTOR * sim.max(TANK_SIDE * top) {
            Some(format!(
                "{said}, {:.3e} times the declared model's level on this command ({:.3e} Pa): check the unit of the column (kPa written under [bar]?), or whether the rig's supply pressure and load are this drive's",
                meas / sim.max(TANK_SIDE * top),
                sim.max(TANK_SIDE * top)
            ))
        } else {
            None
        };
        if let Some(m) = msg {
            let mut p = problem(s, ProblemKind::Units, m);
            p.file.clone_from(&rec.source);
            out.push(p);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn rec(time: Vec<f64>, cols: &[(Signal, Vec<f64>)]) -> Record {
        Record {
            source: "test".into(),
            time,
            signals: cols.iter().cloned().collect::<BTreeMap<_, _>>(),
            ignored: vec![],
            units: Default::default(),
            lines: Vec::new(),
        }
    }

    #[test]
    fn a_dropout_is_a_gap_kept_in_the_fit() {
        // 1 kHz, rows from 1.2 s to 1.5 s removed
        let time: Vec<f64> = (0..2000)
            .map(|i| i as f64 * 1e-3)
            .filter(|t| !(*t > 1.2005 && *t < 1.4995))
            .collect();
        let n = time.len();
        let r = rec(time, &[(Signal::Command, vec![0.0; n])]);
        let p = gap_problem(&r).unwrap();
        assert_eq!(
            (p.channel.as_str(), p.kind, p.left_out),
            ("time", ProblemKind::Gap, false)
        );
        assert!(
            p.message.contains("0.3000 s from 1.2000 s to 1.5000 s"),
            "{}",
            p.message
        );
        assert!(p.message.contains("command"), "{}", p.message);
        // uneven steps of a jittered logger are not gaps
        let time: Vec<f64> = (0..2000)
            .map(|i| i as f64 * 1e-3 + 4e-4 * ((i * 7) % 3) as f64)
            .collect();
        let r = rec(time, &[(Signal::Command, vec![0.0; 2000])]);
        assert_eq!(gap_problem(&r), None);
    }

    #[test]
    fn a_missing_compared_channel_is_named() {
        let time: Vec<f64> = (0..10).map(|i| i as f64 * 1e-3).collect();
        let r = rec(time, &[(Signal::P1, vec![1e6; 10])]);
        let m = missing_channels(&r, &[Signal::P1, Signal::P2]);
        assert_eq!(m.len(), 1);
        assert_eq!(
            (m[0].channel.as_str(), m[0].kind),
            ("p2", ProblemKind::Missing)
        );
        assert!(m[0].left_out && m[0].message.contains("not compared"));
    }

    #[test]
    fn a_pressure_scale_off_the_declared_models_is_named_both_ways() {
        let n = 1000;
        let time: Vec<f64> = (0..n).map(|i| i as f64 * 1e-3).collect();
        let e = crate::smooth::gaussian_noise(n, 9);
        let p = |mean: f64, k: f64| -> Vec<f64> {
            (0..n)
                .map(|i| k * (mean + 5e5 * (i as f64 * 6e-3).sin()) + 2e4 * e[i])
                .collect()
        };
        let (s1, s2) = (p(3e6, 1.0), p(0.0, 1.0));
        let sim = [(Signal::P1, &s1[..]), (Signal::P2, &s2[..])];
        let kinds = |r: &Record| -> Vec<String> {
            pressure_scale_problems(r, &sim)
                .into_iter()
                .map(|p| p.channel)
                .collect()
        };
        // honest: a tank-side p2 at a few bar is not flagged
        let ok = rec(
            time.clone(),
            &[(Signal::P1, p(3.3e6, 1.0)), (Signal::P2, p(1e5, 1.0))],
        );
        assert!(kinds(&ok).is_empty());
        // bar under [kPa]: 100 times too low
        let low = rec(
            time.clone(),
            &[(Signal::P1, p(3e6, 0.01)), (Signal::P2, p(0.0, 0.01))],
        );
        assert_eq!(kinds(&low), ["p1"]);
        // kPa under [bar]: 100 times too high, the tank side too
        let high = rec(
            time,
            &[(Signal::P1, p(3e6, 100.0)), (Signal::P2, p(0.0, 100.0))],
        );
        assert_eq!(kinds(&high), ["p1", "p2"]);
    }
}
