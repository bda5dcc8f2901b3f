//! Stresses below the surface (solver::stress) against closed forms and
//! invariants: Hamilton's explicit Hertz field, the maximum shear and von
//! Mises landmarks, the surface conditions and equilibrium of the
//! response, the trailing-edge tension of a sliding contact, the Stroh
//! path with an isotropic stiffness against the closed form, and the
//! three-fold symmetry of a (111) crystal.

mod stress_closed_forms;

use solver::stress::{peak, tresca, von_mises, Line, StressField, StressPlan};
use solver::{Grid, Material};
use stress_closed_forms::{
    boussinesq, cerruti, hamilton_normal, sliding_tangential, trailing_edge_sxx,
};

const A: f64 = 100e-6;
const P0: f64 = 1e9;

/// Hertz pressure (and q = f p along x) at the cell centres of `n²` cells over `width` contact radii.
fn hertz(n: usize, width: f64, f: f64) -> (Grid, Vec<f64>, Vec<f64>, Vec<f64>) {
    let grid = Grid::square(n, width * A / n as f64);
    let mut p = vec![0.0; n * n];
    for iy in 0..n {
        for ix in 0..n {
            let r2 = (grid.x(ix).powi(2) + grid.y(iy).powi(2)) / (A * A);
            p[iy * n + ix] = if r2 < 1.0 {
                P0 * (1.0 - r2).sqrt()
            } else {
                0.0
            };
        }
    }
    let qx = p.iter().map(|v| f * v).collect();
    (grid, p, qx, vec![0.0; n * n])
}

fn fe() -> Material {
    Material::isotropic("Fe", 210e9, 0.3).unwrap()
}

/// Worst |computed − Hamilton| / p0 over the six components along the row
/// next to the centre, at `depths` (units of a), for the frictionless Hertz field.
fn hamilton_error(material: &Material, n: usize, depths: &[f64]) -> f64 {
    let (grid, p, qx, qy) = hertz(n, 4.0, 0.0);
    let mut plan = StressPlan::new(material, grid).unwrap();
    let t = plan.tractions(&p, &qx, &qy);
    let iy = n / 2;
    let mut worst = 0.0_f64;
    for &z in depths {
        let plane = plan.plane(z * A).unwrap();
        let s = plan.apply_line(&plane, &t, Line::Row(iy));
        let mut here = 0.0_f64;
        for ix in 0..n {
            let (x, y) = (grid.x(ix) / A, grid.y(iy) / A);
            let want = hamilton_normal(x, y, z, 0.3);
            for (comp, w) in s.components.iter().zip(want) {
                here = here.max((comp[ix] / P0 - w).abs());
            }
        }
        println!("n = {n}, z = {z} a: worst component error {here:.2e} p0");
        worst = worst.max(here);
    }
    worst
}

#[test]
fn hertz_field_matches_hamilton_within_half_percent_of_p0_at_128() {
    let worst = hamilton_error(&fe(), 128, &[0.1, 0.25, 0.48, 0.8, 1.5]);
    assert!(worst < 5e-3, "worst {worst:e} p0");
    // At the surface the in-plane stresses of the cell-mean pressure
    // differ most at the contact edge, where Hamilton's field has a kink.
    let surface = hamilton_error(&fe(), 128, &[0.0]);
    assert!(surface < 2e-2, "surface {surface:e} p0");
}

/// 512² version of the Hamilton comparison, for docs/validation.md:
/// `cargo test --release -p mpcontact-solver --test stress -- --ignored --nocapture hamilton_512`
#[test]
#[ignore]
fn hamilton_512() {
    let worst = hamilton_error(&fe(), 512, &[0.0, 0.05, 0.1, 0.25, 0.48, 0.8, 1.5]);
    println!("worst over depths {worst:e} p0");
}

/// The x–z slice through the contact centre (row next to it), depths 0..1.2a.
fn slice(material: &Material, n: usize, f: f64, depths: usize) -> (Grid, Vec<StressField>) {
    let (grid, p, qx, qy) = hertz(n, 4.0, f);
    let mut plan = StressPlan::new(material, grid).unwrap();
    let t = plan.tractions(&p, &qx, &qy);
    let rows = (0..=depths)
        .map(|k| {
            let plane = plan.plane(1.2 * A * k as f64 / depths as f64).unwrap();
            plan.apply_line(&plane, &t, Line::Row(n / 2))
        })
        .collect();
    (grid, rows)
}

/// The largest of `f` over a slice: value, x and z.
fn slice_peak(grid: &Grid, rows: &[StressField], f: impl Fn([f64; 6]) -> f64) -> (f64, f64, f64) {
    let mut best = (f64::NEG_INFINITY, 0.0, 0.0);
    for r in rows {
        let pk = peak(&r.map(&f)).unwrap();
        if pk.value > best.0 {
            best = (pk.value, grid.x(pk.index), r.depth_m);
        }
    }
    best
}

#[test]
fn frictionless_max_shear_is_0_31_p0_at_0_48_a_and_von_mises_matches_hamilton_axis() {
    let (grid, rows) = slice(&fe(), 128, 0.0, 60);
    let (tau, _, z_tau) = slice_peak(&grid, &rows, tresca);
    let (vm, _, z_vm) = slice_peak(&grid, &rows, von_mises);
    // Hamilton on the axis, maximised over z by a fine search.
    let (mut vm_ref, mut z_ref, mut tau_ref, mut zt_ref) = (0.0, 0.0, 0.0, 0.0);
    for k in 1..12000 {
        let z = k as f64 * 1e-4;
        let s = hamilton_normal(0.0, 0.0, z, 0.3);
        let v = von_mises(s);
        if v > vm_ref {
            (vm_ref, z_ref) = (v, z);
        }
        let t = tresca(s);
        if t > tau_ref {
            (tau_ref, zt_ref) = (t, z);
        }
    }
    println!(
        "max shear {:.4} p0 at z = {:.3} a (Hamilton axis {tau_ref:.4} at {zt_ref:.3}); max von Mises {:.4} p0 at z = {:.3} a (Hamilton axis {vm_ref:.4} at {z_ref:.3})",
        tau / P0, z_tau / A, vm / P0, z_vm / A
    );
    assert!((tau / P0 - 0.31).abs() < 0.005, "max shear {}", tau / P0);
    assert!((z_tau / A - 0.48).abs() < 0.021, "its depth {}", z_tau / A);
    assert!((tau - tau_ref * P0).abs() < 5e-3 * P0);
    assert!((vm - vm_ref * P0).abs() < 5e-3 * P0, "max von Mises");
    // The slice samples depth every 0.02 a.
    assert!((z_vm - z_ref * A).abs() < 0.021 * A, "its depth");
}

/// `∂_j σ_ij = 0` inside the body and `σ_iz = −t_i` on the surface, for
/// the response itself (each traction column): with compatibility (the
/// stresses come from a displacement through C) these make it the
/// elastic solution.
#[test]
fn response_satisfies_equilibrium_and_the_surface_tractions() {
    let cu111 = solver::presets::material("Cu(111)").unwrap();
    for material in [fe(), cu111] {
        let plan = StressPlan::new(&material, Grid::square(16, 1e-6)).unwrap();
        let mut worst_bc = 0.0_f64;
        let mut worst_eq = 0.0_f64;
        for k in 0..24 {
            let th = 0.27 + k as f64 * std::f64::consts::TAU / 24.0;
            let rho = 1.0e5;
            let (ex, ey) = (rho * th.cos(), rho * th.sin());
            let m0 = plan.response(ex, ey, 0.0);
            // z rows (σzz, σyz, σxz) against −(p, qy, qx).
            for (row, col) in [(2, 2), (3, 1), (4, 0)] {
                for (c, v) in m0[row].iter().enumerate() {
                    let want = if c == col { -1.0 } else { 0.0 };
                    worst_bc = worst_bc.max((v - want).norm());
                }
            }
            for z in [0.3 / rho, 1.0 / rho, 3.0 / rho] {
                let h = 1e-4 / rho;
                let m = plan.response(ex, ey, z);
                let (mp, mm) = (plan.response(ex, ey, z + h), plan.response(ex, ey, z - h));
                let i = num_complex::Complex64::i();
                // rows (x, y, z) of σ: (xx, xy, xz), (xy, yy, yz), (xz, yz, zz)
                for (a, b, c) in [(0, 5, 4), (5, 1, 3), (4, 3, 2)] {
                    for col in 0..3 {
                        let div = -i * ex * m[a][col] - i * ey * m[b][col]
                            + (mp[c][col] - mm[c][col]) / (2.0 * h);
                        worst_eq = worst_eq.max(div.norm() / rho);
                    }
                }
            }
        }
        println!(
            "{}: surface {worst_bc:.2e}, equilibrium {worst_eq:.2e}",
            material.name
        );
        assert!(
            worst_bc < 1e-9,
            "{}: surface tractions {worst_bc:e}",
            material.name
        );
        assert!(
            worst_eq < 1e-6,
            "{}: equilibrium {worst_eq:e}",
            material.name
        );
    }
}

/// Fraction of the resultant of a traction field `w` (on `grid`) carried
/// through the window of `grid` at depth `z`, with each 4x4 block of cells
/// lumped into a point load at its centroid: Boussinesq's
/// `σzz = −3Pz³/(2πR⁵)` (`normal`) or Cerruti's `σxz = −3Qx²z/(2πR⁵)`,
/// integrated over the window by the midpoint rule on cells 4 times finer.
fn window_fraction(grid: &Grid, w: &[f64], z: f64, normal: bool) -> f64 {
    let n = grid.n;
    let total: f64 = w.iter().sum();
    let half = 0.5 * n as f64 * grid.dx;
    let k = 4 * n;
    let d = 2.0 * half / k as f64;
    let mut acc = 0.0;
    for by in (0..n).step_by(4) {
        for bx in (0..n).step_by(4) {
            let (mut wb, mut xb, mut yb) = (0.0, 0.0, 0.0);
            for iy in by..by + 4 {
                for ix in bx..bx + 4 {
                    let v = w[iy * n + ix];
                    wb += v;
                    xb += v * grid.x(ix);
                    yb += v * grid.y(iy);
                }
            }
            if wb == 0.0 {
                continue;
            }
            let (xb, yb) = (xb / wb, yb / wb);
            let mut inside = 0.0;
            for j in 0..k {
                for i in 0..k {
                    let x = -half + (i as f64 + 0.5) * d - xb;
                    let y = -half + (j as f64 + 0.5) * d - yb;
                    let r2 = x * x + y * y + z * z;
                    let r5 = r2 * r2 * r2.sqrt();
                    let lead = if normal { z * z } else { x * x };
                    inside += 3.0 * lead * z / (2.0 * std::f64::consts::PI * r5);
                }
            }
            acc += wb * inside * d * d;
        }
    }
    acc / total
}

#[test]
fn each_depth_plane_carries_the_applied_forces() {
    let n = 128;
    let (grid, p, qx, qy) = hertz(n, 8.0, 0.3);
    let mut plan = StressPlan::new(&fe(), grid).unwrap();
    let t = plan.tractions(&p, &qx, &qy);
    let da = grid.cell_area();
    let fz: f64 = p.iter().sum::<f64>() * da;
    let fx: f64 = qx.iter().sum::<f64>() * da;
    for z in [0.0, 0.25, 0.5, 1.0] {
        let s = {
            let pl = plan.plane(z * A).unwrap();
            plan.apply(&pl, &t)
        };
        let rz: f64 = -s.components[2].iter().sum::<f64>() * da;
        let rx: f64 = -s.components[4].iter().sum::<f64>() * da;
        let ry: f64 = -s.components[3].iter().sum::<f64>() * da;
        let (in_z, in_x) = if z == 0.0 {
            (1.0, 1.0)
        } else {
            (
                window_fraction(&grid, &p, z * A, true),
                window_fraction(&grid, &qx, z * A, false),
            )
        };
        println!(
            "z = {z} a: Σσzz/P = {:.6} (Boussinesq inside the window {in_z:.6}), Σσxz/Q = {:.6} (Cerruti {in_x:.6}), Σσyz/Q = {:.1e}",
            rz / fz,
            rx / fx,
            ry / fx
        );
        assert!(
            (rz / fz - in_z).abs() < 1e-3,
            "normal resultant at z = {z} a"
        );
        assert!(
            (rx / fx - in_x).abs() < 1e-3,
            "tangential resultant at z = {z} a"
        );
        assert!(ry.abs() < 1e-9 * fx);
    }
}

/// Surface stresses from the surface strains of the (independently
/// validated) influence coefficients: for an isotropic body at z = 0,
/// `σxx = 2G/(1−ν) (εxx + ν εyy) + ν/(1−ν) σzz`, `σxy = 2G εxy`. The
/// strains are central differences over `h = Δx/1000` of displacements
/// summed cell by cell (the cell-mean tractions jump at cell edges, where
/// the surface strains have logarithmic kinks: a difference across the
/// cell would not do).
#[test]
fn surface_stresses_under_sliding_equal_hookes_law_on_the_surface_strains() {
    // (6.9e-5 and 6.7e-5 p0 with the surface's alias series converged,
    // issue #51; 8.2e-4 and 5.9e-4 with 4 orders before)
    let errors: Vec<f64> = [64, 128].map(hooke).to_vec();
    assert!(errors.iter().all(|&e| e < 2e-4), "{errors:?}");
}

fn hooke(n: usize) -> f64 {
    let f = 0.3;
    let (grid, p, qx, qy) = hertz(n, 4.0, f);
    let (g, nu) = (210e9 / 2.6, 0.3);
    let u = |x: f64, y: f64| -> [f64; 2] {
        let mut acc = [0.0; 2];
        for iy in 0..n {
            for ix in 0..n {
                let c = iy * n + ix;
                if p[c] == 0.0 {
                    continue;
                }
                let k = solver::influence::isotropic_cell(
                    g,
                    nu,
                    x - grid.x(ix),
                    y - grid.y(iy),
                    grid.dx,
                    grid.dy,
                );
                acc[0] += k[0][0] * qx[c] + k[0][2] * p[c];
                acc[1] += k[1][0] * qx[c] + k[1][2] * p[c];
            }
        }
        acc
    };
    let mut plan = StressPlan::new(&fe(), grid).unwrap();
    let t = plan.tractions(&p, &qx, &qy);
    let iy = n / 2;
    let s = {
        let pl = plan.plane(0.0).unwrap();
        plan.apply_line(&pl, &t, Line::Row(iy))
    };
    let h = 1e-3 * grid.dx;
    let mut worst = 0.0_f64;
    for ix in 2..n - 2 {
        let (x, y) = (grid.x(ix), grid.y(iy));
        let (xp, xm, yp, ym) = (u(x + h, y), u(x - h, y), u(x, y + h), u(x, y - h));
        let exx = (xp[0] - xm[0]) / (2.0 * h);
        let eyy = (yp[1] - ym[1]) / (2.0 * h);
        let exy = 0.5 * ((yp[0] - ym[0]) / (2.0 * h) + (xp[1] - xm[1]) / (2.0 * h));
        let i = iy * n + ix;
        let sxx = 2.0 * g / (1.0 - nu) * (exx + nu * eyy) - nu / (1.0 - nu) * p[i];
        let syy = 2.0 * g / (1.0 - nu) * (eyy + nu * exx) - nu / (1.0 - nu) * p[i];
        let sxy = 2.0 * g * exy;
        for (c, want) in [(0, sxx), (1, syy), (5, sxy)] {
            worst = worst.max((s.components[c][ix] - want).abs() / P0);
        }
    }
    println!("n = {n}: surface in-plane stresses vs Hooke on the strains: worst {worst:.2e} p0");
    worst
}

/// The peak surface σxx of a sliding Hertz contact (q = f p along +x) on
/// `n²` cells: value (units of p0) and place (units of a).
fn trailing_edge_peak(n: usize, f: f64) -> (f64, f64) {
    let (grid, p, qx, qy) = hertz(n, 4.0, f);
    let mut plan = StressPlan::new(&fe(), grid).unwrap();
    let t = plan.tractions(&p, &qx, &qy);
    let s = {
        let pl = plan.plane(0.0).unwrap();
        plan.apply_line(&pl, &t, Line::Row(n / 2))
    };
    let pk = peak(&s.components[0]).unwrap();
    (pk.value / P0, grid.x(pk.index) / A)
}

/// Hamilton's trailing-edge tension is the value at the edge point; cell
/// centres sit half a cell away, where the field falls like the square
/// root of the distance, so the peak converges like √Δx: extrapolated
/// from 128² and 256² (Richardson with that order) it must land on
/// Hamilton's value within 1 %.
#[test]
fn sliding_surface_tension_peaks_at_the_trailing_edge_as_hamilton() {
    let f = 0.3;
    let want = trailing_edge_sxx(0.3, f);
    let (v1, x1) = trailing_edge_peak(128, f);
    let (v2, x2) = trailing_edge_peak(256, f);
    let r = 2f64.sqrt();
    let extrapolated = (r * v2 - v1) / (r - 1.0);
    println!(
        "peak σxx: 128² {v1:.4} p0 at x = {x1:.4} a, 256² {v2:.4} p0 at x = {x2:.4} a, extrapolated {extrapolated:.4}; Hamilton {want:.4} p0 at x = −a"
    );
    assert!(
        (x1 + 1.0).abs() < 4.0 / 128.0 && (x2 + 1.0).abs() < 4.0 / 256.0,
        "at the trailing edge"
    );
    assert!(v2 > v1 && v2 < want, "converges from below");
    assert!(
        (extrapolated / want - 1.0).abs() < 0.01,
        "extrapolated peak"
    );
}

/// 512² trailing-edge peak for docs/validation.md.
#[test]
#[ignore]
fn trailing_edge_512() {
    let (v, x) = trailing_edge_peak(512, 0.3);
    println!(
        "512²: peak σxx {v:.4} p0 at x = {x:.4} a (Hamilton {:.4})",
        trailing_edge_sxx(0.3, 0.3)
    );
}

#[test]
fn stroh_path_with_an_isotropic_stiffness_equals_the_closed_form_within_1e_6() {
    let iso = fe();
    let c = iso.stiffness();
    let as_crystal = Material::with_stiffness("Fe as a crystal", c, Some(iso.equivalent)).unwrap();
    assert!(!as_crystal.is_isotropic());
    let n = 64;
    let (grid, p, qx, qy) = hertz(n, 4.0, 0.3);
    let mut a = StressPlan::new(&iso, grid).unwrap();
    let mut b = StressPlan::new(&as_crystal, grid).unwrap();
    let (ta, tb) = (a.tractions(&p, &qx, &qy), b.tractions(&p, &qx, &qy));
    let mut worst = 0.0_f64;
    for z in [0.0, 0.1, 0.5, 1.0] {
        let sa = {
            let pl = a.plane(z * A).unwrap();
            a.apply(&pl, &ta)
        };
        let sb = {
            let pl = b.plane(z * A).unwrap();
            b.apply(&pl, &tb)
        };
        for c in 0..6 {
            for (u, v) in sa.components[c].iter().zip(&sb.components[c]) {
                worst = worst.max((u - v).abs() / P0);
            }
        }
    }
    println!("Stroh (isotropic C) vs closed form: worst {worst:.2e} p0");
    assert!(worst < 1e-6);
}

/// Von Mises at `(x, y)` from a map by 4-point Lagrange interpolation.
fn interpolate(grid: &Grid, map: &[f64], x: f64, y: f64) -> f64 {
    let n = grid.n;
    let u = x / grid.dx + 0.5 * (n as f64 - 1.0);
    let v = y / grid.dy + 0.5 * (n as f64 - 1.0);
    let w = |f: f64| {
        [
            -f * (f - 1.0) * (f - 2.0) / 6.0,
            (f + 1.0) * (f - 1.0) * (f - 2.0) / 2.0,
            -(f + 1.0) * f * (f - 2.0) / 2.0,
            (f + 1.0) * f * (f - 1.0) / 6.0,
        ]
    };
    let (i0, j0) = (u.floor() as usize, v.floor() as usize);
    let (wx, wy) = (w(u - i0 as f64), w(v - j0 as f64));
    let mut acc = 0.0;
    for (j, wyj) in wy.iter().enumerate() {
        for (i, wxi) in wx.iter().enumerate() {
            acc += wyj * wxi * map[(j0 + j - 1) * n + i0 + i - 1];
        }
    }
    acc
}

/// Largest change of the von Mises map at depth under a rotation by `deg` about the load axis.
fn rotation_asymmetry(grid: &Grid, map: &[f64], deg: f64) -> f64 {
    let (s, c) = deg.to_radians().sin_cos();
    let mut worst = 0.0_f64;
    for k in 0..40 {
        let r = 0.05 * A + k as f64 * 0.04 * A;
        for l in 0..24 {
            let phi = l as f64 * std::f64::consts::TAU / 24.0 + 0.1;
            let (x, y) = (r * phi.cos(), r * phi.sin());
            let (xr, yr) = (c * x - s * y, s * x + c * y);
            let d = interpolate(grid, map, x, y) - interpolate(grid, map, xr, yr);
            worst = worst.max(d.abs());
        }
    }
    worst
}

#[test]
fn a_111_crystal_under_hertz_pressure_shows_three_fold_symmetry() {
    let cu111 = solver::presets::material("Cu(111)").unwrap();
    let n = 128;
    let (grid, p, qx, qy) = hertz(n, 4.0, 0.0);
    let mut plan = StressPlan::new(&cu111, grid).unwrap();
    let t = plan.tractions(&p, &qx, &qy);
    let s = {
        let pl = plan.plane(0.4 * A).unwrap();
        plan.apply(&pl, &t)
    };
    let vm = s.map(von_mises);
    let (a120, a240, a60) = (
        rotation_asymmetry(&grid, &vm, 120.0),
        rotation_asymmetry(&grid, &vm, 240.0),
        rotation_asymmetry(&grid, &vm, 60.0),
    );
    println!("Cu(111) von Mises at z = 0.4a, change under rotation: 120° {:.2e}, 240° {:.2e}, 60° {:.2e} p0", a120 / P0, a240 / P0, a60 / P0);
    assert!(a120 < 1e-3 * P0 && a240 < 1e-3 * P0, "three-fold");
    assert!(a60 > 10.0 * a120, "not six-fold: the test sees the crystal");
}

/// A load history keeps the tractions of its turning points (what the
/// stresses of a fretting cycle are computed from): one per turning step,
/// the last equal to the case's final fields to the bit.
#[test]
fn a_load_history_keeps_the_tractions_of_its_turning_points() {
    let spec = solver::CaseSpec {
        material: fe(),
        surface: solver::Surface::Flat,
        grid: Grid::square(64, 4e-6),
        load: solver::Load {
            indenter_radius_m: 18e-3,
            normal_force_n: 20.0,
            friction: 0.3,
            tangential_ratio: 0.0,
            angle_deg: 0.0,
        },
        numerics: solver::Numerics::default(),
        history: Some(solver::LoadHistory {
            tangential_ratios: vec![0.0, 0.5, -0.5],
            normal_forces_n: None,
            increments: solver::Increments::Fixed(3),
            sampling: Default::default(),
            shifts_m: None,
            wear: None,
        }),
        indenter: None,
    };
    let out = solver::solve_case(&spec, &mut solver::KernelCache::new()).unwrap();
    let h = out.scalars.history.as_ref().unwrap();
    let steps: Vec<usize> = out.turning.iter().map(|t| t.step).collect();
    assert_eq!(steps, h.turning_steps);
    let last = out.turning.last().unwrap();
    assert!(last.p == out.fields.p && last.qx == out.fields.qx && last.qy == out.fields.qy);
    // The +F state's force, recovered from its tractions, is +0.5 μP.
    let da = spec.grid.cell_area();
    let fx: f64 = out.turning[1].qx.iter().sum::<f64>() * da;
    assert!((fx / (0.3 * 20.0) - 0.5).abs() < 1e-3, "{fx}");
}

/// The reference of the sliding comparisons, checked on its own: Cerruti's
/// point-force field is in equilibrium (`∂jσij = 0`), compatible
/// (Beltrami–Michell, `∇²σij + ∂i∂j I1/(1+ν) = 0`), free of normal and
/// shear traction on the surface away from the force, and carries the
/// force through every plane (`∫σxz dA = −1`, a closed-form integral);
/// its quadrature over the Hertz traction is converged (rules of 16 and
/// 24 points agree), far away the traction acts as its resultant `2π/3`
/// at the centre, and at the trailing edge it gives Hamilton's tension.
#[test]
fn cerruti_reference_is_an_elastic_field_and_its_quadrature_converged() {
    let nu = 0.3;
    let residuals = |h: f64| -> (f64, f64) {
        let mut worst_eq = 0.0_f64;
        let mut worst_bm = 0.0_f64;
        let idx = |i: usize, j: usize| -> usize {
            // Voigt index of (i, j): xx yy zz yz xz xy.
            match (i.min(j), i.max(j)) {
                (0, 0) => 0,
                (1, 1) => 1,
                (2, 2) => 2,
                (1, 2) => 3,
                (0, 2) => 4,
                _ => 5,
            }
        };
        for &(x, y, z) in &[(0.7, -0.4, 0.5), (-1.3, 0.9, 0.8), (0.2, 1.1, 1.7)] {
            let at = |dx: [f64; 3]| cerruti(x + dx[0], y + dx[1], z + dx[2], nu);
            let e = |k: usize, step: f64| {
                let mut v = [0.0; 3];
                v[k] = step;
                v
            };
            let scale = cerruti(x, y, z, nu)
                .iter()
                .fold(0.0_f64, |m, v| m.max(v.abs()));
            for i in 0..3 {
                let mut div = 0.0;
                for j in 0..3 {
                    div += (at(e(j, h))[idx(i, j)] - at(e(j, -h))[idx(i, j)]) / (2.0 * h);
                }
                worst_eq = worst_eq.max(div.abs() / scale);
            }
            let i1 = |d: [f64; 3]| {
                let s = at(d);
                s[0] + s[1] + s[2]
            };
            for i in 0..3 {
                for j in i..3 {
                    let c = idx(i, j);
                    let mut lap = 0.0;
                    for k in 0..3 {
                        lap += (at(e(k, h))[c] - 2.0 * at([0.0; 3])[c] + at(e(k, -h))[c]) / (h * h);
                    }
                    let d_ij = |a: f64, b: f64| {
                        let mut v = e(i, a);
                        v[j] += b;
                        i1(v)
                    };
                    let hess =
                        (d_ij(h, h) - d_ij(h, -h) - d_ij(-h, h) + d_ij(-h, -h)) / (4.0 * h * h);
                    worst_bm = worst_bm.max((lap + hess / (1.0 + nu)).abs() / scale);
                }
            }
        }
        (worst_eq, worst_bm)
    };
    let (eq2, bm2) = residuals(2e-3);
    let (worst_eq, worst_bm) = residuals(1e-3);
    let surface = cerruti(0.6, -0.3, 0.0, nu);
    println!(
        "Cerruti: equilibrium {worst_eq:.1e} ({eq2:.1e} with h = 2e-3), Beltrami–Michell {worst_bm:.1e} ({bm2:.1e}) (relative to the largest component, differences over h = 1e-3), surface σzz σyz σxz {:?}",
        &surface[2..5]
    );
    // Truncation of the differences (falls like h²), not a wrong term.
    assert!(worst_eq < 1e-4 && worst_bm < 1e-3);
    assert!(eq2 > 3.0 * worst_eq && bm2 > 3.0 * worst_bm);
    assert!(surface[2..5].iter().all(|v| *v == 0.0));
    // ∫σxz dA over a plane at depth z, by rings (closed form of the angle part).
    let z = 0.7;
    let mut flux = 0.0;
    let gl = stress_closed_forms::gauss_legendre(40);
    for piece in 0..60 {
        let (ra, rb) = (piece as f64 * 0.5, (piece + 1) as f64 * 0.5);
        for &(u, w) in &gl {
            let r = 0.5 * (ra + rb) + 0.5 * (rb - ra) * u;
            // ∫ cos²θ dθ = π: σxz(r, θ) = cerruti(r cosθ, ..) ∝ cos²θ.
            let s = cerruti(r, 0.0, z, nu)[4];
            flux += 0.5 * (rb - ra) * w * r * s * std::f64::consts::PI;
        }
    }
    // Beyond r = 30 in closed form: −(3z/2) ∫ r³/(r² + z²)^{5/2} dr.
    let u: f64 = 30.0 * 30.0 + z * z;
    flux += -1.5 * z * (u.powf(-0.5) - z * z / (3.0 * u.powf(1.5)));
    println!("Cerruti: ∫σxz dA over z = {z}: {flux:.12} (−1)");
    assert!((flux + 1.0).abs() < 1e-9);

    let mut worst_rule = 0.0_f64;
    for &(x, y, z) in &[
        (0.0, 0.0, 0.1),
        (-0.95, 0.2, 0.1),
        (1.3, 0.4, 0.25),
        (0.3, -1.2, 0.5),
    ] {
        let (a, b) = (
            sliding_tangential(x, y, z, nu, 16),
            sliding_tangential(x, y, z, nu, 24),
        );
        for (u, v) in a.iter().zip(b) {
            worst_rule = worst_rule.max((u - v).abs());
        }
    }
    let far = sliding_tangential(6.0, 2.0, 4.0, nu, 16);
    let point = cerruti(6.0, 2.0, 4.0, nu).map(|v| v * 2.0 * std::f64::consts::PI / 3.0);
    let far_rel = (far[4] / point[4] - 1.0).abs();
    println!("sliding quadrature: rules 16 vs 24 differ by {worst_rule:.1e} (units of f p0); far field σxz vs the resultant at the centre {far_rel:.1e}");
    assert!(worst_rule < 1e-6);
    assert!(far_rel < 0.02);
    // Hamilton's trailing-edge tension of the tangential part, π(4 + ν)/8
    // (per unit f p0) at (−a, 0, 0): the field has a square-root edge, so
    // σxx(z) → σ0 + c√z; Richardson with that order from z = 1e-6, 2e-6.
    let (a, b) = (
        sliding_tangential(-1.0, 0.0, 1e-6, nu, 16)[0],
        sliding_tangential(-1.0, 0.0, 2e-6, nu, 16)[0],
    );
    let r = 2f64.sqrt();
    let edge = (r * a - b) / (r - 1.0);
    let hamilton = trailing_edge_sxx(nu, 1.0) - trailing_edge_sxx(nu, 0.0);
    println!("trailing edge, tangential part: {edge:.8} (Hamilton π(4 + ν)/8 = {hamilton:.8})");
    assert!((edge - hamilton).abs() < 1e-5);
}

/// Worst |computed − reference| / p0 over the six components for the
/// sliding Hertz contact (q = f p along +x): Hamilton's normal field plus
/// `f` times the tangential field (Cerruti integrated, see
/// `sliding_tangential`), on three rows (y ≈ 0, 0.5a, 1.2a: through the
/// contact, and beside it) at `depths` (units of a), every `step`-th cell.
/// On the surface (z = 0) the reference is the limit from below and cells
/// within 0.1a of the contact edge (where the field has its square-root
/// kink, checked by the trailing-edge test) are left out.
fn sliding_error(n: usize, f: f64, depths: &[f64], step: usize) -> f64 {
    let nu = 0.3;
    let (grid, p, qx, qy) = hertz(n, 4.0, f);
    let mut plan = StressPlan::new(&fe(), grid).unwrap();
    let t = plan.tractions(&p, &qx, &qy);
    let rows = [
        n / 2,
        n / 2 + n / 8,
        n / 2 + (1.2 * n as f64 / 4.0) as usize,
    ];
    let mut worst = 0.0_f64;
    for &z in depths {
        let plane = plan.plane(z * A).unwrap();
        let mut here = 0.0_f64;
        let mut size = 0.0_f64;
        let mut worst_at = (0.0, 0.0);
        for &iy in &rows {
            let s = plan.apply_line(&plane, &t, Line::Row(iy));
            for ix in (0..n).step_by(step) {
                let (x, y) = (grid.x(ix) / A, grid.y(iy) / A);
                let normal = hamilton_normal(x, y, z, nu);
                let tangential = if z > 0.0 {
                    sliding_tangential(x, y, z, nu, 16)
                } else {
                    // On the surface: the limit z → 0 of the (smooth, away
                    // from the edge) field, Richardson over z = h, 2h, 3h.
                    let r = (x * x + y * y).sqrt();
                    if (r - 1.0).abs() < 0.1 {
                        continue;
                    }
                    let hz = 0.001;
                    let f1 = sliding_tangential(x, y, hz, nu, 16);
                    let f2 = sliding_tangential(x, y, 2.0 * hz, nu, 16);
                    let f3 = sliding_tangential(x, y, 3.0 * hz, nu, 16);
                    std::array::from_fn(|c| 3.0 * f1[c] - 3.0 * f2[c] + f3[c])
                };
                for c in 0..6 {
                    size = size.max((f * tangential[c]).abs());
                    let want = normal[c] + f * tangential[c];
                    let d = (s.components[c][ix] / P0 - want).abs();
                    if d > here {
                        here = d;
                        worst_at = (x, y);
                    }
                }
            }
        }
        println!(
            "n = {n}, f = {f}, z = {z} a: worst component error {here:.2e} p0 at (x, y) = ({:.3}, {:.3}) a (the tangential part reaches {size:.3} p0)",
            worst_at.0, worst_at.1
        );
        worst = worst.max(here);
    }
    worst
}

/// The sliding Hertz contact (f = 0.3, ν = 0.3) point by point, all six
/// components on rows through and beside the contact at four depths: at
/// 128² within 0.5 % of p0 below the surface and 2 % on it, as the
/// frictionless test (measured numbers in docs/validation.md).
#[test]
fn sliding_hertz_field_matches_hamilton_point_by_point_at_128() {
    let worst = sliding_error(128, 0.3, &[0.1, 0.25, 0.5, 1.0], 1);
    assert!(worst < 5e-3, "worst {worst:e} p0");
    // On the surface the in-plane stresses of the tangential traction
    // follow its local slope: the cell-mean traction's error near the
    // edge falls like √Δ (as the trailing-edge peak), 2 % at 128².
    let surface = sliding_error(128, 0.3, &[0.0], 1);
    assert!(surface < 2e-2, "surface {surface:e} p0");
}

/// 512² version, for docs/validation.md (0.5 % of p0 asked):
/// `cargo test --release -p mpcontact-solver --test stress -- --ignored --nocapture sliding_512`
#[test]
#[ignore]
fn sliding_512() {
    let worst = sliding_error(512, 0.3, &[0.0, 0.1, 0.25, 0.5, 1.0], 2);
    println!("worst over depths {worst:e} p0");
    assert!(worst < 5e-3, "worst {worst:e} p0");
}

/// The stress at `(x, y, z)` of the cell tractions `p` and `qx` on `grid`
/// (Pa, z below the surface in m), each cell's force spread on 4x4
/// points: Boussinesq's and Cerruti's point forces summed.
fn point_force_sum(grid: &Grid, p: &[f64], qx: &[f64], at: [f64; 3], nu: f64) -> [f64; 6] {
    let n = grid.n;
    let (sub, da) = (4, grid.cell_area());
    let mut acc = [0.0; 6];
    for iy in 0..n {
        for ix in 0..n {
            let i = iy * n + ix;
            if p[i] == 0.0 && qx[i] == 0.0 {
                continue;
            }
            let (fz, fx) = (p[i] * da / 16.0, qx[i] * da / 16.0);
            for sy in 0..sub {
                for sx in 0..sub {
                    let x = grid.x(ix) + grid.dx * ((sx as f64 + 0.5) / sub as f64 - 0.5);
                    let y = grid.y(iy) + grid.dy * ((sy as f64 + 0.5) / sub as f64 - 0.5);
                    let (u, v) = (at[0] - x, at[1] - y);
                    let b = boussinesq(u, v, at[2], nu);
                    let c = cerruti(u, v, at[2], nu);
                    for k in 0..6 {
                        acc[k] += fz * b[k] + fx * c[k];
                    }
                }
            }
        }
    }
    acc
}

/// Boussinesq's field, the reference below, checked on its own: the
/// resultant through a plane is the force (`∫σzz dA = −1`, rings in
/// closed form), and far from a Hertz contact Hamilton's exact field is
/// that of the resultant `2π/3 p0 a²` at the centre, all six components
/// within the `(a/R)²` of the spread load.
#[test]
fn boussinesq_reference_carries_the_force_and_is_hamiltons_far_field() {
    let nu = 0.3;
    let z = 0.9;
    let gl = stress_closed_forms::gauss_legendre(40);
    let mut flux = 0.0;
    for piece in 0..60 {
        let (ra, rb) = (piece as f64 * 0.5, (piece + 1) as f64 * 0.5);
        for &(u, w) in &gl {
            let r = 0.5 * (ra + rb) + 0.5 * (rb - ra) * u;
            flux += 0.5 * (rb - ra) * w * r * boussinesq(r, 0.0, z, nu)[2] * std::f64::consts::TAU;
        }
    }
    // Beyond r = 30: −(3z³/2π) 2π ∫ r/(r² + z²)^{5/2} dr = −z³ (r² + z²)^{−3/2}.
    flux -= z * z * z / (30.0f64 * 30.0 + z * z).powf(1.5);
    println!("Boussinesq: ∫σzz dA over z = {z}: {flux:.12} (−1)");
    assert!((flux + 1.0).abs() < 1e-9);
    let mut worst = 0.0_f64;
    for &(x, y, z) in &[(3.0, 1.0, 5.0), (-6.0, 2.0, 4.0), (0.5, -0.2, 8.0)] {
        let far = hamilton_normal(x, y, z, nu);
        let point = boussinesq(x, y, z, nu).map(|v| v * 2.0 * std::f64::consts::PI / 3.0);
        let size = far.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let r2 = x * x + y * y + z * z;
        for c in 0..6 {
            worst = worst.max((far[c] - point[c]).abs() / size * r2);
        }
    }
    println!(
        "Boussinesq against Hamilton far away: largest difference {worst:.2} (a/R)² of the field"
    );
    assert!(worst < 2.0);
}

/// Issue #59 item 7: the stresses of tractions confined to the domain at
/// depths from 0.1a to many domain widths, on the window's centre and two
/// cells off it. A Hertz pressure and, as a second state, a Hertz shear
/// along x, 64² over 4a (the padded period T = 8a): against Hamilton's
/// fields (the normal and, integrated, the sliding one) to a, and from a
/// down against Boussinesq's and Cerruti's point forces summed over the
/// cells, all six components, relative to p0 to a and below it to the
/// point force's `σzz` on its axis.
/// Before, the periodic images of the padded grid's wider lattice were
/// left in: σzz under the pressure fell to a constant `−P/(16T²)`, 3× the
/// point force's at 5T and 2e4× at 1250T.
#[test]
fn deep_planes_carry_boussinesq_and_cerruti_fields_to_a_thousand_domain_widths() {
    let (nu, n) = (0.3, 64);
    let (grid, p, q, zero) = hertz(n, 4.0, 1.0);
    let mut plan = StressPlan::new(&fe(), grid).unwrap();
    let states = [
        plan.tractions(&p, &zero, &zero),
        plan.tractions(&zero, &q, &zero),
    ];
    let cells = [(n / 2, n / 2), (n / 2 + 9, n / 2 - 5), (3, n - 7)];
    let mut worst_shallow = 0.0_f64;
    let mut worst_deep = 0.0_f64;
    for z in [0.1, 0.5, 1.0, 2.0, 4.0, 8.0, 20.0, 40.0, 100.0, 1e3, 1e4] {
        let plane = plan.plane(z * A).unwrap();
        for (s, t) in states.iter().enumerate() {
            let got = plan.apply(&plane, t);
            let wants: Vec<[f64; 6]> = cells
                .iter()
                .map(|&(ix, iy)| {
                    let (x, y) = (grid.x(ix), grid.y(iy));
                    if z <= 1.0 {
                        let f = if s == 0 {
                            hamilton_normal(x / A, y / A, z, nu)
                        } else {
                            sliding_tangential(x / A, y / A, z, nu, 16)
                        };
                        f.map(|v| v * P0)
                    } else {
                        let (pp, qq) = if s == 0 { (&p, &zero) } else { (&zero, &q) };
                        point_force_sum(&grid, pp, qq, [x, y, z * A], nu)
                    }
                })
                .collect();
            // The scale: p0 to a deep, then the point force's σzz on its
            // axis, 3F/(2πz²) (within the window a shear's field is
            // smaller still: Cerruti's vanishes on the axis).
            let force = if s == 0 { &p } else { &q }.iter().sum::<f64>() * grid.cell_area();
            let size = if z <= 1.0 {
                P0
            } else {
                3.0 * force / (std::f64::consts::TAU * (z * A).powi(2))
            };
            let mut err = 0.0_f64;
            for (&(ix, iy), want) in cells.iter().zip(&wants) {
                for (c, w) in want.iter().enumerate() {
                    err = err.max((got.components[c][iy * n + ix] - w).abs() / size);
                    if std::env::var("DEBUG_DEEP").is_ok() {
                        println!(
                            "  z {z} s {s} cell {ix},{iy} c {c}: got {:.6e} want {:.6e}",
                            got.components[c][iy * n + ix],
                            w
                        );
                    }
                }
            }
            println!(
                "{} at z = {z} a ({:.3} T): largest error {err:.1e} of the stress scale",
                ["pressure", "shear"][s],
                z / 8.0
            );
            if z <= 1.0 {
                worst_shallow = worst_shallow.max(err);
            } else {
                worst_deep = worst_deep.max(err);
            }
        }
    }
    assert!(worst_shallow < 2e-3, "{worst_shallow:e}");
    assert!(worst_deep < 1e-4, "{worst_deep:e}");
}
