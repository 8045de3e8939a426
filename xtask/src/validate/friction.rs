//! Validation section: friction.

use crate::report::Section;

/// Runs this section and returns what it measured.
pub fn section() -> Section {
    let mut s = Section::new("friction");
    s.note("not in hydrocyl yet: nothing measured");
    s
}
