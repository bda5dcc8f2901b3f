//! The one config loader: TOML file + `--set KEY=VALUE` overrides → validated
//! cases. Unknown keys are errors naming the key (and the line, when it comes
//! from the file). Units are in the key names; the cases carry SI.

use crate::case::CaseKey;
use crate::npy::read_grid_npy;
use anyhow::{anyhow, bail, Context, Result};
use serde::{Deserialize, Serialize};
use solver::{
    CaseSpec, Grid, Island, Isotropic, LatticeKind, Load, LoadHistory, Material, Numerics,
    SolverError, Surface,
};
use std::collections::BTreeMap;
use std::path::Path;

/// `[grid]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GridCfg {
    /// N: the surface grid is N x N cells.
    pub points: usize,
    /// Cell size, µm.
    pub spacing_um: f64,
}

/// `[indenter]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IndenterCfg {
    /// Sphere radius, mm.
    pub radius_mm: f64,
}

/// `[load]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LoadCfg {
    /// Normal load P, N.
    pub normal_n: f64,
    /// Coulomb friction μ.
    pub friction: f64,
    /// F = ratio · μ · P; 0 = normal contact only.
    #[serde(default = "default_ratio")]
    pub tangential_ratio: f64,
}

fn default_ratio() -> f64 {
    0.6
}

/// Force angles: `{ start, stop, step }` (stop included) or a list.
/// Read through [`AnglesCfg::try_from`], so that a missing or unknown key of
/// the range is named (serde's untagged enums only say that nothing matched).
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(untagged, try_from = "toml::Value")]
pub enum AnglesCfg {
    /// Inclusive range.
    Range {
        /// First angle, degrees.
        start: f64,
        /// Last angle (included when hit), degrees.
        stop: f64,
        /// Step, degrees.
        step: f64,
    },
    /// Explicit list, degrees.
    List(Vec<f64>),
}

/// Most angles one sweep may list (a range or a list): 180° in 0.1° steps
/// is 1801, so this only stops runaway inputs before they allocate.
pub const MAX_ANGLES: usize = 100_000;

impl TryFrom<toml::Value> for AnglesCfg {
    type Error = String;

    fn try_from(v: toml::Value) -> std::result::Result<Self, String> {
        let number = |v: &toml::Value, what: &str| match v {
            toml::Value::Float(x) => Ok(*x),
            toml::Value::Integer(i) => Ok(*i as f64),
            other => Err(format!(
                "{what} must be a number of degrees, got {}",
                other.type_str()
            )),
        };
        match v {
            toml::Value::Array(items) => {
                if items.len() > MAX_ANGLES {
                    return Err(format!(
                        "{} angles is too many (at most {MAX_ANGLES})",
                        items.len()
                    ));
                }
                let list = items
                    .iter()
                    .enumerate()
                    .map(|(i, x)| number(x, &format!("entry {i}")))
                    .collect::<std::result::Result<_, _>>()?;
                Ok(AnglesCfg::List(list))
            }
            toml::Value::Table(t) => {
                if let Some(k) = t
                    .keys()
                    .find(|k| !["start", "stop", "step"].contains(&k.as_str()))
                {
                    return Err(format!(
                        "unknown key `{k}` in the range (expected start, stop, step)"
                    ));
                }
                let get = |k: &str| {
                    t.get(k)
                        .ok_or_else(|| {
                            format!("the range needs `{k}` (start, stop, step in degrees)")
                        })
                        .and_then(|v| number(v, k))
                };
                Ok(AnglesCfg::Range {
                    start: get("start")?,
                    stop: get("stop")?,
                    step: get("step")?,
                })
            }
            other => Err(format!(
                "expected a list of angles or {{ start, stop, step }}, got {}",
                other.type_str()
            )),
        }
    }
}

impl AnglesCfg {
    /// The angles, degrees.
    pub fn values(&self) -> Result<Vec<f64>> {
        match self {
            AnglesCfg::List(v) => {
                if v.is_empty() || v.iter().any(|a| !a.is_finite()) {
                    bail!("sweep.angles_deg: the list must be non-empty and finite");
                }
                if v.len() > MAX_ANGLES {
                    bail!(
                        "sweep.angles_deg: {} angles is too many (at most {MAX_ANGLES})",
                        v.len()
                    );
                }
                Ok(v.clone())
            }
            AnglesCfg::Range { start, stop, step } => {
                if !(start.is_finite() && stop.is_finite() && step.is_finite())
                    || *step <= 0.0
                    || stop < start
                {
                    bail!("sweep.angles_deg: need finite start ≤ stop and step > 0, got start = {start}, stop = {stop}, step = {step}");
                }
                // Counted in floating point: (stop − start)/step can exceed
                // any integer (step = 1e-300), and must not wrap to zero.
                let count = ((stop - start) / step + 1e-9).floor() + 1.0;
                if count > MAX_ANGLES as f64 {
                    bail!(
                        "sweep.angles_deg: start = {start}, stop = {stop}, step = {step} gives {count:.3e} angles, too many (at most {MAX_ANGLES})"
                    );
                }
                Ok((0..count as usize)
                    .map(|k| start + k as f64 * step)
                    .collect())
            }
        }
    }
}

/// `[sweep]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepCfg {
    /// Preset names or keys of `[materials.*]`.
    pub materials: Vec<String>,
    /// Preset names or keys of `[surfaces.*]`.
    #[serde(default = "default_surfaces")]
    pub surfaces: Vec<String>,
    /// Force directions.
    #[serde(default = "default_angles")]
    pub angles_deg: AnglesCfg,
}

fn default_surfaces() -> Vec<String> {
    vec!["flat".into()]
}

fn default_angles() -> AnglesCfg {
    AnglesCfg::List(vec![0.0])
}

/// Isotropic constants in GPa.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct IsoCfg {
    /// Young's modulus, GPa.
    pub youngs_gpa: f64,
    /// Poisson's ratio.
    pub poisson: f64,
}

/// Cubic constants in GPa.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CubicCfg {
    /// C11, GPa.
    pub c11: f64,
    /// C12, GPa.
    pub c12: f64,
    /// C44, GPa.
    pub c44: f64,
}

/// `[materials.NAME]`: exactly one of `isotropic`, `stiffness_gpa`, `cubic_gpa`.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MaterialCfg {
    /// Isotropic constants.
    pub isotropic: Option<IsoCfg>,
    /// Full 6x6 Voigt stiffness in the surface frame (xx, yy, zz, yz, xz, xy; z into the body), GPa.
    pub stiffness_gpa: Option<Vec<Vec<f64>>>,
    /// Cubic constants, rotated so that z ∥ `normal` and x ∥ `x_dir`.
    pub cubic_gpa: Option<CubicCfg>,
    /// Surface normal (Miller indices) for `cubic_gpa`.
    pub normal: Option<[f64; 3]>,
    /// In-plane x direction (Miller indices) for `cubic_gpa`.
    pub x_dir: Option<[f64; 3]>,
    /// Isotropic-equivalent constants for normalisation (default: Hill average).
    pub equivalent: Option<IsoCfg>,
}

/// `[surfaces.NAME]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SurfaceCfg {
    /// `flat`, `circle`, `square`, `stripe` or `heightmap`.
    pub shape: String,
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
    pub file: Option<String>,
}

/// `[solver]`
#[derive(Clone, Debug, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SolverCfg {
    /// Normal–tangential coupling.
    #[serde(default = "yes")]
    pub coupling: bool,
    /// Normal solver: relative change of pressure.
    #[serde(default = "default_tol")]
    pub tolerance: f64,
    /// Tangential solver: KKT residual relative to |δt|.
    #[serde(default = "default_ttol")]
    pub tangential_tolerance: f64,
    /// Iteration budget of each inner solve.
    #[serde(default = "default_iter")]
    pub max_iterations: usize,
    /// Coupling loop: relative change of pressure.
    #[serde(default = "default_ctol")]
    pub coupling_tolerance: f64,
    /// Coupling loop budget.
    #[serde(default = "default_citer")]
    pub max_coupling_iterations: usize,
}

fn yes() -> bool {
    Numerics::default().coupling
}
// The defaults are the solver's (one place).
fn default_tol() -> f64 {
    Numerics::default().tolerance
}
fn default_ttol() -> f64 {
    Numerics::default().tangential_tolerance
}
fn default_iter() -> usize {
    Numerics::default().max_iterations
}
fn default_ctol() -> f64 {
    Numerics::default().coupling_tolerance
}
fn default_citer() -> usize {
    Numerics::default().max_coupling_iterations
}

impl Default for SolverCfg {
    fn default() -> Self {
        SolverCfg {
            coupling: true,
            tolerance: default_tol(),
            tangential_tolerance: default_ttol(),
            max_iterations: default_iter(),
            coupling_tolerance: default_ctol(),
            max_coupling_iterations: default_citer(),
        }
    }
}

/// `[output]`
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct OutputCfg {
    /// Write `.npy` fields and PNG maps of every case of a sweep.
    #[serde(default)]
    pub save_fields: bool,
}

/// `[run]`: how the sweep runner treats its workers (not physics).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RunCfg {
    /// Longest silence, s, of a worker with a case in flight: workers beat
    /// a few times a second while they compute (kernel builds and solver
    /// iterations included), so only a worker that says nothing for this
    /// long is hung; its case is taken from it (the worker is killed when
    /// this coordinator started it) and dispatched again. However long a
    /// case computes, it is never cut short.
    #[serde(default = "default_case_timeout")]
    pub case_timeout_s: f64,
}

fn default_case_timeout() -> f64 {
    60.0
}

impl Default for RunCfg {
    fn default() -> Self {
        RunCfg {
            case_timeout_s: default_case_timeout(),
        }
    }
}

impl RunCfg {
    fn is_default(&self) -> bool {
        *self == RunCfg::default()
    }
}

/// `[convergence]`: grid-convergence ladders (docs/validation.md).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConvergenceCfg {
    /// Grids per case: 1 (the config's grid only), 2 or 3 … up to
    /// [`MAX_LEVELS`]; level k has about 2^(k/2) times the config's points
    /// per side on the same domain (cell sizes h, h/√2, h/2, …).
    #[serde(default = "one")]
    pub levels: usize,
}

fn one() -> usize {
    1
}

/// Most levels a ladder may have (the finest grid has 2^((L−1)/2) times
/// the points per side, 2.8× at 4: 22× the cost of level 0).
pub const MAX_LEVELS: usize = 4;

impl Default for ConvergenceCfg {
    fn default() -> Self {
        ConvergenceCfg { levels: 1 }
    }
}

impl ConvergenceCfg {
    fn is_default(&self) -> bool {
        *self == ConvergenceCfg::default()
    }
}

/// `[history]`: a load path applied to every case (fretting loops,
/// proportional loading), PHYSICS.md §5b. Either the turning points
/// (`tangential_ratios`, optionally `normal_n`) or the `fretting` shorthand.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HistoryCfg {
    /// Turning points of F/(μP) along the case's force angle (signed),
    /// joined by straight lines.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tangential_ratios: Option<Vec<f64>>,
    /// Normal load at each turning point, N (default: `load.normal_n` throughout).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub normal_n: Option<Vec<f64>>,
    /// Increments per segment between turning points.
    #[serde(default = "default_steps")]
    pub steps_per_segment: usize,
    /// Shorthand: 0 → +A → −A → +A … with `cycles` full cycles.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fretting: Option<FrettingCfg>,
}

/// `history.fretting`: a fretting loop of amplitude A = `amplitude_ratio` μP.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrettingCfg {
    /// Amplitude of the tangential force, as a fraction of μP (0 < A < 1).
    pub amplitude_ratio: f64,
    /// Full cycles after the first loading (+A → −A → +A each).
    #[serde(default = "one")]
    pub cycles: usize,
}

fn default_steps() -> usize {
    20
}

/// Most fretting cycles a config may ask for (each is two segments).
pub const MAX_CYCLES: usize = 1000;

impl HistoryCfg {
    /// The solver's load path; errors name the config key.
    pub fn load_history(&self) -> Result<LoadHistory> {
        let ratios = match (&self.tangential_ratios, &self.fretting) {
            (Some(_), Some(_)) => bail!(
                "history: give either tangential_ratios or fretting = {{ amplitude_ratio, cycles }}, not both"
            ),
            (None, None) => bail!(
                "history: give the turning points (tangential_ratios = [0.0, 0.6, -0.6, 0.6]) or fretting = {{ amplitude_ratio = 0.6, cycles = 2 }}"
            ),
            (Some(r), None) => r.clone(),
            (None, Some(f)) => {
                let a = f.amplitude_ratio;
                if !(a.is_finite() && a > 0.0 && a < 1.0) {
                    bail!("history.fretting.amplitude_ratio = {a}: must be above 0 and below 1 (the amplitude as a fraction of μP; at 1 the sphere slides)");
                }
                if !(1..=MAX_CYCLES).contains(&f.cycles) {
                    bail!("history.fretting.cycles = {}: must be 1 to {MAX_CYCLES}", f.cycles);
                }
                if self.normal_n.is_some() {
                    bail!("history.normal_n: not with the fretting shorthand (its normal load is load.normal_n); give tangential_ratios instead");
                }
                let mut r = vec![0.0, a];
                for _ in 0..f.cycles {
                    r.extend([-a, a]);
                }
                r
            }
        };
        Ok(LoadHistory {
            tangential_ratios: ratios,
            normal_forces_n: self.normal_n.clone(),
            steps_per_segment: self.steps_per_segment,
        })
    }
}

/// Points per side of ladder level `level` on a grid of `n`: n·2^(level/2),
/// odd levels rounded to the nearest 5-smooth number (2^a 3^b 5^c: fast
/// FFT sizes; 384 → 540, 256 → 360), so the cell-size ratio is √2 to
/// within 0.5 %; the spacing follows from the fixed domain.
pub fn ladder_points(n: usize, level: usize) -> usize {
    let base = n << (level / 2);
    if level.is_multiple_of(2) {
        return base;
    }
    let target = base as f64 * std::f64::consts::SQRT_2;
    let smooth = |mut m: usize| {
        for f in [2, 3, 5] {
            while m.is_multiple_of(f) {
                m /= f;
            }
        }
        m == 1
    };
    let t = target.round() as usize;
    (0..t)
        .flat_map(|d| [t + d, t - d])
        .find(|&m| m > 0 && smooth(m))
        .unwrap_or(t)
}

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
    /// Directory that relative paths in the config (height maps) start from.
    #[serde(skip)]
    pub base_dir: std::path::PathBuf,
    /// Surfaces already built, by name: a height map is read once per
    /// config, not once per case (#20 item 5).
    #[serde(skip)]
    built_surfaces: SurfaceCache,
}

/// Built surfaces by name, shared by the clones of one config.
#[derive(Clone, Debug, Default)]
struct SurfaceCache(std::sync::Arc<std::sync::Mutex<BTreeMap<String, Surface>>>);

impl SurfaceCache {
    fn get(&self, name: &str) -> Option<Surface> {
        let map = self.0.lock().unwrap_or_else(|e| e.into_inner());
        map.get(name).cloned()
    }
    fn insert(&self, name: &str, surface: &Surface) {
        let mut map = self.0.lock().unwrap_or_else(|e| e.into_inner());
        map.insert(name.to_string(), surface.clone());
    }
}

/// Applies one `KEY=VALUE` override to a TOML table. VALUE is read as TOML
/// (`128`, `true`, `[1, 2]`, `"Cu"`); anything that is not TOML is a string.
fn apply_set(table: &mut toml::Table, set: &str) -> Result<()> {
    let (key, value) = set
        .split_once('=')
        .ok_or_else(|| anyhow!("--set {set}: expected KEY=VALUE"))?;
    let key = key.trim();
    let parsed: toml::Value = match format!("v = {}", value.trim()).parse::<toml::Table>() {
        Ok(mut t) => t
            .remove("v")
            .unwrap_or(toml::Value::String(value.to_string())),
        Err(_) => toml::Value::String(value.trim().to_string()),
    };
    let parts: Vec<&str> = key.split('.').collect();
    if parts.iter().any(|p| p.is_empty()) {
        bail!("--set {set}: malformed key `{key}`");
    }
    let mut cur = table;
    for p in &parts[..parts.len() - 1] {
        let entry = cur
            .entry(p.to_string())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        cur = entry
            .as_table_mut()
            .ok_or_else(|| anyhow!("--set {set}: `{p}` is not a table"))?;
    }
    cur.insert(parts[parts.len() - 1].to_string(), parsed);
    Ok(())
}

/// Longest line of an error message echoed whole: a parse error quotes the
/// offending line, and a 10 MB key made a 31 MB message (#20 item 7).
const MAX_ECHO: usize = 200;

/// `msg` with every line longer than [`MAX_ECHO`] characters cut.
fn shorten(msg: &str) -> String {
    msg.lines()
        .map(|l| match l.char_indices().nth(MAX_ECHO) {
            Some((cut, _)) => format!(
                "{}… ({} more characters)",
                &l[..cut],
                l[cut..].chars().count()
            ),
            None => l.to_string(),
        })
        .collect::<Vec<_>>()
        .join("\n")
}

/// Deepest nesting a config may use: the deepest key of ours is
/// `materials.NAME.isotropic.youngs_gpa`; the TOML parser gives up on deep
/// nesting with "recursion limit" and no line (#20 item 7).
const MAX_NESTING: usize = 16;

/// Refuses a line whose key or value nests deeper than [`MAX_NESTING`]
/// (dots of a dotted key, brackets and braces), naming the line.
fn check_nesting(text: &str) -> Result<()> {
    for (i, line) in text.lines().enumerate() {
        let (mut depth, mut deepest, mut dots) = (0usize, 0usize, 0usize);
        let mut quote: Option<char> = None;
        let mut seen_eq = false;
        for c in line.chars() {
            match (quote, c) {
                (Some(q), c) if c == q => quote = None,
                (Some(_), _) => {}
                (None, '"' | '\'') => quote = Some(c),
                (None, '#') => break,
                (None, '=') => seen_eq = true,
                (None, '.') if !seen_eq => dots += 1,
                (None, '[' | '{') => {
                    depth += 1;
                    deepest = deepest.max(depth);
                }
                (None, ']' | '}') => depth = depth.saturating_sub(1),
                _ => {}
            }
        }
        if dots + deepest > MAX_NESTING {
            bail!(
                "line {}: keys and values nest {} levels deep; a config needs at most {MAX_NESTING}",
                i + 1,
                dots + deepest
            );
        }
    }
    Ok(())
}

/// The config key of a solver parameter that is not in a material or
/// surface table (the solver's errors name its parameters).
fn config_key(param: &str) -> String {
    let key = match param {
        "grid.n" => "grid.points",
        "grid.dx" | "grid.dy" => "grid.spacing_um",
        "load.indenter_radius_m" => "indenter.radius_mm",
        "load.normal_force_n" => "load.normal_n",
        "load.angle_deg" => "sweep.angles_deg",
        other => {
            if let Some(rest) = other.strip_prefix("history.normal_forces_n") {
                return format!("history.normal_n{rest}");
            }
            return match other.strip_prefix("numerics.") {
                Some(rest) => format!("solver.{rest}"),
                None => other.to_string(),
            };
        }
    };
    key.to_string()
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

/// The key in `[materials.NAME]` of a material parameter.
fn material_key<'a>(param: &'a str, cfg: Option<&MaterialCfg>) -> &'a str {
    let cubic = cfg.is_some_and(|m| m.cubic_gpa.is_some());
    match param {
        "youngs" => "isotropic.youngs_gpa",
        "poisson" => "isotropic.poisson",
        "stiffness" if cubic => "cubic_gpa",
        "stiffness" => "stiffness_gpa",
        "orientation" => "normal",
        other => other,
    }
}

/// The key in `[surfaces.NAME]` of a surface parameter (lengths in µm).
fn surface_key(param: &str) -> String {
    match param {
        "heights" => "file".to_string(),
        "pitch" | "height" | "offset" | "diameter" | "side" | "width" => format!("{param}_um"),
        other => other.to_string(),
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
    /// case of `material` on `surface`.
    pub fn explain(&self, e: SolverError, material: &str, surface: &str) -> anyhow::Error {
        let SolverError::Invalid { field, reason } = e else {
            return anyhow!("{e}");
        };
        let key = if let Some(p) = field.strip_prefix("material.") {
            format!(
                "materials.{material}.{}",
                material_key(p, self.materials.get(material))
            )
        } else if let Some(p) = field.strip_prefix("surface.") {
            format!("surfaces.{surface}.{}", surface_key(p))
        } else {
            config_key(&field)
        };
        anyhow!("invalid {key}: {reason}")
    }

    /// Everything that can be checked before any solve; errors name the key.
    pub fn check(&self) -> Result<()> {
        if self.sweep.materials.is_empty() {
            bail!("sweep.materials: list at least one material");
        }
        if self.sweep.surfaces.is_empty() {
            bail!("sweep.surfaces: list at least one surface");
        }
        let t = self.run.case_timeout_s;
        // 1e9 s (32 years) keeps the deadline within what a Duration holds.
        if !(t.is_finite() && t > 0.0 && t <= 1e9) {
            bail!("run.case_timeout_s = {t}: must be a positive number of seconds, at most 1e9");
        }
        self.check_unique(&self.sweep.angles_deg.values()?)?;
        self.check_ladder()?;
        if let Some(h) = &self.history {
            h.load_history()?;
        }
        // Whether the workers fit in this machine's memory is checked where
        // they start (`memory::check_fits`), not here.
        for (key, spec) in self.cases()? {
            spec.validate()
                .map_err(|e| self.explain(e, &key.material, &key.surface))?;
        }
        Ok(())
    }

    /// Every case must have its own identity: no material or surface listed
    /// twice, and no two angles that case ids and outputs (0.1°) cannot tell
    /// apart. (Repeated keys made `run` re-send a case forever, #20 item 1.)
    fn check_unique(&self, angles: &[f64]) -> Result<()> {
        for (key, names) in [
            ("sweep.materials", &self.sweep.materials),
            ("sweep.surfaces", &self.sweep.surfaces),
        ] {
            let mut seen = std::collections::HashSet::new();
            if let Some(name) = names.iter().find(|n| !seen.insert(n.as_str())) {
                bail!("{key}: `{name}` is listed twice; every case must be unique");
            }
        }
        // The text the ids show; `+ 0.0` makes −0 and 0 the same angle.
        let mut shown: BTreeMap<String, f64> = BTreeMap::new();
        for &a in angles {
            let text = format!("{:.1}", a + 0.0);
            if let Some(prev) = shown.insert(text.clone(), a) {
                bail!(
                    "sweep.angles_deg: {prev}° and {a}° both read {text}° in case ids and outputs, which resolve 0.1°; give angles at least 0.1° apart"
                );
            }
        }
        Ok(())
    }

    /// The ladder's length (its surfaces are checked where they are
    /// resolved, in [`Config::cases`]).
    fn check_ladder(&self) -> Result<()> {
        let levels = self.convergence.levels;
        if !(1..=MAX_LEVELS).contains(&levels) {
            bail!("convergence.levels = {levels}: must be 1 (no ladder) to {MAX_LEVELS}");
        }
        Ok(())
    }

    /// The grid of ladder level `level` (level 0: `[grid]` itself).
    pub fn level_grid(&self, level: usize) -> Grid {
        let spacing = self.grid.spacing_um * 1e-6;
        // Level 0 is the spacing as given, not spacing · n / n, which can
        // differ in the last bit and would change every result without a ladder.
        if level == 0 {
            return Grid::square(self.grid.points, spacing);
        }
        let n = ladder_points(self.grid.points, level);
        Grid::square(n, spacing * self.grid.points as f64 / n as f64)
    }

    /// Points per side of the finest grid the sweep solves on.
    pub fn finest_points(&self) -> usize {
        self.level_grid(self.convergence.levels - 1).n
    }

    /// Resolves a material name: `[materials.NAME]` first, then presets.
    pub fn material(&self, name: &str) -> Result<Material> {
        if let Some(m) = self.materials.get(name) {
            return build_material(name, m, &|e| self.explain(within("material", e), name, ""));
        }
        solver::presets::material(name).ok_or_else(|| {
            anyhow!("sweep.materials: unknown material `{name}` (not a preset — see `mpcontact materials` — and no [materials.\"{name}\"] table)")
        })
    }

    /// Resolves a surface name: `[surfaces.NAME]` first, then presets.
    pub fn surface(&self, name: &str) -> Result<Surface> {
        if let Some(s) = self.surfaces.get(name) {
            if let Some(surface) = self.built_surfaces.get(name) {
                return Ok(surface);
            }
            let surface = build_surface(name, s, self.grid.points, &self.base_dir)?;
            surface
                .validate(self.grid.points)
                .map_err(|e| self.explain(within("surface", e), "", name))?;
            self.built_surfaces.insert(name, &surface);
            return Ok(surface);
        }
        solver::presets::surface(name).ok_or_else(|| {
            anyhow!("sweep.surfaces: unknown surface `{name}` (presets: flat, circle-A, circle-B, square-A, square-B; or define [surfaces.\"{name}\"])")
        })
    }

    /// One case spec.
    pub fn spec(&self, material: &str, surface: &str, angle_deg: f64) -> Result<CaseSpec> {
        Ok(self.spec_of(self.material(material)?, self.surface(surface)?, angle_deg))
    }

    /// One case spec on a surface given directly (not by name), e.g. a
    /// [`heightmap_surface`] made from an array.
    pub fn spec_on(&self, material: &str, surface: Surface, angle_deg: f64) -> Result<CaseSpec> {
        Ok(self.spec_of(self.material(material)?, surface, angle_deg))
    }

    /// The spec of a resolved material and surface at one angle.
    fn spec_of(&self, material: Material, surface: Surface, angle_deg: f64) -> CaseSpec {
        let history = self.load_history();
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
            load: Load {
                indenter_radius_m: self.indenter.radius_mm * 1e-3,
                normal_force_n: self.load.normal_n,
                friction: self.load.friction,
                tangential_ratio,
                angle_deg,
            },
            numerics: Numerics {
                coupling: self.solver.coupling,
                tolerance: self.solver.tolerance,
                tangential_tolerance: self.solver.tangential_tolerance,
                max_iterations: self.solver.max_iterations,
                coupling_tolerance: self.solver.coupling_tolerance,
                max_coupling_iterations: self.solver.max_coupling_iterations,
            },
            history,
        }
    }

    /// The load path of `[history]`, if any. A malformed one gives `None`
    /// here; [`Config::check`] reports it by key before any case is made.
    pub fn load_history(&self) -> Option<LoadHistory> {
        self.history.as_ref().and_then(|h| h.load_history().ok())
    }

    /// All cases of the sweep in a fixed order: materials × surfaces × angles
    /// (× ladder levels, finest last). Each material and surface is resolved once.
    pub fn cases(&self) -> Result<Vec<(CaseKey, CaseSpec)>> {
        let angles = self.sweep.angles_deg.values()?;
        let surfaces = self
            .sweep
            .surfaces
            .iter()
            .map(|s| {
                let surface = self.surface(s)?;
                // A height map is sampled on its own grid only.
                let levels = self.convergence.levels;
                if levels > 1 && matches!(surface, Surface::Heightmap { .. }) {
                    bail!("convergence.levels = {levels}: surface `{s}` is a height map, sampled on one grid only; ladders need surfaces defined by shape (or levels = 1)");
                }
                Ok((s, surface))
            })
            .collect::<Result<Vec<_>>>()?;
        let mut out = Vec::new();
        for m in &self.sweep.materials {
            let material = self.material(m)?;
            for (s, surface) in &surfaces {
                for &a in &angles {
                    let spec = self.spec_of(material.clone(), surface.clone(), a);
                    let finer: Vec<_> = (1..self.convergence.levels)
                        .map(|level| {
                            let grid = self.level_grid(level);
                            let key = CaseKey::new(m, s, a).at_level(level);
                            (
                                key,
                                CaseSpec {
                                    grid,
                                    ..spec.clone()
                                },
                            )
                        })
                        .collect();
                    out.push((CaseKey::new(m, s, a), spec));
                    out.extend(finer);
                }
            }
        }
        Ok(out)
    }
}

/// A material from its `[materials.NAME]` table; `explain` turns the
/// solver's errors (parameters of the material) into config errors.
fn build_material(
    name: &str,
    m: &MaterialCfg,
    explain: &dyn Fn(SolverError) -> anyhow::Error,
) -> Result<Material> {
    let key = |k: &str| format!("materials.{name}.{k}");
    let given = [
        m.isotropic.is_some(),
        m.stiffness_gpa.is_some(),
        m.cubic_gpa.is_some(),
    ]
    .iter()
    .filter(|&&b| b)
    .count();
    if given != 1 {
        bail!("materials.{name}: give exactly one of `isotropic`, `stiffness_gpa`, `cubic_gpa`");
    }
    if let Some(iso) = m.isotropic {
        if m.equivalent.is_some() {
            bail!(
                "{}: only applies to anisotropic materials (an isotropic material is its own equivalent)",
                key("equivalent")
            );
        }
        if m.normal.is_some() || m.x_dir.is_some() {
            bail!(
                "{}: `normal`/`x_dir` only apply to `cubic_gpa`",
                key("normal")
            );
        }
        return Material::isotropic(name, iso.youngs_gpa * 1e9, iso.poisson).map_err(explain);
    }
    // The isotropic-equivalent constants only normalise (the paper's Cu(111)
    // has ν = 0.503): taken as given; the material checks them.
    let equivalent = m.equivalent.map(|e| Isotropic {
        youngs: e.youngs_gpa * 1e9,
        poisson: e.poisson,
    });
    if let Some(rows) = &m.stiffness_gpa {
        if rows.len() != 6 || rows.iter().any(|r| r.len() != 6) {
            bail!(
                "{}: must be 6 rows of 6 numbers (GPa)",
                key("stiffness_gpa")
            );
        }
        let c = nalgebra::Matrix6::from_fn(|i, j| rows[i][j] * 1e9);
        return Material::with_stiffness(name, c, equivalent).map_err(explain);
    }
    let cub = m.cubic_gpa.expect("counted above");
    let normal = m
        .normal
        .ok_or_else(|| anyhow!("{}: required with cubic_gpa", key("normal")))?;
    let x_dir = m
        .x_dir
        .ok_or_else(|| anyhow!("{}: required with cubic_gpa", key("x_dir")))?;
    let constants = [cub.c11 * 1e9, cub.c12 * 1e9, cub.c44 * 1e9];
    Material::cubic(name, constants, normal, x_dir, equivalent).map_err(explain)
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

fn build_surface(name: &str, s: &SurfaceCfg, n: usize, base: &Path) -> Result<Surface> {
    let need = |v: Option<f64>, k: &str| {
        v.ok_or_else(|| anyhow!("surfaces.{name}.{k}: required for shape = \"{}\"", s.shape))
    };
    let um = 1e-6;
    let surface = match s.shape.as_str() {
        "flat" => Surface::Flat,
        "circle" | "square" => {
            let island = if s.shape == "circle" {
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
            }
        }
        "stripe" => Surface::Stripes {
            width: need(s.width_um, "width_um")? * um,
            pitch: need(s.pitch_um, "pitch_um")? * um,
            height: need(s.height_um, "height_um")? * um,
            angle_deg: s.angle_deg.unwrap_or(90.0),
            offset: s.offset_um[0] * um,
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
        other => bail!("surfaces.{name}.shape: unknown shape `{other}` (flat, circle, square, stripe, heightmap)"),
    };
    Ok(surface)
}

#[cfg(test)]
mod tests {
    use super::*;

    const BASE: &str = r#"
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

    fn err(text: &str, sets: &[&str]) -> String {
        let sets: Vec<String> = sets.iter().map(|s| s.to_string()).collect();
        format!("{:#}", Config::parse(text, &sets).unwrap_err())
    }

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

    #[test]
    fn issue16_bad_histories_name_their_key() {
        let with = |h: &str| format!("{BASE}\n[history]\n{h}\n");
        let cases: [(&str, &str); 10] = [
            (
                "tangential_ratios = [0.0, 0.6, nan]",
                "history.tangential_ratios[2]: must be finite",
            ),
            (
                "tangential_ratios = [0.0, 1.0]",
                "history.tangential_ratios[1]",
            ),
            ("tangential_ratios = [0.0, -1.5]", "friction limit"),
            (
                "tangential_ratios = [0.0, 0.5]\nnormal_n = [20.0]",
                "history.normal_n: has 1 turning points",
            ),
            (
                "tangential_ratios = [0.0, 0.5]\nnormal_n = [20.0, -1.0]",
                "history.normal_n[1]",
            ),
            (
                "tangential_ratios = [0.0, 0.5]\nsteps_per_segment = 0",
                "history.steps_per_segment: must be at least 1",
            ),
            (
                "tangential_ratios = []",
                "history.tangential_ratios: needs at least one",
            ),
            (
                "fretting = { amplitude_ratio = 1.0 }",
                "history.fretting.amplitude_ratio = 1",
            ),
            (
                "fretting = { amplitude_ratio = 0.5, cycles = 0 }",
                "history.fretting.cycles = 0",
            ),
            ("steps_per_segment = 5", "history: give the turning points"),
        ];
        for (h, expect) in cases {
            let e = err(&with(h), &[]);
            assert!(e.contains(expect), "{h}: {e}");
        }
        // The shorthand expands to 0 → +A → (−A → +A) × cycles.
        let c = Config::parse(
            &with("fretting = { amplitude_ratio = 0.5, cycles = 2 }"),
            &[],
        )
        .unwrap();
        let h = c.load_history().unwrap();
        assert_eq!(h.tangential_ratios, vec![0.0, 0.5, -0.5, 0.5, -0.5, 0.5]);
        assert_eq!(h.steps_per_segment, 20);
        let (_, spec) = &c.cases().unwrap()[0];
        assert_eq!(spec.history.as_ref(), Some(&h));
        assert_eq!(spec.load.tangential_ratio, 0.5, "the path's last ratio");
        // Without [history], no path.
        assert!(Config::parse(BASE, &[]).unwrap().cases().unwrap()[0]
            .1
            .history
            .is_none());
    }

    #[test]
    fn impossible_values_name_their_key() {
        let cases: [(&str, &str, &str); 9] = [
            (
                "tangential_ratio = 0.6",
                "tangential_ratio = 1.0",
                "gross sliding",
            ),
            ("normal_n = 20.0", "normal_n = -5.0", "load.normal_n"),
            ("normal_n = 20.0", "normal_n = nan", "load.normal_n"),
            ("radius_mm = 18.0", "radius_mm = 0.0", "indenter.radius_mm"),
            ("spacing_um = 2.0", "spacing_um = inf", "grid.spacing_um"),
            ("points = 64", "points = 4", "grid.points"),
            ("points = 64", "points = 100000", "grid.points"),
            ("friction = 0.3", "friction = -0.1", "load.friction"),
            (
                "materials = [\"Fe\"]",
                "materials = [\"Unobtainium\"]",
                "Unobtainium",
            ),
        ];
        for (from, to, expect) in cases {
            let e = err(&BASE.replace(from, to), &[]);
            assert!(e.contains(expect), "{to}: {e}");
        }
    }

    #[test]
    fn bad_materials_and_surfaces_are_explained() {
        let poisson = format!(
            "{BASE}\n[materials.rubber]\nisotropic = {{ youngs_gpa = 0.01, poisson = 0.6 }}\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"rubber\"]");
        assert!(err(&poisson, &[]).contains("(-1, 0.5]"));
        let zero_e = format!(
            "{BASE}\n[materials.void]\nisotropic = {{ youngs_gpa = 0.0, poisson = 0.3 }}\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"void\"]");
        assert!(err(&zero_e, &[]).contains("Young"));
        let mut rows = vec![vec![0.0; 6]; 6];
        rows[0][0] = 100.0;
        let not_pd = format!("{BASE}\n[materials.bad]\nstiffness_gpa = {rows:?}\n")
            .replace("materials = [\"Fe\"]", "materials = [\"bad\"]");
        assert!(
            err(&not_pd, &[]).contains("positive definite"),
            "{}",
            err(&not_pd, &[])
        );
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
    fn issue20_item1_repeated_cases_are_refused_naming_them() {
        let cases: [(&str, &str, &str); 6] = [
            (
                "materials = [\"Fe\"]",
                "materials = [\"Fe\", \"Fe\"]",
                "`Fe` is listed twice",
            ),
            (
                "surfaces = [\"flat\"]",
                "surfaces = [\"flat\", \"flat\"]",
                "sweep.surfaces",
            ),
            (
                "angles_deg = { start = 0, stop = 90, step = 45 }",
                "angles_deg = [0.0, 0.0]",
                "sweep.angles_deg",
            ),
            (
                "angles_deg = { start = 0, stop = 90, step = 45 }",
                "angles_deg = [0.0, 0.01]",
                "0° and 0.01° both read 0.0°",
            ),
            (
                "angles_deg = { start = 0, stop = 90, step = 45 }",
                "angles_deg = { start = 0, stop = 1, step = 0.04 }",
                "sweep.angles_deg",
            ),
            (
                "angles_deg = { start = 0, stop = 90, step = 45 }",
                "angles_deg = [-0.0, 0.0]",
                "sweep.angles_deg",
            ),
        ];
        for (from, to, expect) in cases {
            let text = BASE.replace(from, to);
            assert_ne!(text, BASE, "{to}");
            let e = err(&text, &[]);
            assert!(e.contains(expect), "{to}: {e}");
        }
        // Angles 0.1° apart are distinct cases.
        let ok = BASE.replace(
            "angles_deg = { start = 0, stop = 90, step = 45 }",
            "angles_deg = [0.0, 0.1, 0.2]",
        );
        assert_eq!(Config::parse(&ok, &[]).unwrap().cases().unwrap().len(), 3);
    }

    #[test]
    fn issue20_item6_angle_counts_and_timeouts_are_bounded() {
        let range = "angles_deg = { start = 0, stop = 90, step = 45 }";
        let e = err(
            &BASE.replace(
                range,
                "angles_deg = { start = 0, stop = 180, step = 1e-300 }",
            ),
            &[],
        );
        assert!(
            e.contains("sweep.angles_deg") && e.contains("too many"),
            "{e}"
        );
        let long: Vec<String> = (0..MAX_ANGLES + 1).map(|i| format!("{i}.0")).collect();
        let e = err(
            &BASE.replace(range, &format!("angles_deg = [{}]", long.join(","))),
            &[],
        );
        assert!(e.contains("too many"), "{}", &e[..e.len().min(300)]);
        let e = err(&format!("{BASE}\n[run]\ncase_timeout_s = 1e20\n"), &[]);
        assert!(e.contains("run.case_timeout_s"), "{e}");
    }

    #[test]
    fn issue20_item8_equivalent_constants_are_checked_or_refused() {
        let iso = format!(
            "{BASE}\n[materials.soft]\nisotropic = {{ youngs_gpa = 100.0, poisson = 0.3 }}\nequivalent = {{ youngs_gpa = nan, poisson = 0.3 }}\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"soft\"]");
        let e = err(&iso, &[]);
        assert!(e.contains("materials.soft.equivalent"), "{e}");
        let aniso = format!(
            "{BASE}\n[materials.odd]\ncubic_gpa = {{ c11 = 257.1, c12 = 125.9, c44 = 108.6 }}\nnormal = [1, 1, 1]\nx_dir = [1, 1, -2]\nequivalent = {{ youngs_gpa = nan, poisson = 0.3 }}\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"odd\"]");
        let e = err(&aniso, &[]);
        assert!(e.contains("materials.odd.equivalent"), "{e}");
    }

    #[test]
    fn issue20_item5_a_height_map_is_read_once_and_only_from_a_regular_file() {
        let tmp_dir = tempfile::tempdir().unwrap();
        let dir = tmp_dir.path().to_path_buf();
        let heights = vec![0.0; 64 * 64];
        crate::npy::write_npy(&dir.join("h.npy"), 64, &heights).unwrap();
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
    fn issue20_item7_long_lines_are_cut_and_deep_keys_named() {
        let key = "k".repeat(10_000_000);
        let e = err(&format!("{BASE}\n{key} = 1\n"), &[]);
        assert!(e.len() < 2_000, "{} characters", e.len());
        assert!(e.contains("more characters"), "{}", &e[..e.len().min(400)]);
        let deep = vec!["a"; 100].join(".");
        let e = err(&format!("{deep} = 1\n{BASE}"), &[]);
        assert!(e.contains("line 1") && e.contains("nest"), "{e}");
        let nested = format!("x = {}1{}\n", "[".repeat(100), "]".repeat(100));
        let e = err(&format!("{nested}{BASE}"), &[]);
        assert!(e.contains("line 1"), "{e}");
        // Our own deepest keys and quoted names with dots pass.
        let ok = format!(
            "{BASE}\n[materials.\"a.b.c.d.e.f.g.h.i.j.k.l.m.n.o.p.q.r\"]\nisotropic = {{ youngs_gpa = 100.0, poisson = 0.3 }}\n"
        );
        Config::parse(&ok, &[]).unwrap();
    }

    #[test]
    fn issue20_item7_range_keys_are_named() {
        let range = "angles_deg = { start = 0, stop = 90, step = 45 }";
        let e = err(
            &BASE.replace(range, "angles_deg = { start = 0, stop = 90 }"),
            &[],
        );
        assert!(e.contains("needs `step`") && e.contains("line"), "{e}");
        let e = err(
            &BASE.replace(
                range,
                "angles_deg = { start = 0, stop = 90, step = 45, extra = 1 }",
            ),
            &[],
        );
        assert!(e.contains("unknown key `extra`"), "{e}");
        let e = err(&BASE.replace(range, "angles_deg = \"all\""), &[]);
        assert!(e.contains("expected a list of angles"), "{e}");
        // Integers are degrees too.
        let ok = Config::parse(&BASE.replace(range, "angles_deg = [0, 45]"), &[]).unwrap();
        assert_eq!(ok.sweep.angles_deg.values().unwrap(), [0.0, 45.0]);
    }

    #[test]
    fn heightmap_surface_is_read_from_npy_and_its_shape_checked() {
        let tmp_dir = tempfile::tempdir().unwrap();
        let dir = tmp_dir.path().to_path_buf();
        let heights: Vec<f64> = (0..64 * 64)
            .map(|i| if i % 7 == 0 { 0.5 } else { 0.0 })
            .collect();
        crate::npy::write_npy(&dir.join("h.npy"), 64, &heights).unwrap();
        crate::npy::write_npy(&dir.join("small.npy"), 32, &heights[..32 * 32]).unwrap();
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

    #[test]
    fn ladder_levels_and_grids() {
        for bad in ["0", "5"] {
            let e = err(BASE, &[&format!("convergence.levels={bad}")]);
            assert!(
                e.contains(&format!("convergence.levels = {bad}: must be 1")),
                "{e}"
            );
        }
        // h, h/√2 (5-smooth), h/2, h/(2√2) on one domain; level 0 as given.
        assert_eq!(
            (0..4).map(|k| ladder_points(384, k)).collect::<Vec<_>>(),
            vec![384, 540, 768, 1080]
        );
        let c = Config::parse(BASE, &["convergence.levels=3".into()]).unwrap();
        assert_eq!(c.level_grid(0).dx, c.grid.spacing_um * 1e-6);
        assert_eq!(c.finest_points(), 2 * c.grid.points);
        let cases = c.cases().unwrap();
        assert_eq!(
            cases.len(),
            3 * Config::parse(BASE, &[]).unwrap().cases().unwrap().len()
        );
        let (k0, s0) = &cases[0];
        let (k1, s1) = &cases[1];
        assert_eq!((k0.level, k1.level), (0, 1));
        let domain = |g: &Grid| g.n as f64 * g.dx;
        assert!((domain(&s1.grid) / domain(&s0.grid) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn cubic_material_with_111_normal_reproduces_the_fe111_preset() {
        // Back-fitted cubic constants of Fe (see docs/validation.md), frame z ∥ [111], x ∥ [11-2].
        let text = format!(
            "{BASE}\n[materials.fe111]\ncubic_gpa = {{ c11 = 257.120, c12 = 125.913, c44 = 108.576 }}\nnormal = [1, 1, 1]\nx_dir = [1, 1, -2]\n"
        )
        .replace("materials = [\"Fe\"]", "materials = [\"fe111\"]");
        let c = Config::parse(&text, &[]).unwrap();
        let mine = c.material("fe111").unwrap().stiffness();
        let preset = solver::presets::material("Fe(111)").unwrap().stiffness();
        let worst = (mine - preset).amax();
        assert!(worst < 0.05e9, "max deviation {worst:e} Pa");
    }
}
