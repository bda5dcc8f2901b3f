//! A crystal cut at a general orientation (issue #39's first check): Cu
//! with the surface normal [1 2 3], which no mirror plane or rotation axis
//! of the cubic crystal contains, under a rigid sphere, against Willis's
//! elliptical Hertz solution for the anisotropic half-space (Willis 1966;
//! the reference in `common::willis`, from the material's own H33(θ)).
mod common;

use common::rel;
use solver::{solve_case, KernelCache};
use std::f64::consts::PI;

#[test]
fn a_general_orientation_follows_willis_elliptical_hertz() {
    let cu123 = common::cu_123();
    let mut spec = common::table_1a_fe(384, 0.75, false, 0.0);
    spec.material = cu123.clone();
    let (load, radius) = (spec.load.normal_force_n, spec.load.indenter_radius_m);
    let (a, b, phi, p0) =
        common::willis(&|th| cu123.surface_compliance(th)[(2, 2)].re, load, radius);
    let out = solve_case(&spec, &mut KernelCache::new()).unwrap();
    let (sa, sb, sphi) = common::ellipse_of(&out.fields.p, spec.grid);
    let s = &out.scalars;
    let (long, short) = (a.max(b), a.min(b));
    println!(
        "Cu[123]: axes {sa:.6e}, {sb:.6e} at {:.3}° (Willis {long:.6e}, {short:.6e} at {:.3}°; ratio {:.6} vs {:.6}, {:+.2e}), p_max {:.6e} (Willis {p0:.6e}, {:+.2e})",
        sphi.to_degrees(),
        (if a > b { phi } else { phi + 0.5 * PI }).to_degrees().rem_euclid(180.0),
        sb / sa,
        short / long,
        (sb / sa) / (short / long) - 1.0,
        s.p_max_pa,
        s.p_max_pa / p0 - 1.0
    );
    assert!(s.converged);
    // Not circular: the orientation matters, and the test can see it.
    assert!(short / long < 0.995, "ratio {}", short / long);
    assert!(rel(sb / sa, short / long) < 1e-3, "axes ratio");
    assert!(rel(s.p_max_pa, p0) < 1e-3, "p_max");
    let long_dir = if a > b { phi } else { phi + 0.5 * PI };
    let diff = (long_dir - sphi).rem_euclid(PI);
    assert!(diff.min(PI - diff) < 1.0_f64.to_radians(), "orientation");
}

/// Cubic constants (GPa) of Cu (paper Table 2) and Fe (back-fitted to its
/// Table 2 stiffness, docs/validation.md).
const CU: [f64; 3] = [168.4e9, 121.4e9, 75.4e9];
const FE: [f64; 3] = [257.12e9, 125.913e9, 108.576e9];

/// A cubic crystal cut with `normal` and `x_dir`.
fn cut(c: [f64; 3], normal: [f64; 3], x_dir: [f64; 3]) -> solver::Material {
    solver::Material::cubic("crystal", c, normal, x_dir, None).unwrap()
}

/// `[0 1 0] × n`, the default in-plane x of `sweep.orientations`.
fn default_x(n: [f64; 3]) -> [f64; 3] {
    [n[2], 0.0, -n[0]]
}

/// Vlassak and Nix's indentation modulus over the standard triangle, for Cu
/// and Fe: `solver::indentation::indentation_modulus` (the mean of H33 by
/// the integral formalism) against the same mean from the sextic Stroh
/// eigenvalues (an independent route), and against the solved contact: the
/// solved approach equals Willis's, and the modulus it implies,
/// `3P/(4√R δ^3/2)`, differs from Vlassak–Nix's only by the ellipticity of
/// the contact, which Vlassak–Nix's circular approximation leaves out.
#[test]
fn indentation_modulus_over_the_triangle_is_vlassak_nix() {
    use solver::indentation::{indentation_modulus, willis_contact};
    let normals = [
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [1.0, 1.0, 1.0],
        [2.0, 1.0, 3.0],
        [1.0, 0.0, 3.0],
        [1.0, 1.0, 3.0],
        [2.0, 1.0, 2.0],
    ];
    for (name, c) in [("Cu", CU), ("Fe", FE)] {
        let mut moduli = Vec::new();
        for n in normals {
            let m = cut(c, n, default_x(n));
            let mut spec = common::table_1a_fe(256, 1.0, false, 0.0);
            spec.material = m.clone();
            let (p, r) = (spec.load.normal_force_n, spec.load.indenter_radius_m);
            let mvn = indentation_modulus(&m);
            let k = 512;
            let sextic = (0..k)
                .map(|j| {
                    solver::aniso::stroh::surface_compliance_sextic(
                        &m.stiffness(),
                        PI * j as f64 / k as f64,
                    )[(2, 2)]
                        .re
                })
                .sum::<f64>()
                / k as f64;
            let w = willis_contact(&|th| m.surface_compliance(th)[(2, 2)].re, p, r);
            let modulus_of = |d: f64| 3.0 * p / (4.0 * r.sqrt() * d.powf(1.5));
            let out = solve_case(&spec, &mut KernelCache::new()).unwrap();
            let d = out.scalars.delta_z_m;
            println!(
                "{name}{n:?}: M = {:.4} GPa (sextic {:+.1e}); solved δ vs Willis {:+.2e}; M from δ: Willis {:+.2e}, solved {:+.2e}; b/a {:.4}",
                mvn / 1e9,
                (2.0 / sextic) / mvn - 1.0,
                d / w.approach_m - 1.0,
                modulus_of(w.approach_m) / mvn - 1.0,
                modulus_of(d) / mvn - 1.0,
                w.short_m / w.long_m
            );
            assert!(out.scalars.converged);
            assert!(rel(2.0 / sextic, mvn) < 1e-9, "{name}{n:?}: two routes");
            assert!(rel(d, w.approach_m) < 1e-4, "{name}{n:?}: approach");
            let ellipticity = rel(modulus_of(w.approach_m), mvn);
            assert!(
                rel(modulus_of(d), mvn) <= ellipticity + 1e-4,
                "{name}{n:?}: solved modulus"
            );
            // A circular contact (the 3- and 4-fold axes) has none.
            if w.short_m / w.long_m > 1.0 - 1e-9 {
                assert!(ellipticity < 1e-12, "{name}{n:?}");
            }
            moduli.push(mvn);
        }
        // The extremes sit at the corners: softest at (001), stiffest at
        // (111) for these crystals (anisotropy ratio 2C44/(C11−C12) > 1).
        let (lo, hi) = (moduli[0], moduli[2]);
        assert!(
            moduli.iter().all(|&m| m >= lo && m <= hi),
            "{name}: {moduli:?}"
        );
    }
}

/// Equivalent normals with corresponding frames give the same contact: the
/// frames turned by a proper rotation of the cubic group ([1 2 3] → [−3 2 1]
/// by −90° about [010], → [−2 −1 −3] by the mirror x ↔ y composed with the
/// inversion) to round-off; the mirror x ↔ y alone ([2 1 3]) makes the
/// mirror image of the frame (y = z × x), whose response at ψ is the
/// original's at −ψ.
#[test]
fn equivalent_normals_give_the_same_contact() {
    let (n, x) = ([1.0, 2.0, 3.0], [1.0, 1.0, -1.0]);
    let solve = |m: &solver::Material, psi: f64| {
        let mut spec = common::table_1a_fe(128, 2.0, true, 0.6);
        spec.material = m.clone();
        spec.load.angle_deg = psi;
        // Tight tolerances: the frames' stiffnesses differ by round-off,
        // which the iterations carry to their tolerance, not beyond.
        spec.numerics.tangential_tolerance = 1e-12;
        spec.numerics.coupling_tolerance = 1e-12;
        solve_case(&spec, &mut KernelCache::new()).unwrap().scalars
    };
    let base = cut(CU, n, x);
    let rotated = [
        cut(CU, [-3.0, 2.0, 1.0], [1.0, 1.0, 1.0]),
        cut(CU, [-2.0, -1.0, -3.0], [-1.0, -1.0, 1.0]),
    ];
    let mirrored = cut(CU, [2.0, 1.0, 3.0], [1.0, 1.0, -1.0]);
    let scale = base.stiffness().amax();
    for m in &rotated {
        assert!((m.stiffness() - base.stiffness()).amax() / scale < 1e-14);
    }
    for psi in [0.0, 30.0] {
        let s0 = solve(&base, psi);
        let check = |s: &solver::CaseScalars, what: &str| {
            for (name, a, b) in [
                ("mu_a", s.mu_a.unwrap(), s0.mu_a.unwrap()),
                ("delta_t", s.delta_t_m, s0.delta_t_m),
                ("delta_z", s.delta_z_m, s0.delta_z_m),
                ("p_max", s.p_max_pa, s0.p_max_pa),
                ("contact area", s.contact_area_m2, s0.contact_area_m2),
                ("stick area", s.stick_area_m2, s0.stick_area_m2),
            ] {
                println!("{what} ψ = {psi}: {name} {:+.2e}", a / b - 1.0);
                assert!(rel(a, b) < 1e-10, "{what} ψ = {psi}: {name} {a} vs {b}");
            }
        };
        for m in &rotated {
            check(&solve(m, psi), "rotated");
        }
        check(&solve(&mirrored, -psi), "mirrored at −ψ");
    }
}
