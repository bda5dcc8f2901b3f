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
            Surface::Heightmap { n: hn, heights } => {
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
            Surface::Heightmap { heights, .. } => h.copy_from_slice(heights),
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
            Surface::Flat | Surface::Heightmap { .. } => None,
        }
    }

    /// Exact fraction of each cell's area on the islands or ridges
    /// (closed-form areas of [`crate::base::cover`]), row-major; zeros for flat
    /// surfaces and height maps.
    pub fn raised_fraction(&self, grid: &Grid) -> Vec<f64> {
        let n = grid.n;
        let mut f = vec![0.0; grid.len()];
        let (dx, dy) = (grid.dx, grid.dy);
        let half_diagonal = 0.5 * dx.hypot(dy);
        match self {
            Surface::Flat | Surface::Heightmap { .. } => {}
            Surface::Stripes {
                width,
                pitch,
                angle_deg,
                offset,
                ..
            } => {
                let (s, c) = angle_deg.to_radians().sin_cos();
                let (nx, ny) = (-s, c);
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
                            let k0 = ((d - spread - 0.5 * width) / pitch).ceil() as i64;
                            let k1 = ((d + spread + 0.5 * width) / pitch).floor() as i64;
                            let area: f64 = (k0..=k1)
                                .map(|k| {
                                    let line = offset + k as f64 * pitch;
                                    strip_in_rect(nx, ny, line, *width, &rect)
                                })
                                .sum();
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
                let reach = match island {
                    Island::Circle { diameter } => 0.5 * diameter,
                    Island::Square { side } => side * std::f64::consts::FRAC_1_SQRT_2,
                };
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
                        } else if u.hypot(v) - half_diagonal < reach {
                            let rect = Rect::cell(x, y, dx, dy);
                            let area =
                                lattice_area_in(*island, *lattice, *pitch, *offset, reach, &rect);
                            *cell = (area / rect.area()).min(1.0);
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
            Surface::Flat | Surface::Heightmap { .. } => 0.0,
            Surface::Stripes { width, pitch, .. } => width / pitch,
            Surface::Lattice {
                island,
                pitch,
                lattice,
                ..
            } => {
                let a = match island {
                    Island::Circle { diameter } => std::f64::consts::PI * diameter * diameter / 4.0,
                    Island::Square { side } => side * side,
                };
                let cell = match lattice {
                    LatticeKind::Square => pitch * pitch,
                    LatticeKind::Hexagonal => pitch * pitch * 3f64.sqrt() / 2.0,
                };
                a / cell
            }
        }
    }
}

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

/// Area of the islands of a lattice inside `rect`: every site whose island
/// (circumradius `reach`) can reach the rectangle, summed (islands never
/// overlap, [`Surface::validate`]).
fn lattice_area_in(
    island: Island,
    lattice: LatticeKind,
    pitch: f64,
    offset: [f64; 2],
    reach: f64,
    rect: &Rect,
) -> f64 {
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The terrain a case reads is the surface's heights and cover, to the
    /// bit, for every kind of surface and sampling.
    #[test]
    fn the_terrain_is_the_heights_and_the_cover() {
        let grid = Grid {
            n: 96,
            dx: 1.3e-6,
            dy: 1.3e-6,
        };
        let circle = |sampling, height| Surface::Lattice {
            island: Island::Circle { diameter: 23e-6 },
            pitch: 41e-6,
            height,
            offset: [2e-6, -5e-6],
            lattice: LatticeKind::Hexagonal,
            sampling,
        };
        let stripes = |sampling| Surface::Stripes {
            width: 9e-6,
            pitch: 25e-6,
            height: 0.5e-6,
            angle_deg: 30.0,
            offset: 1e-6,
            sampling,
        };
        let surfaces = [
            Surface::Flat,
            circle(Sampling::Area, 1e-6),
            circle(Sampling::Area, -1e-6),
            circle(Sampling::Centre, 1e-6),
            stripes(Sampling::Area),
            stripes(Sampling::Centre),
        ];
        let mut cut = 0;
        for s in &surfaces {
            let t = s.terrain(&grid);
            assert_eq!(t.heights, s.heights(&grid), "{s:?}");
            assert_eq!(t.cover, s.cover(&grid), "{s:?}");
            cut += usize::from(t.cover.is_some());
        }
        assert_eq!(cut, 3, "the area-sampled patterns have cut cells");
    }

    #[test]
    fn sampled_coverage_matches_the_analytic_density() {
        let grid = Grid {
            n: 400,
            dx: 1.0e-6,
            dy: 1.0e-6,
        };
        let surfaces = [
            Surface::Lattice {
                island: Island::Circle { diameter: 30e-6 },
                pitch: 50e-6,
                height: 1e-6,
                offset: [3e-6, -7e-6],
                lattice: LatticeKind::Square,
                sampling: Sampling::Centre,
            },
            Surface::Lattice {
                island: Island::Square { side: 20e-6 },
                pitch: 40e-6,
                height: -1e-6,
                offset: [0.0, 0.0],
                lattice: LatticeKind::Square,
                sampling: Sampling::Centre,
            },
            Surface::Lattice {
                island: Island::Circle { diameter: 30e-6 },
                pitch: 50e-6,
                height: 1e-6,
                offset: [0.0, 0.0],
                lattice: LatticeKind::Hexagonal,
                sampling: Sampling::Centre,
            },
            Surface::Stripes {
                width: 10e-6,
                pitch: 40e-6,
                height: 1e-6,
                angle_deg: 30.0,
                offset: 0.0,
                sampling: Sampling::Centre,
            },
        ];
        for s in &surfaces {
            s.validate(grid.n).unwrap();
            let h = s.heights(&grid);
            let covered = h.iter().filter(|&&v| v != 0.0).count() as f64 / grid.len() as f64;
            assert!(
                (covered - s.density()).abs() < 0.01,
                "{s:?}: {covered} vs {}",
                s.density()
            );
        }
    }

    /// The exact cover sums to the pattern's density: to round-off over a
    /// whole number of square-lattice periods, within the part-period
    /// border otherwise; the centre sampling of the same grid does not.
    #[test]
    fn area_sampling_covers_exactly_the_patterns_area() {
        let grid = Grid {
            n: 400,
            dx: 1.3e-6,
            dy: 1.3e-6,
        };
        // 400 cells of 1.3 µm = 520 µm: 8 periods of 65 µm.
        let circle = Surface::Lattice {
            island: Island::Circle { diameter: 41e-6 },
            pitch: 65e-6,
            height: 1e-6,
            offset: [3.1e-6, -7.7e-6],
            lattice: LatticeKind::Square,
            sampling: Sampling::Area,
        };
        let dimples = Surface::Lattice {
            island: Island::Square { side: 27.3e-6 },
            pitch: 65e-6,
            height: -1e-6,
            offset: [0.4e-6, 0.0],
            lattice: LatticeKind::Square,
            sampling: Sampling::Area,
        };
        for s in [&circle, &dimples] {
            let f = s.raised_fraction(&grid);
            let mean = f.iter().sum::<f64>() / grid.len() as f64;
            assert!((mean / s.density() - 1.0).abs() < 1e-12, "{s:?}: {mean}");
        }
        let hex = Surface::Lattice {
            island: Island::Circle { diameter: 30e-6 },
            pitch: 50e-6,
            height: 1e-6,
            offset: [0.0, 0.0],
            lattice: LatticeKind::Hexagonal,
            sampling: Sampling::Area,
        };
        let ridges = Surface::Stripes {
            width: 10e-6,
            pitch: 40e-6,
            height: 1e-6,
            angle_deg: 30.0,
            offset: 2.0e-6,
            sampling: Sampling::Area,
        };
        for s in [&hex, &ridges] {
            let f = s.raised_fraction(&grid);
            let mean = f.iter().sum::<f64>() / grid.len() as f64;
            assert!((mean / s.density() - 1.0).abs() < 0.02, "{s:?}: {mean}");
        }
        // Heights and cover agree: a cut cell is raised (islands) or at the
        // base (dimples) and its cover is its upper part's fraction.
        let (h, c) = (circle.heights(&grid), circle.cover(&grid).unwrap());
        let f = circle.raised_fraction(&grid);
        for i in 0..grid.len() {
            if f[i] >= MIN_COVER {
                assert_eq!(h[i], 1e-6);
                assert!(f[i] == 1.0 || c[i] == f[i]);
            } else {
                assert_eq!((h[i], c[i]), (0.0, 1.0));
            }
        }
        let (h, c) = (dimples.heights(&grid), dimples.cover(&grid).unwrap());
        let f = dimples.raised_fraction(&grid);
        for i in 0..grid.len() {
            if 1.0 - f[i] >= MIN_COVER {
                assert_eq!(h[i], 0.0);
                assert!(f[i] == 0.0 || (c[i] - (1.0 - f[i])).abs() < 1e-15);
            } else {
                assert_eq!((h[i], c[i]), (-1e-6, 1.0));
            }
        }
        // Centre sampling has no cut cells.
        let mut centre = circle.clone();
        if let Surface::Lattice { sampling, .. } = &mut centre {
            *sampling = Sampling::Centre;
        }
        assert!(centre.cover(&grid).is_none());
    }

    #[test]
    fn hexagonal_sites_are_one_pitch_apart_in_six_directions() {
        let p = 10.0;
        for k in 0..6 {
            let a = (k as f64 * 60.0).to_radians();
            let (u, v) = nearest_centre_offset(
                LatticeKind::Hexagonal,
                p,
                p * a.cos() + 0.3,
                p * a.sin() - 0.2,
            );
            assert!(
                (u - 0.3).abs() < 1e-12 && (v + 0.2).abs() < 1e-12,
                "{k}: {u} {v}"
            );
        }
    }

    #[test]
    fn impossible_patterns_are_refused_with_their_field() {
        let bad = [
            (
                Surface::Lattice {
                    island: Island::Square { side: 40e-6 },
                    pitch: 50e-6,
                    height: 1e-6,
                    offset: [0.0, 0.0],
                    lattice: LatticeKind::Hexagonal,
                    sampling: Sampling::Area,
                },
                "side",
            ),
            (
                Surface::Stripes {
                    width: 50e-6,
                    pitch: 40e-6,
                    height: 1e-6,
                    angle_deg: 0.0,
                    offset: 0.0,
                    sampling: Sampling::Area,
                },
                "width",
            ),
            (
                Surface::Heightmap {
                    n: 8,
                    heights: vec![0.0; 64].into(),
                },
                "heights",
            ),
            (
                Surface::Heightmap {
                    n: 16,
                    heights: {
                        let mut v = vec![0.0; 256];
                        v[17] = f64::NAN;
                        v.into()
                    },
                },
                "heights",
            ),
        ];
        for (s, field) in bad {
            match s.validate(16) {
                Err(SolverError::Invalid { field: f, .. }) => assert_eq!(f, field),
                other => panic!("{s:?}: {other:?}"),
            }
        }
    }
}
