//! fmi2FMUstate pointers: a boxed copy of the instance's FMU state behind a tag, so that a
//! pointer that is not one of ours is refused rather than read as a state.

use crate::instance::{FmiError, FmiResult, Instance};
use fmi_sys::fmi2::fmi2FMUstate;

const TAG: u64 = u64::from_le_bytes(*b"GRFSTATE");

pub struct FmuState {
    tag: u64,
    pub instance: Instance,
}

/// Stores `instance` into `*state`: a new box when it is NULL, else the one it points to.
///
/// # Safety
/// `state` must be a valid pointer to an fmi2FMUstate (NULL or one of ours).
pub unsafe fn store(state: *mut fmi2FMUstate, instance: Instance) -> FmiResult {
    if state.is_null() {
        return Err(FmiError::error("the FMUstate argument is NULL"));
    }
    // SAFETY: non-null pointer to the importer's fmi2FMUstate slot.
    let slot = unsafe { &mut *state };
    if slot.is_null() {
        *slot = Box::into_raw(Box::new(FmuState { tag: TAG, instance })) as fmi2FMUstate;
    } else {
        // SAFETY: a non-null state in the slot is one of ours (checked by the tag).
        unsafe { get(*slot) }?;
        unsafe { (*(*slot as *mut FmuState)).instance = instance };
    }
    Ok(())
}

/// The state behind a pointer fmi2GetFMUstate or fmi2DeSerializeFMUstate returned.
///
/// # Safety
/// `state` must be NULL or a pointer to a live allocation at least as large as a tag.
pub unsafe fn get<'a>(state: fmi2FMUstate) -> FmiResult<&'a FmuState> {
    // SAFETY: NULL is checked; otherwise the caller vouches for the allocation.
    match unsafe { (state as *const FmuState).as_ref() } {
        Some(s) if s.tag == TAG => Ok(s),
        Some(_) => Err(FmiError::error(
            "the FMUstate is not one this FMU made (foreign pointer)",
        )),
        None => Err(FmiError::error("the FMUstate is NULL")),
    }
}

/// Frees `*state` and sets it to NULL (NULL is accepted and left alone).
///
/// # Safety
/// `state` must be NULL or point to NULL or one of our states.
pub unsafe fn free(state: *mut fmi2FMUstate) -> FmiResult {
    // SAFETY: NULL is checked; otherwise the importer's slot.
    let Some(slot) = (unsafe { state.as_mut() }) else {
        return Ok(());
    };
    if !slot.is_null() {
        // SAFETY: checked to be ours, then freed once and the slot cleared.
        unsafe { get(*slot) }?;
        drop(unsafe { Box::from_raw(*slot as *mut FmuState) });
        *slot = std::ptr::null_mut();
    }
    Ok(())
}
