//! The C ABI in-process: the exported `fmi2*` functions called as a host
//! would (instantiate from a resource folder, set, step, get, reset, free),
//! two instances side by side, and the error paths.
#![allow(unsafe_code)]

use hydrocyl_fmu::ffi::*;
use hydrocyl_fmu::model_description::guid;
use hydrocyl_fmu::variables::Variables;
use hydrocyl_system::rig;
use std::ffi::{c_void, CString};
use std::ptr::null_mut;

struct Fmu {
    _dir: tempfile::TempDir,
    uri: CString,
    guid: CString,
    vars: Variables,
}

fn fmu(rig_name: &str) -> Fmu {
    let dir = tempfile::tempdir().unwrap();
    let res = dir.path().join("resources");
    std::fs::create_dir(&res).unwrap();
    let value = rig::preset(rig_name).unwrap();
    let text = serde_json::to_string_pretty(&value).unwrap();
    std::fs::write(res.join("rig.json"), &text).unwrap();
    let vars = Variables::of(&value).unwrap();
    Fmu {
        uri: CString::new(format!("file://{}", res.display())).unwrap(),
        guid: CString::new(guid(&text, &vars)).unwrap(),
        vars,
        _dir: dir,
    }
}

impl Fmu {
    fn vr(&self, name: &str) -> u32 {
        self.vars.list.iter().position(|v| v.name == name).unwrap() as u32
    }
    fn instantiate(&self, guid: &CString) -> *mut c_void {
        let name = CString::new("test").unwrap();
        unsafe {
            fmi2Instantiate(
                name.as_ptr(),
                CO_SIMULATION,
                guid.as_ptr(),
                self.uri.as_ptr(),
                std::ptr::null(),
                0,
                0,
            )
        }
    }
}

fn set(c: *mut c_void, vr: u32, v: f64) -> Status {
    unsafe { fmi2SetReal(c, &vr, 1, &v) }
}

fn get(c: *mut c_void, vr: u32) -> f64 {
    let mut v = f64::NAN;
    assert_eq!(unsafe { fmi2GetReal(c, &vr, 1, &mut v) }, OK);
    v
}

fn start(c: *mut c_void) {
    unsafe {
        assert_eq!(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0), OK);
        assert_eq!(fmi2EnterInitializationMode(c), OK);
        assert_eq!(fmi2ExitInitializationMode(c), OK);
    }
}

/// Position after `n` steps of `h` at command `u`.
fn run(c: *mut c_void, f: &Fmu, u: f64, n: usize, h: f64) -> f64 {
    assert_eq!(set(c, f.vr("command"), u), OK);
    for k in 0..n {
        assert_eq!(unsafe { fmi2DoStep(c, k as f64 * h, h, 1) }, OK, "step {k}");
    }
    get(c, f.vr("position"))
}

#[test]
fn instantiate_set_step_get_reset_free() {
    let f = fmu("leaney-moog");
    assert_eq!(
        unsafe { std::ffi::CStr::from_ptr(fmi2GetVersion()) }.to_str(),
        Ok("2.0")
    );
    let c = f.instantiate(&f.guid);
    assert!(!c.is_null());
    assert_eq!(set(c, f.vr("load.mass"), 50.0), OK);
    assert_eq!(get(c, f.vr("load.mass")), 50.0);
    start(c);
    let x = run(c, &f, 0.1, 100, 1e-3);
    assert!(x > 1e-3, "the rod extends on a positive command: {x}");
    // after a reset the same run gives the same result, bit for bit
    unsafe { assert_eq!(fmi2Reset(c), OK) };
    assert_eq!(get(c, f.vr("load.mass")), 100.0, "reset restores the start");
    assert_eq!(set(c, f.vr("load.mass"), 50.0), OK);
    start(c);
    assert_eq!(run(c, &f, 0.1, 100, 1e-3), x);
    unsafe {
        assert_eq!(fmi2Terminate(c), OK);
        fmi2FreeInstance(c);
    }
}

#[test]
fn two_instances_are_independent() {
    let f = fmu("leaney-moog");
    let single = |mass: f64| {
        let c = f.instantiate(&f.guid);
        assert_eq!(set(c, f.vr("load.mass"), mass), OK);
        start(c);
        let x = run(c, &f, 0.2, 50, 2e-3);
        unsafe { fmi2FreeInstance(c) };
        x
    };
    let (xa, xb) = (single(100.0), single(20.0));
    assert_ne!(xa, xb);
    let (a, b) = (f.instantiate(&f.guid), f.instantiate(&f.guid));
    assert_eq!(set(b, f.vr("load.mass"), 20.0), OK);
    start(a);
    start(b);
    for c in [a, b] {
        assert_eq!(set(c, f.vr("command"), 0.2), OK);
    }
    for k in 0..50 {
        for c in [a, b] {
            assert_eq!(unsafe { fmi2DoStep(c, k as f64 * 2e-3, 2e-3, 1) }, OK);
        }
    }
    assert_eq!(get(a, f.vr("position")), xa);
    assert_eq!(get(b, f.vr("position")), xb);
    unsafe {
        fmi2FreeInstance(a);
        fmi2FreeInstance(b);
    }
}

#[test]
fn errors_are_statuses_not_crashes() {
    let f = fmu("leaney-moog");
    // wrong GUID or resource folder: NULL
    let bad = CString::new("{00000000-0000-0000-0000-000000000000}").unwrap();
    assert!(f.instantiate(&bad).is_null());
    let c = f.instantiate(&f.guid);
    // a bad parameter value is refused and leaves the old value
    assert_eq!(set(c, f.vr("load.mass"), -1.0), ERROR);
    assert_eq!(set(c, f.vr("solver.rtol"), 2.0), ERROR);
    assert_eq!(set(c, 100_000, 1.0), ERROR);
    assert_eq!(get(c, f.vr("load.mass")), 100.0);
    // stepping before initialisation, a step from the wrong time
    unsafe { assert_eq!(fmi2DoStep(c, 0.0, 1e-3, 1), ERROR) };
    start(c);
    unsafe {
        assert_eq!(fmi2DoStep(c, 5.0, 1e-3, 1), ERROR);
        assert_eq!(fmi2DoStep(c, 0.0, -1.0, 1), ERROR);
        // a communication point that is not a number: refused, not a failure
        assert_eq!(fmi2DoStep(c, f64::NAN, 1e-3, 1), ERROR);
        assert_eq!(fmi2DoStep(c, 0.0, 1e-3, 1), OK);
        assert_eq!(fmi2DoStep(c, 1e-3, 1e-3, 1), OK);
        // fixed parameters cannot change after initialisation
        assert_eq!(set(c, f.vr("load.mass"), 50.0), ERROR);
        // a state saved here and freed; a null state pointer is an error
        let mut s = null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut s), OK);
        assert!(!s.is_null());
        assert_eq!(fmi2SetFMUstate(c, null_mut()), ERROR);
        assert_eq!(fmi2FreeFMUstate(c, &mut s), OK);
        assert!(s.is_null());
        // an unsupported optional function says so
        assert_eq!(fmi2CancelStep(c), ERROR);
        // null component
        assert_eq!(fmi2DoStep(null_mut(), 0.0, 1e-3, 1), ERROR);
        // steps of 1 µs and of 1 s both work
        assert_eq!(fmi2DoStep(c, 2e-3, 1e-6, 1), OK);
        assert_eq!(fmi2DoStep(c, 2e-3 + 1e-6, 1.0, 1), OK);
        fmi2FreeInstance(c);
    }
}

/// Freeing an instance twice, or using it after it was freed, is illegal
/// per FMI; the library refuses the pointer (no double free, no use after
/// free) and the host goes on. Likewise an FMU state freed twice.
#[test]
fn a_freed_instance_or_state_is_refused_not_used() {
    let f = fmu("leaney-moog");
    let c = f.instantiate(&f.guid);
    assert!(!c.is_null());
    start(c);
    unsafe {
        let mut s = null_mut();
        assert_eq!(fmi2GetFMUstate(c, &mut s), OK);
        let copy = s;
        assert_eq!(fmi2FreeFMUstate(c, &mut s), OK);
        let mut again = copy;
        assert_eq!(fmi2FreeFMUstate(c, &mut again), ERROR);
        assert_eq!(fmi2SetFMUstate(c, copy), ERROR);
        let mut size = 0;
        assert_eq!(fmi2SerializedFMUstateSize(c, copy, &mut size), ERROR);
        fmi2FreeInstance(c);
        fmi2FreeInstance(c);
        assert_eq!(fmi2DoStep(c, 0.0, 1e-3, 1), ERROR);
        assert_eq!(fmi2Terminate(c), ERROR);
        let vr = f.vr("load.mass");
        let mut v = 0.0;
        assert_eq!(fmi2GetReal(c, &vr, 1, &mut v), ERROR);
        // a pointer never made here
        let mut other = 0u64;
        fmi2FreeInstance((&mut other as *mut u64).cast());
        assert_eq!(fmi2Reset((&mut other as *mut u64).cast()), ERROR);
    }
    // the library goes on: a new instance works
    let c = f.instantiate(&f.guid);
    start(c);
    assert!(run(c, &f, 0.1, 10, 1e-3).is_finite());
    unsafe { fmi2FreeInstance(c) };
}

/// The packager's check against the library of this build (cargo builds
/// the cdylib beside this test binary): it computes the packager's GUID
/// for every preset, and the archive is made.
#[test]
fn the_library_of_this_build_is_accepted() {
    let deps = std::env::current_exe().unwrap();
    let lib = deps
        .parent()
        .unwrap()
        .join(hydrocyl_fmu::package::LIBRARY_FILE);
    assert!(lib.is_file(), "{}", lib.display());
    for p in rig::PRESETS {
        let value = (p.json)();
        let text = serde_json::to_string_pretty(&value).unwrap();
        let ours = guid(&text, &Variables::of(&value).unwrap());
        assert_eq!(library_guid(&lib, &text), Ok(ours), "{}", p.name);
    }
    let value = rig::preset("leaney-moog").unwrap();
    let zip = hydrocyl_fmu::package::fmu_archive(&value, "leaney-moog", &lib).unwrap();
    assert!(zip.starts_with(b"PK"));
}

#[test]
fn resource_locations_are_file_uris_or_paths() {
    assert_eq!(
        resource_dir("file:///tmp/a%20b/resources").unwrap(),
        std::path::PathBuf::from("/tmp/a b/resources")
    );
    assert_eq!(
        resource_dir("file://localhost/x").unwrap(),
        std::path::PathBuf::from("/x")
    );
    assert_eq!(
        resource_dir("file:/x").unwrap(),
        std::path::PathBuf::from("/x")
    );
    assert!(resource_dir("file://server/x").is_err());
}
