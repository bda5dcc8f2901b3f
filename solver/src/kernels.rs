//! Keeping kernels resident: the identity of a kernel (material constants and
//! grid), the per-kernel bundle a process keeps (the operator plus the
//! solvers' caches made for it), and the cache of bundles, optionally backed
//! by a persistent [`KernelStore`] supplied by the caller (the worker's files).
//! Builds operators; solves nothing.

use std::collections::HashMap;

use crate::error::SolverError;
use crate::grid::Grid;
use crate::material::Material;
use crate::normal::{
    solve_normal, solve_normal_from_rest, NormalCache, NormalProblem, NormalSolution,
};
use crate::operator::{Operator, Spectra};
use crate::parallel::Threads;
use crate::progress::Stage;
use crate::spec::CaseSpec;
use crate::tangential::{
    solve_tangential, solve_tangential_taking, TangentialProblem, TangentialSolution,
};
use crate::window::WindowCache;

/// Identity of a kernel: material name and constants, cells per side and
/// cell size. Its text (`name|n|dx|C11,…`) names an entry of a store.
#[derive(Clone, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct KernelKey(String);

impl KernelKey {
    /// The kernel a case needs.
    pub fn of(spec: &CaseSpec) -> Self {
        let consts = |m: &Material| {
            let c: Vec<String> = m.stiffness().iter().map(|v| format!("{v:.9e}")).collect();
            c.join(",")
        };
        let mut key = format!(
            "{}|{}|{:.9e}|{}",
            spec.material.name,
            spec.grid.n,
            spec.grid.dx,
            consts(&spec.material)
        );
        // An elastic ball makes another kernel; a rigid one keeps the key
        // (and the stored kernels) of before balls existed.
        if let Some(ball) = &spec.indenter {
            key.push_str(&format!("|ball {}|{}", ball.name, consts(ball)));
        }
        KernelKey(key)
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
    /// Tries to take the right to build `key` (so that processes sharing the
    /// store build each kernel once): [`BuildLock::Held`] until the guard is
    /// dropped, [`BuildLock::Busy`] while another holder builds it. The lock
    /// must end with its holder, also when the holder dies (e.g. `flock`).
    /// The default: no locking.
    fn try_lock(&self, _key: &KernelKey) -> BuildLock {
        BuildLock::Unsupported
    }
}

/// What [`KernelStore::try_lock`] found.
pub enum BuildLock {
    /// Ours until this guard is dropped.
    Held(Box<dyn std::any::Any>),
    /// Someone else holds it: wait, then look in the store again.
    Busy,
    /// The store does not lock (or cannot now): build without.
    Unsupported,
}

/// How often a process waiting for another's kernel build looks again
/// (the build it waits for takes seconds; 0.6 s for a 384² Cu(111) kernel).
const LOCK_POLL: std::time::Duration = std::time::Duration::from_millis(50);

/// The operator of a material on a grid, built row by row (see
/// [`Operator::build`]); from one quadrant of offsets when the material's
/// influence is mirror symmetric (see [`Operator::build_mirrored`]).
pub fn build_operator(material: &Material, grid: Grid) -> Operator {
    build_pair_operator(material, None, grid)
}

/// The operator of a substrate pressed by a ball of material `indenter`
/// (`None`: rigid, [`build_operator`]): the two bodies' compliances summed
/// ([`crate::material::pair_influence`]); mirrored from one quadrant when
/// both influences are mirror symmetric (R K(x, −y) R keeps the parities).
pub fn build_pair_operator(
    material: &Material,
    indenter: Option<&Material>,
    grid: Grid,
) -> Operator {
    let model = material.model();
    let (influence, mirror) = match indenter {
        None => (model.cell_influence(grid), model.mirror_symmetric()),
        Some(ball) => (
            crate::material::pair_influence(
                model.cell_influence(grid),
                ball.model().cell_influence(grid),
            ),
            model.mirror_symmetric() && ball.model().mirror_symmetric(),
        ),
    };
    if mirror {
        Operator::build_mirrored(grid, influence)
    } else {
        Operator::build(grid, influence)
    }
}

/// True when a case's kernel is expensive enough to persist (a numerical
/// Green's function on either body).
pub fn persists(spec: &CaseSpec) -> bool {
    spec.material.model().persist_tables()
        || spec
            .indenter
            .as_ref()
            .is_some_and(|m| m.model().persist_tables())
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

    /// Runs this kernel's transforms on `threads` (a window operator made
    /// for other threads is dropped and made again when next needed).
    pub fn set_threads(&mut self, threads: &Threads) {
        if !self.operator.threads().same(threads) {
            self.operator.set_threads(threads);
            self.normal.set_threads(threads);
            self.windows.clear();
        }
    }

    /// [`solve_normal`] on this bundle.
    pub fn solve_normal(&mut self, prob: &NormalProblem) -> Result<NormalSolution, SolverError> {
        solve_normal(&mut self.operator, &mut self.normal, prob)
    }

    /// [`solve_normal_from_rest`] on this bundle: the contact a case starts
    /// from, kept for the next case that starts from the same one.
    pub fn solve_normal_from_rest(
        &mut self,
        prob: &NormalProblem,
    ) -> Result<NormalSolution, SolverError> {
        solve_normal_from_rest(&mut self.operator, &mut self.normal, prob)
    }

    /// [`crate::tangential_displacement::solve_displacement`] on this bundle.
    pub fn solve_displacement(
        &mut self,
        prob: &crate::tangential_displacement::DisplacementProblem,
    ) -> Result<TangentialSolution, SolverError> {
        crate::progress::stage(Stage::Tangential);
        crate::tangential_displacement::solve_displacement(
            &mut self.operator,
            &mut self.windows,
            prob,
        )
    }

    /// [`solve_tangential`] on this bundle.
    pub fn solve_tangential(
        &mut self,
        prob: &TangentialProblem,
    ) -> Result<TangentialSolution, SolverError> {
        solve_tangential(&mut self.operator, &mut self.windows, prob)
    }

    /// [`solve_tangential`] on this bundle from the tractions `start`, which
    /// the solver takes over as work space (`prob.start` is not read).
    pub(crate) fn solve_tangential_from(
        &mut self,
        prob: &TangentialProblem,
        start: (Vec<f64>, Vec<f64>),
    ) -> Result<TangentialSolution, SolverError> {
        solve_tangential_taking(&mut self.operator, &mut self.windows, prob, Some(start))
    }
}

/// Resident kernels, keyed by [`KernelKey`].
#[derive(Default)]
pub struct KernelCache {
    resident: HashMap<KernelKey, Resident>,
    builds: usize,
    loads: usize,
    store: Option<Box<dyn KernelStore>>,
    threads: Threads,
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

    /// Solves of this cache's kernels run on `threads` from now on (serial
    /// by default); the results do not depend on it (see [`Threads`]).
    pub fn set_threads(&mut self, threads: Threads) {
        for r in self.resident.values_mut() {
            r.set_threads(&threads);
        }
        self.threads = threads;
    }

    /// The bundle for `spec`, built (or loaded) on first use; the second
    /// value is the time that took (0 when it was already resident).
    pub fn resident(&mut self, spec: &CaseSpec) -> Result<(&mut Resident, f64), SolverError> {
        let key = KernelKey::of(spec);
        let mut took = 0.0;
        if !self.resident.contains_key(&key) {
            crate::progress::stage(Stage::Kernel);
            let start = std::time::Instant::now();
            let grid = spec.grid;
            let len = Spectra::len_for(grid.n);
            let persistent = persists(spec);
            let load = |store: &dyn KernelStore| {
                store
                    .load(&key, len)
                    .and_then(|s| Operator::from_spectra(grid, s))
            };
            let mut loaded = None;
            // Held while this process builds the kernel, so that others
            // sharing the store wait for it and load it instead.
            let mut _guard = None;
            if let (Some(store), true) = (&self.store, persistent) {
                loaded = load(store.as_ref());
                while loaded.is_none() {
                    match store.try_lock(&key) {
                        BuildLock::Held(g) => {
                            // Built by the previous holder while we waited?
                            loaded = load(store.as_ref());
                            _guard = Some(g);
                            break;
                        }
                        BuildLock::Busy => {
                            // A waiting worker still shows it is alive, and
                            // a cancel still stops it.
                            crate::progress::tick_or_cancel()?;
                            std::thread::sleep(LOCK_POLL);
                            loaded = load(store.as_ref());
                        }
                        BuildLock::Unsupported => break,
                    }
                }
            }
            let op = match loaded {
                Some(op) => {
                    self.loads += 1;
                    op
                }
                None => {
                    let mut op = build_pair_operator(&spec.material, spec.indenter.as_ref(), grid);
                    if let (Some(store), true) = (&self.store, persistent) {
                        op.with_spectra(|s| store.save(&key, s));
                    }
                    self.builds += 1;
                    op
                }
            };
            drop(_guard);
            let mut op = op;
            op.set_threads(&self.threads);
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
            let direct = Operator::build(grid, cell).with_spectra(bits);
            let mirrored = Operator::build_mirrored(grid, cell).with_spectra(bits);
            assert!(direct == mirrored, "n = {n}");
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
