//! The fmi2* C exports: every function of FMI 2.0 Co-Simulation (importers such as fmpy load
//! them all by name). Each one turns C arguments into slices, calls the instance inside
//! `catch_unwind` (a panic must not cross the C boundary) and logs a refusal's reason.
//! The C types are declared here by hand (fmi2TypesPlatform.h, fmi2FunctionTypes.h).
//!
//! Safety of every export: the FMI 2.0 contract (a component from fmi2Instantiate, arrays of
//! the lengths given, NUL-terminated strings); NULL pointers are refused.
#![allow(clippy::missing_safety_doc)]

use std::ffi::{CStr, CString, c_char, c_int, c_uint, c_void};
use std::panic::{AssertUnwindSafe, catch_unwind};

use crate::instance::{Instance, Mode, SERIALIZED_SIZE, Snapshot};
use crate::model::{LOG_CATEGORIES, guid};

type Status = c_int;
const OK: Status = 0;
const DISCARD: Status = 2;
const ERROR: Status = 3;
const FATAL: Status = 4;
const CO_SIMULATION: c_int = 1;
const LAST_SUCCESSFUL_TIME: c_int = 2;

type Logger =
    unsafe extern "C" fn(*mut c_void, *const c_char, Status, *const c_char, *const c_char, ...);

#[repr(C)]
pub struct CallbackFunctions {
    logger: Option<Logger>,
    allocate_memory: *const c_void,
    free_memory: *const c_void,
    step_finished: *const c_void,
    component_environment: *mut c_void,
}

/// What fmi2Component points to.
struct Component {
    instance: Instance,
    name: CString,
    logger: Option<Logger>,
    environment: *mut c_void,
    /// Log categories switched on, in the order of LOG_CATEGORIES (errors always).
    logging: [bool; LOG_CATEGORIES.len()],
}

impl Component {
    fn log(&self, status: Status, message: &str) {
        let category = if status >= ERROR { 0 } else { 1 };
        let (Some(logger), true) = (self.logger, self.logging[category]) else {
            return;
        };
        let text = CString::new(message.replace('\0', " ")).expect("no NUL");
        let category = CString::new(LOG_CATEGORIES[category].0).expect("no NUL");
        // "%s": the message is passed as an argument, never read as a printf format.
        unsafe {
            logger(
                self.environment,
                self.name.as_ptr(),
                status,
                category.as_ptr(),
                c"%s".as_ptr(),
                text.as_ptr(),
            )
        }
    }
}

/// Runs `f` on the component behind `c`; a refusal is logged and returned as fmi2Error, a
/// panic as fmi2Fatal (the instance is then in an unknown state).
fn call(c: *mut c_void, f: impl FnOnce(&mut Component) -> Result<Status, String>) -> Status {
    if c.is_null() {
        return ERROR;
    }
    let component = unsafe { &mut *(c as *mut Component) };
    match catch_unwind(AssertUnwindSafe(|| f(component))) {
        Ok(Ok(status)) => status,
        Ok(Err(message)) => {
            component.log(ERROR, &message);
            ERROR
        }
        Err(_) => {
            component.instance.s.mode = Mode::Error;
            component.log(FATAL, "internal error (panic) in the Flywheel FMU");
            FATAL
        }
    }
}

fn ok(r: Result<(), String>) -> Result<Status, String> {
    r.map(|()| OK)
}

/// A C array as a slice (NULL with n = 0 is an empty slice).
unsafe fn slice<'a, T>(p: *const T, n: usize) -> Result<&'a [T], String> {
    match (p.is_null(), n) {
        (_, 0) => Ok(&[]),
        (true, _) => Err("NULL array with a non-zero length".into()),
        (false, _) => Ok(unsafe { std::slice::from_raw_parts(p, n) }),
    }
}

unsafe fn slice_mut<'a, T>(p: *mut T, n: usize) -> Result<&'a mut [T], String> {
    match (p.is_null(), n) {
        (_, 0) => Ok(&mut []),
        (true, _) => Err("NULL array with a non-zero length".into()),
        (false, _) => Ok(unsafe { std::slice::from_raw_parts_mut(p, n) }),
    }
}

unsafe fn string(p: *const c_char) -> Option<String> {
    (!p.is_null()).then(|| unsafe { CStr::from_ptr(p) }.to_string_lossy().into_owned())
}

/// fmi2TypesPlatform and fmi2Version of the standard's headers.
const TYPES_PLATFORM: &CStr = c"default";
const FMI_VERSION: &CStr = c"2.0";

#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    TYPES_PLATFORM.as_ptr()
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    FMI_VERSION.as_ptr()
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instance_name: *const c_char,
    fmu_type: c_int,
    fmu_guid: *const c_char,
    _resource_location: *const c_char,
    functions: *const CallbackFunctions,
    _visible: c_int,
    logging_on: c_int,
) -> *mut c_void {
    let made = catch_unwind(|| {
        let name = unsafe { string(instance_name) }.unwrap_or_default();
        let (logger, environment) = match unsafe { functions.as_ref() } {
            Some(f) => (f.logger, f.component_environment),
            None => (None, std::ptr::null_mut()),
        };
        let component = Component {
            instance: Instance::default(),
            name: CString::new(name.replace('\0', " ")).expect("no NUL"),
            logger,
            environment,
            logging: [true, logging_on != 0],
        };
        let (expected, given) = (guid(), unsafe { string(fmu_guid) }.unwrap_or_default());
        let refusal = if fmu_type != CO_SIMULATION {
            Some(format!(
                "fmuType {fmu_type} refused: Flywheel is a Co-Simulation FMU only"
            ))
        } else if given != expected {
            Some(format!(
                "GUID \"{given}\" does not match this binary's {expected}: \
                 the binary and modelDescription.xml come from different builds"
            ))
        } else {
            None
        };
        match refusal {
            Some(message) => {
                component.log(ERROR, &message);
                std::ptr::null_mut()
            }
            None => Box::into_raw(Box::new(component)) as *mut c_void,
        }
    });
    made.unwrap_or(std::ptr::null_mut())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: *mut c_void) {
    if !c.is_null() {
        let _ = catch_unwind(|| drop(unsafe { Box::from_raw(c as *mut Component) }));
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: *mut c_void,
    on: c_int,
    n: usize,
    categories: *const *const c_char,
) -> Status {
    call(c, |comp| {
        let names = unsafe { slice(categories, n) }?;
        let mut chosen = Vec::new();
        for p in names {
            let name = unsafe { string(*p) }.unwrap_or_default();
            let i = LOG_CATEGORIES
                .iter()
                .position(|(c, _)| *c == name)
                .ok_or(format!("unknown log category \"{name}\""))?;
            chosen.push(i);
        }
        if chosen.is_empty() {
            chosen.extend(0..LOG_CATEGORIES.len());
        }
        for i in chosen {
            comp.logging[i] = on != 0 || i == 0;
        }
        Ok(OK)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: *mut c_void,
    _tol_defined: c_int,
    _tol: f64,
    start: f64,
    _stop_defined: c_int,
    _stop: f64,
) -> Status {
    call(c, |comp| ok(comp.instance.setup_experiment(start)))
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: *mut c_void) -> Status {
    call(c, |comp| ok(comp.instance.enter_initialization_mode()))
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: *mut c_void) -> Status {
    call(c, |comp| ok(comp.instance.exit_initialization_mode()))
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: *mut c_void) -> Status {
    call(c, |comp| ok(comp.instance.terminate()))
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: *mut c_void) -> Status {
    call(c, |comp| {
        comp.instance.reset();
        Ok(OK)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    value: *mut f64,
) -> Status {
    call(c, |comp| {
        ok(comp
            .instance
            .get_real(unsafe { slice(vr, n) }?, unsafe { slice_mut(value, n) }?))
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    value: *const f64,
) -> Status {
    call(c, |comp| {
        ok(comp
            .instance
            .set_real(unsafe { slice(vr, n) }?, unsafe { slice(value, n) }?))
    })
}

/// Integer, Boolean and String calls: the model has no such variables.
fn none_of(kind: &str, c: *mut c_void, vr: *const c_uint, n: usize) -> Status {
    call(c, |_| match unsafe { slice(vr, n) }?.first() {
        Some(vr) => Err(format!(
            "unknown value reference {vr} for type {kind}: the model has no {kind} variables"
        )),
        None => Ok(OK),
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    _value: *mut c_int,
) -> Status {
    none_of("Integer", c, vr, n)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    _value: *const c_int,
) -> Status {
    none_of("Integer", c, vr, n)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    _value: *mut c_int,
) -> Status {
    none_of("Boolean", c, vr, n)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    _value: *const c_int,
) -> Status {
    none_of("Boolean", c, vr, n)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    _value: *mut *const c_char,
) -> Status {
    none_of("String", c, vr, n)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    _value: *const *const c_char,
) -> Status {
    none_of("String", c, vr, n)
}

// ---- FMU state: a boxed Snapshot, or its bytes (instance::Snapshot::to_bytes) ----

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(c: *mut c_void, state: *mut *mut c_void) -> Status {
    call(c, |comp| {
        let state = unsafe { state.as_mut() }.ok_or("fmi2GetFMUstate: NULL pointer")?;
        let snapshot = comp.instance.snapshot();
        match unsafe { (*state as *mut Snapshot).as_mut() } {
            Some(old) => *old = snapshot,
            None => *state = Box::into_raw(Box::new(snapshot)) as *mut c_void,
        }
        Ok(OK)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: *mut c_void, state: *mut c_void) -> Status {
    call(c, |comp| {
        let snapshot =
            unsafe { (state as *const Snapshot).as_ref() }.ok_or("fmi2SetFMUstate: NULL state")?;
        ok(comp.instance.restore(snapshot))
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(c: *mut c_void, state: *mut *mut c_void) -> Status {
    call(c, |_| {
        if let Some(p) = unsafe { state.as_mut() }.filter(|p| !p.is_null()) {
            drop(unsafe { Box::from_raw(*p as *mut Snapshot) });
            *p = std::ptr::null_mut();
        }
        Ok(OK)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: *mut c_void,
    _state: *mut c_void,
    size: *mut usize,
) -> Status {
    call(c, |_| {
        *unsafe { size.as_mut() }.ok_or("fmi2SerializedFMUstateSize: NULL size")? = SERIALIZED_SIZE;
        Ok(OK)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: *mut c_void,
    state: *mut c_void,
    bytes: *mut c_char,
    size: usize,
) -> Status {
    call(c, |_| {
        let snapshot = unsafe { (state as *const Snapshot).as_ref() }
            .ok_or("fmi2SerializeFMUstate: NULL state")?;
        let out = unsafe { slice_mut(bytes as *mut u8, size) }?;
        if size < SERIALIZED_SIZE {
            return Err(format!(
                "fmi2SerializeFMUstate: {size} bytes given, {SERIALIZED_SIZE} needed"
            ));
        }
        out[..SERIALIZED_SIZE].copy_from_slice(&snapshot.to_bytes());
        Ok(OK)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: *mut c_void,
    bytes: *const c_char,
    size: usize,
    state: *mut *mut c_void,
) -> Status {
    call(c, |_| {
        let snapshot = Snapshot::from_bytes(unsafe { slice(bytes as *const u8, size) }?)?;
        let state = unsafe { state.as_mut() }.ok_or("fmi2DeSerializeFMUstate: NULL pointer")?;
        *state = Box::into_raw(Box::new(snapshot)) as *mut c_void;
        Ok(OK)
    })
}

// ---- Capabilities declared false ----

fn unsupported(c: *mut c_void, what: &str) -> Status {
    call(c, |_| {
        Err(format!(
            "{what} is not supported (see the model description's capabilities)"
        ))
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: *mut c_void,
    _u: *const c_uint,
    _nu: usize,
    _k: *const c_uint,
    _nk: usize,
    _dk: *const f64,
    _du: *mut f64,
) -> Status {
    unsupported(c, "fmi2GetDirectionalDerivative")
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    order: *const c_int,
    value: *const f64,
) -> Status {
    call(c, |comp| {
        let (vr, order, value) = unsafe { (slice(vr, n)?, slice(order, n)?, slice(value, n)?) };
        ok(comp.instance.set_input_derivatives(vr, order, value))
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: *mut c_void) -> Status {
    unsupported(c, "fmi2CancelStep (steps are never asynchronous)")
}

// ---- Co-simulation ----

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: *mut c_void,
    vr: *const c_uint,
    n: usize,
    order: *const c_int,
    value: *mut f64,
) -> Status {
    call(c, |comp| {
        let (vr, order, value) = unsafe { (slice(vr, n)?, slice(order, n)?, slice_mut(value, n)?) };
        ok(comp.instance.get_output_derivatives(vr, order, value))
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: *mut c_void,
    current: f64,
    h: f64,
    _no_set_prior: c_int,
) -> Status {
    call(c, |comp| ok(comp.instance.do_step(current, h)))
}

/// Steps are synchronous: only fmi2LastSuccessfulTime is available.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(c: *mut c_void, kind: c_int, value: *mut f64) -> Status {
    call(c, |comp| {
        let value = unsafe { value.as_mut() }.ok_or("fmi2GetRealStatus: NULL value")?;
        if kind != LAST_SUCCESSFUL_TIME {
            return Ok(DISCARD);
        }
        *value = comp.instance.time();
        Ok(OK)
    })
}

fn no_status(c: *mut c_void) -> Status {
    call(c, |_| Ok(DISCARD))
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut Status,
) -> Status {
    no_status(c)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut c_int,
) -> Status {
    no_status(c)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut c_int,
) -> Status {
    no_status(c)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: *mut c_void,
    _kind: c_int,
    _value: *mut *const c_char,
) -> Status {
    no_status(c)
}
