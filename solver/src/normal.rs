//! Normal contact: load-controlled conjugate gradient with active-set
//! projection (Polonsky & Keer 1999) for a rigid body on the half-space.
//! Sees only the operator's `K_zz` (plus an extra gap term supplied by the
//! caller, e.g. `uz(q)` from tangential coupling); knows nothing of geometry.

use crate::error::SolverError;
use crate::operator::Operator;

/// Convergence report of one normal solve.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct NormalReport {
    /// CG iterations used.
    pub iterations: usize,
    /// Final relative change of pressure, `ΔA Σ|p − p_old| / P`.
    pub change: f64,
    /// max over contact cells of |gap| / δz (gap should vanish there).
    pub gap_residual: f64,
    /// max over non-contact cells of the interpenetration / δz (should be 0).
    pub penetration: f64,
    /// |ΔA Σ p − P| / P.
    pub load_error: f64,
    /// True when `change < tolerance` within the iteration budget.
    pub converged: bool,
}

/// Solution of a normal problem.
#[derive(Clone, Debug)]
pub struct NormalSolution {
    /// Pressure per cell, Pa.
    pub p: Vec<f64>,
    /// Normal displacement `uz = K_zz * p` (without any extra term), m.
    pub uz: Vec<f64>,
    /// Rigid-body approach δz, m (gap `g = h0 + extra + uz − δz`).
    pub approach: f64,
    /// Convergence.
    pub report: NormalReport,
}

/// Solves for the pressure under total load `load_n` given the initial
/// separation `h0` (m, per cell) and an optional extra gap term. `p_init`
/// warm-starts the iteration when given.
pub fn solve_normal(
    op: &mut Operator,
    h0: &[f64],
    extra_gap: Option<&[f64]>,
    load_n: f64,
    tolerance: f64,
    max_iterations: usize,
    p_init: Option<&[f64]>,
) -> Result<NormalSolution, SolverError> {
    let grid = op.grid();
    let len = grid.len();
    let da = grid.cell_area();
    if !(load_n.is_finite() && load_n > 0.0) {
        return Err(SolverError::invalid(
            "load.normal_n",
            format!("the normal load must be positive and finite, got {load_n} N"),
        ));
    }
    let h: Vec<f64> = match extra_gap {
        Some(e) => h0.iter().zip(e).map(|(a, b)| a + b).collect(),
        None => h0.to_vec(),
    };
    // Initial guess: the warm start, or a uniform pressure over the cells whose
    // separation is within the smallest 1/4 of the range.
    let mut p = match p_init {
        Some(p0) if p0.iter().any(|&v| v > 0.0) => p0.to_vec(),
        _ => {
            let hmin = h.iter().cloned().fold(f64::INFINITY, f64::min);
            let hmax = h.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
            let cut = hmin + 0.05 * (hmax - hmin);
            h.iter()
                .map(|&v| if v <= cut { 1.0 } else { 0.0 })
                .collect()
        }
    };
    let sum: f64 = p.iter().sum::<f64>() * da;
    p.iter_mut().for_each(|v| *v *= load_n / sum);

    let mut u = vec![0.0; len];
    let mut g = vec![0.0; len];
    let mut t = vec![0.0; len];
    let mut r = vec![0.0; len];
    let mut g_old = 1.0;
    let mut delta = 0.0;
    let mut report = NormalReport::default();
    let mut gbar = 0.0;
    for it in 1..=max_iterations {
        report.iterations = it;
        op.normal(&p, &mut u);
        let mut nc = 0usize;
        let mut sum_g = 0.0;
        for i in 0..len {
            g[i] = u[i] + h[i];
            if p[i] > 0.0 {
                nc += 1;
                sum_g += g[i];
            }
        }
        if nc == 0 {
            break;
        }
        gbar = sum_g / nc as f64;
        let mut gg = 0.0;
        for i in 0..len {
            g[i] -= gbar;
            if p[i] > 0.0 {
                gg += g[i] * g[i];
            }
        }
        for i in 0..len {
            t[i] = if p[i] > 0.0 {
                g[i] + delta * (gg / g_old) * t[i]
            } else {
                0.0
            };
        }
        g_old = gg;
        op.normal(&t, &mut r);
        let (mut sr, mut cnt) = (0.0, 0usize);
        for i in 0..len {
            if p[i] > 0.0 {
                sr += r[i];
                cnt += 1;
            }
        }
        let rbar = sr / cnt as f64;
        let (mut num, mut den) = (0.0, 0.0);
        for i in 0..len {
            if p[i] > 0.0 {
                r[i] -= rbar;
                num += g[i] * t[i];
                den += r[i] * t[i];
            }
        }
        if den <= 0.0 || !den.is_finite() {
            break;
        }
        let tau = num / den;
        let mut change = 0.0;
        // Step, clip, and re-admit cells that interpenetrate (overlap set).
        let mut overlap = false;
        for i in 0..len {
            let old = p[i];
            let mut new = if old > 0.0 {
                (old - tau * t[i]).max(0.0)
            } else {
                0.0
            };
            if new == 0.0 && g[i] < 0.0 {
                new = -tau * g[i];
                overlap = true;
            }
            p[i] = new;
            // store old in r for the change measure
            r[i] = old;
        }
        delta = if overlap { 0.0 } else { 1.0 };
        let total: f64 = p.iter().sum::<f64>() * da;
        if total <= 0.0 || !total.is_finite() {
            return Err(SolverError::invalid(
                "solver",
                "normal solver lost all contact (pressure vanished); check the geometry",
            ));
        }
        let scale = load_n / total;
        for i in 0..len {
            p[i] *= scale;
            change += (p[i] - r[i]).abs();
        }
        report.change = change * da / load_n;
        if report.change < tolerance {
            report.converged = true;
            break;
        }
    }
    // Final state and residuals from the returned pressure.
    op.normal(&p, &mut u);
    let (mut s, mut nc) = (0.0, 0usize);
    for i in 0..len {
        if p[i] > 0.0 {
            s += u[i] + h[i];
            nc += 1;
        }
    }
    let approach = if nc > 0 { s / nc as f64 } else { gbar };
    let scale = approach.abs().max(f64::MIN_POSITIVE);
    let (mut gap_res, mut pen) = (0.0_f64, 0.0_f64);
    for i in 0..len {
        let gap = u[i] + h[i] - approach;
        if p[i] > 0.0 {
            gap_res = gap_res.max(gap.abs() / scale);
        } else {
            pen = pen.max((-gap).max(0.0) / scale);
        }
    }
    report.gap_residual = gap_res;
    report.penetration = pen;
    report.load_error = (p.iter().sum::<f64>() * da - load_n).abs() / load_n;
    Ok(NormalSolution {
        p,
        uz: u,
        approach,
        report,
    })
}
