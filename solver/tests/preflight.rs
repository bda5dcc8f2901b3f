//! `solver::preflight`, a case's first moments alone (what `mpcontact check`
//! runs on every case): it refuses exactly what `solve_case` refuses in
//! them, with the same error, and the reach it reports is Hertz's radius on
//! a flat isotropic surface.

mod common;

use common::{hertz_1a, table_1a_fe};
use solver::{
    preflight, solve_case, Increments, KernelCache, LoadHistory, LoopSampling, SolverError,
};

/// Table 1(a) on 256 cells of 1 µm: the outermost loaded cell along x or y
/// lies within one cell of Hertz's a = 105.4 µm, and the reach is that
/// distance over the outermost cell's, 127.5 µm.
#[test]
fn preflight_reach_of_table_1a_is_the_hertz_radius_within_a_cell() {
    let spec = table_1a_fe(256, 1.0, true, 0.6);
    let found = preflight(&spec, &mut KernelCache::new()).unwrap();
    let (a, _) = hertz_1a();
    let outermost = spec.grid.x(255);
    let reached = found.reach * outermost;
    println!(
        "reach {:.4}: {:.2} µm against Hertz a = {:.2} µm",
        found.reach,
        reached * 1e6,
        a * 1e6
    );
    assert!((reached - a).abs() < spec.grid.dx, "{reached} vs {a}");
    // And the whole case solves.
    solve_case(&spec, &mut KernelCache::new()).unwrap();
}

/// `spec` refused by the pre-flight and by the solve alike, for a contact
/// at the domain's edge, with the same error.
fn refused_at_the_edge_by_both(spec: &solver::CaseSpec) {
    let first = preflight(spec, &mut KernelCache::new()).unwrap_err();
    let solve = solve_case(spec, &mut KernelCache::new()).err().unwrap();
    assert!(
        matches!(first, SolverError::DomainTooSmall { .. }),
        "{first}"
    );
    assert_eq!(first, solve);
}

/// The same case on 64 cells of 2 µm (the outermost cells at 63 µm, inside
/// a = 105 µm): both refuse it, with the same error.
#[test]
fn preflight_refuses_a_contact_at_the_edge_as_the_solve_does() {
    refused_at_the_edge_by_both(&table_1a_fe(64, 2.0, true, 0.6));
}

/// A load path starts from its first turning point's normal load: 60 N
/// (a = 152 µm) reaches past the outermost cells at 127.5 µm where the
/// case's own 20 N (a = 105 µm) would not. Both the pre-flight and the
/// solve refuse it; the same path at 20 N passes.
#[test]
fn preflight_of_a_load_path_starts_from_its_first_load() {
    let path = |p0: f64| LoadHistory {
        tangential_ratios: vec![0.0, 0.3],
        normal_forces_n: Some(vec![p0, 20.0]),
        increments: Increments::Fixed(2),
        sampling: LoopSampling::default(),
        shifts_m: None,
        wear: None,
    };
    let mut spec = table_1a_fe(256, 1.0, false, 0.3);
    spec.history = Some(path(60.0));
    refused_at_the_edge_by_both(&spec);
    spec.history = Some(path(20.0));
    let found = preflight(&spec, &mut KernelCache::new()).unwrap();
    assert!(found.reach < 1.0);
}
