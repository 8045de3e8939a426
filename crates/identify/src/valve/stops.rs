//! End stops: where the measured piston rests on a stop, the record says
//! exactly where the piston is and that it is at rest. When the measured
//! piston leaves the stop, the open-loop simulation's piston is put back
//! there, at rest (its spool and chamber pressures carry on: at the stop
//! they hold what the model says, which is evidence), so that the
//! drift an integrating drive accumulates before a stop (a few per cent of
//! flow over seconds) does not carry into everything after it: each
//! segment between stop exits is then compared on its own dynamics.

use super::restart::{Cause, Restart};

/// Fewest consecutive samples at a stop that count as resting on it.
const MIN_REST: usize = 10;

/// The restarts of a record: the middle sample of every rest of at least
/// [`MIN_REST`] samples on a stop (within `tol` of ±stroke/2) that the
/// piston leaves before the record ends.
pub(super) fn restarts(x: &[f64], stroke: f64, tol: f64) -> Vec<Restart> {
    let half = 0.5 * stroke;
    let side = |v: f64| -> i8 {
        if (v - half).abs() <= tol {
            1
        } else if (v + half).abs() <= tol {
            -1
        } else {
            0
        }
    };
    let mut out = Vec::new();
    let n = x.len();
    let mut i = 0;
    while i < n {
        let s = side(x[i]);
        if s == 0 {
            i += 1;
            continue;
        }
        let start = i;
        while i + 1 < n && side(x[i + 1]) == s {
            i += 1;
        }
        let end = i;
        if end + 1 < n && end > 0 && end + 1 - start >= MIN_REST {
            // the middle of the rest: the measured piston may already be
            // leaving in its last samples, within the noise of the stop
            out.push(Restart {
                index: (start + end) / 2,
                cause: Cause::Stop,
                position: f64::from(s) * half,
                velocity: Some(0.0),
                pressures: [None; 2],
            });
        }
        i += 1;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn restarts_are_the_last_samples_at_rest_on_a_stop() {
        // rests at +0.25 (samples 20..40) and -0.25 (60..65, too short),
        // then on +0.25 to the end (no exit)
        let mut x = vec![0.0; 100];
        for (i, v) in x.iter_mut().enumerate() {
            *v = match i {
                20..40 => 0.25,
                60..65 => -0.25,
                90.. => 0.25,
                _ => 0.1,
            };
        }
        let r = restarts(&x, 0.5, 1e-6);
        assert_eq!(
            r,
            [Restart {
                index: 29,
                cause: Cause::Stop,
                position: 0.25,
                velocity: Some(0.0),
                pressures: [None; 2],
            }]
        );
    }
}
