//! The DC-FFT elastic operator: kernel spectra of the nine influence components
//! on the `2N x 2N` wrap-around grid, applied to traction fields by zero-padded
//! real FFTs (Liu, Wang & Liu 2000). Knows nothing about contact conditions.
//!
//! Build once per (material, grid) — this is the expensive step — and apply
//! many times; `apply` allocates nothing.

use crate::fft2::Fft2;
use crate::influence::Block;
use crate::multilevel::{coarse_levels, CoarseLevel, FourierPrecond};
use num_complex::Complex64;

/// Displacement / traction component index: x, y (tangential) and z (normal).
pub const X: usize = 0;
/// y component.
pub const Y: usize = 1;
/// z component (normal; pressure for tractions).
pub const Z: usize = 2;

/// Square computational grid: `n x n` cells of `dx x dy`, centred on the origin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Grid {
    /// Cells per side.
    pub n: usize,
    /// Cell size along x, m.
    pub dx: f64,
    /// Cell size along y, m.
    pub dy: f64,
}

impl Grid {
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

/// Kernel spectra and FFT plans for one material on one grid.
pub struct Operator {
    grid: Grid,
    fft: Fft2,
    /// `kernels[i][j]`: half spectrum of K_ij (displacement i per traction j).
    kernels: Vec<Vec<Complex64>>,
    src_spec: Vec<Vec<Complex64>>,
    acc: Vec<Complex64>,
    tangential_bound: f64,
    /// Coarse `K_zz` levels for nested initial guesses (finest first).
    coarse: Vec<CoarseLevel>,
    /// Fourier preconditioner of the normal iteration on this grid.
    precond: FourierPrecond,
}

/// Maximum over frequencies of the largest eigenvalue of the Hermitian part of
/// the 2x2 tangential symbol of the circulant embedding: an upper bound of the
/// tangential block's largest eigenvalue.
fn tangential_symbol_max(kernels: &[Vec<Complex64>]) -> f64 {
    let (kxx, kxy, kyx, kyy) = (&kernels[0], &kernels[1], &kernels[3], &kernels[4]);
    let mut best = 0.0_f64;
    for i in 0..kxx.len() {
        let a = kxx[i].re;
        let d = kyy[i].re;
        let b = 0.5 * (kxy[i] + kyx[i].conj());
        let mean = 0.5 * (a + d);
        let disc = (0.25 * (a - d) * (a - d) + b.norm_sqr()).sqrt();
        best = best.max(mean + disc);
    }
    best
}

impl Operator {
    /// Builds the nine kernel spectra from a cell-influence function
    /// `cell(x, y) -> K(x, y)` (offsets of the observation point from the loaded cell).
    pub fn build(grid: Grid, cell: impl Fn(f64, f64) -> Block) -> Self {
        Self::from_tables(grid, &Self::tables(grid, cell))
    }

    /// The nine real-space kernels on the `2N x 2N` wrap-around grid
    /// (`tables[3 i + j]`, row-major), the expensive part of a build.
    pub fn tables(grid: Grid, cell: impl Fn(f64, f64) -> Block) -> Vec<Vec<f64>> {
        let n = grid.n;
        let m = 2 * n;
        let mut real: Vec<Vec<f64>> = (0..9).map(|_| vec![0.0; m * m]).collect();
        for iy in 0..m {
            if iy == n {
                continue;
            }
            let oy = if iy < n {
                iy as f64
            } else {
                iy as f64 - m as f64
            };
            for ix in 0..m {
                if ix == n {
                    continue;
                }
                let ox = if ix < n {
                    ix as f64
                } else {
                    ix as f64 - m as f64
                };
                let k = cell(ox * grid.dx, oy * grid.dy);
                for (c, arr) in real.iter_mut().enumerate() {
                    arr[iy * m + ix] = k[c / 3][c % 3];
                }
            }
        }
        real
    }

    /// Builds the operator from the real-space kernels of [`Operator::tables`].
    pub fn from_tables(grid: Grid, real: &[Vec<f64>]) -> Self {
        let mut fft = Fft2::new(grid.n);
        let slen = fft.spectrum_len();
        let kernels: Vec<Vec<Complex64>> = real
            .iter()
            .map(|r| {
                let mut s = vec![Complex64::default(); slen];
                fft.forward_full(r, &mut s);
                s
            })
            .collect();
        let tangential_bound = tangential_symbol_max(&kernels);
        let coarse = coarse_levels(grid, &real[3 * Z + Z]);
        Operator {
            grid,
            fft,
            tangential_bound,
            coarse,
            precond: FourierPrecond::new(grid),
            kernels,
            src_spec: (0..3).map(|_| vec![Complex64::default(); slen]).collect(),
            acc: vec![Complex64::default(); slen],
        }
    }

    /// The grid this operator was built for.
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// `u_i = Σ_j K_ij * t_j` for the listed source components `src = [(j, t_j)]`
    /// and destination components `dst = [(i, u_i)]` (each `n x n`, row-major `[iy][ix]`).
    /// Destinations are overwritten.
    pub fn apply(&mut self, src: &[(usize, &[f64])], dst: &mut [(usize, &mut [f64])]) {
        debug_assert!(src.len() <= 3);
        for (k, (_, t)) in src.iter().enumerate() {
            self.fft.forward_padded(t, &mut self.src_spec[k]);
        }
        for (i, u) in dst.iter_mut() {
            // One fused pass per destination: acc = Σ_k K_ij(k) · t̂_j(k).
            let k = |j: usize| &self.kernels[*i * 3 + j];
            let s = &self.src_spec;
            match src {
                [(j0, _)] => {
                    for ((a, s0), k0) in self.acc.iter_mut().zip(&s[0]).zip(k(*j0)) {
                        *a = s0 * k0;
                    }
                }
                [(j0, _), (j1, _)] => {
                    let it = self.acc.iter_mut().zip(&s[0]).zip(k(*j0));
                    for (((a, s0), k0), (s1, k1)) in it.zip(s[1].iter().zip(k(*j1))) {
                        *a = s0 * k0 + s1 * k1;
                    }
                }
                _ => {
                    self.acc.fill(Complex64::default());
                    for (c, (j, _)) in src.iter().enumerate() {
                        for ((a, sv), kv) in self.acc.iter_mut().zip(&s[c]).zip(k(*j)) {
                            *a += sv * kv;
                        }
                    }
                }
            }
            self.fft.inverse_cropped(&mut self.acc, u);
        }
    }

    /// The Fourier preconditioner of the normal iteration.
    pub fn precond_mut(&mut self) -> &mut FourierPrecond {
        &mut self.precond
    }

    /// The coarse `K_zz` levels below this grid (finest first).
    pub fn coarse_levels_mut(&mut self) -> &mut [CoarseLevel] {
        &mut self.coarse
    }

    /// Upper bound of the largest eigenvalue of the tangential block (m/Pa),
    /// computed once at construction (the tangential solver's step is its inverse).
    pub fn tangential_bound(&self) -> f64 {
        self.tangential_bound
    }

    /// Normal displacement under pressure only: `uz = K_zz * p`.
    pub fn normal(&mut self, p: &[f64], uz: &mut [f64]) {
        self.apply(&[(Z, p)], &mut [(Z, uz)]);
    }

    /// Tangential displacements under shear only.
    pub fn tangential(&mut self, qx: &[f64], qy: &[f64], ux: &mut [f64], uy: &mut [f64]) {
        self.apply(&[(X, qx), (Y, qy)], &mut [(X, ux), (Y, uy)]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::influence::isotropic_cell;

    fn pseudo_random(len: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..len)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.3
            })
            .collect()
    }

    #[test]
    fn dcfft_equals_direct_summation_on_16x16_to_1e12() {
        let grid = Grid {
            n: 16,
            dx: 1.0e-6,
            dy: 1.3e-6,
        };
        let (g, nu) = (80.0e9, 0.27);
        let cell = |x: f64, y: f64| isotropic_cell(g, nu, x, y, grid.dx, grid.dy);
        let mut op = Operator::build(grid, cell);
        let n = grid.n;
        let t: Vec<Vec<f64>> = (0..3).map(|c| pseudo_random(n * n, 7 + c as u64)).collect();
        let mut u: Vec<Vec<f64>> = (0..3).map(|_| vec![0.0; n * n]).collect();
        {
            let [ux, uy, uz] = &mut u[..] else {
                unreachable!()
            };
            op.apply(
                &[(X, &t[0]), (Y, &t[1]), (Z, &t[2])],
                &mut [(X, ux), (Y, uy), (Z, uz)],
            );
        }
        let mut max_err: f64 = 0.0;
        let mut max_val: f64 = 0.0;
        for iy in 0..n {
            for ix in 0..n {
                let mut d = [0.0; 3];
                for jy in 0..n {
                    for jx in 0..n {
                        let k = cell(
                            (ix as f64 - jx as f64) * grid.dx,
                            (iy as f64 - jy as f64) * grid.dy,
                        );
                        for (a, da) in d.iter_mut().enumerate() {
                            for (b, tb) in t.iter().enumerate() {
                                *da += k[a][b] * tb[jy * n + jx];
                            }
                        }
                    }
                }
                for a in 0..3 {
                    max_err = max_err.max((d[a] - u[a][iy * n + ix]).abs());
                    max_val = max_val.max(d[a].abs());
                }
            }
        }
        assert!(
            max_err < 1e-12 * max_val,
            "max err {max_err:e} vs {max_val:e}"
        );
    }
}
