//! Checks of a friction bench's records before the loop: the data
//! problems kept as they are, and a pressure force that contradicts the
//! load cell.

use super::*;

/// A data problem on a friction bench, where nothing is left out: the
/// motion and the chamber pressures are the model's inputs (the drive
/// imposes the motion; the pressure force is computed from the measured
/// pressure), and the force is the one compared channel. The message says
/// what keeping it means.
pub(super) fn kept_on_bench(
    mut p: crate::data_checks::DataProblem,
) -> crate::data_checks::DataProblem {
    let why = match p.channel.as_str() {
        "p1" | "p2" | "ps" => "kept: an input of the bench (its pressure force is computed from it), not a compared channel: its steps reach the predicted force as they are",
        "force" => "kept: the bench's only compared channel",
        _ => "kept: the motion is an input of the bench (imposed by the drive), not a compared channel",
    };
    p.message = format!("{}; {why}", p.message);
    p.left_out = false;
    p
}

/// Friction opposes the motion: on a bench whose pressure force is
/// computed from a measured pressure, the friction the record implies,
/// `s F − m a + p1 A1 − p2 A2`, must change sign with the velocity. When
/// its medians while extending and while retracting have the same sign and
/// the constant between them is more than a quarter of the pressure force,
/// the pressure force does not balance the load cell: the pressure is in
/// another unit or scale than its header says (a pressure twice what the
/// record's force balance implies: an offset of p A). `None` when there is
/// no pressure or too little motion to tell.
pub(super) fn pressure_force_contradiction(
    rig: &FrictionBench,
    s: &BenchSignals,
) -> Option<String> {
    let n = s.t.len();
    let pf: Vec<f64> = (0..n)
        .map(|i| s.p1[i] * rig.area1 - s.p2[i] * rig.area2)
        .collect();
    let pf_mean = pf.iter().map(|v| v.abs()).sum::<f64>() / n.max(1) as f64;
    if n < 50 || pf_mean <= 0.0 {
        return None;
    }
    let vmax = s.v.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    let ff: Vec<(f64, f64)> = (0..n)
        .filter(|&i| s.v[i].abs() > 0.2 * vmax)
        .map(|i| {
            (
                s.v[i],
                rig.force_sign * s.force[i] - rig.mass * s.a[i] + pf[i],
            )
        })
        .collect();
    let median = |mut v: Vec<f64>| -> Option<f64> {
        if v.len() < 10 {
            return None;
        }
        let mid = v.len() / 2;
        Some(*v.select_nth_unstable_by(mid, f64::total_cmp).1)
    };
    let up = median(
        ff.iter()
            .filter(|(v, _)| *v > 0.0)
            .map(|(_, f)| *f)
            .collect(),
    )?;
    let down = median(
        ff.iter()
            .filter(|(v, _)| *v < 0.0)
            .map(|(_, f)| *f)
            .collect(),
    )?;
    let offset = 0.5 * (up + down);
    if up > 0.0 && down < 0.0 || offset.abs() <= 0.25 * pf_mean {
        return None;
    }
    Some(format!(
        "the pressure force does not balance the load cell: the friction it leaves (s F − m a + p1 A1 − p2 A2) is {up:.4} N extending and {down:.4} N retracting, the same sign both ways, {offset:.4} N off against a pressure force of {pf_mean:.4} N: friction opposes the motion, so check the pressure column's unit and scale (and the rig's areas)"
    ))
}
