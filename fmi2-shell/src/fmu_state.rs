//! FMU states: the boxed copies fmi2GetFMUstate hands out (tagged with the model's GUID, so
//! that a pointer from another model or none of ours is refused, not read), and their
//! serialized form: a header (the model's magic, the format's version, the length), the
//! postcard bytes of the GUID and the instance ([`Fmu`]), and a CRC-32 of those bytes.

use crate::component::{slice, slice_mut};
use crate::fmu::Fmu;
use crate::slave::Slave;
use crate::status::{FmiError, FmiResult};
use fmi_sys::fmi2::fmi2FMUstate;
use serde::{Deserialize, Serialize};

/// What an fmi2FMUstate points to. `repr(C)`: the tag first, so that telling a foreign
/// pointer reads only its first eight bytes (Rust's own layout may put the tag after the
/// instance, thousands of bytes further).
#[repr(C)]
pub struct FmuState<S> {
    tag: u64,
    pub fmu: Fmu<S>,
}

/// FNV-1a of the model's GUID: the tag of its FMU states.
fn tag<S: Slave>() -> u64 {
    S::IDENTITY
        .guid
        .bytes()
        .fold(0xcbf2_9ce4_8422_2325, |h, b| {
            (h ^ b as u64).wrapping_mul(0x0000_0100_0000_01b3)
        })
}

/// Stores a copy of `fmu` into the importer's slot: a new state if it holds NULL, else the
/// state it holds (one of ours) is overwritten.
///
/// # Safety
/// `state` is NULL or points to the importer's slot, holding NULL or a state of this model.
pub unsafe fn store<S: Slave>(state: *mut fmi2FMUstate, fmu: Fmu<S>) -> FmiResult {
    if state.is_null() {
        return Err(FmiError::error("the FMUstate argument is NULL"));
    }
    // SAFETY: the caller's contract.
    let slot = unsafe { &mut *state };
    if slot.is_null() {
        *slot = Box::into_raw(Box::new(FmuState {
            tag: tag::<S>(),
            fmu,
        })) as fmi2FMUstate;
    } else {
        // SAFETY: checked to be one of ours just before it is written.
        unsafe { get::<S>(*slot) }?;
        unsafe { (*(*slot as *mut FmuState<S>)).fmu = fmu };
    }
    Ok(())
}

/// The state behind an fmi2FMUstate, if it is one of this model's.
///
/// # Safety
/// `state` is NULL or a pointer the importer got from this library; a foreign pointer is
/// caught by its tag as long as it points to at least eight readable bytes.
pub unsafe fn get<'a, S: Slave>(state: fmi2FMUstate) -> FmiResult<&'a FmuState<S>> {
    // SAFETY: the caller's contract.
    match unsafe { (state as *const FmuState<S>).as_ref() } {
        Some(s) if s.tag == tag::<S>() => Ok(s),
        Some(_) => Err(FmiError::error(
            "the FMUstate is not one this FMU made (foreign pointer)",
        )),
        None => Err(FmiError::error("the FMUstate is NULL")),
    }
}

/// Frees the state in the importer's slot and sets the slot to NULL (a NULL slot is fine).
///
/// # Safety
/// As [`store`].
pub unsafe fn free<S: Slave>(state: *mut fmi2FMUstate) -> FmiResult {
    // SAFETY: the caller's contract.
    let Some(slot) = (unsafe { state.as_mut() }) else {
        return Ok(());
    };
    if !slot.is_null() {
        // SAFETY: checked to be one of ours, then freed once.
        unsafe { get::<S>(*slot) }?;
        drop(unsafe { Box::from_raw(*slot as *mut FmuState<S>) });
        *slot = std::ptr::null_mut();
    }
    Ok(())
}

/// Header: magic (4), version (2), payload length (4); trailer: CRC-32 of the payload (4).
const HEADER: usize = 4 + 2 + 4;
const TRAILER: usize = 4;

#[derive(Serialize, Deserialize)]
struct Payload<S> {
    guid: String,
    fmu: Fmu<S>,
}

/// The bytes of fmi2SerializeFMUstate.
pub fn serialize<S: Slave>(fmu: &Fmu<S>) -> Vec<u8> {
    let id = &S::IDENTITY;
    let payload = postcard::to_allocvec(&Payload {
        guid: id.guid.to_string(),
        fmu: fmu.snapshot(),
    })
    .expect("an instance always encodes");
    let mut bytes = Vec::with_capacity(HEADER + payload.len() + TRAILER);
    bytes.extend_from_slice(&id.state_magic);
    bytes.extend_from_slice(&id.state_version.to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&payload);
    bytes.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    bytes
}

/// fmi2SerializedFMUstateSize (fmi3SerializedFMUStateSize): the serialized length of a
/// state into the importer's `size`.
///
/// # Safety
/// `state` as for [`get`]; `size` NULL or the importer's pointer to one value.
pub unsafe fn serialized_size<S: Slave>(state: fmi2FMUstate, size: *mut usize) -> FmiResult {
    // SAFETY: the caller's contract.
    let saved = unsafe { get::<S>(state) }?;
    unsafe { slice_mut(size, 1, "size") }?[0] = serialize(&saved.fmu).len();
    Ok(())
}

/// fmi2SerializeFMUstate (fmi3SerializeFMUState): the serialized state into the importer's
/// `size` bytes, which must be its length.
///
/// # Safety
/// `state` as for [`get`]; `bytes` NULL or the importer's `size` writable bytes.
pub unsafe fn serialize_into<S: Slave>(
    state: fmi2FMUstate,
    bytes: *mut u8,
    size: usize,
    size_function: &str,
) -> FmiResult {
    // SAFETY: the caller's contract.
    let data = serialize(&unsafe { get::<S>(state) }?.fmu);
    if data.len() != size {
        return Err(FmiError::error(format!(
            "size {size} given, the serialized state has {} bytes ({size_function})",
            data.len()
        )));
    }
    unsafe { slice_mut(bytes, size, "serializedState") }?.copy_from_slice(&data);
    Ok(())
}

/// fmi2DeSerializeFMUstate (fmi3DeserializeFMUState): the state decoded from the importer's
/// bytes into its slot.
///
/// # Safety
/// `bytes` NULL or the importer's `size` bytes; `state` as for [`store`].
pub unsafe fn deserialize_from<S: Slave>(
    bytes: *const u8,
    size: usize,
    state: *mut fmi2FMUstate,
) -> FmiResult {
    // SAFETY: the caller's contract.
    let data = unsafe { slice(bytes, size, "serializedState") }?;
    let fmu = deserialize::<S>(data)?;
    unsafe { store(state, fmu) }
}

fn refuse(why: &str) -> FmiError {
    FmiError::error(format!("serialized FMU state refused: {why}"))
}

/// fmi2DeSerializeFMUstate: the instance saved in `bytes`, checked for its magic, version,
/// length, checksum and GUID before it is decoded, and as [`Fmu::check_decoded`] after.
pub fn deserialize<S: Slave>(bytes: &[u8]) -> FmiResult<Fmu<S>> {
    let id = &S::IDENTITY;
    if bytes.len() < HEADER + TRAILER || bytes[..4] != id.state_magic {
        return Err(refuse(&format!(
            "not a {} FMU state (no {} header)",
            id.model_identifier,
            String::from_utf8_lossy(&id.state_magic)
        )));
    }
    let version = u16::from_le_bytes([bytes[4], bytes[5]]);
    if version != id.state_version {
        return Err(refuse(&format!(
            "format version {version}, this binary reads version {}",
            id.state_version
        )));
    }
    let length = u32::from_le_bytes(bytes[6..10].try_into().expect("4 bytes")) as usize;
    if bytes.len() != HEADER + length + TRAILER {
        return Err(refuse(&format!(
            "length {} does not match the {length} bytes of payload it announces",
            bytes.len()
        )));
    }
    let payload = &bytes[HEADER..HEADER + length];
    let crc = u32::from_le_bytes(bytes[HEADER + length..].try_into().expect("4 bytes"));
    if crc32fast::hash(payload) != crc {
        return Err(refuse("checksum mismatch (corrupt bytes)"));
    }
    let decoded: Payload<S> =
        postcard::from_bytes(payload).map_err(|e| refuse(&format!("undecodable ({e})")))?;
    if decoded.guid != id.guid {
        return Err(refuse(&format!(
            "saved by model {} but this is {}",
            decoded.guid, id.guid
        )));
    }
    decoded
        .fmu
        .check_decoded()
        .map_err(|e| refuse(&e.message))?;
    Ok(decoded.fmu)
}

#[cfg(test)]
mod tests {
    use super::FmuState;

    /// A foreign pointer to a small object must have only its first eight bytes read: the
    /// tag lay 4392 bytes in, past the end of such an object (AddressSanitizer saw it).
    #[test]
    fn the_tag_is_the_first_eight_bytes() {
        assert_eq!(std::mem::offset_of!(FmuState<[u64; 512]>, tag), 0);
    }
}
