//! The README's promises about the tree: the layout table names exactly the
//! crate folders that exist, the design card's top level is there, and the
//! set-up commands are the ones CI runs.

use super::root;

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

#[test]
fn top_level_is_the_design_cards() {
    for p in [
        "Cargo.toml",
        "crates",
        "xtask",
        "tests",
        "fixtures",
        "docs",
        "README.md",
    ] {
        assert!(root().join(p).exists(), "missing top-level `{p}`");
    }
}

#[test]
fn readme_layout_table_names_every_crate_folder_and_no_other() {
    let text = readme();
    let listed: Vec<String> = text
        .lines()
        .filter_map(|l| l.strip_prefix("| `crates/"))
        .map(|l| l.split('`').next().unwrap().to_string())
        .collect();
    let mut present: Vec<String> = std::fs::read_dir(root().join("crates"))
        .unwrap()
        .map(|e| e.unwrap())
        .filter(|e| e.path().join("Cargo.toml").exists())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    present.sort();
    let mut listed_sorted = listed.clone();
    listed_sorted.sort();
    assert_eq!(listed_sorted, present, "README layout table vs crates/");
}

#[test]
fn ci_runs_the_readme_commands() {
    let text = readme();
    let ci = std::fs::read_to_string(root().join(".ci/run")).unwrap();
    for cmd in ["cargo xtask validate", "cargo xtask test"] {
        assert!(text.contains(cmd), "README lacks `{cmd}`");
        assert!(ci.contains(cmd), ".ci/run lacks `{cmd}`");
    }
}

#[test]
fn every_crate_opens_its_docs_with_a_title_and_a_compiled_example() {
    for e in std::fs::read_dir(root().join("crates")).unwrap() {
        let dir = e.unwrap().path();
        let lib = dir.join("src/lib.rs");
        if !lib.exists() {
            continue; // the CLI crate is a binary
        }
        let text = std::fs::read_to_string(&lib).unwrap();
        assert!(
            text.starts_with("//! # hydrocyl-"),
            "{} does not open with its crate title",
            lib.display()
        );
        // A Python extension module (cdylib only) has no Rust API: its
        // example is Python, run by its pytest suite (`cargo xtask test`).
        let manifest = std::fs::read_to_string(dir.join("Cargo.toml")).unwrap();
        let opening: &[&str] = if manifest.contains(r#"crate-type = ["cdylib"]"#) {
            &["//! ```python"]
        } else {
            &["//! ```", "//! ```rust"]
        };
        let examples = text
            .lines()
            .filter(|l| l.trim_end() == "//! ```" || opening.contains(&l.trim_end()))
            .count();
        // an opening and a closing fence at least; `text` diagrams are not examples
        assert!(examples >= 2, "{} has no example", lib.display());
    }
}

/// The `hydrocyl-*` crates a manifest lists under `[dependencies]` (not dev
/// or build), without the prefix.
fn workspace_dependencies(manifest: &str) -> Vec<String> {
    let mut in_deps = false;
    let mut deps = Vec::new();
    for line in manifest.lines() {
        let line = line.trim();
        if line.starts_with('[') {
            in_deps = line == "[dependencies]";
            continue;
        }
        if let Some(name) = line.strip_prefix("hydrocyl-").filter(|_| in_deps) {
            let name = name.split([' ', '=', '.']).next();
            deps.push(name.unwrap().to_string());
        }
    }
    deps
}

#[test]
fn architecture_graph_is_the_transitive_reduction_of_the_manifests() {
    use std::collections::{BTreeMap, BTreeSet};
    let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    let mut dirs: Vec<_> = std::fs::read_dir(root().join("crates"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    dirs.push(root().join("xtask"));
    for dir in dirs {
        let Ok(manifest) = std::fs::read_to_string(dir.join("Cargo.toml")) else {
            continue;
        };
        let name = dir.file_name().unwrap().to_string_lossy().into_owned();
        graph.insert(
            name,
            workspace_dependencies(&manifest).into_iter().collect(),
        );
    }
    let reaches = |from: &str, to: &str, skip_direct: bool| -> bool {
        let mut stack: Vec<&str> = graph[from]
            .iter()
            .filter(|d| !(skip_direct && d.as_str() == to))
            .map(String::as_str)
            .collect();
        let mut seen = BTreeSet::new();
        while let Some(n) = stack.pop() {
            if n == to {
                return true;
            }
            if seen.insert(n) {
                stack.extend(graph[n].iter().map(String::as_str));
            }
        }
        false
    };
    let mut expected = BTreeSet::new();
    for (from, deps) in &graph {
        for to in deps {
            if !reaches(from, to, true) {
                expected.insert(format!("{from} --> {to}"));
            }
        }
    }
    let doc = std::fs::read_to_string(root().join("docs/architecture.md")).unwrap();
    let drawn: BTreeSet<String> = doc
        .lines()
        .map(str::trim)
        .filter(|l| l.contains(" --> "))
        .map(str::to_string)
        .collect();
    assert_eq!(
        drawn, expected,
        "docs/architecture.md's graph vs the transitive reduction of the crates' [dependencies]"
    );
}
