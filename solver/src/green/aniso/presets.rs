//! Table 2 presets of the paper (Fe, Cu, Ni in the (111) surface frame) and the
//! least-squares back-fit of cubic constants (C11, C12, C44) to a rotated stiffness.
//! Stiffness values are returned in Pa (the table prints GPa).

use crate::green::aniso::crystal::{cubic_stiffness_rotated, rotate_stiffness, surface_frame};
use nalgebra::{Matrix3, Matrix6, Vector3};

/// The three (111) materials of Table 2.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Table2Material {
    Fe111,
    Cu111,
    Ni111,
}

impl Table2Material {
    pub const ALL: [Table2Material; 3] = [Self::Fe111, Self::Cu111, Self::Ni111];

    pub fn name(self) -> &'static str {
        match self {
            Self::Fe111 => "Fe(111)",
            Self::Cu111 => "Cu(111)",
            Self::Ni111 => "Ni(111)",
        }
    }
}

/// Surface normal (into the body, crystal coordinates) of the Table 2 frame.
pub const TABLE2_NORMAL: [f64; 3] = [1.0, 1.0, 1.0];
/// In-plane x direction of the Table 2 frame (y = z × x), found by [`find_table2_frame`].
pub const TABLE2_X_DIR: [f64; 3] = [1.0, 1.0, -2.0];

/// Table 2 stiffness as printed (GPa → Pa). Voigt xx, yy, zz, yz, xz, xy; C_ij = C_ji.
pub fn table2_stiffness(m: Table2Material) -> Matrix6<f64> {
    // C11, C12, C13, C15, C22, C23, C25, C33, C44, C46, C55, C66
    let v: [f64; 12] = match m {
        Table2Material::Fe111 => [
            300.1, 111.6, 97.26, 20.26, 300.1, 97.26, -20.26, 314.4, 79.93, -20.26, 79.93, 94.25,
        ],
        Table2Material::Cu111 => [
            218.6, 103.7, 86.51, 24.32, 218.6, 86.51, -24.32, 235.8, 40.25, -24.32, 40.25, 57.44,
        ],
        Table2Material::Ni111 => [
            325.7, 129.0, 103.2, 36.58, 325.7, 103.20, -36.58, 351.6, 72.47, -36.58, 72.47, 98.33,
        ],
    };
    let idx = [
        (0, 0),
        (0, 1),
        (0, 2),
        (0, 4),
        (1, 1),
        (1, 2),
        (1, 4),
        (2, 2),
        (3, 3),
        (3, 5),
        (4, 4),
        (5, 5),
    ];
    let mut c = Matrix6::zeros();
    for (&(i, j), &x) in idx.iter().zip(v.iter()) {
        c[(i, j)] = x * 1e9;
        c[(j, i)] = x * 1e9;
    }
    c
}

/// Result of a cubic back-fit.
#[derive(Clone, Debug)]
pub struct CubicFit {
    /// Fitted C11, C12, C44 (Pa, cube-axis frame).
    pub c11: f64,
    pub c12: f64,
    pub c44: f64,
    /// Largest |rotated fit − target| over the 21 independent entries (Pa).
    pub max_abs_dev: f64,
}

/// Least-squares fit of (C11, C12, C44) so that the cubic stiffness rotated into the
/// frame (z = `normal`, x = `x_dir`, y = z × x) matches `target` over its 21
/// independent entries. The rotated stiffness is linear in the three constants.
pub fn fit_cubic(
    target: &Matrix6<f64>,
    normal: [f64; 3],
    x_dir: [f64; 3],
) -> Result<CubicFit, String> {
    let r: Matrix3<f64> = surface_frame(normal, x_dir)?;
    let basis = [
        rotate_stiffness(
            &crate::green::aniso::crystal::cubic_stiffness(1.0, 0.0, 0.0),
            &r,
        ),
        rotate_stiffness(
            &crate::green::aniso::crystal::cubic_stiffness(0.0, 1.0, 0.0),
            &r,
        ),
        rotate_stiffness(
            &crate::green::aniso::crystal::cubic_stiffness(0.0, 0.0, 1.0),
            &r,
        ),
    ];
    let mut ata = Matrix3::zeros();
    let mut atb = Vector3::zeros();
    for i in 0..6 {
        for j in i..6 {
            for a in 0..3 {
                atb[a] += basis[a][(i, j)] * target[(i, j)];
                for b in 0..3 {
                    ata[(a, b)] += basis[a][(i, j)] * basis[b][(i, j)];
                }
            }
        }
    }
    let x = ata
        .try_inverse()
        .ok_or("fit_cubic: singular normal equations")?
        * atb;
    let fitted = cubic_stiffness_rotated(x[0], x[1], x[2], normal, x_dir)?;
    let mut dev: f64 = 0.0;
    for i in 0..6 {
        for j in i..6 {
            dev = dev.max((fitted[(i, j)] - target[(i, j)]).abs());
        }
    }
    Ok(CubicFit {
        c11: x[0],
        c12: x[1],
        c44: x[2],
        max_abs_dev: dev,
    })
}

/// Candidate (111) frames: normal ±[111] and x along each <112>/<110> direction
/// perpendicular to it. Returns (normal, x_dir, fit) sorted by deviation.
pub fn find_table2_frame(m: Table2Material) -> Vec<([f64; 3], [f64; 3], CubicFit)> {
    let target = table2_stiffness(m);
    let mut xs: Vec<[f64; 3]> = Vec::new();
    let perms = [[0, 1, 2], [1, 2, 0], [2, 0, 1]];
    for p in perms {
        for base in [[1.0, 1.0, -2.0], [1.0, -1.0, 0.0]] {
            for sign in [1.0, -1.0] {
                xs.push([sign * base[p[0]], sign * base[p[1]], sign * base[p[2]]]);
            }
        }
    }
    let mut out = Vec::new();
    for normal in [[1.0, 1.0, 1.0], [-1.0, -1.0, -1.0]] {
        for &x in &xs {
            if let Ok(f) = fit_cubic(&target, normal, x) {
                out.push((normal, x, f));
            }
        }
    }
    out.sort_by(|a, b| a.2.max_abs_dev.total_cmp(&b.2.max_abs_dev));
    out
}

/// Cubic constants (C11, C12, C44 in Pa) back-fitted to Table 2 in the Table 2 frame.
pub fn table2_cubic_constants(m: Table2Material) -> CubicFit {
    fit_cubic(&table2_stiffness(m), TABLE2_NORMAL, TABLE2_X_DIR).expect("valid frame")
}
