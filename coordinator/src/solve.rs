//! One case in-process (no IPC), for inspection. [`solve_in_memory`] is the
//! part shared by `mpcontact solve` and the Python module (spec, memory
//! check, solve, flat-twin K_E, the `case.json` value); [`write_solved`] is
//! the CLI's files (`case.json`, `.npy` fields, PNG maps: `output`), and
//! [`run_solve`] the CLI's whole command (with its progress line,
//! `solve_progress`). Touches no sweep state (plan, journal, workers).

use crate::case::Status;
use crate::config::Config;
use crate::output::npy::write_fields;
use crate::solve_progress::SolveProgress;
use anyhow::{anyhow, Context, Result};
use serde::Serialize;
use solver::{calibrate_on_flat, solve_case, CaseScalars, CaseSpec, Fields, Surface};
use std::path::Path;

/// What `case.json` holds (and, as the same serde value, Python's
/// `Result.scalars`: a key added here reaches both).
#[derive(Serialize)]
pub struct CaseJson<'a> {
    material: &'a str,
    /// The ball's material, or `rigid`.
    indenter: &'a str,
    surface: &'a str,
    angle_deg: f64,
    status: Status,
    #[serde(flatten)]
    scalars: &'a CaseScalars,
    zone_radius_definition: &'static str,
    apparent_radius_definition: &'static str,
    apparent_radius_definition_cells: &'static str,
    hertz_misfit_definition: &'static str,
    hertz_misfit_limit: f64,
    /// μa flagged: the pressure is further from Hertz's than
    /// `hertz_misfit_limit` (absent without μa).
    #[serde(skip_serializing_if = "Option::is_none")]
    mu_a_non_hertz: Option<bool>,
    grid_points: usize,
    spacing_m: f64,
    spec: &'a CaseSpec,
    /// With a load history: energy dissipated over the last full cycle, J.
    #[serde(skip_serializing_if = "Option::is_none")]
    dissipated_energy_per_cycle_j: Option<f64>,
    /// With a load history: the loop's area over the same cycle, J.
    #[serde(skip_serializing_if = "Option::is_none")]
    loop_area_per_cycle_j: Option<f64>,
    /// With a load history: stiffness right after the last reversal, N/m.
    #[serde(skip_serializing_if = "Option::is_none")]
    reversal_stiffness_n_per_m: Option<f64>,
    /// With a load history: δt along the force where F crosses zero on unloading, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    residual_delta_t_m: Option<f64>,
    /// With a load history: how the dissipated energy is computed.
    #[serde(skip_serializing_if = "Option::is_none")]
    dissipation_definition: Option<&'static str>,
    /// With a load history: the last cycle's force amplitude F*, N.
    #[serde(skip_serializing_if = "Option::is_none")]
    force_amplitude_n: Option<f64>,
    /// With a load history: the last cycle's shift amplitude δ*, m.
    #[serde(skip_serializing_if = "Option::is_none")]
    shift_amplitude_m: Option<f64>,
    /// With a load history: the energy ratio A = W/(4 F* δ*) of the last cycle.
    #[serde(skip_serializing_if = "Option::is_none")]
    energy_ratio: Option<f64>,
    /// With a load history: partial, gross or mixed slip over its cycles.
    #[serde(skip_serializing_if = "Option::is_none")]
    slip_regime: Option<&'a str>,
    /// With a load history: how the slip regime is decided.
    #[serde(skip_serializing_if = "Option::is_none")]
    slip_regime_definition: Option<&'static str>,
    /// With `[stress]`: maxima below the surface, the surface peak and
    /// the fatigue parameter (`crate::output::stress`).
    #[serde(skip_serializing_if = "Option::is_none")]
    stress: Option<&'a crate::output::stress::StressScalars>,
    /// On a scan or random surface: its source, pixels, preparation and
    /// roughness (Sa, Sq, Sz, Sdq) as prepared and on this grid.
    #[serde(skip_serializing_if = "Option::is_none")]
    surface_scan: Option<&'a crate::config::ScanReport>,
}

/// Options of `mpcontact solve`.
pub struct SolveArgs<'a> {
    /// Material name (default: the sweep's first).
    pub material: Option<&'a str>,
    /// Surface name (default: the sweep's first).
    pub surface: Option<&'a str>,
    /// Force angle (default: the sweep's first).
    pub angle_deg: Option<f64>,
    /// The ball: `rigid`, a preset or a `[materials.NAME]` table (default:
    /// the first of `sweep.indenters`, else `indenter.material`, else rigid).
    pub indenter: Option<&'a str>,
    /// Output directory.
    pub out: &'a Path,
    /// Threads for the case (results do not depend on it).
    pub threads: usize,
    /// No progress line (there is none anyway when stderr is not a terminal).
    pub quiet: bool,
}

/// One case picked from a config and checked: its names and its spec.
#[derive(Clone, Debug)]
pub struct CaseChoice {
    /// Material name.
    pub material: String,
    /// Surface name (or the label of a surface given directly).
    pub surface: String,
    /// Force angle, degrees.
    pub angle_deg: f64,
    /// The spec, validated.
    pub spec: CaseSpec,
    /// `[stress]` of the config: stresses below the surface after the solve.
    pub stress: Option<crate::config::StressCfg>,
    /// A scan or random surface: what it is and its roughness on this
    /// case's grid (`case.json`'s `surface_scan`).
    pub scan: Option<crate::config::ScanReport>,
}

impl CaseChoice {
    /// The warning `check`, `solve` and `run` give when the grid does not
    /// resolve this case's pattern (`surface `NAME`: …`, see
    /// [`Config::unresolved_patterns`]); `None` when it does.
    pub fn unresolved_pattern(&self) -> Option<String> {
        let w = self.spec.surface.unresolved_pattern(&self.spec.grid)?;
        Some(format!("surface `{}`: {w}", self.surface))
    }

    /// The case `material` × `surface` × `angle_deg` of `config`; each
    /// defaults to the sweep's first. Errors name config keys.
    pub fn new(
        config: &Config,
        material: Option<&str>,
        surface: Option<&str>,
        angle_deg: Option<f64>,
    ) -> Result<Self> {
        let first = config.first_material()?;
        let material = material.unwrap_or(&first);
        let surface = surface.unwrap_or(&config.sweep.surfaces[0]);
        let angle = Self::angle(config, angle_deg)?;
        let spec = config.spec(material, surface, angle)?;
        let mut case = Self::checked(config, material, surface, angle, spec)?;
        case.scan = config.scan_report(surface, 0)?;
        Ok(case)
    }

    /// The same on a surface given directly (Python's height arrays),
    /// called `label` in outputs and errors.
    pub fn on_surface(
        config: &Config,
        material: Option<&str>,
        label: &str,
        surface: Surface,
        angle_deg: Option<f64>,
    ) -> Result<Self> {
        let first = config.first_material()?;
        let material = material.unwrap_or(&first);
        let angle = Self::angle(config, angle_deg)?;
        let spec = config.spec_on(material, surface, angle)?;
        Self::checked(config, material, label, angle, spec)
    }

    /// The same case pressed by the ball `name` (`rigid`, a preset or a
    /// `[materials.NAME]` table) instead of the config's first; `key` is
    /// the option that gave it, named in errors (`--indenter`).
    pub fn with_indenter(mut self, config: &Config, key: &str, name: &str) -> Result<Self> {
        self.spec.indenter = config.ball(key, name)?;
        self.spec
            .validate()
            .map_err(|e| config.explain_pressed(e, &self.material, &self.surface, Some(name)))?;
        Ok(self)
    }

    fn angle(config: &Config, angle_deg: Option<f64>) -> Result<f64> {
        match angle_deg {
            Some(a) => Ok(a),
            None => Ok(config.sweep.angles_deg.values()?[0]),
        }
    }

    fn checked(
        config: &Config,
        material: &str,
        surface: &str,
        angle_deg: f64,
        mut spec: CaseSpec,
    ) -> Result<Self> {
        // One case is looked at: its last cycle's loop is sampled unless
        // the config says otherwise (a sweep samples none by default).
        if let (Some(h), Some(cfg)) = (spec.history.as_mut(), config.history.as_ref()) {
            if cfg.loop_increments.is_none() {
                h.sampling.increments = crate::config::SOLVE_LOOP_INCREMENTS;
            }
        }
        let ball = match &config.sweep.indenters {
            Some(names) => Some(names[0].as_str()),
            None => config.indenter.material.as_deref(),
        };
        spec.validate()
            .map_err(|e| config.explain_pressed(e, material, surface, ball))?;
        Ok(CaseChoice {
            material: material.to_string(),
            surface: surface.to_string(),
            angle_deg,
            spec,
            stress: config.stress.clone(),
            scan: None,
        })
    }
}

/// A solved case: what it was, its scalars (K_E calibrated) and fields.
pub struct Solved {
    /// The case.
    pub case: CaseChoice,
    /// Scalars, with an anisotropic material's K_E from its flat twin.
    pub scalars: CaseScalars,
    /// Fields of the case itself.
    pub fields: Fields,
    /// With `[stress]`: the stresses below the surface.
    pub stress: Option<crate::output::stress::StressOutput>,
}

impl Solved {
    /// The warning of a case whose peak pressure exceeds a preset's
    /// typical hardness with no `hardness_gpa` to cap it (#59), naming the
    /// key that would; `None` when it does not.
    pub fn beyond_hardness(&self) -> Option<String> {
        let p_max = self.scalars.p_max_pa;
        let (m, range) = self.case.spec.pressure_beyond_hardness(p_max)?;
        Some(format!(
            "p_max = {:.2} GPa exceeds the typical hardness of {} ({:.1}–{:.1} GPa, {}): a real surface yields there; set [materials.{}] hardness_gpa to cap the pressure",
            p_max / 1e9,
            m.name,
            range.low_pa / 1e9,
            range.high_pa / 1e9,
            range.what,
            m.name
        ))
    }

    /// The `case.json` of this case (serialize it, or turn it into another
    /// serde value).
    pub fn case_json(&self) -> CaseJson<'_> {
        let c = &self.case;
        let h = self.scalars.history.as_ref();
        CaseJson {
            material: &c.material,
            indenter: c
                .spec
                .indenter
                .as_ref()
                .map_or("rigid", |m| m.name.as_str()),
            surface: &c.surface,
            angle_deg: c.angle_deg,
            status: Status::of_solved(self.scalars.converged),
            scalars: &self.scalars,
            zone_radius_definition: solver::ZONE_RADIUS_DEFINITION,
            apparent_radius_definition: c.spec.numerics.radii.definition(),
            apparent_radius_definition_cells: solver::APPARENT_RADIUS_DEFINITION_CELLS,
            hertz_misfit_definition: solver::HERTZ_MISFIT_DEFINITION,
            hertz_misfit_limit: solver::HERTZ_MISFIT_LIMIT,
            mu_a_non_hertz: self.scalars.mu_a_non_hertz(),
            grid_points: c.spec.grid.n,
            spacing_m: c.spec.grid.dx,
            spec: &c.spec,
            dissipated_energy_per_cycle_j: h.and_then(|h| h.dissipated_energy_per_cycle_j),
            loop_area_per_cycle_j: h.and_then(|h| h.loop_area_per_cycle_j),
            reversal_stiffness_n_per_m: h.and_then(|h| h.reversal_stiffness_n_per_m),
            residual_delta_t_m: h.and_then(|h| h.residual_delta_t_m),
            dissipation_definition: h.map(|_| solver::DISSIPATION_DEFINITION),
            force_amplitude_n: h.and_then(|h| h.force_amplitude_n),
            shift_amplitude_m: h.and_then(|h| h.shift_amplitude_m),
            energy_ratio: h.and_then(|h| h.energy_ratio),
            slip_regime: h.and_then(|h| h.regime.as_deref()),
            slip_regime_definition: h
                .and_then(|h| h.regime.as_ref())
                .map(|_| solver::SLIP_REGIME_DEFINITION),
            stress: self.stress.as_ref().map(|s| &s.scalars),
            surface_scan: c.scan.as_ref(),
        }
    }
}

/// Solves one case in memory on `threads` threads: memory check, the
/// solve, and for an anisotropic material K_E from its flat twin. Writes
/// nothing. The results are the same to the bit for any thread count.
pub fn solve_in_memory(case: CaseChoice, threads: usize) -> Result<Solved> {
    let spec = &case.spec;
    crate::memory::check_fits(
        &format!(
            "this case ({0} x {0} cells{1})",
            spec.grid.n,
            crate::memory::stress_states_note(case.stress.as_ref(), std::iter::once(spec))
        ),
        crate::memory::worker_bytes(spec.grid.n, 1)
            + case.stress.as_ref().map_or(0.0, |cfg| {
                crate::memory::stress_bytes(spec.grid.n, cfg, std::iter::once(spec))
            }),
        1,
        crate::memory::available_bytes(),
    )?;
    let mut cache = worker::kernel_store::FileStore::cache();
    cache.set_threads(solver::Threads::new(threads).map_err(|e| anyhow!("--threads: {e}"))?);
    let (material, surface, angle) = (&case.material, &case.surface, case.angle_deg);
    let out =
        solve_case(spec, &mut cache).map_err(|e| anyhow!("{material}/{surface}/{angle}°: {e}"))?;
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
    let stress = match &case.stress {
        Some(cfg) => Some(crate::output::stress::compute(
            cfg,
            spec,
            &scalars,
            &out.fields,
            &out.turning,
        )?),
        None => None,
    };
    Ok(Solved {
        case,
        scalars,
        fields: out.fields,
        stress,
    })
}

/// Writes `case.json`, the fields as `.npy` and their PNG maps into `out`.
/// The numbers are written first; a picture that cannot be drawn (e.g. no
/// system font) is an error too, once everything else is written (#59:
/// no output is lost without a word).
pub fn write_solved(solved: &Solved, out: &Path) -> Result<()> {
    std::fs::create_dir_all(out).with_context(|| format!("cannot create {}", out.display()))?;
    let path = out.join("case.json");
    let json = serde_json::to_string_pretty(&solved.case_json())?;
    crate::output::atomic::write(&path, json.as_bytes())?;
    write_fields(out, &solved.fields)?;
    let c = &solved.case;
    let title = format!("{}, {}, ψ = {}°", c.material, c.surface, c.angle_deg);
    let mut lost = Vec::new();
    if let Some(h) = &solved.scalars.history {
        lost.extend(crate::output::history::write_history(
            out,
            h,
            &c.spec.grid,
            &title,
        )?);
        for w in crate::output::history::path_warnings(h, &title) {
            eprintln!("warning: {w}");
        }
    }
    if let Err(e) = crate::output::maps::write_maps(
        out,
        &title,
        &solved.fields,
        &solved.scalars,
        c.spec.grid.dx,
    ) {
        lost.push(format!("maps: {e:#}"));
    }
    if let Surface::Heightmap { heights, .. } | Surface::Resampled { heights, .. } = &c.spec.surface
    {
        let grid = &c.spec.grid;
        if let Err(e) = crate::output::maps::write_surface_map(
            out,
            &title,
            heights,
            &solved.fields,
            (grid.dx, grid.dy),
        ) {
            eprintln!("warning: surface map not written: {e:#}");
        }
    }
    if let Some(stress) = &solved.stress {
        lost.extend(crate::output::stress::write(out, stress, &title)?);
    }
    if !lost.is_empty() {
        anyhow::bail!(
            "{} output(s) of {} could not be written (the others were):\n  {}",
            lost.len(),
            out.display(),
            lost.join("\n  ")
        );
    }
    Ok(())
}

/// Solves one case of `config` and writes its outputs; returns its scalars.
pub fn run_solve(config: &Config, args: &SolveArgs) -> Result<CaseScalars> {
    let mut case = CaseChoice::new(config, args.material, args.surface, args.angle_deg)?;
    if let Some(name) = args.indenter {
        case = case.with_indenter(config, "--indenter", name)?;
    }
    if let Some(w) = case.unresolved_pattern() {
        eprintln!("warning: {w}");
    }
    let label = format!("{}/{}/{}°", case.material, case.surface, case.angle_deg);
    let progress = SolveProgress::start(args.quiet, &label);
    let solved = solve_in_memory(case, args.threads);
    // The line is cleared before anything else is printed (warnings, the result).
    drop(progress);
    let solved = solved?;
    if let Some(w) = solved.beyond_hardness() {
        eprintln!("warning: {w}");
    }
    write_solved(&solved, args.out)?;
    Ok(solved.scalars)
}

#[cfg(test)]
mod tests {
    use super::*;

    const BALLS: &str = r#"
[grid]
points = 64
spacing_um = 2.0

[indenter]
radius_mm = 18.0

[load]
normal_n = 20.0
friction = 0.3

[sweep]
materials = ["Fe"]
indenters = ["steel", "rigid"]
"#;

    #[test]
    fn issue35_solve_takes_the_axis_first_ball_or_the_one_named() {
        let c = Config::parse(BALLS, &[]).unwrap();
        let first = CaseChoice::new(&c, None, None, None).unwrap();
        assert_eq!(first.spec.indenter.as_ref().unwrap().name, "steel");
        let rigid = first
            .clone()
            .with_indenter(&c, "--indenter", "rigid")
            .unwrap();
        assert!(rigid.spec.indenter.is_none());
        let wc = first.clone().with_indenter(&c, "--indenter", "WC").unwrap();
        assert_eq!(wc.spec.indenter.as_ref().unwrap().name, "WC");
        let e = format!(
            "{:#}",
            first
                .with_indenter(&c, "--indenter", "Mithril")
                .unwrap_err()
        );
        assert!(e.contains("--indenter: unknown material `Mithril`"), "{e}");
    }

    /// Issue #59: island edges on Table 1(c) Cu reach 3.6–16 GPa elastic,
    /// beyond copper's 0.4–1.2 GPa: `solve` warns, naming
    /// `materials.Cu.hardness_gpa`; the flat contact (p_H = 0.85 GPa, under
    /// the range's top) does not, nor does a case with a hardness.
    #[test]
    fn issue59_an_elastic_pressure_beyond_a_presets_hardness_warns_naming_the_key() {
        let text = "[grid]\npoints = 64\nspacing_um = 100.0\n[indenter]\nradius_mm = 200.0\n[load]\nnormal_n = 6000.0\nfriction = 0.3\ntangential_ratio = 0.3\n[sweep]\nmaterials = [\"Cu\"]\nsurfaces = [\"circle-B\", \"flat\"]\nangles_deg = [0.0]\n[solver]\ncoupling = false\n";
        let solve = |text: &str, surface: &str| {
            let c = Config::parse(text, &[]).unwrap();
            solve_in_memory(CaseChoice::new(&c, None, Some(surface), None).unwrap(), 1).unwrap()
        };
        let islands = solve(text, "circle-B");
        let range = solver::presets::hardness_range("Cu").unwrap();
        assert!(islands.scalars.p_max_pa > range.high_pa);
        let w = islands.beyond_hardness().expect("a warning");
        assert!(w.contains("[materials.Cu] hardness_gpa"), "{w}");
        let flat = solve(text, "flat");
        assert!(flat.scalars.p_max_pa < range.high_pa);
        assert_eq!(flat.beyond_hardness(), None);
        let capped = solve(
            &format!("{text}[materials.Cu]\nhardness_gpa = 1.0\n"),
            "circle-B",
        );
        assert_eq!(capped.beyond_hardness(), None);
    }

    const FE: &str = "[grid]\npoints = 64\nspacing_um = 5.0\n[indenter]\nradius_mm = 18.0\n[load]\nnormal_n = 20.0\nfriction = 0.28571\n[sweep]\nmaterials = [\"Fe\"]\nangles_deg = [0.0]\n[history]\ntangential_ratios = [0.0, 0.6, -0.6]\nsteps_per_segment = 2\n";

    /// A fretting path's turning states: the frictionless start has the
    /// Hertz von Mises peak (0.62 p_H, Hamilton), the two reversed
    /// states mirror each other (trailing-edge tension behind the force),
    /// and the files and keys appear only with the section.
    #[test]
    fn issue38_turning_states_mirror_and_outputs_only_with_the_section() {
        let text = format!("{FE}[stress]\ndepths_um = [0.0]\nslice_rows = 16\n");
        let c = Config::parse(&text, &[]).unwrap();
        let solved = solve_in_memory(CaseChoice::new(&c, None, None, None).unwrap(), 1).unwrap();
        let s = &solved.stress.as_ref().unwrap().scalars;
        let steps: Vec<_> = s.states.iter().map(|st| st.step).collect();
        assert_eq!(steps, vec![Some(0), Some(2), Some(4)]);
        let start = s.states[0].max_von_mises.over_p_h;
        assert!(
            (start - 0.62).abs() < 0.02,
            "frictionless von Mises {start}"
        );
        let (plus, minus) = (
            s.states[1].surface_peak_along_force.unwrap(),
            s.states[2].surface_peak_along_force.unwrap(),
        );
        assert!(
            plus.at_m[0] < 0.0 && minus.at_m[0] > 0.0,
            "{plus:?} {minus:?}"
        );
        assert!((plus.value_pa / minus.value_pa - 1.0).abs() < 0.01);
        assert!(s.crossland.unwrap().value_pa > 0.0);
        let dir = std::env::temp_dir().join(format!("mpc-stress-{}", std::process::id()));
        write_solved(&solved, &dir).unwrap();
        let json = std::fs::read_to_string(dir.join("case.json")).unwrap();
        assert!(json.contains("\"stress\""));
        for f in [
            "plane_0um_step2_sxx.npy",
            "slice_along_step4_von_mises.npy",
            "slice_across_crossland.npy",
        ] {
            assert!(dir.join("stress").join(f).is_file(), "{f}");
        }
        std::fs::remove_dir_all(&dir).unwrap();

        let plain = Config::parse(FE, &[]).unwrap();
        let solved =
            solve_in_memory(CaseChoice::new(&plain, None, None, None).unwrap(), 1).unwrap();
        assert!(solved.stress.is_none());
        write_solved(&solved, &dir).unwrap();
        let json = std::fs::read_to_string(dir.join("case.json")).unwrap();
        assert!(!json.contains("\"stress\"") && !dir.join("stress").exists());
        std::fs::remove_dir_all(&dir).unwrap();
    }

    /// Issue #59 item 8: a long fretting history computes its stresses at
    /// the turning points of its last cycle by default (+A → −A → +A: what
    /// Crossland over the steady cycle reads), every turning point with
    /// `states = "turning"`; the last cycle's states are the same bits in
    /// both, and `check`'s memory and time estimates count the states.
    #[test]
    fn issue59_a_long_history_stresses_its_last_cycle_by_default() {
        let base = "[grid]\npoints = 32\nspacing_um = 10.0\n[indenter]\nradius_mm = 18.0\n[load]\nnormal_n = 20.0\nfriction = 0.28571\n[sweep]\nmaterials = [\"Fe\"]\nangles_deg = [0.0]\n[history]\nfretting = { amplitude_ratio = 0.6, cycles = 3 }\nsteps_per_segment = 1\n[stress]\ndepths_um = [10.0]\nslice_rows = 4\n";
        let solve = |extra: &str| {
            let c = Config::parse(&format!("{base}{extra}"), &[]).unwrap();
            let cfg = c.stress.clone().unwrap();
            let choice = CaseChoice::new(&c, None, None, None).unwrap();
            let spec = choice.spec.clone();
            let solved = solve_in_memory(choice, 1).unwrap();
            (cfg, spec, solved.stress.unwrap())
        };
        let (last_cfg, spec, last) = solve("");
        let (all_cfg, _, all) = solve("states = \"turning\"\n");
        let steps = |s: &crate::output::stress::StressOutput| -> Vec<Option<usize>> {
            s.scalars.states.iter().map(|st| st.step).collect()
        };
        // 0 → +A, then three cycles of two segments: 8 turning points.
        assert_eq!(steps(&all), (0..8).map(Some).collect::<Vec<_>>());
        assert_eq!(steps(&last), vec![Some(5), Some(6), Some(7)]);
        assert_eq!(last.scalars.states[..], all.scalars.states[5..]);
        let (n, one) = (spec.grid.n, std::iter::once(&spec));
        let per_state = crate::memory::stress_bytes(n, &all_cfg, one.clone())
            - crate::memory::stress_bytes(n, &last_cfg, one);
        assert!(per_state > 0.0);
        let t_all = crate::cost::stress_seconds(&spec, &all_cfg);
        let t_last = crate::cost::stress_seconds(&spec, &last_cfg);
        assert!(
            (t_all / t_last - 8.0 / 3.0).abs() < 1e-12,
            "{t_all} {t_last}"
        );
    }
}
