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
//! grid and subtracted ([`StressPlan::plane`]), so the convolution is the
//! non-periodic one of DC-FFT.

use nalgebra::{Matrix3, Matrix6, SMatrix};
use num_complex::Complex64;
use rustfft::FftPlanner;

use crate::base::grid::Grid;
use crate::error::SolverError;
use crate::green::aniso::stroh::{
    contract, surface_compliance_tensor, voigt_index, voigt_to_tensor,
};
use crate::model::material::{Elasticity, Material};
use crate::operators::fft2::Fft2;

type C = Complex64;
type M3 = Matrix3<C>;
type M63 = SMatrix<C, 6, 3>;

/// The stress components in their stored order (engineering Voigt order,
/// the solver's): `σxx, σyy, σzz, σyz, σxz, σxy`.
pub const COMPONENTS: [&str; 6] = ["sxx", "syy", "szz", "syz", "sxz", "sxy"];

/// Directions tabulated over `[0, 2π)` (closed forms for an isotropic
/// material, Stroh otherwise); `P`, `W` and `H` are interpolated between
/// them (4-point Lagrange).
/// 2048 nodes keep the interpolation error below 1e-9 of the entries
/// (`interpolated_directions_equal_direct_evaluation`).
pub const STROH_DIRECTIONS: usize = 2048;

/// Depth (in cells, of the larger side) from which the aliases of the
/// response are dropped: beyond it they weigh `e^{−πz/Δ}`, below 2e-7.
const ALIAS_FREE_DEPTH_CELLS: f64 = 5.0;

/// Most aliases summed per axis and side at shallow depths (at the
/// surface itself the series is truncated here).
const MAX_ALIASES: i64 = 4;

/// `P`, `W`, `H` of one in-plane direction θ: `σ̂ = P exp(−isW) H t̂`.
#[derive(Clone, Copy, Debug)]
struct Direction {
    p: M63,
    w: M3,
    h: M3,
    /// `P H`: the response on the surface itself.
    ph: M63,
}

impl Direction {
    /// From the stiffness tensor and the surface compliance `H(θ)`.
    fn new(t: &crate::green::aniso::stroh::Tensor4, cv: &Matrix6<f64>, theta: f64, h: M3) -> Self {
        let n = [theta.cos(), theta.sin(), 0.0];
        let m = [0.0, 0.0, 1.0];
        let tt = contract(t, &m, &m);
        let r = contract(t, &n, &m);
        let ti = tt
            .try_inverse()
            .expect("stiffness checked positive definite");
        let n1 = (-ti * r.transpose()).map(|v| C::new(v, 0.0));
        let n2 = ti.map(|v| C::new(v, 0.0));
        let hi = h.try_inverse().expect("H(θ) is positive definite");
        let w = n1 - n2 * hi * C::new(0.0, 1.0);
        // ∂_l u_k → −iρ n_l û_k in-plane, −iρ (W û)_k along z.
        let mut cn = M63::zeros();
        let mut cm = M63::zeros();
        for big in 0..6 {
            for k in 0..3 {
                let along: f64 = (0..2).map(|l| cv[(big, voigt_index(k, l))] * n[l]).sum();
                cn[(big, k)] = C::new(along, 0.0);
                cm[(big, k)] = C::new(cv[(big, voigt_index(k, 2))], 0.0);
            }
        }
        let p = (cn + cm * w) * C::new(0.0, -1.0);
        Direction { p, w, h, ph: p * h }
    }
}

/// How a material responds at depth: `P`, `W`, `H` (and `P H`) tabulated
/// over the directions, interpolated between them (4-point Lagrange).
struct Response {
    /// Isotropic: `H` of §3 at the nodes and `W = −iI + N` with `N² = 0`,
    /// so that `exp(−isW) = e^{−s}(I − isN)`. Otherwise Stroh: `H` from the
    /// Barnett–Lothe integrals, the exponential by scaling and squaring.
    isotropic: bool,
    table: Vec<Direction>,
}

/// The isotropic surface compliance of PHYSICS.md §3.
fn isotropic_h(g: f64, nu: f64, theta: f64) -> M3 {
    let (s, c) = theta.sin_cos();
    let r = |v: f64| C::new(v / g, 0.0);
    let i = |v: f64| C::new(0.0, v / g);
    let k = 0.5 * (1.0 - 2.0 * nu);
    M3::new(
        r(1.0 - nu * c * c),
        r(-nu * c * s),
        i(-k * c),
        r(-nu * c * s),
        r(1.0 - nu * s * s),
        i(-k * s),
        i(k * c),
        i(k * s),
        r(1.0 - nu),
    )
}

/// `exp(x)` of a 3x3 complex matrix: scaling and squaring of a 14-term
/// Taylor series (the scaled norm is at most 1/2, so the truncation is
/// below 3e-17). Exact for defective matrices, which an eigenvector route is not.
pub(crate) fn expm3(x: &M3) -> M3 {
    let norm = (0..3)
        .map(|j| (0..3).map(|i| x[(i, j)].norm()).sum::<f64>())
        .fold(0.0, f64::max);
    let mut squarings = 0;
    let mut scale = 1.0;
    while norm * scale > 0.5 {
        scale *= 0.5;
        squarings += 1;
    }
    let a = x * C::new(scale, 0.0);
    let mut term = M3::identity();
    let mut sum = M3::identity();
    for k in 1..=14 {
        term = term * a * C::new(1.0 / k as f64, 0.0);
        sum += term;
    }
    for _ in 0..squarings {
        sum = sum * sum;
    }
    sum
}

impl Response {
    fn of(material: &Material) -> Result<Self, SolverError> {
        let cv = material.stiffness();
        let t = voigt_to_tensor(&cv);
        let theta = |k: usize| 2.0 * std::f64::consts::PI * k as f64 / STROH_DIRECTIONS as f64;
        let (isotropic, table) = match &material.elasticity {
            Elasticity::Isotropic(iso) => {
                if iso.poisson >= 0.5 {
                    return Err(SolverError::invalid(
                        "poisson",
                        "stresses below the surface need ν < 0.5 (the stiffness of an incompressible solid is unbounded)",
                    ));
                }
                let (g, nu) = (iso.shear(), iso.poisson);
                let table = (0..STROH_DIRECTIONS)
                    .map(|k| Direction::new(&t, &cv, theta(k), isotropic_h(g, nu, theta(k))))
                    .collect();
                (true, table)
            }
            Elasticity::Anisotropic(_) => {
                let table = (0..STROH_DIRECTIONS)
                    .map(|k| {
                        let h = surface_compliance_tensor(
                            &t,
                            theta(k),
                            crate::green::aniso::stroh::DEFAULT_OMEGA_POINTS,
                        );
                        Direction::new(&t, &cv, theta(k), h)
                    })
                    .collect();
                (false, table)
            }
        };
        Ok(Response { isotropic, table })
    }

    /// The nodes and 4-point Lagrange weights of direction θ.
    fn nodes(&self, theta: f64) -> [(usize, f64); 4] {
        let k = self.table.len();
        let u =
            theta.rem_euclid(2.0 * std::f64::consts::PI) / (2.0 * std::f64::consts::PI) * k as f64;
        let i0 = u.floor() as i64;
        let f = u - i0 as f64;
        let wts = [
            -f * (f - 1.0) * (f - 2.0) / 6.0,
            (f + 1.0) * (f - 1.0) * (f - 2.0) / 2.0,
            -(f + 1.0) * f * (f - 2.0) / 2.0,
            (f + 1.0) * f * (f - 1.0) / 6.0,
        ];
        std::array::from_fn(|j| ((i0 - 1 + j as i64).rem_euclid(k as i64) as usize, wts[j]))
    }

    /// `P`, `W`, `H` along θ.
    fn direction(&self, theta: f64) -> Direction {
        let mut d = Direction {
            p: M63::zeros(),
            w: M3::zeros(),
            h: M3::zeros(),
            ph: M63::zeros(),
        };
        for (i, wt) in self.nodes(theta) {
            let node = &self.table[i];
            let c = C::new(wt, 0.0);
            d.p += node.p * c;
            d.w += node.w * c;
            d.h += node.h * c;
        }
        d
    }

    /// `P H` along θ: the response at `s = 0`.
    fn surface(&self, theta: f64) -> M63 {
        let mut ph = M63::zeros();
        for (i, wt) in self.nodes(theta) {
            ph += self.table[i].ph * C::new(wt, 0.0);
        }
        ph
    }

    /// `exp(−isW)` for this response.
    fn propagator(&self, d: &Direction, s: f64) -> M3 {
        if s == 0.0 {
            return M3::identity();
        }
        if self.isotropic {
            let nil = d.w + M3::identity() * C::new(0.0, 1.0);
            (M3::identity() - nil * C::new(0.0, s)) * C::new((-s).exp(), 0.0)
        } else {
            expm3(&(d.w * C::new(0.0, -s)))
        }
    }

    /// Stress per unit traction `σ̂ = M t̂` (6x3) at wave vector `(ex, ey)` and depth `z`.
    fn at(&self, ex: f64, ey: f64, z: f64) -> M63 {
        let theta = ey.atan2(ex);
        if z == 0.0 {
            return self.surface(theta);
        }
        let d = self.direction(theta);
        d.p * self.propagator(&d, ex.hypot(ey) * z) * d.h
    }

    /// The response at `η = 0`: its limit depends on the direction; the
    /// mean over directions (the in-plane rows; the `z` rows are `−I` along
    /// every direction).
    fn mean_at_zero(&self) -> M63 {
        let k = 64;
        let mut acc = M63::zeros();
        for i in 0..k {
            acc += self.surface(2.0 * std::f64::consts::PI * i as f64 / k as f64);
        }
        acc / C::new(k as f64, 0.0)
    }
}

/// `sin(u)/u`.
fn sinc(u: f64) -> f64 {
    if u.abs() < 1e-8 {
        1.0 - u * u / 6.0
    } else {
        u.sin() / u
    }
}

/// The stress response of one material on one grid: what every depth
/// plane and line of it is built from. Build once per (material, grid).
pub struct StressPlan {
    grid: Grid,
    response: Response,
    dc: M63,
    fft: Fft2,
}

/// The spectra of a state's tractions on the padded grid (three forward
/// transforms), shared by every depth and line computed from that state.
pub struct TractionSpectra {
    /// `q̂x, q̂y, p̂`, natural order, `[kx][ky]` (see [`crate::operators::fft2`]).
    spectra: [Vec<C>; 3],
    /// `qx, qy, p` themselves (the stresses on the surface plane).
    fields: [Vec<f64>; 3],
}

/// The kernel spectra of one depth plane (18 half spectra of the padded
/// grid: `6 x 3` stress components per traction component), applied to
/// many states. `18 · 16 · 2n(n + 1)` bytes: 151 MB at `n = 512`.
pub struct StressPlane {
    depth_m: f64,
    kernel: Vec<[C; 18]>,
}

impl StressPlane {
    /// The depth of the plane, m.
    pub fn depth_m(&self) -> f64 {
        self.depth_m
    }
}

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

impl StressPlan {
    /// The plan for `material` on `grid` (tabulates the Stroh matrices of
    /// an anisotropic material, plans the transforms).
    pub fn new(material: &Material, grid: Grid) -> Result<Self, SolverError> {
        material.validate()?;
        let response = Response::of(material)?;
        let dc = response.mean_at_zero();
        Ok(StressPlan {
            grid,
            response,
            dc,
            fft: Fft2::new(grid.n),
        })
    }

    /// The grid.
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// Stress per unit traction `σ̂ = M t̂` (6x3, rows [`COMPONENTS`],
    /// columns `qx, qy, p`) of the continuous half-space at wave vector
    /// `η = (ex, ey)` (1/m, transform `∫∫ f e^{iη·x} dA`) and depth `z`
    /// (m). For tests and documentation of the response itself.
    pub fn response(&self, ex: f64, ey: f64, z: f64) -> [[C; 3]; 6] {
        let m = self.response.at(ex, ey, z);
        std::array::from_fn(|i| std::array::from_fn(|j| m[(i, j)]))
    }

    /// The alias orders summed at depth `z`.
    fn aliases(&self, z: f64) -> i64 {
        let d = self.grid.dx.max(self.grid.dy);
        if z >= ALIAS_FREE_DEPTH_CELLS * d {
            0
        } else if z <= 0.0 {
            MAX_ALIASES
        } else {
            ((ALIAS_FREE_DEPTH_CELLS * d / z).ceil() as i64).min(MAX_ALIASES)
        }
    }

    /// The discrete kernel spectrum (18 values) at padded-grid frequency
    /// `(kx, ky)`: the response times the cell's transform, summed over aliases.
    fn kernel_at(&self, kx: usize, ky: usize, z: f64, aliases: i64) -> M63 {
        let m = 2 * self.grid.n;
        if kx == 0 && ky == 0 {
            return self.dc;
        }
        let signed = |k: usize| {
            if k > m / 2 {
                k as f64 - m as f64
            } else {
                k as f64
            }
        };
        let (dx, dy) = (self.grid.dx, self.grid.dy);
        let tau = 2.0 * std::f64::consts::PI;
        // The DFT `Σ f e^{−2πi k x/M}` is the transform at η = −2πk/(MΔ).
        let ex0 = -tau * signed(kx) / (m as f64 * dx);
        let ey0 = -tau * signed(ky) / (m as f64 * dy);
        // The alias series of the odd (imaginary) parts alternate in sign
        // with terms ~1/j at the surface: the last order counts half (the
        // mean of two partial sums), which leaves an error ~1/J² instead of 1/J.
        let end = |j: i64| {
            if aliases > 0 && j.abs() == aliases {
                0.5
            } else {
                1.0
            }
        };
        let mut acc = M63::zeros();
        for jx in -aliases..=aliases {
            let ex = ex0 + tau * jx as f64 / dx;
            let bx = sinc(0.5 * ex * dx) * end(jx);
            for jy in -aliases..=aliases {
                let ey = ey0 + tau * jy as f64 / dy;
                let b = bx * sinc(0.5 * ey * dy) * end(jy);
                acc += self.response.at(ex, ey, z) * C::new(b, 0.0);
            }
        }
        acc
    }

    /// The kernel of the plane at depth `depth_m` (m, ≥ 0): the response
    /// on the padded grid's frequencies, less the periodic images of the
    /// padded grid (see `StressPlan::images`).
    pub fn plane(&mut self, depth_m: f64) -> Result<StressPlane, SolverError> {
        check_depth(depth_m)?;
        let n = self.grid.n;
        let m = 2 * n;
        let h = m / 2 + 1;
        let aliases = self.aliases(depth_m);
        let mut kernel = vec![[C::default(); 18]; h * m];
        {
            use rayon::prelude::*;
            let this = &*self;
            kernel.par_chunks_mut(m).enumerate().for_each(|(kx, col)| {
                for (ky, v) in col.iter_mut().enumerate() {
                    let k = this.kernel_at(kx, ky, depth_m, aliases);
                    *v = std::array::from_fn(|c| k[(c / 3, c % 3)]);
                }
            });
        }
        let images = self.images(depth_m);
        let mut real = vec![0.0; m * m];
        let mut spec = vec![C::default(); self.fft.spectrum_len()];
        for c in 0..18 {
            for iy in 0..m {
                let y = if iy < n {
                    iy as f64
                } else {
                    iy as f64 - m as f64
                } * self.grid.dy;
                for ix in 0..m {
                    let x = if ix < n {
                        ix as f64
                    } else {
                        ix as f64 - m as f64
                    } * self.grid.dx;
                    real[iy * m + ix] = images.at(c, x, y);
                }
            }
            self.fft.forward_full(&real, &mut spec);
            for (k, s) in kernel.iter_mut().zip(&spec) {
                k[c] -= s;
            }
        }
        Ok(StressPlane { depth_m, kernel })
    }

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
    fn images(&self, z: f64) -> Images {
        const COARSE: usize = 64;
        const WIDER: usize = 4;
        let n = self.grid.n;
        let (tx, ty) = (2.0 * n as f64 * self.grid.dx, 2.0 * n as f64 * self.grid.dy);
        let (cx, cy) = (tx / COARSE as f64, ty / COARSE as f64);
        let rho_c = std::f64::consts::PI / (3.0 * cx.max(cy));
        let (dx, dy) = (self.grid.dx, self.grid.dy);
        let tau = 2.0 * std::f64::consts::PI;
        // The kernel periodised with period `periods · T`, smoothed, at the
        // coarse points `m · (cx, cy)`, m in [0, side)².
        let periodic = |periods: usize| -> Vec<[f64; 18]> {
            let side = COARSE * periods;
            let signed = |k: usize| {
                if k > side / 2 {
                    k as f64 - side as f64
                } else {
                    k as f64
                }
            };
            let mut spec: Vec<[C; 18]> = (0..side * side)
                .map(|i| {
                    let (ky, kx) = (i / side, i % side);
                    let ex = tau * signed(kx) / (periods as f64 * tx);
                    let ey = tau * signed(ky) / (periods as f64 * ty);
                    let k = if kx == 0 && ky == 0 {
                        self.dc
                    } else {
                        let rho = ex.hypot(ey);
                        let b = sinc(0.5 * ex * dx)
                            * sinc(0.5 * ey * dy)
                            * (-(rho / rho_c).powi(2)).exp();
                        self.response.at(ex, ey, z) * C::new(b, 0.0)
                    };
                    std::array::from_fn(|c| k[(c / 3, c % 3)])
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
        let reach = COARSE as i64 / 2 + 3;
        let width = 2 * reach as usize + 1;
        let wrap = |m: i64, side: usize| m.rem_euclid(side as i64) as usize;
        let mut values = vec![[0.0; 18]; width * width];
        for my in -reach..=reach {
            for mx in -reach..=reach {
                let a = near[wrap(my, COARSE) * COARSE + wrap(mx, COARSE)];
                let side = COARSE * WIDER;
                let b = far[wrap(my, side) * side + wrap(mx, side)];
                values[(my + reach) as usize * width + (mx + reach) as usize] =
                    std::array::from_fn(|c| a[c] - b[c]);
            }
        }
        Images {
            cx,
            cy,
            reach,
            values,
        }
    }

    /// The three traction spectra of a state (`p`, `qx`, `qy` row major on
    /// the grid, Pa).
    pub fn tractions(&mut self, p: &[f64], qx: &[f64], qy: &[f64]) -> TractionSpectra {
        let len = self.fft.spectrum_len();
        let spectra = [qx, qy, p].map(|f| {
            let mut s = vec![C::default(); len];
            self.fft.forward_padded(f, &mut s);
            s
        });
        TractionSpectra {
            spectra,
            fields: [qx.to_vec(), qy.to_vec(), p.to_vec()],
        }
    }

    /// The stress on `plane` under `t` (18 spectral products, 6 inverse transforms).
    pub fn apply(&mut self, plane: &StressPlane, t: &TractionSpectra) -> StressField {
        let n = self.grid.n;
        let len = self.fft.spectrum_len();
        let mut spec = vec![C::default(); len];
        let components = std::array::from_fn(|c| {
            for (i, s) in spec.iter_mut().enumerate() {
                let k = &plane.kernel[i];
                *s = k[3 * c] * t.spectra[0][i]
                    + k[3 * c + 1] * t.spectra[1][i]
                    + k[3 * c + 2] * t.spectra[2][i];
            }
            let mut out = vec![0.0; n * n];
            self.fft.inverse_cropped(&mut spec, &mut out);
            out
        });
        let mut field = StressField {
            depth_m: plane.depth_m,
            components,
        };
        if plane.depth_m == 0.0 {
            surface_tractions_exact(&mut field, t, self);
        }
        field
    }

    /// The stress along one line of `plane` under `t`: the products and a
    /// partial inverse transform (a row of an x–z slice, a column of a y–z
    /// slice), without the full plane.
    pub fn apply_line(
        &mut self,
        plane: &StressPlane,
        t: &TractionSpectra,
        line: Line,
    ) -> StressField {
        let n = self.grid.n;
        let m = 2 * n;
        let h = m / 2 + 1;
        let tau = 2.0 * std::f64::consts::PI;
        // f(x, y) = (1/M²) Re Σ_{kx ≤ M/2} c_kx Σ_ky F e^{2πi(kx x + ky y)/M},
        // c = 1 at kx = 0 and M/2, 2 elsewhere.
        let weight = |kx: usize| if kx == 0 || kx == m / 2 { 1.0 } else { 2.0 };
        let product = |i: usize| -> [C; 6] {
            let k = &plane.kernel[i];
            std::array::from_fn(|c| {
                k[3 * c] * t.spectra[0][i]
                    + k[3 * c + 1] * t.spectra[1][i]
                    + k[3 * c + 2] * t.spectra[2][i]
            })
        };
        let mut sums = vec![[C::default(); 6]; m];
        match line {
            Line::Row(iy) => {
                for (kx, g) in sums.iter_mut().enumerate().take(h) {
                    for ky in 0..m {
                        let ph = C::from_polar(weight(kx), tau * (ky * iy % m) as f64 / m as f64);
                        for (a, v) in g.iter_mut().zip(product(kx * m + ky)) {
                            *a += v * ph;
                        }
                    }
                }
            }
            Line::Column(ix) => {
                for kx in 0..h {
                    let ph = C::from_polar(weight(kx), tau * (kx * ix % m) as f64 / m as f64);
                    for (ky, g) in sums.iter_mut().enumerate() {
                        for (a, v) in g.iter_mut().zip(product(kx * m + ky)) {
                            *a += v * ph;
                        }
                    }
                }
            }
        }
        let fft = FftPlanner::<f64>::new().plan_fft_inverse(m);
        let components = std::array::from_fn(|c| {
            let mut buf: Vec<C> = sums.iter().map(|g| g[c]).collect();
            fft.process(&mut buf);
            buf[..n].iter().map(|v| v.re / (m * m) as f64).collect()
        });
        let mut field = StressField {
            depth_m: plane.depth_m,
            components,
        };
        if plane.depth_m == 0.0 {
            // σ_iz = −t_i at the surface, cell by cell.
            let [qx, qy, p] = self.traction_fields(t);
            let pick = |f: &[f64], i: usize| match line {
                Line::Row(iy) => f[iy * n + i],
                Line::Column(ix) => f[i * n + ix],
            };
            for i in 0..n {
                field.components[2][i] = -pick(&p, i);
                field.components[3][i] = -pick(&qy, i);
                field.components[4][i] = -pick(&qx, i);
            }
        }
        field
    }

    /// `qx, qy, p` of a state.
    fn traction_fields(&self, t: &TractionSpectra) -> [Vec<f64>; 3] {
        t.fields.clone()
    }
}

/// The periodic images of a plane's kernel on coarse points, per component
/// (see [`StressPlan::images`]).
struct Images {
    cx: f64,
    cy: f64,
    reach: i64,
    /// `[my][mx]` for `m` in `[−reach, reach]`.
    values: Vec<[f64; 18]>,
}

impl Images {
    /// Component `c` at `(x, y)` (|x|, |y| ≤ T/2), 4-point Lagrange in each direction.
    fn at(&self, c: usize, x: f64, y: f64) -> f64 {
        let width = 2 * self.reach as usize + 1;
        let weights = |u: f64| -> (i64, [f64; 4]) {
            let i0 = u.floor();
            let f = u - i0;
            (
                i0 as i64,
                [
                    -f * (f - 1.0) * (f - 2.0) / 6.0,
                    (f + 1.0) * (f - 1.0) * (f - 2.0) / 2.0,
                    -(f + 1.0) * f * (f - 2.0) / 2.0,
                    (f + 1.0) * f * (f - 1.0) / 6.0,
                ],
            )
        };
        let (ix, wx) = weights(x / self.cx);
        let (iy, wy) = weights(y / self.cy);
        let mut acc = 0.0;
        for (j, wyj) in wy.iter().enumerate() {
            let row = (iy - 1 + j as i64 + self.reach) as usize * width;
            for (i, wxi) in wx.iter().enumerate() {
                let col = (ix - 1 + i as i64 + self.reach) as usize;
                acc += wyj * wxi * self.values[row + col][c];
            }
        }
        acc
    }
}

/// At the surface the stresses on the plane `z = 0` are the tractions
/// themselves: `σzz = −p`, `σxz = −qx`, `σyz = −qy` in each cell (z into
/// the body; the traction on the body is `−σ·e_z`). The transform of the
/// cell's step would converge to them only slowly.
fn surface_tractions_exact(field: &mut StressField, t: &TractionSpectra, plan: &mut StressPlan) {
    let [qx, qy, p] = plan.traction_fields(t);
    for i in 0..field.len() {
        field.components[2][i] = -p[i];
        field.components[3][i] = -qy[i];
        field.components[4][i] = -qx[i];
    }
}

fn check_depth(depth_m: f64) -> Result<(), SolverError> {
    if !depth_m.is_finite() || depth_m < 0.0 {
        return Err(SolverError::invalid(
            "depth",
            format!("a depth below the surface must be finite and ≥ 0, got {depth_m} m"),
        ));
    }
    Ok(())
}

/// The symmetric tensor of a Voigt 6-vector.
pub fn tensor(s: [f64; 6]) -> Matrix3<f64> {
    Matrix3::new(s[0], s[5], s[4], s[5], s[1], s[3], s[4], s[3], s[2])
}

/// Principal stresses, largest first (nalgebra's symmetric eigenvalues).
pub fn principal(s: [f64; 6]) -> [f64; 3] {
    let e = tensor(s).symmetric_eigenvalues();
    let mut v = [e[0], e[1], e[2]];
    v.sort_by(|a, b| b.total_cmp(a));
    v
}

/// Von Mises equivalent stress.
pub fn von_mises(s: [f64; 6]) -> f64 {
    let [xx, yy, zz, yz, xz, xy] = s;
    (0.5 * ((xx - yy).powi(2) + (yy - zz).powi(2) + (zz - xx).powi(2))
        + 3.0 * (yz * yz + xz * xz + xy * xy))
        .sqrt()
}

/// Tresca: the maximum shear stress `(σ₁ − σ₃)/2`.
pub fn tresca(s: [f64; 6]) -> f64 {
    let [a, _, c] = principal(s);
    0.5 * (a - c)
}

/// The largest principal stress `σ₁`.
pub fn max_principal(s: [f64; 6]) -> f64 {
    principal(s)[0]
}

/// A maximum of a field: its value and index.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Peak {
    /// The value.
    pub value: f64,
    /// The index of the point in its field.
    pub index: usize,
}

/// The largest value of `values` and where it is (the first of equals).
pub fn peak(values: &[f64]) -> Option<Peak> {
    values
        .iter()
        .enumerate()
        .fold(None, |best: Option<Peak>, (i, &v)| match best {
            Some(b) if b.value >= v => Some(b),
            _ if v.is_nan() => best,
            _ => Some(Peak { value: v, index: i }),
        })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expm3_of_a_jordan_block_is_exact() {
        // exp(λI + N) with N² = 0 is e^λ (I + N).
        let lam = C::new(-3.0, 0.7);
        let mut n = M3::zeros();
        n[(0, 2)] = C::new(2.5, -1.0);
        n[(1, 2)] = C::new(0.3, 0.2);
        let x = M3::identity() * lam + n;
        let want = (M3::identity() + n) * lam.exp();
        assert!((expm3(&x) - want).camax() < 1e-14 * want.camax());
    }

    #[test]
    fn isotropic_w_has_the_triple_root_minus_i_and_a_nilpotent_part() {
        let fe = crate::model::presets::material("Fe").unwrap();
        let (cv, iso) = (fe.stiffness(), fe.equivalent);
        let t = voigt_to_tensor(&cv);
        for th in [0.0, 0.3, 1.2, 2.5, 4.0] {
            let d = Direction::new(&t, &cv, th, isotropic_h(iso.shear(), iso.poisson, th));
            let nil = d.w + M3::identity() * C::new(0.0, 1.0);
            let scale = d.w.camax();
            assert!(
                (nil * nil).camax() < 1e-12 * scale * scale,
                "(W + iI)² at θ = {th}"
            );
        }
    }

    /// Interpolation between the tabulated directions against direct
    /// evaluation halfway between nodes (the worst place).
    #[test]
    fn interpolated_directions_equal_direct_evaluation() {
        for name in ["Fe", "Cu(111)"] {
            let mat = crate::model::presets::material(name).unwrap();
            let r = Response::of(&mat).unwrap();
            let cv = mat.stiffness();
            let t = voigt_to_tensor(&cv);
            let mut worst: f64 = 0.0;
            for k in 0..40 {
                let th = (k as f64 * 51.0 + 0.5) * std::f64::consts::TAU / STROH_DIRECTIONS as f64;
                let h = match &mat.elasticity {
                    Elasticity::Isotropic(i) => isotropic_h(i.shear(), i.poisson, th),
                    Elasticity::Anisotropic(_) => surface_compliance_tensor(
                        &t,
                        th,
                        crate::green::aniso::stroh::DEFAULT_OMEGA_POINTS,
                    ),
                };
                let exact = Direction::new(&t, &cv, th, h);
                let d = r.direction(th);
                let rel = |a: M63, b: M63| (a - b).camax() / b.camax();
                worst = worst
                    .max(rel(d.p, exact.p))
                    .max(rel(r.surface(th), exact.ph));
                worst = worst.max((d.w - exact.w).camax() / exact.w.camax());
                worst = worst.max((d.h - exact.h).camax() / exact.h.camax());
            }
            assert!(worst < 1e-9, "{name}: {worst:e}");
        }
    }

    #[test]
    fn stroh_roots_decay_into_the_body() {
        let cu = crate::model::presets::material("Cu(111)").unwrap();
        let r = Response::of(&cu).unwrap();
        for k in 0..16 {
            let d = r.direction(k as f64 * 0.4);
            for p in d.w.eigenvalues().expect("eigenvalues").iter() {
                assert!(p.im < -0.1, "root {p} does not decay");
            }
        }
    }
}
