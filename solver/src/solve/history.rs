//! Load histories (fretting): a case's load path solved increment by
//! increment, each from the previous increment's tractions and displacement
//! (Coulomb friction in increments, PHYSICS.md §5b), and what a fretting study
//! reads from it: the path's table, the energy dissipated per cycle, the
//! stiffness after a reversal and the residual shift. Knows the solvers only
//! through `coupling::solve_step`; writes no files.

use serde::{Deserialize, Serialize};

use crate::base::geometry::covered_area;
use crate::error::SolverError;
use crate::model::material::area_at_cap;
use crate::model::radii::{friction_reserve, zone_radius};
use crate::model::spec::{CaseSpec, LoadHistory};
use crate::model::surface::Terrain;
use crate::operators::operator::{X, Y, Z};
use crate::solve::coupling::{solve_step, ContactState, Previous, Step, Target};
use crate::solve::normal::{NormalProblem, NormalSolution};
use crate::solve::resident::Resident;
use crate::solve::tangential::TangentialSolution;
use crate::solve::wear::{CycleRows, Wearing};
pub use crate::solve::wear::{WearCycle, SCAR_DEFINITION, WEAR_JUMP_LIMIT};

/// How the dissipated energy is computed.
pub const DISSIPATION_DEFINITION: &str = "energy dissipated by slip, sum over increments and cells of (q_prev + q)/2 . (delta_t increment - u increment) dA, q the shear tractions and u the total tangential surface displacement (trapezoidal rule for the integral of q . ds, ds the slip increment of the substrate relative to the sphere); per cycle: over the last two segments that return to the same turning point";

/// One row of a load history: the state at the end of an increment.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HistoryStep {
    /// Increment number; 0 is the state after frictionless normal loading.
    pub step: usize,
    /// Segment of the path the increment belongs to (0 for step 0).
    pub segment: usize,
    /// Normal load recovered from the pressure, N.
    pub normal_force_n: f64,
    /// Tangential force recovered from the tractions, x and y, N.
    pub force_n: [f64; 2],
    /// Rigid tangential shift δt of the sphere from the start of the path, x and y, m.
    pub delta_t_m: [f64; 2],
    /// Rigid-body approach δz, m.
    pub delta_z_m: f64,
    /// Contact area (cells with p > 0), m².
    pub contact_area_m2: f64,
    /// Stick area (contact cells with |q| < μp), m².
    pub stick_area_m2: f64,
    /// The stick zone's own radius, its outline ([`crate::ZONE_RADIUS_DEFINITION`]), m.
    pub stick_radius_m: f64,
    /// Energy dissipated in this increment ([`DISSIPATION_DEFINITION`]), J.
    pub dissipated_j: f64,
    /// Worn volume from the start of the path to this increment, m³ (0
    /// without a wear law).
    #[serde(default)]
    pub worn_volume_m3: f64,
    /// With a hardness: the area of the cells whose pressure is at the cap
    /// (their covered part on cut cells), m² (`None`: elastic).
    #[serde(default)]
    pub plastic_area_m2: Option<f64>,
    /// With a hardness: the largest plastic penetration of the dent from
    /// the start of the path to this increment (it is permanent), m.
    #[serde(default)]
    pub plastic_penetration_max_m: Option<f64>,
    /// The increment's solves converged.
    pub converged: bool,
}

/// A solved load history and the quantities a fretting study reads from it.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct HistoryOutput {
    /// Unit vector of the case's force direction (positive tangential ratios).
    pub direction: [f64; 2],
    /// The state after every increment, step 0 first.
    pub steps: Vec<HistoryStep>,
    /// Step index of every turning point (the path's start first).
    pub turning_steps: Vec<usize>,
    /// Energy dissipated over the last full cycle (two segments that return
    /// to the same turning point), J; `None` if the path has no cycle.
    pub dissipated_energy_per_cycle_j: Option<f64>,
    /// Area of the same cycle's loop, ∮ F · dδt (trapezoidal rule), J: the
    /// independent check of `dissipated_energy_per_cycle_j`.
    pub loop_area_per_cycle_j: Option<f64>,
    /// Secant tangential stiffness of the first increment after the last
    /// reversal of the tangential force, along the force direction, N/m.
    pub reversal_stiffness_n_per_m: Option<f64>,
    /// δt along the force direction where F crosses zero on the last
    /// unloading from a positive force (linear between increments), m.
    pub residual_delta_t_m: Option<f64>,
    /// Largest |ΔA Σq − F| over the increments, relative to μP.
    pub force_error_max: f64,
    /// Dissipated energy summed over the whole path, J.
    pub dissipated_total_j: f64,
    /// The last full cycle's force amplitude F*: the largest |F| along the
    /// force direction over it, N.
    #[serde(default)]
    pub force_amplitude_n: Option<f64>,
    /// The last full cycle's shift amplitude δ*: the largest |δt| along the
    /// force direction over it, m.
    #[serde(default)]
    pub shift_amplitude_m: Option<f64>,
    /// The energy ratio A = W / (4 F* δ*) of the last full cycle (Fouvry's
    /// criterion: 0.2 at the transition to gross slip for a sphere).
    #[serde(default)]
    pub energy_ratio: Option<f64>,
    /// The slip regime over the path's full cycles ([`SLIP_REGIME_DEFINITION`]):
    /// `partial`, `gross`, or `mixed` when it changes between cycles.
    #[serde(default)]
    pub regime: Option<String>,
    /// With a wear law: the volume worn over the whole path, m³.
    #[serde(default)]
    pub worn_volume_m3: Option<f64>,
    /// With a wear law: the volume worn over the last full cycle, per
    /// physical cycle (with a cycle jump M, the simulated cycle's over
    /// M), m³.
    #[serde(default)]
    pub worn_volume_per_cycle_m3: Option<f64>,
    /// With a wear law: the largest worn depth, m.
    #[serde(default)]
    pub worn_depth_max_m: Option<f64>,
    /// With a wear law: every simulated full cycle's wear and loop, the
    /// first first (empty without a wear law or a full cycle).
    #[serde(default)]
    pub wear_cycles: Vec<WearCycle>,
    /// With a wear law and a full cycle: the largest depth a simulated
    /// cycle wore (with its jump), relative to the approach of the path's
    /// start. Above [`WEAR_JUMP_LIMIT`] the jump is too coarse for the
    /// profile's transient.
    #[serde(default)]
    pub wear_jump_ratio: Option<f64>,
    /// With a wear law for the ball: its worn volume over the whole path, m³.
    #[serde(default)]
    pub ball_worn_volume_m3: Option<f64>,
}

/// How [`HistoryOutput::regime`] is decided.
pub const SLIP_REGIME_DEFINITION: &str = "a full cycle is in gross slip when at some increment of it no contact cell sticks (every traction on its friction disc: the whole contact slides), in partial slip otherwise; the path is `partial` or `gross` when all its full cycles are, `mixed` when they differ";

/// The tractions of the state at a turning point of the path (what the
/// stresses below the surface of a load history are computed from).
#[derive(Clone, Debug, PartialEq)]
pub struct TurningState {
    /// The increment (a row of [`HistoryOutput::steps`]).
    pub step: usize,
    /// Pressure, Pa (row major, as [`crate::Fields`]).
    pub p: Vec<f64>,
    /// Shear traction x, Pa.
    pub qx: Vec<f64>,
    /// Shear traction y, Pa.
    pub qy: Vec<f64>,
}

impl TurningState {
    fn of(step: usize, state: &ContactState) -> Self {
        TurningState {
            step,
            p: state.p.clone(),
            qx: state.tangential.qx.clone(),
            qy: state.tangential.qy.clone(),
        }
    }
}

/// Sums of the solves over all increments.
pub(crate) struct HistoryState {
    /// The state after the last increment (iteration counts summed over all).
    pub last: ContactState,
    /// Every increment converged.
    pub converged: bool,
    /// The path's table and its reductions.
    pub output: HistoryOutput,
    /// The states at the turning points, the start first.
    pub turning: Vec<TurningState>,
    /// The worn depth per cell over the path, m (empty without wear).
    pub worn: Vec<f64>,
    /// The ball's worn depth in its own frame, m (empty unless it wears).
    pub ball_worn: Vec<f64>,
    /// The substrate's worn depth at the saved cycles (their numbers), m.
    pub worn_saved: Vec<(usize, Vec<f64>)>,
}

/// With coupling, the normal surface displacement `uz(q)` of the tractions
/// of `tangential` (a normal solve's extra gap); empty without.
fn traction_gap(res: &mut Resident, coupling: bool, tangential: &TangentialSolution) -> Vec<f64> {
    let mut hq = Vec::new();
    if coupling {
        hq = vec![0.0; tangential.qx.len()];
        res.operator.apply(
            &[(X, &tangential.qx), (Y, &tangential.qy)],
            &mut [(Z, &mut hq)],
        );
    }
    hq
}

/// Total tangential surface displacement `ut(q) + [ut(p) − ut(p⁰)]` (the
/// bracket only with coupling).
fn displacement(
    res: &mut Resident,
    coupling: bool,
    (qx, qy): (&[f64], &[f64]),
    p: &[f64],
    p0: &[f64],
) -> (Vec<f64>, Vec<f64>) {
    let len = qx.len();
    let (mut ux, mut uy) = (vec![0.0; len], vec![0.0; len]);
    if coupling {
        let dp: Vec<f64> = p.iter().zip(p0).map(|(a, b)| a - b).collect();
        res.operator.apply(
            &[(X, qx), (Y, qy), (Z, &dp)],
            &mut [(X, &mut ux), (Y, &mut uy)],
        );
    } else {
        res.operator
            .apply(&[(X, qx), (Y, qy)], &mut [(X, &mut ux), (Y, &mut uy)]);
    }
    (ux, uy)
}

/// Solves the load path `history` of `spec` from the frictionless normal
/// solution `normal0` (under the first turning point's normal load) of the
/// separation `h0`. `check` is applied to every increment's pressure (the
/// contact must stay inside the domain).
pub(crate) fn solve_history(
    res: &mut Resident,
    spec: &CaseSpec,
    history: &LoadHistory,
    (h0, terrain): (&[f64], &Terrain),
    normal0: NormalSolution,
    check: impl Fn(&[f64]) -> Result<(), SolverError>,
) -> Result<HistoryState, SolverError> {
    let grid = spec.grid;
    let (len, da) = (grid.len(), grid.cell_area());
    let num = spec.numerics_in_effect();
    let mu = spec.load.friction;
    let angle = spec.load.angle_deg.to_radians();
    let dir = [angle.cos(), angle.sin()];
    let points = history.turning_points(&spec.load);
    let displacement_control = history.displacement_controlled();
    let steps = history.steps_per_segment;

    // State after frictionless normal loading.
    let p0 = normal0.p.clone();
    // On a surface with a hardness, the plastic penetration is permanent:
    // every increment's adds to the dent, and the separation the next
    // increment sees is the initial one plus the dent (unloading leaves it).
    // Worn depth likewise, with a wear law (the surface recedes).
    let mut dent = normal0.plastic.clone();
    let mut wearing = history.wear.map(|w| Wearing::new(w, grid));
    let cycle_ends = full_cycles(&points);
    let cycles_total = cycle_ends.len();
    // The separation h0 + dent + worn, rewritten in place after each
    // increment (`None`: h0 itself, no dent and no wear).
    let at = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(0.0);
    let mut dented: Option<Vec<f64>> = (!dent.is_empty() || wearing.is_some())
        .then(|| (0..len).map(|i| h0[i] + at(&dent, i)).collect());
    // With a wear law: the normal contact on the surface the last
    // increment wore, which the next starts from.
    // (And its tractions' normal displacement.)
    let mut worn_normal: Option<(NormalSolution, Vec<f64>)> = None;
    let mut last = ContactState {
        p: normal0.p,
        approach: normal0.approach,
        plastic: normal0.plastic,
        tangential: TangentialSolution {
            qx: vec![0.0; len],
            qy: vec![0.0; len],
            sx: vec![0.0; len],
            sy: vec![0.0; len],
            stick: vec![false; len],
            shift: [0.0; 2],
            report: Default::default(),
        },
        normal_report: normal0.report,
        normal_iterations: normal0.report.iterations,
        tangential_iterations: 0,
        coupling_iterations: 0,
        coupling_change: 0.0,
        coupling_converged: true,
    };
    let mut converged = normal0.report.converged;
    let (mut ux, mut uy) = (vec![0.0; len], vec![0.0; len]);
    let mut delta_t = [0.0_f64; 2];
    // Largest |δt| so far and the last increment's |Δδt| (tolerance scale).
    let (mut delta_t_max, mut last_increment) = (0.0_f64, 0.0_f64);
    let mut normal_iterations = last.normal_iterations;
    let (mut tangential_iterations, mut coupling_iterations) = (0, 0);
    let mut rows = vec![row(
        spec,
        terrain,
        &last,
        &StepSums {
            step: 0,
            segment: 0,
            delta_t,
            dissipated: 0.0,
            converged,
        },
    )];
    rows[0].stick_area_m2 = rows[0].contact_area_m2;
    // With a hardness, the dent's deepest cell (the dent only grows).
    let deepest = |dent: &[f64]| {
        spec.limits()
            .hardness
            .map(|_| dent.iter().cloned().fold(0.0, f64::max))
    };
    rows[0].plastic_penetration_max_m = deepest(&dent);
    let mut force_error_max: f64 = 0.0;
    let mut turning_steps = vec![0];
    let mut turning = vec![TurningState::of(0, &last)];
    let (mut p_prev, mut f_prev) = points[0];

    for (segment, pair) in points.windows(2).enumerate() {
        let ((pa, fa), (pb, fb)) = (pair[0], pair[1]);
        for m in 1..=steps {
            crate::base::progress::increment(segment * steps + m, (points.len() - 1) * steps)?;
            let t = m as f64 / steps as f64;
            let (p_k, f_k) = if m == steps {
                (pb, fb)
            } else {
                (pa + t * (pb - pa), fa + t * (fb - fa))
            };
            let step_no = rows.len();
            if p_k == p_prev && f_k == f_prev {
                // A hold: nothing changes.
                let mut r = rows[step_no - 1].clone();
                r.step = step_no;
                r.segment = segment + 1;
                r.dissipated_j = 0.0;
                rows.push(r);
                continue;
            }
            let h_now = dented.as_deref().unwrap_or(h0);
            // The normal solve at the new load, from the last pressure (with
            // coupling, under the last tractions' normal displacement).
            // With a wear law, the pressure on the surface the last
            // increment wore (the last state is the one its tractions were
            // solved with); else the last pressure.
            let on_worn = worn_normal.take();
            let normal = if p_k == p_prev {
                let (p, approach) = match on_worn {
                    Some((n, _)) => (n.p, n.approach),
                    None => (last.p.clone(), last.approach),
                };
                NormalSolution {
                    p,
                    uz: Vec::new(),
                    approach,
                    // Nothing new flows at an unchanged load.
                    plastic: Vec::new(),
                    report: crate::solve::normal::NormalReport {
                        iterations: 0,
                        ..last.normal_report
                    },
                }
            } else {
                // (The wear's normal solve made it for the same tractions.)
                let hq = match on_worn {
                    Some((_, hq)) => hq,
                    None => traction_gap(res, num.coupling, &last.tangential),
                };
                res.solve_normal(&NormalProblem {
                    extra_gap: num.coupling.then_some(&hq[..]),
                    tolerance: num.tolerance,
                    max_iterations: num.max_iterations,
                    p_init: Some(&last.p),
                    hardness: spec.limits().hardness,
                    ..NormalProblem::new(h_now, p_k)
                })?
            };
            // Force control: the force at the increment's end; displacement
            // control: the shift still to impose to reach the target, the
            // force a result.
            let goal = [f_k * dir[0], f_k * dir[1]];
            let target = if displacement_control {
                Target::Shift([goal[0] - delta_t[0], goal[1] - delta_t[1]])
            } else {
                Target::Force(goal)
            };
            // The KKT tolerance relative to the loop's δt (see Step::tolerance_scale),
            // with the last increment's |Δδt| as the estimate of this one's.
            let tolerance_scale = if last_increment > 0.0 {
                (delta_t_max / last_increment).max(1.0)
            } else {
                1.0
            };
            // The previous tractions; the projection shifts them onto the
            // new force. (Adding the force increment spread like the
            // pressure cost 7–9 % more iterations on Table 1a at 128².)
            let start = (&last.tangential.qx[..], &last.tangential.qy[..]);
            let state = solve_step(
                res,
                spec,
                h_now,
                normal,
                &Step {
                    normal_force_n: p_k,
                    target,
                    previous: Some(Previous {
                        start,
                        u: (&ux, &uy),
                        p0: &p0,
                    }),
                    tolerance_scale,
                },
            )?;
            check(&state.p)?;
            let (vx, vy) = displacement(
                res,
                num.coupling,
                (&state.tangential.qx, &state.tangential.qy),
                &state.p,
                &p0,
            );
            let shift = state.tangential.shift;
            // Dissipation: ∫ q · ds over the increment by the trapezoidal
            // rule, ds = dδt − du the slip increment of the sphere relative
            // to the substrate, negated (q opposes the substrate's slip).
            let (qx0, qy0) = (&last.tangential.qx, &last.tangential.qy);
            let (qx1, qy1) = (&state.tangential.qx, &state.tangential.qy);
            // With a wear law, each cell wears by the same slip increment
            // and means (PHYSICS.md §5d).
            let mut work = 0.0;
            for i in 0..len {
                let (mx, my) = (0.5 * (qx0[i] + qx1[i]), 0.5 * (qy0[i] + qy1[i]));
                let ds = [shift[0] - (vx[i] - ux[i]), shift[1] - (vy[i] - uy[i])];
                if mx != 0.0 || my != 0.0 {
                    work += mx * ds[0] + my * ds[1];
                }
                if let Some(w) = &mut wearing {
                    w.wear_cell(i, 0.5 * (last.p[i] + state.p[i]), [mx, my], ds);
                }
            }
            // With a wear law, the cells' slips δt − u halfway through the
            // increment and at its end (where the substrate's worn points
            // are).
            let slips = wearing.as_ref().map(|_| {
                let mid = |d: f64, s: f64, u0: &[f64], u1: &[f64]| -> Vec<f64> {
                    (0..len)
                        .map(|i| d + 0.5 * s - 0.5 * (u0[i] + u1[i]))
                        .collect()
                };
                let end = |d: f64, u1: &[f64]| -> Vec<f64> { u1.iter().map(|u| d - u).collect() };
                (
                    (
                        mid(delta_t[0], shift[0], &ux, &vx),
                        mid(delta_t[1], shift[1], &uy, &vy),
                    ),
                    (
                        end(delta_t[0] + shift[0], &vx),
                        end(delta_t[1] + shift[1], &vy),
                    ),
                )
            });
            delta_t = [delta_t[0] + shift[0], delta_t[1] + shift[1]];
            last_increment = shift[0].hypot(shift[1]);
            delta_t_max = delta_t_max.max(delta_t[0].hypot(delta_t[1]));
            let mut step_converged = state.normal_report.converged
                && state.tangential.report.converged
                && state.coupling_converged;
            normal_iterations += state.normal_iterations;
            tangential_iterations += state.tangential_iterations;
            coupling_iterations += state.coupling_iterations;
            (ux, uy) = (vx, vy);
            // Whether the separation must be rewritten below: the dent
            // grew, or (with a wear law, whose substrate moves with the
            // slips) always.
            let mut moved = !state.plastic.is_empty();
            if moved {
                dent.iter_mut()
                    .zip(&state.plastic)
                    .for_each(|(d, w)| *d += w);
            }
            // The separation of what follows: h0 + dent + the worn depths
            // (the substrate's at the points the slips brought under the
            // cells).
            let rewrite =
                |dented: &mut Option<Vec<f64>>, dent: &[f64], wearing: &Option<Wearing>| {
                    if let Some(h) = dented {
                        for (i, v) in h.iter_mut().enumerate() {
                            *v = h0[i] + at(dent, i);
                        }
                        if let (Some(w), Some((_, (sx, sy)))) = (wearing, &slips) {
                            w.add_gap((sx, sy), h);
                        }
                    }
                };
            if let (Some(w), Some(((mx, my), _))) = (&mut wearing, &slips) {
                // The increment's wear, and the pressure on the worn surface
                // (the next increment starts from it; at a constant load no
                // other solve would see the wear without coupling).
                // Without a jump the depth is explicit, the trapezoidal
                // means' (the worn volume is α times the energy to
                // round-off). With a jump of M cycles it is taken at the
                // pressure it leaves, `M (dh/p̄) p`: a compliant layer in
                // the normal solve, stable for any M (applied explicitly,
                // M dh oscillates from cell to cell once cells are finer
                // than ~0.03a, PHYSICS.md §5d).
                w.prepare(&last.p, &state.p, (mx, my));
            }
            if wearing.is_some() {
                rewrite(&mut dented, &dent, &wearing);
                moved = false;
            }
            if let (Some(w), Some(((mx, my), _))) = (&mut wearing, &slips) {
                let hq = traction_gap(res, num.coupling, &state.tangential);
                let solved = res.solve_normal(&NormalProblem {
                    extra_gap: num.coupling.then_some(&hq[..]),
                    tolerance: num.tolerance,
                    max_iterations: num.max_iterations,
                    p_init: Some(&state.p),
                    hardness: spec.limits().hardness,
                    layer: w.layer(),
                    ..NormalProblem::new(dented.as_deref().unwrap_or(h0), p_k)
                })?;
                check(&solved.p)?;
                w.commit(&solved.p, (mx, my));
                moved = w.implicit() || !solved.plastic.is_empty();
                if !solved.plastic.is_empty() {
                    dent.iter_mut()
                        .zip(&solved.plastic)
                        .for_each(|(d, w)| *d += w);
                }
                normal_iterations += solved.report.iterations;
                step_converged &= solved.report.converged;
                worn_normal = Some((solved, hq));
            }
            if moved {
                rewrite(&mut dented, &dent, &wearing);
            }
            converged &= step_converged;
            // The row: the state the increment solved (with a wear law,
            // before its own wear, which the next increment starts from).
            let mut r = row(
                spec,
                terrain,
                &state,
                &StepSums {
                    step: step_no,
                    segment: segment + 1,
                    delta_t,
                    dissipated: work * da,
                    converged: step_converged,
                },
            );
            if !displacement_control {
                let ferr = (r.force_n[0] - goal[0]).hypot(r.force_n[1] - goal[1]) / (mu * p_k);
                force_error_max = force_error_max.max(ferr);
            }
            r.worn_volume_m3 = wearing.as_ref().map_or(0.0, |w| w.volume);
            r.plastic_penetration_max_m = deepest(&dent);
            rows.push(r);
            last = state;
            (p_prev, f_prev) = (p_k, f_k);
        }
        turning_steps.push(rows.len() - 1);
        turning.push(TurningState::of(rows.len() - 1, &last));
        let t = segment + 1;
        if let (Some(w), true) = (&mut wearing, cycle_ends.contains(&t)) {
            let number = w.cycles.len() + 1;
            let every = w.settings().save_every;
            let save = number == cycles_total || (every > 0 && number % every == 0);
            let looped = cycle_rows(&rows, (turning_steps[t - 2], turning_steps[t]), dir);
            w.record(terrain, &last.p, &looped, save);
        }
    }
    // The final state's shift is δt from the start of the path, not the
    // last increment's.
    last.tangential.shift = delta_t;
    // The final state's plastic penetration is the whole path's dent.
    last.plastic = dent;
    last.normal_iterations = normal_iterations;
    last.tangential_iterations = tangential_iterations;
    last.coupling_iterations = coupling_iterations;
    let wear = wearing.as_ref().map(|w| (&w.worn[..], w.settings().jump));
    let mut output = reduce_history(dir, rows, &points, turning_steps, force_error_max, wear);
    if let Some(w) = wearing.as_mut() {
        let approach0 = output.steps[0].delta_z_m;
        output.wear_jump_ratio = w
            .cycles
            .iter()
            .map(|c| c.depth_increment_max_m / approach0.abs().max(f64::MIN_POSITIVE))
            .reduce(f64::max);
        output.ball_worn_volume_m3 = w.settings().ball.map(|_| w.ball_volume);
        output.wear_cycles = std::mem::take(&mut w.cycles);
    }
    let (worn, ball_worn, worn_saved) = match wearing {
        Some(w) => (w.worn, w.ball, w.saved),
        None => (Vec::new(), Vec::new(), Vec::new()),
    };
    Ok(HistoryState {
        last,
        converged,
        output,
        turning,
        worn,
        ball_worn,
        worn_saved,
    })
}

/// Whether turning points `a` and `b` are the same (to 1e-12 of their size).
fn same_point(a: (f64, f64), b: (f64, f64)) -> bool {
    let scale = a.0.abs().max(b.0.abs());
    (a.0 - b.0).abs() <= 1e-12 * scale && (a.1 - b.1).abs() <= 1e-12 * scale
}

/// Whether reaching turning point `t` closes a full cycle: the two
/// segments before it return to the point they left.
fn closes_cycle(points: &[(f64, f64)], t: usize) -> bool {
    t >= 2
        && t < points.len()
        && same_point(points[t], points[t - 2])
        && !same_point(points[t], points[t - 1])
}

/// The turning points that close the path's full cycles, one after
/// another: 0 → +A → −A → +A → −A → +A closes two, at the second and the
/// third +A (the −A → +A → −A between them is not a third).
fn full_cycles(points: &[(f64, f64)]) -> Vec<usize> {
    let mut ends: Vec<usize> = Vec::new();
    for t in 0..points.len() {
        if closes_cycle(points, t) && ends.last().is_none_or(|&e| t >= e + 2) {
            ends.push(t);
        }
    }
    ends
}

/// What the rows of a full cycle (turning steps `s0` to `s1`) say.
fn cycle_rows(steps: &[HistoryStep], (s0, s1): (usize, usize), dir: [f64; 2]) -> CycleRows {
    let along = |v: [f64; 2]| v[0] * dir[0] + v[1] * dir[1];
    let rows = &steps[s0..=s1];
    CycleRows {
        dissipated: rows[1..].iter().map(|r| r.dissipated_j).sum(),
        force_amplitude: rows
            .iter()
            .map(|r| along(r.force_n).abs())
            .fold(0.0, f64::max),
        shift_amplitude: rows
            .iter()
            .map(|r| along(r.delta_t_m).abs())
            .fold(0.0, f64::max),
        gross: rows[1..]
            .iter()
            .any(|r| r.stick_area_m2 == 0.0 && r.contact_area_m2 > 0.0),
        stick_radius_min: rows[1..]
            .iter()
            .map(|r| r.stick_radius_m)
            .fold(f64::INFINITY, f64::min),
        worn_volume: (steps[s0].worn_volume_m3, steps[s1].worn_volume_m3),
    }
}

/// What a row needs besides the contact state.
struct StepSums {
    step: usize,
    segment: usize,
    delta_t: [f64; 2],
    dissipated: f64,
    converged: bool,
}

/// The table row of a solved increment on the surface's `terrain`.
fn row(spec: &CaseSpec, terrain: &Terrain, state: &ContactState, sums: &StepSums) -> HistoryStep {
    let grid = spec.grid;
    let (len, da) = (grid.len(), grid.cell_area());
    let p = &state.p;
    let tan = &state.tangential;
    let mu = spec.load.friction;
    let contact: Vec<bool> = p.iter().map(|&v| v > 0.0).collect();
    let stick: Vec<bool> = (0..len).map(|i| contact[i] && tan.stick[i]).collect();
    let count = |v: &[bool]| covered_area(v, terrain.cover.as_deref(), da);
    let stick_radius = if stick.iter().any(|&b| b) {
        let bound = spec.friction_pressure(p, terrain.cover.as_deref());
        let reserve = friction_reserve(mu, &bound, (&tan.qx, &tan.qy));
        zone_radius(&grid, &stick, &reserve, terrain)
    } else {
        0.0
    };
    HistoryStep {
        step: sums.step,
        segment: sums.segment,
        normal_force_n: p.iter().sum::<f64>() * da,
        force_n: [
            tan.qx.iter().sum::<f64>() * da,
            tan.qy.iter().sum::<f64>() * da,
        ],
        delta_t_m: sums.delta_t,
        delta_z_m: state.approach,
        contact_area_m2: count(&contact),
        stick_area_m2: count(&stick),
        stick_radius_m: stick_radius,
        dissipated_j: sums.dissipated,
        worn_volume_m3: 0.0,
        plastic_area_m2: spec
            .limits()
            .hardness
            .map(|hardness| area_at_cap(hardness, terrain.cover.as_deref(), p, da)),
        plastic_penetration_max_m: None,
        converged: sums.converged,
    }
}

/// The cycle, reversal and residual-shift reductions of a solved path, and
/// with a wear law (`wear`: the worn depth and the cycle jump) its wear.
fn reduce_history(
    dir: [f64; 2],
    steps: Vec<HistoryStep>,
    points: &[(f64, f64)],
    turning_steps: Vec<usize>,
    force_error_max: f64,
    wear: Option<(&[f64], f64)>,
) -> HistoryOutput {
    let along = |v: [f64; 2]| v[0] * dir[0] + v[1] * dir[1];
    // The last full cycle: segments j, j+1 that return to turning point j.
    let cycle = (0..points.len().saturating_sub(2))
        .rev()
        .find(|&j| closes_cycle(points, j + 2))
        .map(|j| (turning_steps[j], turning_steps[j + 2]));
    let (dissipated, loop_area) = match cycle {
        Some((s0, s1)) => {
            let d = cycle_rows(&steps, (s0, s1), dir).dissipated;
            let area: f64 = (s0 + 1..=s1)
                .map(|k| {
                    let (a, b) = (&steps[k - 1], &steps[k]);
                    (0..2)
                        .map(|c| {
                            0.5 * (a.force_n[c] + b.force_n[c]) * (b.delta_t_m[c] - a.delta_t_m[c])
                        })
                        .sum::<f64>()
                })
                .sum();
            (Some(d), Some(area))
        }
        None => (None, None),
    };
    // The last reversal: a turning point where F along the direction turns back.
    let reversal = (1..points.len().saturating_sub(1)).rev().find(|&j| {
        let (d0, d1) = (points[j].1 - points[j - 1].1, points[j + 1].1 - points[j].1);
        d0 * d1 < 0.0
    });
    let reversal_stiffness = reversal.and_then(|j| {
        let s = turning_steps[j];
        let (a, b) = (steps.get(s)?, steps.get(s + 1)?);
        let dd = along(b.delta_t_m) - along(a.delta_t_m);
        (dd != 0.0).then(|| (along(b.force_n) - along(a.force_n)) / dd)
    });
    // The last unloading from a positive force through zero.
    let residual = (0..points.len().saturating_sub(1))
        .rev()
        .find(|&j| points[j].1 > 0.0 && points[j + 1].1 < 0.0)
        .and_then(|j| {
            (turning_steps[j] + 1..=turning_steps[j + 1]).find_map(|k| {
                let (a, b) = (&steps[k - 1], &steps[k]);
                let (fa, fb) = (along(a.force_n), along(b.force_n));
                (fa > 0.0 && fb <= 0.0).then(|| {
                    let t = fa / (fa - fb);
                    along(a.delta_t_m) + t * (along(b.delta_t_m) - along(a.delta_t_m))
                })
            })
        });
    let dissipated_total_j = steps.iter().map(|r| r.dissipated_j).sum();
    // Amplitudes and the energy ratio of the last cycle.
    let (force_amplitude_n, shift_amplitude_m, energy_ratio) = match (cycle, dissipated) {
        (Some((s0, s1)), Some(w)) => {
            let rows = cycle_rows(&steps, (s0, s1), dir);
            let (f, d) = (rows.force_amplitude, rows.shift_amplitude);
            let ratio = (f > 0.0 && d > 0.0).then(|| w / (4.0 * f * d));
            (Some(f), Some(d), ratio)
        }
        _ => (None, None, None),
    };
    // The regime of every full cycle, from the last one back.
    let mut regimes = Vec::new();
    let mut j = cycle.map(|(s0, _)| turning_steps.iter().position(|&t| t == s0));
    while let Some(Some(k)) = j {
        if k + 2 >= points.len() || !same_point(points[k], points[k + 2]) {
            break;
        }
        let (s0, s1) = (turning_steps[k], turning_steps[k + 2]);
        regimes.push(cycle_rows(&steps, (s0, s1), dir).gross);
        j = (k >= 2).then(|| Some(k - 2));
    }
    // The rows carry the volume worn so far.
    // Per physical cycle: a simulated one stands for `jump`.
    let worn_volume = wear.and(steps.last().map(|r| r.worn_volume_m3));
    let worn_per_cycle = wear
        .zip(cycle)
        .map(|((_, jump), (s0, s1))| (steps[s1].worn_volume_m3 - steps[s0].worn_volume_m3) / jump);
    let worn_depth_max = wear.map(|(worn, _)| worn.iter().cloned().fold(0.0, f64::max));
    let regime = (!regimes.is_empty()).then(|| {
        if regimes.iter().all(|&g| g) {
            "gross".to_string()
        } else if regimes.iter().all(|&g| !g) {
            "partial".to_string()
        } else {
            "mixed".to_string()
        }
    });
    HistoryOutput {
        direction: dir,
        steps,
        turning_steps,
        dissipated_energy_per_cycle_j: dissipated,
        loop_area_per_cycle_j: loop_area,
        reversal_stiffness_n_per_m: reversal_stiffness,
        residual_delta_t_m: residual,
        force_error_max,
        dissipated_total_j,
        force_amplitude_n,
        shift_amplitude_m,
        energy_ratio,
        regime,
        worn_volume_m3: worn_volume,
        worn_volume_per_cycle_m3: worn_per_cycle,
        worn_depth_max_m: worn_depth_max,
        wear_cycles: Vec::new(),
        wear_jump_ratio: None,
        ball_worn_volume_m3: None,
    }
}
