//! Encoding and decoding of one message payload, and validation of results.
//! Owns the byte layout described in the crate docs; never panics on input,
//! every malformed payload is a [`ProtocolError`].

use std::borrow::Cow;
use std::fmt::Display;

use serde::de::DeserializeOwned;
use serde::Serialize;
use thiserror::Error;

use crate::messages::{CheckFinite, Envelope, ResultHeader, ToCoord, ToWorker, FIELD_NAMES};
use crate::PROTOCOL_VERSION;

/// First four bytes of every payload.
pub const MAGIC: [u8; 4] = *b"MPCT";
/// Offset of the bincode header in a payload.
pub const HEADER_OFFSET: usize = 12;
/// Largest header accepted (bytes); headers are small, fields travel raw.
const MAX_HEADER: usize = 16 << 20;

fn bincode_config() -> impl bincode::config::Config {
    bincode::config::standard().with_limit::<MAX_HEADER>()
}

/// Why a payload was rejected.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum ProtocolError {
    /// Shorter than the fixed prefix or than the header it declares.
    #[error("payload of {len} bytes is too short: {what}")]
    Truncated {
        /// Payload length.
        len: usize,
        /// What did not fit.
        what: String,
    },
    /// Not an mpcontact message.
    #[error("bad magic {0:?}: not an mpcontact message")]
    BadMagic([u8; 4]),
    /// Sent by a peer of another protocol version.
    #[error("protocol version {got} is not supported (this build speaks {expected})")]
    Version {
        /// Version in the message.
        got: u32,
        /// [`PROTOCOL_VERSION`].
        expected: u32,
    },
    /// The bincode header does not decode.
    #[error("malformed header: {0}")]
    Header(String),
    /// The header could not be encoded.
    #[error("cannot encode header: {0}")]
    Encode(String),
    /// Belongs to another run.
    #[error("message of run {got:?} received in run {expected:?}")]
    WrongRun {
        /// Run id in the message.
        got: String,
        /// Our run id.
        expected: String,
    },
    /// A result for a case this run does not know or did not dispatch
    /// (the key as displayed).
    #[error("result for unknown case {0:?}")]
    UnknownCase(String),
    /// Grid size in the result differs from the case's.
    #[error("case {case_id}: grid {got} in result, {expected} expected")]
    Grid {
        /// Case.
        case_id: String,
        /// In the message.
        got: u32,
        /// Of the case.
        expected: u32,
    },
    /// The raw array region does not hold `fields * n²` values.
    #[error("case {case_id}: {got_bytes} bytes of field data, {expected_bytes} expected ({fields} arrays of {n}²)")]
    FieldLength {
        /// Case.
        case_id: String,
        /// Number of arrays declared.
        fields: usize,
        /// Grid points per side.
        n: u32,
        /// Bytes present.
        got_bytes: usize,
        /// Bytes expected.
        expected_bytes: usize,
    },
    /// A field name that is not in [`FIELD_NAMES`], or a repeated one.
    #[error("case {case_id}: unexpected field {name:?}")]
    FieldName {
        /// Case.
        case_id: String,
        /// Offending name.
        name: String,
    },
    /// Fields were requested and not sent, or sent and not requested.
    #[error("case {case_id}: {got} field arrays, {expected} expected")]
    FieldCount {
        /// Case.
        case_id: String,
        /// Arrays in the message.
        got: usize,
        /// Arrays expected.
        expected: usize,
    },
    /// A scalar is NaN or infinite.
    #[error("case {case_id}: scalar {name} is not finite")]
    NonFinite {
        /// Case.
        case_id: String,
        /// Which scalar.
        name: String,
    },
    /// A timing or counter is impossible (negative or non-finite seconds).
    #[error("case {case_id}: invalid {what}")]
    Invalid {
        /// Case.
        case_id: String,
        /// Which value.
        what: String,
    },
    /// The destination buffer has the wrong size.
    #[error("buffer of {got} bytes, frame needs {expected}")]
    BufferSize {
        /// Given.
        got: usize,
        /// Needed.
        expected: usize,
    },
}

/// Encode a header (envelope) with bincode; the bytes go to [`encode_into`].
pub fn encode_header<T: Serialize>(envelope: &Envelope<T>) -> Result<Vec<u8>, ProtocolError> {
    let bytes = bincode::serde::encode_to_vec(envelope, bincode_config())
        .map_err(|e| ProtocolError::Encode(e.to_string()))?;
    if bytes.len() > MAX_HEADER {
        return Err(ProtocolError::Encode(format!(
            "header of {} bytes exceeds {MAX_HEADER}",
            bytes.len()
        )));
    }
    Ok(bytes)
}

fn fields_offset(header_len: usize) -> usize {
    (HEADER_OFFSET + header_len).div_ceil(8) * 8
}

/// Total payload size for a header of `header_len` bytes followed by
/// `values` f64 values.
pub fn frame_len(header_len: usize, values: usize) -> usize {
    fields_offset(header_len) + values * 8
}

/// Write a frame (prefix, header, padding, raw arrays) into `buf`, which must
/// be exactly [`frame_len`] bytes (e.g. a loaned shared-memory slice).
pub fn encode_into(buf: &mut [u8], header: &[u8], fields: &[&[f64]]) -> Result<(), ProtocolError> {
    let values: usize = fields.iter().map(|f| f.len()).sum();
    let expected = frame_len(header.len(), values);
    if buf.len() != expected {
        return Err(ProtocolError::BufferSize {
            got: buf.len(),
            expected,
        });
    }
    buf[0..4].copy_from_slice(&MAGIC);
    buf[4..8].copy_from_slice(&PROTOCOL_VERSION.to_le_bytes());
    buf[8..12].copy_from_slice(&(header.len() as u32).to_le_bytes());
    let end = HEADER_OFFSET + header.len();
    buf[HEADER_OFFSET..end].copy_from_slice(header);
    let start = fields_offset(header.len());
    buf[end..start].fill(0);
    let mut at = start;
    for field in fields {
        let bytes = field.len() * 8;
        write_f64_le(&mut buf[at..at + bytes], field);
        at += bytes;
    }
    Ok(())
}

fn write_f64_le(dst: &mut [u8], src: &[f64]) {
    #[cfg(target_endian = "little")]
    {
        // SAFETY: f64 has no padding and every byte pattern of u8 is valid;
        // on a little-endian target its in-memory bytes are the wire bytes.
        let raw = unsafe { std::slice::from_raw_parts(src.as_ptr().cast::<u8>(), src.len() * 8) };
        dst.copy_from_slice(raw);
    }
    #[cfg(not(target_endian = "little"))]
    for (chunk, v) in dst.chunks_exact_mut(8).zip(src) {
        chunk.copy_from_slice(&v.to_le_bytes());
    }
}

/// Encode a whole message into a new vector (tests, small messages).
pub fn encode_to_vec<T: Serialize>(
    envelope: &Envelope<T>,
    fields: &[&[f64]],
) -> Result<Vec<u8>, ProtocolError> {
    let header = encode_header(envelope)?;
    let values: usize = fields.iter().map(|f| f.len()).sum();
    let mut buf = vec![0u8; frame_len(header.len(), values)];
    encode_into(&mut buf, &header, fields)?;
    Ok(buf)
}

/// A decoded message: its header and the raw array region, borrowed from
/// the payload.
#[derive(Debug)]
pub struct Decoded<'a, T> {
    /// The envelope (version and run already checked).
    pub header: Envelope<T>,
    /// Bytes of the f64 arrays (possibly empty).
    pub field_bytes: &'a [u8],
}

impl<T> Decoded<'_, T> {
    /// Number of f64 values in the array region (trailing partial bytes ignored;
    /// [`validate_result`] rejects them).
    pub fn values(&self) -> usize {
        self.field_bytes.len() / 8
    }

    /// Array `index` of `len` values, see [`read_field`].
    pub fn field(&self, index: usize, len: usize) -> Option<Cow<'_, [f64]>> {
        read_field(self.field_bytes, index, len)
    }
}

/// Array `index` of `len` values from an array region: borrowed zero-copy
/// when it is 8-byte aligned on a little-endian machine, copied otherwise.
/// `None` when the region is too short.
pub fn read_field(field_bytes: &[u8], index: usize, len: usize) -> Option<Cow<'_, [f64]>> {
    let start = index.checked_mul(len)?.checked_mul(8)?;
    let end = start.checked_add(len.checked_mul(8)?)?;
    let bytes = field_bytes.get(start..end)?;
    #[cfg(target_endian = "little")]
    {
        // SAFETY: every 8-byte pattern is a valid f64; align_to only
        // returns a middle part that is correctly aligned.
        let (head, mid, tail) = unsafe { bytes.align_to::<f64>() };
        if head.is_empty() && tail.is_empty() {
            return Some(Cow::Borrowed(mid));
        }
    }
    Some(Cow::Owned(
        bytes
            .chunks_exact(8)
            .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
            .collect(),
    ))
}

/// Decode and check the fixed prefix, the version and the run id of any message.
pub fn decode<'a, T: DeserializeOwned>(
    payload: &'a [u8],
    run_id: &str,
) -> Result<Decoded<'a, T>, ProtocolError> {
    if payload.len() < HEADER_OFFSET {
        return Err(ProtocolError::Truncated {
            len: payload.len(),
            what: "fixed prefix".into(),
        });
    }
    let magic: [u8; 4] = [payload[0], payload[1], payload[2], payload[3]];
    if magic != MAGIC {
        return Err(ProtocolError::BadMagic(magic));
    }
    let version = u32::from_le_bytes([payload[4], payload[5], payload[6], payload[7]]);
    if version != PROTOCOL_VERSION {
        return Err(ProtocolError::Version {
            got: version,
            expected: PROTOCOL_VERSION,
        });
    }
    let header_len =
        u32::from_le_bytes([payload[8], payload[9], payload[10], payload[11]]) as usize;
    let start = fields_offset(header_len);
    if header_len > MAX_HEADER || payload.len() < start {
        return Err(ProtocolError::Truncated {
            len: payload.len(),
            what: format!("header of {header_len} bytes"),
        });
    }
    let header_bytes = &payload[HEADER_OFFSET..HEADER_OFFSET + header_len];
    let (header, used): (Envelope<T>, usize) =
        bincode::serde::decode_from_slice(header_bytes, bincode_config())
            .map_err(|e| ProtocolError::Header(e.to_string()))?;
    if used != header_len {
        return Err(ProtocolError::Header(format!(
            "{} trailing bytes after the header",
            header_len - used
        )));
    }
    if header.version != PROTOCOL_VERSION {
        return Err(ProtocolError::Version {
            got: header.version,
            expected: PROTOCOL_VERSION,
        });
    }
    if header.run_id != run_id {
        return Err(ProtocolError::WrongRun {
            got: header.run_id,
            expected: run_id.to_string(),
        });
    }
    Ok(Decoded {
        header,
        field_bytes: &payload[start..],
    })
}

/// Decode a worker → coordinator message.
pub fn decode_to_coord<'a, K: DeserializeOwned, R: DeserializeOwned>(
    payload: &'a [u8],
    run_id: &str,
) -> Result<Decoded<'a, ToCoord<K, R>>, ProtocolError> {
    decode(payload, run_id)
}

/// Decode a coordinator → worker message (no arrays allowed).
pub fn decode_to_worker<'a, K: DeserializeOwned + Display, S: DeserializeOwned>(
    payload: &'a [u8],
    run_id: &str,
) -> Result<Decoded<'a, ToWorker<K, S>>, ProtocolError> {
    let d = decode::<ToWorker<K, S>>(payload, run_id)?;
    if !d.field_bytes.is_empty() {
        return Err(ProtocolError::Header(format!(
            "{} unexpected bytes after a coordinator message",
            d.field_bytes.len()
        )));
    }
    if let ToWorker::Case(c) = &d.header.body {
        if c.grid_n == 0 {
            return Err(ProtocolError::Invalid {
                case_id: c.key.to_string(),
                what: format!("grid size (n = {})", c.grid_n),
            });
        }
    }
    Ok(d)
}

/// What the coordinator expects of a result for one case.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Expected {
    /// Grid points per side.
    pub grid_n: u32,
    /// Whether all [`FIELD_NAMES`] must be present (otherwise none may be).
    pub want_fields: bool,
}

/// Validate a decoded result against what was dispatched: known case, same
/// grid, array region of exactly `fields * n²` values, known field names,
/// finite scalars and timings. `expected` looks a case key up; errors name
/// the case by the key's `Display` text.
pub fn validate_result<K: Display, R: CheckFinite>(
    header: &ResultHeader<K, R>,
    field_bytes: &[u8],
    expected: impl Fn(&K) -> Option<Expected>,
) -> Result<(), ProtocolError> {
    let case_id = &header.key.to_string();
    let exp = expected(&header.key).ok_or_else(|| ProtocolError::UnknownCase(case_id.clone()))?;
    if header.grid_n != exp.grid_n {
        return Err(ProtocolError::Grid {
            case_id: case_id.clone(),
            got: header.grid_n,
            expected: exp.grid_n,
        });
    }
    let want = if exp.want_fields {
        FIELD_NAMES.len()
    } else {
        0
    };
    if header.field_names.len() != want {
        return Err(ProtocolError::FieldCount {
            case_id: case_id.clone(),
            got: header.field_names.len(),
            expected: want,
        });
    }
    for (i, name) in header.field_names.iter().enumerate() {
        if !FIELD_NAMES.contains(&name.as_str()) || header.field_names[..i].contains(name) {
            return Err(ProtocolError::FieldName {
                case_id: case_id.clone(),
                name: name.clone(),
            });
        }
    }
    let n = exp.grid_n as usize;
    let expected_bytes = header.field_names.len() * n * n * 8;
    if field_bytes.len() != expected_bytes {
        return Err(ProtocolError::FieldLength {
            case_id: case_id.clone(),
            fields: header.field_names.len(),
            n: exp.grid_n,
            got_bytes: field_bytes.len(),
            expected_bytes,
        });
    }
    if !header.solve_seconds.is_finite() || header.solve_seconds < 0.0 {
        return Err(ProtocolError::Invalid {
            case_id: case_id.clone(),
            what: format!("solve_seconds = {}", header.solve_seconds),
        });
    }
    if let Some(name) = header.scalars.first_non_finite() {
        return Err(ProtocolError::NonFinite {
            case_id: case_id.clone(),
            name,
        });
    }
    Ok(())
}
