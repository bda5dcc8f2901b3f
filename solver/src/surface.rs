//! Surface topography of the substrate: flat, or raised islands on a lattice.
//! Produces the height field on the solver grid; the indenter profile and the
//! initial separation `h0` are assembled in `case`.

use crate::error::SolverError;
use crate::operator::Grid;
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

/// A substrate surface.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Surface {
    /// Plane surface.
    Flat,
    /// Square lattice of identical raised islands aligned with x and y.
    Lattice {
        /// Island shape.
        island: Island,
        /// Lattice pitch, m.
        pitch: f64,
        /// Island height above the base, m (negative: dimples).
        height: f64,
        /// Position of one island centre relative to the sphere apex, m.
        offset: [f64; 2],
    },
}

impl Surface {
    /// Checks that the surface is geometrically possible.
    pub fn validate(&self) -> Result<(), SolverError> {
        match self {
            Surface::Flat => Ok(()),
            Surface::Lattice {
                island,
                pitch,
                height,
                offset,
            } => {
                if !(pitch.is_finite() && *pitch > 0.0) {
                    return Err(SolverError::invalid(
                        "pitch_um",
                        format!("the lattice pitch must be positive and finite, got {pitch} m"),
                    ));
                }
                if !height.is_finite() {
                    return Err(SolverError::invalid(
                        "height_um",
                        "the island height must be finite",
                    ));
                }
                if !(offset[0].is_finite() && offset[1].is_finite()) {
                    return Err(SolverError::invalid(
                        "offset_um",
                        "the lattice offset must be finite",
                    ));
                }
                let (name, size) = match island {
                    Island::Circle { diameter } => ("diameter_um", *diameter),
                    Island::Square { side } => ("side_um", *side),
                };
                if !(size.is_finite() && size > 0.0) {
                    return Err(SolverError::invalid(
                        name,
                        format!("the island size must be positive and finite, got {size} m"),
                    ));
                }
                if size >= *pitch {
                    return Err(SolverError::invalid(
                        name,
                        format!(
                            "the island ({size:.3e} m) does not fit in the pitch ({pitch:.3e} m): islands would merge"
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
        if let Surface::Lattice {
            island,
            pitch,
            height,
            offset,
        } = self
        {
            for iy in 0..n {
                for ix in 0..n {
                    // Position relative to the nearest island centre.
                    let rel = |c: f64, o: f64| {
                        let u = c - o;
                        u - pitch * (u / pitch).round()
                    };
                    let (u, v) = (rel(grid.x(ix), offset[0]), rel(grid.y(iy), offset[1]));
                    let inside = match island {
                        Island::Circle { diameter } => u.hypot(v) <= 0.5 * diameter,
                        Island::Square { side } => u.abs() <= 0.5 * side && v.abs() <= 0.5 * side,
                    };
                    if inside {
                        h[iy * n + ix] = *height;
                    }
                }
            }
        }
        h
    }

    /// Area fraction of the lattice cell covered by islands (0 for flat).
    pub fn density(&self) -> f64 {
        match self {
            Surface::Flat => 0.0,
            Surface::Lattice { island, pitch, .. } => {
                let a = match island {
                    Island::Circle { diameter } => std::f64::consts::PI * diameter * diameter / 4.0,
                    Island::Square { side } => side * side,
                };
                a / (pitch * pitch)
            }
        }
    }
}
