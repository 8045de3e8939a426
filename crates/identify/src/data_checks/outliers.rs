//! A handful of position samples beyond the stroke while the rest of the
//! channel stays within it: outliers (a logger glitch, a typo), named at
//! their rows, not a unit.

use super::{robust_range, DataProblem, ProblemKind, RigFacts};
use crate::data::{DataError, Record, Signal};
use crate::smooth::noise_sigma;

/// Most rows an outlier error lists (the count says how many there are).
const ROWS_LISTED: usize = 5;

/// How far from mid-stroke a position may read \[m\]: half the stroke,
/// plus 5 noise sigmas and 2 % of the stroke (a piston on its stop reads a
/// little past it in a real record).
pub(super) fn half_stroke_allowed(f: &RigFacts, sigma: f64) -> f64 {
    0.5 * f.stroke + 5.0 * sigma + 0.02 * f.stroke
}

/// Position samples beyond the stroke (outside ±(stroke/2 + 5σ + 2 % of it))
/// while the bulk of the channel, its 0.5th to 99.5th percentiles, stays
/// within it (the range check of [`super::check_record`] judges the bulk):
/// an error naming the first such sample's row and the position column,
/// with the count and the first few rows. A unit error moves the bulk of
/// the channel; one cell of 1000 mm in a record of ±100 mm is a glitch or a
/// typo (it used to be called a unit problem, "mm written as m?", and the
/// whole channel dropped). At most 0.5 % of the samples at either end can
/// be outliers; more move the percentiles, and the channel is a `units`
/// problem. Skipped when the position already has a problem (its scale is
/// then unknown).
pub fn position_outliers(
    rec: &Record,
    f: &RigFacts,
    problems: &[DataProblem],
) -> Result<(), DataError> {
    let Some(x) = rec.get(Signal::Position) else {
        return Ok(());
    };
    if x.len() < 2
        || problems
            .iter()
            .any(|p| p.channel == Signal::Position.name() && p.kind != ProblemKind::Missing)
    {
        return Ok(());
    }
    let mut sorted = x.to_vec();
    sorted.sort_by(f64::total_cmp);
    let (lo, hi) = super::range(x);
    let sigma = noise_sigma(&rec.time, x).min(robust_range(&sorted, hi - lo));
    let half = half_stroke_allowed(f, sigma);
    let beyond: Vec<usize> = (0..x.len()).filter(|&k| x[k].abs() > half).collect();
    let Some(&first) = beyond.first() else {
        return Ok(());
    };
    let column = match rec.units.get(&Signal::Position) {
        Some(u) => format!("position [{u}]"),
        None => "position".to_string(),
    };
    let rows: Vec<String> = beyond
        .iter()
        .take(ROWS_LISTED)
        .map(|&k| rec.row(k).to_string())
        .collect();
    let which = match beyond.len() {
        1 => "the only sample beyond it".to_string(),
        c => format!(
            "{c} samples beyond it, rows {}{}",
            rows.join(", "),
            if c > ROWS_LISTED { ", ..." } else { "" }
        ),
    };
    Err(DataError::Outlier {
        file: rec.source.clone(),
        row: rec.row(first),
        column,
        reason: format!(
            "position {} m is beyond the stroke ±{:.4} m while the bulk of the column stays within it: an outlier ({which}): a logger glitch or a typo? correct or remove the sample",
            super::num(x[first]),
            0.5 * f.stroke,
        ),
    })
}

#[cfg(test)]
mod tests {
    use super::position_outliers;
    use crate::data::{DataError, Signal};
    use crate::data_checks::tests::{facts, moving, rec};
    use crate::data_checks::{check_record, ProblemKind};

    fn noisy_position() -> (Vec<f64>, Vec<f64>) {
        let (u, x) = moving(2000);
        let e = crate::smooth::gaussian_noise(2000, 7);
        (u, x.iter().zip(&e).map(|(x, e)| x + 2e-5 * e).collect())
    }

    /// One position cell of 1 m (1000 mm) on a 0.5 m stroke, at sample 501
    /// (row 503): an outlier named at its row and column, not a `units`
    /// problem that drops the channel; likewise three of them.
    #[test]
    fn a_position_spike_is_an_outlier_at_its_row() {
        let (u, mut x) = noisy_position();
        x[501] = 1.0;
        let r = rec(&[(Signal::Command, u.clone()), (Signal::Position, x.clone())]);
        let probs = check_record(&r, Some(&facts()));
        assert_eq!(probs, vec![]);
        match position_outliers(&r, &facts(), &probs) {
            Err(e @ DataError::Outlier { .. }) => {
                let s = e.to_string();
                assert!(s.starts_with("test: row 503, column 'position'"), "{s}");
                assert!(s.contains("the only sample beyond it"), "{s}");
            }
            other => panic!("{other:?}"),
        }
        x[900] = -0.9;
        x[1500] = 0.4;
        let r = rec(&[(Signal::Command, u), (Signal::Position, x)]);
        let e = position_outliers(&r, &facts(), &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("3 samples beyond it, rows 503, 902, 1502"),
            "{e}"
        );
    }

    /// A clean position has no outlier; a position whose bulk is out of
    /// range (mm under `[m]`, or 2 % of the samples beyond the stroke) is
    /// still a `units` problem, and no outlier error.
    #[test]
    fn a_unit_error_moves_the_bulk() {
        let (u, x) = noisy_position();
        let r = rec(&[(Signal::Command, u.clone()), (Signal::Position, x.clone())]);
        assert_eq!(position_outliers(&r, &facts(), &[]), Ok(()));
        let mm: Vec<f64> = x.iter().map(|v| v * 1e3).collect();
        let r = rec(&[(Signal::Command, u.clone()), (Signal::Position, mm)]);
        let probs = check_record(&r, Some(&facts()));
        assert_eq!(probs[0].kind, ProblemKind::Units, "{probs:?}");
        assert_eq!(position_outliers(&r, &facts(), &probs), Ok(()));
        let mut many = x;
        for v in many.iter_mut().skip(100).step_by(50) {
            *v = 1.0;
        }
        let r = rec(&[(Signal::Command, u), (Signal::Position, many)]);
        let probs = check_record(&r, Some(&facts()));
        assert_eq!(probs[0].channel, "position", "{probs:?}");
        assert_eq!(probs[0].kind, ProblemKind::Units, "{probs:?}");
    }
}
