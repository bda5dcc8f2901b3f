//! Real-to-complex 2-D FFTs on the padded `M x M` grid (M = 2N) used by DC-FFT.
//! Owns FFT plans and scratch; knows nothing about kernels or physics.
//!
//! Layout: real arrays are row-major `[iy][ix]` with `M` columns. Spectra are
//! stored *transposed*, `[kx][ky]` with `M/2 + 1` rows of `M` complex values,
//! so the column transforms run on contiguous memory. Forward transforms may
//! assume that only the first `N` rows and columns of the input are non-zero
//! (zero padding), and inverse transforms only produce the first `N` rows.

use num_complex::Complex64;
use realfft::{ComplexToReal, RealFftPlanner, RealToComplex};
use rustfft::{Fft, FftPlanner};
use std::sync::Arc;

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
        static SPANS: Cell<u64> = const { Cell::new(0) };
    }

    /// Starts timing this thread's transforms from zero.
    pub fn start() {
        ON.set(true);
        SECONDS.set(0.0);
        SPANS.set(0);
    }

    /// Stops timing; returns the seconds spent in transforms and the number
    /// of timed spans (each includes about one clock read of overhead, which
    /// the caller can calibrate with empty spans).
    pub fn stop() -> (f64, u64) {
        ON.set(false);
        (SECONDS.get(), SPANS.get())
    }

    /// One timed span: from its creation to its drop, when timing is on.
    pub struct Span(Option<Instant>);

    impl Span {
        /// Starts a span (a no-op unless timing is on).
        #[inline]
        #[allow(clippy::new_without_default)]
        pub fn new() -> Self {
            Span(ON.get().then(Instant::now))
        }
    }

    impl Drop for Span {
        #[inline]
        fn drop(&mut self) {
            if let Some(t) = self.0 {
                SECONDS.set(SECONDS.get() + t.elapsed().as_secs_f64());
                SPANS.set(SPANS.get() + 1);
            }
        }
    }
}

/// Rows transformed together and moved to (from) the transposed spectrum as
/// one tile: the tile (`TILE x (M/2 + 1)` complex values) stays in cache.
const TILE: usize = 16;

/// FFT plans and scratch for one padded grid size. Build once, apply many times.
pub struct Fft2 {
    m: usize,
    n: usize,
    r2c: Arc<dyn RealToComplex<f64>>,
    c2r: Arc<dyn ComplexToReal<f64>>,
    col_fwd: Arc<dyn Fft<f64>>,
    col_inv: Arc<dyn Fft<f64>>,
    row_real: Vec<f64>,
    /// `TILE` row spectra, `[row][kx]`.
    tile: Vec<Complex64>,
    scratch: Vec<Complex64>,
}

impl Fft2 {
    /// Plans for an `n x n` physical grid padded to `2n x 2n`.
    pub fn new(n: usize) -> Self {
        Self::with_sizes(n, 2 * n)
    }

    /// Plans for an `n x n` field on an unpadded periodic `n x n` grid.
    pub fn periodic(n: usize) -> Self {
        Self::with_sizes(n, n)
    }

    /// The padded-grid side (`2n`, or `n` for a periodic transform).
    pub fn padded_len(&self) -> usize {
        self.m
    }

    fn with_sizes(n: usize, m: usize) -> Self {
        let mut rp = RealFftPlanner::<f64>::new();
        let r2c = rp.plan_fft_forward(m);
        let c2r = rp.plan_fft_inverse(m);
        let mut cp = FftPlanner::<f64>::new();
        let col_fwd = cp.plan_fft_forward(m);
        let col_inv = cp.plan_fft_inverse(m);
        let h = m / 2 + 1;
        let scratch_len = [
            r2c.get_scratch_len(),
            c2r.get_scratch_len(),
            col_fwd.get_inplace_scratch_len(),
            col_inv.get_inplace_scratch_len(),
        ]
        .into_iter()
        .max()
        .unwrap_or(0)
        .max(1);
        Fft2 {
            m,
            n,
            r2c,
            c2r,
            col_fwd,
            col_inv,
            row_real: vec![0.0; m],
            tile: vec![Complex64::default(); TILE.min(m) * h],
            scratch: vec![Complex64::default(); scratch_len],
        }
    }

    /// Number of complex values of a (half) spectrum.
    pub fn spectrum_len(&self) -> usize {
        self.m * (self.m / 2 + 1)
    }

    /// Forward transform of a full `M x M` real array (used for kernels).
    pub fn forward_full(&mut self, input: &[f64], out: &mut [Complex64]) {
        let _span = timing::Span::new();
        self.forward_rows(input, self.m, self.m, out);
    }

    /// Forward transform of an `N x N` field (row-major, `N` columns) zero-padded to `M x M`.
    pub fn forward_padded(&mut self, input: &[f64], out: &mut [Complex64]) {
        let _span = timing::Span::new();
        self.forward_rows(input, self.n, self.n, out);
    }

    /// Row stage of [`Fft2::forward_padded`]: the row transforms of the `N`
    /// non-zero rows, in place in the transposed spectrum. Entries `N..M` of
    /// each column are left as they were; [`Fft2::forward_column`] zeroes and
    /// transforms one column, so a caller can process a column while it is in
    /// cache (the spectral products between the forward and inverse column
    /// transforms, see `Operator::apply`).
    pub fn forward_rows_padded(&mut self, input: &[f64], out: &mut [Complex64]) {
        let _span = timing::Span::new();
        self.row_stage(input, self.n, self.n, out);
    }

    /// Column `kx` (`M` values, `col`) of a spectrum after
    /// [`Fft2::forward_rows_padded`]: zero padding, then the forward column transform.
    pub fn forward_column(&mut self, col: &mut [Complex64]) {
        let _span = timing::Span::new();
        debug_assert_eq!(col.len(), self.m);
        col[self.n..].fill(Complex64::default());
        self.col_fwd.process_with_scratch(col, &mut self.scratch);
    }

    /// Inverse column transform of column `col` (`M` values) of a spectrum;
    /// [`Fft2::inverse_rows_cropped`] completes the inverse transform.
    pub fn inverse_column(&mut self, col: &mut [Complex64]) {
        let _span = timing::Span::new();
        debug_assert_eq!(col.len(), self.m);
        self.col_inv.process_with_scratch(col, &mut self.scratch);
    }

    /// Row stage of [`Fft2::inverse_cropped`] (`add`: of
    /// [`Fft2::inverse_cropped_add`]) on a spectrum whose columns have been
    /// through [`Fft2::inverse_column`].
    pub fn inverse_rows_cropped(&mut self, spec: &mut [Complex64], out: &mut [f64], add: bool) {
        let _span = timing::Span::new();
        self.inverse_row_stage(spec, self.n, self.n, out, add);
    }

    fn forward_rows(&mut self, input: &[f64], nrows: usize, ncols: usize, out: &mut [Complex64]) {
        let m = self.m;
        let h = m / 2 + 1;
        self.row_stage(input, nrows, ncols, out);
        // Zero padding rows.
        for kx in 0..h {
            out[kx * m + nrows..(kx + 1) * m].fill(Complex64::default());
        }
        self.col_fwd.process_with_scratch(out, &mut self.scratch);
    }

    fn row_stage(&mut self, input: &[f64], nrows: usize, ncols: usize, out: &mut [Complex64]) {
        let m = self.m;
        let h = m / 2 + 1;
        debug_assert_eq!(input.len(), nrows * ncols);
        debug_assert_eq!(out.len(), m * h);
        // Row transforms of the non-zero rows, a tile at a time, each tile
        // moved into its place in the transposed spectrum ([kx][ky]).
        for iy0 in (0..nrows).step_by(TILE) {
            let iy1 = (iy0 + TILE).min(nrows);
            for (r, iy) in (iy0..iy1).enumerate() {
                self.row_real[..ncols].copy_from_slice(&input[iy * ncols..(iy + 1) * ncols]);
                self.row_real[ncols..].fill(0.0);
                let dst = &mut self.tile[r * h..(r + 1) * h];
                // Lengths are fixed by construction, so this cannot fail.
                let _ = self
                    .r2c
                    .process_with_scratch(&mut self.row_real, dst, &mut self.scratch);
            }
            for kx in 0..h {
                let col = &mut out[kx * m + iy0..kx * m + iy1];
                for (r, c) in col.iter_mut().enumerate() {
                    *c = self.tile[r * h + kx];
                }
            }
        }
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
        self.row_real.copy_from_slice(row);
        let dst = &mut self.tile[..h];
        // Lengths are fixed by construction, so this cannot fail.
        let _ = self
            .r2c
            .process_with_scratch(&mut self.row_real, dst, &mut self.scratch);
        for (kx, v) in dst.iter().enumerate() {
            out[kx * m + iy] = *v;
        }
    }

    /// Column stage completing the rows given to [`Fft2::forward_row_into`].
    pub fn forward_columns(&mut self, out: &mut [Complex64]) {
        let _span = timing::Span::new();
        self.col_fwd.process_with_scratch(out, &mut self.scratch);
    }

    /// Inverse transform of a spectrum (consumed as scratch) into the first
    /// `N x N` block of the real result, scaled by `1/M²`.
    pub fn inverse_cropped(&mut self, spec: &mut [Complex64], out: &mut [f64]) {
        let _span = timing::Span::new();
        self.inverse_columns(spec);
        self.inverse_row_stage(spec, self.n, self.n, out, false);
    }

    /// [`Fft2::inverse_cropped`] added to `out` instead of overwriting it.
    pub fn inverse_cropped_add(&mut self, spec: &mut [Complex64], out: &mut [f64]) {
        let _span = timing::Span::new();
        self.inverse_columns(spec);
        self.inverse_row_stage(spec, self.n, self.n, out, true);
    }

    /// Inverse transform of a spectrum (consumed as scratch) into the full
    /// `M x M` real array, scaled by `1/M²`.
    pub fn inverse_full(&mut self, spec: &mut [Complex64], out: &mut [f64]) {
        let _span = timing::Span::new();
        self.inverse_columns(spec);
        self.inverse_row_stage(spec, self.m, self.m, out, false);
    }

    /// Inverse column transforms of a whole spectrum.
    fn inverse_columns(&mut self, spec: &mut [Complex64]) {
        self.col_inv.process_with_scratch(spec, &mut self.scratch);
    }

    fn inverse_row_stage(
        &mut self,
        spec: &mut [Complex64],
        n: usize,
        ncols: usize,
        out: &mut [f64],
        add: bool,
    ) {
        let m = self.m;
        let h = m / 2 + 1;
        debug_assert_eq!(spec.len(), m * h);
        debug_assert_eq!(out.len(), n * ncols);
        let scale = 1.0 / (m as f64 * m as f64);
        // The first n rows, a tile at a time: gather from the transposed
        // spectrum, then inverse row transforms.
        for iy0 in (0..n).step_by(TILE) {
            let iy1 = (iy0 + TILE).min(n);
            for kx in 0..h {
                let col = &spec[kx * m + iy0..kx * m + iy1];
                for (r, c) in col.iter().enumerate() {
                    self.tile[r * h + kx] = *c;
                }
            }
            for (r, iy) in (iy0..iy1).enumerate() {
                let dst = &mut self.tile[r * h..(r + 1) * h];
                // The imaginary parts of the DC and Nyquist bins are zero up to
                // round-off; realfft would reject them, so clear them explicitly.
                dst[0].im = 0.0;
                dst[h - 1].im = 0.0;
                let _ = self
                    .c2r
                    .process_with_scratch(dst, &mut self.row_real, &mut self.scratch);
                let row = out[iy * ncols..(iy + 1) * ncols]
                    .iter_mut()
                    .zip(&self.row_real[..ncols]);
                if add {
                    row.for_each(|(o, v)| *o += v * scale);
                } else {
                    row.for_each(|(o, v)| *o = v * scale);
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
