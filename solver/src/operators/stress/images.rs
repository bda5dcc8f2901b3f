//! The periodic images a kernel sampled on the padded grid carries, and
//! their subtraction: estimated on a coarse grid over the window and
//! convolved there (a DC-FFT of its own), so that a plane's convolution
//! is DC-FFT's non-periodic one.

use rustfft::FftPlanner;
use std::sync::Arc;

use super::{sinc, StressPlan, StressPlane, TractionSpectra, C};
use crate::operators::fft2::Fft2;

/// Coarse points per padded period on which the periodic images of a
/// kernel are estimated and convolved (see [`StressPlan::images`]).
const COARSE: usize = 32;

/// The wider lattice's period, in padded periods (its own images weigh
/// `WIDER⁻³` of the first while the depth is well inside it).
const WIDER: usize = 4;

/// The widest lattice's period over the depth, from which its own images
/// are left out (see [`StressPlan::image_levels`]): below the depth `z`
/// the images of a lattice of period `L` leave about `F z/L³` in the
/// stresses (`F` the load), and at `L = 128 z` the stresses of tractions
/// confined to the domain are Boussinesq's and Cerruti's to 1.6e-5 of
/// their scale `3F/(2πz²)` from 2a to 10⁴a
/// (`deep_planes_carry_boussinesq_and_cerruti_fields_to_a_thousand_domain_widths`;
/// at `L = 4T`, the only lattice before issue #59, σzz had a floor of
/// `−F/(16T²)`).
const IMAGE_REACH: f64 = 128.0;

/// The widest lattice's period in padded periods at any depth: near the
/// surface the in-plane stresses fall like `1/r²`, so a lattice of period
/// `L` leaves about `F/L²` there; on a Hertz contact 4a wide (`T = 8a`),
/// 8e-5 p0 at `L = 4T`, 1.2e-6 at `16T`, 2e-8 at `64T`.
const IMAGE_FLOOR: f64 = 64.0;

/// The decay the smoothing of the lattice sums leaves at the coarse
/// grid's Nyquist number, with the response's own: `e^{−9}` = 1.2e-4.
const SMOOTHING: f64 = 9.0;

/// Most lattices summed, a guard: the deepest plane a plan computes
/// (`MAX_DEPTH_PERIODS`, 10⁶ padded periods) needs 13.
const MAX_IMAGE_LEVELS: usize = 24;

/// The coarse grid over the window on which the periodic images are
/// subtracted in real space (a DC-FFT of its own, see
/// [`StressPlan::images`]): `nc` nodes per axis spaced `T/COARSE` (`T`
/// the padded period, so `2n/COARSE` cells), the middle one on the
/// window's centre (a grid symmetric about it keeps the symmetries of the
/// load: off centre, the resultant of σyz under a load along x was 8e-9 of
/// it instead of 0), and each cell's 4-point Lagrange weights on them (the
/// same along x and y: both periods are `2n` cells).
pub(super) struct Coarse {
    nc: usize,
    pub(super) fft: Fft2,
    /// Per cell index: its first node and the four weights.
    pub(super) weights: Vec<(usize, [f64; 4])>,
}

/// 4-point Lagrange weights at the fraction `f` (nodes −1, 0, 1, 2).
pub(super) fn lagrange4(f: f64) -> [f64; 4] {
    [
        -f * (f - 1.0) * (f - 2.0) / 6.0,
        (f + 1.0) * (f - 1.0) * (f - 2.0) / 2.0,
        -(f + 1.0) * f * (f - 2.0) / 2.0,
        (f + 1.0) * f * (f - 1.0) / 6.0,
    ]
}

impl Coarse {
    pub(super) fn new(n: usize) -> Self {
        // Cells reach COARSE/4 nodes either side of the centre, a stencil
        // two more.
        let nc = COARSE / 2 + 5;
        let cells_per_node = (2 * n) as f64 / COARSE as f64;
        let centre = 0.5 * (n as f64 - 1.0);
        let weights = (0..n)
            .map(|i| {
                let u = (i as f64 - centre) / cells_per_node + 0.5 * (nc - 1) as f64;
                let i0 = u.floor();
                (i0 as usize, lagrange4(u - i0))
            })
            .collect();
        Coarse {
            nc,
            fft: Fft2::new(nc),
            weights,
        }
    }

    /// The transpose of the interpolation: each cell's value spread onto
    /// its 4 x 4 nodes (`Σ E(x − x') f(x') = Σ E(x − X) F(X)` when `E` is
    /// cubic over a stencil), `nc x nc` row major.
    pub(super) fn spread(&self, f: &[f64]) -> Vec<f64> {
        let (n, nc) = (self.weights.len(), self.nc);
        let mut rows = vec![0.0; n * nc];
        for iy in 0..n {
            let row = &mut rows[iy * nc..(iy + 1) * nc];
            for (ix, &(first, w)) in self.weights.iter().enumerate() {
                let v = f[iy * n + ix];
                if v != 0.0 {
                    for (b, wb) in w.iter().enumerate() {
                        row[first + b] += wb * v;
                    }
                }
            }
        }
        let mut out = vec![0.0; nc * nc];
        for (iy, &(first, w)) in self.weights.iter().enumerate() {
            for (a, wa) in w.iter().enumerate() {
                let dst = &mut out[(first + a) * nc..(first + a + 1) * nc];
                for (d, r) in dst.iter_mut().zip(&rows[iy * nc..(iy + 1) * nc]) {
                    *d += wa * r;
                }
            }
        }
        out
    }

    /// `g` (`nc x nc` nodes) interpolated at cell `(ix, iy)`.
    pub(super) fn at(&self, g: &[f64], ix: usize, iy: usize) -> f64 {
        let nc = self.nc;
        let (fx, wx) = self.weights[ix];
        let (fy, wy) = self.weights[iy];
        let mut acc = 0.0;
        for (a, wa) in wy.iter().enumerate() {
            let row = &g[(fy + a) * nc + fx..(fy + a) * nc + fx + 4];
            acc += wa * (wx[0] * row[0] + wx[1] * row[1] + wx[2] * row[2] + wx[3] * row[3]);
        }
        acc
    }
}

/// The periodic images of a plane's kernel on coarse points, per component
/// (see [`StressPlan::images`]).
pub(super) struct Images {
    pub(super) reach: i64,
    /// `[my][mx]` for `m` in `[−reach, reach]`.
    pub(super) values: Vec<[f64; 18]>,
}

impl Images {
    /// Component `c` at the coarse offset `(mx, my)` (within `reach`).
    fn at_node(&self, c: usize, mx: i64, my: i64) -> f64 {
        let width = 2 * self.reach as usize + 1;
        self.values[(my + self.reach) as usize * width + (mx + self.reach) as usize][c]
    }
}

impl StressPlan {
    /// The periodic images a kernel sampled on the padded grid's
    /// frequencies carries (DC-FFT wants the kernel of one cell alone on
    /// the padded window): `E(x) = Σ_{j≠0} K(x + jT)`, `T` the padded
    /// period. `E` is smooth over the window (every image is at least `T/2`
    /// away), so it is computed on a coarse grid, as the difference of the
    /// kernel periodised with period `T` and with period `4T`, both
    /// smoothed by a Gaussian of about the coarse spacing (the near field
    /// cancels in the difference), and interpolated. Without it, the
    /// in-plane stresses at depth z carry an offset of order `F z / T³`
    /// (1 % of p0 at z = 1.5a on a domain 4a wide).
    pub(super) fn images(&self, z: f64, coarse: usize, levels: usize) -> Images {
        let reach = coarse as i64 / 2 + 4;
        let mut values = self.lattice_difference(z, coarse, 1.0, reach);
        // The wider lattice's own images, when the depth reaches them: the
        // difference of the next two lattices, each `WIDER` times wider,
        // on its own coarser points, interpolated at these.
        let width = 2 * reach as usize + 1;
        for level in 1..levels {
            let stretch = (WIDER as f64).powi(level as i32);
            let outer = (reach as f64 / stretch).ceil() as i64 + 2;
            let wide = self.lattice_difference(z, coarse, stretch, outer);
            let at = |mx: i64, my: i64| {
                &wide[(my + outer) as usize * (2 * outer as usize + 1) + (mx + outer) as usize]
            };
            // The first of the 4 points of offset `m` and its weights.
            let stencil = |m: i64| {
                let u = m as f64 / stretch;
                let first = u.floor();
                (first as i64 - 1, lagrange4(u - first))
            };
            for my in -reach..=reach {
                let (fy, wy) = stencil(my);
                for mx in -reach..=reach {
                    let (fx, wx) = stencil(mx);
                    let v = &mut values[(my + reach) as usize * width + (mx + reach) as usize];
                    for (a, wa) in wy.iter().enumerate() {
                        for (b, wb) in wx.iter().enumerate() {
                            let src = at(fx + b as i64, fy + a as i64);
                            for (x, s) in v.iter_mut().zip(src) {
                                *x += wa * wb * s;
                            }
                        }
                    }
                }
            }
        }
        Images { reach, values }
    }

    /// The lattices whose images [`StressPlan::images`] sums down to depth
    /// `z`: the padded period's and `WIDER` times it, then as many more,
    /// each `WIDER` times the last, as make the widest period at least
    /// `IMAGE_REACH` times the depth, and at least `IMAGE_FLOOR` padded
    /// periods (at most `MAX_IMAGE_LEVELS`). A plane takes its own depth's;
    /// a slice's rows, which interpolate the images between anchor depths,
    /// all take their deepest row's (a lattice added from one anchor to the
    /// next would be a step there).
    pub(super) fn image_levels(&self, z: f64) -> usize {
        let t = 2.0 * self.grid.n as f64 * self.grid.dx.max(self.grid.dy);
        let widest = (IMAGE_REACH * z).max(IMAGE_FLOOR * t);
        let mut period = WIDER as f64 * t;
        let mut levels = 1;
        while period < widest && levels < MAX_IMAGE_LEVELS {
            period *= WIDER as f64;
            levels += 1;
        }
        levels
    }

    /// `E` of the lattice `stretch` times the padded period's (the
    /// periodised kernel less that of the lattice `WIDER` times wider, both
    /// smoothed over the coarse spacing, `stretch` times this grid's
    /// `T/coarse`) at its coarse offsets `m`, `|m| ≤ reach` in both axes.
    fn lattice_difference(
        &self,
        z: f64,
        coarse: usize,
        stretch: f64,
        reach: i64,
    ) -> Vec<[f64; 18]> {
        let n = self.grid.n;
        let (tx, ty) = (
            2.0 * n as f64 * self.grid.dx * stretch,
            2.0 * n as f64 * self.grid.dy * stretch,
        );
        let (cx, cy) = (tx / coarse as f64, ty / coarse as f64);
        // The smoothing `e^{−(ρ/ρc)²}`, `(ρmax/ρc)² = 9 e^{−u/9}` with
        // `u = slowest ρmax z` the response's own decay at the coarse
        // grid's Nyquist number `ρmax`: the two leave `e^{−u − 9e^{−u/9}}
        // ≤ e^{−9}` there, as at the surface, and the smoothing fades
        // smoothly with the depth (the slices' rows interpolate the images
        // between depths). The images it also blurs are at least half a
        // period away; smoothing them as at the surface, `ρc = ρmax/3`,
        // had left σzz 0.3 % low at depths of a period and beyond.
        let rho_max = std::f64::consts::PI / cx.max(cy);
        let decay = self.response.slowest * rho_max * z;
        let squeeze = SMOOTHING * (-decay / SMOOTHING).exp() / (rho_max * rho_max);
        let (dx, dy) = (self.grid.dx, self.grid.dy);
        let tau = 2.0 * std::f64::consts::PI;
        // The kernel periodised with period `periods · T`, smoothed, at the
        // coarse points `m · (cx, cy)`, m in [0, side)².
        let periodic = |periods: usize| -> Vec<[f64; 18]> {
            let side = coarse * periods;
            let signed = |k: usize| {
                if k > side / 2 {
                    k as f64 - side as f64
                } else {
                    k as f64
                }
            };
            use rayon::prelude::*;
            let mut spec: Vec<[C; 18]> = (0..side * side)
                .into_par_iter()
                .map(|i| {
                    let (ky, kx) = (i / side, i % side);
                    let ex = tau * signed(kx) / (periods as f64 * tx);
                    let ey = tau * signed(ky) / (periods as f64 * ty);
                    if kx == 0 && ky == 0 {
                        self.dc
                    } else {
                        let rho = (ex * ex + ey * ey).sqrt();
                        let b = sinc(0.5 * ex * dx)
                            * sinc(0.5 * ey * dy)
                            * (-rho * rho * squeeze).exp();
                        self.response.at(ex, ey, z).map(|v| v * b)
                    }
                })
                .collect();
            // f_T(x) = (1/(T_x T_y)) Σ_k f̂(η_k) e^{−iη_k·x}: forward transforms.
            let fft = FftPlanner::<f64>::new().plan_fft_forward(side);
            let mut buf = vec![C::default(); side];
            // (component by component: one transform's buffer at a time)
            #[allow(clippy::needless_range_loop)]
            for c in 0..18 {
                for row in 0..side {
                    for (kx, b) in buf.iter_mut().enumerate() {
                        *b = spec[row * side + kx][c];
                    }
                    fft.process(&mut buf);
                    for (kx, b) in buf.iter().enumerate() {
                        spec[row * side + kx][c] = *b;
                    }
                }
                for col in 0..side {
                    for (ky, b) in buf.iter_mut().enumerate() {
                        *b = spec[ky * side + col][c];
                    }
                    fft.process(&mut buf);
                    for (ky, b) in buf.iter().enumerate() {
                        spec[ky * side + col][c] = *b;
                    }
                }
            }
            // The cell's transform is `Δx Δy sinc sinc`: the kernel of a
            // cell is `(1/(T_x T_y)) Σ Δx Δy M sinc sinc e^{…}`.
            let scale = (dx * dy) / ((periods * periods) as f64 * tx * ty);
            spec.iter()
                .map(|v| std::array::from_fn(|c| v[c].re * scale))
                .collect()
        };
        let near = periodic(1);
        let far = periodic(WIDER);
        let width = 2 * reach as usize + 1;
        let wrap = |m: i64, side: usize| m.rem_euclid(side as i64) as usize;
        let mut values = vec![[0.0; 18]; width * width];
        for my in -reach..=reach {
            for mx in -reach..=reach {
                let a = near[wrap(my, coarse) * coarse + wrap(mx, coarse)];
                let side = coarse * WIDER;
                let b = far[wrap(my, side) * side + wrap(mx, side)];
                values[(my + reach) as usize * width + (mx + reach) as usize] =
                    std::array::from_fn(|c| a[c] - b[c]);
            }
        }
        values
    }

    /// [`StressPlan::image_spectra`] at depth `z` with `levels` lattices,
    /// computed once per plan.
    pub(super) fn images_at(&mut self, z: f64, levels: usize) -> Arc<Vec<[C; 18]>> {
        if let Some(v) = self.images.get(&(z.to_bits(), levels)) {
            return v.clone();
        }
        let v = Arc::new(self.image_spectra(z, levels));
        self.images.insert((z.to_bits(), levels), v.clone());
        v
    }

    /// The coarse spectra of the periodic images at depth `z` summed over
    /// `levels` lattices ([`StressPlan::images`]) for the real-space
    /// correction.
    pub(super) fn image_spectra(&mut self, z: f64, levels: usize) -> Vec<[C; 18]> {
        let images = self.images(z, COARSE, levels);
        // E at the coarse offsets m in [−nc, nc), periodic on the coarse
        // padded grid, and its 18 spectra.
        let nc = self.coarse.nc;
        let side = 2 * nc;
        let mut real = vec![0.0; side * side];
        let mut spec = vec![C::default(); self.coarse.fft.spectrum_len()];
        let mut out = vec![[C::default(); 18]; spec.len()];
        let signed = |i: usize| {
            if i < nc {
                i as i64
            } else {
                i as i64 - side as i64
            }
        };
        for c in 0..18 {
            for iy in 0..side {
                for ix in 0..side {
                    // (offset −nc joins no two nodes: left 0)
                    let (mx, my) = (signed(ix), signed(iy));
                    real[iy * side + ix] = if mx.abs() < nc as i64 && my.abs() < nc as i64 {
                        images.at_node(c, mx, my)
                    } else {
                        0.0
                    };
                }
            }
            self.coarse.fft.forward_full(&real, &mut spec);
            for (k, v) in out.iter_mut().zip(&spec) {
                k[c] = *v;
            }
        }
        out
    }

    /// The stresses of the periodic images on the coarse nodes
    /// (`Σ E(X − X') T(X')`, six `nc x nc` fields), to be interpolated and
    /// subtracted: 18 products and 6 inverse transforms of the coarse grid.
    pub(super) fn image_stresses(
        &mut self,
        plane: &StressPlane,
        t: &TractionSpectra,
    ) -> [Vec<f64>; 6] {
        let nc = self.coarse.nc;
        let mut spec = vec![C::default(); self.coarse.fft.spectrum_len()];
        std::array::from_fn(|c| {
            for (i, s) in spec.iter_mut().enumerate() {
                let k = &plane.images[i];
                *s = k[3 * c] * t.coarse[0][i]
                    + k[3 * c + 1] * t.coarse[1][i]
                    + k[3 * c + 2] * t.coarse[2][i];
            }
            let mut out = vec![0.0; nc * nc];
            self.coarse.fft.inverse_cropped(&mut spec, &mut out);
            out
        })
    }
}
