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
    /// When the previous survey was taken.
    last_survey: Option<Instant>,
    /// When this coordinator last came back from a stall (see
    /// [`STALL_GAP`]); silence before it is not counted against workers.
    resumed_at: Option<Instant>,
}

/// A gap between two surveys (normally one 0.5 s tick apart) longer than
/// this means this coordinator did not run: the run was paused (SIGSTOP,
/// `scontrol suspend`, whose pause stops workers too) or the machine starved
/// it. Workers' heartbeats are as old as the pause then, so silence is
/// counted from the resumption: a suspended job resumed after more than
/// `run.case_timeout_s` would otherwise see every busy worker killed as hung.
const STALL_GAP: Duration = Duration::from_secs(2);

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
            last_survey: None,
            resumed_at: None,
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

    /// Whether worker `k` is ours and exited with
    /// [`protocol::EXIT_LEFT_WAITING`]: it left while waiting for an
    /// answer, so it held no case (whatever was sent to it went unread).
    pub fn left_waiting(&mut self, k: usize) -> bool {
        use std::os::unix::process::ExitStatusExt;
        self.children.get_mut(&k).is_some_and(|c| {
            matches!(c.try_wait(), Ok(Some(st))
                if st.signal().is_none()
                    && st.code() == Some(i32::from(protocol::EXIT_LEFT_WAITING)))
        })
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

    /// List the nodes of the system (and clean up after dead ones); notes a
    /// stall of this coordinator since the previous survey.
    pub fn survey(&mut self, exchange: &Exchange) -> NodeSurvey {
        let now = Instant::now();
        if self
            .last_survey
            .is_some_and(|t| now.duration_since(t) > STALL_GAP)
        {
            self.resumed_at = Some(now);
        }
        self.last_survey = Some(now);
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
    /// dispatch, the worker's last heartbeat and this coordinator's return
    /// from a stall.
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
            let silent = self.resumed_at.map_or(silent, |r| silent.min(r.elapsed()));
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A worker that exits with `protocol::EXIT_LEFT_WAITING` is told apart
    /// from one that ended otherwise (#33 item 3: its case is not charged).
    #[test]
    fn issue33_item3_a_worker_that_left_waiting_is_told_by_its_exit_status() {
        let out = tempfile::Builder::new()
            .prefix("mpc-left-")
            .tempdir()
            .unwrap();
        let status_of = |code: &str| {
            // `sh -c SCRIPT worker --run …`: the worker's arguments become
            // the script's $0…, and the script only exits.
            let exe = WorkerCommand {
                program: "/bin/sh".into(),
                args: vec!["-c".into(), format!("exit {code}")],
                arg0: None,
            };
            let mut sup = Supervisor::new(SuperviseArgs {
                run_id: "mpc-left-test",
                exe: &exe,
                out_dir: out.path(),
                workers: 1,
                case_timeout: Duration::from_secs(60),
            });
            let k = sup.spawn().unwrap();
            let t = Instant::now();
            while sup.exited(k) != Some(true) {
                assert!(t.elapsed() < Duration::from_secs(30), "sh did not exit");
                std::thread::sleep(Duration::from_millis(10));
            }
            sup.left_waiting(k)
        };
        assert!(status_of(&protocol::EXIT_LEFT_WAITING.to_string()));
        assert!(!status_of("0"));
        assert!(!status_of("2"));
    }
}
