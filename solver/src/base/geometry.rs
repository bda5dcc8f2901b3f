//! Planar geometry of cell sets: convex-hull area of a set of grid cells,
//! either as whole squares or with its boundary located between cell centres
//! (used for the apparent contact and stick radii). No physics.

use crate::base::grid::Grid;

/// Area (m²) of the convex hull of the union of the cell squares in `mask`
/// (row-major `[iy][ix]`). Zero for an empty mask.
pub fn hull_area(grid: &Grid, mask: &[bool]) -> f64 {
    let n = grid.n;
    let mut pts: Vec<(f64, f64)> = Vec::new();
    // Only the outermost cells of each row can contribute hull corners.
    for iy in 0..n {
        let row = &mask[iy * n..(iy + 1) * n];
        let first = row.iter().position(|&b| b);
        let last = row.iter().rposition(|&b| b);
        if let (Some(f), Some(l)) = (first, last) {
            let (y0, y1) = (grid.y(iy) - 0.5 * grid.dy, grid.y(iy) + 0.5 * grid.dy);
            let (x0, x1) = (grid.x(f) - 0.5 * grid.dx, grid.x(l) + 0.5 * grid.dx);
            pts.extend_from_slice(&[(x0, y0), (x0, y1), (x1, y0), (x1, y1)]);
        }
    }
    polygon_area(&convex_hull(pts))
}

/// Radius (m) of the zone `mask` from the second moment of the weight
/// `level` over it: `sqrt(5/2 · Σ w r² / Σ w)`, `r` measured from the
/// weight's own centroid (cells outside the mask, or of level ≤ 0, weigh
/// nothing). A Hertz-shaped
/// weight `√(1 − r²/a²)` on a disc of radius `a` has `⟨r²⟩ = 2a²/5`, so the
/// radius is exactly `a` in the continuum (the pressure of a Hertz contact;
/// μp − |q| on a Cattaneo–Mindlin stick zone, a Hertz shape on `c`). Unlike
/// a hull, it is continuous in the weight: a cell or a far island that joins
/// the zone with a small weight moves it by that weight's share. Zero for a
/// zero weight.
pub fn moment_radius(grid: &Grid, mask: &[bool], level: &[f64]) -> f64 {
    let weight = |i: usize| if mask[i] { level[i] } else { 0.0 };
    let Some((w, cx, cy)) = centroid(grid, &weight) else {
        return 0.0;
    };
    let mut wr2 = 0.0;
    about(grid, &weight, (cx, cy), |v, dx, dy| {
        wr2 += v * (dx * dx + dy * dy)
    });
    (2.5 * wr2 / w).sqrt()
}

/// Calls `f(w, dx, dy)` for every cell of positive weight `w = weight(i)`,
/// `(dx, dy)` its centre's offset from `(cx, cy)`, row by row in a fixed
/// order (the sums it makes do not depend on threads).
fn about(
    grid: &Grid,
    weight: &dyn Fn(usize) -> f64,
    (cx, cy): (f64, f64),
    mut f: impl FnMut(f64, f64, f64),
) {
    let n = grid.n;
    for iy in 0..n {
        let dy = grid.y(iy) - cy;
        for ix in 0..n {
            let v = weight(iy * n + ix);
            if v > 0.0 {
                f(v, grid.x(ix) - cx, dy);
            }
        }
    }
}

/// The total of the positive weights `weight(i)` over the grid's cells and
/// their centroid `(Σw, x̄, ȳ)`; `None` for a zero total. Sums row by row
/// in a fixed order (results do not depend on threads).
fn centroid(grid: &Grid, weight: &dyn Fn(usize) -> f64) -> Option<(f64, f64, f64)> {
    let n = grid.n;
    let (mut w, mut wx, mut wy) = (0.0, 0.0, 0.0);
    for iy in 0..n {
        let y = grid.y(iy);
        for ix in 0..n {
            let v = weight(iy * n + ix);
            if v > 0.0 {
                w += v;
                wx += v * grid.x(ix);
                wy += v * y;
            }
        }
    }
    (w > 0.0).then(|| (w, wx / w, wy / w))
}

/// The spread of a weight over a zone about its own centroid: the
/// weighted means of `(x − x̄)²`, `(x − x̄)(y − ȳ)`, `(y − ȳ)²` (the second
/// moment tensor) and of `r⁴ = ((x − x̄)² + (y − ȳ)²)²`, m² and m⁴.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RadialMoments {
    /// `⟨(x − x̄)²⟩`, `⟨(x − x̄)(y − ȳ)⟩`, `⟨(y − ȳ)²⟩`, m².
    pub second: [f64; 3],
    /// `⟨r⁴⟩`, m⁴.
    pub fourth: f64,
}

/// [`RadialMoments`] of the weight `level` over the zone `mask` (cells
/// outside it, or of level ≤ 0, weigh nothing); `None` for a zero weight.
pub fn radial_moments(grid: &Grid, mask: &[bool], level: &[f64]) -> Option<RadialMoments> {
    let weight = |i: usize| if mask[i] { level[i] } else { 0.0 };
    let (w, cx, cy) = centroid(grid, &weight)?;
    let (mut xx, mut xy, mut yy, mut r4) = (0.0, 0.0, 0.0, 0.0);
    about(grid, &weight, (cx, cy), |v, dx, dy| {
        let r2 = dx * dx + dy * dy;
        xx += v * dx * dx;
        xy += v * dx * dy;
        yy += v * dy * dy;
        r4 += v * r2 * r2;
    });
    Some(RadialMoments {
        second: [xx / w, xy / w, yy / w],
        fourth: r4 / w,
    })
}

/// Area (m²) of the convex hull of the boundary of `mask` located to
/// sub-cell precision with the level field `level` (≥ 0 in the mask, falling
/// to zero at the boundary like the square root of the distance to it, as the
/// pressure at a Hertzian edge and μp − |q| at a Mindlin stick edge do).
///
/// Along every row and every column, the outermost cell at each end and its
/// inner neighbour give `level²`, which is linear in the distance near such
/// an edge; its zero, extrapolated outward, is a boundary point. The point is
/// kept between the outermost cell's centre and the next (outside) centre,
/// and within the terrain's own edge where it falls away beyond the cell
/// (`heights` lower in the outside cell: an island's edge, which the contact
/// cannot pass): the cell's outer face, or with a `cover` (the fraction of
/// each cell on its upper part, [`crate::Surface::cover`]) the edge of that
/// part, `cover − 1/2` of a pitch beyond the centre. Where the level does not
/// fall outward (the pressure rising towards an island's edge, or a run one
/// cell long) the point is that edge, or the cell's outer face on level
/// ground, as in [`hull_area`]. The hull of the row and column points is the
/// area; unlike [`hull_area`], whose radius jumps by up to a cell as cells
/// join, it moves continuously with the solution.
pub fn subcell_hull_area(
    grid: &Grid,
    mask: &[bool],
    level: &[f64],
    heights: &[f64],
    cover: Option<&[f64]>,
) -> f64 {
    let n = grid.n;
    // Fraction of a cell pitch beyond the edge cell's centre where the
    // boundary lies, from the edge value and its inner neighbour's.
    let reach = |edge: usize, inner: Option<usize>, outer: Option<usize>| -> f64 {
        let g0 = level[edge] * level[edge];
        let terrain = match outer {
            Some(o) if heights[o] < heights[edge] => Some(cover.map_or(0.5, |c| c[edge] - 0.5)),
            _ => None,
        };
        match inner {
            Some(i) if mask[i] && level[i] * level[i] > g0 => {
                let g1 = level[i] * level[i];
                (g0 / (g1 - g0)).min(terrain.unwrap_or(1.0))
            }
            _ => terrain.unwrap_or(0.5),
        }
    };
    // The first and last cell of the zone on one grid line (cell k of the
    // line is `at(k)`), each with how far beyond its centre the boundary lies.
    let line_ends = |at: &dyn Fn(usize) -> usize| -> Option<[(usize, f64); 2]> {
        let f = (0..n).position(|k| mask[at(k)])?;
        let l = (0..n).rposition(|k| mask[at(k)])?;
        let step = |k: usize, d: isize| k.checked_add_signed(d).filter(|&j| j < n).map(at);
        Some([
            (f, reach(at(f), step(f, 1), step(f, -1))),
            (l, reach(at(l), step(l, -1), step(l, 1))),
        ])
    };
    let mut pts: Vec<(f64, f64)> = Vec::new();
    for iy in 0..n {
        if let Some([(f, low), (l, high)]) = line_ends(&|k| iy * n + k) {
            pts.push((grid.x(f) - low * grid.dx, grid.y(iy)));
            pts.push((grid.x(l) + high * grid.dx, grid.y(iy)));
        }
    }
    for ix in 0..n {
        if let Some([(f, low), (l, high)]) = line_ends(&|k| k * n + ix) {
            pts.push((grid.x(ix), grid.y(f) - low * grid.dy));
            pts.push((grid.x(ix), grid.y(l) + high * grid.dy));
        }
    }
    polygon_area(&convex_hull(pts))
}

/// Area (m²) of the cells in `mask`, each `da` times its `cover` (the
/// fraction on its upper part, [`crate::Surface::cover`]) when there is one.
pub fn covered_area(mask: &[bool], cover: Option<&[f64]>, da: f64) -> f64 {
    match cover {
        None => mask.iter().filter(|&&b| b).count() as f64 * da,
        Some(c) => {
            let sum: f64 = mask
                .iter()
                .zip(c)
                .filter(|(&m, _)| m)
                .map(|(_, &c)| c)
                .sum();
            sum * da
        }
    }
}

/// Radius of the circle with the given area.
pub fn equivalent_radius(area: f64) -> f64 {
    (area / std::f64::consts::PI).sqrt()
}

/// Andrew's monotone chain; returns the hull counter-clockwise.
fn convex_hull(mut pts: Vec<(f64, f64)>) -> Vec<(f64, f64)> {
    pts.sort_by(|a, b| a.partial_cmp(b).unwrap_or(std::cmp::Ordering::Equal));
    pts.dedup();
    if pts.len() < 3 {
        return pts;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64)> = Vec::with_capacity(2 * pts.len());
    for &p in &pts {
        while hull.len() >= 2 && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
            hull.pop();
        }
        hull.push(p);
    }
    let lower = hull.len() + 1;
    for &p in pts.iter().rev().skip(1) {
        while hull.len() >= lower && cross(hull[hull.len() - 2], hull[hull.len() - 1], p) <= 0.0 {
            hull.pop();
        }
        hull.push(p);
    }
    hull.pop();
    hull
}

fn polygon_area(poly: &[(f64, f64)]) -> f64 {
    if poly.len() < 3 {
        return 0.0;
    }
    let mut s = 0.0;
    for i in 0..poly.len() {
        let (a, b) = (poly[i], poly[(i + 1) % poly.len()]);
        s += a.0 * b.1 - b.0 * a.1;
    }
    0.5 * s.abs()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The second-moment radius of a sampled Hertz weight, off the grid's
    /// centre, against its radius: within `0.05 (h/r)^1.5` at 10 to 80
    /// cells per radius (the edge's square root makes the midpoint rule's
    /// error about h^1.5; the circle's sampling makes it non-monotone, 1.5e-4,
    /// 3.7e-4, 5.5e-5, 1.6e-6 relative).
    #[test]
    fn moment_radius_of_a_sampled_hertz_weight_converges_to_its_radius() {
        let mut errs = Vec::new();
        for n in [50usize, 100, 200, 400] {
            let h = 200.0 / n as f64;
            let grid = Grid { n, dx: h, dy: h };
            let (r0, cx, cy) = (40.0, 13.3, -7.1);
            let w: Vec<f64> = (0..grid.len())
                .map(|i| {
                    let r = (grid.x(i % n) - cx).hypot(grid.y(i / n) - cy);
                    (1.0 - (r / r0).powi(2)).max(0.0).sqrt()
                })
                .collect();
            let mask: Vec<bool> = w.iter().map(|&v| v > 0.0).collect();
            let err = (moment_radius(&grid, &mask, &w) / r0 - 1.0).abs();
            assert!(err < 0.05 * (h / r0).powf(1.5), "{n}: {err}");
            errs.push(err);
        }
        assert!(errs[3] < 1e-5, "{errs:?}");
    }

    /// A far cell with a small weight moves the moment radius by about its
    /// share of the weight (continuous), where it moves the hull's radius
    /// by a finite step whatever its weight.
    #[test]
    fn moment_radius_moves_by_a_far_cells_share_where_the_hull_jumps() {
        let n = 200;
        let grid = Grid {
            n,
            dx: 1.0,
            dy: 1.0,
        };
        let disc: Vec<f64> = (0..grid.len())
            .map(|i| {
                (1.0 - grid.x(i % n).hypot(grid.y(i / n)).powi(2) / 1600.0)
                    .max(0.0)
                    .sqrt()
            })
            .collect();
        let total: f64 = disc.iter().sum();
        let far = 95 * n + 190; // about 90 cells out along x
        let radius = |eps: f64| {
            let mut w = disc.clone();
            w[far] = eps * total;
            let mask: Vec<bool> = w.iter().map(|&v| v > 0.0).collect();
            (
                moment_radius(&grid, &mask, &w),
                equivalent_radius(hull_area(&grid, &mask)),
            )
        };
        let (m0, h0) = radius(0.0);
        let (m1, h1) = radius(1e-6);
        assert!((m1 - m0).abs() < 1e-3 * m0, "{m0} {m1}");
        assert!(h1 - h0 > 0.1 * h0, "{h0} {h1}");
    }

    #[test]
    fn hull_of_an_l_shape_is_its_bounding_pentagon() {
        // Cells (0,0), (1,0), (0,1) of unit size: hull = unit square 2x2 minus a corner triangle.
        let grid = Grid {
            n: 4,
            dx: 1.0,
            dy: 1.0,
        };
        let mut mask = vec![false; 16];
        mask[0] = true;
        mask[1] = true;
        mask[4] = true;
        assert!((hull_area(&grid, &mask) - 3.5).abs() < 1e-12);
    }

    #[test]
    fn hull_radius_of_a_sampled_disc_is_within_one_cell() {
        let grid = Grid {
            n: 200,
            dx: 1.0,
            dy: 1.0,
        };
        let r = 60.0;
        let mask: Vec<bool> = (0..grid.len())
            .map(|i| grid.x(i % 200).hypot(grid.y(i / 200)) <= r)
            .collect();
        let re = equivalent_radius(hull_area(&grid, &mask));
        assert!(re > r - 0.5 && re < r + 1.0, "{re}");
    }

    /// A Hertzian level sqrt(a² − r²) sampled at cell centres: the boundary
    /// radius converges at second order in the cell size, the whole-cell hull
    /// at first order with jumps.
    #[test]
    fn subcell_radius_of_a_sampled_hertz_level_converges_at_second_order() {
        let a = 1.0;
        let errs: Vec<(f64, f64)> = [24usize, 48, 96]
            .iter()
            .map(|&cells_per_radius| {
                let n = 4 * cells_per_radius;
                let h = a / cells_per_radius as f64;
                let grid = Grid { n, dx: h, dy: h };
                // Off-centre by a third of a cell so no row is symmetric.
                let r = |i: usize| (grid.x(i % n) - h / 3.0).hypot(grid.y(i / n) - h / 7.0);
                let level: Vec<f64> = (0..grid.len())
                    .map(|i| (a * a - r(i).powi(2)).max(0.0).sqrt())
                    .collect();
                let mask: Vec<bool> = level.iter().map(|&v| v > 0.0).collect();
                let flat = vec![0.0; grid.len()];
                let sub = equivalent_radius(subcell_hull_area(&grid, &mask, &level, &flat, None));
                let cells = equivalent_radius(hull_area(&grid, &mask));
                ((sub / a - 1.0).abs(), (cells / a - 1.0).abs())
            })
            .collect();
        println!("{errs:?}");
        for w in errs.windows(2) {
            let order = (w[0].0 / w[1].0).log2();
            assert!(order > 1.5, "order {order} from {errs:?}");
        }
        assert!(errs[2].0 < 1e-4 && errs[2].0 < errs[2].1 / 10.0, "{errs:?}");
    }
}
