//! The partial-slip problem's iteration: an active-set method whose inner
//! preconditioned conjugate gradient runs on a frozen stick/slip split
//! (Zhao, Vollebregt & Oosterlee, J. Comput. Phys. 288 (2015), CONTACT's
//! TangCG), with the exact inverse of the discrete compliance's circulant
//! embedding as its preconditioner. The design and the measurements behind
//! each of its parts are in `docs/physics-choices.md` ("The tangential
//! iteration"); the numerical study it follows is
//! `../shared/research/tangential-precond/`.
//!
//! The problem: tractions `q` on the contact cells with `|q_i| ≤ b_i`
//! (`b_i = μ p_i`) and `Σ q = F/ΔA`, slip `s = C q + e` (`e`: the coupling
//! term, or minus the last state's displacement in a load history); stick
//! cells slip with the rigid shift, `s_i = δ`, slip cells carry `|q_i| =
//! b_i` against their slip, `q_i ∥ −(s_i − δ)`.
//!
//! * **Unknowns on a frozen split.** Stick cells carry `(q_x, q_y)`; a slip
//!   cell carries one unknown along the tangent `t_i` of its rim, with the
//!   rim's curvature `κ_i = |n_i · (s_i − δ)| / b_i` on its diagonal (a
//!   Newton step on its direction). The linear system is symmetric positive
//!   definite on `{Σ q = 0}`; `δ` is the multiplier of that constraint.
//! * **Inner solve:** projected PCG with the constraint preconditioner
//!   `P_M = M − M B (Bᵀ M B)⁻¹ Bᵀ M` (`B`: the two force columns); every
//!   iteration removes the `range(B)` part of the residual (Gould, Hribar &
//!   Nocedal 2001), without which the multiplier's part, 10⁶ times the rest
//!   near the tolerance, spoils `rᵀz`. Conjugacy restarts only at a split
//!   update.
//! * **Preconditioner `M`:** interpolated in `κ` between the inverse of the
//!   `2N`-circulant embedding of the tangential block (stick cells, and slip
//!   cells with `κ ≤ C₀₀`), the inverse of the shifted symbol `Ĉ + 4 C₀₀ I`
//!   and Jacobi `1/(C₀₀ + κ)` from `16 C₀₀` on, with hat weights linear in
//!   `log κ`: `M = Σ_j W_j^½ R (Ĉ + κ_j I)⁻¹ Rᵀ W_j^½ + W_J D⁻¹`, symmetric
//!   positive definite. Cut cells are scaled by their own compliance's
//!   factor on both sides.
//! * **Outer update (primal–dual active set):** stick cells over their bound
//!   become slip cells on their rims; slip cells whose slip runs along their
//!   traction become stick cells; every slip cell goes back onto its rim,
//!   directions and `κ` are linearised again, and the `M`-weighted shift
//!   `M B (Bᵀ M B)⁻¹ d` restores the force.
//! * **Inexact steps:** the PCG hands over to an outer update as soon as the
//!   KKT measure has fallen tenfold since its restart and the split would
//!   change; the last run goes to the tolerance.
//! * **Projection guess:** before the first PCG, stick cells that the force
//!   shift put over their bounds become slip cells.
//! * **Without the force condition** ([`Condition::Shift`], displacement
//!   control): `δ` is imposed (the caller folds it into `e`, so the slip is
//!   measured from it) and `Σ q` is free. The frozen system is then SPD on
//!   the whole space, the PCG runs with `M` alone (no deflation, no `P_M`,
//!   no force shift, no columns `M e_k`), and a split without stick cells
//!   (gross slip) is solved like any other.

use crate::base::parallel::{Chunks, Threads};
use crate::error::SolverError;
use crate::operators::operator::Operator;

/// `|(x, y)|` without `hypot`'s overflow guard (tractions and slips are far
/// from the f64 range; `hypot` cost a twentieth of a tangential solve).
#[inline(always)]
pub(crate) fn norm(x: f64, y: f64) -> f64 {
    (x * x + y * y).sqrt()
}

/// The feasible set of a solve, { |q_i| ≤ b_i on `cells`, Σ q_i = target }.
#[derive(Clone, Copy)]
pub(crate) struct Feasible<'a> {
    /// The contact cells.
    pub cells: &'a [usize],
    /// Their fixed pieces, on which every pass over them runs, and the
    /// threads those passes may use (see [`crate::base::parallel`]).
    pub chunks: &'a Chunks<'a>,
    pub threads: &'a Threads,
    /// Pressure per cell, Pa: the friction bound is [`Feasible::bound`].
    pub p: &'a [f64],
    /// Friction coefficient.
    pub mu: f64,
    /// Σ b_i over `cells` (fixed for a solve, so it is summed once).
    pub cap: f64,
    /// Σ q_i required: the force over the cell area, Pa.
    pub target: [f64; 2],
}

impl<'a> Feasible<'a> {
    /// The set of the contact cells of `chunks` of the pressure `p`.
    pub fn new(
        (chunks, threads): (&'a Chunks<'a>, &'a Threads),
        cells: &'a [usize],
        p: &'a [f64],
        mu: f64,
        target: [f64; 2],
    ) -> Self {
        let mut set = Feasible {
            cells,
            chunks,
            threads,
            p,
            mu,
            cap: 0.0,
            target,
        };
        // Σ b_i over the contact cells: the largest force the discs can carry.
        let parts = threads.chunked(chunks, chunks.items(), |part| {
            let mut s = 0.0;
            for &i in part.list() {
                s += set.bound(i);
            }
            s
        });
        set.cap = parts.into_iter().fold(0.0, |a, b| a + b);
        set
    }

    /// Friction bound b_i = μ p_i of cell `i`, Pa (computed where it is
    /// used: a stored field of them was 34 MB of a 2048² solve's peak).
    #[inline]
    pub fn bound(&self, i: usize) -> f64 {
        self.mu * self.p[i].max(0.0)
    }
}

/// The solution of the 2x2 system `a x = b` by Cramer's rule, or `None`
/// when `a` is singular to working precision (|det| ≤ 1e-300).
pub(crate) fn solve2(a: [[f64; 2]; 2], b: [f64; 2]) -> Option<[f64; 2]> {
    let det = a[0][0] * a[1][1] - a[0][1] * a[1][0];
    (det.abs() > 1e-300).then(|| {
        [
            (a[1][1] * b[0] - a[0][1] * b[1]) / det,
            (a[0][0] * b[1] - a[1][0] * b[0]) / det,
        ]
    })
}

/// What the iteration is asked besides the problem.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Controls {
    /// KKT tolerance, relative to `max(|δ|, floor)`.
    pub tolerance: f64,
    /// Floor of the KKT measure's scale, m.
    pub floor: f64,
    /// Budget of inner iterations.
    pub budget: usize,
}

/// Outcome of the iteration.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Outcome {
    /// Inner PCG iterations.
    pub iterations: usize,
    /// Tangential operator applications.
    pub applications: usize,
    /// Preconditioner applications (inverse circulants; a slip cell between
    /// two nodes costs two).
    pub inverses: usize,
    /// Outer updates that changed the split.
    pub split_updates: usize,
    /// The product's KKT measure of the returned state.
    pub kkt: f64,
    /// The rigid shift δ (mean slip of the stick cells), m.
    pub shift: [f64; 2],
    pub converged: bool,
}

/// Node of the shifted symbol, and the `κ` from which a slip cell takes
/// Jacobi alone, in units of a cell's own compliance `C₀₀`; the plain
/// inverse holds up to [`SOFT`]. (Study, section 4: with one node at 4 C₀₀
/// and Jacobi from 16 C₀₀ the linear solve on a converged split takes 8–10
/// iterations from 64² to 1024², largest Ritz value 2.5–4.4; three nodes
/// 3/10/30 C₀₀ keep it at 2.8 for 1.7× the transforms and the same counts on
/// a history.) Without the force condition the node is left out, the slip
/// cells between [`SOFT`] and [`JACOBI`] interpolated between the plain
/// inverse and Jacobi: it saved more iterations than the second inverse of
/// each costs nowhere (Table 1a at 128², 2 displacement-controlled cycles,
/// operator and inverse applications with / without the node: Δ = 0.05 µm
/// 2244 / 1844 at 10 increments per segment, 404 / 317 at 1; coupled 3789 /
/// 3182 and 626 / 509; Δ = 0.4 µm coupled 3385 / 2890; all without the
/// start guess of [`crate::solve::tangential_displacement`]).
const NODE: f64 = 4.0;
/// See [`NODE`].
const JACOBI: f64 = 16.0;
/// See [`NODE`].
const SOFT: f64 = 1.0;

/// The KKT measure must fall by this factor within a PCG run before an
/// outer update may interrupt it (inexact active-set steps; the study's
/// 1024² history: 71 → 26 iterations per increment against exact steps).
const INEXACT: f64 = 0.1;

/// A stick cell counts as over its bound beyond this fraction of it.
const OVER: f64 = 1e-9;

/// A slip cell slips along its traction when its slip's component along
/// it exceeds this fraction of the tolerance (times the KKT scale): such a
/// component `a` counts `2a` or more in the product's measure `|w + |w| n|`,
/// so a larger threshold let the linearised test pass where that measure
/// failed (Table 1(a) coupled at 256², a pass that cycled between the two).
const WRONG: f64 = 0.5;

/// Outer updates after which the iteration gives up (the caller's
/// projected-gradient phase takes over).
const MAX_OUTER: usize = 200;

/// The frozen split and its preconditioner.
struct Split {
    stick: Vec<bool>,
    /// Traction direction `n` of each slip cell (tangent `t = (−n_y, n_x)`).
    nx: Vec<f64>,
    ny: Vec<f64>,
    /// Rim curvature `κ` of each slip cell, m/Pa.
    kap: Vec<f64>,
    /// Square roots of the weights of node 0 (plain inverse) and node 1
    /// (shifted), and the Jacobi part `W_J / (C_ii + κ)`.
    w0: Vec<f64>,
    w1: Vec<f64>,
    wj: Vec<f64>,
    /// Whether any cell has weight on node 1.
    node1: bool,
    /// `M e_1`, `M e_2` (x and y each), `Bᵀ M B` and `Bᵀ B` (`B`: the two
    /// force columns).
    me: [(Vec<f64>, Vec<f64>); 2],
    gram: [[f64; 2]; 2],
    bb: [[f64; 2]; 2],
}

/// Per-solve constants and scratch fields.
struct Work<'a> {
    set: &'a Feasible<'a>,
    /// Whether `Σ q = target` binds (force control); without it the shift
    /// is imposed (zero in the slip the caller supplies).
    force: bool,
    extra: Option<(&'a [f64], &'a [f64])>,
    /// A whole cell's own compliance `C₀₀`, m/Pa, and the cut cells' extra
    /// own compliance (ascending cells, [`Operator::extra_diagonal`]).
    c00: f64,
    cut: Vec<(usize, f64)>,
    /// Scratch of the preconditioner.
    a: (Vec<f64>, Vec<f64>),
    b: (Vec<f64>, Vec<f64>),
    /// Scratch of the force columns `e_k`.
    e: (Vec<f64>, Vec<f64>),
    out: Outcome,
}

impl Split {
    fn new(len: usize) -> Self {
        let z = || vec![0.0; len];
        Split {
            stick: vec![false; len],
            nx: z(),
            ny: z(),
            kap: z(),
            w0: z(),
            w1: z(),
            wj: z(),
            node1: false,
            me: [(z(), z()), (z(), z())],
            gram: [[0.0; 2]; 2],
            bb: [[0.0; 2]; 2],
        }
    }

    #[inline(always)]
    fn t(&self, i: usize) -> [f64; 2] {
        [-self.ny[i], self.nx[i]]
    }

    /// `R v`: both components on stick cells, the tangential part on slip
    /// cells (in place, on the contact cells).
    fn restrict(&self, cells: &[usize], vx: &mut [f64], vy: &mut [f64]) {
        for &i in cells {
            if !self.stick[i] {
                let t = self.t(i);
                let s = t[0] * vx[i] + t[1] * vy[i];
                vx[i] = s * t[0];
                vy[i] = s * t[1];
            }
        }
    }
}

impl<'a> Work<'a> {
    /// `z = M r` (see the module's notes).
    fn precondition(
        &mut self,
        op: &mut Operator,
        sp: &Split,
        (rx, ry): (&[f64], &[f64]),
        (zx, zy): (&mut [f64], &mut [f64]),
    ) {
        let cells = self.set.cells;
        for &i in cells {
            zx[i] = sp.wj[i] * rx[i];
            zy[i] = sp.wj[i] * ry[i];
        }
        let nodes: &[(f64, &Vec<f64>)] = if sp.node1 {
            &[(0.0, &sp.w0), (NODE, &sp.w1)]
        } else {
            &[(0.0, &sp.w0)]
        };
        for &(shift, w) in nodes {
            let (ax, ay) = (&mut self.a.0, &mut self.a.1);
            for &i in cells {
                ax[i] = w[i] * rx[i];
                ay[i] = w[i] * ry[i];
            }
            op.scale_cut(ax);
            op.scale_cut(ay);
            let (bx, by) = (&mut self.b.0, &mut self.b.1);
            op.tangential_inverse(shift * self.c00, (ax, ay), (bx, by));
            self.out.inverses += 1;
            op.scale_cut(bx);
            op.scale_cut(by);
            sp.restrict(cells, bx, by);
            for &i in cells {
                zx[i] += w[i] * bx[i];
                zy[i] += w[i] * by[i];
            }
        }
    }

    /// `Σ_cells v` (x and y): `Bᵀ v` for a field of the unknowns' space.
    fn sums(&self, (vx, vy): (&[f64], &[f64])) -> [f64; 2] {
        let (mut sx, mut sy) = (0.0, 0.0);
        for &i in self.set.cells {
            sx += vx[i];
            sy += vy[i];
        }
        [sx, sy]
    }

    /// Freezes the split `sp.stick` with directions `sp.n` and curvatures
    /// `sp.kap`: the preconditioner's weights, `M e_k`, `Bᵀ M B` and `Bᵀ B`.
    fn freeze(&mut self, op: &mut Operator, sp: &mut Split, columns: bool) {
        let cells = self.set.cells;
        let (l_soft, l_node, l_jac) = (SOFT.ln(), NODE.ln(), JACOBI.ln());
        sp.node1 = false;
        let mut bb = [[0.0; 2]; 2];
        // The cut cells, walked along with the (ascending) contact cells.
        let mut cut = self.cut.iter().peekable();
        for &i in cells {
            if sp.stick[i] {
                sp.w0[i] = 1.0;
                sp.w1[i] = 0.0;
                sp.wj[i] = 0.0;
                bb[0][0] += 1.0;
                bb[1][1] += 1.0;
                continue;
            }
            let t = sp.t(i);
            bb[0][0] += t[0] * t[0];
            bb[0][1] += t[0] * t[1];
            bb[1][1] += t[1] * t[1];
            let k = sp.kap[i] / self.c00;
            let (w0, w1, wj) = if k <= SOFT {
                (1.0, 0.0, 0.0)
            } else if k >= JACOBI {
                (0.0, 0.0, 1.0)
            } else if !self.force {
                // No shifted node (see [`NODE`]): plain inverse to Jacobi.
                let wj = (k.ln() - l_soft) / (l_jac - l_soft);
                (1.0 - wj, 0.0, wj)
            } else if k <= NODE {
                let w1 = (k.ln() - l_soft) / (l_node - l_soft);
                (1.0 - w1, w1, 0.0)
            } else {
                let wj = (k.ln() - l_node) / (l_jac - l_node);
                (0.0, 1.0 - wj, wj)
            };
            sp.w0[i] = w0.sqrt();
            sp.w1[i] = w1.sqrt();
            while cut.next_if(|&&(c, _)| c < i).is_some() {}
            let extra = cut.next_if(|&&(c, _)| c == i).map_or(0.0, |&(_, e)| e);
            sp.wj[i] = wj / (self.c00 + extra + sp.kap[i]);
            sp.node1 |= w1 > 0.0;
        }
        bb[1][0] = bb[0][1];
        sp.bb = bb;
        if !columns || !self.force {
            return;
        }
        // M e_k, e_k = R (unit vector k).
        let mut me = std::mem::take(&mut sp.me);
        let mut e = std::mem::take(&mut self.e);
        let mut gram = [[0.0; 2]; 2];
        for (k, (mx, my)) in me.iter_mut().enumerate() {
            for &i in cells {
                e.0[i] = if k == 0 { 1.0 } else { 0.0 };
                e.1[i] = if k == 0 { 0.0 } else { 1.0 };
            }
            sp.restrict(cells, &mut e.0, &mut e.1);
            self.precondition(op, sp, (&e.0, &e.1), (mx, my));
            let s = self.sums((mx, my));
            gram[0][k] = s[0];
            gram[1][k] = s[1];
        }
        sp.me = me;
        self.e = e;
        // Bᵀ M B is symmetric; its computed halves differ by round-off.
        let off = 0.5 * (gram[0][1] + gram[1][0]);
        gram[0][1] = off;
        gram[1][0] = off;
        sp.gram = gram;
    }

    /// `r −= B (Bᵀ B)⁻¹ Bᵀ r` (the residual update of projected CG).
    fn deflate(&self, sp: &Split, (rx, ry): (&mut [f64], &mut [f64])) {
        if !self.force {
            return;
        }
        let y = solve_or_zero(sp.bb, self.sums((rx, ry)));
        for &i in self.set.cells {
            if sp.stick[i] {
                rx[i] -= y[0];
                ry[i] -= y[1];
            } else {
                let t = sp.t(i);
                let c = t[0] * y[0] + t[1] * y[1];
                rx[i] -= c * t[0];
                ry[i] -= c * t[1];
            }
        }
    }

    /// `z −= M B (Bᵀ M B)⁻¹ Bᵀ z`: `M r` into `P_M r`.
    fn project(&self, sp: &Split, (zx, zy): (&mut [f64], &mut [f64])) {
        if !self.force {
            return;
        }
        let c = solve_or_zero(sp.gram, self.sums((zx, zy)));
        let [(m1x, m1y), (m2x, m2y)] = &sp.me;
        for &i in self.set.cells {
            zx[i] -= c[0] * m1x[i] + c[1] * m2x[i];
            zy[i] -= c[0] * m1y[i] + c[1] * m2y[i];
        }
    }

    /// The `M`-weighted shift that restores the force, `x += M B (Bᵀ M
    /// B)⁻¹ (target − Σ x)`, its change added to `d`. (The orthogonal
    /// shift `B (Bᵀ B)⁻¹ (…)`, with `Π M Π` in place of `P_M`, saved the
    /// two preconditioner applications of each freeze, but on a coupled
    /// history at 256² its passes cycled between releasing and re-slipping
    /// a few cells for 200 updates.)
    fn force_shift(
        &self,
        sp: &Split,
        (xx, xy): (&mut [f64], &mut [f64]),
        (dx, dy): (&mut [f64], &mut [f64]),
    ) {
        if !self.force {
            return;
        }
        let s = self.sums((xx, xy));
        let target = self.set.target;
        let c = solve_or_zero(sp.gram, [target[0] - s[0], target[1] - s[1]]);
        let [(m1x, m1y), (m2x, m2y)] = &sp.me;
        for &i in self.set.cells {
            let (ax, ay) = (c[0] * m1x[i] + c[1] * m2x[i], c[0] * m1y[i] + c[1] * m2y[i]);
            xx[i] += ax;
            xy[i] += ay;
            dx[i] += ax;
            dy[i] += ay;
        }
    }

    /// The KKT measure of the frozen split, relative to `max(|δ|, floor)`,
    /// with `δ` and that scale (`None` without stick cells): max over stick
    /// cells of `|s − δ|`, over slip cells of the linearised `|t·(s − δ) +
    /// κ τ|` (`τ = t·x`), or (`exact`, on a state with every slip cell on
    /// its rim) the product's `|w + |w| n|` (`w = s − δ`, `n` the traction's
    /// direction: zero when the traction opposes the slip).
    fn kkt(
        &self,
        sp: &Split,
        floor: f64,
        (xx, xy): (&[f64], &[f64]),
        s: (&[f64], &[f64]),
        exact: bool,
    ) -> Option<(f64, [f64; 2], f64)> {
        self.measure(sp, floor, s, |i, w| {
            if exact {
                let r = norm(w[0], w[1]) / norm(xx[i], xy[i]);
                norm(w[0] + r * xx[i], w[1] + r * xy[i])
            } else {
                let t = sp.t(i);
                let tau = t[0] * xx[i] + t[1] * xy[i];
                (t[0] * w[0] + t[1] * w[1] + sp.kap[i] * tau).abs()
            }
        })
    }

    /// The KKT measure with slip cells' term `slip(i, s_i − δ)`: `δ` the
    /// stick cells' mean slip, the max over stick cells of `|s − δ|` and
    /// over slip cells of their term, relative to `max(|δ|, floor)`.
    /// Without the force condition `δ` is zero (imposed, and folded into
    /// the slip by the caller, whose floor carries its size) and a split
    /// without stick cells is measured like any other.
    fn measure(
        &self,
        sp: &Split,
        floor: f64,
        (sx, sy): (&[f64], &[f64]),
        slip: impl Fn(usize, [f64; 2]) -> f64,
    ) -> Option<(f64, [f64; 2], f64)> {
        let cells = self.set.cells;
        let d = if self.force {
            let (mut mx, mut my, mut ns) = (0.0, 0.0, 0usize);
            for &i in cells {
                if sp.stick[i] {
                    mx += sx[i];
                    my += sy[i];
                    ns += 1;
                }
            }
            if ns == 0 {
                return None;
            }
            [mx / ns as f64, my / ns as f64]
        } else {
            [0.0; 2]
        };
        let scale = norm(d[0], d[1]).max(floor).max(f64::MIN_POSITIVE);
        let mut e = 0.0_f64;
        for &i in cells {
            let w = [sx[i] - d[0], sy[i] - d[1]];
            e = e.max(if sp.stick[i] {
                norm(w[0], w[1])
            } else {
                slip(i, w)
            });
        }
        Some((e / scale, d, scale))
    }

    /// Whether an outer update would change the split: a stick cell over
    /// its bound, or a slip cell slipping along its traction by more than
    /// `tolerance · scale`.
    fn would_change(
        &self,
        sp: &Split,
        tol: f64,
        (d, scale): ([f64; 2], f64),
        (xx, xy): (&[f64], &[f64]),
        (sx, sy): (&[f64], &[f64]),
    ) -> bool {
        self.set.cells.iter().any(|&i| {
            if sp.stick[i] {
                norm(xx[i], xy[i]) > (1.0 + OVER) * self.set.bound(i)
            } else {
                let w = [sx[i] - d[0], sy[i] - d[1]];
                slips_along(sp, i, w, [xx[i], xy[i]], tol * scale)
            }
        })
    }

    /// The outer update: the active-set rules on every cell, every slip cell
    /// on its rim, directions and `κ` of the state `(x, s)` with shift `d`.
    /// Returns whether the split changed; the change of `x` is in `dq`.
    #[allow(clippy::too_many_arguments)]
    fn update(
        &self,
        sp: &mut Split,
        tol: f64,
        (d, scale): ([f64; 2], f64),
        (xx, xy): (&mut [f64], &mut [f64]),
        (sx, sy): (&[f64], &[f64]),
        (dx, dy): (&mut [f64], &mut [f64]),
    ) -> bool {
        let mut changed = false;
        for &i in self.set.cells {
            let b = self.set.bound(i);
            let (wx, wy) = (sx[i] - d[0], sy[i] - d[1]);
            let q = norm(xx[i], xy[i]);
            if sp.stick[i] {
                if q <= (1.0 + OVER) * b {
                    dx[i] = 0.0;
                    dy[i] = 0.0;
                    continue;
                }
                sp.stick[i] = false;
                changed = true;
            } else if slips_along(sp, i, [wx, wy], [xx[i], xy[i]], tol * scale) {
                sp.stick[i] = true;
                sp.nx[i] = 0.0;
                sp.ny[i] = 0.0;
                sp.kap[i] = 0.0;
                dx[i] = 0.0;
                dy[i] = 0.0;
                changed = true;
                continue;
            }
            let (nx, ny) = if q > 0.0 {
                (xx[i] / q, xy[i] / q)
            } else if sp.nx[i] != 0.0 || sp.ny[i] != 0.0 {
                (sp.nx[i], sp.ny[i])
            } else {
                (1.0, 0.0)
            };
            sp.nx[i] = nx;
            sp.ny[i] = ny;
            sp.kap[i] = curvature([nx, ny], [wx, wy], b);
            let (ox, oy) = (xx[i], xy[i]);
            xx[i] = b * nx;
            xy[i] = b * ny;
            dx[i] = xx[i] - ox;
            dy[i] = xy[i] - oy;
        }
        changed
    }
}

/// Whether slip cell `i` with slip `w` (relative to the shift) and traction
/// `q` slips along its traction: by more than [`WRONG`] of the tolerance
/// `limit`, or at all where the product's measure `|w + |w| q/|q||` exceeds
/// `limit` (the release it needs).
#[inline]
fn slips_along(sp: &Split, i: usize, w: [f64; 2], q: [f64; 2], limit: f64) -> bool {
    let along = sp.nx[i] * w[0] + sp.ny[i] * w[1];
    if along > WRONG * limit {
        return true;
    }
    if along <= 0.0 {
        return false;
    }
    let r = norm(w[0], w[1]) / norm(q[0], q[1]);
    norm(w[0] + r * q[0], w[1] + r * q[1]) > limit
}

/// [`solve2`], or zero where the 2x2 matrix is singular (no slip cell's
/// tangent and no stick cell: nothing to shift or project).
#[inline]
fn solve_or_zero(a: [[f64; 2]; 2], b: [f64; 2]) -> [f64; 2] {
    solve2(a, b).unwrap_or_default()
}

/// A slip cell's rim curvature `κ = max(−n·w, 0)/b`, m/Pa: its slip `w`
/// (relative to the shift) pressing its traction, of direction `n`, onto
/// the rim of radius `b`.
#[inline]
fn curvature(n: [f64; 2], w: [f64; 2], b: f64) -> f64 {
    (-(n[0] * w[0] + n[1] * w[1])).max(0.0) / b
}

/// The slip field `s = C q + e` of tractions `q` (`e`: the coupling term,
/// or minus the last state's displacement, if any).
pub(crate) fn slip_field(
    op: &mut Operator,
    extra: Option<(&[f64], &[f64])>,
    (qx, qy): (&[f64], &[f64]),
    (sx, sy): (&mut [f64], &mut [f64]),
) {
    op.tangential(qx, qy, sx, sy);
    if let Some((ex, ey)) = extra {
        for i in 0..sx.len() {
            sx[i] += ex[i];
            sy[i] += ey[i];
        }
    }
}

/// What the iteration holds besides the friction discs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Condition {
    /// `Σ q = set.target` (force control): `δ`, the stick cells' mean slip,
    /// is its multiplier; the start's slip is computed here.
    Force,
    /// Nothing more (displacement control): `δ` is imposed, folded by the
    /// caller into `e` (negated), so stick cells' slip `C q + e` must
    /// vanish; `set.target` is not read; `ctl.floor` is the measure's scale
    /// (the caller's `max(|δ|, floor)`); `s` holds the start's slip on entry
    /// (the caller computed it to choose the start); the returned `shift`
    /// is zero.
    Shift,
}

/// Solves the force-controlled partial-slip problem of `set`:
/// [`active_set_under`] with [`Condition::Force`].
pub(crate) fn active_set(
    op: &mut Operator,
    extra: Option<(&[f64], &[f64])>,
    set: &Feasible,
    ctl: Controls,
    q: (&mut [f64], &mut [f64]),
    s: (&mut [f64], &mut [f64]),
) -> Result<Outcome, SolverError> {
    active_set_under(op, extra, set, Condition::Force, ctl, q, s)
}

/// Solves the partial-slip problem of `set` under `condition` from the
/// feasible tractions `q` (a start whose cells on their rims are its slip
/// cells), leaving the solution in `q` and its slip field `C q + e` in `s`.
/// Returns with `converged` false when the budget or [`MAX_OUTER`] outer
/// updates run out, or (force control) no stick cell is left; the caller's
/// projected-gradient phase then continues from `q`.
pub(crate) fn active_set_under(
    op: &mut Operator,
    extra: Option<(&[f64], &[f64])>,
    set: &Feasible,
    condition: Condition,
    ctl: Controls,
    (qx, qy): (&mut [f64], &mut [f64]),
    (sx, sy): (&mut [f64], &mut [f64]),
) -> Result<Outcome, SolverError> {
    let len = qx.len();
    let cells = set.cells;
    let z = || vec![0.0; len];
    let mut cut = op.extra_diagonal().unwrap_or_default();
    cut.sort_unstable_by_key(|&(c, _)| c);
    let force = condition == Condition::Force;
    let mut w = Work {
        set,
        force,
        extra,
        c00: op.tangential_self(),
        cut,
        a: (z(), z()),
        b: (z(), z()),
        e: (z(), z()),
        out: Outcome::default(),
    };
    let tol = ctl.tolerance;
    let mut sp = Split::new(len);
    // The start's split: cells on their rims slip.
    for &i in cells {
        let b = set.bound(i);
        let q = norm(qx[i], qy[i]);
        sp.stick[i] = q < (1.0 - 1e-12) * b;
        if !sp.stick[i] && q > 0.0 {
            sp.nx[i] = qx[i] / q;
            sp.ny[i] = qy[i] / q;
        } else if !sp.stick[i] {
            sp.nx[i] = 1.0;
        }
    }
    if force {
        slip_field(op, w.extra, (qx, qy), (sx, sy));
        w.out.applications += 1;
    }
    let (mut dqx, mut dqy) = (z(), z());
    // κ of the start. Its force is met and its stick cells are within their
    // bounds (the caller's projection), so it is frozen only if it needs a
    // PCG run: a warm start at the tolerance costs one application.
    let Some((_, d, _)) = w.kkt(&sp, ctl.floor, (qx, qy), (sx, sy), false) else {
        return Ok(w.out);
    };
    for &i in cells {
        if !sp.stick[i] {
            let w = [sx[i] - d[0], sy[i] - d[1]];
            sp.kap[i] = curvature([sp.nx[i], sp.ny[i]], w, set.bound(i));
        }
    }
    let mut frozen = false;
    // Whether `s` is `C q + e` computed afresh for the current `q`.
    let mut fresh = true;
    let mut pw = PcgFields {
        r: (z(), z()),
        z: (z(), z()),
        p: (z(), z()),
        h: (z(), z()),
        c: (z(), z()),
    };
    let mut outer = 0;
    // Consecutive acceptance tests the exact measure failed.
    let mut misses = 0;
    loop {
        let Some((e, d, scale)) = w.kkt(&sp, ctl.floor, (qx, qy), (sx, sy), false) else {
            return Ok(w.out);
        };
        w.out.shift = d;
        w.out.kkt = e;
        let (mut d, mut scale) = (d, scale);
        let settled = e <= tol && !w.would_change(&sp, tol, (d, scale), (qx, qy), (sx, sy));
        if !settled {
            misses = 0;
        }
        if settled {
            // Accept on the state with every slip cell on its rim and its
            // slip computed afresh; if that misses the tolerance (the
            // linearisation's error), update the split from it.
            for &i in cells {
                let q = norm(qx[i], qy[i]);
                let b = set.bound(i);
                if (!sp.stick[i] && (q - b).abs() > 1e-12 * b) || q > b {
                    qx[i] *= b / q;
                    qy[i] *= b / q;
                    fresh = false;
                }
            }
            if !fresh {
                slip_field(op, w.extra, (qx, qy), (sx, sy));
                w.out.applications += 1;
            }
            let Some((ek, dk, sk)) = w.kkt(&sp, ctl.floor, (qx, qy), (sx, sy), true) else {
                return Ok(w.out);
            };
            w.out.kkt = ek;
            w.out.shift = dk;
            if ek <= tol {
                w.out.converged = true;
                return Ok(w.out);
            }
            misses += 1;
            if misses > 1 {
                // The linearised test passes where the exact one fails, twice
                // in a row: the caller's projected-gradient phase takes over.
                return Ok(w.out);
            }
            (d, scale) = (dk, sk);
        }
        if w.out.iterations >= ctl.budget || outer >= MAX_OUTER {
            return Ok(w.out);
        }
        if !settled {
            if !frozen {
                w.freeze(op, &mut sp, true);
            }
            let pe = pcg(&mut w, op, &sp, ctl, e, (qx, qy), (sx, sy), &mut pw)?;
            let Some((dn, sn)) = pe else {
                return Ok(w.out);
            };
            (d, scale) = (dn, sn);
        }
        // Outer update: the rules, rims, directions and κ; the force.
        outer += 1;
        dqx.fill(0.0);
        dqy.fill(0.0);
        let changed = w.update(
            &mut sp,
            tol,
            (d, scale),
            (qx, qy),
            (sx, sy),
            (&mut dqx, &mut dqy),
        );
        if changed {
            w.out.split_updates += 1;
        }
        // `M e_k` only when the split changed: `P_M` still maps into
        // `{Σ q = 0}` with the columns of an earlier freeze (`Bᵀ M̃ B` is
        // their Gram matrix), and the re-linearised κ moves the weights of
        // a few cells (a fretting cycle at 256²: 634 iterations either way,
        // 11 % fewer preconditioner applications).
        w.freeze(op, &mut sp, changed || !frozen);
        frozen = true;
        w.force_shift(&sp, (qx, qy), (&mut dqx, &mut dqy));
        op.tangential_add(&dqx, &dqy, sx, sy);
        w.out.applications += 1;
        fresh = false;
    }
}

/// The PCG's fields: residual, preconditioned residual, direction, its
/// image `H p` and `C p`.
struct PcgFields {
    r: (Vec<f64>, Vec<f64>),
    z: (Vec<f64>, Vec<f64>),
    p: (Vec<f64>, Vec<f64>),
    h: (Vec<f64>, Vec<f64>),
    c: (Vec<f64>, Vec<f64>),
}

/// One run of the inner PCG on the frozen split `sp` from `q` (KKT measure
/// `e_start`), until the tolerance, the budget, or (inexact steps) a
/// tenfold fall of the measure with a split that would change. Returns the
/// last shift and scale (`None`: no stick cell).
#[allow(clippy::too_many_arguments)]
fn pcg(
    w: &mut Work,
    op: &mut Operator,
    sp: &Split,
    ctl: Controls,
    e_start: f64,
    (qx, qy): (&mut [f64], &mut [f64]),
    (sx, sy): (&mut [f64], &mut [f64]),
    f: &mut PcgFields,
) -> Result<Option<([f64; 2], f64)>, SolverError> {
    let cells = w.set.cells;
    let tol = ctl.tolerance;
    let (rx, ry) = (&mut f.r.0, &mut f.r.1);
    let (zx, zy) = (&mut f.z.0, &mut f.z.1);
    let (px, py) = (&mut f.p.0, &mut f.p.1);
    let (hx, hy) = (&mut f.h.0, &mut f.h.1);
    let (cx, cy) = (&mut f.c.0, &mut f.c.1);
    for &i in cells {
        let (mut ax, mut ay) = (-sx[i], -sy[i]);
        if !sp.stick[i] {
            let t = sp.t(i);
            let tau = t[0] * qx[i] + t[1] * qy[i];
            let r = t[0] * ax + t[1] * ay - sp.kap[i] * tau;
            ax = r * t[0];
            ay = r * t[1];
        }
        rx[i] = ax;
        ry[i] = ay;
    }
    w.deflate(sp, (rx, ry));
    w.precondition(op, sp, (rx, ry), (zx, zy));
    w.project(sp, (zx, zy));
    for &i in cells {
        px[i] = zx[i];
        py[i] = zy[i];
    }
    let mut rz = dot(cells, (rx, ry), (zx, zy));
    let mut last = None;
    loop {
        crate::base::progress::tick_or_cancel()?;
        op.tangential(px, py, cx, cy);
        w.out.applications += 1;
        let mut php = 0.0;
        for &i in cells {
            let (mut ax, mut ay) = (cx[i], cy[i]);
            if !sp.stick[i] {
                let t = sp.t(i);
                let pt = t[0] * px[i] + t[1] * py[i];
                let h = t[0] * ax + t[1] * ay + sp.kap[i] * pt;
                ax = h * t[0];
                ay = h * t[1];
            }
            hx[i] = ax;
            hy[i] = ay;
            php += px[i] * ax + py[i] * ay;
        }
        w.out.iterations += 1;
        if php <= 0.0 || !php.is_finite() || rz <= 0.0 {
            return Ok(last.or_else(|| {
                w.kkt(sp, ctl.floor, (qx, qy), (sx, sy), false)
                    .map(|(_, d, s)| (d, s))
            }));
        }
        let alpha = rz / php;
        for &i in cells {
            qx[i] += alpha * px[i];
            qy[i] += alpha * py[i];
            rx[i] -= alpha * hx[i];
            ry[i] -= alpha * hy[i];
            sx[i] += alpha * cx[i];
            sy[i] += alpha * cy[i];
        }
        let Some((e, dn, sn)) = w.kkt(sp, ctl.floor, (qx, qy), (sx, sy), false) else {
            return Ok(None);
        };
        last = Some((dn, sn));
        w.out.kkt = e;
        if e <= tol || w.out.iterations >= ctl.budget {
            return Ok(last);
        }
        if e <= INEXACT * e_start && w.would_change(sp, tol, (dn, sn), (qx, qy), (sx, sy)) {
            return Ok(last);
        }
        w.deflate(sp, (rx, ry));
        w.precondition(op, sp, (rx, ry), (zx, zy));
        w.project(sp, (zx, zy));
        let rz_new = dot(cells, (rx, ry), (zx, zy));
        let beta = rz_new / rz;
        rz = rz_new;
        for &i in cells {
            px[i] = zx[i] + beta * px[i];
            py[i] = zy[i] + beta * py[i];
        }
    }
}

fn dot(cells: &[usize], (ax, ay): (&[f64], &[f64]), (bx, by): (&[f64], &[f64])) -> f64 {
    let mut s = 0.0;
    for &i in cells {
        s += ax[i] * bx[i] + ay[i] * by[i];
    }
    s
}
