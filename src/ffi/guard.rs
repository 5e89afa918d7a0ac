//! The one guard around every export: checks the component pointer and the call sequence,
//! runs the call with panics caught (a panic crossing the C boundary would abort the host),
//! turns errors into a status plus a log line, and hands queued log lines to the importer.

use super::logger::{Logger, fmi2_status};
use crate::instance::{FmiError, FmiResult, FmiState, Instance, Status};
use fmi_sys::fmi2::{fmi2Component, fmi2Status, fmi2Status_fmi2Error};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// What an fmi2Component points to.
pub struct Component {
    pub instance: Instance,
    pub logger: Logger,
}

impl Component {
    pub fn flush_log(&mut self) {
        if self.instance.messages.is_empty() {
            return;
        }
        for m in self.instance.messages.drain(..) {
            self.logger.log(m.status, m.category, &m.text);
        }
    }
}

/// Text of a caught panic.
pub fn panic_text(payload: &(dyn std::any::Any + Send)) -> String {
    payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown panic".to_string())
}

/// Runs `call` on the instance behind `c` if the current state is in `allowed`.
#[inline]
pub fn guard(
    c: fmi2Component,
    function: &str,
    allowed: u8,
    call: impl FnOnce(&mut Instance) -> FmiResult,
) -> fmi2Status {
    if c.is_null() {
        return fmi2Status_fmi2Error;
    }
    // SAFETY: a non-null fmi2Component is one fmi2Instantiate returned and fmi2FreeInstance
    // has not freed (the importer's side of the contract).
    let component = unsafe { &mut *(c as *mut Component) };
    let instance = &mut component.instance;
    if !instance.state.allows(allowed) {
        return refuse(component, function);
    }
    let outcome = catch_unwind(AssertUnwindSafe(|| call(instance)));
    // The path of a call that succeeds and logs nothing: what a master's loop takes.
    if matches!(outcome, Ok(Ok(()))) && component.instance.messages.is_empty() {
        return fmi2_status(Status::Ok);
    }
    report(component, function, outcome)
}

/// A call the current state does not allow (kept out of `guard`'s path: it is rare).
#[cold]
#[inline(never)]
fn refuse(component: &mut Component, function: &str) -> fmi2Status {
    let e = FmiError::error(format!(
        "illegal call sequence: {function} is not allowed in state {:?}",
        component.instance.state
    ));
    report(component, function, Ok(Err(e)))
}

/// The status of a call that failed, panicked or queued log lines, with those lines and the
/// reason handed to the importer's logger.
#[cold]
#[inline(never)]
fn report(
    component: &mut Component,
    function: &str,
    outcome: std::thread::Result<FmiResult>,
) -> fmi2Status {
    let instance = &mut component.instance;
    let status = match outcome {
        Ok(Ok(())) => Status::Ok,
        Ok(Err(e)) => {
            let e = FmiError {
                message: format!("{function}: {}", e.message),
                ..e
            };
            instance.log_error(&e);
            e.status
        }
        Err(payload) => {
            instance.state = FmiState::Error;
            let e = FmiError::error(format!(
                "{function}: internal error ({}); the instance is in the error state, fmi2Reset to start over",
                panic_text(payload.as_ref())
            ));
            instance.log_error(&e);
            e.status
        }
    };
    component.flush_log();
    fmi2_status(status)
}

/// A slice from an importer's pointer and length; NULL is accepted only for length 0.
///
/// # Safety
/// `ptr` must point to `len` valid elements when non-null.
pub unsafe fn slice<'a, T>(ptr: *const T, len: usize, what: &str) -> FmiResult<&'a [T]> {
    if len == 0 {
        Ok(&[])
    } else if ptr.is_null() {
        Err(FmiError::error(format!(
            "{what} is NULL with {len} elements"
        )))
    } else {
        // SAFETY: non-null, and the caller vouches for len elements.
        Ok(unsafe { std::slice::from_raw_parts(ptr, len) })
    }
}

/// A mutable slice from an importer's pointer and length; NULL only for length 0.
///
/// # Safety
/// `ptr` must point to `len` valid, writable elements when non-null.
pub unsafe fn slice_mut<'a, T>(ptr: *mut T, len: usize, what: &str) -> FmiResult<&'a mut [T]> {
    if len == 0 {
        Ok(&mut [])
    } else if ptr.is_null() {
        Err(FmiError::error(format!(
            "{what} is NULL with {len} elements"
        )))
    } else {
        // SAFETY: non-null, and the caller vouches for len writable elements.
        Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len) })
    }
}
