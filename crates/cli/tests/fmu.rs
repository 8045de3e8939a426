//! `hydrocyl fmu` end to end without the slave library of this build:
//! one-line errors, exit code 2, no file written. (Exports with the library, checked by
//! FMPy, are in `crates/fmu/tests/python`, run by `crates/fmu/tests/run_fmpy_tests.sh`.)

mod common;

use common::hydrocyl;
use std::path::Path;

/// `hydrocyl fmu --rig leaney-moog [extra] --out <out>` with `library` as
/// `--library` (or none), checked to fail with exit code 2 and no file;
/// returns stderr.
fn refused(out: &Path, extra: &[&str], library: Option<&Path>, env: Option<&Path>) -> String {
    let mut cmd = hydrocyl();
    cmd.args(["fmu", "--rig", "leaney-moog"])
        .args(extra)
        .arg("--out")
        .arg(out);
    if let Some(l) = library {
        cmd.arg("--library").arg(l);
    }
    if let Some(e) = env {
        cmd.env("HYDROCYL_FMU_LIBRARY", e);
    }
    let o = cmd.output().unwrap();
    assert_eq!(o.status.code(), Some(2));
    assert!(!out.exists());
    let err = String::from_utf8(o.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    err
}

#[test]
fn lists_the_presets() {
    let out = hydrocyl().args(["fmu", "--list-presets"]).output().unwrap();
    assert!(out.status.success());
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.lines().any(|l| l == "leaney-moog"), "{text}");
}

#[test]
fn a_missing_library_is_one_line_exit_2_and_no_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("drive.fmu");
    let missing = dir.path().join("nope.so");
    let err = refused(&out, &[], Some(&missing), None);
    assert!(
        err.contains("nope.so") && err.contains("--library"),
        "{err}"
    );
    let err = refused(&out, &[], None, Some(&missing));
    assert!(err.contains("HYDROCYL_FMU_LIBRARY"), "{err}");
}

#[test]
fn a_file_that_is_not_the_library_and_a_bad_set_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("drive.fmu");
    let fake = dir.path().join("fake.so");
    std::fs::write(&fake, b"not a library").unwrap();
    assert!(refused(&out, &[], Some(&fake), None).contains("fmi2DoStep"));
    let err = refused(&out, &["--set", "load.mass=-1"], Some(&fake), None);
    assert!(err.contains("load.mass"), "{err}");
}

/// A library that is not the one of this build is refused before anything
/// is written: a shared library that is not the FMU's (a proc-macro library
/// of this build's dependencies, beside the test binary) and an ELF file
/// that names `fmi2DoStep` but does not load. The message names the library
/// and the remedy. (A library lacking `hydrocyl_fmu_guid`, or computing
/// another GUID, is refused by the same check: `hydrocyl_fmu::ffi` tests.)
#[test]
fn a_library_of_another_build_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("drive.fmu");
    let older = hydrocyl_fmu::test_support::foreign_library();
    let err = refused(&out, &[], Some(&older), None);
    assert!(
        err.contains(&older.display().to_string())
            && err.contains("is not the hydrocyl FMU library")
            && err.contains("cargo build -p hydrocyl-fmu -p hydrocyl-cli"),
        "{err}"
    );
    let broken = dir.path().join("broken.so");
    std::fs::write(&broken, b"\x7fELF\x02\x01\x01 truncated, names fmi2DoStep").unwrap();
    let err = refused(&out, &[], None, Some(&broken));
    assert!(
        err.contains("broken.so")
            && err.contains("is not from the same build as this hydrocyl")
            && err.contains("does not load as a library")
            && err.contains("cargo build -p hydrocyl-fmu -p hydrocyl-cli"),
        "{err}"
    );
}

#[test]
fn the_fmu_is_never_written_over_its_rig_file_or_library() {
    let dir = tempfile::tempdir().unwrap();
    let rig = dir.path().join("my-rig.json");
    let text = std::fs::read(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../fixtures/rigs/leaney-moog.json"
    ))
    .unwrap();
    std::fs::write(&rig, &text).unwrap();
    let lib = dir.path().join("lib.so");
    std::fs::write(&lib, b"not a library").unwrap();
    for (out, what) in [(&rig, "--rig"), (&lib, "--library")] {
        let o = hydrocyl()
            .args(["fmu", "--rig"])
            .arg(&rig)
            .arg("--library")
            .arg(&lib)
            .arg("--out")
            .arg(out)
            .output()
            .unwrap();
        assert_eq!(o.status.code(), Some(2));
        let err = String::from_utf8(o.stderr).unwrap();
        assert_eq!(err.lines().count(), 1, "{err}");
        assert!(err.contains(what) && err.contains("destroy"), "{err}");
    }
    assert_eq!(std::fs::read(&rig).unwrap(), text);
    assert_eq!(std::fs::read(&lib).unwrap(), b"not a library");
}
