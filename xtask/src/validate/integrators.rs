//! Validation section: integrators.

use crate::report::Section;

/// Runs this section and returns what it measured.
pub fn section() -> Section {
    let mut s = Section::new("integrators");
    s.note("not in hydrocyl yet: nothing measured");
    s
}
