//! Real-to-complex 2-D FFTs on the padded `M x M` grid (M = 2N) used by DC-FFT.
//! Owns FFT plans and scratch; knows nothing about kernels or physics.
//!
//! Layout: real arrays are row-major `[iy][ix]` with `M` columns. Spectra are
//! stored *transposed*, `[kx][ky]` with `M/2 + 1` rows of `M` complex values,
//! so the column transforms run on contiguous memory. Forward transforms may
//! assume that only the first `N` rows and columns of the input are non-zero
//! (zero padding), and inverse transforms only produce the first `N` rows.
//!
//! Split columns: a column of the padded grid is `N` values and `N` zeros,
//! so its length-`2N` transform is two length-`N` transforms (of the values,
//! and of the values times `e^{−2πi n/2N}`), and its inverse, of which only
//! the first `N` values are kept, two length-`N` inverse transforms combined
//! with the same factors. For the sides in [`SPLIT_SIDES`] a column pass
//! ([`Fft2::column_pass`]) transforms its columns so and holds them in
//! *split order*: the even frequencies `ky = 2j` at `j`, the odd ones
//! `ky = 2j + 1` at `N + j` ([`Fft2::to_split_order`]); for other sides in
//! natural order, with one length-`2N` transform.

use num_complex::Complex64;
use rayon::prelude::*;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

use crate::base::parallel::Threads;

/// Time spent in the transforms of this thread, for benchmarks that divide an
/// iteration's time by the time of the transforms it ran (the "FFT floor" in
/// place). Off unless [`timing::start`] was called: each public transform
/// method of [`Fft2`] is then one timed span.
pub mod timing {
    use std::cell::Cell;
    use std::time::Instant;

    thread_local! {
        static ON: Cell<bool> = const { Cell::new(false) };
        static SECONDS: Cell<f64> = const { Cell::new(0.0) };
        static PRODUCTS: Cell<f64> = const { Cell::new(0.0) };
        static SPANS: Cell<u64> = const { Cell::new(0) };
        static PRODUCT_SPANS: Cell<u64> = const { Cell::new(0) };
    }

    /// Starts timing this thread's transforms from zero.
    pub fn start() {
        ON.set(true);
        SECONDS.set(0.0);
        PRODUCTS.set(0.0);
        SPANS.set(0);
        PRODUCT_SPANS.set(0);
    }

    /// Seconds spent in the operator's spectral products (the one read of
    /// the kernel spectra per application, [`Span::product`]) since
    /// [`start`], and the number of their spans ([`stop`] counts only the
    /// transforms').
    pub fn products() -> (f64, u64) {
        (PRODUCTS.get(), PRODUCT_SPANS.get())
    }

    /// Stops timing; returns the seconds spent in transforms and the number
    /// of timed spans (each includes about one clock read of overhead, which
    /// the caller can calibrate with empty spans).
    pub fn stop() -> (f64, u64) {
        ON.set(false);
        (SECONDS.get(), SPANS.get())
    }

    /// One timed span: from its creation to its drop, when timing is on.
    pub struct Span(Option<(Instant, bool)>);

    impl Span {
        /// Starts a span of transforms (a no-op unless timing is on).
        #[inline]
        #[allow(clippy::new_without_default)]
        pub fn new() -> Self {
            Span(ON.get().then(|| (Instant::now(), false)))
        }

        /// Starts a span of spectral products (see [`products`]).
        #[inline]
        pub fn product() -> Self {
            Span(ON.get().then(|| (Instant::now(), true)))
        }
    }

    impl Drop for Span {
        #[inline]
        fn drop(&mut self) {
            if let Some((t, product)) = self.0 {
                let (acc, count) = if product {
                    (&PRODUCTS, &PRODUCT_SPANS)
                } else {
                    (&SECONDS, &SPANS)
                };
                acc.set(acc.get() + t.elapsed().as_secs_f64());
                count.set(count.get() + 1);
            }
        }
    }
}

/// Rows transformed together and moved to (from) the transposed spectrum as
/// one tile (`tile_rows(M) x (M/2 + 1)` complex values, kept in cache): 64
/// rows from `M = 2048` on, 16 below.
///
/// (64 rows: the row stage of a 2048² field took 7.6 instead of 8.7 ns per
/// cell, that of a 512² field 5.0 instead of 5.5; `cargo run --release -p
/// mpcontact-solver --example fft_stages`. Each `Fft2` keeps its tiles, and
/// at 512² the larger ones added 3 MB, 2.5 %, to a coupled solve's peak.)
fn tile_rows(m: usize) -> usize {
    if m >= 2048 {
        64
    } else {
        16
    }
}

/// Grid sides `N` whose column passes run split columns (module docs): the
/// sides where that was measured faster. rustfft's length-4096 plan stands
/// out on the development machine, at 0.33–0.35 ns per value and radix-2
/// level against 0.27 for 2048 and 0.31 for 8192: a forward and inverse
/// column took 25–26 µs split against 29–38 µs whole at `N = 2048`, but
/// 4.6–6.9 against 4.3 at 512, 11.1 against 10.2–10.7 at 1024 and 68–83
/// against 56–57 at 4096 (the factors cost a pass each way); see
/// docs/performance-history.md (round 2). Only results on these sides differ, at round-off,
/// from whole-column transforms.
const SPLIT_SIDES: [usize; 1] = [2048];

/// The length-`N` plans and the factors `e^{−2πi n/M}` (`n < N`) of split
/// columns (module docs).
struct Split {
    fwd: Arc<dyn Fft<f64>>,
    inv: Arc<dyn Fft<f64>>,
    twiddles: Vec<Complex64>,
}

/// The buffers of one task of a row or column stage.
struct TaskBufs {
    row_real: Vec<f64>,
    /// `tile_rows(M)` row spectra, `[row][kx]`.
    tile: Vec<Complex64>,
    scratch: Vec<Complex64>,
    /// Two whole columns (`M` values each) of a [`Fft2::column_pass`].
    columns: [Vec<Complex64>; 2],
}

/// A spectrum written by several tasks at once, each at indices no other
/// task reads or writes (its own rows of the transposed layout).
#[derive(Clone, Copy)]
struct Scatter {
    ptr: *mut Complex64,
    len: usize,
}

// SAFETY: a `Scatter` is only shared between tasks that write disjoint
// index sets of the spectrum it points to (see `row_tiles`), while the
// `&mut` borrow it was made from is held by the stage that spawned them.
unsafe impl Send for Scatter {}
unsafe impl Sync for Scatter {}

impl Scatter {
    fn new(out: &mut [Complex64]) -> Self {
        Scatter {
            ptr: out.as_mut_ptr(),
            len: out.len(),
        }
    }

    /// Writes `v` at `i`.
    ///
    /// # Safety
    /// No other task accesses index `i` during the stage.
    #[inline]
    unsafe fn write(self, i: usize, v: Complex64) {
        assert!(i < self.len);
        // SAFETY: in bounds (checked above); exclusive by the caller's contract.
        unsafe { *self.ptr.add(i) = v };
    }
}

/// The column transforms with one task's scratch: what work done column by
/// column (see [`Fft2::column_pass`]) transforms its columns with.
pub struct Columns<'a> {
    n: usize,
    /// Length `N` for split columns, else `M`.
    fwd: &'a dyn Fft<f64>,
    inv: &'a dyn Fft<f64>,
    /// `e^{−2πi n/M}` for `n < N` for split columns, else empty.
    twiddles: &'a [Complex64],
    scratch: &'a mut [Complex64],
}

impl Columns<'_> {
    /// Column `kx` of a spectrum after [`Fft2::forward_rows_padded`] (its
    /// `N` values first, the other `M − N` are ignored): the forward column
    /// transform of the zero-padded column (in split order for split
    /// columns, module docs).
    pub fn forward(&mut self, col: &mut [Complex64]) {
        let _span = timing::Span::new();
        if self.twiddles.is_empty() {
            col[self.n..].fill(Complex64::default());
            self.fwd.process_with_scratch(col, self.scratch);
            return;
        }
        let (lo, hi) = col.split_at_mut(self.n);
        for ((h, l), t) in hi.iter_mut().zip(lo.iter()).zip(self.twiddles) {
            *h = l * t;
        }
        self.fwd.process_with_scratch(lo, self.scratch);
        self.fwd.process_with_scratch(hi, self.scratch);
    }

    /// Inverse column transform of one column (`M` values, in the order
    /// [`Columns::forward`] leaves) of a spectrum: its first `N` values (the
    /// others are left undefined for split columns);
    /// [`Fft2::inverse_rows_cropped`] completes the inverse transform.
    pub fn inverse(&mut self, col: &mut [Complex64]) {
        let _span = timing::Span::new();
        if self.twiddles.is_empty() {
            self.inv.process_with_scratch(col, self.scratch);
            return;
        }
        let (lo, hi) = col.split_at_mut(self.n);
        self.inv.process_with_scratch(lo, self.scratch);
        self.inv.process_with_scratch(hi, self.scratch);
        for ((l, h), t) in lo.iter_mut().zip(hi.iter()).zip(self.twiddles) {
            *l += h * t.conj();
        }
    }
}

/// `v` made `len` zeros if it is not that long: a work spectrum that was
/// released between uses (`Operator::release_work`) is made again on its
/// next use.
pub(crate) fn ensure_len(v: &mut Vec<Complex64>, len: usize) {
    if v.len() != len {
        *v = vec![Complex64::default(); len];
    }
}

/// FFT plans and scratch for one padded grid size. Build once, apply many times.
///
/// The row and column stages run on the threads set by
/// [`Fft2::set_threads`] (serial by default): each row or column is one FFT
/// with the same plan whatever thread runs it, so the results do not depend
/// on the thread count (see [`crate::base::parallel`]).
pub struct Fft2 {
    m: usize,
    n: usize,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
    col_fwd: Arc<dyn Fft<f64>>,
    col_inv: Arc<dyn Fft<f64>>,
    /// A column pass's split columns (module docs), when asked for.
    split: Option<Split>,
    /// Rows per tile of the row stages ([`tile_rows`]).
    tile: usize,
    threads: Threads,
    /// One per task ([`Threads`]`::tasks`); the serial stages use the first.
    tasks: Vec<TaskBufs>,
    scratch_len: usize,
}

impl Fft2 {
    /// Plans for an `n x n` physical grid padded to `2n x 2n`.
    pub fn new(n: usize) -> Self {
        Self::padded_with_split(n, SPLIT_SIDES.contains(&n))
    }

    /// [`Fft2::new`] with split columns (module docs) or not, whatever the side.
    pub(crate) fn padded_with_split(n: usize, split: bool) -> Self {
        Self::with_sizes(n, 2 * n, split)
    }

    /// Plans for an `n x n` field on an unpadded periodic `n x n` grid.
    pub fn periodic(n: usize) -> Self {
        Self::with_sizes(n, n, false)
    }

    /// The padded-grid side (`2n`, or `n` for a periodic transform).
    pub fn padded_len(&self) -> usize {
        self.m
    }

    fn with_sizes(n: usize, m: usize, split: bool) -> Self {
        let mut rp = RealFftPlanner::<f64>::new();
        let r2c = rp.plan_fft_forward(m);
        let c2r = rp.plan_fft_inverse(m);
        let mut cp = FftPlanner::<f64>::new();
        let col_fwd = cp.plan_fft_forward(m);
        let col_inv = cp.plan_fft_inverse(m);
        let split = split.then(|| Split {
            fwd: cp.plan_fft_forward(n),
            inv: cp.plan_fft_inverse(n),
            twiddles: (0..n)
                .map(|k| {
                    Complex64::from_polar(1.0, -2.0 * std::f64::consts::PI * k as f64 / m as f64)
                })
                .collect(),
        });
        let scratch_len = [
            r2c.get_scratch_len(),
            c2r.get_scratch_len(),
            col_fwd.get_inplace_scratch_len(),
            col_inv.get_inplace_scratch_len(),
        ]
        .into_iter()
        .chain(split.iter().flat_map(|s| {
            [
                s.fwd.get_inplace_scratch_len(),
                s.inv.get_inplace_scratch_len(),
            ]
        }))
        .max()
        .unwrap_or(0)
        .max(1);
        let mut fft = Fft2 {
            m,
            n,
            r2c,
            c2r,
            col_fwd,
            col_inv,
            split,
            tile: tile_rows(m),
            threads: Threads::serial(),
            tasks: Vec::new(),
            scratch_len,
        };
        fft.tasks.push(fft.task_bufs());
        fft
    }

    fn task_bufs(&self) -> TaskBufs {
        let h = self.m / 2 + 1;
        TaskBufs {
            row_real: vec![0.0; self.m],
            tile: vec![Complex64::default(); self.tile.min(self.m) * h],
            scratch: vec![Complex64::default(); self.scratch_len],
            columns: std::array::from_fn(|_| vec![Complex64::default(); self.m]),
        }
    }

    /// Runs the stages on `threads` from now on (buffers for its tasks are
    /// made here, not in the transforms), or on the calling thread alone
    /// when the transform is smaller than [`Threads::min_side`].
    pub fn set_threads(&mut self, threads: &Threads) {
        self.threads = if self.m >= threads.min_side() {
            threads.clone()
        } else {
            Threads::serial()
        };
        let threads = &self.threads;
        let want = threads.tasks();
        self.tasks.truncate(want);
        while self.tasks.len() < want {
            let b = self.task_bufs();
            self.tasks.push(b);
        }
    }

    /// The threads the stages run on.
    pub fn threads(&self) -> &Threads {
        &self.threads
    }

    /// Number of complex values of a (half) spectrum.
    pub fn spectrum_len(&self) -> usize {
        self.m * (self.m / 2 + 1)
    }

    /// Number of complex values of a compact spectrum: the first `N` of the
    /// `M` values of each column of a half spectrum, what the row stage of a
    /// zero-padded field fills and the cropped inverse row stage reads (the
    /// other `M − N` live only in a column pass's column, see
    /// [`Fft2::column_pass`]). Half of [`Fft2::spectrum_len`] for a padded grid.
    pub fn compact_len(&self) -> usize {
        self.n * (self.m / 2 + 1)
    }

    /// Forward transform of a full `M x M` real array (used for kernels).
    pub fn forward_full(&mut self, input: &[f64], out: &mut [Complex64]) {
        let _span = timing::Span::new();
        let threads = self.threads.clone();
        threads.install(|| self.forward_rows(input, self.m, self.m, out));
    }

    /// Forward transform of an `N x N` field (row-major, `N` columns) zero-padded to `M x M`.
    pub fn forward_padded(&mut self, input: &[f64], out: &mut [Complex64]) {
        let _span = timing::Span::new();
        let threads = self.threads.clone();
        threads.install(|| self.forward_rows(input, self.n, self.n, out));
    }

    /// Row stage of [`Fft2::forward_padded`]: the row transforms of the `N`
    /// non-zero rows, into a compact spectrum ([`Fft2::compact_len`]: the
    /// `N` non-zero values of each column). A [`Fft2::column_pass`] zero-pads
    /// and transforms one column at a time ([`Columns::forward`]), so a caller
    /// can process a column while it is in cache (the spectral products
    /// between the forward and inverse column transforms, see `Operator::apply`).
    pub fn forward_rows_padded(&mut self, input: &[f64], out: &mut [Complex64]) {
        let _span = timing::Span::new();
        self.row_stage(input, self.n, self.n, out, self.n);
    }

    /// Calls `f(kx, a_kx, b_kx, columns)` for every column `kx` of two
    /// compact spectra `a` and `b` (see [`Fft2::compact_len`]) and stores its
    /// value in `values[kx]`; the columns are shared out among the threads,
    /// each with its own [`Columns`]. `f` sees whole columns (`M` values, the
    /// compact column's `N` then whatever the last column left: the forward
    /// transform reads only the first `N`, and its result is in split order,
    /// see the module docs); with `keep`, their first `N` values are stored
    /// back (for [`Fft2::inverse_rows_cropped`]). With `two` false, `f`
    /// leaves its second column alone and `b` is not read or written.
    /// Padded grids only (`M = 2N`).
    ///
    /// (The full-height work spectra this replaces were 268 MB of the peak
    /// of a coupled 2048² solve. The column copies did not show in the
    /// time: coupled Table 1a at 1024², 21.5–21.8 s before and 21.2–21.7 s
    /// after, alternating runs; docs/performance-history.md.)
    pub fn column_pass<F>(
        &mut self,
        (a, b): (&mut [Complex64], &mut [Complex64]),
        (two, keep): (bool, bool),
        values: &mut [f64],
        f: F,
    ) where
        F: Fn(usize, &mut [Complex64], &mut [Complex64], &mut Columns<'_>) -> f64 + Sync,
    {
        let m = self.m;
        let h = m / 2 + 1;
        let n = self.n;
        assert_eq!(m, 2 * n, "a column pass needs a padded grid");
        debug_assert_eq!(a.len(), n * h);
        debug_assert_eq!(b.len(), n * h);
        debug_assert_eq!(values.len(), h);
        let (fwd, inv, twiddles) = match &self.split {
            Some(s) => (&*s.fwd, &*s.inv, &s.twiddles[..]),
            None => (&*self.col_fwd, &*self.col_inv, &[][..]),
        };
        // Columns `first..` of (a, b) through `f`, with one task's buffers.
        let run = |first: usize,
                   a: &mut [Complex64],
                   b: &mut [Complex64],
                   vals: &mut [f64],
                   bufs: &mut TaskBufs| {
            let [ca, cb] = &mut bufs.columns;
            let mut cols = Columns {
                n,
                fwd,
                inv,
                twiddles,
                scratch: &mut bufs.scratch,
            };
            let pairs = a.chunks_exact_mut(n).zip(b.chunks_exact_mut(n));
            for (k, ((sa, sb), v)) in pairs.zip(vals.iter_mut()).enumerate() {
                ca[..n].copy_from_slice(sa);
                if two {
                    cb[..n].copy_from_slice(sb);
                }
                *v = f(first + k, ca, cb, &mut cols);
                if keep {
                    sa.copy_from_slice(&ca[..n]);
                    if two {
                        sb.copy_from_slice(&cb[..n]);
                    }
                }
            }
        };
        let Some(pool) = self.threads.pool() else {
            run(0, a, b, values, &mut self.tasks[0]);
            return;
        };
        let per = h.div_ceil(self.tasks.len());
        let parts = a
            .par_chunks_mut(per * n)
            .zip(b.par_chunks_mut(per * n))
            .zip(values.par_chunks_mut(per))
            .zip(self.tasks.par_iter_mut())
            .enumerate();
        pool.install(|| {
            parts.for_each(|(t, (((a, b), vals), bufs))| run(t * per, a, b, vals, bufs))
        });
    }

    /// Puts every column (`M` values) of a spectrum in natural order
    /// (`[kx][ky]`, as [`Fft2::forward_full`] makes it) into the order of a
    /// column pass: split order for split columns (module docs), else
    /// unchanged. What a kernel spectrum multiplied in a column pass is
    /// stored in.
    pub fn to_split_order<T: Copy + Default>(&self, spec: &mut [T]) {
        self.reorder_columns(spec, true);
    }

    /// The inverse of [`Fft2::to_split_order`].
    pub fn to_natural_order<T: Copy + Default>(&self, spec: &mut [T]) {
        self.reorder_columns(spec, false);
    }

    /// Frequency `ky` of a column sits at `split(ky)` in split order; each
    /// column is moved there (`to_split`) or back.
    pub(crate) fn reorder_columns<T: Copy + Default>(&self, spec: &mut [T], to_split: bool) {
        if self.split.is_none() {
            return;
        }
        let (m, n) = (self.m, self.n);
        let split = |ky: usize| ky / 2 + (ky % 2) * n;
        let mut tmp = vec![T::default(); m];
        for col in spec.chunks_exact_mut(m) {
            for (ky, &v) in col.iter().enumerate() {
                if to_split {
                    tmp[split(ky)] = v;
                } else {
                    tmp[ky] = col[split(ky)];
                }
            }
            col.copy_from_slice(&tmp);
        }
    }

    /// Inverse row stage of [`Fft2::inverse_cropped`] (`add`: of
    /// [`Fft2::inverse_cropped_add`]) on a spectrum whose columns have been
    /// through [`Columns::inverse`].
    pub fn inverse_rows_cropped(&mut self, spec: &[Complex64], out: &mut [f64], add: bool) {
        let _span = timing::Span::new();
        self.inverse_row_stage(spec, self.n, self.n, out, add, self.n);
    }

    fn forward_rows(&mut self, input: &[f64], nrows: usize, ncols: usize, out: &mut [Complex64]) {
        let m = self.m;
        let h = m / 2 + 1;
        self.row_stage(input, nrows, ncols, out, m);
        // Zero padding rows.
        for kx in 0..h {
            out[kx * m + nrows..(kx + 1) * m].fill(Complex64::default());
        }
        self.whole_columns(out, true);
    }

    /// The column transforms (forward or inverse) of a whole spectrum.
    fn whole_columns(&mut self, spec: &mut [Complex64], forward: bool) {
        let plan = if forward {
            &self.col_fwd
        } else {
            &self.col_inv
        };
        let Some(pool) = self.threads.pool() else {
            plan.process_with_scratch(spec, &mut self.tasks[0].scratch);
            return;
        };
        let m = self.m;
        let per = (m / 2 + 1).div_ceil(self.tasks.len());
        let parts = spec.par_chunks_mut(per * m).zip(self.tasks.par_iter_mut());
        pool.install(|| {
            parts.for_each(|(s, bufs)| plan.process_with_scratch(s, &mut bufs.scratch))
        });
    }

    /// The row transforms of `nrows` rows of `input` into a transposed
    /// spectrum whose columns hold `stride` values (`M`, or `N` compact).
    fn row_stage(
        &mut self,
        input: &[f64],
        nrows: usize,
        ncols: usize,
        out: &mut [Complex64],
        stride: usize,
    ) {
        let m = self.m;
        debug_assert_eq!(input.len(), nrows * ncols);
        debug_assert_eq!(out.len(), stride * (m / 2 + 1));
        debug_assert!(nrows <= stride);
        let r2c = &*self.r2c;
        let out = Scatter::new(out);
        let at = Layout {
            m,
            stride,
            tile: self.tile,
        };
        let Some(pool) = self.threads.pool() else {
            row_tiles(r2c, &mut self.tasks[0], input, ncols, 0..nrows, at, out);
            return;
        };
        // Whole tiles per task, so the tasks' rows are disjoint.
        let per = nrows.div_ceil(self.tile).div_ceil(self.tasks.len()) * self.tile;
        let parts = self.tasks.par_iter_mut().enumerate();
        pool.install(|| {
            parts.for_each(|(t, bufs)| {
                let rows = (t * per).min(nrows)..((t + 1) * per).min(nrows);
                row_tiles(r2c, bufs, input, ncols, rows, at, out);
            })
        });
    }

    /// Row stage of a forward transform of a full `M x M` real array supplied
    /// one row at a time: transforms row `iy` (`M` values) into its place in
    /// `out`. After all rows, [`Fft2::forward_columns`] completes the transform.
    pub fn forward_row_into(&mut self, iy: usize, row: &[f64], out: &mut [Complex64]) {
        let _span = timing::Span::new();
        let m = self.m;
        let h = m / 2 + 1;
        debug_assert_eq!(row.len(), m);
        debug_assert_eq!(out.len(), m * h);
        let bufs = &mut self.tasks[0];
        bufs.row_real.copy_from_slice(row);
        let dst = &mut bufs.tile[..h];
        // Lengths are fixed by construction, so this cannot fail.
        let _ = self
            .r2c
            .process_with_scratch(&mut bufs.row_real, dst, &mut bufs.scratch);
        for (kx, v) in dst.iter().enumerate() {
            out[kx * m + iy] = *v;
        }
    }

    /// Column stage completing the rows given to [`Fft2::forward_row_into`].
    pub fn forward_columns(&mut self, out: &mut [Complex64]) {
        let _span = timing::Span::new();
        self.whole_columns(out, true);
    }

    /// Inverse transform of a spectrum (consumed as scratch) into the first
    /// `N x N` block of the real result, scaled by `1/M²`.
    pub fn inverse_cropped(&mut self, spec: &mut [Complex64], out: &mut [f64]) {
        let _span = timing::Span::new();
        let threads = self.threads.clone();
        threads.install(|| {
            self.whole_columns(spec, false);
            self.inverse_row_stage(spec, self.n, self.n, out, false, self.m);
        });
    }

    /// [`Fft2::inverse_cropped`] added to `out` instead of overwriting it.
    pub fn inverse_cropped_add(&mut self, spec: &mut [Complex64], out: &mut [f64]) {
        let _span = timing::Span::new();
        let threads = self.threads.clone();
        threads.install(|| {
            self.whole_columns(spec, false);
            self.inverse_row_stage(spec, self.n, self.n, out, true, self.m);
        });
    }

    /// Inverse transform of a spectrum (consumed as scratch) into the full
    /// `M x M` real array, scaled by `1/M²`.
    pub fn inverse_full(&mut self, spec: &mut [Complex64], out: &mut [f64]) {
        let _span = timing::Span::new();
        let threads = self.threads.clone();
        threads.install(|| {
            self.whole_columns(spec, false);
            self.inverse_row_stage(spec, self.m, self.m, out, false, self.m);
        });
    }

    /// The inverse row transforms of the first `n` rows of a transposed
    /// spectrum whose columns hold `stride` values (`M`, or `N` compact).
    fn inverse_row_stage(
        &mut self,
        spec: &[Complex64],
        n: usize,
        ncols: usize,
        out: &mut [f64],
        add: bool,
        stride: usize,
    ) {
        let m = self.m;
        debug_assert_eq!(spec.len(), stride * (m / 2 + 1));
        debug_assert_eq!(out.len(), n * ncols);
        debug_assert!(n <= stride);
        let c2r = &*self.c2r;
        let at = Layout {
            m,
            stride,
            tile: self.tile,
        };
        let Some(pool) = self.threads.pool() else {
            inverse_tiles(c2r, &mut self.tasks[0], spec, 0, ncols, at, out, add);
            return;
        };
        // Whole tiles per task: each task owns its rows of `out`.
        let per = n.div_ceil(self.tile).div_ceil(self.tasks.len()) * self.tile;
        let parts = out
            .par_chunks_mut(per * ncols)
            .zip(self.tasks.par_iter_mut())
            .enumerate();
        pool.install(|| {
            parts.for_each(|(t, (rows, bufs))| {
                inverse_tiles(c2r, bufs, spec, t * per, ncols, at, rows, add);
            })
        });
    }
}

/// The padded side `M`, the values held per column of a transposed
/// spectrum (`M` for a whole spectrum, `N` for a compact one) and the rows
/// per tile.
#[derive(Clone, Copy)]
struct Layout {
    m: usize,
    stride: usize,
    tile: usize,
}

/// Row transforms of rows `rows` of `input` (`ncols` values each, zero
/// padded to `M`), a tile at a time, each tile moved into its place in the
/// transposed spectrum `out` (`[kx][ky]`). Writes only
/// `out[kx * stride + iy]` for `iy` in `rows`.
fn row_tiles(
    r2c: &dyn RealToComplex<f64>,
    bufs: &mut TaskBufs,
    input: &[f64],
    ncols: usize,
    rows: std::ops::Range<usize>,
    Layout { m, stride, tile }: Layout,
    out: Scatter,
) {
    let h = m / 2 + 1;
    for iy0 in rows.clone().step_by(tile) {
        let iy1 = (iy0 + tile).min(rows.end);
        for (r, iy) in (iy0..iy1).enumerate() {
            bufs.row_real[..ncols].copy_from_slice(&input[iy * ncols..(iy + 1) * ncols]);
            bufs.row_real[ncols..].fill(0.0);
            let dst = &mut bufs.tile[r * h..(r + 1) * h];
            // Lengths are fixed by construction, so this cannot fail.
            let _ = r2c.process_with_scratch(&mut bufs.row_real, dst, &mut bufs.scratch);
        }
        for kx in 0..h {
            for (r, iy) in (iy0..iy1).enumerate() {
                // SAFETY: row `iy` belongs to this task's `rows` only.
                unsafe { out.write(kx * stride + iy, bufs.tile[r * h + kx]) };
            }
        }
    }
}

/// Columns ahead whose values [`inverse_tiles`] asks the cache for.
const AHEAD: usize = 4;

/// Asks the CPU for the cache line (64 bytes, four values) holding `v`: a
/// hint, which neither faults nor changes memory (a no-op off x86-64).
#[inline(always)]
fn prefetch(v: &Complex64) {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a prefetch only reads the address as a hint, and SSE is part
    // of the x86-64 baseline.
    unsafe {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        _mm_prefetch::<_MM_HINT_T0>((v as *const Complex64).cast::<i8>());
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = v;
}

/// Inverse row transforms of the rows `first..` of a transposed spectrum
/// whose columns are done, into `out` (those rows, `ncols` values each,
/// scaled by `1/M²`, added when `add`), a tile at a time.
#[allow(clippy::too_many_arguments)]
fn inverse_tiles(
    c2r: &dyn ComplexToReal<f64>,
    bufs: &mut TaskBufs,
    spec: &[Complex64],
    first: usize,
    ncols: usize,
    Layout { m, stride, tile }: Layout,
    out: &mut [f64],
    add: bool,
) {
    let h = m / 2 + 1;
    let scale = 1.0 / (m as f64 * m as f64);
    let nrows = out.len() / ncols;
    // Gather a tile from the transposed spectrum, then inverse row transforms.
    for r0 in (0..nrows).step_by(tile) {
        let r1 = (r0 + tile).min(nrows);
        let (iy0, iy1) = (first + r0, first + r1);
        for kx in 0..h {
            // The tile's part of column `kx + AHEAD` is asked for now: the
            // columns are `stride` values apart, too far for the hardware's
            // prefetcher. (At 2048² the stage took 7.4 instead of 8.1–8.5
            // ns per cell, at 1024² 6.5–7.0 instead of 7.1–7.6;
            // `--example fft_stages`.)
            if let Some(ahead) = spec.get((kx + AHEAD) * stride + iy0..(kx + AHEAD) * stride + iy1)
            {
                ahead.iter().step_by(4).for_each(prefetch);
            }
            let col = &spec[kx * stride + iy0..kx * stride + iy1];
            for (r, c) in col.iter().enumerate() {
                bufs.tile[r * h + kx] = *c;
            }
        }
        for r in 0..r1 - r0 {
            let dst = &mut bufs.tile[r * h..(r + 1) * h];
            // The imaginary parts of the DC and Nyquist bins are zero up to
            // round-off; realfft would reject them, so clear them explicitly.
            dst[0].im = 0.0;
            dst[h - 1].im = 0.0;
            let _ = c2r.process_with_scratch(dst, &mut bufs.row_real, &mut bufs.scratch);
            let row = out[(r0 + r) * ncols..(r0 + r + 1) * ncols]
                .iter_mut()
                .zip(&bufs.row_real[..ncols]);
            if add {
                row.for_each(|(o, v)| *o += v * scale);
            } else {
                row.for_each(|(o, v)| *o = v * scale);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A column pass with split columns and a kernel spectrum in split
    /// order gives the convolution of whole columns, to round-off, for even
    /// and odd sides; the orders are inverse permutations.
    #[test]
    fn split_columns_give_the_whole_columns_convolution() {
        for n in [8, 24, 33] {
            let m = 2 * n;
            let h = m / 2 + 1;
            let wave = |len: usize, a: f64| -> Vec<f64> {
                (0..len)
                    .map(|i| (i as f64 * a).sin() + 0.3 * (i as f64 * 0.11).cos())
                    .collect()
            };
            let (fa, fb) = (wave(n * n, 0.37), wave(n * n, 0.73));
            let mut kernel = vec![Complex64::default(); m * h];
            Fft2::new(n).forward_full(&wave(m * m, 0.19), &mut kernel);
            let convolve = |split: bool| -> Vec<f64> {
                let mut fft = Fft2::padded_with_split(n, split);
                let mut k = kernel.clone();
                fft.to_split_order(&mut k);
                if split {
                    assert_ne!(k, kernel);
                    let mut back = k.clone();
                    fft.to_natural_order(&mut back);
                    assert_eq!(back, kernel);
                }
                let mut a = vec![Complex64::default(); fft.compact_len()];
                let mut b = a.clone();
                fft.forward_rows_padded(&fa, &mut a);
                fft.forward_rows_padded(&fb, &mut b);
                let mut values = vec![0.0; h];
                fft.column_pass(
                    (&mut a, &mut b),
                    (true, true),
                    &mut values,
                    |kx, c0, c1, cols| {
                        cols.forward(c0);
                        cols.forward(c1);
                        let kc = &k[kx * m..(kx + 1) * m];
                        for ((x, y), k) in c0.iter_mut().zip(c1.iter_mut()).zip(kc) {
                            (*x, *y) = (*x * k + *y, *y * k.conj());
                        }
                        cols.inverse(c0);
                        cols.inverse(c1);
                        0.0
                    },
                );
                let mut out = vec![0.0; 2 * n * n];
                let (o0, o1) = out.split_at_mut(n * n);
                fft.inverse_rows_cropped(&a, o0, false);
                fft.inverse_rows_cropped(&b, o1, false);
                out
            };
            let (whole, split) = (convolve(false), convolve(true));
            let scale = whole.iter().fold(0.0_f64, |s, v| s.max(v.abs()));
            assert!(scale > 1.0);
            for (w, s) in whole.iter().zip(&split) {
                assert!((w - s).abs() < 1e-13 * scale, "n = {n}: {w} vs {s}");
            }
        }
    }

    #[test]
    fn timing_counts_transforms_only_while_on() {
        let n = 8;
        let mut fft = Fft2::new(n);
        let field: Vec<f64> = (0..n * n).map(|i| (i as f64 * 0.37).sin()).collect();
        let mut spec = vec![Complex64::default(); fft.spectrum_len()];
        let mut out = vec![0.0; n * n];
        // Off by default (each test runs on its own thread).
        fft.forward_padded(&field, &mut spec);
        assert_eq!(timing::stop(), (0.0, 0));
        timing::start();
        fft.forward_padded(&field, &mut spec);
        fft.inverse_cropped(&mut spec, &mut out);
        let (seconds, spans) = timing::stop();
        assert_eq!(spans, 2);
        assert!(seconds > 0.0);
        // Timing does not touch the numbers: the round trip is exact.
        for (a, b) in field.iter().zip(&out) {
            assert!((a - b).abs() < 1e-12, "{a} vs {b}");
        }
        // Off again after stop.
        fft.forward_padded(&field, &mut spec);
        assert_eq!(timing::stop().1, 2);
    }
}
