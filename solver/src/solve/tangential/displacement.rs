//! Partial and gross slip at fixed pressure under an **imposed** rigid
//! tangential shift δt of the ball (displacement control, as fretting rigs
//! run): shear tractions `q` on the contact cells with the friction disc
//! `|q_i| ≤ μ p_i` per cell and no condition on their sum, which is the
//! result (the tangential force). Sees only the operator's tangential block
//! and an extra slip term supplied by the caller, as the force-controlled
//! solver ([`crate::solve::tangential::force`]) does.
//!
//! Method: the convex problem min ½qᵀCq + (e − δt)ᵀq over the discs, whose
//! gradient is the slip `s = Cq + e − δt`, by accelerated projected gradient
//! (FISTA with gradient-based adaptive restart); the projection onto the
//! discs is a clip per cell. Stick cells end with zero slip, slip cells with
//! the traction on their rim opposing the slip. When the imposed shift
//! exceeds what the stick zone can hold, no stick cell is left and every
//! traction sits on its rim: gross slip, F = μP on a flat Coulomb surface.

use crate::error::SolverError;
use crate::operators::operator::Operator;
use crate::solve::tangential::fista::{self, Momentum};
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
    let (mut yx, mut yy) = (qx.clone(), qy.clone());
    let (mut px, mut py) = (vec![0.0; len], vec![0.0; len]);
    let (mut sx, mut sy) = (vec![0.0; len], vec![0.0; len]);
    let step = 1.0 / op.tangential_bound();
    let scale = prob.shift[0]
        .hypot(prob.shift[1])
        .max(prob.slip_floor)
        .max(f64::MIN_POSITIVE);
    let slip = |op: &mut Operator, qx: &[f64], qy: &[f64], sx: &mut [f64], sy: &mut [f64]| {
        op.tangential(qx, qy, sx, sy);
        for i in 0..sx.len() {
            sx[i] -= prob.shift[0];
            sy[i] -= prob.shift[1];
        }
        if let Some((ex, ey)) = prob.extra {
            for i in 0..sx.len() {
                sx[i] += ex[i];
                sy[i] += ey[i];
            }
        }
    };
    let mut report = TangentialReport::default();
    let mut momentum = Momentum::new();
    for it in 1..=prob.max_iterations {
        crate::base::progress::tick_or_cancel()?;
        report.iterations = it;
        report.applications += 1;
        slip(op, &yx, &yy, &mut sx, &mut sy);
        for &i in &cells {
            (px[i], py[i]) = clip(yx[i] - step * sx[i], yy[i] - step * sy[i], bound(i));
        }
        // The gradient mapping (a slip) relative to the scale.
        let (res, restart) = fista::mapping(&cells, (&yx, &yy), (&px, &py), (&qx, &qy));
        report.change = res / step / scale;
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
    // Final slip, stick set and KKT residuals of the returned tractions.
    slip(op, &qx, &qy, &mut sx, &mut sy);
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
    report.cg_iterations = 0;
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
