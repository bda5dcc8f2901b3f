//! # mpcontact protocol
//!
//! What the coordinator and its workers say to each other, and nothing else:
//! the message types, the wire format, the protocol version, the service and
//! node names of a run, and the one iceoryx2 [`Config`](iceoryx2::config::Config)
//! every process of a run must share. No physics: case keys, case
//! specifications and result scalars are carried as type parameters chosen
//! by the caller (`K`, `S`, `R`).
//!
//! ## Wire format
//!
//! Every message is one `[u8]` payload of a request or response of the
//! `<run>/work` request-response service:
//!
//! ```text
//! 0..4    magic  b"MPCT"
//! 4..8    PROTOCOL_VERSION, u32 little endian
//! 8..12   header length H, u32 little endian
//! 12..    bincode-2 (serde, standard config) header of H bytes
//!         zero padding up to the next multiple of 8
//!         raw little-endian f64 arrays, one after the other
//! ```
//!
//! The arrays are never serialised per element: they are copied into the
//! shared-memory payload with one `memcpy` each and read back zero-copy when
//! the payload is 8-byte aligned.
//!
//! ```
//! use protocol::{decode_to_worker, encode_to_vec, ToWorker, Envelope};
//! let msg: Envelope<ToWorker<String, String>> = Envelope::new("run1", ToWorker::Done);
//! let bytes = encode_to_vec(&msg, &[]).unwrap();
//! let back = decode_to_worker::<String, String>(&bytes, "run1").unwrap();
//! assert_eq!(back.header.body, ToWorker::Done);
//! ```

mod ipc;
mod messages;
mod wire;

pub use ipc::{
    coord_node_name, create_node, event_service_port, heartbeat_path, ipc_config, ipc_root_dir,
    node_alive, read_heartbeat, to_coord_event, to_workers_event, work_service, work_service_port,
    worker_node_name, write_heartbeat, EventService, IpcSetupError, WorkService, EXIT_LEFT_WAITING,
    HEARTBEAT_INTERVAL, IPC_PREFIX, IPC_PREFIX_ENV, PORT_SLACK,
};
pub use messages::{
    CaseAssignment, CheckFinite, Envelope, Failure, Ready, ResultHeader, ToCoord, ToWorker,
    FIELD_NAMES,
};
pub use wire::{
    decode, decode_to_coord, decode_to_worker, encode_header, encode_into, encode_to_vec,
    frame_len, read_field, validate_result, Decoded, Expected, ProtocolError, HEADER_OFFSET, MAGIC,
};

/// The version of this protocol. Bumped on every change of a message type or
/// of the wire layout; a message carrying another version is rejected.
///
/// 2: the case identity is a caller-chosen key type `K` (was a `case_id` string).
/// 3: the payloads the coordinator sends carry an elastic ball
/// (`CaseSpec::indenter`, `CaseKey::indenter`) and displacement-controlled
/// load paths (`LoadHistory::shifts_m`), and results the cycle's amplitudes,
/// energy ratio and slip regime: a worker of another build is refused
/// cleanly instead of misreading them.
/// 4: a patterned surface in the payload carries its sampling (issue #34).
/// 5: an assignment may ask for the stresses below the surface (`[stress]`,
/// issue #38) and a result carries their scalars.
/// 6: a case's numerics carry the definition of the apparent radii
/// (`solver.radii`, issue #34).
/// 7: a surface may be a scan resampled onto the case's grid
/// (`Surface::Resampled`, issue #61).
/// 8: results carry μa's apparent radii apart from the zones' own radii,
/// and the pressure's distance from Hertz (issue #59); journals of earlier
/// versions, whose `contact_radius_m`/`stick_radius_m` were μa's, do not
/// resume.
pub const PROTOCOL_VERSION: u32 = 8;

#[cfg(test)]
mod tests;
