//! Partial slip under a tangential force, with or without normal–tangential
//! coupling: the tangential solve at the current pressure, and (coupled) the
//! fixed-point loop between it and the normal solve with the tangential
//! tractions' normal displacement as an extra gap, accelerated by Anderson
//! mixing while far from converged. Knows the case's load and numerics, and
//! the solvers through a [`Resident`] bundle; reduces nothing to scalars.

use std::collections::VecDeque;

use crate::error::SolverError;
use crate::model::spec::CaseSpec;
use crate::operators::operator::{X, Y, Z};
use crate::solve::normal::{NormalProblem, NormalReport, NormalSolution};
use crate::solve::resident::Resident;
use crate::solve::tangential::displacement::DisplacementProblem;
use crate::solve::tangential::{
    TangentialProblem, TangentialReport, TangentialSolution, TangentialStart,
};

/// History depth of the Anderson mixing of the coupling loop.
const ANDERSON_DEPTH: usize = 3;

/// Anderson acceleration (type II) of a fixed point `x = G(x)`: given
/// `g = G(x_prev)`, replaces it by `g − ΔG γ` with `γ` minimising
/// `|f − ΔF γ|`, `f = g − x_prev`, over the last `depth` differences.
///
/// The history holds the last `depth` pairs `(g, f)`, and the differences
/// `ΔG`, `ΔF` are formed cell by cell where they are used: `2 depth + 1`
/// fields instead of `2 depth` differences plus the last pair and `x_prev`
/// (two fields fewer, 67 MB of a 2048² solve), with the same arithmetic.
struct Anderson {
    depth: usize,
    x_prev: Vec<f64>,
    /// `(g, f)` of the last calls since a reset, oldest first.
    history: VecDeque<(Vec<f64>, Vec<f64>)>,
}

impl Anderson {
    fn new(depth: usize, len: usize) -> Self {
        Anderson {
            depth,
            x_prev: vec![0.0; len],
            history: VecDeque::new(),
        }
    }

    fn reset(&mut self) {
        self.history.clear();
    }

    /// `g` holds G(x_prev) on entry and the next iterate on return.
    fn mix(&mut self, g: &mut [f64]) {
        let f: Vec<f64> = g.iter().zip(&self.x_prev).map(|(a, b)| a - b).collect();
        self.history.push_back((g.to_vec(), f));
        if self.history.len() > self.depth + 1 {
            self.history.pop_front();
        }
        // Difference i is between entries i and i + 1 (the last: this call's).
        let h = &self.history;
        let m = h.len() - 1;
        if m > 0 {
            let f = &h[m].1;
            let df_dot = |i: usize, j: usize| -> f64 {
                let (a0, a1, b0, b1) = (&h[i].1, &h[i + 1].1, &h[j].1, &h[j + 1].1);
                (0..f.len())
                    .map(|c| (a1[c] - a0[c]) * (b1[c] - b0[c]))
                    .sum::<f64>()
            };
            let a = nalgebra::DMatrix::from_fn(m, m, df_dot);
            let b = nalgebra::DVector::from_fn(m, |i, _| {
                let (a0, a1) = (&h[i].1, &h[i + 1].1);
                (0..f.len()).map(|c| (a1[c] - a0[c]) * f[c]).sum::<f64>()
            });
            let reg = 1e-12 * a.trace().max(f64::MIN_POSITIVE);
            let a = a + nalgebra::DMatrix::identity(m, m) * reg;
            if let Some(gamma) = a.cholesky().map(|c| c.solve(&b)) {
                if gamma.iter().all(|v| v.is_finite()) {
                    for j in 0..m {
                        let (g0, g1) = (&h[j].0, &h[j + 1].0);
                        for (c, gi) in g.iter_mut().enumerate() {
                            *gi -= gamma[j] * (g1[c] - g0[c]);
                        }
                    }
                }
            }
        }
        // Only `depth` pairs are needed by the next call.
        if self.history.len() > self.depth {
            self.history.pop_front();
        }
        self.x_prev.copy_from_slice(g);
    }
}

/// Pressure, tractions, slip and convergence of a case after its partial-slip solve.
pub(crate) struct ContactState {
    /// Pressure, Pa.
    pub p: Vec<f64>,
    /// Rigid-body approach δz, m.
    pub approach: f64,
    /// Plastic penetration per cell under the last normal solve's
    /// separation, m (empty on an elastic surface; see
    /// [`NormalSolution::plastic`]).
    pub plastic: Vec<f64>,
    /// The last tangential solution (without a tangential force: no
    /// tractions, every contact cell sticks).
    pub tangential: TangentialSolution,
    /// Report of the last normal solve.
    pub normal_report: NormalReport,
    /// Normal iterations, summed over coupling passes.
    pub normal_iterations: usize,
    /// Tangential iterations, summed over coupling passes.
    pub tangential_iterations: usize,
    /// Coupling passes (0 without a tangential force).
    pub coupling_iterations: usize,
    /// Last relative change of p between coupling passes.
    pub coupling_change: f64,
    /// The coupling loop converged (true when uncoupled).
    pub coupling_converged: bool,
}

/// Solves the tangential problem of `spec` (and, coupled, the coupling loop)
/// from the normal solution `normal0` of the separation `h0`.
pub(crate) fn solve_partial_slip(
    res: &mut Resident,
    spec: &CaseSpec,
    h0: &[f64],
    normal0: NormalSolution,
) -> Result<ContactState, SolverError> {
    let step = Step {
        normal_force_n: spec.load.normal_force_n,
        target: Target::Force(spec.load.tangential_force()),
        previous: None,
        tolerance_scale: 1.0,
        coupling_tolerance: spec.numerics_in_effect().coupling_tolerance,
        tangential_tolerance: spec.numerics_in_effect().tangential_tolerance,
    };
    solve_step(res, spec, h0, normal0, &step)
}

/// The state a load increment starts from (see [`Step`]).
pub(crate) struct Previous<'a> {
    /// Tractions the increment's iteration starts from (the previous
    /// increment's), Pa. (A linear extrapolation of the last two left an
    /// increment of Table 1a at 128² unconverged.)
    pub start: (&'a [f64], &'a [f64]),
    /// Total tangential surface displacement at the end of the previous
    /// increment, `ut(q) + [ut(p) − ut(p⁰)]` (the bracket only with
    /// coupling), m.
    pub u: (&'a [f64], &'a [f64]),
    /// The pressure after the initial normal loading, p⁰, Pa (coupling only).
    pub p0: &'a [f64],
}

/// What a step imposes tangentially.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Target {
    /// The tangential force at the step's end, N (force control).
    Force([f64; 2]),
    /// The increment of the ball's rigid shift δt over the step, m
    /// (displacement control: the force is a result, and the contact may
    /// slide as a whole).
    Shift([f64; 2]),
}

impl Target {
    /// The imposed vector (its direction is the loading direction).
    fn vector(self) -> [f64; 2] {
        match self {
            Target::Force(v) | Target::Shift(v) => v,
        }
    }
}

/// The load of one solve: one monotonic step from rest (`previous: None`,
/// the case of §5 of PHYSICS.md) or one increment of a load history from
/// the previous increment's state (§5b).
pub(crate) struct Step<'a> {
    /// Normal load P at the end of the step, N.
    pub normal_force_n: f64,
    /// The tangential force or shift the step imposes.
    pub target: Target,
    /// The previous increment's state; `None` from rest.
    pub previous: Option<Previous<'a>>,
    /// Factor (≥ 1) on the tangential tolerance. The solver measures its KKT
    /// residual relative to the shift it solves for, which for an increment
    /// is the increment of δt; a history passes |δt| / |Δδt| here so that
    /// every increment is solved to the tolerance relative to the loop's δt,
    /// as a monotonic step is (relative to its increment, the residual
    /// stalled near 1e-6 for thousands of iterations: 20 steps of 0.6 μP
    /// on Table 1a, 128², 14 of 20 increments not converged in 5000).
    pub tolerance_scale: f64,
    /// The coupling loop's tolerance for this step (the relative change of
    /// the pressure between passes): the configured one, or a looser one
    /// for an increment inside a load path's segment (see
    /// `history::walk::INTERIOR_COUPLING`).
    pub coupling_tolerance: f64,
    /// The tangential solves' KKT tolerance for this step (before
    /// `tolerance_scale`): the configured one, or a looser one inside a
    /// load path's segment.
    pub tangential_tolerance: f64,
}

/// One step of tangential loading (and, coupled, the coupling loop) from the
/// normal solution `normal0` at `step.normal_force_n`. From a previous state,
/// the slip the solver sees is the increment since that state (its
/// displacement enters, negated, as the extra term) and the shift it returns
/// is the increment of δt.
pub(crate) fn solve_step(
    res: &mut Resident,
    spec: &CaseSpec,
    h0: &[f64],
    normal0: NormalSolution,
    step: &Step,
) -> Result<ContactState, SolverError> {
    let num = spec.numerics_in_effect();
    let grid = spec.grid;
    let len = grid.len();
    let da = grid.cell_area();
    let load = step.normal_force_n;
    let tol = num.tolerance;
    let mut normal_iterations = normal0.report.iterations;
    let mut normal_report = normal0.report;
    let mut approach = normal0.approach;
    let mut plastic = normal0.plastic;
    let mut p = normal0.p;
    drop(normal0.uz);
    let force = match step.target {
        Target::Force(f) => f,
        Target::Shift(_) => [0.0; 2],
    };
    let drive = step.target.vector();
    let fnorm = drive[0].hypot(drive[1]);
    let previous = step.previous.as_ref();

    // The last pass's tangential solution (none before the first pass).
    let mut last: Option<TangentialSolution> = None;
    let mut tangential_iterations = 0;
    let mut coupling_iterations = 0;
    let mut coupling_change = 0.0;
    let mut coupling_converged = true;

    // An increment of a history is solved even at zero force (unloading
    // passes through it with tractions locked in).
    if fnorm > 0.0 || previous.is_some() {
        // The pressure before tangential loading: the coupling term is the
        // tangential displacement of the pressure's change since then.
        let p0 = match previous {
            Some(prev) if num.coupling => prev.p0.to_vec(),
            _ if num.coupling => p.clone(),
            _ => Vec::new(),
        };
        let has_extra = num.coupling || previous.is_some();
        coupling_converged = !num.coupling;
        // Inexact inner solves while the coupling loop is far from converged:
        // each inner tolerance follows the last change of p, and the final
        // passes use the configured tolerances.
        // (Exact passes from the first for a history's increments, which
        // start next to their solution, made them slower: 60 increments of
        // Table 1a at 256² took over 318 s against 113 s with this schedule.)
        let mut prev_change: f64 = 1e-2;
        let mut anderson = Anderson::new(ANDERSON_DEPTH, len);
        for k in 1..=num.max_coupling_iterations {
            crate::base::progress::pass(num.coupling.then_some(k))?;
            coupling_iterations = k;
            let coupling_tolerance = step.coupling_tolerance;
            let exact_pass = !num.coupling || prev_change < 10.0 * coupling_tolerance;
            // In the final passes the tangential residual must not show as a
            // change of p above the coupling tolerance: with the default
            // coupling tolerance the KKT tolerance stays as configured; a
            // tighter coupling tolerance tightens it (p moves by about 1e-2 of
            // the tangential residual per pass).
            let (tan_tol, normal_tol) = if exact_pass {
                (
                    step.tangential_tolerance
                        .min(100.0 * coupling_tolerance)
                        .max(1e-12),
                    tol,
                )
            } else {
                (
                    step.tangential_tolerance.max(0.1 * prev_change),
                    tol.max(1e-2 * prev_change),
                )
            };
            let tan_tol = tan_tol * step.tolerance_scale;
            // The slip terms (ex, ey), dp and hq live only while they are
            // used: a pass's tangential and normal solves each hold only
            // their own inputs (on Table 1a the two are the case's memory
            // peaks, 2.2 and 2.3 times the stored spectra and nine fields).
            let (mut ex, mut ey) = (vec![0.0; len], vec![0.0; len]);
            if num.coupling {
                let dp: Vec<f64> = p.iter().zip(&p0).map(|(a, b)| a - b).collect();
                res.operator
                    .apply(&[(Z, &dp)], &mut [(X, &mut ex), (Y, &mut ey)]);
            }
            // Slip measured from the previous increment's state (uncoupled,
            // there is one pass).
            if let Some(prev) = previous.filter(|_| num.coupling || k == 1) {
                for i in 0..len {
                    ex[i] -= prev.u.0[i];
                    ey[i] -= prev.u.1[i];
                }
            }
            let slip_floor = if has_extra {
                slip_floor(&p, (&ex, &ey)) / step.tolerance_scale
            } else {
                0.0
            };
            // The friction bound's pressure (the pressure itself without a
            // shear limit).
            let bound = spec.friction_pressure(&p, res.operator.cover());
            let prob = TangentialProblem {
                p: &bound,
                friction: spec.load.friction,
                force,
                extra: has_extra.then_some((&ex[..], &ey[..])),
                tolerance: tan_tol,
                slip_floor,
                max_iterations: num.max_iterations,
                start: match previous {
                    Some(prev) => TangentialStart::Tractions(prev.start.0, prev.start.1),
                    None => TangentialStart::Proportional,
                },
                // A history's uncoupled increments start next to their
                // solution, where the Fourier preconditioner halves the
                // iterations (Table 1a at 256², one cycle after the first
                // loading: 3536 → 1652, 16.8 s → 9.8 s). A coupled increment's
                // ~7 passes take 8–11 iterations each with or without it
                // (4958 → 4555 in all), and its transforms add a quarter to
                // each iteration: 29.6 / 32.9 s → 34.4 / 38.3 s, so coupled
                // passes keep the Jacobi preconditioner.
                precondition: previous.is_some() && !num.coupling,
                method: num.tangential_method,
            };
            // From the second pass on, the last pass's tractions start the
            // solve, which takes them over (they are replaced by its own).
            let mut tan = match (step.target, last.take()) {
                // Displacement control: the shift is imposed, the force a result.
                (Target::Shift(shift), pass) => res.solve_displacement(&DisplacementProblem {
                    p: &bound,
                    friction: spec.load.friction,
                    shift,
                    extra: prob.extra,
                    tolerance: tan_tol,
                    slip_floor,
                    max_iterations: num.max_iterations,
                    start: match &pass {
                        Some(t) => TangentialStart::Tractions(&t.qx, &t.qy),
                        None => prob.start,
                    },
                })?,
                (Target::Force(_), Some(prev)) => {
                    res.solve_tangential_from(&prob, (prev.qx, prev.qy))?
                }
                (Target::Force(_), None) => res.solve_tangential(&prob)?,
            };
            tangential_iterations += tan.report.iterations;
            if !num.coupling || coupling_converged {
                last = Some(tan);
                break;
            }
            drop((ex, ey));
            // When another tangential solve follows this pass, its slip is
            // not needed again; after the last pass the budget allows, it is
            // the slip the case reports.
            if k < num.max_coupling_iterations {
                drop((std::mem::take(&mut tan.sx), std::mem::take(&mut tan.sy)));
            }
            let mut hq = vec![0.0; len];
            res.operator
                .apply(&[(X, &tan.qx), (Y, &tan.qy)], &mut [(Z, &mut hq)]);
            // Anderson mixing of the coupling gap uz(q) while the loop is far
            // from converged; plain (Picard) passes at the end, so the
            // convergence test below is the fixed-point test of the plain loop.
            if exact_pass {
                anderson.reset();
            } else {
                anderson.mix(&mut hq);
            }
            let nsol = res.solve_normal(&NormalProblem {
                extra_gap: Some(&hq),
                tolerance: normal_tol,
                max_iterations: num.max_iterations,
                p_init: Some(&p),
                hardness: spec.limits().hardness,
                ..NormalProblem::new(h0, load)
            })?;
            normal_iterations += nsol.report.iterations;
            normal_report = nsol.report;
            coupling_change = p
                .iter()
                .zip(&nsol.p)
                .map(|(a, b)| (a - b).abs())
                .sum::<f64>()
                * da
                / load;
            let new_bound = spec.friction_pressure(&nsol.p, res.operator.cover());
            rescale_slip(&mut tan, &bound, &new_bound, spec.load.friction, drive);
            drop(new_bound);
            drop(bound);
            last = Some(tan);
            p = nsol.p;
            approach = nsol.approach;
            plastic = nsol.plastic;
            // One more tangential solve at the updated pressure closes the loop.
            if coupling_change < coupling_tolerance && exact_pass {
                coupling_converged = true;
            }
            prev_change = coupling_change;
        }
    }
    // Without a tangential force: no tractions, every contact cell sticks.
    let tangential = last.unwrap_or_else(|| TangentialSolution {
        qx: vec![0.0; len],
        qy: vec![0.0; len],
        sx: vec![0.0; len],
        sy: vec![0.0; len],
        stick: p.iter().map(|&v| v > 0.0).collect(),
        shift: [0.0; 2],
        report: TangentialReport {
            converged: true,
            ..Default::default()
        },
    });
    Ok(ContactState {
        p,
        approach,
        plastic,
        tangential,
        normal_report,
        normal_iterations,
        tangential_iterations,
        coupling_iterations,
        coupling_change,
        coupling_converged,
    })
}

/// Keeps the slip cells of `tan` on the rims of their friction discs when the
/// pressure changes from `p_old` to `p_new` between coupling passes: their
/// tractions are scaled by `p_new / p_old`, so that the next pass starts from
/// the slip zone the last one ended with. (Kept as they were, the slip cells
/// whose pressure rose started the next pass inside their discs, as stick
/// cells with slip: on Table 1a, 160 tangential iterations over the passes
/// against 93 with the rescaling at 512², 197 against 157 at 1024².)
///
/// Cells that came into contact start on their rims along the force, as the
/// slip cells at the contact's edge are: left at zero traction they were
/// stick cells slipping by a third of δt, and the pass that met them first
/// took 65 iterations instead of about 25 (Table 1a, 2048², pass 5).
fn rescale_slip(
    tan: &mut TangentialSolution,
    p_old: &[f64],
    p_new: &[f64],
    friction: f64,
    force: [f64; 2],
) {
    let fnorm = force[0].hypot(force[1]);
    for i in 0..p_old.len() {
        if p_old[i] > 0.0 && !tan.stick[i] {
            let r = p_new[i].max(0.0) / p_old[i];
            tan.qx[i] *= r;
            tan.qy[i] *= r;
        } else if p_old[i] <= 0.0 && p_new[i] > 0.0 && fnorm > 0.0 {
            let b = friction * p_new[i] / fnorm;
            tan.qx[i] = b * force[0];
            tan.qy[i] = b * force[1];
        }
    }
}

/// Fraction of the extra slip term's largest value on the contact that
/// floors the scale of the tangential KKT residual (see
/// [`TangentialProblem::slip_floor`]).
const SLIP_FLOOR: f64 = 1e-2;

/// The floor of the tangential KKT scale for a pass whose slip carries the
/// extra term `(ex, ey)`: `SLIP_FLOOR` times its largest magnitude over the
/// contact cells, i.e. the slip the increment would see if no traction
/// changed (the inward draw of the pressure's change under Spence's normal
/// loading with friction; the previous state's displacement in a history).
/// A history divides it by its tolerance factor, so that the floor stays a
/// hundredth of the loop's scale: below every increment's |Δδt| in the
/// histories of the configs (results unchanged to the bit), where δt exists.
fn slip_floor(p: &[f64], (ex, ey): (&[f64], &[f64])) -> f64 {
    let mut m = 0.0_f64;
    for i in 0..p.len() {
        if p[i] > 0.0 {
            m = m.max(ex[i].hypot(ey[i]));
        }
    }
    SLIP_FLOOR * m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The mixing with stored differences that [`Anderson`] replaced: `2
    /// depth` difference fields, the last `(g, f)` and `x_prev`.
    struct StoredDifferences {
        depth: usize,
        x_prev: Vec<f64>,
        last: Option<(Vec<f64>, Vec<f64>)>,
        dg: VecDeque<Vec<f64>>,
        df: VecDeque<Vec<f64>>,
    }

    impl StoredDifferences {
        fn mix(&mut self, g: &mut [f64]) {
            let f: Vec<f64> = g.iter().zip(&self.x_prev).map(|(a, b)| a - b).collect();
            if let Some((g_old, f_old)) = self.last.take() {
                if self.dg.len() == self.depth {
                    self.dg.pop_front();
                    self.df.pop_front();
                }
                self.dg
                    .push_back(g.iter().zip(&g_old).map(|(a, b)| a - b).collect());
                self.df
                    .push_back(f.iter().zip(&f_old).map(|(a, b)| a - b).collect());
            }
            let next_last = (g.to_vec(), f.clone());
            let m = self.df.len();
            if m > 0 {
                let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
                let a = nalgebra::DMatrix::from_fn(m, m, |i, j| dot(&self.df[i], &self.df[j]));
                let b = nalgebra::DVector::from_fn(m, |i, _| dot(&self.df[i], &f));
                let reg = 1e-12 * a.trace().max(f64::MIN_POSITIVE);
                let a = a + nalgebra::DMatrix::identity(m, m) * reg;
                if let Some(gamma) = a.cholesky().map(|c| c.solve(&b)) {
                    for (j, dgj) in self.dg.iter().enumerate() {
                        for (gi, d) in g.iter_mut().zip(dgj) {
                            *gi -= gamma[j] * d;
                        }
                    }
                }
            }
            self.last = Some(next_last);
            self.x_prev.copy_from_slice(g);
        }
    }

    /// Differences formed where they are used give the iterates of stored
    /// differences to the bit, through a full history and a reset, on a
    /// contractive map (a damped rotation plus a cubic term).
    #[test]
    fn anderson_without_stored_differences_mixes_to_the_bit() {
        let len = 257;
        let map = |x: &[f64], k: usize| -> Vec<f64> {
            (0..len)
                .map(|i| {
                    let j = (i * 7 + k) % len;
                    0.6 * x[j] - 0.3 * x[i]
                        + 0.05 * x[i].powi(3)
                        + ((i * 13 + 5) % 17) as f64 * 1e-3
                })
                .collect()
        };
        let mut new = Anderson::new(3, len);
        let mut old = StoredDifferences {
            depth: 3,
            x_prev: vec![0.0; len],
            last: None,
            dg: VecDeque::new(),
            df: VecDeque::new(),
        };
        let (mut xa, mut xb) = (vec![0.1; len], vec![0.1; len]);
        for k in 0..12 {
            if k == 7 {
                new.reset();
                old.last = None;
                old.dg.clear();
                old.df.clear();
            }
            let (mut ga, mut gb) = (map(&xa, k), map(&xb, k));
            new.mix(&mut ga);
            old.mix(&mut gb);
            for (a, b) in ga.iter().zip(&gb) {
                assert_eq!(a.to_bits(), b.to_bits(), "iterate {k}");
            }
            // The mixing did something: the iterate is not the plain map's.
            if k > 1 && k != 7 && k != 8 {
                let plain = map(&xa, k);
                assert!(ga.iter().zip(&plain).any(|(a, b)| a != b), "iterate {k}");
            }
            (xa, xb) = (ga, gb);
        }
    }

    #[test]
    fn rescaled_slip_stays_on_the_rims_and_new_contact_cells_start_on_theirs() {
        let mu = 0.3;
        // Cells: stick, slip, slip leaving contact, out of contact, entering contact.
        let p_old = [2.0, 1.0, 1.0, 0.0, 0.0];
        let p_new = [2.5, 1.5, 0.0, 0.0, 4.0];
        let mut tan = TangentialSolution {
            qx: vec![0.1, 0.18, 0.3, 0.0, 0.0],
            qy: vec![0.2, 0.24, 0.0, 0.0, 0.0],
            sx: Vec::new(),
            sy: Vec::new(),
            stick: vec![true, false, false, false, false],
            shift: [0.0; 2],
            report: TangentialReport::default(),
        };
        let force = [3.0, -4.0];
        rescale_slip(&mut tan, &p_old, &p_new, mu, force);
        // The stick cell keeps its traction.
        assert_eq!((tan.qx[0], tan.qy[0]), (0.1, 0.2));
        // The slip cell stays on its rim, in its direction.
        let q1 = tan.qx[1].hypot(tan.qy[1]);
        assert!((q1 - mu * p_new[1]).abs() < 1e-15, "{q1}");
        assert!((tan.qy[1] / tan.qx[1] - 0.24 / 0.18).abs() < 1e-12);
        // Out of contact: no traction.
        assert_eq!((tan.qx[2], tan.qy[2]), (0.0, 0.0));
        assert_eq!((tan.qx[3], tan.qy[3]), (0.0, 0.0));
        // Into contact: on the rim, along the force.
        let q4 = tan.qx[4].hypot(tan.qy[4]);
        assert!((q4 - mu * p_new[4]).abs() < 1e-15, "{q4}");
        assert!((tan.qx[4] / q4 - 0.6).abs() < 1e-15 && (tan.qy[4] / q4 + 0.8).abs() < 1e-15);
    }
}
