//! The stall at a reversal: how long the piston stands still between the
//! command's reversal and its motion in the new direction (thesis 7.1–7.2,
//! Figs 7-4, 7-6, 7-9).
//!
//! **Definition.** The **total** time, from the command's reversal until the
//! piston's velocity first reaches half the target speed in the new
//! direction, during which `|v| <` [`STALL_SPEED`] (1 mm/s), with `v` linear
//! between samples.
//!
//! **Why the total and not the first contiguous run.** Where the piston
//! bounces through v = 0 on the oil spring of the closed chambers (the pilot
//! valve centred), the earlier measure (from the first sample below 1 mm/s to
//! the first sample above it in the new direction) took the first sample
//! below the threshold *after* the bounce as the start: it reported a 6 ms
//! "stall" for a reversal in which the piston was already retracting at
//! 17 mm/s, and none for one in which no sample fell below 1 mm/s. A bounce
//! through zero now counts only the time it spends inside ±1 mm/s.
//!
//! **What it undercounts.** At rest the LuGre bristle (σ0 = 3e7 N/m,
//! σ1 = 0.1 N·s/m, Table 5-8) is an almost undamped spring: a stuck piston
//! can ring in pre-sliding at ±2–3 mm/s with an amplitude of a few µm (below
//! the `Fs/σ0` = 6 µm the bristle allows before sliding). That ringing is
//! stationary to a potentiometer but counts only while it is inside ±1 mm/s,
//! so the measure is a lower bound there. A displacement-based measure
//! (position within a band, or a velocity averaged over an interval) was
//! tried and rejected: it counts a smooth turn at the square's 2–4 m/s²
//! deceleration as several ms of stall, or shortens a true dwell by the
//! averaging interval. A smooth turn at deceleration `a` counts `2 × 1 mm/s / a`
//! here (0.5–1 ms). docs/hybrid.md ("The stall at a reversal: which
//! measure") compares every candidate on the preset and on controls without
//! the charging interval: none of the velocity measures separates them, the
//! charging interval ([`super::Phenomena::charge_to_retract`]) does.
//!
//! **Sampling.** The ringing's period (~5 ms) is a few samples of the 1-ms
//! traces validate measures, so a ringing stall is resolved only to a few ms
//! there (chapter 7's 10-kg square: 4.3 ms on the 1-ms trace, 1.4 ms on a
//! 0.1-ms one); a stall without ringing (the preset's) agrees to 0.3 ms.

/// Speed below which the piston counts as stationary \[m·s⁻¹\].
pub const STALL_SPEED: f64 = 1.0e-3;

/// The stall at the reversal at sample `k` towards `dir` (+1 extending,
/// −1 retracting), looking no further than sample `end`: the time with
/// `|v| <` [`STALL_SPEED`] from `k` until `v · dir` first reaches
/// `half_speed` (module docs) \[s\]; `None` when it never does before `end`.
pub fn stall_at(
    t: &[f64],
    v: &[f64],
    k: usize,
    dir: f64,
    half_speed: f64,
    end: usize,
) -> Option<f64> {
    let end = end.min(t.len().min(v.len()).saturating_sub(1));
    let mut j = k;
    while j < end && v[j] * dir < half_speed {
        j += 1;
    }
    if j >= end {
        return None;
    }
    Some(
        (k..j)
            .map(|i| time_inside(t[i], t[i + 1], v[i], v[i + 1]))
            .sum(),
    )
}

/// Time within `[t0, t1]` during which the linear interpolant from `a` to `b`
/// lies strictly inside `±STALL_SPEED`.
fn time_inside(t0: f64, t1: f64, a: f64, b: f64) -> f64 {
    let thr = STALL_SPEED;
    if a == b {
        return if a.abs() < thr { t1 - t0 } else { 0.0 };
    }
    // parameter s in [0, 1] where the line crosses -thr and +thr
    let (lo, hi) = {
        let s1 = (-thr - a) / (b - a);
        let s2 = (thr - a) / (b - a);
        (s1.min(s2), s1.max(s2))
    };
    let (lo, hi) = (lo.max(0.0), hi.min(1.0));
    (hi - lo).max(0.0) * (t1 - t0)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(n: usize, dt: f64) -> Vec<f64> {
        (0..n).map(|k| k as f64 * dt).collect()
    }

    /// A piston stopped for 8 ms between two ramps stalls the 8 ms plus the
    /// ramps' time inside ±1 mm/s.
    #[test]
    fn a_dwell_is_its_length_plus_the_ramps_crossing() {
        let dt = 1e-4;
        let t = grid(2000, dt);
        // decelerating at 5 m/s² to rest at 50 ms, at rest until 58 ms,
        // accelerating at 5 m/s² after
        let v: Vec<f64> = t
            .iter()
            .map(|&s| {
                if s < 0.05 {
                    -5.0 * (0.05 - s)
                } else if s < 0.058 {
                    0.0
                } else {
                    5.0 * (s - 0.058)
                }
            })
            .collect();
        let s = stall_at(&t, &v, 300, 1.0, 0.025, t.len() - 1).unwrap();
        assert!((s - (8e-3 + 2.0 * 1e-3 / 5.0)).abs() < 1e-6, "{s}");
    }

    /// A bounce through zero counts only its time inside ±1 mm/s, not the
    /// time from the first sample below 1 mm/s after it.
    #[test]
    fn a_bounce_is_motion() {
        let dt = 1e-4;
        let t = grid(3000, dt);
        // one ±17 mm/s, 50 Hz bounce (20 ms, through zero at 0, 10 and
        // 20 ms), then retraction at 5 m/s²
        let w = 2.0 * std::f64::consts::PI * 50.0;
        let v: Vec<f64> = t
            .iter()
            .map(|&s| {
                if s < 0.02 {
                    -0.017 * (w * s).sin()
                } else {
                    -5.0 * (s - 0.02)
                }
            })
            .collect();
        let s = stall_at(&t, &v, 0, -1.0, 0.025, t.len() - 1).unwrap();
        // inside ±1 mm/s: ~1/(0.017 w) each side of the three zeros of the
        // bounce (0.19 + 0.37 + 0.19 ms) and 1/5 ms as the retraction starts
        let c = 1e-3 / (0.017 * w);
        let expected = 4.0 * c + 1e-3 / 5.0;
        assert!((s - expected).abs() < 0.05e-3, "{s} vs {expected}");
    }

    /// A smooth turn at constant deceleration counts 2 × 1 mm/s / a.
    #[test]
    fn a_smooth_turn_counts_only_its_crossing() {
        let dt = 1e-4;
        let t = grid(3000, dt);
        let a = 2.0;
        let v: Vec<f64> = t.iter().map(|&s| a * (s - 0.1)).collect();
        let s = stall_at(&t, &v, 500, 1.0, 0.025, t.len() - 1).unwrap();
        assert!((s - 2.0 * 1e-3 / a).abs() < 1e-9, "{s}");
    }

    #[test]
    fn no_reversal_reached_is_none() {
        let t = grid(100, 1e-3);
        let v = vec![0.0; 100];
        assert!(stall_at(&t, &v, 10, 1.0, 0.025, 99).is_none());
    }
}
