//! Restarts of the open-loop simulation from the measured state, where the
//! record says where the piston is and the simulation's own account of it
//! should not carry on: where the measured piston leaves an end stop
//! ([`super::stops`]: put on the stop, at rest), and at the first sample
//! after a gap in the time axis ([`after_gaps`]: a dropped logger buffer,
//! across which the input is interpolated and the motion nobody measured;
//! put where it was measured). The states the record does not give carry
//! on from the simulation before the restart.

use crate::data_checks::gap_ends;

/// Why the simulation restarts.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Cause {
    /// The measured piston leaves an end stop.
    Stop,
    /// The first sample after a gap in the time axis.
    Gap,
}

impl Cause {
    /// What the record does there, in a message (`the record rests on a
    /// stop`).
    pub(super) fn what(self) -> &'static str {
        match self {
            Cause::Stop => "rests on a stop",
            Cause::Gap => "has a gap in its time axis",
        }
    }
}

/// A restart of the simulation from the measured state.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Restart {
    /// Sample index where the new segment starts.
    pub index: usize,
    /// Why.
    pub cause: Cause,
    /// The piston's position \[m\].
    pub position: f64,
    /// Its velocity \[m/s\]; `None`: the simulation's carries on.
    pub velocity: Option<f64>,
    /// The chamber pressures p1, p2 \[Pa\]; `None`: the simulation's carry on.
    pub pressures: [Option<f64>; 2],
}

/// The measured channels a gap restart puts into the simulation (each
/// `None` where the record has none, or it is left out of the fit).
#[derive(Clone, Copy)]
pub(super) struct Measured<'a> {
    /// Position \[m\].
    pub position: &'a [f64],
    /// Velocity \[m/s\], only as measured (a derivative of the noisy
    /// position across a gap would be the smoother's guess).
    pub velocity: Option<&'a [f64]>,
    /// Chamber pressures \[Pa\].
    pub p1: Option<&'a [f64]>,
    /// The other chamber's.
    pub p2: Option<&'a [f64]>,
}

/// A restart at the first sample after each gap of time axis `t`
/// ([`gap_ends`], the rule of the `gap` data problem), from the samples
/// measured there; the position within ±`half_stroke`.
pub(super) fn after_gaps(t: &[f64], m: Measured<'_>, half_stroke: f64) -> Vec<Restart> {
    let at = |y: Option<&[f64]>, k: usize| y.and_then(|y| y.get(k).copied());
    gap_ends(t)
        .1
        .into_iter()
        .filter(|&k| k + 1 < t.len())
        .map(|k| Restart {
            index: k,
            cause: Cause::Gap,
            position: m.position[k].clamp(-half_stroke, half_stroke),
            velocity: at(m.velocity, k),
            pressures: [at(m.p1, k), at(m.p2, k)],
        })
        .collect()
}

/// Both kinds of restart in the order of their samples, one per sample (a
/// stop's, whose position is exact, where both fall on one).
pub(super) fn merged(mut stops: Vec<Restart>, gaps: Vec<Restart>) -> Vec<Restart> {
    for g in gaps {
        if !stops.iter().any(|s| s.index == g.index) {
            stops.push(g);
        }
    }
    stops.sort_by_key(|r| r.index);
    stops
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A restart after each gap (5 times the median step), from the samples
    /// measured there; none after a last sample; a stop's wins a sample
    /// both fall on.
    #[test]
    fn a_gap_restarts_from_the_samples_measured_after_it() {
        let t = [0.0, 0.001, 0.002, 0.003, 0.010, 0.011, 0.012, 0.020];
        let x = [0.0, 0.1, 0.2, 0.3, 0.6, 0.5, 0.4, 0.3];
        let p1 = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0];
        let m = Measured {
            position: &x,
            velocity: None,
            p1: Some(&p1),
            p2: None,
        };
        let r = after_gaps(&t, m, 0.5);
        assert_eq!(
            r,
            [Restart {
                index: 4,
                cause: Cause::Gap,
                position: 0.5,
                velocity: None,
                pressures: [Some(5.0), None],
            }]
        );
        let stop = Restart {
            cause: Cause::Stop,
            velocity: Some(0.0),
            pressures: [None; 2],
            ..r[0]
        };
        let early = Restart { index: 2, ..stop };
        assert_eq!(merged(vec![stop], r.clone()), [stop]);
        assert_eq!(merged(vec![stop, early], r), [early, stop]);
    }
}
