//! The force balance of the two chamber pressures: pressures in another
//! unit than their headers say, or the two columns swapped.

use super::{problem, DataProblem, ProblemKind, RigFacts, BALANCE_FACTOR};
use crate::data::{Record, Signal};

/// With p1 and p2 exchanged, a balance coefficient within this factor of 1
/// (either way) says the columns are swapped. A swap gives about (A1/A2)²
/// (1.3 to 4 on real cylinders) and exchanged columns about 1; a unit error
/// by a factor s on one column gives s, and exchanged about (A1/A2)²/s,
/// which lands within 1.25 of 1 only where s is within 1.25 of (A1/A2)²
/// (psi and bar, 14.5, would need A1/A2 between 3.4 and 4.3). The wider
/// band of the unit test ([1/3, 3]) would call bar under `[psi]` a swap on
/// a cylinder with A1/A2 = 2.2.
const SWAP_BAND: f64 = 1.25;

/// The balance coefficient on `p2 A2` (the rig's `1`) and its standard
/// error.
struct Balance {
    gain: f64,
    se: f64,
}

/// Pressure channels that contradict the rig's force balance: with the
/// piston off its stops, `p1 A1 − m a` must follow `p2 A2` (plus a constant
/// load and friction, fitted alongside as `c + f tanh(v/5 mm/s) + b v`); a
/// coefficient on `p2 A2` far from 1 means the two pressures are not in the
/// same unit (bar under `[psi]` reads 14.5 times too low), or that the two
/// columns are swapped. Which of the two columns is wrong the balance cannot
/// tell, so both are named (and left out); when the same fit with the two
/// columns exchanged balances the piston (its coefficient within
/// [`SWAP_BAND`] of 1, pinned down as well), the message says the columns
/// look swapped.
pub(super) fn balance_problems(rec: &Record, f: &RigFacts) -> Vec<DataProblem> {
    let Some((a1, a2)) = f.areas else {
        return vec![];
    };
    let (Some(p1), Some(p2), Some(x)) = (
        rec.get(Signal::P1),
        rec.get(Signal::P2),
        rec.get(Signal::Position),
    ) else {
        return vec![];
    };
    if !(a1 > 0.0 && a2 > 0.0) {
        return vec![];
    }
    let Some(b) = balance(&rec.time, x, p1, p2, (a1, a2), f) else {
        return vec![];
    };
    let passes = |b: &Balance| (1.0 / BALANCE_FACTOR..=BALANCE_FACTOR).contains(&b.gain);
    // judged only where the record pins the coefficient down
    if !(b.se < 0.1 && b.gain.is_finite()) || passes(&b) {
        return vec![];
    }
    let (gain, se) = (b.gain, b.se);
    let swapped = balance(&rec.time, x, p2, p1, (a1, a2), f)
        .filter(|s| s.se < 0.1 && (1.0 / SWAP_BAND..=SWAP_BAND).contains(&s.gain));
    let message = match swapped {
        Some(s) => format!(
            "p1 and p2 do not balance the piston: p1 A1 − m a ≈ {gain:.3} × p2 A2 (± {se:.2}; 1 on this rig, whatever the load and friction), but with the two columns exchanged it is {:.3} × (± {:.2}): p1 and p2 look swapped; check which column is the cap side (p1, area A1); both left out",
            s.gain, s.se
        ),
        None => {
            let unit_of = |s: Signal| rec.units.get(&s).map_or("Pa", String::as_str).to_string();
            let (u1, u2) = (unit_of(Signal::P1), unit_of(Signal::P2));
            format!("p1 and p2 do not balance the piston: p1 A1 − m a ≈ {gain:.3} × p2 A2 (± {se:.2}; 1 on this rig, whatever the load and friction): one of the two columns (p1 in {u1}, p2 in {u2}) is in another unit than its header says; both left out")
        }
    };
    [Signal::P1, Signal::P2]
        .into_iter()
        .map(|s| problem(s, ProblemKind::Units, message.clone()))
        .collect()
}

/// The least-squares fit of `p1 A1 − m a` on `p2 A2`, a constant and
/// friction, off the stops (velocity and acceleration from central
/// differences over about 50 ms); `None` where the record is too short or
/// the fit singular.
fn balance(
    t: &[f64],
    x: &[f64],
    p1: &[f64],
    p2: &[f64],
    (a1, a2): (f64, f64),
    f: &RigFacts,
) -> Option<Balance> {
    let n = t.len();
    if n < 50 {
        return None;
    }
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    let k = ((0.025 / dt).round() as usize).clamp(1, n / 4);
    let mut xtx = nalgebra::Matrix4::<f64>::zeros();
    let mut xty = nalgebra::Vector4::<f64>::zeros();
    let mut rows: Vec<(nalgebra::Vector4<f64>, f64)> = Vec::new();
    for i in k..n - k {
        if x[i].abs() > 0.45 * f.stroke {
            continue;
        }
        let (hm, hp) = (t[i] - t[i - k], t[i + k] - t[i]);
        let v = (x[i + k] - x[i - k]) / (hm + hp);
        let a = 2.0 * ((x[i + k] - x[i]) / hp - (x[i] - x[i - k]) / hm) / (hm + hp);
        let row = nalgebra::Vector4::new(p2[i] * a2, 1.0, (v / 5e-3).tanh(), v);
        let y = p1[i] * a1 - f.mass * a;
        xtx += row * row.transpose();
        xty += row * y;
        rows.push((row, y));
    }
    let m = rows.len();
    if m < 50 {
        return None;
    }
    let inv = xtx.try_inverse()?;
    let beta = inv * xty;
    let rss: f64 = rows.iter().map(|(r, y)| (y - r.dot(&beta)).powi(2)).sum();
    let se = (rss / (m - 4) as f64 * inv[(0, 0)]).max(0.0).sqrt();
    Some(Balance { gain: beta[0], se })
}

#[cfg(test)]
mod tests {
    use crate::data::Signal;
    use crate::data_checks::tests::{facts, moving, pressure, rec};
    use crate::data_checks::{check_record, ProblemKind, RigFacts};

    /// A record whose pressures balance the piston (A1 = 2e-3, A2 = 1e-3
    /// m², 100 kg, a 500 N load and 200 N of Coulomb friction), with its
    /// p1 and p2 as given by `f`.
    fn balanced(
        f: impl Fn(Vec<f64>, Vec<f64>) -> (Vec<f64>, Vec<f64>),
    ) -> Vec<(String, ProblemKind, String)> {
        let n = 2000;
        let (u, x) = moving(n);
        let w = 2.0 * std::f64::consts::PI;
        let p2 = pressure(n, 4e6);
        let e = crate::smooth::gaussian_noise(n, 11);
        let p1: Vec<f64> = (0..n)
            .map(|i| {
                let t = i as f64 * 1e-3;
                let (v, a) = (0.2 * (w * t).sin(), 0.2 * w * (w * t).cos());
                (p2[i] * 1e-3 + 100.0 * a + 500.0 + 200.0 * (v / 5e-3).tanh()) / 2e-3 + 2e4 * e[i]
            })
            .collect();
        let (p1, p2) = f(p1, p2);
        let facts = RigFacts {
            areas: Some((2e-3, 1e-3)),
            ..facts()
        };
        check_record(
            &rec(&[
                (Signal::Command, u),
                (Signal::Position, x),
                (Signal::P1, p1),
                (Signal::P2, p2),
            ]),
            Some(&facts),
        )
        .into_iter()
        .map(|p| (p.channel, p.kind, p.message))
        .collect()
    }

    #[test]
    fn balanced_pressures_have_no_problem() {
        assert_eq!(balanced(|p1, p2| (p1, p2)), vec![]);
    }

    /// p1 and p2 exchanged balance at about (A1/A2)² = 4: both named, the
    /// message says they look swapped (it said "another unit").
    #[test]
    fn swapped_pressures_are_named_as_swapped() {
        let probs = balanced(|p1, p2| (p2, p1));
        assert_eq!(probs.len(), 2, "{probs:?}");
        for (ch, kind, msg) in &probs {
            assert!(ch == "p1" || ch == "p2");
            assert_eq!(*kind, ProblemKind::Units);
            assert!(msg.contains("look swapped"), "{msg}");
        }
    }

    /// p2 in psi under a bar header (14.5 times too low) is a unit, not a
    /// swap: exchanged, the columns balance at about 4/14.5.
    #[test]
    fn a_pressure_in_another_unit_is_not_called_swapped() {
        let probs = balanced(|p1, p2| (p1, p2.iter().map(|p| p / 14.5).collect()));
        assert_eq!(probs.len(), 2, "{probs:?}");
        for (_, kind, msg) in &probs {
            assert_eq!(*kind, ProblemKind::Units);
            assert!(
                msg.contains("another unit") && !msg.contains("swapped"),
                "{msg}"
            );
        }
    }
}
