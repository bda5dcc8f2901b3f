//! The DC-FFT elastic operator: kernel spectra of the nine influence components
//! on the `2N x 2N` wrap-around grid, applied to traction fields by zero-padded
//! real FFTs (Liu, Wang & Liu 2000). Knows nothing about contact conditions.
//!
//! Build once per (material, grid) — this is the expensive step — and apply
//! many times; `apply` allocates nothing.

pub use crate::base::grid::Grid;
use crate::base::parallel::Threads;
use crate::green::influence::Block;
use crate::operators::fft2::Fft2;
use num_complex::Complex64;

/// Displacement / traction component index: x, y (tangential) and z (normal).
pub const X: usize = 0;
/// y component.
pub const Y: usize = 1;
/// z component (normal; pressure for tractions).
pub const Z: usize = 2;

/// The kernel spectra an operator holds, on the `2N x 2N` wrap-around grid.
///
/// By reciprocity (Betti) the cell-integrated influence coefficients satisfy
/// `K_ji(r) = K_ij(−r)`, so the spectrum of `K_ji` is the complex conjugate of
/// that of `K_ij`, and `K_xx`, `K_yy`, `K_zz` (even in `r`) have real spectra:
/// three real and three complex half spectra describe all nine components.
#[derive(Clone, Debug, PartialEq)]
pub struct Spectra {
    /// Real spectra of `K_xx`, `K_yy`, `K_zz` (`M (M/2 + 1)` values each).
    pub diag: [Vec<f64>; 3],
    /// Spectra of `K_xy`, `K_xz`, `K_yz`.
    pub off: [Vec<Complex64>; 3],
}

impl Spectra {
    /// Values per spectrum on an `n x n` grid.
    pub fn len_for(n: usize) -> usize {
        2 * n * (n + 1)
    }

    /// Bytes held.
    pub fn bytes(&self) -> usize {
        self.diag.iter().map(|d| d.len() * 8).sum::<usize>()
            + self.off.iter().map(|o| o.len() * 16).sum::<usize>()
    }

    /// The spectra of the six stored components, complex and in the order
    /// of `STORED`; the diagonal ones are kept as their real parts.
    fn from_stored(six: Vec<Vec<Complex64>>) -> Spectra {
        let mut six = six.into_iter();
        let mut next = || six.next().expect("six components");
        let mut real = || next().iter().map(|z| z.re).collect::<Vec<f64>>();
        let diag = [real(), real(), real()];
        let off = [next(), next(), next()];
        Spectra { diag, off }
    }

    /// The tangential block only, from the complex spectra of `K_xx`, `K_yy`
    /// (kept as their real parts) and `K_xy`: what the operators of windows
    /// and coarse tangential levels hold.
    fn tangential(xx: Vec<Complex64>, yy: Vec<Complex64>, xy: Vec<Complex64>) -> Spectra {
        let re = |s: Vec<Complex64>| s.iter().map(|z| z.re).collect::<Vec<f64>>();
        Spectra {
            diag: [re(xx), re(yy), Vec::new()],
            off: [xy, Vec::new(), Vec::new()],
        }
    }

    fn component(&self, i: usize, j: usize) -> Kr<'_> {
        match (i, j) {
            _ if i == j => Kr::Re(&self.diag[i]),
            (0, 1) => Kr::Cx(&self.off[0]),
            (0, 2) => Kr::Cx(&self.off[1]),
            (1, 2) => Kr::Cx(&self.off[2]),
            (1, 0) => Kr::Cj(&self.off[0]),
            (2, 0) => Kr::Cj(&self.off[1]),
            _ => Kr::Cj(&self.off[2]),
        }
    }
}

/// One kernel component's spectrum as stored: real, complex, or the conjugate
/// of a stored complex one.
#[derive(Clone, Copy)]
enum Kr<'a> {
    Re(&'a [f64]),
    Cx(&'a [Complex64]),
    Cj(&'a [Complex64]),
}

impl<'a> Kr<'a> {
    /// The values `r` of this spectrum (one column of the transposed layout);
    /// the empty placeholder of an unused slot stays empty.
    fn part(self, r: std::ops::Range<usize>) -> Kr<'a> {
        fn cut<T>(v: &[T], r: std::ops::Range<usize>) -> &[T] {
            if v.is_empty() {
                v
            } else {
                &v[r]
            }
        }
        match self {
            Kr::Re(v) => Kr::Re(cut(v, r)),
            Kr::Cx(v) => Kr::Cx(cut(v, r)),
            Kr::Cj(v) => Kr::Cj(cut(v, r)),
        }
    }

    /// The whole spectrum as complex values, into `out`.
    fn write_complex(self, out: &mut [Complex64]) {
        match self {
            Kr::Re(v) => out
                .iter_mut()
                .zip(v)
                .for_each(|(z, &r)| *z = Complex64::new(r, 0.0)),
            Kr::Cx(v) => out.copy_from_slice(v),
            Kr::Cj(v) => out.iter_mut().zip(v).for_each(|(z, c)| *z = c.conj()),
        }
    }

    #[inline(always)]
    fn at(self, f: usize) -> Complex64 {
        match self {
            Kr::Re(v) => Complex64::new(v[f], 0.0),
            Kr::Cx(v) => v[f],
            Kr::Cj(v) => v[f].conj(),
        }
    }
}

/// The spectral products of one apply round, in place over the source
/// spectra: `(w0, w1) ← (Σ_s k[0][s] ŝ, Σ_s k[1][s] ŝ)` for `ns` sources
/// (`w0`, then `w1`) and `nd` destinations (one or two), one pass.
fn mix(k: &[[Kr; 2]; 2], ns: usize, nd: usize, w0: &mut [Complex64], w1: &mut [Complex64]) {
    match (ns, nd) {
        (1, 1) => match k[0][0] {
            Kr::Re(k00) => w0.iter_mut().zip(k00).for_each(|(a, k)| *a *= k),
            k00 => w0.iter_mut().enumerate().for_each(|(f, a)| *a *= k00.at(f)),
        },
        (1, _) => {
            let (k00, k10) = (k[0][0], k[1][0]);
            for (f, (a, b)) in w0.iter_mut().zip(w1.iter_mut()).enumerate() {
                *b = *a * k10.at(f);
                *a *= k00.at(f);
            }
        }
        (_, 1) => {
            let (k00, k01) = (k[0][0], k[0][1]);
            for (f, (a, b)) in w0.iter_mut().zip(w1.iter()).enumerate() {
                *a = *a * k00.at(f) + b * k01.at(f);
            }
        }
        _ if matches!(k, [[Kr::Re(_), Kr::Cx(_)], [Kr::Cj(_), Kr::Re(_)]]) => {
            // The symmetric blocks (tangential xx/xy/yy): `k10 = conj(k01)`.
            let [[Kr::Re(k00), Kr::Cx(k01)], [_, Kr::Re(k11)]] = *k else {
                unreachable!("matched above")
            };
            let it = w0.iter_mut().zip(w1.iter_mut());
            for ((a, b), ((&d0, &d1), &c)) in it.zip(k00.iter().zip(k11).zip(k01)) {
                let (x, y) = (*a, *b);
                *a = x * d0 + y * c;
                *b = x * c.conj() + y * d1;
            }
        }
        _ => {
            let [[k00, k01], [k10, k11]] = *k;
            for (f, (a, b)) in w0.iter_mut().zip(w1.iter_mut()).enumerate() {
                let (x, y) = (*a, *b);
                *a = x * k00.at(f) + y * k01.at(f);
                *b = x * k10.at(f) + y * k11.at(f);
            }
        }
    }
}

/// Smallest eigenvalue of the tangential symbol that
/// [`Operator::tangential_inverse`] inverts as it is, relative to a cell's
/// own compliance `K(0, 0)`; smaller ones are raised to it. The embedding's
/// kernel is zero on the row and column `N` that separate positive from
/// negative offsets, and its symbol is not positive definite: isotropic Fe
/// at 256² and 512² (Table 1(a)'s grids) has smallest eigenvalue −0.008
/// `K(0, 0)` and 170 / 341 frequencies below 0.25 `K(0, 0)` (Galerkin coarse
/// levels, 0.19–0.37 and positive). Inverted as they are, those modes made
/// the preconditioner useless: a five-increment history at 256² took 80
/// tangential iterations per increment with a floor of 1e-3, 15–16 with
/// 0.1, 0.25 or 0.4.
pub const INVERSE_FLOOR: f64 = 0.25;

/// The products of [`Operator::tangential_inverse`] over one column: `(w0,
/// w1) ← (K̂ + σ I)⁻¹ (w0, w1)` with `K̂ = [[K_xx, K_xy], [conj K_xy,
/// K_yy]]` per frequency, its eigenvalues raised to `floor` where below.
fn mix_inverse(
    k: &[[Kr; 2]; 2],
    [shift, floor]: [f64; 2],
    w0: &mut [Complex64],
    w1: &mut [Complex64],
) {
    // The tangential block as stored: real K_xx, K_yy and complex K_xy.
    // (Per call this costs 2.5× a product `mix`, for its division: 8 % of
    // a coupled 1024² active-set solve's profile either way.)
    let [[Kr::Re(kxx), Kr::Cx(kxy)], [_, Kr::Re(kyy)]] = *k else {
        unreachable!("the tangential block's spectra: real, complex, real")
    };
    let it = w0.iter_mut().zip(w1.iter_mut());
    for ((x, y), ((&kxx, &kyy), &b)) in it.zip(kxx.iter().zip(kyy).zip(kxy)) {
        let a = kxx + shift;
        let d = kyy + shift;
        let b2 = b.norm_sqr();
        // Both eigenvalues ≥ floor ⟺ a ≥ floor and (a − floor)(d − floor) ≥
        // |b|²: the usual case, without a square root.
        let (i00, i01, i11) = if a >= floor && (a - floor) * (d - floor) >= b2 {
            let r = 1.0 / (a * d - b2);
            (d * r, -b * r, a * r)
        } else {
            // (1/λ₁') P₁ + (1/λ₂') P₂ with P₁ = (K − λ₂)/(λ₁ − λ₂), P₂ = I − P₁.
            let mean = 0.5 * (a + d);
            let disc = (0.25 * (a - d) * (a - d) + b2).sqrt();
            let (l1, l2) = (mean + disc, mean - disc);
            let (r1, r2) = (1.0 / l1.max(floor), 1.0 / l2.max(floor));
            if disc > 0.0 {
                let c = (r1 - r2) / (l1 - l2);
                (r2 + c * (a - l2), c * b, r2 + c * (d - l2))
            } else {
                (r1, Complex64::default(), r1)
            }
        };
        let (u, v) = (*x, *y);
        *x = u * i00 + v * i01;
        *y = u * i01.conj() + v * i11;
    }
}

/// `Σ_f conj(â, b̂) K̂ (â, b̂)ᵀ` over one column of the symmetric tangential
/// block's spectra: `K_xx |â|² + K_yy |b̂|² + 2 Re(conj(â) K_xy b̂)`. Four
/// partial sums, so the additions do not wait on each other.
fn energy_column(a: &[Complex64], b: &[Complex64], d0: &[f64], d1: &[f64], c: &[Complex64]) -> f64 {
    let term = |f: usize| {
        let (a, b, c) = (a[f], b[f], c[f]);
        let (sr, si) = (a.re * b.re + a.im * b.im, a.re * b.im - a.im * b.re);
        d0[f] * (a.re * a.re + a.im * a.im)
            + d1[f] * (b.re * b.re + b.im * b.im)
            + 2.0 * (c.re * sr - c.im * si)
    };
    let len = a.len();
    let mut acc = [0.0; 4];
    let body = len / 4 * 4;
    for f in (0..body).step_by(4) {
        for (k, s) in acc.iter_mut().enumerate() {
            *s += term(f + k);
        }
    }
    let tail: f64 = (body..len).map(term).sum();
    acc.iter().sum::<f64>() + tail
}

/// Every stored component of `s` put into the split order of a column pass
/// (`to_split`) or back into natural order.
fn split_order(fft: &Fft2, s: &mut Spectra, to_split: bool) {
    for d in &mut s.diag {
        fft.reorder_columns(d, to_split);
    }
    for o in &mut s.off {
        fft.reorder_columns(o, to_split);
    }
}

/// The `(i, j)` components stored, in the order of a build: diagonal, then
/// `xy`, `xz`, `yz`.
const STORED: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

/// Kernel spectra and FFT plans for one material on one grid.
pub struct Operator {
    grid: Grid,
    fft: Fft2,
    spectra: Spectra,
    /// Two compact work spectra ([`Fft2::compact_len`]): the sources of an
    /// apply round, overwritten in place by the destinations' spectra.
    work: [Vec<Complex64>; 2],
    /// One value per column of a column pass (the energy product's terms).
    column_values: Vec<f64>,
    tangential_bound: f64,
    tangential_self: f64,
    /// `K_ii(0, 0)` for i = x, y, z: a whole cell's own compliance.
    self_compliance: [f64; 3],
    /// The cells an edge cuts, if the case's surface has any.
    cut: Option<CutCells>,
}

/// How much more compliant under its own load a cell is when only the
/// fraction `cover` of it carries the load: `(1 + β (1 − cover)) / cover`
/// with β = [`CUT_CELL_BETA`]. At β = 0 the covered part's pressure
/// (`t / cover`) meets a whole cell's compliance; β makes a cut cell's
/// stiffness move with its cover so that a straight-edged punch's stiffness
/// moves linearly, not in a wave, as its edge crosses a cell (the
/// consistency condition; measured in `docs/physics-choices.md`). Covers
/// below [`CUT_COVER_FLOOR`] take the factor of the floor.
pub fn cut_self_factor(cover: f64) -> f64 {
    let cover = cover.max(CUT_COVER_FLOOR);
    (1.0 + CUT_CELL_BETA * (1.0 - cover)) / cover
}

/// The smallest cover whose own compliance [`cut_self_factor`] follows:
/// a sliver cell (2–10 % covered) gets the factor of 10 % (13.6) instead of
/// up to 70. Such a cell carries almost nothing, but its 1/cover compliance
/// made the tangential conjugate gradient's stick block ill-conditioned:
/// the quick sweep's patterned cases took 4946 tangential iterations (2438
/// with whole-cell sampling), with the floor 2738, its wall time +48 % →
/// +24 % against whole-cell sampling. The plateau ladders keep their first
/// order (orders 0.93–1.12, finest error 0.088 % against 0.093 % without
/// the floor; `solver/tests/island_edge.rs`). At 0.2 the orders scatter
/// (0.08–1.8 on the square plateau).
pub const CUT_COVER_FLOOR: f64 = 0.1;

/// β of [`cut_self_factor`]: the factor that keeps a straight punch edge's
/// stiffness linear in its position within a cell, measured at 3 to 24 cells
/// per half-width (`cover · factor − 1 = β (1 − cover)` with β from 0.30 to
/// 0.45, rising slowly with the resolution); 0.4 is the middle of that range.
pub const CUT_CELL_BETA: f64 = 0.4;

/// The cells of a grid that a pattern's edge cuts ([`crate::Surface::cover`]):
/// each carries its cell-mean traction on the covered part only, and is more
/// compliant under its own load by [`cut_self_factor`]. The operator adds
/// `K_ii(0, 0) (factor − 1) t_i` to each cut cell's displacement.
#[derive(Clone, Debug)]
struct CutCells {
    /// The cover of every cell (1 where whole), row-major; `None` on a
    /// coarse level, whose extra diagonal is the fine one's restriction.
    cover: Option<Vec<f64>>,
    /// The cut cells and their extra factor (`factor − 1`).
    extra: Vec<(usize, f64)>,
}

impl CutCells {
    fn new(cover: &[f64]) -> Self {
        let extra = cover
            .iter()
            .enumerate()
            .filter(|(_, &c)| c < 1.0)
            .map(|(i, &c)| (i, cut_self_factor(c) - 1.0))
            .collect();
        CutCells {
            cover: Some(cover.to_vec()),
            extra,
        }
    }

    /// The largest extra factor (0 without cut cells).
    fn largest(&self) -> f64 {
        self.extra.iter().fold(0.0, |m, &(_, e)| m.max(e))
    }
}

/// Maximum over frequencies of the largest eigenvalue of the Hermitian
/// 2x2 tangential symbol `[[K_xx, K_xy], [conj K_xy, K_yy]]` of the circulant
/// embedding: an upper bound of the tangential block's largest eigenvalue.
fn tangential_symbol_max(s: &Spectra) -> f64 {
    let (kxx, kyy, kxy) = (&s.diag[X], &s.diag[Y], &s.off[0]);
    let mut best = 0.0_f64;
    for ((&a, &d), b) in kxx.iter().zip(kyy).zip(kxy) {
        let mean = 0.5 * (a + d);
        let disc = (0.25 * (a - d) * (a - d) + b.norm_sqr()).sqrt();
        best = best.max(mean + disc);
    }
    best
}

/// The mean of `K_xx(0, 0)` and `K_yy(0, 0)`, a cell's tangential
/// displacement under a unit traction on itself: the mean of the two spectra
/// over the full `m x m` grid (the inner columns of a half spectrum stand for
/// their mirrors too).
fn tangential_self(s: &Spectra, m: usize) -> f64 {
    let mut sum = 0.0;
    for (kx, (a, d)) in s.diag[X].chunks(m).zip(s.diag[Y].chunks(m)).enumerate() {
        let weight = if kx == 0 || 2 * kx == m { 1.0 } else { 2.0 };
        let col: f64 = a.iter().zip(d).map(|(a, d)| a + d).sum();
        sum += weight * col;
    }
    0.5 * sum / (m as f64 * m as f64)
}

/// `K_ii(0, 0)` of one diagonal component, the mean of its spectrum over the
/// full `m x m` grid as in [`tangential_self`] (0 for a component not held).
fn self_compliance(d: &[f64], m: usize) -> f64 {
    let mut sum = 0.0;
    for (kx, col) in d.chunks(m).enumerate() {
        let weight = if kx == 0 || 2 * kx == m { 1.0 } else { 2.0 };
        sum += weight * col.iter().sum::<f64>();
    }
    sum / (m as f64 * m as f64)
}

/// The kernel values of row `iy` of the `2N x 2N` wrap-around grid
/// (`blocks[ix]`, zero on the row and column `N` that separate positive
/// from negative offsets).
fn kernel_row(grid: Grid, iy: usize, cell: &impl Fn(f64, f64) -> Block, blocks: &mut [Block]) {
    let n = grid.n;
    let m = 2 * n;
    let offset = |i: usize| if i < n { i as f64 } else { i as f64 - m as f64 };
    for (ix, b) in blocks.iter_mut().enumerate() {
        *b = if iy == n || ix == n {
            [[0.0; 3]; 3]
        } else {
            cell(offset(ix) * grid.dx, offset(iy) * grid.dy)
        };
    }
}

impl Operator {
    /// Builds the kernel spectra from a cell-influence function
    /// `cell(x, y) -> K(x, y)` (offsets of the observation point from the
    /// loaded cell), row by row: no real-space table is ever held whole.
    pub fn build(grid: Grid, cell: impl Fn(f64, f64) -> Block) -> Self {
        let n = grid.n;
        let m = 2 * n;
        let mut fft = Fft2::new(n);
        let slen = fft.spectrum_len();
        let mut full: Vec<Vec<Complex64>> = (0..STORED.len())
            .map(|_| vec![Complex64::default(); slen])
            .collect();
        let mut blocks = vec![[[0.0; 3]; 3]; m];
        let mut row = vec![0.0; m];
        for iy in 0..m {
            crate::base::progress::tick();
            kernel_row(grid, iy, &cell, &mut blocks);
            for (&(i, j), out) in STORED.iter().zip(full.iter_mut()) {
                for (r, b) in row.iter_mut().zip(&blocks) {
                    *r = b[i][j];
                }
                fft.forward_row_into(iy, &row, out);
            }
        }
        for s in full.iter_mut() {
            fft.forward_columns(s);
        }
        Self::with_fft(grid, fft, Spectra::from_stored(full))
    }

    /// [`Operator::build`] for a cell influence that is exactly even or odd in x
    /// and y with the parities of [`crate::green::influence::mirror_sign`]: `cell` is evaluated only at
    /// offsets `x, y ≥ 0` (the `N x N` quadrant of the `2N x 2N` wrap-around
    /// grid, a quarter of the `(2N − 1)²` evaluations of the direct build), and
    /// each quadrant row gives the rows of `+y` and `−y`, mirrored in x with the
    /// components' signs. The rows handed to the transforms are those of the
    /// direct build, to the bit, so the spectra are too (tested). Isotropic
    /// closed forms at 2048²: 12 s in the direct build, dominated by the
    /// `ln`/`atan` of the corner sums.
    pub fn build_mirrored(grid: Grid, cell: impl Fn(f64, f64) -> Block) -> Self {
        let n = grid.n;
        let m = 2 * n;
        let mut fft = Fft2::new(n);
        let slen = fft.spectrum_len();
        let mut full: Vec<Vec<Complex64>> = (0..STORED.len())
            .map(|_| vec![Complex64::default(); slen])
            .collect();
        let mut quad = vec![[[0.0; 3]; 3]; n];
        let mut row = vec![0.0; m];
        for oy in 0..=n {
            if oy == n {
                crate::base::progress::tick();
                // The row separating positive from negative offsets is zero.
                row.fill(0.0);
                for out in full.iter_mut() {
                    fft.forward_row_into(n, &row, out);
                }
                continue;
            }
            for (ox, b) in quad.iter_mut().enumerate() {
                *b = cell(ox as f64 * grid.dx, oy as f64 * grid.dy);
            }
            let rows = [(oy, false)]
                .into_iter()
                .chain((oy > 0).then_some((m - oy, true)));
            for (iy, neg_y) in rows {
                // One tick per row of the wrap-around grid, as in the direct build.
                crate::base::progress::tick();
                for (&(i, j), out) in STORED.iter().zip(full.iter_mut()) {
                    let (s, sx) = (
                        crate::green::influence::mirror_sign(i, j, false, neg_y),
                        crate::green::influence::mirror_sign(i, j, true, neg_y),
                    );
                    for (ix, r) in row.iter_mut().enumerate() {
                        *r = match ix.cmp(&n) {
                            std::cmp::Ordering::Less => s * quad[ix][i][j],
                            std::cmp::Ordering::Equal => 0.0,
                            std::cmp::Ordering::Greater => sx * quad[m - ix][i][j],
                        };
                    }
                    fft.forward_row_into(iy, &row, out);
                }
            }
        }
        for s in full.iter_mut() {
            fft.forward_columns(s);
        }
        Self::with_fft(grid, fft, Spectra::from_stored(full))
    }

    /// The nine real-space kernels on the `2N x 2N` wrap-around grid
    /// (`tables[3 i + j]`, row-major), for tests and inspection.
    pub fn tables(grid: Grid, cell: impl Fn(f64, f64) -> Block) -> Vec<Vec<f64>> {
        let m = 2 * grid.n;
        let mut real: Vec<Vec<f64>> = (0..9).map(|_| vec![0.0; m * m]).collect();
        let mut blocks = vec![[[0.0; 3]; 3]; m];
        for iy in 0..m {
            kernel_row(grid, iy, &cell, &mut blocks);
            for (c, arr) in real.iter_mut().enumerate() {
                for (v, b) in arr[iy * m..(iy + 1) * m].iter_mut().zip(&blocks) {
                    *v = b[c / 3][c % 3];
                }
            }
        }
        real
    }

    /// Builds the operator from the nine real-space kernels of
    /// [`Operator::tables`] (only `xx, yy, zz, xy, xz, yz` are used; the
    /// others follow by reciprocity).
    pub fn from_tables(grid: Grid, real: &[Vec<f64>]) -> Self {
        let mut fft = Fft2::new(grid.n);
        let slen = fft.spectrum_len();
        let six = STORED
            .iter()
            .map(|&(i, j)| {
                let mut s = vec![Complex64::default(); slen];
                fft.forward_full(&real[3 * i + j], &mut s);
                s
            })
            .collect();
        Self::with_fft(grid, fft, Spectra::from_stored(six))
    }

    /// An operator holding `spectra` (e.g. loaded from a store); `None` when
    /// their lengths do not fit the grid.
    pub fn from_spectra(grid: Grid, spectra: Spectra) -> Option<Self> {
        let len = Spectra::len_for(grid.n);
        let fits = spectra.diag.iter().all(|d| d.len() == len)
            && spectra.off.iter().all(|o| o.len() == len);
        fits.then(|| Self::with_fft(grid, Fft2::new(grid.n), spectra))
    }

    /// An operator from its parts; work spectra and the tangential bound
    /// follow from them.
    fn with_fft(grid: Grid, fft: Fft2, mut spectra: Spectra) -> Self {
        let tangential_bound = tangential_symbol_max(&spectra);
        let tangential_self = tangential_self(&spectra, fft.padded_len());
        let self_compliance = spectra
            .diag
            .each_ref()
            .map(|d| self_compliance(d, fft.padded_len()));
        split_order(&fft, &mut spectra, true);
        Operator {
            grid,
            tangential_bound,
            tangential_self,
            self_compliance,
            cut: None,
            spectra,
            work: std::array::from_fn(|_| vec![Complex64::default(); fft.compact_len()]),
            column_values: vec![0.0; fft.padded_len() / 2 + 1],
            fft,
        }
    }

    /// This operator on transforms with split columns or not (see
    /// [`crate::operators::fft2`]), whatever the grid's side: for tests of both paths.
    #[cfg(test)]
    fn with_split_columns(mut self, split: bool) -> Self {
        let spectra = self.with_spectra(Spectra::clone);
        let mut fft = Fft2::padded_with_split(self.grid.n, split);
        fft.set_threads(self.fft.threads());
        Self::with_fft(self.grid, fft, spectra)
    }

    /// The real table of component `(i, j)` on the `2N x 2N` wrap-around grid
    /// (layout of [`Operator::tables`]), by one inverse transform of its
    /// stored spectrum: what Galerkin coarse levels are made from.
    pub fn table(&mut self, i: usize, j: usize) -> Vec<f64> {
        let mut spec = vec![Complex64::default(); self.fft.spectrum_len()];
        let m = self.fft.padded_len();
        let mut table = vec![0.0; m * m];
        self.table_into(i, j, &mut spec, &mut table);
        table
    }

    /// [`Operator::table`] into `table`, with `spec` (a spectrum's length)
    /// as scratch; the stored spectrum is put back into natural order first.
    fn table_into(&mut self, i: usize, j: usize, spec: &mut [Complex64], table: &mut [f64]) {
        self.spectra.component(i, j).write_complex(spec);
        self.fft.to_natural_order(spec);
        self.fft.inverse_full(spec, table);
    }

    /// An operator of the tangential block only, from the real tables of
    /// `K_xx`, `K_yy` and `K_xy` (layout of [`Operator::tables`]): what the
    /// tangential solver's coarse levels need. The normal and coupling
    /// components are left empty (no memory): only
    /// [`Operator::tangential`], [`Operator::tangential_add`] and
    /// [`Operator::tangential_energy`] may be used on it.
    pub fn tangential_from_tables(grid: Grid, xx: &[f64], yy: &[f64], xy: &[f64]) -> Self {
        let mut fft = Fft2::new(grid.n);
        let slen = fft.spectrum_len();
        let mut spec = |t: &[f64]| {
            let mut s = vec![Complex64::default(); slen];
            fft.forward_full(t, &mut s);
            s
        };
        let spectra = Spectra::tangential(spec(xx), spec(yy), spec(xy));
        Self::with_fft(grid, fft, spectra)
    }

    /// The tangential block (xx, yy, xy) of the operator of an `nw x nw`
    /// window of this grid (same cells, `nw ≤ N`): the same influence
    /// coefficients for offsets below `nw` cells, on the smaller `2nw x 2nw`
    /// wrap-around grid, taken from this operator's spectra by one inverse
    /// transform per component (no re-integration). Tractions that vanish
    /// outside the window (on the contact cells) are applied exactly by it,
    /// and its transforms cost `(nw/N)²` of this grid's. Like the coarse
    /// tangential levels, it has no normal components.
    pub fn window_operator(&mut self, nw: usize) -> Operator {
        assert!(
            nw >= 1 && nw <= self.grid.n,
            "window {nw} on a {} grid",
            self.grid.n
        );
        let grid = Grid { n: nw, ..self.grid };
        let m = self.fft.padded_len();
        let mw = 2 * nw;
        let mut fft = Fft2::new(nw);
        fft.set_threads(self.fft.threads());
        // One component at a time: its real-space table on this grid (an
        // inverse transform of the stored spectrum), the window's offsets
        // (row and column `nw` zero, as in a build) into the window's spectrum.
        let mut spec = vec![Complex64::default(); self.fft.spectrum_len()];
        let mut table = vec![0.0; m * m];
        let mut row = vec![0.0; mw];
        let source = |i: usize| if i < nw { i } else { i + m - mw };
        // Only the tangential block: a window operator applies tractions
        // (the tangential solver's; the coupling terms come from the whole
        // grid's operator), and the other three components were 56 % of its
        // bytes.
        let [xx, yy, xy] = [(X, X), (Y, Y), (X, Y)].map(|(i, j)| {
            crate::base::progress::tick();
            self.table_into(i, j, &mut spec, &mut table);
            let mut w = vec![Complex64::default(); fft.spectrum_len()];
            for iy in 0..mw {
                for (ix, r) in row.iter_mut().enumerate() {
                    *r = if iy == nw || ix == nw {
                        0.0
                    } else {
                        table[source(iy) * m + source(ix)]
                    };
                }
                fft.forward_row_into(iy, &row, &mut w);
            }
            fft.forward_columns(&mut w);
            w
        });
        drop((spec, table));
        Self::with_fft(grid, fft, Spectra::tangential(xx, yy, xy))
    }

    /// Frees the two work spectra until the next application (which makes
    /// them again): for operators used in bursts, such as the coarse levels
    /// of a coarse-to-fine start (at 2048², 34 MB held between cases by the
    /// whole grid's tangential levels alone).
    pub fn release_work(&mut self) {
        self.work = Default::default();
    }

    /// The work spectra, made again if [`Operator::release_work`] freed them.
    fn ensure_work(&mut self) {
        let len = self.fft.compact_len();
        for w in &mut self.work {
            crate::operators::fft2::ensure_len(w, len);
        }
    }

    /// Runs the transforms and spectral products on `threads` from now on
    /// (the results do not change, see [`crate::base::parallel`]); window
    /// operators made later inherit them.
    pub fn set_threads(&mut self, threads: &Threads) {
        self.fft.set_threads(threads);
    }

    /// The threads this operator runs on.
    pub fn threads(&self) -> &Threads {
        self.fft.threads()
    }

    /// `f` of the kernel spectra held, in natural order (what a kernel
    /// store persists; the operator holds them in the split order of its
    /// column passes, see [`crate::operators::fft2`], and puts them back in place
    /// around the call instead of copying them).
    pub fn with_spectra<R>(&mut self, f: impl FnOnce(&Spectra) -> R) -> R {
        split_order(&self.fft, &mut self.spectra, false);
        let r = f(&self.spectra);
        split_order(&self.fft, &mut self.spectra, true);
        r
    }

    /// Sets the cover of the cells for the solves that follow (the case's
    /// [`crate::Surface::cover`]): cut cells (cover < 1) get their own
    /// compliance times `cover^(-1/2)` in every application, energy product
    /// and tangential bound. `None` (whole cells) restores the bare
    /// convolution, to the bit.
    pub fn set_cover(&mut self, cover: Option<&[f64]>) {
        if let Some(c) = cover {
            assert_eq!(c.len(), self.grid.len(), "one cover per cell");
        }
        self.cut = cover.map(CutCells::new).filter(|c| !c.extra.is_empty());
    }

    /// The cover set by [`Operator::set_cover`], if any cell is cut.
    pub fn cover(&self) -> Option<&[f64]> {
        self.cut.as_ref().and_then(|c| c.cover.as_deref())
    }

    /// The cut cells' extra own compliance, m/Pa, as the mean of the two
    /// tangential components: `(cell, K(0,0) (factor − 1))`; `None` without
    /// cut cells (what a coarse level restricts, [`Operator::set_extra_diagonal`]).
    pub fn extra_diagonal(&self) -> Option<Vec<(usize, f64)>> {
        let cut = self.cut.as_ref()?;
        Some(
            cut.extra
                .iter()
                .map(|&(c, e)| (c, e * self.tangential_self))
                .collect(),
        )
    }

    /// A coarse level's extra diagonal (m/Pa per cell, the Galerkin
    /// restriction of the fine grid's cut cells), or none: added to its
    /// tangential components as a cut cell's is. Results of a fine solve do
    /// not depend on it (a coarse level only starts the fine solve).
    pub fn set_extra_diagonal(&mut self, extra: Option<&[(usize, f64)]>) {
        let k = self.tangential_self;
        self.cut = extra
            .filter(|e| !e.is_empty() && k > 0.0)
            .map(|e| CutCells {
                cover: None,
                extra: e.iter().map(|&(c, d)| (c, d / k)).collect(),
            });
    }

    /// Multiplies the cut cells' entries of `v` by `factor^(-1/2)` (their
    /// own compliance relative to a whole cell's, [`cut_self_factor`]): the
    /// symmetric Jacobi scaling that a preconditioner of the bare
    /// convolution needs around it to see the cut cells' larger diagonal.
    /// Nothing without cut cells.
    pub fn scale_cut(&self, v: &mut [f64]) {
        if let Some(cut) = &self.cut {
            for &(c, e) in &cut.extra {
                v[c] /= (1.0 + e).sqrt();
            }
        }
    }

    /// Adds the cut cells' extra own compliance to the destinations whose
    /// component has a source of the same component.
    fn add_cut(&self, src: &[(usize, &[f64])], dst: &mut [(usize, &mut [f64])]) {
        let Some(cut) = &self.cut else { return };
        for (i, u) in dst.iter_mut() {
            let Some((_, t)) = src.iter().find(|(j, _)| j == i) else {
                continue;
            };
            let k = self.self_compliance[*i];
            for &(c, e) in &cut.extra {
                u[c] += k * e * t[c];
            }
        }
    }

    /// The grid this operator was built for.
    pub fn grid(&self) -> Grid {
        self.grid
    }

    /// `u_i = Σ_j K_ij * t_j` for the listed source components `src = [(j, t_j)]`
    /// and destination components `dst = [(i, u_i)]` (each `n x n`, row-major
    /// `[iy][ix]`, at most three of each). Destinations are overwritten.
    pub fn apply(&mut self, src: &[(usize, &[f64])], dst: &mut [(usize, &mut [f64])]) {
        assert!(src.len() <= 3 && dst.len() <= 3, "at most three components");
        // Rounds of at most two sources and two destinations; a third source
        // is added by a second round, a third destination costs its sources'
        // transforms again (only the final displacements of a case need either).
        for (r, s) in src.chunks(2).enumerate() {
            for d in dst.chunks_mut(2) {
                self.round(s, d, r > 0);
            }
        }
    }

    /// `u_i (+)= Σ_j K_ij * t_j` for one or two sources and destinations.
    ///
    /// The row transforms run over whole fields; the column stage runs one
    /// column (`M` values) at a time through forward transforms, spectral
    /// products and inverse transforms while it is in cache, instead of three
    /// passes over the work spectra.
    fn round(&mut self, src: &[(usize, &[f64])], dst: &mut [(usize, &mut [f64])], add: bool) {
        let threads = self.fft.threads().clone();
        threads.install(|| self.round_stages(src, dst, add, None));
    }

    /// The stages of [`Operator::round`].
    fn round_stages(
        &mut self,
        src: &[(usize, &[f64])],
        dst: &mut [(usize, &mut [f64])],
        add: bool,
        inverse: Option<[f64; 2]>,
    ) {
        self.ensure_work();
        let [w0, w1] = &mut self.work;
        for ((_, t), w) in src.iter().zip([&mut *w0, &mut *w1]) {
            self.fft.forward_rows_padded(t, w);
        }
        let mut k = [[Kr::Re(&[]); 2]; 2];
        for (kd, (i, _)) in k.iter_mut().zip(dst.iter()) {
            for (kds, &(j, _)) in kd.iter_mut().zip(src) {
                *kds = self.spectra.component(*i, j);
            }
        }
        let m = self.fft.padded_len();
        let (ns, nd) = (src.len(), dst.len());
        let two = ns > 1 || nd > 1;
        self.fft.column_pass(
            (w0, w1),
            (two, true),
            &mut self.column_values,
            |kx, c0, c1, cols| {
                cols.forward(c0);
                if ns > 1 {
                    cols.forward(c1);
                }
                let r = kx * m..(kx + 1) * m;
                let kc = k.map(|row| row.map(|kr| kr.part(r.clone())));
                {
                    let _span = crate::operators::fft2::timing::Span::product();
                    match inverse {
                        None => mix(&kc, ns, nd, c0, c1),
                        Some(shift) => mix_inverse(&kc, shift, c0, c1),
                    }
                }
                cols.inverse(c0);
                if nd > 1 {
                    cols.inverse(c1);
                }
                0.0
            },
        );
        for ((_, u), w) in dst.iter_mut().zip([w0, w1]) {
            self.fft.inverse_rows_cropped(w, u, add);
        }
        if inverse.is_none() {
            self.add_cut(src, dst);
        }
    }

    /// The elastic energy product `⟨t, K t⟩ = Σ_cells t · (K t)` of a shear
    /// field `t = (tx, ty)`, from its spectra by Parseval: two forward
    /// transforms and no inverse (`t` is zero outside the grid, so the sum
    /// over the padded grid is the sum over the cells). Each column's products
    /// are summed as soon as its transforms are done.
    pub fn tangential_energy(&mut self, tx: &[f64], ty: &[f64]) -> f64 {
        let threads = self.fft.threads().clone();
        threads.install(|| self.energy_stages(tx, ty))
    }

    /// The stages of [`Operator::tangential_energy`].
    fn energy_stages(&mut self, tx: &[f64], ty: &[f64]) -> f64 {
        self.ensure_work();
        let [w0, w1] = &mut self.work;
        self.fft.forward_rows_padded(tx, w0);
        self.fft.forward_rows_padded(ty, w1);
        let m = self.fft.padded_len();
        let (kxx, kyy, kxy) = (
            &self.spectra.diag[X],
            &self.spectra.diag[Y],
            &self.spectra.off[0],
        );
        // Each column's term on the threads, their sum in column order here.
        self.fft.column_pass(
            (w0, w1),
            (true, false),
            &mut self.column_values,
            |kx, c0, c1, cols| {
                let col = kx * m..(kx + 1) * m;
                cols.forward(c0);
                cols.forward(c1);
                // A half spectrum: columns 0 < kx < M/2 stand for their mirror too.
                let weight = if kx == 0 || 2 * kx == m { 1.0 } else { 2.0 };
                let _span = crate::operators::fft2::timing::Span::product();
                weight * energy_column(c0, c1, &kxx[col.clone()], &kyy[col.clone()], &kxy[col])
            },
        );
        let mut sum = 0.0;
        for v in &self.column_values {
            sum += v;
        }
        let mut energy = sum / (m as f64 * m as f64);
        if let Some(cut) = &self.cut {
            let [kx, ky, _] = self.self_compliance;
            for &(c, e) in &cut.extra {
                energy += e * (kx * tx[c] * tx[c] + ky * ty[c] * ty[c]);
            }
        }
        energy
    }

    /// Upper bound of the largest eigenvalue of the tangential block (m/Pa),
    /// computed once at construction (the tangential solver's step is its inverse).
    pub fn tangential_bound(&self) -> f64 {
        match &self.cut {
            None => self.tangential_bound,
            Some(cut) => {
                let [kx, ky, _] = self.self_compliance;
                self.tangential_bound + cut.largest() * kx.max(ky)
            }
        }
    }

    /// The mean of `K_xx` and `K_yy` at zero offset (m/Pa): a cell's own
    /// tangential compliance, the diagonal of the tangential block (computed
    /// once at construction).
    pub fn tangential_self(&self) -> f64 {
        self.tangential_self
    }

    /// `(ux, uy) = crop (K̂ + σ I)⁻¹ pad (qx, qy)`: the inverse of the
    /// `2N`-circulant embedding of the tangential block, shifted by `σ`
    /// (m/Pa) on its diagonal, applied to the zero-padded field and read
    /// back on the grid (CONTACT's `fft_makePrec`; Zhao, Vollebregt &
    /// Oosterlee 2015). The 2x2 Hermitian symbol is inverted per frequency
    /// as the column pass reaches it (no stored spectra); eigenvalues below
    /// [`INVERSE_FLOOR`] times a cell's own compliance are raised to it, so
    /// that the result is symmetric positive definite whatever the
    /// embedding's spectrum. The cut cells' extra compliance is not in it:
    /// the caller scales around it ([`Operator::scale_cut`]). The
    /// tangential solver's preconditioner.
    pub fn tangential_inverse(
        &mut self,
        shift: f64,
        (qx, qy): (&[f64], &[f64]),
        (ux, uy): (&mut [f64], &mut [f64]),
    ) {
        let floor = INVERSE_FLOOR * self.tangential_self;
        let threads = self.fft.threads().clone();
        threads.install(|| {
            self.round_stages(
                &[(X, qx), (Y, qy)],
                &mut [(X, ux), (Y, uy)],
                false,
                Some([shift, floor]),
            )
        });
    }

    /// Normal displacement under pressure only: `uz = K_zz * p`.
    pub fn normal(&mut self, p: &[f64], uz: &mut [f64]) {
        self.apply(&[(Z, p)], &mut [(Z, uz)]);
    }

    /// Adds the tangential displacements of a shear field to `(ux, uy)`
    /// (accumulated in the inverse transforms, no extra pass).
    pub fn tangential_add(&mut self, qx: &[f64], qy: &[f64], ux: &mut [f64], uy: &mut [f64]) {
        self.round(&[(X, qx), (Y, qy)], &mut [(X, ux), (Y, uy)], true);
    }

    /// Tangential displacements under shear only.
    pub fn tangential(&mut self, qx: &[f64], qy: &[f64], ux: &mut [f64], uy: &mut [f64]) {
        self.apply(&[(X, qx), (Y, qy)], &mut [(X, ux), (Y, uy)]);
    }
}

#[cfg(test)]
mod tests;
