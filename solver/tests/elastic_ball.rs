//! An elastic ball (issue #35; PHYSICS.md §5c "Two elastic bodies"): the
//! contact compliance is the sum of the two bodies', the ball's
//! normal–tangential coupling entering with the opposite sign. Checked
//! against Hertz and Cattaneo–Mindlin with the pair's constants, and by the
//! symmetries of the summed kernel.
mod common;

use common::rel;
use solver::pair_influence;
use solver::{presets, solve_case, CaseSpec, KernelCache, Material};
use std::f64::consts::PI;

const P: f64 = 20.0;
const R: f64 = 18.0e-3;
const MU: f64 = 0.28571;

/// `substrate` pressed by a ball of `ball` (R = 18 mm, P = 20 N) on `n`
/// cells of `spacing_um`, F = `ratio` μP along x.
fn pair(
    substrate: &str,
    ball: Option<&str>,
    n: usize,
    spacing_um: f64,
    coupling: bool,
    ratio: f64,
) -> CaseSpec {
    let mut spec = common::table_1a_fe(n, spacing_um, coupling, ratio);
    spec.material = presets::material(substrate).unwrap();
    spec.indenter = ball.map(|b| presets::material(b).unwrap());
    spec
}

/// Isotropic E, ν of a preset.
fn iso(name: &str) -> (f64, f64) {
    let m = presets::material(name).unwrap();
    (m.equivalent.youngs, m.equivalent.poisson)
}

/// Hertz with the pair's contact modulus: (a, p₀, δ).
fn hertz(bodies: &[(f64, f64)]) -> (f64, f64, f64) {
    let e_star = 1.0
        / bodies
            .iter()
            .map(|(e, nu)| (1.0 - nu * nu) / e)
            .sum::<f64>();
    let a = (3.0 * P * R / (4.0 * e_star)).cbrt();
    (a, 3.0 * P / (2.0 * PI * a * a), a * a / R)
}

/// Mindlin's tangential compliance of the pair, Σ (2 − ν)/G.
fn compliance(bodies: &[(f64, f64)]) -> f64 {
    bodies
        .iter()
        .map(|(e, nu)| (2.0 - nu) * 2.0 * (1.0 + nu) / e)
        .sum()
}

#[test]
fn steel_ball_on_copper_follows_hertz_with_the_pairs_modulus() {
    let (a, p0, delta) = hertz(&[iso("Cu"), iso("steel")]);
    let (a_rigid, p0_rigid, _) = hertz(&[iso("Cu")]);
    // The numbers: the contact radius grows by about 19 %, p_max falls by about 29 %.
    assert!((a / a_rigid - 1.177).abs() < 0.01, "{}", a / a_rigid);
    assert!((p0 / p0_rigid - 0.722).abs() < 0.01, "{}", p0 / p0_rigid);
    let spec = pair("Cu", Some("steel"), 512, 0.75, false, 0.0);
    let s = solve_case(&spec, &mut KernelCache::new()).unwrap().scalars;
    println!(
        "steel on Cu: a = {:.6e} (Hertz {a:.6e}, {:+.3e}), p_max = {:.6e} (Hertz {p0:.6e}, {:+.3e}), δz = {:.6e} (Hertz {delta:.6e}, {:+.3e})",
        s.contact_radius_m,
        s.contact_radius_m / a - 1.0,
        s.p_max_pa,
        s.p_max_pa / p0 - 1.0,
        s.delta_z_m,
        s.delta_z_m / delta - 1.0
    );
    assert!(s.converged);
    assert!(
        rel(s.hertz_radius_m, a) < 1e-12,
        "normalisation with the pair's E*"
    );
    assert!(rel(s.contact_radius_m, a) < 1e-3, "a");
    assert!(rel(s.p_max_pa, p0) < 1e-3, "p_max");
    assert!(rel(s.delta_z_m, delta) < 1e-3, "δz");
}

#[test]
fn identical_balls_have_no_coupling_and_follow_cattaneo_mindlin() {
    // Steel on steel, coupling on: β = 0, so the coupled solve is the
    // uncoupled one (one pass) and Cattaneo–Mindlin is exact.
    let bodies = [iso("steel"), iso("steel")];
    let (a, _, _) = hertz(&bodies);
    let ratio: f64 = 0.6;
    let c = a * (1.0 - ratio).cbrt();
    let delta =
        3.0 * MU * P * compliance(&bodies) / (16.0 * a) * (1.0 - (1.0 - ratio).powf(2.0 / 3.0));
    let spec = pair("steel", Some("steel"), 512, 0.65, true, ratio);
    let s = solve_case(&spec, &mut KernelCache::new()).unwrap().scalars;
    println!(
        "steel on steel, coupled: passes {}, c = {:.6e} (CM {c:.6e}, {:+.3e}), δt = {:.6e} (CM {delta:.6e}, {:+.3e}), μa = {:?}",
        s.coupling_iterations,
        s.stick_radius_m,
        s.stick_radius_m / c - 1.0,
        s.delta_t_m,
        s.delta_t_m / delta - 1.0,
        s.mu_a
    );
    assert!(s.converged);
    assert_eq!(
        s.coupling_iterations, 1,
        "the coupling loop ends in its first pass"
    );
    assert!(rel(s.stick_radius_m, c) < 1e-3, "c");
    assert!(rel(s.delta_t_m, delta) < 1e-3, "δt");
    assert!(rel(s.mu_a.unwrap(), MU) < 1e-2, "μa with the pair's K_E");
    // The same pair with coupling off gives the same numbers to the bit.
    let off = solve_case(
        &pair("steel", Some("steel"), 512, 0.65, false, ratio),
        &mut KernelCache::new(),
    )
    .unwrap()
    .scalars;
    assert_eq!(off.delta_t_m, s.delta_t_m);
    assert_eq!(off.stick_radius_m, s.stick_radius_m);
}

#[test]
fn dissimilar_pair_sums_the_tangential_compliances_and_couples_less_than_a_rigid_ball() {
    let bodies = [iso("Cu"), iso("steel")];
    let (a, _, _) = hertz(&bodies);
    let ratio: f64 = 0.6;
    let delta =
        3.0 * MU * P * compliance(&bodies) / (16.0 * a) * (1.0 - (1.0 - ratio).powf(2.0 / 3.0));
    let mut cache = KernelCache::new();
    let off = solve_case(
        &pair("Cu", Some("steel"), 256, 1.5, false, ratio),
        &mut cache,
    )
    .unwrap()
    .scalars;
    println!(
        "steel on Cu, uncoupled: δt = {:.6e} (Mindlin, both bodies {delta:.6e}, {:+.3e})",
        off.delta_t_m,
        off.delta_t_m / delta - 1.0
    );
    assert!(off.converged);
    assert!(rel(off.delta_t_m, delta) < 5e-3, "δt");
    // Coupled: the pair's Dundurs β is a fifth of the rigid ball's, and so
    // is the stick zone's departure from Cattaneo–Mindlin.
    let beta = |g1: f64, nu1: f64, g2: f64, nu2: f64| {
        0.5 * ((1.0 - 2.0 * nu2) / g2 - (1.0 - 2.0 * nu1) / g1)
            / ((1.0 - nu1) / g1 + (1.0 - nu2) / g2)
    };
    let g = |(e, nu): (f64, f64)| e / (2.0 * (1.0 + nu));
    let (cu, steel) = (iso("Cu"), iso("steel"));
    let beta_pair = beta(g(steel), steel.1, g(cu), cu.1);
    let beta_rigid = beta(f64::INFINITY, 0.0, g(cu), cu.1);
    let on = solve_case(
        &pair("Cu", Some("steel"), 256, 1.5, true, ratio),
        &mut cache,
    )
    .unwrap()
    .scalars;
    let rigid_off = solve_case(&pair("Cu", None, 256, 1.5, false, ratio), &mut cache)
        .unwrap()
        .scalars;
    let rigid_on = solve_case(&pair("Cu", None, 256, 1.5, true, ratio), &mut cache)
        .unwrap()
        .scalars;
    let ca = |s: &solver::CaseScalars| s.stick_radius_m / s.contact_radius_m;
    // The stick zone's centroid along the force, relative to the contact
    // radius: zero without coupling (symmetry); with it, the pressure moves
    // towards the trailing edge (uz(q) opens the gap ahead of the traction
    // and closes it behind) and the stick zone follows it backwards.
    let centroid = |out: &solver::CaseOutput| {
        let (n, dx) = (spec_n(), out.scalars.contact_radius_m);
        let (mut sum, mut count) = (0.0, 0.0);
        for j in 0..n {
            for i in 0..n {
                if out.fields.stick[j * n + i] > 0.0 {
                    sum += i as f64 - 0.5 * (n as f64 - 1.0);
                    count += 1.0;
                }
            }
        }
        sum / count * 1.5e-6 / dx
    };
    let on_c = solve_case(
        &pair("Cu", Some("steel"), 256, 1.5, true, ratio),
        &mut cache,
    )
    .unwrap();
    let rigid_on_c = solve_case(&pair("Cu", None, 256, 1.5, true, ratio), &mut cache).unwrap();
    let off_c = solve_case(
        &pair("Cu", Some("steel"), 256, 1.5, false, ratio),
        &mut cache,
    )
    .unwrap();
    let (x_pair, x_rigid, x_off) = (centroid(&on_c), centroid(&rigid_on_c), centroid(&off_c));
    println!(
        "β pair {beta_pair:.4}, rigid {beta_rigid:.4}; c/a coupled − uncoupled: pair {:+.4e}, rigid {:+.4e}; stick centroid / a: pair {x_pair:+.4e}, rigid {x_rigid:+.4e}, uncoupled {x_off:+.1e}",
        ca(&on) - ca(&off),
        ca(&rigid_on) - ca(&rigid_off)
    );
    assert!(on.converged && rigid_on.converged);
    assert!(beta_pair > 0.0 && beta_pair < 0.3 * beta_rigid);
    assert!(x_off.abs() < 1e-12);
    // Backwards (against the force) for both; less for the smaller β.
    assert!(x_rigid < 0.0 && x_pair < 0.0, "{x_pair} {x_rigid}");
    assert!(x_pair.abs() < 0.5 * x_rigid.abs());
}

fn spec_n() -> usize {
    256
}

#[test]
fn crystal_substrate_under_a_steel_ball_and_the_swap() {
    // Cu(111) under a steel ball: load–approach of Hertz with
    // 1/E* = 1/M(Cu(111)) + (1 − ν²)/E(steel), to the accuracy of the
    // near-circular anisotropic contact (1.5 %, as for the rigid ball).
    let crystal = presets::material("Cu(111)").unwrap();
    let m = solver::indentation::indentation_modulus(&crystal);
    let (e, nu) = iso("steel");
    let e_star = 1.0 / (1.0 / m + (1.0 - nu * nu) / e);
    let a = (3.0 * P * R / (4.0 * e_star)).cbrt();
    let mut cache = KernelCache::new();
    let s = solve_case(
        &pair("Cu(111)", Some("steel"), 256, 1.3, false, 0.0),
        &mut cache,
    )
    .unwrap()
    .scalars;
    println!(
        "Cu(111) under steel: δz = {:.6e} (Hertz with M {:.6e}, {:+.3e})",
        s.delta_z_m,
        a * a / R,
        s.delta_z_m / (a * a / R) - 1.0
    );
    assert!(s.converged);
    assert!(rel(s.delta_z_m, a * a / R) < 0.015);
    // Swapped: a steel substrate under a Cu(111) ball. Frictionless normal
    // contact sees only Kzz, the sum of the substrate's at (x, y) and the
    // ball's at (x, −y): the approach is the same and the pressure is the
    // mirror image in y.
    let swapped = solve_case(
        &pair("steel", Some("Cu(111)"), 256, 1.3, false, 0.0),
        &mut cache,
    )
    .unwrap();
    let straight = solve_case(
        &pair("Cu(111)", Some("steel"), 256, 1.3, false, 0.0),
        &mut cache,
    )
    .unwrap();
    assert!(rel(swapped.scalars.delta_z_m, straight.scalars.delta_z_m) < 1e-6);
    let n = 256;
    let mut worst: f64 = 0.0;
    for j in 0..n {
        for i in 0..n {
            let mirrored = (n - 1 - j) * n + i;
            worst = worst.max((swapped.fields.p[j * n + i] - straight.fields.p[mirrored]).abs());
        }
    }
    println!(
        "swap: max |p_swapped(x, y) − p(x, −y)| / p_max = {:.2e}",
        worst / straight.scalars.p_max_pa
    );
    assert!(worst < 1e-6 * straight.scalars.p_max_pa);
}

/// The stiffness mirrored through the plane y = 0 (Voigt components with
/// one y index, yz and xy, change sign against the others).
fn mirror_y(c: &nalgebra::Matrix6<f64>) -> nalgebra::Matrix6<f64> {
    let s = [1.0, 1.0, 1.0, -1.0, 1.0, -1.0];
    nalgebra::Matrix6::from_fn(|i, j| s[i] * s[j] * c[(i, j)])
}

#[test]
fn a_crystal_ball_mirroring_its_flat_through_the_interface_has_no_coupling() {
    // The ball's frame is the substrate's turned 180° about x; a ball that
    // is the substrate's mirror image through the interface (z → −z) has,
    // in its own frame, the substrate's stiffness mirrored in y.
    // Cu (Table 2's cubic constants) with the general normal [1 2 3]: no
    // mirror plane of the crystal contains the frame's axes.
    let crystal = common::cu_123();
    let grid = solver::Grid::square(64, 1e-6);
    let mirror = Material::with_stiffness("mirror", mirror_y(&crystal.stiffness()), None).unwrap();
    let mirrored = pair_influence(
        crystal.model().cell_influence(grid),
        mirror.model().cell_influence(grid),
    );
    let same = pair_influence(
        crystal.model().cell_influence(grid),
        crystal.model().cell_influence(grid),
    );
    let scale = mirrored(0.0, 0.0)[2][2];
    let (mut worst, mut unmirrored): (f64, f64) = (0.0, 0.0);
    for &(x, y) in &[
        (1e-6, 0.0),
        (0.0, 2e-6),
        (3e-6, -2e-6),
        (-5e-6, 4e-6),
        (7e-6, 7e-6),
    ] {
        let k = mirrored(x, y);
        let u = same(x, y);
        for (i, j) in [(0, 2), (1, 2), (2, 0), (2, 1)] {
            worst = worst.max(k[i][j].abs() / scale);
            unmirrored = unmirrored.max(u[i][j].abs() / scale);
        }
    }
    println!(
        "coupling / Kzz(0): mirrored pair {worst:.2e}, same crystal unmirrored {unmirrored:.2e}"
    );
    assert!(worst < 1e-9, "{worst:e}");
    // The crystal against itself (not mirrored) is not such a pair.
    assert!(unmirrored > 1e-3, "{unmirrored:e}");
}

#[test]
fn willis_reference_reduces_to_hertz_for_an_isotropic_pair() {
    let (e, nu) = iso("Cu");
    let (es, nus) = iso("steel");
    let h = 2.0 * (1.0 - nu * nu) / e + 2.0 * (1.0 - nus * nus) / es;
    let (a, b, _, p0) = common::willis(&|_| h, P, R);
    let (ah, ph, _) = hertz(&[iso("Cu"), iso("steel")]);
    assert!(rel(a, ah) < 1e-12 && rel(b, ah) < 1e-12 && rel(p0, ph) < 1e-12);
}

#[test]
fn crystal_substrate_under_a_steel_ball_against_willis() {
    // Cu(110) (x along [001]) is strongly anisotropic in its plane. The
    // pair's normal compliance: the substrate's H33(θ) plus the ball's
    // (isotropic, constant).
    let cu110 = Material::cubic(
        "Cu(110)",
        [168.4e9, 121.4e9, 75.4e9],
        [1.0, 1.0, 0.0],
        [0.0, 0.0, 1.0],
        None,
    )
    .unwrap();
    let (es, nus) = iso("steel");
    let ball = 2.0 * (1.0 - nus * nus) / es;
    let (a, b, phi, p0) =
        common::willis(&|th| cu110.surface_compliance(th)[(2, 2)].re + ball, P, R);
    let n = 384;
    let mut spec = pair("Cu", Some("steel"), n, 0.85, false, 0.0);
    spec.material = cu110;
    let out = solve_case(&spec, &mut KernelCache::new()).unwrap();
    let (sa, sb, sphi) = common::ellipse_of(&out.fields.p, spec.grid);
    let s = &out.scalars;
    println!(
        "Cu(110) under steel: axes {sa:.6e}, {sb:.6e} at {:.3}° (Willis {a:.6e}, {b:.6e} at {:.3}°; ratio {:.5} vs {:.5}), p_max {:.6e} (Willis {p0:.6e}, {:+.2e})",
        sphi.to_degrees(),
        phi.to_degrees().rem_euclid(180.0),
        sb / sa,
        b.min(a) / a.max(b),
        s.p_max_pa,
        s.p_max_pa / p0 - 1.0
    );
    assert!(s.converged);
    let (long, short) = (a.max(b), a.min(b));
    assert!(rel(sa, long) < 1e-3 && rel(sb, short) < 1e-3, "axes");
    assert!(rel(sb / sa, short / long) < 1e-3, "axes ratio");
    assert!(rel(s.p_max_pa, p0) < 1e-3, "p_max");
    // The long axis in the same direction (modulo π), within 0.5°.
    let long_dir = if a > b { phi } else { phi + 0.5 * PI };
    let diff = (long_dir - sphi).rem_euclid(PI);
    assert!(diff.min(PI - diff) < 0.5_f64.to_radians(), "orientation");
}
