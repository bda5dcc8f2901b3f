//! The threads one case may use, and the rule that keeps every result the
//! same for any thread count. Owns the rayon pool; knows no physics.
//!
//! Work whose every output element is computed by the same arithmetic
//! whatever thread runs it is split across threads freely: the row and
//! column transforms of [`crate::operators::fft2::Fft2`] (each row or column is one
//! independent FFT, with the same plan), the spectral products of one column
//! and the per-column terms of an energy product (summed in column order on
//! the calling thread). The solvers' vector passes, which carry the sums,
//! dot products and maxima, run over [`Chunks`]: fixed pieces of [`CHUNK`]
//! cells that do not depend on the thread count. Each piece's partial result
//! starts from zero and runs over its cells in order, on whatever thread,
//! and the partial results are combined in chunk order on the calling thread
//! ([`Threads::chunked`]). So a solve with N threads performs, in the same
//! order, the same floating-point operations as with one thread, and its
//! results are identical to the bit (`solver/tests/threads.rs` checks).

use std::ops::Range;
use std::sync::Arc;

use rayon::prelude::*;

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

/// Cells per piece of a solver's vector pass ([`Chunks`]). Fixed: the
/// partial sums, and so every result, do not depend on the thread count.
/// Small enough that the test grids have several pieces (a 64² contact of
/// 1500 cells has two), large enough that a piece's bookkeeping (one partial
/// result) is nothing against its cells' arithmetic; a 2048² field has 4096.
pub const CHUNK: usize = 1024;

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

    /// `f` of each piece's item (`items`: one per piece of `chunks`, in
    /// order), in that order. On the pool when there is one and the pass has
    /// as many cells as a field of side `min_side() / 2` (the grid whose
    /// padded transforms are shared), otherwise here, one piece after the
    /// other: the same arithmetic either way.
    pub(crate) fn chunked<I: Send, T: Send>(
        &self,
        chunks: &Chunks,
        items: Vec<I>,
        f: impl Fn(I) -> T + Sync + Send,
    ) -> Vec<T> {
        let side = self.min_side().div_ceil(2);
        match &self.pool {
            Some(p) if items.len() > 1 && chunks.cells() >= side * side => {
                p.install(|| items.into_par_iter().map(f).collect())
            }
            _ => items.into_iter().map(f).collect(),
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

/// One piece of a pass: the flat indices `start..end` of the fields that it
/// owns and, for a pass over a list of cells, its cells (all in that range).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Part<'a> {
    list: &'a [usize],
    /// First flat index of the piece: its local field slices start here.
    pub start: usize,
    end: usize,
}

impl<'a> Part<'a> {
    /// The flat indices the piece owns (its cells, for a flat pass).
    pub fn range(&self) -> Range<usize> {
        self.start..self.end
    }

    /// The piece's cells of a pass over a list of cells, in order.
    pub fn list(&self) -> &'a [usize] {
        self.list
    }
}

/// The fixed pieces of a vector pass (see [`CHUNK`]): over all `len` cells
/// of a field ([`Chunks::flat`]), or over an ascending list of cells
/// ([`Chunks::of_cells`]), whose pieces then own disjoint index ranges of the
/// fields, so that a pass may write its cells' values on any thread.
pub(crate) struct Chunks<'a> {
    list: Option<&'a [usize]>,
    /// Flat index where each piece starts, and the field's length last.
    bounds: Vec<usize>,
}

impl<'a> Chunks<'a> {
    /// All cells `0..len`.
    pub fn flat(len: usize) -> Chunks<'static> {
        let mut bounds: Vec<usize> = (0..len.div_ceil(CHUNK)).map(|k| k * CHUNK).collect();
        bounds.push(len);
        Chunks { list: None, bounds }
    }

    /// The cells `cells` (strictly ascending) of fields of `len` values.
    pub fn of_cells(cells: &'a [usize], len: usize) -> Self {
        debug_assert!(cells.windows(2).all(|w| w[0] < w[1]), "cells ascending");
        debug_assert!(cells.last().is_none_or(|&c| c < len), "cells in the field");
        let count = cells.len().div_ceil(CHUNK);
        let mut bounds: Vec<usize> = (0..count)
            .map(|k| if k == 0 { 0 } else { cells[k * CHUNK] })
            .collect();
        bounds.push(len);
        Chunks {
            list: Some(cells),
            bounds,
        }
    }

    /// Number of pieces.
    pub fn count(&self) -> usize {
        self.bounds.len() - 1
    }

    /// Cells of the pass (the length of a flat pass, the list's otherwise).
    pub fn cells(&self) -> usize {
        match self.list {
            Some(l) => l.len(),
            None => self.bounds[self.count()],
        }
    }

    /// The pieces, in order.
    pub fn parts(&self) -> impl Iterator<Item = Part<'a>> + '_ {
        (0..self.count()).map(move |k| {
            let list = match self.list {
                Some(l) => &l[k * CHUNK..((k + 1) * CHUNK).min(l.len())],
                None => &[][..],
            };
            Part {
                list,
                start: self.bounds[k],
                end: self.bounds[k + 1],
            }
        })
    }

    /// The pieces, in order, as the items of a read-only pass.
    pub fn items(&self) -> Vec<Part<'a>> {
        self.parts().collect()
    }

    /// The flat ranges the pieces own.
    fn ranges(&self) -> impl Iterator<Item = Range<usize>> + '_ {
        self.bounds.windows(2).map(|w| w[0]..w[1])
    }

    /// A field cut into the pieces' ranges (index a piece's slice with
    /// `i - part.start`).
    pub fn split<'b, T>(&self, mut v: &'b mut [T]) -> Vec<&'b mut [T]> {
        assert_eq!(
            v.len(),
            self.bounds[self.count()],
            "field of the pass's length"
        );
        let mut out = Vec::with_capacity(self.count());
        for r in self.ranges() {
            let (head, tail) = std::mem::take(&mut v).split_at_mut(r.len());
            out.push(head);
            v = tail;
        }
        out
    }

    /// The pieces with one field cut into their ranges.
    pub fn with<'b, T>(&self, v: &'b mut [T]) -> Vec<(Part<'a>, &'b mut [T])> {
        self.parts().zip(self.split(v)).collect()
    }

    /// The pieces with two fields cut into their ranges.
    #[allow(clippy::type_complexity)]
    pub fn with2<'b, T, U>(
        &self,
        a: &'b mut [T],
        b: &'b mut [U],
    ) -> Vec<(Part<'a>, &'b mut [T], &'b mut [U])> {
        self.parts()
            .zip(self.split(a))
            .zip(self.split(b))
            .map(|((p, a), b)| (p, a, b))
            .collect()
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

    /// The pieces of a cell list tile the field, each holding its cells; a
    /// pass that writes its cells and sums them gives the same bits on 1, 2
    /// and 3 threads: the pieces' sums, each over its cells in order, added
    /// in piece order (and the plain serial sum to round-off).
    #[test]
    fn pieces_own_their_cells_and_sums_combine_in_piece_order_on_any_threads() {
        let len = 10_000;
        let cells: Vec<usize> = (0..len).filter(|i| i % 3 != 1).collect();
        let chunks = Chunks::of_cells(&cells, len);
        assert_eq!(chunks.count(), cells.len().div_ceil(CHUNK));
        assert!(chunks.count() > 3, "several pieces");
        let (mut next, mut seen) = (0, 0);
        for part in chunks.parts() {
            assert_eq!(part.range().start, next);
            next = part.range().end;
            assert!(part.list().iter().all(|c| part.range().contains(c)));
            seen += part.list().len();
        }
        assert_eq!((next, seen), (len, cells.len()));
        let flat = Chunks::flat(len);
        assert_eq!(flat.count(), len.div_ceil(CHUNK));
        assert!(flat
            .parts()
            .all(|p| p.list().is_empty() && p.range().len() <= CHUNK));

        let values: Vec<f64> = (0..len).map(|i| 1.0 / (1.0 + i as f64)).collect();
        let mut expect = 0.0;
        for part in chunks.parts() {
            let mut s = 0.0;
            for &c in part.list() {
                s += values[c];
            }
            expect += s;
        }
        let serial: f64 = cells.iter().map(|&c| values[c]).sum();
        assert!((expect - serial).abs() < 1e-14 * serial);
        for t in [1, 2, 3] {
            let threads = Threads::new(t).unwrap().at_every_size();
            let mut out = vec![0.0; len];
            let parts = threads.chunked(&chunks, chunks.with(&mut out), |(part, out)| {
                let mut s = 0.0;
                for &c in part.list() {
                    out[c - part.start] = values[c];
                    s += values[c];
                }
                s
            });
            let total = parts.into_iter().fold(0.0, |a, b| a + b);
            assert_eq!(total.to_bits(), expect.to_bits(), "{t} threads");
            assert!(cells.iter().all(|&c| out[c] == values[c]));
            assert_eq!(out.iter().filter(|&&v| v != 0.0).count(), cells.len());
        }
    }
}
