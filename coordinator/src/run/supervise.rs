//! Worker processes: starting the ones this coordinator owns (logs in
//! `worker-logs/`), watching them, and the verdict on any worker's liveness
//! (process exited, node gone, silent past `run.case_timeout_s` while a case
//! is in flight — workers beat while they compute, so a long computation is
//! never a hang). Must not touch IPC messages, the plan or the journal: it
//! judges, `dispatch` acts.

use std::collections::{BTreeMap, HashMap};
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use anyhow::Context;
use iceoryx2::node::NodeView;
use iceoryx2::prelude::*;

use super::exchange::Exchange;

/// How a worker process is started: `PROGRAM [ARGS…] worker --run RUN --index K`.
#[derive(Clone, Debug)]
pub struct WorkerCommand {
    /// The program: the `mpcontact` binary, or a Python interpreter that
    /// hosts the same worker (`mpcontact.run`).
    pub program: PathBuf,
    /// Arguments before `worker` (Python's `-c CODE`).
    pub args: Vec<String>,
    /// `argv[0]` shown in process lists; `None` keeps the program's path
    /// (a Python interpreter finds its environment from it).
    pub arg0: Option<String>,
}

impl WorkerCommand {
    /// The `mpcontact` binary at `exe` (e.g. `/proc/self/exe`), named
    /// `mpcontact` in process lists.
    pub fn mpcontact(exe: PathBuf) -> Self {
        WorkerCommand {
            program: exe,
            args: Vec::new(),
            arg0: Some("mpcontact".into()),
        }
    }
}

/// What the supervisor starts workers with.
pub struct SuperviseArgs<'a> {
    /// Run id (`worker --run`).
    pub run_id: &'a str,
    /// How a worker is started.
    pub exe: &'a WorkerCommand,
    /// Output directory (`worker-logs/` goes there).
    pub out_dir: &'a Path,
    /// Workers of the run; replacements are limited to `2 × workers + 2`
    /// starts in all.
    pub workers: usize,
    /// Longest silence of a worker with a case in flight (`run.case_timeout_s`).
    pub case_timeout: Duration,
}

/// The worker processes of a run and the case deadline.
pub struct Supervisor<'a> {
    args: SuperviseArgs<'a>,
    children: BTreeMap<usize, Child>,
    next_index: usize,
    spawns_left: usize,
}

/// Which worker nodes of the system were alive at one listing.
pub struct NodeSurvey {
    /// Node name → some node of that name is alive.
    alive: HashMap<String, bool>,
    /// The listing succeeded (otherwise node liveness is not trusted).
    listed: bool,
}

/// The supervisor's verdict on one worker.
pub enum Verdict {
    /// Nothing wrong seen.
    Alive,
    /// It has said nothing (no message, no heartbeat) for longer than the
    /// limit while a case was in flight.
    Hung {
        /// How long the case has been in flight.
        took: Duration,
        /// How long the worker has been silent.
        silent: Duration,
        /// The limit it passed.
        deadline: Duration,
    },
    /// Its process exited or its node is gone.
    Gone,
}

impl<'a> Supervisor<'a> {
    /// A supervisor with no worker started yet.
    pub fn new(args: SuperviseArgs<'a>) -> Self {
        Supervisor {
            spawns_left: args.workers * 2 + 2,
            args,
            children: BTreeMap::new(),
            next_index: 0,
        }
    }

    /// Start worker `k` (the next index) as `EXE worker --run RUN --index K`;
    /// returns `k`.
    pub fn spawn(&mut self) -> anyhow::Result<usize> {
        let k = self.next_index;
        self.next_index += 1;
        self.spawns_left = self.spawns_left.saturating_sub(1);
        let log_dir = self.args.out_dir.join("worker-logs");
        std::fs::create_dir_all(&log_dir).with_context(|| {
            format!(
                "cannot create the worker log directory {}",
                log_dir.display()
            )
        })?;
        let log_path = log_dir.join(format!("worker-{k}.log"));
        let log = std::fs::File::create(&log_path)
            .with_context(|| format!("cannot create {}", log_path.display()))?;
        let exe = self.args.exe;
        let mut command = Command::new(&exe.program);
        // The CLI's workers are named `mpcontact` in process lists even
        // when started through /proc/self/exe.
        if let Some(name) = &exe.arg0 {
            command.arg0(name);
        }
        let child = command
            .args(&exe.args)
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
            .with_context(|| format!("while starting worker {k} ({})", exe.program.display()))?;
        self.children.insert(k, child);
        Ok(k)
    }

    /// A replacement may still be started.
    pub fn may_spawn(&self) -> bool {
        self.spawns_left > 0
    }

    /// Worker `k` was started (and may be killed) by this coordinator.
    pub fn owns(&self, k: usize) -> bool {
        self.children.contains_key(&k)
    }

    /// Whether the process of worker `k` has exited; `None` when it is not
    /// ours (started by hand, or already reaped by [`Supervisor::stop`]).
    pub fn exited(&mut self, k: usize) -> Option<bool> {
        self.children
            .get_mut(&k)
            .map(|c| matches!(c.try_wait(), Ok(Some(_))))
    }

    /// Kill worker `k` if it is ours, and reap it.
    pub fn stop(&mut self, k: usize) {
        if let Some(mut c) = self.children.remove(&k) {
            let _ = c.kill();
            let _ = c.wait();
        }
        self.forget_heartbeat(k);
    }

    fn forget_heartbeat(&self, k: usize) {
        if let Ok(p) = protocol::heartbeat_path(self.args.run_id, k) {
            let _ = std::fs::remove_file(p);
        }
    }

    /// List the nodes of the system (and clean up after dead ones).
    pub fn survey(&self, exchange: &Exchange) -> NodeSurvey {
        let mut alive: HashMap<String, bool> = HashMap::new();
        let mut saw_dead = false;
        let listed = Node::<ipc::Service>::list(exchange.config(), |st| {
            let (is_alive, details) = match &st {
                NodeState::Alive(v) => (true, v.details().clone()),
                NodeState::Dead(v) => (false, v.details().clone()),
                _ => return CallbackProgression::Continue,
            };
            saw_dead |= !is_alive;
            if let Some(d) = details {
                let e = alive.entry(d.name().as_str().to_string()).or_insert(false);
                *e |= is_alive;
            }
            CallbackProgression::Continue
        });
        if saw_dead {
            exchange.cleanup_dead_nodes();
        }
        NodeSurvey {
            alive,
            listed: listed.is_ok(),
        }
    }

    /// How long a worker with a case in flight may be silent.
    pub fn case_deadline(&self) -> Duration {
        self.args.case_timeout
    }

    /// How long ago worker `k` last beat, if it ever did.
    fn since_heartbeat(&self, k: usize) -> Option<Duration> {
        let path = protocol::heartbeat_path(self.args.run_id, k).ok()?;
        let beat = protocol::read_heartbeat(&path)?;
        let now = SystemTime::now().duration_since(UNIX_EPOCH).ok()?;
        Some(now.saturating_sub(Duration::from_nanos(beat)))
    }

    /// Judge worker `k`: `registered` when it has sent a message (only then
    /// is a missing node meaningful), `in_flight_for` how long its case has
    /// been in flight to it. Silence is counted from the later of the
    /// dispatch and the worker's last heartbeat.
    pub fn verdict(
        &mut self,
        k: usize,
        registered: bool,
        in_flight_for: Option<Duration>,
        survey: &NodeSurvey,
    ) -> Verdict {
        let deadline = self.case_deadline();
        if let Some(took) = in_flight_for {
            let silent = self.since_heartbeat(k).map_or(took, |b| b.min(took));
            if silent > deadline {
                return Verdict::Hung {
                    took,
                    silent,
                    deadline,
                };
            }
        }
        let exited = self.exited(k).unwrap_or(false);
        let name = protocol::worker_node_name(self.args.run_id, k);
        let node_alive = survey.alive.get(&name).copied().unwrap_or(false);
        // Trust the node list only when it could be read.
        if exited || (survey.listed && registered && !node_alive) {
            Verdict::Gone
        } else {
            Verdict::Alive
        }
    }

    /// Give the workers 2 s to exit after `Done`, then kill the stragglers;
    /// remove every heartbeat file of the run.
    pub fn stop_all(&mut self) {
        for k in 0..self.next_index {
            self.forget_heartbeat(k);
        }
        let deadline = Instant::now() + Duration::from_secs(2);
        for c in self.children.values_mut() {
            while Instant::now() < deadline && matches!(c.try_wait(), Ok(None)) {
                std::thread::sleep(Duration::from_millis(20));
            }
            if matches!(c.try_wait(), Ok(None)) {
                let _ = c.kill();
            }
            let _ = c.wait();
        }
    }
}
