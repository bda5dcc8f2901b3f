//! The threads one case may use, and the rule that keeps every result the
//! same for any thread count. Owns the rayon pool; knows no physics.
//!
//! Only work whose every output element is computed by the same arithmetic
//! whatever thread runs it is split across threads: the row and column
//! transforms of [`crate::fft2::Fft2`] (each row or column is one
//! independent FFT, with the same plan), the spectral products of one column
//! and the per-column terms of an energy product. Every reduction (sums, dot
//! products, maxima that feed a decision) stays a single serial loop in its
//! original order: per-column partial results are stored and then summed in
//! column order on the calling thread. So a solve with N threads performs, in
//! the same order, the same floating-point operations as with one thread, and
//! its results are identical to the bit (`solver/tests/threads.rs` checks).

use std::sync::Arc;

use crate::error::SolverError;

/// How many pieces each thread's share of a stage is cut into, so that a
/// thread slowed by other load on the machine hands work to the others.
const TASKS_PER_THREAD: usize = 4;

/// Transform side (padded, or periodic) from which a transform's row and
/// column stages are shared among threads ([`Threads::min_side`]). Below it a
/// stage is too short for the hand-over between threads to pay, and a case
/// with 2 threads was slower than with one (rigid sphere on Fe, 80² grid, 20
/// force increments: 0.34 s → 0.70 s on a machine shared with other work).
/// One tangential CG iteration's transforms (`tangential_step` example,
/// fastest of 31, same machine), 1 → 2 threads: 128² (side 256) 0.635 →
/// 0.667 ms, 192² (384) 1.72–1.77 → 1.67 ms, 256² (512) 3.27–3.44 →
/// 2.97–3.00 ms.
pub const PARALLEL_FROM: usize = 512;

/// The threads of one case: serial (the calling thread only) or a rayon pool.
#[derive(Clone, Default)]
pub struct Threads {
    pool: Option<Arc<rayon::ThreadPool>>,
    /// Smaller transforms run serial (0 in a `Default`: see `min_side`).
    min_side: usize,
}

impl std::fmt::Debug for Threads {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Threads({})", self.count())
    }
}

impl Threads {
    /// The calling thread only (what a sweep's worker uses: processes fill the cores).
    pub fn serial() -> Self {
        Threads {
            pool: None,
            min_side: PARALLEL_FROM,
        }
    }

    /// `n` threads; 1 is [`Threads::serial`]. Fails for 0 or when the
    /// operating system refuses the threads.
    pub fn new(n: usize) -> Result<Self, SolverError> {
        match n {
            0 => Err(SolverError::invalid("threads", "must be at least 1, got 0")),
            1 => Ok(Self::serial()),
            _ => rayon::ThreadPoolBuilder::new()
                .num_threads(n)
                .thread_name(|i| format!("mpcontact-{i}"))
                .build()
                .map(|p| Threads {
                    pool: Some(Arc::new(p)),
                    min_side: PARALLEL_FROM,
                })
                .map_err(|e| {
                    SolverError::invalid("threads", format!("cannot start {n} threads: {e}"))
                }),
        }
    }

    /// The cores of this machine (at least 1): the default of `mpcontact solve`.
    pub fn available() -> usize {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    }

    /// The same threads for transforms of every size, however small (for
    /// tests that must run the shared stages on small grids).
    pub fn at_every_size(mut self) -> Self {
        self.min_side = 1;
        self
    }

    /// Side of the smallest transform whose stages these threads share;
    /// smaller ones run on the calling thread ([`PARALLEL_FROM`] unless
    /// [`Threads::at_every_size`]).
    pub fn min_side(&self) -> usize {
        if self.min_side == 0 {
            PARALLEL_FROM
        } else {
            self.min_side
        }
    }

    /// Number of threads.
    pub fn count(&self) -> usize {
        self.pool.as_ref().map_or(1, |p| p.current_num_threads())
    }

    /// The pool, `None` when serial.
    pub(crate) fn pool(&self) -> Option<&rayon::ThreadPool> {
        self.pool.as_deref()
    }

    /// Runs `f` on the pool (serial: here). The stages inside `f` then start
    /// from a pool thread, which hands work to the others without waking
    /// the caller between stages: one hand-over per operator application
    /// instead of one per stage.
    pub(crate) fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        match &self.pool {
            Some(p) => p.install(f),
            None => f(),
        }
    }

    /// Pieces a stage is cut into (each with its own scratch buffers).
    pub(crate) fn tasks(&self) -> usize {
        match self.pool {
            None => 1,
            Some(_) => TASKS_PER_THREAD * self.count(),
        }
    }

    /// True when both are the same pool (or both serial).
    pub(crate) fn same(&self, other: &Threads) -> bool {
        let pools = match (&self.pool, &other.pool) {
            (None, None) => true,
            (Some(a), Some(b)) => Arc::ptr_eq(a, b),
            _ => false,
        };
        pools && self.min_side() == other.min_side()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn zero_threads_is_an_error_naming_threads_and_one_is_serial() {
        let e = Threads::new(0).unwrap_err();
        assert!(e.to_string().contains("threads"), "{e}");
        let one = Threads::new(1).unwrap();
        assert!(one.pool().is_none());
        assert_eq!(one.count(), 1);
        assert_eq!(one.tasks(), 1);
        let two = Threads::new(2).unwrap();
        assert_eq!(two.count(), 2);
        assert_eq!(two.tasks(), 2 * TASKS_PER_THREAD);
        assert!(two.same(&two.clone()) && !two.same(&one));
        assert_eq!(two.min_side(), PARALLEL_FROM);
        let every = two.clone().at_every_size();
        assert_eq!(every.min_side(), 1);
        assert!(!every.same(&two));
    }
}
