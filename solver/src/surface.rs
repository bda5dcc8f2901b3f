//! Surface topography of the substrate: flat, raised islands (or dimples) on a
//! square or hexagonal lattice, parallel stripes, or an arbitrary height map on
//! the solver grid. Produces the height field on the grid; the indenter profile
//! and the initial separation `h0` are assembled in `case`.

use crate::error::SolverError;
use crate::grid::Grid;
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

    /// Height of the surface above its base at each cell centre (m), row-major.
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
        }
        h
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

#[cfg(test)]
mod tests {
    use super::*;

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
            },
            Surface::Lattice {
                island: Island::Square { side: 20e-6 },
                pitch: 40e-6,
                height: -1e-6,
                offset: [0.0, 0.0],
                lattice: LatticeKind::Square,
            },
            Surface::Lattice {
                island: Island::Circle { diameter: 30e-6 },
                pitch: 50e-6,
                height: 1e-6,
                offset: [0.0, 0.0],
                lattice: LatticeKind::Hexagonal,
            },
            Surface::Stripes {
                width: 10e-6,
                pitch: 40e-6,
                height: 1e-6,
                angle_deg: 30.0,
                offset: 0.0,
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
