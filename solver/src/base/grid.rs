//! The square computational grid: `n x n` cells centred on the origin.
//! Geometry of cells only; no fields, no physics.

/// Square computational grid: `n x n` cells of `dx x dy`, centred on the origin.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Grid {
    /// Cells per side.
    pub n: usize,
    /// Cell size along x, m.
    pub dx: f64,
    /// Cell size along y, m.
    pub dy: f64,
}

impl Grid {
    /// `n x n` square cells of side `spacing_m`.
    pub fn square(n: usize, spacing_m: f64) -> Self {
        Grid {
            n,
            dx: spacing_m,
            dy: spacing_m,
        }
    }
    /// Cell area, m².
    pub fn cell_area(&self) -> f64 {
        self.dx * self.dy
    }
    /// x coordinate of the centre of column `ix` (origin at the grid centre).
    pub fn x(&self, ix: usize) -> f64 {
        (ix as f64 - 0.5 * (self.n as f64 - 1.0)) * self.dx
    }
    /// y coordinate of the centre of row `iy`.
    pub fn y(&self, iy: usize) -> f64 {
        (iy as f64 - 0.5 * (self.n as f64 - 1.0)) * self.dy
    }
    /// Number of cells.
    pub fn len(&self) -> usize {
        self.n * self.n
    }
    /// True for an empty grid.
    pub fn is_empty(&self) -> bool {
        self.n == 0
    }
}
