//! `[stress]`: stresses below the surface (issue #38), opt-in. Without the
//! section nothing is computed and every output is as before. The
//! computation is `solver::stress`; the files and scalars
//! `crate::output::stress`.

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use solver::stress_summary::{StressRequest, StressStates};

/// Most depth planes (each costs a kernel of 18 padded spectra).
pub const MAX_DEPTHS: usize = 64;
/// Most depth rows of a slice.
pub const MAX_SLICE_ROWS: usize = 256;

/// `[stress]`
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StressCfg {
    /// Depths of the horizontal planes, µm (each ≥ 0; none: no planes;
    /// −0 read as 0, one plane and one file name).
    #[serde(default, deserialize_with = "depths")]
    pub depths_um: Vec<f64>,
    /// Vertical slices through the contact centre along and across the force.
    #[serde(default = "yes")]
    pub slices: bool,
    /// Deepest row of the slices, µm (default: twice the contact radius).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub slice_depth_um: Option<f64>,
    /// Depth rows of a slice, the surface included.
    #[serde(default = "default_rows")]
    pub slice_rows: usize,
    /// Which states of a load history: `last_cycle` (the turning points of
    /// its last cycle), `turning` (every turning point) or `final` (the
    /// last increment). A case without a history has one state.
    #[serde(default = "last_cycle")]
    pub states: String,
    /// Crossland's coefficient α of the largest hydrostatic stress
    /// (`√J2,a + α σH,max`), for the fretting-fatigue parameter.
    #[serde(default = "default_alpha")]
    pub crossland_alpha: f64,
}

/// The depths as written, `−0` read as `0` (`x + 0.0`): the plane at the
/// surface has one name, `plane_0um_*`.
fn depths<'de, D: serde::Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
    let v: Vec<f64> = Vec::deserialize(d)?;
    Ok(v.into_iter().map(|x| x + 0.0).collect())
}

fn yes() -> bool {
    true
}
fn default_rows() -> usize {
    41
}
fn last_cycle() -> String {
    "last_cycle".into()
}
fn default_alpha() -> f64 {
    0.3
}

impl StressCfg {
    /// The solver's form of the section (what `solve`, Python and the
    /// sweep's workers compute).
    pub fn request(&self) -> StressRequest {
        StressRequest {
            depths_m: self.depths_um.iter().map(|d| d * 1e-6).collect(),
            slices: self.slices,
            slice_depth_m: self.slice_depth_um.map(|d| d * 1e-6),
            slice_rows: self.slice_rows,
            states: self.chosen_states(),
            crossland_alpha: self.crossland_alpha,
        }
    }

    /// `states` as the solver's choice (checked by [`StressCfg::check`]).
    pub fn chosen_states(&self) -> StressStates {
        match self.states.as_str() {
            "turning" => StressStates::Turning,
            "final" => StressStates::Final,
            _ => StressStates::LastCycle,
        }
    }

    /// Checks the section on the config's `grid` (its deepest plane);
    /// errors name the key.
    pub(super) fn check(&self, grid: &super::GridCfg) -> Result<()> {
        if self.depths_um.len() > MAX_DEPTHS {
            bail!(
                "stress.depths_um: {} depths, at most {MAX_DEPTHS} (each plane holds 18 spectra of the padded grid)",
                self.depths_um.len()
            );
        }
        // The deepest plane of the grid's padded period (every level of a
        // convergence ladder covers the same domain).
        let deepest_um =
            solver::stress::max_depth_m(&solver::Grid::square(grid.points, grid.spacing_um * 1e-6))
                * 1e6;
        let mut seen: Vec<f64> = Vec::new();
        for &d in &self.depths_um {
            if !d.is_finite() || d < 0.0 {
                bail!("stress.depths_um: {d} is not a depth below the surface (µm, ≥ 0)");
            }
            if d > deepest_um {
                bail!(
                    "stress.depths_um: {d} µm is below the deepest plane computed on this grid, {deepest_um:.0} µm ({} padded domains 2 x grid.points x grid.spacing_um)",
                    solver::stress::MAX_DEPTH_PERIODS
                );
            }
            // (−0 and 0 are one plane, `plane_0um_*`)
            if seen.contains(&d) {
                bail!("stress.depths_um: {d} is listed twice; every plane must be unique");
            }
            seen.push(d);
        }
        if let Some(d) = self.slice_depth_um {
            if !d.is_finite() || d <= 0.0 {
                bail!("stress.slice_depth_um = {d}: must be positive (µm)");
            }
            if d > deepest_um {
                bail!(
                    "stress.slice_depth_um = {d}: below the deepest row computed on this grid, {deepest_um:.0} µm ({} padded domains 2 x grid.points x grid.spacing_um)",
                    solver::stress::MAX_DEPTH_PERIODS
                );
            }
        }
        if !(2..=MAX_SLICE_ROWS).contains(&self.slice_rows) {
            bail!(
                "stress.slice_rows = {}: must be 2 to {MAX_SLICE_ROWS}",
                self.slice_rows
            );
        }
        if !["last_cycle", "turning", "final"].contains(&self.states.as_str()) {
            bail!(
                "stress.states = \"{}\": must be \"last_cycle\" (the turning points of the load history's last cycle), \"turning\" (all its turning points) or \"final\"",
                self.states
            );
        }
        if !self.crossland_alpha.is_finite() || self.crossland_alpha < 0.0 {
            bail!(
                "stress.crossland_alpha = {}: must be finite and ≥ 0",
                self.crossland_alpha
            );
        }
        if self.depths_um.is_empty() && !self.slices {
            bail!(
                "stress: neither depths_um nor slices: nothing to compute (leave the section out)"
            );
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use crate::config::Config;

    const BASE: &str = "[grid]\npoints = 64\nspacing_um = 2.0\n[indenter]\nradius_mm = 18.0\n[load]\nnormal_n = 20.0\nfriction = 0.3\n[sweep]\nmaterials = [\"Fe\"]\n";

    fn err(stress: &str) -> String {
        let text = format!("{BASE}[stress]\n{stress}\n");
        format!("{:#}", Config::parse(&text, &[]).unwrap_err())
    }

    #[test]
    fn issue38_bad_stress_keys_are_named() {
        assert!(err("depths_um = [-1.0]").contains("stress.depths_um"));
        assert!(err("slice_depth_um = 0.0").contains("stress.slice_depth_um"));
        assert!(err("slice_rows = 1").contains("stress.slice_rows"));
        assert!(err("states = \"all\"").contains("stress.states"));
        assert!(err("crossland_alpha = -1.0").contains("stress.crossland_alpha"));
        assert!(err("slices = false").contains("nothing to compute"));
        assert!(err("depth_um = [1.0]").contains("depth_um"));
    }

    /// Issue #59 item 12: a depth listed twice is refused like the other
    /// lists' duplicates (−0 and 0 too: one plane), and a lone −0 is the
    /// surface plane `0` (its files `plane_0um_*`, never `plane_-0um_*`).
    #[test]
    fn issue59_duplicate_depths_are_refused_and_minus_zero_is_the_surface() {
        let e = err("depths_um = [25.0, 10.0, 25.0]");
        assert!(e.contains("stress.depths_um: 25 is listed twice"), "{e}");
        let e = err("depths_um = [0.0, -0.0]");
        assert!(e.contains("stress.depths_um: 0 is listed twice"), "{e}");
        let c = Config::parse(&format!("{BASE}[stress]\ndepths_um = [-0.0, 5.0]\n"), &[]).unwrap();
        let d = &c.stress.unwrap().depths_um;
        assert_eq!(d[0].to_bits(), 0.0f64.to_bits());
        assert_eq!(crate::float_text::fmt_f64(d[0]), "0");
    }

    /// Issue #59 item 7: a depth below the deepest plane a grid computes
    /// (10⁶ padded domains: 128 mm here, 2 x 64 x 2 µm a domain) is refused
    /// with the limit, for the planes and the slices.
    #[test]
    fn issue59_a_depth_beyond_the_deepest_plane_is_refused_with_the_limit() {
        let e = err("depths_um = [1.0, 3e8]");
        assert!(
            e.contains("stress.depths_um: 300000000 µm is below the deepest plane computed on this grid, 256000000 µm"),
            "{e}"
        );
        let e = err("slice_depth_um = 3e8");
        assert!(
            e.contains("stress.slice_depth_um = 300000000: below the deepest row"),
            "{e}"
        );
        // 200 m below a 128 µm domain is computed (the images of its
        // padded grid are summed there, solver/tests/stress.rs).
        Config::parse(&format!("{BASE}[stress]\ndepths_um = [1e9]\n"), &[]).unwrap_err();
        Config::parse(&format!("{BASE}[stress]\ndepths_um = [2e8]\n"), &[]).unwrap();
    }

    #[test]
    fn issue38_no_section_no_stress_and_defaults_with_one() {
        let c = Config::parse(BASE, &[]).unwrap();
        assert!(c.stress.is_none());
        let c = Config::parse(&format!("{BASE}[stress]\ndepths_um = [5.0]\n"), &[]).unwrap();
        let s = c.stress.unwrap();
        assert!(s.slices && s.slice_rows == 41 && s.states == "last_cycle");
    }
}
