//! The fast path for reading and writing numeric CSV: one pass over the
//! bytes, no allocation per row, shortest round-trip float text.
//!
//! Measured records and command files are almost always *plain*: no quotes,
//! one header line, then rows of numbers separated by commas. [`PlainCsv`]
//! reads exactly those and gives up (returns `None`) at the first thing it
//! does not handle — a quote, a byte-order mark, a blank line inside the data,
//! a row with the wrong number of cells, a cell that is not a finite number.
//! The caller then re-reads the text with the full CSV reader (the `csv`
//! crate), which accepts everything else and writes the error messages (file,
//! row, column). So the fast path changes speed only: the values it returns
//! are the ones `str::parse::<f64>` gives for the trimmed cells, as on the
//! full path, and every error comes from the full path.
//!
//! Numbers are parsed with [`fast_float2`] (the Eisel–Lemire algorithm of
//! the standard library's `f64::from_str`, the same values, about twice as
//! fast); they are written with [`zmij`] (shortest text that parses back to
//! the same `f64`). [`Rows`] reads data lines in pieces, for a file read a
//! buffer at a time.
//!
//! Both directions skip the number conversion where a cell repeats the one
//! above it (a held command, a supply pressure, a saturated spool): the
//! writer copies the text above when the value is the same bits, the reader
//! takes the value above when the text is the same bytes. Long tables are
//! split into blocks of whole rows, one per core
//! ([`PlainCsv::columns`], [`write_columns_in_parts`] with [`write_parts`]).

/// Wanted cells each thread of [`PlainCsv::columns`] has at least: ~0.3–0.5
/// ms of parsing (9–16 ns a cell), well above what a second thread costs.
/// Measured on the 2-core machine (`cargo xtask bench --only csv`, and single
/// reads in fresh processes): the 10-column table (10 000 rows, 100 000
/// cells) reads in ~140 ns/row on one thread and 76–90 on two when the
/// second core is free, and once (a fresh process) in 1.8 ms on one and
/// 1.3–1.5 ms on two, rayon's threads started; the 1 kHz command file
/// (10 000 rows of 2 cells, half of them repeats, so cheap per cell) in 15
/// ns/row on one and 12 on two once rayon's threads run, but once in 220 µs
/// on one thread and 320–460 µs on two (the threads' start): it stays on
/// one.
const PARALLEL_CELLS: usize = 1 << 15;

/// Cells each part of a parallel write has at least ([`write_parts`]):
/// 8192 cells are ~160 µs of formatting, several times a thread's start.
const WRITE_PART_CELLS: usize = 1 << 13;

/// The cores there are to use (at most 8), asked of the system once.
fn cores() -> usize {
    static CORES: std::sync::OnceLock<usize> = std::sync::OnceLock::new();
    *CORES.get_or_init(|| std::thread::available_parallelism().map_or(1, |n| n.get().min(8)))
}

/// A CSV text without quoting, split into its header and its data lines.
#[derive(Clone, Debug)]
pub struct PlainCsv<'a> {
    header: &'a str,
    body: &'a str,
}

/// One line without its terminator (`\n` or `\r\n`).
fn strip_cr(line: &str) -> &str {
    line.strip_suffix('\r').unwrap_or(line)
}

impl<'a> PlainCsv<'a> {
    /// The text as plain CSV, or `None` when it needs the full reader
    /// (quotes, a byte-order mark, a lone `\r`, no header line).
    pub fn new(text: &'a str) -> Option<Self> {
        if text.starts_with('\u{feff}') {
            return None;
        }
        let (line, body) = match memchr::memchr(b'\n', text.as_bytes()) {
            Some(i) => (&text[..=i], &text[i + 1..]),
            None => (text, ""),
        };
        // no quote, no lone carriage return (a line end to the full reader);
        // the data lines are checked as they are read
        if !Rows::plain_bytes(line.as_bytes()) {
            return None;
        }
        let header = strip_cr(line.strip_suffix('\n').unwrap_or(line));
        if header.trim().is_empty() {
            return None;
        }
        Some(Self { header, body })
    }

    /// The header cells, trimmed.
    pub fn headers(&self) -> impl Iterator<Item = &'a str> {
        self.header.split(',').map(str::trim)
    }

    /// Number of header cells.
    pub fn width(&self) -> usize {
        self.header.split(',').count()
    }

    /// Reads the columns `wanted` (indices into the header; each becomes one
    /// output vector, in the order given) from every data row. `None` when a
    /// row has a number of cells other than the header's, a blank line
    /// precedes more data, a wanted cell is not a finite number, or a data
    /// line holds a quote or a lone carriage return.
    ///
    /// A long body is read in consecutive pieces (whole lines each), one per
    /// core ([`PlainCsv::threads`]), and the pieces' columns joined: the
    /// values are the same.
    pub fn columns(&self, wanted: &[usize]) -> Option<Vec<Vec<f64>>> {
        self.columns_on(wanted, self.threads(wanted))
    }

    /// The threads [`PlainCsv::columns`] reads the columns `wanted` with:
    /// one per core (at most 8), as long as each has at least 32 768 wanted
    /// cells (rows estimated from the first line's length), else one. The
    /// work is counted in cells, not bytes: a cell costs about the same
    /// however long its line, and a narrow file's cells are few for its
    /// bytes.
    pub fn threads(&self, wanted: &[usize]) -> usize {
        let line = memchr::memchr(b'\n', self.body.as_bytes()).map_or(self.body.len(), |i| i + 1);
        let cells = (self.body.len() / line.max(1)).saturating_mul(wanted.len());
        match cells / PARALLEL_CELLS {
            // one: the cores are not asked (that reads cgroup files, 30 µs)
            0 | 1 => 1,
            n => n.min(cores()),
        }
    }

    /// [`PlainCsv::columns`] on at most `threads` threads (one piece each).
    pub fn columns_on(&self, wanted: &[usize], threads: usize) -> Option<Vec<Vec<f64>>> {
        let rows = Rows::new(self.width(), wanted)?;
        let body = self.body.as_bytes();
        // rows estimated from the first line's length (a quarter more for
        // longer lines below it); a wrong guess only costs a reallocation
        let line = memchr::memchr(b'\n', body)
            .map_or(body.len(), |i| i + 1)
            .max(1);
        let rows_in = |bytes: usize| bytes / line + bytes / (4 * line) + 2;
        let read = |piece: &[u8], hint: usize| -> Option<(Body, Vec<Vec<f64>>)> {
            let mut out: Vec<Vec<f64>> = wanted.iter().map(|_| Vec::with_capacity(hint)).collect();
            Some((rows.parse(piece, &mut out)?, out))
        };
        let threads = threads.clamp(1, 8);
        if threads == 1 {
            return read(body, rows_in(body.len())).map(|(_, out)| out);
        }
        // cut after the line end at or after each share of the bytes
        let mut cuts = vec![0];
        for i in 1..threads {
            let from = (i * body.len() / threads).max(cuts[cuts.len() - 1]);
            let cut = memchr::memchr(b'\n', &body[from..]).map_or(body.len(), |j| from + j + 1);
            cuts.push(cut);
        }
        cuts.push(body.len());
        let pieces: Vec<&[u8]> = cuts.windows(2).map(|w| &body[w[0]..w[1]]).collect();
        // the first piece on this thread, the others on rayon's threads,
        // started once, not per call. Measured by the bench, the 10-column
        // read on 2 threads, fastest (median) of 60 rounds in four runs each,
        // interleaved, load 2.4-2.8: 76-142 (85-150) ns/row this way, 92-145
        // (101-183) on threads started for the call (std::thread::scope),
        // 83-91 (151-171) with every piece on rayon's threads (par_iter: this
        // thread sleeps, and two of rayon's must wake). Inside a rayon task
        // the pieces are shared out among the threads already there.
        let mut rest: Vec<Option<(Body, Vec<Vec<f64>>)>> =
            pieces[1..].iter().map(|_| None).collect();
        let first = rayon::in_place_scope(|s| {
            for (part, &p) in rest.iter_mut().zip(&pieces[1..]) {
                s.spawn(move |_| *part = read(p, rows_in(p.len())));
            }
            // the first piece's columns take the others' rows after their
            // own: room for all of them from the start
            read(pieces[0], rows_in(body.len()))
        });
        let parts = std::iter::once(first).chain(rest);
        let mut parts = pieces.iter().zip(parts);
        let (_, first) = parts.next()?;
        let (end, mut out) = first?;
        let mut blank_end = end == Body::BlankEnd;
        for (piece, part) in parts {
            // after blank lines only blank lines may follow (as in `parse`)
            if blank_end && !blank_tail(piece) {
                return None;
            }
            let (end, cols) = part?;
            blank_end |= end == Body::BlankEnd;
            for (o, c) in out.iter_mut().zip(cols) {
                o.extend_from_slice(&c);
            }
        }
        Some(out)
    }

    /// The data lines after the header line (its terminator included).
    pub fn body(&self) -> &'a str {
        self.body
    }
}

/// How a piece of CSV data lines ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Body {
    /// With a data row (or nothing).
    Rows,
    /// With blank lines: more data after them is not plain.
    BlankEnd,
}

/// The row reader of [`PlainCsv`], for data lines given whole or in pieces
/// that end at a line end (a long file read a buffer at a time).
#[derive(Clone, Debug)]
pub struct Rows {
    width: usize,
    /// Per column: its output slot (`usize::MAX`: not wanted) and the byte
    /// that ends its cell (`,`, the last `\n`).
    slot: Vec<(usize, u8)>,
}

impl Rows {
    /// Rows of `width` cells of which the columns `wanted` are read;
    /// `None` when a wanted column is not among them.
    pub fn new(width: usize, wanted: &[usize]) -> Option<Self> {
        let mut slot = vec![(usize::MAX, b','); width];
        for (k, &j) in wanted.iter().enumerate() {
            slot.get_mut(j)?.0 = k;
        }
        slot.last_mut()?.1 = b'\n';
        Some(Self { width, slot })
    }

    /// Whether bytes are plain: no quote, no carriage return but before a
    /// line feed (a lone one ends a line for the full reader).
    pub fn plain_bytes(bytes: &[u8]) -> bool {
        memchr::memchr(b'"', bytes).is_none()
            && memchr::memchr_iter(b'\r', bytes).all(|i| bytes.get(i + 1) == Some(&b'\n'))
    }

    /// Appends the wanted cells of the lines in `b` (whole lines) to `out`
    /// (one vector per wanted column). `None` as for [`PlainCsv::columns`],
    /// and where the bytes are not plain ([`Rows::plain_bytes`]); a blank
    /// line is plain only when nothing but blank lines follows it, here or
    /// in a later piece ([`Body::BlankEnd`]).
    ///
    /// One pass: each wanted cell is parsed where it starts, and the parser
    /// says where its number ends. A cell whose text is the text of the cell
    /// above it (a held command, a supply pressure) takes that cell's value
    /// without being parsed again.
    pub fn parse(&self, b: &[u8], out: &mut [Vec<f64>]) -> Option<Body> {
        let len = b.len();
        // per column, the text of the cell above and its value
        let mut above: Vec<Above> = vec![Above::default(); self.width];
        // the values of a block of rows, column after column: one store per
        // cell, and one copy per column and block into `out`
        let mut block: Vec<f64> = vec![0.0; BLOCK_ROWS * out.len()];
        let mut r = 0;
        let flush = |block: &[f64], r: usize, out: &mut [Vec<f64>]| {
            for (o, c) in out.iter_mut().zip(block.chunks_exact(BLOCK_ROWS)) {
                o.extend_from_slice(&c[..r]);
            }
        };
        let mut pos = 0;
        while pos < len {
            if b[pos] == b'\n' || b[pos] == b'\r' {
                flush(&block, r, out);
                // the full reader skips blank lines, which shifts its row
                // numbers away from the line numbers: only a blank end is plain
                return blank_tail(&b[pos..]).then_some(Body::BlankEnd);
            }
            for (&(k, sep), a) in self.slot.iter().zip(above.iter_mut()) {
                let end = if k == usize::MAX {
                    skip_cell(b, pos)?
                } else {
                    let (v, end) = match repeat(b, pos, a) {
                        Some(end) => (a.value, end),
                        None => {
                            let (v, start, n) = number_at(b, pos)?;
                            // texts longer than any shortest round trip
                            // (24 bytes) are not compared
                            *a = Above {
                                start,
                                len: if n <= MAX_CELL { n } else { 0 },
                                value: v,
                            };
                            (v, start + n)
                        }
                    };
                    block[k * BLOCK_ROWS + r] = v;
                    // mostly the separator follows the number at once
                    if b.get(end) == Some(&sep) {
                        pos = end + 1;
                        continue;
                    }
                    cell_end(b, end)?
                };
                // a cell ends at a comma, the last at the line's end
                if *b.get(end).unwrap_or(&b'\n') != sep {
                    return None;
                }
                pos = end + 1;
            }
            r += 1;
            if r == BLOCK_ROWS {
                flush(&block, r, out);
                r = 0;
            }
        }
        flush(&block, r, out);
        Some(Body::Rows)
    }
}

/// Rows whose values [`Rows::parse`] gathers before appending them to the
/// output columns: a store per cell instead of a push (a length and a
/// capacity read and a length written), one copy per column and block;
/// with the separator checked where the number ends, 158 ns/row against 166
/// for the 10-column table on one thread.
const BLOCK_ROWS: usize = 64;

/// The cell above one being read: where its text starts, its length (0:
/// none to compare with) and its value.
#[derive(Clone, Copy, Debug, Default)]
struct Above {
    start: usize,
    len: usize,
    value: f64,
}

/// Whether `b` is nothing but line ends (`\n`, `\r\n`).
fn blank_tail(b: &[u8]) -> bool {
    b.iter()
        .enumerate()
        .all(|(i, &c)| c == b'\n' || (c == b'\r' && b.get(i + 1) == Some(&b'\n')))
}

/// Whether `c` is white space a cell may carry before its number (what
/// `<[u8]>::trim_ascii` takes off, but the line ends); after it, also a
/// carriage return just before the line feed.
#[inline]
fn blank(c: u8) -> bool {
    matches!(c, b' ' | b'\t' | b'\x0c')
}

/// The end of the cell (the index of its `,` or `\n`, or `b.len()`) whose
/// number ends at `e`: blanks may follow the number, nothing else.
#[inline]
fn cell_end(b: &[u8], mut e: usize) -> Option<usize> {
    while e < b.len() {
        match b[e] {
            b',' | b'\n' => return Some(e),
            c if blank(c) => e += 1,
            b'\r' if b.get(e + 1) == Some(&b'\n') => e += 1,
            _ => return None,
        }
    }
    Some(e)
}

/// The end of an unwanted cell that starts at `pos` (as [`cell_end`]);
/// `None` when it holds a quote or a lone carriage return.
fn skip_cell(b: &[u8], pos: usize) -> Option<usize> {
    let mut e = pos;
    while e < b.len() {
        match b[e] {
            b',' | b'\n' => return Some(e),
            b'"' => return None,
            b'\r' if b.get(e + 1) != Some(&b'\n') => return None,
            _ => e += 1,
        }
    }
    Some(e)
}

/// Eight bytes of `b` from `i` as one word.
#[inline(always)]
fn word(b: &[u8], i: usize) -> u64 {
    let mut w = [0u8; 8];
    w.copy_from_slice(&b[i..i + 8]);
    u64::from_le_bytes(w)
}

/// Where the number ends if the cell at `pos` repeats the text of the cell
/// above (`above`): the same bytes, then a byte no number goes on with (so
/// the parser would stop there too, with the same value). `None` when it
/// does not, or when that is not quickly seen.
#[inline(always)]
fn repeat(b: &[u8], pos: usize, above: &Above) -> Option<usize> {
    // both texts as arrays of a known length, and n <= MAX_CELL: the words
    // read need no bounds checks (7 ns/row of the 10-column table's 180)
    let n = above.len.min(MAX_CELL);
    let here: &[u8; MAX_CELL + 1] = b.get(pos..pos + MAX_CELL + 1)?.try_into().ok()?;
    let there: &[u8; MAX_CELL + 1] = b[above.start..].get(..MAX_CELL + 1)?.try_into().ok()?;
    let same = if n <= 8 {
        n > 0 && (word(there, 0) ^ word(here, 0)) & (u64::MAX >> (64 - 8 * n)) == 0
    } else {
        word(there, 0) == word(here, 0)
            && word(there, n - 8) == word(here, n - 8)
            && (n <= 16 || word(there, 8) == word(here, 8))
    };
    let next = here[n];
    (same && (next == b',' || next == b'\n' || next == b'\r' || blank(next))).then_some(pos + n)
}

/// The finite number of the cell that starts at `start` in `b`, parsed as
/// `str::parse::<f64>` parses the trimmed cell (the Eisel–Lemire algorithm,
/// `fast-float2`, which reads `inf`/`nan` spellings and a leading `+` as it
/// does and refuses the rest), where its text starts and its length (what
/// follows is for [`cell_end`] to judge); `None` when there is no such
/// number or it is not finite.
#[inline(always)]
fn number_at(b: &[u8], start: usize) -> Option<(f64, usize, usize)> {
    let mut i = start;
    while i < b.len() && blank(b[i]) {
        i += 1;
    }
    let (v, n): (f64, usize) = fast_float2::parse_partial(&b[i..]).ok()?;
    v.is_finite().then_some((v, i, n))
}

/// [`number_at`] on one whole cell.
#[cfg(test)]
fn number(cell: &[u8]) -> Option<f64> {
    let (v, start, n) = number_at(cell, 0)?;
    (cell_end(cell, start + n)? == cell.len()).then_some(v)
}

/// The longest text zmij writes for an `f64`.
const MAX_CELL: usize = 24;

/// Puts `s` (at most [`MAX_CELL`] bytes) into `row` at `at` with two
/// overlapping fixed-size copies (no `memcpy` call for a few bytes);
/// returns the end. `row` must have room for [`MAX_CELL`] bytes at `at`.
#[inline(always)]
fn put_short(row: &mut [u8], at: usize, s: &[u8]) -> usize {
    let n = s.len();
    let d = &mut row[at..at + MAX_CELL];
    if n >= 16 {
        d[..16].copy_from_slice(&s[..16]);
        d[n - 16..n].copy_from_slice(&s[n - 16..]);
    } else if n >= 8 {
        d[..8].copy_from_slice(&s[..8]);
        d[n - 8..n].copy_from_slice(&s[n - 8..]);
    } else if n >= 4 {
        d[..4].copy_from_slice(&s[..4]);
        d[n - 4..n].copy_from_slice(&s[n - 4..]);
    } else {
        for (d, s) in d.iter_mut().zip(s) {
            *d = *s;
        }
    }
    at + n
}

/// The columns of a run in the measured-data format: `time`, then every
/// channel, names and values.
pub fn run_columns(run: &hydrocyl_system::run::Run) -> (Vec<&str>, Vec<&[f64]>) {
    let names = std::iter::once("time")
        .chain(run.channels.iter().map(|c| c.name.as_str()))
        .collect();
    let columns = std::iter::once(run.time.as_slice())
        .chain(run.channels.iter().map(|c| c.values.as_slice()))
        .collect();
    (names, columns)
}

/// Columns formatted before any of their texts is copied out: zmij writes
/// a text with several narrow stores, and reading it back at once with wide
/// loads stalls until they reach the cache; a group later they have.
const GROUP: usize = 16;

/// Rows put together between two growths of the output.
const CHUNK_ROWS: usize = 64;

/// Appends rows `rows` of `columns` as CSV lines (shortest round-trip text).
/// A value equal (bit for bit) to the one above it in its column is not
/// formatted again: its text is copied from the row above (a supply
/// pressure, a held command).
///
/// The output grows by a chunk of rows at their longest at a time, the rows
/// are written into it in place (no row buffer, no copy of a row), and it is
/// cut back to what was written.
fn write_rows(columns: &[&[f64]], rows: std::ops::Range<usize>, out: &mut Vec<u8>) {
    let width = columns.len();
    if width == 0 {
        return;
    }
    let row_max = width * (MAX_CELL + 1);
    let mut bufs: Vec<zmij::Buffer> = (0..width).map(|_| zmij::Buffer::new()).collect();
    // per column, the row above's value (bits) and its text's place in
    // `out` (start, length; length 0: no row above)
    let mut above: Vec<(u64, usize, usize)> = vec![(0, 0, 0); width];
    // where the row above starts in `out`
    // room for every row at its longest: the chunks below never move it
    out.reserve(rows.len() * row_max);
    let mut prev = out.len();
    let mut last = prev;
    let mut k = rows.start;
    while k < rows.end {
        let n = (rows.end - k).min(CHUNK_ROWS);
        let base = out.len();
        out.resize(base + n * row_max, 0);
        // the chunk and the row above it, whose texts a repeat copies
        let d = &mut out[prev..];
        let mut at = base - prev;
        for k in k..k + n {
            let row = at;
            for ((cols, bufs), above) in columns
                .chunks(GROUP)
                .zip(bufs.chunks_mut(GROUP))
                .zip(above.chunks_mut(GROUP))
            {
                // the group's formatted texts; empty: the text above repeats
                let mut texts: [&[u8]; GROUP] = [&[]; GROUP];
                for (((t, c), b), a) in texts.iter_mut().zip(cols).zip(bufs).zip(above.iter()) {
                    if a.2 == 0 || a.0 != c[k].to_bits() {
                        *t = b.format(c[k]).as_bytes();
                    }
                }
                for ((t, c), a) in texts.iter().zip(cols).zip(above.iter_mut()) {
                    let start = at;
                    at = if t.is_empty() {
                        let (done, rest) = d.split_at_mut(at);
                        at + put_short(rest, 0, &done[a.1 - prev..a.1 - prev + a.2])
                    } else {
                        put_short(d, at, t)
                    };
                    *a = (c[k].to_bits(), prev + start, at - start);
                    d[at] = b',';
                    at += 1;
                }
            }
            // the last separator becomes the line end
            d[at - 1] = b'\n';
            last = prev + row;
        }
        out.truncate(prev + at);
        prev = last;
        k += n;
    }
}

/// Appends every row of `columns` (all of the same length) to `out` as CSV
/// lines, as [`write_columns`] writes them after its header.
pub fn append_rows(columns: &[&[f64]], out: &mut Vec<u8>) {
    let rows = columns.first().map_or(0, |c| c.len());
    write_rows(columns, 0..rows, out);
}

/// CSV text of a table: the header `names` (comma-separated), then one row
/// per entry of `columns[0]`, each value as its shortest round-trip text.
/// All columns must have the same length.
pub fn write_columns(names: &[&str], columns: &[&[f64]]) -> Vec<u8> {
    write_columns_in_parts(names, columns, 1)
        .pop()
        .unwrap_or_default()
}

/// How many parts [`write_columns_in_parts`] pays to use for `rows` rows of
/// `width` columns: one per core (at most 8), as long as each part has at
/// least 8192 cells.
pub fn write_parts(rows: usize, width: usize) -> usize {
    let cores = cores();
    (rows.saturating_mul(width) / WRITE_PART_CELLS).clamp(1, cores)
}

/// [`write_columns`] formatted by `parts` threads (this one and `parts - 1`
/// started for it), each a contiguous block of rows (the header goes with
/// the first): the parts, in order, are the text. Writing them one after
/// the other spares the copy of a concatenation.
pub fn write_columns_in_parts(names: &[&str], columns: &[&[f64]], parts: usize) -> Vec<Vec<u8>> {
    let mut head = names.join(",").into_bytes();
    head.push(b'\n');
    let rows = columns.first().map_or(0, |c| c.len());
    let parts = parts.clamp(1, rows.max(1));
    let bounds: Vec<usize> = (0..=parts).map(|i| i * rows / parts).collect();
    let mut out: Vec<Vec<u8>> = vec![Vec::new(); parts];
    out[0] = head;
    let (first, rest) = out.split_at_mut(1);
    std::thread::scope(|s| {
        for (i, o) in rest.iter_mut().enumerate() {
            let range = bounds[i + 1]..bounds[i + 2];
            s.spawn(move || write_rows(columns, range, o));
        }
        write_rows(columns, 0..bounds[1], &mut first[0]);
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The full reader's view of the same text (trimmed cells, numbers).
    fn full(text: &str, wanted: &[usize]) -> Option<Vec<Vec<f64>>> {
        let mut rdr = csv::ReaderBuilder::new()
            .trim(csv::Trim::All)
            .from_reader(text.as_bytes());
        let mut out = vec![Vec::new(); wanted.len()];
        for rec in rdr.records() {
            let rec = rec.ok()?;
            for (k, &j) in wanted.iter().enumerate() {
                let v: f64 = rec.get(j)?.parse().ok()?;
                if !v.is_finite() {
                    return None;
                }
                out[k].push(v);
            }
        }
        Some(out)
    }

    #[test]
    fn reads_plain_and_declines_the_rest() {
        let t = "time [s], command ,x\r\n0,1.5,a\n0.001, -2e-3 ,b\n\n";
        let p = PlainCsv::new(t).unwrap();
        assert_eq!(
            p.headers().collect::<Vec<_>>(),
            ["time [s]", "command", "x"]
        );
        let c = p.columns(&[1, 0]).unwrap();
        assert_eq!(c, vec![vec![1.5, -2e-3], vec![0.0, 0.001]]);
        assert!(PlainCsv::new("\"time\",u\n0,1\n").is_none());
        assert!(PlainCsv::new("time,u\r0,1\r").is_none());
        let p = PlainCsv::new("time,u\n0,1\n\n1,2\n").unwrap();
        assert!(p.columns(&[0, 1]).is_none(), "blank line inside the data");
        let p = PlainCsv::new("time,u\n0,1\n1\n").unwrap();
        assert!(p.columns(&[0]).is_none(), "ragged row");
        let p = PlainCsv::new("time,u\n0,NaN\n").unwrap();
        assert!(p.columns(&[1]).is_none(), "not finite");
        assert!(p.columns(&[0]).is_some(), "unwanted cells are not parsed");
        // the data lines are checked as they are read, wanted cell or not
        for (t, why) in [
            ("t,u\n0,\"1\"\n", "a quote"),
            ("t,u\n0,1\r2,3\n", "a lone carriage return"),
            ("t,u\n0,1\n\r", "a lone carriage return at the end"),
            ("t,u\n0, 1\r\r\n", "a carriage return before another"),
        ] {
            let p = PlainCsv::new(t).unwrap();
            assert!(p.columns(&[0, 1]).is_none(), "{why}: {t:?}");
            assert!(
                p.columns(&[0]).is_none(),
                "{why} in an unwanted cell: {t:?}"
            );
        }
        let p = PlainCsv::new("t,u\r\n0, 1 \r\n2,3\r\n\r\n").unwrap();
        assert_eq!(p.columns(&[0, 1]).unwrap(), [[0.0, 2.0], [1.0, 3.0]]);
    }

    /// A cell whose text repeats the one above it reads as if parsed, also
    /// where the text above is only a prefix of it or it carries blanks.
    #[test]
    fn repeated_texts_read_as_parsed() {
        let cells = [
            "7000000.0",
            "7000000.0",
            "7000000.01",
            "7000000.0 ",
            " 7000000.0",
            "7000000.0e0",
            "7000000.0",
            "7000000.0e",
            "7000000.0",
            "0.13641301660791483",
            "0.136413016607914830",
            "0.13641301660791483\t",
            "0.13641301660791483",
        ];
        let mut text = String::from("a,b\n");
        for c in cells {
            text.push_str(&format!("{c},{c}\r\n"));
        }
        // the long tail keeps every cell above within the compared window
        text.push_str(&"1,2\n".repeat(20));
        let bad = text.replace("7000000.0e,7000000.0e", "7000000.0,7000000.0");
        assert_eq!(full(&text, &[0, 1]), None, "`7000000.0e` is not a number");
        assert_eq!(PlainCsv::new(&text).unwrap().columns(&[0, 1]), None);
        let fast = PlainCsv::new(&bad).unwrap().columns(&[1, 0]);
        assert_eq!(fast, full(&bad, &[1, 0]));
        assert_eq!(fast.unwrap()[0][..3], [7e6, 7e6, 7000000.01]);
    }

    /// The cell parser takes what `str::parse::<f64>` takes, the same value.
    #[test]
    fn cells_parse_as_the_standard_library_does() {
        for cell in [
            "1.",
            ".5",
            "+1.5",
            "-0",
            "1e5",
            "1E5",
            "1e+5",
            "1e-5",
            "  3.25 ",
            "1_0",
            "0x10",
            "1e",
            "e5",
            ".",
            "+",
            "-",
            "",
            "1.5.2",
            "inf",
            "-inf",
            "NaN",
            "infinity",
            "1e400",
            "1e-400",
            "00012",
            "2.2250738585072011e-308",
            "9007199254740993",
            "1,5",
            "1 5",
            "0.1000000000000000055511151231257827",
            "\t7\t",
        ] {
            let std = cell.trim().parse::<f64>().ok().filter(|v| v.is_finite());
            assert_eq!(
                number(cell.as_bytes()).map(f64::to_bits),
                std.map(f64::to_bits),
                "cell `{cell}`"
            );
        }
    }

    #[test]
    fn written_text_reads_back_exactly() {
        let a = [0.0, 1e-300, -3.25, 1.0 / 3.0, 6.02e23];
        let b = [f64::MIN_POSITIVE, -0.0, 7e6, 2.5e-9, 1e16];
        let text = String::from_utf8(write_columns(&["a", "b"], &[&a, &b])).unwrap();
        for parts in 1..=4 {
            let p = write_columns_in_parts(&["a", "b"], &[&a, &b], parts).concat();
            assert_eq!(String::from_utf8(p).unwrap(), text, "{parts} parts");
        }
        let c = PlainCsv::new(&text).unwrap().columns(&[0, 1]).unwrap();
        assert_eq!(c[0], a);
        assert_eq!(
            c[1].iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
            b.iter().map(|v| v.to_bits()).collect::<Vec<_>>()
        );
    }

    /// A body long enough to be read in pieces reads as it does whole, on
    /// any number of threads: every value, the blank end, and blank lines
    /// inside refused wherever the cut falls.
    #[test]
    fn pieces_read_as_the_whole() {
        let mut text = String::from("time,u,x\n");
        let mut k = 0u64;
        // two wanted cells a row: enough for two threads
        while k < (PARALLEL_CELLS + 1000) as u64 {
            text.push_str(&format!("{},{},{}\n", k as f64 * 1e-3, (k as f64).sin(), k));
            k += 1;
        }
        let p = PlainCsv::new(&text).unwrap();
        let rows = Rows::new(3, &[1, 0]).unwrap();
        let mut whole = vec![Vec::new(), Vec::new()];
        assert_eq!(
            rows.parse(p.body().as_bytes(), &mut whole),
            Some(Body::Rows)
        );
        assert_eq!(p.columns(&[1, 0]).unwrap(), whole);
        assert_eq!(whole[1].len() as u64, k);
        let ended = format!("{text}\n\r\n\n");
        let ended = PlainCsv::new(&ended).unwrap();
        for threads in 1..=4 {
            assert_eq!(p.columns_on(&[1, 0], threads).unwrap(), whole);
            assert_eq!(ended.columns_on(&[1, 0], threads).unwrap(), whole);
        }
        for at in [0.1, 0.45, 0.5, 0.55, 0.9] {
            let mut i = (text.len() as f64 * at) as usize;
            while text.as_bytes()[i] != b'\n' {
                i += 1;
            }
            let holed = format!("{}\n{}", &text[..=i], &text[i + 1..]);
            for threads in 1..=3 {
                assert!(
                    PlainCsv::new(&holed)
                        .unwrap()
                        .columns_on(&[0], threads)
                        .is_none(),
                    "blank line at {at}, {threads} threads"
                );
            }
        }
    }

    /// The threads go by wanted cells: a long narrow file stays on one, a
    /// table as long with ten columns goes on every core (up to two here).
    #[test]
    fn threads_go_by_wanted_cells() {
        let cores = std::thread::available_parallelism().map_or(1, |n| n.get().min(2));
        let narrow = format!("t,u\n{}", "0.001,0.13641301660791483\n".repeat(10_000));
        assert_eq!(PlainCsv::new(&narrow).unwrap().threads(&[0, 1]), 1);
        let row = ["0.5"; 10].join(",") + "\n";
        let wide = format!("{}\n{}", ["c"; 10].join(","), row.repeat(10_000));
        let p = PlainCsv::new(&wide).unwrap();
        let all: Vec<usize> = (0..10).collect();
        assert_eq!(p.threads(&all).min(2), cores);
        assert_eq!(p.threads(&[0, 1]), 1, "two columns of the same rows");
    }

    proptest! {
        /// What is written reads back bit for bit, in any number of parts or
        /// blocks, across the writer's chunks of rows, where values repeat.
        #[test]
        fn round_trip_is_exact(
            cells in proptest::collection::vec(
                (any::<f64>().prop_filter("finite", |v| v.is_finite()), any::<f64>(), 0u8..4),
                1..60),
        ) {
            let (mut a, mut b) = (Vec::new(), Vec::new());
            for (x, y, times) in &cells {
                for _ in 0..=*times {
                    a.push(*x);
                    b.push(if y.is_finite() { *y } else { -0.0 });
                }
            }
            let text = write_columns(&["a", "b"], &[&a, &b]);
            for parts in [2, 3] {
                prop_assert_eq!(&write_columns_in_parts(&["a", "b"], &[&a, &b], parts).concat(), &text);
            }
            let mut blocks = b"a,b\n".to_vec();
            for k in (0..a.len()).step_by(7) {
                let e = (k + 7).min(a.len());
                append_rows(&[&a[k..e], &b[k..e]], &mut blocks);
            }
            prop_assert_eq!(&blocks, &text);
            let text = String::from_utf8(text).unwrap();
            let back = PlainCsv::new(&text).unwrap().columns(&[0, 1]).unwrap();
            let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
            prop_assert_eq!(bits(&back[0]), bits(&a));
            prop_assert_eq!(bits(&back[1]), bits(&b));
        }

        /// Every cell is the shortest round-trip text of its value, also
        /// where a value repeats the one above it (its text copied) or
        /// differs from it only in sign (0.0 below -0.0).
        #[test]
        fn repeated_values_are_written_as_each_alone(
            cells in proptest::collection::vec(
                (prop_oneof![Just(0.0), Just(-0.0), Just(7e6), -1e9f64..1e9], 0u8..3), 1..40),
        ) {
            // runs of a value in column a; b the same values from its end
            let mut a = Vec::new();
            for (v, times) in &cells {
                for _ in 0..=*times {
                    a.push(*v);
                }
            }
            let b: Vec<f64> = a.iter().rev().copied().collect();
            let text = String::from_utf8(write_columns(&["a", "b"], &[&a, &b])).unwrap();
            let mut one = zmij::Buffer::new();
            let mut expected = String::from("a,b\n");
            for (x, y) in a.iter().zip(&b) {
                expected.push_str(one.format(*x));
                expected.push(',');
                expected.push_str(one.format(*y));
                expected.push('\n');
            }
            prop_assert_eq!(text, expected);
        }

        /// Wherever the fast path answers, it answers what the full reader does.
        #[test]
        fn agrees_with_the_full_reader(
            rows in proptest::collection::vec(
                (-1e9f64..1e9, prop_oneof![Just(" "), Just(""), Just("\t")], 0u8..8), 0..20),
            crlf in any::<bool>(),
        ) {
            let nl = if crlf { "\r\n" } else { "\n" };
            let mut text = format!("time, u{nl}");
            for (v, pad, kind) in &rows {
                match kind {
                    0 => text.push_str(&format!("{v}{nl}")),            // ragged
                    1 => text.push_str(&format!("{v},x{nl}")),          // not a number
                    2 => text.push_str(nl),                             // blank line
                    _ => text.push_str(&format!("{pad}{v:e}{pad},{v}{nl}")),
                }
            }
            if let Some(fast) = PlainCsv::new(&text).and_then(|p| p.columns(&[0, 1])) {
                prop_assert_eq!(Some(fast), full(&text, &[0, 1]));
            }
        }
    }
}
