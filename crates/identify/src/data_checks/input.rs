//! The model's input against the record's motion: a command that never
//! changes while the piston moves drives nothing.

use super::{robust_range, RigFacts};
use crate::data::{DataError, Record, Signal};
use crate::smooth::noise_sigma;

/// The piston moves when its position spans, rises and falls by more than
/// this many noise sigmas (the span between the 0.5th and 99.5th
/// percentiles). White noise of sigma σ over a few thousand samples spans
/// about 7σ; 20σ is motion.
const MOVING_SIGMAS: f64 = 20.0;
/// ... and more than this share of the stroke (a sensor drifting by a few
/// tenths of a millimetre is not a moving piston).
const MOVING_STROKE: f64 = 0.01;

/// A `command` that reads the same value in every sample while the piston
/// moves both ways (a disconnected or unlogged command channel), as an
/// error naming the file and the command column: a constant input drives a
/// drive one way at most (a constant spool opening, a null bias's drift,
/// a step to a stop), so a piston that rises and falls by more than the
/// noise allows moves on an input the record does not hold, and any fit
/// would fit noise (a command of 0 under the back-and-forth motion of
/// `valve-none.csv` used to be diagnosed as a supply pressure of 86 bar).
/// A closed-loop record is driven by its `reference`; its command is
/// compared, not an input, and is not judged here. A constant command on a
/// piston at rest, or moving one way, is not an error.
pub fn input_errors(rec: &Record, f: &RigFacts) -> Result<(), DataError> {
    if rec.get(Signal::Reference).is_some() {
        return Ok(());
    }
    let (Some(u), Some(x)) = (rec.get(Signal::Command), rec.get(Signal::Position)) else {
        return Ok(());
    };
    if u.len() < 2 || x.len() < 2 {
        return Ok(());
    }
    let (lo, hi) = super::range(u);
    if hi - lo > 1e-12 * lo.abs().max(hi.abs()) {
        return Ok(());
    }
    let (xlo, xhi) = super::range(x);
    let mut sorted = x.to_vec();
    sorted.sort_by(f64::total_cmp);
    let span = robust_range(&sorted, xhi - xlo);
    let sigma = noise_sigma(&rec.time, x);
    let (rise, fall) = excursions(x);
    let moves = |d| is_motion(d, sigma, f.stroke);
    if !(moves(span) && moves(rise) && moves(fall)) {
        return Ok(());
    }
    let column = match rec.units.get(&Signal::Command) {
        Some(unit) => format!("command [{unit}]"),
        None => "command".to_string(),
    };
    Err(DataError::ConstantInput {
        file: rec.source.clone(),
        column,
        reason: format!(
            "the command reads {lo} in every sample while the piston moves over {span:.4} m: nothing in the record drives the model (a disconnected or unlogged command channel?); check the logged command column"
        ),
    })
}

/// Whether a travel `d` of the piston is motion: more than
/// [`MOVING_SIGMAS`] noise sigmas `sigma` and [`MOVING_STROKE`] of the
/// stroke.
pub(super) fn is_motion(d: f64, sigma: f64, stroke: f64) -> bool {
    d > MOVING_SIGMAS * sigma && d > MOVING_STROKE * stroke
}

/// The largest rise (a later sample above an earlier one) and the largest
/// fall of `x`.
fn excursions(x: &[f64]) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let (mut rise, mut fall) = (0.0f64, 0.0f64);
    for &v in x {
        lo = lo.min(v);
        hi = hi.max(v);
        rise = rise.max(v - lo);
        fall = fall.max(hi - v);
    }
    (rise, fall)
}

#[cfg(test)]
mod tests {
    use super::input_errors;
    use crate::data::{DataError, Signal};
    use crate::data_checks::tests::{facts, moving, rec};

    /// A command stuck at 0 while the piston moves (a disconnected
    /// channel) is an error naming the command column (it was diagnosed as
    /// a supply pressure of 86 bar).
    #[test]
    fn a_constant_command_on_a_moving_piston_is_an_error() {
        let (_, x) = moving(2000);
        let r = rec(&[(Signal::Command, vec![0.0; 2000]), (Signal::Position, x)]);
        match input_errors(&r, &facts()) {
            Err(e @ DataError::ConstantInput { .. }) => {
                let s = e.to_string();
                assert!(s.starts_with("test: row 1, column 'command'"), "{s}");
            }
            other => panic!("{other:?}"),
        }
    }

    /// A moving command, a constant command on a piston at rest (a record
    /// of a rest, position noise only), and a constant command on a piston
    /// moving one way (a constant opening, a null bias's drift) are not
    /// errors.
    #[test]
    fn a_moving_command_or_a_resting_piston_is_not_an_error() {
        let (u, x) = moving(2000);
        let r = rec(&[(Signal::Command, u), (Signal::Position, x)]);
        assert_eq!(input_errors(&r, &facts()), Ok(()));
        let e = crate::smooth::gaussian_noise(2000, 9);
        let still: Vec<f64> = e.iter().map(|v| 0.01 + 2e-5 * v).collect();
        let r = rec(&[
            (Signal::Command, vec![0.0; 2000]),
            (Signal::Position, still),
        ]);
        assert_eq!(input_errors(&r, &facts()), Ok(()));
        let ramp: Vec<f64> = (0..2000).map(|i| -0.1 + 1e-4 * i as f64).collect();
        let r = rec(&[(Signal::Command, vec![0.5; 2000]), (Signal::Position, ramp)]);
        assert_eq!(input_errors(&r, &facts()), Ok(()));
    }
}
