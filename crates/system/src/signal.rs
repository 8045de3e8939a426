//! Command signals: square with bias, sine, sawtooth, step, ramp and a
//! sampled table with first-order hold (the CSV-given command), and a value
//! set from outside between solver calls (a co-simulation input).

use crate::external::ExternalInput;
use serde::{Deserialize, Serialize};
use std::cell::Cell;
use std::sync::Arc;
pub use streamed::StreamedTable;
use thiserror::Error;

mod streamed;

/// A bad signal definition; names the field and the value.
#[derive(Clone, Debug, Error, PartialEq)]
pub enum SignalError {
    /// A parameter out of range.
    #[error("signal parameter `{what}` = {value}: {why}")]
    Parameter {
        /// The parameter.
        what: &'static str,
        /// Its value.
        value: f64,
        /// What is wrong.
        why: &'static str,
    },
    /// A table sample is bad.
    #[error("command sample {row}: {why}")]
    Table {
        /// 0-based sample index.
        row: usize,
        /// What is wrong.
        why: String,
    },
}

/// A scalar signal of time (a normalised valve command, a drive voltage).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case", deny_unknown_fields)]
pub enum Signal {
    /// `value` for all t.
    Constant {
        /// The value.
        value: f64,
    },
    /// `before` for t < `time_s`, `after` from then on.
    Step {
        /// Switching time \[s\].
        time_s: f64,
        /// Value before.
        before: f64,
        /// Value after.
        after: f64,
    },
    /// Square wave: `bias + amplitude` for the first half of each period,
    /// `bias − amplitude` for the second (the open-loop test of §3.1.3).
    Square {
        /// Half the peak-to-peak value.
        amplitude: f64,
        /// Period \[s\].
        period_s: f64,
        /// Offset (the bias that makes an asymmetric cylinder's velocity symmetric).
        bias: f64,
    },
    /// `bias + amplitude sin(2π t/period + phase)`.
    Sine {
        /// Amplitude.
        amplitude: f64,
        /// Period \[s\].
        period_s: f64,
        /// Offset.
        bias: f64,
        /// Phase \[rad\].
        phase_rad: f64,
    },
    /// Sawtooth: rises linearly from `bias − amplitude` to `bias + amplitude`
    /// over each period, then drops back.
    Sawtooth {
        /// Half the peak-to-peak value.
        amplitude: f64,
        /// Period \[s\].
        period_s: f64,
        /// Offset.
        bias: f64,
    },
    /// `from` until `t0_s`, linear to `to` at `t1_s`, `to` after.
    Ramp {
        /// Start value.
        from: f64,
        /// End value.
        to: f64,
        /// Ramp start \[s\].
        t0_s: f64,
        /// Ramp end \[s\].
        t1_s: f64,
    },
    /// Samples with first-order hold (linear between samples), held constant
    /// outside the sampled range. The samples are shared, not copied, when
    /// the signal is cloned (a circuit per thread, per parameter set or per
    /// record simulation reads the same table).
    Table {
        /// Sample times, strictly increasing \[s\].
        time_s: Arc<[f64]>,
        /// Sample values.
        value: Arc<[f64]>,
    },
    /// A value the host sets between solver calls (an FMU's input), linear
    /// inside a step; see [`ExternalInput`]. Not part of rig or command
    /// files (never serialised).
    #[serde(skip)]
    External(ExternalInput),
    /// A table too long to hold, read while the run goes: a window the host
    /// fills ahead of the integration ([`StreamedTable`]). Not part of rig
    /// or command files (never serialised).
    #[serde(skip)]
    Streamed(StreamedTable),
}

impl Signal {
    /// A table signal, checked: equal lengths, at least one sample, finite
    /// values, strictly increasing times. The samples are moved into shared
    /// storage (one copy); [`Signal::shared_table`] takes samples already
    /// shared.
    pub fn table(time_s: Vec<f64>, value: Vec<f64>) -> Result<Self, SignalError> {
        Self::shared_table(time_s.into(), value.into())
    }

    /// [`Signal::table`] on samples already shared (another table's, a
    /// record's column): no copy, the same checks.
    pub fn shared_table(time_s: Arc<[f64]>, value: Arc<[f64]>) -> Result<Self, SignalError> {
        let s = Signal::Table { time_s, value };
        s.validate()?;
        Ok(s)
    }

    /// Checks the parameters.
    pub fn validate(&self) -> Result<(), SignalError> {
        let fin = |what, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                Err(SignalError::Parameter {
                    what,
                    value: v,
                    why: "must be finite",
                })
            }
        };
        let period = |v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(SignalError::Parameter {
                    what: "period_s",
                    value: v,
                    why: "must be positive",
                })
            }
        };
        match self {
            Signal::Constant { value } => fin("value", *value),
            Signal::External(_) | Signal::Streamed(_) => Ok(()),
            Signal::Step {
                time_s,
                before,
                after,
            } => {
                fin("time_s", *time_s)?;
                fin("before", *before)?;
                fin("after", *after)
            }
            Signal::Square {
                amplitude,
                period_s,
                bias,
            }
            | Signal::Sawtooth {
                amplitude,
                period_s,
                bias,
            } => {
                fin("amplitude", *amplitude)?;
                fin("bias", *bias)?;
                period(*period_s)
            }
            Signal::Sine {
                amplitude,
                period_s,
                bias,
                phase_rad,
            } => {
                fin("amplitude", *amplitude)?;
                fin("bias", *bias)?;
                fin("phase_rad", *phase_rad)?;
                period(*period_s)
            }
            Signal::Ramp {
                from,
                to,
                t0_s,
                t1_s,
            } => {
                fin("from", *from)?;
                fin("to", *to)?;
                fin("t0_s", *t0_s)?;
                fin("t1_s", *t1_s)?;
                if t1_s <= t0_s {
                    return Err(SignalError::Parameter {
                        what: "t1_s",
                        value: *t1_s,
                        why: "must be after t0_s",
                    });
                }
                Ok(())
            }
            Signal::Table { time_s, value } => {
                if time_s.len() != value.len() {
                    return Err(SignalError::Table {
                        row: time_s.len().min(value.len()),
                        why: format!("{} times but {} values", time_s.len(), value.len()),
                    });
                }
                if time_s.is_empty() {
                    return Err(SignalError::Table {
                        row: 0,
                        why: "no samples".into(),
                    });
                }
                // a table is checked whole at every assembly: first in one
                // pass without a branch per sample, then, only when it
                // fails, row by row for the first bad one
                let finite = |x: &[f64]| x.iter().fold(true, |ok, v| ok & v.is_finite());
                let rising = time_s[1..]
                    .iter()
                    .zip(time_s.iter())
                    .fold(true, |ok, (b, a)| ok & (b > a));
                if finite(time_s) && finite(value) && rising {
                    return Ok(());
                }
                for (i, (t, v)) in time_s.iter().zip(value.iter()).enumerate() {
                    if !t.is_finite() || !v.is_finite() {
                        return Err(SignalError::Table {
                            row: i,
                            why: format!("time {t} / value {v} is not finite"),
                        });
                    }
                    if i > 0 && *t <= time_s[i - 1] {
                        return Err(SignalError::Table {
                            row: i,
                            why: format!(
                                "time {t} s does not increase (previous {} s)",
                                time_s[i - 1]
                            ),
                        });
                    }
                }
                Ok(())
            }
        }
    }

    /// The value at time `t`.
    pub fn value(&self, t: f64) -> f64 {
        self.value_hinted(t, &Cell::new(0))
    }

    /// The value at time `t`; `hint` caches the table interval last used so
    /// that the integrator's nearby calls need no search.
    #[inline]
    pub fn value_hinted(&self, t: f64, hint: &Cell<usize>) -> f64 {
        match self {
            Signal::Constant { value } => *value,
            Signal::External(input) => input.value(t),
            Signal::Streamed(table) => table.value_hinted(t, hint),
            Signal::Step {
                time_s,
                before,
                after,
            } => {
                if t < *time_s {
                    *before
                } else {
                    *after
                }
            }
            Signal::Square {
                amplitude,
                period_s,
                bias,
            } => {
                let ph = (t / period_s).rem_euclid(1.0);
                if ph < 0.5 {
                    bias + amplitude
                } else {
                    bias - amplitude
                }
            }
            Signal::Sine {
                amplitude,
                period_s,
                bias,
                phase_rad,
            } => bias + amplitude * (std::f64::consts::TAU * t / period_s + phase_rad).sin(),
            Signal::Sawtooth {
                amplitude,
                period_s,
                bias,
            } => {
                let ph = (t / period_s).rem_euclid(1.0);
                bias + amplitude * (2.0 * ph - 1.0)
            }
            Signal::Ramp {
                from,
                to,
                t0_s,
                t1_s,
            } => {
                if t <= *t0_s {
                    *from
                } else if t >= *t1_s {
                    *to
                } else {
                    from + (to - from) * (t - t0_s) / (t1_s - t0_s)
                }
            }
            Signal::Table { time_s, value } => {
                if t <= time_s[0] {
                    return value[0];
                }
                let Some(i) = interval_hinted(time_s, t, hint) else {
                    return value[value.len() - 1];
                };
                let dv = value[i + 1] - value[i];
                if dv == 0.0 {
                    // a held interval (most of a stepped command): the
                    // formula below without its division, bit for bit
                    // (`+ 0.0` turns a −0.0 sample into +0.0 as it does)
                    return value[i] + 0.0;
                }
                let (t0, t1) = (time_s[i], time_s[i + 1]);
                value[i] + dv * (t - t0) / (t1 - t0)
            }
        }
    }
}

impl Signal {
    /// The smallest and largest value of a sampled command (a table, or a
    /// streamed table whose host gave its range); `None` for the others.
    pub fn value_range(&self) -> Option<(f64, f64)> {
        match self {
            Signal::Table { value, .. } => Some(
                value
                    .iter()
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &u| {
                        (lo.min(u), hi.max(u))
                    }),
            ),
            Signal::Streamed(table) => table.range(),
            _ => None,
        }
    }

    /// The time derivative at `t` (right-hand: the slope of the interval
    /// that starts at `t` for a table or ramp; 0 across a step's or a
    /// square's jump, which have no finite derivative) \[1/s\]. What an
    /// imposed-motion source takes as the acceleration of an imposed velocity.
    pub fn slope_hinted(&self, t: f64, hint: &Cell<usize>) -> f64 {
        match self {
            Signal::Constant { .. } | Signal::Step { .. } | Signal::Square { .. } => 0.0,
            Signal::External(input) => input.get().2,
            Signal::Streamed(table) => table.slope_hinted(t, hint),
            Signal::Sine {
                amplitude,
                period_s,
                phase_rad,
                ..
            } => {
                let w = std::f64::consts::TAU / period_s;
                amplitude * w * (w * t + phase_rad).cos()
            }
            Signal::Sawtooth {
                amplitude,
                period_s,
                ..
            } => 2.0 * amplitude / period_s,
            Signal::Ramp {
                from,
                to,
                t0_s,
                t1_s,
            } => {
                if t < *t0_s || t >= *t1_s {
                    0.0
                } else {
                    (to - from) / (t1_s - t0_s)
                }
            }
            Signal::Table { time_s, value } => match interval_hinted(time_s, t, hint) {
                Some(i) => (value[i + 1] - value[i]) / (time_s[i + 1] - time_s[i]),
                None => 0.0,
            },
        }
    }
}

/// The interval `i` of a table with `time_s[i] <= t < time_s[i + 1]`
/// (`None` outside `[time_s[0], time_s[n − 1])`), searched from the interval
/// in `hint`, which it updates.
#[inline]
fn interval_hinted(time_s: &[f64], t: f64, hint: &Cell<usize>) -> Option<usize> {
    let n = time_s.len();
    if n < 2 || t < time_s[0] || t >= time_s[n - 1] {
        return None;
    }
    let i = table_interval(time_s, t, hint.get().min(n - 2));
    hint.set(i);
    Some(i)
}

/// The interval `i` of a table with `time_s[i] <= t < time_s[i + 1]`, for
/// `time_s[0] < t < time_s[n − 1]`, searched outwards from the interval
/// `from` (the last one used): doubling steps bracket `t`, a binary search
/// inside the bracket finishes. Costs `O(log d)` for a distance of `d`
/// intervals — constant for an integrator marching through the table,
/// whatever its length (a search from the start would cost `O(log n)` with a
/// cache miss a probe, and made the cost per step grow with the record).
#[inline]
fn table_interval(time_s: &[f64], t: f64, from: usize) -> usize {
    let n = time_s.len();
    if time_s[from] <= t && t < time_s[from + 1] {
        return from;
    }
    let (lo, hi) = if t >= time_s[from + 1] {
        // forward: time_s[lo] <= t < time_s[hi]
        let (mut lo, mut step) = (from + 1, 1);
        loop {
            let hi = lo + step;
            if hi >= n - 1 {
                break (lo, n - 1);
            }
            if time_s[hi] > t {
                break (lo, hi);
            }
            lo = hi;
            step *= 2;
        }
    } else {
        // backward: time_s[lo] <= t < time_s[hi]
        let (mut hi, mut step) = (from, 1);
        loop {
            let lo = hi.saturating_sub(step);
            if lo == 0 || time_s[lo] <= t {
                break (lo, hi);
            }
            hi = lo;
            step *= 2;
        }
    };
    lo + time_s[lo..hi].partition_point(|&s| s <= t) - 1
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn a_cloned_table_shares_its_samples_and_a_shared_one_is_checked() {
        let t: Arc<[f64]> = vec![0.0, 1.0, 2.0].into();
        let u: Arc<[f64]> = vec![0.0, 1.0, 0.5].into();
        let a = Signal::shared_table(t.clone(), u.clone()).unwrap();
        let b = a.clone();
        let (Signal::Table { time_s, value }, Signal::Table { time_s: t2, .. }) = (&a, &b) else {
            panic!("not tables");
        };
        assert!(Arc::ptr_eq(time_s, &t) && Arc::ptr_eq(value, &u) && Arc::ptr_eq(t2, &t));
        let h = Cell::new(0);
        assert_eq!(b.value_hinted(1.5, &h), 0.75);
        // the same checks as `table`
        let back: Arc<[f64]> = vec![0.0, 2.0, 1.0].into();
        assert!(matches!(
            Signal::shared_table(back, u.clone()),
            Err(SignalError::Table { row: 2, .. })
        ));
        let short: Arc<[f64]> = vec![0.0, 1.0].into();
        assert!(Signal::shared_table(short, u).is_err());
        // a table still reads and writes as JSON arrays
        let json = serde_json::to_string(&a).unwrap();
        assert_eq!(
            json,
            r#"{"kind":"table","time_s":[0.0,1.0,2.0],"value":[0.0,1.0,0.5]}"#
        );
        assert_eq!(serde_json::from_str::<Signal>(&json).unwrap(), a);
    }

    #[test]
    fn a_held_table_interval_is_the_interpolation_bit_for_bit() {
        // the shortcut on equal samples returns what the formula gives,
        // signed zeros included
        let time_s = vec![0.0, 1.0, 2.0, 3.0, 4.0];
        let value = vec![-0.0, -0.0, 0.0, 2.5, 2.5];
        let formula = |t: f64| {
            let i = (t.floor() as usize).min(3);
            let (t0, t1) = (time_s[i], time_s[i + 1]);
            value[i] + (value[i + 1] - value[i]) * (t - t0) / (t1 - t0)
        };
        let s = Signal::table(time_s.clone(), value.clone()).unwrap();
        for t in [0.25, 1.0, 1.5, 2.0, 2.75, 3.0, 3.5] {
            assert_eq!(s.value(t).to_bits(), formula(t).to_bits(), "t = {t}");
        }
    }

    #[test]
    fn shapes() {
        let sq = Signal::Square {
            amplitude: 0.2,
            period_s: 2.0,
            bias: -0.05,
        };
        assert!((sq.value(0.5) - 0.15).abs() < 1e-15);
        assert!((sq.value(1.5) + 0.25).abs() < 1e-15);
        let saw = Signal::Sawtooth {
            amplitude: 1.0,
            period_s: 4.0,
            bias: 0.0,
        };
        assert_eq!(saw.value(0.0), -1.0);
        assert_eq!(saw.value(2.0), 0.0);
        assert_eq!(saw.value(5.0), -0.5);
        let step = Signal::Step {
            time_s: 1.0,
            before: 0.0,
            after: 2.0,
        };
        assert_eq!(step.value(0.999), 0.0);
        assert_eq!(step.value(1.0), 2.0);
        let r = Signal::Ramp {
            from: 1.0,
            to: -1.0,
            t0_s: 0.0,
            t1_s: 2.0,
        };
        assert_eq!(r.value(1.0), 0.0);
    }

    #[test]
    fn table_rejects_bad_samples() {
        let e = Signal::table(vec![0.0, 1.0, 1.0], vec![0.0; 3]).unwrap_err();
        assert!(e.to_string().contains("sample 2"), "{e}");
        assert!(Signal::table(vec![0.0, f64::NAN], vec![0.0; 2]).is_err());
        assert!(Signal::table(vec![], vec![]).is_err());
        let e = Signal::Square {
            amplitude: 1.0,
            period_s: 0.0,
            bias: 0.0,
        }
        .validate()
        .unwrap_err();
        assert!(e.to_string().contains("period_s"));
    }

    proptest! {
        /// First-order hold: exact at the samples and linear in between,
        /// whatever the hint says.
        #[test]
        fn table_is_first_order_hold(t in -1.0f64..12.0, h in 0usize..20) {
            let ts: Vec<f64> = (0..11).map(|i| i as f64 + 0.1 * (i % 3) as f64).collect();
            let vs: Vec<f64> = ts.iter().map(|t| 3.0 * t - 2.0).collect();
            let s = Signal::table(ts.clone(), vs).unwrap();
            let hint = Cell::new(h);
            let expect = 3.0 * t.clamp(ts[0], ts[10]) - 2.0;
            prop_assert!((s.value_hinted(t, &hint) - expect).abs() < 1e-12);
        }

        /// A table's first bad sample (a time or value not finite, a time
        /// not after the one before) is the row its error names, however
        /// many bad samples follow.
        #[test]
        fn table_error_names_the_first_bad_sample(
            n in 2usize..40,
            bad in proptest::collection::vec((0usize..40, 0u8..4), 0..4),
        ) {
            let mut t: Vec<f64> = (0..n).map(|i| i as f64).collect();
            let mut u = vec![0.5; n];
            for &(i, kind) in &bad {
                let i = i % n;
                match kind {
                    0 => t[i] = f64::NAN,
                    1 => u[i] = f64::INFINITY,
                    2 if i > 0 => t[i] = t[i - 1],
                    _ => u[i] = f64::NAN,
                }
            }
            let first = (0..n).find(|&i| {
                !t[i].is_finite() || !u[i].is_finite() || (i > 0 && t[i] <= t[i - 1])
            });
            match (Signal::table(t, u), first) {
                (Ok(_), None) => {}
                (Err(SignalError::Table { row, .. }), Some(i)) => prop_assert_eq!(row, i),
                (r, f) => prop_assert!(false, "{:?} against first bad row {:?}", r.err(), f),
            }
        }

        /// The search from the last interval finds the interval a binary
        /// search from the start finds, from any starting interval.
        #[test]
        fn interval_search_from_the_hint(t in 0.0f64..1000.0, from in 0usize..1000) {
            let ts: Vec<f64> = (0..1001).map(|i| i as f64 + 0.5 * ((i * 7) % 3) as f64 / 3.0).collect();
            prop_assume!(t > ts[0] && t < ts[1000]);
            let expect = ts.partition_point(|&s| s <= t) - 1;
            prop_assert_eq!(table_interval(&ts, t, from), expect);
        }
    }
}
