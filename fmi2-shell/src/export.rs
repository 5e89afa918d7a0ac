//! The bodies of the `fmi2*` C exports, generic over the slave: each unpacks its C arguments
//! and calls the slave through [`guard`]. [`export_co_simulation!`](crate::export_co_simulation)
//! defines the exported symbols in the model's cdylib (a generic function cannot be
//! exported, and the symbols must live in the library the importer loads).
#![allow(non_snake_case, clippy::missing_safety_doc, clippy::too_many_arguments)]

use crate::component::{Component, guard, slice, slice_mut};
use crate::fmu_state::{self, deserialize, serialize};
use crate::logger::Logger;
use crate::slave::{Interface, Slave, reset, restore, snapshot};
use crate::state::allowed;
use crate::status::{FmiError, FmiResult, Status};
use fmi_sys::fmi2::*;
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

pub fn types_platform() -> *const c_char {
    c"default".as_ptr()
}

pub fn version() -> *const c_char {
    c"2.0".as_ptr()
}

/// The interface fmi2Instantiate asks for, or the reason it refuses, checked before anything
/// is allocated.
unsafe fn check_instantiate<S: Slave>(
    fmu_type: fmi2Type,
    guid: fmi2String,
) -> FmiResult<Interface> {
    let id = &S::IDENTITY;
    let interface = match fmu_type {
        t if t == fmi2Type_fmi2CoSimulation => Interface::CoSimulation,
        t if t == fmi2Type_fmi2ModelExchange && id.model_exchange => Interface::ModelExchange,
        _ => {
            return Err(FmiError::error(format!(
                "{} does not offer fmuType = {fmu_type} (0 Model Exchange, 1 Co-Simulation)",
                id.model_identifier
            )));
        }
    };
    // SAFETY: the importer's string argument.
    match unsafe { text(guid) } {
        Some(guid) if guid == id.guid => Ok(interface),
        other => Err(FmiError::error(format!(
            "GUID {other:?} does not match this binary's {}: the model description and the binary are from different builds",
            id.guid
        ))),
    }
}

pub unsafe fn instantiate<S: Slave>(
    instance_name: fmi2String,
    fmu_type: fmi2Type,
    guid: fmi2String,
    functions: *const fmi2CallbackFunctions,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    catch_unwind(AssertUnwindSafe(|| {
        // SAFETY: NULL is tolerated; otherwise the importer's callback table.
        let (callback, environment) = match unsafe { functions.as_ref() } {
            Some(f) => (f.logger, f.componentEnvironment),
            None => (None, std::ptr::null_mut()),
        };
        // The name is only handed back to the logger: kept as the importer's bytes, UTF-8
        // or not (FMI asks for UTF-8; some importers pass their code page).
        let name = if instance_name.is_null() {
            c""
        } else {
            // SAFETY: a non-null fmi2String is a NUL-terminated string owned by the importer.
            unsafe { CStr::from_ptr(instance_name) }
        };
        let logger = Logger::new(callback, environment, name);
        let error = S::IDENTITY.log_categories[0].0;
        if name.is_empty() {
            logger.log(
                Status::Error,
                error,
                "fmi2Instantiate: instanceName is missing or empty",
            );
            return std::ptr::null_mut();
        }
        // SAFETY: the importer's arguments.
        let interface = match unsafe { check_instantiate::<S>(fmu_type, guid) } {
            Ok(interface) => interface,
            Err(e) => {
                logger.log(e.status, error, &format!("fmi2Instantiate: {}", e.message));
                return std::ptr::null_mut();
            }
        };
        let component = Box::new(Component {
            slave: S::new(logging_on != 0, interface),
            logger,
        });
        Box::into_raw(component) as fmi2Component
    }))
    .unwrap_or(std::ptr::null_mut())
}

pub unsafe fn free_instance<S: Slave>(c: fmi2Component) {
    if !c.is_null() {
        // SAFETY: c came from fmi2Instantiate's Box::into_raw and is freed once.
        let _ = catch_unwind(AssertUnwindSafe(|| {
            drop(unsafe { Box::from_raw(c as *mut Component<S>) })
        }));
    }
}

pub unsafe fn set_debug_logging<S: Slave>(
    c: fmi2Component,
    logging_on: fmi2Boolean,
    n: usize,
    categories: *const fmi2String,
) -> fmi2Status {
    guard(
        c,
        "fmi2SetDebugLogging",
        allowed::SET_DEBUG_LOGGING,
        |s: &mut S| {
            // SAFETY: the importer's array of n strings.
            let names = unsafe { slice(categories, n, "categories") }?;
            let names: Vec<String> = names
                .iter()
                .map(|&s| unsafe { text(s) }.unwrap_or("<NULL>").to_string())
                .collect();
            s.log().set_debug_logging(logging_on != 0, &names)
        },
    )
}

pub fn setup_experiment<S: Slave>(
    c: fmi2Component,
    tolerance_defined: fmi2Boolean,
    tolerance: fmi2Real,
    start_time: fmi2Real,
) -> fmi2Status {
    guard(
        c,
        "fmi2SetupExperiment",
        allowed::SETUP_EXPERIMENT,
        |s: &mut S| s.setup_experiment((tolerance_defined != 0).then_some(tolerance), start_time),
    )
}

pub fn enter_initialization_mode<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard(
        c,
        "fmi2EnterInitializationMode",
        allowed::ENTER_INITIALIZATION_MODE,
        S::enter_initialization_mode,
    )
}

pub fn exit_initialization_mode<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard(
        c,
        "fmi2ExitInitializationMode",
        allowed::EXIT_INITIALIZATION_MODE,
        S::exit_initialization_mode,
    )
}

pub fn terminate<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard(c, "fmi2Terminate", allowed::TERMINATE, S::terminate)
}

pub fn reset_instance<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard(c, "fmi2Reset", allowed::RESET, |s: &mut S| {
        reset(s);
        Ok(())
    })
}

pub unsafe fn get_real<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *mut fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2GetReal", allowed::GET, |s: &mut S| {
        // SAFETY: the importer's arrays of n elements.
        let (vr, out) = unsafe { (slice(vr, n, "vr")?, slice_mut(value, n, "value")?) };
        s.get_real(vr, out)
    })
}

pub unsafe fn get_integer<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *mut fmi2Integer,
) -> fmi2Status {
    guard(c, "fmi2GetInteger", allowed::GET, |s: &mut S| {
        // SAFETY: the importer's arrays of n elements.
        let (vr, out) = unsafe { (slice(vr, n, "vr")?, slice_mut(value, n, "value")?) };
        s.get_integer(vr, out)
    })
}

pub unsafe fn set_real<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2SetReal", allowed::SET, |s: &mut S| {
        // SAFETY: the importer's arrays of n elements.
        let (vr, values) = unsafe { (slice(vr, n, "vr")?, slice(value, n, "value")?) };
        s.set_real(vr, values)
    })
}

pub unsafe fn set_integer<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    value: *const fmi2Integer,
) -> fmi2Status {
    guard(c, "fmi2SetInteger", allowed::SET, |s: &mut S| {
        // SAFETY: the importer's arrays of n elements.
        let (vr, values) = unsafe { (slice(vr, n, "vr")?, slice(value, n, "value")?) };
        s.set_integer(vr, values)
    })
}

/// fmi2Get/SetBoolean and fmi2Get/SetString: the model has no such variables, so any value
/// reference is unknown.
pub unsafe fn no_variables<S: Slave>(
    c: fmi2Component,
    function: &str,
    allowed: u8,
    kind: &str,
    vr: *const fmi2ValueReference,
    n: usize,
) -> fmi2Status {
    guard(c, function, allowed, |_: &mut S| {
        // SAFETY: the importer's array of n elements.
        match unsafe { slice(vr, n, "vr") }?.first() {
            None => Ok(()),
            Some(vr) => Err(FmiError::error(format!(
                "unknown value reference {vr} for type {kind}: the model has no {kind} variables"
            ))),
        }
    })
}

pub fn do_step<S: Slave>(c: fmi2Component, current: fmi2Real, h: fmi2Real) -> fmi2Status {
    guard(c, "fmi2DoStep", allowed::DO_STEP, |s: &mut S| {
        s.do_step(current, h)
    })
}

pub fn cancel_step<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard(
        c,
        "fmi2CancelStep",
        allowed::CANCEL_STEP,
        |_: &mut S| Ok(()),
    )
}

/// A status kind this FMU has no value for: fmi2Discard, as the standard asks.
fn unavailable(kind: fmi2StatusKind) -> FmiResult {
    Err(FmiError::discard(format!(
        "status kind {kind} is not available: fmi2DoStep never returns fmi2Pending"
    )))
}

pub fn get_status<S: Slave>(c: fmi2Component, function: &str, kind: fmi2StatusKind) -> fmi2Status {
    guard(c, function, allowed::GET_STATUS, |_: &mut S| {
        unavailable(kind)
    })
}

pub unsafe fn get_real_status<S: Slave>(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Real,
) -> fmi2Status {
    guard(c, "fmi2GetRealStatus", allowed::GET_STATUS, |s: &mut S| {
        if kind != fmi2StatusKind_fmi2LastSuccessfulTime {
            return unavailable(kind);
        }
        // SAFETY: the importer's pointer to one value.
        unsafe { slice_mut(value, 1, "value") }?[0] = s.last_successful_time();
        Ok(())
    })
}

pub unsafe fn get_boolean_status<S: Slave>(
    c: fmi2Component,
    kind: fmi2StatusKind,
    value: *mut fmi2Boolean,
) -> fmi2Status {
    guard(
        c,
        "fmi2GetBooleanStatus",
        allowed::GET_STATUS,
        |_: &mut S| {
            if kind != fmi2StatusKind_fmi2Terminated {
                return unavailable(kind);
            }
            // The slave never asks the master to end the simulation.
            // SAFETY: the importer's pointer to one value.
            unsafe { slice_mut(value, 1, "value") }?[0] = 0;
            Ok(())
        },
    )
}

pub unsafe fn get_fmu_state<S: Slave>(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    guard(c, "fmi2GetFMUstate", allowed::FMU_STATE, |s: &mut S| {
        // SAFETY: the importer's slot for a state.
        unsafe { fmu_state::store(state, snapshot(s)) }
    })
}

pub unsafe fn set_fmu_state<S: Slave>(c: fmi2Component, state: fmi2FMUstate) -> fmi2Status {
    guard(c, "fmi2SetFMUstate", allowed::FMU_STATE, |s: &mut S| {
        // SAFETY: a state fmi2GetFMUstate or fmi2DeSerializeFMUstate returned.
        let saved = unsafe { fmu_state::get::<S>(state) }?;
        // A state holds its instance's interface, which the importer's calls must keep.
        if saved.slave.interface() != s.interface() {
            return Err(FmiError::error(format!(
                "the FMU state is of a {:?} instance, this one is {:?}",
                saved.slave.interface(),
                s.interface()
            )));
        }
        restore(s, &saved.slave);
        Ok(())
    })
}

pub unsafe fn free_fmu_state<S: Slave>(c: fmi2Component, state: *mut fmi2FMUstate) -> fmi2Status {
    // SAFETY: the importer's slot holding one of our states, or NULL.
    guard(
        c,
        "fmi2FreeFMUstate",
        allowed::FMU_STATE,
        |_: &mut S| unsafe { fmu_state::free::<S>(state) },
    )
}

pub unsafe fn serialized_fmu_state_size<S: Slave>(
    c: fmi2Component,
    state: fmi2FMUstate,
    size: *mut usize,
) -> fmi2Status {
    guard(
        c,
        "fmi2SerializedFMUstateSize",
        allowed::FMU_STATE,
        |_: &mut S| {
            // SAFETY: one of our states, and the importer's pointer to one size.
            let saved = unsafe { fmu_state::get::<S>(state) }?;
            unsafe { slice_mut(size, 1, "size") }?[0] = serialize(&saved.slave).len();
            Ok(())
        },
    )
}

pub unsafe fn serialize_fmu_state<S: Slave>(
    c: fmi2Component,
    state: fmi2FMUstate,
    bytes: *mut fmi2Byte,
    size: usize,
) -> fmi2Status {
    guard(
        c,
        "fmi2SerializeFMUstate",
        allowed::FMU_STATE,
        |_: &mut S| {
            // SAFETY: one of our states.
            let data = serialize(&unsafe { fmu_state::get::<S>(state) }?.slave);
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
        },
    )
}

pub unsafe fn deserialize_fmu_state<S: Slave>(
    c: fmi2Component,
    bytes: *const fmi2Byte,
    size: usize,
    state: *mut fmi2FMUstate,
) -> fmi2Status {
    guard(
        c,
        "fmi2DeSerializeFMUstate",
        allowed::FMU_STATE,
        |_: &mut S| {
            // SAFETY: the importer's buffer of `size` bytes, and its slot for a state.
            let data = unsafe { slice(bytes as *const u8, size, "serializedState") }?;
            let slave = deserialize::<S>(data)?;
            unsafe { fmu_state::store(state, slave) }
        },
    )
}

pub unsafe fn get_directional_derivative<S: Slave>(
    c: fmi2Component,
    unknown: *const fmi2ValueReference,
    n_unknown: usize,
    known: *const fmi2ValueReference,
    n_known: usize,
    dv_known: *const fmi2Real,
    dv_unknown: *mut fmi2Real,
) -> fmi2Status {
    guard(
        c,
        "fmi2GetDirectionalDerivative",
        allowed::GET,
        |s: &mut S| {
            // SAFETY: the importer's arrays of n_unknown and n_known elements.
            let (unknowns, knowns, dv_known, dv_unknown) = unsafe {
                (
                    slice(unknown, n_unknown, "vUnknown_ref")?,
                    slice(known, n_known, "vKnown_ref")?,
                    slice(dv_known, n_known, "dvKnown")?,
                    slice_mut(dv_unknown, n_unknown, "dvUnknown")?,
                )
            };
            s.directional_derivative(unknowns, knowns, dv_known, dv_unknown)
        },
    )
}

pub unsafe fn set_real_input_derivatives<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    order: *const fmi2Integer,
    value: *const fmi2Real,
) -> fmi2Status {
    guard(
        c,
        "fmi2SetRealInputDerivatives",
        allowed::SET,
        |s: &mut S| {
            // SAFETY: the importer's arrays of n elements.
            let (vr, order, value) = unsafe {
                (
                    slice(vr, n, "vr")?,
                    slice(order, n, "order")?,
                    slice(value, n, "value")?,
                )
            };
            s.set_input_derivatives(vr, order, value)
        },
    )
}

pub unsafe fn get_real_output_derivatives<S: Slave>(
    c: fmi2Component,
    vr: *const fmi2ValueReference,
    n: usize,
    order: *const fmi2Integer,
    value: *mut fmi2Real,
) -> fmi2Status {
    guard(
        c,
        "fmi2GetRealOutputDerivatives",
        allowed::GET,
        |s: &mut S| {
            // SAFETY: the importer's arrays of n elements.
            let (vr, order, out) = unsafe {
                (
                    slice(vr, n, "vr")?,
                    slice(order, n, "order")?,
                    slice_mut(value, n, "value")?,
                )
            };
            s.get_output_derivatives(vr, order, out)
        },
    )
}

// Model Exchange.

pub fn set_time<S: Slave>(c: fmi2Component, t: fmi2Real) -> fmi2Status {
    guard(c, "fmi2SetTime", allowed::SET_TIME, |s: &mut S| {
        s.set_time(t)
    })
}

pub unsafe fn set_continuous_states<S: Slave>(
    c: fmi2Component,
    x: *const fmi2Real,
    n: usize,
) -> fmi2Status {
    guard(
        c,
        "fmi2SetContinuousStates",
        allowed::SET_CONTINUOUS_STATES,
        |s: &mut S| {
            // SAFETY: the importer's array of n elements.
            s.set_continuous_states(unsafe { slice(x, n, "x") }?)
        },
    )
}

/// fmi2GetDerivatives, fmi2GetEventIndicators, fmi2GetContinuousStates and
/// fmi2GetNominalsOfContinuousStates: an array of n values the slave fills.
pub unsafe fn get_vector<S: Slave>(
    c: fmi2Component,
    function: &str,
    out: *mut fmi2Real,
    n: usize,
    get: impl FnOnce(&mut S, &mut [f64]) -> FmiResult,
) -> fmi2Status {
    guard(c, function, allowed::GET_CONTINUOUS, |s: &mut S| {
        // SAFETY: the importer's array of n elements.
        get(s, unsafe { slice_mut(out, n, "the output array") }?)
    })
}

pub fn enter_event_mode<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard(
        c,
        "fmi2EnterEventMode",
        allowed::ENTER_EVENT_MODE,
        S::enter_event_mode,
    )
}

pub unsafe fn new_discrete_states<S: Slave>(
    c: fmi2Component,
    info: *mut fmi2EventInfo,
) -> fmi2Status {
    guard(
        c,
        "fmi2NewDiscreteStates",
        allowed::NEW_DISCRETE_STATES,
        |s: &mut S| {
            // SAFETY: the importer's struct, or NULL (refused).
            let Some(out) = (unsafe { info.as_mut() }) else {
                return Err(FmiError::error("fmi2EventInfo is NULL"));
            };
            let e = s.new_discrete_states()?;
            out.newDiscreteStatesNeeded = e.new_discrete_states_needed.into();
            out.terminateSimulation = e.terminate_simulation.into();
            out.nominalsOfContinuousStatesChanged = e.nominals_of_continuous_states_changed.into();
            out.valuesOfContinuousStatesChanged = e.values_of_continuous_states_changed.into();
            out.nextEventTimeDefined = e.next_event_time.is_some().into();
            out.nextEventTime = e.next_event_time.unwrap_or(0.0);
            Ok(())
        },
    )
}

pub fn enter_continuous_time_mode<S: Slave>(c: fmi2Component) -> fmi2Status {
    guard(
        c,
        "fmi2EnterContinuousTimeMode",
        allowed::ENTER_CONTINUOUS_TIME_MODE,
        S::enter_continuous_time_mode,
    )
}

pub unsafe fn completed_integrator_step<S: Slave>(
    c: fmi2Component,
    enter_event_mode: *mut fmi2Boolean,
    terminate: *mut fmi2Boolean,
) -> fmi2Status {
    guard(
        c,
        "fmi2CompletedIntegratorStep",
        allowed::COMPLETED_INTEGRATOR_STEP,
        |s: &mut S| {
            let event = s.completed_integrator_step()?;
            // SAFETY: the importer's pointers to one value each, or NULL (then not written).
            if let Some(out) = unsafe { enter_event_mode.as_mut() } {
                *out = event.into();
            }
            if let Some(out) = unsafe { terminate.as_mut() } {
                *out = 0;
            }
            Ok(())
        },
    )
}
