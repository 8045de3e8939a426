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

use crate::instantiate::instantiate;
pub use crate::instantiate::{hydrocyl_fmu_guid, library_guid, resource_dir};
use crate::slave::{Slave, Snapshot};
use std::collections::BTreeSet;
use std::ffi::{c_char, c_int, c_uint, c_void, CStr, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
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
    /// Logs `message` through the importer's logger: warnings and errors
    /// always, anything else only with logging on (`fmi2Instantiate`'s
    /// `loggingOn`, `fmi2SetDebugLogging`).
    fn log(&self, status: Status, message: &str) {
        if status >= WARNING || self.logging {
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

pub(crate) unsafe fn string(p: *const c_char) -> Option<String> {
    (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
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
/// assembles the circuit; `fmi2Warning`, each warning logged, where a
/// parameter is far outside what real rigs have (a unit slip).
#[no_mangle]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Status {
    unsafe {
        with(c, "fmi2ExitInitializationMode", |i| {
            i.slave.exit_initialization().map(|warnings| {
                for w in &warnings {
                    i.log(WARNING, &format!("fmi2ExitInitializationMode: {w}"));
                }
                if warnings.is_empty() {
                    OK
                } else {
                    WARNING
                }
            })
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
