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
//! active-set iteration of [`crate::solve::tangential::active_set`]; the start's
//! projection, the FISTA phase and the KKT test are the same.

use crate::base::parallel::Chunks;
use crate::error::SolverError;
use crate::operators::multilevel::FourierPrecond;
use crate::operators::operator::Operator;
use crate::solve::tangential::active_set::{
    active_set, norm, slip_field, solve2, Controls, Feasible,
};
use crate::solve::tangential::cg::{cg_disc, fourier_pays, on_rim, sum_in_order, CgOutcome};
use crate::solve::tangential::coarse_slip::{coarse_start, TangentialLevels};
use crate::solve::tangential::fista::Momentum;
pub use crate::solve::tangential::problem::{
    TangentialMethod, TangentialProblem, TangentialReport, TangentialSolution, TangentialStart,
};
use crate::solve::tangential::window::{contact_window, WindowCache};

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
pub(super) fn project_holding(
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
        report.change = momentum.finish(
            &cells,
            (&mut qx, &mut qy),
            (&px, &py),
            (&mut yx, &mut yy),
            (step, shift_norm),
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
