//! What the `fmi2*` C exports ([`export_co_simulation!`](crate::export_co_simulation)) share
//! beyond the guard: fmi2Instantiate and fmi2FreeInstance (no component to guard yet, or any
//! more), C strings, and the answers of the functions for which this shell's models have no
//! values (the asynchronous step's statuses).
#![allow(clippy::missing_safety_doc)]

use crate::component::{Component, slice, slice_mut};
use crate::fmu::Fmu;
use crate::logger::Logger;
use crate::packed::{self, Refusal};
use crate::slave::{EventInfo, Interface, Slave};
use crate::status::{FmiError, FmiResult, Status};
use crate::values::Starts;
use fmi_sys::fmi2::*;
use std::ffi::CStr;
use std::panic::{AssertUnwindSafe, catch_unwind};

/// A C string argument as &str (None for NULL or invalid UTF-8).
///
/// # Safety
/// `s` is NULL or a NUL-terminated string.
pub unsafe fn text<'a>(s: fmi2String) -> Option<&'a str> {
    if s.is_null() {
        None
    } else {
        // SAFETY: a non-null fmi2String is a NUL-terminated string owned by the importer.
        unsafe { CStr::from_ptr(s) }.to_str().ok()
    }
}

/// The interface fmi2Instantiate asks for and the instance's start values, or the reason it
/// refuses, checked before anything is allocated.
unsafe fn check_instantiate<S: Slave>(
    fmu_type: fmi2Type,
    guid: fmi2String,
    resource_location: fmi2String,
) -> FmiResult<(Interface, Starts)> {
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
    // SAFETY: the importer's string arguments.
    let starts = unsafe { check_token::<S>(guid, resource_location) }?;
    Ok((interface, starts))
}

/// The start values of the importer's GUID (FMI 3.0: instantiationToken): the contract's for
/// the GUID this binary was built with, without reading anything; a packed model
/// description's (beside `resources`, [`packed`]) for the GUID it names.
///
/// # Safety
/// `guid` and `resources` are NULL or NUL-terminated strings.
pub unsafe fn check_token<S: Slave>(guid: fmi2String, resources: fmi2String) -> FmiResult<Starts> {
    let id = &S::IDENTITY;
    // SAFETY: the importer's string argument.
    let Some(guid) = (unsafe { text(guid) }) else {
        return Err(FmiError::error(format!(
            "no GUID given (NULL or not UTF-8): this binary's is {}",
            id.guid
        )));
    };
    if guid == id.guid {
        return Ok(Starts::default());
    }
    // SAFETY: the importer's string argument.
    let resources = unsafe { text(resources) };
    packed::starts(id, guid, resources).map_err(|refusal| match refusal {
        Refusal::Invalid(e) => FmiError::error(format!(
            "the model description beside the binary (GUID {guid}) has an invalid start value: {}",
            e.message
        )),
        Refusal::Mismatch(why) => FmiError::error(format!(
            "GUID {guid} does not match this binary's {}, and no model description matching it was found beside the binary ({why}): the model description and the binary are from different builds",
            id.guid
        )),
    })
}

pub unsafe fn instantiate<S: Slave>(
    instance_name: fmi2String,
    fmu_type: fmi2Type,
    guid: fmi2String,
    resource_location: fmi2String,
    functions: *const fmi2CallbackFunctions,
    logging_on: fmi2Boolean,
) -> fmi2Component {
    // SAFETY: NULL is tolerated; otherwise the importer's callback table.
    let (callback, environment) = match unsafe { functions.as_ref() } {
        Some(f) => (f.logger, f.componentEnvironment),
        None => (None, std::ptr::null_mut()),
    };
    // SAFETY: the importer's arguments.
    unsafe {
        create::<S>(
            "fmi2Instantiate",
            instance_name,
            |name| Logger::new(callback, environment, name),
            || check_instantiate::<S>(fmu_type, guid, resource_location),
            logging_on != 0,
        )
    }
}

/// A new instance behind a component pointer, from the start values `check` gives, or NULL
/// (logged) for an empty name or the error `check` finds in the importer's other arguments
/// (no panic crosses the C boundary).
///
/// # Safety
/// `instance_name` is NULL or a NUL-terminated string; `check` reads only valid arguments.
pub unsafe fn create<S: Slave>(
    function: &str,
    instance_name: fmi2String,
    logger: impl FnOnce(&CStr) -> Logger,
    check: impl FnOnce() -> FmiResult<(Interface, Starts)>,
    logging_on: bool,
) -> fmi2Component {
    catch_unwind(AssertUnwindSafe(|| {
        // The name is only handed back to the logger: kept as the importer's bytes, UTF-8
        // or not (FMI asks for UTF-8; some importers pass their code page).
        let name = if instance_name.is_null() {
            c""
        } else {
            // SAFETY: a non-null fmi2String is a NUL-terminated string owned by the importer.
            unsafe { CStr::from_ptr(instance_name) }
        };
        let logger = logger(name);
        let error = S::IDENTITY.log_categories[0].0;
        if name.is_empty() {
            logger.log(
                Status::Error,
                error,
                &format!("{function}: instanceName is missing or empty"),
            );
            return std::ptr::null_mut();
        }
        let fmu = check().and_then(|(interface, starts)| {
            let mut fmu = Fmu::<S>::new(logging_on, interface);
            fmu.start_from(starts)?;
            Ok(fmu)
        });
        let fmu = match fmu {
            Ok(fmu) => fmu,
            Err(e) => {
                logger.log(e.status, error, &format!("{function}: {}", e.message));
                return std::ptr::null_mut();
            }
        };
        let component = Box::new(Component { fmu, logger });
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

/// fmi2SetDebugLogging's category names ("<NULL>" for a NULL one).
pub unsafe fn category_names(categories: *const fmi2String, n: usize) -> FmiResult<Vec<String>> {
    // SAFETY: the importer's array of n strings.
    let names = unsafe { slice(categories, n, "categories") }?;
    Ok(names
        .iter()
        .map(|&s| unsafe { text(s) }.unwrap_or("<NULL>").to_string())
        .collect())
}

/// A status kind this FMU has no value for: fmi2Discard, as the standard asks.
pub fn unavailable(kind: fmi2StatusKind) -> FmiResult {
    Err(FmiError::discard(format!(
        "status kind {kind} is not available: fmi2DoStep never returns fmi2Pending"
    )))
}

/// fmi2GetRealStatus and fmi2GetBooleanStatus: `value` for the one kind `answered`.
pub unsafe fn status<T>(
    kind: fmi2StatusKind,
    answered: fmi2StatusKind,
    out: *mut T,
    value: T,
) -> FmiResult {
    if kind != answered {
        return unavailable(kind);
    }
    // SAFETY: the importer's pointer to one value.
    unsafe { slice_mut(out, 1, "value") }?[0] = value;
    Ok(())
}

/// fmi2NewDiscreteStates's answer in the importer's struct.
pub fn event_info(e: EventInfo, out: &mut fmi2EventInfo) {
    out.newDiscreteStatesNeeded = e.new_discrete_states_needed.into();
    out.terminateSimulation = e.terminate_simulation.into();
    out.nominalsOfContinuousStatesChanged = e.nominals_of_continuous_states_changed.into();
    out.valuesOfContinuousStatesChanged = e.values_of_continuous_states_changed.into();
    out.nextEventTimeDefined = e.next_event_time.is_some().into();
    out.nextEventTime = e.next_event_time.unwrap_or(0.0);
}
