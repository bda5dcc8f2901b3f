//! `[surfaces.NAME]`: custom surfaces (island lattices, stripes, height
//! maps read from `.npy` by [`read_grid_npy`]; scans and random surfaces
//! are `scan`'s), how a name resolves (tables first, each built once per
//! config and grid, then presets) and the config keys of its parameters.

use super::{within, Config};
use anyhow::{anyhow, bail, Context, Result};
use serde::{Deserialize, Serialize};
use solver::{Island, LatticeKind, Sampling, Surface};
use std::collections::BTreeMap;
use std::path::Path;

/// `[surfaces.NAME]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceCfg {
    /// `flat`, `circle`, `square`, `stripe` or `heightmap`; absent in a
    /// table named after a preset, which then only sets `sampling`.
    pub shape: Option<String>,
    /// How a pattern's edges are put on the grid: `area` (default, each
    /// cell's exact covered fraction) or `centre` (whole cells by their
    /// centre, the paper's).
    pub sampling: Option<String>,
    /// Circle diameter, µm.
    pub diameter_um: Option<f64>,
    /// Square side, µm.
    pub side_um: Option<f64>,
    /// Stripe (ridge) width, µm.
    pub width_um: Option<f64>,
    /// Lattice or stripe pitch, µm.
    pub pitch_um: Option<f64>,
    /// Island / ridge height, µm (negative: dimples / grooves).
    pub height_um: Option<f64>,
    /// `square` (default) or `hexagonal` island lattice.
    pub lattice: Option<String>,
    /// Ridge direction for stripes, degrees from x (default 90: ridges along y).
    pub angle_deg: Option<f64>,
    /// Position of one island centre (or ridge line) relative to the sphere apex, µm.
    #[serde(default)]
    pub offset_um: [f64; 2],
    /// Height map: a 2-D float64 `.npy` of heights in µm, shape (N, N) = the grid,
    /// rows along y; a relative path is taken from the config file's directory.
    /// Scan: an `.x3p`, or an `.npy` of heights in µm with `pixel_um`.
    pub file: Option<String>,
    /// Scan (`.npy`) or random surface: the pixel size, µm (one number,
    /// or `[x, y]` for a scan).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pixel_um: Option<super::scan::PixelCfg>,
    /// Scan or random surface: `none`, `plane` (a scan's default) or
    /// `polynomial` (with `degree`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub levelling: Option<String>,
    /// The levelling polynomial's degree.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub degree: Option<usize>,
    /// Missing points of a scan: `refuse` (default) or `fill`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub missing: Option<String>,
    /// The scan's point under the ball's apex, µm from its first pixel's
    /// outer corner (default: the scan's centre).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub apex_um: Option<[f64; 2]>,
    /// Random surface: the Hurst exponent.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub hurst: Option<f64>,
    /// Random surface: the rms height, µm (or `rms_slope`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms_height_um: Option<f64>,
    /// Random surface: the rms slope (or `rms_height_um`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub rms_slope: Option<f64>,
    /// Random surface: the shortest wavelength, µm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub short_cutoff_um: Option<f64>,
    /// Random surface: the roll-off wavelength, µm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub long_cutoff_um: Option<f64>,
    /// Random surface: the seed (default 0).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Random surface: pixels per side (default: enough to cover the grid).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pixels: Option<usize>,
}

impl SurfaceCfg {
    /// True when a key of scans or random surfaces is set.
    fn any_scan_key(&self) -> bool {
        self.pixel_um.is_some()
            || self.levelling.is_some()
            || self.degree.is_some()
            || self.missing.is_some()
            || self.apex_um.is_some()
            || self.hurst.is_some()
            || self.rms_height_um.is_some()
            || self.rms_slope.is_some()
            || self.short_cutoff_um.is_some()
            || self.long_cutoff_um.is_some()
            || self.seed.is_some()
            || self.pixels.is_some()
    }
}

/// What a config has built of its surfaces, shared by its clones.
#[derive(Debug, Default)]
struct Built {
    /// Surfaces by name and ladder level (a scan is resampled per level;
    /// every other surface is built once, at level 0).
    surfaces: BTreeMap<(String, usize), Surface>,
    /// Prepared scans by name.
    scans: BTreeMap<String, std::sync::Arc<super::scan::PreparedScan>>,
}

/// Built surfaces by name, shared by the clones of one config.
#[derive(Clone, Debug, Default)]
pub(super) struct SurfaceCache(std::sync::Arc<std::sync::Mutex<Built>>);

impl SurfaceCache {
    fn lock(&self) -> std::sync::MutexGuard<'_, Built> {
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
    fn get(&self, name: &str, level: usize) -> Option<Surface> {
        self.lock()
            .surfaces
            .get(&(name.to_string(), level))
            .cloned()
    }
    fn insert(&self, name: &str, level: usize, surface: &Surface) {
        self.lock()
            .surfaces
            .insert((name.to_string(), level), surface.clone());
    }
    pub(super) fn scan(&self, name: &str) -> Option<std::sync::Arc<super::scan::PreparedScan>> {
        self.lock().scans.get(name).cloned()
    }
    pub(super) fn insert_scan(&self, name: &str, p: &std::sync::Arc<super::scan::PreparedScan>) {
        self.lock().scans.insert(name.to_string(), p.clone());
    }
}

/// The key in `[surfaces.NAME]` of a surface parameter (lengths in µm).
pub(super) fn surface_key(param: &str) -> String {
    match param {
        "heights" => "file".to_string(),
        "pitch" | "height" | "offset" | "diameter" | "side" | "width" => format!("{param}_um"),
        other => other.to_string(),
    }
}

impl Config {
    /// Resolves a surface name: `[surfaces.NAME]` first, then presets; a
    /// scan on the grid of `grid` (ladder level 0).
    pub fn surface(&self, name: &str) -> Result<Surface> {
        self.surface_at(name, 0)
    }

    /// A surface on the grid of ladder level `level`: a scan or random
    /// surface resampled onto it (once per level, shared by its cases);
    /// every other surface is the same on every grid.
    pub fn surface_at(&self, name: &str, level: usize) -> Result<Surface> {
        if let Some(s) = self.surfaces.get(name) {
            let scan = self.scan(name)?;
            let level = if scan.is_some() { level } else { 0 };
            if let Some(surface) = self.built_surfaces.get(name, level) {
                return Ok(surface);
            }
            let surface = match scan {
                Some(p) => self.scan_on_level(name, &p, level)?,
                None => {
                    let surface = build_surface(name, s, self.grid.points, &self.base_dir)?;
                    surface
                        .validate(self.grid.points)
                        .map_err(|e| self.explain(within("surface", e), "", name))?;
                    surface
                }
            };
            self.built_surfaces.insert(name, level, &surface);
            return Ok(surface);
        }
        solver::presets::surface(name).ok_or_else(|| {
            anyhow!("sweep.surfaces: unknown surface `{name}` (presets: flat, circle-A, circle-B, square-A, square-B; or define [surfaces.\"{name}\"])")
        })
    }
}

/// The height-map surface of `n x n` heights in µm, rows along y: what
/// `shape = "heightmap"` makes of its file (and Python of an array), so
/// both give the solver the same metres. Not validated (`Surface::validate`).
pub fn heightmap_surface(n: usize, heights_um: &[f64]) -> Surface {
    Surface::Heightmap {
        n,
        heights: std::sync::Arc::new(heights_um.iter().map(|v| v * 1e-6).collect()),
    }
}

/// The sampling named by `surfaces.NAME.sampling` (default `area`).
fn sampling(name: &str, s: &SurfaceCfg) -> Result<Sampling> {
    Ok(match s.sampling.as_deref() {
        None | Some("area") => Sampling::Area,
        Some("centre") | Some("center") => Sampling::Centre,
        Some(other) => {
            bail!("surfaces.{name}.sampling: unknown sampling `{other}` (area, centre)")
        }
    })
}

/// A preset named by a table without `shape`: the preset with the table's
/// `sampling` (the only key such a table may set).
fn preset_with_sampling(name: &str, s: &SurfaceCfg) -> Result<Surface> {
    let mut surface = solver::presets::surface(name).ok_or_else(|| {
        anyhow!("surfaces.{name}.shape: required (`{name}` is not a preset; shapes: flat, circle, square, stripe, heightmap, scan, random)")
    })?;
    let others = [
        s.diameter_um,
        s.side_um,
        s.width_um,
        s.pitch_um,
        s.height_um,
        s.angle_deg,
    ]
    .iter()
    .any(Option::is_some)
        || s.lattice.is_some()
        || s.file.is_some()
        || s.any_scan_key()
        || s.offset_um != [0.0, 0.0];
    if others {
        bail!("surfaces.{name}: a table named after the preset `{name}` without `shape` may only set `sampling`; give `shape` (and all its dimensions) to define a new surface");
    }
    let chosen = sampling(name, s)?;
    match &mut surface {
        Surface::Lattice { sampling, .. } | Surface::Stripes { sampling, .. } => *sampling = chosen,
        Surface::Flat | Surface::Heightmap { .. } | Surface::Resampled { .. } => {}
    }
    Ok(surface)
}

fn build_surface(name: &str, s: &SurfaceCfg, n: usize, base: &Path) -> Result<Surface> {
    let Some(shape) = s.shape.as_deref() else {
        return preset_with_sampling(name, s);
    };
    let need = |v: Option<f64>, k: &str| {
        v.ok_or_else(|| anyhow!("surfaces.{name}.{k}: required for shape = \"{shape}\""))
    };
    let um = 1e-6;
    if matches!(shape, "flat" | "heightmap") && s.sampling.is_some() {
        bail!("surfaces.{name}.sampling: only patterns (circle, square, stripe) have edges to sample; a {shape} surface has one height per cell");
    }
    if s.any_scan_key() {
        bail!("surfaces.{name}: pixel_um, levelling, degree, missing, apex_um and the random keys are for shape = \"scan\" or \"random\", not \"{shape}\"");
    }
    let surface = match shape {
        "flat" => Surface::Flat,
        "circle" | "square" => {
            let island = if shape == "circle" {
                Island::Circle {
                    diameter: need(s.diameter_um, "diameter_um")? * um,
                }
            } else {
                Island::Square {
                    side: need(s.side_um, "side_um")? * um,
                }
            };
            let lattice = match s.lattice.as_deref() {
                None | Some("square") => LatticeKind::Square,
                Some("hexagonal") => LatticeKind::Hexagonal,
                Some(other) => bail!("surfaces.{name}.lattice: unknown lattice `{other}` (square, hexagonal)"),
            };
            Surface::Lattice {
                island,
                pitch: need(s.pitch_um, "pitch_um")? * um,
                height: need(s.height_um, "height_um")? * um,
                offset: [s.offset_um[0] * um, s.offset_um[1] * um],
                lattice,
                sampling: sampling(name, s)?,
            }
        }
        "stripe" => Surface::Stripes {
            width: need(s.width_um, "width_um")? * um,
            pitch: need(s.pitch_um, "pitch_um")? * um,
            height: need(s.height_um, "height_um")? * um,
            angle_deg: s.angle_deg.unwrap_or(90.0),
            offset: s.offset_um[0] * um,
            sampling: sampling(name, s)?,
        },
        "heightmap" => {
            let file = s
                .file
                .as_ref()
                .ok_or_else(|| anyhow!("surfaces.{name}.file: required for shape = \"heightmap\""))?;
            let path = base.join(file);
            let values =
                read_grid_npy(&path, n).with_context(|| format!("surfaces.{name}.file"))?;
            heightmap_surface(n, &values)
        }
        other => bail!("surfaces.{name}.shape: unknown shape `{other}` (flat, circle, square, stripe, heightmap, scan, random)"),
    };
    Ok(surface)
}

/// Reads an `n x n` float64 (or float32) `.npy` file in C order. Only a
/// regular file is opened (a FIFO would block, `/dev/zero` never end), and
/// its header is checked against the grid before any data is read, so a
/// wrong file costs no more than its header.
pub fn read_grid_npy(path: &Path, n: usize) -> Result<Vec<f64>> {
    let (_, _, values) = crate::scan_file::npy::read_2d(path, |shape| {
        if shape == [n as u64, n as u64] {
            Ok(())
        } else {
            Err(format!(
                "has shape {shape:?} but the grid is {n} x {n} (grid.points)"
            ))
        }
    })?;
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{err, BASE};
    use crate::config::Config;
    use solver::Surface;

    #[test]
    fn bad_surfaces_are_explained() {
        let island = format!("{BASE}\n[surfaces.fat]\nshape = \"circle\"\ndiameter_um = 50.0\npitch_um = 40.0\nheight_um = 1.0\n")
            .replace("surfaces = [\"flat\"]", "surfaces = [\"fat\"]");
        assert!(
            err(&island, &[]).contains("does not fit"),
            "{}",
            err(&island, &[])
        );
        let nan_h = format!("{BASE}\n[surfaces.odd]\nshape = \"square\"\nside_um = 10.0\npitch_um = 40.0\nheight_um = nan\n")
            .replace("surfaces = [\"flat\"]", "surfaces = [\"odd\"]");
        assert!(err(&nan_h, &[]).contains("height"), "{}", err(&nan_h, &[]));
    }

    #[test]
    fn sampling_is_area_by_default_centre_on_request_and_checked() {
        use solver::Sampling;
        let with = |extra: &str, surface: &str| {
            format!("{BASE}\n{extra}").replace(
                "surfaces = [\"flat\"]",
                &format!("surfaces = [\"{surface}\"]"),
            )
        };
        let c = Config::parse(&with("", "circle-A"), &[]).unwrap();
        assert_eq!(
            c.surface("circle-A").unwrap().sampling(),
            Some(Sampling::Area)
        );
        // A preset's table without shape sets its sampling only.
        let text = with("[surfaces.circle-A]\nsampling = \"centre\"\n", "circle-A");
        let c = Config::parse(&text, &[]).unwrap();
        let mut preset = solver::presets::surface("circle-A").unwrap();
        if let Surface::Lattice { sampling, .. } = &mut preset {
            *sampling = Sampling::Centre;
        }
        assert_eq!(c.surface("circle-A").unwrap(), preset);
        let bad = with("[surfaces.circle-A]\nsampling = \"corner\"\n", "circle-A");
        assert!(
            err(&bad, &[]).contains("surfaces.circle-A.sampling: unknown sampling `corner`"),
            "{}",
            err(&bad, &[])
        );
        let more = with(
            "[surfaces.circle-A]\nsampling = \"centre\"\npitch_um = 10.0\n",
            "circle-A",
        );
        assert!(
            err(&more, &[]).contains("may only set `sampling`"),
            "{}",
            err(&more, &[])
        );
        let unknown = with("[surfaces.mine]\nsampling = \"centre\"\n", "mine");
        assert!(
            err(&unknown, &[]).contains("surfaces.mine.shape: required"),
            "{}",
            err(&unknown, &[])
        );
        let flat = with(
            "[surfaces.plain]\nshape = \"flat\"\nsampling = \"area\"\n",
            "plain",
        );
        assert!(
            err(&flat, &[]).contains("only patterns"),
            "{}",
            err(&flat, &[])
        );
    }

    #[test]
    fn issue20_item5_a_height_map_is_read_once_and_only_from_a_regular_file() {
        let tmp_dir = tempfile::tempdir().unwrap();
        let dir = tmp_dir.path().to_path_buf();
        let heights = vec![0.0; 64 * 64];
        crate::output::npy::write_npy(&dir.join("h.npy"), 64, &heights).unwrap();
        let text = format!("{BASE}\n[surfaces.rough]\nshape = \"heightmap\"\nfile = \"h.npy\"\n")
            .replace("surfaces = [\"flat\"]", "surfaces = [\"rough\"]");
        let c = Config::parse_in(&text, &[], &dir).unwrap();
        // Read when the config was checked; the cases share that one copy,
        // and a file changed afterwards is not read again.
        std::fs::remove_file(dir.join("h.npy")).unwrap();
        let cases = c.cases().unwrap();
        assert_eq!(cases.len(), 3);
        let map = |i: usize| match &cases[i].1.surface {
            Surface::Heightmap { heights, .. } => heights.clone(),
            _ => panic!("not a height map"),
        };
        assert!(std::sync::Arc::ptr_eq(&map(0), &map(2)), "one copy");
        // A FIFO (which would block a read) and a directory are refused at once.
        let fifo = dir.join("pipe.npy");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status();
        if made.is_ok_and(|s| s.success()) {
            let e = format!(
                "{:#}",
                Config::parse_in(&text.replace("h.npy", "pipe.npy"), &[], &dir).unwrap_err()
            );
            assert!(
                e.contains("not a regular file") && e.contains("surfaces.rough.file"),
                "{e}"
            );
        }
        std::fs::create_dir(dir.join("d.npy")).unwrap();
        let e = format!(
            "{:#}",
            Config::parse_in(&text.replace("h.npy", "d.npy"), &[], &dir).unwrap_err()
        );
        assert!(e.contains("not a regular file"), "{e}");
    }

    #[test]
    fn heightmap_surface_is_read_from_npy_and_its_shape_checked() {
        let tmp_dir = tempfile::tempdir().unwrap();
        let dir = tmp_dir.path().to_path_buf();
        let heights: Vec<f64> = (0..64 * 64)
            .map(|i| if i % 7 == 0 { 0.5 } else { 0.0 })
            .collect();
        crate::output::npy::write_npy(&dir.join("h.npy"), 64, &heights).unwrap();
        crate::output::npy::write_npy(&dir.join("small.npy"), 32, &heights[..32 * 32]).unwrap();
        let text = format!("{BASE}\n[surfaces.rough]\nshape = \"heightmap\"\nfile = \"h.npy\"\n")
            .replace("surfaces = [\"flat\"]", "surfaces = [\"rough\"]");
        let c = Config::parse_in(&text, &[], &dir).unwrap();
        let Surface::Heightmap { n, heights: h } = c.surface("rough").unwrap() else {
            panic!("not a height map")
        };
        assert_eq!(n, 64);
        assert_eq!(h[0], 0.5e-6, "µm in the file, m in the solver");
        let small = text.replace("h.npy", "small.npy");
        let e = format!("{:#}", Config::parse_in(&small, &[], &dir).unwrap_err());
        assert!(e.contains("grid is 64 x 64"), "{e}");
        let missing = text.replace("h.npy", "nope.npy");
        let e = format!("{:#}", Config::parse_in(&missing, &[], &dir).unwrap_err());
        assert!(e.contains("surfaces.rough.file"), "{e}");
        // A height map has no finer grids: a ladder on it is refused, by name.
        let sets = ["convergence.levels=2".to_string()];
        let e = format!("{:#}", Config::parse_in(&text, &sets, &dir).unwrap_err());
        assert!(
            e.contains("convergence.levels = 2: surface `rough` is a height map"),
            "{e}"
        );
    }
}
