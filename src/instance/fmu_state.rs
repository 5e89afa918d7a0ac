//! The serialized FMU state: a versioned, checksummed byte string with no pointers, so that
//! a state saved by one instance (or process) restores bit-identically into another.
//!
//! Layout: magic "GRFS" | format version (u16 LE) | payload length (u32 LE) | payload |
//! CRC-32 of the payload (u32 LE). The payload is the postcard encoding of the model's GUID
//! and the instance; a state from another build of the model (other GUID) is refused.

use super::{FmiError, FmiResult, Instance};
use crate::contract::GUID;
use serde::{Deserialize, Serialize};

const MAGIC: &[u8; 4] = b"GRFS";
/// 3: the gear pair keeps the start of the free flight it passes through; 4: that start
/// and the dynamics also keep the constants derived from the parameters (λ, 1/λ, u∞,
/// 1/r_L, 1/I_L) and the bench's sine its amplitudes A/w and A/w²; 5: the solver may keep a
/// Taylor step past the end time and counts its Taylor steps.
const VERSION: u16 = 5;
const HEADER: usize = 4 + 2 + 4;
const TRAILER: usize = 4;

#[derive(Serialize, Deserialize)]
struct Payload {
    guid: String,
    instance: Instance,
}

pub fn serialize(instance: &Instance) -> Vec<u8> {
    let payload = postcard::to_allocvec(&Payload {
        guid: GUID.to_string(),
        instance: instance.snapshot(),
    })
    .expect("an instance always encodes");
    let mut bytes = Vec::with_capacity(HEADER + payload.len() + TRAILER);
    bytes.extend_from_slice(MAGIC);
    bytes.extend_from_slice(&VERSION.to_le_bytes());
    bytes.extend_from_slice(&(payload.len() as u32).to_le_bytes());
    bytes.extend_from_slice(&payload);
    bytes.extend_from_slice(&crc32fast::hash(&payload).to_le_bytes());
    bytes
}

fn refuse(why: &str) -> FmiError {
    FmiError::error(format!("serialized FMU state refused: {why}"))
}

pub fn deserialize(bytes: &[u8]) -> FmiResult<Instance> {
    if bytes.len() < HEADER + TRAILER || &bytes[..4] != MAGIC {
        return Err(refuse("not a GearRattle FMU state (no GRFS header)"));
    }
    let version = u16::from_le_bytes([bytes[4], bytes[5]]);
    if version != VERSION {
        return Err(refuse(&format!(
            "format version {version}, this binary reads version {VERSION}"
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
    let decoded: Payload =
        postcard::from_bytes(payload).map_err(|e| refuse(&format!("undecodable ({e})")))?;
    if decoded.guid != GUID {
        return Err(refuse(&format!(
            "saved by model {} but this is {GUID}",
            decoded.guid
        )));
    }
    Ok(decoded.instance)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stepped() -> Instance {
        let mut i = Instance::new(false);
        i.set_integer(&[crate::contract::vr::excitation], &[1])
            .unwrap();
        i.enter_initialization_mode().unwrap();
        i.exit_initialization_mode().unwrap();
        i.do_step(0.0, 0.01).unwrap();
        i
    }

    #[test]
    fn round_trip_is_exact() {
        let i = stepped();
        let back = deserialize(&serialize(&i)).unwrap();
        assert_eq!(serialize(&back), serialize(&i));
    }

    #[test]
    fn corrupt_or_foreign_bytes_are_refused() {
        let bytes = serialize(&stepped());
        let mut flipped = bytes.clone();
        flipped[HEADER + 3] ^= 1;
        assert!(
            deserialize(&flipped)
                .unwrap_err()
                .message
                .contains("checksum")
        );
        assert!(deserialize(&bytes[..bytes.len() - 1]).is_err());
        assert!(deserialize(b"hello world, not a state").is_err());
        let mut version = bytes.clone();
        version[4] = 9;
        assert!(
            deserialize(&version)
                .unwrap_err()
                .message
                .contains("version")
        );
    }
}
