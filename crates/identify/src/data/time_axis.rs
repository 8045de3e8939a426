//! The time axis a record (or a command file) may have: a span of at most
//! [`MAX_SPAN_S`], and no interval that is both more than
//! [`MAX_GAP_FACTOR`] times the record's median interval and more than
//! [`GAP_OVER_REST`] times the rest of its span together. Both are checked
//! on reading: past them the time column holds a typo or a wrong unit
//! (`1e308`, a last time stamp of 1000 s after 12 s), and a model run across
//! it would integrate, for as long as it takes, an input nobody measured.
//! Uneven steps are allowed (the data format's rule): a record logged on
//! change, with long rests between its moves, is read, its long steps the
//! `gap` data problem.

use super::DataError;

/// The longest time span a record or command file may have \[s\] (about
/// 11.6 days): a longer span is a time column in the wrong unit or a typo
/// (`1e300`), which would otherwise run until the solver's step limit.
/// `hydrocyl simulate`'s command reader and the record reader share it.
pub const MAX_SPAN_S: f64 = 1.0e6;

/// An interval of the time axis over this many times the record's median
/// interval is an error (not a `gap` data problem, which starts at
/// [`crate::data_checks::GAP_FACTOR`] times): the input would be made up
/// for at least a hundred of the record's own samples.
pub const MAX_GAP_FACTOR: f64 = 100.0;

/// ... and over this many times the rest of the record's span together
/// (the span without it): one interval the record is mostly made of, not a
/// rest between measured moves.
pub const GAP_OVER_REST: f64 = 10.0;

/// `true` when time `t` lies more than [`MAX_SPAN_S`] after the first
/// sample `t0` (the one rule of every reader).
pub fn beyond_span(t0: f64, t: f64) -> bool {
    t - t0 > MAX_SPAN_S
}

/// The median of the intervals of `t` (`NaN` with fewer than 2 samples).
fn median_interval(t: &[f64]) -> f64 {
    if t.len() < 2 {
        return f64::NAN;
    }
    let mut dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let mid = dt.len() / 2;
    *dt.select_nth_unstable_by(mid, f64::total_cmp).1
}

/// Checks the (strictly increasing) time axis `t` of file `file`, column
/// `column`: the span ([`MAX_SPAN_S`]) first, then the gaps
/// ([`MAX_GAP_FACTOR`]). `row(k)` is sample `k`'s row (file line).
pub(super) fn check(
    file: &str,
    column: &str,
    t: &[f64],
    row: impl Fn(usize) -> usize,
) -> Result<(), DataError> {
    let Some(&t0) = t.first() else {
        return Ok(());
    };
    if let Some(k) = t.iter().position(|&tk| beyond_span(t0, tk)) {
        return Err(DataError::SpanTooLong {
            file: file.to_string(),
            row: row(k),
            column: column.to_string(),
            t: t[k],
            span: t[k] - t0,
        });
    }
    let median = median_interval(t);
    if median.is_nan() || median <= 0.0 {
        return Ok(());
    }
    let span = t[t.len() - 1] - t0;
    let absurd = |k: usize| {
        let step = t[k] - t[k - 1];
        step > MAX_GAP_FACTOR * median && step > GAP_OVER_REST * (span - step)
    };
    if let Some(k) = (1..t.len()).find(|&k| absurd(k)) {
        return Err(DataError::TimeGap {
            file: file.to_string(),
            row: row(k),
            column: column.to_string(),
            t: t[k],
            step: t[k] - t[k - 1],
            median,
        });
    }
    Ok(())
}

/// `true` when [`check`] finds nothing (the fast reader's test: it leaves
/// any error to the full reader, which names the row).
pub(super) fn fine(t: &[f64]) -> bool {
    check("", "", t, |k| k).is_ok()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn axis(last: f64) -> Vec<f64> {
        let mut t: Vec<f64> = (0..2000).map(|k| k as f64 * 0.006).collect();
        *t.last_mut().unwrap() = last;
        t
    }

    #[test]
    fn a_long_span_or_a_wide_gap_is_refused_with_its_row() {
        assert!(check("f", "time", &axis(11.994), |k| k + 2).is_ok());
        for last in [1e308, 1e9, 1e6 + 1.0] {
            let e = check("f", "time [s]", &axis(last), |k| k + 2).unwrap_err();
            assert!(matches!(e, DataError::SpanTooLong { row: 2001, .. }), "{e}");
            let m = e.to_string();
            assert!(
                m.contains("row 2001, column 'time [s]'") && m.len() < 300,
                "{m}"
            );
        }
        // 1000 s after 12 s: inside the span, a gap of 988 s
        let e = check("f", "time", &axis(1000.0), |k| k + 3).unwrap_err();
        assert!(matches!(e, DataError::TimeGap { row: 2002, .. }), "{e}");
        // a rest between measured moves, however long against the median
        // step (a record logged on change): a `gap` data problem at most
        let mut t = axis(11.994);
        for v in &mut t[1000..] {
            *v += 60.0;
        }
        assert!(check("f", "time", &t, |k| k + 2).is_ok());
        // one interval ten times the rest of the record together: an error
        for v in &mut t[1000..] {
            *v += 70.0;
        }
        assert!(check("f", "time", &t, |k| k + 2).is_err());
    }
}
