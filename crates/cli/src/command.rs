//! The command file of `hydrocyl simulate`: CSV with a `time` column
//! (`time`, `time [s]` or `time [ms]`) and one `command` column in the unit
//! the rig's command takes ([`CommandUnit`]) — or, for a closed-loop rig
//! (one with a `position_controller`), one `reference` column, the position
//! set-point in m or mm; other columns are ignored. Errors name the file, row
//! and column.

use crate::error::CliError;
use hydrocyl_identify::data::{scale_decimal, scaled_decimal, DataError};
use hydrocyl_identify::plaincsv::{Body, PlainCsv, Rows};
use hydrocyl_system::signal::Signal;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{mpsc, Arc};

/// Plain bodies of at least this many bytes are parsed in two halves by
/// [`Ahead`]'s two threads; a shorter one by its reading thread alone.
const SPLIT_ABOVE: usize = 1 << 16;

/// What a rig's command is, by the port that reads it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CommandUnit {
    /// A normalised spool demand \[-\] (valve rigs): `command`,
    /// `command [-]`, `command [1]` or `command [%]`.
    Normalised,
    /// A drive voltage \[V\] (pump rigs): `command`, `command [V]` or
    /// `command [mV]`.
    Volt,
    /// A position set-point \[m\] (closed-loop rigs, whose controller makes
    /// the command): `reference`, `reference [m]` or `reference [mm]`.
    Reference,
    /// An imposed velocity \[m/s\] (a friction bench's drive): `command`,
    /// `command [m/s]` or `command [mm/s]`.
    Velocity,
    /// A position \[m\] the input sets directly (a spool position read by
    /// a valve, no spool model between): `command`, `command [m]` or
    /// `command [mm]`.
    Position,
}

impl CommandUnit {
    /// The unit's symbol.
    pub fn symbol(self) -> &'static str {
        match self {
            CommandUnit::Normalised => "-",
            CommandUnit::Volt => "V",
            CommandUnit::Reference | CommandUnit::Position => "m",
            CommandUnit::Velocity => "m/s",
        }
    }

    /// The input column's name: `command`, or `reference` for a closed-loop rig.
    pub fn column(self) -> &'static str {
        match self {
            CommandUnit::Reference => "reference",
            _ => "command",
        }
    }

    /// The factor from `unit` to this unit, `None` if it does not fit.
    fn factor(self, unit: Option<&str>) -> Option<f64> {
        match (self, unit) {
            (_, None) => Some(1.0),
            (CommandUnit::Normalised, Some("-" | "1")) => Some(1.0),
            (CommandUnit::Normalised, Some("%")) => Some(0.01),
            (CommandUnit::Volt, Some("V")) => Some(1.0),
            (CommandUnit::Volt, Some("mV")) => Some(1e-3),
            (CommandUnit::Reference | CommandUnit::Position, Some("m")) => Some(1.0),
            (CommandUnit::Reference | CommandUnit::Position, Some("mm")) => Some(1e-3),
            (CommandUnit::Velocity, Some("m/s")) => Some(1.0),
            (CommandUnit::Velocity, Some("mm/s")) => Some(1e-3),
            _ => None,
        }
    }

    fn accepted(self) -> &'static str {
        match self {
            CommandUnit::Normalised => "-, 1 or % (a normalised spool demand)",
            CommandUnit::Volt => "V or mV (a drive voltage)",
            CommandUnit::Reference => "m or mm (a position set-point)",
            CommandUnit::Velocity => "m/s or mm/s (the rod velocity the drive imposes)",
            CommandUnit::Position => "m or mm (a position the input sets directly)",
        }
    }
}

/// Where the command file's columns are.
#[derive(Debug)]
pub struct Columns {
    /// Index of the `time` column.
    pub time: usize,
    /// Its header cell (`time [ms]`), as errors name the column.
    pub time_header: String,
    /// Its factor to seconds.
    pub time_factor: f64,
    /// Index of the `command` (or `reference`) column.
    pub command: usize,
    /// Its factor to the rig's unit.
    pub command_factor: f64,
}

/// Splits `name [unit]`.
fn name_unit(h: &str) -> (&str, Option<&str>) {
    match h.find('[') {
        Some(o) if h.ends_with(']') => (h[..o].trim(), Some(h[o + 1..h.len() - 1].trim())),
        _ => (h.trim(), None),
    }
}

/// Finds the `time` and `command` columns among `headers` of file `file`.
pub fn columns_of<'a>(
    file: &str,
    headers: impl Iterator<Item = &'a str>,
    unit: CommandUnit,
) -> Result<Columns, CliError> {
    let headers: Vec<&str> = headers.collect();
    // an empty file, or a first line of nothing but commas and blanks: as
    // the record reader (`diagnose`) words it
    if headers.iter().all(|h| h.trim().is_empty()) {
        return Err(CliError::Input(format!("{file}: row 1: empty header")));
    }
    if let Some(why) = hydrocyl_identify::data::foreign_separator(&headers) {
        return Err(CliError::Input(format!(
            "{file}: row 1: {why} (`time,command`)"
        )));
    }
    let mut time: Option<(usize, f64)> = None;
    let mut command: Option<(usize, f64)> = None;
    for (i, h) in headers.iter().enumerate() {
        let (name, u) = name_unit(h);
        let found = match name {
            "time" => &mut time,
            n if n == unit.column() => &mut command,
            _ => continue,
        };
        if let Some((j, _)) = found {
            // as the record reader (`diagnose`) words it
            return Err(CliError::Input(format!(
                "{file}: row 1, column '{h}': a second `{name}` column (columns {} and {}); keep one",
                *j + 1,
                i + 1
            )));
        }
        let f = if name == "time" {
            match u {
                None | Some("s") => 1.0,
                Some("ms") => 1e-3,
                Some(u) => {
                    return Err(CliError::Input(format!(
                        "{file}: row 1, column '{h}': unknown unit '{u}' (accepted: s, ms)"
                    )))
                }
            }
        } else {
            unit.factor(u).ok_or_else(|| {
                CliError::Input(format!(
                    "{file}: row 1, column '{h}': unit `{}` does not fit this rig's {} [{}] (use {})",
                    u.unwrap_or_default(),
                    unit.column(),
                    unit.symbol(),
                    unit.accepted()
                ))
            })?
        };
        *found = Some((i, f));
    }
    let (time, time_factor) = time.ok_or_else(|| {
        CliError::Input(format!(
            "{file}: row 1: missing column 'time'{}",
            hydrocyl_identify::data::missing_time_hint(&headers)
        ))
    })?;
    let (command, command_factor) = command.ok_or_else(|| {
        CliError::Input(match unit {
            CommandUnit::Reference => format!(
                "{file}: row 1: missing column 'reference' (a closed-loop rig is driven by its position set-point)"
            ),
            _ => format!(
                "{file}: row 1: missing column 'command'{}",
                hydrocyl_identify::data::unread_header_hint(&headers, "command")
            ),
        })
    })?;
    Ok(Columns {
        time,
        time_header: headers[time].to_string(),
        time_factor,
        command,
        command_factor,
    })
}

/// The fast path of [`parse_command`] for plain numeric CSV; `None` sends the
/// text to the full reader, which also reports every error.
fn read_plain(text: &str, c: &Columns) -> Option<(Vec<f64>, Vec<f64>)> {
    let csv = PlainCsv::new(text)?;
    finish_plain(csv.columns(&[c.time, c.command])?, c)
}

/// The time and command columns read by the fast path, put in seconds and
/// the rig's unit; `None` (the full reader) unless the times increase.
fn finish_plain(mut cols: Vec<Vec<f64>>, c: &Columns) -> Option<(Vec<f64>, Vec<f64>)> {
    let (t, u) = scaled(&mut cols, c)?;
    let (t, u) = (std::mem::take(t), std::mem::take(u));
    increasing(&t).then_some((t, u))
}

/// The time and command columns `cols` (as the fast path reads them), put
/// in seconds and the rig's unit.
fn scaled<'a>(
    cols: &'a mut [Vec<f64>],
    c: &Columns,
) -> Option<(&'a mut Vec<f64>, &'a mut Vec<f64>)> {
    let [t, u] = cols else { return None };
    scale_decimal(t, c.time_factor);
    scale_decimal(u, c.command_factor);
    Some((t, u))
}

/// At least two times, none at or before the one before.
fn increasing(t: &[f64]) -> bool {
    t.len() >= 2 && !t.windows(2).any(|w| w[1] <= w[0])
}

/// Scales the columns of the two halves of a long body (as the fast path
/// reads them, [`scaled`]); `None` (the full reader) unless the times
/// increase through both, as [`increasing`] on the two joined.
fn scaled_halves(first: &mut [Vec<f64>], second: &mut [Vec<f64>], c: &Columns) -> Option<()> {
    let (t1, _) = scaled(first, c)?;
    let (t2, _) = scaled(second, c)?;
    let across = match (t1.last(), t2.first()) {
        (Some(a), Some(b)) => b > a || b.is_nan() || a.is_nan(),
        _ => true,
    };
    let each = |t: &[f64]| t.len() < 2 || increasing(t);
    (t1.len() + t2.len() >= 2 && across && each(t1) && each(t2)).then_some(())
}

/// The time and command columns of two halves ([`scaled_halves`]) joined
/// straight into the shared storage a [`Table`] keeps (one copy).
fn joined(first: &[Vec<f64>], second: &[Vec<f64>]) -> (Arc<[f64]>, Arc<[f64]>) {
    fn part(h: &[Vec<f64>], k: usize) -> &[f64] {
        h.get(k).map_or(&[], Vec::as_slice)
    }
    let column = |k: usize| -> Arc<[f64]> {
        part(first, k)
            .iter()
            .chain(part(second, k))
            .copied()
            .collect()
    };
    (column(0), column(1))
}

/// The bytes of file `path` (an error names it).
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, CliError> {
    read_into(path, Vec::new())
}

/// The bytes of file `path` appended to `buf` (an error names the file).
fn read_into(path: &Path, mut buf: Vec<u8>) -> Result<Vec<u8>, CliError> {
    use std::io::Read as _;
    std::fs::File::open(path)
        .and_then(|mut f| f.read_to_end(&mut buf))
        .map(|_| buf)
        .map_err(|source| CliError::Io {
            path: path.display().to_string(),
            source,
        })
}

/// A command file read whole, as a run takes it.
pub struct Table {
    /// The sample times \[s\] (the output times).
    pub times: std::sync::Arc<[f64]>,
    /// The command as a signal of time.
    pub signal: Signal,
    /// Samples outside ±1 (a normalised command; else 0).
    pub outside: usize,
    /// The largest sample in magnitude and its time (a normalised command).
    pub peak: (f64, f64),
}

/// Reads the command CSV `bytes` of file `path` as a [`Table`]: errors
/// name file, row and column.
pub fn read_table(path: &Path, bytes: &[u8], unit: CommandUnit) -> Result<Table, CliError> {
    let file = path.display().to_string();
    let (t, u) = parse_command(&file, bytes, unit)?;
    table_of(&file, t.into(), u.into(), unit)
}

/// The samples `u` (at times `t`) beyond `limit` in magnitude, and the
/// largest in magnitude with its time.
pub fn beyond(t: &[f64], u: &[f64], limit: f64) -> (usize, (f64, f64)) {
    hydrocyl_system::netlist::samples_beyond(t, u, limit)
}

/// The [`Table`] of file `file`'s samples `(t, u)`.
fn table_of(
    file: &str,
    times: Arc<[f64]>,
    u: Arc<[f64]>,
    unit: CommandUnit,
) -> Result<Table, CliError> {
    let (outside, peak) = if unit == CommandUnit::Normalised {
        beyond(&times, &u, 1.0)
    } else {
        (0, (0.0, f64::NAN))
    };
    // the output times are the table's own (shared, not copied)
    let signal = Signal::shared_table(times.clone(), u)
        .map_err(|e| CliError::Input(format!("{file}: {e}")))?;
    Ok(Table {
        times,
        signal,
        outside,
        peak,
    })
}

/// The fast path's view of command CSV `bytes`: its plain text; `None`
/// for the full reader.
fn plain_text(bytes: &[u8]) -> Option<PlainCsv<'_>> {
    PlainCsv::new(std::str::from_utf8(bytes).ok()?)
}

/// Where the columns of `unit` are in the plain text `csv` of file `file`;
/// `None` for the full reader. The header cells are split and trimmed as
/// the full reader reads a header without quotes (which a plain one is):
/// building that reader (its state machine) cost more than reading a short
/// command file.
fn plain_columns(file: &str, csv: &PlainCsv, unit: CommandUnit) -> Option<Columns> {
    columns_of(file, csv.headers(), unit).ok()
}

/// The second half of the body of the plain text `csv` (after
/// [`cut_of`]); `None` when it is not long enough to halve.
fn second_half<'a>(csv: &PlainCsv<'a>) -> Option<&'a [u8]> {
    let body = csv.body().as_bytes();
    Some(&body[cut_of(body)?..])
}

/// Where a plain body long enough to halve is cut: after the line end at
/// or after its middle.
fn cut_of(body: &[u8]) -> Option<usize> {
    if body.len() < SPLIT_ABOVE {
        return None;
    }
    let mid = body.len() / 2;
    let at = body[mid..].iter().position(|&b| b == b'\n')?;
    Some(mid + at + 1).filter(|&cut| cut < body.len())
}

/// The cells of columns `[time, command]` (indices) of the whole lines
/// `piece` (see [`Rows::parse`]), in columns.
fn parse_piece(csv: &PlainCsv, cols: [usize; 2], piece: &[u8]) -> Option<(Body, Vec<Vec<f64>>)> {
    let rows = Rows::new(csv.width(), &cols)?;
    let hint = piece.len() / (8 * csv.width()).max(1) + 1;
    let mut out = vec![Vec::with_capacity(hint), Vec::with_capacity(hint)];
    let end = rows.parse(piece, &mut out)?;
    Some((end, out))
}

/// A piece of a plain body parsed ([`parse_piece`]; `None`: not plain).
type Piece = Option<(Body, Vec<Vec<f64>>)>;

/// What the reading thread of [`Ahead`] hands back.
enum Read {
    /// The table read whole (`None`: a file to stream).
    Whole(Option<Table>),
    /// The halves of a long plain body: the first, and the second when this
    /// thread parsed it too (else the caller reads it).
    Half(Piece, Option<Piece>),
}

/// The halves of a long plain body parsed before the rig's unit is known,
/// on the columns its header suggests: `time`, and `command` (else
/// `reference`). Used when the unit's columns are these.
struct Early {
    /// The indices of the time and input columns parsed.
    columns: [usize; 2],
    first: Piece,
    /// `None` when the caller took the second half first.
    second: Option<Piece>,
}

impl Early {
    /// Parses the halves of the plain text `csv` (a body long enough to
    /// halve; else `None`); the second only when `second_taken` was not yet
    /// set (by the caller, which then parses it), and sets it.
    fn parse(csv: &PlainCsv, second_taken: &AtomicBool) -> Option<Self> {
        let names: Vec<&str> = csv.headers().map(|h| name_unit(h).0).collect();
        let at = |name: &str| names.iter().position(|n| *n == name);
        let input =
            at(CommandUnit::Normalised.column()).or_else(|| at(CommandUnit::Reference.column()))?;
        let columns = [at("time")?, input];
        let body = csv.body().as_bytes();
        let cut = cut_of(body)?;
        let first = parse_piece(csv, columns, &body[..cut]);
        let second = (!second_taken.swap(true, Ordering::AcqRel))
            .then(|| parse_piece(csv, columns, &body[cut..]));
        Some(Early {
            columns,
            first,
            second,
        })
    }
}

/// A command file read ahead: a thread reads it while the rig is read and
/// checked. A long plain body is parsed at once, in halves, on the columns
/// its header suggests ([`Early`]): the thread parses the first, and the
/// second unless the thread that waits for the table ([`Ahead::table`])
/// comes for it first. Once told the rig's unit, a body parsed on other
/// columns than the unit's (or a short or not plain one) is parsed (or
/// read whole) again. A file longer than `stream_above` bytes is left to
/// the streamed reader (`None`).
pub struct Ahead {
    path: PathBuf,
    unit: mpsc::Sender<CommandUnit>,
    bytes: mpsc::Receiver<Arc<Vec<u8>>>,
    /// Set by whichever thread parses a long body's second half first.
    second_taken: Arc<AtomicBool>,
    /// The thread's result, sent as its last act (its exit is not waited for).
    read: mpsc::Receiver<Result<Read, CliError>>,
}

impl Ahead {
    /// Starts reading `path`. Its buffer is allocated here, on the thread
    /// that later takes the table: freed once the file is parsed, its
    /// memory serves that thread's next allocations (the output's blocks)
    /// instead of fresh pages (see [`crate::heap`]).
    pub fn start(path: PathBuf, stream_above: u64) -> Self {
        let (unit, told) = mpsc::channel::<CommandUnit>();
        let (send, bytes) = mpsc::channel::<Arc<Vec<u8>>>();
        let (done, read) = mpsc::channel::<Result<Read, CliError>>();
        let file = path.clone();
        let len = std::fs::metadata(&path).ok().map(|m| m.len());
        let buf = match len {
            Some(n) if n <= stream_above => Vec::with_capacity(n.try_into().unwrap_or(0)),
            _ => Vec::new(),
        };
        let second_taken = Arc::new(AtomicBool::new(false));
        let taken = second_taken.clone();
        std::thread::spawn(move || {
            let path = file;
            let _ = done.send(Self::read(
                &path,
                len,
                stream_above,
                buf,
                (&send, &told),
                &taken,
            ));
        });
        Ahead {
            path,
            unit,
            bytes,
            second_taken,
            read,
        }
    }

    /// The reading thread's work on the file of `len` bytes, read into
    /// `buf`: the bytes go out on `channels.0` as soon as they are in, the
    /// rig's unit comes in on `channels.1`.
    fn read(
        path: &Path,
        len: Option<u64>,
        stream_above: u64,
        buf: Vec<u8>,
        channels: (&mpsc::Sender<Arc<Vec<u8>>>, &mpsc::Receiver<CommandUnit>),
        second_taken: &AtomicBool,
    ) -> Result<Read, CliError> {
        let (send, told) = channels;
        if len.is_some_and(|n| n > stream_above) {
            return Ok(Read::Whole(None));
        }
        crate::progress::mark("command: reading");
        let read = read_into(path, buf).map(Arc::new);
        if let Ok(b) = &read {
            let _ = send.send(b.clone());
        }
        crate::progress::mark("command: read");
        let csv = read.as_deref().ok().and_then(|b| plain_text(b));
        let early = csv.as_ref().and_then(|c| Early::parse(c, second_taken));
        crate::progress::mark("command: parsed early");
        // the run stopped before it needed the command: nothing to say
        let Ok(unit) = told.recv() else {
            return Ok(Read::Whole(None));
        };
        crate::progress::mark("command: unit told");
        if let Some(csv) = &csv {
            let body = csv.body().as_bytes();
            let file = path.display().to_string();
            if let (Some(c), Some(cut)) = (plain_columns(&file, csv, unit), cut_of(body)) {
                let columns = [c.time, c.command];
                return Ok(match early.filter(|e| e.columns == columns) {
                    Some(e) => Read::Half(e.first, e.second),
                    // parsed on other columns: the second half, if this
                    // thread took it, is parsed again by the caller
                    None => Read::Half(parse_piece(csv, columns, &body[..cut]), None),
                });
            }
        }
        let bytes = read?;
        read_table(path, &bytes, unit).map(|t| Read::Whole(Some(t)))
    }

    /// Tells the thread the rig's unit: it parses the file now.
    pub fn parse(&self, unit: CommandUnit) {
        let _ = self.unit.send(unit);
    }

    /// The table in `unit` (after [`Ahead::parse`]), `None` for a file to
    /// stream; the second half of a long body is parsed here meanwhile,
    /// unless the reading thread has taken it (then after it, if that
    /// thread parsed it on other columns than the unit's).
    pub fn table(self, unit: CommandUnit) -> Result<Option<Table>, CliError> {
        let file = self.path.display().to_string();
        let bytes = self.bytes.recv().ok();
        // the plain text, the unit's columns in it and its second half
        let plain = bytes.as_deref().and_then(|b| {
            let csv = plain_text(b)?;
            let c = plain_columns(&file, &csv, unit)?;
            let piece = second_half(&csv)?;
            Some((csv, c, piece))
        });
        let parse_second = |(csv, c, piece): &(PlainCsv, Columns, &[u8])| -> Piece {
            parse_piece(csv, [c.time, c.command], piece)
        };
        // the second half here, unless the reading thread took it first
        let mut second = match &plain {
            Some(p) if !self.second_taken.swap(true, Ordering::AcqRel) => Some(parse_second(p)),
            _ => None,
        };
        let read = self
            .read
            .recv()
            .map_err(|_| CliError::Input("the command file's reader failed".into()))??;
        let first = match read {
            Read::Whole(t) => return Ok(t),
            Read::Half(first, early) => {
                // the thread's second half (on the unit's columns), or, if
                // it took it and parsed it on others, the second half now
                second = second.or(early);
                if second.is_none() {
                    second = plain.as_ref().map(parse_second);
                }
                first
            }
        };
        // both halves plain (blank lines only at the very end), or the
        // full reader, which names what is wrong
        let halves = second.zip(plain).and_then(|(second, (_, c, piece))| {
            let ((end, mut first), (_, mut second)) = (first?, second?);
            if end == Body::BlankEnd && !piece.iter().all(|&b| b == b'\n' || b == b'\r') {
                return None;
            }
            scaled_halves(&mut first, &mut second, &c)?;
            Some((first, second, c.time_header))
        });
        // a half read by the thread and no bytes here: the thread read them
        let Some(bytes) = bytes else {
            return Err(CliError::Input(format!("{file}: not read")));
        };
        match halves {
            Some((first, second, column)) => {
                // the file's bytes, done with, are freed first: the table
                // takes their memory, not fresh pages (see `crate::heap`)
                drop(bytes);
                let (t, u) = joined(&first, &second);
                check_plain_span(&file, &column, &t)?;
                table_of(&file, t, u, unit).map(Some)
            }
            None => read_table(&self.path, &bytes, unit).map(Some),
        }
    }
}

// a command file spans at most the record reader's limit (`MAX_SPAN_S`,
// about 11.6 days), one rule for both
use hydrocyl_identify::data::beyond_span;

/// Refuses sample `t` (at CSV row `row` of `file`, time column header
/// `column`) lying more than [`MAX_SPAN_S`](hydrocyl_identify::data::MAX_SPAN_S) after the first sample `t0`,
/// with the record reader's error.
pub fn check_span(file: &str, column: &str, row: usize, t0: f64, t: f64) -> Result<(), CliError> {
    if beyond_span(t0, t) {
        return Err(CliError::Input(
            DataError::SpanTooLong {
                file: file.to_string(),
                row,
                column: column.to_string(),
                t,
                span: t - t0,
            }
            .to_string(),
        ));
    }
    Ok(())
}

/// The command CSV `bytes` of file `file` as `(time [s], command [unit])`;
/// a span longer than [`MAX_SPAN_S`](hydrocyl_identify::data::MAX_SPAN_S) is refused.
pub fn parse_command(
    file: &str,
    bytes: &[u8],
    unit: CommandUnit,
) -> Result<(Vec<f64>, Vec<f64>), CliError> {
    let (t, u, column) = parse_samples(file, bytes, unit)?;
    check_plain_span(file, &column, &t)?;
    Ok((t, u))
}

/// [`check_span`] on the times `t` of a whole file (time column header
/// `column`). The full reader checked each row at its line; what reaches
/// here from the fast path has no blank line inside, so sample k is on
/// line k + 2.
fn check_plain_span(file: &str, column: &str, t: &[f64]) -> Result<(), CliError> {
    match t.iter().position(|&tk| beyond_span(t[0], tk)) {
        Some(k) => check_span(file, column, k + 2, t[0], t[k]),
        None => Ok(()),
    }
}

/// [`parse_command`] without the span check; also the time column's header.
/// A bad row is refused with the record reader's errors ([`DataError`]).
fn parse_samples(
    file: &str,
    bytes: &[u8],
    unit: CommandUnit,
) -> Result<(Vec<f64>, Vec<f64>, String), CliError> {
    // UTF-16 or UTF-32 text is named so, as the record reader names it
    if let Some(why) = hydrocyl_identify::data::foreign_encoding(bytes) {
        return Err(CliError::Input(format!("{file}: row 1: {why}")));
    }
    // bytes that are not UTF-8 (a logger's `°C` in Windows-1252 in a
    // column the run does not read) are kept as U+FFFD: a column the run
    // reads is then refused at its row and column, as the record reader
    // (`diagnose`) does, and any other is ignored
    let text = String::from_utf8_lossy(bytes);
    let text: &str = &text;
    let mut rdr = csv::ReaderBuilder::new()
        .trim(csv::Trim::All)
        .from_reader(text.as_bytes());
    let headers = rdr
        .headers()
        .map_err(|e| CliError::Input(format!("{file}: row 1: {e}")))?
        .clone();
    let c = columns_of(file, headers.iter(), unit)?;
    if let Some((t, u)) = read_plain(text, &c) {
        return Ok((t, u, c.time_header));
    }
    let header_list: Vec<&str> = headers.iter().collect();
    let input = |e: DataError| CliError::Input(e.to_string());
    let (mut t, mut u) = (Vec::new(), Vec::new());
    // a row is the file's line: the CSV reader skips blank lines, which
    // its record count would not see
    let mut row = 1;
    let mut lines = hydrocyl_identify::data::LineCounter::new(text);
    for rec in rdr.records() {
        let at = match &rec {
            Ok(r) => r.position(),
            Err(e) => e.position(),
        };
        // a line of spaces or tabs is blank (skipped, as an empty one is),
        // as the record reader (`diagnose`) has it
        if let (Err(e), Some(p)) = (&rec, at) {
            if matches!(e.kind(), csv::ErrorKind::UnequalLengths { len: 1, .. })
                && lines.is_blank_at(p.byte() as usize)
            {
                continue;
            }
        }
        row = at.map_or(row + 1, |p| lines.line_at(p.byte() as usize));
        let rec = rec.map_err(|e| match e.kind() {
            csv::ErrorKind::UnequalLengths { len, .. } => {
                input(DataError::ragged(file, row, *len as usize, &header_list))
            }
            _ => CliError::Input(format!("{file}: row {row}: {e}")),
        })?;
        let cell = |i: usize| -> Result<f64, CliError> {
            let column = headers.get(i).unwrap_or("").to_string();
            let text = rec.get(i).unwrap_or("").to_string();
            let (file, row) = (file.to_string(), row);
            match text.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                Ok(_) => Err(input(DataError::NotFinite {
                    file,
                    row,
                    column,
                    text,
                })),
                Err(_) => Err(input(DataError::NotANumber {
                    file,
                    row,
                    column,
                    text,
                })),
            }
        };
        let tv = scaled_decimal(cell(c.time)?, c.time_factor);
        if let Some(&t0) = t.first() {
            check_span(file, &c.time_header, row, t0, tv)?;
        }
        if let Some(&prev) = t.last() {
            if tv <= prev {
                return Err(input(DataError::TimeNotIncreasing {
                    file: file.to_string(),
                    row,
                    column: c.time_header.clone(),
                    t: tv,
                    prev,
                }));
            }
        }
        t.push(tv);
        u.push(scaled_decimal(cell(c.command)?, c.command_factor));
    }
    if t.len() < 2 {
        return Err(CliError::Input(format!(
            "{file}: needs at least two samples, found {}",
            t.len()
        )));
    }
    Ok((t, u, c.time_header))
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A long body's two halves, scaled and joined, are the columns the
    /// one-piece fast path reads from the whole ([`finish_plain`]), bit for
    /// bit, or both send the file to the full reader: for any cut, in
    /// either unit, with times that stop increasing anywhere (at the cut
    /// too) or are NaN.
    #[test]
    fn halves_join_as_the_whole() {
        let step = prop_oneof![Just(1.0), Just(2.5), Just(0.0), Just(-1.0), Just(f64::NAN)];
        let rows = prop::collection::vec((step, -2.0..2.0f64), 0..12);
        let factors = (
            prop::sample::select(vec![1.0, 1e-3]),
            prop::sample::select(vec![1.0, 0.01]),
        );
        proptest!(|(rows in rows, cut in 0..13usize, (tf, cf) in factors)| {
            let mut t = Vec::new();
            let mut at = 0.0;
            for (s, _) in &rows {
                at += s;
                t.push(at);
            }
            let u: Vec<f64> = rows.iter().map(|r| r.1).collect();
            let c = Columns { time: 0, time_header: "time".into(), time_factor: tf, command: 1, command_factor: cf };
            let cut = cut.min(t.len());
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            let whole = finish_plain(vec![t.clone(), u.clone()], &c)
                .map(|(t, u)| (bits(&t), bits(&u)));
            let mut first = vec![t[..cut].to_vec(), u[..cut].to_vec()];
            let mut second = vec![t[cut..].to_vec(), u[cut..].to_vec()];
            let halves = scaled_halves(&mut first, &mut second, &c).map(|()| {
                let (t, u) = joined(&first, &second);
                (bits(&t), bits(&u))
            });
            prop_assert_eq!(halves, whole);
        });
    }

    #[test]
    fn units_and_duplicates() {
        let r = parse_command(
            "f",
            b"time [ms],command [%]\n0,50\n10,-20\n",
            CommandUnit::Normalised,
        )
        .unwrap();
        assert_eq!(r, (vec![0.0, 0.01], vec![0.5, -0.2]));
        let e = parse_command(
            "f",
            b"time,command [mV]\n0,50\n1,2\n",
            CommandUnit::Normalised,
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("`mV`") && e.contains("[-]"), "{e}");
        let r = parse_command("f", b"time,command [mV]\n0,50\n1,2\n", CommandUnit::Volt).unwrap();
        assert_eq!(r.1, vec![0.05, 0.002]);
        let e = parse_command(
            "f",
            b"time,command,command\n0,1,2\n1,2,3\n",
            CommandUnit::Volt,
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("a second `command` column (columns 2 and 3); keep one"),
            "{e}"
        );
    }

    /// A row is the file's line after blank lines too (the `nan` on line 8
    /// was "row 6"), for a bad cell and for the span.
    #[test]
    fn rows_are_file_lines_after_blank_lines() {
        let text = "time,command\n0,0\n\n1,0\n2,0\n\n3,0\n4,nan\n";
        let e = parse_command("f", text.as_bytes(), CommandUnit::Normalised)
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 8, column 'command'"), "{e}");
        let text = "time,command\n0,0\n\n1,0\n\n2e6,0\n";
        let e = parse_command("f", text.as_bytes(), CommandUnit::Normalised)
            .unwrap_err()
            .to_string();
        assert!(e.contains("row 6, column 'time'"), "{e}");
    }
}
