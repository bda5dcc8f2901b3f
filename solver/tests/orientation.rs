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
