//! Reading a record's CSV text: the header's columns (signals, units, a
//! [`ColumnMap`]) and the values, by the plain numeric fast path or the
//! full CSV reader.

use std::collections::BTreeMap;
use std::path::Path;

use super::{time_axis, ColumnMap, DataError, Record, Signal, MIN_SAMPLES};
use crate::plaincsv::PlainCsv;

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

/// Why a file's bytes are not UTF-8 text that a CSV reader can read, when
/// they are text in a wide encoding: UTF-16 or UTF-32, told by its
/// byte-order mark, or UTF-16 without one, told by a NUL byte beside each
/// character of the first line (a spreadsheet's "Unicode text" export).
/// Read as UTF-8 such a file's header would be `t\0i\0m\0e\0`, which no
/// column matches ("missing column 'time'"). Every CSV reader of hydrocyl
/// (records, command files) gives this message for row 1.
pub fn foreign_encoding(bytes: &[u8]) -> Option<String> {
    let (encoding, mark) = match bytes {
        [0xFF, 0xFE, 0, 0, ..] => ("UTF-32", Some("FF FE 00 00")),
        [0, 0, 0xFE, 0xFF, ..] => ("UTF-32", Some("00 00 FE FF")),
        [0xFF, 0xFE, ..] => ("UTF-16", Some("FF FE")),
        [0xFE, 0xFF, ..] => ("UTF-16", Some("FE FF")),
        _ => {
            // UTF-16 without a mark: ASCII characters each with a NUL byte
            // before (big-endian) or after (little-endian) it
            let line = bytes.split(|&b| b == b'\n').next().unwrap_or(bytes);
            let head = &line[..line.len().min(64) & !1];
            let ascii = |b: u8| b != 0 && b.is_ascii();
            let le = head.chunks(2).all(|c| ascii(c[0]) && c[1] == 0);
            let be = head.chunks(2).all(|c| c[0] == 0 && ascii(c[1]));
            if head.len() < 4 || !(le || be) {
                return None;
            }
            ("UTF-16", None)
        }
    };
    let mark = mark.map_or_else(
        || "no byte-order mark, a NUL byte beside each character".to_string(),
        |m| format!("byte-order mark {m}"),
    );
    Some(format!(
        "the file is {encoding} text ({mark}); hydrocyl reads UTF-8 (or ASCII) text: save it as UTF-8 CSV"
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
                if let Some(first) = seen.insert(sig, j) {
                    return Err(DataError::DuplicateSignal {
                        file: file.to_string(),
                        column: h.to_string(),
                        signal: sig.name().to_string(),
                        first: first + 1,
                        second: j + 1,
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

impl Record {
    /// Reads a CSV file in the measured-data format.
    pub fn read(path: &Path) -> Result<Record, DataError> {
        Self::read_mapped(path, &ColumnMap::default())
    }

    /// Reads a CSV file whose columns are found through `map`.
    pub fn read_mapped(path: &Path, map: &ColumnMap) -> Result<Record, DataError> {
        let file = path.display().to_string();
        let bytes = std::fs::read(path).map_err(|e| DataError::Io {
            file: file.clone(),
            reason: e.to_string(),
        })?;
        if let Some(reason) = foreign_encoding(&bytes) {
            return Err(DataError::Malformed {
                file,
                row: 1,
                reason,
            });
        }
        // bytes that are not UTF-8 (a logger's `°C` in Windows-1252 in a
        // column that is not a signal) are kept as U+FFFD: such a column is
        // kept and ignored, and a signal's cell or header with one is
        // refused at its row and column (it used to refuse the whole file
        // with no row: "stream did not contain valid UTF-8")
        let text = String::from_utf8_lossy(&bytes);
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
                    hint: if map.0.contains_key(&Signal::Time) {
                        String::new()
                    } else {
                        missing_time_hint(&header_list)
                    },
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
        // the file line of each sample: the CSV reader skips blank lines,
        // which its record count would not see
        let mut lines = Vec::new();
        let mut counter = LineCounter::new(text);
        for (k, rec) in rdr.records().enumerate() {
            // a line of spaces or tabs is blank (skipped, as an empty one)
            if let Err(e) = &rec {
                if let (csv::ErrorKind::UnequalLengths { len: 1, .. }, Some(p)) =
                    (e.kind(), e.position())
                {
                    if counter.is_blank_at(p.byte() as usize) {
                        continue;
                    }
                }
            }
            let rec = rec.map_err(|e| {
                let row = e
                    .position()
                    .map_or(lines.last().map_or(k + 2, |l| l + 1), |p| {
                        counter.line_at(p.byte() as usize)
                    });
                match e.kind() {
                    csv::ErrorKind::UnequalLengths { len, .. } => {
                        DataError::ragged(file, row, *len as usize, &header_list)
                    }
                    _ => DataError::Malformed {
                        file: file.to_string(),
                        row,
                        reason: e.to_string(),
                    },
                }
            })?;
            let row = rec
                .position()
                .map_or(k + 2, |p| counter.line_at(p.byte() as usize));
            lines.push(row);
            if rec.len() != headers.len() {
                return Err(DataError::ragged(file, row, rec.len(), &header_list));
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
                if !v.is_finite() {
                    // finite as written, beyond f64 in SI (1e308 bar)
                    return Err(DataError::NotFiniteInSi {
                        file: file.to_string(),
                        row,
                        column: headers[j].to_string(),
                        text: cell.to_string(),
                        value: v,
                    });
                }
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
        time_axis::check(file, &headers[time_col], &time, |k| lines[k])?;
        // no blank line inside: sample k is on line k + 2 (see `Record::row`)
        if lines.iter().enumerate().all(|(k, &l)| l == k + 2) {
            lines = Vec::new();
        }
        Ok(Record {
            source: file.to_string(),
            time,
            signals,
            ignored,
            units,
            lines,
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
        if time.len() < MIN_SAMPLES
            || time.windows(2).any(|w| w[1] <= w[0])
            || !time.iter().all(|t| t.is_finite())
            || !time_axis::fine(&time)
        {
            return None;
        }
        let mut signals = BTreeMap::new();
        for (&j, v) in wanted[1..].iter().zip(values) {
            let (sig, _) = cols[j]?;
            let v = scale(j, v);
            // a value beyond f64 once in SI (1e308 bar): the full reader names it
            if !v.iter().all(|x| x.is_finite()) {
                return None;
            }
            signals.insert(sig, v);
        }
        Some(Record {
            source: file.to_string(),
            time,
            signals,
            ignored,
            units,
            lines: Vec::new(),
        })
    }
}

/// Where `signal` is missing from a file with headers `headers`: a
/// header that names it but is not read as it — its unit in parentheses
/// (`p1 (bar)`) or its name in capitals (`Time [s]`) — as the hint that
/// ends the error or data problem — ``(the header 'p1 (bar)' is not read
/// as p1: ... `p1 [bar]`)`` — empty where there is none.
pub fn unread_header_hint<S: AsRef<str>>(headers: &[S], signal: &str) -> String {
    headers
        .iter()
        .map(|h| h.as_ref().trim())
        .find_map(|h| {
            let cut = h.find(['[', '(']).unwrap_or(h.len());
            let name = h[..cut].trim();
            if !name.eq_ignore_ascii_case(signal) {
                return None;
            }
            let unit = h[cut..]
                .trim_matches(|c: char| matches!(c, '[' | ']' | '(' | ')') || c.is_whitespace());
            let right = if unit.is_empty() {
                signal.to_string()
            } else {
                format!("{signal} [{unit}]")
            };
            Some(format!(
                " (the header '{h}' is not read as {signal}: a signal's name is lower case and its unit in brackets, `{right}`)"
            ))
        })
        .unwrap_or_default()
}

/// Where `time` is missing from a file whose row 1 is `headers`: the hint
/// of [`unread_header_hint`]; or, where row 1 is not a header at all but a
/// line above it — a comment (`# ...`, `% ...`, `// ...`) or a
/// spreadsheet's separator line (`sep=,`) — `(row 1, 'sep=', is not a
/// header: the header must be the file's first line; delete the line(s)
/// above it)`; empty where there is neither. Both CSV readers (records,
/// command files) end their "missing column 'time'" with it.
pub fn missing_time_hint<S: AsRef<str>>(headers: &[S]) -> String {
    let hint = unread_header_hint(headers, "time");
    if !hint.is_empty() {
        return hint;
    }
    let Some(first) = headers.first().map(|h| h.as_ref().trim()) else {
        return hint;
    };
    let first = first.trim_start_matches('\u{feff}');
    let above = ["#", "%", "//"].iter().any(|p| first.starts_with(p))
        || first
            .get(..4)
            .is_some_and(|p| p.eq_ignore_ascii_case("sep="));
    if !above {
        return hint;
    }
    format!(
        " (row 1, '{first}', is not a header: the header must be the file's first line; delete the line(s) above it)"
    )
}

/// The file line (1-based, blank lines counted) of byte offsets of a text,
/// asked in increasing order: the CSV reader's own line count skips the
/// blank lines it skips. Shared by every CSV reader of hydrocyl.
pub struct LineCounter<'a> {
    text: &'a [u8],
    byte: usize,
    line: usize,
}

impl<'a> LineCounter<'a> {
    /// A counter at the start of `text` (line 1).
    pub fn new(text: &'a str) -> Self {
        LineCounter {
            text: text.as_bytes(),
            byte: 0,
            line: 1,
        }
    }

    /// Whether the record the CSV reader starts at byte offset `byte` is a
    /// line of nothing but spaces and tabs (a logger's padded blank line):
    /// blank, skipped as an empty line is, not a row of one empty cell.
    pub fn is_blank_at(&self, byte: usize) -> bool {
        let mut at = byte.min(self.text.len());
        while at < self.text.len() && matches!(self.text[at], b'\n' | b'\r') {
            at += 1;
        }
        self.text[at..]
            .iter()
            .take_while(|&&b| b != b'\n')
            .all(|&b| matches!(b, b' ' | b'\t' | b'\r'))
    }

    /// The line of the record starting at byte offset `byte` (not before
    /// the last one asked): the CSV reader's offset of a record is before
    /// the blank lines it skipped, which are passed over here.
    pub fn line_at(&mut self, byte: usize) -> usize {
        let mut to = byte.min(self.text.len());
        while to < self.text.len() && matches!(self.text[to], b'\n' | b'\r') {
            to += 1;
        }
        if to > self.byte {
            self.line += self.text[self.byte..to]
                .iter()
                .filter(|&&b| b == b'\n')
                .count();
            self.byte = to;
        }
        self.line
    }
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
    fn a_utf16_or_utf32_file_is_named_as_such() {
        let text = "time,command,position\n0,0,0\n1,0,0\n";
        let utf16le: Vec<u8> = text.encode_utf16().flat_map(u16::to_le_bytes).collect();
        let utf16be: Vec<u8> = text.encode_utf16().flat_map(u16::to_be_bytes).collect();
        let utf32le: Vec<u8> = text
            .chars()
            .flat_map(|c| (c as u32).to_le_bytes())
            .collect();
        let with_mark = |mark: &[u8], b: &[u8]| [mark, b].concat();
        let dir = std::env::temp_dir().join(format!("hydrocyl-utf16-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        for (bytes, words) in [
            (
                with_mark(&[0xFF, 0xFE], &utf16le),
                "UTF-16 text (byte-order mark FF FE)",
            ),
            (
                with_mark(&[0xFE, 0xFF], &utf16be),
                "UTF-16 text (byte-order mark FE FF)",
            ),
            (utf16le.clone(), "UTF-16 text (no byte-order mark"),
            (utf16be, "UTF-16 text (no byte-order mark"),
            (
                with_mark(&[0xFF, 0xFE, 0, 0], &utf32le),
                "UTF-32 text (byte-order mark FF FE 00 00)",
            ),
        ] {
            let p = dir.join("rec.csv");
            std::fs::write(&p, &bytes).unwrap();
            let e = Record::read(&p).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("{}: row 1: the file is {words}", p.display()))
                    && e.contains("save it as UTF-8 CSV")
                    && !e.contains('\n'),
                "{e}"
            );
        }
        // UTF-8 text, with its mark or not, and a one-character line are not
        for ok in [text.as_bytes(), "\u{feff}time\n".as_bytes(), b"t\n0\n"] {
            assert_eq!(foreign_encoding(ok), None);
        }
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_line_above_the_header_is_named_as_not_the_header() {
        let body = "time,position\n0,0\n1,0\n2,0\n3,0\n4,0\n5,0\n6,0\n7,0\n";
        for (line, cell) in [
            ("sep=,", "sep="),
            ("SEP=,", "SEP="),
            ("# rig 3, 2024-05-01", "# rig 3"),
            ("% logged", "% logged"),
            ("\u{feff}// export", "// export"),
        ] {
            let e = parse(&format!("{line}\n{body}")).unwrap_err().to_string();
            assert_eq!(
                e,
                format!("t.csv: row 1: missing column 'time' (row 1, '{cell}', is not a header: the header must be the file's first line; delete the line(s) above it)")
            );
        }
        // a header without time that is a header gets no such hint
        let e = parse("position,p1\n0,0\n").unwrap_err().to_string();
        assert_eq!(e, "t.csv: row 1: missing column 'time'");
    }

    #[test]
    fn a_decimal_comma_is_named_with_the_number_meant() {
        let ok = "time,position\n0,0\n1,0\n2,0\n3,0\n4,0\n5,0\n6,0\n7,0\n";
        for (cell, meant) in [("0,5", "0.5"), ("-1,25e-3", "-1.25e-3"), (" 12,0 ", "12.0")] {
            let e = parse(&ok.replace("3,0", &format!("3,\"{cell}\"")))
                .unwrap_err()
                .to_string();
            assert_eq!(
                e,
                format!("t.csv: row 5, column 'position': '{}' is not a number (a decimal comma: hydrocyl reads a decimal point, `{meant}`)", cell.trim())
            );
        }
        // text that is no number with a decimal comma gets no hint
        for cell in ["1,2,3", "a,5", "5,", ",5", "abc"] {
            let e = parse(&ok.replace("3,0", &format!("3,\"{cell}\"")))
                .unwrap_err()
                .to_string();
            assert!(e.ends_with("is not a number"), "{e}");
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

    /// Blank lines are skipped, but a row is still the file's line (it was
    /// the count of data rows: the `nan` on line 13 was "row 12").
    #[test]
    fn rows_are_file_lines_after_blank_lines() {
        let mut s = String::from("time,p1 [bar]\n");
        for i in 0..20 {
            s.push_str(&format!("{i},1\n"));
            if i == 5 || i == 7 {
                s.push('\n');
            }
        }
        let r = parse(&s).unwrap();
        assert_eq!((r.row(0), r.row(5), r.row(6), r.row(8)), (2, 7, 9, 12));
        let e = parse(&s.replace("10,1", "10,nan")).unwrap_err().to_string();
        assert!(e.contains("row 14,"), "{e}");
        let e = parse(&s.replace("10,1", "10,1,2")).unwrap_err().to_string();
        assert!(
            e.contains("row 14, column 3:") && !e.contains("record"),
            "{e}"
        );
        let e = parse(&s.replace("19,1", "1e9,1")).unwrap_err().to_string();
        assert!(
            e.contains("row 23, column 'time'") && e.contains("1e6"),
            "{e}"
        );
        // without blank lines the fast path reads it; rows are k + 2
        let r = parse(&s.replace("\n\n", "\n")).unwrap();
        assert!(r.lines.is_empty() && r.row(10) == 12);
    }

    /// A cell finite as written but infinite in SI (1e308 bar) is the
    /// non-finite error of a `nan` cell; a last time stamp far from the
    /// others is refused (it used to be simulated across, for minutes).
    #[test]
    fn values_beyond_f64_in_si_and_absurd_time_stamps_are_errors() {
        let mut s = String::from("time [s],p1 [bar]\n");
        for i in 0..2000 {
            s.push_str(&format!("{},{}\n", i as f64 * 0.006, 50 + i % 7));
        }
        assert!(parse(&s).is_ok());
        let e = parse(&s.replace("\n3,53", "\n3,1e308"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("row 502, column 'p1 [bar]'") && e.contains("not finite"),
            "{e}"
        );
        let last = format!("{}", 1999.0 * 0.006);
        for bad in ["1e308", "1e9", "1000000.5", "1000"] {
            let e = parse(&s.replace(&format!("{last},"), &format!("{bad},")))
                .unwrap_err()
                .to_string();
            assert!(e.contains("row 2001, column 'time [s]'"), "{bad}: {e}");
        }
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

    /// A column that is not a signal, written in Windows-1252 by a logger
    /// (`Öl [°C]`), is kept and ignored, as the format promises of columns
    /// that are not signals; a signal's cell with such a byte is refused at
    /// its row and column. The file was refused whole, with no row ("cannot
    /// read: stream did not contain valid UTF-8").
    #[test]
    fn bytes_that_are_not_utf8_are_named_only_where_a_signal_has_them() {
        let dir = std::env::temp_dir().join(format!("hydrocyl-latin1-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mut s = b"time [s],command,\xd6l [\xb0C]\r\n".to_vec();
        for i in 0..10 {
            s.extend(format!("{},0.1,41.5\r\n", i as f64 * 1e-3).bytes());
        }
        let ok = dir.join("ok.csv");
        std::fs::write(&ok, &s).unwrap();
        let r = Record::read(&ok).unwrap();
        assert_eq!(r.time.len(), 10);
        assert_eq!(r.ignored.len(), 1, "{:?}", r.ignored);
        let at = s.windows(5).position(|w| w == b"0.1,4").unwrap();
        s[at + 2] = 0xb0;
        let bad = dir.join("bad.csv");
        std::fs::write(&bad, &s).unwrap();
        let e = Record::read(&bad).unwrap_err().to_string();
        std::fs::remove_dir_all(&dir).ok();
        assert!(e.contains("row 2, column 'command'"), "{e}");
    }

    /// A line of spaces or tabs (a logger's padded blank line, at the end
    /// or between rows) is blank: skipped as an empty line is, and counted
    /// in the rows of later errors. It was refused as a row of one cell
    /// ("row 5, column 'command': 1 cell, the header has 2").
    #[test]
    fn a_line_of_spaces_is_blank() {
        let map = ColumnMap::default();
        let mut s = String::from("time [s],command\n");
        for i in 0..10 {
            s.push_str(&format!("{},0.1\n", i));
            if i == 3 {
                s.push_str("  \t \r\n");
            }
        }
        s.push_str(" \n\t\r\n");
        let r = Record::parse("x.csv", &s, &map).unwrap();
        assert_eq!(r.time.len(), 10);
        let bad = s.replacen("5,0.1", "5,x", 1);
        let e = Record::parse("x.csv", &bad, &map).unwrap_err().to_string();
        assert!(e.contains("row 8, column 'command'"), "{e}");
    }
}
