//! The message types of a run. Owns their shapes only; encoding lives in
//! `wire`, names and iceoryx2 settings in `ipc`. Case keys (`K`), case
//! specifications (`S`) and result scalars (`R`) are chosen by the caller, so
//! this crate knows no physics: a worker echoes the key it was given, and
//! nothing here looks inside it.

use serde::{Deserialize, Serialize};

use crate::PROTOCOL_VERSION;

/// Field arrays a worker may return, in the order they are laid out on the wire
/// when all are requested. Each holds `n * n` values, row-major `[iy][ix]`.
pub const FIELD_NAMES: [&str; 9] = ["p", "qx", "qy", "sx", "sy", "stick", "ux", "uy", "uz"];

/// Every header on the wire: the protocol version (also in the fixed prefix,
/// checked first), the run it belongs to, and the body.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Envelope<T> {
    /// [`PROTOCOL_VERSION`] of the sender.
    pub version: u32,
    /// Run id; a message of another run is rejected.
    pub run_id: String,
    /// The message itself.
    pub body: T,
}

impl<T> Envelope<T> {
    /// An envelope of the current protocol version.
    pub fn new(run_id: &str, body: T) -> Self {
        Envelope {
            version: PROTOCOL_VERSION,
            run_id: run_id.to_string(),
            body,
        }
    }
}

/// Worker → coordinator (requests of `<run>/work`). Each request also asks for
/// the next piece of work: the coordinator answers with a [`ToWorker`].
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ToCoord<K, R> {
    /// First message of a worker.
    Ready(Ready),
    /// A solved case; its field arrays (if any) follow the header.
    Result(ResultHeader<K, R>),
    /// A case the solver refused or failed.
    Failed(Failure<K>),
    /// Liveness while idle or between cases (reserved; the coordinator
    /// answers with the next case like any other request).
    Heartbeat {
        /// Sender.
        worker_index: u32,
    },
}

/// Coordinator → worker (responses of `<run>/work`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum ToWorker<K, S> {
    /// Solve this case.
    Case(CaseAssignment<K, S>),
    /// The run is over: exit.
    Done,
    /// The request was rejected (wrong version, malformed, ...): exit.
    Rejected {
        /// Why, for the worker's log.
        reason: String,
    },
}

/// A worker announcing itself.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Ready {
    /// `k` of `--index K`; also in its node name `<run>-worker-<k>`.
    pub worker_index: u32,
    /// OS process id, for logs and liveness.
    pub pid: u32,
}

/// One case to solve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CaseAssignment<K, S> {
    /// Case identity, chosen by the coordinator; returned unchanged with the result.
    pub key: K,
    /// Grid points per side; every returned field must hold `n * n` values.
    pub grid_n: u32,
    /// Return the field arrays with the result.
    pub want_fields: bool,
    /// How many times this case was dispatched before (0 on the first try).
    pub attempt: u32,
    /// The full specification.
    pub spec: S,
}

/// The header of a solved case; `field_names.len()` arrays of
/// `grid_n * grid_n` f64 follow it on the wire.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ResultHeader<K, R> {
    /// Which case: the key of its [`CaseAssignment`].
    pub key: K,
    /// Who solved it.
    pub worker_index: u32,
    /// Grid points per side of the fields.
    pub grid_n: u32,
    /// Wall time of the solve in the worker, s.
    pub solve_seconds: f64,
    /// Kernels (operators) this worker has computed so far in this run.
    pub kernels_built: u64,
    /// Kernels it has loaded from the kernel store so far (stored by
    /// another worker or an earlier run) instead of computing them.
    #[serde(default)]
    pub kernels_loaded: u64,
    /// Distinct (material, grid) kernels resident in this worker.
    pub kernels_resident: u64,
    /// Nanoseconds since the Unix epoch when the result was ready to send
    /// (for measuring the IPC cost; clocks of one machine).
    pub sent_unix_ns: u64,
    /// Names of the arrays that follow, in order (a subset of [`FIELD_NAMES`]).
    pub field_names: Vec<String>,
    /// The result scalars.
    pub scalars: R,
}

/// A case the worker could not solve.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Failure<K> {
    /// Which case: the key of its [`CaseAssignment`].
    pub key: K,
    /// Who tried.
    pub worker_index: u32,
    /// The solver's error, rendered.
    pub error: String,
    /// Wall time until the failure, s.
    pub solve_seconds: f64,
    /// Kernels this worker has computed so far.
    pub kernels_built: u64,
}

/// Result scalars that can be checked for NaN/∞ before they are recorded.
pub trait CheckFinite {
    /// Name of the first non-finite value, or `None` when all are finite.
    fn first_non_finite(&self) -> Option<String>;
}

impl CheckFinite for f64 {
    fn first_non_finite(&self) -> Option<String> {
        (!self.is_finite()).then(|| "value".to_string())
    }
}

impl CheckFinite for Vec<(String, f64)> {
    fn first_non_finite(&self) -> Option<String> {
        self.iter()
            .find(|(_, v)| !v.is_finite())
            .map(|(k, _)| k.clone())
    }
}
