//! One contact case end to end, top to bottom: validate, take the resident
//! kernel, solve normal contact, then partial slip (with coupling), and reduce
//! the state to the case's scalars and fields. A driver: the steps live in
//! `spec`, `kernels`, `normal`, `coupling` and `results`.

use crate::error::SolverError;
use crate::kernels::KernelCache;
use crate::normal::NormalProblem;
use crate::results::{reduce, CaseOutput};
use crate::spec::CaseSpec;

/// Fails when any cell of the outermost ring carries pressure: the contact
/// then reaches the edge of the domain and the result would be wrong.
fn check_inside(n: usize, p: &[f64]) -> Result<(), SolverError> {
    let active = |i: usize| p[i] > 0.0;
    let touches = (0..n)
        .any(|k| active(k) || active((n - 1) * n + k) || active(k * n) || active(k * n + n - 1));
    if touches {
        return Err(SolverError::DomainTooSmall {
            detail: "pressure is non-zero on the outermost cells".into(),
        });
    }
    Ok(())
}

/// Solves one case. Its kernel comes from (and stays in) `cache`.
pub fn solve_case(spec: &CaseSpec, cache: &mut KernelCache) -> Result<CaseOutput, SolverError> {
    spec.validate()?;
    let (res, kernel_seconds) = cache.resident(spec)?;
    let started = std::time::Instant::now();
    let n = spec.grid.n;
    let h0 = spec.initial_gap();
    let normal = res.solve_normal(&NormalProblem {
        tolerance: spec.numerics.tolerance,
        max_iterations: spec.numerics.max_iterations,
        ..NormalProblem::new(&h0, spec.load.normal_force_n)
    })?;
    check_inside(n, &normal.p)?;
    let state = crate::coupling::solve_partial_slip(res, spec, &h0, normal)?;
    check_inside(n, &state.p)?;
    reduce(spec, &mut res.operator, state, started, kernel_seconds)
}
