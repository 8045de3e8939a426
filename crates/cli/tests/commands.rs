//! The shipped command files of the thesis's experiments
//! (`fixtures/commands/`): they are what `cargo xtask commands` writes from
//! the studies' signal definitions (so they cannot drift from them), and
//! each runs through `hydrocyl simulate` on its preset by the command line
//! its README gives (on its first 0.3 s, to keep the test fast).

use hydrocyl_studies::commands::{all, readme, CommandFile, FOLDER};
use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn folder() -> PathBuf {
    root().join(FOLDER)
}

#[test]
fn the_shipped_files_are_what_the_generator_writes() {
    let files = all().unwrap();
    let dir = folder();
    for f in &files {
        let shipped = std::fs::read_to_string(dir.join(&f.name))
            .unwrap_or_else(|e| panic!("{}: {e} (run `cargo xtask commands`)", f.name));
        assert!(
            shipped == f.csv(),
            "{}: not what the generator writes; run `cargo xtask commands`",
            f.name
        );
    }
    let shipped = std::fs::read_to_string(dir.join("README.md")).unwrap();
    assert!(
        shipped == readme(&files),
        "README.md: not what the generator writes; run `cargo xtask commands`"
    );
    // nothing else: every CSV there is one the generator makes
    for e in std::fs::read_dir(&dir).unwrap() {
        let name = e.unwrap().file_name().to_string_lossy().into_owned();
        assert!(
            name == "README.md" || files.iter().any(|f| f.name == name),
            "{name}: not written by the generator"
        );
    }
}

/// The first `span` seconds of `f` as a command file in `dir`.
fn head(f: &CommandFile, span: f64, dir: &Path) -> PathBuf {
    let mut text = String::new();
    for (i, line) in f.csv().lines().enumerate() {
        if i > 0 && f.time[i - 1] > span {
            break;
        }
        text.push_str(line);
        text.push('\n');
    }
    let p = dir.join(&f.name);
    std::fs::write(&p, text).unwrap();
    p
}

#[test]
fn each_runs_on_its_preset_by_the_readmes_command_line() {
    let dir = tempfile::tempdir().unwrap();
    for f in all().unwrap() {
        let cmd = head(&f, 0.3, dir.path());
        // the README's line, its files swapped for the test's
        let line = f.command_line();
        let words: Vec<&str> = line.split_whitespace().collect();
        assert_eq!(words[..2], ["hydrocyl", "simulate"], "{line}");
        let mut args: Vec<String> = vec!["simulate".into()];
        let mut it = words[2..].iter();
        while let Some(&w) = it.next() {
            args.push(w.to_string());
            let value = match w {
                "--command" => {
                    let shipped = it.next().unwrap();
                    assert!(root().join(shipped).exists(), "{line}");
                    cmd.to_string_lossy().into_owned()
                }
                "--out" | "--ledger" => dir
                    .path()
                    .join(it.next().unwrap())
                    .to_string_lossy()
                    .into_owned(),
                // the short run has no warm-up period
                "--ledger-from" => {
                    it.next();
                    "0".into()
                }
                _ if w.starts_with("--") && w != "--quiet" => it.next().unwrap().to_string(),
                _ => continue,
            };
            args.push(value);
        }
        let st = Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
            .args(&args)
            .output()
            .unwrap();
        assert!(
            st.status.success(),
            "{line}: {}",
            String::from_utf8_lossy(&st.stderr)
        );
        let stem = f.name.trim_end_matches(".csv");
        let out = std::fs::read_to_string(dir.path().join(format!("{stem}.out.csv"))).unwrap();
        assert_eq!(
            out.lines().count(),
            std::fs::read_to_string(&cmd).unwrap().lines().count(),
            "{line}"
        );
        if f.ledger_from.is_some() {
            let l: serde_json::Value = serde_json::from_str(
                &std::fs::read_to_string(dir.path().join(format!("{stem}.ledger.json"))).unwrap(),
            )
            .unwrap();
            let closure = l["closure_relative"].as_f64().unwrap();
            assert!(closure.abs() < 1e-6, "{line}: closure {closure}");
        }
    }
}
