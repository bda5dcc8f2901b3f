//! The multi-process sweep runner behind `mpcontact run`: plans the cases,
//! serves the `<run>/work` pull queue to spawned (or hand-started) workers,
//! detects dead workers and requeues their cases, journals every result
//! before acknowledging it, and writes the outputs. Physics stays in
//! `solver`, message shapes in `protocol`; this module wires them together.
//!
//! Flow: [`run_sweep`] → plan + journal (resume) → [`server::Session`] loop
//! (WaitSet on the to-coord event + a liveness interval) → outputs.

mod journal;
mod output;
mod plan;
mod progress;
mod server;

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::time::{Instant, SystemTime, UNIX_EPOCH};

use anyhow::Context;
use serde::Serialize;

pub use journal::{Journal, Line, Record, JOURNAL_FILE};
pub use output::{fmt_f64, CURVES_HEADER, RESULTS_HEADER};
pub use plan::{CaseState, Plan, PlannedCase};

use crate::config::Config;

/// Everything `mpcontact run` passes to the runner.
pub struct RunArgs {
    /// The loaded sweep config.
    pub config: Config,
    /// Workers to spawn (≥ 1).
    pub workers: usize,
    /// Output directory (created when missing).
    pub out_dir: PathBuf,
    /// Continue the sweep journalled in `out_dir`.
    pub resume: bool,
    /// No progress output.
    pub quiet: bool,
    /// Write `fields/<case>/*.npy` (or'ed with the config's `save_fields`).
    pub save_fields: bool,
    /// The `mpcontact` binary; workers are started as
    /// `EXE worker --run RUN_ID --index K`.
    pub exe: PathBuf,
}

/// Per-worker statistics in `summary.json`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct WorkerSummary {
    /// Cases this worker recorded.
    pub cases: u64,
    /// Kernels (operators) it built — once per (material, grid) it saw.
    pub kernel_builds: u64,
    /// It died (or was lost) during the run.
    pub died: bool,
}

/// IPC cost of results by grid size (clocks of one machine).
#[derive(Clone, Debug, Default, Serialize)]
pub struct IpcStats {
    /// Grid points per side.
    pub grid_n: u32,
    /// Results measured.
    pub count: usize,
    /// Median from "result ready" in the worker to "recorded" (fields
    /// written, journal synced) in the coordinator, ms.
    pub median_ms: f64,
    /// Maximum of the same, ms.
    pub max_ms: f64,
    /// Median from "result ready" to "request received" by the coordinator
    /// (the shared-memory transfer and wake-up alone), ms.
    pub median_transfer_ms: f64,
    /// Bytes of one result payload (with fields when requested).
    pub payload_bytes: usize,
}

/// What a sweep did; also written to `summary.json` (with the config echo).
#[derive(Clone, Debug, Default, Serialize)]
pub struct RunSummary {
    /// Run id (service and node names).
    pub run_id: String,
    /// Output directory.
    pub out_dir: PathBuf,
    /// Cases in the sweep.
    pub total: usize,
    /// Recorded with status `ok`.
    pub ok: usize,
    /// Recorded but not converged (excluded from curves).
    pub not_converged: usize,
    /// Failed cases (excluded from curves).
    pub failed: usize,
    /// Cases taken from the journal of an earlier run (`--resume`).
    pub resumed: usize,
    /// Failures: case id → reason.
    pub failures: BTreeMap<String, String>,
    /// Ids of non-converged cases.
    pub not_converged_cases: Vec<String>,
    /// Workers requested.
    pub workers: usize,
    /// Statistics by worker index.
    pub per_worker: BTreeMap<String, WorkerSummary>,
    /// Kernel builds by worker index (same numbers as `per_worker`).
    pub kernel_builds: BTreeMap<String, u64>,
    /// Wall time of the sweep, s.
    pub wall_seconds: f64,
    /// Cases solved in this invocation per minute of wall time.
    pub cases_per_minute: f64,
    /// Start, s since the Unix epoch.
    pub started_unix_s: f64,
    /// IPC cost of results by grid size.
    pub ipc: Vec<IpcStats>,
    /// Messages rejected by validation (logged).
    pub rejected_messages: usize,
    /// Output files that could not be written (plots need fonts).
    pub output_warnings: Vec<String>,
    /// Definition of the apparent radii a, c used in μa.
    pub apparent_radius_definition: &'static str,
    /// How K_E is obtained.
    pub k_e_definition: &'static str,
}

fn new_run_id() -> String {
    let nanos = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_nanos())
        .unwrap_or(0);
    format!(
        "mpc{:x}x{:x}",
        std::process::id(),
        (nanos as u64) & 0xffff_ffff_ffff
    )
}

/// An exclusive claim on an output directory for the life of a run.
struct DirLock(PathBuf);

impl DirLock {
    fn take(out_dir: &std::path::Path) -> anyhow::Result<DirLock> {
        let path = out_dir.join(".mpcontact.lock");
        for _ in 0..2 {
            match std::fs::OpenOptions::new()
                .write(true)
                .create_new(true)
                .open(&path)
            {
                Ok(mut f) => {
                    use std::io::Write;
                    writeln!(f, "{}", std::process::id())?;
                    return Ok(DirLock(path));
                }
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => {
                    let pid = std::fs::read_to_string(&path).unwrap_or_default();
                    let pid = pid.trim();
                    if !pid.is_empty() && std::path::Path::new(&format!("/proc/{pid}")).exists() {
                        anyhow::bail!(
                            "{} is in use by a running sweep (pid {pid})",
                            out_dir.display()
                        );
                    }
                    let _ = std::fs::remove_file(&path);
                }
                Err(e) => return Err(e).context(format!("while locking {}", out_dir.display())),
            }
        }
        anyhow::bail!("cannot lock {}", out_dir.display())
    }
}

impl Drop for DirLock {
    fn drop(&mut self) {
        let _ = std::fs::remove_file(&self.0);
    }
}

/// Run a sweep to the end and write its outputs; see the module docs.
pub fn run_sweep(args: &RunArgs) -> anyhow::Result<RunSummary> {
    let started = Instant::now();
    let started_unix_s = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0);
    std::fs::create_dir_all(&args.out_dir)
        .with_context(|| format!("while creating {}", args.out_dir.display()))?;
    let _lock = DirLock::take(&args.out_dir)?;
    let run_id = new_run_id();
    let save_fields = args.save_fields || args.config.output.save_fields;
    let mut plan = Plan::new(args.config.cases()?);
    anyhow::ensure!(!plan.cases.is_empty(), "the sweep has no cases");
    let raw = args.config.to_toml();
    let (mut journal, previous) = Journal::open(&args.out_dir, &run_id, &raw, args.resume)?;
    let mut records: BTreeMap<String, Record> = BTreeMap::new();
    for r in previous.records {
        if let Some(i) = plan.index_of(&r.case_id) {
            plan.cases[i].state = CaseState::Done;
            records.insert(r.case_id.clone(), r);
        }
    }
    let resumed = records.len();
    let progress = progress::Progress::new(args.quiet, plan.cases.len(), resumed);
    if previous.torn_tail {
        progress.note("journal: dropped a torn last line");
    }

    let mut summary = RunSummary {
        run_id: run_id.clone(),
        out_dir: args.out_dir.clone(),
        total: plan.cases.len(),
        resumed,
        workers: args.workers,
        started_unix_s,
        apparent_radius_definition: solver::APPARENT_RADIUS_DEFINITION,
        k_e_definition: solver::K_E_DEFINITION,
        ..Default::default()
    };

    if plan.remaining() > 0 {
        let mut session = server::Session::start(server::SessionArgs {
            run_id: &run_id,
            workers: args.workers.max(1).min(plan.remaining()),
            exe: &args.exe,
            out_dir: &args.out_dir,
            save_fields,
            progress: &progress,
            case_timeout: std::time::Duration::from_secs_f64(args.config.run.case_timeout_s),
        })?;
        let outcome = session.serve(&mut plan, &mut journal, &mut records);
        let stats = session.shutdown();
        summary.per_worker = stats.per_worker;
        summary.ipc = stats.ipc;
        summary.rejected_messages = stats.rejected;
        outcome?;
    }
    progress.finish();

    summary.kernel_builds = summary
        .per_worker
        .iter()
        .map(|(k, w)| (k.clone(), w.kernel_builds))
        .collect();
    for r in records.values() {
        match r.status.as_str() {
            "ok" => summary.ok += 1,
            "not_converged" => {
                summary.not_converged += 1;
                summary.not_converged_cases.push(r.case_id.clone());
            }
            _ => {
                summary.failed += 1;
                summary.failures.insert(
                    r.case_id.clone(),
                    r.error.clone().unwrap_or_else(|| r.status.clone()),
                );
            }
        }
    }
    summary.wall_seconds = started.elapsed().as_secs_f64();
    let solved_now = records.len() - resumed;
    summary.cases_per_minute = solved_now as f64 / (summary.wall_seconds / 60.0).max(1e-9);

    write_outputs(args, &plan, &records, &mut summary, &raw)?;
    if !args.quiet {
        eprintln!(
            "{} cases: {} ok, {} not converged, {} failed ({} resumed) in {:.1} s → {}",
            summary.total,
            summary.ok,
            summary.not_converged,
            summary.failed,
            summary.resumed,
            summary.wall_seconds,
            args.out_dir.display()
        );
        for (id, why) in &summary.failures {
            eprintln!("  failed {id}: {why}");
        }
    }
    Ok(summary)
}

fn write_outputs(
    args: &RunArgs,
    plan: &Plan,
    records: &BTreeMap<String, Record>,
    summary: &mut RunSummary,
    raw_config: &str,
) -> anyhow::Result<()> {
    let dir = &args.out_dir;
    let rows = output::calibrate(&plan.cases, records);
    let write = |name: &str, text: String| {
        let p = dir.join(name);
        std::fs::write(&p, text).with_context(|| format!("while writing {}", p.display()))
    };
    write("results.csv", output::results_csv(&rows))?;
    write("curves.csv", output::curves_csv(&rows))?;
    let curves = output::curves(&rows);
    for name in ["mu_a_vs_angle.png", "mu_a_vs_angle.svg"] {
        if let Err(e) = output::plot_curves(&dir.join(name), &curves) {
            summary.output_warnings.push(format!("{name}: {e:#}"));
        }
    }
    #[derive(Serialize)]
    struct SummaryFile<'a> {
        #[serde(flatten)]
        summary: &'a RunSummary,
        config: &'a str,
        protocol_version: u32,
    }
    let text = serde_json::to_string_pretty(&SummaryFile {
        summary,
        config: raw_config,
        protocol_version: protocol::PROTOCOL_VERSION,
    })?;
    write("summary.json", text + "\n")?;
    Ok(())
}
