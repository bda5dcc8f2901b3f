//! The contact window of the tangential solver: the smallest square window
//! of the grid that holds every contact cell, and the window operator a
//! tangential solve runs on (kept between solves of the same window size).
//! Knows the grid's cells and the operator's window construction; no contact
//! conditions.

use crate::operators::operator::Operator;
use crate::solve::tangential::coarse_slip::TangentialLevels;

/// A square `n x n` window of an `N x N` grid, its first cell at column `x0`, row `y0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Window {
    /// Cells per side of the grid.
    pub grid_n: usize,
    /// Cells per side of the window.
    pub n: usize,
    /// Column of the window's first cell.
    pub x0: usize,
    /// Row of the window's first cell.
    pub y0: usize,
}

impl Window {
    /// The window's values of a grid field (row-major).
    pub fn gather<T: Copy>(&self, field: &[T]) -> Vec<T> {
        let mut out = Vec::with_capacity(self.n * self.n);
        for iy in self.y0..self.y0 + self.n {
            let row = iy * self.grid_n + self.x0;
            out.extend_from_slice(&field[row..row + self.n]);
        }
        out
    }

    /// A grid field holding `part` on the window and `fill` elsewhere.
    pub fn scatter<T: Copy>(&self, part: &[T], fill: T) -> Vec<T> {
        let mut out = vec![fill; self.grid_n * self.grid_n];
        for (r, iy) in (self.y0..self.y0 + self.n).enumerate() {
            let row = iy * self.grid_n + self.x0;
            out[row..row + self.n].copy_from_slice(&part[r * self.n..(r + 1) * self.n]);
        }
        out
    }
}

/// Smallest window side `≥ side` whose padded transforms are fast: a multiple
/// of 8 whose quotient has no prime factors but 2, 3 and 7 (8, 16, 24, 32, 48,
/// 56, 64, 72, 96, 112, 128, ...). Measured with rustfft on the development
/// machine, padded sizes with a factor 5 or 13 cost more per point (a window of
/// 120 cells took longer than one of 128, 240 as long as 256).
fn window_side(side: usize) -> usize {
    let smooth = |mut k: usize| {
        for f in [2, 3, 7] {
            while k.is_multiple_of(f) {
                k /= f;
            }
        }
        k == 1
    };
    let mut k = side.div_ceil(8).max(1);
    while !smooth(k) {
        k += 1;
    }
    8 * k
}

/// The window of an `n x n` grid that holds every cell with `p > 0`, or `None`
/// when such a window would not be clearly smaller than the grid (over 80 %
/// of its side) or there is no contact. It depends on `p` alone (not on the
/// window an operator keeps from an earlier solve), so a case's result does
/// not depend on which cases a worker solved before it.
pub fn contact_window(n: usize, p: &[f64]) -> Option<Window> {
    let (mut x0, mut x1, mut y0, mut y1) = (usize::MAX, 0, usize::MAX, 0);
    for (iy, row) in p.chunks_exact(n).enumerate() {
        for (ix, _) in row.iter().enumerate().filter(|(_, &v)| v > 0.0) {
            x0 = x0.min(ix);
            x1 = x1.max(ix);
            y0 = y0.min(iy);
            y1 = y1.max(iy);
        }
    }
    if x0 == usize::MAX {
        return None;
    }
    let wn = window_side((x1 - x0).max(y1 - y0) + 1);
    if 5 * wn > 4 * n {
        return None;
    }
    Some(Window {
        grid_n: n,
        n: wn,
        x0: x0.min(n - wn),
        y0: y0.min(n - wn),
    })
}

/// The window operator the tangential solver keeps for one operator: the
/// last window size asked for. A window of another size replaces it. With it,
/// the coarse tangential levels of that window and of the whole grid (the
/// coarse-to-fine start), made on first use.
#[derive(Default)]
pub struct WindowCache {
    window: Option<Box<Operator>>,
    window_levels: Option<TangentialLevels>,
    grid_levels: Option<TangentialLevels>,
}

impl WindowCache {
    /// The operator of an `nw x nw` window of `op`'s grid (see
    /// [`Operator::window_operator`]), built on first use of that size.
    pub fn operator(&mut self, op: &mut Operator, nw: usize) -> &mut Operator {
        if self.window.as_ref().map(|w| w.grid().n) != Some(nw) {
            // Free the old window before building the new one (lower peak).
            self.window = None;
            self.window_levels = None;
            self.window = Some(Box::new(op.window_operator(nw)));
        }
        self.window.as_mut().expect("set above")
    }

    /// The window operator of [`WindowCache::operator`] and its coarse
    /// tangential levels (made on first use).
    pub fn operator_and_levels(
        &mut self,
        op: &mut Operator,
        nw: usize,
    ) -> (&mut Operator, &mut TangentialLevels) {
        self.operator(op, nw);
        let w = self.window.as_mut().expect("set above");
        let levels = self
            .window_levels
            .get_or_insert_with(|| TangentialLevels::new(w));
        (w, levels)
    }

    /// The coarse tangential levels of `op`'s whole grid (made on first use).
    pub fn grid_levels(&mut self, op: &mut Operator) -> &mut TangentialLevels {
        if self.grid_levels.as_ref().map(|l| l.fine_n()) != Some(op.grid().n) {
            self.grid_levels = None;
            self.grid_levels = Some(TangentialLevels::new(op));
        }
        self.grid_levels.as_mut().expect("set above")
    }

    /// Frees the window operator and the coarse levels kept, if any.
    pub fn clear(&mut self) {
        self.window = None;
        self.window_levels = None;
        self.grid_levels = None;
    }

    /// The side of the window operator kept, if any.
    pub fn side(&self) -> Option<usize> {
        self.window.as_ref().map(|w| w.grid().n)
    }
}
