//! The signals a bench model runs on, prepared from a measured record:
//! smoothed velocity and acceleration, pressures, force.

use crate::data::{Record, Signal};

/// The signals of one record the bench model runs on (all SI, per sample).
#[derive(Clone, Debug, PartialEq)]
pub struct BenchSignals {
    /// Record name.
    pub source: String,
    /// Time \[s\].
    pub t: Vec<f64>,
    /// Position (smoothed, or integrated from measured velocity) \[m\].
    pub x: Vec<f64>,
    /// Velocity (smoothed derivative of position, or measured) \[m·s⁻¹\].
    pub v: Vec<f64>,
    /// Acceleration \[m·s⁻²\].
    pub a: Vec<f64>,
    /// Chamber pressure p1 (zero if not measured) \[Pa\].
    pub p1: Vec<f64>,
    /// Chamber pressure p2 (zero if not measured) \[Pa\].
    pub p2: Vec<f64>,
    /// Measured load-cell force \[N\].
    pub force: Vec<f64>,
}

/// Prepares a record for the bench: smoothed velocity and acceleration from
/// position (or measured velocity), pressures (zero where absent), force.
pub fn bench_signals(
    rec: &Record,
    half_window: Option<usize>,
    steady_state: bool,
) -> Result<(BenchSignals, crate::smooth::SmootherInfo), crate::data::DataError> {
    let force = rec.require(Signal::Force)?.to_vec();
    let t = rec.time.clone();
    let zeros = vec![0.0; t.len()];
    let p1 = rec
        .get(Signal::P1)
        .map_or_else(|| zeros.clone(), |p| p.to_vec());
    let p2 = rec
        .get(Signal::P2)
        .map_or_else(|| zeros.clone(), |p| p.to_vec());
    if steady_state {
        if half_window.is_some() {
            return Err(crate::data::DataError::WindowNotUsed {
                file: rec.source.clone(),
            });
        }
        let v = rec.require(Signal::Velocity)?.to_vec();
        let info = crate::smooth::SmootherInfo {
            method: "none (steady-state samples: measured velocity, zero acceleration)".into(),
            order: 0,
            half_window: 0,
            window_s: 0.0,
            criterion: "steady".into(),
            residual_rms: 0.0,
        };
        return Ok((
            BenchSignals {
                source: rec.source.clone(),
                x: zeros.clone(),
                a: zeros,
                t,
                v,
                p1,
                p2,
                force,
            },
            info,
        ));
    }
    let (x, v, a, info) = if let Some(x) = rec.get(Signal::Position) {
        let s = match half_window {
            Some(h) => crate::smooth::smooth_with(rec, x, h, crate::smooth::ORDER)?,
            None => crate::smooth::smooth_gcv(&t, x, crate::smooth::ORDER, 400),
        };
        (s.value, s.d1, s.d2, s.info)
    } else {
        let vel = rec.require(Signal::Velocity)?;
        let s = match half_window {
            Some(h) => crate::smooth::smooth_with(rec, vel, h, crate::smooth::ORDER)?,
            None => crate::smooth::smooth_gcv(&t, vel, crate::smooth::ORDER, 400),
        };
        let mut x = vec![0.0; t.len()];
        for i in 1..t.len() {
            x[i] = x[i - 1] + 0.5 * (s.value[i] + s.value[i - 1]) * (t[i] - t[i - 1]);
        }
        (x, s.value, s.d1, s.info)
    };
    Ok((
        BenchSignals {
            source: rec.source.clone(),
            t,
            x,
            v,
            a,
            p1,
            p2,
            force,
        },
        info,
    ))
}
