//! The projected conjugate gradient of the force-controlled problem (the
//! default `solver.tangential_method`): the stick cells' tractions and the
//! slip cells' rotation on their rims as the conjugate variables
//! (`cg_disc`), and the Fourier preconditioner of the stick cells that a
//! history's uncoupled increments ask for (`StickPrecond`).

use crate::base::parallel::Threads;
use crate::error::SolverError;
use crate::operators::multilevel::FourierPrecond;
use crate::operators::operator::Operator;
use crate::solve::tangential::active_set::{norm, slip_field, solve2, Feasible};
use crate::solve::tangential::force::project_holding;
use crate::solve::tangential::problem::{TangentialMethod, TangentialProblem};

/// Outcome of the conjugate-gradient phase.
pub(super) struct CgOutcome {
    pub(super) iterations: usize,
    pub(super) applications: usize,
    pub(super) energy_products: usize,
    pub(super) kkt: f64,
    pub(super) shift: [f64; 2],
    pub(super) converged: bool,
}

/// Consecutive iterations without a new best KKT residual after which the
/// conjugate-gradient phase hands over to FISTA.
pub(super) const CG_STALL: usize = 60;

/// Iterations between full recomputations of the slip field `C q + e`
/// (it is otherwise updated by `C Δq`, which accumulates round-off).
pub(super) const REFRESH: usize = 32;

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
pub(super) fn cg_disc(
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
pub(super) struct StickPrecond<'a> {
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
pub(super) fn fourier_pays(prob: &TangentialProblem, grid: crate::base::grid::Grid) -> bool {
    prob.method == TangentialMethod::ConjugateGradient
        && prob.precondition
        && grid.n <= FOURIER_STICK_MAX_SIDE
}

/// Diagonal of the stick cells' Fourier preconditioner relative to the
/// Jacobi weight one of the slip cells. (Table 1a uncoupled at 256², one
/// fretting cycle after the first loading, 60 increments: 3536 tangential
/// iterations without `W`; with `W` scaled to diagonal 0.3 / 1 / 3 / 10 /
/// 30: 3153 / 1992 / 1639 / 2221 / 4120.)
pub(super) const STICK_SCALE: f64 = 3.0;

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
pub(super) struct StickZ<'a>(Option<(&'a [f64], &'a [f64])>);

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
pub(super) fn sum_in_order(
    parts: impl IntoIterator<Item = (f64, f64, usize)>,
) -> (f64, f64, usize) {
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
pub(super) const STIFF_RIM: f64 = 1e3;

/// A slip cell's traction direction `n`, the curvature `c` of its disc's rim
/// (m/Pa) and the cell's Jacobi weight `k`.
pub(super) struct SlipCell {
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
pub(super) fn on_rim(qx: f64, qy: f64, b: f64) -> bool {
    norm(qx, qy) >= (1.0 - 1e-12) * b
}
