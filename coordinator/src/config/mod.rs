//! The one config loader: TOML file + `--set KEY=VALUE` overrides → validated
//! cases. Unknown keys are errors naming the key (and the line, when it comes
//! from the file). Units are in the key names; the cases carry SI.
//!
//! This file owns the whole config (`Config`): reading it, checking its
//! sections in order, expanding it into cases and naming the config key of a
//! solver error. Each section has its own file with its keys, defaults,
//! checks and the config keys of its solver parameters, so that a new key
//! lives in one place: `grid` (`[grid]`, `[indenter]`, `[load]`),
//! `convergence`, `sweep`, `materials`, `surfaces` (and `scan`: measured
//! and random surfaces), `history`, `stress` and `solving`
//! (`[solver]`, `[run]`, `[output]`); `toml_text` guards the text itself.

mod convergence;
mod grid;
mod history;
mod materials;
pub mod orientations;
mod scan;
mod solving;
mod stress;
mod surfaces;
mod sweep;
mod toml_text;

pub use convergence::{ladder_points, ConvergenceCfg, MAX_LEVELS};
pub use grid::{GridCfg, IndenterCfg, LoadCfg};
pub use history::{
    AutoWord, FrettingCfg, HistoryCfg, StepsCfg, WearCfg, WearLawCfg, MAX_CYCLES,
    SOLVE_LOOP_INCREMENTS,
};
pub use materials::{CubicCfg, IsoCfg, MaterialCfg, SweepMaterial};
pub use orientations::{Orientation, OrientationsCfg};
pub use scan::{PixelCfg, PreparedScan, RoughnessUm, ScanReport};
pub use solving::{OutputCfg, RunCfg, SolverCfg};
pub use stress::StressCfg;
pub use surfaces::{heightmap_surface, read_grid_npy, SurfaceCfg};
pub use sweep::{AnglesCfg, SweepCfg, MAX_ANGLES, RIGID};

use crate::case::CaseKey;
use anyhow::{anyhow, bail, Context, Result};
use serde::{Deserialize, Serialize};
use solver::{CaseSpec, Material, SolverError, Surface};
use std::collections::BTreeMap;
use std::path::Path;
use toml_text::{apply_set, check_nesting, shorten};

/// The whole config file.
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Config {
    /// `[grid]`
    pub grid: GridCfg,
    /// `[indenter]`
    pub indenter: IndenterCfg,
    /// `[load]`
    pub load: LoadCfg,
    /// `[sweep]`
    pub sweep: SweepCfg,
    /// `[materials.*]`
    #[serde(default)]
    pub materials: BTreeMap<String, MaterialCfg>,
    /// `[surfaces.*]`
    #[serde(default)]
    pub surfaces: BTreeMap<String, SurfaceCfg>,
    /// `[solver]`
    #[serde(default)]
    pub solver: SolverCfg,
    /// `[output]`
    #[serde(default)]
    pub output: OutputCfg,
    /// `[run]` (left out of the config echo when it is the default, so
    /// journals written before it existed still resume).
    #[serde(default, skip_serializing_if = "RunCfg::is_default")]
    pub run: RunCfg,
    /// `[convergence]` (left out of the echo when it is the default, as `[run]`).
    #[serde(default, skip_serializing_if = "ConvergenceCfg::is_default")]
    pub convergence: ConvergenceCfg,
    /// `[history]`: a load path for every case (none: one monotonic step).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub history: Option<HistoryCfg>,
    /// `[stress]`: stresses below the surface (none: not computed; left
    /// out of the echo then, so journals and outputs are as before).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stress: Option<StressCfg>,
    /// Directory that relative paths in the config (height maps) start from.
    #[serde(skip)]
    pub base_dir: std::path::PathBuf,
    /// Surfaces already built, by name: a height map is read once per
    /// config, not once per case (#20 item 5).
    #[serde(skip)]
    built_surfaces: surfaces::SurfaceCache,
}

/// The config key of a solver parameter that is not in a material or
/// surface table (the solver's errors name its parameters): the section
/// that sets it names it; one no section claims is shown as the solver's.
fn config_key(param: &str) -> String {
    grid::config_key(param)
        .or_else(|| sweep::config_key(param))
        .or_else(|| history::config_key(param))
        .or_else(|| solving::config_key(param))
        .unwrap_or_else(|| param.to_string())
}

/// `e` with its parameter put under `prefix` (`material`, `surface`).
fn within(prefix: &str, e: SolverError) -> SolverError {
    match e {
        SolverError::Invalid { field, reason } => {
            SolverError::invalid(&format!("{prefix}.{field}"), reason)
        }
        other => other,
    }
}

impl Config {
    /// Reads a config file and applies `--set` overrides.
    pub fn load(path: &Path, sets: &[String]) -> Result<Config> {
        Self::parse_file(&Self::read(path)?, sets, path)
    }

    /// The text of the config file at `path`.
    pub fn read(path: &Path) -> Result<String> {
        std::fs::read_to_string(path)
            .with_context(|| format!("cannot read config {}", path.display()))
    }

    /// Parses `text`, read from `path`, and applies `--set` overrides;
    /// relative paths start at the file's directory, errors name the file.
    /// (Python's `Config.set` re-parses the file's text with one more `--set`.)
    pub fn parse_file(text: &str, sets: &[String], path: &Path) -> Result<Config> {
        let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Self::parse_in(text, sets, &base).with_context(|| format!("in config {}", path.display()))
    }

    /// Parses config text and applies `--set` overrides (relative paths from the current directory).
    pub fn parse(text: &str, sets: &[String]) -> Result<Config> {
        Self::parse_in(text, sets, Path::new(""))
    }

    /// Parses config text and applies `--set` overrides; relative paths start at `base`.
    pub fn parse_in(text: &str, sets: &[String], base: &Path) -> Result<Config> {
        check_nesting(text)?;
        // First pass on the text itself: errors carry line and column.
        let mut cfg: Config =
            toml::from_str(text).map_err(|e| anyhow!("{}", shorten(&e.to_string())))?;
        cfg.base_dir = base.to_path_buf();
        if sets.is_empty() {
            cfg.check()?;
            return Ok(cfg);
        }
        let mut table: toml::Table = text
            .parse()
            .map_err(|e: toml::de::Error| anyhow!("{}", shorten(&e.to_string())))?;
        for s in sets {
            apply_set(&mut table, s)?;
        }
        let mut cfg: Config = toml::Value::Table(table)
            .try_into()
            .map_err(|e| anyhow!("after --set {}: {e}", sets.join(" --set ")))?;
        cfg.base_dir = base.to_path_buf();
        cfg.check()?;
        Ok(cfg)
    }

    /// The effective config as TOML (echoed into outputs; compared on resume).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).unwrap_or_default()
    }

    /// A solver error with its parameter named by its config key, for a
    /// case of `material` on `surface` pressed by the config's one ball.
    pub fn explain(&self, e: SolverError, material: &str, surface: &str) -> anyhow::Error {
        self.explain_pressed(e, material, surface, self.indenter.material.as_deref())
    }

    /// The same for a case pressed by the ball `ball` (a material name;
    /// `None` or `rigid`: no ball).
    pub fn explain_pressed(
        &self,
        e: SolverError,
        material: &str,
        surface: &str,
        ball: Option<&str>,
    ) -> anyhow::Error {
        let SolverError::Invalid { field, reason } = e else {
            return anyhow!("{e}");
        };
        let key = if let Some(p) = field.strip_prefix("material.") {
            format!(
                "materials.{material}.{}",
                materials::material_key(p, self.materials.get(material))
            )
        } else if let Some(p) = field.strip_prefix("indenter.") {
            let ball = ball.unwrap_or_default();
            format!(
                "materials.{ball}.{}",
                materials::material_key(p, self.materials.get(ball))
            )
        } else if let Some(p) = field.strip_prefix("surface.") {
            format!("surfaces.{surface}.{}", surfaces::surface_key(p))
        } else {
            config_key(&field)
        };
        anyhow!("invalid {key}: {reason}")
    }

    /// Everything that can be checked before any solve; errors name the key.
    /// The sections are checked in this order, which is the order in which
    /// a config with several mistakes reports them.
    pub fn check(&self) -> Result<()> {
        self.sweep.check_lists()?;
        self.run.check()?;
        self.sweep.check_unique(&self.sweep.angles_deg.values()?)?;
        self.convergence.check()?;
        if let Some(s) = &self.stress {
            s.check(&self.grid)?;
        }
        let amplitude = self.sweep.amplitude_axis()[0];
        match &self.history {
            Some(h) => {
                h.load_history_at(amplitude)?;
                if self.sweep.normal_loads_n.is_some() && h.normal_n.is_some() {
                    bail!("history.normal_n and sweep.normal_loads_n both set the normal load: leave history.normal_n out (the axis gives each case's)");
                }
            }
            None if amplitude.is_some() => bail!(
                "sweep.amplitudes_um: needs [history] fretting = {{ cycles = N }} (displacement control; the axis gives each case's amplitude)"
            ),
            None => {}
        }
        self.check_material_tables()?;
        // Whether the workers fit in this machine's memory is checked where
        // they start (`memory::check_fits`), not here.
        for (key, spec) in self.cases()? {
            let ball = key
                .indenter
                .as_deref()
                .or(self.indenter.material.as_deref());
            spec.validate()
                .map_err(|e| self.explain_pressed(e, &key.material, &key.surface, ball))?;
        }
        Ok(())
    }

    /// One case spec, pressed by the sweep's first ball
    /// ([`Config::default_ball`]).
    pub fn spec(&self, material: &str, surface: &str, angle_deg: f64) -> Result<CaseSpec> {
        Ok(self.spec_of(
            self.material(material)?,
            self.surface(surface)?,
            angle_deg,
            self.default_ball()?,
            self.default_map_point(),
        ))
    }

    /// One case spec on a surface given directly (not by name), e.g. a
    /// [`heightmap_surface`] made from an array.
    pub fn spec_on(&self, material: &str, surface: Surface, angle_deg: f64) -> Result<CaseSpec> {
        Ok(self.spec_of(
            self.material(material)?,
            surface,
            angle_deg,
            self.default_ball()?,
            self.default_map_point(),
        ))
    }

    /// The normal load and amplitude a single case gets when none is
    /// chosen: the first of `sweep.normal_loads_n` and `sweep.amplitudes_um`
    /// (`None` without the axis).
    pub fn default_map_point(&self) -> (Option<f64>, Option<f64>) {
        (self.sweep.load_axis()[0], self.sweep.amplitude_axis()[0])
    }

    /// The spec of a resolved material and surface at one angle, pressed by
    /// the resolved ball `indenter` (`None`: rigid), at the fretting-map
    /// point `(normal load N, amplitude µm)` (`None`s: the config's).
    fn spec_of(
        &self,
        material: Material,
        surface: Surface,
        angle_deg: f64,
        indenter: Option<Material>,
        (normal_n, amplitude_um): (Option<f64>, Option<f64>),
    ) -> CaseSpec {
        let history = self.load_history_at(amplitude_um);
        // With a load path, the case's own ratio is the path's last one (its
        // final state is reduced like a monotonic case: μa, K_E calibration).
        let tangential_ratio = match &history {
            Some(h) => h.tangential_ratios.last().map_or(0.0, |r| r.max(0.0)),
            None => self.load.tangential_ratio,
        };
        CaseSpec {
            material,
            surface,
            grid: self.level_grid(0),
            load: {
                let mut load = self.load_at(tangential_ratio, angle_deg);
                if let Some(p) = normal_n {
                    load.normal_force_n = p;
                }
                load
            },
            numerics: self.solver.numerics(),
            history,
            indenter,
        }
    }

    /// All cases of the sweep in a fixed order: materials × surfaces × angles
    /// × balls × normal loads × amplitudes (× ladder levels, finest last). Each material, surface and
    /// ball is resolved once. Without `sweep.indenters` there is one ball
    /// and the keys carry none (the cases of before).
    pub fn cases(&self) -> Result<Vec<(CaseKey, CaseSpec)>> {
        let angles = self.sweep.angles_deg.values()?;
        let surfaces = self
            .sweep
            .surfaces
            .iter()
            .map(|s| {
                let surface = self.surface(s)?;
                // A height map is sampled on its own grid only; a scan is
                // resampled onto each level's.
                let levels = self.convergence.levels;
                let scan = self.scan(s)?.is_some();
                if levels > 1 && !scan && matches!(surface, Surface::Heightmap { .. }) {
                    bail!("convergence.levels = {levels}: surface `{s}` is a height map, sampled on one grid only; ladders need surfaces defined by shape, a scan (shape = \"scan\") or levels = 1");
                }
                Ok((s, surface, scan))
            })
            .collect::<Result<Vec<_>>>()?;
        let balls = self.balls()?;
        let loads = self.sweep.load_axis();
        let amplitudes = self.sweep.amplitude_axis();
        let mut points = Vec::new();
        for b in &balls {
            for &p in &loads {
                for &d in &amplitudes {
                    points.push((b, p, d));
                }
            }
        }
        let mut out = Vec::new();
        for SweepMaterial {
            name: m, material, ..
        } in self.sweep_materials()?
        {
            let m = &m;
            for (s, surface, scan) in &surfaces {
                for &a in &angles {
                    for &((name, ball), p, d) in &points {
                        let mut key = match name {
                            Some(name) => CaseKey::new(m, s, a).with_indenter(name),
                            None => CaseKey::new(m, s, a),
                        };
                        key.normal_n = p;
                        key.amplitude_um = d;
                        let spec = self.spec_of(
                            material.clone(),
                            surface.clone(),
                            a,
                            ball.clone(),
                            (p, d),
                        );
                        let finer = (1..self.convergence.levels)
                            .map(|level| {
                                let grid = self.level_grid(level);
                                let surface = if *scan {
                                    self.surface_at(s, level)?
                                } else {
                                    spec.surface.clone()
                                };
                                Ok((
                                    key.clone().at_level(level),
                                    CaseSpec {
                                        grid,
                                        surface,
                                        ..spec.clone()
                                    },
                                ))
                            })
                            .collect::<Result<Vec<_>>>()?;
                        out.push((key, spec));
                        out.extend(finer);
                    }
                }
            }
        }
        Ok(out)
    }
}

/// The smallest config the tests of every section start from, and its errors.
#[cfg(test)]
mod fixtures {
    use super::Config;

    pub(super) const BASE: &str = r#"
[grid]
points = 64
spacing_um = 2.0

[indenter]
radius_mm = 18.0

[load]
normal_n = 20.0
friction = 0.3
tangential_ratio = 0.6

[sweep]
materials = ["Fe"]
surfaces = ["flat"]
angles_deg = { start = 0, stop = 90, step = 45 }
"#;

    /// The error of `text` with `sets`, with its context.
    pub(super) fn err(text: &str, sets: &[&str]) -> String {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        format!("{:#}", Config::parse(text, &sets).unwrap_err())
    }
}

#[cfg(test)]
mod tests {
    use super::fixtures::{err, BASE};
    use super::*;

    #[test]
    fn base_config_expands_to_three_cases_in_order() {
        let c = Config::parse(BASE, &[]).unwrap();
        let ids: Vec<String> = c
            .cases()
            .unwrap()
            .into_iter()
            .map(|(key, _)| key.to_string())
            .collect();
        assert_eq!(ids, ["Fe/flat/000.0", "Fe/flat/045.0", "Fe/flat/090.0"]);
    }

    #[test]
    fn unknown_key_is_named_with_its_line() {
        let text = BASE.replace("friction = 0.3", "friction = 0.3\nfriction_coef = 0.2");
        let e = err(&text, &[]);
        assert!(e.contains("friction_coef") && e.contains("line 12"), "{e}");
    }

    #[test]
    fn wrong_type_is_named() {
        let e = err(&BASE.replace("points = 64", "points = \"many\""), &[]);
        assert!(e.contains("points") || e.contains("invalid type"), "{e}");
    }

    #[test]
    fn set_overrides_a_key_and_rejects_unknown_ones() {
        let c = Config::parse(
            BASE,
            &["grid.points=128".into(), "load.tangential_ratio=0".into()],
        )
        .unwrap();
        assert_eq!(c.grid.points, 128);
        assert_eq!(c.load.tangential_ratio, 0.0);
        let e = err(BASE, &["grid.pointz=128"]);
        assert!(e.contains("pointz"), "{e}");
    }
}
