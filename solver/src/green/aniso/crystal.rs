//! Stiffness matrices (engineering Voigt, Pa, surface frame): isotropic and rotated
//! cubic constructors, general tensor rotation, and a positive-definiteness check.
//! Frame convention: z = surface normal pointing into the body, x given, y = z × x.

use crate::green::aniso::stroh::{voigt_index, voigt_to_tensor};
use nalgebra::{Matrix3, Matrix6, Vector3};

/// Isotropic stiffness from Young's modulus (Pa) and Poisson's ratio.
pub fn isotropic_stiffness(e_pa: f64, nu: f64) -> Matrix6<f64> {
    let lam = e_pa * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
    let mu = e_pa / (2.0 * (1.0 + nu));
    let mut c = Matrix6::zeros();
    for i in 0..3 {
        for j in 0..3 {
            c[(i, j)] = lam;
        }
        c[(i, i)] = lam + 2.0 * mu;
        c[(i + 3, i + 3)] = mu;
    }
    c
}

/// Cubic stiffness in the crystal frame (cube axes).
pub fn cubic_stiffness(c11: f64, c12: f64, c44: f64) -> Matrix6<f64> {
    let mut c = Matrix6::zeros();
    for i in 0..3 {
        for j in 0..3 {
            c[(i, j)] = c12;
        }
        c[(i, i)] = c11;
        c[(i + 3, i + 3)] = c44;
    }
    c
}

/// Rotate a stiffness into a new frame. `r` has the new axes (unit vectors,
/// expressed in the old frame) as its rows: `C'_ijkl = r_ia r_jb r_kc r_ld C_abcd`.
pub fn rotate_stiffness(c: &Matrix6<f64>, r: &Matrix3<f64>) -> Matrix6<f64> {
    let t = voigt_to_tensor(c);
    let mut out = Matrix6::zeros();
    for (i, j) in [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)] {
        for (k, l) in [(0, 0), (1, 1), (2, 2), (1, 2), (0, 2), (0, 1)] {
            let mut s = 0.0;
            for (a, ta) in t.iter().enumerate() {
                for (b, tab) in ta.iter().enumerate() {
                    let f_ab = r[(i, a)] * r[(j, b)];
                    if f_ab == 0.0 {
                        continue;
                    }
                    for (cc, tabc) in tab.iter().enumerate() {
                        for (d, v) in tabc.iter().enumerate() {
                            s += f_ab * r[(k, cc)] * r[(l, d)] * v;
                        }
                    }
                }
            }
            out[(voigt_index(i, j), voigt_index(k, l))] = s;
        }
    }
    out
}

/// Surface-frame rotation for a crystal: rows x, y, z (crystal coordinates) with
/// z = `normal`/|normal| (into the body), x = `x_dir`/|x_dir|, y = z × x (right-handed).
pub fn surface_frame(normal: [f64; 3], x_dir: [f64; 3]) -> Result<Matrix3<f64>, String> {
    let z = Vector3::from(normal);
    let x = Vector3::from(x_dir);
    if z.norm() == 0.0 || x.norm() == 0.0 || !z.norm().is_finite() || !x.norm().is_finite() {
        return Err("surface frame: normal and x direction must be non-zero and finite".into());
    }
    let z = z.normalize();
    let x = x.normalize();
    let dot = x.dot(&z);
    if dot.abs() > 1e-9 {
        return Err(format!(
            "surface frame: x direction {x_dir:?} is not perpendicular to the normal {normal:?} \
             (cos angle = {dot:.3e})"
        ));
    }
    let y = z.cross(&x);
    Ok(Matrix3::from_rows(&[
        x.transpose(),
        y.transpose(),
        z.transpose(),
    ]))
}

/// Cubic crystal (C11, C12, C44 in Pa, cube-axis frame) expressed in the surface
/// frame with z along `normal_miller` (pointing into the body), x along
/// `x_dir_miller`, y = z × x. Errors if x is not perpendicular to the normal.
/// Note: flipping the normal with x fixed equals flipping x with the normal fixed
/// (a 180° turn about x composed with the inversion symmetry of any stiffness).
pub fn cubic_stiffness_rotated(
    c11: f64,
    c12: f64,
    c44: f64,
    normal_miller: [f64; 3],
    x_dir_miller: [f64; 3],
) -> Result<Matrix6<f64>, String> {
    let r = surface_frame(normal_miller, x_dir_miller)?;
    Ok(rotate_stiffness(&cubic_stiffness(c11, c12, c44), &r))
}

/// Check that a stiffness is finite, symmetric (relative tolerance 1e-9 of the largest
/// entry) and positive definite (all eigenvalues > 1e-12 × the largest).
pub fn check_positive_definite(c: &Matrix6<f64>) -> Result<(), String> {
    if c.iter().any(|v| !v.is_finite()) {
        return Err("stiffness has non-finite entries".into());
    }
    let scale = c.amax();
    if scale == 0.0 {
        return Err("stiffness is identically zero".into());
    }
    for i in 0..6 {
        for j in (i + 1)..6 {
            let d = (c[(i, j)] - c[(j, i)]).abs();
            if d > 1e-9 * scale {
                return Err(format!(
                    "stiffness not symmetric: C{}{} = {:.6e} but C{}{} = {:.6e}",
                    i + 1,
                    j + 1,
                    c[(i, j)],
                    j + 1,
                    i + 1,
                    c[(j, i)]
                ));
            }
        }
    }
    let sym = (c + c.transpose()) * 0.5;
    let eig = sym.symmetric_eigen();
    let min = eig.eigenvalues.min();
    let max = eig.eigenvalues.max();
    if min <= 1e-12 * max.abs() {
        return Err(format!(
            "stiffness not positive definite: smallest eigenvalue {min:.6e} Pa \
             (largest {max:.6e} Pa); strain energy would not be positive"
        ));
    }
    Ok(())
}
