//! Planar geometry of cell sets: convex-hull area of a set of grid cells
//! (used for the apparent contact and stick radii). No physics.

use crate::grid::Grid;

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
}
