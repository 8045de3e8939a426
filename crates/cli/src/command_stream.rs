//! A long command file read a buffer at a time, so that `hydrocyl simulate`
//! holds a window of it, never the whole (issue 18: memory grows with the
//! rig, not the record).
//!
//! [`scan`] reads the file once before the run: it checks every row (so a
//! bad row stops the command before any computation, as for a file read
//! whole) and gives the row count, the first and last time and the range of
//! the values. [`Chunks`] then reads it again during the run, a buffer at a
//! time, as a [`CommandSource`]. Both read *plain* CSV only (the fast path
//! of [`hydrocyl_identify::plaincsv`]); a file that is not plain (quotes, a
//! blank line inside, a bad cell) makes [`scan`] return `None`, and the
//! caller reads it whole with [`crate::command::read_table`], which
//! accepts any CSV and words every error.

use crate::command::{columns_of, CommandUnit};
use crate::error::CliError;
use hydrocyl_identify::plaincsv::{Body, Rows};
use hydrocyl_system::run::CommandSource;
use std::fs::File;
use std::io::Read as _;
use std::path::Path;

/// Bytes read at a time.
const BUFFER: usize = 1 << 20;

/// What [`scan`] found in a plain command file.
#[derive(Clone, Debug)]
pub struct Scan {
    /// Data rows.
    pub rows: usize,
    /// First and last time \[s\].
    pub t0: f64,
    /// Last time \[s\].
    pub t1: f64,
    /// Smallest and largest command (in the rig's unit).
    pub min: f64,
    /// Largest command.
    pub max: f64,
    /// Commands beyond the limit [`scan`] was given (±1, a normalised
    /// valve's stroke; a pump's rating).
    pub outside: usize,
    /// The largest command in magnitude and its time.
    pub peak: (f64, f64),
}

/// Reads a plain command file a buffer at a time.
pub struct Chunks {
    file: File,
    rows: Rows,
    /// The time column's header, as errors name it.
    time_header: String,
    time_factor: f64,
    command_factor: f64,
    buf: Vec<u8>,
    /// Bytes of `buf` not yet parsed (a partial line).
    kept: usize,
    eof: bool,
    blank: bool,
    cols: [Vec<f64>; 2],
    prev: f64,
}

impl Chunks {
    /// Opens `path` and reads its header; `None` when it is not plain.
    fn open(path: &Path, unit: CommandUnit) -> Result<Option<Self>, CliError> {
        let file_name = path.display().to_string();
        let mut file = File::open(path).map_err(|source| CliError::Io {
            path: file_name.clone(),
            source,
        })?;
        let mut buf = vec![0u8; BUFFER];
        let mut len = 0;
        // the header line
        let nl = loop {
            if let Some(i) = buf[..len].iter().position(|&b| b == b'\n') {
                break i;
            }
            if len == buf.len() {
                return Ok(None);
            }
            let n = file.read(&mut buf[len..]).map_err(|source| CliError::Io {
                path: file_name.clone(),
                source,
            })?;
            if n == 0 {
                return Ok(None);
            }
            len += n;
        };
        let Ok(header) = std::str::from_utf8(&buf[..nl]) else {
            return Ok(None);
        };
        if header.starts_with('\u{feff}') || !Rows::plain_bytes(&buf[..=nl]) {
            return Ok(None);
        }
        let header = header.strip_suffix('\r').unwrap_or(header);
        let c = columns_of(&file_name, header.split(',').map(str::trim), unit)?;
        let width = header.split(',').count();
        let Some(rows) = Rows::new(width, &[c.time, c.command]) else {
            return Ok(None);
        };
        buf.copy_within(nl + 1..len, 0);
        Ok(Some(Self {
            file,
            rows,
            time_factor: c.time_factor,
            command_factor: c.command_factor,
            time_header: c.time_header,
            buf,
            kept: len - nl - 1,
            eof: false,
            blank: false,
            cols: [Vec::new(), Vec::new()],
            prev: f64::NEG_INFINITY,
        }))
    }

    /// The next rows (times \[s\] and commands) into `self.cols`, cleared
    /// first; `Ok(false)` at the end of the file, `Err(())` when the rest
    /// is not plain (or the times do not increase).
    fn next(&mut self) -> Result<bool, std::io::Error> {
        self.cols[0].clear();
        self.cols[1].clear();
        loop {
            if self.eof && self.kept == 0 {
                return Ok(false);
            }
            if !self.eof {
                let n = self.file.read(&mut self.buf[self.kept..])?;
                self.kept += n;
                self.eof = n == 0;
            }
            // whole lines only, unless the file has ended
            let cut = if self.eof {
                self.kept
            } else {
                match self.buf[..self.kept].iter().rposition(|&b| b == b'\n') {
                    Some(i) => i + 1,
                    None if self.kept == self.buf.len() => {
                        // a line longer than the buffer: grow it
                        self.buf.resize(self.buf.len() * 2, 0);
                        continue;
                    }
                    None => continue,
                }
            };
            let piece = &self.buf[..cut];
            let plain = std::str::from_utf8(piece).is_ok() && Rows::plain_bytes(piece);
            let body = if plain {
                self.rows.parse(piece, &mut self.cols)
            } else {
                None
            };
            let got_rows = !self.cols[0].is_empty();
            let bad = match body {
                None => true,
                Some(_) if self.blank && got_rows => true,
                Some(b) => {
                    self.blank |= b == Body::BlankEnd;
                    false
                }
            };
            if bad {
                return Err(std::io::Error::other("not plain"));
            }
            self.buf.copy_within(cut..self.kept, 0);
            self.kept -= cut;
            // a power-of-ten unit on the decimal: 1.999 ms is 0.001999 s
            let [t, u] = &mut self.cols;
            hydrocyl_identify::data::scale_decimal(t, self.time_factor);
            hydrocyl_identify::data::scale_decimal(u, self.command_factor);
            for &t in &self.cols[0] {
                if t <= self.prev {
                    return Err(std::io::Error::other("not plain"));
                }
                self.prev = t;
            }
            if got_rows {
                return Ok(true);
            }
        }
    }
}

impl CommandSource for Chunks {
    fn read(&mut self, t: &mut Vec<f64>, u: &mut Vec<f64>) -> Result<bool, String> {
        let more = self
            .next()
            .map_err(|e| format!("the command file changed while it was read ({e})"))?;
        t.extend_from_slice(&self.cols[0]);
        u.extend_from_slice(&self.cols[1]);
        Ok(more)
    }
}

/// Checks a plain command file row by row without holding it (see the
/// module doc): its [`Scan`] and a [`Chunks`] reader at its first row, or
/// `None` when it is not plain (read it whole instead; that reports any
/// error).
/// Commands beyond `limit` in magnitude are counted ([`Scan::outside`]).
pub fn scan(
    path: &Path,
    unit: CommandUnit,
    limit: f64,
) -> Result<Option<(Scan, Chunks)>, CliError> {
    let Some(mut c) = Chunks::open(path, unit)? else {
        return Ok(None);
    };
    let mut s = Scan {
        rows: 0,
        t0: f64::NAN,
        t1: f64::NAN,
        min: f64::INFINITY,
        max: f64::NEG_INFINITY,
        outside: 0,
        peak: (0.0, f64::NAN),
    };
    let io = |source| CliError::Io {
        path: path.display().to_string(),
        source,
    };
    loop {
        match c.next() {
            Ok(true) => {}
            Ok(false) => break,
            Err(e) if e.kind() == std::io::ErrorKind::Other => return Ok(None),
            Err(e) => return Err(io(e)),
        }
        let [t, u] = &c.cols;
        if s.rows == 0 {
            s.t0 = t[0];
        }
        if let Some(k) = t
            .iter()
            .position(|&tk| hydrocyl_identify::data::beyond_span(s.t0, tk))
        {
            let file = path.display().to_string();
            crate::command::check_span(&file, &c.time_header, s.rows + k + 2, s.t0, t[k])?;
        }
        s.rows += t.len();
        s.t1 = t[t.len() - 1];
        for (&tk, &uk) in t.iter().zip(u) {
            s.min = s.min.min(uk);
            s.max = s.max.max(uk);
            if uk.abs() > limit {
                s.outside += 1;
            }
            if uk.abs() > s.peak.0.abs() {
                s.peak = (uk, tk);
            }
        }
    }
    if s.rows < 2 {
        return Ok(None);
    }
    let again = Chunks::open(path, unit)?.ok_or_else(|| {
        CliError::Input(format!(
            "{}: the command file changed while it was read",
            path.display()
        ))
    })?;
    Ok(Some((s, again)))
}
