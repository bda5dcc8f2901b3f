//! Validation ladder steps 2 and 6 for anisotropic substrates: the anisotropic
//! influence-coefficient route against the isotropic closed forms, and normal /
//! partial-slip contact on the paper's Fe(111).

mod common;

use common::table_1a_fe;
use solver::aniso::{cell_influence, AngularKernel};
use solver::influence::isotropic_cell;
use solver::Isotropic;
use solver::{solve_case, KernelCache};

#[test]
fn anisotropic_route_with_isotropic_stiffness_equals_closed_forms_on_64x64() {
    let iso = Isotropic::new(210.0e9, 0.3).unwrap();
    let kernel = AngularKernel::new(&iso.stiffness());
    let (dx, dy) = (0.5e-6, 0.5e-6);
    let k00 = isotropic_cell(iso.shear(), iso.poisson, 0.0, 0.0, dx, dy)[2][2];
    let mut worst: f64 = 0.0;
    // Every offset of the 2N x 2N wrap-around kernel of a 64 x 64 grid.
    for j in -63i32..=63 {
        for i in -63i32..=63 {
            let (x, y) = (i as f64 * dx, j as f64 * dy);
            let a = cell_influence(&kernel, x, y, dx, dy);
            let b = isotropic_cell(iso.shear(), iso.poisson, x, y, dx, dy);
            for r in 0..3 {
                for c in 0..3 {
                    worst = worst.max((a[(r, c)] - b[r][c]).abs() / k00);
                }
            }
        }
    }
    println!("max |K_aniso − K_closed| / K_zz(0,0) = {worst:.3e}");
    assert!(worst < 1e-6, "{worst:e}");
}

fn fe111(n: usize, spacing_um: f64, ratio: f64) -> solver::CaseSpec {
    let mut spec = table_1a_fe(n, spacing_um, true, ratio);
    spec.material = solver::presets::material("Fe(111)").unwrap();
    spec
}

/// Bilinear interpolation of a row-major field at (x, y).
fn sample(f: &[f64], grid: &solver::operator::Grid, x: f64, y: f64) -> f64 {
    let n = grid.n;
    let fx = x / grid.dx + 0.5 * (n as f64 - 1.0);
    let fy = y / grid.dy + 0.5 * (n as f64 - 1.0);
    let (i, j) = (fx.floor() as usize, fy.floor() as usize);
    let (u, v) = (fx - i as f64, fy - j as f64);
    let at = |a: usize, b: usize| f[b * n + a];
    (1.0 - u) * (1.0 - v) * at(i, j)
        + u * (1.0 - v) * at(i + 1, j)
        + (1.0 - u) * v * at(i, j + 1)
        + u * v * at(i + 1, j + 1)
}

#[test]
fn fe111_normal_contact_follows_hertz_with_indentation_modulus_and_is_threefold() {
    let spec = fe111(384, 0.6, 0.0);
    let m = solver::indentation::indentation_modulus(&spec.material);
    let out = solve_case(&spec, &mut KernelCache::new()).unwrap();
    let s = &out.scalars;
    let (p, r) = (20.0_f64, 18.0e-3_f64);
    let a_m = (3.0 * p * r / (4.0 * m)).cbrt();
    let delta_m = a_m * a_m / r;
    let p_m = 3.0 * p / (2.0 * std::f64::consts::PI * a_m * a_m);
    println!(
        "M = {:.3} GPa; δz = {:.6e} (Hertz-M {delta_m:.6e}); a = {:.6e} (Hertz-M {a_m:.6e}, paper 0.10124e-3); p_max = {:.5e} (Hertz-M {p_m:.5e}, paper 931.62e6)",
        m / 1e9,
        s.delta_z_m,
        s.contact_radius_m,
        s.p_max_pa
    );
    assert!(s.converged);
    assert!(
        (s.delta_z_m / delta_m - 1.0).abs() < 0.015,
        "load–approach vs Hertz with M"
    );
    assert!((s.normal_force_n / p - 1.0).abs() < 1e-8);
    // Three-fold symmetry of the pressure: p(r, φ) = p(r, φ + 120°) inside the contact.
    let grid = spec.grid;
    let mut worst: f64 = 0.0;
    for k in 0..36 {
        let phi = (k as f64 * 10.0).to_radians();
        for frac in [0.0, 0.3, 0.6, 0.85] {
            let rr = frac * s.contact_radius_m;
            let p0 = sample(&out.fields.p, &grid, rr * phi.cos(), rr * phi.sin());
            let ph = phi + 2.0 * std::f64::consts::PI / 3.0;
            let p1 = sample(&out.fields.p, &grid, rr * ph.cos(), rr * ph.sin());
            worst = worst.max((p0 - p1).abs() / s.p_max_pa);
        }
    }
    println!("max |p(φ) − p(φ+120°)| / p_max = {worst:.2e}");
    assert!(worst < 2e-3, "{worst:e}");
}

#[test]
fn fe111_coupled_partial_slip_converges_with_equilibrium() {
    let spec = fe111(256, 0.9, 0.6);
    let s = solve_case(&spec, &mut KernelCache::new()).unwrap().scalars;
    println!(
        "Fe(111) coupled: c/a = {:.4}, δt = {:.4e}, δt⊥ = {:.3e}, p_max = {:.4e}, q_max = {:.4e}, iterations n/t/c {} {} {}",
        s.stick_radius_m / s.contact_radius_m,
        s.delta_t_m,
        s.delta_t_perp_m,
        s.p_max_pa,
        s.q_max_pa,
        s.normal_iterations,
        s.tangential_iterations,
        s.coupling_iterations
    );
    assert!(s.converged);
    let f = 0.6 * 0.28571 * 20.0;
    assert!((s.tangential_force_n[0] / f - 1.0).abs() < 1e-8);
    assert!(s.tangential_force_n[1].abs() < 1e-8 * f);
    assert!((s.normal_force_n / 20.0 - 1.0).abs() < 1e-8);
    assert!(s.stick_radius_m < s.contact_radius_m && s.stick_radius_m > 0.5 * s.contact_radius_m);
}
