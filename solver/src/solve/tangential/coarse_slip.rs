//! Coarse-to-fine start of the tangential solver: the partial-slip problem
//! solved on Galerkin coarse grids (2x2 merged cells, down to 32²), each
//! solution prolonged to start the next finer one, and the last to start the
//! fine solve. The coarse levels only ever provide a starting point: the fine
//! solve runs with the caller's tolerance and KKT test, so its answer is the
//! fine problem's to that tolerance.
//!
//! A coarse cell's tangential influence coefficients are the Galerkin
//! projection of the fine ones (the same [`coarse_table`] as the normal
//! solver's levels, applied to `K_xx`, `K_yy` and `K_xy`): the block-averaged
//! displacement under a uniform traction on another block. The coarse problem
//! is the fine one restricted to block-constant tractions, with the block
//! averages of the pressure (friction bounds) and of the coupling term.

use crate::base::grid::Grid;
use crate::error::SolverError;
use crate::operators::multilevel::{coarse_table, prolong, restrict, FourierPrecond};
use crate::operators::operator::{Operator, X, Y};
use crate::solve::tangential::problem::{TangentialProblem, TangentialSolution, TangentialStart};

/// Smallest grid that is still coarsened further (as the normal solver's levels).
const MIN_COARSE_N: usize = 32;

/// The coarse tangential operators below one operator's grid (finest first).
pub struct TangentialLevels {
    /// Cells per side of the grid the levels were made for.
    fine_n: usize,
    levels: Vec<Operator>,
    /// The fine grid's Fourier preconditioner for the warm-started solves
    /// that ask for it (made on first use, kept with the levels of its grid).
    pub(crate) fourier: Option<FourierPrecond>,
}

impl TangentialLevels {
    /// The Galerkin coarse levels of `op`'s tangential block: one component at
    /// a time, its real table from the stored spectrum, merged down the chain
    /// (only one fine table is held at a time).
    pub fn new(op: &mut Operator) -> Self {
        let grid = op.grid();
        let mut grids = Vec::new();
        let mut g = grid;
        while g.n.is_multiple_of(2) && g.n / 2 >= MIN_COARSE_N {
            g = Grid {
                n: g.n / 2,
                dx: 2.0 * g.dx,
                dy: 2.0 * g.dy,
            };
            grids.push(g);
        }
        let mut tables: Vec<[Vec<f64>; 3]> = grids.iter().map(|_| Default::default()).collect();
        if !grids.is_empty() {
            for (c, (i, j)) in [(X, X), (Y, Y), (X, Y)].into_iter().enumerate() {
                crate::base::progress::tick();
                let mut t = op.table(i, j);
                let mut n = grid.n;
                for (level, g) in tables.iter_mut().zip(&grids) {
                    crate::base::progress::tick();
                    t = coarse_table(&t, n);
                    level[c] = t.clone();
                    n = g.n;
                }
            }
        }
        let levels = grids
            .iter()
            .zip(tables)
            .map(|(&g, [xx, yy, xy])| {
                crate::base::progress::tick();
                Operator::tangential_from_tables(g, &xx, &yy, &xy)
            })
            .collect();
        TangentialLevels {
            fine_n: grid.n,
            levels,
            fourier: None,
        }
    }

    /// Cells per side of the grid these levels were made for.
    pub fn fine_n(&self) -> usize {
        self.fine_n
    }

    /// Number of coarse levels.
    pub fn len(&self) -> usize {
        self.levels.len()
    }

    /// True when the grid is too small (or odd) for a coarse level.
    pub fn is_empty(&self) -> bool {
        self.levels.is_empty()
    }
}

/// Tractions `(qx, qy)` prolonged from the coarse levels, and the coarse
/// iterations spent on them.
pub(crate) type CoarseStart = (Vec<f64>, Vec<f64>, usize);

/// The single-grid tangential solve run on each coarse level. The tangential
/// solver passes its own (`tangential::solve_tangential_on_grid`): it sits
/// above this module, which therefore never imports it.
pub(crate) type GridSolve =
    fn(&mut Operator, &TangentialProblem) -> Result<TangentialSolution, SolverError>;

/// A start for the fine solve of `prob` (on the grid `levels` were made for):
/// the tractions of the coarse solves, coarsest first, each prolonged to the
/// next level, and the coarse iterations spent. `None` when there are no
/// levels or a coarse problem has no partial-slip solution (the fine solve
/// then starts as asked, and reports its own verdict). Each level is solved
/// by `solve_on_grid`.
///
/// `extra`: the fine grid's extra diagonal (its cut cells,
/// [`Operator::extra_diagonal`]); each level gets its Galerkin restriction,
/// the mean over the merged cells, so that the coarse problems see the cut
/// cells' compliance too: the coarse problems are then the Galerkin
/// projection of the fine one, cut cells included (quick sweep, tangential
/// iterations summed over the 14 cases of each pattern: circle-A 1527 →
/// 1498, circle-B 1687 → 1601, square-B 1979 → 1847; μa within 2e-7).
pub(crate) fn coarse_start(
    levels: &mut TangentialLevels,
    prob: &TangentialProblem,
    solve_on_grid: GridSolve,
    extra: Option<&[(usize, f64)]>,
) -> Result<Option<CoarseStart>, SolverError> {
    if levels.is_empty() {
        return Ok(None);
    }
    // The extra diagonal restricted down the chain (none: every level's
    // cleared, as the levels outlive the case).
    let mut fine_n = levels.fine_n;
    let mut diag: Option<Vec<(usize, f64)>> = extra.map(<[_]>::to_vec);
    for op in &mut levels.levels {
        diag = diag.map(|d| restrict_diagonal(&d, fine_n));
        op.set_extra_diagonal(diag.as_deref());
        fine_n /= 2;
    }
    // Pressures and coupling terms restricted down the chain, finest first.
    let mut ps = vec![restrict(prob.p, levels.fine_n)];
    let mut es: Vec<Option<(Vec<f64>, Vec<f64>)>> = vec![prob
        .extra
        .map(|(ex, ey)| (restrict(ex, levels.fine_n), restrict(ey, levels.fine_n)))];
    for l in 1..levels.len() {
        let n = levels.levels[l - 1].grid().n;
        let p = restrict(&ps[l - 1], n);
        let e = es[l - 1]
            .as_ref()
            .map(|(ex, ey)| (restrict(ex, n), restrict(ey, n)));
        ps.push(p);
        es.push(e);
    }

    // Every level is solved to the caller's tolerance: a looser one leaves
    // the fine iteration more to do than the coarse iterations saved
    // (Cattaneo–Mindlin 1024², tolerance 1e-6: fine iterations 237 plain,
    // 179 after coarse solves to 1e-5, 163 after coarse solves to 1e-6,
    // as at 512²: 178 plain, 161 after coarse solves to 1e-6).
    let mut iterations = 0;
    let mut start: Option<(Vec<f64>, Vec<f64>)> = None;
    for l in (0..levels.len()).rev() {
        let op = &mut levels.levels[l];
        let sub = TangentialProblem {
            p: &ps[l],
            extra: es[l].as_ref().map(|(x, y)| (&x[..], &y[..])),
            start: match &start {
                Some((x, y)) => TangentialStart::Tractions(x, y),
                None => TangentialStart::Proportional,
            },
            ..*prob
        };
        let solved = solve_on_grid(op, &sub);
        // A level is used once per start: its work spectra are not kept
        // between starts (see `Operator::release_work`).
        op.release_work();
        let sol = match solved {
            Ok(s) => s,
            Err(SolverError::GrossSliding { .. }) => return Ok(None),
            Err(e) => return Err(e),
        };
        iterations += sol.report.iterations;
        if !sol.report.converged {
            return Ok(None);
        }
        // The next finer level's pressure (the caller's on the fine grid).
        let finer_p: &[f64] = if l == 0 { prob.p } else { &ps[l - 1] };
        start = Some(prolong_tractions(
            &sol,
            &ps[l],
            finer_p,
            prob.friction,
            op.grid().n,
        ));
    }
    Ok(start.map(|(x, y)| (x, y, iterations)))
}

/// The Galerkin restriction of a diagonal on an `n x n` grid to the
/// `n/2 x n/2` grid of merged 2x2 cells: a quarter of the sum over each
/// block (the block-averaged displacement under a uniform traction on it).
fn restrict_diagonal(d: &[(usize, f64)], n: usize) -> Vec<(usize, f64)> {
    let nc = n / 2;
    let mut sums = std::collections::BTreeMap::new();
    for &(c, v) in d {
        let (ix, iy) = (c % n, c / n);
        *sums.entry((iy / 2) * nc + ix / 2).or_insert(0.0) += 0.25 * v;
    }
    sums.into_iter().collect()
}

/// Fine tractions from a coarse solution: the traction relative to its bound,
/// `r = q / (μ p)` (|r| ≤ 1), interpolated bilinearly and multiplied by the
/// fine bound `μ p`; in cells whose coarse cell slips, `r` is a unit vector
/// (those cells start on their disc's edge, as the slip zone they continue).
/// Interpolating `q` itself would blur the slip zone's `|q| = μp` where `p`
/// falls to zero at the contact edge.
fn prolong_tractions(
    sol: &TangentialSolution,
    pc: &[f64],
    pf: &[f64],
    mu: f64,
    nc: usize,
) -> (Vec<f64>, Vec<f64>) {
    let ratio = |q: &[f64]| -> Vec<f64> {
        q.iter()
            .zip(pc)
            .map(|(&q, &p)| if p > 0.0 { q / (mu * p) } else { 0.0 })
            .collect()
    };
    let (rx, ry) = (prolong(&ratio(&sol.qx), nc), prolong(&ratio(&sol.qy), nc));
    let n = 2 * nc;
    let (mut qx, mut qy) = (vec![0.0; n * n], vec![0.0; n * n]);
    for i in 0..n * n {
        if pf[i] <= 0.0 {
            continue;
        }
        let parent = (i / n / 2) * nc + (i % n) / 2;
        let (mut x, mut y) = (rx[i], ry[i]);
        let r = x.hypot(y);
        let slips = pc[parent] > 0.0 && !sol.stick[parent];
        if r > 0.0 && (slips || r > 1.0) {
            x /= r;
            y /= r;
        }
        let b = mu * pf[i];
        qx[i] = b * x;
        qy[i] = b * y;
    }
    (qx, qy)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::green::influence::isotropic_cell;

    /// Each coarse level applies exactly R C P: the block-averaged fine
    /// tangential displacement under block-constant tractions.
    #[test]
    fn coarse_tangential_operators_are_the_galerkin_projection_to_1e12() {
        let grid = Grid {
            n: 64,
            dx: 1.0e-6,
            dy: 1.3e-6,
        };
        let (g, nu) = (80.0e9, 0.3);
        let mut op = Operator::build(grid, |x, y| isotropic_cell(g, nu, x, y, grid.dx, grid.dy));
        let mut levels = TangentialLevels::new(&mut op);
        assert_eq!(levels.len(), 1);
        let nc = 32;
        let field = |seed: usize| -> Vec<f64> {
            (0..nc * nc)
                .map(|i| (i * seed % 101) as f64 / 101.0 - 0.4)
                .collect()
        };
        let (cx, cy) = (field(37), field(53));
        let fine = |c: &[f64]| -> Vec<f64> {
            (0..64 * 64)
                .map(|i| c[(i / 64 / 2) * nc + (i % 64) / 2])
                .collect()
        };
        let (fx, fy) = (fine(&cx), fine(&cy));
        let (mut ux, mut uy) = (vec![0.0; 64 * 64], vec![0.0; 64 * 64]);
        op.tangential(&fx, &fy, &mut ux, &mut uy);
        let (mut vx, mut vy) = (vec![0.0; nc * nc], vec![0.0; nc * nc]);
        levels.levels[0].tangential(&cx, &cy, &mut vx, &mut vy);
        for (u, v) in [(restrict(&ux, 64), vx), (restrict(&uy, 64), vy)] {
            let scale = u.iter().fold(0.0_f64, |m, a| m.max(a.abs()));
            let err = u
                .iter()
                .zip(&v)
                .fold(0.0_f64, |m, (a, b)| m.max((a - b).abs()));
            assert!(err < 1e-12 * scale, "err {err:e} of {scale:e}");
        }
    }
}
