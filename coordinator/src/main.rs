//! `mpcontact`: frictional contact of a rigid sphere on an (an)isotropic,
//! micropatterned half-space — single solves, kernels, materials, and sweeps
//! over worker processes. Thin: parses arguments and wires the libraries.

use anyhow::{anyhow, bail, Context, Result};
use clap::{Parser, Subcommand};
use coordinator::config::Config;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "mpcontact",
    version,
    about = "Frictional contact of a sphere on an (an)isotropic, micropatterned half-space"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
    /// Run a sweep (materials × surfaces × force angles) on worker processes.
    Run {
        /// Config file (default: configs/quick.toml).
        config: Option<PathBuf>,
        /// Number of worker processes (default: number of cores).
        #[arg(long)]
        workers: Option<usize>,
        /// Output directory (default: out/<config's file stem>, and
        /// out/<stem>/shard-K for `--shard K/N`).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Continue an interrupted sweep from DIR/journal.jsonl.
        #[arg(long)]
        resume: bool,
        /// No progress output.
        #[arg(long)]
        quiet: bool,
        /// Also write the fields of every case (fields/<case>/).
        #[arg(long)]
        save_fields: bool,
        /// Override one config key, e.g. --set grid.points=128.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Check everything and print what the sweep would do; solve nothing, write nothing.
        #[arg(long)]
        dry_run: bool,
        /// Solve every case on L grids of the same domain (cell sizes h,
        /// h/√2, h/2, …) and report μa with an error bar (= --set convergence.levels=L).
        #[arg(long, value_name = "L")]
        refine: Option<usize>,
        /// Run only shard K of N (0-based), e.g. 0/4; `slurm` reads
        /// SLURM_ARRAY_TASK_ID / SLURM_ARRAY_TASK_COUNT. Merge with `mpcontact merge`.
        #[arg(long)]
        shard: Option<String>,
    },
    /// Merge the output directories of a sharded sweep into one run's outputs.
    Merge {
        /// The shard directories (all N of them).
        #[arg(required = true)]
        shards: Vec<PathBuf>,
        /// Output directory of the merged results.
        #[arg(long)]
        out: PathBuf,
    },
    /// Load and check a config and print what `run` would do (= run --dry-run).
    Check {
        /// Config file.
        config: PathBuf,
        /// Number of worker processes (default: number of cores).
        #[arg(long)]
        workers: Option<usize>,
        /// Override one config key.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// As `run --refine L`: a convergence ladder of L grids.
        #[arg(long, value_name = "L")]
        refine: Option<usize>,
        /// The output directory `run` would write into (default: out/<config's
        /// file stem>): whether it already holds a sweep.
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Solve one case in-process and write case.json and the fields.
    Solve {
        /// Config file.
        config: PathBuf,
        /// Material (default: the sweep's first).
        #[arg(long)]
        material: Option<String>,
        /// Surface (default: the sweep's first).
        #[arg(long)]
        surface: Option<String>,
        /// Force direction in degrees (default: the sweep's first).
        #[arg(long = "angle-deg", allow_hyphen_values = true)]
        angle_deg: Option<f64>,
        /// The ball: `rigid`, a preset or a [materials.NAME] table (default:
        /// the first of sweep.indenters, else indenter.material, else rigid).
        #[arg(long)]
        indenter: Option<String>,
        /// Output directory (default: out-solve/<config's file stem>).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Override one config key.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        sets: Vec<String>,
        /// Threads for this one case (default: all cores); the results are
        /// the same to the bit for any number.
        #[arg(long, value_name = "N")]
        threads: Option<std::num::NonZeroUsize>,
        /// No progress line on stderr (there is none when stderr is not a terminal).
        #[arg(long)]
        quiet: bool,
    },
    /// Print the Fourier-domain surface compliance H(θ) of a material as JSON.
    Kernel {
        /// Material preset name.
        #[arg(long)]
        material: String,
        /// Angles START:STOP:STEP in degrees (stop included).
        #[arg(long = "angles-deg", default_value = "0:180:15")]
        angles_deg: String,
    },
    /// List the preset materials and their constants.
    Materials,
    /// Worker process (started by `run`).
    Worker {
        /// Run id to attach to.
        #[arg(long)]
        run: String,
        /// Worker index (unique within the run; default derived from the pid).
        #[arg(long)]
        index: Option<usize>,
    },
}

fn parse_angles(s: &str) -> Result<Vec<f64>> {
    let parts: Vec<&str> = s.split(':').collect();
    let bad = || anyhow!("--angles-deg {s}: expected START:STOP:STEP, e.g. 0:180:15");
    if parts.len() != 3 {
        return Err(bad());
    }
    let v: Vec<f64> = parts
        .iter()
        .map(|p| p.trim().parse::<f64>())
        .collect::<Result<_, _>>()
        .map_err(|_| bad())?;
    coordinator::config::AnglesCfg::Range {
        start: v[0],
        stop: v[1],
        step: v[2],
    }
    .values()
}

fn kernel_json(material: &str, angles: &[f64]) -> Result<String> {
    let m = solver::presets::material(material).ok_or_else(|| {
        anyhow!("--material {material}: unknown preset (see `mpcontact materials`)")
    })?;
    let rows: Vec<serde_json::Value> = angles
        .iter()
        .map(|&deg| {
            let h = m.surface_compliance(deg.to_radians());
            let part = |f: fn(&num_complex::Complex64) -> f64| -> Vec<Vec<f64>> {
                (0..3)
                    .map(|i| (0..3).map(|j| f(&h[(i, j)])).collect())
                    .collect()
            };
            serde_json::json!({
                "material": material,
                "theta_deg": deg,
                "H_re": part(|z| z.re),
                "H_im": part(|z| z.im),
            })
        })
        .collect();
    Ok(serde_json::to_string_pretty(&rows)?)
}

fn materials_table() -> String {
    let mut s =
        String::from("name       kind         E_eq_GPa  nu_eq   constants (GPa)  [source]\n");
    for m in solver::presets::materials() {
        let model = m.model();
        s.push_str(&format!(
            "{:<10} {:<12} {:>8.2}  {:<6}  {}  [{}]\n",
            m.name,
            model.kind(),
            m.equivalent.youngs / 1e9,
            m.equivalent.poisson,
            model.describe(),
            solver::presets::material_source(&m.name)
        ));
    }
    s.push_str("\nFrame: x, y in the surface, z into the body. (111) crystals: z ∥ [111], x ∥ [1,1,-2], y = z × x;\nE_eq, nu_eq are the paper's isotropic-equivalent values, used only to normalise (Hertz a, p_H) and in\nthe isotropic μa formula. Your own materials: [materials.NAME] in the config (docs/config.md).\n");
    s
}

/// `--workers`, or the number of cores.
fn worker_count(workers: Option<usize>) -> Result<usize> {
    let workers = workers.unwrap_or_else(|| {
        std::thread::available_parallelism()
            .map(|n| n.get())
            .unwrap_or(1)
    });
    if workers == 0 {
        bail!("--workers must be at least 1");
    }
    Ok(workers)
}

/// The dry-run report, headed by the config's path, with the folder `run`
/// would write into (`out`) and what it holds.
fn check_report(
    path: &std::path::Path,
    config: &Config,
    workers: usize,
    out: &std::path::Path,
) -> Result<String> {
    let journal = coordinator::run::JOURNAL_FILE;
    let output = if out.join(journal).exists() {
        format!(
            "{} holds a sweep ({journal}): `run` continues it with --resume, or give another --out",
            out.display()
        )
    } else {
        out.display().to_string()
    };
    Ok(format!(
        "config:    {} (valid)\n{}output:    {output}\nnothing was written (dry run; of the cases only their normal contacts were solved)\n",
        path.display(),
        coordinator::dry_run::report(config, workers)?
    ))
}

/// The program workers are started from: this very one. Linux's
/// `/proc/self/exe` names the running image even after the file at its path
/// was rebuilt or removed, so a replacement worker never runs another build
/// (#20 item 12); elsewhere, the path this program was started from.
fn worker_exe() -> Result<PathBuf> {
    let this = std::path::Path::new("/proc/self/exe");
    if this.exists() {
        return Ok(this.to_path_buf());
    }
    std::env::current_exe().context("cannot locate the mpcontact executable")
}

/// Success when every case has an `ok` result, else
/// [`coordinator::case::EXIT_NOT_ALL_OK`] (the outputs are written).
fn all_ok(ok: bool) -> ExitCode {
    if ok {
        ExitCode::SUCCESS
    } else {
        ExitCode::from(coordinator::case::EXIT_NOT_ALL_OK)
    }
}

/// Where `run` and `solve` write without `--out`: a folder named after the
/// config file (`configs/quick.toml` → `quick`), under `out/` for a sweep
/// (`out/<stem>/shard-K` for one shard) and `out-solve/` for one case. Two
/// configs' sweeps never share a journal (a second sweep into one folder is
/// refused: it would need `--resume`), and a solve never writes into a
/// sweep's folder. A second solve of one config is a re-run and replaces it.
fn default_out(
    root: &str,
    config: &std::path::Path,
    shard: Option<coordinator::shard::Shard>,
) -> PathBuf {
    let stem = config
        .file_stem()
        .unwrap_or_else(|| std::ffi::OsStr::new("config"));
    let dir = std::path::Path::new(root).join(stem);
    match shard {
        Some(s) => dir.join(format!("shard-{}", s.index)),
        None => dir,
    }
}

/// `--refine L` is `--set convergence.levels=L` (one place for the key).
fn refine_set(refine: Option<usize>) -> Option<String> {
    refine.map(|levels| format!("convergence.levels={levels}"))
}

fn real_main() -> Result<ExitCode> {
    match Cli::parse().cmd {
        Cmd::Run {
            config,
            workers,
            out,
            resume,
            quiet,
            save_fields,
            mut sets,
            dry_run,
            refine,
            shard,
        } => {
            sets.extend(refine_set(refine));
            let shard = shard
                .as_deref()
                .map(coordinator::shard::Shard::parse)
                .transpose()?;
            let path = config.unwrap_or_else(|| PathBuf::from("configs/quick.toml"));
            let out = out.unwrap_or_else(|| default_out("out", &path, shard));
            let config = Config::load(&path, &sets)?;
            let workers = worker_count(workers)?;
            if dry_run {
                print!("{}", check_report(&path, &config, workers, &out)?);
                return Ok(ExitCode::SUCCESS);
            }
            for w in config.unresolved_patterns(&config.sweep.surfaces)? {
                eprintln!("warning: {w}");
            }
            let args = coordinator::run::RunArgs {
                config,
                workers,
                out_dir: out,
                resume,
                quiet,
                save_fields,
                exe: coordinator::run::WorkerCommand::mpcontact(worker_exe()?),
                shard,
                names: coordinator::run::OptionNames::CLI,
            };
            let summary = coordinator::run::run_sweep(&args)?;
            Ok(all_ok(summary.without_result().is_none()))
        }
        Cmd::Solve {
            config,
            material,
            surface,
            angle_deg,
            indenter,
            out,
            sets,
            threads,
            quiet,
        } => {
            let cfg = Config::load(&config, &sets)?;
            let out = out.unwrap_or_else(|| default_out("out-solve", &config, None));
            let threads = threads.map_or_else(solver::Threads::available, |n| n.get());
            let s = coordinator::solve::run_solve(
                &cfg,
                &coordinator::solve::SolveArgs {
                    material: material.as_deref(),
                    surface: surface.as_deref(),
                    angle_deg,
                    indenter: indenter.as_deref(),
                    out: &out,
                    threads,
                    quiet,
                },
            )?;
            println!(
                "a = {:.6e} m, c = {:.6e} m, δz = {:.6e} m, δt = {:.6e} m, p_max = {:.6e} Pa, μa = {}{} (paper's whole-cell radii: {}), converged = {} → {}",
                s.contact_radius_m,
                s.stick_radius_m,
                s.delta_z_m,
                s.delta_t_m,
                s.p_max_pa,
                s.mu_a.map(|v| format!("{v:.5}")).unwrap_or_else(|| "n/a".into()),
                if s.mu_a_non_hertz() == Some(true) {
                    " (flagged: the pressure is not Hertz's)"
                } else {
                    ""
                },
                s.mu_a_cells.map(|v| format!("{v:.5}")).unwrap_or_else(|| "n/a".into()),
                s.converged,
                out.join("case.json").display()
            );
            if !s.converged {
                eprintln!(
                    "error: the case did not converge (status not_converged; case.json gives the residuals); its numbers are written but are not a solution (exit status {})",
                    coordinator::case::EXIT_NOT_ALL_OK
                );
            }
            Ok(all_ok(s.converged))
        }
        Cmd::Merge { shards, out } => {
            let s = coordinator::run::merge_shards(&shards, &out)?;
            eprintln!(
                "merged {} shards: {} cases, {} ok, {} not converged, {} failed → {}",
                shards.len(),
                s.total,
                s.ok,
                s.not_converged,
                s.failed,
                out.display()
            );
            if let Some(line) = s.without_result() {
                eprintln!("error: {line}");
            }
            Ok(all_ok(s.without_result().is_none()))
        }
        Cmd::Check {
            config,
            workers,
            mut sets,
            refine,
            out,
        } => {
            sets.extend(refine_set(refine));
            let cfg = Config::load(&config, &sets)?;
            let out = out.unwrap_or_else(|| default_out("out", &config, None));
            print!(
                "{}",
                check_report(&config, &cfg, worker_count(workers)?, &out)?
            );
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Kernel {
            material,
            angles_deg,
        } => {
            println!("{}", kernel_json(&material, &parse_angles(&angles_deg)?)?);
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Materials => {
            print!("{}", materials_table());
            Ok(ExitCode::SUCCESS)
        }
        Cmd::Worker { run, index } => {
            let end = worker::run_worker::<coordinator::case::CaseKey>(
                &run,
                index.unwrap_or(1000 + std::process::id() as usize),
            )?;
            if end == worker::WorkerEnd::CoordinatorGone {
                // Tells our coordinator, should it still be there, that this
                // worker held no case (see protocol::EXIT_LEFT_WAITING).
                return Ok(ExitCode::from(protocol::EXIT_LEFT_WAITING));
            }
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn main() -> ExitCode {
    match real_main() {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}
