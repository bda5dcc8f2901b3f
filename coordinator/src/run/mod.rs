//! The multi-process sweep runner behind `mpcontact run`: plans the cases,
//! serves the `<run>/work` pull queue to spawned (or hand-started) workers,
//! detects dead workers and requeues their cases, journals every result
//! before acknowledging it, and writes the outputs. Physics stays in
//! `solver`, message shapes in `protocol`; this module only drives:
//!
//! [`run_sweep`]: lock the output directory (`lock`) → plan the cases
//! (`plan`) → open the record (`record`, resuming the journal) → start
//! workers (`supervise`) and serve them (`dispatch` over `exchange`) until
//! every case is recorded → write the outputs (`calibrate` into rows, then
//! `crate::output`, and `summary`).

mod calibrate;
mod dispatch;
mod exchange;
mod journal;
mod lock;
mod merge;
mod plan;
mod progress;
mod record;
mod summary;
mod supervise;

use std::path::PathBuf;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

use anyhow::Context;
use serde::Serialize;

pub use crate::output::fretting_map::{FRETTING_MAP_HEADER, TRANSITIONS_HEADER};
pub use crate::output::orientation_map::ORIENTATIONS_HEADER;
pub use crate::output::sweep::{
    CURVES_HEADER, CURVES_PLASTIC_COLUMNS, CURVES_STRESS_COLUMNS, RESULTS_HEADER,
    RESULTS_PLASTIC_COLUMNS, RESULTS_STRESS_COLUMNS,
};
pub use exchange::Interrupted;
pub use journal::{Entry, Journal, Line, Outcome, JOURNAL_FILE};
pub use merge::{merge_shards, ShardInfo, SHARD_FILE};
pub use plan::{CaseState, Plan, PlannedCase};
pub use summary::{IpcStats, RunSummary, WorkerSummary};
pub use supervise::WorkerCommand;

use crate::config::Config;
use crate::float_text::fmt_f64;
use crate::output::{atomic, fretting_map, history, orientation_map, sweep};

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
    /// How workers are started (`PROGRAM [ARGS…] worker --run RUN_ID
    /// --index K`): the `mpcontact` binary, or Python hosting the same worker.
    pub exe: WorkerCommand,
    /// Run only this shard of the cases (`--shard K/N`).
    pub shard: Option<crate::shard::Shard>,
    /// How the caller spells its options in messages ([`OptionNames::CLI`]
    /// or [`OptionNames::PYTHON`]).
    pub names: OptionNames,
}

/// How the caller spells the options a message points to: the CLI's flags
/// or Python's keywords, so that `mpcontact.run` does not tell a Python
/// user to pass `--resume`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OptionNames {
    /// The option that continues a journalled sweep.
    pub resume: &'static str,
    /// The option that chooses the output directory.
    pub out: &'static str,
}

impl OptionNames {
    /// `mpcontact run`'s flags.
    pub const CLI: OptionNames = OptionNames {
        resume: "--resume",
        out: "--out",
    };
    /// `mpcontact.run`'s keywords.
    pub const PYTHON: OptionNames = OptionNames {
        resume: "resume=True",
        out: "out=",
    };
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

/// Run a sweep to the end and write its outputs; see the module docs.
pub fn run_sweep(args: &RunArgs) -> anyhow::Result<RunSummary> {
    let started = Instant::now();
    let started_unix_s = SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0);
    if args.out_dir.exists() && !args.out_dir.is_dir() {
        anyhow::bail!(
            "{} {}: exists and is not a directory",
            args.names.out,
            args.out_dir.display()
        );
    }
    std::fs::create_dir_all(&args.out_dir).with_context(|| {
        format!(
            "cannot create the output directory {}",
            args.out_dir.display()
        )
    })?;
    let _lock = lock::DirLock::take(&args.out_dir)?;
    let run_id = new_run_id();
    let mut cases = args.config.cases()?;
    anyhow::ensure!(!cases.is_empty(), "the sweep has no cases");
    if let Some(shard) = args.shard {
        let of = crate::shard::assign(&cases, shard.count);
        cases = cases
            .into_iter()
            .zip(of)
            .filter(|(_, s)| *s == shard.index)
            .map(|(case, _)| case)
            .collect();
        merge::write_shard_info(&args.out_dir, shard, &args.config.base_dir)?;
        if cases.is_empty() && !args.quiet {
            eprintln!("shard {shard} has no cases (more shards than the cost balance needs); writing an empty shard");
        }
    }
    let plan = Plan::new(cases);
    let kernels: std::collections::HashSet<_> = plan.cases.iter().map(|c| &c.kernel_key).collect();
    let n = args.config.finest_points();
    let stress_bytes = args.config.stress.as_ref().map_or(0.0, |cfg| {
        crate::memory::stress_bytes(n, cfg, plan.cases.iter().map(|c| &c.spec))
    });
    crate::memory::check_fits(
        &format!(
            "the sweep{}",
            crate::memory::stress_states_note(
                args.config.stress.as_ref(),
                plan.cases.iter().map(|c| &c.spec)
            )
        ),
        crate::memory::worker_bytes(n, kernels.len()) + stress_bytes,
        args.workers,
        crate::memory::available_bytes(),
    )?;
    // The first moments of every case, before the journal is written: a
    // case a solve would refuse at once (a contact at the domain's edge)
    // refuses the sweep, as `check` does. A resumed sweep passed them when
    // it began. The kernels built here are stored for the workers.
    if !args.resume {
        crate::preflight::check(
            plan.cases.iter().map(|c| (&c.key, &c.spec)),
            crate::preflight::Kernels::Store,
        )?;
    }
    let raw = args.config.to_toml();
    let (mut recorder, resumed) =
        record::Recorder::open(plan, &args.out_dir, &run_id, &raw, args.resume, args.names)?;
    let total = recorder.plan().cases.len();
    let progress = progress::Progress::new(args.quiet, total, resumed.cases);
    if resumed.torn_tail {
        progress.note("journal: dropped a torn last line");
    }

    let mut summary = RunSummary {
        run_id: run_id.clone(),
        out_dir: args.out_dir.clone(),
        total,
        resumed: resumed.cases,
        workers: args.workers,
        started_unix_s,
        ..Default::default()
    };

    let remaining = recorder.plan().remaining();
    if remaining > 0 {
        let workers = args.workers.max(1).min(remaining);
        let exchange = exchange::Exchange::open(&run_id, workers, args.names)?;
        let mut supervisor = supervise::Supervisor::new(supervise::SuperviseArgs {
            run_id: &run_id,
            exe: &args.exe,
            out_dir: &args.out_dir,
            workers,
            case_timeout: Duration::from_secs_f64(args.config.run.case_timeout_s),
        });
        let mut dispatch = dispatch::Dispatch::new(dispatch::DispatchArgs {
            out_dir: &args.out_dir,
            save_fields: args.save_fields || args.config.output.save_fields,
            progress: &progress,
            stress: args.config.stress.clone(),
        });
        let outcome = start_workers(&mut dispatch, &mut supervisor, workers, &progress)
            .and_then(|()| dispatch.serve(&exchange, &mut supervisor, &mut recorder));
        let stats = dispatch.finish(&exchange);
        supervisor.stop_all();
        exchange.cleanup_dead_nodes();
        summary.per_worker = stats.per_worker;
        summary.ipc = stats.ipc;
        summary.rejected_messages = stats.rejected;
        outcome?;
    }
    progress.finish();

    summary.count_kernels();
    let (cases, outcomes) = recorder.results();
    summary.tally(cases, outcomes);
    summary.wall_seconds = started.elapsed().as_secs_f64();
    let solved_now = recorder.recorded() - resumed.cases;
    summary.cases_per_minute = solved_now as f64 / (summary.wall_seconds / 60.0).max(1e-9);

    let (cases, outcomes) = recorder.results();
    let orientations = args.config.orientations()?;
    write_outputs(
        &args.out_dir,
        cases,
        outcomes,
        &mut summary,
        &raw,
        &orientations,
    )?;
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
    for w in &summary.warnings {
        eprintln!("warning: {w}");
    }
    if let Some(line) = summary.without_result() {
        eprintln!("error: {line}");
    }
    Ok(summary)
}

/// Starts `workers` worker processes; goes on with those that started
/// (saying so) unless none did.
fn start_workers(
    dispatch: &mut dispatch::Dispatch,
    supervisor: &mut supervise::Supervisor,
    workers: usize,
    progress: &progress::Progress,
) -> anyhow::Result<()> {
    let mut started = 0;
    let mut last_error = None;
    for _ in 0..workers {
        match dispatch.spawn(supervisor) {
            Ok(()) => started += 1,
            Err(e) => last_error = Some(e),
        }
    }
    match last_error {
        Some(e) if started == 0 => Err(e),
        Some(e) => {
            progress.note(&format!(
                "only {started} of {workers} workers could be started ({e:#}); going on with {started}"
            ));
            Ok(())
        }
        None => Ok(()),
    }
}

/// Writes `results.csv`, `curves.csv`, the plots and `summary.json` of
/// `cases` with their `outcomes` into `dir` (a run, or a merge of shards).
fn write_outputs(
    dir: &std::path::Path,
    cases: &[PlannedCase],
    outcomes: &[Option<Outcome>],
    summary: &mut RunSummary,
    raw_config: &str,
    orientations: &[crate::config::Orientation],
) -> anyhow::Result<()> {
    let rows = calibrate::calibrate(cases, outcomes);
    // Outputs that could not be written; summary.json lists them too.
    let mut lost: Vec<String> = Vec::new();
    let write = |name: &str, text: String| atomic::write(&dir.join(name), text.as_bytes());
    write("results.csv", sweep::results_csv(&rows))?;
    let levels = cases.iter().map(|c| c.key.level + 1).max().unwrap_or(1);
    let (points, incomplete) = sweep::curve_points(&rows, levels);
    write("curves.csv", sweep::curves_csv(&points))?;
    // One definition per run (`solver.radii` is a key of the whole config).
    summary.apparent_radius_definition = cases
        .first()
        .map(|c| c.spec.numerics.radii)
        .unwrap_or_default()
        .definition();
    summary.apparent_radius_definition_cells = solver::APPARENT_RADIUS_DEFINITION_CELLS;
    summary.zone_radius_definition = solver::ZONE_RADIUS_DEFINITION;
    summary.hertz_misfit_definition = solver::HERTZ_MISFIT_DEFINITION;
    summary.hertz_misfit_limit = solver::HERTZ_MISFIT_LIMIT;
    summary.k_e_definition = solver::K_E_DEFINITION;
    summary.error_estimate = crate::convergence::ERROR_ESTIMATE;
    summary.convergence_levels = levels;
    summary.incomplete_points = incomplete.len();
    summary.curves = sweep::curve_summaries(&points);
    summary.sampling = cases
        .iter()
        .map(|c| {
            let how = c
                .spec
                .surface
                .sampling()
                .map_or("none", solver::Sampling::name);
            (c.key.surface.to_string(), how)
        })
        .collect();
    // Cases with a load history: their table and loop beside their fields.
    for r in &rows {
        let Some(h) = r.scalars.as_ref().and_then(|s| s.history.as_ref()) else {
            continue;
        };
        let key = r.key;
        let mut title = format!("{}, {}, ψ = {}°", key.material, key.surface, key.angle_deg);
        if let Some(ball) = &key.indenter {
            title.push_str(&format!(", {ball} ball"));
        }
        if let Some(n) = key.normal_n {
            title.push_str(&format!(", P = {} N", fmt_f64(n)));
        }
        if let Some(a) = key.amplitude_um {
            title.push_str(&format!(", Δ = {} µm", fmt_f64(a)));
        }
        summary
            .output_warnings
            .extend(history::path_warnings(h, &title));
        let fields = sweep::fields_dir(dir, key);
        match history::write_history(&fields, h, &r.spec.grid, &title) {
            Ok(figures) => lost.extend(figures.into_iter().map(|f| format!("{key}: {f}"))),
            Err(e) => lost.push(format!("history of {key}: {e:#}")),
        }
    }
    // With [stress]: each case's stress scalars beside its fields, the
    // value `mpcontact solve` puts under `stress` in case.json.
    for r in &rows {
        let Some(s) = r.stress else {
            continue;
        };
        let dir = sweep::fields_dir(dir, r.key);
        std::fs::create_dir_all(&dir)
            .with_context(|| format!("cannot create {}", dir.display()))?;
        let text = serde_json::to_string_pretty(s)? + "\n";
        atomic::write(&dir.join("stress.json"), text.as_bytes())?;
    }
    // A fretting map (sweep.amplitudes_um): its table, transitions, figure.
    let map = fretting_map::map_points(&rows);
    if !map.is_empty() {
        write("fretting_map.csv", fretting_map::fretting_map_csv(&map))?;
        write(
            "fretting_transitions.csv",
            fretting_map::transitions_csv(&map),
        )?;
        for name in ["fretting_map.png", "fretting_map.svg"] {
            if let Err(e) = fretting_map::plot_map(&dir.join(name), &map) {
                lost.push(format!("{name}: {e:#}"));
            }
        }
    }
    // Orientation maps (sweep.orientations): their table and the IPF maps.
    if !orientations.is_empty() {
        let table = orientation_map::orientation_rows(&rows, &points, orientations);
        write(
            "orientations.csv",
            orientation_map::orientations_csv(&table),
        )?;
        for map in orientation_map::ipf_maps(&table) {
            if let Err(e) = orientation_map::write_ipf(&dir.join("ipf"), &map) {
                lost.push(format!("ipf/{}: {e:#}", map.path.display()));
            }
        }
    }
    for name in ["mu_a_vs_angle.png", "mu_a_vs_angle.svg"] {
        if let Err(e) = sweep::plot_curves(&dir.join(name), &points, &incomplete) {
            lost.push(format!("{name}: {e:#}"));
        }
    }
    summary.output_warnings.extend(lost.iter().cloned());
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
    // An output that could not be written is an error (#59: a history lost
    // to a file name too long was only a line in summary.json), said after
    // everything else was written.
    if !lost.is_empty() {
        anyhow::bail!(
            "{} output(s) of {} could not be written (the others were):\n  {}",
            lost.len(),
            dir.display(),
            lost.join("\n  ")
        );
    }
    Ok(())
}
