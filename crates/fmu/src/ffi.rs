//! The FMI 2.0 Co-Simulation C API, written by hand over [`Slave`].
//!
//! Every exported function checks its pointers, runs inside
//! `catch_unwind` (a panic becomes `fmi2Error` and a logged message, never
//! an unwind into the host), and logs every rejected call through the
//! host's logger with the instance name. Error messages are always logged;
//! others only with logging on. Memory is Rust's own (the host's allocator
//! callbacks are not used: `canNotUseMemoryManagementFunctions`).
//!
//! The C types: `fmi2Component`/`fmi2ComponentEnvironment`/`fmi2FMUstate`
//! are `void*`, `fmi2ValueReference` `unsigned int`, `fmi2Real` `double`,
//! `fmi2Integer`/`fmi2Boolean`/`fmi2Status`/`fmi2Type` `int`,
//! `fmi2String` `const char*`.
#![allow(unsafe_code, non_snake_case, clippy::missing_safety_doc)]

use crate::model_description::{guid, rig_digest, variables_digest, DIGESTS};
use crate::slave::{Slave, Snapshot};
use crate::variables::Variables;
use std::collections::BTreeSet;
use std::ffi::{c_char, c_int, c_uint, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};
use std::sync::{Mutex, MutexGuard};

/// `fmi2Status`.
pub type Status = c_int;
/// `fmi2OK`.
pub const OK: Status = 0;
/// `fmi2Warning`.
pub const WARNING: Status = 1;
/// `fmi2Discard`.
pub const DISCARD: Status = 2;
/// `fmi2Error`.
pub const ERROR: Status = 3;
/// `fmi2Fatal`.
pub const FATAL: Status = 4;
/// `fmi2CoSimulation` (an `fmi2Type`).
pub const CO_SIMULATION: c_int = 1;
/// `fmi2LastSuccessfulTime` (an `fmi2StatusKind`).
pub const LAST_SUCCESSFUL_TIME: c_int = 2;

/// `fmi2CallbackLogger`: `void (*)(env, instanceName, status, category, message, ...)`.
pub type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char, ...);

/// `fmi2CallbackFunctions`.
#[repr(C)]
#[derive(Clone, Copy)]
pub struct CallbackFunctions {
    /// `logger`.
    pub logger: Option<Logger>,
    /// `allocateMemory` (unused).
    pub allocate_memory: Option<unsafe extern "C" fn(usize, usize) -> *mut c_void>,
    /// `freeMemory` (unused).
    pub free_memory: Option<unsafe extern "C" fn(*mut c_void)>,
    /// `stepFinished` (unused: no asynchronous steps).
    pub step_finished: Option<unsafe extern "C" fn(*mut c_void, Status)>,
    /// `componentEnvironment`, handed back to the logger.
    pub component_environment: *mut c_void,
}

/// One instance as the host holds it (`fmi2Component`).
struct Instance {
    name: CString,
    callbacks: CallbackFunctions,
    logging: bool,
    slave: Slave,
}

fn log_with(cb: &CallbackFunctions, name: &CStr, status: Status, message: &str) {
    let Some(logger) = cb.logger else { return };
    let category: &CStr = if status >= ERROR {
        c"logStatusError"
    } else {
        c"logAll"
    };
    // the message is the format string, `%` doubled: hosts that format it
    // (printf-style, as the standard says) and hosts that print it as is
    // (FMPy's default callbacks) both show it whole
    let msg = CString::new(message.replace('\0', " ").replace('%', "%%")).unwrap_or_default();
    unsafe {
        logger(
            cb.component_environment,
            name.as_ptr(),
            status,
            category.as_ptr(),
            msg.as_ptr(),
        )
    };
}

impl Instance {
    fn log(&self, status: Status, message: &str) {
        if status >= ERROR || self.logging {
            log_with(&self.callbacks, &self.name, status, message);
        }
    }
}

/// The addresses of the live instances (from `fmi2Instantiate` to
/// `fmi2FreeInstance`) and of the live FMU states (from `fmi2GetFMUstate` or
/// `fmi2DeSerializeFMUstate` to `fmi2FreeFMUstate`). An entry point given
/// a pointer that is not in its set (freed already, never made here) refuses
/// it (`fmi2Error`, nothing logged: there is no instance to log through)
/// instead of using or freeing it again.
static LIVE_INSTANCES: Mutex<BTreeSet<usize>> = Mutex::new(BTreeSet::new());
static LIVE_STATES: Mutex<BTreeSet<usize>> = Mutex::new(BTreeSet::new());

fn registry(set: &'static Mutex<BTreeSet<usize>>) -> MutexGuard<'static, BTreeSet<usize>> {
    // a panic never happens while the lock is held; a poisoned set is whole
    set.lock().unwrap_or_else(|e| e.into_inner())
}

/// Whether `c` is a live instance.
fn is_live(c: *mut c_void) -> bool {
    registry(&LIVE_INSTANCES).contains(&(c as usize))
}

/// Whether `s` is a live FMU state.
fn is_state(s: *mut c_void) -> bool {
    registry(&LIVE_STATES).contains(&(s as usize))
}

/// A new live FMU state.
fn new_state(snap: Snapshot) -> *mut c_void {
    let p: *mut c_void = Box::into_raw(Box::new(snap)).cast();
    registry(&LIVE_STATES).insert(p as usize);
    p
}

/// Frees a live FMU state; `false` (nothing done) for any other pointer.
unsafe fn free_state(s: *mut c_void) -> bool {
    let was = registry(&LIVE_STATES).remove(&(s as usize));
    if was {
        drop(unsafe { Box::from_raw(s.cast::<Snapshot>()) });
    }
    was
}

/// The live FMU state behind `s`, or why it is not one.
unsafe fn state<'a>(s: *mut c_void) -> Result<&'a mut Snapshot, String> {
    if s.is_null() {
        Err("null FMU state".into())
    } else if !is_state(s) {
        Err("not an FMU state of this FMU (freed already?)".into())
    } else {
        Ok(unsafe { &mut *s.cast::<Snapshot>() })
    }
}

/// Runs `f` on the instance behind `c`, turning an `Err` into a logged
/// `fmi2Error` and a panic into a logged `fmi2Error` that fails the instance.
unsafe fn with(
    c: *mut c_void,
    what: &str,
    f: impl FnOnce(&mut Instance) -> Result<Status, String>,
) -> Status {
    // not an instance (null, freed, never made here): nothing to log through
    if c.is_null() || !is_live(c) {
        return ERROR;
    }
    let inst = unsafe { &mut *(c as *mut Instance) };
    match catch_unwind(AssertUnwindSafe(|| f(inst))) {
        Ok(Ok(s)) => s,
        Ok(Err(msg)) => {
            inst.log(ERROR, &format!("{what}: {msg}"));
            ERROR
        }
        Err(panic) => {
            let why = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            inst.slave.fail();
            inst.log(ERROR, &format!("{what}: internal error (panic: {why})"));
            ERROR
        }
    }
}

/// The slice behind a C array, empty for `n == 0` whatever the pointer.
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Result<&'a [T], String> {
    if n == 0 {
        Ok(&[])
    } else if p.is_null() {
        Err("null array".into())
    } else {
        Ok(unsafe { std::slice::from_raw_parts(p, n) })
    }
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Result<&'a mut [T], String> {
    if n == 0 {
        Ok(&mut [])
    } else if p.is_null() {
        Err("null array".into())
    } else {
        Ok(unsafe { std::slice::from_raw_parts_mut(p, n) })
    }
}

unsafe fn string(p: *const c_char) -> Option<String> {
    (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

/// The folder of `fmuResourceLocation`: a `file:` URI (`file:///a/b`,
/// `file://localhost/a/b`, `file:/a/b`, percent-encoded) or a plain path.
pub fn resource_dir(location: &str) -> Result<PathBuf, String> {
    let Some(rest) = location.strip_prefix("file:") else {
        return Ok(PathBuf::from(location));
    };
    let path = match rest.strip_prefix("//") {
        Some(auth) => {
            let slash = auth.find('/').unwrap_or(auth.len());
            match &auth[..slash] {
                "" | "localhost" => &auth[slash..],
                host => {
                    return Err(format!(
                        "fmuResourceLocation `{location}`: remote host `{host}`"
                    ))
                }
            }
        }
        None => rest,
    };
    if !path.starts_with('/') {
        return Err(format!(
            "fmuResourceLocation `{location}` is not an absolute file URI"
        ));
    }
    let bytes: Vec<u8> = percent_encoding::percent_decode_str(path).collect();
    use std::os::unix::ffi::OsStringExt;
    Ok(PathBuf::from(std::ffi::OsString::from_vec(bytes)))
}

/// The value of attribute `name` of the first element of `xml` that has
/// it after `from` (the model description is ours: attributes in double
/// quotes, nothing escaped in those read here).
fn attribute<'a>(xml: &'a str, from: &str, name: &str) -> Option<&'a str> {
    let at = xml.find(from)?;
    let key = format!(" {name}=\"");
    let start = at + xml[at..].find(&key)? + key.len();
    let end = xml[start..].find('"')?;
    Some(&xml[start..start + end])
}

/// Why the GUID the host gives (the one in `modelDescription.xml`) is not
/// the one this library computes for `text` (the FMU's `resources/rig.json`
/// at `rig`) and the variables it makes of it (`made`: the variables, or
/// why it cannot make them). The GUID covers this crate's version, the
/// variable list and the rig's text; the model description beside the
/// `resources` folder names the version that packaged the FMU
/// (`generationTool`) and holds the digests of the rig's text and of the
/// variable list as packaged, which tell which of them differs.
fn why_guid_differs(rig: &Path, text: &str, made: Result<&Variables, &str>) -> String {
    let ours = env!("CARGO_PKG_VERSION");
    let rebuild = "rebuild with `cargo build -p hydrocyl-fmu -p hydrocyl-cli` and export the rig again (`hydrocyl fmu`)";
    let xml = rig
        .parent()
        .and_then(Path::parent)
        .and_then(|root| std::fs::read_to_string(root.join("modelDescription.xml")).ok());
    let xml = xml.as_deref().unwrap_or("");
    let version = attribute(xml, "<fmiModelDescription", "generationTool")
        .and_then(|t| t.strip_prefix("hydrocyl "));
    let digests = (
        attribute(xml, &format!("<{DIGESTS} "), "rig"),
        attribute(xml, &format!("<{DIGESTS} "), "variables"),
    );
    match (version, digests) {
        (Some(v), _) if v != ours => format!(
            "the FMU was packaged by hydrocyl {v} (modelDescription.xml), this library is hydrocyl {ours}: {rebuild}"
        ),
        (_, (Some(r), _)) if r != rig_digest(text) => format!(
            "the rig differs: resources/rig.json is not the rig this FMU was packaged with (edited after the export; the library is the same build as far as the rig can tell): export the edited rig again (`hydrocyl fmu`), or set its parameters through the FMU's variables{}",
            made.err().map(|e| format!("; the edited rig: {e}")).unwrap_or_default()
        ),
        (_, (Some(_), Some(vd))) => match made {
            Err(e) => format!(
                "the build differs: resources/rig.json is the rig packaged, but this library (another build than the one that packaged the FMU) cannot read it: {e}; {rebuild}"
            ),
            Ok(vars) if variables_digest(vars) != vd => format!(
                "the build differs: resources/rig.json is the rig packaged, but this library is another build than the one that packaged the FMU: it makes other variables of the rig (value references would reach the wrong parameters); {rebuild}"
            ),
            Ok(_) => "the rig and the variables are those packaged: the GUID given is not the one in modelDescription.xml".into(),
        },
        _ => format!(
            "resources/rig.json differs from the rig the FMU was packaged with (edited after the export?), or this library is another build than the one that packaged the FMU (hydrocyl {ours}; the model description holds no digests to tell which): the GUID covers both{}",
            made.err().map(|e| format!("; the rig: {e}")).unwrap_or_default()
        ),
    }
}

fn instantiate(guid_given: &str, location: Option<&str>) -> Result<Slave, String> {
    let location = location.ok_or("no fmuResourceLocation: the rig is in resources/rig.json")?;
    let path = resource_dir(location)?.join("rig.json");
    let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
    let slave = serde_json::from_str(&text)
        .map_err(|e| format!("not valid JSON: {e}"))
        .and_then(Slave::new);
    let expected = slave
        .as_ref()
        .map(|s| guid(&text, s.variables()))
        .map_err(String::as_str);
    if expected.as_deref() != Ok(guid_given) {
        let why = why_guid_differs(
            &path,
            &text,
            slave.as_ref().map(Slave::variables).map_err(String::as_str),
        );
        return Err(match expected {
            Ok(expected) => format!(
                "fmuGUID {guid_given} does not match this library and {} ({expected}): {why}",
                path.display()
            ),
            Err(_) => format!(
                "fmuGUID {guid_given}: this library cannot compute the GUID of {}: {why}",
                path.display()
            ),
        });
    }
    slave
}

/// The size of the buffer [`library_guid`] hands to [`hydrocyl_fmu_guid`].
const GUID_BUFFER: usize = 4096;

/// hydrocyl's own entry point (not FMI), for the packager: writes into
/// `out` (`size` bytes, NUL-terminated, truncated to fit) the GUID this
/// library computes for an FMU whose `resources/rig.json` holds the
/// NUL-terminated `rig_text`, and returns 0; when it cannot read the rig,
/// writes why and returns 1; -1 on a null pointer. `hydrocyl fmu` packages
/// a library only if its GUID is the packager's ([`library_guid`]).
#[no_mangle]
pub unsafe extern "C" fn hydrocyl_fmu_guid(
    rig_text: *const c_char,
    out: *mut c_char,
    size: usize,
) -> c_int {
    if rig_text.is_null() || out.is_null() || size == 0 {
        return -1;
    }
    let text = unsafe { CStr::from_ptr(rig_text) }
        .to_string_lossy()
        .into_owned();
    let result = catch_unwind(|| {
        let rig = serde_json::from_str(&text).map_err(|e| format!("not valid JSON: {e}"))?;
        Slave::new(rig).map(|s| guid(&text, s.variables()))
    })
    .unwrap_or_else(|_| Err("internal error (panic)".into()));
    let (code, msg) = match result {
        Ok(g) => (0, g),
        Err(e) => (1, e),
    };
    let bytes = msg.replace('\0', " ").into_bytes();
    let n = bytes.len().min(size - 1);
    unsafe {
        std::ptr::copy_nonoverlapping(bytes.as_ptr(), out.cast::<u8>(), n);
        *out.add(n) = 0;
    }
    code
}

/// The GUID the slave library at `library` computes for the rig `rig_text`
/// (through its [`hydrocyl_fmu_guid`]), or why there is none: the file
/// does not load as a library, has no `hydrocyl_fmu_guid` (a build older
/// than it), or cannot read the rig. The library stays loaded (unloading a
/// Rust library can leave its thread-local destructors dangling).
pub fn library_guid(library: &Path, rig_text: &str) -> Result<String, String> {
    use std::os::unix::ffi::OsStrExt;
    let one_line = |s: String| s.split_whitespace().collect::<Vec<_>>().join(" ");
    let path = CString::new(library.as_os_str().as_bytes())
        .map_err(|_| "its path holds a NUL byte".to_string())?;
    let text = CString::new(rig_text).map_err(|_| "the rig's text holds a NUL byte".to_string())?;
    let handle = unsafe { libc::dlopen(path.as_ptr(), libc::RTLD_NOW | libc::RTLD_LOCAL) };
    if handle.is_null() {
        let why = unsafe { string(libc::dlerror()) }.unwrap_or_default();
        return Err(one_line(format!("it does not load as a library: {why}")));
    }
    let sym = unsafe { libc::dlsym(handle, c"hydrocyl_fmu_guid".as_ptr()) };
    if sym.is_null() {
        return Err("it has no hydrocyl_fmu_guid: a build older than this hydrocyl's".to_string());
    }
    type GuidFn = unsafe extern "C" fn(*const c_char, *mut c_char, usize) -> c_int;
    let f: GuidFn = unsafe { std::mem::transmute::<*mut c_void, GuidFn>(sym) };
    let mut buf = vec![0 as c_char; GUID_BUFFER];
    let code = unsafe { f(text.as_ptr(), buf.as_mut_ptr(), buf.len()) };
    let msg = unsafe { string(buf.as_ptr()) }.unwrap_or_default();
    match code {
        0 => Ok(msg),
        _ => Err(one_line(format!("it cannot read this rig: {msg}"))),
    }
}

/// `fmi2GetTypesPlatform`.
#[no_mangle]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

/// `fmi2GetVersion`.
#[no_mangle]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// `fmi2Instantiate`: reads `resources/rig.json` under `fmuResourceLocation`,
/// checks the GUID, and returns a new independent instance (NULL on error,
/// logged).
#[no_mangle]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    fmu_guid: *const c_char,
    resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> *mut c_void {
    let result = catch_unwind(|| {
        let callbacks = if functions.is_null() {
            CallbackFunctions {
                logger: None,
                allocate_memory: None,
                free_memory: None,
                step_finished: None,
                component_environment: std::ptr::null_mut(),
            }
        } else {
            unsafe { *functions }
        };
        let name = unsafe { string(instance_name) }.unwrap_or_else(|| "hydrocyl".into());
        let name = CString::new(name).unwrap_or_default();
        let fail = |msg: String| {
            log_with(&callbacks, &name, ERROR, &format!("fmi2Instantiate: {msg}"));
            std::ptr::null_mut()
        };
        if fmu_type != CO_SIMULATION {
            return fail("only Co-Simulation (fmi2CoSimulation) is implemented".into());
        }
        let g = unsafe { string(fmu_guid) }.unwrap_or_default();
        let loc = unsafe { string(resource_location) };
        match instantiate(&g, loc.as_deref()) {
            Ok(slave) => {
                let c = Box::into_raw(Box::new(Instance {
                    name,
                    callbacks,
                    logging: logging_on != 0,
                    slave,
                })) as *mut c_void;
                registry(&LIVE_INSTANCES).insert(c as usize);
                c
            }
            Err(msg) => fail(msg),
        }
    });
    result.unwrap_or(std::ptr::null_mut())
}

/// `fmi2FreeInstance`: frees a live instance; any other pointer (freed
/// already, null, never made here) is ignored.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if registry(&LIVE_INSTANCES).remove(&(c as usize)) {
        let _ = catch_unwind(|| drop(unsafe { Box::from_raw(c as *mut Instance) }));
    }
}

/// `fmi2SetDebugLogging`: turns the non-error messages on or off.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    logging_on: c_int,
    _n: usize,
    _categories: *const *const c_char,
) -> Status {
    unsafe {
        with(c, "fmi2SetDebugLogging", |i| {
            i.logging = logging_on != 0;
            Ok(OK)
        })
    }
}

/// `fmi2SetupExperiment`: the start time (tolerance and stop time are
/// ignored: the tolerance is the parameter `solver.rtol`).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    _tolerance_defined: c_int,
    _tolerance: f64,
    start_time: f64,
    _stop_time_defined: c_int,
    _stop_time: f64,
) -> Status {
    unsafe {
        with(c, "fmi2SetupExperiment", |i| {
            i.slave.setup_experiment(start_time).map(|_| OK)
        })
    }
}

/// `fmi2EnterInitializationMode`.
#[no_mangle]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> Status {
    unsafe {
        with(c, "fmi2EnterInitializationMode", |i| {
            i.slave.enter_initialization().map(|_| OK)
        })
    }
}

/// `fmi2ExitInitializationMode`: checks the parameters set as a whole and
/// assembles the circuit.
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Status {
    unsafe {
        with(c, "fmi2ExitInitializationMode", |i| {
            i.slave.exit_initialization().map(|_| OK)
        })
    }
}

/// `fmi2Terminate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> Status {
    unsafe { with(c, "fmi2Terminate", |i| i.slave.terminate().map(|_| OK)) }
}

/// `fmi2Reset`: back to the state after `fmi2Instantiate`.
#[no_mangle]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> Status {
    unsafe {
        with(c, "fmi2Reset", |i| {
            i.slave.reset();
            Ok(OK)
        })
    }
}

/// Reads `nvr` values through `get`, one per value reference.
unsafe fn get_each<T>(
    c: *mut c_void,
    what: &str,
    vr: *const c_uint,
    nvr: usize,
    value: *mut T,
    get: impl Fn(&mut Slave, u32) -> Result<T, String>,
) -> Status {
    unsafe {
        with(c, what, |i| {
            let (vr, out) = (slice(vr, nvr)?, slice_mut(value, nvr)?);
            for (r, o) in vr.iter().zip(out) {
                *o = get(&mut i.slave, *r)?;
            }
            Ok(OK)
        })
    }
}

/// Writes `nvr` values through `set`, one per value reference; stops at the
/// first refused one.
unsafe fn set_each<T: Copy>(
    c: *mut c_void,
    what: &str,
    vr: *const c_uint,
    nvr: usize,
    value: *const T,
    set: impl Fn(&mut Slave, u32, T) -> Result<(), String>,
) -> Status {
    unsafe {
        with(c, what, |i| {
            for (r, v) in slice(vr, nvr)?.iter().zip(slice(value, nvr)?) {
                set(&mut i.slave, *r, *v)?;
            }
            Ok(OK)
        })
    }
}

/// `fmi2GetReal`.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetReal(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    value: *mut f64,
) -> Status {
    unsafe { get_each(c, "fmi2GetReal", vr, nvr, value, Slave::get_real) }
}

/// `fmi2SetReal`: the input, or a parameter (its value checked on its own;
/// a rejected value is `fmi2Error` with a message naming the parameter and
/// the rule; the rules relating parameters are checked at
/// `fmi2ExitInitializationMode`).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    value: *const f64,
) -> Status {
    unsafe { set_each(c, "fmi2SetReal", vr, nvr, value, Slave::set_real) }
}

/// `fmi2GetInteger` (`solver.method`).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetInteger(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    value: *mut c_int,
) -> Status {
    unsafe { get_each(c, "fmi2GetInteger", vr, nvr, value, |s, r| s.get_integer(r)) }
}

/// `fmi2SetInteger` (`solver.method`).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetInteger(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    value: *const c_int,
) -> Status {
    unsafe { set_each(c, "fmi2SetInteger", vr, nvr, value, Slave::set_integer) }
}

/// No Boolean or String variables: any value reference is unknown.
fn no_variables(kind: &str, nvr: usize) -> Result<Status, String> {
    if nvr == 0 {
        Ok(OK)
    } else {
        Err(format!("the FMU has no {kind} variables"))
    }
}

/// `fmi2GetBoolean` (no Boolean variables).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: *mut c_void,
    _vr: *const c_uint,
    nvr: usize,
    _value: *mut c_int,
) -> Status {
    unsafe { with(c, "fmi2GetBoolean", |_| no_variables("Boolean", nvr)) }
}

/// `fmi2SetBoolean` (no Boolean variables).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: *mut c_void,
    _vr: *const c_uint,
    nvr: usize,
    _value: *const c_int,
) -> Status {
    unsafe { with(c, "fmi2SetBoolean", |_| no_variables("Boolean", nvr)) }
}

/// `fmi2GetString` (no String variables).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetString(
    c: *mut c_void,
    _vr: *const c_uint,
    nvr: usize,
    _value: *mut *const c_char,
) -> Status {
    unsafe { with(c, "fmi2GetString", |_| no_variables("String", nvr)) }
}

/// `fmi2SetString` (no String variables).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetString(
    c: *mut c_void,
    _vr: *const c_uint,
    nvr: usize,
    _value: *const *const c_char,
) -> Status {
    unsafe { with(c, "fmi2SetString", |_| no_variables("String", nvr)) }
}

/// `fmi2SetRealInputDerivatives`: first-order derivatives of the input
/// (its slope over the next step).
#[no_mangle]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: *mut c_void,
    vr: *const c_uint,
    nvr: usize,
    order: *const c_int,
    value: *const f64,
) -> Status {
    unsafe {
        with(c, "fmi2SetRealInputDerivatives", |i| {
            let (vr, order, value) = (slice(vr, nvr)?, slice(order, nvr)?, slice(value, nvr)?);
            for k in 0..nvr {
                i.slave.set_input_derivative(vr[k], order[k], value[k])?;
            }
            Ok(OK)
        })
    }
}

/// `fmi2DoStep`: integrates the rig from `currentCommunicationPoint` over
/// `communicationStepSize`; a solver failure is `fmi2Error` with the time and
/// the state logged.
#[no_mangle]
pub unsafe extern "C" fn fmi2DoStep(
    c: *mut c_void,
    current: f64,
    step: f64,
    _no_set_prior_state: c_int,
) -> Status {
    unsafe {
        with(c, "fmi2DoStep", |i| {
            i.slave.do_step(current, step).map(|_| OK)
        })
    }
}

/// An unsupported optional function: `fmi2Error` with a message.
unsafe fn unsupported(c: *mut c_void, what: &str) -> Status {
    unsafe {
        with(c, what, |_| {
            Err("not supported by this FMU (see its capability flags)".into())
        })
    }
}

/// `fmi2GetRealOutputDerivatives` (not supported: `maxOutputDerivativeOrder` 0).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: *mut c_void,
    _vr: *const c_uint,
    _nvr: usize,
    _order: *const c_int,
    _value: *mut f64,
) -> Status {
    unsafe { unsupported(c, "fmi2GetRealOutputDerivatives") }
}

/// `fmi2CancelStep` (steps are synchronous).
#[no_mangle]
pub unsafe extern "C" fn fmi2CancelStep(c: *mut c_void) -> Status {
    unsafe { unsupported(c, "fmi2CancelStep") }
}

/// `fmi2GetFMUstate`: saves the instance's state into `*s` (a new state when
/// `*s` is null, else the one given, overwritten).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetFMUstate(c: *mut c_void, s: *mut *mut c_void) -> Status {
    unsafe {
        with(c, "fmi2GetFMUstate", |i| {
            if s.is_null() {
                return Err("fmi2GetFMUstate: null state pointer".into());
            }
            let snap = i.slave.get_state()?;
            if (*s).is_null() {
                *s = new_state(snap);
            } else {
                *state(*s)? = snap;
            }
            Ok(OK)
        })
    }
}

/// `fmi2SetFMUstate`: restores a saved state.
#[no_mangle]
pub unsafe extern "C" fn fmi2SetFMUstate(c: *mut c_void, s: *mut c_void) -> Status {
    unsafe {
        with(c, "fmi2SetFMUstate", |i| {
            i.slave.set_state(state(s)?).map(|_| OK)
        })
    }
}

/// `fmi2FreeFMUstate`: frees a saved state and nulls `*s`.
#[no_mangle]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: *mut c_void, s: *mut *mut c_void) -> Status {
    unsafe {
        with(c, "fmi2FreeFMUstate", |_| {
            if s.is_null() || (*s).is_null() {
                return Ok(OK);
            }
            if !free_state(*s) {
                return Err("not an FMU state of this FMU (freed already?)".into());
            }
            *s = std::ptr::null_mut();
            Ok(OK)
        })
    }
}

/// `fmi2SerializedFMUstateSize`: the length of a state's bytes.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: *mut c_void,
    s: *mut c_void,
    size: *mut usize,
) -> Status {
    unsafe {
        with(c, "fmi2SerializedFMUstateSize", |_| {
            if size.is_null() {
                return Err("null size pointer".into());
            }
            *size = state(s)?.serialize().len();
            Ok(OK)
        })
    }
}

/// `fmi2SerializeFMUstate`: a state's bytes into the host's buffer.
#[no_mangle]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: *mut c_void,
    s: *mut c_void,
    bytes: *mut c_char,
    size: usize,
) -> Status {
    unsafe {
        with(c, "fmi2SerializeFMUstate", |_| {
            if bytes.is_null() {
                return Err("null buffer".into());
            }
            let data = state(s)?.serialize();
            if data.len() > size {
                return Err(format!(
                    "buffer of {size} bytes, the state needs {}",
                    data.len()
                ));
            }
            std::ptr::copy_nonoverlapping(data.as_ptr(), bytes.cast::<u8>(), data.len());
            Ok(OK)
        })
    }
}

/// `fmi2DeSerializeFMUstate`: a new state from serialized bytes.
#[no_mangle]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: *mut c_void,
    bytes: *const c_char,
    size: usize,
    s: *mut *mut c_void,
) -> Status {
    unsafe {
        with(c, "fmi2DeSerializeFMUstate", |_| {
            if bytes.is_null() || s.is_null() {
                return Err("null buffer or state pointer".into());
            }
            let data = std::slice::from_raw_parts(bytes.cast::<u8>(), size);
            let snap = Snapshot::deserialize(data)?;
            // a live state given is replaced; any other pointer is output only
            free_state(*s);
            *s = new_state(snap);
            Ok(OK)
        })
    }
}

/// `fmi2GetDirectionalDerivative` (not supported).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: *mut c_void,
    _unknown: *const c_uint,
    _n_unknown: usize,
    _known: *const c_uint,
    _n_known: usize,
    _dv_known: *const f64,
    _dv_unknown: *mut f64,
) -> Status {
    unsafe { unsupported(c, "fmi2GetDirectionalDerivative") }
}

/// `fmi2GetStatus` (no asynchronous step: nothing to report).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut Status,
) -> Status {
    unsafe { with(c, "fmi2GetStatus", |_| Ok(DISCARD)) }
}

/// `fmi2GetRealStatus`: `fmi2LastSuccessfulTime` is the time reached.
#[no_mangle]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, kind: c_int, value: *mut f64) -> Status {
    unsafe {
        with(c, "fmi2GetRealStatus", |i| {
            if kind == LAST_SUCCESSFUL_TIME && !value.is_null() {
                *value = i.slave.time();
                Ok(OK)
            } else {
                Ok(DISCARD)
            }
        })
    }
}

/// `fmi2GetIntegerStatus` (nothing to report).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut c_int,
) -> Status {
    unsafe { with(c, "fmi2GetIntegerStatus", |_| Ok(DISCARD)) }
}

/// `fmi2GetBooleanStatus`: `fmi2Terminated` is false (the FMU never ends a run itself).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: *mut c_void,
    _kind: c_int,
    value: *mut c_int,
) -> Status {
    unsafe {
        with(c, "fmi2GetBooleanStatus", |_| {
            if !value.is_null() {
                *value = 0;
            }
            Ok(OK)
        })
    }
}

/// `fmi2GetStringStatus` (nothing to report).
#[no_mangle]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut *const c_char,
) -> Status {
    unsafe { with(c, "fmi2GetStringStatus", |_| Ok(DISCARD)) }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model_description::model_description;

    /// An unpacked FMU of leaney-moog: its `resources/rig.json` as packaged
    /// and, unless `tool` is None, a `modelDescription.xml` naming that
    /// generation tool (with the digests when `digests`); returns the
    /// folder, the resource URI and the GUID.
    fn unpacked(tool: Option<&str>, digests: bool) -> (tempfile::TempDir, String, String) {
        let dir = tempfile::tempdir().unwrap();
        let res = dir.path().join("resources");
        std::fs::create_dir(&res).unwrap();
        let rig = hydrocyl_system::rig::preset("leaney-moog").unwrap();
        let text = serde_json::to_string_pretty(&rig).unwrap();
        std::fs::write(res.join("rig.json"), &text).unwrap();
        let vars = Variables::of(&rig).unwrap();
        let g = guid(&text, &vars);
        if let Some(tool) = tool {
            let mut xml = model_description(&vars, "leaney-moog", "a rig", &text)
                .replace(&format!("hydrocyl {}", env!("CARGO_PKG_VERSION")), tool);
            if !digests {
                let (a, b) = (
                    xml.find("  <VendorAnnotations>").unwrap(),
                    xml.find("  <ModelVariables>").unwrap(),
                );
                xml.replace_range(a..b, "");
            }
            std::fs::write(dir.path().join("modelDescription.xml"), xml).unwrap();
        }
        let uri = format!("file://{}", res.display());
        (dir, uri, g)
    }

    fn edit_rig(dir: &tempfile::TempDir) {
        let path = dir.path().join("resources").join("rig.json");
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::write(&path, text.replace("100.0", "50.0")).unwrap();
    }

    #[test]
    fn an_edited_rig_file_is_refused_as_such() {
        let ours = format!("hydrocyl {}", env!("CARGO_PKG_VERSION"));
        let (dir, uri, g) = unpacked(Some(&ours), true);
        assert!(instantiate(&g, Some(&uri)).is_ok());
        edit_rig(&dir);
        let e = instantiate(&g, Some(&uri)).err().unwrap();
        assert!(
            e.contains(
                "the rig differs: resources/rig.json is not the rig this FMU was packaged with"
            ),
            "{e}"
        );
        assert!(
            !e.contains("version") && !e.contains("build differs"),
            "{e}"
        );
    }

    /// The same rig, a library that makes other variables of it (another
    /// build): the message says the build differs, not the rig.
    #[test]
    fn another_build_is_named() {
        let ours = format!("hydrocyl {}", env!("CARGO_PKG_VERSION"));
        let (dir, uri, g) = unpacked(Some(&ours), true);
        // the packager's variables had one more parameter than this library's
        let md = dir.path().join("modelDescription.xml");
        let xml = std::fs::read_to_string(&md).unwrap();
        let vd = attribute(&xml, "<Digests ", "variables")
            .unwrap()
            .to_string();
        std::fs::write(
            &md,
            xml.replace(&vd, "{00000000-0000-0000-0000-000000000002}"),
        )
        .unwrap();
        let e = instantiate("{00000000-0000-0000-0000-000000000003}", Some(&uri))
            .err()
            .unwrap();
        assert!(
            e.contains("the build differs")
                && e.contains("cargo build -p hydrocyl-fmu -p hydrocyl-cli"),
            "{e}"
        );
        assert!(!e.contains("rig differs"), "{e}");
        // the GUID itself still opens the FMU
        assert!(instantiate(&g, Some(&uri)).is_ok());
    }

    #[test]
    fn another_version_is_named() {
        let (_dir, uri, _) = unpacked(Some("hydrocyl 0.0.0-old"), true);
        // the GUID in such an FMU is that version's
        let e = instantiate("{00000000-0000-0000-0000-000000000001}", Some(&uri))
            .err()
            .unwrap();
        assert!(
            e.contains("packaged by hydrocyl 0.0.0-old")
                && e.contains(&format!(
                    "this library is hydrocyl {}",
                    env!("CARGO_PKG_VERSION")
                )),
            "{e}"
        );
    }

    #[test]
    fn without_digests_both_causes_are_named() {
        let ours = format!("hydrocyl {}", env!("CARGO_PKG_VERSION"));
        for tool in [None, Some(ours.as_str())] {
            let (dir, uri, g) = unpacked(tool, false);
            edit_rig(&dir);
            let e = instantiate(&g, Some(&uri)).err().unwrap();
            assert!(
                e.contains("differs from the rig the FMU was packaged with")
                    && e.contains("another build"),
                "{e}"
            );
        }
    }

    /// The packager's check of a library: a file that does not load, and a
    /// library without `hydrocyl_fmu_guid` (a proc-macro library of this
    /// build's dependencies, beside the test binary), are named as such.
    #[test]
    fn a_library_without_the_guid_function_is_named() {
        let dir = tempfile::tempdir().unwrap();
        let fake = dir.path().join("fake.so");
        std::fs::write(&fake, b"\x7fELF not a library fmi2DoStep").unwrap();
        let e = library_guid(&fake, "{}").unwrap_err();
        assert!(
            e.starts_with("it does not load as a library") && !e.contains('\n'),
            "{e}"
        );
        let deps = std::env::current_exe()
            .unwrap()
            .parent()
            .unwrap()
            .to_path_buf();
        let other = std::fs::read_dir(&deps)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .find(|p| {
                let n = p.file_name().unwrap().to_string_lossy();
                n.starts_with("libthiserror_impl-") && n.ends_with(".so")
            })
            .expect("thiserror's proc-macro library beside the test binary");
        let e = library_guid(&other, "{}").unwrap_err();
        assert!(e.contains("no hydrocyl_fmu_guid"), "{e}");
    }

    /// The library's own entry point: the GUID of a rig, or why there is none.
    #[test]
    fn the_guid_entry_point_gives_the_guid_or_why_not() {
        let rig = hydrocyl_system::rig::preset("leaney-moog").unwrap();
        let text = serde_json::to_string_pretty(&rig).unwrap();
        let call = |t: &str, size: usize| {
            let t = CString::new(t).unwrap();
            let mut buf = vec![0 as c_char; size];
            let code = unsafe { hydrocyl_fmu_guid(t.as_ptr(), buf.as_mut_ptr(), size) };
            (code, unsafe { string(buf.as_ptr()) }.unwrap())
        };
        let (code, g) = call(&text, GUID_BUFFER);
        assert_eq!((code, g), (0, guid(&text, &Variables::of(&rig).unwrap())));
        let (code, e) = call("{\"kind\": 3}", GUID_BUFFER);
        assert!(code == 1 && e.contains("kind"), "{e}");
        let (code, e) = call("not json", 8);
        assert!(code == 1 && e.len() == 7, "{e}");
    }
}
