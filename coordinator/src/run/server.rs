//! The coordinator's side of the IPC: the single server of `<run>/work`,
//! worker processes, dispatch, liveness. Waits on a WaitSet (the to-coord
//! event plus an interval for liveness checks), never busy-polls. Every
//! result is validated, its fields written and its record journalled before
//! the worker gets its next answer (the acknowledgement).

use std::collections::{BTreeMap, HashMap, HashSet};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use anyhow::{anyhow, bail, Context};
use iceoryx2::active_request::ActiveRequest;
use iceoryx2::node::NodeView;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::server::Server;
use iceoryx2::prelude::*;
use iceoryx2::waitset::WaitSetRunResult;
use protocol::{CaseAssignment, Envelope, Expected, ToCoord, ToWorker};
use worker::{WireScalars, WireSpec};

use super::journal::{Journal, Line, Record};
use super::output;
use super::plan::{CaseState, Plan};
use super::progress::Progress;
use super::{IpcStats, WorkerSummary};

/// Liveness check period.
const TICK: Duration = Duration::from_millis(500);
/// How long workers get to exit after `Done`.
const EXIT_GRACE: Duration = Duration::from_secs(10);
/// Dispatches of one case before it is marked failed (its workers died).
const MAX_ATTEMPTS: u32 = 2;

type Active = ActiveRequest<ipc::Service, [u8], (), [u8], ()>;

struct Slot {
    child: Option<Child>,
    registered: bool,
    held: Option<Active>,
    in_flight: Option<usize>,
    keys: HashSet<solver::KernelKey>,
    stats: WorkerSummary,
    dead: bool,
    done_sent: bool,
}

impl Slot {
    fn new(child: Option<Child>) -> Self {
        Slot {
            child,
            registered: false,
            held: None,
            in_flight: None,
            keys: HashSet::new(),
            stats: WorkerSummary::default(),
            dead: false,
            done_sent: false,
        }
    }
}

/// Inputs of a session.
pub struct SessionArgs<'a> {
    /// Run id.
    pub run_id: &'a str,
    /// Workers to spawn.
    pub workers: usize,
    /// Binary to spawn them with.
    pub exe: &'a Path,
    /// Output directory (fields, worker logs).
    pub out_dir: &'a Path,
    /// Ask workers for fields and write them.
    pub save_fields: bool,
    /// Progress reporter.
    pub progress: &'a Progress,
    /// Floor of the per-case deadline (`run.case_timeout_s`).
    pub case_timeout: Duration,
}

/// What a session measured, for the summary.
pub struct SessionStats {
    /// By worker index.
    pub per_worker: BTreeMap<String, WorkerSummary>,
    /// IPC cost by grid size.
    pub ipc: Vec<IpcStats>,
    /// Rejected messages.
    pub rejected: usize,
}

/// One run's IPC endpoints and worker table.
pub struct Session<'a> {
    args: SessionArgs<'a>,
    cfg: Config,
    node: Node<ipc::Service>,
    server: Server<ipc::Service, [u8], (), [u8], ()>,
    listener: Option<Listener<ipc::Service>>,
    notifier: Notifier<ipc::Service>,
    slots: BTreeMap<usize, Slot>,
    next_index: usize,
    spawns_left: usize,
    rejected: usize,
    ipc_ms: BTreeMap<u32, (Vec<f64>, Vec<f64>, usize)>,
    /// Longest dispatch → record time of a case seen so far.
    longest_case: Duration,
}

fn unix_ns() -> u64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos() as u64)
        .unwrap_or(0)
}

impl<'a> Session<'a> {
    /// Create the node and services of the run and spawn the workers.
    pub fn start(args: SessionArgs<'a>) -> anyhow::Result<Self> {
        let cfg = protocol::ipc_config()?;
        let node = protocol::create_node(
            &cfg,
            &protocol::coord_node_name(args.run_id),
            SignalHandlingMode::HandleTerminationRequests,
        )?;
        node.try_cleanup_dead_nodes();
        let work = protocol::work_service_port(&node, args.run_id, args.workers, true)?;
        let server = work
            .server_builder()
            .initial_max_slice_len(4096)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(|e| anyhow!("cannot create the work server: {e:?}"))?;
        let listener = protocol::event_service_port(
            &node,
            &protocol::to_coord_event(args.run_id),
            args.workers,
            true,
        )?
        .listener_builder()
        .create()
        .map_err(|e| anyhow!("cannot create listener: {e:?}"))?;
        let notifier = protocol::event_service_port(
            &node,
            &protocol::to_workers_event(args.run_id),
            args.workers,
            true,
        )?
        .notifier_builder()
        .create()
        .map_err(|e| anyhow!("cannot create notifier: {e:?}"))?;
        let mut s = Session {
            spawns_left: args.workers * 2 + 2,
            args,
            cfg,
            node,
            server,
            listener: Some(listener),
            notifier,
            slots: BTreeMap::new(),
            next_index: 0,
            rejected: 0,
            ipc_ms: BTreeMap::new(),
            longest_case: Duration::ZERO,
        };
        for _ in 0..s.args.workers {
            s.spawn()?;
        }
        Ok(s)
    }

    fn spawn(&mut self) -> anyhow::Result<()> {
        let k = self.next_index;
        self.next_index += 1;
        self.spawns_left = self.spawns_left.saturating_sub(1);
        let log_dir = self.args.out_dir.join("worker-logs");
        std::fs::create_dir_all(&log_dir)?;
        let log = std::fs::File::create(log_dir.join(format!("worker-{k}.log")))?;
        let child = Command::new(self.args.exe)
            .args([
                "worker",
                "--run",
                self.args.run_id,
                "--index",
                &k.to_string(),
            ])
            .stdin(Stdio::null())
            .stdout(log.try_clone()?)
            .stderr(log)
            .spawn()
            .with_context(|| format!("while starting worker {k} ({})", self.args.exe.display()))?;
        self.slots.insert(k, Slot::new(Some(child)));
        Ok(())
    }

    /// Serve until every case is recorded.
    pub fn serve(
        &mut self,
        plan: &mut Plan,
        journal: &mut Journal,
        records: &mut BTreeMap<String, Record>,
    ) -> anyhow::Result<()> {
        let listener = self
            .listener
            .take()
            .ok_or_else(|| anyhow!("serve called twice"))?;
        let result = self.serve_with(&listener, plan, journal, records);
        self.listener = Some(listener);
        result
    }

    fn serve_with(
        &mut self,
        listener: &Listener<ipc::Service>,
        plan: &mut Plan,
        journal: &mut Journal,
        records: &mut BTreeMap<String, Record>,
    ) -> anyhow::Result<()> {
        let waitset = WaitSetBuilder::new()
            .create::<ipc::Service>()
            .map_err(|e| anyhow!("cannot create waitset: {e:?}"))?;
        let _event = waitset
            .attach_notification(listener)
            .map_err(|e| anyhow!("cannot attach listener: {e:?}"))?;
        let _tick = waitset
            .attach_interval(TICK)
            .map_err(|e| anyhow!("cannot attach interval: {e:?}"))?;
        let mut last_tick = Instant::now();
        let mut finished_at: Option<Instant> = None;
        loop {
            match waitset.wait_and_process_once(|_| CallbackProgression::Continue) {
                Ok(WaitSetRunResult::TerminationRequest | WaitSetRunResult::Interrupt) => {
                    bail!("interrupted; the journal keeps what was recorded (use --resume)")
                }
                Ok(_) => {}
                Err(e) => bail!("waiting failed: {e:?}"),
            }
            let _ = listener.try_wait(|_| {});
            self.drain(plan, journal, records)?;
            if last_tick.elapsed() >= TICK {
                last_tick = Instant::now();
                self.check_liveness(plan, journal, records)?;
            }
            self.serve_held(plan)?;
            if plan.remaining() == 0 {
                let started = *finished_at.get_or_insert_with(Instant::now);
                if self.all_exited() || started.elapsed() > EXIT_GRACE {
                    return Ok(());
                }
            }
        }
    }

    fn all_exited(&mut self) -> bool {
        self.slots.values_mut().all(|s| {
            s.dead
                || match &mut s.child {
                    Some(c) => matches!(c.try_wait(), Ok(Some(_))),
                    None => s.done_sent,
                }
        })
    }

    fn drain(
        &mut self,
        plan: &mut Plan,
        journal: &mut Journal,
        records: &mut BTreeMap<String, Record>,
    ) -> anyhow::Result<()> {
        let mut answered = false;
        while let Some(active) = self
            .server
            .receive()
            .map_err(|e| anyhow!("receive failed: {e:?}"))?
        {
            let received_ns = unix_ns();
            let payload_len = active.payload().len();
            let decoded =
                protocol::decode_to_coord::<WireScalars>(active.payload(), self.args.run_id);
            let msg = match decoded {
                Ok(d) => {
                    let body = d.header.body;
                    let worker = match &body {
                        ToCoord::Ready(r) => r.worker_index,
                        ToCoord::Result(h) => h.worker_index,
                        ToCoord::Failed(f) => f.worker_index,
                        ToCoord::Heartbeat { worker_index } => *worker_index,
                    } as usize;
                    let slot = self.slots.entry(worker).or_insert_with(|| Slot::new(None));
                    if slot.dead {
                        // A worker we declared dead came back: tell it to go.
                        self.rejected += 1;
                        let _ = respond(
                            &active,
                            self.args.run_id,
                            &ToWorker::Rejected {
                                reason: "this worker was declared dead".into(),
                            },
                        );
                        answered = true;
                        continue;
                    }
                    slot.registered = true;
                    let in_flight = slot.in_flight.take();
                    match body {
                        ToCoord::Result(h) => {
                            self.record_result(
                                plan,
                                journal,
                                records,
                                worker,
                                h,
                                d.field_bytes,
                                (received_ns, payload_len),
                            )?;
                        }
                        ToCoord::Failed(f) => {
                            if let Some(i) = plan.index_of(&f.case_id) {
                                if plan.cases[i].state != CaseState::Done {
                                    let rec = Record {
                                        case_id: f.case_id.clone(),
                                        status: "failed".into(),
                                        error: Some(f.error.clone()),
                                        worker: worker as u32,
                                        seconds: f.solve_seconds,
                                        kernel_builds: f.kernel_builds,
                                        scalars: None,
                                    };
                                    self.commit(plan, journal, records, i, worker, rec)?;
                                }
                            }
                        }
                        ToCoord::Ready(_) | ToCoord::Heartbeat { .. } => {}
                    }
                    // Whatever this worker had in flight and did not report goes back.
                    if let Some(i) = in_flight {
                        if matches!(plan.cases[i].state, CaseState::InFlight { worker: w, .. } if w == worker)
                        {
                            // Handed back, not crashed on: not an attempt.
                            plan.cases[i].state = CaseState::Pending;
                            plan.cases[i].attempts = plan.cases[i].attempts.saturating_sub(1);
                        }
                    }
                    worker
                }
                Err(e) => {
                    self.rejected += 1;
                    self.args.progress.note(&format!("rejected a message: {e}"));
                    let _ = respond(
                        &active,
                        self.args.run_id,
                        &ToWorker::Rejected {
                            reason: e.to_string(),
                        },
                    );
                    answered = true;
                    continue;
                }
            };
            answered |= self.assign(plan, msg, active)?;
        }
        if answered {
            let _ = self.notifier.notify();
        }
        Ok(())
    }

    #[allow(clippy::too_many_arguments)]
    fn record_result(
        &mut self,
        plan: &mut Plan,
        journal: &mut Journal,
        records: &mut BTreeMap<String, Record>,
        worker: usize,
        h: protocol::ResultHeader<WireScalars>,
        field_bytes: &[u8],
        (received_ns, payload_len): (u64, usize),
    ) -> anyhow::Result<()> {
        let Some(i) = plan.index_of(&h.case_id) else {
            self.rejected += 1;
            self.args.progress.note(&format!(
                "rejected: result for unknown case {:?}",
                h.case_id
            ));
            return Ok(());
        };
        if plan.cases[i].state == CaseState::Done {
            self.rejected += 1;
            self.args
                .progress
                .note(&format!("ignored a duplicate result for {}", h.case_id));
            return Ok(());
        }
        let want_fields = self.args.save_fields;
        let n = plan.cases[i].spec.grid.n as u32;
        if let Err(e) = protocol::validate_result(&h, field_bytes, |_| {
            Some(Expected {
                grid_n: n,
                want_fields,
            })
        }) {
            self.rejected += 1;
            self.args.progress.note(&format!("rejected a result: {e}"));
            let case = &mut plan.cases[i];
            // NaN/∞ scalars are deterministic physics, not a transport fault:
            // recomputing would give the same, so record the failure now.
            let deterministic = matches!(e, protocol::ProtocolError::NonFinite { .. });
            // Only the worker the case is in flight to can fail or requeue
            // it; a bad result from anyone else is just rejected.
            let mine = matches!(case.state, CaseState::InFlight { worker: w, .. } if w == worker);
            if mine && (deterministic || case.attempts >= MAX_ATTEMPTS) {
                let rec = Record {
                    case_id: h.case_id.clone(),
                    status: "failed".into(),
                    error: Some(format!("invalid result: {e}")),
                    worker: worker as u32,
                    seconds: h.solve_seconds,
                    kernel_builds: h.kernel_builds,
                    scalars: None,
                };
                self.commit(plan, journal, records, i, worker, rec)?;
            } else if mine {
                case.state = CaseState::Pending;
            }
            return Ok(());
        }
        if want_fields {
            let dir = output::fields_dir(self.args.out_dir, &h.case_id);
            std::fs::create_dir_all(&dir)
                .with_context(|| format!("while creating {}", dir.display()))?;
            let len = (n as usize) * (n as usize);
            for (k, name) in h.field_names.iter().enumerate() {
                let data = protocol::read_field(field_bytes, k, len)
                    .ok_or_else(|| anyhow!("field {name} missing"))?;
                crate::solve::write_npy(&dir.join(format!("{name}.npy")), n as usize, &data)?;
            }
        }
        let status = if h.scalars.0.converged {
            "ok"
        } else {
            "not_converged"
        };
        let rec = Record {
            case_id: h.case_id.clone(),
            status: status.into(),
            error: None,
            worker: worker as u32,
            seconds: h.solve_seconds,
            kernel_builds: h.kernel_builds,
            scalars: Some(h.scalars.0),
        };
        self.commit(plan, journal, records, i, worker, rec)?;
        let recorded = unix_ns();
        if h.sent_unix_ns > 0 && recorded >= h.sent_unix_ns {
            let e = self.ipc_ms.entry(n).or_default();
            e.0.push((recorded - h.sent_unix_ns) as f64 / 1e6);
            e.1.push(received_ns.saturating_sub(h.sent_unix_ns) as f64 / 1e6);
            e.2 = payload_len;
        }
        Ok(())
    }

    /// Journal a record (synced), then mark the case done: the answer that
    /// follows is the acknowledgement.
    fn commit(
        &mut self,
        plan: &mut Plan,
        journal: &mut Journal,
        records: &mut BTreeMap<String, Record>,
        i: usize,
        worker: usize,
        mut rec: Record,
    ) -> anyhow::Result<()> {
        // JSON has no NaN/∞: a record that would not read back on --resume
        // keeps its status but loses its scalars, with the reason.
        let line = Line::Case(Box::new(rec.clone()));
        let readable = serde_json::to_string(&line)
            .ok()
            .and_then(|t| serde_json::from_str::<Line>(&t).ok())
            .is_some();
        if !readable {
            rec.scalars = None;
            rec.status = "failed".into();
            rec.error = Some("result holds non-finite values".into());
        }
        journal.append(&Line::Case(Box::new(rec.clone())))?;
        if let CaseState::InFlight { since, .. } = plan.cases[i].state {
            self.longest_case = self.longest_case.max(since.elapsed());
        }
        plan.cases[i].state = CaseState::Done;
        if let Some(slot) = self.slots.get_mut(&worker) {
            slot.stats.cases += 1;
            slot.stats.kernel_builds = slot.stats.kernel_builds.max(rec.kernel_builds);
        }
        let line = format!(
            "{} {} by worker {} in {:.2} s",
            rec.case_id, rec.status, rec.worker, rec.seconds
        );
        records.insert(rec.case_id.clone(), rec);
        let states: Vec<String> = self
            .slots
            .iter()
            .map(|(k, s)| {
                let st = if s.dead {
                    "dead".to_string()
                } else if let Some(c) = s.in_flight {
                    plan.cases[c].id.clone()
                } else {
                    "idle".to_string()
                };
                format!("w{k}:{st}")
            })
            .collect();
        self.args
            .progress
            .case_done(records.len(), &line, &states.join(" "));
        Ok(())
    }

    /// Answer `active` from worker `k` with a case, `Done`, or hold it.
    /// Returns whether something was sent.
    fn assign(&mut self, plan: &mut Plan, k: usize, active: Active) -> anyhow::Result<bool> {
        let others: HashSet<solver::KernelKey> = self
            .slots
            .iter()
            .filter(|(j, s)| **j != k && !s.dead)
            .flat_map(|(_, s)| s.keys.iter().cloned())
            .collect();
        let Some(slot) = self.slots.get_mut(&k) else {
            return Ok(false);
        };
        if let Some(i) = plan.pick(&slot.keys, &others) {
            let case = &mut plan.cases[i];
            let msg = ToWorker::Case(CaseAssignment {
                case_id: case.id.clone(),
                grid_n: case.spec.grid.n as u32,
                want_fields: self.args.save_fields,
                attempt: case.attempts,
                spec: case.spec.clone(),
            });
            if let Err(e) = respond(&active, self.args.run_id, &msg) {
                self.args
                    .progress
                    .note(&format!("worker {k}: cannot send {}: {e:#}", case.id));
                return Ok(false);
            }
            case.attempts += 1;
            case.state = CaseState::InFlight {
                worker: k,
                since: Instant::now(),
            };
            slot.in_flight = Some(i);
            slot.keys.insert(case.kernel_key.clone());
            Ok(true)
        } else if plan.remaining() == 0 {
            slot.done_sent = true;
            Ok(respond(&active, self.args.run_id, &ToWorker::Done).is_ok())
        } else {
            slot.held = Some(active);
            Ok(false)
        }
    }

    fn serve_held(&mut self, plan: &mut Plan) -> anyhow::Result<()> {
        let mut answered = false;
        let waiting: Vec<usize> = self
            .slots
            .iter()
            .filter(|(_, s)| s.held.is_some() && !s.dead)
            .map(|(k, _)| *k)
            .collect();
        for k in waiting {
            if plan.pending() == 0 && plan.remaining() > 0 {
                break;
            }
            if let Some(active) = self.slots.get_mut(&k).and_then(|s| s.held.take()) {
                answered |= self.assign(plan, k, active)?;
            }
        }
        if answered {
            let _ = self.notifier.notify();
        }
        Ok(())
    }

    /// Declare workers dead whose process exited or whose node is no longer
    /// alive; requeue their cases; spawn replacements while cases remain.
    fn check_liveness(
        &mut self,
        plan: &mut Plan,
        journal: &mut Journal,
        records: &mut BTreeMap<String, Record>,
    ) -> anyhow::Result<()> {
        let mut states: HashMap<String, bool> = HashMap::new();
        let mut saw_dead = false;
        let listed = Node::<ipc::Service>::list(&self.cfg, |st| {
            let (alive, details) = match &st {
                NodeState::Alive(v) => (true, v.details().clone()),
                NodeState::Dead(v) => (false, v.details().clone()),
                _ => return CallbackProgression::Continue,
            };
            saw_dead |= !alive;
            if let Some(d) = details {
                let e = states.entry(d.name().as_str().to_string()).or_insert(false);
                *e |= alive;
            }
            CallbackProgression::Continue
        });
        if saw_dead {
            self.node.try_cleanup_dead_nodes();
        }
        let deadline = self.case_deadline();
        let mut died = Vec::new();
        for (k, slot) in self.slots.iter_mut() {
            if slot.dead {
                continue;
            }
            if let Some(i) = slot.in_flight {
                if let CaseState::InFlight { worker, since } = plan.cases[i].state {
                    let took = since.elapsed();
                    if worker == *k && took > deadline {
                        self.args.progress.note(&format!(
                            "worker {k} hung: {} in flight for {:.1} s (deadline {:.1} s); {}",
                            plan.cases[i].id,
                            took.as_secs_f64(),
                            deadline.as_secs_f64(),
                            if slot.child.is_some() {
                                "killing it"
                            } else {
                                "dropping it (not started by this coordinator, so not killed)"
                            }
                        ));
                        died.push(*k);
                        continue;
                    }
                }
            }
            let exited = match &mut slot.child {
                Some(c) => matches!(c.try_wait(), Ok(Some(_))),
                None => false,
            };
            let name = protocol::worker_node_name(self.args.run_id, *k);
            let node_alive = states.get(&name).copied().unwrap_or(false);
            // Trust the node list only when it could be read.
            if exited || (listed.is_ok() && slot.registered && !node_alive) {
                died.push(*k);
            }
        }
        for k in died {
            let slot = self.slots.get_mut(&k).expect("listed above");
            slot.dead = true;
            slot.stats.died = plan.remaining() > 0;
            slot.held = None;
            if let Some(mut c) = slot.child.take() {
                let _ = c.kill();
                let _ = c.wait();
            }
            if let Some(i) = slot.in_flight.take() {
                let case = &mut plan.cases[i];
                if matches!(case.state, CaseState::InFlight { worker, .. } if worker == k) {
                    self.args.progress.note(&format!(
                        "worker {k} died while solving {}; requeued",
                        case.id
                    ));
                    if case.attempts >= MAX_ATTEMPTS {
                        let rec = Record {
                            case_id: case.id.clone(),
                            status: "failed".into(),
                            error: Some(format!(
                                "its worker died or hung on it {} times",
                                case.attempts
                            )),
                            worker: k as u32,
                            seconds: 0.0,
                            kernel_builds: 0,
                            scalars: None,
                        };
                        self.commit(plan, journal, records, i, k, rec)?;
                    } else {
                        case.state = CaseState::Pending;
                    }
                }
            }
            if plan.remaining() > 0 && self.spawns_left > 0 {
                self.spawn()?;
            }
        }
        if plan.remaining() > 0 && self.slots.values().all(|s| s.dead) {
            bail!(
                "all workers died and no replacement may be started; see {}",
                self.args.out_dir.join("worker-logs").display()
            );
        }
        Ok(())
    }

    /// How long a case may be in flight before its worker counts as hung:
    /// max(`run.case_timeout_s`, HUNG_FACTOR × the longest case so far).
    fn case_deadline(&self) -> Duration {
        self.args
            .case_timeout
            .max(self.longest_case.mul_f64(crate::config::HUNG_FACTOR))
    }

    /// Tell held workers `Done`, stop stragglers, and report statistics.
    pub fn shutdown(mut self) -> SessionStats {
        for slot in self.slots.values_mut() {
            if let Some(active) = slot.held.take() {
                let _ = respond(&active, self.args.run_id, &ToWorker::Done);
            }
        }
        let _ = self.notifier.notify();
        let deadline = Instant::now() + Duration::from_secs(2);
        for slot in self.slots.values_mut() {
            if let Some(c) = slot.child.as_mut() {
                while Instant::now() < deadline && matches!(c.try_wait(), Ok(None)) {
                    std::thread::sleep(Duration::from_millis(20));
                }
                if matches!(c.try_wait(), Ok(None)) {
                    let _ = c.kill();
                }
                let _ = c.wait();
            }
        }
        self.node.try_cleanup_dead_nodes();
        let ipc = self
            .ipc_ms
            .iter()
            .map(|(n, (v, t, bytes))| {
                let sorted = |v: &Vec<f64>| {
                    let mut v = v.clone();
                    v.sort_by(f64::total_cmp);
                    v
                };
                let (v, t) = (sorted(v), sorted(t));
                IpcStats {
                    grid_n: *n,
                    count: v.len(),
                    median_ms: v.get(v.len() / 2).copied().unwrap_or(0.0),
                    max_ms: v.last().copied().unwrap_or(0.0),
                    median_transfer_ms: t.get(t.len() / 2).copied().unwrap_or(0.0),
                    payload_bytes: *bytes,
                }
            })
            .collect();
        SessionStats {
            per_worker: self
                .slots
                .iter()
                .map(|(k, s)| (k.to_string(), s.stats.clone()))
                .collect(),
            ipc,
            rejected: self.rejected,
        }
    }
}

fn respond(active: &Active, run_id: &str, msg: &ToWorker<WireSpec>) -> anyhow::Result<()> {
    let header = protocol::encode_header(&Envelope::new(run_id, msg.clone()))?;
    let len = protocol::frame_len(header.len(), 0);
    let mut response = active
        .loan_slice(len)
        .map_err(|e| anyhow!("cannot loan a response: {e:?}"))?;
    protocol::encode_into(response.payload_mut(), &header, &[])?;
    response
        .send()
        .map_err(|e| anyhow!("cannot send a response: {e:?}"))?;
    Ok(())
}
