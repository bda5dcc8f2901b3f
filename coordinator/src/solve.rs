//! `mpcontact solve`: one case in-process (no IPC), for inspection — writes
//! `case.json`, the fields as `.npy` (via `npy`) and their PNG maps. Touches
//! no sweep state (plan, journal, workers).

use crate::case::Status;
use crate::config::Config;
use crate::npy::write_fields;
use anyhow::{anyhow, Context, Result};
use serde::Serialize;
use solver::{calibrate_on_flat, solve_case, CaseScalars, CaseSpec, Surface};
use std::path::Path;

/// What `case.json` holds.
#[derive(Serialize)]
struct CaseJson<'a> {
    material: &'a str,
    surface: &'a str,
    angle_deg: f64,
    status: Status,
    #[serde(flatten)]
    scalars: &'a CaseScalars,
    apparent_radius_definition: &'static str,
    apparent_radius_definition_cells: &'static str,
    grid_points: usize,
    spacing_m: f64,
    spec: &'a CaseSpec,
}

/// Options of `mpcontact solve`.
pub struct SolveArgs<'a> {
    /// Material name (default: the sweep's first).
    pub material: Option<&'a str>,
    /// Surface name (default: the sweep's first).
    pub surface: Option<&'a str>,
    /// Force angle (default: the sweep's first).
    pub angle_deg: Option<f64>,
    /// Output directory.
    pub out: &'a Path,
}

/// Solves one case of `config` and writes its outputs; returns its scalars.
pub fn run_solve(config: &Config, args: &SolveArgs) -> Result<CaseScalars> {
    let material = args.material.unwrap_or(&config.sweep.materials[0]);
    let surface = args.surface.unwrap_or(&config.sweep.surfaces[0]);
    let angle = match args.angle_deg {
        Some(a) => a,
        None => config.sweep.angles_deg.values()?[0],
    };
    let spec = config.spec(material, surface, angle)?;
    spec.validate()
        .map_err(|e| config.explain(e, material, surface))?;
    crate::memory::check_fits(
        "this case",
        crate::memory::worker_bytes(spec.grid.n, 1),
        1,
        crate::memory::available_bytes(),
    )?;
    let mut cache = worker::kernel_store::FileStore::cache();
    let out =
        solve_case(&spec, &mut cache).map_err(|e| anyhow!("{material}/{surface}/{angle}°: {e}"))?;
    let mut scalars = out.scalars;
    // Anisotropic material: K_E from the flat twin (docs/physics-choices.md,
    // "Reported quantities").
    if spec.needs_flat_calibration() && scalars.mu_a.is_some() {
        let flat = if spec.surface == Surface::Flat {
            scalars.clone()
        } else {
            solve_case(&spec.flat_twin(), &mut cache)
                .map_err(|e| anyhow!("flat twin for K_E: {e}"))?
                .scalars
        };
        calibrate_on_flat(&mut scalars, &flat, &spec.load);
    }
    std::fs::create_dir_all(args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let json = CaseJson {
        material,
        surface,
        angle_deg: angle,
        status: Status::of_solved(scalars.converged),
        scalars: &scalars,
        apparent_radius_definition: solver::APPARENT_RADIUS_DEFINITION,
        apparent_radius_definition_cells: solver::APPARENT_RADIUS_DEFINITION_CELLS,
        grid_points: spec.grid.n,
        spacing_m: spec.grid.dx,
        spec: &spec,
    };
    let path = args.out.join("case.json");
    crate::atomic::write(&path, serde_json::to_string_pretty(&json)?.as_bytes())?;
    write_fields(args.out, &out.fields)?;
    // The numbers are written first; a picture that cannot be drawn (e.g. no
    // system font) is a warning, not a lost result.
    let title = format!("{material}, {surface}, ψ = {angle}°");
    if let Err(e) = crate::maps::write_maps(args.out, &title, &out.fields, &scalars, spec.grid.dx) {
        eprintln!("warning: maps not written: {e:#}");
    }
    Ok(scalars)
}
