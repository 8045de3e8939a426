//! `cargo xtask commands`: writes `fixtures/commands/` — the command files
//! of the thesis's experiments and their README — from the studies' own
//! signal definitions (`hydrocyl_studies::commands`). The test
//! `crates/cli/tests/commands.rs` checks that the shipped files are what
//! this writes.

use hydrocyl_studies::commands::{all, readme, FOLDER};
use std::path::Path;

/// Writes the folder (from the workspace root); `false` on failure.
pub fn run() -> bool {
    match write(
        &Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("..")
            .join(FOLDER),
    ) {
        Ok(n) => {
            println!("wrote {n} command files and README.md to {FOLDER}");
            true
        }
        Err(e) => {
            eprintln!("xtask commands: {e}");
            false
        }
    }
}

/// Writes every file and the README into `dir`, removing CSV files the
/// generator no longer makes; the number of command files.
fn write(dir: &Path) -> Result<usize, String> {
    let files = all()?;
    std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    let io = |p: &Path, e: std::io::Error| format!("{}: {e}", p.display());
    for entry in std::fs::read_dir(dir).map_err(|e| io(dir, e))? {
        let p = entry.map_err(|e| io(dir, e))?.path();
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        if name.ends_with(".csv") && !files.iter().any(|f| f.name == name) {
            std::fs::remove_file(&p).map_err(|e| io(&p, e))?;
        }
    }
    for f in &files {
        let p = dir.join(&f.name);
        std::fs::write(&p, f.csv()).map_err(|e| io(&p, e))?;
    }
    let p = dir.join("README.md");
    std::fs::write(&p, readme(&files)).map_err(|e| io(&p, e))?;
    Ok(files.len())
}
