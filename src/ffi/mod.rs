//! The `fmi2*` C exports on fmi-sys types: each a few lines that unpack C arguments and call
//! the instance through [`guard::guard`]. Every function of FMI 2.0 Co-Simulation is
//! exported (importers such as fmpy load all of them by name), and every capability the
//! model description declares is implemented.
#![allow(non_snake_case)]
#![allow(clippy::missing_safety_doc)]

pub mod fmu_state;
pub mod guard;
pub mod logger;

use crate::contract::{GUID, MODEL_IDENTIFIER};
use crate::instance::fmu_state::{deserialize, serialize};
use crate::instance::{FmiError, FmiResult, Instance, state::allowed};
use fmi_sys::fmi2::*;
use guard::{Component, guard, slice, slice_mut};
use logger::Logger;
use std::ffi::{CStr, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// A C string argument as &str (None for NULL or invalid UTF-8).
unsafe fn text<'a>(s: fmi2String) -> Option<&'a str> {
    if s.is_null() {
        None
    } else {
        // SAFETY: a non-null fmi2String is a NUL-terminated string owned by the importer.
        unsafe { CStr::from_ptr(s) }.to_str().ok()
    }
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetTypesPlatform() -> *const c_char {
    c"default".as_ptr()
}

#[unsafe(no_mangle)]
pub extern "C" fn fmi2GetVersion() -> *const c_char {
    c"2.0".as_ptr()
}

/// Reasons fmi2Instantiate refuses, checked before anything is allocated.
unsafe fn check_instantiate(fmuType: fmi2Type, fmuGUID: fmi2String) -> FmiResult {
    if fmuType != fmi2Type_fmi2CoSimulation {
        return Err(FmiError::error(format!(
            "{MODEL_IDENTIFIER} is a Co-Simulation FMU only (fmuType = {fmuType} requested)"
        )));
    }
    // SAFETY: the importer's string argument.
    match unsafe { text(fmuGUID) } {
        Some(guid) if guid == GUID => Ok(()),
        other => Err(FmiError::error(format!(
            "GUID {other:?} does not match this binary's {GUID}: the model description and the binary are from different builds"
        ))),
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Instantiate(
    instanceName: fmi2String,
    fmuType: fmi2Type,
    fmuGUID: fmi2String,
    _fmuResourceLocation: fmi2String,
    functions: *const fmi2CallbackFunctions,
    _visible: fmi2Boolean,
    loggingOn: fmi2Boolean,
) -> fmi2Component {
    catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: NULL is tolerated; otherwise the importer's callback table.
        let (callback, environment) = match unsafe { functions.as_ref() } {
            Some(f) => (f.logger, f.componentEnvironment),
            None => (None, std::ptr::null_mut()),
        };
        // SAFETY: the importer's string argument.
        let name = unsafe { text(instanceName) }.unwrap_or("");
        let logger = Logger::new(callback, environment, name);
        if name.is_empty() {
            logger.log(
                crate::instance::Status::Error,
                "logStatusError",
                "fmi2Instantiate: instanceName is missing or empty",
            );
            return std::ptr::null_mut();
        }
        // SAFETY: the importer's arguments.
        if let Err(e) = unsafe { check_instantiate(fmuType, fmuGUID) } {
            logger.log(
                e.status,
                "logStatusError",
                &format!("fmi2Instantiate: {}", e.message),
            );
            return std::ptr::null_mut();
        }
        let component = Box::new(Component {
            instance: Instance::new(loggingOn != 0),
            logger,
        });
        Box::into_raw(component) as fmi2Component
    }))
    .unwrap_or(std::ptr::null_mut())
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeInstance(c: fmi2Component) {
    if !c.is_null() {
        // SAFETY: c came from fmi2Instantiate's Box::into_raw and is freed once.
        let _ = catch_unwind(AssertUnwindSafe(|| {
            drop(unsafe { Box::from_raw(c as *mut Component) })
        }));
    }
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetDebugLogging(
    c: fmi2Component,
    loggingOn: fmi2Boolean,
    nCategories: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    guard(c, "fmi2SetDebugLogging", allowed::SET_DEBUG_LOGGING, |i| {
        // SAFETY: the importer's array of nCategories strings.
        let names = unsafe { slice(categories, nCategories, "categories") }?;
        let names: Vec<String> = names
            .iter()
            .map(|&s| unsafe { text(s) }.unwrap_or("<NULL>").to_string())
            .collect();
        i.set_debug_logging(loggingOn != 0, &names)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetupExperiment(
    c: fmi2Component,
    toleranceDefined: fmi2Boolean,
    tolerance: fmi2Real,
    startTime: fmi2Real,
    _stopTimeDefined: fmi2Boolean,
    _stopTime: fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2SetupExperiment", allowed::SETUP_EXPERIMENT, |i| {
        i.setup_experiment((toleranceDefined != 0).then_some(tolerance), startTime)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2EnterInitializationMode(c: fmi2Component) -> fmi2Status {
    guard(
        c,
        "fmi2EnterInitializationMode",
        allowed::ENTER_INITIALIZATION_MODE,
        Instance::enter_initialization_mode,
    )
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2ExitInitializationMode(c: fmi2Component) -> fmi2Status {
    guard(
        c,
        "fmi2ExitInitializationMode",
        allowed::EXIT_INITIALIZATION_MODE,
        Instance::exit_initialization_mode,
    )
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Terminate(c: fmi2Component) -> fmi2Status {
    guard(c, "fmi2Terminate", allowed::TERMINATE, Instance::terminate)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2Reset(c: fmi2Component) -> fmi2Status {
    guard(c, "fmi2Reset", allowed::RESET, Instance::reset)
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2GetReal", allowed::GET, |i| {
        // SAFETY: the importer's arrays of nvr elements.
        let (vr, out) = unsafe { (slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?) };
        i.get_real(vr, out)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    guard(c, "fmi2GetInteger", allowed::GET, |i| {
        // SAFETY: the importer's arrays of nvr elements.
        let (vr, out) = unsafe { (slice(vr, nvr, "vr")?, slice_mut(value, nvr, "value")?) };
        i.get_integer(vr, out)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    _value: *mut fmi2Boolean,
) -> fmi2Status {
    guard(c, "fmi2GetBoolean", allowed::GET, |_| {
        // SAFETY: the importer's array of nvr elements.
        Instance::no_variables_of("Boolean", unsafe { slice(vr, nvr, "vr")? })
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    _value: *mut fmi2String,
) -> fmi2Status {
    guard(c, "fmi2GetString", allowed::GET, |_| {
        // SAFETY: the importer's array of nvr elements.
        Instance::no_variables_of("String", unsafe { slice(vr, nvr, "vr")? })
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetReal(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2SetReal", allowed::SET, |i| {
        // SAFETY: the importer's arrays of nvr elements.
        let (vr, values) = unsafe { (slice(vr, nvr, "vr")?, slice(value, nvr, "value")?) };
        i.set_real(vr, values)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetInteger(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    guard(c, "fmi2SetInteger", allowed::SET, |i| {
        // SAFETY: the importer's arrays of nvr elements.
        let (vr, values) = unsafe { (slice(vr, nvr, "vr")?, slice(value, nvr, "value")?) };
        i.set_integer(vr, values)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetBoolean(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    _value: *const fmi2Boolean,
) -> fmi2Status {
    guard(c, "fmi2SetBoolean", allowed::SET, |_| {
        // SAFETY: the importer's array of nvr elements.
        Instance::no_variables_of("Boolean", unsafe { slice(vr, nvr, "vr")? })
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetString(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    _value: *const fmi2String,
) -> fmi2Status {
    guard(c, "fmi2SetString", allowed::SET, |_| {
        // SAFETY: the importer's array of nvr elements.
        Instance::no_variables_of("String", unsafe { slice(vr, nvr, "vr")? })
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DoStep(
    c: fmi2Component,
    currentCommunicationPoint: fmi2Real,
    communicationStepSize: fmi2Real,
    _noSetFMUStatePriorToCurrentPoint: fmi2Boolean,
) -> fmi2Status {
    guard(c, "fmi2DoStep", allowed::DO_STEP, |i| {
        i.do_step(currentCommunicationPoint, communicationStepSize)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2CancelStep(c: fmi2Component) -> fmi2Status {
    guard(c, "fmi2CancelStep", allowed::CANCEL_STEP, |_| Ok(()))
}

/// A status kind this FMU has no value for: fmi2Discard, as the standard asks.
fn unavailable(kind: fmi2StatusKind) -> FmiResult {
    Err(FmiError::discard(format!(
        "status kind {kind} is not available: fmi2DoStep never returns fmi2Pending"
    )))
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    _value: *mut fmi2Status,
) -> fmi2Status {
    guard(c, "fmi2GetStatus", allowed::GET_STATUS, |_| unavailable(s))
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2GetRealStatus", allowed::GET_STATUS, |i| {
        if s != fmi2StatusKind_fmi2LastSuccessfulTime {
            return unavailable(s);
        }
        // SAFETY: the importer's pointer to one value.
        unsafe { slice_mut(value, 1, "value") }?[0] = i.last_successful_time();
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetIntegerStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    _value: *mut fmi2Integer,
) -> fmi2Status {
    guard(c, "fmi2GetIntegerStatus", allowed::GET_STATUS, |_| {
        unavailable(s)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetBooleanStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    guard(c, "fmi2GetBooleanStatus", allowed::GET_STATUS, |_| {
        if s != fmi2StatusKind_fmi2Terminated {
            return unavailable(s);
        }
        // The slave never asks the master to end the simulation.
        // SAFETY: the importer's pointer to one value.
        unsafe { slice_mut(value, 1, "value") }?[0] = 0;
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetStringStatus(
    c: fmi2Component,
    s: fmi2StatusKind,
    _value: *mut fmi2String,
) -> fmi2Status {
    guard(c, "fmi2GetStringStatus", allowed::GET_STATUS, |_| {
        unavailable(s)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetFMUstate(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    guard(c, "fmi2GetFMUstate", allowed::FMU_STATE, |i| {
        // SAFETY: the importer's slot for a state.
        unsafe { fmu_state::store(state, i.snapshot()) }
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetFMUstate(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    guard(c, "fmi2SetFMUstate", allowed::FMU_STATE, |i| {
        // SAFETY: a state fmi2GetFMUstate or fmi2DeSerializeFMUstate returned.
        let saved = unsafe { fmu_state::get(state) }?;
        i.restore(&saved.instance);
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2FreeFMUstate(
    c: fmi2Component,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    // SAFETY: the importer's slot holding one of our states, or NULL.
    guard(c, "fmi2FreeFMUstate", allowed::FMU_STATE, |_| unsafe {
        fmu_state::free(state)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializedFMUstateSize(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    guard(c, "fmi2SerializedFMUstateSize", allowed::FMU_STATE, |_| {
        // SAFETY: one of our states, and the importer's pointer to one size.
        let saved = unsafe { fmu_state::get(state) }?;
        unsafe { slice_mut(size, 1, "size") }?[0] = serialize(&saved.instance).len();
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SerializeFMUstate(
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    guard(c, "fmi2SerializeFMUstate", allowed::FMU_STATE, |_| {
        // SAFETY: one of our states.
        let data = serialize(&unsafe { fmu_state::get(state) }?.instance);
        if data.len() != size {
            return Err(FmiError::error(format!(
                "size {size} given, the serialized state has {} bytes (fmi2SerializedFMUstateSize)",
                data.len()
            )));
        }
        // SAFETY: the importer's buffer of `size` bytes.
        let out = unsafe { slice_mut(bytes as *mut u8, size, "serializedState") }?;
        out.copy_from_slice(&data);
        Ok(())
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2DeSerializeFMUstate(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    guard(c, "fmi2DeSerializeFMUstate", allowed::FMU_STATE, |_| {
        // SAFETY: the importer's buffer of `size` bytes, and its slot for a state.
        let data = unsafe { slice(bytes as *const u8, size, "serializedState") }?;
        let instance = deserialize(data)?;
        unsafe { fmu_state::store(state, instance) }
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetDirectionalDerivative(
    c: fmi2Component,
    vUnknown_ref: *const fmi2ValueReference,
    nUnknown: usize,
    vKnown_ref: *const fmi2ValueReference,
    nKnown: usize,
    dvKnown: *const fmi2Real,
    dvUnknown: *mut fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2GetDirectionalDerivative", allowed::GET, |i| {
        // SAFETY: the importer's arrays of nUnknown and nKnown elements.
        let (unknowns, knowns, dv_known, dv_unknown) = unsafe {
            (
                slice(vUnknown_ref, nUnknown, "vUnknown_ref")?,
                slice(vKnown_ref, nKnown, "vKnown_ref")?,
                slice(dvKnown, nKnown, "dvKnown")?,
                slice_mut(dvUnknown, nUnknown, "dvUnknown")?,
            )
        };
        i.directional_derivative(unknowns, knowns, dv_known, dv_unknown)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2SetRealInputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2SetRealInputDerivatives", allowed::SET, |i| {
        // SAFETY: the importer's arrays of nvr elements.
        let (vr, order, value) = unsafe {
            (
                slice(vr, nvr, "vr")?,
                slice(order, nvr, "order")?,
                slice(value, nvr, "value")?,
            )
        };
        i.set_input_derivatives(vr, order, value)
    })
}

#[unsafe(no_mangle)]
pub unsafe extern "C" fn fmi2GetRealOutputDerivatives(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    nvr: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2GetRealOutputDerivatives", allowed::GET, |i| {
        // SAFETY: the importer's arrays of nvr elements.
        let (vr, order, out) = unsafe {
            (
                slice(vr, nvr, "vr")?,
                slice(order, nvr, "order")?,
                slice_mut(value, nvr, "value")?,
            )
        };
        i.get_output_derivatives(vr, order, out)
    })
}
