//! `cargo xtask validate`: every section runs, prints what it measured, and the
//! task fails if any check failed. Sections for work not yet in hydrocyl say so
//! and report no result.

use crate::report::Section;

mod chapter9;
mod diagnose;
mod doc_table;
mod friction;
mod hybrid;
mod integrators;
mod valve_rig;
mod xfactor;

/// A validation section: its name and the function that measures it.
type SectionFn = fn() -> Section;

fn sections() -> Vec<(&'static str, SectionFn)> {
    vec![
        ("integrators", integrators::section),
        ("xfactor", xfactor::section),
        ("friction", friction::section),
        ("valve-rig", valve_rig::section),
        ("hybrid", hybrid::section),
        ("diagnose", diagnose::section),
        ("chapter9", chapter9::section),
    ]
}

/// Runs the sections whose name contains `only` (all when `None`); returns
/// `true` when every check passed.
pub fn run(only: Option<&str>) -> bool {
    let start = std::time::Instant::now();
    let mut all_ok = true;
    let mut n_checks = 0;
    let mut n_failed = 0;
    let chosen: Vec<_> = sections()
        .into_iter()
        .filter(|(name, _)| only.is_none_or(|o| name.contains(o)))
        .collect();
    let bar = crate::progress::bar("validate sections", chosen.len());
    for (name, f) in chosen {
        bar.set_message(name);
        let s = f();
        bar.inc(1);
        bar.suspend(|| s.print());
        n_checks += s.checks.len();
        n_failed += s.checks.iter().filter(|c| !c.pass).count();
        all_ok &= s.passed();
    }
    bar.finish_and_clear();
    println!("\nvalidate: {} checks, {} failed", n_checks, n_failed);
    crate::progress::wall("validate", start);
    all_ok
}
