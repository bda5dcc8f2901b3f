//! Keeping kernels resident: the identity of a kernel (material constants and
//! grid), the per-kernel bundle a process keeps (the operator plus the
//! solvers' caches made for it), and the cache of bundles, optionally backed
//! by a persistent [`KernelStore`] supplied by the caller (the worker's files).
//! Builds operators; solves nothing.

use std::collections::HashMap;

use crate::error::SolverError;
use crate::grid::Grid;
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

/// The operator of a material on a grid, built row by row (see [`Operator::build`]).
pub fn build_operator(material: &Material, grid: Grid) -> Operator {
    Operator::build(grid, material.model().cell_influence(grid))
}

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
