//! Partial-slip tangential contact at fixed pressure: shear tractions `q` on the
//! contact cells with the friction disc `|q_i| ≤ μ p_i` per cell and the total
//! force `ΔA Σ q = F` (force control). Sees only the operator's tangential block
//! and an extra slip term supplied by the caller (normal–tangential coupling).
//!
//! Method: the convex problem min ½qᵀCq + eᵀq over {|q_i| ≤ μp_i} ∩
//! {ΔA Σq = F}, solved by a projected conjugate gradient over the stick
//! cells' tractions and the slip cells' rotation on their discs (`cg_disc`),
//! and by accelerated projected gradient (FISTA with adaptive restart) from
//! where it stopped if its KKT residual stalls. Both end on a projection
//! onto that set, which shifts the tractions by one 2-D multiplier λ (found
//! by Newton's method) before clipping them to their discs: FISTA's is the
//! exact Euclidean projection (all tractions shifted); the CG's shifts all
//! but the slip cells it moved along their rims, which it holds there. The
//! rigid shift δt of the sphere is the stick cells' mean slip (CG) or λ
//! divided by the step (FISTA). A warm start that asks for it (a load
//! history's uncoupled increments) preconditions the CG's stick cells with the
//! Fourier inverse of the compliance (`StickPrecond`), which halves their
//! iterations; the answer is the same problem's to the same KKT tolerance.
//! With `TangentialMethod::ActiveSet` the first phase is instead the
//! active-set iteration of [`crate::solve::active_set`]; the start's
//! projection, the FISTA phase and the KKT test are the same.

use crate::base::parallel::{Chunks, Threads};
use crate::error::SolverError;
use crate::operators::multilevel::FourierPrecond;
use crate::operators::operator::Operator;
use crate::solve::active_set::{active_set, norm, slip_field, solve2, Controls, Feasible};
use crate::solve::coarse_slip::{coarse_start, TangentialLevels};
use crate::solve::fista::{self, Momentum};
pub use crate::solve::tangential_problem::{
    TangentialMethod, TangentialProblem, TangentialReport, TangentialSolution, TangentialStart,
};
use crate::solve::window::{contact_window, WindowCache};

/// Exact projection of `z` onto the feasible set: q_i = Π_i(z_i + λ).
/// Returns `None` if no λ satisfies the force (gross sliding).
///
/// With `held` cells, those are put on their rims, `q_i = b_i z_i / |z_i|`,
/// and only the others shift by λ: a point of the feasible set, not the
/// nearest one. The conjugate gradient holds the slip cells it moved along
/// their rims (see [`cg_disc`]); `None` when the other cells cannot carry
/// the force ([`project_holding`] then projects exactly).
fn project(
    (zx, zy): (&[f64], &[f64]),
    set: &Feasible,
    lambda: &mut [f64; 2],
    (qx, qy): (&mut [f64], &mut [f64]),
    held: Option<&[bool]>,
) -> Option<()> {
    let Feasible {
        cells,
        chunks,
        threads,
        cap,
        target,
        ..
    } = *set;
    let tnorm = target[0].hypot(target[1]);
    if tnorm >= cap {
        return None;
    }
    let tol = 1e-14 * cap;
    let mut l = *lambda;
    let eval = |l: [f64; 2], qx: &mut [f64], qy: &mut [f64]| {
        let parts = threads.chunked(chunks, chunks.with2(qx, qy), |(part, qx, qy)| {
            let (mut f, mut j) = ([0.0; 2], [0.0; 3]);
            for &i in part.list() {
                let k = i - part.start;
                let b = set.bound(i);
                if held.is_some_and(|h| h[i]) {
                    let w = norm(zx[i], zy[i]);
                    let s = if w > 0.0 { b / w } else { 0.0 };
                    qx[k] = s * zx[i];
                    qy[k] = s * zy[i];
                    f[0] += qx[k];
                    f[1] += qy[k];
                    continue;
                }
                let (wx, wy) = (zx[i] + l[0], zy[i] + l[1]);
                let w = norm(wx, wy);
                if w <= b {
                    qx[k] = wx;
                    qy[k] = wy;
                    j[0] += 1.0;
                    j[2] += 1.0;
                } else {
                    let s = b / w;
                    let (nx, ny) = (wx / w, wy / w);
                    qx[k] = s * wx;
                    qy[k] = s * wy;
                    j[0] += s * (1.0 - nx * nx);
                    j[1] -= s * nx * ny;
                    j[2] += s * (1.0 - ny * ny);
                }
                f[0] += qx[k];
                f[1] += qy[k];
            }
            (f, j)
        });
        let mut f = [-target[0], -target[1]];
        let mut j = [[0.0; 2]; 2];
        for (pf, pj) in parts {
            f[0] += pf[0];
            f[1] += pf[1];
            j[0][0] += pj[0];
            j[0][1] += pj[1];
            j[1][1] += pj[2];
        }
        j[1][0] = j[0][1];
        (f, j)
    };
    let (mut f, mut j) = eval(l, qx, qy);
    for _ in 0..200 {
        let fn_ = norm(f[0], f[1]);
        if fn_ <= tol {
            *lambda = l;
            return Some(());
        }
        let (mut dx, mut dy) = match solve2(j, f) {
            Some([x, y]) => (-x, -y),
            None => (-f[0] / cells.len() as f64, -f[1] / cells.len() as f64),
        };
        // Backtracking on |f| (f is the gradient of a convex function of λ).
        let mut accepted = false;
        for _ in 0..60 {
            let trial = [l[0] + dx, l[1] + dy];
            let (ft, jt) = eval(trial, qx, qy);
            if norm(ft[0], ft[1]) < fn_ {
                l = trial;
                f = ft;
                j = jt;
                accepted = true;
                break;
            }
            dx *= 0.5;
            dy *= 0.5;
        }
        if !accepted {
            break;
        }
    }
    // Final evaluation at the best λ; accept a tiny residual.
    let (f, _) = eval(l, qx, qy);
    *lambda = l;
    if f[0].hypot(f[1]) <= 1e-10 * cap.max(tnorm) {
        Some(())
    } else {
        None
    }
}

/// [`project`] holding the `held` cells on their rims, or the exact
/// projection (from λ = 0) where the other cells cannot carry the force;
/// gross sliding if neither exists.
fn project_holding(
    z: (&[f64], &[f64]),
    set: &Feasible,
    lambda: &mut [f64; 2],
    (qx, qy): (&mut [f64], &mut [f64]),
    held: &[bool],
) -> Result<(), SolverError> {
    if project(z, set, lambda, (&mut *qx, &mut *qy), Some(held)).is_some() {
        return Ok(());
    }
    *lambda = [0.0; 2];
    project(z, set, lambda, (qx, qy), None).ok_or_else(gross_sliding)
}

/// The error of a force no traction field within the discs can carry.
fn gross_sliding() -> SolverError {
    SolverError::GrossSliding {
        detail: "no traction field satisfies both the friction discs and the force".into(),
    }
}

/// Solves the force-controlled partial-slip problem at fixed pressure.
///
/// Tractions, slip and stick set vanish outside the contact cells (`p > 0`),
/// so the problem is solved on the smallest square window of the grid that
/// holds them (see [`contact_window`]) with the operator of that window, and
/// the result is placed back on the grid: the same equations, with transforms
/// `(nw/N)²` as large. [`solve_tangential_on_grid`] solves on the whole grid.
pub fn solve_tangential(
    op: &mut Operator,
    windows: &mut WindowCache,
    prob: &TangentialProblem,
) -> Result<TangentialSolution, SolverError> {
    solve_tangential_taking(op, windows, prob, None)
}

/// Start tractions `(qx, qy)` handed over to a solve, which keeps them as
/// its work fields instead of copying them (two fields fewer at its peak:
/// 67 MB of a coupled 2048² solve). Given, they replace
/// [`TangentialProblem::start`].
pub(crate) type Handed = Option<(Vec<f64>, Vec<f64>)>;

/// [`solve_tangential`], from the tractions `handed` when given.
pub(crate) fn solve_tangential_taking(
    op: &mut Operator,
    windows: &mut WindowCache,
    prob: &TangentialProblem,
    handed: Handed,
) -> Result<TangentialSolution, SolverError> {
    crate::base::progress::stage(crate::base::progress::Stage::Tangential);
    let n = op.grid().n;
    let Some(win) = contact_window(n, prob.p) else {
        let levels = windows.grid_levels(op);
        return solve_nested_taking(op, levels, prob, handed);
    };
    let p = win.gather(prob.p);
    let extra = prob.extra.map(|(ex, ey)| (win.gather(ex), win.gather(ey)));
    let q_init = match (handed, prob.start) {
        (Some((qx, qy)), _) => Some((win.gather(&qx), win.gather(&qy))),
        (None, TangentialStart::Tractions(qx, qy)) => Some((win.gather(qx), win.gather(qy))),
        (None, TangentialStart::Proportional) => None,
    };
    let sub = TangentialProblem {
        p: &p,
        extra: extra.as_ref().map(|(x, y)| (&x[..], &y[..])),
        ..*prob
    };
    let cover = op.cover().map(|c| win.gather(c));
    let (wop, levels) = windows.operator_and_levels(op, win.n);
    wop.set_cover(cover.as_deref());
    let sol = solve_nested_taking(wop, levels, &sub, q_init)?;
    Ok(TangentialSolution {
        qx: win.scatter(&sol.qx, 0.0),
        qy: win.scatter(&sol.qy, 0.0),
        sx: win.scatter(&sol.sx, 0.0),
        sy: win.scatter(&sol.sy, 0.0),
        stick: win.scatter(&sol.stick, false),
        ..sol
    })
}

/// [`solve_tangential_on_grid`] with a coarse-to-fine start when the problem
/// starts from rest ([`TangentialStart::Proportional`]): the problem is solved
/// on `levels` (coarsest first), and the prolonged coarse tractions start the
/// fine iteration, which runs to the same tolerance and KKT test as without
/// them. A start given by the caller is kept as it is.
pub fn solve_nested(
    op: &mut Operator,
    levels: &mut TangentialLevels,
    prob: &TangentialProblem,
) -> Result<TangentialSolution, SolverError> {
    solve_nested_taking(op, levels, prob, None)
}

/// [`solve_nested`], from the tractions `handed` when given.
fn solve_nested_taking(
    op: &mut Operator,
    levels: &mut TangentialLevels,
    prob: &TangentialProblem,
    handed: Handed,
) -> Result<TangentialSolution, SolverError> {
    if handed.is_some() || !matches!(prob.start, TangentialStart::Proportional) {
        let fourier = fourier_pays(prob, op.grid()).then(|| {
            let grid = op.grid();
            levels
                .fourier
                .get_or_insert_with(|| FourierPrecond::new(grid))
        });
        let sol = on_grid_taking(op, prob, handed, fourier);
        if let Some(f) = &mut levels.fourier {
            // The work spectrum is held only while a solve runs (8 B per cell).
            f.release_work();
        }
        return sol;
    }
    let extra = op.extra_diagonal();
    let Some((qx, qy, coarse)) =
        coarse_start(levels, prob, solve_tangential_on_grid, extra.as_deref())?
    else {
        return on_grid_taking(op, prob, None, None);
    };
    let mut sol = on_grid_taking(op, prob, Some((qx, qy)), None)?;
    sol.report.coarse_iterations = coarse;
    Ok(sol)
}

/// [`solve_tangential`] on the whole grid, without a contact window or a
/// coarse-to-fine start (for comparisons and tests).
pub fn solve_tangential_on_grid(
    op: &mut Operator,
    prob: &TangentialProblem,
) -> Result<TangentialSolution, SolverError> {
    on_grid_taking(op, prob, None, None)
}

/// [`solve_tangential_on_grid`], from the tractions `handed` when given.
/// `fourier`: the grid's preconditioner when the caller holds one (made here
/// if `prob` asks for one and none is given).
fn on_grid_taking(
    op: &mut Operator,
    prob: &TangentialProblem,
    handed: Handed,
    fourier: Option<&mut FourierPrecond>,
) -> Result<TangentialSolution, SolverError> {
    let grid = op.grid();
    let len = grid.len();
    let da = grid.cell_area();
    let p = prob.p;
    let mu = prob.friction;
    let mut cells: Vec<usize> = (0..len).filter(|&i| p[i] > 0.0).collect();
    // Collected by doubling: up to twice the contact's cells (4 MB at 1024²).
    cells.shrink_to_fit();
    let normal: f64 = p.iter().sum::<f64>() * da;
    let fnorm = prob.force[0].hypot(prob.force[1]);
    if fnorm >= mu * normal {
        return Err(SolverError::GrossSliding {
            detail: format!(
                "tangential force {fnorm:.6e} N reaches the friction limit Σ μp ΔA = {:.6e} N (μP; with a shear limit, Σ min(μp, τ_c) ΔA)",
                mu * normal
            ),
        });
    }
    let target = [prob.force[0] / da, prob.force[1] / da];
    let threads = op.threads().clone();
    let chunks = Chunks::of_cells(&cells, len);
    let set = Feasible::new((&chunks, &threads), &cells, p, mu, target);
    let (mut qx, mut qy) = (vec![0.0; len], vec![0.0; len]);
    let (mut zx, mut zy) = match handed {
        Some((zx, zy)) => {
            assert!(
                zx.len() == len && zy.len() == len,
                "start tractions off the grid"
            );
            (zx, zy)
        }
        None => {
            let (mut zx, mut zy) = (vec![0.0; len], vec![0.0; len]);
            match prob.start {
                TangentialStart::Tractions(ix, iy) => {
                    zx.copy_from_slice(ix);
                    zy.copy_from_slice(iy);
                }
                TangentialStart::Proportional => {
                    for &i in &cells {
                        zx[i] = prob.force[0] / normal * p[i];
                        zy[i] = prob.force[1] / normal * p[i];
                    }
                }
            }
            (zx, zy)
        }
    };
    for i in 0..len {
        if p[i] <= 0.0 {
            zx[i] = 0.0;
            zy[i] = 0.0;
        }
    }
    let mut lambda = [0.0; 2];
    // The start's cells on their rims stay there: a warm start's tractions
    // (the last coupling pass's, rescaled to the new pressure, or the last
    // increment's) meet the new force by shifting the others. Shifted too,
    // slip cells at the contact's edge fell inside their discs by a
    // fraction of λ and started as stick cells slipping by 0.3 |δt|
    // (Table 1a coupled at 1024²: a pass that started 4e-6 from the
    // tolerance took 31 iterations).
    let held: Vec<bool> = (0..len)
        .map(|i| p[i] > 0.0 && on_rim(zx[i], zy[i], set.bound(i)))
        .collect();
    project_holding((&zx, &zy), &set, &mut lambda, (&mut qx, &mut qy), &held)?;
    drop(held);

    let (mut sx, mut sy) = (vec![0.0; len], vec![0.0; len]);
    let mut stick = vec![false; len];
    let mut report = TangentialReport::default();
    let stick_tol = 1.0 - 1e-9;
    // Step 1/L, L the largest eigenvalue of the tangential block.
    let step = 1.0 / op.tangential_bound();

    // Phase 1: the projected conjugate gradient (below) or the active-set
    // iteration, as `prob.method` says. Phase 2, only if phase 1 did not
    // converge: FISTA from where it stopped.
    let cg = match prob.method {
        TangentialMethod::ConjugateGradient => {
            let mut own = None;
            let fourier = match fourier {
                Some(f) => Some(f),
                None if fourier_pays(prob, grid) => Some(own.insert(FourierPrecond::new(grid))),
                None => None,
            };
            cg_disc(
                (op, fourier),
                prob,
                &set,
                (&mut qx, &mut qy),
                (&mut sx, &mut sy),
                (&mut zx, &mut zy),
                &mut lambda,
            )?
        }
        TangentialMethod::ActiveSet => {
            let ctl = Controls {
                tolerance: prob.tolerance,
                floor: prob.slip_floor,
                budget: prob.max_iterations,
            };
            let out = active_set(
                op,
                prob.extra,
                &set,
                ctl,
                (&mut qx, &mut qy),
                (&mut sx, &mut sy),
            )?;
            report.preconditioner_applications = out.inverses;
            report.split_updates = out.split_updates;
            CgOutcome {
                iterations: out.iterations,
                applications: out.applications,
                energy_products: 0,
                kkt: out.kkt,
                shift: out.shift,
                converged: out.converged,
            }
        }
    };
    report.cg_iterations = cg.iterations;
    report.applications = cg.applications;
    report.energy_products = cg.energy_products;
    report.iterations = cg.iterations;
    report.change = cg.kkt;
    if cg.converged {
        report.converged = true;
    }
    // λ of the FISTA projection is step · δt.
    lambda = [cg.shift[0] * step, cg.shift[1] * step];
    let fista_budget = if report.converged {
        0
    } else {
        prob.max_iterations.saturating_sub(cg.iterations)
    };
    // FISTA's work fields exist only when it runs.
    let (mut yx, mut yy) = (Vec::new(), Vec::new());
    let (mut px, mut py) = (Vec::new(), Vec::new());
    if fista_budget > 0 {
        (yx, yy) = (qx.clone(), qy.clone());
        (px, py) = (vec![0.0; len], vec![0.0; len]);
    }

    // Accelerated projected gradient (FISTA) with gradient-based adaptive restart
    // (O'Donoghue & Candès 2015) on min ½qᵀCq + eᵀq over {discs} ∩ {force}.
    // The projection's multiplier λ is the rigid shift: δt = λ / step.
    let mut momentum = Momentum::new();
    for it in 1..=fista_budget {
        crate::base::progress::tick_or_cancel()?;
        report.iterations = cg.iterations + it;
        report.applications += 1;
        slip_field(op, prob.extra, (&yx, &yy), (&mut sx, &mut sy));
        for &i in &cells {
            zx[i] = yx[i] - step * sx[i];
            zy[i] = yy[i] - step * sy[i];
        }
        project((&zx, &zy), &set, &mut lambda, (&mut px, &mut py), None)
            .ok_or_else(gross_sliding)?;
        // Gradient mapping residual, relative to the rigid shift.
        let shift_norm = (lambda[0].hypot(lambda[1]) / step)
            .max(prob.slip_floor)
            .max(f64::MIN_POSITIVE);
        let (res, restart) = fista::mapping(&cells, (&yx, &yy), (&px, &py), (&qx, &qy));
        report.change = res / step / shift_norm;
        momentum.advance(
            restart,
            &cells,
            (&mut qx, &mut qy),
            (&px, &py),
            (&mut yx, &mut yy),
        );
        if report.change < prob.tolerance {
            report.converged = true;
            break;
        }
    }
    let mut shift = if fista_budget > 0 {
        [lambda[0] / step, lambda[1] / step]
    } else {
        cg.shift
    };

    // Final slip, stick set, shift and KKT residuals of the returned tractions.
    // A converged CG phase left `s = C q + e` of these tractions in (sx, sy).
    if !(cg.converged && fista_budget == 0) {
        slip_field(op, prob.extra, (&qx, &qy), (&mut sx, &mut sy));
    }
    let parts = threads.chunked(&chunks, chunks.with(&mut stick), |(part, stick)| {
        let (mut mx, mut my, mut nst) = (0.0, 0.0, 0usize);
        for &i in part.list() {
            let sticks = qx[i].hypot(qy[i]) < stick_tol * set.bound(i);
            stick[i - part.start] = sticks;
            if sticks {
                mx += sx[i];
                my += sy[i];
                nst += 1;
            }
        }
        (mx, my, nst)
    });
    let (mx, my, nst) = sum_in_order(parts);
    if nst > 0 {
        shift = [mx / nst as f64, my / nst as f64];
    }
    let scale = shift[0]
        .hypot(shift[1])
        .max(prob.slip_floor)
        .max(f64::MIN_POSITIVE);
    let flat = Chunks::flat(len);
    let parts = threads.chunked(&flat, flat.with2(&mut sx, &mut sy), |(part, sx, sy)| {
        let (mut st_res, mut sl_res) = (0.0_f64, 0.0_f64);
        let (mut fx, mut fy) = (0.0, 0.0);
        for i in part.range() {
            let k = i - part.start;
            fx += qx[i];
            fy += qy[i];
            if p[i] <= 0.0 {
                sx[k] = 0.0;
                sy[k] = 0.0;
                continue;
            }
            let (wx, wy) = (sx[k] - shift[0], sy[k] - shift[1]);
            if stick[i] {
                st_res = st_res.max(wx.hypot(wy) / scale);
                sx[k] = 0.0;
                sy[k] = 0.0;
            } else {
                let qn = qx[i].hypot(qy[i]);
                let w = wx.hypot(wy);
                sl_res = sl_res.max((wx + w * qx[i] / qn).hypot(wy + w * qy[i] / qn) / scale);
                sx[k] = wx;
                sy[k] = wy;
            }
        }
        (st_res, sl_res, fx, fy)
    });
    let (mut st_res, mut sl_res) = (0.0_f64, 0.0_f64);
    let (mut fx, mut fy) = (0.0, 0.0);
    for (st, sl, x, y) in parts {
        st_res = st_res.max(st);
        sl_res = sl_res.max(sl);
        fx += x;
        fy += y;
    }
    report.stick_residual = st_res;
    report.slip_residual = sl_res;
    // At zero force the error is measured against the friction limit μP.
    let force_scale = if fnorm > 0.0 { fnorm } else { mu * normal };
    report.force_error = (fx * da - prob.force[0]).hypot(fy * da - prob.force[1])
        / force_scale.max(f64::MIN_POSITIVE);
    Ok(TangentialSolution {
        qx,
        qy,
        sx,
        sy,
        stick,
        shift,
        report,
    })
}

/// Outcome of the conjugate-gradient phase.
struct CgOutcome {
    iterations: usize,
    applications: usize,
    energy_products: usize,
    kkt: f64,
    shift: [f64; 2],
    converged: bool,
}

/// Consecutive iterations without a new best KKT residual after which the
/// conjugate-gradient phase hands over to FISTA.
const CG_STALL: usize = 60;

/// Iterations between full recomputations of the slip field `C q + e`
/// (it is otherwise updated by `C Δq`, which accumulates round-off).
const REFRESH: usize = 32;

/// Projected conjugate gradient for the disc-constrained problem, in the
/// manner of Polonsky & Keer's normal solver, with the slip cells' rotation
/// among the conjugate variables. The variables are the stick cells'
/// tractions (|q_i| < μp_i, two per cell) and each slip cell's move along the
/// tangent `t_i` of its disc (|q_i| = μp_i, one per cell). The residual is the
/// slip relative to the rigid shift, `u_i − d` on stick cells and its
/// tangential part on slip cells, made orthogonal to the force constraint
/// ΔA Σq = F; the step length sees the elastic energy of the direction and,
/// on slip cells, the curvature of the disc's rim, `c_i = |n_i · (u_i − d)| /
/// (μ p_i)` per unit tangential move (`n_i` the traction's direction: the
/// slip pressing the traction onto the rim). The residual is preconditioned by
/// the diagonal of that Hessian (Jacobi), with the cells' elastic stiffness
/// taken as that of the last step, 1/τ: a slip cell's move is its Newton
/// rotation where its rim is stiff and a conjugate-gradient move where it is
/// not. (When the caller asks, the stick cells' block is the Fourier inverse
/// of the compliance instead of the identity, see [`StickPrecond`].) Slip
/// cells whose rim is stiffer than 1000/τ (pressures a millionth of
/// the peak at the contact's edge) take the plain projected-gradient step
/// instead, which aligns them in one step; a slip cell whose slip turns along
/// its traction is released inwards by the gradient step. The trial point is
/// projected exactly onto discs ∩ force. As in Polonsky & Keer, conjugacy
/// restarts when a cell is released into the stick set, not when a stick
/// cell reaches its disc. Returns with `converged` false if the KKT residual
/// stops improving; the caller then continues with FISTA.
///
/// (Moving every slip cell by the plain projected-gradient step with the
/// stick cells' step length, and restarting at every change of the stick
/// set, left a tail in which the stick residual was below 1e-8 |δt| while
/// the slip cells' alignment fell from 3e-6 to 1e-6 over 80–100 iterations,
/// and warm starts that were steepest descent. Table 1a, fine iterations
/// after the coarse start, Cattaneo–Mindlin at 256² / 512² / 1024² / 2048²:
/// 213 / 164 / 174 / 193, now 38 / 48 / 63 / 94; coupled at 512² / 1024² /
/// 2048²: 250 / 329 / 444, now 93 / 157 / 158. docs/performance-history.md has the
/// table.)
///
/// Per iteration: the step length needs `⟨t, C t⟩` of the direction, taken
/// from its spectra by Parseval (two forward transforms), and the slip field
/// is updated by `C Δq` of the actual move (one tangential application):
/// six padded transforms; with the Fourier preconditioner (`fourier`, the
/// warm starts that ask for it) four periodic `n x n` transforms more.
fn cg_disc(
    (op, fourier): (&mut Operator, Option<&mut FourierPrecond>),
    prob: &TangentialProblem,
    set: &Feasible,
    (qx, qy): (&mut [f64], &mut [f64]),
    (ux, uy): (&mut [f64], &mut [f64]),
    (zx, zy): (&mut [f64], &mut [f64]),
    lambda: &mut [f64; 2],
) -> Result<CgOutcome, SolverError> {
    let (cells, chunks, threads) = (set.cells, set.chunks, set.threads);
    let bound = |i: usize| set.bound(i);
    let len = qx.len();
    // The cells' elastic stiffness in the preconditioner, m/Pa: a cell's own
    // compliance for the first step, then 1/τ of the last step.
    let mut stiffness = op.tangential_self();
    // The stick cells' preconditioner (see `StickPrecond`).
    let mut pre = StickPrecond::new(fourier, op.threads(), len);
    // The direction as a shear field: two components on stick cells, along
    // the tangent on slip cells, zero elsewhere.
    let (mut vx, mut vy) = (vec![0.0; len], vec![0.0; len]);
    let (mut dqx, mut dqy) = (vec![0.0; len], vec![0.0; len]);
    // Stick set of the current tractions: here, then after each projection.
    let mut stick = vec![false; len];
    for &i in cells {
        stick[i] = !on_rim(qx[i], qy[i], bound(i));
    }
    // This iteration's `SlipCell` of each slip cell, per piece of `chunks`
    // in the order of its cells (the later passes walk them in that order).
    let mut rims: Vec<Vec<SlipCell>> = (0..chunks.count()).map(|_| Vec::new()).collect();
    // The slip cells each move holds on their rims (see the projection).
    let mut held = vec![false; len];
    let mut rz_old = 1.0;
    let mut conj = false;
    // The slip field in (ux, uy) is exact (`fresh`) or updated since `age` moves.
    let mut fresh = false;
    let mut age = REFRESH;
    let mut best = f64::INFINITY;
    let mut since_best = 0;
    let mut out = CgOutcome {
        iterations: 0,
        applications: 0,
        energy_products: 0,
        kkt: f64::INFINITY,
        shift: [0.0; 2],
        converged: false,
    };
    let budget = prob.max_iterations;
    for it in 1..=budget {
        crate::base::progress::tick_or_cancel()?;
        out.iterations = it;
        if age >= REFRESH {
            out.applications += 1;
            slip_field(op, prob.extra, (qx, qy), (ux, uy));
            fresh = true;
            age = 0;
        }
        // The mean slip over the stick set (the rigid shift δt). Every sum
        // below is over the pieces of `chunks`, combined in their order.
        let parts = threads.chunked(chunks, chunks.items(), |part| {
            let (mut mx, mut my, mut ns) = (0.0, 0.0, 0usize);
            for &i in part.list() {
                if stick[i] {
                    mx += ux[i];
                    my += uy[i];
                    ns += 1;
                }
            }
            (mx, my, ns)
        });
        let (mx, my, ns) = sum_in_order(parts);
        if ns == 0 {
            // Every cell slips: not a partial-slip state; let FISTA take over.
            return Ok(out);
        }
        let d = [mx / ns as f64, my / ns as f64];
        out.shift = d;
        // The preconditioned stick residual, less its mean mode: Π W Π u.
        let alpha = pre.prepare(&stick, ns, op.grid(), (ux, uy));
        let sz = pre.view();
        // A slip cell's traction direction n, tangent t, rim curvature c and
        // Jacobi weight k (0: aligned by its own gradient step).
        let (q, u) = ((&*qx, &*qy), (&*ux, &*uy));
        let rim = |i: usize| -> SlipCell {
            let qn = norm(q.0[i], q.1[i]);
            let n = [q.0[i] / qn, q.1[i] / qn];
            let press = -((u.0[i] - d[0]) * n[0] + (u.1[i] - d[1]) * n[1]);
            let c = press.max(0.0) / bound(i);
            let k = if c > STIFF_RIM * stiffness {
                0.0
            } else {
                1.0 / (1.0 + c / stiffness)
            };
            SlipCell { n, c, k }
        };
        // KKT residual relative to |δt|; the weighted Gram matrix of the force
        // constraint, A M⁻¹ Aᵀ = α n_stick I + Σ_slip k t tᵀ, and A M⁻¹ u.
        let scale = d[0].hypot(d[1]).max(prob.slip_floor).max(f64::MIN_POSITIVE);
        let items: Vec<_> = chunks.parts().zip(rims.iter_mut()).collect();
        let parts = threads.chunked(chunks, items, |(part, rims)| {
            let (mut kkt_stick, mut kkt_slip) = (0.0_f64, 0.0_f64);
            let (mut gram, mut rhs) = ([0.0; 3], [0.0; 2]);
            rims.clear();
            for &i in part.list() {
                let (wx, wy) = (u.0[i] - d[0], u.1[i] - d[1]);
                if stick[i] {
                    kkt_stick = kkt_stick.max(norm(wx, wy));
                    rhs[0] += alpha * u.0[i];
                    rhs[1] += alpha * u.1[i];
                } else {
                    let cell = rim(i);
                    let (n, t, k) = (cell.n, cell.t(), cell.k);
                    let w = norm(wx, wy);
                    kkt_slip = kkt_slip.max(norm(wx + w * n[0], wy + w * n[1]));
                    gram[0] += k * t[0] * t[0];
                    gram[1] += k * t[0] * t[1];
                    gram[2] += k * t[1] * t[1];
                    let rt = k * (t[0] * u.0[i] + t[1] * u.1[i]);
                    rhs[0] += t[0] * rt;
                    rhs[1] += t[1] * rt;
                    rims.push(cell);
                }
            }
            (kkt_stick.max(kkt_slip), gram, rhs)
        });
        let mut kkt = 0.0_f64;
        let mut gram = [[alpha * ns as f64, 0.0], [0.0, alpha * ns as f64]];
        let mut rhs = [0.0; 2];
        for (k, g, r) in parts {
            kkt = kkt.max(k);
            gram[0][0] += g[0];
            gram[0][1] += g[1];
            gram[1][1] += g[2];
            rhs[0] += r[0];
            rhs[1] += r[1];
        }
        gram[1][0] = gram[0][1];
        out.kkt = kkt / scale;

        if out.kkt < prob.tolerance {
            if fresh {
                out.converged = true;
                *lambda = d;
                return Ok(out);
            }
            // Confirm on the exact slip field before accepting.
            age = REFRESH;
            continue;
        }
        if out.kkt < 0.999 * best {
            best = out.kkt;
            since_best = 0;
        } else {
            since_best += 1;
            if since_best > CG_STALL {
                return Ok(out);
            }
        }
        // The preconditioned residual z = M⁻¹ (u − Aᵀ m), orthogonal to the
        // force constraint (A z = 0): m solves A M⁻¹ Aᵀ m = A M⁻¹ u.
        // (The Gram matrix holds n_stick ≥ 1 on its diagonal: never singular.)
        let Some(m) = solve2(gram, rhs) else {
            return Ok(out);
        };
        // Conjugate direction v = z + β v_old (the old one taken along the
        // current tangent on slip cells), then made orthogonal to the force
        // constraint again, as the tangents turned a little since.
        // On stick cells z = P (u − d) + α (d − m).
        let zm = [alpha * (d[0] - m[0]), alpha * (d[1] - m[1])];
        let items: Vec<_> = chunks.parts().zip(rims.iter()).collect();
        let parts = threads.chunked(chunks, items, |(part, rims)| {
            let mut rz = 0.0;
            let mut slip = rims.iter();
            for &i in part.list() {
                let (rx, ry) = (u.0[i] - m[0], u.1[i] - m[1]);
                if stick[i] {
                    let z = sz.at(i, [rx, ry], zm);
                    rz += rx * z[0] + ry * z[1];
                } else {
                    let cell = slip.next().expect("one per slip cell");
                    let (t, k) = (cell.t(), cell.k);
                    let rt = t[0] * rx + t[1] * ry;
                    rz += k * rt * rt;
                }
            }
            rz
        });
        let rz = parts.into_iter().fold(0.0, |a, b| a + b);
        let beta = if conj { rz / rz_old } else { 0.0 };
        rz_old = rz;
        let items: Vec<_> = chunks
            .with2(&mut vx, &mut vy)
            .into_iter()
            .zip(rims.iter())
            .collect();
        let parts = threads.chunked(chunks, items, |((part, vx, vy), rims)| {
            let mut rhs = [0.0; 2];
            let mut slip = rims.iter();
            for &i in part.list() {
                let j = i - part.start;
                let (rx, ry) = (u.0[i] - m[0], u.1[i] - m[1]);
                if stick[i] {
                    let z = sz.at(i, [rx, ry], zm);
                    vx[j] = z[0] + beta * vx[j];
                    vy[j] = z[1] + beta * vy[j];
                    rhs[0] += vx[j];
                    rhs[1] += vy[j];
                } else {
                    let cell = slip.next().expect("one per slip cell");
                    let (t, k) = (cell.t(), cell.k);
                    let s = if k > 0.0 {
                        k * (t[0] * rx + t[1] * ry) + beta * (t[0] * vx[j] + t[1] * vy[j])
                    } else {
                        0.0
                    };
                    vx[j] = s * t[0];
                    vy[j] = s * t[1];
                    rhs[0] += t[0] * s;
                    rhs[1] += t[1] * s;
                }
            }
            rhs
        });
        let mut rhs = [0.0; 2];
        for r in parts {
            rhs[0] += r[0];
            rhs[1] += r[1];
        }
        // v −= M⁻¹ Aᵀ m2 with A M⁻¹ Aᵀ m2 = A v, so that A v = 0.
        let Some(m2) = solve2(gram, rhs) else {
            return Ok(out);
        };
        let items: Vec<_> = chunks
            .with2(&mut vx, &mut vy)
            .into_iter()
            .zip(rims.iter())
            .collect();
        let parts = threads.chunked(chunks, items, |((part, vx, vy), rims)| {
            let (mut num, mut bend) = (0.0, 0.0);
            let mut slip = rims.iter();
            for &i in part.list() {
                let j = i - part.start;
                let (rx, ry) = (u.0[i] - m[0], u.1[i] - m[1]);
                if stick[i] {
                    vx[j] -= alpha * m2[0];
                    vy[j] -= alpha * m2[1];
                    num += rx * vx[j] + ry * vy[j];
                } else {
                    let cell = slip.next().expect("one per slip cell");
                    let (t, c, k) = (cell.t(), cell.c, cell.k);
                    let s = t[0] * vx[j] + t[1] * vy[j] - k * (t[0] * m2[0] + t[1] * m2[1]);
                    vx[j] = s * t[0];
                    vy[j] = s * t[1];
                    num += (t[0] * rx + t[1] * ry) * s;
                    bend += c * s * s;
                }
            }
            (num, bend)
        });
        let (mut num, mut bend) = (0.0, 0.0);
        for (a, b) in parts {
            num += a;
            bend += b;
        }
        if num <= 0.0 {
            // Not a descent direction: the old direction no longer conjugate
            // (restart), or no residual left to reduce (FISTA takes over).
            if !conj {
                return Ok(out);
            }
            conj = false;
            continue;
        }
        let den = op.tangential_energy(&vx, &vy) + bend;
        out.energy_products += 1;
        if den <= 0.0 || !den.is_finite() {
            return Ok(out);
        }
        let tau = num / den;
        // Trial point: the conjugate step; on slip cells outside the
        // conjugate directions the projected-gradient step, and on slip cells
        // whose slip runs along their traction the inward gradient step that
        // releases them. Δq holds the current tractions until the projection.
        let (v, u) = ((&vx, &vy), (&*ux, &*uy));
        let items: Vec<_> = chunks
            .with2(&mut dqx, &mut dqy)
            .into_iter()
            .zip(chunks.split(zx))
            .zip(chunks.split(zy))
            .zip(chunks.split(&mut held))
            .zip(rims.iter())
            .collect();
        threads.chunked(
            chunks,
            items,
            |(((((part, dqx, dqy), zx), zy), held), rims)| {
                let mut slip = rims.iter();
                for &i in part.list() {
                    let j = i - part.start;
                    dqx[j] = q.0[i];
                    dqy[j] = q.1[i];
                    zx[j] = q.0[i] - tau * v.0[i];
                    zy[j] = q.1[i] - tau * v.1[i];
                    held[j] = false;
                    if !stick[i] {
                        let cell = slip.next().expect("one per slip cell");
                        let (n, k) = (cell.n, cell.k);
                        let (wx, wy) = (u.0[i] - d[0], u.1[i] - d[1]);
                        let along = wx * n[0] + wy * n[1];
                        if k == 0.0 {
                            zx[j] = q.0[i] - tau * wx;
                            zy[j] = q.1[i] - tau * wy;
                        } else if along > 0.0 {
                            zx[j] -= tau * along * n[0];
                            zy[j] -= tau * along * n[1];
                        }
                        held[j] = along <= 0.0;
                    }
                }
            },
        );
        stiffness = 1.0 / tau;
        // Projection onto discs ∩ force, the slip cells that moved along
        // their rims held there (λ shifts the stick cells and the released
        // ones): λ is not exactly zero after such a move, and shifted with
        // the rest, slip cells at the contact's edge fell inside their
        // discs, were taken as stick cells slipping by 0.3 |δt| and
        // restarted the conjugacy (Table 1a coupled, closing solves of 27
        // and 31 iterations at 512² and 1024² from 4e-6 of the tolerance;
        // with them held, 1 to 3: 128 → 98 and 136 → 104 tangential
        // iterations, docs/performance-history.md, round 3 fifth pass). The exact projection if the
        // other cells cannot carry the force.
        let mut l = [0.0; 2];
        project_holding((&*zx, &*zy), set, &mut l, (&mut *qx, &mut *qy), &held)?;
        // The new stick set, whether a cell was released into it, and Δq of
        // the move.
        let q = (&*qx, &*qy);
        let items: Vec<_> = chunks
            .with2(&mut dqx, &mut dqy)
            .into_iter()
            .zip(chunks.split(&mut stick))
            .collect();
        let parts = threads.chunked(chunks, items, |((part, dqx, dqy), stick)| {
            let mut released = false;
            for &i in part.list() {
                let j = i - part.start;
                let sticks = !on_rim(q.0[i], q.1[i], bound(i));
                released |= sticks && !stick[j];
                stick[j] = sticks;
                dqx[j] = q.0[i] - dqx[j];
                dqy[j] = q.1[i] - dqy[j];
            }
            released
        });
        conj = !parts.contains(&true);
        // Slip field of the new tractions: u += C Δq.
        op.tangential_add(&dqx, &dqy, ux, uy);
        out.applications += 1;
        fresh = false;
        age += 1;
    }
    Ok(out)
}

/// The stick cells' block of the conjugate gradient's preconditioner, `M⁻¹ r
/// = Π W Π r + α mean(r)` on the stick set. `W` is the normal solver's
/// Fourier `|k|` multiplier ([`FourierPrecond`], on each component: the
/// tangential compliance is `1/|k|` times a 2x2 matrix of eigenvalues 1 and
/// 1 − ν, so `W` inverts it to within a factor of two), scaled to a diagonal
/// of [`STICK_SCALE`] in real space; `Π` restricts to the stick cells and
/// removes their mean; the mean mode (the stick set's tractions shifted as
/// one, which the force constraint trades against the slip cells' rotation)
/// is weighted by `α`, `W`'s multiplier of a wave twice the stick set's
/// diameter. Without `W`, `M⁻¹ = I` on the stick cells (`Π r` and α = 1):
/// the Jacobi preconditioner the slip cells keep in both cases.
struct StickPrecond<'a> {
    /// `W` and its scale (the inverse of its mean symbol, m, times
    /// [`STICK_SCALE`]).
    fourier: Option<(&'a mut FourierPrecond, f64)>,
    /// `Π W Π u` on the stick cells, x and y (empty without `W`).
    z: (Vec<f64>, Vec<f64>),
}

/// Largest side of the grid (or contact window) on which a solve that asks
/// for the Fourier stick preconditioner ([`TangentialProblem::precondition`])
/// gets it; above, it keeps Jacobi. Table 1(a) uncoupled, first loading in 5
/// increments of 0.12 μP, tangential iterations per increment (Fourier /
/// Jacobi): 1024² 37, 50, 70, 79, 102 / 111, 113, 105, 111, 76 (Fourier
/// 338 in all against 516); 2048² 56, 186, 253, 343, 1694 / 125, 177, 109,
/// 125, 117 (2532 against 653: the Fourier-preconditioned iteration degrades
/// as the stick zone shrinks; since the conjugate gradient holds its slip
/// cells on their rims, 1233 against 610: half the cause was rim cells
/// taken for stick cells, the rest not found). Both grids have the same
/// geometry in cells (no window), so it is the resolution that differs.
/// At 256² and 512² (fretting, 60 increments) Fourier halves the iterations
/// (docs/performance-history.md, round 3).
pub const FOURIER_STICK_MAX_SIDE: usize = 1024;

/// Whether `prob`'s solve on `grid` uses the Fourier stick preconditioner.
fn fourier_pays(prob: &TangentialProblem, grid: crate::base::grid::Grid) -> bool {
    prob.method == TangentialMethod::ConjugateGradient
        && prob.precondition
        && grid.n <= FOURIER_STICK_MAX_SIDE
}

/// Diagonal of the stick cells' Fourier preconditioner relative to the
/// Jacobi weight one of the slip cells. (Table 1a uncoupled at 256², one
/// fretting cycle after the first loading, 60 increments: 3536 tangential
/// iterations without `W`; with `W` scaled to diagonal 0.3 / 1 / 3 / 10 /
/// 30: 3153 / 1992 / 1639 / 2221 / 4120.)
const STICK_SCALE: f64 = 3.0;

impl<'a> StickPrecond<'a> {
    fn new(fourier: Option<&'a mut FourierPrecond>, threads: &Threads, len: usize) -> Self {
        let fourier = fourier.map(|f| {
            f.set_threads(threads);
            let w = STICK_SCALE / f.symbol_mean();
            (f, w)
        });
        // Without `W` the residual itself is z (no fields).
        let len = if fourier.is_some() { len } else { 0 };
        StickPrecond {
            fourier,
            z: (vec![0.0; len], vec![0.0; len]),
        }
    }

    /// What the passes over the stick cells read of it ([`StickZ::at`]).
    fn view(&self) -> StickZ<'_> {
        StickZ(self.fourier.is_some().then_some((&self.z.0, &self.z.1)))
    }

    /// Makes `z = Π W Π u` on the `ns` cells of `stick` of `grid`; returns α
    /// (1 without `W`).
    fn prepare(
        &mut self,
        stick: &[bool],
        ns: usize,
        grid: crate::base::grid::Grid,
        (ux, uy): (&[f64], &[f64]),
    ) -> f64 {
        let Some((f, w)) = &mut self.fourier else {
            return 1.0;
        };
        f.apply(ux, stick, &mut self.z.0);
        f.apply(uy, stick, &mut self.z.1);
        for v in self.z.0.iter_mut().chain(self.z.1.iter_mut()) {
            *v *= *w;
        }
        // |k| of a wave of length 2D, D = 2 √(ns ΔA / π), is n / 2D (1/m,
        // the symbol's units on the periodic n x n grid).
        let diameter = 2.0 * (ns as f64 * grid.cell_area() / std::f64::consts::PI).sqrt();
        *w * grid.n as f64 / (2.0 * diameter)
    }
}

/// `Π W Π u` of a [`StickPrecond`] with `W` (x and y), `None` without.
#[derive(Clone, Copy)]
struct StickZ<'a>(Option<(&'a [f64], &'a [f64])>);

impl StickZ<'_> {
    /// `M⁻¹ r` on stick cell `i` for the residual `r = u − m`, with `zm = α
    /// (d − m)`: `z_i + zm`, or `r` itself without `W` (the same arithmetic
    /// as before the preconditioner existed).
    #[inline(always)]
    fn at(&self, i: usize, r: [f64; 2], zm: [f64; 2]) -> [f64; 2] {
        match self.0 {
            Some((zx, zy)) => [zx[i] + zm[0], zy[i] + zm[1]],
            None => r,
        }
    }
}

/// The pieces' partial sums of (slip x, slip y, stick cells), added in the
/// pieces' order: the same arithmetic whatever the thread count.
fn sum_in_order(parts: impl IntoIterator<Item = (f64, f64, usize)>) -> (f64, f64, usize) {
    let (mut mx, mut my, mut n) = (0.0, 0.0, 0usize);
    for (x, y, c) in parts {
        mx += x;
        my += y;
        n += c;
    }
    (mx, my, n)
}

/// Rim stiffness, relative to the cells' elastic stiffness 1/τ, above which a
/// slip cell is aligned by its own projected-gradient step rather than
/// within the conjugate directions. (At 1e3 these are the cells at the
/// contact's edge with pressures about 1e-12 of the peak, whose Jacobi weight
/// would all but freeze them: without it, Table 1a coupled at 512² stalled
/// with their misalignment at 5e-2 |δt|.)
const STIFF_RIM: f64 = 1e3;

/// A slip cell's traction direction `n`, the curvature `c` of its disc's rim
/// (m/Pa) and the cell's Jacobi weight `k`.
struct SlipCell {
    n: [f64; 2],
    c: f64,
    k: f64,
}

impl SlipCell {
    /// The unit tangent of the rim at the traction.
    fn t(&self) -> [f64; 2] {
        [-self.n[1], self.n[0]]
    }
}

/// Whether a traction `(qx, qy)` is on the rim of its friction disc of
/// radius `b` (to 1e-12 of `b`): a slip cell of the conjugate gradient.
#[inline]
fn on_rim(qx: f64, qy: f64, b: f64) -> bool {
    norm(qx, qy) >= (1.0 - 1e-12) * b
}
