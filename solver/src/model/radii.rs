//! What the model means by a zone's radius: the zone's own (its outline,
//! `contact_radius_m` and `stick_radius_m` in every output), the apparent
//! radii μa and K_E can use (`Radii`, `mu_a_*_radius_m`, with the texts
//! outputs state), and the radius of a zone read from its level field under
//! each. The solvers' load histories and the results both apply them, so
//! they live below both.

use serde::{Deserialize, Serialize};

use crate::base::geometry::{equivalent_radius, moment_radius, subcell_hull_area};
use crate::base::grid::Grid;
use crate::model::surface::Terrain;

/// The definition of the apparent contact and stick radii that μa and K_E
/// use (PHYSICS.md §7: the second moments by default, the paper's convex
/// hull on request; docs/physics-choices.md, "Reported quantities", says
/// why).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Radii {
    /// The circle with the area of the convex hull of the contact (stick)
    /// boundary, located between cell centres
    /// ([`APPARENT_RADIUS_DEFINITION`]): the paper's definition, its
    /// boundary found below the cell. It jumps when a far island or a stick
    /// cell joins the hull, so patterned ladders rarely extrapolate with
    /// it; the configs that reproduce the paper pin it.
    Hull,
    /// From the second moment of the pressure (of μp − |q| on the stick
    /// cells) about its centroid, `r² = 5/2 ⟨r²⟩`
    /// ([`APPARENT_RADIUS_DEFINITION_MOMENTS`]): exact for Hertz and
    /// Cattaneo–Mindlin, and continuous in the solution, so that patterned
    /// μa converges monotonically with the grid. The default (issue #47).
    #[default]
    Moments,
}

impl Radii {
    /// The definition's text, as outputs state it.
    pub fn definition(self) -> &'static str {
        match self {
            Radii::Hull => APPARENT_RADIUS_DEFINITION,
            Radii::Moments => APPARENT_RADIUS_DEFINITION_MOMENTS,
        }
    }
}

/// How the apparent radii a and c (`mu_a_contact_radius_m`,
/// `mu_a_stick_radius_m`, used for `mu_a` and `k_e`) are defined under
/// `solver.radii = "hull"`; also the zones' own radii
/// ([`ZONE_RADIUS_DEFINITION`]).
pub const APPARENT_RADIUS_DEFINITION: &str = "radius of the circle with the area of the convex hull of the contact (stick) boundary located between cell centres: along every row and column, the zero of p^2 ((mu p - |q|)^2 for stick) extrapolated linearly outward from the two outermost cells, kept within one cell pitch (the cell face where the level does not fall outward)";

/// The second-moment definition of the apparent radii (`solver.radii =
/// "moments"`, the default; the paper's is [`APPARENT_RADIUS_DEFINITION`]).
pub const APPARENT_RADIUS_DEFINITION_MOMENTS: &str = "radius from the second moment about the centroid, r^2 = 5/2 <r^2>, of the pressure over the contact cells (of mu p - |q| over the stick cells): exact for a Hertz pressure and a Cattaneo-Mindlin stick zone, continuous in the solution";

/// How the zones' own radii (`contact_radius_m`, `stick_radius_m`: the
/// contact and the stick zone under every load, whatever `solver.radii`
/// says) are defined: their outline, the hull of [`APPARENT_RADIUS_DEFINITION`]
/// (issue #59: the second moments are exact only for Hertz and Mindlin's
/// stick zone; on Spence's normal loading with friction they read 0.76 a
/// where the stick zone's edge is at 0.896 a).
pub const ZONE_RADIUS_DEFINITION: &str = "the zone's outline, under any solver.radii: radius of the circle with the area of the convex hull of the contact (stick) boundary located between cell centres (as solver.radii = \"hull\" defines it)";

/// How the paper's radii (`contact_radius_cells_m`, `stick_radius_cells_m`,
/// used for `mu_a_cells` and `k_e_cells`) are defined.
pub const APPARENT_RADIUS_DEFINITION_CELLS: &str =
    "radius of the circle with the area of the convex hull of the contact (stick) cells, each cell taken as its full square (the paper's definition)";

/// The apparent radius (m) of the zone `mask` of `grid` under the
/// definition `radii`, from its level field (the pressure on the contact,
/// [`friction_reserve`] on the stick zone): the sub-cell hull's
/// ([`APPARENT_RADIUS_DEFINITION`]; the `terrain`'s heights and cover
/// bound it at island edges) or the second moment's
/// ([`APPARENT_RADIUS_DEFINITION_MOMENTS`]).
pub(crate) fn apparent_radius(
    radii: Radii,
    grid: &Grid,
    mask: &[bool],
    level: &[f64],
    terrain: &Terrain,
) -> f64 {
    match radii {
        Radii::Hull => equivalent_radius(subcell_hull_area(
            grid,
            mask,
            level,
            &terrain.heights,
            terrain.cover.as_deref(),
        )),
        Radii::Moments => moment_radius(grid, mask, level),
    }
}

/// The zone's own radius (m) of `mask` from its level field
/// ([`ZONE_RADIUS_DEFINITION`]): its outline, the sub-cell hull, under any
/// `solver.radii`.
pub(crate) fn zone_radius(grid: &Grid, mask: &[bool], level: &[f64], terrain: &Terrain) -> f64 {
    apparent_radius(Radii::Hull, grid, mask, level, terrain)
}

/// The stick zone's friction reserve `(μp − |q|)⁺` per cell, Pa: the level
/// whose zero is a Mindlin stick edge.
pub(crate) fn friction_reserve(mu: f64, p: &[f64], (qx, qy): (&[f64], &[f64])) -> Vec<f64> {
    (0..p.len())
        .map(|i| (mu * p[i] - qx[i].hypot(qy[i])).max(0.0))
        .collect()
}
