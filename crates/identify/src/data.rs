//! Reading measured records (the CSV format of `spec/measured-data.md`).
//!
//! One header row; one sample a row; a column is `signal` or `signal [unit]`.
//! Every value is converted to SI on reading. Columns that are not signals are
//! kept by name (see [`Record::ignored`]) and otherwise ignored. Real data sets
//! whose headers differ (`time_ms`, `force_N`, ...) are read through a
//! [`ColumnMap`] that names, per signal, the header and the unit to apply.

use std::collections::BTreeMap;
use std::fmt;
use std::path::Path;

use serde::{Deserialize, Serialize};

mod decimal;
mod error;
mod read;
mod repeat;
mod time_axis;

pub use decimal::{scale_decimal, scaled_decimal};
pub use error::DataError;
pub use read::{
    foreign_encoding, foreign_separator, missing_time_hint, unread_header_hint, LineCounter,
};
pub use repeat::{repeated_record, RecordInput, Repeated};
pub use time_axis::{beyond_span, GAP_OVER_REST, MAX_GAP_FACTOR, MAX_SPAN_S};

/// A signal of the measured-data format.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Signal {
    /// Sample time \[s\].
    Time,
    /// Rig input: normalised spool demand \[-\] or drive voltage \[V\].
    Command,
    /// Piston position from mid-stroke, + extending \[m\].
    Position,
    /// Piston velocity \[m·s⁻¹\].
    Velocity,
    /// Cap-side chamber pressure, gauge \[Pa\].
    P1,
    /// Rod-side chamber pressure, gauge \[Pa\].
    P2,
    /// Supply / pump-line pressure \[Pa\].
    Ps,
    /// Pump or supply flow \[m³·s⁻¹\].
    Flow,
    /// External force on the rod \[N\].
    Force,
    /// Position set-point of a closed-loop record \[m\].
    Reference,
}

impl Signal {
    /// Every signal, in column order of the format.
    pub const ALL: [Signal; 10] = [
        Signal::Time,
        Signal::Command,
        Signal::Position,
        Signal::Velocity,
        Signal::P1,
        Signal::P2,
        Signal::Ps,
        Signal::Flow,
        Signal::Force,
        Signal::Reference,
    ];

    /// The column name of the format (`time`, `p1`, ...).
    pub fn name(self) -> &'static str {
        match self {
            Signal::Time => "time",
            Signal::Command => "command",
            Signal::Position => "position",
            Signal::Velocity => "velocity",
            Signal::P1 => "p1",
            Signal::P2 => "p2",
            Signal::Ps => "ps",
            Signal::Flow => "flow",
            Signal::Force => "force",
            Signal::Reference => "reference",
        }
    }

    /// The signal with this column name, if any.
    pub fn from_name(name: &str) -> Option<Signal> {
        Signal::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The factor that converts a value in `unit` to SI, or `None` if the unit
    /// is not accepted for this signal. The SI unit's own symbol is accepted too.
    pub fn unit_factor(self, unit: &str) -> Option<f64> {
        let f = match (self, unit) {
            (Signal::Time, "s") => 1.0,
            (Signal::Time, "ms") => 1e-3,
            (Signal::Command, "-" | "V" | "1") => 1.0,
            // as `simulate` reads a command file: a spool demand in per
            // cent, a drive voltage in millivolts
            (Signal::Command, "%") => 1e-2,
            (Signal::Command, "mV") => 1e-3,
            (Signal::Position | Signal::Reference, "m") => 1.0,
            (Signal::Position | Signal::Reference, "mm") => 1e-3,
            (Signal::Velocity, "m/s") => 1.0,
            (Signal::Velocity, "mm/s") => 1e-3,
            (Signal::Velocity, "cm/s") => 1e-2,
            (Signal::P1 | Signal::P2 | Signal::Ps, u) => match u {
                "Pa" => 1.0,
                "bar" => 1e5,
                "kPa" => 1e3,
                "MPa" => 1e6,
                "psi" => hydrocyl_ports::PSI_IN_PA,
                _ => return None,
            },
            (Signal::Flow, "m^3/s" | "m3/s") => 1.0,
            (Signal::Flow, "l/min" | "L/min") => 1e-3 / 60.0,
            (Signal::Force, "N") => 1.0,
            (Signal::Force, "kN") => 1e3,
            _ => return None,
        };
        Some(f)
    }

    /// The units accepted for this signal (for error messages).
    pub fn accepted_units(self) -> &'static str {
        match self {
            Signal::Time => "s, ms",
            Signal::Command => "-, %, V, mV",
            Signal::Position | Signal::Reference => "m, mm",
            Signal::Velocity => "m/s, mm/s, cm/s",
            Signal::P1 | Signal::P2 | Signal::Ps => "Pa, bar, kPa, MPa, psi",
            Signal::Flow => "m^3/s, l/min",
            Signal::Force => "N, kN",
        }
    }
}

impl fmt::Display for Signal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Where each signal is found when the headers are not the format's own:
/// signal → `"header"` or `"header [unit]"`. Signals not in the map are
/// looked up by their own name as usual.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct ColumnMap(pub BTreeMap<Signal, String>);

/// A measured record: time and the signals present, all in SI.
#[derive(Clone, Debug, PartialEq)]
pub struct Record {
    /// Where it came from (file name), for messages.
    pub source: String,
    /// Sample times, strictly increasing \[s\].
    pub time: Vec<f64>,
    /// The signals present other than time, in SI units.
    pub signals: BTreeMap<Signal, Vec<f64>>,
    /// Headers of the columns that are not signals (kept, not used).
    pub ignored: Vec<String>,
    /// The unit each signal's column was written in (`ms`, `bar`, `V`, ...),
    /// for the signals whose header (or column map) named one; the values
    /// are already in SI. The data checks compare it with the rig's (a
    /// `command [V]` on a rig whose command is a normalised spool demand).
    pub units: BTreeMap<Signal, String>,
    /// The file line of each sample (header = row 1), for messages; empty
    /// when sample `k` is on line `k + 2` (no blank line inside the data).
    /// See [`Record::row`].
    pub lines: Vec<usize>,
}

/// Minimum number of samples of a usable record.
pub const MIN_SAMPLES: usize = 8;

impl Record {
    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// `true` when there are no samples (never for a record read from a file).
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
    }

    /// The row (file line, header = row 1, blank lines counted) of sample
    /// `k`, as error messages and data problems name it.
    pub fn row(&self, k: usize) -> usize {
        self.lines.get(k).copied().unwrap_or(k + 2)
    }

    /// The samples of `signal`, if present.
    pub fn get(&self, signal: Signal) -> Option<&[f64]> {
        if signal == Signal::Time {
            return Some(&self.time);
        }
        self.signals.get(&signal).map(|v| v.as_slice())
    }

    /// The samples of `signal`, or an error naming the file and the column.
    pub fn require(&self, signal: Signal) -> Result<&[f64], DataError> {
        self.get(signal).ok_or_else(|| DataError::MissingColumn {
            file: self.source.clone(),
            column: signal.name().to_string(),
            hint: read::unread_header_hint(&self.ignored, signal.name()),
        })
    }

    /// The value of `signal` at time `t` by first-order hold (linear between
    /// samples, held constant outside the record). `None` if absent.
    pub fn interpolate(&self, signal: Signal, t: f64) -> Option<f64> {
        let y = self.get(signal)?;
        Some(interp_linear(&self.time, y, t))
    }

    /// A record that keeps samples `range` only.
    pub fn slice(&self, range: std::ops::Range<usize>) -> Record {
        Record {
            source: self.source.clone(),
            time: self.time[range.clone()].to_vec(),
            signals: self
                .signals
                .iter()
                .map(|(k, v)| (*k, v[range.clone()].to_vec()))
                .collect(),
            ignored: self.ignored.clone(),
            units: self.units.clone(),
            lines: self
                .lines
                .get(range)
                .map(<[usize]>::to_vec)
                .unwrap_or_default(),
        }
    }
}

/// Linear interpolation of samples `(t, y)` at `x`, held constant outside.
pub fn interp_linear(t: &[f64], y: &[f64], x: f64) -> f64 {
    let n = t.len().min(y.len());
    if n == 0 {
        return f64::NAN;
    }
    if x <= t[0] {
        return y[0];
    }
    if x >= t[n - 1] {
        return y[n - 1];
    }
    let k = t[..n].partition_point(|&ti| ti <= x);
    let (t0, t1) = (t[k - 1], t[k]);
    let w = (x - t0) / (t1 - t0);
    y[k - 1] + w * (y[k] - y[k - 1])
}

/// Writes a record to CSV in the format's own columns (SI units, no
/// suffixes), atomically: to a temporary file renamed into place.
pub fn write_csv(path: &Path, time: &[f64], columns: &[(Signal, &[f64])]) -> std::io::Result<()> {
    let mut out = String::new();
    out.push_str("time");
    for (s, _) in columns {
        out.push(',');
        out.push_str(s.name());
    }
    out.push('\n');
    for (i, t) in time.iter().enumerate() {
        out.push_str(&format!("{t:.6}"));
        for (_, c) in columns {
            out.push_str(&format!(",{:.9e}", c[i]));
        }
        out.push('\n');
    }
    write_atomic(path, out.as_bytes())
}

/// Writes `bytes` to `path` through a temporary file in the same folder, so
/// that a failure never leaves a half-written file.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let tmp = path.with_extension(format!(
        "{}.tmp{}",
        path.extension().and_then(|e| e.to_str()).unwrap_or(""),
        std::process::id()
    ));
    std::fs::write(&tmp, bytes)?;
    std::fs::rename(&tmp, path).inspect_err(|_| {
        let _ = std::fs::remove_file(&tmp);
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_order_hold() {
        let t = [0.0, 1.0, 3.0];
        let y = [0.0, 2.0, -2.0];
        assert_eq!(interp_linear(&t, &y, 0.5), 1.0);
        assert_eq!(interp_linear(&t, &y, 2.0), 0.0);
        assert_eq!(interp_linear(&t, &y, -1.0), 0.0);
        assert_eq!(interp_linear(&t, &y, 9.0), -2.0);
    }
}
