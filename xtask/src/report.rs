//! A small report shared by the xtask sections: named checks with the measured
//! value, the reference (thesis or closed form) and whether the check passed.

use std::fmt::Write as _;

/// One measured check.
pub struct Check {
    /// What was checked.
    pub name: String,
    /// What hydrocyl measured, formatted.
    pub measured: String,
    /// The reference it is compared with (thesis value, closed form), formatted.
    pub reference: String,
    /// `true` when the measured value meets the criterion.
    pub pass: bool,
}

/// The checks of one section and free-form notes (tables, remarks).
#[derive(Default)]
pub struct Section {
    /// Section title.
    pub title: String,
    /// The checks, in order.
    pub checks: Vec<Check>,
    /// Text printed after the checks (tables, remarks).
    pub notes: String,
}

impl Section {
    /// A new, empty section.
    pub fn new(title: &str) -> Self {
        Self {
            title: title.to_string(),
            ..Self::default()
        }
    }

    /// Records a check.
    pub fn check(&mut self, name: &str, measured: String, reference: String, pass: bool) {
        self.checks.push(Check {
            name: name.to_string(),
            measured,
            reference,
            pass,
        });
    }

    /// Appends a line to the notes.
    pub fn note(&mut self, line: &str) {
        let _ = writeln!(self.notes, "{line}");
    }

    /// `true` when every check passed.
    pub fn passed(&self) -> bool {
        self.checks.iter().all(|c| c.pass)
    }

    /// Prints the section as a table.
    pub fn print(&self) {
        println!("\n== {} ==", self.title);
        if !self.checks.is_empty() {
            let w = self
                .checks
                .iter()
                .map(|c| c.name.len())
                .max()
                .unwrap_or(0)
                .max(5);
            let wm = self
                .checks
                .iter()
                .map(|c| c.measured.len())
                .max()
                .unwrap_or(0)
                .max(8);
            println!(
                "{:<w$}  {:<wm$}  {:<6}  reference",
                "check", "hydrocyl", "result"
            );
            for c in &self.checks {
                let r = if c.pass { "pass" } else { "FAIL" };
                println!(
                    "{:<w$}  {:<wm$}  {:<6}  {}",
                    c.name, c.measured, r, c.reference
                );
            }
        }
        if !self.notes.is_empty() {
            print!("{}", self.notes);
        }
    }
}
