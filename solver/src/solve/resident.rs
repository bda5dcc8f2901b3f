//! Keeping kernels resident: the per-kernel bundle a process keeps (the
//! operator plus the solvers' caches made for it) and the cache of bundles,
//! optionally backed by a persistent [`KernelStore`] supplied by the caller.

use std::collections::HashMap;

use crate::base::parallel::Threads;
use crate::base::progress::Stage;
use crate::error::SolverError;
use crate::model::spec::CaseSpec;
use crate::operators::kernels::{obtain_operator, KernelKey, KernelStore, Obtained};
use crate::operators::operator::Operator;
use crate::solve::normal::{
    solve_normal, solve_normal_from_rest, NormalCache, NormalProblem, NormalSolution,
};
use crate::solve::tangential::window::WindowCache;
use crate::solve::tangential::{
    solve_tangential, solve_tangential_taking, TangentialProblem, TangentialSolution,
};

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

    /// [`crate::solve::tangential::displacement::solve_displacement`] on this bundle.
    pub fn solve_displacement(
        &mut self,
        prob: &crate::solve::tangential::displacement::DisplacementProblem,
    ) -> Result<TangentialSolution, SolverError> {
        crate::base::progress::stage(Stage::Tangential);
        crate::solve::tangential::displacement::solve_displacement(
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

    /// Number of operators built in this process so far (not those loaded
    /// from the store: [`KernelCache::loads`]).
    pub fn builds(&self) -> usize {
        self.builds
    }

    /// Number of operators loaded from the persistent store so far.
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
            crate::base::progress::stage(Stage::Kernel);
            let start = std::time::Instant::now();
            let (mut op, obtained) = obtain_operator(self.store.as_deref(), &key, spec)?;
            match obtained {
                Obtained::Loaded => self.loads += 1,
                Obtained::Built => self.builds += 1,
            }
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
