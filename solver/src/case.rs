//! One contact case end to end, top to bottom: validate, take the resident
//! kernel, solve normal contact, then partial slip (with coupling), and reduce
//! the state to the case's scalars and fields. A driver: the steps live in
//! `spec`, `kernels`, `normal`, `coupling` and `results`.

use crate::error::SolverError;
use crate::model::spec::{CaseSpec, LoadHistory};
use crate::model::surface::Terrain;
use crate::post::results::{reduce, CaseOutput};
use crate::solve::normal::{NormalProblem, NormalSolution};
use crate::solve::resident::{KernelCache, Resident};

/// Fails when any cell of the outermost ring carries pressure: the contact
/// then reaches the edge of the domain and the result would be wrong. With
/// a hardness the error says that the cap spreads the contact (#59).
fn check_inside(spec: &CaseSpec, p: &[f64]) -> Result<(), SolverError> {
    let n = spec.grid.n;
    let active = |i: usize| p[i] > 0.0;
    let touches = (0..n)
        .any(|k| active(k) || active((n - 1) * n + k) || active(k * n) || active(k * n + n - 1));
    if touches {
        let mut detail = String::from("pressure is non-zero on the outermost cells");
        if let Some(h) = spec.limits().hardness {
            detail.push_str(&format!(
                "; the hardness {:.3e} GPa caps the pressure and spreads the contact (a larger hardness_gpa shrinks it)",
                h / 1e9
            ));
        }
        return Err(SolverError::DomainTooSmall { detail });
    }
    Ok(())
}

/// What every case starts from: its kernel resident, the surface on the
/// grid (heights and cover, once), the initial gap, and the frictionless
/// normal contact under the first load, checked inside the domain.
struct Start<'c> {
    res: &'c mut Resident,
    terrain: Terrain,
    h0: Vec<f64>,
    normal: NormalSolution,
    started: std::time::Instant,
    kernel_seconds: f64,
}

/// The first moments of a case, shared by [`solve_case`] and [`preflight`]:
/// what they refuse is what the solve refuses before its tangential steps.
fn start<'c>(spec: &CaseSpec, cache: &'c mut KernelCache) -> Result<Start<'c>, SolverError> {
    spec.validate()?;
    let (res, kernel_seconds) = cache.resident(spec)?;
    // The surface on the grid, once: an area-sampled pattern's cover is
    // integrated cell by cell, about 0.4 ms at 128² (the quick sweep
    // integrated it three times per case: 1.6 % of its time).
    let terrain = spec.surface.terrain(&spec.grid);
    // Every case sets its own cut cells (none on flat surfaces): the
    // resident operator outlives the case.
    res.operator.set_cover(terrain.cover.as_deref());
    let started = std::time::Instant::now();
    let h0 = spec.initial_gap_on(&terrain.heights);
    // A load path starts from its first turning point's normal load.
    let first_load = match &spec.history {
        Some(history) => history.turning_points(&spec.load)[0].0,
        None => spec.load.normal_force_n,
    };
    let normal = res.solve_normal_from_rest(&NormalProblem {
        tolerance: spec.numerics.tolerance,
        max_iterations: spec.numerics.max_iterations,
        hardness: spec.limits().hardness,
        ..NormalProblem::new(&h0, first_load)
    })?;
    check_inside(spec, &normal.p)?;
    Ok(Start {
        res,
        terrain,
        h0,
        normal,
        started,
        kernel_seconds,
    })
}

/// What a case's first moments found ([`preflight`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Preflight {
    /// How far the frictionless contact reaches towards the domain's edge:
    /// the outermost loaded cell centre's distance from the domain's centre
    /// (along x or y, whichever is larger) over the outermost ring's, which
    /// [`solve_case`] refuses to load; below 1.
    pub reach: f64,
}

/// Runs only the first moments of [`solve_case`] — validation, the kernel,
/// the frictionless normal contact under the first load — and refuses what
/// it would refuse there, with the same errors (a contact at the domain's
/// edge, a normal solve that loses contact, an impossible input). A few
/// normal solves' time; `mpcontact check` runs it on every case.
pub fn preflight(spec: &CaseSpec, cache: &mut KernelCache) -> Result<Preflight, SolverError> {
    let start = start(spec, cache)?;
    let (grid, n) = (&spec.grid, spec.grid.n);
    let mut reach = 0.0_f64;
    for (i, &p) in start.normal.p.iter().enumerate() {
        if p > 0.0 {
            reach = reach.max(grid.x(i % n).abs().max(grid.y(i / n).abs()));
        }
    }
    Ok(Preflight {
        reach: reach / grid.x(n - 1),
    })
}

/// Solves one case. Its kernel comes from (and stays in) `cache`.
pub fn solve_case(spec: &CaseSpec, cache: &mut KernelCache) -> Result<CaseOutput, SolverError> {
    crate::base::progress::start_case();
    let start = start(spec, cache)?;
    let (res, terrain, h0) = (start.res, &start.terrain, &start.h0);
    let (started, kernel_seconds) = (start.started, start.kernel_seconds);
    if let Some(history) = &spec.history {
        return solve_history_case(
            spec,
            history,
            res,
            (h0, terrain),
            start.normal,
            started,
            kernel_seconds,
        );
    }
    let state = crate::solve::coupling::solve_partial_slip(res, spec, h0, start.normal)?;
    check_inside(spec, &state.p)?;
    reduce(
        spec,
        terrain,
        &mut res.operator,
        state,
        started,
        kernel_seconds,
        None,
    )
}

/// A case with a load path: from the frictionless normal contact under the
/// first turning point's load (`normal`), the increments, and the scalars
/// and fields of the final state with the path's table.
fn solve_history_case(
    spec: &CaseSpec,
    history: &LoadHistory,
    res: &mut Resident,
    (h0, terrain): (&[f64], &Terrain),
    normal: NormalSolution,
    started: std::time::Instant,
    kernel_seconds: f64,
) -> Result<CaseOutput, SolverError> {
    let points = history.turning_points(&spec.load);
    let solved =
        crate::solve::history::solve_history(res, spec, history, (h0, terrain), normal, |p| {
            check_inside(spec, p)
        })?;
    // The final state is reduced as a case under the path's last load.
    let &(p_last, f_last) = points.last().expect("validated: at least one point");
    let mut last_spec = spec.clone();
    last_spec.load.normal_force_n = p_last;
    // Under displacement control the last turning point is a shift; the
    // force it left is the last row's.
    let f_last = if history.displacement_controlled() {
        let dir = solved.output.direction;
        let f = solved.output.steps.last().map_or([0.0; 2], |r| r.force_n);
        f[0] * dir[0] + f[1] * dir[1]
    } else {
        f_last
    };
    last_spec.load.tangential_ratio = (f_last / (spec.load.friction * p_last)).max(0.0);
    let converged = solved.converged;
    let turning = solved.turning;
    let mut out = reduce(
        &last_spec,
        terrain,
        &mut res.operator,
        solved.last,
        started,
        kernel_seconds,
        Some(solved.output),
    )?;
    out.scalars.converged &= converged;
    // μa (Eq. 19) reads a force-controlled partial slip: a path that
    // imposes the shift has none (#59 item 10).
    if history.displacement_controlled() {
        out.scalars.mu_a = None;
        out.scalars.mu_a_cells = None;
    }
    out.turning = turning;
    out.fields.wear = solved.worn;
    out.fields.ball_wear = solved.ball_worn;
    out.fields.wear_saved = solved.worn_saved;
    Ok(out)
}
