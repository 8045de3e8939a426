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

/// Highest median chamber pressure taken as plausible on a bench \[Pa\]
/// (1000 bar: above any hydraulic supply).
const PLAUSIBLE_MAX_PA: f64 = 1e8;
/// Lowest median chamber pressure taken as plausible \[Pa\] (gauge: absolute
/// vacuum, with room for an offset of the transducer).
const PLAUSIBLE_MIN_PA: f64 = -1.5e5;

/// Scales a misread force column is tried at: the ratios of the force units
/// the reader takes (N, kN).
const FORCE_SCALES: [f64; 2] = [1e-3, 1e3];

/// Scales a misread pressure column is tried at: the ratios of the pressure
/// units the reader takes (Pa, kPa, bar, MPa, psi), both ways.
fn pressure_scales() -> Vec<f64> {
    let units = [1.0, 1e3, 1e5, 1e6, hydrocyl_ports::PSI_IN_PA];
    let mut out = Vec::new();
    for a in units {
        for b in units {
            if a != b {
                out.push(a / b);
            }
        }
    }
    out
}

/// How far the friction a record implies is from opposing the motion.
struct Imbalance {
    /// Median friction while extending \[N\].
    up: f64,
    /// Median friction while retracting \[N\].
    down: f64,
    /// The constant between them \[N\].
    offset: f64,
    /// Mean magnitude of the pressure force \[N\].
    pf_mean: f64,
}

/// The friction `s F f − m a + c (p1 A1 − p2 A2)` with the force scaled by
/// `f` and the pressures by `c`: `Some` when its medians while extending
/// and while retracting have the same sign and the constant between them
/// is more than a quarter of the pressure force; `None` when it opposes the
/// motion, or when there is no pressure or too little motion to tell.
fn imbalance(rig: &FrictionBench, s: &BenchSignals, f: f64, c: f64) -> Option<Imbalance> {
    let n = s.t.len();
    let pf: Vec<f64> = (0..n)
        .map(|i| c * (s.p1[i] * rig.area1 - s.p2[i] * rig.area2))
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
                rig.force_sign * f * s.force[i] - rig.mass * s.a[i] + pf[i],
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
    Some(Imbalance {
        up,
        down,
        offset,
        pf_mean,
    })
}

/// The median of each chamber pressure the bench's force uses (its area is
/// not zero), scaled by `c`, as `(name, value [Pa])`.
fn chamber_medians(rig: &FrictionBench, s: &BenchSignals, c: f64) -> Vec<(&'static str, f64)> {
    [("p1", rig.area1, &s.p1), ("p2", rig.area2, &s.p2)]
        .into_iter()
        .filter(|(_, area, p)| *area != 0.0 && !p.is_empty())
        .map(|(name, _, p)| {
            let mut v: Vec<f64> = p.iter().map(|x| c * x).collect();
            let mid = v.len() / 2;
            (name, *v.select_nth_unstable_by(mid, f64::total_cmp).1)
        })
        .collect()
}

/// Whether every chamber pressure the force uses, scaled by `c`, has a
/// median a hydraulic bench can have.
fn plausible(rig: &FrictionBench, s: &BenchSignals, c: f64) -> bool {
    chamber_medians(rig, s, c)
        .iter()
        .all(|(_, p)| (PLAUSIBLE_MIN_PA..=PLAUSIBLE_MAX_PA).contains(p))
}

/// Friction opposes the motion: on a bench whose pressure force is
/// computed from a measured pressure, the friction the record implies,
/// `s F − m a + p1 A1 − p2 A2`, must change sign with the velocity. When
/// its medians while extending and while retracting have the same sign and
/// the constant between them is more than a quarter of the pressure force,
/// the pressure force does not balance the load cell: one of the columns is
/// in another unit or scale than its header says. The force column is
/// blamed when the evidence points there: the pressures are plausible as
/// they are (median in [−1.5 bar, 1000 bar]), the force read in the other
/// force unit balances them, and no pressure unit that keeps them plausible
/// does; else the pressure column (a pressure twice what the record's force
/// balance implies: an offset of p A). `units` are the record's column
/// units (for the message). `None` when there is no pressure or too little
/// motion to tell.
pub(super) fn pressure_force_contradiction(
    rig: &FrictionBench,
    s: &BenchSignals,
    units: &BTreeMap<crate::data::Signal, String>,
) -> Option<String> {
    let Imbalance {
        up,
        down,
        offset,
        pf_mean,
    } = imbalance(rig, s, 1.0, 1.0)?;
    let leaves = format!(
        "the friction it leaves (s F − m a + p1 A1 − p2 A2) is {up:.4} N extending and {down:.4} N retracting, the same sign both ways, {offset:.4} N off against a pressure force of {pf_mean:.4} N"
    );
    let force_fix = FORCE_SCALES
        .into_iter()
        .find(|&f| imbalance(rig, s, f, 1.0).is_none());
    let pressure_fix = pressure_scales()
        .into_iter()
        .any(|c| plausible(rig, s, c) && imbalance(rig, s, 1.0, c).is_none());
    match force_fix {
        Some(f) if plausible(rig, s, 1.0) && !pressure_fix => {
            let pressures: Vec<String> = chamber_medians(rig, s, 1.0)
                .iter()
                .map(|(name, p)| format!("{name} {:.4} bar", p * 1e-5))
                .collect();
            let unit = units
                .get(&crate::data::Signal::Force)
                .map_or_else(|| "no unit in its header: N".to_string(), |u| u.clone());
            let times = if f < 1.0 {
                format!("{:.0}× what they give", 1.0 / f)
            } else {
                format!("1/{f:.0} of what they give")
            };
            Some(format!(
                "the load cell does not balance the pressure force: {leaves}; the pressures are plausible (median {}) and the force reads {times} (scaled by {f:e} it balances them): friction opposes the motion, so check the force column's unit and scale (written in {unit})",
                pressures.join(", ")
            ))
        }
        _ => Some(format!(
            "the pressure force does not balance the load cell: {leaves}: friction opposes the motion, so check the pressure column's unit and scale (and the rig's areas)"
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::Signal;
    use crate::synth::{declared_for, record, truth_with, Foreign, Noise};

    /// The bench record of the fixtures' `bench-none` shape (p2 about 5 bar,
    /// pressure force about 1 kN) with the force scaled by `f` and the
    /// pressure by `c`, the columns' units as written `units`; the check's
    /// message.
    fn message(f: f64, c: f64, units: &[(Signal, &str)]) -> Option<String> {
        let mut rec = record(
            &truth_with(&[]),
            2000,
            1e-3,
            Noise::default(),
            Foreign::None,
            1,
        );
        for (sig, k) in [(Signal::Force, f), (Signal::P2, c)] {
            rec.signals
                .get_mut(&sig)
                .unwrap()
                .iter_mut()
                .for_each(|x| *x *= k);
        }
        for (sig, u) in units {
            rec.units.insert(*sig, u.to_string());
        }
        let (s, _) = bench_signals(&rec, None, false).unwrap();
        pressure_force_contradiction(&declared_for(&[]), &s, &rec.units)
    }

    /// A record whose columns are what their headers say is no contradiction.
    #[test]
    fn a_consistent_record_passes() {
        assert_eq!(message(1.0, 1.0, &[]), None);
    }

    /// Values in N under a `force [kN]` header (tester t38d, D9): the force
    /// is 1000× what the pressures (plausible, about 5 bar) can give, and
    /// the force column is named with its unit, not the pressure's.
    #[test]
    fn a_force_in_the_wrong_unit_names_the_force_column() {
        let m = message(1e3, 1.0, &[(Signal::Force, "kN")]).unwrap();
        assert!(
            m.contains("check the force column's unit and scale (written in kN)"),
            "{m}"
        );
        assert!(
            m.contains("1000× what they give") && m.contains("median p2 "),
            "{m}"
        );
        assert!(!m.contains("pressure column"), "{m}");
    }

    /// The pressure stays blamed where the evidence points there: bar values
    /// under a `Pa` header (a pressure force of a hundredth of a newton,
    /// implausibly low pressures), and Pa values under a `bar` header
    /// (pressures of 10⁵ bar).
    #[test]
    fn a_pressure_in_the_wrong_unit_still_names_the_pressure_column() {
        for (c, unit) in [(1e-5, "Pa"), (1e5, "bar")] {
            let m = message(1.0, c, &[(Signal::P2, unit), (Signal::Force, "N")]).unwrap();
            assert!(
                m.contains("check the pressure column's unit and scale"),
                "{unit}: {m}"
            );
            assert!(!m.contains("force column"), "{unit}: {m}");
        }
    }
}
