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

/// Bodies at least this long are read on every core ([`PlainCsv::columns`]):
/// below it, starting the threads costs more than they save.
const PARALLEL_BYTES: usize = 1 << 16;

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
        // one pass: no quote, no lone carriage return (a line end to the full reader)
        if !Rows::plain_bytes(text.as_bytes()) {
            return None;
        }
        let (header, body) = match text.find('\n') {
            Some(i) => (strip_cr(&text[..i]), &text[i + 1..]),
            None => (strip_cr(text), ""),
        };
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
    /// precedes more data, or a wanted cell is not a finite number.
    ///
    /// A long body is read in consecutive pieces (whole lines each), one per
    /// core, and the pieces' columns joined: the values are the same.
    pub fn columns(&self, wanted: &[usize]) -> Option<Vec<Vec<f64>>> {
        let rows = Rows::new(self.width(), wanted)?;
        let body = self.body.as_bytes();
        let threads = if body.len() < PARALLEL_BYTES {
            1
        } else {
            std::thread::available_parallelism().map_or(1, |n| n.get().min(8))
        };
        let read = |piece: &[u8]| -> Option<(Body, Vec<Vec<f64>>)> {
            let hint = piece.len() / (8 * rows.width).max(1) + 1;
            let mut out: Vec<Vec<f64>> = wanted.iter().map(|_| Vec::with_capacity(hint)).collect();
            Some((rows.parse(piece, &mut out)?, out))
        };
        if threads == 1 {
            return read(body).map(|(_, out)| out);
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
        let parts: Vec<Option<(Body, Vec<Vec<f64>>)>> = std::thread::scope(|s| {
            let handles: Vec<_> = pieces[1..]
                .iter()
                .map(|&p| s.spawn(move || read(p)))
                .collect();
            std::iter::once(read(pieces[0]))
                .chain(handles.into_iter().map(|h| h.join().ok().flatten()))
                .collect()
        });
        let mut out: Vec<Vec<f64>> = wanted.iter().map(|_| Vec::new()).collect();
        let mut blank_end = false;
        for (piece, part) in pieces.iter().zip(parts) {
            // after blank lines only blank lines may follow (as in `parse`)
            if blank_end && !piece.iter().all(|&c| c == b'\n' || c == b'\r') {
                return None;
            }
            let (end, cols) = part?;
            blank_end |= end == Body::BlankEnd;
            for (o, c) in out.iter_mut().zip(cols) {
                if o.is_empty() {
                    *o = c;
                } else {
                    o.extend_from_slice(&c);
                }
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
    /// Column index → output slot (`usize::MAX`: not wanted).
    slot: Vec<usize>,
}

impl Rows {
    /// Rows of `width` cells of which the columns `wanted` are read;
    /// `None` when a wanted column is not among them.
    pub fn new(width: usize, wanted: &[usize]) -> Option<Self> {
        let mut slot = vec![usize::MAX; width];
        for (k, &j) in wanted.iter().enumerate() {
            *slot.get_mut(j)? = k;
        }
        Some(Self { width, slot })
    }

    /// Whether bytes are plain: no quote, no carriage return but before a
    /// line feed (a lone one ends a line for the full reader).
    pub fn plain_bytes(bytes: &[u8]) -> bool {
        memchr::memchr(b'"', bytes).is_none()
            && memchr::memchr_iter(b'\r', bytes).all(|i| bytes.get(i + 1) == Some(&b'\n'))
    }

    /// Appends the wanted cells of the lines in `b` (whole lines) to `out`
    /// (one vector per wanted column). `None` as for [`PlainCsv::columns`];
    /// a blank line is plain only when nothing but blank lines follows it,
    /// here or in a later piece ([`Body::BlankEnd`]).
    pub fn parse(&self, b: &[u8], out: &mut [Vec<f64>]) -> Option<Body> {
        let len = b.len();
        let mut pos = 0;
        while pos < len {
            if b[pos] == b'\n' || b[pos] == b'\r' {
                // the full reader skips blank lines, which shifts its row
                // numbers away from the line numbers: only a blank end is plain
                if b[pos..].iter().all(|&c| c == b'\n' || c == b'\r') {
                    return Some(Body::BlankEnd);
                }
                return None;
            }
            let mut n = 0;
            loop {
                let k = *self.slot.get(n)?;
                n += 1;
                // one pass: a wanted cell is parsed where it starts and must
                // end at its separator; an unwanted one is skipped
                let end = if k == usize::MAX {
                    memchr::memchr2(b',', b'\n', &b[pos..]).map_or(len, |i| pos + i)
                } else {
                    let (v, end) = number_at(b, pos)?;
                    out[k].push(v);
                    end
                };
                pos = end + 1;
                if end == len || b[end] == b'\n' {
                    break;
                }
            }
            if n != self.width {
                return None;
            }
        }
        Some(Body::Rows)
    }
}

/// Whether `c` is white space a cell may carry around its number (what
/// `<[u8]>::trim_ascii` takes off, but the line feed, which ends the line).
#[inline]
fn blank(c: u8) -> bool {
    matches!(c, b' ' | b'\t' | b'\r' | b'\x0c')
}

/// The finite number of the cell that starts at `start` in `b`, parsed as
/// `str::parse::<f64>` parses the trimmed cell (the Eisel–Lemire algorithm,
/// `fast-float2`, which reads `inf`/`nan` spellings and a leading `+` as it
/// does and refuses the rest), and the index of the byte that ends the cell
/// (`,`, `\n` or `b.len()`); `None` when the trimmed cell is anything but a
/// finite number.
#[inline]
fn number_at(b: &[u8], start: usize) -> Option<(f64, usize)> {
    let mut i = start;
    while i < b.len() && blank(b[i]) {
        i += 1;
    }
    let (v, n): (f64, usize) = fast_float2::parse_partial(&b[i..]).ok()?;
    let mut end = i + n;
    while end < b.len() && blank(b[end]) {
        end += 1;
    }
    if end < b.len() && b[end] != b',' && b[end] != b'\n' {
        return None;
    }
    v.is_finite().then_some((v, end))
}

/// [`number_at`] on one whole cell.
#[cfg(test)]
fn number(cell: &[u8]) -> Option<f64> {
    match number_at(cell, 0) {
        Some((v, end)) if end == cell.len() => Some(v),
        _ => None,
    }
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

/// Appends rows `rows` of `columns` as CSV lines (shortest round-trip text).
/// A value equal (bit for bit) to the one above it in its column is not
/// formatted again: its text is copied from the row above (a supply
/// pressure, a held command).
fn write_rows(columns: &[&[f64]], rows: std::ops::Range<usize>, out: &mut Vec<u8>) {
    let mut buf = zmij::Buffer::new();
    // a row is put together in `row`, then appended with one copy
    let mut row = vec![0u8; columns.len() * (MAX_CELL + 1) + 1];
    // per column, the row above's value (bits) and its text's place in `out`
    let mut above: Vec<(u64, usize, usize)> = vec![(0, 0, 0); columns.len()];
    out.reserve(rows.len() * columns.len() * 20);
    for k in rows {
        let base = out.len();
        let mut at = 0;
        for (c, a) in columns.iter().zip(above.iter_mut()) {
            let bits = c[k].to_bits();
            let start = at;
            at = if a.2 > 0 && a.0 == bits {
                put_short(&mut row, at, &out[a.1..a.1 + a.2])
            } else {
                put_short(&mut row, at, buf.format(c[k]).as_bytes())
            };
            *a = (bits, base + start, at - start);
            row[at] = b',';
            at += 1;
        }
        // the last separator becomes the line end
        if at > 0 {
            row[at - 1] = b'\n';
        }
        out.extend_from_slice(&row[..at]);
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

/// [`write_columns`] formatted by `parts` threads, each a contiguous block of
/// rows (the header goes with the first): the parts, in order, are the text.
/// Writing them one after the other spares the copy of a concatenation.
pub fn write_columns_in_parts(names: &[&str], columns: &[&[f64]], parts: usize) -> Vec<Vec<u8>> {
    let mut head = names.join(",").into_bytes();
    head.push(b'\n');
    let rows = columns.first().map_or(0, |c| c.len());
    let parts = parts.clamp(1, rows.max(1));
    let bounds: Vec<usize> = (0..=parts).map(|i| i * rows / parts).collect();
    let mut out: Vec<Vec<u8>> = vec![Vec::new(); parts];
    out[0] = head;
    if parts == 1 {
        write_rows(columns, 0..rows, &mut out[0]);
        return out;
    }
    std::thread::scope(|s| {
        for (i, o) in out.iter_mut().enumerate() {
            let range = bounds[i]..bounds[i + 1];
            s.spawn(move || write_rows(columns, range, o));
        }
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

    /// A body long enough to be read in pieces reads as it does whole:
    /// every value, the blank end, and blank lines inside refused wherever
    /// the cut falls.
    #[test]
    fn pieces_read_as_the_whole() {
        let mut text = String::from("time,u,x\n");
        let mut k = 0u64;
        while text.len() < 3 * PARALLEL_BYTES {
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
        assert_eq!(
            PlainCsv::new(&ended).unwrap().columns(&[1, 0]).unwrap(),
            whole
        );
        for at in [0.1, 0.45, 0.5, 0.55, 0.9] {
            let mut i = (text.len() as f64 * at) as usize;
            while text.as_bytes()[i] != b'\n' {
                i += 1;
            }
            let holed = format!("{}\n{}", &text[..=i], &text[i + 1..]);
            assert!(
                PlainCsv::new(&holed).unwrap().columns(&[0]).is_none(),
                "blank line at {at}"
            );
        }
    }

    proptest! {
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
