//! What an fmi2Component points to, and the guard every C export goes through: it checks the
//! state table, runs the call inside `catch_unwind` (no panic crosses the C boundary), and
//! hands the call's log lines to the importer's logger.

use crate::fmu::Fmu;
use crate::logger::{Logger, fmi2_status};
use crate::slave::Slave;
use crate::state::FmiState;
use crate::status::{FmiError, FmiResult, Status};
use fmi_sys::fmi2::{fmi2Component, fmi2Status, fmi2Status_fmi2Error};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// An FMU instance and the logger of the importer that instantiated it.
pub struct Component<S> {
    pub fmu: Fmu<S>,
    pub logger: Logger,
}

impl<S: Slave> Component<S> {
    /// Hands the queued log lines to the importer's logger.
    pub fn flush_log(&mut self) {
        for m in self.fmu.log().messages.drain(..) {
            self.logger.log(m.status, m.category, &m.text);
        }
    }
}

/// A panic's message.
pub fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_string())
}

/// Runs `call` on the instance behind `c` if `allowed` admits its state; a refused call or an
/// error is logged with the function's name, a panic puts the instance into the error state.
/// The path of an accepted call that logs nothing is kept short: it is taken at every step.
#[inline]
pub fn guard<S: Slave>(
    c: fmi2Component,
    function: &str,
    allowed: u8,
    call: impl FnOnce(&mut Fmu<S>) -> FmiResult,
) -> fmi2Status {
    if c.is_null() {
        return fmi2Status_fmi2Error;
    }
    // SAFETY: a non-null fmi2Component is one fmi2Instantiate returned for this slave type,
    // not yet freed, and FMI forbids concurrent calls on one instance.
    let component = unsafe { &mut *(c as *mut Component<S>) };
    if !component.fmu.state.allows(allowed) {
        return refuse(component, function);
    }
    let outcome = catch_unwind(AssertUnwindSafe(|| call(&mut component.fmu)));
    if matches!(outcome, Ok(Ok(()))) && component.fmu.log().messages.is_empty() {
        return fmi2_status(Status::Ok);
    }
    report(component, function, outcome)
}

#[cold]
#[inline(never)]
fn refuse<S: Slave>(component: &mut Component<S>, function: &str) -> fmi2Status {
    let e = FmiError::error(format!(
        "illegal call sequence: {function} is not allowed in state {:?}",
        component.fmu.state
    ));
    report(component, function, Ok(Err(e)))
}

#[cold]
#[inline(never)]
fn report<S: Slave>(
    component: &mut Component<S>,
    function: &str,
    outcome: std::thread::Result<FmiResult>,
) -> fmi2Status {
    let fmu = &mut component.fmu;
    let status = match outcome {
        Ok(Ok(())) => Status::Ok,
        Ok(Err(e)) => {
            let e = FmiError {
                message: format!("{function}: {}", e.message),
                ..e
            };
            fmu.log().error(&e);
            e.status
        }
        Err(payload) => {
            fmu.state = FmiState::Error;
            let e = FmiError::error(format!(
                "{function}: internal error ({}); the instance is in the error state, fmi2Reset to start over",
                panic_text(payload.as_ref())
            ));
            fmu.log().error(&e);
            e.status
        }
    };
    component.flush_log();
    fmi2_status(status)
}

/// An importer's array as a slice: empty for length 0 (any pointer), refused if NULL.
///
/// # Safety
/// A non-null `ptr` must point to `len` valid elements that outlive the call.
pub unsafe fn slice<'a, T>(ptr: *const T, len: usize, what: &str) -> FmiResult<&'a [T]> {
    if len == 0 {
        Ok(&[])
    } else if ptr.is_null() {
        Err(null_array(what, len))
    } else {
        // SAFETY: the caller's contract.
        Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
    }
}

/// The error of a NULL array of `len` elements, out of the accepted call's path.
#[cold]
#[inline(never)]
fn null_array(what: &str, len: usize) -> FmiError {
    FmiError::error(format!("{what} is NULL with {len} elements"))
}

/// An importer's output array as a mutable slice (see [`slice`]).
///
/// # Safety
/// A non-null `ptr` must point to `len` writable elements that outlive the call.
pub unsafe fn slice_mut<'a, T>(ptr: *mut T, len: usize, what: &str) -> FmiResult<&'a mut [T]> {
    if len == 0 {
        Ok(&mut [])
    } else if ptr.is_null() {
        Err(null_array(what, len))
    } else {
        // SAFETY: the caller's contract.
        Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len) })
    }
}
