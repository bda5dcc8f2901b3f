//! Partial and gross slip at fixed pressure under an **imposed** rigid
//! tangential shift δt of the ball (displacement control, as fretting rigs
//! run): shear tractions `q` on the contact cells with the friction disc
//! `|q_i| ≤ μ p_i` per cell and no condition on their sum, which is the
//! result (the tangential force). Sees only the operator's tangential block
//! and an extra slip term supplied by the caller, as the force-controlled
//! solver ([`crate::solve::tangential::force`]) does.
//!
//! Method: the convex problem min ½qᵀCq + (e − δt)ᵀq over the discs, whose
//! gradient is the slip `s = Cq + e − δt`. It is the force-controlled
//! problem without its load constraint, so it is solved by the same
//! active-set iteration with the circulant-inverse preconditioner, one
//! constraint fewer and no multiplier
//! ([`crate::solve::tangential::active_set::active_set_under`] with
//! `Condition::Shift`), from a start moved along the shift when it does not
//! yet carry it ([`shift_guess`]); if that stops short, accelerated
//! projected gradient (FISTA with gradient-based adaptive restart, the
//! projection a clip per cell) continues from where it stopped. Stick cells
//! end with zero slip, slip cells with the traction on their rim opposing
//! the slip. When the imposed shift exceeds what the stick zone can hold,
//! no stick cell is left and every traction sits on its rim: gross slip,
//! F = μP on a flat Coulomb surface, solved by the same iteration on a
//! split without stick cells.

use crate::base::parallel::Chunks;
use crate::error::SolverError;
use crate::operators::operator::Operator;
use crate::solve::tangential::active_set::{
    active_set_under, slip_field, Condition, Controls, Feasible,
};
use crate::solve::tangential::fista::Momentum;
use crate::solve::tangential::problem::{TangentialReport, TangentialSolution, TangentialStart};
use crate::solve::tangential::window::{contact_window, WindowCache};

/// Inputs of a displacement-controlled tangential solve.
#[derive(Clone, Copy, Debug)]
pub struct DisplacementProblem<'a> {
    /// Pressure (fixed), Pa.
    pub p: &'a [f64],
    /// Friction coefficient μ.
    pub friction: f64,
    /// The imposed rigid tangential shift of the ball, m, x and y (from the
    /// state the slip is measured from).
    pub shift: [f64; 2],
    /// Extra tangential displacement added to the slip (coupling term, the
    /// previous increment's displacement negated), m; `None` for none.
    pub extra: Option<(&'a [f64], &'a [f64])>,
    /// Tolerance on the KKT residual relative to `max(|shift|, slip_floor)`.
    pub tolerance: f64,
    /// Floor of the residual's scale, m (see
    /// [`crate::solve::tangential::TangentialProblem::slip_floor`]).
    pub slip_floor: f64,
    /// Iteration budget.
    pub max_iterations: usize,
    /// Starting tractions.
    pub start: TangentialStart<'a>,
}

/// Solves the displacement-controlled problem on the smallest square
/// window of the grid that holds the contact (as
/// [`crate::solve::tangential::solve_tangential`] does), the result placed back on
/// the grid. The returned `shift` is the imposed one; the force is
/// `ΔA Σ q`.
pub fn solve_displacement(
    op: &mut Operator,
    windows: &mut WindowCache,
    prob: &DisplacementProblem,
) -> Result<TangentialSolution, SolverError> {
    let n = op.grid().n;
    let Some(win) = contact_window(n, prob.p) else {
        return solve_displacement_on_grid(op, prob);
    };
    let p = win.gather(prob.p);
    let extra = prob.extra.map(|(ex, ey)| (win.gather(ex), win.gather(ey)));
    let start = match prob.start {
        TangentialStart::Tractions(qx, qy) => Some((win.gather(qx), win.gather(qy))),
        TangentialStart::Proportional => None,
    };
    let sub = DisplacementProblem {
        p: &p,
        extra: extra.as_ref().map(|(x, y)| (&x[..], &y[..])),
        start: match &start {
            Some((x, y)) => TangentialStart::Tractions(x, y),
            None => TangentialStart::Proportional,
        },
        ..*prob
    };
    let cover = op.cover().map(|c| win.gather(c));
    let wop = windows.operator(op, win.n);
    wop.set_cover(cover.as_deref());
    let sol = solve_displacement_on_grid(wop, &sub)?;
    Ok(TangentialSolution {
        qx: win.scatter(&sol.qx, 0.0),
        qy: win.scatter(&sol.qy, 0.0),
        sx: win.scatter(&sol.sx, 0.0),
        sy: win.scatter(&sol.sy, 0.0),
        stick: win.scatter(&sol.stick, false),
        ..sol
    })
}

/// The friction disc's clip of `(x, y)` to radius `b`.
#[inline]
fn clip(x: f64, y: f64, b: f64) -> (f64, f64) {
    let r = (x * x + y * y).sqrt();
    if r <= b {
        (x, y)
    } else {
        (x * b / r, y * b / r)
    }
}

/// Fraction of the KKT scale by which the start's loose cells (below) must
/// slip, on the mean, for [`shift_guess`] to move the start: the imposed
/// shift not yet carried by the tractions. On Table 1a at 128² (coupled,
/// Δ = 0.05 µm) that mean is the scale itself (1.000) in the first pass of
/// every history increment and at most 1.6e-2 of it in the coupling passes
/// that follow, where moving an almost converged start cost more than it
/// saved (2256 against 924 iterations for the path).
const GUESS: f64 = 0.5;

/// The start guess of a displacement-controlled solve. The start's loose
/// cells — inside their discs, or on their rims with a slip `s` that does
/// not oppose the traction — slip by `m` on the mean; if `|m| ≥ GUESS ·
/// scale`, the tractions `q` move by the uniform field `t d` (`d = −m` on
/// every contact cell) with the `t` that minimises the energy along it, `t =
/// −dᵀs / dᵀCd`, and are clipped to their discs: the cells the increment's
/// shift makes slip start on their rims in its direction, where the
/// force-controlled solver's projection of a new force puts them. Returns
/// `None` when the start is left as it is (no energy product spent), else
/// `t` (0 if `dᵀCd` vanished and nothing moved). (Table 1a at 128² of 2
/// µm, 2 cycles, uncoupled, a whole segment as one increment: Δ = 0.2 µm
/// 164 → 85 iterations, Δ = 0.4 µm (gross slip: a reversal from a plateau
/// turns every rim) 179 → 21; 10 increments per segment −5 % to +1 %.)
fn shift_guess(
    op: &mut Operator,
    cells: &[usize],
    bound: impl Fn(usize) -> f64,
    scale: f64,
    (qx, qy): (&mut [f64], &mut [f64]),
    (sx, sy): (&[f64], &[f64]),
) -> Option<f64> {
    let (mut mx, mut my, mut n) = (0.0, 0.0, 0usize);
    for &i in cells {
        let loose =
            qx[i].hypot(qy[i]) < (1.0 - 1e-12) * bound(i) || sx[i] * qx[i] + sy[i] * qy[i] >= 0.0;
        if loose {
            mx += sx[i];
            my += sy[i];
            n += 1;
        }
    }
    if n == 0 {
        return None;
    }
    let d = [-mx / n as f64, -my / n as f64];
    if d[0].hypot(d[1]) < GUESS * scale {
        return None;
    }
    let len = qx.len();
    let (mut dx, mut dy) = (vec![0.0; len], vec![0.0; len]);
    let mut ds = 0.0;
    for &i in cells {
        dx[i] = d[0];
        dy[i] = d[1];
        ds += d[0] * sx[i] + d[1] * sy[i];
    }
    let dcd = op.tangential_energy(&dx, &dy);
    if dcd <= 0.0 || !dcd.is_finite() {
        return Some(0.0);
    }
    let t = -ds / dcd;
    for &i in cells {
        (qx[i], qy[i]) = clip(qx[i] + t * d[0], qy[i] + t * d[1], bound(i));
    }
    Some(t)
}

/// [`solve_displacement`] on the whole grid (for comparisons and tests).
pub fn solve_displacement_on_grid(
    op: &mut Operator,
    prob: &DisplacementProblem,
) -> Result<TangentialSolution, SolverError> {
    let len = op.grid().len();
    let p = prob.p;
    // (μ is checked with the case, `CaseSpec::validate`.)
    let mu = prob.friction;
    let cells: Vec<usize> = (0..len).filter(|&i| p[i] > 0.0).collect();
    let bound = |i: usize| mu * p[i];
    let (mut qx, mut qy) = (vec![0.0; len], vec![0.0; len]);
    if let TangentialStart::Tractions(ix, iy) = prob.start {
        for &i in &cells {
            (qx[i], qy[i]) = clip(ix[i], iy[i], bound(i));
        }
    }
    let (mut sx, mut sy) = (vec![0.0; len], vec![0.0; len]);
    let scale = prob.shift[0]
        .hypot(prob.shift[1])
        .max(prob.slip_floor)
        .max(f64::MIN_POSITIVE);
    // The slip's constant part `e − δt`: with it, the slip is measured from
    // the imposed shift, and the iteration below is the force-controlled
    // one's without its multiplier.
    let (mut ex, mut ey) = (vec![-prob.shift[0]; len], vec![-prob.shift[1]; len]);
    if let Some((px, py)) = prob.extra {
        for i in 0..len {
            ex[i] += px[i];
            ey[i] += py[i];
        }
    }
    let extra = Some((&ex[..], &ey[..]));
    let slip = |op: &mut Operator, qx: &[f64], qy: &[f64], sx: &mut [f64], sy: &mut [f64]| {
        slip_field(op, extra, (qx, qy), (sx, sy));
    };

    // The start's slip, and the guess that moves the start along the shift.
    slip(op, &qx, &qy, &mut sx, &mut sy);
    let mut applications = 1;
    let mut energy_products = 0;
    if let Some(t) = shift_guess(op, &cells, bound, scale, (&mut qx, &mut qy), (&sx, &sy)) {
        energy_products += 1;
        if t != 0.0 {
            slip(op, &qx, &qy, &mut sx, &mut sy);
            applications += 1;
        }
    }

    // Phase 1: the active set (preconditioned by the circulant inverse).
    let threads = op.threads().clone();
    let chunks = Chunks::of_cells(&cells, len);
    let set = Feasible::new((&chunks, &threads), &cells, p, mu, [0.0; 2]);
    let ctl = Controls {
        tolerance: prob.tolerance,
        floor: scale,
        budget: prob.max_iterations,
    };
    let q = (&mut qx[..], &mut qy[..]);
    let out = active_set_under(
        op,
        extra,
        &set,
        Condition::Shift,
        ctl,
        q,
        (&mut sx, &mut sy),
    )?;
    let mut report = TangentialReport {
        iterations: out.iterations,
        cg_iterations: out.iterations,
        applications: applications + out.applications,
        energy_products,
        preconditioner_applications: out.inverses,
        split_updates: out.split_updates,
        change: out.kkt,
        converged: out.converged,
        ..TangentialReport::default()
    };

    // Phase 2, only if phase 1 stopped short: FISTA from where it stopped.
    let fista_budget = if report.converged {
        0
    } else {
        prob.max_iterations.saturating_sub(out.iterations)
    };
    if fista_budget > 0 {
        let step = 1.0 / op.tangential_bound();
        let (mut yx, mut yy) = (qx.clone(), qy.clone());
        let (mut px, mut py) = (vec![0.0; len], vec![0.0; len]);
        let mut momentum = Momentum::new();
        for it in 1..=fista_budget {
            crate::base::progress::tick_or_cancel()?;
            report.iterations = out.iterations + it;
            report.applications += 1;
            slip(op, &yx, &yy, &mut sx, &mut sy);
            for &i in &cells {
                (px[i], py[i]) = clip(yx[i] - step * sx[i], yy[i] - step * sy[i], bound(i));
            }
            // The gradient mapping (a slip) relative to the scale.
            report.change = momentum.finish(
                &cells,
                (&mut qx, &mut qy),
                (&px, &py),
                (&mut yx, &mut yy),
                (step, scale),
            );
            if report.change < prob.tolerance {
                report.converged = true;
                break;
            }
        }
    }
    // Final slip, stick set and KKT residuals of the returned tractions. A
    // converged active set left `s = C q + e − δt` of these tractions in
    // (sx, sy).
    if !out.converged {
        slip(op, &qx, &qy, &mut sx, &mut sy);
    }
    let mut stick = vec![false; len];
    let (mut st_res, mut sl_res) = (0.0_f64, 0.0_f64);
    for i in 0..len {
        if p[i] <= 0.0 {
            sx[i] = 0.0;
            sy[i] = 0.0;
            continue;
        }
        let qn = qx[i].hypot(qy[i]);
        stick[i] = qn < (1.0 - 1e-9) * bound(i);
        if stick[i] {
            st_res = st_res.max(sx[i].hypot(sy[i]) / scale);
            sx[i] = 0.0;
            sy[i] = 0.0;
        } else if qn > 0.0 {
            let w = sx[i].hypot(sy[i]);
            sl_res = sl_res.max((sx[i] + w * qx[i] / qn).hypot(sy[i] + w * qy[i] / qn) / scale);
        }
    }
    report.stick_residual = st_res;
    report.slip_residual = sl_res;
    Ok(TangentialSolution {
        qx,
        qy,
        sx,
        sy,
        stick,
        shift: prob.shift,
        report,
    })
}
