//! Where a JSON path stands in a rig file's text (for messages that name the
//! line), and duplicate keys — which a JSON value cannot show, because the
//! parser keeps only the last.
//!
//! Paths are written as in every rig error: `components.valve.orifice.cd`,
//! `connections[3][1]`.

use std::collections::{HashMap, HashSet};

/// The result of scanning a JSON text.
#[derive(Clone, Debug, Default)]
pub struct Located {
    lines: HashMap<String, usize>,
    /// The first key that appears twice in one object: `(path, line)`.
    pub duplicate: Option<(String, usize)>,
}

impl Located {
    /// The 1-based line of `path`, or of its longest prefix that is in the
    /// text (a missing parameter is reported at its component, a missing
    /// top-level key at the object's opening line).
    pub fn line_of(&self, path: &str) -> Option<usize> {
        let mut p = path.to_string();
        loop {
            if let Some(l) = self.lines.get(&p) {
                return Some(*l);
            }
            match p.rfind(['.', '[']) {
                Some(cut) => p.truncate(cut),
                None => return self.lines.get("").copied(),
            }
        }
    }
}

struct Scanner<'a> {
    s: &'a [u8],
    i: usize,
    line: usize,
    out: Located,
}

impl Scanner<'_> {
    fn ws(&mut self) {
        while let Some(&c) = self.s.get(self.i) {
            match c {
                b'\n' => {
                    self.line += 1;
                    self.i += 1;
                }
                b' ' | b'\t' | b'\r' => self.i += 1,
                _ => break,
            }
        }
    }

    fn string(&mut self) -> Option<String> {
        // at the opening quote
        self.i += 1;
        let start = self.i;
        let mut escaped = false;
        while let Some(&c) = self.s.get(self.i) {
            self.i += 1;
            match c {
                b'\\' if !escaped => escaped = true,
                b'"' if !escaped => {
                    let raw = &self.s[start..self.i - 1];
                    return serde_json::from_slice::<String>(&self.s[start - 1..self.i])
                        .ok()
                        .or_else(|| Some(String::from_utf8_lossy(raw).into_owned()));
                }
                b'\n' => {
                    self.line += 1;
                    escaped = false;
                }
                _ => escaped = false,
            }
        }
        None
    }

    fn value(&mut self, path: &str) -> Option<()> {
        self.ws();
        self.out.lines.entry(path.to_string()).or_insert(self.line);
        match *self.s.get(self.i)? {
            b'{' => {
                self.i += 1;
                let mut seen = HashSet::new();
                loop {
                    self.ws();
                    match *self.s.get(self.i)? {
                        b'}' => {
                            self.i += 1;
                            return Some(());
                        }
                        b',' => {
                            self.i += 1;
                            continue;
                        }
                        b'"' => {}
                        _ => return None,
                    }
                    let line = self.line;
                    let key = self.string()?;
                    let child = if path.is_empty() {
                        key.clone()
                    } else {
                        format!("{path}.{key}")
                    };
                    if seen.insert(key) {
                        // the later of a key given flat and nested (`"a.b"`,
                        // `"a": {"b"}`) is where the reader refuses it
                        self.out.lines.insert(child.clone(), line);
                    } else if self.out.duplicate.is_none() {
                        self.out.duplicate = Some((child.clone(), line));
                    }
                    self.ws();
                    if *self.s.get(self.i)? != b':' {
                        return None;
                    }
                    self.i += 1;
                    self.value(&child)?;
                }
            }
            b'[' => {
                self.i += 1;
                let mut k = 0;
                loop {
                    self.ws();
                    match *self.s.get(self.i)? {
                        b']' => {
                            self.i += 1;
                            return Some(());
                        }
                        b',' => {
                            self.i += 1;
                            continue;
                        }
                        _ => {}
                    }
                    self.value(&format!("{path}[{k}]"))?;
                    k += 1;
                }
            }
            b'"' => self.string().map(|_| ()),
            _ => {
                while let Some(&c) = self.s.get(self.i) {
                    if matches!(c, b',' | b'}' | b']' | b' ' | b'\n' | b'\t' | b'\r') {
                        break;
                    }
                    self.i += 1;
                }
                Some(())
            }
        }
    }
}

/// Scans a JSON text (one that parses): the line of every key and element,
/// and the first duplicate key.
pub fn scan(text: &str) -> Located {
    let mut sc = Scanner {
        s: text.as_bytes(),
        i: 0,
        line: 1,
        out: Located::default(),
    };
    let _ = sc.value("");
    sc.out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lines_of_keys_and_elements_and_the_first_duplicate() {
        let text = "{\n  \"a\": {\n    \"b\": 1,\n    \"c\": [\n      [\"x\", \"y\"],\n      [\"z\"]\n    ]\n  },\n  \"a\": 2\n}\n";
        let l = scan(text);
        assert_eq!(l.line_of("a.b"), Some(3));
        assert_eq!(l.line_of("a.c[1]"), Some(6));
        assert_eq!(l.line_of("a.c[0][1]"), Some(5));
        assert_eq!(l.line_of("a.missing.deep"), Some(2));
        assert_eq!(l.duplicate, Some(("a".to_string(), 9)));
        assert!(scan("{\"k\": \"a\\\"b\", \"q\": 1}").duplicate.is_none());
        // a parameter given flat and nested: the later key's line
        let l = scan("{\"o\": {\"cd\": 1},\n \"o.cd\": 2}");
        assert_eq!(l.line_of("o.cd"), Some(2));
        assert_eq!(l.line_of("missing"), Some(1));
    }
}
