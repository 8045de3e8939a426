//! Units that contradict the rig, found in the record as a whole: errors
//! (not data problems) naming the file, the row and the column.

use super::{DataProblem, ProblemKind, RigFacts, GAIN_FACTOR};
use crate::data::{DataError, Record, Signal};

/// A unit that contradicts the rig, as an error naming the file, row 1 and
/// the column: a `command` written in volts on a rig whose command is a
/// normalised spool demand (or the other way round), and a time axis whose
/// unit makes the piston move far faster than the rig can (seconds under
/// `[ms]`: 1000 times). `problems` are the record's data problems (a
/// position already found in the wrong unit says nothing about time). One
/// position sample that alone makes the piston that fast is an error
/// naming its row and the position column.
pub fn unit_errors(rec: &Record, f: &RigFacts, problems: &[DataProblem]) -> Result<(), DataError> {
    let column = |s: Signal| match rec.units.get(&s) {
        Some(u) => format!("{} [{u}]", s.name()),
        None => s.name().to_string(),
    };
    if let (Some(want), Some(got)) = (f.command_unit, rec.units.get(&Signal::Command)) {
        // the unit's kind (per cent is a normalised demand, millivolts a
        // voltage: the reader has scaled them)
        let norm = |u: &str| match u {
            "1" | "%" => "-".to_string(),
            "mV" => "V".to_string(),
            _ => u.to_string(),
        };
        if norm(got) != norm(want) {
            let what = |u: &str| match u {
                "-" => "a normalised spool demand (unit `-`)",
                "V" => "a drive voltage (unit `V`)",
                _ => "in another unit",
            };
            return Err(DataError::UnitContradictsRig {
                file: rec.source.clone(),
                column: column(Signal::Command),
                reason: format!(
                    "the rig's command is {}, not {}: write the column as the rig takes it",
                    what(want),
                    what(got)
                ),
            });
        }
    }
    let (Some(g), Some(u), Some(x)) = (
        f.velocity_gain,
        rec.get(Signal::Command),
        rec.get(Signal::Position),
    ) else {
        return Ok(());
    };
    let n = x.len();
    if n < 50 || !(g.is_finite() && g > 0.0) {
        return Ok(());
    }
    // the fastest the rig can move the piston on this record's command
    let umax = u.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let vmax = g * umax;
    // block means (noise averaged out), about 50 blocks
    let fastest = fastest_block_speed(&rec.time, x);
    if fastest > GAIN_FACTOR * vmax {
        // one sample far off its neighbours (a glitch, a typo) makes the
        // piston fast at one place only: the sample, not the time unit
        if let Some(k) = spike(x) {
            let mut y = x.to_vec();
            y[k] = neighbours(x, k);
            if fastest_block_speed(&rec.time, &y) <= GAIN_FACTOR * vmax {
                return Err(DataError::Outlier {
                    file: rec.source.clone(),
                    row: rec.row(k),
                    column: column(Signal::Position),
                    reason: format!(
                        "position {:.4e} m is {:.3e} m off its neighbours: the piston would move at {fastest:.3e} m/s, {} times the rig's fastest ({vmax:.3e} m/s at this command): a logger glitch or a typo? correct or remove the sample",
                        x[k],
                        (x[k] - y[k]).abs(),
                        times(fastest / vmax)
                    ),
                });
            }
        }
        // (a single sample is named whatever the position's data problems)
        let position_bad = problems
            .iter()
            .any(|p| p.channel == Signal::Position.name() && p.kind == ProblemKind::Units);
        if position_bad {
            return Ok(());
        }
        let span = rec.time[n - 1] - rec.time[0];
        return Err(DataError::UnitContradictsRig {
            file: rec.source.clone(),
            column: column(Signal::Time),
            reason: format!(
                "the piston would move at {fastest:.3e} m/s, {} times the rig's fastest ({vmax:.3e} m/s at this command), over a record of {span:.4e} s: check the unit of the time column (seconds written under [ms]?)",
                times(fastest / vmax)
            ),
        });
    }
    Ok(())
}

/// A ratio for a message: whole below 1e4 (`468`), else `1.215e304`.
fn times(r: f64) -> String {
    if r < 1e4 {
        format!("{r:.0}")
    } else {
        format!("{r:.3e}")
    }
}

/// The fastest change of the block-mean position `x` per block-mean time
/// `t`, over about 50 blocks (noise averaged out) \[m/s\].
fn fastest_block_speed(t: &[f64], x: &[f64]) -> f64 {
    let b = (x.len() / 50).max(5);
    let means: Vec<(f64, f64)> = t
        .chunks(b)
        .zip(x.chunks(b))
        .map(|(tc, xc)| {
            let l = tc.len() as f64;
            (tc.iter().sum::<f64>() / l, xc.iter().sum::<f64>() / l)
        })
        .collect();
    means
        .windows(2)
        .map(|w| (w[1].1 - w[0].1).abs() / (w[1].0 - w[0].0))
        .fold(0.0, f64::max)
}

/// The mean of sample `k`'s neighbours in `x` (one at either end).
fn neighbours(x: &[f64], k: usize) -> f64 {
    match (k.checked_sub(1).map(|j| x[j]), x.get(k + 1)) {
        (Some(a), Some(&b)) => 0.5 * (a + b),
        (Some(a), None) => a,
        (None, Some(&b)) => b,
        (None, None) => x[k],
    }
}

/// The sample of `x` farthest off its neighbours' mean, if any.
fn spike(x: &[f64]) -> Option<usize> {
    (0..x.len())
        .map(|k| (k, (x[k] - neighbours(x, k)).abs()))
        .filter(|(_, d)| d.is_finite())
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .map(|(k, _)| k)
}
