//! Validation ladder steps 3–5 and 8 (docs/validation.md): Hertz, Cattaneo–Mindlin,
//! flat isotropic μa = μ, and equilibrium, on the paper's Table 1a case.

mod common;

use common::table_1a_fe;
use solver::{solve_case, KernelCache};

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn hertz_table_1a_radius_peak_and_approach_within_1pct() {
    let spec = table_1a_fe(512, 0.5, false, 0.0);
    let out = solve_case(&spec, &mut KernelCache::new()).unwrap();
    let s = &out.scalars;
    let e_star: f64 = 210.0e9 / (1.0 - 0.09);
    let a = (3.0 * 20.0 * 18.0e-3 / (4.0 * e_star)).cbrt();
    let p_h = 3.0 * 20.0 / (2.0 * std::f64::consts::PI * a * a);
    println!(
        "a = {:.6e} (Hertz {a:.6e}), p_max = {:.6e} (Hertz {p_h:.6e}), δz = {:.6e} (a²/R {:.6e}), iterations {}",
        s.contact_radius_m,
        s.p_max_pa,
        s.delta_z_m,
        a * a / 18.0e-3,
        s.normal_iterations
    );
    assert!(s.converged, "{:?}", s.normal);
    assert!((a / 0.1054e-3 - 1.0).abs() < 0.01, "paper's a");
    assert!(rel(s.contact_radius_m, a) < 0.01, "contact radius");
    assert!(rel(s.p_max_pa, p_h) < 0.01, "peak pressure");
    assert!(rel(s.p_max_pa, 860.0e6) < 0.01, "paper's p_H");
    assert!(rel(s.delta_z_m, a * a / 18.0e-3) < 0.01, "approach");
    assert!(rel(s.normal_force_n, 20.0) < 1e-8, "Σ p ΔA = P");
}

/// Cattaneo–Mindlin closed forms for Table 1a with the Hertz radius `a`.
struct Mindlin {
    a: f64,
    c: f64,
    delta: f64,
}

fn mindlin() -> Mindlin {
    mindlin_at(0.6)
}

/// [`mindlin`] at F/μP = `ratio`.
fn mindlin_at(ratio: f64) -> Mindlin {
    let (e, nu, p, r, mu): (f64, f64, f64, f64, f64) = (210.0e9, 0.3, 20.0, 18.0e-3, 0.28571);
    let a = (3.0 * p * r / (4.0 * e / (1.0 - nu * nu))).cbrt();
    let c = a * (1.0 - ratio).cbrt();
    let delta0 = 3.0 * mu * p * (2.0 - nu) * (1.0 + nu) / (8.0 * a * e);
    Mindlin {
        a,
        c,
        delta: delta0 * (1.0 - (1.0 - ratio).powf(2.0 / 3.0)),
    }
}

#[test]
fn cattaneo_mindlin_uncoupled_then_coupled_on_table_1a() {
    let mut cache = KernelCache::new();
    let m = mindlin();
    let f = 0.6 * 0.28571 * 20.0;

    // Coupling off: Cattaneo–Mindlin exactly.
    let spec = table_1a_fe(512, 0.5, false, 0.6);
    let off = solve_case(&spec, &mut cache).unwrap().scalars;
    println!(
        "uncoupled: c = {:.6e} (Mindlin {:.6e}), c/a = {:.5}, δx = {:.6e} (Mindlin {:.6e}), μa = {:?}, iterations n/t {} {}, {:?}",
        off.stick_radius_m,
        m.c,
        off.stick_radius_m / off.contact_radius_m,
        off.delta_t_m,
        m.delta,
        off.mu_a,
        off.normal_iterations,
        off.tangential_iterations,
        off.tangential
    );
    assert!(off.converged);
    assert!(rel(off.contact_radius_m, m.a) < 0.01, "contact radius");
    assert!(rel(off.stick_radius_m, m.c) < 0.02, "stick radius");
    assert!(rel(off.delta_t_m, m.delta) < 0.01, "tangential shift");
    assert!(rel(off.tangential_force_n[0], f) < 1e-8, "Σ q ΔA = F");
    assert!(off.tangential_force_n[1].abs() < 1e-8 * f);
    assert!(rel(off.normal_force_n, 20.0) < 1e-8, "Σ p ΔA = P");
    assert!(rel(off.mu_a.unwrap(), 0.28571) < 0.01, "μa = μ");
    // KKT residuals of the returned tractions are within the requested tolerance.
    let ttol = spec.numerics.tangential_tolerance;
    assert!(
        off.tangential.stick_residual < 2.0 * ttol && off.tangential.slip_residual < 2.0 * ttol
    );

    // Coupling on: converges, equilibrium holds, μa close to μ.
    let spec = table_1a_fe(512, 0.5, true, 0.6);
    let on = solve_case(&spec, &mut cache).unwrap().scalars;
    println!(
        "coupled: c/a = {:.5}, δx = {:.6e}, μa = {:?}, p_max {:.6e} ({:+.3}% vs uncoupled), stick area {:+.3}%, δt⊥ = {:.3e}, iterations n/t/c {} {} {}",
        on.stick_radius_m / on.contact_radius_m,
        on.delta_t_m,
        on.mu_a,
        on.p_max_pa,
        100.0 * (on.p_max_pa / off.p_max_pa - 1.0),
        100.0 * (on.stick_area_m2 / off.stick_area_m2 - 1.0),
        on.delta_t_perp_m,
        on.normal_iterations,
        on.tangential_iterations,
        on.coupling_iterations
    );
    assert!(on.converged);
    assert!(
        rel(on.tangential_force_n[0], f) < 1e-8,
        "Σ q ΔA = F (coupled)"
    );
    assert!(rel(on.normal_force_n, 20.0) < 1e-8, "Σ p ΔA = P (coupled)");
    assert!(rel(on.mu_a.unwrap(), 0.28571) < 0.03, "μa ≈ μ (coupled)");
    assert!(cache.builds() == 1, "one kernel for both cases");
}

#[test]
fn issue20_item8_zones_the_grid_cannot_resolve_are_refused() {
    // F = (1 − 1e-10) μP leaves a stick zone far below one cell (it gave
    // μa = 434 before); a 1e-300 m sphere touches a single cell.
    let mut spec = table_1a_fe(64, 5.0, false, 0.9999999999);
    let e = solve_case(&spec, &mut KernelCache::new()).unwrap_err();
    assert!(
        matches!(e, solver::SolverError::SlipUnresolved { .. }),
        "{e}"
    );
    assert!(e.to_string().contains("stick zone"), "{e}");
    spec.load.tangential_ratio = 0.6;
    spec.load.indenter_radius_m = 1e-300;
    let e = solve_case(&spec, &mut KernelCache::new()).unwrap_err();
    assert!(
        matches!(e, solver::SolverError::ContactUnresolved { .. }),
        "{e}"
    );
}

/// Issue #15: the sub-cell apparent radii (the hull's, `solver.radii =
/// "hull"`) converge to Hertz's a and Mindlin's c at a measured order ≥ 1.5
/// and are within 0.1 % at 256² (the paper's whole-cell radii: first order,
/// 0.6 % off at 256²). Table 1a, uncoupled, on its 256 µm domain.
///
/// The errors also carry a part that oscillates with where the boundary
/// falls between cell centres (docs/validation.md has every grid from 32² to
/// 512²): a's order is taken from 32², 64², 128² (a/h = 13 … 53); c's, whose
/// oscillating part is larger, from the first and last of 45², 90², 180².
#[test]
fn issue15_subcell_radii_converge_to_hertz_and_mindlin() {
    let mut cache = KernelCache::new();
    let m = mindlin();
    let mut solve = |n: usize| {
        let mut spec = table_1a_fe(n, 256.0 / n as f64, false, 0.6);
        spec.numerics.radii = solver::Radii::Hull;
        let s = solve_case(&spec, &mut cache).unwrap().scalars;
        assert!(s.converged);
        let errs = (
            rel(s.contact_radius_m, m.a),
            rel(s.stick_radius_m, m.c),
            rel(s.contact_radius_cells_m, m.a),
            rel(s.stick_radius_cells_m, m.c),
        );
        println!(
            "{n}²: |a/a_H − 1|, |c/c_M − 1| = {:.2e}, {:.2e} (cells {:.2e}, {:.2e})",
            errs.0, errs.1, errs.2, errs.3
        );
        errs
    };
    let a: Vec<f64> = [32, 64, 128].iter().map(|&n| solve(n).0).collect();
    for w in a.windows(2) {
        let order = (w[0] / w[1]).log2();
        assert!(order >= 1.5, "order of a {order} from {a:?}");
    }
    let c: Vec<f64> = [45, 90, 180].iter().map(|&n| solve(n).1).collect();
    let order = (c[0] / c[2]).log2() / 2.0;
    assert!(order >= 1.5, "order of c {order} from {c:?}");
    let (ea, ec, ea_cells, ec_cells) = solve(256);
    assert!(ea < 1e-3 && ec < 1e-3, "{ea:.2e} {ec:.2e}");
    // The paper's radii are first order: half a cell (0.5 %) and more off.
    assert!(ea_cells > 10.0 * ea && ec_cells > 10.0 * ec);
}

/// Light tangential loads, whose slip annulus is a few cells wide, converge:
/// at 256² of 1 µm, F = 0.12 μP and 0.24 μP stopped unconverged after 5000
/// iterations with the earlier tangential CG (slip cells moved by the
/// projected-gradient step only, conjugacy restarted at every change of the
/// stick set); measured now 90 and 47 fine iterations. The stick radius and
/// the shift follow Cattaneo–Mindlin (measured: c within 0.01 %, δx within
/// 0.02 %).
#[test]
fn light_tangential_loads_converge_to_cattaneo_mindlin() {
    let mut cache = KernelCache::new();
    for ratio in [0.12, 0.24] {
        let spec = common::table_1a_fe(256, 1.0, false, ratio);
        let s = solve_case(&spec, &mut cache).unwrap().scalars;
        let m = mindlin_at(ratio);
        println!(
            "F/μP = {ratio}: c = {:.6e} (Mindlin {:.6e}), δx = {:.6e} (Mindlin {:.6e}), iterations {}",
            s.stick_radius_m, m.c, s.delta_t_m, m.delta, s.tangential_iterations
        );
        assert!(s.converged && s.tangential.converged, "{s:?}");
        assert!(s.tangential_iterations < 500, "{}", s.tangential_iterations);
        assert!(rel(s.stick_radius_m, m.c) < 0.01, "stick radius");
        assert!(rel(s.delta_t_m, m.delta) < 0.01, "shift");
    }
}

/// `solver.radii = "moments"` (issue #34; the default since issue #47): μa's
/// radii (`mu_a_*_radius_m`) from the second moments of p and of μp − |q| on the stick cells
/// are Hertz's a and Mindlin's c on Table 1a uncoupled, and flat isotropic
/// μa is μ with them, as with the hull's (measured at 256² of 1 µm: a
/// −1.1e-5, c −3.5e-4, μa 0.28535 against the hull's 0.28532, μ = 0.28571).
/// Everything else about the case is the same solve: δt, areas and
/// iterations do not depend on the definition.
#[test]
fn moment_radii_are_hertz_and_mindlin_and_give_mu_on_flat() {
    let mut cache = KernelCache::new();
    let m = mindlin();
    let mut spec = table_1a_fe(256, 1.0, false, 0.6);
    spec.numerics.radii = solver::Radii::Hull;
    let hull = solve_case(&spec, &mut cache).unwrap().scalars;
    let spec = table_1a_fe(256, 1.0, false, 0.6);
    assert_eq!(spec.numerics.radii, solver::Radii::Moments, "the default");
    let s = solve_case(&spec, &mut cache).unwrap().scalars;
    println!(
        "moments: a {:.3e}, c {:.3e} off; μa {:.5} (hull {:.5})",
        s.mu_a_contact_radius_m / m.a - 1.0,
        s.mu_a_stick_radius_m / m.c - 1.0,
        s.mu_a.unwrap(),
        hull.mu_a.unwrap()
    );
    assert!(s.converged);
    assert!(rel(s.mu_a_contact_radius_m, m.a) < 1e-4, "a");
    assert!(rel(s.mu_a_stick_radius_m, m.c) < 1e-3, "c");
    assert!(rel(s.mu_a.unwrap(), 0.28571) < 3e-3, "μa");
    // The same solve: only μa's radii (and μa through them) differ; the
    // zones' own radii are their outlines under either (issue #59).
    assert_eq!(s.delta_t_m.to_bits(), hull.delta_t_m.to_bits());
    assert_eq!(s.stick_area_m2.to_bits(), hull.stick_area_m2.to_bits());
    assert_eq!(s.tangential_iterations, hull.tangential_iterations);
    assert_ne!(s.mu_a_contact_radius_m, hull.mu_a_contact_radius_m);
    assert_eq!(hull.mu_a_contact_radius_m, hull.contact_radius_m);
    assert_eq!(
        s.contact_radius_m.to_bits(),
        hull.contact_radius_m.to_bits()
    );
    assert_eq!(s.stick_radius_m.to_bits(), hull.stick_radius_m.to_bits());
}
