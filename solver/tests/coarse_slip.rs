//! The coarse-to-fine start of the tangential solver changes the path, not
//! the answer: on Cattaneo–Mindlin (Table 1a, coupling off) the nested solve
//! and the plain fine solve, both to the same KKT tolerance 1e-6, give the
//! same stick set, shifts within the tolerance (measured 1e-10 relative) and
//! tractions within 100x it relative to μ p_max (measured 1.3e-5 and 1.6e-5:
//! two solutions whose slip residuals are below 1e-6 |δt| differ in traction
//! by the residual times the inverse compliance, about 10x here).

mod common;

use common::{hertz_fe as hertz, LOAD_1A, MU_1A};
use solver::coarse_slip::TangentialLevels;
use solver::operator::Operator;
use solver::tangential::{
    solve_nested, solve_tangential, solve_tangential_on_grid, TangentialProblem,
    TangentialSolution, TangentialStart,
};
use solver::window::WindowCache;

const MU: f64 = MU_1A;
const LOAD: f64 = LOAD_1A;
const TOL: f64 = 1e-6;

fn problem(p: &[f64]) -> TangentialProblem<'_> {
    common::cattaneo_problem(p, Default::default())
}

use common::tangential_difference as compare;

#[test]
fn nested_start_reaches_the_plain_fine_solution_on_the_whole_grid() {
    // Domain 2.4 a: the contact spans more than 80 % of the side, no window.
    let (mut op, p) = hertz(128, 2.0e-6);
    let mut levels = TangentialLevels::new(&mut op);
    assert_eq!(levels.len(), 2, "64² and 32²");
    let plain = solve_tangential_on_grid(&mut op, &problem(&p)).unwrap();
    let nested = solve_nested(&mut op, &mut levels, &problem(&p)).unwrap();
    let (dq, dt, stick) = compare(&plain, &nested, &p);
    println!(
        "plain {} it, nested {} fine + {} coarse it: max|Δq|/μp_max {dq:.2e}, Δδt/δt {dt:.2e}, stick cells differing {stick}",
        plain.report.iterations, nested.report.iterations, nested.report.coarse_iterations
    );
    assert!(plain.report.converged && nested.report.converged);
    assert!(plain.report.change < TOL && nested.report.change < TOL);
    assert!(nested.report.coarse_iterations > 0, "the coarse levels ran");
    assert!(dq < 100.0 * TOL, "tractions differ by {dq:e} of μ p_max");
    assert!(dt < TOL, "shifts differ by {dt:e}");
    assert_eq!(stick, 0, "stick sets differ");
    assert!(nested.report.force_error < 1e-10);
}

#[test]
fn nested_start_through_the_contact_window_reaches_the_plain_solution() {
    // Domain 4.5 a: the solve runs on a window and its own coarse levels.
    let (mut op, p) = hertz(128, 3.7e-6);
    let mut windows = WindowCache::default();
    let nested = solve_tangential(&mut op, &mut windows, &problem(&p)).unwrap();
    assert!(windows.side().is_some_and(|s| s < 128), "a window was used");
    let plain = solve_tangential_on_grid(&mut op, &problem(&p)).unwrap();
    let (dq, dt, stick) = compare(&plain, &nested, &p);
    println!(
        "plain {} it, nested {} fine + {} coarse it: max|Δq|/μp_max {dq:.2e}, Δδt/δt {dt:.2e}, stick cells differing {stick}",
        plain.report.iterations, nested.report.iterations, nested.report.coarse_iterations
    );
    assert!(plain.report.converged && nested.report.converged);
    assert!(nested.report.coarse_iterations > 0, "the coarse levels ran");
    assert!(dq < 100.0 * TOL, "tractions differ by {dq:e} of μ p_max");
    assert!(dt < TOL, "shifts differ by {dt:e}");
    assert_eq!(stick, 0, "stick sets differ");
}

/// A caller's start (a load history's previous increment) is kept: the
/// solve equals the plain one to the bit.
#[test]
fn a_given_start_is_not_replaced() {
    let (mut op, p) = hertz(64, 4.0e-6);
    let mut levels = TangentialLevels::new(&mut op);
    let first = solve_tangential_on_grid(&mut op, &problem(&p)).unwrap();
    let warm = TangentialProblem {
        start: TangentialStart::Tractions(&first.qx, &first.qy),
        force: [0.5 * MU * LOAD, 0.1 * MU * LOAD],
        ..problem(&p)
    };
    let plain = solve_tangential_on_grid(&mut op, &warm).unwrap();
    let nested = solve_nested(&mut op, &mut levels, &warm).unwrap();
    assert_eq!(plain.qx, nested.qx);
    assert_eq!(plain.qy, nested.qy);
    assert_eq!(nested.report.coarse_iterations, 0);
}

/// The Fourier preconditioner of a load history's increments changes the
/// path, not the answer: a reversal (0.6 μP to 0.3 μP, the slip front moving
/// in from the edge, as in a fretting cycle's first unloading increments),
/// solved from the loaded state's tractions with the slip measured from that
/// state, gives with and without it the same stick set, shifts within the
/// tolerance and tractions within 100x it of μ p_max, both with KKT residuals
/// below the tolerance. On the whole grid and through the contact window (and
/// its cached preconditioner, used twice).
#[test]
fn preconditioned_increments_reach_the_jacobi_solution() {
    for (d, windowed) in [(2.0e-6, false), (3.7e-6, true)] {
        let (mut op, p) = hertz(128, d);
        let loaded = solve_tangential_on_grid(&mut op, &problem(&p)).unwrap();
        // The slip of the increment: the loaded state's displacement, negated.
        let n = p.len();
        let (mut ux, mut uy) = (vec![0.0; n], vec![0.0; n]);
        op.tangential(&loaded.qx, &loaded.qy, &mut ux, &mut uy);
        let (ex, ey): (Vec<f64>, Vec<f64>) = ux.iter().zip(&uy).map(|(x, y)| (-x, -y)).unzip();
        let mut windows = WindowCache::default();
        for force in [0.3, 0.0] {
            let increment = |precondition| TangentialProblem {
                force: [force * MU * LOAD, 0.0],
                extra: Some((&ex, &ey)),
                slip_floor: 1e-3 * loaded.shift[0].abs(),
                start: TangentialStart::Tractions(&loaded.qx, &loaded.qy),
                precondition,
                ..problem(&p)
            };
            let solve = |op: &mut Operator, windows: &mut WindowCache, prob: &TangentialProblem| {
                if windowed {
                    solve_tangential(op, windows, prob).unwrap()
                } else {
                    solve_tangential_on_grid(op, prob).unwrap()
                }
            };
            let plain = solve(&mut op, &mut windows, &increment(false));
            let pre = solve(&mut op, &mut windows, &increment(true));
            assert_eq!(windows.side().is_some_and(|s| s < 128), windowed);
            let (dq, _, stick) = compare(&plain, &pre, &p);
            let dt = (plain.shift[0] - pre.shift[0]).hypot(plain.shift[1] - pre.shift[1])
                / loaded.shift[0].abs();
            let nstick = |s: &TangentialSolution| s.stick.iter().filter(|&&b| b).count();
            println!(
                "cell {d:.1e}, F {force} μP: Jacobi {} it, Fourier {} it; max|Δq|/μp_max {dq:.2e}, Δδt/δt {dt:.2e}, stick cells {} / {} (differing {stick})",
                plain.report.iterations,
                pre.report.iterations,
                nstick(&plain),
                nstick(&pre)
            );
            for s in [&plain, &pre] {
                assert!(s.report.converged && s.report.change < TOL);
                assert!(s.report.force_error < 1e-10);
            }
            assert!(dq < 100.0 * TOL, "tractions differ by {dq:e} of μ p_max");
            assert!(dt < TOL, "shifts differ by {dt:e} of δt");
            assert_eq!(stick, 0, "stick sets differ");
        }
    }
}

/// A solve started from its own solution, with the force lowered by 1e-9 of
/// itself, stays at its solution: the start's slip cells stay on their rims
/// (the stick cells alone shift by the change), one iteration confirms it,
/// and tractions and δt move by the size of the change (measured 7.3e-10
/// μ p_max and 1.3e-9). When the shift moved every cell, it pushed each
/// slip cell (traction along +x, shift along −x) inside its disc, the
/// conjugate gradient took them for stick cells slipping by a third of δt,
/// and it took 3 iterations to come back to within the tolerance, the
/// tractions moved by 1.3e-6 μ p_max (on Table 1a coupled at 512² and 1024²
/// such closing passes took 27 and 31 iterations).
#[test]
fn a_restart_from_the_solution_keeps_its_slip_cells_on_their_rims() {
    let (mut op, p) = hertz(128, 2.0e-6);
    let first = solve_tangential_on_grid(&mut op, &problem(&p)).unwrap();
    assert!(first.report.converged);
    let slip_cells = (0..p.len())
        .filter(|&i| p[i] > 0.0 && !first.stick[i])
        .count();
    assert!(slip_cells > 1000, "{slip_cells} slip cells");
    let force = [0.6 * MU * LOAD * (1.0 - 1e-9), 0.0];
    let again = solve_tangential_on_grid(
        &mut op,
        &TangentialProblem {
            force,
            start: TangentialStart::Tractions(&first.qx, &first.qy),
            ..problem(&p)
        },
    )
    .unwrap();
    let (dq, dt, stick) = compare(&first, &again, &p);
    println!(
        "restart: {} iterations, stick cells differing {stick}, |Δq| {dq:.2e} μ p_max, |Δδt| {dt:.2e}",
        again.report.iterations
    );
    assert!(again.report.converged);
    assert_eq!(again.report.iterations, 1);
    assert_eq!(stick, 0);
    assert!(dt < 1e-8, "{dt:e}");
    assert!(dq < 1e-8, "{dq:e}");
}
