//! CDR (OMG Common Data Representation, the XCDR1 plain encoding that ROS 2's rmw layers put
//! on the wire and rosbag2 stores): a 4-byte encapsulation header, `00 01 00 00` for
//! little-endian CDR, then the fields in order, each aligned to its own size counted from the
//! end of that header; strings as a u32 length including a NUL, then the bytes and the NUL;
//! sequences as a u32 count then the elements; fixed arrays as the elements alone.
//!
//! The field encoding is `cdr-encoding`'s serde serializer, which does not write the
//! encapsulation header: [`encode`] writes it, [`decode`] checks and strips it. Decoding reads
//! from the slice with bounds checks, so a corrupt length fails instead of allocating it.

use byteorder::{BigEndian, LittleEndian};
use serde::Serialize;
use serde::de::DeserializeOwned;
use thiserror::Error;

/// Encapsulation header of little-endian plain CDR (`CDR_LE`, options 0).
pub const CDR_LE_HEADER: [u8; 4] = [0x00, 0x01, 0x00, 0x00];

/// Why a CDR payload could not be decoded.
#[derive(Debug, Error)]
pub enum CdrError {
    #[error("CDR payload of {0} bytes is shorter than its 4-byte encapsulation header")]
    TooShort(usize),
    #[error(
        "unsupported CDR encapsulation {0:02x} {1:02x} (expected 00 01, plain little-endian CDR, \
         or 00 00, big-endian)"
    )]
    Encapsulation(u8, u8),
    #[error("CDR payload does not decode: {0}")]
    Payload(#[from] cdr_encoding::Error),
    #[error(
        "{left} bytes left over after the message ({used} of {total} used): not this message type?"
    )]
    TrailingBytes {
        left: usize,
        used: usize,
        total: usize,
    },
}

/// The CDR payload of a message: encapsulation header then fields, little-endian.
///
/// Panics only for types CDR cannot express (an `Option`, a sequence of unknown length), which
/// no message type of [`super::messages`] has.
pub fn encode<T: Serialize>(msg: &T) -> Vec<u8> {
    let mut out = Vec::with_capacity(256);
    encode_into(&mut out, msg);
    out
}

/// [`encode`] into a buffer (cleared first), to reuse its allocation.
pub fn encode_into<T: Serialize>(out: &mut Vec<u8>, msg: &T) {
    out.clear();
    encode_append(out, msg);
}

/// [`encode`] appended to `out` (whatever it holds stays in front): for gathering several
/// payloads in one buffer.
pub fn encode_append<T: Serialize>(out: &mut Vec<u8>, msg: &T) {
    out.extend_from_slice(&CDR_LE_HEADER);
    cdr_encoding::to_writer::<T, LittleEndian, _>(&mut *out, msg)
        .expect("ROS message types serialize to CDR");
}

/// Decodes a CDR payload (either byte order). Up to 3 bytes may follow the message (the
/// padding to a multiple of 4 that some rmw layers add); more means a type mismatch.
pub fn decode<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, CdrError> {
    let (msg, used, total) = decode_front(bytes)?;
    let left = total - used;
    if left > 3 {
        return Err(CdrError::TrailingBytes { left, used, total });
    }
    Ok(msg)
}

/// Decodes the leading fields of a payload as `T` and ignores the rest: e.g. the
/// `std_msgs/Header` that every stamped message starts with.
pub fn decode_prefix<T: DeserializeOwned>(bytes: &[u8]) -> Result<T, CdrError> {
    decode_front(bytes).map(|(msg, ..)| msg)
}

/// `T` from the front of the body: (message, bytes used, body length).
fn decode_front<T: DeserializeOwned>(bytes: &[u8]) -> Result<(T, usize, usize), CdrError> {
    let Some(body) = bytes.get(4..) else {
        return Err(CdrError::TooShort(bytes.len()));
    };
    let (msg, used) = match (bytes[0], bytes[1]) {
        (0x00, 0x01) => cdr_encoding::from_bytes::<T, LittleEndian>(body)?,
        (0x00, 0x00) => cdr_encoding::from_bytes::<T, BigEndian>(body)?,
        (a, b) => return Err(CdrError::Encapsulation(a, b)),
    };
    Ok((msg, used, body.len()))
}

#[cfg(test)]
mod tests;
