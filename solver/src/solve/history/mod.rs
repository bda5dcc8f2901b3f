//! Load histories (fretting): a case's load path solved increment by
//! increment, each from the previous increment's tractions and displacement
//! (Coulomb friction in increments, PHYSICS.md §5b), and what a fretting study
//! reads from it: the path's table, the energy dissipated per cycle, the
//! stiffness after a reversal and the residual shift. Knows the solvers only
//! through `coupling::solve_step`; writes no files. Its parts: `walk` (one
//! increment), `auto` (the increments' sizes), `output` (the table and its
//! reductions); this file drives the path and reduces it.

use crate::error::SolverError;
use crate::model::spec::{
    closes_cycle, full_cycles, looked_at_segments, same_point, CaseSpec, Increments, LoadHistory,
};
use crate::model::surface::Terrain;
use crate::solve::coupling::ContactState;
use crate::solve::normal::NormalSolution;
use crate::solve::resident::Resident;
use crate::solve::tangential::TangentialSolution;
use crate::solve::wear::{CycleRows, Wearing};
pub use crate::solve::wear::{WearCycle, SCAR_DEFINITION, WEAR_JUMP_LIMIT};

mod auto;
mod output;
mod walk;

use auto::{along_segment, AutoSteps};
use output::{row, StepSums};
pub use output::{
    HistoryOutput, HistoryStep, TurningState, DISSIPATION_DEFINITION, SLIP_REGIME_DEFINITION,
};
use walk::Walk;

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
    let len = grid.len();
    let angle = spec.load.angle_deg.to_radians();
    let dir = [angle.cos(), angle.sin()];
    let points = history.turning_points(&spec.load);
    let cycle_ends = full_cycles(&points);
    let cycles_total = cycle_ends.len();
    let looked_at = looked_at_segments(&points, history.sampling.every);

    // On a surface with a hardness, the plastic penetration is permanent:
    // every increment's adds to the dent, and the separation the next
    // increment sees is the initial one plus the dent (unloading leaves it).
    // Worn depth likewise, with a wear law (the surface recedes).
    let dent = normal0.plastic.clone();
    let wearing = history.wear.map(|w| Wearing::new(w, grid));
    let at = |v: &[f64], i: usize| v.get(i).copied().unwrap_or(0.0);
    let dented: Option<Vec<f64>> = (!dent.is_empty() || wearing.is_some())
        .then(|| (0..len).map(|i| h0[i] + at(&dent, i)).collect());
    let converged = normal0.report.converged;
    // The state after frictionless normal loading: no tractions, every
    // contact cell sticks (solved: nothing was asked of it).
    let last = ContactState {
        p: normal0.p,
        approach: normal0.approach,
        plastic: normal0.plastic,
        tangential: TangentialSolution {
            qx: vec![0.0; len],
            qy: vec![0.0; len],
            sx: vec![0.0; len],
            sy: vec![0.0; len],
            stick: vec![true; len],
            shift: [0.0; 2],
            report: crate::solve::tangential::TangentialReport {
                converged: true,
                ..Default::default()
            },
        },
        normal_report: normal0.report,
        normal_iterations: normal0.report.iterations,
        tangential_iterations: 0,
        coupling_iterations: 0,
        coupling_change: 0.0,
        coupling_converged: true,
    };
    let mut walk = Walk {
        spec,
        terrain,
        h0,
        p0: last.p.clone(),
        dir,
        displacement_control: history.displacement_controlled(),
        u: (vec![0.0; len], vec![0.0; len]),
        delta_t: [0.0; 2],
        delta_t_max: 0.0,
        last_increment: 0.0,
        dent,
        dented,
        wearing,
        worn_normal: None,
        load: points[0],
        normal_iterations: last.normal_iterations,
        tangential_iterations: 0,
        coupling_iterations: 0,
        converged,
        rows: Vec::new(),
        force_error_max: 0.0,
        last,
    };
    let mut first = row(
        spec,
        terrain,
        &walk.last,
        &StepSums {
            step: 0,
            segment: 0,
            delta_t: [0.0; 2],
            dissipated: 0.0,
            converged,
        },
    );
    first.stick_area_m2 = first.contact_area_m2;
    first.plastic_penetration_max_m = walk.deepest();
    walk.rows.push(first);
    let approach0 = walk.last.approach;
    let mut turning_steps = vec![0];
    let mut turning = vec![TurningState::of(0, &walk.last)];
    let mut increments_per_segment = Vec::with_capacity(points.len() - 1);
    let mut sampled_segments = Vec::new();
    // The first segment of the first full cycle: the segments before it
    // (the first loading) happen once whatever the wear's cycle jump.
    let cycles_from = cycle_ends.first().map_or(usize::MAX, |&t| t - 2);
    let mut auto = AutoSteps {
        approach0,
        ..Default::default()
    };
    let segments = points.len() - 1;

    for (segment, pair) in points.windows(2).enumerate() {
        crate::base::progress::segment(segment + 1, segments)?;
        let (a, b) = (pair[0], pair[1]);
        if let Some(w) = walk.wearing.as_mut() {
            w.set_cycles(segment >= cycles_from);
        }
        let split = history.segment_increments(segment, &looked_at);
        if let Increments::Fixed(_) = split {
            sampled_segments.push(segment);
        }
        let rows_before = walk.rows.len();
        let work_before: f64 = walk.rows.iter().map(|r| r.dissipated_j).sum();
        match split {
            Increments::Fixed(k) => {
                for m in 1..=k {
                    let load = along_segment(a, b, m as f64 / k as f64);
                    if load == walk.load {
                        walk.hold(segment);
                        continue;
                    }
                    let trial = walk.trial(res, load, None, &check)?;
                    walk.accept(res, trial, segment, &check)?;
                }
            }
            Increments::Auto { tolerance } => {
                auto.segment(&mut walk, res, (a, b), segment, tolerance, &check)?;
            }
        }
        let taken = walk.rows.len() - rows_before;
        increments_per_segment.push(taken);
        for r in &mut walk.rows[rows_before..] {
            r.segment_increments = taken;
        }
        auto.last_segment_work =
            walk.rows.iter().map(|r| r.dissipated_j).sum::<f64>() - work_before;
        turning_steps.push(walk.rows.len() - 1);
        turning.push(TurningState::of(walk.rows.len() - 1, &walk.last));
        let t = segment + 1;
        if let (Some(w), true) = (&mut walk.wearing, cycle_ends.contains(&t)) {
            let number = w.cycles.len() + 1;
            let save = number == cycles_total || looked_at.contains(&segment);
            let looped = cycle_rows(&walk.rows, (turning_steps[t - 2], turning_steps[t]), dir);
            w.record(terrain, &walk.last.p, &looped, save);
        }
    }
    let Walk {
        mut last,
        delta_t,
        dent,
        wearing,
        rows,
        normal_iterations,
        tangential_iterations,
        coupling_iterations,
        converged,
        force_error_max,
        ..
    } = walk;
    // The final state's shift is δt from the start of the path, not the
    // last increment's.
    last.tangential.shift = delta_t;
    // The final state's plastic penetration is the whole path's dent.
    last.plastic = dent;
    last.normal_iterations = normal_iterations;
    last.tangential_iterations = tangential_iterations;
    last.coupling_iterations = coupling_iterations;
    let mut wearing = wearing;
    let wear = wearing.as_ref().map(|w| (&w.worn[..], w.settings().jump));
    let sampled_last = cycle_ends
        .last()
        .is_some_and(|&t| looked_at.contains(&(t - 1)) && history.sampling.increments > 0)
        || matches!(history.increments, Increments::Fixed(_));
    let mut output = reduce_history(
        dir,
        rows,
        &points,
        turning_steps,
        force_error_max,
        wear,
        sampled_last,
    );
    output.increments_per_segment = increments_per_segment;
    output.sampled_segments = sampled_segments;
    if let Increments::Auto { .. } = history.increments {
        output.auto_rejected = Some(auto.rejected);
        output.auto_tolerance_met = Some(auto.tolerance_met);
    }
    if let Some(w) = wearing.as_mut() {
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

/// The cycle, reversal and residual-shift reductions of a solved path, and
/// with a wear law (`wear`: the worn depth and the cycle jump) its wear.
fn reduce_history(
    dir: [f64; 2],
    steps: Vec<HistoryStep>,
    points: &[(f64, f64)],
    turning_steps: Vec<usize>,
    force_error_max: f64,
    wear: Option<(&[f64], f64)>,
    sampled_last: bool,
) -> HistoryOutput {
    let along = |v: [f64; 2]| v[0] * dir[0] + v[1] * dir[1];
    // The last full cycle: segments j, j+1 that return to turning point j.
    let cycle = (0..points.len().saturating_sub(2))
        .rev()
        .find(|&j| closes_cycle(points, j + 2))
        .map(|j| (turning_steps[j], turning_steps[j + 2]));
    let (dissipated, loop_area) = match cycle {
        Some((s0, s1)) if !sampled_last => {
            (Some(cycle_rows(&steps, (s0, s1), dir).dissipated), None)
        }
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
    let dissipated_per_cycle_j = full_cycles(points)
        .iter()
        .map(|&t| cycle_rows(&steps, (turning_steps[t - 2], turning_steps[t]), dir).dissipated)
        .collect();
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
        dissipated_per_cycle_j,
        increments_per_segment: Vec::new(),
        sampled_segments: Vec::new(),
        auto_rejected: None,
        auto_tolerance_met: None,
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
