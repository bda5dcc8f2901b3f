//! Wear along a load path (issue #49, PHYSICS.md §5d): the substrate's
//! worn depth per increment, `dh = k p |ds|` (Archard) or `dh = α |q · ds|`
//! (dissipated energy), joins the separation the next increment sees.
//! Checked against the closed forms of gross slip for a rigid sphere
//! without coupling: while the contact slides its surface has moved
//! elastically by u(r) = δ*(1 − r²/2a²), pressure-weighted mean 0.8 δ*, so a
//! cycle 0 → +Δ → −Δ → 0 from rest wears V₁ = 4kP(Δ − δ*) (Δ ≥ 2δ*) and
//! every later one V = 4kP(Δ − 0.8δ*); and the energy law's volume is α
//! times the dissipated energy.
mod common;

use common::{LOAD_1A, MU_1A};
use solver::{solve_case, KernelCache, LoadHistory, Wear, WearLaw};

/// Mindlin's δ* = 3μP(2 − ν)/(16 a G) on Table 1(a) Fe.
fn delta_star() -> f64 {
    let (e, nu, r) = (210.0e9_f64, 0.3_f64, 18.0e-3_f64);
    let a = (3.0 * LOAD_1A * r / (4.0 * e / (1.0 - nu * nu))).cbrt();
    let g = e / (2.0 * (1.0 + nu));
    3.0 * MU_1A * LOAD_1A * (2.0 - nu) / (16.0 * a * g)
}

/// The shifts `shifts` imposed on Table 1(a) Fe at 128² of 2 µm,
/// coupling off, with `law`, `steps` increments per segment.
fn worn(law: WearLaw, shifts: Vec<f64>, steps: usize) -> solver::CaseOutput {
    let mut spec = common::table_1a_fe(128, 2.0, false, 0.0);
    spec.history = Some(LoadHistory {
        tangential_ratios: Vec::new(),
        normal_forces_n: None,
        steps_per_segment: steps,
        shifts_m: Some(shifts),
        wear: Some(Wear::new(law)),
    });
    solve_case(&spec, &mut KernelCache::new()).expect("the path solves")
}

#[test]
fn archard_wear_in_gross_slip_follows_the_sliding_distance() {
    // A coefficient so small that the worn depth (≈ 1e-17 m) leaves the
    // contact as it is: the volume is then k P times the sliding distance.
    let k = 1e-20;
    let ds = delta_star();
    let amplitude = 3.0 * ds;
    let a = amplitude;
    let out = worn(
        WearLaw::Archard { k },
        vec![0.0, a, -a, 0.0, a, -a, 0.0],
        20,
    );
    assert!(out.scalars.converged);
    let h = out.scalars.history.expect("a path");
    let at = |j: usize| h.steps[h.turning_steps[j]].worn_volume_m3;
    let first = at(3);
    let second = at(6) - at(3);
    let v1 = 4.0 * k * LOAD_1A * (amplitude - ds);
    let v2 = 4.0 * k * LOAD_1A * (amplitude - 0.8 * ds);
    println!(
        "first cycle {first:.6e} m³ against 4kP(Δ − δ*) {v1:.6e} ({:+.2e}); second {second:.6e} against 4kP(Δ − 0.8δ*) {v2:.6e} ({:+.2e})",
        first / v1 - 1.0,
        second / v2 - 1.0
    );
    assert!((first / v1 - 1.0).abs() < 0.01, "first cycle");
    assert!((second / v2 - 1.0).abs() < 0.01, "later cycle");
    // The path's total (these cycles start and end at 0, not at a turning
    // point of their own: no two-segment cycle to report).
    assert_eq!(h.worn_volume_m3, Some(at(6)));
    assert_eq!(h.worn_volume_per_cycle_m3, None);
    // The worn depth field carries the volume.
    let da = 4e-12;
    let field: f64 = out.fields.wear.iter().sum::<f64>() * da;
    assert!((field / at(6) - 1.0).abs() < 1e-12);
    assert_eq!(
        h.worn_depth_max_m,
        Some(out.fields.wear.iter().cloned().fold(0.0, f64::max))
    );
}

#[test]
fn the_energy_law_wears_alpha_times_the_dissipated_energy() {
    let alpha = 1e-20;
    let a = 3.0 * delta_star();
    let out = worn(WearLaw::Energy { alpha }, vec![0.0, a, -a, a], 10);
    let h = out.scalars.history.expect("a path");
    let volume = h.worn_volume_m3.expect("worn");
    let energy = h.dissipated_total_j;
    println!(
        "worn {volume:.9e} m³, α × dissipated {:.9e} m³",
        alpha * energy
    );
    // To the trapezoidal rule's sign: at the stick–slip transitions a few
    // cells' mean traction and slip increment make a slightly negative
    // product, which the dissipated energy sums with its sign and the law's
    // |q · ds| does not (9e-8 of the total on two cycles at 10 increments).
    assert!((volume / (alpha * energy) - 1.0).abs() < 1e-6);
    let per_cycle = h.worn_volume_per_cycle_m3.expect("a cycle");
    let w = h.dissipated_energy_per_cycle_j.expect("a cycle");
    println!(
        "last cycle: worn {per_cycle:.9e} m³, α × dissipated {:.9e} m³",
        alpha * w
    );
    assert!((per_cycle / (alpha * w) - 1.0).abs() < 1e-6);
}
