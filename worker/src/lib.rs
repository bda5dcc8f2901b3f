//! # mpcontact worker
//!
//! The worker process of a sweep: attaches to a run as a client of the
//! `<run>/work` pull queue, announces itself, solves the cases it is sent
//! with operators kept resident per (material, grid), and returns scalars
//! (and fields when asked) in shared memory. A thin shell around
//! [`solver::solve_case`]; all names and the wire format come from
//! `protocol`.
//!
//! It exits cleanly when the coordinator answers `Done`, and on its own when
//! the coordinator's node disappears (checked on every timed-wait timeout).
//!
//! The case key is the coordinator's type (`K`): the worker returns it
//! unchanged with the result and never looks inside it.

pub mod heartbeat;
pub mod kernel_store;

use std::collections::HashSet;
use std::fmt::{Debug, Display};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use anyhow::{anyhow, bail, Context};
use iceoryx2::pending_response::PendingResponse;
use iceoryx2::port::client::Client;
use iceoryx2::port::listener::{Listener, ListenerWaitError};
use iceoryx2::port::notifier::Notifier;
use iceoryx2::prelude::*;
use protocol::{
    CaseAssignment, CheckFinite, Envelope, Failure, Ready, ResultHeader, ToCoord, ToWorker,
    FIELD_NAMES,
};
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use solver::stress_summary::{StressCache, StressRequest, StressScalars};
use solver::{solve_case, CaseScalars, CaseSpec, KernelCache, KernelKey};

/// Case specification as it travels on the wire: the case, and what of
/// its stresses below the surface to compute after the solve (`[stress]`).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WireSpec {
    /// The case.
    pub case: CaseSpec,
    /// With `[stress]`: the stresses to compute from the solved tractions.
    pub stress: Option<StressRequest>,
}

impl From<CaseSpec> for WireSpec {
    fn from(case: CaseSpec) -> Self {
        WireSpec { case, stress: None }
    }
}

/// Result scalars as they travel on the wire: the solver's scalars, checked
/// for NaN/∞ in the values a results row reports, and the stress scalars
/// when the assignment asked for them.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct WireScalars(pub CaseScalars, pub Option<StressScalars>);

impl CheckFinite for WireScalars {
    fn first_non_finite(&self) -> Option<String> {
        let s = &self.0;
        let named = [
            ("contact_radius_m", s.contact_radius_m),
            ("stick_radius_m", s.stick_radius_m),
            ("mu_a_contact_radius_m", s.mu_a_contact_radius_m),
            ("mu_a_stick_radius_m", s.mu_a_stick_radius_m),
            ("pressure_hertz_misfit", s.pressure_hertz_misfit),
            ("delta_t_m", s.delta_t_m),
            ("delta_z_m", s.delta_z_m),
            ("p_max_pa", s.p_max_pa),
            ("contact_area_m2", s.contact_area_m2),
            ("stick_area_m2", s.stick_area_m2),
            ("k_e", s.k_e),
            ("mu_a", s.mu_a.unwrap_or(0.0)),
            ("contact_radius_cells_m", s.contact_radius_cells_m),
            ("stick_radius_cells_m", s.stick_radius_cells_m),
            ("k_e_cells", s.k_e_cells),
            ("mu_a_cells", s.mu_a_cells.unwrap_or(0.0)),
        ];
        if let Some((k, _)) = named.iter().find(|(_, v)| !v.is_finite()) {
            return Some(k.to_string());
        }
        let st = self.1.as_ref()?;
        let mut located: Vec<(&str, f64)> = Vec::new();
        for state in &st.states {
            located.push(("stress.max_von_mises", state.max_von_mises.value_pa));
            located.push(("stress.max_tresca", state.max_tresca.value_pa));
            located.push(("stress.max_principal", state.max_principal.value_pa));
            if let Some(l) = state.surface_peak_along_force {
                located.push(("stress.surface_peak_along_force", l.value_pa));
            }
        }
        if let Some(l) = st.crossland {
            located.push(("stress.crossland", l.value_pa));
        }
        located.push(("stress.swt", st.swt.value_pa));
        located
            .iter()
            .find(|(_, v)| !v.is_finite())
            .map(|(k, _)| k.to_string())
    }
}

/// What a case key must be to travel: the worker only clones, displays (in
/// logs and fault-injection hooks) and sends it back.
pub trait WireKey: Clone + Debug + Display + Serialize + DeserializeOwned {}
impl<K: Clone + Debug + Display + Serialize + DeserializeOwned> WireKey for K {}

/// Coordinator → worker message of this build, for case keys `K`.
pub type CoordMessage<K> = ToWorker<K, WireSpec>;
/// Worker → coordinator message of this build, for case keys `K`.
pub type WorkerMessage<K> = ToCoord<K, WireScalars>;

/// How long a worker waits for the work service to appear at start.
const ATTACH_TIMEOUT: Duration = Duration::from_secs(20);
/// Timed-wait period; on each timeout the coordinator's liveness is checked.
const WAIT_PERIOD: Duration = Duration::from_millis(500);

type WorkClient = Client<ipc::Service, [u8], (), [u8], ()>;
type Pending = PendingResponse<ipc::Service, [u8], (), [u8], ()>;

/// Everything a worker holds while attached to a run.
struct Attached {
    run_id: String,
    cfg: Config,
    index: usize,
    node: Node<ipc::Service>,
    client: WorkClient,
    notifier: Notifier<ipc::Service>,
    listener: Listener<ipc::Service>,
}

/// How a wait for the coordinator's answer ended.
enum Answer<K> {
    Message(Box<CoordMessage<K>>),
    /// The coordinator is gone; why the worker concluded so.
    CoordinatorGone(&'static str),
}

/// Consecutive checks in which the coordinator's node must be missing from
/// the node list before a worker concludes it is gone (one check per
/// `WAIT_PERIOD` without an answer). Workers have twice left a live run
/// saying it was gone (paper sweeps during #15; which check fired was not
/// logged then), so the one check that can be transient is repeated.
const UNLISTED_CHECKS: u32 = 3;

pub use protocol::EXIT_LEFT_WAITING;

/// How a worker's service ended (when it did not fail).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorkerEnd {
    /// The coordinator said `Done`.
    Done,
    /// The coordinator looked gone while this worker waited for an answer
    /// (so it held no case); its process should exit with
    /// [`protocol::EXIT_LEFT_WAITING`].
    CoordinatorGone,
}

/// Attach to run `run_id` as worker `worker_index`, solve cases until the
/// coordinator says `Done` (or disappears), then detach. Returns an error
/// only when attaching fails or the coordinator rejects this worker. `K` is
/// the coordinator's case key type.
pub fn run_worker<K: WireKey>(run_id: &str, worker_index: usize) -> anyhow::Result<WorkerEnd> {
    let w = attach(run_id, worker_index)?;
    // The solver's loops beat for this worker while it computes.
    let heartbeat = std::rc::Rc::new(std::cell::RefCell::new(heartbeat::Heartbeat::open(
        run_id,
        worker_index,
    )?));
    let ticking = heartbeat.clone();
    solver::set_tick_hook(Some(Box::new(move || ticking.borrow_mut().tick())));
    let mut cache = kernel_store::FileStore::cache();
    let mut keys: HashSet<KernelKey> = HashSet::new();
    // The stress plan and surface plane of the last material and grid
    // (`[stress]`), shared by the cases that follow.
    let mut stress_cache = StressCache::new();
    let mut next: WorkerMessage<K> = ToCoord::Ready(Ready {
        worker_index: worker_index as u32,
        pid: std::process::id(),
    });
    let mut fields_buf: Option<solver::Fields> = None;
    loop {
        let pending = w.send(&next, fields_buf.as_ref())?;
        let answer = match w.wait_answer::<K>(&pending)? {
            Answer::Message(m) => Ok(*m),
            Answer::CoordinatorGone(why) => Err(why),
        };
        match answer {
            Err(why) => {
                eprintln!(
                    "worker {worker_index}: coordinator of run {run_id} is gone ({why}); exiting"
                );
                return Ok(WorkerEnd::CoordinatorGone);
            }
            Ok(ToWorker::Done) => return Ok(WorkerEnd::Done),
            Ok(ToWorker::Rejected { reason }) => {
                bail!("worker {worker_index}: rejected by the coordinator: {reason}")
            }
            Ok(ToWorker::Case(case)) => {
                drop(pending);
                heartbeat.borrow_mut().beat();
                #[cfg(feature = "fault-injection")]
                fault_injection::before_solve(&case.key.to_string());
                let (msg, fields) = solve_one(
                    &case,
                    worker_index,
                    &mut cache,
                    &mut keys,
                    &mut stress_cache,
                );
                next = msg;
                fields_buf = fields;
            }
        }
    }
}

#[cfg(feature = "fault-injection")]
pub mod fault_injection;

/// Test hook (fault injection): how long the coordinator's journal should
/// sleep after each sync to play a slow disk
/// (`fault_injection::JOURNAL_SYNC_DELAY_ENV`). Always `None` in a build
/// without the `fault-injection` feature, so a shipped binary has no hook.
pub fn test_journal_sync_delay() -> Option<Duration> {
    #[cfg(feature = "fault-injection")]
    {
        fault_injection::journal_sync_delay()
    }
    #[cfg(not(feature = "fault-injection"))]
    {
        None
    }
}

fn solve_one<K: WireKey>(
    case: &CaseAssignment<K, WireSpec>,
    worker_index: usize,
    cache: &mut KernelCache,
    keys: &mut HashSet<KernelKey>,
    stress_cache: &mut StressCache,
) -> (WorkerMessage<K>, Option<solver::Fields>) {
    let start = Instant::now();
    keys.insert(KernelKey::of(&case.spec.case));
    let solved = solve_case(&case.spec.case, cache).and_then(|out| {
        // The stresses below the surface, from the solved tractions: the
        // same function `mpcontact solve` calls, on the same inputs.
        let stress = match &case.spec.stress {
            Some(req) => Some(
                solver::stress_summary::compute_with(
                    req,
                    &case.spec.case,
                    &out.scalars,
                    &out.fields,
                    &out.turning,
                    stress_cache,
                )?
                .scalars,
            ),
            None => None,
        };
        Ok((out, stress))
    });
    let solve_seconds = start.elapsed().as_secs_f64();
    match solved {
        Ok((out, stress)) => {
            let want = case.want_fields;
            let header = ResultHeader {
                key: case.key.clone(),
                worker_index: worker_index as u32,
                grid_n: case.grid_n,
                solve_seconds,
                kernels_built: cache.builds() as u64,
                kernels_loaded: cache.loads() as u64,
                kernels_resident: keys.len() as u64,
                sent_unix_ns: 0,
                field_names: if want {
                    FIELD_NAMES.iter().map(|s| s.to_string()).collect()
                } else {
                    Vec::new()
                },
                scalars: WireScalars(out.scalars, stress),
            };
            (ToCoord::Result(header), want.then_some(out.fields))
        }
        Err(e) => (
            ToCoord::Failed(Failure {
                key: case.key.clone(),
                worker_index: worker_index as u32,
                error: e.to_string(),
                solve_seconds,
                kernels_built: cache.builds() as u64,
            }),
            None,
        ),
    }
}

fn unix_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos() as u64)
        .unwrap_or(0)
}

fn attach(run_id: &str, index: usize) -> anyhow::Result<Attached> {
    let cfg = protocol::ipc_config()?;
    let node = protocol::create_node(
        &cfg,
        &protocol::worker_node_name(run_id, index),
        SignalHandlingMode::Disabled,
    )?;
    let deadline = Instant::now() + ATTACH_TIMEOUT;
    let service = loop {
        match protocol::work_service_port(&node, run_id, 0, false) {
            Ok(s) => break s,
            Err(e) if Instant::now() > deadline => {
                return Err(anyhow!(e)).context(format!("attaching to run {run_id}"))
            }
            Err(_) => std::thread::sleep(Duration::from_millis(50)),
        }
    };
    let client = service
        .client_builder()
        .initial_max_slice_len(4096)
        .allocation_strategy(AllocationStrategy::PowerOfTwo)
        .create()
        .map_err(|e| anyhow!("cannot create the work client: {e:?}"))?;
    let notifier =
        protocol::event_service_port(&node, &protocol::to_coord_event(run_id), 0, false)?
            .notifier_builder()
            .create()
            .map_err(|e| anyhow!("cannot create notifier: {e:?}"))?;
    let listener =
        protocol::event_service_port(&node, &protocol::to_workers_event(run_id), 0, false)?
            .listener_builder()
            .create()
            .map_err(|e| anyhow!("cannot create listener: {e:?}"))?;
    Ok(Attached {
        run_id: run_id.to_string(),
        cfg,
        index,
        node,
        client,
        notifier,
        listener,
    })
}

impl Attached {
    /// Encode `msg` (and `fields` after its header) straight into a loaned
    /// request, send it and wake the coordinator.
    fn send<K: WireKey>(
        &self,
        msg: &WorkerMessage<K>,
        fields: Option<&solver::Fields>,
    ) -> anyhow::Result<Pending> {
        let mut msg = msg.clone();
        if let ToCoord::Result(h) = &mut msg {
            h.sent_unix_ns = unix_ns();
        }
        let env = Envelope::new(&self.run_id, msg);
        let header = protocol::encode_header(&env)?;
        let arrays: Vec<&[f64]> = match fields {
            Some(f) => f.named().iter().map(|(_, v)| v.as_slice()).collect(),
            None => Vec::new(),
        };
        let values: usize = arrays.iter().map(|a| a.len()).sum();
        let len = protocol::frame_len(header.len(), values);
        let deadline = Instant::now() + ATTACH_TIMEOUT;
        let pending = loop {
            let mut request = self
                .client
                .loan_slice(len)
                .map_err(|e| anyhow!("cannot loan a request of {len} bytes: {e:?}"))?;
            protocol::encode_into(request.payload_mut(), &header, &arrays)?;
            let pending = request
                .send()
                .map_err(|e| anyhow!("cannot send request: {e:?}"))?;
            // Not delivered (no server connected yet, or it is gone): retry
            // for a while, then give up.
            if pending.number_of_server_connections() > 0 {
                break pending;
            }
            if Instant::now() > deadline {
                bail!(
                    "worker {}: no coordinator is serving run {}",
                    self.index,
                    self.run_id
                );
            }
            drop(pending);
            std::thread::sleep(Duration::from_millis(50));
        };
        self.notifier
            .notify()
            .map_err(|e| anyhow!("cannot notify the coordinator: {e:?}"))?;
        Ok(pending)
    }

    /// Wait for the coordinator's answer to `pending`, checking on every
    /// timeout that the coordinator is still there. Only the absence of an
    /// answer is evidence: a busy coordinator may answer late (a journal on
    /// a slow disk made it 0.6 s: two results at 300 ms per sync before the
    /// wake-up, #33), and it closes a request right after answering it.
    fn wait_answer<K: WireKey>(&self, pending: &Pending) -> anyhow::Result<Answer<K>> {
        let mut unlisted = 0;
        loop {
            if let Some(m) = self.take_answer(pending)? {
                return Ok(Answer::Message(m));
            }
            let woke = match self.listener.timed_wait(|_| {}, WAIT_PERIOD) {
                Ok(n) => n,
                // A signal cut the wait short (a stopped job resumed with
                // SIGCONT, #33 item 4): not a timeout, just look again.
                Err(ListenerWaitError::InterruptSignal) => continue,
                Err(e) => bail!("waiting for the coordinator failed: {e:?}"),
            };
            if woke == 0 {
                if let Some(why) = self.coordinator_gone(pending, &mut unlisted) {
                    // The coordinator sends its answer before it closes the
                    // request, so an answer that arrived after the last look
                    // is still waiting here: #33 item 3 lost five healthy
                    // workers, each with its next case unread in this buffer.
                    if let Some(m) = self.take_answer(pending)? {
                        return Ok(Answer::Message(m));
                    }
                    return Ok(Answer::CoordinatorGone(why));
                }
            }
        }
    }

    /// The coordinator's answer to `pending`, if one has arrived.
    fn take_answer<K: WireKey>(
        &self,
        pending: &Pending,
    ) -> anyhow::Result<Option<Box<CoordMessage<K>>>> {
        let Some(response) = pending
            .receive()
            .map_err(|e| anyhow!("cannot receive response: {e:?}"))?
        else {
            return Ok(None);
        };
        let decoded = protocol::decode_to_worker::<K, WireSpec>(response.payload(), &self.run_id)
            .context("malformed message from the coordinator")?;
        Ok(Some(Box::new(decoded.header.body)))
    }

    /// Why the coordinator is gone, or None while it may still answer. A
    /// request it closed (the caller then looks for an answer once more) or
    /// a node listed dead are final; a node missing from
    /// the list only after `UNLISTED_CHECKS` checks in a row (`unlisted`
    /// counts them): one missing listing is not taken as proof. The reason
    /// goes into the worker's log, so that a false "gone" can be traced.
    fn coordinator_gone(&self, pending: &Pending, unlisted: &mut u32) -> Option<&'static str> {
        self.node.try_cleanup_dead_nodes();
        if !pending.is_connected() {
            return Some("it dropped this worker's request");
        }
        let name = protocol::coord_node_name(&self.run_id);
        match protocol::node_alive(&self.cfg, &name) {
            Ok(Some(false)) => Some("its node is listed dead"),
            Ok(None) => {
                *unlisted += 1;
                (*unlisted >= UNLISTED_CHECKS).then_some("its node is no longer listed")
            }
            // Listed alive, or the list cannot be read: keep waiting.
            Ok(Some(true)) | Err(_) => {
                *unlisted = 0;
                None
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use solver::{Grid, Load, Material, Numerics, Surface};

    fn spec(material: &str, youngs: f64, angle: f64) -> CaseSpec {
        CaseSpec {
            material: Material::isotropic(material, youngs, 0.3).unwrap(),
            surface: Surface::Flat,
            grid: Grid::square(16, 400e-6),
            load: Load {
                indenter_radius_m: 0.2,
                normal_force_n: 6000.0,
                friction: 0.3,
                tangential_ratio: 0.0,
                angle_deg: angle,
            },
            numerics: Numerics {
                coupling: false,
                tolerance: 1e-8,
                tangential_tolerance: 1e-6,
                max_iterations: 2000,
                coupling_tolerance: 1e-6,
                max_coupling_iterations: 5,
                ..Numerics::default()
            },
            history: None,
            indenter: None,
        }
    }

    fn assignment(id: &str, spec: CaseSpec, want_fields: bool) -> CaseAssignment<String, WireSpec> {
        CaseAssignment {
            key: id.into(),
            grid_n: spec.grid.n as u32,
            want_fields,
            attempt: 0,
            spec: spec.into(),
        }
    }

    #[test]
    fn kernel_built_once_per_material_and_grid() {
        let mut cache = KernelCache::new();
        let mut keys = HashSet::new();
        let mut builds = Vec::new();
        for (id, s) in [
            ("A/flat/000.0", spec("A", 130e9, 0.0)),
            ("A/flat/045.0", spec("A", 130e9, 45.0)),
            ("B/flat/000.0", spec("B", 200e9, 0.0)),
            ("A/flat/090.0", spec("A", 130e9, 90.0)),
        ] {
            let (msg, fields) = solve_one(
                &assignment(id, s, false),
                3,
                &mut cache,
                &mut keys,
                &mut StressCache::new(),
            );
            assert!(fields.is_none());
            match msg {
                ToCoord::Result(h) => {
                    assert_eq!(h.worker_index, 3);
                    assert!(h.field_names.is_empty());
                    builds.push((h.kernels_built, h.kernels_resident));
                }
                other => panic!("{id}: {other:?}"),
            }
        }
        assert_eq!(builds, vec![(1, 1), (1, 1), (2, 2), (2, 2)]);
    }

    #[test]
    fn result_carries_all_fields_of_the_grid_when_asked() {
        let mut cache = KernelCache::new();
        let mut keys = HashSet::new();
        let s = spec("A", 130e9, 0.0);
        let (msg, fields) = solve_one(
            &assignment("A/flat/000.0", s, true),
            0,
            &mut cache,
            &mut keys,
            &mut StressCache::new(),
        );
        let ToCoord::Result(h) = msg else {
            panic!("not a result")
        };
        assert_eq!(h.field_names.len(), FIELD_NAMES.len());
        let f = fields.unwrap();
        for (_, v) in f.named() {
            assert_eq!(v.len(), 16 * 16);
        }
        // The encoded message passes the coordinator's validation.
        let arrays: Vec<&[f64]> = f.named().iter().map(|(_, v)| v.as_slice()).collect();
        let bytes =
            protocol::encode_to_vec(&Envelope::new("r", ToCoord::Result(h)), &arrays).unwrap();
        let d = protocol::decode_to_coord::<String, WireScalars>(&bytes, "r").unwrap();
        let ToCoord::Result(h) = &d.header.body else {
            panic!("not a result")
        };
        protocol::validate_result(h, d.field_bytes, |_| {
            Some(protocol::Expected {
                grid_n: 16,
                want_fields: true,
            })
        })
        .unwrap();
        assert_eq!(d.field(0, 256).unwrap().as_ref(), f.p.as_slice());
    }

    #[test]
    fn solver_refusal_becomes_a_failure_message() {
        let mut cache = KernelCache::new();
        let mut keys = HashSet::new();
        let mut s = spec("A", 130e9, 0.0);
        s.load.tangential_ratio = 1.5;
        let (msg, _) = solve_one(
            &assignment("A/flat/000.0", s, false),
            0,
            &mut cache,
            &mut keys,
            &mut StressCache::new(),
        );
        match msg {
            ToCoord::Failed(f) => assert!(f.error.contains("tangential_ratio"), "{}", f.error),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn non_finite_scalars_are_named() {
        let mut s = WireScalars::default();
        assert_eq!(s.first_non_finite(), None);
        s.0.mu_a = Some(f64::NAN);
        assert_eq!(s.first_non_finite().as_deref(), Some("mu_a"));
        s.0.contact_radius_m = f64::INFINITY;
        assert_eq!(s.first_non_finite().as_deref(), Some("contact_radius_m"));
    }
}
