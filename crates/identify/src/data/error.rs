//! Why a record could not be read: [`DataError`], naming the file and,
//! for one cell, its row and column.

use thiserror::Error;

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
    /// A row with more or fewer cells than the header has columns; the
    /// column is the first without a cell (fewer) or the first cell
    /// without a column (more). Made by [`DataError::ragged`], for the
    /// record reader and `simulate`'s command reader alike.
    #[error("{file}: row {row}, column {column}: {cells} cell{}, the header has {header} ({what})", if *cells == 1 { "" } else { "s" })]
    Ragged {
        /// The file.
        file: String,
        /// The row (1-based line).
        row: usize,
        /// The column: its header in quotes (`'force [N]'`), or its number
        /// where it is beyond the header.
        column: String,
        /// The row's cells.
        cells: usize,
        /// The header's columns.
        header: usize,
        /// What is missing or extra.
        what: String,
    },
    /// A required column is missing.
    #[error("{file}: row 1: missing column '{column}'{hint}")]
    MissingColumn {
        /// The file.
        file: String,
        /// The missing column's name.
        column: String,
        /// A header that names it but is not read as it, as a remark
        /// ([`super::unread_header_hint`]); empty where there is none.
        hint: String,
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
    #[error("{file}: row 1, column '{column}': a second `{signal}` column (columns {first} and {second}); keep one")]
    DuplicateSignal {
        /// The file.
        file: String,
        /// The second column header.
        column: String,
        /// The signal.
        signal: String,
        /// The first column holding it (1-based).
        first: usize,
        /// The second (1-based).
        second: usize,
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
    /// The smoother half-width asked for is too narrow to smooth: its window
    /// holds no more samples than the polynomial has coefficients.
    #[error("{file}: a smoother half-width (window) of {half_window} samples is too narrow for the order-{order} smoother: its {} samples would be interpolated, not smoothed; at least {}", 2 * half_window + 1, (order + 2) / 2)]
    WindowTooNarrow {
        /// The record.
        file: String,
        /// The half-width asked for.
        half_window: usize,
        /// The polynomial degree.
        order: usize,
    },
    /// A smoother half-width given for records that are not smoothed.
    #[error("{file}: a steady-state bench's samples are not smoothed (measured velocity, zero acceleration): leave out the smoother half-width (window)")]
    WindowNotUsed {
        /// The record.
        file: String,
    },
    /// A cell is not a number.
    #[error(
        "{file}: row {row}, column '{column}': '{text}' is not a number{}",
        decimal_comma_hint(text)
    )]
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
    #[error("{file}: row {row}, column '{column}': '{text}' is not finite")]
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
    /// A cell finite as written but not in SI units (`1e308` under `[bar]`).
    #[error("{file}: row {row}, column '{column}': '{text}' is {value} in SI units: not finite")]
    NotFiniteInSi {
        /// The file.
        file: String,
        /// The row (1-based line).
        row: usize,
        /// The column header.
        column: String,
        /// The cell's text.
        text: String,
        /// Its value in SI units.
        value: f64,
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
    /// A time stamp lies more than [`super::MAX_SPAN_S`] after the first.
    #[error("{file}: row {row}, column '{column}': time {t:.4e} s is {span:.4e} s after the first sample: a record or command file spans at most {max:e} s (about 11.6 days); is the time column in seconds, or this time stamp a typo?", max = super::MAX_SPAN_S)]
    SpanTooLong {
        /// The file.
        file: String,
        /// The row (1-based line).
        row: usize,
        /// The time column's header.
        column: String,
        /// This row's time \[s\].
        t: f64,
        /// Its distance from the first sample \[s\].
        span: f64,
    },
    /// An interval of the time axis over [`super::MAX_GAP_FACTOR`] times
    /// the record's median interval and over [`super::GAP_OVER_REST`] times
    /// the rest of its span.
    #[error("{file}: row {row}, column '{column}': time {t:.6e} s is {step:.4e} s after the previous sample, {ratio:.3e} times the record's median interval ({median:.4e} s) and more than {rest} times the rest of the record together: a time stamp typo, or a gap the model would run across on an input nobody measured; correct it or split the record at the gap", ratio = step / median, rest = super::GAP_OVER_REST)]
    TimeGap {
        /// The file.
        file: String,
        /// The row (1-based line) of the sample after the gap.
        row: usize,
        /// The time column's header.
        column: String,
        /// This row's time \[s\].
        t: f64,
        /// The interval before it \[s\].
        step: f64,
        /// The record's median interval \[s\].
        median: f64,
    },
    /// One sample far off its neighbours, which the rig cannot have made (a
    /// position that would move the piston far faster than the rig can).
    #[error("{file}: row {row}, column '{column}': {reason}")]
    Outlier {
        /// The file.
        file: String,
        /// The row (1-based line).
        row: usize,
        /// The column header.
        column: String,
        /// What was seen and what to check.
        reason: String,
    },
    /// A column the rig's model needs (an input) is not in the file.
    #[error("{file}: row 1: missing column '{column}': {why}")]
    MissingInput {
        /// The file.
        file: String,
        /// The missing column's name.
        column: String,
        /// Why the model needs it.
        why: String,
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
    /// The model's input never changes while the piston moves: nothing in
    /// the record drives the model (a disconnected command channel).
    #[error("{file}: row 1, column '{column}': {reason}")]
    ConstantInput {
        /// The file.
        file: String,
        /// The column header.
        column: String,
        /// What was seen and what to check.
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

/// The hint after "is not a number" for a cell written with a decimal
/// comma (`0,5`, `-1,25e-3`: a spreadsheet in a locale that writes one,
/// its cells quoted in a comma-separated file): ``(a decimal comma:
/// hydrocyl reads a decimal point, `0.5`)``; empty for any other text.
fn decimal_comma_hint(text: &str) -> String {
    let Some((int, frac)) = text.trim().split_once(',') else {
        return String::new();
    };
    let int_digits = int.strip_prefix(['-', '+']).unwrap_or(int);
    let mantissa = frac.split(['e', 'E']).next().unwrap_or(frac);
    let digits = |d: &str| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit());
    let point = format!("{int},{frac}").replacen(',', ".", 1);
    if !digits(int_digits) || !digits(mantissa) || point.trim().parse::<f64>().is_err() {
        return String::new();
    }
    format!(
        " (a decimal comma: hydrocyl reads a decimal point, `{}`)",
        point.trim()
    )
}

impl DataError {
    /// The [`DataError::Ragged`] error of row `row` of file `file`: `cells`
    /// cells under the header `headers`.
    pub fn ragged(file: &str, row: usize, cells: usize, headers: &[&str]) -> DataError {
        let (column, what) = match headers.get(cells) {
            Some(h) => (format!("'{h}'"), "no cell for this column".to_string()),
            None => (
                (headers.len() + 1).to_string(),
                "a cell beyond the header's last column".to_string(),
            ),
        };
        DataError::Ragged {
            file: file.to_string(),
            row,
            column,
            cells,
            header: headers.len(),
            what,
        }
    }
}
