//! Surface topography of the substrate: flat, raised islands (or dimples) on a
//! square or hexagonal lattice, parallel stripes, or an arbitrary height map on
//! the solver grid. Produces the height field on the grid; the indenter profile
//! and the initial separation `h0` are assembled in `case`.

use crate::base::cover::{disc_in_rect, rect_in_rect, strip_in_rect, Rect};
use crate::base::grid::Grid;
use crate::error::SolverError;
use serde::{Deserialize, Serialize};

/// Island shape of a patterned surface.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Island {
    /// Circular island of the given diameter (m).
    Circle {
        /// Diameter, m.
        diameter: f64,
    },
    /// Square island of the given side (m), edges along x and y.
    Square {
        /// Side, m.
        side: f64,
    },
}

/// Arrangement of the island centres.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum LatticeKind {
    /// Square lattice aligned with x and y (the paper's).
    #[default]
    Square,
    /// Hexagonal (triangular) lattice, one basis vector along x.
    Hexagonal,
}

/// How a patterned surface is put on the grid.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Sampling {
    /// Each cell carries its upper part only, with that part's exact area
    /// fraction (its cover); a cell cut by an edge is a smaller, more
    /// compliant cell (see [`Surface::cover`]). The default.
    #[default]
    Area,
    /// Whole cells, on the raised part when their centre is (the paper's).
    Centre,
}

impl Sampling {
    /// The name used in configs and outputs.
    pub fn name(self) -> &'static str {
        match self {
            Sampling::Area => "area",
            Sampling::Centre => "centre",
        }
    }
}

/// Covers below this fraction of a cell count as uncovered: such a sliver
/// would carry under 1.5 % of a whole cell's load (its compliance grows as
/// `1/cover`, [`crate::operators::operator::cut_self_factor`]), and keeping it would
/// raise the tangential operator's largest eigenvalue, and so slow its
/// solver, for nothing.
pub const MIN_COVER: f64 = 0.02;

/// A substrate surface.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Surface {
    /// Plane surface.
    Flat,
    /// Lattice of identical islands (height > 0) or dimples (height < 0).
    Lattice {
        /// Island shape.
        island: Island,
        /// Lattice pitch (nearest-neighbour distance), m.
        pitch: f64,
        /// Island height above the base, m (negative: dimples).
        height: f64,
        /// Position of one island centre relative to the sphere apex, m.
        offset: [f64; 2],
        /// Square or hexagonal arrangement.
        #[serde(default)]
        lattice: LatticeKind,
        /// How the islands' edges are put on the grid.
        #[serde(default)]
        sampling: Sampling,
    },
    /// Parallel raised stripes (ridges) of a given width.
    Stripes {
        /// Ridge width, m.
        width: f64,
        /// Pitch, m.
        pitch: f64,
        /// Ridge height, m (negative: grooves).
        height: f64,
        /// Direction of the ridges, degrees from x.
        angle_deg: f64,
        /// Offset of one ridge centre line from the apex, across the ridges, m.
        offset: f64,
        /// How the ridges' edges are put on the grid.
        #[serde(default)]
        sampling: Sampling,
    },
    /// Heights on the solver grid (m), row-major `[iy][ix]`, `n x n`.
    Heightmap {
        /// Cells per side.
        n: usize,
        /// Heights, m; shared, so that the cases of a sweep hold one copy.
        heights: std::sync::Arc<Vec<f64>>,
    },
    /// A scan resampled onto the solver grid ([`crate::model::resample`]):
    /// a height per cell and, when the scan's two levels are kept apart
    /// (`sampling = "area"`), each cut cell's cover as a pattern's.
    Resampled {
        /// Cells per side.
        n: usize,
        /// Heights, m, row-major `[iy][ix]`.
        heights: std::sync::Arc<Vec<f64>>,
        /// The cover of every cell (`None`: whole cells).
        cover: Option<std::sync::Arc<Vec<f64>>>,
    },
}

fn positive(field: &str, v: f64, what: &str) -> Result<(), SolverError> {
    crate::error::positive(field, v, what, " m")
}

/// A surface sampled on a grid ([`Surface::terrain`]): each cell's height
/// above the base and, where an edge cuts cells, every cell's cover.
#[derive(Clone, Debug, PartialEq)]
pub struct Terrain {
    /// [`Surface::heights`].
    pub heights: Vec<f64>,
    /// [`Surface::cover`].
    pub cover: Option<Vec<f64>>,
}

/// An area-sampled pattern's cell heights from the fractions on its upper
/// level: the upper level wherever at least [`MIN_COVER`] of a cell is on it.
fn levels(upper: &[f64], height: f64) -> Vec<f64> {
    upper
        .iter()
        .map(|&f| {
            if f >= MIN_COVER {
                height.max(0.0)
            } else {
                height.min(0.0)
            }
        })
        .collect()
}

/// The cover from the fractions on the upper level: the fraction on the cut
/// cells, 1 elsewhere; `None` when no cell is cut.
fn cover_of(upper: Vec<f64>) -> Option<Vec<f64>> {
    let mut cut = false;
    let cover: Vec<f64> = upper
        .into_iter()
        .map(|f| {
            if (MIN_COVER..1.0).contains(&f) {
                cut = true;
                f
            } else {
                1.0
            }
        })
        .collect();
    cut.then_some(cover)
}

impl Surface {
    /// Checks that the surface is geometrically possible on an `n x n` grid.
    pub fn validate(&self, n: usize) -> Result<(), SolverError> {
        match self {
            Surface::Flat => Ok(()),
            Surface::Lattice {
                island,
                pitch,
                height,
                offset,
                ..
            } => {
                positive("pitch", *pitch, "the lattice pitch")?;
                if !height.is_finite() {
                    return Err(SolverError::invalid(
                        "height",
                        "the island height must be finite",
                    ));
                }
                if !(offset[0].is_finite() && offset[1].is_finite()) {
                    return Err(SolverError::invalid(
                        "offset",
                        "the lattice offset must be finite",
                    ));
                }
                let (name, size, reach) = match island {
                    Island::Circle { diameter } => ("diameter", *diameter, *diameter),
                    Island::Square { side } => ("side", *side, *side * std::f64::consts::SQRT_2),
                };
                positive(name, size, "the island size")?;
                // Islands must not touch their nearest neighbours (side-by-side for
                // squares on a square lattice, corner reach on a hexagonal one).
                let limit = match self {
                    Surface::Lattice {
                        lattice: LatticeKind::Hexagonal,
                        ..
                    } => reach,
                    _ => size,
                };
                if limit >= *pitch {
                    return Err(SolverError::invalid(
                        name,
                        format!(
                            "the island ({size:.3e} m) does not fit in the pitch ({pitch:.3e} m): islands would merge"
                        ),
                    ));
                }
                Ok(())
            }
            Surface::Stripes {
                width,
                pitch,
                height,
                angle_deg,
                offset,
                ..
            } => {
                positive("pitch", *pitch, "the stripe pitch")?;
                positive("width", *width, "the stripe width")?;
                if width >= pitch {
                    return Err(SolverError::invalid(
                        "width",
                        format!("the stripe width ({width:.3e} m) must be below the pitch ({pitch:.3e} m)"),
                    ));
                }
                if !(height.is_finite() && angle_deg.is_finite() && offset.is_finite()) {
                    return Err(SolverError::invalid(
                        "height",
                        "stripe height, angle and offset must be finite",
                    ));
                }
                Ok(())
            }
            Surface::Resampled {
                cover: Some(cover), ..
            } if cover.len() != n * n || cover.iter().any(|c| !(MIN_COVER..=1.0).contains(c)) => {
                Err(SolverError::invalid(
                    "cover",
                    format!("the cover must hold {n} x {n} fractions in [{MIN_COVER}, 1]"),
                ))
            }
            Surface::Heightmap { n: hn, heights } | Surface::Resampled { n: hn, heights, .. } => {
                if *hn != n || heights.len() != n * n {
                    return Err(SolverError::invalid(
                        "heights",
                        format!(
                            "the height map is {hn} x {hn} ({} values) but the grid is {n} x {n}",
                            heights.len()
                        ),
                    ));
                }
                if let Some(i) = heights.iter().position(|h| !h.is_finite()) {
                    return Err(SolverError::invalid(
                        "heights",
                        format!(
                            "the height map has a non-finite value at row {}, column {}",
                            i / n,
                            i % n
                        ),
                    ));
                }
                Ok(())
            }
        }
    }

    /// Height of each cell above the base (m), row-major: for a pattern
    /// sampled by [`Sampling::Centre`], the level at the cell's centre; by
    /// [`Sampling::Area`], the level of the cell's upper part (the raised
    /// level wherever at least [`MIN_COVER`] of the cell is raised). Height
    /// maps give one height per cell as they are.
    pub fn heights(&self, grid: &Grid) -> Vec<f64> {
        let n = grid.n;
        let mut h = vec![0.0; grid.len()];
        match self {
            Surface::Flat => {}
            Surface::Heightmap { heights, .. } | Surface::Resampled { heights, .. } => {
                h.copy_from_slice(heights)
            }
            Surface::Stripes {
                width,
                pitch,
                height,
                angle_deg,
                offset,
                sampling: Sampling::Centre,
            } => {
                let (s, c) = angle_deg.to_radians().sin_cos();
                for iy in 0..n {
                    for ix in 0..n {
                        // Distance across the ridges from the reference centre line.
                        let d = -grid.x(ix) * s + grid.y(iy) * c - offset;
                        let u = d - pitch * (d / pitch).round();
                        if u.abs() <= 0.5 * width {
                            h[iy * n + ix] = *height;
                        }
                    }
                }
            }
            Surface::Lattice {
                island,
                pitch,
                height,
                offset,
                lattice,
                sampling: Sampling::Centre,
            } => {
                for iy in 0..n {
                    for ix in 0..n {
                        let (u, v) = nearest_centre_offset(
                            *lattice,
                            *pitch,
                            grid.x(ix) - offset[0],
                            grid.y(iy) - offset[1],
                        );
                        let inside = match island {
                            Island::Circle { diameter } => u.hypot(v) <= 0.5 * diameter,
                            Island::Square { side } => {
                                u.abs() <= 0.5 * side && v.abs() <= 0.5 * side
                            }
                        };
                        if inside {
                            h[iy * n + ix] = *height;
                        }
                    }
                }
            }
            Surface::Lattice { height, .. } | Surface::Stripes { height, .. } => {
                return levels(&self.upper_fraction(grid, *height), *height);
            }
        }
        h
    }

    /// The heights and the cover of every cell ([`Surface::heights`],
    /// [`Surface::cover`]), the fractions of an area-sampled pattern
    /// integrated once for both: what a case needs of its surface.
    pub fn terrain(&self, grid: &Grid) -> Terrain {
        if let Surface::Resampled { heights, cover, .. } = self {
            return Terrain {
                heights: heights.to_vec(),
                cover: cover.as_ref().map(|c| c.to_vec()),
            };
        }
        match self.area_height() {
            Some(height) => {
                let upper = self.upper_fraction(grid, height);
                Terrain {
                    heights: levels(&upper, height),
                    cover: cover_of(upper),
                }
            }
            None => Terrain {
                heights: self.heights(grid),
                cover: None,
            },
        }
    }

    /// The pattern height of an area-sampled pattern (`None` for every other
    /// surface: whole cells).
    fn area_height(&self) -> Option<f64> {
        match self {
            Surface::Lattice {
                height,
                sampling: Sampling::Area,
                ..
            }
            | Surface::Stripes {
                height,
                sampling: Sampling::Area,
                ..
            } => Some(*height),
            _ => None,
        }
    }

    /// The fraction of each cell's area at the level [`Surface::heights`]
    /// gives it, row-major: below 1 on the cells that an edge cuts (their
    /// upper part), 1 elsewhere. `None` when every cell is whole (flat
    /// surfaces, height maps, patterns sampled by [`Sampling::Centre`]).
    ///
    /// A cut cell carries its load on that part only: the solver takes the
    /// cell-mean tractions as unknowns, so that forces are sums over cells as
    /// everywhere, counts the cell's area times its cover, and makes the cell
    /// more compliant under its own load
    /// ([`crate::operators::operator::cut_self_factor`], `docs/physics-choices.md`).
    pub fn cover(&self, grid: &Grid) -> Option<Vec<f64>> {
        if let Surface::Resampled { cover, .. } = self {
            return cover.as_ref().map(|c| c.to_vec());
        }
        let height = self.area_height()?;
        cover_of(self.upper_fraction(grid, height))
    }

    /// The fraction of each cell's area on the pattern's upper level: the
    /// raised part for islands and ridges (`height > 0`), the rest for
    /// dimples and grooves. What [`Surface::heights`] and
    /// [`Surface::cover`] of an area-sampled pattern both read.
    fn upper_fraction(&self, grid: &Grid, height: f64) -> Vec<f64> {
        let mut f = self.raised_fraction(grid);
        if height <= 0.0 {
            f.iter_mut().for_each(|v| *v = 1.0 - *v);
        }
        f
    }

    /// The sampling of a patterned surface (`None` for flat surfaces and
    /// height maps, which have no edges to sample).
    pub fn sampling(&self) -> Option<Sampling> {
        match self {
            Surface::Lattice { sampling, .. } | Surface::Stripes { sampling, .. } => {
                Some(*sampling)
            }
            Surface::Flat | Surface::Heightmap { .. } | Surface::Resampled { .. } => None,
        }
    }

    /// Exact fraction of each cell's area on the islands or ridges
    /// (closed-form areas of [`crate::base::cover`]), row-major; zeros for flat
    /// surfaces and height maps. A cell costs a handful of islands or
    /// ridges however fine the pattern (whole periods in closed form,
    /// [`Sites::area_in`], [`Ridges::area_in`]; #47).
    pub fn raised_fraction(&self, grid: &Grid) -> Vec<f64> {
        let n = grid.n;
        let mut f = vec![0.0; grid.len()];
        let (dx, dy) = (grid.dx, grid.dy);
        let half_diagonal = 0.5 * dx.hypot(dy);
        match self {
            Surface::Flat | Surface::Heightmap { .. } | Surface::Resampled { .. } => {}
            Surface::Stripes {
                width,
                pitch,
                angle_deg,
                offset,
                ..
            } => {
                let (s, c) = angle_deg.to_radians().sin_cos();
                let (nx, ny) = (-s, c);
                let ridges = Ridges {
                    nx,
                    ny,
                    offset: *offset,
                    width: *width,
                    pitch: *pitch,
                };
                // Half the extent of a cell across the ridges.
                let spread = 0.5 * (dx * s.abs() + dy * c.abs());
                for iy in 0..n {
                    for ix in 0..n {
                        let (x, y) = (grid.x(ix), grid.y(iy));
                        let d = nx * x + ny * y - offset;
                        let u = d - pitch * (d / pitch).round();
                        let cell = &mut f[iy * n + ix];
                        if u.abs() + spread <= 0.5 * width {
                            *cell = 1.0;
                        } else if u.abs() - spread < 0.5 * width
                            || pitch - u.abs() - spread < 0.5 * width
                        {
                            let rect = Rect::cell(x, y, dx, dy);
                            let area = ridges.area_in(&rect, d, spread);
                            *cell = (area / rect.area()).min(1.0);
                        }
                    }
                }
            }
            Surface::Lattice {
                island,
                pitch,
                offset,
                lattice,
                ..
            } => {
                let sites = Sites::new(*island, *lattice, *pitch, *offset);
                for iy in 0..n {
                    for ix in 0..n {
                        let (x, y) = (grid.x(ix), grid.y(iy));
                        let (u, v) =
                            nearest_centre_offset(*lattice, *pitch, x - offset[0], y - offset[1]);
                        // Whole cells (inside or outside the nearest island)
                        // first; only cells near an edge are integrated.
                        let inside = match island {
                            Island::Circle { diameter } => {
                                u.hypot(v) + half_diagonal <= 0.5 * diameter
                            }
                            Island::Square { side } => {
                                u.abs() + 0.5 * dx <= 0.5 * side && v.abs() + 0.5 * dy <= 0.5 * side
                            }
                        };
                        let cell = &mut f[iy * n + ix];
                        if inside {
                            *cell = 1.0;
                        } else if u.hypot(v) - half_diagonal < sites.reach {
                            let rect = Rect::cell(x, y, dx, dy);
                            *cell = (sites.area_in(&rect) / rect.area()).min(1.0);
                        }
                    }
                }
            }
        }
        f
    }

    /// Area fraction of the surface covered by islands or ridges (0 for flat and height maps).
    pub fn density(&self) -> f64 {
        match self {
            Surface::Flat | Surface::Heightmap { .. } | Surface::Resampled { .. } => 0.0,
            Surface::Stripes { width, pitch, .. } => width / pitch,
            Surface::Lattice {
                island,
                pitch,
                lattice,
                ..
            } => {
                let a = island_area(*island);
                let cell = match lattice {
                    LatticeKind::Square => pitch * pitch,
                    LatticeKind::Hexagonal => pitch * pitch * 3f64.sqrt() / 2.0,
                };
                a / cell
            }
        }
    }

    /// The pattern's pitch in cells of `grid` (its larger side): how
    /// finely the grid resolves the islands, ridges or dimples. `None` for
    /// flat surfaces and height maps.
    pub fn cells_per_pitch(&self, grid: &Grid) -> Option<f64> {
        match self {
            Surface::Lattice { pitch, .. } | Surface::Stripes { pitch, .. } => {
                Some(pitch / grid.dx.max(grid.dy))
            }
            Surface::Flat | Surface::Heightmap { .. } | Surface::Resampled { .. } => None,
        }
    }

    /// What a grid that does not resolve the pattern (fewer than
    /// [`RESOLVED_CELLS_PER_PITCH`] cells per pitch) makes of it, in one
    /// line without the surface's name; `None` when it resolves it (and for
    /// flat surfaces and height maps). The case is solved all the same.
    pub fn unresolved_pattern(&self, grid: &Grid) -> Option<String> {
        let ratio = self.cells_per_pitch(grid)?;
        if ratio >= RESOLVED_CELLS_PER_PITCH {
            return None;
        }
        let (pitch, height, what) = match self {
            Surface::Lattice { pitch, height, .. } => (
                *pitch,
                *height,
                if *height < 0.0 { "dimples" } else { "islands" },
            ),
            Surface::Stripes { pitch, height, .. } => (
                *pitch,
                *height,
                if *height < 0.0 { "grooves" } else { "ridges" },
            ),
            Surface::Flat | Surface::Heightmap { .. } | Surface::Resampled { .. } => return None,
        };
        let upper = if height <= 0.0 {
            1.0 - self.density()
        } else {
            self.density()
        };
        let made = match self.sampling() {
            Some(Sampling::Centre) => "centre sampling puts each cell on one level by the point at its centre alone: an aliased pattern (sampling = \"area\" gives each cell its exact cover)".to_string(),
            _ if upper < MIN_COVER => format!(
                "the upper level covers {upper:.3} of the surface, under the smallest cover kept ({MIN_COVER}): a cell holding many {what} lies whole at the lower level, as on a flat surface"
            ),
            _ => format!(
                "each cell carries its exact cover, the fraction of its area on the upper level ({upper:.3} on average where a cell holds many {what}): a homogenised pattern"
            ),
        };
        Some(format!(
            "pitch {} µm is {} cells of {} µm, below {RESOLVED_CELLS_PER_PITCH} cells per pitch: the grid does not resolve the {what}; {made}",
            short(pitch * 1e6),
            short(ratio),
            short(grid.dx.max(grid.dy) * 1e6),
        ))
    }
}

/// A number in four significant digits, plainly between 0.001 and 10⁴,
/// in scientific notation otherwise.
fn short(v: f64) -> String {
    if (1e-3..1e4).contains(&v.abs()) {
        let digits = (3 - v.abs().log10().floor() as i32).max(0) as usize;
        let text = format!("{v:.digits$}");
        if text.contains('.') {
            text.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            text
        }
    } else {
        format!("{v:.3e}")
    }
}

/// Cells per pitch below which a grid does not resolve a pattern's
/// islands, ridges or dimples: each cell then holds about a whole period or
/// more, and the pattern acts as its mean cover per cell
/// ([`Surface::unresolved_pattern`], `docs/physics-choices.md`).
pub const RESOLVED_CELLS_PER_PITCH: f64 = 2.0;

/// Offset of the point (x, y) from its nearest lattice site (a site at the origin).
fn nearest_centre_offset(kind: LatticeKind, pitch: f64, x: f64, y: f64) -> (f64, f64) {
    match kind {
        LatticeKind::Square => (
            x - pitch * (x / pitch).round(),
            y - pitch * (y / pitch).round(),
        ),
        LatticeKind::Hexagonal => {
            // Basis a1 = (p, 0), a2 = (p/2, p√3/2); check the sites around the
            // rounded lattice coordinates and keep the nearest.
            let h = pitch * 3f64.sqrt() / 2.0;
            let j0 = (y / h).round();
            let mut best = (f64::INFINITY, 0.0, 0.0);
            for dj in -1..=1 {
                let j = j0 + dj as f64;
                let i0 = ((x - 0.5 * pitch * j) / pitch).round();
                for di in -1..=1 {
                    let i = i0 + di as f64;
                    let (cx, cy) = (pitch * i + 0.5 * pitch * j, h * j);
                    let d = (x - cx).hypot(y - cy);
                    if d < best.0 {
                        best = (d, x - cx, y - cy);
                    }
                }
            }
            (best.1, best.2)
        }
    }
}

/// The lattice's rectangular period (its supercell), the rectangle the
/// islands repeat in along x and y: `(width, height, sites in it)`. Pitch
/// x pitch with one site for a square lattice; pitch x √3 pitch with two
/// for a hexagonal one (rows `√3/2` pitch apart, every other row shifted).
fn supercell(lattice: LatticeKind, pitch: f64) -> (f64, f64, f64) {
    match lattice {
        LatticeKind::Square => (pitch, pitch, 1.0),
        LatticeKind::Hexagonal => (pitch, 2.0 * (pitch * 3f64.sqrt() / 2.0), 2.0),
    }
}

/// The circumradius of an island: how far from its site it reaches.
fn island_reach(island: Island) -> f64 {
    match island {
        Island::Circle { diameter } => 0.5 * diameter,
        Island::Square { side } => side * std::f64::consts::FRAC_1_SQRT_2,
    }
}

/// Area of one island.
fn island_area(island: Island) -> f64 {
    match island {
        Island::Circle { diameter } => std::f64::consts::PI * diameter * diameter / 4.0,
        Island::Square { side } => side * side,
    }
}

/// The islands of a lattice: their shape, the lattice, its pitch and the
/// offset of one site, and how far an island reaches from its site (its
/// circumradius).
#[derive(Clone, Copy, Debug)]
struct Sites {
    island: Island,
    lattice: LatticeKind,
    pitch: f64,
    offset: [f64; 2],
    reach: f64,
}

impl Sites {
    fn new(island: Island, lattice: LatticeKind, pitch: f64, offset: [f64; 2]) -> Self {
        Sites {
            island,
            lattice,
            pitch,
            offset,
            reach: island_reach(island),
        }
    }

    /// Area of the islands inside `rect`, at a cost bounded by a handful of
    /// sites however many islands the rectangle holds (#47: a pattern far
    /// finer than the grid). Exact: the rectangle is split into `m_x x m_y`
    /// whole supercells (their islands' area in closed form), the `m_x`
    /// whole supercells' widths of the strip above them and the `m_y`
    /// heights of the column beside them (each a copy of one window at most
    /// a supercell wide and high, [`Sites::area_direct`]), and the corner.
    /// A rectangle that spans no whole supercell either way is summed site
    /// by site as it is ([`Sites::area_direct`], the same bits as before
    /// #47).
    fn area_in(&self, rect: &Rect) -> f64 {
        let (px, py, sites) = supercell(self.lattice, self.pitch);
        let mx = ((rect.x1 - rect.x0) / px).floor();
        let my = ((rect.y1 - rect.y0) / py).floor();
        let window = |x0, x1, y0, y1| self.area_direct(&Rect { x0, x1, y0, y1 });
        if mx < 1.0 && my < 1.0 {
            return self.area_direct(rect);
        }
        // The ends of the whole supercells (never past the rectangle's edge).
        let xm = (rect.x0 + mx * px).min(rect.x1);
        let ym = (rect.y0 + my * py).min(rect.y1);
        let mut area = mx * my * sites * island_area(self.island);
        if mx >= 1.0 {
            area += mx * window(rect.x0, rect.x0 + px, ym, rect.y1);
        }
        if my >= 1.0 {
            area += my * window(xm, rect.x1, rect.y0, rect.y0 + py);
        }
        area + window(xm, rect.x1, ym, rect.y1)
    }

    /// Area of the islands inside `rect`: every site whose island can
    /// reach the rectangle, summed (islands never overlap,
    /// [`Surface::validate`]).
    fn area_direct(&self, rect: &Rect) -> f64 {
        let Sites {
            island,
            lattice,
            pitch,
            offset,
            reach,
        } = *self;
        let (x0, x1) = (rect.x0 - reach - offset[0], rect.x1 + reach - offset[0]);
        let (y0, y1) = (rect.y0 - reach - offset[1], rect.y1 + reach - offset[1]);
        let (row, shear) = match lattice {
            LatticeKind::Square => (pitch, 0.0),
            LatticeKind::Hexagonal => (pitch * 3f64.sqrt() / 2.0, 0.5 * pitch),
        };
        let mut area = 0.0;
        for j in (y0 / row).ceil() as i64..=(y1 / row).floor() as i64 {
            let cy = j as f64 * row;
            let start = shear * j as f64;
            for i in ((x0 - start) / pitch).ceil() as i64..=((x1 - start) / pitch).floor() as i64 {
                let cx = start + i as f64 * pitch;
                let (sx, sy) = (offset[0] + cx, offset[1] + cy);
                area += match island {
                    Island::Circle { diameter } => disc_in_rect(sx, sy, 0.5 * diameter, rect),
                    Island::Square { side } => rect_in_rect(&Rect::square(sx, sy, side), rect),
                };
            }
        }
        area
    }
}

/// Parallel ridges: the unit normal across them, the offset of one ridge's
/// centre line along it, their width and pitch.
#[derive(Clone, Copy, Debug)]
struct Ridges {
    nx: f64,
    ny: f64,
    offset: f64,
    width: f64,
    pitch: f64,
}

impl Ridges {
    /// Area of the ridges inside `rect` (its centre `d` across the ridges,
    /// `spread` half its extent across them), at a cost bounded by a
    /// handful of ridges however many the rectangle holds (#47). Exact:
    /// the ridges repeat along x every `pitch / |nx|` and along y every
    /// `pitch / |ny|`, and a whole period along x of any strip of height
    /// `h` holds `width h / |nx|` of ridge (along y likewise). So the
    /// rectangle is split into its `m_x` whole periods along x, the `m_y`
    /// whole periods along y of the column left beside them, and the
    /// corner, whose ridges are summed ([`Ridges::area_direct`]). A
    /// rectangle that spans no whole period along x or y (under one pitch
    /// across the ridges from either side) is summed as it is, the same
    /// bits as before #47.
    fn area_in(&self, rect: &Rect, d: f64, spread: f64) -> f64 {
        let (ax, ay) = (self.nx.abs(), self.ny.abs());
        let mx = ((rect.x1 - rect.x0) * ax / self.pitch).floor();
        let my = ((rect.y1 - rect.y0) * ay / self.pitch).floor();
        if mx < 1.0 && my < 1.0 {
            return self.area_direct(rect, d, spread);
        }
        let mut area = 0.0;
        let mut x0 = rect.x0;
        if mx >= 1.0 {
            area += mx * self.width * (rect.y1 - rect.y0) / ax;
            x0 = (rect.x0 + mx * self.pitch / ax).min(rect.x1);
        }
        let mut y0 = rect.y0;
        if my >= 1.0 {
            area += my * self.width * (rect.x1 - x0) / ay;
            y0 = (rect.y0 + my * self.pitch / ay).min(rect.y1);
        }
        let corner = Rect {
            x0,
            x1: rect.x1,
            y0,
            y1: rect.y1,
        };
        let (cx, cy) = (0.5 * (corner.x0 + corner.x1), 0.5 * (corner.y0 + corner.y1));
        let d = self.nx * cx + self.ny * cy - self.offset;
        let spread = 0.5 * ((corner.x1 - corner.x0) * ax + (corner.y1 - corner.y0) * ay);
        area + self.area_direct(&corner, d, spread)
    }

    /// Area of the ridges inside `rect` (centre `d` across the ridges,
    /// `spread` half its extent across them): every ridge that can reach
    /// it, summed.
    fn area_direct(&self, rect: &Rect, d: f64, spread: f64) -> f64 {
        let Ridges {
            nx,
            ny,
            offset,
            width,
            pitch,
        } = *self;
        let k0 = ((d - spread - 0.5 * width) / pitch).ceil() as i64;
        let k1 = ((d + spread + 0.5 * width) / pitch).floor() as i64;
        (k0..=k1)
            .map(|k| {
                let line = offset + k as f64 * pitch;
                strip_in_rect(nx, ny, line, width, rect)
            })
            .sum()
    }
}

#[cfg(test)]
mod tests;
