//! Normal contact: load-controlled conjugate gradient with active-set
//! projection (Polonsky & Keer 1999) for a rigid body on the half-space.
//! Sees only the operator's `K_zz` (plus an extra gap term supplied by the
//! caller, e.g. `uz(q)` from tangential coupling); knows nothing of geometry.
//! Owns its per-grid aids (coarse levels, Fourier preconditioner) in
//! [`NormalCache`]; the operator stays the bare DC-FFT operator.

use crate::base::parallel::{Chunks, Threads};
use crate::error::SolverError;
use crate::model::material::limit_per_cell;
use crate::operators::multilevel::{coarse_levels, prolong, restrict, CoarseLevel, FourierPrecond};
use crate::operators::operator::{Operator, Z};

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
    /// Operator applications on the fine grid.
    pub applications: usize,
    /// Iterations on the coarse levels of a nested start (each costs a
    /// quarter, a sixteenth, … of a fine one).
    pub coarse_iterations: usize,
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
    /// Plastic penetration per cell, m: on the cells whose pressure is at
    /// the cap ([`NormalProblem::hardness`]), `δz − (h0 + extra + uz)`, the
    /// depth by which the surface has flowed below its elastic position;
    /// zero elsewhere. Empty without a hardness.
    pub plastic: Vec<f64>,
    /// Convergence.
    pub report: NormalReport,
}

/// What the Polonsky–Keer iteration needs of an operator: `uz = K_zz * p`,
/// and the Fourier preconditioner of its grid.
trait ZzApply {
    /// The threads of the grid's transforms, which the vector passes share.
    fn threads(&self) -> Threads;
    fn apply_zz(&mut self, p: &[f64], uz: &mut [f64]);
    fn precondition(&mut self, g: &[f64], active: &[bool], z: &mut [f64]);
}

/// The fine grid: the operator and the cache's preconditioner.
struct Fine<'a> {
    op: &'a mut Operator,
    precond: &'a mut Option<FourierPrecond>,
    /// The scaled residual on a grid with cut cells (one per solve, not
    /// per iteration).
    scaled: Vec<f64>,
}

impl ZzApply for Fine<'_> {
    fn threads(&self) -> Threads {
        self.op.threads().clone()
    }
    fn apply_zz(&mut self, p: &[f64], uz: &mut [f64]) {
        self.op.normal(p, uz);
    }
    fn precondition(&mut self, g: &[f64], active: &[bool], z: &mut [f64]) {
        let (grid, threads) = (self.op.grid(), self.op.threads());
        let pre = self.precond.get_or_insert_with(|| {
            let mut pre = FourierPrecond::new(grid);
            pre.set_threads(threads);
            pre
        });
        if self.op.cover().is_none() {
            pre.apply(g, active, z);
            return;
        }
        // Cut cells: their own compliance is larger than the convolution's
        // by `factor`; a symmetric Jacobi scaling around the Fourier inverse
        // keeps them from slowing the iteration (quick sweep, circle-A at
        // 128² of 60 µm: 169 iterations without it).
        self.scaled.clear();
        self.scaled.extend_from_slice(g);
        self.op.scale_cut(&mut self.scaled);
        pre.apply(&self.scaled, active, z);
        self.op.scale_cut(z);
    }
}

impl ZzApply for CoarseLevel {
    fn threads(&self) -> Threads {
        CoarseLevel::threads(self).clone()
    }
    fn apply_zz(&mut self, p: &[f64], uz: &mut [f64]) {
        self.normal(p, uz);
    }
    fn precondition(&mut self, g: &[f64], active: &[bool], z: &mut [f64]) {
        self.precond_mut().apply(g, active, z);
    }
}

/// An operator with a compliant layer on top: `uz = K p + c p`, `c` per
/// cell in m/Pa. It is how a load history takes the wear of a cycle jump
/// implicitly (the depth `c p` worn at the pressure it leaves, see
/// `history.rs`): the layer only adds to the diagonal, so the iteration
/// and its preconditioner are those of `K`.
struct Layered<'a, Z> {
    inner: &'a mut Z,
    layer: &'a [f64],
}

impl<Z: ZzApply> ZzApply for Layered<'_, Z> {
    fn threads(&self) -> Threads {
        self.inner.threads()
    }
    fn apply_zz(&mut self, p: &[f64], uz: &mut [f64]) {
        self.inner.apply_zz(p, uz);
        add_layer(self.layer, p, uz);
    }
    fn precondition(&mut self, g: &[f64], active: &[bool], z: &mut [f64]) {
        self.inner.precondition(g, active, z);
    }
}

/// Adds the compression `c p` of a compliant layer `c` to `uz`.
fn add_layer(layer: &[f64], p: &[f64], uz: &mut [f64]) {
    for ((u, &pi), &c) in uz.iter_mut().zip(p).zip(layer) {
        *u += c * pi;
    }
}

/// What the normal solver keeps per operator between cases: the Galerkin
/// coarse `K_zz` levels of nested starts, the Fourier preconditioner of
/// the fine grid (made on first use) and the last contact solved from rest
/// ([`solve_normal_from_rest`]).
pub struct NormalCache {
    coarse: Vec<CoarseLevel>,
    precond: Option<FourierPrecond>,
    rest: Option<RestContact>,
    reused: usize,
}

/// A normal contact solved from rest and what it was solved for: the
/// problem (without warm start or extra gap) and the operator's cover.
struct RestContact {
    h0: Vec<f64>,
    cover: Option<Vec<f64>>,
    load_n: f64,
    tolerance: f64,
    max_iterations: usize,
    options: NormalOptions,
    hardness: Option<f64>,
    solution: NormalSolution,
}

impl RestContact {
    /// Whether `prob` on an operator with `cover` is the problem this
    /// contact solves, to the bit.
    fn solves(&self, prob: &NormalProblem, cover: Option<&[f64]>) -> bool {
        let same = |a: &[f64], b: &[f64]| {
            a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
        };
        self.load_n.to_bits() == prob.load_n.to_bits()
            && self.tolerance.to_bits() == prob.tolerance.to_bits()
            && self.max_iterations == prob.max_iterations
            && self.options == prob.options
            && self.hardness.map(f64::to_bits) == prob.hardness.map(f64::to_bits)
            && same(&self.h0, prob.h0)
            && match (&self.cover, cover) {
                (None, None) => true,
                (Some(a), Some(b)) => same(a, b),
                _ => false,
            }
    }
}

/// Largest grid whose contact from rest [`solve_normal_from_rest`] keeps:
/// an entry holds up to three fields (separation, cover, pressure), 25 MB
/// at 1024²; above, the memory of a big case goes to its solve.
pub const REST_CONTACT_MAX_CELLS: usize = 1024 * 1024;

impl NormalCache {
    /// The coarse levels below `op`'s grid, from its real `K_zz` table
    /// (held only while they are made).
    pub fn new(op: &mut Operator) -> Self {
        let table = op.table(Z, Z);
        let mut cache = NormalCache {
            coarse: coarse_levels(op.grid(), &table),
            precond: None,
            rest: None,
            reused: 0,
        };
        cache.set_threads(op.threads());
        cache
    }

    /// Runs the coarse levels' and the preconditioner's transforms on
    /// `threads` (results unchanged, see [`crate::Threads`]).
    pub fn set_threads(&mut self, threads: &Threads) {
        for level in &mut self.coarse {
            level.set_threads(threads);
        }
        if let Some(pre) = &mut self.precond {
            pre.set_threads(threads);
        }
    }

    /// How many contacts from rest [`solve_normal_from_rest`] returned
    /// without solving them again.
    pub fn reused(&self) -> usize {
        self.reused
    }

    /// Number of coarse levels (finest first).
    pub fn levels(&self) -> usize {
        self.coarse.len()
    }
}

/// Options of a normal solve (both on by default).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct NormalOptions {
    /// Start from the coarse levels when no warm start is given.
    pub nested: bool,
    /// Precondition the conjugate gradient with the `|k|` Fourier multiplier.
    pub precondition: bool,
}

impl Default for NormalOptions {
    fn default() -> Self {
        NormalOptions {
            nested: true,
            precondition: true,
        }
    }
}

/// Default start: a uniform pressure over the cells whose separation is within
/// the smallest 5 % of the range.
fn default_start(h: &[f64]) -> Vec<f64> {
    let hmin = h.iter().cloned().fold(f64::INFINITY, f64::min);
    let hmax = h.iter().cloned().fold(f64::NEG_INFINITY, f64::max);
    let cut = hmin + 0.05 * (hmax - hmin);
    h.iter()
        .map(|&v| if v <= cut { 1.0 } else { 0.0 })
        .collect()
}

/// One grid's normal problem as the iteration sees it.
#[derive(Clone, Copy)]
struct Level<'a> {
    /// Separation before loading (with any extra gap), m.
    h: &'a [f64],
    /// Cell area, m².
    da: f64,
    load_n: f64,
    tolerance: f64,
    max_iterations: usize,
    precondition: bool,
    /// The pressure cap per cell (the hardness times the cell's cover),
    /// Pa; `None`: elastic.
    cap: Option<&'a [f64]>,
}

/// One grid's normal solve: [`polonsky_keer`], or with caps the plastic
/// zone of [`plastic_zone`]. A start with no cell at its cap (a contact from
/// rest, a warm start that did not yield) is first solved elastically, and
/// the capped solve goes on from there only if that pressure exceeds a cap
/// somewhere: a hardness the contact never reaches changes nothing, to the
/// bit (the same Polonsky–Keer iterations as without it). The flag says
/// whether `u` is `K p` of the returned `p` exactly (a converged capped
/// CG's last application), so the caller need not apply `K` again.
fn solve_level(
    op: &mut impl ZzApply,
    level: &Level,
    p: &mut [f64],
    u: &mut [f64],
) -> Result<(NormalReport, bool), SolverError> {
    let Some(cap) = level.cap else {
        let budget = level.max_iterations;
        return Ok((polonsky_keer(op, level, None, budget, p, u)?, false));
    };
    if p.iter().zip(cap).any(|(&v, &c)| starts_capped(v, c)) {
        return plastic_zone(op, level, cap, p, u);
    }
    let elastic = polonsky_keer(op, level, None, level.max_iterations, p, u)?;
    if !p.iter().zip(cap).any(|(&v, &c)| v > c) {
        return Ok((elastic, false));
    }
    let (mut report, fresh) = plastic_zone(op, level, cap, p, u)?;
    report.iterations += elastic.iterations;
    report.applications += elastic.applications;
    Ok((report, fresh))
}

/// Iterations after which `u = K p` is recomputed even if it could be updated.
const REFRESH: usize = 32;

/// The cells a capped iteration holds at their caps: the caps per cell
/// and the plastic zone, which the iteration moves (cells stepped above
/// their cap join it, cells whose surface lifts off the indenter leave).
struct Capped<'a> {
    cap: &'a [f64],
    zone: &'a mut [bool],
}

/// The Polonsky–Keer iteration on one grid, bound-constrained when
/// `capped` (`0 ≤ p ≤ cap` under the load; elastic `p ≥ 0` without):
/// `p` (any non-negative start; an elastic one with nothing to scale
/// starts from [`default_start`]) is overwritten by the solution, `u`
/// receives `K_zz p`. At most `budget` iterations.
///
/// The direction is the preconditioned residual of the free cells (in
/// contact, not at a cap) less its mean there, so a step that changes no
/// set keeps the load to round-off: `p` and `u = K p` then both follow
/// the step, `u − τ K t`, one application an iteration. A step that
/// clips, admits an interpenetrating cell or caps one rescales the free
/// cells to the load (the zone's caps taken off it) and recomputes `u`
/// next iteration; an admission or a cap restarts the conjugacy. A zone
/// cell whose surface lifts off the indenter is released with its cap as
/// its pressure (the load unchanged, nothing recomputed). Converged when
/// the pressure changed by less than the tolerance in a step that capped
/// no cell.
///
/// Capped, on return `p` carries the caps on the zone and `u = K p`
/// exactly (one last application); not converged when the budget ran out
/// or the zone would carry the load, and [`plastic_zone`]'s iteration
/// then goes on from there (the safeguard against a cycling zone).
/// Elastic, `u` is the last iterate's (its caller applies `K` to the
/// returned `p` when it needs it exactly).
///
/// This one iteration replaced two near-copies (issue #62): the elastic
/// Polonsky–Keer step had rescaled every cell to the load after each step
/// of an unconstrained direction (`den = Σ (K t − mean) t`), the capped
/// CG of #50 moved no load. The capped one's first version kept the free
/// cells' and the zone's displacements apart (each step rescaled the free
/// cells, a join recomputed both): Table 1(c)'s circle-A at 0.5 GPa, 512²
/// of 30 µm, took 52 operator applications in 25 iterations from rest, 30
/// in 26 with one displacement.
fn polonsky_keer(
    op: &mut impl ZzApply,
    level: &Level,
    mut capped: Option<Capped>,
    budget: usize,
    p: &mut [f64],
    u: &mut [f64],
) -> Result<NormalReport, SolverError> {
    let Level {
        h,
        da,
        load_n,
        tolerance,
        precondition,
        ..
    } = *level;
    let len = h.len();
    let target = load_n / da;
    let threads = op.threads();
    let chunks = Chunks::flat(len);
    // Every sum below is over the fixed pieces of `chunks`, combined in
    // their order (see `crate::base::parallel`): the same bits on any threads.
    let sum = |parts: Vec<f64>| parts.into_iter().fold(0.0, |a, b| a + b);
    // Elastic: no cell is ever in the zone.
    let mut elastic_zone = Vec::new();
    let (cap, zone): (&[f64], &mut [bool]) = match &mut capped {
        Some(c) => (c.cap, &mut *c.zone),
        None => {
            elastic_zone.resize(len, false);
            (&[], &mut elastic_zone)
        }
    };
    let bounded = !cap.is_empty();
    let mut report = NormalReport::default();
    let mut g = vec![0.0; len];
    let mut t = vec![0.0; len];
    let mut r = vec![0.0; len];
    let mut z = if precondition {
        vec![0.0; len]
    } else {
        Vec::new()
    };
    let mut free = vec![false; len];
    let mut p_old = vec![0.0; len];
    let mut zone_old = if bounded {
        vec![false; len]
    } else {
        Vec::new()
    };
    // Sets the zone's cells to their caps and rescales the free cells to
    // carry what the zone does not; false (nothing rescaled) when the zone
    // alone carries the load or nothing is free.
    let rescale = |p: &mut [f64], zone: &[bool]| -> bool {
        let parts = threads.chunked(&chunks, chunks.with(p), |(part, p)| {
            let (mut carried, mut rest) = (0.0, 0.0);
            for i in part.range() {
                let pi = &mut p[i - part.start];
                if zone[i] {
                    *pi = cap[i];
                    carried += cap[i];
                } else {
                    rest += *pi;
                }
            }
            (carried, rest)
        });
        let (mut carried, mut rest) = (0.0, 0.0);
        for (c, r) in parts {
            carried += c;
            rest += r;
        }
        if carried >= target || rest <= 0.0 || !rest.is_finite() {
            return false;
        }
        let s = (target - carried) / rest;
        threads.chunked(&chunks, chunks.with(p), |(part, p)| {
            for i in part.range() {
                if !zone[i] {
                    p[i - part.start] *= s;
                }
            }
        });
        true
    };
    let start: f64 = p.iter().sum();
    if !(bounded || start > 0.0 && start.is_finite()) {
        // (no pressure to scale: the separation's lowest cells)
        p.copy_from_slice(&default_start(h));
    }
    if !rescale(p, zone) {
        return Ok(report);
    }
    let (mut valid, mut since_refresh, mut g_old, mut delta) = (false, 0, 1.0, 0.0);
    for it in 1..=budget {
        crate::base::progress::tick_or_cancel()?;
        report.iterations = it;
        if !valid || since_refresh >= REFRESH {
            op.apply_zz(p, u);
            report.applications += 1;
            (valid, since_refresh) = (true, 0);
        }
        since_refresh += 1;
        // (One pass: the memory, not the arithmetic, is what costs.)
        let items = chunks.with2(&mut g, &mut free);
        let parts = threads.chunked(&chunks, items, |(part, g, free)| {
            let (mut nc, mut sg, mut reach, mut top) = (0usize, 0.0, 0.0_f64, f64::NEG_INFINITY);
            for i in part.range() {
                let k = i - part.start;
                g[k] = u[i] + h[i];
                free[k] = !zone[i] && p[i] > 0.0;
                if free[k] {
                    nc += 1;
                    sg += g[k];
                } else if zone[i] {
                    top = top.max(g[k]);
                }
                if bounded {
                    reach = reach.max(u[i].abs());
                }
            }
            (nc, sg, reach, top)
        });
        let (mut nc, mut sg, mut reach, mut top) = (0usize, 0.0, 0.0_f64, f64::NEG_INFINITY);
        for (c, s, m, tp) in parts {
            nc += c;
            sg += s;
            reach = reach.max(m);
            top = top.max(tp);
        }
        if nc == 0 {
            break;
        }
        let gbar = sg / nc as f64;
        // Zone cells whose surface lifted off the indenter leave it, with
        // their cap as their pressure (the load is unchanged).
        let lift = gbar + ZONE_SLACK * reach;
        if top > lift {
            for i in 0..len {
                if zone[i] && g[i] > lift {
                    zone[i] = false;
                }
            }
            delta = 0.0;
            continue;
        }
        threads.chunked(&chunks, chunks.with(&mut g), |(_, g)| {
            g.iter_mut().for_each(|v| *v -= gbar);
        });
        if precondition {
            op.precondition(&g, &free, &mut z);
        }
        let zdir: &[f64] = if precondition { &z } else { &g };
        let gg = sum(threads.chunked(&chunks, chunks.items(), |part| {
            part.range()
                .filter(|&i| free[i])
                .map(|i| g[i] * zdir[i])
                .sum::<f64>()
        }));
        if gg == 0.0 {
            // The free cells' gaps are equal to the bit: the set is
            // solved. That happens when the kernel's mirror symmetry is exact
            // and the set is symmetric (one 2x2 island top from the default
            // start: Ni, circle-A, 32² of 200 µm stopped here unconverged
            // with 4 of its 24 contact cells). Admit the cells that
            // interpenetrate, if any, and go on; otherwise the set is final.
            if admit_overlap(&g, p, zone) && rescale(p, zone) {
                valid = false;
                delta = 0.0;
                continue;
            }
            report.converged = true;
            break;
        }
        if gg < 0.0 || !gg.is_finite() {
            break;
        }
        let beta = delta * (gg / g_old);
        let st = sum(threads.chunked(&chunks, chunks.with(&mut t), |(part, t)| {
            let mut st = 0.0;
            for i in part.range() {
                let ti = &mut t[i - part.start];
                *ti = if free[i] { zdir[i] + beta * *ti } else { 0.0 };
                st += *ti;
            }
            st
        }));
        // The direction moves no load: less its mean over the free cells
        // (g sums to zero there, so ⟨g, t⟩ keeps its value).
        let tbar = st / nc as f64;
        threads.chunked(&chunks, chunks.with(&mut t), |(part, t)| {
            for i in part.range() {
                if free[i] {
                    t[i - part.start] -= tbar;
                }
            }
        });
        g_old = gg;
        op.apply_zz(&t, &mut r);
        report.applications += 1;
        let parts = threads.chunked(&chunks, chunks.items(), |part| {
            let (mut num, mut den) = (0.0, 0.0);
            for i in part.range().filter(|&i| free[i]) {
                num += g[i] * t[i];
                den += r[i] * t[i];
            }
            (num, den)
        });
        let (mut num, mut den) = (0.0, 0.0);
        for (a, b) in parts {
            num += a;
            den += b;
        }
        if den <= 0.0 || !den.is_finite() {
            break;
        }
        let mut tau = num / den;
        p_old.copy_from_slice(p);
        if bounded {
            zone_old.copy_from_slice(zone);
        }
        // A step that would cap cells carrying the whole load is halved
        // (from a poor start the first steps overshoot).
        let mut stepped = None;
        for _ in 0..8 {
            let items = chunks.with2(&mut *p, &mut *zone);
            let parts = threads.chunked(&chunks, items, |(part, p, zone)| {
                let (mut overlap, mut clipped, mut joined) = (false, false, false);
                for i in part.range() {
                    let k = i - part.start;
                    if zone[k] {
                        continue;
                    }
                    // (A cell outside the zone is free when it has pressure.)
                    let (mut new, clip, admit) = step_cell(p_old[i], t[i], g[i], tau);
                    clipped |= clip;
                    overlap |= admit;
                    if bounded && new >= cap[i] {
                        new = cap[i];
                        zone[k] = true;
                        joined = true;
                    }
                    p[k] = new;
                }
                (overlap, clipped, joined)
            });
            let (mut overlap, mut clipped, mut joined) = (false, false, false);
            for (o, c, j) in parts {
                overlap |= o;
                clipped |= c;
                joined |= j;
            }
            let changed = overlap || clipped || joined;
            if !changed || rescale(p, zone) {
                stepped = Some((changed, overlap, joined));
                break;
            }
            p.copy_from_slice(&p_old);
            if !bounded {
                // (a load-free step that clips only adds load: nothing left free)
                return Err(SolverError::invalid(
                    "solver",
                    "normal solver lost all contact (pressure vanished); check the geometry",
                ));
            }
            zone.copy_from_slice(&zone_old);
            tau *= 0.5;
        }
        let Some((changed, admitted, joined)) = stepped else {
            break;
        };
        // Without a change of set, `u = K p` follows the step.
        valid = !changed;
        let change = sum(threads.chunked(&chunks, chunks.with(&mut *u), |(part, u)| {
            let mut change = 0.0;
            for i in part.range() {
                if valid {
                    u[i - part.start] -= tau * r[i];
                }
                change += (p[i] - p_old[i]).abs();
            }
            change
        }));
        delta = if admitted || joined { 0.0 } else { 1.0 };
        report.change = change * da / load_n;
        // (a cell admitted at the last step carries a pressure of the order
        // of the change; one that joined the zone moved the caps, which the
        // release test must see settle: requiring another step after an
        // admission too cost the fretting history of Table 1(a) at 128² 2 %
        // more normal and 10 % more tangential iterations)
        if report.change < tolerance && !joined {
            report.converged = true;
            break;
        }
    }
    if !bounded {
        return Ok(report);
    }
    for i in 0..len {
        if zone[i] {
            p[i] = cap[i];
        }
    }
    op.apply_zz(p, u);
    report.applications += 1;
    if report.converged {
        // Converged only if no zone cell stands above the indenter (the
        // release test of the next iteration).
        let (lift, nc) = lift_off(h, u, p, zone);
        report.converged = nc > 0 && (0..len).all(|i| !zone[i] || h[i] + u[i] <= lift);
    }
    Ok(report)
}

/// One cell's Polonsky–Keer step of length `tau` along `t`: a cell in
/// contact (`old > 0`) moves to `old − τt`, clipped at zero; a cell that
/// ends out of contact but interpenetrates (`g < 0`, the gap less the
/// contact's mean) is admitted at `−τg`. Returns the new pressure, whether
/// it was clipped and whether admitted (the elastic and the capped
/// iterations' step).
#[inline]
fn step_cell(old: f64, t: f64, g: f64, tau: f64) -> (f64, bool, bool) {
    let mut clipped = false;
    let mut new = if old > 0.0 {
        let v = old - tau * t;
        if v < 0.0 {
            clipped = true;
            0.0
        } else {
            v
        }
    } else {
        0.0
    };
    let admitted = new == 0.0 && g < 0.0;
    if admitted {
        new = -tau * g;
    }
    (new, clipped, admitted)
}

/// Largest number of plastic-zone updates of a capped solve (each an
/// elastic solve from the last); the zone of a sphere settles in a few.
const MAX_ZONE_UPDATES: usize = 100;

/// Relative slack of the zone's tests: a cell joins when its pressure
/// exceeds its cap by this fraction, and leaves when its gap exceeds the
/// approach by this fraction of the largest displacement.
const ZONE_SLACK: f64 = 1e-9;

/// Relative margin below its cap at which a cell of a warm start begins
/// in the plastic zone (an interpolated coarse solution carries the cap to
/// round-off).
const ZONE_START: f64 = 1e-6;

/// A start's cell of pressure `p` at its cap `cap` ([`ZONE_START`]): it
/// begins in the plastic zone, and a start with one is solved capped.
fn starts_capped(p: f64, cap: f64) -> bool {
    p >= cap * (1.0 - ZONE_START)
}

/// Tolerance of a capped solve's elastic solves while its plastic zone
/// moves.
const SETTLING_TOLERANCE: f64 = 1e-3;

/// The separation that keeps a cell of the plastic zone out of the elastic
/// contact around it, m (gaps are micrometres; a cell so far is never
/// admitted, and its square stays finite).
const OUT_OF_REACH: f64 = 1e30;

/// The normal contact with the pressure capped at `cap` per cell (an
/// elastic–perfectly plastic surface: `0 ≤ p ≤ cap`, a capped cell's
/// surface may lie below the indenter, by its plastic penetration). The
/// plastic zone is iterated around the elastic solver: with the capped
/// cells carrying their cap (their displacement added to the others'
/// separation, their load taken off the total) the rest is an elastic
/// contact, solved by [`polonsky_keer`] from the last pressure; then the
/// cells of that contact pushed above their cap join the zone and the
/// capped cells whose surface no longer reaches the indenter leave it,
/// until neither happens. A cell in the zone is kept out of the elastic
/// contact by the separation [`OUT_OF_REACH`]. On return `p` carries the
/// caps on the zone and `u = K p`, exactly (from one application) when the
/// flag is true, else summed from the zone's and the rest's.
fn plastic_zone(
    op: &mut impl ZzApply,
    level: &Level,
    cap: &[f64],
    p: &mut [f64],
    u: &mut [f64],
) -> Result<(NormalReport, bool), SolverError> {
    let Level { h, da, load_n, .. } = *level;
    let len = h.len();
    // The zone a warm start (or an interpolated coarse solution) had: the
    // coupling passes of a case and the increments of a path start next to
    // their zone (circle-B of the quick sweep: 7 updates in every pass
    // from an empty zone).
    let mut zone: Vec<bool> = (0..len).map(|i| starts_capped(p[i], cap[i])).collect();
    let mut report = NormalReport::default();
    let (mut p_zone, mut u_zone, mut h_in) = (vec![0.0; len], vec![0.0; len], vec![0.0; len]);
    // While the zone moves, its elastic solves stop early (at 1e-4 the
    // Table 1(c)'s circle-B at 512² of 30 µm took 125 normal iterations, at 1e-3
    // 109; solving a warm zone to the tolerance from its first update,
    // 199); once the zone holds, one solve to the tolerance decides.
    // First the cap inside the conjugate gradient ([`polonsky_keer`]): it
    // moves the zone at every step, where the iteration below moves it
    // by about a ring of cells per elastic solve (circle-B of Table 1(c)
    // at 0.9 GPa, 512² of 30 µm: 47 normal iterations against 109). When
    // it does not converge (its budget, a zone that would carry the
    // load) the zone iteration goes on from its state.
    let capped = Capped {
        cap,
        zone: &mut zone,
    };
    let budget = level.max_iterations.min(CAPPED_BUDGET);
    let rep = polonsky_keer(op, level, Some(capped), budget, p, u)?;
    report.iterations += rep.iterations;
    report.applications += rep.applications;
    if rep.converged {
        report.converged = true;
        report.change = rep.change;
        return Ok((report, true));
    }
    let mut settling = true;
    for _ in 0..MAX_ZONE_UPDATES {
        let mut carried: f64 = (0..len).filter(|&i| zone[i]).map(|i| cap[i]).sum();
        if carried * da >= load_n {
            // The zone alone would carry the load (after a join it cannot:
            // a cell joins when its pressure exceeds its cap; a start may):
            // release its cells whose surface stands highest until it does
            // not.
            let gap = |i: usize| h[i] + u[i];
            let mut order: Vec<usize> = (0..len).filter(|&i| zone[i]).collect();
            order.sort_by(|&a, &b| gap(b).total_cmp(&gap(a)));
            for i in order {
                if carried * da < load_n {
                    break;
                }
                zone[i] = false;
                p[i] = cap[i];
                carried -= cap[i];
            }
        }
        for i in 0..len {
            p_zone[i] = if zone[i] { cap[i] } else { 0.0 };
        }
        if zone.iter().any(|&z| z) {
            op.apply_zz(&p_zone, &mut u_zone);
            report.applications += 1;
        } else {
            u_zone.iter_mut().for_each(|v| *v = 0.0);
        }
        for i in 0..len {
            if zone[i] {
                h_in[i] = OUT_OF_REACH;
                p[i] = 0.0;
            } else {
                h_in[i] = h[i] + u_zone[i];
            }
        }
        let inner = Level {
            h: &h_in,
            load_n: load_n - carried * da,
            cap: None,
            tolerance: if settling {
                level.tolerance.max(SETTLING_TOLERANCE)
            } else {
                level.tolerance
            },
            ..*level
        };
        let rep = polonsky_keer(op, &inner, None, inner.max_iterations, p, u)?;
        report.iterations += rep.iterations;
        report.applications += rep.applications;
        report.change = rep.change;
        for i in 0..len {
            if zone[i] {
                p[i] = cap[i];
            }
            u[i] += u_zone[i];
        }
        if !rep.converged {
            break;
        }
        let (lift, _) = lift_off(h, u, p, &zone);
        let (mut joined, mut left) = (0usize, 0usize);
        for i in 0..len {
            if zone[i] && h[i] + u[i] > lift {
                // Lifted off its cap: back to the elastic contact.
                zone[i] = false;
                left += 1;
            } else if !zone[i] && p[i] > cap[i] * (1.0 + ZONE_SLACK) {
                zone[i] = true;
                joined += 1;
            }
        }
        if joined == 0 && left == 0 {
            if !settling || level.tolerance >= SETTLING_TOLERANCE {
                report.converged = true;
                break;
            }
            settling = false;
        }
    }
    Ok((report, false))
}

/// Budget of a capped [`polonsky_keer`]'s iterations before the zone
/// iteration takes over.
const CAPPED_BUDGET: usize = 150;

/// The height of the surface (`h + u`) above which a cell of the plastic
/// `zone` has lifted off its cap: the approach of the elastic part (the
/// mean gap of its contact cells) plus `ZONE_SLACK` of the largest
/// displacement; and the number of those contact cells. A cell on the
/// zone's edge after a reloading sits at its cap with its gap closed,
/// both to round-off: the slack keeps it from joining and leaving in turn
/// (a dented surface reloaded cycled for 100 updates without it).
fn lift_off(h: &[f64], u: &[f64], p: &[f64], zone: &[bool]) -> (f64, usize) {
    let (mut s, mut nc) = (0.0, 0usize);
    for i in 0..h.len() {
        if !zone[i] && p[i] > 0.0 {
            s += h[i] + u[i];
            nc += 1;
        }
    }
    let approach = s / nc.max(1) as f64;
    let reach = u.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
    (approach + ZONE_SLACK * reach, nc)
}

/// Gives the cells outside the contact set and the plastic `zone` that
/// interpenetrate (`g < 0`, with `g` the gap less the contact cells' mean)
/// a pressure proportional to their overlap, the largest equal to the mean
/// pressure of the free contact cells (the caller rescales to the load).
/// False when no cell interpenetrates.
fn admit_overlap(g: &[f64], p: &mut [f64], zone: &[bool]) -> bool {
    let outside = |i: usize, p: &[f64]| !zone[i] && p[i] <= 0.0;
    let deepest = (0..g.len())
        .filter(|&i| outside(i, p))
        .fold(0.0_f64, |m, i| m.min(g[i]));
    if deepest >= 0.0 {
        return false;
    }
    let (total, count) = (0..p.len())
        .filter(|&i| !zone[i] && p[i] > 0.0)
        .fold((0.0, 0usize), |(s, c), i| (s + p[i], c + 1));
    let mean = total / count.max(1) as f64;
    for i in 0..p.len() {
        if outside(i, p) && g[i] < 0.0 {
            p[i] = mean * g[i] / deepest;
        }
    }
    true
}

/// A normal contact problem on an operator's grid.
#[derive(Clone, Copy, Debug)]
pub struct NormalProblem<'a> {
    /// Initial separation between indenter and surface, m per cell.
    pub h0: &'a [f64],
    /// An extra gap term added to `h0` (e.g. `uz(q)` of the tangential
    /// tractions under coupling), m.
    pub extra_gap: Option<&'a [f64]>,
    /// Total normal load P, N.
    pub load_n: f64,
    /// Relative change of pressure between iterations at convergence.
    pub tolerance: f64,
    /// Iteration budget.
    pub max_iterations: usize,
    /// Warm start; without it, the problem is first solved on the coarse
    /// levels (coarsest first) and each solution, interpolated, starts the
    /// next finer iteration.
    pub p_init: Option<&'a [f64]>,
    /// Nested start and preconditioning.
    pub options: NormalOptions,
    /// The surface's hardness H, Pa: the pressure is capped at H on the
    /// covered part of every cell (an elastic–perfectly plastic surface);
    /// `None`: elastic, no cap.
    pub hardness: Option<f64>,
    /// A compliant layer per cell, m/Pa: the surface under a cell of
    /// pressure `p` lies `layer · p` lower (the returned `uz` includes it).
    /// A load history's implicit wear; `None`: no layer.
    pub layer: Option<&'a [f64]>,
}

impl<'a> NormalProblem<'a> {
    /// Separation `h0` under load `load_n`, with the default tolerance
    /// (1e-10), budget (5000), options and no warm start or extra gap.
    pub fn new(h0: &'a [f64], load_n: f64) -> Self {
        NormalProblem {
            h0,
            extra_gap: None,
            load_n,
            tolerance: 1e-10,
            max_iterations: 5000,
            p_init: None,
            options: NormalOptions::default(),
            hardness: None,
            layer: None,
        }
    }
}

/// Solves for the pressure of `prob` on `op`'s grid, with the coarse levels
/// and preconditioner of `cache` (made for `op`).
pub fn solve_normal(
    op: &mut Operator,
    cache: &mut NormalCache,
    prob: &NormalProblem,
) -> Result<NormalSolution, SolverError> {
    crate::base::progress::stage(crate::base::progress::Stage::Normal);
    let NormalProblem {
        h0,
        extra_gap,
        load_n,
        tolerance,
        max_iterations,
        p_init,
        options,
        hardness,
        layer,
    } = *prob;
    let grid = op.grid();
    let len = grid.len();
    let da = grid.cell_area();
    if !(load_n.is_finite() && load_n > 0.0) {
        return Err(SolverError::invalid(
            "load.normal_force_n",
            format!("the normal load must be positive and finite, got {load_n} N"),
        ));
    }
    if let Some(hv) = hardness {
        if !(hv.is_finite() && hv > 0.0) {
            return Err(SolverError::invalid(
                "hardness",
                format!("the hardness must be positive and finite, got {hv} Pa"),
            ));
        }
    }
    let caps: Option<Vec<f64>> = hardness.map(|hv| limit_per_cell(hv, op.cover(), len));
    let h: Vec<f64> = match extra_gap {
        Some(e) => h0.iter().zip(e).map(|(a, b)| a + b).collect(),
        None => h0.to_vec(),
    };
    let fine = Level {
        h: &h,
        da,
        load_n,
        tolerance,
        max_iterations,
        precondition: options.precondition,
        cap: caps.as_deref(),
    };
    let mut coarse_iterations = 0;
    let mut p = match p_init {
        Some(p0) if p0.iter().any(|&v| v > 0.0) => p0.to_vec(),
        _ => {
            let levels = &mut cache.coarse;
            if levels.is_empty() || !options.nested {
                default_start(&h)
            } else {
                // Separations restricted down the chain, finest first.
                // (The caps too: a coarse cell's pressure is the mean of
                // its four.)
                let mut hs = vec![restrict(&h, grid.n)];
                let mut cs = vec![caps.as_deref().map(|c| restrict(c, grid.n))];
                for l in 1..levels.len() {
                    let n_above = levels[l - 1].grid().n;
                    let next = restrict(&hs[l - 1], n_above);
                    hs.push(next);
                    let next = cs[l - 1].as_deref().map(|c| restrict(c, n_above));
                    cs.push(next);
                }
                let coarse_tol = tolerance.max(COARSE_TOLERANCE);
                let mut start: Option<Vec<f64>> = None;
                for ((level, hl), cl) in levels.iter_mut().zip(&hs).zip(&cs).rev() {
                    let g = level.grid();
                    let mut pl = match start.take() {
                        Some(v) => v,
                        None => default_start(hl),
                    };
                    let mut ul = vec![0.0; g.len()];
                    let coarse = Level {
                        h: hl,
                        da: g.cell_area(),
                        tolerance: coarse_tol,
                        cap: cl.as_deref(),
                        ..fine
                    };
                    let rep = solve_level(level, &coarse, &mut pl, &mut ul);
                    // Levels are used once per nested start: no work
                    // spectra are kept between starts.
                    level.release_work();
                    coarse_iterations += rep?.0.iterations;
                    let mut up = prolong(&pl, g.n);
                    up.iter_mut().for_each(|v| *v = v.max(0.0));
                    start = Some(up);
                }
                start.unwrap_or_else(|| default_start(&h))
            }
        }
    };
    let mut u = vec![0.0; len];
    let mut fine_op = Fine {
        op: &mut *op,
        precond: &mut cache.precond,
        scaled: Vec::new(),
    };
    let report = match layer {
        Some(layer) => {
            let mut layered = Layered {
                inner: &mut fine_op,
                layer,
            };
            solve_level(&mut layered, &fine, &mut p, &mut u)
        }
        None => solve_level(&mut fine_op, &fine, &mut p, &mut u),
    };
    // The preconditioner's work spectrum is not held between normal solves
    // (through the tangential solves, where a coupled case peaks).
    if let Some(pre) = &mut cache.precond {
        pre.release_work();
    }
    let (mut report, fresh) = report?;
    report.coarse_iterations = coarse_iterations;
    // Final state and residuals from the returned pressure (`u` is already
    // `K p` after a converged capped CG).
    if !fresh {
        op.normal(&p, &mut u);
        if let Some(layer) = layer {
            add_layer(layer, &p, &mut u);
        }
    }
    // The approach is the gap of the cells in elastic contact (below their
    // caps); with every contact cell capped, the largest capped gap.
    let at_cap = |i: usize| caps.as_ref().is_some_and(|c| p[i] >= c[i]);
    let (mut s, mut nc, mut top) = (0.0, 0usize, f64::NEG_INFINITY);
    for i in 0..len {
        if at_cap(i) {
            top = top.max(u[i] + h[i]);
        } else if p[i] > 0.0 {
            s += u[i] + h[i];
            nc += 1;
        }
    }
    if nc == 0 && !top.is_finite() {
        return Err(SolverError::invalid(
            "solver",
            "normal solver lost all contact (pressure vanished); check the geometry",
        ));
    }
    let approach = if nc > 0 { s / nc as f64 } else { top };
    let scale = approach.abs().max(f64::MIN_POSITIVE);
    let (mut gap_res, mut pen) = (0.0_f64, 0.0_f64);
    let mut plastic = Vec::new();
    if caps.is_some() {
        plastic = vec![0.0; len];
    }
    for i in 0..len {
        let gap = u[i] + h[i] - approach;
        if at_cap(i) {
            // A capped cell's surface reaches below the indenter (plastic
            // penetration); one above it should have been released.
            gap_res = gap_res.max(gap.max(0.0) / scale);
            plastic[i] = (-gap).max(0.0);
        } else if p[i] > 0.0 {
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
        plastic,
        report,
    })
}

/// [`solve_normal`] of a problem without warm start or extra gap (the
/// frictionless contact a case starts from), or the solution kept from the
/// last such solve on this operator when it was of the same problem to the
/// bit (separation, load, tolerance, budget, options, hardness and the operator's
/// cover): the solve is deterministic, so the result is the same bits. A
/// sweep's force directions share their contact from rest: the quick sweep
/// solved 8 such problems 56 times, about 20 of each case's 45 normal
/// iterations (docs/performance-history.md, #34 last pass). Grids above [`REST_CONTACT_MAX_CELLS`]
/// keep nothing. The solution comes without its displacement (`uz` empty,
/// kept or not): the cases that start from it do not read it.
pub fn solve_normal_from_rest(
    op: &mut Operator,
    cache: &mut NormalCache,
    prob: &NormalProblem,
) -> Result<NormalSolution, SolverError> {
    if prob.p_init.is_some() || prob.extra_gap.is_some() || prob.layer.is_some() {
        // Not a contact from rest: solved, nothing kept.
        return solve_normal(op, cache, prob);
    }
    if let Some(rest) = &cache.rest {
        if rest.solves(prob, op.cover()) {
            cache.reused += 1;
            return Ok(rest.solution.clone());
        }
    }
    cache.rest = None;
    let mut solution = solve_normal(op, cache, prob)?;
    solution.uz = Vec::new();
    if prob.h0.len() <= REST_CONTACT_MAX_CELLS {
        cache.rest = Some(RestContact {
            h0: prob.h0.to_vec(),
            cover: op.cover().map(<[f64]>::to_vec),
            load_n: prob.load_n,
            tolerance: prob.tolerance,
            max_iterations: prob.max_iterations,
            options: prob.options,
            hardness: prob.hardness,
            solution: solution.clone(),
        });
    }
    Ok(solution)
}

/// Tolerance of the coarse-level solves (they only provide a start).
const COARSE_TOLERANCE: f64 = 1e-6;

#[cfg(test)]
mod tests;
