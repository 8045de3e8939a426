//! What the CLI's end-to-end tests share: the binary, and a run of
//! `hydrocyl simulate` that must succeed.

// each test crate uses what it needs of this module
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

/// The `hydrocyl` binary built for these tests.
pub fn hydrocyl() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
}

/// `hydrocyl simulate --rig <rig>` on `cmd` into `out` with `extra`
/// arguments, which must succeed.
pub fn simulate_ok(rig: &str, cmd: &Path, out: &Path, extra: &[&str]) -> Output {
    let st = hydrocyl()
        .args(["simulate", "--rig", rig, "--command"])
        .arg(cmd)
        .arg("--out")
        .arg(out)
        .args(extra)
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{extra:?}: {}",
        String::from_utf8_lossy(&st.stderr)
    );
    st
}
