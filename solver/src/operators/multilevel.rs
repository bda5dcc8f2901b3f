//! The normal solver's aids: coarse grids for nested (coarse-to-fine) initial
//! guesses, and the Fourier preconditioner. Used only by `normal`.
//!
//! A coarse cell is the union of a 2x2 block of fine cells. Its normal
//! influence coefficients are the Galerkin projection of the fine ones: the
//! block-averaged displacement under a uniform pressure on another block,
//! `K_c(D) = ¼ Σ_{e ∈ {−1,0,1}²} w(e_x) w(e_y) K_f(2D + e)` with `w = (1, 2, 1)`,
//! computed exactly from the fine table (any material). The coarse problem is
//! thus the fine problem restricted to block-constant pressures, and its
//! solution, interpolated back, is a good start for the fine iteration. The
//! coarse levels only ever provide initial guesses: every result is converged on
//! the fine grid.

use crate::base::grid::Grid;
use crate::base::parallel::{Chunks, Threads};
use crate::operators::fft2::{ensure_len, Fft2};
use num_complex::Complex64;

/// Fourier preconditioner of the normal iteration: `z = Π W Π g` with `W` the
/// `|k|` multiplier on the periodic `n x n` grid (the inverse of the
/// half-space's `1/|k|` compliance up to a constant, which cancels in CG) and
/// `Π` the restriction to the contact cells with their mean removed, on both
/// sides so that the applied operator is symmetric.
pub struct FourierPrecond {
    fft: Fft2,
    symbol: Vec<f64>,
    spec: Vec<Complex64>,
}

impl FourierPrecond {
    /// Plans and the `|k|` symbol for a grid.
    pub fn new(grid: Grid) -> Self {
        let n = grid.n;
        let fft = Fft2::periodic(n);
        let m = fft.padded_len();
        let h = m / 2 + 1;
        let mut symbol = vec![0.0; fft.spectrum_len()];
        for kx in 0..h {
            let fx = kx as f64 / grid.dx;
            for ky in 0..m {
                let ky_s = if ky <= m / 2 {
                    ky as f64
                } else {
                    ky as f64 - m as f64
                };
                symbol[kx * m + ky] = fx.hypot(ky_s / grid.dy);
            }
        }
        symbol[0] = 0.0;
        FourierPrecond {
            fft,
            symbol,
            spec: Vec::new(),
        }
    }

    /// Runs the transforms on `threads` (results unchanged, see [`Threads`]).
    pub fn set_threads(&mut self, threads: &Threads) {
        self.fft.set_threads(threads);
    }

    /// The mean of the `|k|` symbol over the spectrum, 1/m: the diagonal of
    /// `W` in real space, what `W` does to one cell's value.
    pub fn symbol_mean(&self) -> f64 {
        self.symbol.iter().sum::<f64>() / self.symbol.len() as f64
    }

    /// `z = Π W Π g` over the cells where `active` is true (`z` is zero elsewhere).
    /// (`z` holds the intermediate fields: no field-sized buffer of its own.)
    pub fn apply(&mut self, g: &[f64], active: &[bool], z: &mut [f64]) {
        ensure_len(&mut self.spec, self.fft.spectrum_len());
        z.copy_from_slice(g);
        let threads = self.fft.threads();
        centre_on(threads, active, z);
        self.fft.forward_padded(z, &mut self.spec);
        for (v, w) in self.spec.iter_mut().zip(&self.symbol) {
            *v *= *w;
        }
        self.fft.inverse_cropped(&mut self.spec, z);
        centre_on(self.fft.threads(), active, z);
    }

    /// Frees the work spectrum until the next application: a normal solve
    /// holds it, the rest of a case does not (see [`crate::solve::normal::NormalCache`]).
    pub fn release_work(&mut self) {
        self.spec = Vec::new();
    }
}

/// `Π` in place: `v − mean_active(v)` on the active cells, zero elsewhere
/// (the mean summed over fixed pieces, see [`crate::base::parallel`]).
fn centre_on(threads: &Threads, active: &[bool], v: &mut [f64]) {
    let len = v.len();
    let chunks = Chunks::flat(len);
    let parts = threads.chunked(&chunks, chunks.items(), |part| {
        let (mut s, mut c) = (0.0, 0usize);
        for i in part.range() {
            if active[i] {
                s += v[i];
                c += 1;
            }
        }
        (s, c)
    });
    let (mut s, mut c) = (0.0, 0usize);
    for (ps, pc) in parts {
        s += ps;
        c += pc;
    }
    let mean = if c > 0 { s / c as f64 } else { 0.0 };
    threads.chunked(&chunks, chunks.with(v), |(part, v)| {
        for i in part.range() {
            let x = &mut v[i - part.start];
            *x = if active[i] { *x - mean } else { 0.0 };
        }
    });
}

/// Smallest grid that is still coarsened further.
const MIN_COARSE_N: usize = 32;

/// One coarse level: grid, FFT plans and the `K_zz` spectrum only.
pub struct CoarseLevel {
    grid: Grid,
    fft: Fft2,
    /// Real spectrum of the (even) coarse `K_zz`.
    zz: Vec<f64>,
    /// Work spectrum (empty between nested starts).
    spec: Vec<Complex64>,
    precond: FourierPrecond,
}

impl CoarseLevel {
    /// The coarse grid.
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// `uz = K_zz * p` on this level.
    pub fn normal(&mut self, p: &[f64], uz: &mut [f64]) {
        ensure_len(&mut self.spec, self.fft.spectrum_len());
        self.fft.forward_padded(p, &mut self.spec);
        for (s, k) in self.spec.iter_mut().zip(&self.zz) {
            *s *= k;
        }
        self.fft.inverse_cropped(&mut self.spec, uz);
    }

    /// Frees this level's work spectra until its next use (a nested start).
    pub fn release_work(&mut self) {
        self.spec = Vec::new();
        self.precond.release_work();
    }

    /// Runs this level's transforms on `threads` (results unchanged).
    pub fn set_threads(&mut self, threads: &Threads) {
        self.fft.set_threads(threads);
        self.precond.set_threads(threads);
    }

    /// The threads of this level's transforms.
    pub fn threads(&self) -> &Threads {
        self.fft.threads()
    }

    /// The Fourier preconditioner of this level.
    pub fn precond_mut(&mut self) -> &mut FourierPrecond {
        &mut self.precond
    }
}

/// Galerkin coarse table (wrap-around layout of [`crate::operators::operator::Operator::tables`])
/// from the fine `2n x 2n` table; `n` must be even.
pub fn coarse_table(fine: &[f64], n: usize) -> Vec<f64> {
    let mf = 2 * n;
    let mc = n;
    debug_assert_eq!(fine.len(), mf * mf);
    let w = [1.0, 2.0, 1.0];
    let mut out = vec![0.0; mc * mc];
    for dy in 0..mc {
        for dx in 0..mc {
            let mut s = 0.0;
            for (ey, wy) in w.iter().enumerate() {
                let fy = (2 * dy + mf + ey - 1) % mf;
                for (ex, wx) in w.iter().enumerate() {
                    let fx = (2 * dx + mf + ex - 1) % mf;
                    s += wx * wy * fine[fy * mf + fx];
                }
            }
            out[dy * mc + dx] = 0.25 * s;
        }
    }
    out
}

/// The chain of coarse levels below a fine grid (coarsest last), built from the
/// fine `K_zz` table. Empty when the grid is too small or odd.
pub fn coarse_levels(grid: Grid, zz_table: &[f64]) -> Vec<CoarseLevel> {
    let mut levels = Vec::new();
    let mut table = zz_table.to_vec();
    let mut g = grid;
    while g.n.is_multiple_of(2) && g.n / 2 >= MIN_COARSE_N {
        crate::base::progress::tick();
        table = coarse_table(&table, g.n);
        g = Grid {
            n: g.n / 2,
            dx: 2.0 * g.dx,
            dy: 2.0 * g.dy,
        };
        let mut fft = Fft2::new(g.n);
        let mut spec = vec![Complex64::default(); fft.spectrum_len()];
        fft.forward_full(&table, &mut spec);
        let zz = spec.iter().map(|z| z.re).collect();
        levels.push(CoarseLevel {
            grid: g,
            fft,
            zz,
            spec: Vec::new(),
            precond: FourierPrecond::new(g),
        });
    }
    levels
}

/// 2x2 block average of an `n x n` field (n even).
pub fn restrict(fine: &[f64], n: usize) -> Vec<f64> {
    let nc = n / 2;
    let mut out = vec![0.0; nc * nc];
    for iy in 0..nc {
        for ix in 0..nc {
            let (a, b) = (2 * iy * n + 2 * ix, (2 * iy + 1) * n + 2 * ix);
            out[iy * nc + ix] = 0.25 * (fine[a] + fine[a + 1] + fine[b] + fine[b + 1]);
        }
    }
    out
}

/// Cell-centred bilinear interpolation of an `nc x nc` field onto the `2nc x 2nc`
/// grid (weights 9/16, 3/16, 3/16, 1/16; edges use the nearest coarse cell).
pub fn prolong(coarse: &[f64], nc: usize) -> Vec<f64> {
    let n = 2 * nc;
    let mut out = vec![0.0; n * n];
    let at = |ix: isize, iy: isize| -> f64 {
        let cx = ix.clamp(0, nc as isize - 1) as usize;
        let cy = iy.clamp(0, nc as isize - 1) as usize;
        coarse[cy * nc + cx]
    };
    for fy in 0..n {
        let cy = (fy / 2) as isize;
        let ny = if fy % 2 == 0 { cy - 1 } else { cy + 1 };
        for fx in 0..n {
            let cx = (fx / 2) as isize;
            let nx = if fx % 2 == 0 { cx - 1 } else { cx + 1 };
            out[fy * n + fx] =
                (9.0 * at(cx, cy) + 3.0 * at(nx, cy) + 3.0 * at(cx, ny) + at(nx, ny)) / 16.0;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::green::influence::isotropic_cell;
    use crate::operators::operator::Operator;

    /// The coarse operator is exactly R K P: block-average of the fine
    /// displacement under a block-constant pressure.
    #[test]
    fn coarse_operator_is_the_galerkin_projection_to_1e12() {
        let grid = Grid {
            n: 64,
            dx: 1.0e-6,
            dy: 1.0e-6,
        };
        let (g, nu) = (80.0e9, 0.3);
        let tables = Operator::tables(grid, |x, y| isotropic_cell(g, nu, x, y, grid.dx, grid.dy));
        let mut op = Operator::from_tables(grid, &tables);
        let mut levels = coarse_levels(grid, &tables[8]);
        assert_eq!(levels.len(), 1);
        let nc = 32;
        let pc: Vec<f64> = (0..nc * nc)
            .map(|i| ((i * 37 % 101) as f64 / 101.0 - 0.2).max(0.0))
            .collect();
        // Block-constant fine field.
        let pf: Vec<f64> = (0..64 * 64)
            .map(|i| pc[(i / 64 / 2) * nc + (i % 64) / 2])
            .collect();
        let mut uf = vec![0.0; 64 * 64];
        op.normal(&pf, &mut uf);
        let expect = restrict(&uf, 64);
        let mut uc = vec![0.0; nc * nc];
        levels[0].normal(&pc, &mut uc);
        let scale = expect.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let err = expect
            .iter()
            .zip(&uc)
            .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(err < 1e-12 * scale, "err {err:e} of {scale:e}");
    }

    #[test]
    fn prolongation_reproduces_linear_fields_inside() {
        let nc = 8;
        let c: Vec<f64> = (0..nc * nc)
            .map(|i| 2.0 * (i % nc) as f64 - 3.0 * (i / nc) as f64)
            .collect();
        let f = prolong(&c, nc);
        let n = 2 * nc;
        for fy in 1..n - 1 {
            for fx in 1..n - 1 {
                // Fine centre in coarse index units: (f + 0.5)/2 − 0.5.
                let (x, y) = ((fx as f64 + 0.5) / 2.0 - 0.5, (fy as f64 + 0.5) / 2.0 - 0.5);
                assert!((f[fy * n + fx] - (2.0 * x - 3.0 * y)).abs() < 1e-12);
            }
        }
    }
}
