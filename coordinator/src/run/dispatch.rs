//! Who works on what: the table of workers a run has heard of, the answer to
//! each request (a case, `Done`, or hold it until a case frees up), and what
//! a result, a failure or a dead worker means for its case. Decides only:
//! the IPC is `exchange`'s, processes are `supervise`'s, and every record
//! goes through `record::Recorder`; fields are written by `output`.

use std::collections::{BTreeMap, HashSet};
use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::bail;
use protocol::{CaseAssignment, Expected, Failure, ResultHeader, ToCoord, ToWorker};
use worker::WireScalars;

use super::exchange::{unix_ns, Exchange, Next, Request};
use super::journal::Outcome;
use super::progress::Progress;
use super::record::Recorder;
use super::summary::{IpcStats, IpcTimes, WorkerSummary};
use super::supervise::{Supervisor, Verdict};
use crate::case::{CaseKey, Status};
use crate::output::sweep;

/// Liveness check period.
const TICK: Duration = Duration::from_millis(500);
/// How long workers get to exit after `Done`.
const EXIT_GRACE: Duration = Duration::from_secs(10);
/// How often the workers' exits are looked for once every case is recorded
/// (a worker's exit wakes no wait set: on the liveness tick alone the quick
/// sweep's last worker was seen up to 0.5 s late, a quarter of its 2 s).
const EXIT_POLL: Duration = Duration::from_millis(5);
/// Dispatches of one case before it is marked failed (its workers died).
const MAX_ATTEMPTS: u32 = 2;

/// What the dispatcher knows of one worker.
struct Peer {
    /// It has sent a message (so its node must exist while it lives).
    registered: bool,
    /// Its request, parked until a case frees up.
    held: Option<Request>,
    /// The plan index of the case it is solving.
    in_flight: Option<usize>,
    /// Kernels it holds (material affinity).
    kernels: HashSet<solver::KernelKey>,
    stats: WorkerSummary,
    dead: bool,
    done_sent: bool,
}

impl Peer {
    fn new() -> Self {
        Peer {
            registered: false,
            held: None,
            in_flight: None,
            kernels: HashSet::new(),
            stats: WorkerSummary::default(),
            dead: false,
            done_sent: false,
        }
    }
}

/// Inputs of a dispatcher.
pub struct DispatchArgs<'a> {
    /// Output directory (fields).
    pub out_dir: &'a Path,
    /// Ask workers for fields and write them.
    pub save_fields: bool,
    /// Progress reporter.
    pub progress: &'a Progress,
    /// `[stress]`: what the workers compute below the surface of each case.
    pub stress: Option<crate::config::StressCfg>,
}

/// What a run's dispatch measured, for the summary.
pub struct DispatchStats {
    /// By worker index.
    pub per_worker: BTreeMap<String, WorkerSummary>,
    /// IPC cost by grid size.
    pub ipc: Vec<IpcStats>,
    /// Rejected messages.
    pub rejected: usize,
}

/// The worker table and the decisions of one run.
pub struct Dispatch<'a> {
    args: DispatchArgs<'a>,
    peers: BTreeMap<usize, Peer>,
    rejected: usize,
    ipc: IpcTimes,
}

impl<'a> Dispatch<'a> {
    /// A dispatcher with no worker yet.
    pub fn new(args: DispatchArgs<'a>) -> Self {
        Dispatch {
            args,
            peers: BTreeMap::new(),
            rejected: 0,
            ipc: IpcTimes::default(),
        }
    }

    /// Start a worker process and expect it in the table.
    pub fn spawn(&mut self, sup: &mut Supervisor) -> anyhow::Result<()> {
        let k = sup.spawn()?;
        self.peers.insert(k, Peer::new());
        Ok(())
    }

    /// Serve requests until every case is recorded and the workers have
    /// exited (or had [`EXIT_GRACE`] to).
    pub fn serve(
        &mut self,
        ex: &Exchange,
        sup: &mut Supervisor,
        rec: &mut Recorder,
    ) -> anyhow::Result<()> {
        let mut last_tick = Instant::now();
        let mut finished_at: Option<Instant> = None;
        ex.wait_loop(TICK, || {
            self.drain(ex, rec)?;
            if last_tick.elapsed() >= TICK {
                last_tick = Instant::now();
                self.check_liveness(ex, sup, rec)?;
            }
            self.serve_held(ex, rec)?;
            if rec.plan().remaining() > 0 {
                return Ok(Next::Within(Duration::MAX));
            }
            // Every case recorded: wait for the workers' exits, looked for
            // every EXIT_POLL (requests still get their `Done`).
            let finished = *finished_at.get_or_insert_with(Instant::now);
            Ok(if self.all_exited(sup) || finished.elapsed() > EXIT_GRACE {
                Next::Done
            } else {
                Next::Within(EXIT_POLL)
            })
        })
    }

    fn all_exited(&self, sup: &mut Supervisor) -> bool {
        self.peers
            .iter()
            .all(|(k, p)| p.dead || sup.exited(*k).unwrap_or(p.done_sent))
    }

    fn note(&self, line: &str) {
        self.args.progress.note(line);
    }

    /// Take every waiting request: act on it, then answer it (or hold it).
    /// Each answer wakes its worker at once, not after the batch: every
    /// result is synced to the journal before its answer, and a batch on a
    /// slow disk outlasted a worker's wait period (two results at 300 ms
    /// per sync: 0.6 s, #33 item 3).
    fn drain(&mut self, ex: &Exchange, rec: &mut Recorder) -> anyhow::Result<()> {
        while let Some(request) = ex.receive()? {
            let d = match ex.decode(&request) {
                Ok(d) => d,
                Err(e) => {
                    self.rejected += 1;
                    self.note(&format!("rejected a message: {e}"));
                    let reason = e.to_string();
                    let _ = ex.respond(&request, &ToWorker::Rejected { reason });
                    ex.notify();
                    continue;
                }
            };
            let body = d.header.body;
            let worker = match &body {
                ToCoord::Ready(r) => r.worker_index,
                ToCoord::Result(h) => h.worker_index,
                ToCoord::Failed(f) => f.worker_index,
                ToCoord::Heartbeat { worker_index } => *worker_index,
            } as usize;
            let peer = self.peers.entry(worker).or_insert_with(Peer::new);
            if peer.dead {
                // A worker we declared dead came back: tell it to go.
                self.rejected += 1;
                let reason = "this worker was declared dead".to_string();
                let _ = ex.respond(&request, &ToWorker::Rejected { reason });
                ex.notify();
                continue;
            }
            peer.registered = true;
            let in_flight = peer.in_flight.take();
            match body {
                ToCoord::Result(h) => {
                    let arrived = (request.received_ns(), request.payload_len());
                    self.on_result(rec, worker, h, d.field_bytes, arrived)?;
                }
                ToCoord::Failed(f) => self.on_failure(rec, worker, f)?,
                ToCoord::Ready(_) | ToCoord::Heartbeat { .. } => {}
            }
            // Whatever this worker had in flight and did not report goes back.
            if let Some(i) = in_flight {
                if rec.plan().in_flight(i).is_some_and(|(w, _)| w == worker) {
                    rec.hand_back(i);
                }
            }
            if self.assign(ex, rec, worker, request)? {
                ex.notify();
            }
        }
        Ok(())
    }

    fn on_failure(
        &mut self,
        rec: &mut Recorder,
        worker: usize,
        f: Failure<CaseKey>,
    ) -> anyhow::Result<()> {
        if let Some(i) = rec.plan().index_of(&f.key) {
            let outcome = Outcome::failed(f.error, worker, f.solve_seconds, f.kernels_built);
            self.record(rec, i, worker, outcome)?;
        }
        Ok(())
    }

    fn on_result(
        &mut self,
        rec: &mut Recorder,
        worker: usize,
        h: ResultHeader<CaseKey, WireScalars>,
        field_bytes: &[u8],
        (received_ns, payload_len): (u64, usize),
    ) -> anyhow::Result<()> {
        let Some(i) = rec.plan().index_of(&h.key) else {
            self.rejected += 1;
            self.note(&format!(
                "rejected: result for unknown case {:?}",
                h.key.to_string()
            ));
            return Ok(());
        };
        let case = &rec.plan().cases[i];
        if case.state == super::plan::CaseState::Done {
            self.rejected += 1;
            self.note(&format!("ignored a duplicate result for {}", h.key));
            return Ok(());
        }
        let want_fields = self.args.save_fields;
        let n = case.spec.grid.n as u32;
        let expected = Expected {
            grid_n: n,
            want_fields,
        };
        if let Err(e) = protocol::validate_result(&h, field_bytes, |_| Some(expected)) {
            self.rejected += 1;
            self.note(&format!("rejected a result: {e}"));
            // NaN/∞ scalars are deterministic physics, not a transport fault:
            // recomputing would give the same, so record the failure now.
            let deterministic = matches!(e, protocol::ProtocolError::NonFinite { .. });
            // Only the worker the case is in flight to can fail or requeue
            // it; a bad result from anyone else is just rejected.
            let mine = rec.plan().in_flight(i).is_some_and(|(w, _)| w == worker);
            if mine && (deterministic || case.attempts >= MAX_ATTEMPTS) {
                let error = format!("invalid result: {e}");
                let outcome = Outcome::failed(error, worker, h.solve_seconds, h.kernels_built);
                self.record(rec, i, worker, outcome)?;
            } else if mine {
                rec.requeue(i);
            }
            return Ok(());
        }
        if want_fields {
            sweep::write_result_fields(
                self.args.out_dir,
                &h.key,
                n as usize,
                &h.field_names,
                field_bytes,
            )?;
            if let Some(cfg) = &self.args.stress {
                let note = sweep::write_stress_fields(
                    self.args.out_dir,
                    &case.key,
                    &case.spec,
                    cfg,
                    &h.scalars.0,
                    (&h.field_names, field_bytes),
                )?;
                if let Some(note) = note {
                    self.note(&note);
                }
            }
        }
        if let Some(peer) = self.peers.get_mut(&worker) {
            peer.stats.kernels_loaded = peer.stats.kernels_loaded.max(h.kernels_loaded);
        }
        let outcome = Outcome {
            status: Status::of_solved(h.scalars.0.converged),
            error: None,
            worker: worker as u32,
            seconds: h.solve_seconds,
            kernel_builds: h.kernels_built,
            scalars: Some(h.scalars.0),
            stress: h.scalars.1,
        };
        self.record(rec, i, worker, outcome)?;
        self.ipc
            .add(n, payload_len, h.sent_unix_ns, received_ns, unix_ns());
        Ok(())
    }

    /// Record case `i` (see [`Recorder::record`]) and report it.
    fn record(
        &mut self,
        rec: &mut Recorder,
        i: usize,
        worker: usize,
        outcome: Outcome,
    ) -> anyhow::Result<()> {
        let Some(done) = rec.record(i, outcome)? else {
            return Ok(());
        };
        let r = &done.outcome;
        if let Some(peer) = self.peers.get_mut(&worker) {
            peer.stats.cases += 1;
            peer.stats.kernels_built = peer.stats.kernels_built.max(r.kernel_builds);
        }
        let line = format!(
            "{} {} by worker {} in {:.2} s",
            rec.plan().cases[i].key,
            r.status,
            r.worker,
            r.seconds
        );
        let states: Vec<String> = self
            .peers
            .iter()
            .map(|(k, p)| {
                let st = if p.dead {
                    "dead".to_string()
                } else if let Some(c) = p.in_flight {
                    rec.plan().cases[c].key.to_string()
                } else {
                    "idle".to_string()
                };
                format!("w{k}:{st}")
            })
            .collect();
        self.args
            .progress
            .case_done(rec.recorded(), &line, &states.join(" "));
        Ok(())
    }

    /// Answer `request` from worker `k` with a case, `Done`, or hold it.
    /// Returns whether something was sent.
    fn assign(
        &mut self,
        ex: &Exchange,
        rec: &mut Recorder,
        k: usize,
        request: Request,
    ) -> anyhow::Result<bool> {
        let others: HashSet<solver::KernelKey> = self
            .peers
            .iter()
            .filter(|(j, p)| **j != k && !p.dead)
            .flat_map(|(_, p)| p.kernels.iter().cloned())
            .collect();
        let Some(peer) = self.peers.get_mut(&k) else {
            return Ok(false);
        };
        let plan = rec.plan();
        if let Some(i) = plan.pick(&peer.kernels, &others) {
            let case = &plan.cases[i];
            let msg = ToWorker::Case(CaseAssignment {
                key: case.key.clone(),
                grid_n: case.spec.grid.n as u32,
                want_fields: self.args.save_fields,
                attempt: case.attempts,
                spec: worker::WireSpec {
                    case: case.spec.clone(),
                    stress: self.args.stress.as_ref().map(|s| s.request()),
                },
            });
            if let Err(e) = ex.respond(&request, &msg) {
                self.args
                    .progress
                    .note(&format!("worker {k}: cannot send {}: {e:#}", case.key));
                return Ok(false);
            }
            peer.kernels.insert(case.kernel_key.clone());
            peer.in_flight = Some(i);
            rec.dispatched(i, k);
            Ok(true)
        } else if plan.remaining() == 0 {
            peer.done_sent = true;
            Ok(ex.respond(&request, &ToWorker::Done).is_ok())
        } else {
            peer.held = Some(request);
            Ok(false)
        }
    }

    /// Give held requests a case as soon as one is pending (or `Done`).
    fn serve_held(&mut self, ex: &Exchange, rec: &mut Recorder) -> anyhow::Result<()> {
        let mut answered = false;
        let waiting: Vec<usize> = self
            .peers
            .iter()
            .filter(|(_, p)| p.held.is_some() && !p.dead)
            .map(|(k, _)| *k)
            .collect();
        for k in waiting {
            if rec.plan().pending() == 0 && rec.plan().remaining() > 0 {
                break;
            }
            if let Some(request) = self.peers.get_mut(&k).and_then(|p| p.held.take()) {
                answered |= self.assign(ex, rec, k, request)?;
            }
        }
        if answered {
            ex.notify();
        }
        Ok(())
    }

    /// Declare workers dead that the supervisor judges gone or hung; requeue
    /// their cases (or fail a case that has used up its attempts); start
    /// replacements while cases remain.
    fn check_liveness(
        &mut self,
        ex: &Exchange,
        sup: &mut Supervisor,
        rec: &mut Recorder,
    ) -> anyhow::Result<()> {
        let survey = sup.survey(ex);
        let mut died = Vec::new();
        for (&k, peer) in &self.peers {
            if peer.dead {
                continue;
            }
            let in_flight_for = peer
                .in_flight
                .and_then(|i| rec.plan().in_flight(i))
                .filter(|(w, _)| *w == k)
                .map(|(_, took)| took);
            match sup.verdict(k, peer.registered, in_flight_for, &survey) {
                Verdict::Alive => {}
                Verdict::Gone => died.push(k),
                Verdict::Hung {
                    took,
                    silent,
                    deadline,
                } => {
                    let i = peer.in_flight.unwrap_or_default();
                    self.note(&format!(
                        "worker {k} hung: {} in flight for {:.1} s, no sign of life for {:.1} s (run.case_timeout_s = {:.1} s); {}",
                        rec.plan().cases[i].key,
                        took.as_secs_f64(),
                        silent.as_secs_f64(),
                        deadline.as_secs_f64(),
                        if sup.owns(k) {
                            "killing it"
                        } else {
                            "dropping it (not started by this coordinator, so not killed)"
                        }
                    ));
                    died.push(k);
                }
            }
        }
        for k in died {
            let remaining = rec.plan().remaining();
            let Some(peer) = self.peers.get_mut(&k) else {
                continue;
            };
            peer.dead = true;
            peer.stats.died = remaining > 0;
            peer.held = None;
            let in_flight = peer.in_flight.take();
            let left_waiting = sup.left_waiting(k);
            sup.stop(k);
            if let Some(i) = in_flight {
                if rec.plan().in_flight(i).is_some_and(|(w, _)| w == k) {
                    let case = &rec.plan().cases[i];
                    if left_waiting {
                        // It never started the case, so the case is not to
                        // blame (#33 item 3: charged for two such workers, a
                        // healthy case was failed).
                        self.note(&format!(
                            "worker {k} left while waiting for an answer (it judged this coordinator gone; see its log); {} was never started, requeued without counting an attempt",
                            case.key
                        ));
                        rec.hand_back(i);
                    } else if case.attempts >= MAX_ATTEMPTS {
                        self.note(&format!(
                            "worker {k} died while solving {}; requeued",
                            case.key
                        ));
                        let error =
                            format!("its worker died or hung on it {} times", case.attempts);
                        let outcome = Outcome::failed(error, k, 0.0, 0);
                        self.record(rec, i, k, outcome)?;
                    } else {
                        self.note(&format!(
                            "worker {k} died while solving {}; requeued",
                            case.key
                        ));
                        rec.requeue(i);
                    }
                }
            }
            if rec.plan().remaining() > 0 && sup.may_spawn() {
                // A worker that cannot be replaced is no reason to stop the
                // healthy ones (#20 item 12): go on with fewer.
                if let Err(e) = self.spawn(sup) {
                    let live = self.peers.values().filter(|p| !p.dead).count();
                    self.note(&format!(
                        "cannot start a replacement for worker {k} ({e:#}); going on with {live} worker(s)"
                    ));
                }
            }
        }
        if rec.plan().remaining() > 0 && self.peers.values().all(|p| p.dead) {
            bail!(
                "all workers died and no replacement may be started; see {}",
                self.args.out_dir.join("worker-logs").display()
            );
        }
        Ok(())
    }

    /// Tell held workers `Done` and report statistics.
    pub fn finish(mut self, ex: &Exchange) -> DispatchStats {
        for peer in self.peers.values_mut() {
            if let Some(request) = peer.held.take() {
                let _ = ex.respond(&request, &ToWorker::Done);
            }
        }
        ex.notify();
        DispatchStats {
            per_worker: self
                .peers
                .iter()
                .map(|(k, p)| (k.to_string(), p.stats.clone()))
                .collect(),
            ipc: self.ipc.stats(),
            rejected: self.rejected,
        }
    }
}
