//! A prepared scan put on a case's grid: each cell's height from the
//! pixels under it (their area-weighted mean when the cell is larger than a
//! pixel, linear interpolation between pixel centres when it is smaller),
//! with the ball's apex over a chosen point of the scan. The grid and the
//! scan are independent, so every level of a refinement ladder resamples
//! the same scan. Touches no file and no solver state.

use crate::base::grid::Grid;
use crate::error::SolverError;
use crate::model::scan::Scan;
use crate::model::surface::MIN_COVER;

/// Relative slack on the scan's edges: a grid that spans the scan exactly
/// (n cells of the scan's extent / n) must not be refused for round-off.
const EDGE_SLACK: f64 = 1e-9;

/// One cell's weights along one axis: pixels `first..first + w.len()`.
struct Weights {
    first: usize,
    w: Vec<f64>,
}

/// The weights of `n` cells of width `cell` centred at `centre(k)` on
/// `pixels` pixels of width `pixel` (pixel i spans `[i, i + 1] · pixel`).
/// Cells at least a pixel wide take the pixels' overlaps with the cell
/// (each pixel a constant over its footprint); narrower cells interpolate
/// linearly between the two pixel centres around their own centre (the
/// outermost half pixels hold their pixel's value).
fn weights(
    n: usize,
    cell: f64,
    centre: impl Fn(usize) -> f64,
    pixels: usize,
    pixel: f64,
) -> Vec<Weights> {
    (0..n)
        .map(|k| {
            let c = centre(k);
            if cell >= pixel {
                let (a, b) = (c - 0.5 * cell, c + 0.5 * cell);
                let first = ((a / pixel).floor().max(0.0) as usize).min(pixels - 1);
                let last = (((b / pixel).ceil() as usize).max(first + 1)).min(pixels);
                let w = (first..last)
                    .map(|i| {
                        let (p0, p1) = (i as f64 * pixel, (i + 1) as f64 * pixel);
                        (b.min(p1) - a.max(p0)).max(0.0) / cell
                    })
                    .collect();
                Weights { first, w }
            } else {
                let u = c / pixel - 0.5;
                if u <= 0.0 {
                    Weights {
                        first: 0,
                        w: vec![1.0],
                    }
                } else if u >= (pixels - 1) as f64 {
                    Weights {
                        first: pixels - 1,
                        w: vec![1.0],
                    }
                } else {
                    let i = u.floor();
                    let t = u - i;
                    Weights {
                        first: i as usize,
                        w: vec![1.0 - t, t],
                    }
                }
            }
        })
        .collect()
}

/// The pixels each cell of a grid reads, along x and y, and the rows of
/// the scan any cell reads: built once, applied to the scan's heights and
/// to fields derived from them.
struct Resampler {
    n: usize,
    nx: usize,
    along_x: Vec<Weights>,
    along_y: Vec<Weights>,
    rows: std::ops::Range<usize>,
}

impl Resampler {
    fn new(scan: &Scan, apex: [f64; 2], grid: &Grid) -> Result<Self, SolverError> {
        let (ex, ey) = scan.extent();
        let (wx, wy) = (grid.n as f64 * grid.dx, grid.n as f64 * grid.dy);
        let fits = |centre: f64, width: f64, extent: f64| {
            let slack = EDGE_SLACK * extent;
            centre - 0.5 * width >= -slack && centre + 0.5 * width <= extent + slack
        };
        if !(apex[0].is_finite() && apex[1].is_finite()) {
            return Err(SolverError::invalid(
                "apex",
                "the apex position must be finite",
            ));
        }
        if !(fits(apex[0], wx, ex) && fits(apex[1], wy, ey)) {
            return Err(SolverError::invalid(
                "scan",
                format!(
                    "the scan is {:.4} x {:.4} µm but the grid spans {:.4} x {:.4} µm around the apex at ({:.4}, {:.4}) µm of the scan, reaching [{:.4}, {:.4}] x [{:.4}, {:.4}] µm: give a smaller grid (grid.points x grid.spacing_um), move the apex (apex_um), or measure a larger area",
                    ex * 1e6,
                    ey * 1e6,
                    wx * 1e6,
                    wy * 1e6,
                    apex[0] * 1e6,
                    apex[1] * 1e6,
                    (apex[0] - 0.5 * wx) * 1e6,
                    (apex[0] + 0.5 * wx) * 1e6,
                    (apex[1] - 0.5 * wy) * 1e6,
                    (apex[1] + 0.5 * wy) * 1e6,
                ),
            ));
        }
        let n = grid.n;
        let along_x = weights(n, grid.dx, |k| apex[0] + grid.x(k), scan.nx, scan.dx);
        let along_y = weights(n, grid.dy, |k| apex[1] + grid.y(k), scan.ny, scan.dy);
        let row0 = along_y.iter().map(|w| w.first).min().unwrap_or(0);
        let row1 = along_y
            .iter()
            .map(|w| w.first + w.w.len())
            .max()
            .unwrap_or(0);
        Ok(Resampler {
            n,
            nx: scan.nx,
            along_x,
            along_y,
            rows: row0..row1,
        })
    }

    /// `values` (one per pixel, row-major) on the grid's cells: the pixel
    /// rows any cell reads resampled along x once each, then along y.
    fn apply(&self, values: &[f64]) -> Vec<f64> {
        let (n, nx, row0) = (self.n, self.nx, self.rows.start);
        let mut rows = vec![0.0; self.rows.len() * n];
        for (r, out) in rows.chunks_exact_mut(n).enumerate() {
            let line = &values[(row0 + r) * nx..(row0 + r + 1) * nx];
            for (v, wx) in out.iter_mut().zip(&self.along_x) {
                *v = wx.w.iter().zip(&line[wx.first..]).map(|(w, h)| w * h).sum();
            }
        }
        let mut h = vec![0.0; n * n];
        for (ky, wy) in self.along_y.iter().enumerate() {
            let out = &mut h[ky * n..(ky + 1) * n];
            for (j, w) in wy.w.iter().enumerate() {
                let r = wy.first + j - row0;
                for (v, x) in out.iter_mut().zip(&rows[r * n..(r + 1) * n]) {
                    *v += w * x;
                }
            }
        }
        h
    }
}

/// The heights of `grid`'s cells (row-major, m) from `scan`, the ball's
/// apex (the grid's centre) over the scan's point `apex` (m from the
/// outer corner of its first pixel). Refused, with both extents, when the
/// grid reaches past the scan; a missing point left in the scan makes its
/// cells NaN (prepare the scan first, [`Scan::prepared`]).
pub fn resample(scan: &Scan, apex: [f64; 2], grid: &Grid) -> Result<Vec<f64>, SolverError> {
    Ok(Resampler::new(scan, apex, grid)?.apply(&scan.heights))
}

/// A two-level scan (a texture: islands, dimples, grooves) on `grid` as
/// an area-sampled pattern is ([`crate::model::surface::Sampling::Area`]):
/// the pixels at or above the scan's mean height are its upper level;
/// a cell carries the mean height of its upper pixels and their share of
/// the cell as its cover, or — with under [`MIN_COVER`] of it up there —
/// the mean of its lower pixels, whole. The heights and the cover (`None`
/// when no cell is cut, or when cells are finer than the pixels, which
/// are then interpolated as by [`resample`]). For a scan of a pattern at
/// m x m pixels a cell, the cover is the pattern's to within 1/m².
pub fn resample_two_level(
    scan: &Scan,
    apex: [f64; 2],
    grid: &Grid,
) -> Result<(Vec<f64>, Option<Vec<f64>>), SolverError> {
    let r = Resampler::new(scan, apex, grid)?;
    let all = r.apply(&scan.heights);
    if grid.dx < scan.dx || grid.dy < scan.dy {
        return Ok((all, None));
    }
    let mean = scan.heights.iter().sum::<f64>() / scan.heights.len() as f64;
    let upper: Vec<f64> = scan
        .heights
        .iter()
        .map(|&h| if h >= mean { 1.0 } else { 0.0 })
        .collect();
    let upper_heights: Vec<f64> = scan
        .heights
        .iter()
        .zip(&upper)
        .map(|(h, u)| h * u)
        .collect();
    let share = r.apply(&upper);
    let upper_sum = r.apply(&upper_heights);
    let mut cut = false;
    let mut cover = vec![1.0; all.len()];
    let heights = (0..all.len())
        .map(|i| {
            // Round-off of the weights' sums must not cut a whole cell.
            let f = share[i];
            if f >= 1.0 - 1e-12 {
                upper_sum[i] / f
            } else if f >= MIN_COVER {
                cut = true;
                cover[i] = f;
                upper_sum[i] / f
            } else if f > 0.0 {
                (all[i] - upper_sum[i]) / (1.0 - f)
            } else {
                all[i]
            }
        })
        .collect();
    Ok((heights, cut.then_some(cover)))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scan(nx: usize, ny: usize, d: f64, f: impl Fn(f64, f64) -> f64) -> Scan {
        let h = (0..nx * ny)
            .map(|i| f((i % nx) as f64 * d + 0.5 * d, (i / nx) as f64 * d + 0.5 * d))
            .collect();
        Scan::new(nx, ny, d, d, h).unwrap()
    }

    /// Cells 4 pixels wide, aligned with the pixels, are the mean of their
    /// 16 pixels; a linear field is interpolated exactly on cells a third
    /// of a pixel wide; a constant stays itself at any ratio.
    #[test]
    fn cells_average_their_pixels_and_interpolate_between_them() {
        let s = scan(64, 48, 1e-6, |x, y| (x * 7e5).sin() + (y * 3e5).cos());
        let grid = Grid::square(12, 4e-6);
        let apex = [32e-6, 24e-6];
        let h = resample(&s, apex, &grid).unwrap();
        // Cell (0, 0) spans pixels 8..12 along x, 0..4 along y.
        for (ky, kx) in [(0, 0), (5, 7), (11, 11)] {
            let (x0, y0) = (8 + 4 * kx, 4 * ky);
            let mean: f64 = (y0..y0 + 4)
                .flat_map(|iy| (x0..x0 + 4).map(move |ix| (iy, ix)))
                .map(|(iy, ix)| s.heights[iy * 64 + ix])
                .sum::<f64>()
                / 16.0;
            let got = h[ky * 12 + kx];
            assert!((got - mean).abs() < 1e-14, "{got} vs {mean}");
        }
        let linear = scan(20, 20, 3e-6, |x, y| 2.0 * x - 0.5 * y + 1e-6);
        let grid = Grid::square(90, 0.5e-6);
        let h = resample(&linear, [30e-6, 30e-6], &grid).unwrap();
        let worst = (0..90 * 90)
            .map(|i| {
                let (x, y) = (30e-6 + grid.x(i % 90), 30e-6 + grid.y(i / 90));
                (h[i] - (2.0 * x - 0.5 * y + 1e-6)).abs()
            })
            .fold(0.0f64, f64::max);
        assert!(worst < 1e-18, "{worst:e}");
        let flat = scan(30, 17, 1e-6, |_, _| 2.5e-6);
        for cell in [0.3e-6, 1e-6, 1.7e-6, 3e-6] {
            let grid = Grid::square(5, cell);
            let h = resample(&flat, [15e-6, 8.5e-6], &grid).unwrap();
            assert!(h.iter().all(|v| (v - 2.5e-6).abs() < 1e-20), "{cell}");
        }
    }

    /// A two-level scan of a half-plane edge at 4 x 4 pixels a cell: the
    /// cut cells carry the upper level with their share of upper pixels
    /// as cover (k/16), whole cells either level, as area sampling does.
    #[test]
    fn a_two_level_scan_keeps_its_levels_and_the_cut_cells_cover() {
        // Edge at x = 13 pixels (a quarter into cell 3): upper to its left.
        let s = scan(64, 64, 1e-6, |x, _| if x < 13e-6 { 30e-6 } else { 0.0 });
        let grid = Grid::square(16, 4e-6);
        let (h, cover) = resample_two_level(&s, [32e-6, 32e-6], &grid).unwrap();
        let cover = cover.unwrap();
        let near = |a: f64, b: f64| (a - b).abs() <= 1e-12 * b.abs().max(1e-6);
        for ky in 0..16 {
            let row = ky * 16;
            assert!(near(h[row], 30e-6) && cover[row] == 1.0);
            assert!(near(h[row + 3], 30e-6) && near(cover[row + 3], 0.25));
            assert!(h[row + 4].abs() < 1e-18 && cover[row + 4] == 1.0);
        }
        // The mean of the same cells smears the level instead.
        let mean = resample(&s, [32e-6, 32e-6], &grid).unwrap();
        assert!((mean[3] - 7.5e-6).abs() < 1e-18, "{}", mean[3]);
    }

    /// A grid that reaches past the scan is refused with both extents.
    #[test]
    fn a_scan_smaller_than_the_grid_is_refused_with_both_extents() {
        let s = scan(100, 50, 1e-6, |_, _| 0.0);
        let e = resample(&s, [50e-6, 25e-6], &Grid::square(64, 1e-6))
            .unwrap_err()
            .to_string();
        println!("{e}");
        assert!(
            e.contains("the scan is 100.0000 x 50.0000 µm but the grid spans 64.0000 x 64.0000 µm"),
            "{e}"
        );
        // The same grid fits a scan that holds it exactly.
        let s = scan(64, 64, 1e-6, |_, _| 0.0);
        resample(&s, [32e-6, 32e-6], &Grid::square(64, 1e-6)).unwrap();
        let e = resample(&s, [31e-6, 32e-6], &Grid::square(64, 1e-6)).unwrap_err();
        assert!(e.to_string().contains("apex_um"), "{e}");
    }
}
