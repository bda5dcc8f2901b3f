//! Names and the shared iceoryx2 configuration of a run. Every service and
//! node of a run is named here, nowhere else; every process of a run builds
//! its `Config` with [`ipc_config`].

use std::os::unix::fs::{MetadataExt, PermissionsExt};
use std::path::PathBuf;

use iceoryx2::config::Config;
use iceoryx2::node::NodeView;
use iceoryx2::prelude::{
    ipc, Alignment, CallbackProgression, FileName, Node, NodeBuilder, NodeName, NodeState, Path,
    SemanticString, ServiceName, SignalHandlingMode,
};

/// The iceoryx2 prefix of all mpcontact resources (`/dev/shm/mpcontact_…`).
/// A fixed prefix lets the next run clean up after a crashed one.
pub const IPC_PREFIX: &str = "mpcontact_";

/// Environment variable overriding [`IPC_PREFIX`] (it must start with it);
/// used by tests to tell their own shared-memory files apart.
pub const IPC_PREFIX_ENV: &str = "MPCONTACT_IPC_PREFIX";

/// The request-response service of the pull queue: workers are clients, the
/// coordinator is the only server.
pub fn work_service(run_id: &str) -> String {
    format!("{run_id}/work")
}

/// Event service the workers notify after sending a request.
pub fn to_coord_event(run_id: &str) -> String {
    format!("{run_id}/to-coord")
}

/// Event service the coordinator notifies after sending responses.
pub fn to_workers_event(run_id: &str) -> String {
    format!("{run_id}/to-workers")
}

/// Node name of the coordinator.
pub fn coord_node_name(run_id: &str) -> String {
    format!("{run_id}-coord")
}

/// Node name of worker `k`.
pub fn worker_node_name(run_id: &str, k: usize) -> String {
    format!("{run_id}-worker-{k}")
}

fn uid() -> Result<u32, IpcSetupError> {
    Ok(std::fs::metadata("/proc/self")
        .map_err(|e| IpcSetupError(format!("cannot read /proc/self to find the user id: {e}")))?
        .uid())
}

/// The per-user iceoryx2 root directory: `$XDG_RUNTIME_DIR/mpcontact/` when
/// that variable names a directory owned by the user, else
/// `/tmp/mpcontact-<uid>/`. Created with mode 0700; refused when it exists
/// and belongs to someone else or is open to others.
pub fn ipc_root_dir() -> Result<PathBuf, IpcSetupError> {
    let uid = uid()?;
    let xdg = std::env::var_os("XDG_RUNTIME_DIR")
        .map(PathBuf::from)
        .filter(|p| p.is_absolute())
        .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.is_dir() && m.uid() == uid));
    let dir = match xdg {
        Some(base) => base.join("mpcontact"),
        None => PathBuf::from(format!("/tmp/mpcontact-{uid}")),
    };
    match std::fs::create_dir(&dir) {
        Ok(()) => {
            std::fs::set_permissions(&dir, std::fs::Permissions::from_mode(0o700)).map_err(|e| {
                IpcSetupError(format!("cannot set mode 0700 on {}: {e}", dir.display()))
            })?
        }
        Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {}
        Err(e) => {
            return Err(IpcSetupError(format!(
                "cannot create {}: {e}",
                dir.display()
            )))
        }
    }
    let meta = std::fs::symlink_metadata(&dir)
        .map_err(|e| IpcSetupError(format!("cannot stat {}: {e}", dir.display())))?;
    if !meta.is_dir() || meta.uid() != uid {
        return Err(IpcSetupError(format!(
            "{} is not a directory owned by uid {uid}; remove it or set XDG_RUNTIME_DIR",
            dir.display()
        )));
    }
    if meta.mode() & 0o077 != 0 {
        return Err(IpcSetupError(format!(
            "{} is accessible by other users (mode {:o}); chmod 700 it",
            dir.display(),
            meta.mode() & 0o777
        )));
    }
    Ok(dir)
}

/// Exit status of a worker that left while it waited for an answer,
/// having concluded that the coordinator was gone. Such a worker held no
/// case: one the coordinator had sent it was never started, so the
/// coordinator hands it back without charging it an attempt (#33 item 3: a
/// healthy case was failed for two workers that left this way).
pub const EXIT_LEFT_WAITING: u8 = 3;

/// How often at most a worker beats while it computes (a few times a
/// second: enough to tell a long computation from a hang within a second).
pub const HEARTBEAT_INTERVAL: std::time::Duration = std::time::Duration::from_millis(250);

/// The file worker `worker_index` of run `run_id` beats in while it computes,
/// in the per-user IPC root (0700): 8 bytes, the Unix time in ns of its last
/// sign of life (little endian), rewritten in place.
pub fn heartbeat_path(run_id: &str, worker_index: usize) -> Result<PathBuf, IpcSetupError> {
    Ok(ipc_root_dir()?.join(format!("{run_id}-worker-{worker_index}.beat")))
}

/// Writes a beat (`unix_ns`) into an open heartbeat file.
pub fn write_heartbeat(file: &std::fs::File, unix_ns: u64) -> std::io::Result<()> {
    use std::os::unix::fs::FileExt;
    file.write_all_at(&unix_ns.to_le_bytes(), 0)
}

/// The last beat in a heartbeat file (Unix time, ns), if it holds one.
pub fn read_heartbeat(path: &std::path::Path) -> Option<u64> {
    let bytes = std::fs::read(path).ok()?;
    Some(u64::from_le_bytes(bytes.get(..8)?.try_into().ok()?))
}

/// The iceoryx2 configuration shared by every process of every run: the
/// per-user prefix `mpcontact_u<uid>_` (or `$MPCONTACT_IPC_PREFIX`, which
/// must start with [`IPC_PREFIX`]), per-user root directory
/// [`ipc_root_dir`]. Never reads iceoryx2 config files.
pub fn ipc_config() -> Result<Config, IpcSetupError> {
    let prefix = match std::env::var(IPC_PREFIX_ENV) {
        Ok(p) if p.starts_with(IPC_PREFIX) && p.len() < 64 => p,
        Ok(p) => {
            return Err(IpcSetupError(format!(
                "{IPC_PREFIX_ENV}={p:?} must start with {IPC_PREFIX:?} and be shorter than 64 bytes"
            )))
        }
        // Per user: another user's runs never touch this user's files.
        Err(_) => format!("{IPC_PREFIX}u{}_", uid()?),
    };
    let root = ipc_root_dir()?;
    let mut root_str = root
        .to_str()
        .ok_or_else(|| IpcSetupError(format!("{} is not UTF-8", root.display())))?
        .to_string();
    if !root_str.ends_with('/') {
        root_str.push('/');
    }
    let mut cfg = Config::default();
    cfg.global.prefix = FileName::new(prefix.as_bytes())
        .map_err(|e| IpcSetupError(format!("invalid iceoryx2 prefix {prefix:?}: {e:?}")))?;
    let path = Path::new(root_str.as_bytes())
        .map_err(|e| IpcSetupError(format!("invalid iceoryx2 root {root_str:?}: {e:?}")))?;
    cfg.global.set_root_path(&path);
    Ok(cfg)
}

/// Why the IPC configuration could not be set up.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{0}")]
pub struct IpcSetupError(pub String);

/// The `<run>/work` request-response service (`[u8]` both ways).
pub type WorkService = iceoryx2::service::port_factory::request_response::PortFactory<
    iceoryx2::service::ipc::Service,
    [u8],
    (),
    [u8],
    (),
>;

/// An event service of a run.
pub type EventService =
    iceoryx2::service::port_factory::event::PortFactory<iceoryx2::service::ipc::Service>;

/// Ports and nodes of the work service beyond the worker count: a hand-started
/// worker or a replacement for a dead one.
pub const PORT_SLACK: usize = 8;

fn service_name(name: &str) -> Result<ServiceName, IpcSetupError> {
    ServiceName::new(name)
        .map_err(|e| IpcSetupError(format!("invalid service name {name:?}: {e:?}")))
}

/// Create (coordinator, `create = true`) or open (worker) the pull queue
/// `<run>/work` with the QoS of the notes: one server, no silent overwrites,
/// at most two requests in flight per client, 8-byte aligned payloads.
/// `max_workers` sizes clients and nodes (plus [`PORT_SLACK`]).
pub fn work_service_port(
    node: &Node<ipc::Service>,
    run_id: &str,
    max_workers: usize,
    create: bool,
) -> Result<WorkService, IpcSetupError> {
    let name = service_name(&work_service(run_id))?;
    let builder = node
        .service_builder(&name)
        .request_response::<[u8], [u8]>()
        .request_payload_alignment(Alignment::ALIGN_8)
        .response_payload_alignment(Alignment::ALIGN_8)
        .enable_safe_overflow_for_requests(false)
        .enable_safe_overflow_for_responses(false)
        .max_active_requests_per_client(2)
        .max_loaned_requests(1)
        .max_response_buffer_size(1)
        .max_servers(1);
    if create {
        builder
            .max_clients(max_workers + PORT_SLACK)
            .max_nodes(max_workers + PORT_SLACK + 1)
            .create()
            .map_err(|e| IpcSetupError(format!("cannot create service {name}: {e:?}")))
    } else {
        builder
            .open()
            .map_err(|e| IpcSetupError(format!("cannot open service {name}: {e:?}")))
    }
}

/// Create or open an event service of the run, sized for `max_workers`.
pub fn event_service_port(
    node: &Node<ipc::Service>,
    name: &str,
    max_workers: usize,
    create: bool,
) -> Result<EventService, IpcSetupError> {
    let sname = service_name(name)?;
    let builder = node.service_builder(&sname).event();
    if create {
        builder
            .max_notifiers(max_workers + PORT_SLACK + 1)
            .max_listeners(max_workers + PORT_SLACK + 1)
            .max_nodes(max_workers + PORT_SLACK + 1)
            .create()
            .map_err(|e| IpcSetupError(format!("cannot create event service {name}: {e:?}")))
    } else {
        builder
            .open()
            .map_err(|e| IpcSetupError(format!("cannot open event service {name}: {e:?}")))
    }
}

/// Create a node of the run named `name` with the shared configuration.
pub fn create_node(
    cfg: &Config,
    name: &str,
    signals: SignalHandlingMode,
) -> Result<Node<ipc::Service>, IpcSetupError> {
    let node_name = NodeName::new(name)
        .map_err(|e| IpcSetupError(format!("invalid node name {name:?}: {e:?}")))?;
    let prefix = cfg.global.prefix.to_string();
    let me = uid()?;
    check_global_mgmt(&prefix, me)?;
    let create = || {
        NodeBuilder::new()
            .name(&node_name)
            .config(cfg)
            .signal_handling_mode(signals)
            .create::<ipc::Service>()
    };
    let node = match create() {
        Ok(node) => node,
        // A counter file of ours that iceoryx2 cannot use (left damaged by
        // a crash): ours to recover, once.
        Err(e) if format!("{e:?}").contains("UnableToGenerateUniqueNodeId") => {
            let removed = remove_global_mgmt(&prefix, me);
            eprintln!(
                "note: the iceoryx2 node counter of prefix {prefix} was unusable ({e:?}); removed {removed} file(s) and tried again"
            );
            create().map_err(|e| IpcSetupError(format!("cannot create node {name}: {e:?}")))?
        }
        Err(e) => return Err(IpcSetupError(format!("cannot create node {name}: {e:?}"))),
    };
    restrict_global_mgmt(&prefix, me)?;
    Ok(node)
}

/// Where iceoryx2 keeps its per-prefix node counter (`<prefix>…global_mgmt`,
/// 16 bytes), which it creates world-writable (0666) and never removes.
const SHM_DIR: &str = "/dev/shm";

/// The counter files of `prefix` (normally one).
fn global_mgmt_files(prefix: &str) -> Vec<(std::path::PathBuf, std::fs::Metadata)> {
    let Ok(dir) = std::fs::read_dir(SHM_DIR) else {
        return Vec::new();
    };
    dir.flatten()
        .filter(|e| {
            let name = e.file_name();
            let name = name.to_string_lossy();
            name.starts_with(prefix) && name.ends_with("global_mgmt")
        })
        .filter_map(|e| Some((e.path(), std::fs::symlink_metadata(e.path()).ok()?)))
        .collect()
}

/// How long an empty counter file may stay empty before it counts as left
/// by a crash (iceoryx2 creates it empty and sizes it at once).
const EMPTY_GRACE: std::time::Duration = std::time::Duration::from_secs(1);

/// Before a node is created: a counter file of another user under our
/// prefix is an error that says so (iceoryx2 would hang or fail obscurely);
/// one of ours that stays empty for [`EMPTY_GRACE`] — a crash, or another
/// user emptying it while it was writable — is removed, since iceoryx2
/// waits forever for an empty counter to be initialised.
fn check_global_mgmt(prefix: &str, me: u32) -> Result<(), IpcSetupError> {
    for (path, meta) in global_mgmt_files(prefix) {
        if meta.uid() != me {
            return Err(IpcSetupError(format!(
                "{} belongs to user id {}, not to this user ({me}); another user created it under this user's iceoryx2 prefix. Set {IPC_PREFIX_ENV}={IPC_PREFIX}<something>_ to use another prefix",
                path.display(),
                meta.uid()
            )));
        }
        if meta.len() != 0 {
            continue;
        }
        let since = std::time::Instant::now();
        let mut empty = true;
        while empty && since.elapsed() < EMPTY_GRACE {
            std::thread::sleep(std::time::Duration::from_millis(50));
            empty = std::fs::metadata(&path).is_ok_and(|m| m.len() == 0);
        }
        if empty {
            std::fs::remove_file(&path).map_err(|e| {
                IpcSetupError(format!("cannot remove the empty {}: {e}", path.display()))
            })?;
            eprintln!(
                "note: removed {}: an empty iceoryx2 node counter (left by a crash) would make the run wait forever",
                path.display()
            );
        }
    }
    Ok(())
}

/// Removes this user's counter files of `prefix`; returns how many.
fn remove_global_mgmt(prefix: &str, me: u32) -> usize {
    global_mgmt_files(prefix)
        .into_iter()
        .filter(|(_, m)| m.uid() == me)
        .filter(|(p, _)| std::fs::remove_file(p).is_ok())
        .count()
}

/// After a node is created: the counter file is this user's only (0600).
fn restrict_global_mgmt(prefix: &str, me: u32) -> Result<(), IpcSetupError> {
    for (path, meta) in global_mgmt_files(prefix) {
        if meta.uid() == me && meta.mode() & 0o077 != 0 {
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(0o600)).map_err(
                |e| IpcSetupError(format!("cannot restrict {} to 0600: {e}", path.display())),
            )?;
        }
    }
    Ok(())
}

/// State of the node named `name` under `cfg`: `Some(true)` alive,
/// `Some(false)` present but dead/inaccessible, `None` absent.
pub fn node_alive(cfg: &Config, name: &str) -> Result<Option<bool>, IpcSetupError> {
    let mut found = None;
    Node::<ipc::Service>::list(cfg, |state| {
        let (alive, details) = match &state {
            NodeState::Alive(v) => (true, v.details().clone()),
            NodeState::Dead(v) => (false, v.details().clone()),
            _ => return CallbackProgression::Continue,
        };
        if details.is_some_and(|d| d.name().as_str() == name) {
            found = Some(found.unwrap_or(false) || alive);
        }
        CallbackProgression::Continue
    })
    .map_err(|e| IpcSetupError(format!("cannot list nodes: {e:?}")))?;
    Ok(found)
}
