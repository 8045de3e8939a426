//! `hydrocyl fmu` end to end without the slave library: one-line errors,
//! exit code 2, no file written. (Exports with the library, checked by
//! FMPy, are in `crates/fmu/tests/python`, run by `crates/fmu/tests/run_fmpy_tests.sh`.)

use std::process::Command;

fn hydrocyl() -> Command {
    Command::new(env!("CARGO_BIN_EXE_hydrocyl"))
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
    let out_path = dir.path().join("drive.fmu");
    let missing = dir.path().join("nope.so");
    let out = hydrocyl()
        .args(["fmu", "--rig", "leaney-moog", "--out"])
        .arg(&out_path)
        .arg("--library")
        .arg(&missing)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8(out.stderr).unwrap();
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(
        err.contains("nope.so") && err.contains("--library"),
        "{err}"
    );
    assert!(!out_path.exists());
    // the same through the environment variable
    let out = hydrocyl()
        .args(["fmu", "--rig", "leaney-moog", "--out"])
        .arg(&out_path)
        .env("HYDROCYL_FMU_LIBRARY", &missing)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8(out.stderr)
        .unwrap()
        .contains("HYDROCYL_FMU_LIBRARY"));
    assert!(!out_path.exists());
}

#[test]
fn a_file_that_is_not_the_library_and_a_bad_set_are_refused() {
    let dir = tempfile::tempdir().unwrap();
    let out_path = dir.path().join("drive.fmu");
    let fake = dir.path().join("fake.so");
    std::fs::write(&fake, b"not a library").unwrap();
    let out = hydrocyl()
        .args(["fmu", "--rig", "leaney-moog", "--out"])
        .arg(&out_path)
        .arg("--library")
        .arg(&fake)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8(out.stderr)
        .unwrap()
        .contains("fmi2DoStep"));
    assert!(!out_path.exists());
    let out = hydrocyl()
        .args([
            "fmu",
            "--rig",
            "leaney-moog",
            "--set",
            "load.mass=-1",
            "--out",
        ])
        .arg(&out_path)
        .arg("--library")
        .arg(&fake)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8(out.stderr).unwrap().contains("load.mass"));
    assert!(!out_path.exists());
}
