//! `[grid]`, `[indenter]` and `[load]`: the surface grid, the sphere and
//! the load on it, and the solver's `Load` they make. The ladder of finer
//! grids is `convergence`; the force angles are `sweep`.

use super::Config;
use serde::{Deserialize, Serialize};
use solver::Load;

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
    /// The ball's material (a preset or a `[materials.NAME]` table), in the
    /// ball's own frame; absent: a rigid ball. Not written back when absent,
    /// so that a rigid-ball config echoes (and resumes) as before.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub material: Option<String>,
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

impl Config {
    /// A warning for each of `surfaces` whose pattern `[grid]` does not
    /// resolve (fewer than [`solver::RESOLVED_CELLS_PER_PITCH`] cells per
    /// pitch, [`solver::Surface::unresolved_pattern`]), naming the surface:
    /// what `check`, `solve` and `run` print. Such cases are solved all the
    /// same, on the pattern's exact cover per cell.
    pub fn unresolved_patterns(&self, surfaces: &[String]) -> anyhow::Result<Vec<String>> {
        let grid = self.level_grid(0);
        let mut warnings = Vec::new();
        for name in surfaces {
            if let Some(w) = self.surface(name)?.unresolved_pattern(&grid) {
                warnings.push(format!("surface `{name}`: {w}"));
            }
        }
        Ok(warnings)
    }

    /// The load of one case: the sphere of `[indenter]` under `[load]`, with
    /// `tangential_ratio` (the config's, or a load history's last) at `angle_deg`.
    pub(super) fn load_at(&self, tangential_ratio: f64, angle_deg: f64) -> Load {
        Load {
            indenter_radius_m: self.indenter.radius_mm * 1e-3,
            normal_force_n: self.load.normal_n,
            friction: self.load.friction,
            tangential_ratio,
            angle_deg,
        }
    }
}

/// The config key of a solver parameter of the grid or the load.
pub(super) fn config_key(param: &str) -> Option<String> {
    let key = match param {
        "grid.n" => "grid.points",
        "grid.dx" | "grid.dy" => "grid.spacing_um",
        "load.indenter_radius_m" => "indenter.radius_mm",
        "load.normal_force_n" => "load.normal_n",
        _ => return None,
    };
    Some(key.to_string())
}

#[cfg(test)]
mod tests {
    use super::super::fixtures::{err, BASE};

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
}
