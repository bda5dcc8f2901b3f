//! The normal solve's unit tests: a contact from rest reused only for the
//! same problem, and the nested and preconditioned solves against the plain
//! one.

use super::{solve_normal, solve_normal_from_rest, NormalCache, NormalOptions, NormalProblem};
use crate::green::influence::isotropic_cell;
use crate::operators::operator::{Grid, Operator};

/// Load of [`hertz`]'s contact, N.
const HERTZ_LOAD: f64 = 20.0;

/// A steel half-space on `n x n` cells spanning 4.5 Hertz radii under
/// [`HERTZ_LOAD`] from a 18 mm sphere, and the sphere's separation.
fn hertz(n: usize) -> (Operator, Vec<f64>) {
    let (e, nu, r) = (210.0e9_f64, 0.3_f64, 18.0e-3_f64);
    let a = (3.0 * HERTZ_LOAD * r / (4.0 * e / (1.0 - nu * nu))).cbrt();
    let d = 4.5 * a / n as f64;
    let grid = Grid { n, dx: d, dy: d };
    let g = e / (2.0 * (1.0 + nu));
    let op = Operator::build(grid, |x, y| isotropic_cell(g, nu, x, y, grid.dx, grid.dy));
    let h = (0..grid.len())
        .map(|i| {
            let (x, y) = (grid.x(i % n), grid.y(i / n));
            (x * x + y * y) / (2.0 * r)
        })
        .collect();
    (op, h)
}

/// The contact from rest kept between cases is returned only for the
/// same problem on the same cover, and is then the fresh solve's bits;
/// another load or another cover is solved.
#[test]
fn a_contact_from_rest_is_reused_for_the_same_problem_only() {
    let (n, load) = (64, HERTZ_LOAD);
    let (mut op, h) = hertz(n);
    let grid = op.grid();
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    let prob = NormalProblem::new(&h, load);
    let mut own = NormalCache::new(&mut op);
    let fresh = solve_normal(&mut op, &mut own, &prob).unwrap();
    let mut cache = NormalCache::new(&mut op);
    let first = solve_normal_from_rest(&mut op, &mut cache, &prob).unwrap();
    let again = solve_normal_from_rest(&mut op, &mut cache, &prob).unwrap();
    assert_eq!(cache.reused(), 1);
    for s in [&first, &again] {
        assert_eq!(bits(&s.p), bits(&fresh.p));
        assert!(s.uz.is_empty());
        assert_eq!(s.approach.to_bits(), fresh.approach.to_bits());
        assert_eq!(s.report.iterations, fresh.report.iterations);
    }
    // Another load: solved, and a different contact.
    let heavier = NormalProblem::new(&h, 1.5 * load);
    let s = solve_normal_from_rest(&mut op, &mut cache, &heavier).unwrap();
    assert_eq!(cache.reused(), 1);
    assert!(s.approach > 1.2 * fresh.approach);
    // The same problem on a cover with a cut cell under the contact:
    // solved again (the operator differs), with another pressure there.
    let mut cover = vec![1.0; grid.len()];
    let centre = n / 2 * n + n / 2;
    cover[centre] = 0.5;
    op.set_cover(Some(&cover));
    let cut = solve_normal_from_rest(&mut op, &mut cache, &heavier).unwrap();
    assert_eq!(cache.reused(), 1);
    assert!(
        cut.p[centre] < 0.9 * s.p[centre],
        "{} {}",
        cut.p[centre],
        s.p[centre]
    );
    let cut_again = solve_normal_from_rest(&mut op, &mut cache, &heavier).unwrap();
    assert_eq!(cache.reused(), 2);
    assert_eq!(bits(&cut_again.p), bits(&cut.p));
}

/// Nesting and preconditioning change the path, not the answer: all four
/// combinations reach the same discrete Hertz pressure, and the
/// preconditioned iteration needs far fewer fine iterations.
#[test]
fn nested_and_preconditioned_solves_reach_the_plain_solution() {
    let load = HERTZ_LOAD;
    let (mut op, h) = hertz(128);
    let mut cache = NormalCache::new(&mut op);
    let mut runs = Vec::new();
    for (nested, precondition) in [(false, false), (true, false), (false, true), (true, true)] {
        let options = NormalOptions {
            nested,
            precondition,
        };
        let prob = NormalProblem {
            tolerance: 1e-12,
            options,
            ..NormalProblem::new(&h, load)
        };
        let s = solve_normal(&mut op, &mut cache, &prob).unwrap();
        assert!(s.report.converged, "{options:?}");
        runs.push(s);
    }
    let pmax = runs[0].p.iter().cloned().fold(0.0, f64::max);
    for s in &runs[1..] {
        let err =
            s.p.iter()
                .zip(&runs[0].p)
                .fold(0.0_f64, |m, (x, y)| m.max((x - y).abs()));
        assert!(err < 1e-8 * pmax, "max |Δp| = {:e} of p_max", err / pmax);
        assert!((s.approach / runs[0].approach - 1.0).abs() < 1e-10);
    }
    let plain = runs[0].report.iterations;
    let pc = runs[2].report.iterations;
    assert!(
        2 * pc < plain,
        "preconditioned {pc} vs plain {plain} iterations"
    );
}
