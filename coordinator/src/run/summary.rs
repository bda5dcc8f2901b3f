//! What a sweep did, for `summary.json`: counts, failures, per-worker and
//! IPC statistics. Owns the tallying only; the file is written by the driver
//! (`run::run_sweep`), the numbers come from `record` and `dispatch`.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Serialize;

use super::journal::Outcome;
use super::plan::PlannedCase;
use crate::case::Status;

/// Per-worker statistics in `summary.json`.
#[derive(Clone, Debug, Default, Serialize)]
pub struct WorkerSummary {
    /// Cases this worker recorded.
    pub cases: u64,
    /// Kernels (operators) it built — once per (material, grid) it saw.
    pub kernel_builds: u64,
    /// Of those, how many it loaded from the kernel store (built by another
    /// worker, which it waited for, or by an earlier run) instead of computing.
    pub kernel_loads: u64,
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
    /// Definition of the apparent radii a, c used in μa (`mu_a`, `k_e`).
    pub apparent_radius_definition: &'static str,
    /// Definition of the paper's radii (`mu_a_cells`, `k_e_cells`).
    pub apparent_radius_definition_cells: &'static str,
    /// Grids per case (1: no convergence ladder).
    pub convergence_levels: usize,
    /// How the error bars in curves.csv are formed.
    pub error_estimate: &'static str,
    /// Curve points left out because a level of their ladder did not solve.
    pub incomplete_points: usize,
    /// Per "material / surface": μa range over angle, error, resolved.
    pub curves: BTreeMap<String, super::output::CurveSummary>,
    /// How K_E is obtained.
    pub k_e_definition: &'static str,
}

impl RunSummary {
    /// Count the recorded cases by status; list failures and non-converged
    /// cases by their display text.
    pub fn tally(&mut self, cases: &[PlannedCase], outcomes: &[Option<Outcome>]) {
        for (case, outcome) in cases.iter().zip(outcomes) {
            let Some(r) = outcome else { continue };
            match r.status {
                Status::Ok => self.ok += 1,
                Status::NotConverged => {
                    self.not_converged += 1;
                    self.not_converged_cases.push(case.key.to_string());
                }
                Status::Failed => {
                    self.failed += 1;
                    self.failures.insert(
                        case.key.to_string(),
                        r.error.clone().unwrap_or_else(|| r.status.to_string()),
                    );
                }
            }
        }
    }
}

/// IPC cost of results as they arrive, by grid size (ms).
#[derive(Debug, Default)]
pub struct IpcTimes {
    /// Grid n → (ready → recorded, ready → received, payload bytes).
    by_grid: BTreeMap<u32, (Vec<f64>, Vec<f64>, usize)>,
}

impl IpcTimes {
    /// A result of grid `n` and `payload_bytes`, stamped `sent_ns` by its
    /// worker, was received at `received_ns` and recorded at `recorded_ns`.
    pub fn add(
        &mut self,
        n: u32,
        payload_bytes: usize,
        sent_ns: u64,
        received_ns: u64,
        recorded_ns: u64,
    ) {
        if sent_ns > 0 && recorded_ns >= sent_ns {
            let e = self.by_grid.entry(n).or_default();
            e.0.push((recorded_ns - sent_ns) as f64 / 1e6);
            e.1.push(received_ns.saturating_sub(sent_ns) as f64 / 1e6);
            e.2 = payload_bytes;
        }
    }

    /// Medians and maxima by grid size.
    pub fn stats(&self) -> Vec<IpcStats> {
        self.by_grid
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
            .collect()
    }
}
