//! `[surfaces.NAME]` of `shape = "scan"` (a measured scan read from a
//! file, `crate::scan_file`) and `shape = "random"` (a random self-affine
//! surface, `solver::SelfAffine`): their keys, the scan each makes —
//! prepared once per config (missing points, levelling) — and its heights
//! on each grid of a ladder (`solver::resample`), with the statistics that
//! `check` and `case.json` show.

use super::{Config, SurfaceCfg};
use crate::scan_file::read_scan;
use anyhow::{anyhow, bail, Result};
use serde::{Deserialize, Serialize};
use solver::{
    roughness, Amplitude, Grid, Levelling, Missing, Roughness, Scan, SelfAffine, SolverError,
    Surface,
};
use std::sync::Arc;

/// `pixel_um`: one size (square pixels) or `[x, y]`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum PixelCfg {
    /// Square pixels of this side, µm.
    Square(f64),
    /// Pixels of `[x, y]`, µm.
    Sides([f64; 2]),
}

impl PixelCfg {
    fn metres(self) -> [f64; 2] {
        match self {
            PixelCfg::Square(d) => [d * 1e-6, d * 1e-6],
            PixelCfg::Sides([x, y]) => [x * 1e-6, y * 1e-6],
        }
    }
}

/// A scan ready for the cases: read (or generated), missing points
/// refused or filled, levelled; where the ball's apex lands on it.
#[derive(Clone, Debug)]
pub struct PreparedScan {
    /// The file read, or the generator and its seed.
    pub source: String,
    /// The prepared heights.
    pub scan: Scan,
    /// Points the instrument did not measure.
    pub missing_points: usize,
    /// What was done with them.
    pub missing: Missing,
    /// The form removed.
    pub levelling: Levelling,
    /// The scan's point under the ball's apex, m from its first pixel's
    /// outer corner.
    pub apex: [f64; 2],
    /// The prepared scan's roughness.
    pub roughness: Roughness,
    /// Cells carry the mean of their pixels (`false`) or a two-level
    /// scan's upper level with its cover (`true`, `sampling = "area"`).
    pub two_level: bool,
}

/// A roughness in µm (Sdq dimensionless), as outputs show it.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct RoughnessUm {
    /// Sa, µm.
    pub sa_um: f64,
    /// Sq, µm.
    pub sq_um: f64,
    /// Sz, µm.
    pub sz_um: f64,
    /// Sdq.
    pub sdq: f64,
}

impl From<Roughness> for RoughnessUm {
    fn from(r: Roughness) -> Self {
        RoughnessUm {
            sa_um: r.sa * 1e6,
            sq_um: r.sq * 1e6,
            sz_um: r.sz * 1e6,
            sdq: r.sdq,
        }
    }
}

/// What `check` and `case.json` say about a scan on a case's grid.
#[derive(Clone, Debug, Serialize)]
pub struct ScanReport {
    /// The file read, or the generator and its seed.
    pub source: String,
    /// Pixels `[x, y]`.
    pub pixels: [usize; 2],
    /// Pixel size `[x, y]`, µm.
    pub pixel_um: [f64; 2],
    /// The scan's extent `[x, y]`, µm.
    pub extent_um: [f64; 2],
    /// Points the instrument did not measure.
    pub missing_points: usize,
    /// `refuse` or `fill`.
    pub missing: &'static str,
    /// The form removed.
    pub levelling: String,
    /// How cells take their pixels: `mean` or `area` (two levels).
    pub sampling: &'static str,
    /// The scan's point under the ball's apex, µm from its corner.
    pub apex_um: [f64; 2],
    /// The prepared scan's roughness.
    pub scan: RoughnessUm,
    /// The case's cell `[x, y]`, µm.
    pub cell_um: [f64; 2],
    /// The roughness of the heights on the case's grid (resampled).
    pub grid: RoughnessUm,
}

impl PreparedScan {
    /// The surface on `grid`: the scan resampled.
    pub fn on(&self, grid: &Grid) -> Result<Surface, SolverError> {
        let (heights, cover) = if self.two_level {
            solver::resample_two_level(&self.scan, self.apex, grid)?
        } else {
            (solver::resample(&self.scan, self.apex, grid)?, None)
        };
        Ok(Surface::Resampled {
            n: grid.n,
            heights: Arc::new(heights),
            cover: cover.map(Arc::new),
        })
    }

    /// The report of this scan on `grid` with the heights it has there.
    pub fn report(&self, grid: &Grid, heights: &[f64]) -> ScanReport {
        let s = &self.scan;
        let (ex, ey) = s.extent();
        ScanReport {
            source: self.source.clone(),
            pixels: [s.nx, s.ny],
            pixel_um: [s.dx * 1e6, s.dy * 1e6],
            extent_um: [ex * 1e6, ey * 1e6],
            missing_points: self.missing_points,
            missing: match self.missing {
                Missing::Refuse => "refuse",
                Missing::Fill => "fill",
            },
            levelling: self.levelling.name(),
            sampling: if self.two_level { "area" } else { "mean" },
            apex_um: [self.apex[0] * 1e6, self.apex[1] * 1e6],
            scan: self.roughness.into(),
            cell_um: [grid.dx * 1e6, grid.dy * 1e6],
            grid: roughness(heights, grid.n, grid.n, grid.dx, grid.dy).into(),
        }
    }
}

/// True for the shapes this file builds.
pub(super) fn is_scan_shape(shape: Option<&str>) -> bool {
    matches!(shape, Some("scan" | "random"))
}

/// The key of `[surfaces.NAME]` that a parameter of a scan or a random
/// surface comes from.
fn scan_key(field: &str) -> &str {
    match field {
        "scan" => "file",
        "apex" => "apex_um",
        "pixel" => "pixel_um",
        "short_cutoff" => "short_cutoff_um",
        "long_cutoff" => "long_cutoff_um",
        "rms_height" => "rms_height_um",
        other => other,
    }
}

/// A solver error about the scan of `surfaces.NAME` (read from `source`),
/// naming its key and the source.
fn explain(name: &str, source: &str, e: SolverError) -> anyhow::Error {
    match e {
        SolverError::Invalid { field, reason } => {
            anyhow!(
                "invalid surfaces.{name}.{} ({source}): {reason}",
                scan_key(&field)
            )
        }
        other => anyhow!("surfaces.{name} ({source}): {other}"),
    }
}

impl Config {
    /// The scan of `[surfaces.NAME]` when its shape is `scan` or
    /// `random`, prepared once per config; `None` for other surfaces.
    pub fn scan(&self, name: &str) -> Result<Option<Arc<PreparedScan>>> {
        let Some(s) = self.surfaces.get(name) else {
            return Ok(None);
        };
        if !is_scan_shape(s.shape.as_deref()) {
            return Ok(None);
        }
        if let Some(p) = self.built_surfaces.scan(name) {
            return Ok(Some(p));
        }
        let prepared = Arc::new(self.prepare_scan(name, s)?);
        self.built_surfaces.insert_scan(name, &prepared);
        Ok(Some(prepared))
    }

    /// The report of the scan of `name` on the grid of ladder level
    /// `level`; `None` for other surfaces.
    pub fn scan_report(&self, name: &str, level: usize) -> Result<Option<ScanReport>> {
        let Some(p) = self.scan(name)? else {
            return Ok(None);
        };
        let grid = self.level_grid(level);
        match self.surface_at(name, level)? {
            Surface::Resampled { heights, .. } => Ok(Some(p.report(&grid, &heights))),
            _ => Ok(None),
        }
    }

    /// `[surfaces.NAME]` of shape `scan` or `random`, read or generated
    /// and prepared.
    fn prepare_scan(&self, name: &str, s: &SurfaceCfg) -> Result<PreparedScan> {
        let shape = s.shape.as_deref().unwrap_or_default();
        let random_keys = [
            ("hurst", s.hurst.is_some()),
            ("rms_height_um", s.rms_height_um.is_some()),
            ("rms_slope", s.rms_slope.is_some()),
            ("short_cutoff_um", s.short_cutoff_um.is_some()),
            ("long_cutoff_um", s.long_cutoff_um.is_some()),
            ("seed", s.seed.is_some()),
            ("pixels", s.pixels.is_some()),
        ];
        let (source, raw) = if shape == "scan" {
            if let Some((key, _)) = random_keys.iter().find(|(_, set)| *set) {
                bail!("surfaces.{name}.{key}: only for shape = \"random\"; a scan's heights come from its file");
            }
            let file = s
                .file
                .as_ref()
                .ok_or_else(|| anyhow!("surfaces.{name}.file: required for shape = \"scan\" (an .x3p, or an .npy with pixel_um)"))?;
            let path = self.base_dir.join(file);
            let is_x3p =
                crate::scan_file::Format::of(&path).ok() == Some(crate::scan_file::Format::X3p);
            if is_x3p && s.pixel_um.is_some() {
                bail!("surfaces.{name}.pixel_um: an .x3p gives its own pixel sizes ({}); leave pixel_um out", path.display());
            }
            let scan = read_scan(&path, s.pixel_um.map(PixelCfg::metres))
                .map_err(|e| anyhow!("surfaces.{name}.file: {e}"))?;
            (path.display().to_string(), scan)
        } else {
            let need = |v: Option<f64>, k: &str| {
                v.ok_or_else(|| anyhow!("surfaces.{name}.{k}: required for shape = \"random\""))
            };
            let amplitude = match (s.rms_height_um, s.rms_slope) {
                (Some(h), None) => Amplitude::RmsHeight(h * 1e-6),
                (None, Some(g)) => Amplitude::RmsSlope(g),
                _ => bail!("surfaces.{name}: give one of rms_height_um and rms_slope for shape = \"random\""),
            };
            let pixel = match s.pixel_um {
                None => self.grid.spacing_um * 1e-6,
                Some(PixelCfg::Square(d)) => d * 1e-6,
                Some(PixelCfg::Sides(_)) => bail!(
                    "surfaces.{name}.pixel_um: a random surface has square pixels; give one size"
                ),
            };
            let domain = self.grid.points as f64 * self.grid.spacing_um * 1e-6;
            let pixels = s
                .pixels
                .unwrap_or_else(|| (domain / pixel * (1.0 + 1e-9)).ceil().max(8.0) as usize);
            let seed = s.seed.unwrap_or(0);
            let generator = SelfAffine {
                pixels,
                pixel,
                hurst: need(s.hurst, "hurst")?,
                short_cutoff: need(s.short_cutoff_um, "short_cutoff_um")? * 1e-6,
                long_cutoff: need(s.long_cutoff_um, "long_cutoff_um")? * 1e-6,
                amplitude,
                seed,
            };
            let source = format!("random self-affine surface, seed {seed}");
            let scan = generator
                .generate()
                .map_err(|e| explain(name, &source, e))?;
            (source, scan)
        };
        let missing = match s.missing.as_deref() {
            None | Some("refuse") => Missing::Refuse,
            Some("fill") => Missing::Fill,
            Some(other) => {
                bail!("surfaces.{name}.missing: unknown choice `{other}` (refuse, fill)")
            }
        };
        let default_levelling = if shape == "scan" { "plane" } else { "none" };
        let levelling = match (
            s.levelling.as_deref().unwrap_or(default_levelling),
            s.degree,
        ) {
            ("none", None) => Levelling::None,
            ("plane", None) => Levelling::Polynomial { degree: 1 },
            ("polynomial", Some(degree)) => Levelling::Polynomial { degree },
            ("polynomial", None) => {
                bail!(
                    "surfaces.{name}.degree: required for levelling = \"polynomial\" (1 to {})",
                    solver::MAX_LEVELLING_DEGREE
                )
            }
            ("none" | "plane", Some(_)) => {
                bail!("surfaces.{name}.degree: only for levelling = \"polynomial\"")
            }
            (other, _) => bail!(
                "surfaces.{name}.levelling: unknown levelling `{other}` (none, plane, polynomial)"
            ),
        };
        let two_level = match s.sampling.as_deref() {
            None | Some("mean") => false,
            Some("area") => true,
            Some(other) => bail!("surfaces.{name}.sampling: unknown sampling `{other}` for a {shape} surface (mean, area)"),
        };
        let missing_points = raw.missing().0;
        let scan = raw
            .prepared(missing, levelling)
            .map_err(|e| explain(name, &source, e))?;
        let (ex, ey) = scan.extent();
        let apex = match s.apex_um {
            Some([x, y]) => [x * 1e-6, y * 1e-6],
            None => [0.5 * ex, 0.5 * ey],
        };
        let roughness = roughness(&scan.heights, scan.nx, scan.ny, scan.dx, scan.dy);
        Ok(PreparedScan {
            source,
            scan,
            missing_points,
            missing,
            levelling,
            apex,
            roughness,
            two_level,
        })
    }

    /// The scan of `name` on the grid of ladder level `level`, checked.
    pub(super) fn scan_on_level(
        &self,
        name: &str,
        p: &PreparedScan,
        level: usize,
    ) -> Result<Surface> {
        let grid = self.level_grid(level);
        let surface = p.on(&grid).map_err(|e| explain(name, &p.source, e))?;
        surface
            .validate(grid.n)
            .map_err(|e| explain(name, &p.source, e))?;
        Ok(surface)
    }
}
