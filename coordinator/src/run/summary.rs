//! What a sweep did, for `summary.json`: counts, failures, per-worker and
//! IPC statistics. Owns the tallying only; the file is written by the driver
//! (`run::run_sweep`), the numbers come from `record` and `dispatch`.

use std::collections::BTreeMap;
use std::path::PathBuf;

use serde::Serialize;

use super::journal::Outcome;
use super::plan::PlannedCase;
use crate::case::Status;

/// Per-worker statistics, as `dispatch` takes them from the worker's
/// messages; `summary.json` shows them as a [`WorkerReport`].
#[derive(Clone, Debug, Default, Serialize)]
#[serde(into = "WorkerReport")]
pub struct WorkerSummary {
    /// Cases this worker recorded.
    pub cases: u64,
    /// Kernels (operators) it computed itself: the wire's `kernels_built`
    /// (`KernelCache::builds()`), once per (material, grid).
    pub kernels_built: u64,
    /// Kernels it loaded from the kernel store (built by another worker,
    /// which it waited for, or by an earlier run) instead of computing them:
    /// the wire's `kernels_loaded` (`KernelCache::loads()`).
    pub kernels_loaded: u64,
    /// It died (or was lost) during the run.
    pub died: bool,
}

impl WorkerSummary {
    /// The deprecated `kernel_builds` of `summary.json`: the kernels this
    /// worker made resident, computed or loaded.
    pub fn kernels_resident(&self) -> u64 {
        self.kernels_built + self.kernels_loaded
    }
}

/// One worker in `summary.json` → `per_worker`: the kernels it built and
/// loaded under names that say so, beside the old keys. `kernel_builds`
/// counted loads too, so a reader took one build and one load for two
/// builds; it stays, with that meaning, for readers of older summaries.
#[derive(Serialize)]
struct WorkerReport {
    /// Cases this worker recorded.
    cases: u64,
    /// Kernels it computed itself.
    kernels_built: u64,
    /// Kernels it loaded from the kernel store instead of computing them.
    kernels_loaded: u64,
    /// Deprecated: `kernels_built + kernels_loaded` (kernels made resident).
    kernel_builds: u64,
    /// Deprecated: the same as `kernels_loaded`.
    kernel_loads: u64,
    /// It died (or was lost) during the run.
    died: bool,
}

impl From<WorkerSummary> for WorkerReport {
    fn from(w: WorkerSummary) -> Self {
        WorkerReport {
            cases: w.cases,
            kernels_built: w.kernels_built,
            kernels_loaded: w.kernels_loaded,
            kernel_builds: w.kernels_resident(),
            kernel_loads: w.kernels_loaded,
            died: w.died,
        }
    }
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
    /// Kernels computed by all workers (the sum of `per_worker` →
    /// `kernels_built`); with a shared kernel store, each (material, grid)
    /// at most once.
    pub kernels_built: u64,
    /// Kernels loaded from the kernel store by all workers.
    pub kernels_loaded: u64,
    /// Deprecated: by worker index, the kernels it made resident, built or
    /// loaded (`per_worker` → `kernel_builds`); kept for existing readers.
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
    /// Output files that could not be written (the run then ends with an
    /// error naming them), and the warnings of worn paths.
    pub output_warnings: Vec<String>,
    /// Physics the run warns of, printed on the console too: per material,
    /// cases whose peak pressure exceeds its typical hardness as a preset
    /// with no `hardness_gpa` to cap it. Left out when there is none.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub warnings: Vec<String>,
    /// Definition of the zones' own radii (`contact_radius_m`, `stick_radius_m`).
    pub zone_radius_definition: &'static str,
    /// Definition of the apparent radii a, c used in μa (`mu_a`, `k_e`,
    /// `mu_a_contact_radius_m`, `mu_a_stick_radius_m`).
    pub apparent_radius_definition: &'static str,
    /// Definition of `pressure_hertz_misfit`, and the limit beyond which μa
    /// is flagged (`mu_a_non_hertz`).
    pub hertz_misfit_definition: &'static str,
    /// See `hertz_misfit_definition`.
    pub hertz_misfit_limit: f64,
    /// Definition of the paper's radii (`mu_a_cells`, `k_e_cells`).
    pub apparent_radius_definition_cells: &'static str,
    /// Grids per case (1: no convergence ladder).
    pub convergence_levels: usize,
    /// How the error bars in curves.csv are formed.
    pub error_estimate: &'static str,
    /// Curve points left out because a level of their ladder did not solve.
    pub incomplete_points: usize,
    /// Per "material / surface": μa range over angle, error, resolved.
    pub curves: BTreeMap<String, crate::output::sweep::CurveSummary>,
    /// How K_E is obtained.
    pub k_e_definition: &'static str,
    /// By surface name, how its edges were put on the grid: `area` (the
    /// cut cells' exact cover) or `centre` (whole cells); `none` for flat
    /// surfaces and height maps.
    pub sampling: BTreeMap<String, &'static str>,
}

impl RunSummary {
    /// What the console says when some cases have no result (failed or
    /// not converged), `None` when every case is ok: the run then exits
    /// with [`crate::case::EXIT_NOT_ALL_OK`] (#59: all seven circle-A cases
    /// of Table 1(c) at H = 0.9 GPa failed, and the run said "ok").
    pub fn without_result(&self) -> Option<String> {
        let missing = self.failed + self.not_converged;
        (missing > 0).then(|| {
            format!(
                "{missing} of {} cases have no result ({} failed, {} not converged): their points are left out of curves.csv and crossed on the floor of mu_a_vs_angle.png/.svg (exit status {})",
                self.total,
                self.failed,
                self.not_converged,
                crate::case::EXIT_NOT_ALL_OK
            )
        })
    }

    /// The kernel counts of the whole run, from `per_worker`.
    pub fn count_kernels(&mut self) {
        let workers = self.per_worker.values();
        self.kernels_built = workers.clone().map(|w| w.kernels_built).sum();
        self.kernels_loaded = workers.map(|w| w.kernels_loaded).sum();
        self.kernel_builds = self
            .per_worker
            .iter()
            .map(|(k, w)| (k.clone(), w.kernels_resident()))
            .collect();
    }

    /// Count the recorded cases by status; list failures and non-converged
    /// cases by their display text; warn once per material of the cases
    /// that press it beyond its typical hardness.
    pub fn tally(&mut self, cases: &[PlannedCase], outcomes: &[Option<Outcome>]) {
        // Material → (cases, the largest p_max and its case, the range).
        let mut beyond: BTreeMap<String, (usize, f64, String, solver::presets::HardnessRange)> =
            BTreeMap::new();
        for (case, outcome) in cases.iter().zip(outcomes) {
            let Some(r) = outcome else { continue };
            if let Some(s) = &r.scalars {
                if let Some((m, range)) = case.spec.pressure_beyond_hardness(s.p_max_pa) {
                    let e = beyond
                        .entry(m.name.clone())
                        .or_insert((0, 0.0, String::new(), range));
                    e.0 += 1;
                    if s.p_max_pa > e.1 {
                        (e.1, e.2) = (s.p_max_pa, case.key.to_string());
                    }
                }
            }
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
        let solved = outcomes
            .iter()
            .flatten()
            .filter(|o| o.scalars.is_some())
            .count();
        for (name, (count, p_max, at, range)) in beyond {
            self.warnings.push(format!(
                "{count} of {solved} solved cases press {name} beyond its typical hardness ({:.1}–{:.1} GPa, {}): p_max up to {:.2} GPa ({at}); a real surface yields there — set [materials.{name}] hardness_gpa to cap the pressure",
                range.low_pa / 1e9,
                range.high_pa / 1e9,
                range.what,
                p_max / 1e9
            ));
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::Config;
    use solver::KernelCache;
    use worker::kernel_store::FileStore;

    /// A worker's statistics as `dispatch` takes them from its results,
    /// whose counts are the worker's `KernelCache::builds()` and `loads()`.
    fn seen_by_dispatch(cache: &KernelCache) -> WorkerSummary {
        WorkerSummary {
            cases: 1,
            kernels_built: cache.builds() as u64,
            kernels_loaded: cache.loads() as u64,
            died: false,
        }
    }

    #[test]
    fn two_kernel_builds_read_as_two_built_and_a_store_load_as_loaded() {
        // Two anisotropic kernels (stored on disk; isotropic ones are closed
        // forms and never stored) on a small grid.
        let text = std::fs::read_to_string(
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../configs/quick.toml"),
        )
        .unwrap();
        let config = Config::parse(&text, &["grid.points=32".into()]).unwrap();
        let spec = |m: &str| config.spec(m, "flat", 0.0).unwrap();
        let tmp = tempfile::tempdir().unwrap();
        let store = || KernelCache::with_store(Box::new(FileStore::new(tmp.path().join("k"))));
        // Worker 0 computes both; worker 1 then finds Cu(111) in the store.
        let mut first = store();
        first.resident(&spec("Cu(111)")).unwrap();
        first.resident(&spec("Fe(111)")).unwrap();
        let mut second = store();
        second.resident(&spec("Cu(111)")).unwrap();

        let mut summary = RunSummary::default();
        summary
            .per_worker
            .insert("0".into(), seen_by_dispatch(&first));
        summary
            .per_worker
            .insert("1".into(), seen_by_dispatch(&second));
        summary.count_kernels();
        let json = serde_json::to_value(&summary).unwrap();
        let w0 = &json["per_worker"]["0"];
        let w1 = &json["per_worker"]["1"];
        assert_eq!(
            (w0["kernels_built"].as_u64(), w0["kernels_loaded"].as_u64()),
            (Some(2), Some(0))
        );
        assert_eq!(
            (w1["kernels_built"].as_u64(), w1["kernels_loaded"].as_u64()),
            (Some(0), Some(1))
        );
        assert_eq!(
            (
                json["kernels_built"].as_u64(),
                json["kernels_loaded"].as_u64()
            ),
            (Some(2), Some(1))
        );
        // The deprecated keys keep their meaning: kernels made resident.
        assert_eq!(w0["kernel_builds"], 2);
        assert_eq!(w1["kernel_builds"], 1);
        assert_eq!(w1["kernel_loads"], 1);
        assert_eq!(json["kernel_builds"], serde_json::json!({ "0": 2, "1": 1 }));
    }
}
