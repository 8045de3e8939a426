//! The tables of results written into the docs, checked against the results
//! this run computes: every number in a cell must be the computed value
//! rounded to the digits the cell shows. A table that went stale (a change
//! moved a result and nobody re-measured the docs) fails here.

use std::collections::BTreeMap;

use crate::report::Section;

/// One Markdown table of a document: its rows by their first cell.
pub struct DocTable {
    /// The document, for messages.
    doc: &'static str,
    rows: BTreeMap<String, Vec<String>>,
}

impl DocTable {
    /// The table of `text` whose header row starts with `header` (e.g.
    /// `"| fixture | planted | found | fitted"`); `None` if it has none.
    pub fn find(doc: &'static str, text: &str, header: &str) -> Option<Self> {
        let mut lines = text.lines().skip_while(|l| !l.starts_with(header));
        lines.next()?;
        let rows = lines
            .skip(1) // the |---| line
            .take_while(|l| l.starts_with('|'))
            .map(|l| {
                let cells: Vec<String> = l
                    .trim()
                    .trim_matches('|')
                    .split('|')
                    .map(|c| c.trim().to_string())
                    .collect();
                (cells[0].clone(), cells)
            })
            .collect();
        Some(Self { doc, rows })
    }

    /// The text of cell `col` of the row of `fixture`.
    pub fn cell(&self, fixture: &str, col: usize) -> Option<String> {
        self.rows.get(fixture)?.get(col).cloned()
    }

    /// Checks the row of `fixture`: each `(column, values)` cell shows
    /// `values`, in order, at its printed precision ([`Shown::shows`]), and the
    /// `(column, text)` cells read `text`.
    pub fn check_row(
        &self,
        s: &mut Section,
        fixture: &str,
        numbers: &[(usize, Vec<f64>)],
        texts: &[(usize, String)],
    ) {
        let name = format!("{} table row {fixture}", self.doc);
        let Some(cells) = self.rows.get(fixture) else {
            s.check(&name, "no such row".into(), "a row".into(), false);
            return;
        };
        let mut wrong = Vec::new();
        for (col, values) in numbers {
            let cell = cells.get(*col).map_or("", String::as_str);
            let shown = numbers_in(cell);
            let ok =
                shown.len() == values.len() && shown.iter().zip(values).all(|(n, &v)| n.shows(v));
            if !ok {
                let got: Vec<String> = values.iter().map(|v| format!("{v:.6e}")).collect();
                wrong.push(format!(
                    "column {col} shows `{cell}`, the run gives {}",
                    got.join(", ")
                ));
            }
        }
        for (col, text) in texts {
            let cell = cells.get(*col).map_or("", String::as_str);
            if cell != text {
                wrong.push(format!(
                    "column {col} shows `{cell}`, the run gives `{text}`"
                ));
            }
        }
        let pass = wrong.is_empty();
        s.check(
            &name,
            if pass {
                "as shown".into()
            } else {
                wrong.join("; ")
            },
            "every number as the run gives it, at the digits shown".into(),
            pass,
        );
    }
}

/// A number as a document prints it: its value and half a unit of its last
/// digit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Shown {
    value: f64,
    half_unit: f64,
}

impl Shown {
    /// Reads `1.25`, `0.00748`, `2.48e-4`, `-3e5`, `800` (a Unicode minus
    /// too); `None` for anything else.
    pub fn parse(token: &str) -> Option<Self> {
        let t = token.replace('−', "-");
        let value: f64 = t.parse().ok()?;
        if !value.is_finite() {
            return None;
        }
        let (mantissa, exp) = match t.split_once(['e', 'E']) {
            Some((m, e)) => (m, e.parse::<i32>().ok()?),
            None => (t.as_str(), 0),
        };
        let decimals = mantissa.split_once('.').map_or(0, |(_, d)| d.len()) as i32;
        Some(Self {
            value,
            half_unit: 0.5 * 10f64.powi(exp - decimals),
        })
    }

    /// Whether `v` rounds to this number at its printed precision (with a
    /// rounding slack of a few ulps).
    pub fn shows(&self, v: f64) -> bool {
        (v - self.value).abs() <= self.half_unit * (1.0 + 1e-9) + 4.0 * f64::EPSILON * v.abs()
    }
}

/// The numbers of a cell, in order: its whitespace-separated tokens that
/// read as numbers once parentheses are stripped (`0.00748 → 0.00748
/// (0.00765)` holds three; `sigma0 2.4126e5 ± 7.1e4` two).
pub fn numbers_in(cell: &str) -> Vec<Shown> {
    cell.split_whitespace()
        .filter_map(|t| Shown::parse(t.trim_matches(|c| c == '(' || c == ')' || c == ',')))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_number_shows_what_rounds_to_it() {
        let n = Shown::parse("0.00748").unwrap();
        assert!(n.shows(0.007484) && n.shows(0.007475));
        assert!(!n.shows(0.007486) && !n.shows(0.00747));
        let e = Shown::parse("2.48e-4").unwrap();
        assert!(e.shows(2.484e-4) && !e.shows(2.49e-4));
        let i = Shown::parse("800").unwrap();
        assert!(i.shows(800.24) && !i.shows(800.6));
        assert!(Shown::parse("−3e5").unwrap().shows(-3.0e5));
        assert_eq!(Shown::parse("sigma0"), None);
    }

    #[test]
    fn a_cell_holds_its_numbers_in_order() {
        let v: Vec<f64> = numbers_in("0.104 → 0.00778 (0.00794)")
            .iter()
            .map(|n| n.value)
            .collect();
        assert_eq!(v, [0.104, 0.00778, 0.00794]);
        assert_eq!(numbers_in("sigma0 2.4126e5 ± 7.1e4").len(), 2);
        assert!(numbers_in("–").is_empty());
    }

    #[test]
    fn a_table_is_found_by_its_header() {
        let md =
            "text\n\n| fixture | a | b |\n|---|---|---|\n| x | 1 | 2.5 |\n| y | 3 | 4 |\n\nmore\n";
        let t = DocTable::find("doc.md", md, "| fixture | a").unwrap();
        assert_eq!(t.rows["y"], ["y", "3", "4"]);
        let mut s = Section::new("t");
        t.check_row(&mut s, "x", &[(2, vec![2.54])], &[(1, "1".into())]);
        t.check_row(&mut s, "x", &[(2, vec![2.56])], &[]);
        t.check_row(&mut s, "z", &[], &[]);
        assert_eq!(
            s.checks.iter().map(|c| c.pass).collect::<Vec<_>>(),
            [true, false, false]
        );
    }
}
