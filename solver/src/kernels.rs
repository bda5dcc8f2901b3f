//! Keeping kernels resident: the identity of a kernel (material constants and
//! grid), the per-kernel bundle a process keeps (the operator plus the
//! solvers' caches made for it), and the cache of bundles, optionally backed
//! by a persistent [`KernelStore`] supplied by the caller (the worker's files).
//! Builds operators; solves nothing.

use std::collections::HashMap;

use num_complex::Complex64;

use crate::error::SolverError;
use crate::fft2::Fft2;
use crate::grid::Grid;
use crate::influence::{mirror_sign, Block};
use crate::material::Material;
use crate::normal::{solve_normal, NormalCache, NormalProblem, NormalSolution};
use crate::operator::{Operator, Spectra};
use crate::spec::CaseSpec;
use crate::tangential::{solve_tangential, TangentialProblem, TangentialSolution};
use crate::window::WindowCache;

/// Identity of a kernel: material name and constants, cells per side and
/// cell size. Its text (`name|n|dx|C11,…`) names an entry of a store.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct KernelKey(String);

impl KernelKey {
    /// The kernel a case needs.
    pub fn of(spec: &CaseSpec) -> Self {
        let c = spec.material.stiffness();
        let consts: Vec<String> = c.iter().map(|v| format!("{v:.9e}")).collect();
        KernelKey(format!(
            "{}|{}|{:.9e}|{}",
            spec.material.name,
            spec.grid.n,
            spec.grid.dx,
            consts.join(",")
        ))
    }

    /// The key as text (what a store writes and compares).
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl std::fmt::Display for KernelKey {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

/// Persistent storage of kernel spectra (e.g. files), so that a new process
/// does not pay an expensive anisotropic kernel build again.
pub trait KernelStore {
    /// The spectra stored under `key`, if present and of `len` values each
    /// (see [`Spectra::len_for`]).
    fn load(&self, key: &KernelKey, len: usize) -> Option<Spectra>;
    /// Stores the spectra under `key` (best effort).
    fn save(&self, key: &KernelKey, spectra: &Spectra);
}

/// The operator of a material on a grid, built row by row (see
/// [`Operator::build`]); from one quadrant of offsets when the material's
/// influence is mirror symmetric (see [`build_mirrored`]).
pub fn build_operator(material: &Material, grid: Grid) -> Operator {
    let model = material.model();
    if model.mirror_symmetric() {
        build_mirrored(grid, model.cell_influence(grid))
    } else {
        Operator::build(grid, model.cell_influence(grid))
    }
}

/// [`Operator::build`] for a cell influence that is exactly even or odd in x
/// and y with the parities of [`mirror_sign`]: `cell` is evaluated only at
/// offsets `x, y ≥ 0` (the `N x N` quadrant of the `2N x 2N` wrap-around
/// grid, a quarter of the `(2N − 1)²` evaluations of the direct build), and
/// each quadrant row gives the rows of `+y` and `−y`, mirrored in x with the
/// components' signs. The rows handed to the transforms are those of the
/// direct build, to the bit, so the spectra are too (tested). Isotropic
/// closed forms at 2048²: 12 s in the direct build, dominated by the
/// `ln`/`atan` of the corner sums.
pub fn build_mirrored(grid: Grid, cell: impl Fn(f64, f64) -> Block) -> Operator {
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
        crate::progress::tick();
        if oy == n {
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
            for (&(i, j), out) in STORED.iter().zip(full.iter_mut()) {
                let (s, sx) = (
                    mirror_sign(i, j, false, neg_y),
                    mirror_sign(i, j, true, neg_y),
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
    let mut six = full.into_iter();
    let mut next = || six.next().expect("six components");
    let mut real = || next().iter().map(|z| z.re).collect::<Vec<f64>>();
    let diag = [real(), real(), real()];
    let off = [next(), next(), next()];
    Operator::from_spectra(grid, Spectra { diag, off }).expect("spectra of the grid")
}

/// The `(i, j)` components an operator stores, in the order of
/// [`Operator::build`]: diagonal, then `xy`, `xz`, `yz`.
const STORED: [(usize, usize); 6] = [(0, 0), (1, 1), (2, 2), (0, 1), (0, 2), (1, 2)];

/// What a process keeps per kernel: the DC-FFT operator and the caches the
/// solvers made for it (the normal solver's coarse levels and
/// preconditioner, the tangential solver's contact-window operator).
pub struct Resident {
    /// The operator.
    pub operator: Operator,
    /// The normal solver's aids for this operator.
    pub normal: NormalCache,
    /// The tangential solver's window operator.
    pub windows: WindowCache,
}

impl Resident {
    /// The bundle of `operator` (makes the coarse levels).
    pub fn new(mut operator: Operator) -> Self {
        Resident {
            normal: NormalCache::new(&mut operator),
            windows: WindowCache::default(),
            operator,
        }
    }

    /// [`solve_normal`] on this bundle.
    pub fn solve_normal(&mut self, prob: &NormalProblem) -> Result<NormalSolution, SolverError> {
        solve_normal(&mut self.operator, &mut self.normal, prob)
    }

    /// [`solve_tangential`] on this bundle.
    pub fn solve_tangential(
        &mut self,
        prob: &TangentialProblem,
    ) -> Result<TangentialSolution, SolverError> {
        solve_tangential(&mut self.operator, &mut self.windows, prob)
    }
}

/// Resident kernels, keyed by [`KernelKey`].
#[derive(Default)]
pub struct KernelCache {
    resident: HashMap<KernelKey, Resident>,
    builds: usize,
    loads: usize,
    store: Option<Box<dyn KernelStore>>,
}

impl KernelCache {
    /// An empty cache.
    pub fn new() -> Self {
        Self::default()
    }

    /// An empty cache backed by a persistent store for the kernels worth
    /// persisting (see [`crate::ElasticModel::persist_tables`]).
    pub fn with_store(store: Box<dyn KernelStore>) -> Self {
        KernelCache {
            store: Some(store),
            ..Self::default()
        }
    }

    /// Number of operators made resident so far (built or loaded).
    pub fn builds(&self) -> usize {
        self.builds + self.loads
    }

    /// Of those, how many came from the persistent store.
    pub fn loads(&self) -> usize {
        self.loads
    }

    /// The bundle for `spec`, built (or loaded) on first use; the second
    /// value is the time that took (0 when it was already resident).
    pub fn resident(&mut self, spec: &CaseSpec) -> Result<(&mut Resident, f64), SolverError> {
        let key = KernelKey::of(spec);
        let mut took = 0.0;
        if !self.resident.contains_key(&key) {
            let start = std::time::Instant::now();
            let grid = spec.grid;
            let len = Spectra::len_for(grid.n);
            let persistent = spec.material.model().persist_tables();
            let stored = match (&self.store, persistent) {
                (Some(store), true) => store.load(&key, len),
                _ => None,
            };
            let op = match stored.and_then(|s| Operator::from_spectra(grid, s)) {
                Some(op) => {
                    self.loads += 1;
                    op
                }
                None => {
                    let op = build_operator(&spec.material, grid);
                    if let (Some(store), true) = (&self.store, persistent) {
                        store.save(&key, op.spectra());
                    }
                    self.builds += 1;
                    op
                }
            };
            let bundle = Resident::new(op);
            took = start.elapsed().as_secs_f64();
            self.resident.insert(key.clone(), bundle);
        }
        // Only the kernel in use keeps a contact-window operator: the
        // others' are rebuilt from their spectra (tens of ms) when needed.
        for (k, r) in self.resident.iter_mut() {
            if *k != key {
                r.windows.clear();
            }
        }
        Ok((self.resident.get_mut(&key).expect("inserted above"), took))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::influence::isotropic_cell;

    fn bits(s: &Spectra) -> Vec<u64> {
        let re = s.diag.iter().flatten().map(|v| v.to_bits());
        let cx = s
            .off
            .iter()
            .flatten()
            .flat_map(|z| [z.re.to_bits(), z.im.to_bits()]);
        re.chain(cx).collect()
    }

    /// The quadrant-and-mirror build hands the transforms the rows of the
    /// direct build, so the spectra are equal to the bit.
    #[test]
    fn mirrored_build_equals_the_direct_build_to_the_bit() {
        for (n, dx, dy) in [(48, 1.0e-6, 1.3e-6), (33, 2.0e-6, 2.0e-6)] {
            let grid = Grid { n, dx, dy };
            let (g, nu) = (80.0e9, 0.29);
            let cell = |x, y| isotropic_cell(g, nu, x, y, dx, dy);
            let direct = Operator::build(grid, cell);
            let mirrored = build_mirrored(grid, cell);
            assert!(
                bits(direct.spectra()) == bits(mirrored.spectra()),
                "n = {n}"
            );
        }
    }

    /// Isotropic materials take the mirrored build.
    #[test]
    fn isotropic_materials_are_mirror_symmetric_and_crystals_are_not() {
        let fe = crate::presets::material("Fe").unwrap();
        assert!(fe.model().mirror_symmetric());
        let cu111 = crate::presets::material("Cu(111)").unwrap();
        assert!(!cu111.model().mirror_symmetric());
    }
}
