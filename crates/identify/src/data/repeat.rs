//! A record given twice among the records of one joint fit: its samples
//! would count twice and every ± interval would be √2 too narrow. Said
//! once for every front end (the CLI's `--data`, Python's list of records).

use std::path::Path;

/// One of the records of a joint fit, as it was given.
#[derive(Clone, Copy, Debug)]
pub enum RecordInput<'a> {
    /// A CSV file by path.
    File(&'a Path),
    /// A record made in memory (arrays written as CSV text): its bytes.
    Text(&'a [u8]),
}

/// Two inputs that are one record: their positions among the inputs (from
/// 0, `first < second`) and how they are one.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Repeated {
    /// Position of the first of the two.
    pub first: usize,
    /// Position of the second.
    pub second: usize,
    /// How they are one: `the same file, given twice` or `the same content
    /// (one record under two names)`.
    pub how: &'static str,
}

impl Repeated {
    /// The message refusing it: `first` and `second` name the two inputs
    /// as the caller's arguments do (`--data a.csv`), `positions` is the
    /// plural word their positions (from 1) are counted in (`arguments`).
    pub fn message(&self, first: &str, second: &str, positions: &str) -> String {
        format!(
            "{first} and {second} ({positions} {} and {}): {}; its samples would count twice in the joint fit (every ± interval √2 too narrow): give each record once",
            self.first + 1,
            self.second + 1,
            self.how
        )
    }
}

/// The first pair of `inputs` that are one record, or `None`: the same
/// file (the same path once resolved through links, or the same file under
/// two names: a hard link), or the same bytes (a copy of a file, a record
/// made in memory twice, or one made as a file holds it). What is not a
/// regular file (a pipe) or cannot be read is not compared.
pub fn repeated_record(inputs: &[RecordInput<'_>]) -> Option<Repeated> {
    let meta: Vec<Option<std::fs::Metadata>> = inputs
        .iter()
        .map(|i| match i {
            RecordInput::File(p) => std::fs::metadata(p).ok().filter(|m| m.is_file()),
            RecordInput::Text(_) => None,
        })
        .collect();
    let canon: Vec<Option<std::path::PathBuf>> = inputs
        .iter()
        .map(|i| match i {
            RecordInput::File(p) => p.canonicalize().ok(),
            RecordInput::Text(_) => None,
        })
        .collect();
    // the length of each input's bytes, where known without reading them
    let len = |k: usize| match inputs[k] {
        RecordInput::File(_) => meta[k].as_ref().map(|m| m.len()),
        RecordInput::Text(t) => Some(t.len() as u64),
    };
    let bytes = |k: usize| match inputs[k] {
        RecordInput::File(p) => meta[k].as_ref().and_then(|_| std::fs::read(p).ok()),
        RecordInput::Text(t) => Some(t.to_vec()),
    };
    for second in 1..inputs.len() {
        for first in 0..second {
            let pair = |how| Some(Repeated { first, second, how });
            if let (Some(a), Some(b)) = (&meta[first], &meta[second]) {
                if canon[first].is_some() && canon[first] == canon[second] || same_inode(a, b) {
                    return pair("the same file, given twice");
                }
            }
            if len(first).is_some() && len(first) == len(second) {
                if let (Some(x), Some(y)) = (bytes(first), bytes(second)) {
                    if x == y {
                        return pair("the same content (one record under two names)");
                    }
                }
            }
        }
    }
    None
}

/// Whether `a` and `b` are one file (device and inode).
#[cfg(unix)]
fn same_inode(a: &std::fs::Metadata, b: &std::fs::Metadata) -> bool {
    use std::os::unix::fs::MetadataExt;
    a.dev() == b.dev() && a.ino() == b.ino()
}

/// Elsewhere the canonical paths and the content decide.
#[cfg(not(unix))]
fn same_inode(_: &std::fs::Metadata, _: &std::fs::Metadata) -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Records made in memory are compared by their bytes, with each other
    /// and with files; different ones pass.
    #[test]
    fn a_record_made_in_memory_twice_is_one_record() {
        let dir = std::env::temp_dir().join(format!("hydrocyl-repeat-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("a.csv");
        std::fs::write(&file, "time,force\n0,1\n").unwrap();
        let (a, b): (&[u8], &[u8]) = (b"time,force\n0,1\n", b"time,force\n0,2\n");
        let r = |i: &[RecordInput<'_>]| repeated_record(i);
        assert_eq!(r(&[RecordInput::Text(a), RecordInput::Text(b)]), None);
        let twice = r(&[
            RecordInput::Text(b),
            RecordInput::Text(a),
            RecordInput::Text(a),
        ])
        .unwrap();
        assert_eq!((twice.first, twice.second), (1, 2));
        assert!(twice.how.starts_with("the same content"), "{twice:?}");
        let m = r(&[RecordInput::File(&file), RecordInput::Text(a)])
            .unwrap()
            .message("x", "y", "records");
        assert!(
            m.starts_with("x and y (records 1 and 2): the same content"),
            "{m}"
        );
        assert!(m.ends_with("give each record once"), "{m}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
