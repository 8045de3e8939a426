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

use crate::plaincsv::PlainCsv;
use thiserror::Error;

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
            Signal::Command => "-, V",
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

/// What went wrong reading a record. Every variant names the file; those
/// about one cell name its row (1-based line of the file, header = row 1)
/// and column.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DataError {
    /// The file could not be opened or read.
    #[error("{file}: cannot read: {reason}")]
    Io {
        /// The file.
        file: String,
        /// The operating system's reason.
        reason: String,
    },
    /// The CSV structure is broken (ragged row, bad quoting, empty file).
    #[error("{file}: row {row}: {reason}")]
    Malformed {
        /// The file.
        file: String,
        /// The row (1-based line).
        row: usize,
        /// What is wrong.
        reason: String,
    },
    /// A required column is missing.
    #[error("{file}: row 1: missing column '{column}'")]
    MissingColumn {
        /// The file.
        file: String,
        /// The missing column's name.
        column: String,
    },
    /// A column the rig's column map names is not in the file.
    #[error("{file}: row 1: missing column '{column}' (the rig's column map, `identify.columns.{signal}`; the file's headers: {headers})")]
    MissingMappedColumn {
        /// The file.
        file: String,
        /// The header the map names (as written in the map).
        column: String,
        /// The signal it was to hold.
        signal: String,
        /// The file's headers, comma separated.
        headers: String,
    },
    /// A column's unit is not accepted for its signal.
    #[error("{file}: row 1, column '{column}': unknown unit '{unit}' (accepted: {accepted})")]
    UnknownUnit {
        /// The file.
        file: String,
        /// The column header.
        column: String,
        /// The unit found.
        unit: String,
        /// The units accepted.
        accepted: String,
    },
    /// The same signal appears twice.
    #[error("{file}: row 1, column '{column}': signal '{signal}' appears twice")]
    DuplicateSignal {
        /// The file.
        file: String,
        /// The second column header.
        column: String,
        /// The signal.
        signal: String,
    },
    /// The smoother half-width asked for is wider than the record allows.
    #[error("{file}: a smoother half-width (window) of {half_window} samples does not fit its {samples} samples: at most {max}", max = samples.saturating_sub(1) / 2)]
    WindowTooWide {
        /// The record.
        file: String,
        /// The half-width asked for.
        half_window: usize,
        /// The record's samples.
        samples: usize,
    },
    /// A smoother half-width given for records that are not smoothed.
    #[error("{file}: a steady-state bench's samples are not smoothed (measured velocity, zero acceleration): leave out the smoother half-width (window)")]
    WindowNotUsed {
        /// The record.
        file: String,
    },
    /// A cell is not a number.
    #[error("{file}: row {row}, column '{column}': '{text}' is not a number")]
    NotANumber {
        /// The file.
        file: String,
        /// The row (1-based line).
        row: usize,
        /// The column header.
        column: String,
        /// The cell's text.
        text: String,
    },
    /// A cell is NaN or infinite.
    #[error("{file}: row {row}, column '{column}': value is not finite ({text})")]
    NotFinite {
        /// The file.
        file: String,
        /// The row (1-based line).
        row: usize,
        /// The column header.
        column: String,
        /// The cell's text.
        text: String,
    },
    /// Time does not increase strictly.
    #[error(
        "{file}: row {row}, column '{column}': time {t} s does not increase (previous {prev} s)"
    )]
    TimeNotIncreasing {
        /// The file.
        file: String,
        /// The row (1-based line).
        row: usize,
        /// The time column's header.
        column: String,
        /// This row's time \[s\].
        t: f64,
        /// The previous row's time \[s\].
        prev: f64,
    },
    /// A column's unit contradicts the rig (a `command [V]` on a rig whose
    /// command is a normalised spool demand; seconds under `time [ms]`).
    #[error("{file}: row 1, column '{column}': {reason}")]
    UnitContradictsRig {
        /// The file.
        file: String,
        /// The column header.
        column: String,
        /// What contradicts what, and what to check.
        reason: String,
    },
    /// Too few samples to do anything with.
    #[error("{file}: only {n} samples (at least {min} needed)")]
    TooShort {
        /// The file.
        file: String,
        /// Samples found.
        n: usize,
        /// Samples needed.
        min: usize,
    },
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
}

/// Splits `name [unit]` into name and unit.
fn split_header(h: &str) -> (String, Option<String>) {
    let h = h.trim();
    if let Some(open) = h.find('[') {
        if h.ends_with(']') {
            let name = h[..open].trim().to_string();
            let unit = h[open + 1..h.len() - 1].trim().to_string();
            return (name, Some(unit));
        }
    }
    (h.to_string(), None)
}

/// The columns of a header: which signal each holds and its SI factor.
struct Columns {
    /// Column index → (signal, SI factor).
    cols: Vec<Option<(Signal, f64)>>,
    /// Signal → column index.
    seen: BTreeMap<Signal, usize>,
    /// Headers of the columns that are not signals.
    ignored: Vec<String>,
    /// Signal → the unit its header named.
    units: BTreeMap<Signal, String>,
}

/// Why a header of one cell is not comma-separated CSV, when the cell
/// shows another separator (`;` or a tab): "the file is separated by `;`;
/// hydrocyl reads comma-separated CSV". Every CSV reader of hydrocyl
/// (records, command files) gives this message for row 1.
pub fn foreign_separator(headers: &[&str]) -> Option<String> {
    let [cell] = headers else {
        return None;
    };
    let sep = if cell.contains(';') {
        "`;`"
    } else if cell.contains('\t') {
        "tabs"
    } else {
        return None;
    };
    Some(format!(
        "the file is separated by {sep}; hydrocyl reads comma-separated CSV"
    ))
}

/// Finds the signals among `headers` (trimmed), directly or through `map`.
fn map_columns(file: &str, headers: &[&str], map: &ColumnMap) -> Result<Columns, DataError> {
    if let Some(reason) = foreign_separator(headers) {
        return Err(DataError::Malformed {
            file: file.to_string(),
            row: 1,
            reason,
        });
    }
    let mut cols: Vec<Option<(Signal, f64)>> = vec![None; headers.len()];
    let mut seen: BTreeMap<Signal, usize> = BTreeMap::new();
    let mut ignored = Vec::new();
    let mut units = BTreeMap::new();
    // Mapped signals first: header name → (signal, unit).
    let mut mapped: BTreeMap<String, (Signal, Option<String>)> = BTreeMap::new();
    for (sig, spec) in &map.0 {
        let (name, unit) = split_header(spec);
        mapped.insert(name, (*sig, unit));
    }
    for (j, h) in headers.iter().enumerate() {
        let (name, unit) = split_header(h);
        let hit = if let Some((sig, munit)) = mapped.get(h.trim()).or_else(|| mapped.get(&name)) {
            // A mapped header: the map's unit wins, else the header's own.
            Some((*sig, munit.clone().or(unit)))
        } else {
            Signal::from_name(&name)
                .filter(|s| !map.0.contains_key(s))
                .map(|s| (s, unit))
        };
        match hit {
            Some((sig, unit)) => {
                let factor = match &unit {
                    None => 1.0,
                    Some(u) => sig.unit_factor(u).ok_or_else(|| DataError::UnknownUnit {
                        file: file.to_string(),
                        column: h.to_string(),
                        unit: u.clone(),
                        accepted: sig.accepted_units().to_string(),
                    })?,
                };
                if seen.insert(sig, j).is_some() {
                    return Err(DataError::DuplicateSignal {
                        file: file.to_string(),
                        column: h.to_string(),
                        signal: sig.name().to_string(),
                    });
                }
                cols[j] = Some((sig, factor));
                if let Some(u) = unit {
                    units.insert(sig, u);
                }
            }
            None => ignored.push(h.to_string()),
        }
    }
    // A column the map names must be there: read by its own name instead,
    // the record would say "missing column 'position'", not which header
    // was looked for.
    if let Some((sig, spec)) = map.0.iter().find(|(sig, _)| !seen.contains_key(sig)) {
        return Err(DataError::MissingMappedColumn {
            file: file.to_string(),
            column: spec.clone(),
            signal: sig.name().to_string(),
            headers: headers.join(", "),
        });
    }
    Ok(Columns {
        cols,
        seen,
        ignored,
        units,
    })
}

/// Minimum number of samples of a usable record.
pub const MIN_SAMPLES: usize = 8;

impl Record {
    /// Reads a CSV file in the measured-data format.
    pub fn read(path: &Path) -> Result<Record, DataError> {
        Self::read_mapped(path, &ColumnMap::default())
    }

    /// Reads a CSV file whose columns are found through `map`.
    pub fn read_mapped(path: &Path, map: &ColumnMap) -> Result<Record, DataError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|e| DataError::Io {
            file: file.clone(),
            reason: e.to_string(),
        })?;
        Self::parse(&file, &text, map)
    }

    /// Parses CSV text; `file` names it in errors. Plain numeric text takes
    /// the fast path of [`crate::plaincsv`]; anything else (and every error)
    /// goes through the full CSV reader.
    pub fn parse(file: &str, text: &str, map: &ColumnMap) -> Result<Record, DataError> {
        if let Some(r) = Self::parse_plain(file, text, map) {
            return Ok(r);
        }
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(true)
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let headers = rdr
            .headers()
            .map_err(|e| DataError::Malformed {
                file: file.to_string(),
                row: 1,
                reason: e.to_string(),
            })?
            .clone();
        if headers.iter().all(|h| h.trim().is_empty()) {
            return Err(DataError::Malformed {
                file: file.to_string(),
                row: 1,
                reason: "empty header".into(),
            });
        }
        let header_list: Vec<&str> = headers.iter().collect();
        let Columns {
            cols,
            seen,
            ignored,
            units,
        } = map_columns(file, &header_list, map)?;
        let time_col = match seen.get(&Signal::Time) {
            Some(&j) => j,
            None => {
                return Err(DataError::MissingColumn {
                    file: file.to_string(),
                    column: map
                        .0
                        .get(&Signal::Time)
                        .cloned()
                        .unwrap_or_else(|| "time".into()),
                })
            }
        };
        let mut time = Vec::new();
        let mut signals: BTreeMap<Signal, Vec<f64>> = seen
            .keys()
            .filter(|s| **s != Signal::Time)
            .map(|s| (*s, Vec::new()))
            .collect();
        for (k, rec) in rdr.records().enumerate() {
            let row = k + 2;
            let rec = rec.map_err(|e| DataError::Malformed {
                file: file.to_string(),
                row,
                reason: e.to_string(),
            })?;
            if rec.len() != headers.len() {
                return Err(DataError::Malformed {
                    file: file.to_string(),
                    row,
                    reason: format!("{} cells, header has {}", rec.len(), headers.len()),
                });
            }
            for (j, col) in cols.iter().enumerate() {
                let Some((sig, factor)) = col else { continue };
                let cell = &rec[j];
                let v: f64 = cell.parse().map_err(|_| DataError::NotANumber {
                    file: file.to_string(),
                    row,
                    column: headers[j].to_string(),
                    text: cell.to_string(),
                })?;
                if !v.is_finite() {
                    return Err(DataError::NotFinite {
                        file: file.to_string(),
                        row,
                        column: headers[j].to_string(),
                        text: cell.to_string(),
                    });
                }
                let v = v * factor;
                if *sig == Signal::Time {
                    if let Some(&prev) = time.last() {
                        if v <= prev {
                            return Err(DataError::TimeNotIncreasing {
                                file: file.to_string(),
                                row,
                                column: headers[time_col].to_string(),
                                t: v,
                                prev,
                            });
                        }
                    }
                    time.push(v);
                } else if let Some(s) = signals.get_mut(sig) {
                    s.push(v);
                }
            }
        }
        if time.len() < MIN_SAMPLES {
            return Err(DataError::TooShort {
                file: file.to_string(),
                n: time.len(),
                min: MIN_SAMPLES,
            });
        }
        Ok(Record {
            source: file.to_string(),
            time,
            signals,
            ignored,
            units,
        })
    }

    /// The fast path of [`Record::parse`]: `None` whenever the text is not
    /// plain numeric CSV or anything is wrong with it (the full reader then
    /// reports what).
    fn parse_plain(file: &str, text: &str, map: &ColumnMap) -> Option<Record> {
        let csv = PlainCsv::new(text)?;
        let headers: Vec<&str> = csv.headers().collect();
        let Columns {
            cols,
            seen,
            ignored,
            units,
        } = map_columns(file, &headers, map).ok()?;
        let time_col = *seen.get(&Signal::Time)?;
        let wanted: Vec<usize> = std::iter::once(time_col)
            .chain(seen.values().copied().filter(|&j| j != time_col))
            .collect();
        let mut values = csv.columns(&wanted)?.into_iter();
        let scale = |j: usize, mut v: Vec<f64>| {
            let factor = cols[j].map_or(1.0, |(_, f)| f);
            if factor != 1.0 {
                v.iter_mut().for_each(|x| *x *= factor);
            }
            v
        };
        let time = scale(time_col, values.next()?);
        if time.len() < MIN_SAMPLES || time.windows(2).any(|w| w[1] <= w[0]) {
            return None;
        }
        let mut signals = BTreeMap::new();
        for (&j, v) in wanted[1..].iter().zip(values) {
            let (sig, _) = cols[j]?;
            signals.insert(sig, scale(j, v));
        }
        Some(Record {
            source: file.to_string(),
            time,
            signals,
            ignored,
            units,
        })
    }

    /// Number of samples.
    pub fn len(&self) -> usize {
        self.time.len()
    }

    /// `true` when there are no samples (never for a record read from a file).
    pub fn is_empty(&self) -> bool {
        self.time.is_empty()
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

    fn parse(text: &str) -> Result<Record, DataError> {
        Record::parse("t.csv", text, &ColumnMap::default())
    }

    #[test]
    fn units_are_converted_to_si() {
        let mut s = String::from("time [ms],position [mm],p1 [bar],p2 [psi],force [kN],other\n");
        for i in 0..10 {
            s.push_str(&format!("{},{},{},1,2,x\n", i * 10, i, 100 + i));
        }
        let r = parse(&s).unwrap();
        assert_eq!(r.len(), 10);
        assert!((r.time[3] - 0.03).abs() < 1e-15);
        assert!((r.get(Signal::Position).unwrap()[4] - 4e-3).abs() < 1e-15);
        assert!((r.get(Signal::P1).unwrap()[0] - 100e5).abs() < 1e-6);
        assert!((r.get(Signal::P2).unwrap()[0] - 6894.757293168361).abs() < 1e-9);
        assert!((r.get(Signal::Force).unwrap()[0] - 2000.0).abs() < 1e-12);
        assert_eq!(r.ignored, vec!["other".to_string()]);
    }

    #[test]
    fn a_semicolon_or_tab_file_is_named_as_such() {
        for (text, sep) in [
            ("time [s];command;position [mm]\n0;0;0\n1;0;0\n", "`;`"),
            ("time\tcommand\tposition\n0\t0\t0\n1\t0\t0\n", "tabs"),
        ] {
            let e = parse(text).unwrap_err().to_string();
            assert!(
                e.contains("row 1") && e.contains(&format!("separated by {sep}")),
                "{e}"
            );
        }
    }

    #[test]
    fn errors_name_row_and_column() {
        let ok = "time,position\n0,0\n1,0\n2,0\n3,0\n4,0\n5,0\n6,0\n7,0\n";
        assert!(parse(ok).is_ok());
        let e = parse("position\n0\n").unwrap_err();
        assert!(matches!(e, DataError::MissingColumn { .. }), "{e}");
        let e = parse(&ok.replace("3,0", "3,abc")).unwrap_err().to_string();
        assert!(
            e.contains("row 5") && e.contains("'position'") && e.contains("abc"),
            "{e}"
        );
        let e = parse(&ok.replace("4,0", "4,NaN")).unwrap_err().to_string();
        assert!(e.contains("row 6") && e.contains("not finite"), "{e}");
        let e = parse(&ok.replace("5,0", "3.5,0")).unwrap_err().to_string();
        assert!(
            e.contains("row 7") && e.contains("does not increase"),
            "{e}"
        );
        let e = parse(&ok.replace("position", "position [furlong]"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("unknown unit 'furlong'") && e.contains("row 1"),
            "{e}"
        );
        let e = parse(&ok.replace("6,0", "6")).unwrap_err().to_string();
        assert!(e.contains("row 8"), "{e}");
        let e = parse("time,position\n0,0\n").unwrap_err();
        assert!(matches!(e, DataError::TooShort { .. }));
    }

    #[test]
    fn column_map_reads_foreign_headers() {
        let mut map = ColumnMap::default();
        map.0.insert(Signal::Time, "time_ms [ms]".into());
        map.0.insert(Signal::P1, "pressure_bar_gauge [bar]".into());
        let mut s = String::from("time_ms,pressure_bar_gauge,force_N\n");
        for i in 0..10 {
            s.push_str(&format!("{},{},5\n", i * 10, 2));
        }
        let r = Record::parse("x.csv", &s, &map).unwrap();
        assert!((r.time[1] - 0.01).abs() < 1e-15);
        assert!((r.get(Signal::P1).unwrap()[1] - 2e5).abs() < 1e-9);
        assert_eq!(r.ignored, vec!["force_N".to_string()]);
    }

    /// A column map naming a header the file lacks: the error names the
    /// header looked for (it said "missing column 'position'").
    #[test]
    fn a_mapped_column_that_is_missing_is_named_by_its_header() {
        let mut map = ColumnMap::default();
        map.0.insert(Signal::Position, "pos [mm]".into());
        let mut s = String::from("time [s],command,position [mm]\n");
        for i in 0..10 {
            s.push_str(&format!("{},0,{}\n", i, i));
        }
        let e = Record::parse("x.csv", &s, &map).unwrap_err().to_string();
        assert!(
            e.contains("x.csv")
                && e.contains("missing column 'pos [mm]'")
                && e.contains("identify.columns.position"),
            "{e}"
        );
    }

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
