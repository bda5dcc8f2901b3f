//! Stresses below the surface: the full stress tensor on a plane at depth
//! `z` (or along a line of it) from the surface tractions `(qx, qy, p)` of a
//! solved state, and the invariants a fatigue or yield check reads.
//! Reads a material and traction fields; solves no contact.
//!
//! Method (docs/physics-choices.md, "Stresses below the surface"): the
//! exact frequency-domain response of the half-space,
//! `σ̂(η, z) = P(θ) exp(−iρz W(θ)) H(θ) t̂(η)`, with `H` the surface
//! compliance of §3, `W = N₁ − i N₂ H⁻¹` the matrix whose eigenvalues are
//! the three decaying Stroh roots (its exponential is the paper's
//! `A⟨e^{−ipρz}⟩A⁻¹`, Eq. 18, written without eigenvectors, so it holds
//! for the degenerate isotropic roots too) and `P = −i(C·n + C·m W)` the
//! displacement gradient turned into stress through the stiffness. The
//! cell-mean tractions are piecewise constant: the response is multiplied
//! by the cell's transform and summed over the aliases the grid cannot
//! resolve, and the product applied by FFT on the zero-padded `2n x 2n`
//! grid (DC-FFT's padding). Sampled in frequency, that kernel still carries
//! its periodic images at the padded period; they are estimated on a coarse
//! grid and subtracted there in real space (`StressPlan::images`), so the
//! convolution is the non-periodic one of DC-FFT. Per direction the
//! response is tabulated in Putzer's form (`Node`), so a depth costs an
//! exponential per root, not a matrix exponential (issue #51); a slice's
//! rows are summed into their lines without planes ([`StressPlan::slice`]);
//! within 5 cells of the surface the aliases live in a short real-space
//! near field summed on a coarse grid of frequencies
//! ([`StressPlan::near_field`]), not at every frequency of the padded grid.
//!
//! Files by job: `response` (the half-space's response per wave vector),
//! `plan` (a material on a grid: the kernel of a depth plane, a state's
//! traction spectra), `near` (a shallow plane's near field), `images` (the
//! padded grid's periodic images, subtracted), `apply` (planes, lines and
//! slices applied to states), `tensor` (principal stresses, von Mises,
//! Tresca, peaks), `fatigue` (Crossland and Smith–Watson–Topper of one
//! point's states); this file the fields they share.

use nalgebra::{Matrix3, SMatrix};
use num_complex::Complex64;

use crate::base::grid::Grid;
use crate::error::SolverError;

mod apply;
mod fatigue;
mod images;
mod near;
mod plan;
mod response;
mod tensor;
#[cfg(test)]
mod tests;

pub use apply::{slice_state_bytes, SLICE_BATCH_BYTES};
pub use fatigue::{crossland_at, swt_point, SwtPoint, SWT_DIRECTIONS};
pub use plan::{StressPlan, StressPlane, TractionSpectra};
pub use response::STROH_DIRECTIONS;
pub use tensor::{max_principal, peak, principal, tensor, tresca, tresca_of, von_mises, Peak};

type C = Complex64;
type M3 = Matrix3<C>;
type M63 = SMatrix<C, 6, 3>;

/// The stress components in their stored order (engineering Voigt order,
/// the solver's): `σxx, σyy, σzz, σyz, σxz, σxy`.
pub const COMPONENTS: [&str; 6] = ["sxx", "syy", "szz", "syz", "sxz", "sxy"];

/// The six stress components on the `n x n` cell centres of a plane (row
/// major `[iy][ix]`, Pa), or along a line of it.
#[derive(Clone, Debug, PartialEq)]
pub struct StressField {
    /// Depth, m.
    pub depth_m: f64,
    /// `σxx, σyy, σzz, σyz, σxz, σxy` ([`COMPONENTS`]), Pa.
    pub components: [Vec<f64>; 6],
}

impl StressField {
    /// The stress tensor at point `i` (Voigt order).
    pub fn at(&self, i: usize) -> [f64; 6] {
        std::array::from_fn(|c| self.components[c][i])
    }
    /// Number of points.
    pub fn len(&self) -> usize {
        self.components[0].len()
    }
    /// True when empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// `f` of the tensor at every point.
    pub fn map(&self, f: impl Fn([f64; 6]) -> f64) -> Vec<f64> {
        (0..self.len()).map(|i| f(self.at(i))).collect()
    }
}

/// Which line of a depth plane: the row through `iy` (an x–z slice when
/// stacked over depths) or the column through `ix` (a y–z slice).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Line {
    /// Along x at row `iy`.
    Row(usize),
    /// Along y at column `ix`.
    Column(usize),
}

/// The deepest plane or row computed, in padded periods `2 n Δ` of the
/// grid (the larger side): far below any part a contact stresses (10⁶
/// domains of a millimetre are a kilometre), and within the lattices
/// whose images are subtracted (`images`).
pub const MAX_DEPTH_PERIODS: f64 = 1e6;

/// A depth below the surface of a plan on `grid`: finite, ≥ 0 and within
/// [`MAX_DEPTH_PERIODS`].
fn check_depth(depth_m: f64, grid: &Grid) -> Result<(), SolverError> {
    if !depth_m.is_finite() || depth_m < 0.0 {
        return Err(SolverError::invalid(
            "depth",
            format!("a depth below the surface must be finite and ≥ 0, got {depth_m} m"),
        ));
    }
    let deepest = max_depth_m(grid);
    if depth_m > deepest {
        return Err(SolverError::invalid(
            "depth",
            format!("a depth below the surface must be at most {deepest} m ({MAX_DEPTH_PERIODS} padded periods of the grid), got {depth_m} m"),
        ));
    }
    Ok(())
}

/// The deepest plane or row computed on `grid`, m ([`MAX_DEPTH_PERIODS`]).
pub fn max_depth_m(grid: &Grid) -> f64 {
    MAX_DEPTH_PERIODS * 2.0 * grid.n as f64 * grid.dx.max(grid.dy)
}

/// `sin(u)/u`.
fn sinc(u: f64) -> f64 {
    if u.abs() < 1e-8 {
        1.0 - u * u / 6.0
    } else {
        u.sin() / u
    }
}

/// Frequency index `k` of a length-`m` transform as a signed wave number
/// (`k − m` above `m/2`).
fn signed_frequency(k: usize, m: usize) -> f64 {
    if k > m / 2 {
        k as f64 - m as f64
    } else {
        k as f64
    }
}
