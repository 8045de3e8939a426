//! A fixture the crate's tests and `hydrocyl-cli`'s share: a shared library
//! of another build. Not part of the crate's interface.

use std::path::PathBuf;

/// A shared library that is not the FMU's: thiserror's proc-macro library
/// (`libthiserror_impl-*.so`), which cargo builds beside the test binary
/// that calls this (this build's dependencies). Panics when there is none.
pub fn foreign_library() -> PathBuf {
    let exe = std::env::current_exe().expect("the test binary's path");
    let deps = exe.parent().expect("the test binary's directory");
    std::fs::read_dir(deps)
        .expect("the test binary's directory lists")
        .filter_map(|e| e.ok().map(|e| e.path()))
        .find(|p| {
            let n = p.file_name().unwrap_or_default().to_string_lossy();
            n.starts_with("libthiserror_impl-") && n.ends_with(".so")
        })
        .expect("thiserror's proc-macro library beside the test binary")
}
